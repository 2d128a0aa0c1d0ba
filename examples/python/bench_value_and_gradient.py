"""`SmoothDistance.value_and_gradient` on the points `examples/api_bench.rs` wrote, to
compare with the same query through the Rust API (README, "Python").

Run (after `cargo run --release --example api_bench` has written the points):
    python examples/python/bench_value_and_gradient.py [MESH] [--points FILE]
        [--alpha-rel R] [--beta B] [--repeat K]
"""

import argparse
import time

import numpy as np

import smoothtrace as st

ap = argparse.ArgumentParser()
ap.add_argument("mesh", nargs="?", default="data/bunny.obj")
ap.add_argument("--points", default="/tmp/smoothtrace_points.f64")
ap.add_argument("--alpha-rel", type=float, default=1000.0)
ap.add_argument("--beta", type=float, default=0.5)
ap.add_argument("--repeat", type=int, default=1)
a = ap.parse_args()

V, F = st.load_mesh(a.mesh)
sd = st.SmoothDistance(V, faces=F, alpha_rel=a.alpha_rel, beta=a.beta)
P = np.fromfile(a.points, dtype="<f8").reshape(-1, 3)
best = best_cpu = float("inf")
for _ in range(a.repeat):
    t, c = time.perf_counter(), time.process_time()  # process_time: all threads' CPU
    s, g = sd.value_and_gradient(P)
    best = min(best, time.perf_counter() - t)
    best_cpu = min(best_cpu, time.process_time() - c)
print(
    f"python: {len(P)} points, {len(F)} triangles, alpha_rel {a.alpha_rel}, beta {a.beta}: "
    f"{best:.3f} s wall, {best_cpu:.2f} s CPU (best of {a.repeat}), sum of s {s.sum():.9e}"
)
