"""The Python module: load errors, renders to numpy, exact merges, bytes,
EXR equal to the CLI's, the GIL released while rendering, Ctrl-C."""

import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import candela
from conftest import CORNELL, CROP, make_multifile_scene, run_cli


@pytest.fixture(scope="module")
def cornell():
    return candela.load(CORNELL)


def test_a_syntax_error_raises_scene_error_with_file_line_col(scene_dir):
    path = scene_dir / "bad.pbrt"
    path.write_text('WorldBegin\nShape "sphere"\n  Shape "sphere" "float radius" [ oops ]\n')
    with pytest.raises(candela.SceneError) as info:
        candela.load(path)
    e = info.value
    assert isinstance(e, candela.CandelaError)
    assert (e.file, e.line) == (str(path), 3)
    assert e.col > 0
    assert str(e).startswith(f"{path}:3:{e.col}: ")


def test_a_missing_ply_raises_at_the_shape_that_names_it(scene_dir):
    path = scene_dir / "s.pbrt"
    path.write_text('WorldBegin\n\nShape "plymesh" "string filename" "nowhere.ply"\n')
    with pytest.raises(candela.SceneError) as info:
        candela.load(path)
    assert info.value.line == 3
    assert f"{path}:3:" in str(info.value) and "nowhere.ply" in str(info.value)


def test_info_describes_the_scene_and_its_overrides(cornell):
    info = cornell.info()
    assert info["resolution"] == (256, 256)
    assert info["passes"] == 64 and info["integrator_name"] == "path"
    assert info["independent_passes"] is True
    assert info["triangles"] > 0 and info["lights"]
    small = cornell.info(spp=3, integrator="bdpt", crop=CROP)
    assert small["resolution"] == (64, 64)
    assert (small["passes"], small["integrator_name"]) == (3, "bdpt")
    assert small["fingerprint"] != info["fingerprint"]


def test_render_gives_float32_layers_of_height_width_channels(cornell):
    r = cornell.render(spp=2, crop=(0.25, 0.75, 0.5, 0.75), seed=1)
    assert r.size == (128, 64)
    assert r.channels["main"] == ("R", "G", "B")
    rgb = r.layers["main"]
    assert rgb.dtype == np.float32 and rgb.shape == (64, 128, 3)
    assert np.isfinite(rgb).all() and rgb.mean() > 0.01
    assert (r.pass_count, r.total_passes, r.passes, r.integrator) == (2, 2, [(0, 2)], "path")
    rgb[0, 0, 0] = -1.0  # the arrays are the caller's own
    assert r.layers["main"][0, 0, 0] != -1.0


def test_two_halves_merge_into_the_bytes_of_one_render(cornell):
    opts = dict(spp=6, crop=CROP, seed=4)
    full = cornell.render(**opts)
    a = cornell.render(passes=range(0, 4), **opts)
    b = cornell.render(passes=(4, 6), **opts)
    assert a.exr_bytes() != full.exr_bytes()
    assert a.merge(b).exr_bytes() == full.exr_bytes()
    assert b.merge(a).to_bytes() == full.to_bytes()
    assert np.array_equal(a.merge(b).layers["main"], full.layers["main"])
    assert candela.merge_states(b.to_bytes(), a.to_bytes()) == full.to_bytes()
    with pytest.raises(candela.StateError):
        a.merge(a)
    other = cornell.render(spp=6, crop=CROP, seed=5, passes=range(4, 6))
    with pytest.raises(candela.StateError):
        a.merge(other)


def test_states_go_to_bytes_and_back(cornell):
    a = cornell.render(spp=4, crop=CROP, passes=range(1, 3))
    back = candela.Render.from_bytes(cornell, a.to_bytes())
    assert back.to_bytes() == a.to_bytes() and back.passes == [(1, 3)]
    assert back.exr_bytes() == a.exr_bytes()
    info = candela.state_info(a.to_bytes())
    assert info["passes"] == [(1, 3)] and info["total_passes"] == 4
    assert info["settings"] == a.settings == "spp=4\ncropwindow=0.25,0.5,0.5,0.75\n"
    with pytest.raises(candela.StateError):
        candela.state_info(a.to_bytes()[:-1])
    assert not isinstance(ValueError(), candela.StateError)


def test_exr_is_the_clis_and_cli_merges_module_parts(cornell, tmp_path):
    crop = ",".join(str(v) for v in CROP)
    cli_exr = tmp_path / "cli.exr"
    run_cli("render", str(CORNELL), "--spp", "4", "--seed", "3", "--cropwindow", crop,
            "--quiet", "--outfile", str(cli_exr))
    full = cornell.render(spp=4, seed=3, crop=CROP, threads=1)
    full.save(tmp_path / "module.exr")
    assert (tmp_path / "module.exr").read_bytes() == cli_exr.read_bytes()
    parts = []
    for a, b in [(0, 1), (1, 4)]:
        p = tmp_path / f"part{a}.cndl"
        p.write_bytes(cornell.render(spp=4, seed=3, crop=CROP, passes=range(a, b)).to_bytes())
        parts.append(str(p))
    run_cli("merge", str(CORNELL), *parts, "--outfile", str(tmp_path / "merged.exr"))
    assert (tmp_path / "merged.exr").read_bytes() == cli_exr.read_bytes()


