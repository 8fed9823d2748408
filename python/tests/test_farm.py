"""The Dask farm against real `dask scheduler` and `dask worker` processes
on 127.0.0.1 (each worker with its own temporary directory, so each unpacks
its own copy of the scene archive): the results equal one-process renders
byte for byte, also when a worker is killed mid-render, and a scene that
cannot be built comes back as a SceneError with the client's paths."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import candela
from candela import farm
from conftest import CORNELL, CROP, make_multifile_scene, run_cli

distributed = pytest.importorskip("distributed")

DASK = str(Path(sys.executable).with_name("dask"))


class Cluster:
    """A scheduler and `n` single-threaded workers, each its own process."""

    def __init__(self, tmp: Path, n: int):
        self.tmp = tmp
        tmp.mkdir(parents=True, exist_ok=True)
        self.file = tmp / "scheduler.json"
        self.workers = []
        self.scheduler = self._spawn("scheduler", "--host", "127.0.0.1", "--port", "0",
                                     "--no-dashboard", "--scheduler-file", str(self.file))
        for _ in range(n):
            self.start_worker()
        deadline = time.monotonic() + 60
        while not self.file.exists() and time.monotonic() < deadline:
            time.sleep(0.05)
        self.client = distributed.Client(scheduler_file=str(self.file), timeout=60)
        self.client.wait_for_workers(n, timeout=60)

    @property
    def address(self) -> str:
        return self.client.scheduler.address

    def _spawn(self, *args: str, env=None) -> subprocess.Popen:
        log = open(self.tmp / f"{args[0]}-{len(self.workers)}.log", "wb")
        return subprocess.Popen([DASK, *args], stdout=log, stderr=subprocess.STDOUT,
                                env=env, start_new_session=True)

    def start_worker(self) -> subprocess.Popen:
        own_tmp = self.tmp / f"worker-{len(self.workers)}"
        own_tmp.mkdir()
        env = dict(os.environ, TMPDIR=str(own_tmp))
        w = self._spawn("worker", "--scheduler-file", str(self.file), "--nthreads", "1",
                        "--no-nanny", "--host", "127.0.0.1", "--no-dashboard",
                        "--local-directory", str(own_tmp), env=env)
        self.workers.append(w)
        return w

    def kill(self, proc: subprocess.Popen) -> None:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()

    def close(self) -> None:
        """Shuts the scheduler and the workers down (or kills them)."""
        try:
            self.client.shutdown()
        except Exception:
            self.client.close()
        for p in self.workers + [self.scheduler]:
            try:
                p.wait(timeout=5)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    c = Cluster(tmp_path_factory.mktemp("cluster"), 2)
    yield c
    c.close()


def test_ppm_over_two_workers_equals_one_process(cluster, ppm_cornell):
    seen = []
    with distributed.get_task_stream(cluster.client) as ts:
        r = farm.render(cluster.client, ppm_cornell, passes=8, chunk=2, crop=CROP, seed=2,
                        threads=1, progress=lambda d, t, s: seen.append((d, t)))
    ref = candela.load(ppm_cornell).render(spp=8, crop=CROP, seed=2)
    assert r.exr == ref.exr_bytes()
    assert r.state == ref.to_bytes()
    assert (r.passes, r.chunks) == (8, 4)
    assert seen[-1] == (8, 8) and [d for d, _ in seen] == [2, 4, 6, 8]
    rendering = {t["worker"] for t in ts.data if t["key"].startswith("candela-passes-")}
    assert len(rendering) == 2, "both workers rendered passes"


def test_path_through_the_command_line_equals_candela_render(cluster, tmp_path):
    crop = ",".join(str(v) for v in CROP)
    out, state = tmp_path / "farm.exr", tmp_path / "farm.cndl"
    r = subprocess.run([sys.executable, "-m", "candela.farm", str(CORNELL), "--scheduler",
                        cluster.address, "--passes", "8", "--chunk", "2", "--crop", crop,
                        "--seed", "1", "-o", str(out), "--state", str(state)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert "8/8 passes" in r.stderr
    ref = tmp_path / "cli.exr"
    run_cli("render", str(CORNELL), "--spp", "8", "--cropwindow", crop, "--seed", "1",
            "--quiet", "--outfile", str(ref))
    assert out.read_bytes() == ref.read_bytes()
    run_cli("merge", str(CORNELL), str(state), "--outfile", str(tmp_path / "merged.exr"))
    assert (tmp_path / "merged.exr").read_bytes() == ref.read_bytes()


def test_every_file_of_the_scene_travels_in_the_archive(cluster, tmp_path):
    path, files = make_multifile_scene(tmp_path)
    r = farm.render(cluster.client, path, passes=4, chunk=1, progress=False)
    assert r.exr == candela.load(path).render(spp=4).exr_bytes()
    packed = candela.archive.pack(path)
    assert packed.files == ["scene/parts/floor.pbrt", "scene/refl.spd", "scene/scene.pbrt",
                            "scene/tex/checks.png", "shared/quad.ply"]
    assert len(files) == len(packed.files)


def test_a_missing_ply_comes_back_with_the_clients_file_line_col(cluster, scene_dir):
    path = scene_dir / "s.pbrt"
    path.write_text('Film "rgb" "integer xresolution" [8] "integer yresolution" [8]\nWorldBegin\n'
                    'LightSource "infinite"\n  Shape "plymesh" "string filename" "lost.ply"\n')
    with pytest.raises(candela.SceneError) as info:
        farm.render(cluster.client, path, passes=2, progress=False)
    e = info.value
    # The client only parses the scene: this came from the worker's build,
    # with the worker's unpack directory mapped back to the client's.
    # Line 4, column 19: the "string filename" parameter that names it.
    assert str(e).startswith(f"{path}:4:19: ")
    assert (e.file, e.line, e.col) == (str(path), 4, 19)
    assert "lost.ply" in str(e) and "candela-farm-" not in str(e)


def test_a_worker_killed_mid_render_changes_nothing(tmp_path, ppm_cornell):
    c = Cluster(tmp_path / "kill", 2)
    try:
        at_kill = []

        def progress(done, total, secs):
            if at_kill or done < 4:
                return
            # Kill a worker that holds partial states, so their loss must be
            # made good by running their tasks again.
            held = c.client.has_what()
            victim = max(c.workers, key=lambda w: _partials(held, c, w))
            at_kill.append((done, _partials(held, c, victim)))
            c.kill(victim)

        with distributed.get_task_stream(c.client) as ts:
            r = farm.render(c.client, ppm_cornell, passes=24, chunk=1, crop=CROP, seed=9,
                            threads=1, progress=progress)
        assert at_kill and at_kill[0][0] < 24 and at_kill[0][1] > 0, "killed mid-render"
        assert len(c.client.scheduler_info()["workers"]) == 1
        keys = [t["key"] for t in ts.data]
        assert len(keys) > len(set(keys)), "some task ran twice"
    finally:
        c.close()
    ref = candela.load(ppm_cornell).render(spp=24, crop=CROP, seed=9)
    assert r.exr == ref.exr_bytes()
    assert r.state == ref.to_bytes()


def _partials(held: dict, cluster: Cluster, proc: subprocess.Popen) -> int:
    """How many partial states (pass ranges or merges) worker process `proc` holds."""
    address = {pid: a for a, pid in cluster.client.run(os.getpid).items()}
    keys = held.get(address.get(proc.pid), ())
    return sum(1 for k in keys if str(k).startswith(("candela-passes-", "candela-merge-")))
