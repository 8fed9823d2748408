#!/usr/bin/env python3
"""Equal-time error of vcm, bdpt, sppm, ppm and path (issue 12, "Speed").

    python3 bench/vcm_equal_time.py                 # the real bench (hours)
    python3 bench/vcm_equal_time.py --quick         # tiny: proves it runs end to end
    python3 bench/vcm_equal_time.py --scenes pool --t0 2 --steps 4 --ref-seconds 600

For each scene (caustic-glass, cornell-box, pool) a long reference is
rendered once and cached under target/vcm-bench/ (by scene, scale,
reference integrator and its time; `--ref SCENE=FILE.exr` supplies one),
then every integrator renders the scene with `--time-limit` t for a
geometric series t0, 2 t0, ..., and `candela diff` gives its relMSE against
the reference (eps 0.01, the whole image). Wall time on a shared machine
drifts by ±20 % over minutes, so `--reps N` renders every point N times
(seeds differ), interleaving the integrators at each time limit, and the
tables hold the medians. Every integrator renders the
scene file's own Integrator parameters (maxdepth) through `--integrator`,
with its defaults otherwise (the photon integrators' scene-derived radius;
one light path per pixel per iteration): no per-integrator tuning.

The reference is candela's vcm by default (`--ref-integrator`): it favours
no integrator's noise, but it carries the kernel bias of the radii its
iterations merged with, which blurs sharp caustics, and a blurred reference
favours the estimators that blur alike. Where the caustics are sharp (the
pool's floor, caustic-glass) pass `--ref` a render with a small written
radius (the pool: vcm `"float radius" [0.025]`, 2 × 24 000 iterations at
scale 0.5; caustic-glass: `[0.02]`, 600 s): against the means of vcm and
sppm renders of a few thousand iterations each, vcm's relMSE on the pool
had looked 20 % better than it is, and the right α for it another. `--ref-integrator
path` or `bdpt` give an unbiased, slower reference where those converge
(not the pool's floor, which is L S D S E).

Every image is also measured by relMSE without its worst 0.1 % of pixels
(`candela diff`). On the pool that once decided everything: the small,
bright light reflected in the waves (E S L) was found by one camera sample
in 1/F, so whichever run drew such a sample lost, and medians of three runs
swung a hundredfold. Camera walks now fork at a first water or glass vertex
(`splitspecular`, module doc of `integrator::subpath`), and the two figures
differ by 10–20 %.

Output (in --out, default target/vcm-bench/): results.md (a markdown table:
error, passes and light paths/s per scene, integrator and time; the stored
light vertex's size in bytes and the vertices stored per vcm iteration; vcm's
ratio to the best other integrator at every time limit, by relMSE and by
the trimmed relMSE), and error_vs_time.png, log-log plots of relMSE, the
trimmed relMSE and MAE against render time per scene (relMSE is dominated
by rare bright paths; MAE shows the bulk).
The plot needs matplotlib; when the running Python has none, the script
creates a virtual environment target/vcm-bench/venv (shared by all runs) and pip-installs
matplotlib there (printing that it does; `--no-plot` skips it). Nothing else
is installed; the renderer is built with `cargo build --release -p candela`.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.join(ROOT, "target", "release", "candela")
SCENES = {
    "caustic-glass": os.path.join(ROOT, "scenes", "caustic-glass", "scene.pbrt"),
    "cornell-box": os.path.join(ROOT, "scenes", "cornell-box", "scene.pbrt"),
    "pool": os.path.join(ROOT, "scenes", "pool", "scene.pbrt"),
}
INTEGRATORS = ["vcm", "bdpt", "sppm", "ppm", "path"]
# Integrators that trace light paths, and how many per pass per pixel.
LIGHT_PATHS_PER_PIXEL = {"vcm": 1, "bdpt": 1, "sppm": 1, "ppm": 1}
MATPLOTLIB = "matplotlib==3.11.2"
CLOSING = re.compile(
    r"with (\d+) of \d+ passes[^:]*?(?:\((?P<status>[^()]*(?:\([^()]*\)[^()]*)*)\))?: load ([0-9.]+) s, "
    r"render ([0-9.]+) s")


def scaled_scene(path, scale, maxdepth=None):
    """The scene at `scale` × its film resolution and, when given, with its
    Integrator's `maxdepth` set to `maxdepth`, as a temporary file beside it
    (so relative includes resolve), or the scene itself."""
    if scale == 1.0 and maxdepth is None:
        return path, False
    text = open(path).read()

    def res(m):
        return f'"integer {m.group(1)}resolution" [{max(8, round(int(m.group(2)) * scale))}]'
    text, n = re.subn(r'"integer ([xy])resolution"\s*\[\s*(\d+)\s*\]', res, text)
    if n != 2:
        sys.exit(f"{path}: expected x and y resolutions to scale, found {n}")
    if maxdepth is not None:
        text = re.sub(r'\s*"integer maxdepth"\s*\[\s*\d+\s*\]', "", text)
        text, n = re.subn(r'^(Integrator\s+"[^"]+")', rf'\1 "integer maxdepth" [{maxdepth}]', text,
                          flags=re.M)
        if n != 1:
            sys.exit(f"{path}: expected one Integrator line to set maxdepth, found {n}")
    f = tempfile.NamedTemporaryFile("w", suffix=".pbrt", dir=os.path.dirname(path), delete=False)
    f.write(text)
    f.close()
    return f.name, True


def render(scene, integrator, seconds, out, threads, seed):
    """Renders with --time-limit; returns (passes, render seconds, status)."""
    cmd = [BIN, "render", scene, "--integrator", integrator, "--time-limit", f"{seconds}",
           "--spp", str(1 << 20), "--seed", str(seed), "--outfile", out]
    if threads:
        cmd += ["--nthreads", str(threads)]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{p.stderr}")
    m = None
    for line in p.stderr.splitlines():
        m = CLOSING.search(line) or m
    if not m:
        sys.exit(f"no closing line in the output of {' '.join(cmd)}:\n{p.stderr}")
    return int(m.group(1)), float(m.group(4)), m.group("status") or ""


def errors(img, ref):
    """relMSE (eps 0.01), MAE and relMSE without the worst 0.1 % of pixels
    of `img` against `ref` (`candela diff`)."""
    out = subprocess.run([BIN, "diff", img, ref], capture_output=True, text=True)
    m = re.search(r"relMSE \(eps [^)]*\)\s+([0-9.eE+-]+|inf|nan)", out.stdout)
    mae = re.search(r"MAE\s+([0-9.eE+-]+|inf|nan)", out.stdout)
    robust = re.search(r"relMSE without the worst 0\.1 % of pixels\s+([0-9.eE+-]+|inf|nan)", out.stdout)
    if out.returncode != 0 or not m or not mae or not robust:
        sys.exit(f"candela diff {img} {ref} failed:\n{out.stdout}{out.stderr}")
    return float(m.group(1)), float(mae.group(1)), float(robust.group(1))


def film_pixels(scene):
    out = subprocess.run([BIN, "info", scene], capture_output=True, text=True).stdout
    m = re.search(r"film\s+\S+\s+(\d+)×(\d+)", out)
    if not m:
        sys.exit(f"candela info {scene}: no film line:\n{out}")
    return int(m.group(1)) * int(m.group(2))


def reference(name, scene, a, outdir):
    given = dict(r.split("=", 1) for r in a.ref)
    if name in given:
        return given[name]
    path = os.path.join(outdir, f"ref-{name}-x{a.scale}-{a.ref_integrator}-{a.ref_seconds:g}s.exr")
    if os.path.exists(path):
        print(f"{name}: cached reference {path}")
        return path
    print(f"{name}: rendering the reference ({a.ref_integrator}, {a.ref_seconds:g} s) ...", flush=True)
    passes, secs, _ = render(scene, a.ref_integrator, a.ref_seconds, path, a.threads, 999)
    print(f"{name}: reference {passes} passes in {secs:.1f} s -> {path}")
    return path


def bench_scene(name, a, outdir, rows, vertex_info):
    """Renders every (integrator, time limit) `--reps` times, interleaved:
    each repetition walks the time limits and, at each, every integrator in
    turn, so a slow spell of the machine falls on neighbours alike; rows
    get the median of each figure over the repetitions."""
    scene, temporary = scaled_scene(SCENES[name], a.scale, a.maxdepth)
    try:
        ref = reference(name, scene, a, outdir)
        pixels = film_pixels(scene)
        # Untimed warm-up: the first render of a run read its files cold and
        # ran at 40 % of the speed of the next ones.
        render(scene, a.integrators[0], min(a.t0, 1.0), os.path.join(outdir, "warmup.exr"), a.threads, 0)
        runs = {}
        for r in range(a.reps):
            for k in range(a.steps):
                t = a.t0 * 2 ** k
                for integ in a.integrators:
                    img = os.path.join(outdir, f"{name}-x{a.scale}-{integ}-{t:g}s-r{r}.exr")
                    passes, secs, status = render(scene, integ, t, img, a.threads, 1 + k + 100 * r)
                    err, mae, robust = errors(img, ref)
                    lps = passes * pixels * LIGHT_PATHS_PER_PIXEL.get(integ, 0) / secs if secs > 0 else 0
                    runs.setdefault((integ, t), []).append((passes, secs, err, lps, mae, robust))
                    print(f"{name:14} {integ:5} t={t:<6g} rep {r} passes {passes:6} render {secs:7.2f} s "
                          f"relMSE {err:.5g} (w/o worst 0.1 %: {robust:.5g}) MAE {mae:.4g} "
                          f"light paths/s {lps:.3g}", flush=True)
                    v = re.search(r"(\d+) light vertices stored × (\d+) B(?: \(\+ (\d+) B to merge\))?",
                                  status)
                    if integ == "vcm" and v:
                        size = int(v.group(2)) + int(v.group(3) or 0)
                        vertex_info[name] = (int(v.group(1)), size, pixels)
        for integ in a.integrators:
            for k in range(a.steps):
                t = a.t0 * 2 ** k
                med = [median([run[i] for run in runs[(integ, t)]]) for i in range(6)]
                passes, secs, err, lps, mae, robust = med
                rows.append((name, integ, t, passes, secs, err, lps, mae, robust))
    finally:
        if temporary:
            os.unlink(scene)


def median(xs):
    xs = sorted(xs)
    n = len(xs)
    return xs[n // 2] if n % 2 else 0.5 * (xs[n // 2 - 1] + xs[n // 2])


def table(rows, vertex_info, a):
    given = ", ".join(a.ref)
    reference = (f"references given: {given}; otherwise {a.ref_integrator} {a.ref_seconds:g} s" if given
                 else f"reference {a.ref_integrator} {a.ref_seconds:g} s")
    lines = [f"# Equal-time relMSE (scale {a.scale}, {reference}, medians of {a.reps} interleaved run(s)"
             f"{', QUICK: not the real bench' if a.quick else ''})", "",
             "| scene | integrator | time limit s | passes | render s | relMSE | relMSE w/o worst 0.1 % "
             "| MAE | light paths/s |",
             "|---|---|---|---|---|---|---|---|---|"]
    for name, integ, t, passes, secs, err, lps, mae, robust in rows:
        lp = f"{lps:.3g}" if lps else "-"
        lines.append(f"| {name} | {integ} | {t:g} | {passes:g} | {secs:.2f} | {err:.4g} | {robust:.4g} "
                     f"| {mae:.4g} | {lp} |")
    lines += ["", "## vcm: stored light vertices (last iteration of the longest run)", "",
              "| scene | light paths / iteration | vertices stored | bytes / vertex | MB / iteration |",
              "|---|---|---|---|---|"]
    for name, (n, size, pixels) in vertex_info.items():
        lines.append(f"| {name} | {pixels} | {n} | {size} | {n * size / 1e6:.2f} |")
    for col, label in [(5, "relMSE"), (8, "relMSE without the worst 0.1 % of pixels")]:
        lines += ["", f"## vcm against the best other integrator at every time limit: {label}", "",
                  f"| scene | time limit s | vcm | best other | its {label} | ratio (target <= 1.2; < 1 on pool) |",
                  "|---|---|---|---|---|---|"]
        for name in a.scenes:
            for k in range(a.steps):
                t = a.t0 * 2 ** k
                at = {r[1]: r[col] for r in rows if r[0] == name and r[2] == t}
                if "vcm" not in at or len(at) < 2:
                    continue
                best = min((e, i) for i, e in at.items() if i != "vcm")
                lines.append(f"| {name} | {t:g} | {at['vcm']:.4g} | {best[1]} | {best[0]:.4g} | "
                             f"{at['vcm'] / best[0]:.3g} |")
    return "\n".join(lines) + "\n"


def python_with_matplotlib():
    try:
        import matplotlib  # noqa: F401
        return sys.executable
    except ImportError:
        pass
    venv = os.path.join(ROOT, "target", "vcm-bench", "venv")
    py = os.path.join(venv, "bin", "python")
    if not os.path.exists(py):
        print(f"matplotlib is missing: creating {venv} and pip-installing {MATPLOTLIB} there")
        subprocess.check_call([sys.executable, "-m", "venv", venv])
        subprocess.check_call([py, "-m", "pip", "install", "-q", MATPLOTLIB])
    return py


PLOT = r'''
import json, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
rows, out, title = json.load(open(sys.argv[1])), sys.argv[2], sys.argv[3]
scenes = list(dict.fromkeys(r[0] for r in rows))
fig, axes = plt.subplots(3, len(scenes), figsize=(5 * len(scenes), 12), squeeze=False)
for col, s in enumerate(scenes):
    for row, (k, label) in enumerate([(5, "relMSE"), (8, "relMSE w/o worst 0.1 %"), (7, "MAE")]):
        ax = axes[row][col]
        for integ in dict.fromkeys(r[1] for r in rows if r[0] == s):
            pts = sorted((r[4], r[k]) for r in rows if r[0] == s and r[1] == integ and r[k] > 0)
            if pts:
                ax.loglog(*zip(*pts), marker="o", label=integ)
        ax.set_title(s); ax.set_xlabel("render time [s]"); ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3); ax.legend()
fig.suptitle(title); fig.tight_layout(); fig.savefig(out, dpi=100)
'''


def plot(rows, outdir, title):
    import json
    py = python_with_matplotlib()
    data = os.path.join(outdir, "results.json")
    json.dump(rows, open(data, "w"))
    png = os.path.join(outdir, "error_vs_time.png")
    subprocess.check_call([py, "-c", PLOT, data, png, title])
    return png


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", nargs="+", default=list(SCENES), choices=list(SCENES))
    ap.add_argument("--integrators", nargs="+", default=INTEGRATORS)
    ap.add_argument("--t0", type=float, default=4.0, help="shortest time limit, seconds")
    ap.add_argument("--steps", type=int, default=6, help="time limits t0 * 2^k, k < steps")
    ap.add_argument("--reps", type=int, default=1,
                    help="repetitions, interleaved; the table holds medians (the machine's speed drifts)")
    ap.add_argument("--maxdepth", type=int, default=None,
                    help="set every scene's Integrator maxdepth (sppm and ppm bound each subpath, "
                         "vcm, bdpt and path the whole path: at a small depth they render different "
                         "images, so compare them where the image has stopped changing)")
    ap.add_argument("--ref-seconds", type=float, default=3600.0)
    ap.add_argument("--ref-integrator", default="vcm")
    ap.add_argument("--ref", action="append", default=[], metavar="SCENE=EXR",
                    help="use this reference image for SCENE")
    ap.add_argument("--scale", type=float, default=1.0, help="film resolution factor")
    ap.add_argument("--threads", type=int, default=0, help="worker threads (default: all)")
    ap.add_argument("--out", default=os.path.join(ROOT, "target", "vcm-bench"))
    ap.add_argument("--quick", action="store_true",
                    help="tiny settings (scale 0.25, t0 0.25 s, 3 steps, 8 s references)")
    ap.add_argument("--no-plot", action="store_true")
    a = ap.parse_args()
    if a.quick:
        a.scale, a.t0, a.steps, a.ref_seconds = 0.25, 0.25, 3, 8.0
        a.out = os.path.join(a.out, "quick")
    os.makedirs(a.out, exist_ok=True)
    subprocess.check_call(["cargo", "build", "--release", "-q", "-p", "candela"], cwd=ROOT)
    rows, vertex_info = [], {}
    for name in a.scenes:
        bench_scene(name, a, a.out, rows, vertex_info)
    md = table(rows, vertex_info, a)
    with open(os.path.join(a.out, "results.md"), "w") as f:
        f.write(md)
    print(md)
    print(f"table: {os.path.join(a.out, 'results.md')}")
    if not a.no_plot:
        print(f"plot: {plot(rows, a.out, 'error vs time' + (' (quick)' if a.quick else ''))}")


if __name__ == "__main__":
    main()
