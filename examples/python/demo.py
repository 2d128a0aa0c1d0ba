"""A tour of the Python package: load a mesh, query the smooth distance on a grid, plot
a slice (with matplotlib, when it is installed), render the smooth surface to an array.

Run from the repository root after `pip install .`:
    python examples/python/demo.py [MESH] [--out DIR]
MESH defaults to data/bunny-7k.obj, or a procedural torus when the data is not linked.
"""

import argparse
import pathlib
import time

import numpy as np

import smoothtrace as st

ap = argparse.ArgumentParser()
ap.add_argument("mesh", nargs="?", default="data/bunny-7k.obj")
ap.add_argument("--out", default=".", help="directory for the plot and the render")
a = ap.parse_args()
out = pathlib.Path(a.out)

# 1. A mesh: from a file, or a torus made here when the file is absent.
if pathlib.Path(a.mesh).is_file():
    V, F = st.load_mesh(a.mesh)
    name = pathlib.Path(a.mesh).stem
else:
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 48, endpoint=False), np.linspace(0, 2 * np.pi, 24, endpoint=False), indexing="ij")
    V = np.stack([(1 + 0.35 * np.cos(v)) * np.cos(u), 0.35 * np.sin(v), (1 + 0.35 * np.cos(v)) * np.sin(u)], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(48), np.arange(24), indexing="ij")
    a00, a10 = i * 24 + j, ((i + 1) % 48) * 24 + j
    a11, a01 = ((i + 1) % 48) * 24 + (j + 1) % 24, i * 24 + (j + 1) % 24
    F = np.concatenate([np.stack([a00, a10, a11], -1).reshape(-1, 3), np.stack([a00, a11, a01], -1).reshape(-1, 3)])
    name = "torus"
print(f"{name}: {len(V)} vertices, {len(F)} triangles")

# 2. The smooth distance on a 256 x 256 grid in the plane through the box centre.
sd = st.SmoothDistance(V, faces=F, alpha_rel=300, beta=0.5)
print(sd)
lo, hi = V.min(0), V.max(0)
c, pad = 0.5 * (lo + hi), 0.15 * np.linalg.norm(hi - lo)
xs = np.linspace(lo[0] - pad, hi[0] + pad, 256)
ys = np.linspace(lo[1] - pad, hi[1] + pad, 256)
X, Y = np.meshgrid(xs, ys)
P = np.stack([X.ravel(), Y.ravel(), np.full(X.size, c[2])], axis=1)
t = time.perf_counter()
s, g = sd.value_and_gradient(P)
print(f"{len(P)} queries in {time.perf_counter() - t:.3f} s; s in [{s.min():.4g}, {s.max():.4g}]")
d, idx, closest = sd.nearest(P[:5])
print("nearest triangles of the first 5 points:", idx, "at distances", np.round(d, 5))

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: skipping the slice plot")
else:
    fig, ax = plt.subplots(figsize=(6, 5))
    S = s.reshape(X.shape)
    im = ax.contourf(X, Y, S, levels=30, cmap="viridis")
    ax.contour(X, Y, S, levels=[0.0], colors="white", linewidths=1.5)
    G = g.reshape(*X.shape, 3)
    k = slice(None, None, 16)
    ax.quiver(X[k, k], Y[k, k], G[k, k, 0], G[k, k, 1], color="white", alpha=0.6)
    ax.set_aspect("equal")
    ax.set_title(f"{name}: smooth distance at z = {c[2]:.3g} (white: s = 0)")
    fig.colorbar(im)
    fig.savefig(out / f"{name}_slice.png", dpi=100)
    print(f"wrote {out / (name + '_slice.png')}")

# 3. The zero level set rendered to a (h, w, 4) uint8 array with the default camera.
img = st.render_arrays(V, faces=F, alpha_rel=300, width=320, height=240, matcap="clay")
print(f"render: {img.shape} {img.dtype}, {np.mean(img[..., :3].min(-1) < 250):.0%} of the pixels show the surface")
try:
    import matplotlib.pyplot as plt

    plt.imsave(out / f"{name}_render.png", img)
    print(f"wrote {out / (name + '_render.png')}")
except ImportError:
    np.save(out / f"{name}_render.npy", img)
    print(f"wrote {out / (name + '_render.npy')} (matplotlib is not installed to write a PNG)")
