#!/usr/bin/env python3
"""Scene load time for a 1M-triangle binary PLY mesh: parse + PLY read + BVH build.

    python3 bench/ply_load.py [--triangles 1000000] [--runs 3] [--threads N]

Writes a sphere tessellated as a latitude/longitude grid (positions, normals
and uvs, little-endian binary PLY, 3-index faces) into a temporary directory,
with a scene that loads it through `Shape "plymesh"`, and times
`candela info` on it (wall clock of the whole process, best of --runs) next
to the parse/build split that `info` prints. The target is < 2 s.
Build candela first: cargo build --release -p candela.
"""
import argparse, math, os, re, struct, subprocess, sys, tempfile, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.join(ROOT, "target", "release", "candela")


def write_sphere_ply(path, triangles):
    """A (rings x segments) lat/long sphere grid with about `triangles` triangles."""
    seg = max(3, int(math.sqrt(triangles / 2)))
    rings = max(2, triangles // (2 * seg))
    nv = (rings + 1) * (seg + 1)
    nf = 2 * rings * seg
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {nv}\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        "property float u\nproperty float v\n"
        f"element face {nf}\n"
        "property list uchar int vertex_indices\nend_header\n"
    )
    vert = struct.Struct("<8f")
    face = struct.Struct("<B3i")
    with open(path, "wb") as f:
        f.write(header.encode())
        buf = bytearray()
        for i in range(rings + 1):
            theta = math.pi * i / rings
            st, ct = math.sin(theta), math.cos(theta)
            for j in range(seg + 1):
                phi = 2 * math.pi * j / seg
                x, y, z = st * math.cos(phi), st * math.sin(phi), ct
                buf += vert.pack(x, y, z, x, y, z, j / seg, i / rings)
        f.write(buf)
        buf = bytearray()
        for i in range(rings):
            for j in range(seg):
                a = i * (seg + 1) + j
                b, c, d = a + 1, a + seg + 1, a + seg + 2
                buf += face.pack(3, a, c, b)
                buf += face.pack(3, b, c, d)
        f.write(buf)
    return nf


SCENE = """LookAt 0 0 -4  0 0 0  0 1 0
Camera "perspective" "float fov" [40]
Film "rgb" "integer xresolution" [64] "integer yresolution" [64]
Sampler "independent" "integer pixelsamples" [1]
Integrator "path"
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
Material "diffuse"
Shape "plymesh" "string filename" "sphere.ply"
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--triangles", type=int, default=1_000_000)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--threads", type=int, default=0, help="RAYON_NUM_THREADS (0: all cores)")
    args = ap.parse_args()
    if not os.path.exists(BIN):
        sys.exit(f"{BIN} not found: run cargo build --release -p candela")
    env = dict(os.environ)
    if args.threads:
        env["RAYON_NUM_THREADS"] = str(args.threads)
    with tempfile.TemporaryDirectory(prefix="candela-ply-") as d:
        t0 = time.perf_counter()
        nf = write_sphere_ply(os.path.join(d, "sphere.ply"), args.triangles)
        size = os.path.getsize(os.path.join(d, "sphere.ply")) / 1e6
        print(f"wrote {nf} triangles ({size:.1f} MB) in {time.perf_counter() - t0:.1f} s")
        scene = os.path.join(d, "scene.pbrt")
        with open(scene, "w") as f:
            f.write(SCENE)
        best, out = math.inf, ""
        for _ in range(args.runs):
            t0 = time.perf_counter()
            r = subprocess.run([BIN, "info", scene], capture_output=True, text=True, env=env)
            dt = time.perf_counter() - t0
            if r.returncode != 0:
                sys.exit(r.stderr)
            if dt < best:
                best, out = dt, r.stdout
        tri = re.search(r"triangles\s+(\d+)", out).group(1)
        load = re.search(r"load\s+(.*)", out).group(1)
        print(f"candela info: {tri} triangles; {load}")
        print(f"scene load (whole process, best of {args.runs}): {best:.3f} s  [target < 2 s]")


if __name__ == "__main__":
    main()
