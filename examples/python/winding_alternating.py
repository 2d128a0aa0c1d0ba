"""Winding numbers, smoothtrace and libigl called in turn (issue 32): the ratio of each
pair of calls on the same 1M points, so that both libraries see the same moment of a
noisy machine (the best-of-N figures of `bench_winding.py` move by 20% between runs).

Run (from the repository root, with the package and libigl in the virtual environment):
    .venv/bin/python examples/python/winding_alternating.py [--mesh data/bunny.obj]
        [--points 1000000] [--pairs 9] [--threads 2]

Points as in `bench_winding.py` (uniform in the box grown by 10% of the diagonal, seed
32). Prints each library's times, the median and range of the per-pair ratios and the
median CPU time (user + sys, all threads) per call.
"""

import argparse
import statistics
import sys
import time

import numpy as np

import smoothtrace as st

ap = argparse.ArgumentParser()
ap.add_argument("--mesh", default="data/bunny.obj")
ap.add_argument("--points", type=int, default=1_000_000)
ap.add_argument("--pairs", type=int, default=9)
ap.add_argument("--threads", type=int, default=2)
a = ap.parse_args()
try:
    import igl
except ImportError:
    sys.exit("libigl is not installed (pip install libigl): nothing to compare with")

V, F = st.load_mesh(a.mesh)
lo, hi = V.min(0), V.max(0)
diag = float(np.linalg.norm(hi - lo))
P = np.random.default_rng(32).uniform(lo - 0.1 * diag, hi + 0.1 * diag, size=(a.points, 3))
ours, theirs, ours_cpu, theirs_cpu = [], [], [], []
for _ in range(a.pairs):
    t, c = time.perf_counter(), time.process_time()
    st.winding_number(V, F, P, threads=a.threads)
    ours.append(time.perf_counter() - t)
    ours_cpu.append(time.process_time() - c)
    t, c = time.perf_counter(), time.process_time()
    igl.fast_winding_number(V, F, P)
    theirs.append(time.perf_counter() - t)
    theirs_cpu.append(time.process_time() - c)
ratios = [b / o for o, b in zip(ours, theirs)]
print("smoothtrace s:", " ".join(f"{x:.3f}" for x in ours))
print("libigl s:     ", " ".join(f"{x:.3f}" for x in theirs))
print(
    f"median {statistics.median(ours):.3f} s against {statistics.median(theirs):.3f} s; "
    f"ratio per pair: median {statistics.median(ratios):.2f}x, "
    f"range {min(ratios):.2f}x-{max(ratios):.2f}x"
)
print(
    f"CPU (user + sys) per call, median: {statistics.median(ours_cpu):.3f} s against "
    f"{statistics.median(theirs_cpu):.3f} s"
)
