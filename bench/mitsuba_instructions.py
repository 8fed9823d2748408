#!/usr/bin/env python3
"""Instructions per path vertex: candela's path tracer against Mitsuba 3's
(`scalar_spectral`) on the bundled Cornell box, counted by valgrind.

    CANDELA=/path/to/x86-64-v3/candela python3 bench/mitsuba_instructions.py

`bench/peers_speed.py --cases mitsuba` times the two; this says where the
difference is. Each renderer renders the scene at 1 and at 3 samples per pixel
on one thread under `valgrind --tool=callgrind`; the difference of the two runs
is two samples per pixel of rendering alone (parsing, building, start-up and
writing cancel). Mitsuba's scene is the one `bench/cornell_vs_mitsuba.py`
builds from the same .pbrt file. The table gives, per closest-hit ray (one per
path vertex: the camera ray and every continuation), the instructions of:
the whole path sample; closest-hit traversal (candela's BVH, Mitsuba's
Embree `rtcIntersect1`); shadow rays (`intersect_p`, `rtcOccluded1`, with
their per-call wrappers); light sampling without its shadow ray (candela's
`nee::sample_light`, Mitsuba's `Scene::sample_emitter_direction`); and the
rest. Rays per sample are given too: Mitsuba plays Russian roulette from
depth 5 (`rr_depth`), candela and pbrt-v4 from depth 1, so Mitsuba's paths are
longer and only per-vertex figures compare.

Instruction counts ignore caches and branch prediction; they do not depend on
the machine's load, which is why they are used here beside the wall times.

Needs valgrind (the Debian package) and mitsuba with numpy in the running
Python (`pip install mitsuba numpy`). valgrind 3.19 stops at the first
AVX-512 or GFNI instruction of a `target-cpu=native` build, so CANDELA must be
built with `RUSTFLAGS="-C target-cpu=x86-64-v3"` (the same images, bit for
bit), e.g. `RUSTFLAGS="-C target-cpu=x86-64-v3" CARGO_TARGET_DIR=target/v3
cargo build --release -p candela` (then CANDELA=target/v3/release/candela).
"""
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "scenes", "cornell-box", "scene.pbrt")

MITSUBA_RENDER = r"""
import sys
sys.path.insert(0, {bench!r})
import mitsuba as mi, drjit as dr
from cornell_vs_mitsuba import build_mitsuba
mi.set_variant("scalar_spectral")
dr.set_thread_count(1)
spp = int(sys.argv[1])
scene = mi.load_dict(build_mitsuba(mi, spp))
mi.render(scene, spp=spp, seed=1)
"""

# (what, regex of the function as callgrind_annotate names it)
CANDELA = {
    "sample": r"candela_core::integrator::path::PathIntegrator::trace",
    "closest": r"candela_core::accel::simd::x86::intersect_avx2",
    "shadow": r"candela_core::accel::simd::x86::intersect_p_avx2",
    "lights": r"candela_core::integrator::nee::sample_light",
}
MITSUBA = {
    "sample": r"mitsuba::PathIntegrator<float, mitsuba::Spectrum<float, 4ul> >::sample\(",
    "closest": r"mitsuba::rtcIntersect1\(",
    "shadow": r"mitsuba::EmbreeAccel<float, mitsuba::Color<float, 3ul> >::ray_test\(",
    "lights": r"mitsuba::Scene<float, mitsuba::Spectrum<float, 4ul> >::sample_emitter_direction\(",
}


def callgrind(cmd, out):
    r = subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", *cmd],
                       capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr[-2000:]}")


def annotate(path, *flags):
    return subprocess.run(["callgrind_annotate", *flags, path], capture_output=True, text=True).stdout


def inclusive(text, fn):
    """The largest inclusive count of a line naming `fn` (its own entry)."""
    best = 0
    for line in text.splitlines():
        m = re.match(r"\s*([\d,]+) \(", line)
        if m and re.search(fn, line):
            best = max(best, int(m.group(1).replace(",", "")))
    return best


def calls(text, fn):
    """Calls of `fn`: the sum of the (Nx) counts on the callee lines naming it."""
    total = 0
    for line in text.splitlines():
        if re.search(r"\s>\s", line) and re.search(fn, line):
            m = re.search(r"\(([\d,]+)x\)", line)
            if m:
                total += int(m.group(1).replace(",", ""))
    return total


def profile(name, cmd_for, fns, tmp):
    """Inclusive counts and call counts of two samples per pixel."""
    counts = {}
    for spp in (1, 3):
        out = os.path.join(tmp, f"{name}-{spp}.cg")
        print(f"{name}: callgrind at {spp} spp ...", file=sys.stderr)
        callgrind(cmd_for(spp), out)
        inc, tree = annotate(out, "--inclusive=yes"), annotate(out, "--tree=calling")
        counts[spp] = {k: (inclusive(inc, f), calls(tree, f)) for k, f in fns.items()}
    return {k: (counts[3][k][0] - counts[1][k][0], counts[3][k][1] - counts[1][k][1]) for k in fns}


def table(c, m, samples):
    print("| renderer | closest rays / sample | shadow rays / sample | instructions per closest-hit ray: "
          "whole sample | closest hit | shadow rays | light sampling without them | rest |")
    print("|---|---|---|---|---|---|---|---|")
    for name, d in (("candela", c), ("Mitsuba 3", m)):
        rays = d["closest"][1]
        shadow = d["shadow"][0]
        # Both renderers trace their shadow rays inside light sampling.
        lights = d["lights"][0] - shadow
        rest = d["sample"][0] - d["closest"][0] - shadow - lights
        cols = [d["sample"][0], d["closest"][0], shadow, lights, rest]
        print(f"| {name} | {rays / samples:.2f} | {d['shadow'][1] / samples:.2f} | "
              + " | ".join(f"{v / rays:.0f}" for v in cols) + " |")


def main():
    candela = os.environ.get("CANDELA")
    if not candela:
        sys.exit("set CANDELA to a candela binary built for x86-64-v3 (see the module doc)")
    try:
        import mitsuba  # noqa: F401
    except ImportError:
        sys.exit("this Python has no mitsuba: pip install mitsuba numpy")
    res = re.search(r'"integer xresolution" \[(\d+)\].*?"integer yresolution" \[(\d+)\]',
                    open(SCENE).read(), re.S)
    samples = 2 * int(res.group(1)) * int(res.group(2))
    with tempfile.TemporaryDirectory() as tmp:
        script = os.path.join(tmp, "mitsuba_render.py")
        with open(script, "w") as f:
            f.write(MITSUBA_RENDER.format(bench=os.path.join(ROOT, "bench")))
        c = profile("candela", lambda spp: [candela, "render", SCENE, "--spp", str(spp), "--nthreads", "1",
                                            "--quiet", "--outfile", os.path.join(tmp, "c.exr")], CANDELA, tmp)
        m = profile("mitsuba", lambda spp: [sys.executable, script, str(spp)], MITSUBA, tmp)
    print(f"Cornell box, {samples} path samples (2 spp), one thread, instructions by callgrind\n")
    table(c, m, samples)


if __name__ == "__main__":
    main()
