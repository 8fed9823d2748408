#!/usr/bin/env python3
"""candela against pbrt-v4 and Mitsuba 3 on the same machine in one run: the
speed targets of the speed issue, printed as ratios.

    PBRT_V4=/path/to/pbrt python3 bench/peers_speed.py [--reps 3] [--cases path,bdpt,mitsuba,sppm,scaling]

pbrt-v4 is not on the package registries: build mmp/pbrt-v4 (with its
submodules) from source yourself, outside this repository, and name the
binary in $PBRT_V4; without it the pbrt-v4 columns are skipped with a message.
pbrt-v4's default build is compiled for the host CPU (`-march=native`, its
PBRT_BUILD_NATIVE_EXECUTABLE option) and candela's for generic x86-64 (its
BVH kernel picks AVX2 at run time); on a host with AVX-512 that was worth
1.27-1.31x to pbrt-v4. $PBRT_V4_GENERIC, if set, names a second pbrt-v4 built
with -DPBRT_BUILD_NATIVE_EXECUTABLE=OFF: the path and bdpt cases then time it
in the same alternation and print the ratio against it too.
Mitsuba 3 (`scalar_spectral`) is imported if this Python has it (install it
with `pip install mitsuba numpy`, e.g. in a virtual environment, and run this
script with that environment's python); otherwise its case is skipped.

Cases (wall time of the whole process unless said; runs alternate A B A B and
medians are printed, so load from other processes skews both sides alike):
- path: the path tracer on the Cornell box (256², 64 spp) and killeroo-simple
  (700², 16 spp), 2 threads, candela / pbrt-v4 (target <= 0.5).
- bdpt: BDPT on the Cornell box at maxdepth 5, 64 spp, 2 threads, candela /
  pbrt-v4 (target <= 0.5).
- mitsuba: the path tracer on the Cornell box against Mitsuba's
  `scalar_spectral` path tracer on the same geometry (built by
  bench/cornell_vs_mitsuba.py; Mitsuba's scene load is not counted), candela /
  Mitsuba (target <= 0.8). killeroo-simple is not compared with Mitsuba: its
  `coateddiffuse` material has no Mitsuba counterpart. The two do not do the
  same work per sample: candela plays Russian roulette from the second bounce
  (pbrt-v4's rule), Mitsuba from the fifth (`rr_depth` 5), so at equal spp
  Mitsuba's image is less noisy (0.0049 against 0.0060 at 64 spp) and
  candela's is cheaper; with roulette from the fifth bounce candela's noise
  equals Mitsuba's and its time grows 23 %, so its noise x time is unchanged.
- sppm: SPPM on caustic-glass at equal time (--seconds, default 30), relMSE
  over the image and in the caustic, each renderer against its own converged
  image (candela: its BDPT at --ref-spp, cached in bench/out/peers; pbrt-v4:
  its 1024-spp BDPT render beside the scene), so the comparison measures the
  estimators and not the models: candela's coated floor is ~7.5 % darker than
  pbrt-v4's by design (it matches pbrt-v4's layered random walk, which
  pbrt-v4's stochastic f() overestimates). pbrt-v4 has no time limit: its
  iteration count is calibrated to about --seconds, and in every rep candela
  is then given the wall time pbrt-v4 took (both printed). Both render --reps
  times with seeds 1, 2, ... (pbrt-v4's --seed), and the medians are compared.
  Target: candela's relMSE <= 0.7 x pbrt-v4's. Lines "without the worst 0.1 %
  of pixels" give both (`candela diff`): candela's photons carry the adjoint shading-normal
  correction [Veach 1997, eq. 5.19] that pbrt-v4 leaves out, which keeps them
  consistent with camera paths on smooth-shaded glass but gives rare photons
  hundreds of times the usual power, and one of them can carry most of the
  relMSE of a 30-second render.
- scaling: candela's path, bdpt and photon (sppm) renders at 1 and 2 threads;
  speed-up = t(1) / t(2) (target >= 1.8).
"""
import argparse, os, re, statistics, subprocess, sys, tempfile, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.join(ROOT, "target", "release", "candela")
OUT = os.path.join(ROOT, "bench", "out", "peers")
CORNELL = os.path.join(ROOT, "scenes", "cornell-box", "scene.pbrt")
KILLEROO = os.path.join(ROOT, "scenes", "killeroo-simple", "killeroo-simple.pbrt")
CAUSTIC = os.path.join(ROOT, "scenes", "caustic-glass", "scene.pbrt")
CAUSTIC_REF_PBRT = os.path.join(ROOT, "scenes", "caustic-glass", "reference-pbrt-v4-bdpt-1024spp.exr")
CAUSTIC_REGION = "120,200,260,330"
SPPM = '"float radius" [0.03] "integer photonsperiteration" [200000] "integer maxdepth" [20]'


