#!/usr/bin/env python3
"""Equal-time error of SPPM, PPM and BDPT on the bundled caustic-glass scene.

    python3 bench/caustic_equal_time.py [--seconds 60] [--threads 2]

Each integrator is calibrated on a short run, then given about the same wall
time; the error against pbrt-v4's 1024-spp BDPT render beside the scene is
printed for the whole image and for the caustic below the glass (relMSE and
the mean ratio). pbrt-v4's own SPPM cannot be installed from the registries
this machine reaches, so candela's BDPT is the equal-time baseline.
"""
import argparse, os, re, subprocess, sys, tempfile, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "scenes", "caustic-glass", "scene.pbrt")
REF = os.path.join(ROOT, "scenes", "caustic-glass", "reference-pbrt-v4-bdpt-1024spp.exr")
BIN = os.path.join(ROOT, "target", "release", "candela")
CAUSTIC = "120,200,260,330"
SPPM = '"float radius" [0.03] "integer photonsperiteration" [200000]'


def scene_for(integrator):
    text = open(SCENE).read()
    if integrator in ("sppm", "ppm"):
        text = text.replace('Integrator "bdpt"', f'Integrator "{integrator}" {SPPM}')
    f = tempfile.NamedTemporaryFile("w", suffix=".pbrt", dir=os.path.dirname(SCENE), delete=False)
    f.write(text)
    f.close()
    return f.name


def render(integrator, spp, threads, out):
    path = scene_for(integrator)
    try:
        t0 = time.perf_counter()
        subprocess.check_call([BIN, "render", "--quiet", "--integrator", integrator, "--spp", str(spp),
                               "--nthreads", str(threads), "--outfile", out, path])
        return time.perf_counter() - t0
    finally:
        os.unlink(path)


def errors(img, region=None):
    args = [BIN, "diff", img, REF] + (["--region", region] if region else [])
    out = subprocess.run(args, capture_output=True, text=True).stdout
    rel = float(re.search(r"relMSE \(eps [^)]*\)\s+([0-9.e+-]+)", out).group(1))
    ratios = [float(m) for m in re.findall(r"^[RGB]\s+\S+\s+\S+\s+(\S+)", out, re.M)]
    return rel, sum(ratios) / 3


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=60)
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    subprocess.check_call(["cargo", "build", "--release", "-q", "-p", "candela"], cwd=ROOT)
    tmp = tempfile.mkdtemp()
    for integrator in ["bdpt", "sppm", "ppm"]:
        t1 = render(integrator, 2, a.threads, os.path.join(tmp, "cal.exr")) / 2
        spp = max(1, round(a.seconds / t1))
        out = os.path.join(tmp, f"{integrator}.exr")
        t = render(integrator, spp, a.threads, out)
        (rw, mw), (rc, mc) = errors(out), errors(out, CAUSTIC)
        print(f"{integrator:5} {spp:4} spp/iterations in {t:6.1f} s: image relMSE {rw:.5f} "
              f"(mean ratio {mw:.4f}); caustic relMSE {rc:.5f} (mean ratio {mc:.4f})")


if __name__ == "__main__":
    sys.exit(main())