def test_threads_do_not_change_the_bytes(cornell):
    one = cornell.render(spp=2, crop=CROP, threads=1)
    two = cornell.render(spp=2, crop=CROP, threads=2)
    assert one.to_bytes() == two.to_bytes()
    with pytest.raises(ValueError):
        cornell.render(spp=2, crop=CROP, threads=0)


def test_bad_options_raise_value_error(cornell):
    with pytest.raises(ValueError):
        cornell.render(spp=4, passes=range(2, 9))
    with pytest.raises(ValueError):
        cornell.render(spp=4, passes=range(0, 4, 2))
    with pytest.raises(ValueError):
        cornell.render(crop=(0.5, 0.2, 0, 1))
    with pytest.raises(ValueError):
        cornell.render(spp=4, integrator="sppm", passes=range(0, 2))
    with pytest.raises(candela.SceneError):
        cornell.render(integrator="nonesuch")


def test_progress_reports_every_pass(cornell):
    seen = []
    cornell.render(spp=5, crop=CROP, progress=lambda done, total, secs: seen.append((done, total)))
    assert seen[-1] == (5, 5)
    assert [d for d, _ in seen] == sorted(set(d for d, _ in seen))


def test_other_python_threads_run_during_a_render(cornell):
    ticks, stop = [], threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.002)

    t = threading.Thread(target=tick)
    t.start()
    time.sleep(0.05)
    t0 = time.monotonic()
    cornell.render(spp=24, crop=(0.0, 0.5, 0.0, 0.5), threads=1)
    t1 = time.monotonic()
    stop.set()
    t.join()
    assert t1 - t0 > 0.3, "the render must last long enough to tell"
    during = [x for x in ticks if t0 + 0.1 < x < t1 - 0.1]
    # A held GIL would give none: the ticker could not run at all.
    assert len(during) > (t1 - t0 - 0.2) / 0.002 * 0.3


class Stopped(Exception):
    """Raised by the test's SIGINT handler (pytest ends a session on a KeyboardInterrupt)."""


def _raise_stopped(signum, frame):
    raise Stopped()


def test_a_signal_handler_that_raises_stops_the_render(cornell):
    before = signal.signal(signal.SIGINT, _raise_stopped)
    timer = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT))
    try:
        t0 = time.monotonic()
        timer.start()
        with pytest.raises(Stopped):
            # Most of a minute of work (256×256, one thread): only the
            # handler can end it within seconds.
            cornell.render(spp=200, threads=1)
        stopped = time.monotonic() - t0
    finally:
        timer.join()
        signal.signal(signal.SIGINT, before)
    assert stopped < 10.0
    assert cornell.render(spp=1, crop=CROP).pass_count == 1


def test_ctrl_c_stops_a_render_with_keyboard_interrupt(tmp_path):
    # The child restores Python's own Ctrl-C handler: a test run started in
    # the background by a non-interactive shell inherits SIGINT ignored, and
    # Python then installs no handler, so Ctrl-C (rightly) does nothing.
    script = (
        "import signal, sys, time, candela\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        f"scene = candela.load({str(CORNELL)!r})\n"
        "print('rendering', flush=True)\n"
        "t0 = time.monotonic()\n"
        "try:\n"
        "    scene.render(spp=200, threads=1)\n"
        "except KeyboardInterrupt:\n"
        "    print(f'interrupted after {time.monotonic() - t0:.2f} s', flush=True)\n"
        "    sys.exit(130)\n"
    )
    p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline() == "rendering\n"
    time.sleep(0.3)
    p.send_signal(signal.SIGINT)
    try:
        out, _ = p.communicate(timeout=60)
    finally:
        p.kill()
    assert p.returncode == 130, out
    assert float(out.split()[2]) < 10.0


def test_files_lists_includes_meshes_images_and_spectra(tmp_path):
    path, expected = make_multifile_scene(tmp_path)
    scene = candela.load(path)
    want = sorted(os.path.abspath(p) for p in expected)
    assert sorted(os.path.abspath(p) for p in scene.files()) == want
    assert sorted(os.path.abspath(p) for p in candela.scene_files(path)) == want
    assert scene.render(spp=1).layers["main"].shape == (16, 24, 3)


def test_an_absolute_file_path_cannot_be_shipped(tmp_path):
    path, _ = make_multifile_scene(tmp_path)
    ply = tmp_path / "shared" / "quad.ply"
    text = path.read_text().replace('"../shared/quad.ply"', f'"{ply}"')
    path.write_text(text)
    line = text.splitlines().index(f'Shape "plymesh" "string filename" "{ply}"') + 1
    candela.load(path)  # renders fine here
    with pytest.raises(candela.SceneError) as info:
        candela.scene_files(path)
    assert (info.value.line, info.value.col) == (line, 35)
    assert "absolute path" in str(info.value)
