"""Batch queries against Open3D (issue 30, item 4): `nearest` (exact distance to the
triangles) against Open3D's `RaycastingScene.compute_distance` (Embree), and
`SmoothDistance.value` against `nearest`, on the same points and threads.

Two kinds of points: `near` (a random vertex plus a Gaussian offset of sigma 0.005 of the
diagonal) and `box` (uniform in the mesh's box grown by 10% of the diagonal). Open3D
stores the mesh and the queries in float32; its distances are checked against ours
(largest difference relative to the diagonal). Without Open3D (`pip install open3d`)
its columns are skipped, saying why.

`value` is timed at the default pruning and at each `--tolerance-rel` (how far pruning
may lower the value, relative to the diagonal: `SmoothDistance(..., tolerance=)`), with
the largest difference from the default's values.

Run:
    python examples/python/bench_queries.py [MESH] [--n-near 500000] [--n-box 1000000]
        [--alpha-rel 1000,3000] [--tolerance-rel 1e-7] [--beta 0.5] [--threads 2]
        [--repeat 3] [--json F] [--csv F]
"""

import argparse
import csv
import json
import time

import numpy as np

import smoothtrace as st

ap = argparse.ArgumentParser()
ap.add_argument("mesh", nargs="?", default="data/bunny.obj")
ap.add_argument("--n-near", type=int, default=500_000)
ap.add_argument("--n-box", type=int, default=1_000_000)
ap.add_argument("--alpha-rel", default="1000,3000")
ap.add_argument("--tolerance-rel", default="1e-7")
ap.add_argument("--beta", type=float, default=0.5)
ap.add_argument("--threads", type=int, default=2)
ap.add_argument("--repeat", type=int, default=3)
ap.add_argument("--json")
ap.add_argument("--csv")
a = ap.parse_args()

V, F = st.load_mesh(a.mesh)
lo, hi = V.min(axis=0), V.max(axis=0)
diag = float(np.linalg.norm(hi - lo))
rng = np.random.default_rng(5)
points = {
    "near": V[rng.integers(0, len(V), a.n_near)] + rng.normal(0.0, 0.005 * diag, (a.n_near, 3)),
    "box": rng.uniform(lo - 0.1 * diag, hi + 0.1 * diag, (a.n_box, 3)),
}


def best_of(f):
    best, out = float("inf"), None
    for _ in range(a.repeat):
        t = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t)
    return best, out


try:
    import open3d as o3d

    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(
        o3d.core.Tensor(V.astype(np.float32)), o3d.core.Tensor(F.astype(np.uint32))
    )
    open3d_why = None
except ImportError as e:
    o3d, open3d_why = None, f"Open3D not installed ({e}); pip install open3d"

rows = []
for kind, P in points.items():
    sd0 = st.SmoothDistance(V, faces=F, alpha_rel=1000.0, beta=a.beta)
    t_near, (d, _, _) = best_of(lambda: sd0.nearest(P, threads=a.threads))
    row = {"points": kind, "n": len(P), "threads": a.threads, "nearest_s": round(t_near, 4)}
    if o3d is not None:
        q = o3d.core.Tensor(P.astype(np.float32))
        t_o3d, d3 = best_of(lambda: scene.compute_distance(q, nthreads=a.threads).numpy())
        row["open3d_s"] = round(t_o3d, 4)
        row["open3d_over_nearest"] = round(t_o3d / t_near, 2)
        row["max_diff_rel_diag"] = float(np.abs(d3 - d).max() / diag)
    for r in [float(x) for x in a.alpha_rel.split(",")]:
        sd = st.SmoothDistance(V, faces=F, alpha_rel=r, beta=a.beta)
        t_val, s_default = best_of(lambda: sd.value(P, threads=a.threads))
        row[f"value_s_alpha_rel_{r:g}"] = round(t_val, 4)
        row[f"value_over_nearest_alpha_rel_{r:g}"] = round(t_val / t_near, 2)
        for tr in [float(x) for x in a.tolerance_rel.split(",") if x]:
            sd_t = st.SmoothDistance(V, faces=F, alpha_rel=r, beta=a.beta, tolerance=tr * diag)
            t_t, s_t = best_of(lambda: sd_t.value(P, threads=a.threads))
            key = f"alpha_rel_{r:g}_tolerance_rel_{tr:g}"
            row[f"value_s_{key}"] = round(t_t, 4)
            row[f"value_over_nearest_{key}"] = round(t_t / t_near, 2)
            row[f"max_diff_rel_diag_{key}"] = float(np.abs(s_t - s_default).max() / diag)
    rows.append(row)
    print(", ".join(f"{k} {v}" for k, v in row.items()), flush=True)
if open3d_why:
    print(f"skipped the Open3D columns: {open3d_why}")
if a.json:
    with open(a.json, "w") as f:
        json.dump({"mesh": a.mesh, "beta": a.beta, "rows": rows}, f, indent=1)
if a.csv:
    keys = sorted({k for r in rows for k in r}, key=lambda k: list(rows[0]).index(k) if k in rows[0] else 99)
    with open(a.csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