def variant(scene, integrator, params=""):
    """A copy of `scene` (beside it, so includes resolve) with its Integrator replaced."""
    text = open(scene).read()
    text, n = re.subn(r'Integrator\s+"[^"]*"[^\n]*(\n\s+"[^\n]*)*', f'Integrator "{integrator}" {params}', text)
    if n == 0:
        text = re.sub(r"WorldBegin", f'Integrator "{integrator}" {params}\nWorldBegin', text, count=1)
    f = tempfile.NamedTemporaryFile("w", suffix=".pbrt", dir=os.path.dirname(scene), delete=False)
    f.write(text)
    f.close()
    return f.name


def timed(cmd):
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr[-2000:]}")
    return dt


def candela_cmd(scene, spp, threads, out, extra=()):
    return [BIN, "render", scene, "--spp", str(spp), "--nthreads", str(threads), "--outfile", out, "--quiet", *extra]


def pbrt_cmd(pbrt, scene, spp, threads, out, extra=()):
    return [pbrt, "--spp", str(spp), "--nthreads", str(threads), "--outfile", out, "--quiet", *extra, scene]


def alternate(runs, reps):
    """Medians of `reps` rounds of the callables in `runs` (name -> () -> seconds), alternating."""
    times = {name: [] for name in runs}
    for _ in range(reps):
        for name, run in runs.items():
            times[name].append(run())
    return {name: statistics.median(t) for name, t in times.items()}


def ratio_line(label, a, b, target, cmp):
    r = a / b
    ok = "meets" if cmp(r, target) else "misses"
    print(f"{label:<44} {a:8.2f} s {b:8.2f} s   ratio {r:5.3f}  ({ok} target {target})")


def case_path_bdpt(pbrt, generic, reps, which):
    if not pbrt:
        print(f"{which}: skipped, $PBRT_V4 is not set")
        return
    cases = [("path", CORNELL, "path", 64, ""), ("path", KILLEROO, "path", 16, ""),
             ("bdpt", CORNELL, "bdpt", 64, '"integer maxdepth" [5]')]
    for kind, scene, integ, spp, params in cases:
        if kind != which:
            continue
        s = variant(scene, integ, params)
        runs = {
            "candela": lambda: timed(candela_cmd(s, spp, 2, os.path.join(OUT, "c.exr"))),
            "pbrt": lambda: timed(pbrt_cmd(pbrt, s, spp, 2, os.path.join(OUT, "p.exr"))),
        }
        if generic:
            runs["generic"] = lambda: timed(pbrt_cmd(generic, s, spp, 2, os.path.join(OUT, "p.exr")))
        try:
            t = alternate(runs, reps)
        finally:
            os.unlink(s)
        name = f"{integ} {os.path.basename(os.path.dirname(scene))} {spp} spp, 2 threads"
        ratio_line(f"{name}: candela / pbrt-v4", t["candela"], t["pbrt"], 0.5, float.__le__)
        if generic:
            ratio_line(f"{name}: candela / pbrt-v4 generic", t["candela"], t["generic"], 0.5, float.__le__)


def case_mitsuba(reps):
    try:
        import mitsuba as mi
        import drjit as dr
    except ImportError:
        print("mitsuba: skipped, this Python has no mitsuba (pip install mitsuba numpy)")
        return
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from cornell_vs_mitsuba import build_mitsuba
    mi.set_variant("scalar_spectral")
    dr.set_thread_count(2)
    scene = mi.load_dict(build_mitsuba(mi, 64))
    mi.render(scene, spp=1)  # warm-up

    def mitsuba():
        t0 = time.perf_counter()
        mi.render(scene, spp=64, seed=1)
        return time.perf_counter() - t0

    t = alternate({
        "candela": lambda: timed(candela_cmd(CORNELL, 64, 2, os.path.join(OUT, "c.exr"))),
        "mitsuba": mitsuba,
    }, reps)
    ratio_line("path cornell-box 64 spp, 2 threads: / Mitsuba", t["candela"], t["mitsuba"], 0.8, float.__le__)


def rel_mse(img, ref, region=None):
    """relMSE of `img` against `ref`, and without the worst 0.1 % of pixels (one `candela diff`)."""
    args = [BIN, "diff", img, ref] + (["--region", region] if region else [])
    out = subprocess.run(args, capture_output=True, text=True).stdout
    full = re.search(r"relMSE \(eps [^)]*\)\s+([0-9.e+-]+)", out).group(1)
    trimmed = re.search(r"relMSE without the worst [^%]*% of pixels\s+([0-9.e+-]+)", out).group(1)
    return {False: float(full), True: float(trimmed)}


def candela_reference(ref_spp):
    """candela's converged caustic-glass (BDPT at ref_spp), rendered once and cached."""
    ref = os.path.join(OUT, f"caustic-glass-candela-bdpt-{ref_spp}spp.exr")
    if not os.path.exists(ref):
        print(f"rendering candela's reference ({ref_spp} spp BDPT; cached as {ref}) ...", flush=True)
        timed(candela_cmd(CAUSTIC, ref_spp, 2, ref, ["--integrator", "bdpt"]))
    return ref


