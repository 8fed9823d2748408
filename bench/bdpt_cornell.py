#!/usr/bin/env python3
"""BDPT throughput and equal-time error on the bundled Cornell box.

    python3 bench/bdpt_cornell.py [--spp 16] [--threads 2]

1. Throughput: `candela render --integrator bdpt` at maxdepth 5 and the given
   spp; prints camera samples per second (pbrt-v4's BDPT is measured the same
   way: pixels x spp / wall time). pbrt-v4 itself cannot be installed from the
   package registries this machine reaches, so its number must be measured
   elsewhere and the ratio formed by hand.
2. Equal-time error: BDPT and the path tracer at the scene's own maxdepth
   (100, as the pbrt-v4 reference beside the scene), each given the same wall
   time, compared with reference-pbrt-v4-path-1024spp.exr by relMSE (and MAE).
"""
import argparse, os, re, subprocess, sys, tempfile, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "scenes", "cornell-box", "scene.pbrt")
REF = os.path.join(ROOT, "..", "shared", "scenes", "cornell-box", "reference-pbrt-v4-path-1024spp.exr")
BIN = os.path.join(ROOT, "target", "release", "candela")


def render(scene_text, integrator, spp, threads, out):
    with tempfile.NamedTemporaryFile("w", suffix=".pbrt", dir=os.path.dirname(SCENE), delete=False) as f:
        f.write(scene_text)
        path = f.name
    try:
        t0 = time.perf_counter()
        subprocess.check_call([BIN, "render", "--quiet", "--integrator", integrator, "--spp", str(spp),
                               "--nthreads", str(threads), "--outfile", out, path])
        return time.perf_counter() - t0
    finally:
        os.unlink(path)


def errors(img):
    out = subprocess.run([BIN, "diff", img, REF], capture_output=True, text=True).stdout
    rel = float(re.search(r"relMSE \(eps [^)]*\)\s+([0-9.e+-]+)", out).group(1))
    mae = float(re.search(r"MAE\s+([0-9.e+-]+)", out).group(1))
    return rel, mae


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    subprocess.check_call(["cargo", "build", "--release", "-q", "-p", "candela"], cwd=ROOT)
    text = open(SCENE).read()
    res = [int(v) for v in re.findall(r'"integer [xy]resolution" \[(\d+)\]', text)]
    pixels = res[0] * res[1]
    tmp = tempfile.mkdtemp()
    d5 = re.sub(r'"integer maxdepth" \[\d+\]', '"integer maxdepth" [5]', text)
    t = render(d5, "bdpt", a.spp, a.threads, os.path.join(tmp, "b5.exr"))
    print(f"BDPT maxdepth 5, {a.spp} spp, {a.threads} threads: {t:.2f} s, "
          f"{pixels * a.spp / t / 1e3:.1f} k samples/s")
    tb = render(text, "bdpt", a.spp, a.threads, os.path.join(tmp, "b.exr"))
    t1 = render(text, "path", a.spp, a.threads, os.path.join(tmp, "p1.exr"))
    spp_pt = max(1, round(a.spp * tb / t1))
    tp = render(text, "path", spp_pt, a.threads, os.path.join(tmp, "p.exr"))
    rb, mb = errors(os.path.join(tmp, "b.exr"))
    rp, mp = errors(os.path.join(tmp, "p.exr"))
    print(f"equal time (maxdepth 100): BDPT {a.spp} spp in {tb:.2f} s: relMSE {rb:.5f}, MAE {mb:.5f}")
    print(f"                            PT {spp_pt} spp in {tp:.2f} s: relMSE {rp:.5f}, MAE {mp:.5f}")
    print(f"BDPT/PT relMSE at equal time: {rb / rp:.3f}")


if __name__ == "__main__":
    sys.exit(main())
