"""Winding numbers and signed distances (issue 32): smoothtrace against libigl on the
full bunny, both run here, back to back, on the same points.

Run (from the repository root, with the package and libigl in the virtual environment:
`.venv/bin/pip install . libigl`):
    .venv/bin/python examples/python/bench_winding.py [--mesh data/bunny.obj]
        [--winding-points 1000000] [--signed-points 200000] [--threads 2] [--beta 0.3]
        [--repeat 3] [--exact 2000] [--out doc/winding-bench.csv]

Points are uniform in the mesh's box grown by 10% of its diagonal on every side (seed
32). Timings are the best of `--repeat` runs (wall seconds and CPU seconds of all
threads); smoothtrace runs with `threads=--threads`, libigl with its own thread pool
(all cores: on the 2-core machine of the README, 2 threads). Accuracy: the largest
error against the exact winding number (`igl.winding_number`) on the first `--exact`
points, counting points farther than 1e-3 of the diagonal from the surface, and the
number of sign disagreements (inside = exact w > 1/2) there. Without libigl the
comparison rows are skipped and the script says why. Writes a CSV table.
"""

import argparse
import csv
import os
import sys
import time

import numpy as np

import smoothtrace as st

ap = argparse.ArgumentParser()
ap.add_argument("--mesh", default="data/bunny.obj")
ap.add_argument("--winding-points", type=int, default=1_000_000)
ap.add_argument("--signed-points", type=int, default=200_000)
ap.add_argument("--threads", type=int, default=2)
ap.add_argument("--beta", type=float, default=0.3, help="smoothtrace's far-field parameter")
ap.add_argument("--repeat", type=int, default=3)
ap.add_argument("--exact", type=int, default=2000)
ap.add_argument("--out", default="doc/winding-bench.csv")
a = ap.parse_args()

if not os.path.exists(a.mesh):
    sys.exit(f"{a.mesh} not found: link ../shared/data as data/ (see the README)")
try:
    import igl
except ImportError as e:
    igl = None
    print(f"note: libigl is not installed ({e}); only smoothtrace is timed. "
          "Install it with `.venv/bin/pip install libigl`.")

V, F = st.load_mesh(a.mesh)
lo, hi = V.min(0), V.max(0)
diag = float(np.linalg.norm(hi - lo))
rng = np.random.default_rng(32)
n = max(a.winding_points, a.signed_points)
P = rng.uniform(lo - 0.1 * diag, hi + 0.1 * diag, size=(n, 3))


def best(f):
    out, wall, cpu = None, float("inf"), float("inf")
    for _ in range(a.repeat):
        t, c = time.perf_counter(), time.process_time()
        out = f()
        wall = min(wall, time.perf_counter() - t)
        cpu = min(cpu, time.process_time() - c)
    return out, wall, cpu


# References on the first --exact points.
E = P[: a.exact]
d_ref, _, _ = st.SmoothDistance(V, faces=F, alpha=1.0).nearest(E)
away = d_ref > 1e-3 * diag
exact = igl.winding_number(V, F, E) if igl else st.winding_number(V, F, E, beta=0.0)


def accuracy(w):
    e = np.abs(w[: a.exact] - exact)[away]
    return float(e.max()), int(((w[: a.exact] > 0.5) != (exact > 0.5))[away].sum())


rows = []
Pw, Ps = P[: a.winding_points], P[: a.signed_points]


def add(task, library, points, wall, cpu, max_err, signs):
    rows.append(dict(task=task, library=library, beta=a.beta if library == "smoothtrace" else "",
                     points=points, wall_s=round(wall, 4),
                     cpu_s=round(cpu, 3), max_err=f"{max_err:.2e}", sign_errors=signs,
                     checked=int(away.sum())))
    print(rows[-1], flush=True)


for _ in range(1):  # interleave the libraries so that both see the same machine load
    w, wall, cpu = best(lambda: st.winding_number(V, F, Pw, threads=a.threads, beta=a.beta))
    add("winding_number", "smoothtrace", len(Pw), wall, cpu, *accuracy(w))
    if igl:
        w, wall, cpu = best(lambda: igl.fast_winding_number(V, F, Pw))
        add("winding_number", "libigl fast_winding_number", len(Pw), wall, cpu, *accuracy(w))
    (S, _, _), wall, cpu = best(lambda: st.signed_distance(V, F, Ps, threads=a.threads, beta=a.beta))
    e = np.abs(np.abs(S[: a.exact]) - d_ref).max()
    assert e == 0.0, f"|S| differs from the unsigned distance by {e}"
    add("signed_distance", "smoothtrace", len(Ps), wall, cpu, float("nan"),
        int(((S[: a.exact] < 0) != (exact > 0.5))[away].sum()))
    if igl:
        t = igl.SIGNED_DISTANCE_TYPE_FAST_WINDING_NUMBER
        (S, _, _, _), wall, cpu = best(lambda: igl.signed_distance(Ps, V, F, sign_type=t))
        add("signed_distance", "libigl signed_distance(FAST_WINDING_NUMBER)", len(Ps), wall, cpu,
            float("nan"), int(((S[: a.exact] < 0) != (exact > 0.5))[away].sum()))

os.makedirs(os.path.dirname(a.out) or ".", exist_ok=True)
with open(a.out, "w", newline="") as f:
    wr = csv.DictWriter(f, fieldnames=list(rows[0]))
    wr.writeheader()
    wr.writerows(rows)
print(f"wrote {a.out}")
