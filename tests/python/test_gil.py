"""The GIL is released while a query runs: another Python thread makes progress meanwhile."""

import threading
import time

import numpy as np

import smoothtrace as st
from conftest import torus


def test_a_second_thread_runs_during_a_long_query():
    V, F = torus(48, 24)
    sd = st.SmoothDistance(V, faces=F, alpha_rel=5, beta=0.0)  # soft: many terms per query
    P = np.random.default_rng(3).uniform(-2, 2, size=(2_000, 3))
    window = {}

    def query():
        window["start"] = time.perf_counter()
        sd.value_and_gradient(P, threads=1)
        window["end"] = time.perf_counter()

    worker = threading.Thread(target=query)
    ticks = []
    worker.start()
    while worker.is_alive():
        ticks.append(time.perf_counter())
    worker.join()
    start, end = window["start"], window["end"]
    # Ticks can only fall inside the query's middle half if this thread ran Python code
    # while the query held no GIL (held, the GIL would block this loop until the end).
    lo, hi = start + 0.25 * (end - start), end - 0.25 * (end - start)
    inside = sum(lo < t < hi for t in ticks)
    assert inside > 100, f"{inside} ticks in the middle of a {end - start:.3f} s query"
