#!/usr/bin/env python3
"""The Dask farm on this machine: 1 vs 2 local workers on a 64-pass PPM
render of the Cornell box, the overhead of each task, and a paper estimate
for 100 machines.

    nice -n 10 target/python-venv/bin/python bench/farm.py [--passes 64] [--chunk 4]

(after ./test.sh, or `pip install ./python dask distributed` in any venv).

1. A one-process render (`Scene.render`, 2 threads) gives the reference
   bytes and the time per pass.
2. The farm renders the same passes on a LocalCluster of 1 worker (one task
   slot, 2 render threads per task) and of 2 workers (one slot and one
   thread each): the same 2 cores. Both must equal the reference byte for
   byte (checked).
3. From Dask's task stream: the compute time of the render tasks (per pass),
   of the merge tasks, the transfers between workers (states, with bytes),
   and the overhead per task: (wall time x task slots - compute time of all
   tasks) / tasks, i.e. slot time not spent computing, per task. The archive
   is scattered to every worker once: its bytes and that time are printed.
4. A paper estimate for 100 machines of this kind: throughput from the
   per-pass time measured here, the state size and a 1 Gbit/s network, and
   the chunk size that keeps the measured per-task overhead under 5 %.
"""
import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "scenes" / "cornell-box" / "scene.pbrt"
PPM = '"ppm" "float radius" [0.05] "integer photonsperiteration" [20000] "integer maxdepth" [5]'


def ppm_cornell(tmp: Path) -> Path:
    lines = [f"Integrator {PPM}" if ln.startswith("Integrator") else ln
             for ln in SCENE.read_text().splitlines()]
    p = tmp / "cornell" / "scene.pbrt"
    p.parent.mkdir(parents=True)
    p.write_text("\n".join(lines) + "\n")
    return p


def farm_run(scene, passes, chunk, workers, threads):
    """One farm render on a fresh LocalCluster; returns (result, wall, stream, scatter)."""
    import distributed
    from candela import archive, farm

    with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, dashboard_address=None,
                                  processes=True) as cluster, distributed.Client(cluster) as client:
        client.run(lambda: None)  # workers up
        packed = archive.pack(scene)
        t0 = time.perf_counter()
        client.scatter([packed.data], broadcast=True, hash=False)
        scatter = time.perf_counter() - t0
        with distributed.get_task_stream(client) as ts:
            t0 = time.perf_counter()
            r = farm.render(client, scene, passes=passes, chunk=chunk, threads=threads, progress=False)
            wall = time.perf_counter() - t0
        return r, wall, ts.data, scatter


def spans(stream, prefix, action):
    """(seconds, count) of `action` spans of the tasks whose key starts with `prefix`."""
    total, n = 0.0, 0
    for t in stream:
        if str(t["key"]).startswith(prefix):
            for s in t["startstops"]:
                if s["action"] == action:
                    total += s["stop"] - s["start"]
                    n += 1
    return total, n


def report(name, r, wall, stream, slots, passes):
    render_s, render_n = spans(stream, "candela-passes-", "compute")
    merge_s, merge_n = spans(stream, "candela-merge-", "compute")
    other_s = sum(spans(stream, p, "compute")[0] for p in ("candela-check-", "candela-develop-"))
    xfer_s, xfer_n = spans(stream, "candela-", "transfer")
    tasks = len(stream)
    computing = render_s + merge_s + other_s
    overhead = (wall * slots - computing) / tasks
    print(f"{name}: {wall:.2f} s wall, {passes / wall:.2f} passes/s; {tasks} tasks "
          f"({render_n} render, {merge_n} merge)")
    print(f"  render compute {render_s / passes * 1e3:.0f} ms/pass (one slot), "
          f"merge {merge_s / max(merge_n, 1) * 1e3:.1f} ms/merge, "
          f"check+develop {other_s * 1e3:.0f} ms")
    print(f"  transfers between workers: {xfer_n}, {xfer_s / max(xfer_n, 1) * 1e3:.1f} ms each; "
          f"overhead per task {overhead * 1e3:.1f} ms (slot time not computing)")
    return {"wall": wall, "per_pass": render_s / passes, "merge": merge_s / max(merge_n, 1),
            "overhead": overhead}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--passes", type=int, default=64)
    ap.add_argument("--chunk", type=int, default=4)
    args = ap.parse_args()
    import candela

    tmp = Path(tempfile.mkdtemp())
    scene = ppm_cornell(tmp)
    s = candela.load(scene, spp=args.passes)
    t0 = time.perf_counter()
    ref = s.render(spp=args.passes, threads=2)
    one = time.perf_counter() - t0
    state_bytes = len(s.render(spp=args.passes, passes=range(0, args.chunk)).to_bytes())
    exr = ref.exr_bytes()
    print(f"one process, 2 threads: {one:.2f} s, {one / args.passes * 1e3:.0f} ms/pass, "
          f"{args.passes / one:.2f} passes/s; state of a {args.chunk}-pass task {state_bytes} bytes")
    archive_bytes = len(candela.archive.pack(scene).data)
    results = {}
    for workers, threads in [(1, 2), (2, 1)]:
        r, wall, stream, scatter = farm_run(scene, args.passes, args.chunk, workers, threads)
        assert r.exr == exr, "farm result differs from the one-process render"
        name = f"farm, {workers} worker(s) x {threads} render thread(s)"
        results[workers] = report(name, r, wall, stream, workers, args.passes)
        print(f"  archive {archive_bytes} bytes scattered to {workers} worker(s) in {scatter * 1e3:.1f} ms; "
              f"bytes equal to the one-process render: yes")
    estimate(results[2], state_bytes, args.chunk, archive_bytes)


def estimate(m, state_bytes, chunk, archive_bytes):
    """Paper throughput on 100 machines like this one (2 cores: 2 task slots)."""
    machines, slots_each, link = 100, 2, 125e6  # bytes/s of 1 Gbit/s
    slots = machines * slots_each
    t_pass = m["per_pass"]
    ideal = slots / t_pass
    xfer = state_bytes / link
    # Each task's state crosses the network about once (to its merge): in
    # parallel across machines, so it costs the slot time of one transfer.
    per_task = m["overhead"] + xfer + m["merge"]
    k5 = max(1, int(per_task / (0.05 * t_pass)) + 1)
    eff = k5 * t_pass / (k5 * t_pass + m["overhead"] + xfer + m["merge"])
    tasks_per_s = 2 * ideal / k5  # render + merge tasks through the one scheduler
    print("paper estimate, 100 machines x 2 cores, 1 Gbit/s:")
    print(f"  {t_pass * 1e3:.0f} ms/pass/slot -> ideal {ideal:.0f} passes/s; a state of {state_bytes} bytes "
          f"takes {xfer * 1e3:.1f} ms on the wire")
    print(f"  chunk >= {k5} passes keeps overhead ({m['overhead'] * 1e3:.1f} ms/task measured) + transfer "
          f"+ merge ({m['merge'] * 1e3:.0f} ms) under 5 %: ~{eff * ideal:.0f} passes/s ({eff:.0%}), {tasks_per_s:.0f} tasks/s "
          f"at the scheduler (Dask: ~1 ms of scheduler time per task)")
    print(f"  the archive ({archive_bytes} bytes) reaches 100 machines in ~{100 * archive_bytes / link * 1e3:.0f} ms "
          f"from one client link (once per render); passes must be >> {slots} to fill every slot")


if __name__ == "__main__":
    sys.exit(main())
