#!/usr/bin/env python3
"""Writes scenes/coated-killeroo/geometry/killeroo.ply from the killeroo
control mesh in scenes/killeroo-simple/geometry/killeroo.pbrt.

    python3 tools/killeroo_ply.py

The control mesh (the `loopsubdiv` shape's "point3 P" and "integer indices")
becomes a binary little-endian PLY with smooth per-vertex normals (the
area-weighted average of the adjacent faces' normals), so candela's PLY
reader, shading normals and `plymesh` path are exercised by a small,
organic mesh. Standard library only.
"""
import math, os, re, struct

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SRC = os.path.join(ROOT, "scenes", "killeroo-simple", "geometry", "killeroo.pbrt")
DST = os.path.join(ROOT, "scenes", "coated-killeroo", "geometry", "killeroo.ply")


def values(text, decl):
    """The bracketed numbers after the parameter declaration `decl`."""
    m = re.search(r'"' + decl + r'"\s*\[([^\]]*)\]', text)
    return m.group(1).split()


def main():
    text = open(SRC).read()
    p = [float(v) for v in values(text, "point3 P")]
    idx = [int(v) for v in values(text, "integer indices")]
    verts = [p[i:i + 3] for i in range(0, len(p), 3)]
    tris = [idx[i:i + 3] for i in range(0, len(idx), 3)]
    normals = [[0.0, 0.0, 0.0] for _ in verts]
    for a, b, c in tris:
        pa, pb, pc = verts[a], verts[b], verts[c]
        e1 = [pb[k] - pa[k] for k in range(3)]
        e2 = [pc[k] - pa[k] for k in range(3)]
        # The cross product's length is twice the area: an area weight.
        n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
        for v in (a, b, c):
            for k in range(3):
                normals[v][k] += n[k]
    for n in normals:
        length = math.sqrt(sum(x * x for x in n)) or 1.0
        for k in range(3):
            n[k] /= length
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        "comment killeroo control mesh from scenes/killeroo-simple, smooth normals\n"
        f"element vertex {len(verts)}\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        f"element face {len(tris)}\n"
        "property list uchar int vertex_indices\nend_header\n"
    )
    os.makedirs(os.path.dirname(DST), exist_ok=True)
    with open(DST, "wb") as f:
        f.write(header.encode())
        for v, n in zip(verts, normals):
            f.write(struct.pack("<6f", *v, *n))
        for t in tris:
            f.write(struct.pack("<B3i", 3, *t))
    print(f"wrote {DST}: {len(verts)} vertices, {len(tris)} triangles")


if __name__ == "__main__":
    main()