def case_sppm(pbrt, seconds, ref_spp, reps):
    if not pbrt:
        print("sppm: skipped, $PBRT_V4 is not set")
        return
    ref = candela_reference(ref_spp)
    s = variant(CAUSTIC, "sppm", SPPM)
    # errors[label][renderer] over the reps (seeds 1..reps), trimmed or not.
    errors = {(label, trim): {"candela": [], "pbrt": []}
              for label in ("image", "caustic") for trim in (False, True)}
    try:
        c_out, p_out = os.path.join(OUT, "sppm-candela.exr"), os.path.join(OUT, "sppm-pbrt.exr")
        # pbrt-v4 has no time limit: time two short runs and give it the
        # iterations that fill about `seconds` (its iterations slow down as
        # they go, so this is only a start); then candela gets the wall time
        # pbrt-v4 actually took in that rep: its --time-limit is that time
        # less candela's fixed cost (parse, build, write) and half an
        # iteration (it stops after the pass that crosses the limit).
        t8 = timed(pbrt_cmd(pbrt, s, 8, 2, p_out))
        t16 = timed(pbrt_cmd(pbrt, s, 16, 2, p_out))
        per = max((t16 - t8) / 8, 1e-3)
        n = max(1, round((seconds - (t8 - 8 * per)) / per))
        c1 = timed(candela_cmd(s, 1, 2, c_out))
        c5 = timed(candela_cmd(s, 5, 2, c_out))
        c_per = (c5 - c1) / 4
        c_fixed = max(c1 - c_per, 0.0)
        for rep in range(reps):
            seed = str(rep + 1)
            tp = timed(pbrt_cmd(pbrt, s, n, 2, p_out, ["--seed", seed]))
            limit = max(tp - c_fixed - c_per / 2, 1.0)
            tc = timed(candela_cmd(s, 10**6, 2, c_out, ["--time-limit", f"{limit:.2f}", "--seed", seed]))
            print(f"sppm caustic-glass seed {seed}: candela {tc:.1f} s, pbrt-v4 {tp:.1f} s ({n} iterations)")
            for region, label in ((None, "image"), (CAUSTIC_REGION, "caustic")):
                ec, ep = rel_mse(c_out, ref, region), rel_mse(p_out, CAUSTIC_REF_PBRT, region)
                for trim in (False, True):
                    errors[(label, trim)]["candela"].append(ec[trim])
                    errors[(label, trim)]["pbrt"].append(ep[trim])
    finally:
        os.unlink(s)
    for (label, trim), e in errors.items():
        ec, ep = statistics.median(e["candela"]), statistics.median(e["pbrt"])
        what = f"{label:<8} relMSE" + (" without the worst 0.1 % of pixels" if trim else "")
        each = ", ".join(f"{c:.4f}/{p:.4f}" for c, p in zip(e["candela"], e["pbrt"]))
        target = "" if trim else "  (target 0.7)"
        print(f"sppm caustic-glass {what}: candela {ec:.4f}  pbrt-v4 {ep:.4f}   ratio {ec / ep:5.3f}{target}"
              f"   [candela/pbrt-v4 per seed: {each}]")


def case_scaling(reps):
    s_bdpt = variant(CORNELL, "bdpt", '"integer maxdepth" [5]')
    s_sppm = variant(CAUSTIC, "sppm", SPPM)
    try:
        for name, scene, spp in (("path", CORNELL, 32), ("bdpt", s_bdpt, 16), ("sppm (photon passes)", s_sppm, 8)):
            t = alternate({th: (lambda th=th: timed(candela_cmd(scene, spp, th, os.path.join(OUT, "s.exr"))))
                           for th in (1, 2)}, reps)
            print(f"scaling {name:<22} 1 thread {t[1]:6.2f} s, 2 threads {t[2]:6.2f} s: speed-up {t[1] / t[2]:4.2f}"
                  f"  (target 1.8)")
    finally:
        os.unlink(s_bdpt)
        os.unlink(s_sppm)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--cases", default="path,bdpt,mitsuba,sppm,scaling")
    ap.add_argument("--seconds", type=float, default=30)
    ap.add_argument("--ref-spp", type=int, default=1024)
    a = ap.parse_args()
    os.makedirs(OUT, exist_ok=True)
    subprocess.check_call(["cargo", "build", "--release", "-q", "-p", "candela"], cwd=ROOT)
    pbrt = os.environ.get("PBRT_V4")
    generic = os.environ.get("PBRT_V4_GENERIC")
    with open("/proc/loadavg") as f:
        print(f"load average at start: {f.read().split()[0]} on {os.cpu_count()} cores")
    cases = a.cases.split(",")
    if "path" in cases:
        case_path_bdpt(pbrt, generic, a.reps, "path")
    if "bdpt" in cases:
        case_path_bdpt(pbrt, generic, a.reps, "bdpt")
    if "mitsuba" in cases:
        case_mitsuba(a.reps)
    if "sppm" in cases:
        case_sppm(pbrt, a.seconds, a.ref_spp, a.reps)
    if "scaling" in cases:
        case_scaling(a.reps)
    with open("/proc/loadavg") as f:
        print(f"load average at end: {f.read().split()[0]}")


if __name__ == "__main__":
    main()
