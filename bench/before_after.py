#!/usr/bin/env python3
"""Before/after speed of path, bdpt and sppm on the Cornell box and caustic-glass.

    CANDELA_BEFORE=/path/to/old/candela python3 bench/before_after.py [--reps 5] [--callgrind]

CANDELA_BEFORE is a `candela` binary built from an older commit (build it in a
separate worktree: `git worktree add /tmp/before OLD && cargo build --release -p
candela` there); CANDELA_AFTER defaults to this checkout's target/release/candela.

Wall time: every case runs `--reps` times per binary, interleaved (before, after,
after, before, ...) so that a change in machine load hits both alike; the table
gives the median seconds of each and the ratio after/before (< 1: faster now).
The whole process is timed (parse, build, render, write), with 2 threads; the
CPU time (user + system of the process) is given beside it, a second opinion
when other work shares the machine (it ignores waiting, not contention).

`--callgrind`: each case runs under `valgrind --tool=callgrind` with one thread
at 1 and at 3 passes per binary; the instructions of one pass, (I3 - I1)/2, and
the fixed part (parse, build, write), I1 - one pass, are given apart, since a
slower BVH build and a faster pass would otherwise blur together. Instruction
counts do not depend on machine load (they ignore cache and branch effects, so
they are a second opinion beside the wall times, not a replacement). Valgrind
does not decode every instruction of a `target-cpu=native` build on recent CPUs
(AVX-512, GFNI): for `--callgrind` build both binaries with
`RUSTFLAGS="-C target-cpu=x86-64-v3"` (the same images, bit for bit).

SPPM is given an explicit radius and photon count so that both binaries do the
same work whatever their defaults.
"""
import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = {
    "cornell": os.path.join(ROOT, "scenes", "cornell-box", "scene.pbrt"),
    "caustic-glass": os.path.join(ROOT, "scenes", "caustic-glass", "scene.pbrt"),
}
SPPM = {
    "cornell": '"float radius" [0.02] "integer photonsperiteration" [250000] "integer maxdepth" [5]',
    "caustic-glass": '"float radius" [0.03] "integer photonsperiteration" [200000]',
}
# (scene, integrator, spp for wall time)
CASES = [
    ("cornell", "path", 32),
    ("cornell", "bdpt", 8),
    ("cornell", "sppm", 8),
    ("caustic-glass", "path", 16),
    ("caustic-glass", "bdpt", 4),
    ("caustic-glass", "sppm", 8),
]


def scene_for(scene, integrator):
    """A copy of the scene beside it (relative includes keep working) with the
    Integrator line replaced for sppm."""
    text = open(SCENES[scene]).read()
    if integrator == "sppm":
        text = re.sub(r'^Integrator\s+"[a-z]+".*$', f'Integrator "sppm" {SPPM[scene]}', text,
                      count=1, flags=re.M)
    f = tempfile.NamedTemporaryFile("w", suffix=".pbrt", dir=os.path.dirname(SCENES[scene]),
                                    delete=False)
    f.write(text)
    f.close()
    return f.name


def command(binary, path, integrator, spp, threads, out):
    return [binary, "render", "--quiet", "--integrator", integrator, "--spp", str(spp),
            "--nthreads", str(threads), "--seed", "1", "--outfile", out, path]


def wall(binary, path, integrator, spp, out):
    """(wall seconds, CPU seconds: user + system) of one whole run."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(command(binary, path, integrator, spp, 2, out), check=True,
                   stdout=subprocess.DEVNULL)
    t = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return t, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)


def instructions(binary, path, integrator, spp, out, tmp):
    log = os.path.join(tmp, "cg.out")
    r = subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={log}"]
                       + command(binary, path, integrator, spp, 1, out),
                       check=True, capture_output=True, text=True)
    m = re.search(r"Collected\s*:\s*(\d+)", r.stderr)
    os.unlink(log)
    return int(m.group(1))


def per_pass(binary, path, integrator, out, tmp):
    """Instructions [G] of one pass and of the fixed part."""
    i1, i3 = (instructions(binary, path, integrator, s, out, tmp) / 1e9 for s in (1, 3))
    one = (i3 - i1) / 2
    return one, i1 - one


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--callgrind", action="store_true")
    a = ap.parse_args()
    before = os.environ.get("CANDELA_BEFORE")
    after = os.environ.get("CANDELA_AFTER", os.path.join(ROOT, "target", "release", "candela"))
    if not before:
        sys.exit("set CANDELA_BEFORE to a candela binary built from the older commit")
    tmp = tempfile.mkdtemp()
    out = os.path.join(tmp, "out.exr")
    unit = "Ginstr/pass" if a.callgrind else "s"
    print(f"{'scene':14} {'integrator':10} {'spp':>4} {'before ' + unit:>13} {'after ' + unit:>13} ratio")
    for scene, integrator, spp_wall in CASES:
        path = scene_for(scene, integrator)
        try:
            if a.callgrind:
                (b, bf), (n, nf) = [per_pass(x, path, integrator, out, tmp) for x in (before, after)]
                print(f"{scene:14} {integrator:10} fixed {bf:8.3f} -> {nf:8.3f} Ginstr ({nf / bf:.3f})")
                spp = 1
            else:
                tb, ta = [], []
                for i in range(a.reps):
                    order = [(before, tb), (after, ta)] if i % 2 == 0 else [(after, ta), (before, tb)]
                    for binary, times in order:
                        times.append(wall(binary, path, integrator, spp_wall, out))
                b, n, spp = (statistics.median(t[0] for t in tb),
                             statistics.median(t[0] for t in ta), spp_wall)
                cb, cn = statistics.median(t[1] for t in tb), statistics.median(t[1] for t in ta)
        finally:
            os.unlink(path)
        line = f"{scene:14} {integrator:10} {spp:4} {b:13.3f} {n:13.3f} {n / b:.3f}"
        if not a.callgrind:
            line += f"   cpu {cb:7.2f} -> {cn:7.2f} s ({cn / cb:.3f})"
        print(line, flush=True)


if __name__ == "__main__":
    sys.exit(main())
