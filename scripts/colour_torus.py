#!/usr/bin/env python3
"""Writes tests/data/colour_torus.ply: a torus (major radius 0.7, minor 0.3, in the xz
plane, y up) of 36 x 18 vertices and 1296 triangles with per-vertex uchar colours in six
hue bands around the major circle. It is the input of
scenes/colour_vertex.toml (the colour-by-vertex golden and gallery image).

Run: python3 scripts/colour_torus.py  (no dependencies; the output is deterministic)
"""
import math
import struct
from pathlib import Path

MAJOR, MINOR = 0.7, 0.3
NU, NV = 36, 18
BANDS = [(230, 57, 70), (244, 162, 97), (233, 196, 106), (42, 157, 143), (38, 70, 83), (131, 56, 236)]

out = Path(__file__).resolve().parent.parent / "tests" / "data" / "colour_torus.ply"
verts, tris = [], []
for i in range(NU):
    u = 2 * math.pi * i / NU
    band = BANDS[i * len(BANDS) // NU]
    for j in range(NV):
        v = 2 * math.pi * j / NV
        r = MAJOR + MINOR * math.cos(v)
        verts.append((r * math.cos(u), MINOR * math.sin(v), r * math.sin(u), band))
for i in range(NU):
    for j in range(NV):
        a = i * NV + j
        b = ((i + 1) % NU) * NV + j
        c = ((i + 1) % NU) * NV + (j + 1) % NV
        d = i * NV + (j + 1) % NV
        tris += [(a, b, c), (a, c, d)]
header = (
    "ply\nformat binary_little_endian 1.0\n"
    "comment written by scripts/colour_torus.py\n"
    f"element vertex {len(verts)}\n"
    "property float x\nproperty float y\nproperty float z\n"
    "property uchar red\nproperty uchar green\nproperty uchar blue\n"
    f"element face {len(tris)}\nproperty list uchar int vertex_indices\nend_header\n"
)
with open(out, "wb") as f:
    f.write(header.encode("ascii"))
    for x, y, z, (r, g, b) in verts:
        f.write(struct.pack("<fffBBB", x, y, z, r, g, b))
    for t in tris:
        f.write(struct.pack("<Biii", 3, *t))
print(f"wrote {out} ({len(verts)} vertices, {len(tris)} triangles)")
