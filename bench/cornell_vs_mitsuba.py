#!/usr/bin/env python3
"""Times `candela render` on the bundled Cornell box against Mitsuba 3
(scalar_spectral path tracer, the same scene built from the same .pbrt file)
on this machine in the same run, and prints the time ratio.

    python3 bench/cornell_vs_mitsuba.py [--spp 64] [--threads 2] [--repeats 3]

Needs `pip install mitsuba numpy` (done automatically if missing). Builds the
candela binary with `cargo build --release -p candela` if it is not there.
"""
import argparse, os, re, statistics, subprocess, sys, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "scenes", "cornell-box", "scene.pbrt")
OUT = os.path.join(ROOT, "bench", "out")


def ensure_mitsuba():
    # numpy is needed to read the images back; the mitsuba wheel does not pull it in.
    for module in ("mitsuba", "numpy"):
        try:
            __import__(module)
        except ImportError:
            print(f"installing {module} from PyPI ...", file=sys.stderr)
            subprocess.check_call([sys.executable, "-m", "pip", "install", "-q", module])
    import mitsuba as mi
    return mi


def floats(block, name):
    m = re.search(r'"(?:point3|normal|rgb|float|integer)\s+' + name + r'"\s*\[([^\]]*)\]', block)
    return [float(v) for v in m.group(1).split()] if m else None


def parse_cornell(path):
    """The subset of pbrt-v4 the Cornell box uses: camera, film, maxdepth, quads with diffuse and area light."""
    text = open(path).read()
    fov = floats(text, "fov")[0]
    res = (int(floats(text, "xresolution")[0]), int(floats(text, "yresolution")[0]))
    maxdepth = int(floats(text, "maxdepth")[0])
    look = [float(v) for v in re.search(r"LookAt([^\n]*)", text).group(1).split()]
    meshes = []
    for block in re.findall(r"AttributeBegin(.*?)AttributeEnd", text, re.S):
        p, idx = floats(block, "P"), floats(block, "indices")
        refl = floats(block, "reflectance")
        emit = floats(block, "L") if "AreaLightSource" in block else None
        meshes.append((p, [int(i) for i in idx], refl, emit))
    return fov, res, maxdepth, look, meshes


def build_mitsuba(mi, spp):
    fov, res, maxdepth, look, meshes = parse_cornell(SCENE)
    T = mi.ScalarTransform4f
    # pbrt's `Scale -1 1 1` only undoes the opposite image-x conventions of the
    # two renderers (pbrt's camera space is left-handed): the plain look-at gives
    # pbrt's framing, red wall on the left (checked by pixel means of each side).
    to_world = T().look_at(origin=look[0:3], target=look[3:6], up=look[6:9])
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": maxdepth + 1},
        "sensor": {
            "type": "perspective", "fov": fov, "fov_axis": "smaller", "to_world": to_world,
            "film": {"type": "hdrfilm", "width": res[0], "height": res[1], "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": spp},
        },
    }
    os.makedirs(OUT, exist_ok=True)
    for k, (p, idx, refl, emit) in enumerate(meshes):
        # Write each quad list as a tiny OBJ so Mitsuba's own loader builds the mesh.
        obj = os.path.join(OUT, f"cornell_{k}.obj")
        with open(obj, "w") as f:
            for i in range(0, len(p), 3):
                f.write(f"v {p[i]} {p[i+1]} {p[i+2]}\n")
            for i in range(0, len(idx), 3):
                f.write(f"f {idx[i]+1} {idx[i+1]+1} {idx[i+2]+1}\n")
        shape = {"type": "obj", "filename": obj, "face_normals": True,
                 "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": refl}}}
        if emit:
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": emit}}
        scene[f"shape{k}"] = shape
    return scene


def time_candela(binary, spp, threads, repeats):
    out = os.path.join(OUT, "candela-cornell.exr")
    cmd = [binary, "render", SCENE, "--spp", str(spp), "--nthreads", str(threads), "--outfile", out, "--quiet"]
    times = []
    for i in range(repeats + 1):
        t0 = time.perf_counter()
        r = subprocess.run(cmd, capture_output=True, text=True)
        dt = time.perf_counter() - t0
        if r.returncode != 0:
            sys.exit(f"candela failed:\n{r.stderr}")
        if i > 0:
            times.append(dt)
    return statistics.median(times), out


def time_mitsuba(mi, spp, threads, repeats):
    mi.set_variant("scalar_spectral")
    import drjit as dr
    dr.set_thread_count(threads)
    t0 = time.perf_counter()
    scene = mi.load_dict(build_mitsuba(mi, spp))
    load = time.perf_counter() - t0
    times, img = [], None
    for i in range(repeats + 1):
        t0 = time.perf_counter()
        img = mi.render(scene, spp=spp, seed=i)
        dt = time.perf_counter() - t0
        if i > 0:
            times.append(dt)
    out = os.path.join(OUT, "mitsuba-cornell.exr")
    mi.Bitmap(img).write(out)
    return statistics.median(times), load, out


def means(mi, path):
    import numpy as np
    a = np.array(mi.Bitmap(path))
    return a[..., :3].reshape(-1, 3).mean(axis=0)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--candela", default=os.path.join(ROOT, "target", "release", "candela"))
    a = ap.parse_args()
    os.makedirs(OUT, exist_ok=True)
    if not os.path.exists(a.candela):
        subprocess.check_call(["cargo", "build", "--release", "-p", "candela"], cwd=ROOT)
    mi = ensure_mitsuba()
    tc, cout = time_candela(a.candela, a.spp, a.threads, a.repeats)
    tm, load, mout = time_mitsuba(mi, a.spp, a.threads, a.repeats)
    _, res, _, _, _ = parse_cornell(SCENE)
    n = res[0] * res[1] * a.spp
    print(f"{'renderer':<28}{'spp':>5}{'threads':>8}{'median s':>10}{'Msamples/s':>12}")
    print(f"{'candela (whole process)':<28}{a.spp:>5}{a.threads:>8}{tc:>10.3f}{n / tc / 1e6:>12.3f}")
    print(f"{'mitsuba scalar_spectral':<28}{a.spp:>5}{a.threads:>8}{tm:>10.3f}{n / tm / 1e6:>12.3f}   (scene load {load:.3f} s, not counted)")
    print(f"ratio candela/mitsuba = {tc / tm:.3f}  (< 1: candela faster)")
    mc, mm = means(mi, cout), means(mi, mout)
    import numpy as np
    for name, path in (("candela", cout), ("mitsuba", mout)):
        a = np.array(mi.Bitmap(path))[..., 0]
        side = "left" if a[:, : a.shape[1] // 6].mean() > a[:, -a.shape[1] // 6 :].mean() else "right"
        print(f"{name}: red wall on the {side}")
    print(f"mean RGB candela {mc.round(5)}  mitsuba {mm.round(5)}  (pbrt-v4 normalises RGB emitters by luminance, Mitsuba does not)")


if __name__ == "__main__":
    main()
