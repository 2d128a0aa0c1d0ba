"""Smooth distance values and gradients against numpy references (SPEC 2, 4, 5)."""

import numpy as np
import pytest

import smoothtrace as st
from conftest import as_stored
from reference import edge_weights, lse, point_distances, segment_closest, triangle_distances

# Pruning keeps every value within 2e-10 / alpha of the exact sum (README, "Barnes-Hut").
def close(a, b, alpha):
    return np.abs(a - b) <= 1e-9 / alpha + 1e-9 * np.abs(b)


def queries(V, n, rng, spread=0.3):
    lo, hi = V.min(axis=0), V.max(axis=0)
    d = np.linalg.norm(hi - lo)
    return rng.uniform(lo - spread * d, hi + spread * d, size=(n, 3))


def test_points_match_numpy_logsumexp_at_beta_0(rng):
    V = rng.normal(size=(400, 3))
    P = queries(V, 60, rng)
    for alpha_rel in (5.0, 50.0, 500.0):
        sd = st.SmoothDistance(V, alpha_rel=alpha_rel, beta=0.0)
        assert sd.primitives == ["points"]
        ref = lse(point_distances(P, as_stored(V)), sd.alpha)
        s = sd.value(P)
        bad = ~close(s, ref, sd.alpha)
        assert not bad.any(), f"alpha_rel {alpha_rel}: {s[bad]} vs {ref[bad]}"


def test_edges_with_weights_match_numpy_at_beta_0(torus_mesh, rng):
    V, F = torus_mesh
    E = np.unique(np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1), axis=0)
    # A few extra edges at one vertex raise its valence, so the weights vary.
    E = np.concatenate([E, [[0, 40], [0, 80], [0, 120]]])
    P = queries(V, 40, rng, 0.1)
    for alpha, max_alpha in ((30.0, 30.0), (30.0, 120.0)):
        sd = st.SmoothDistance(V, edges=E, alpha=alpha, max_alpha=max_alpha, beta=0.0)
        np.testing.assert_array_equal(sd.edges, E)
        val = np.bincount(E.ravel(), minlength=len(V))
        Vs = as_stored(V)
        D, t = segment_closest(P, Vs[E[:, 0]], Vs[E[:, 1]])
        W = edge_weights(t, val[E[:, 0]], val[E[:, 1]], val.max(), min(alpha / max_alpha, 1.0))
        ref = lse(D, alpha, W)
        s = sd.value(P)
        bad = ~close(s, ref, alpha)
        assert not bad.any(), f"max_alpha {max_alpha}: {s[bad]} vs {ref[bad]}"


def test_triangles_match_numpy_logsumexp_with_flat_weights(torus_mesh, rng):
    # max_alpha = 1e12 alpha makes the attenuation exponent 1e-12: every weight is 1 to
    # within 1e-11, so the sum is the plain LogSumExp of the exact triangle distances.
    V, F = torus_mesh
    alpha = 20.0
    sd = st.SmoothDistance(V, faces=F, alpha=alpha, max_alpha=1e12 * alpha, beta=0.0)
    P = queries(V, 40, rng, 0.1)
    ref = lse(triangle_distances(P, as_stored(V), F), alpha)
    s = sd.value(P)
    bad = np.abs(s - ref) > 1e-9 + 1e-9 * np.abs(ref)
    assert not bad.any(), f"{s[bad]} vs {ref[bad]}"


def test_beta_gives_a_lower_bound_below_the_nearest_distance(torus_mesh, rng):
    V, F = torus_mesh
    P = queries(V, 300, rng)
    exact = st.SmoothDistance(V, faces=F, alpha_rel=100, beta=0.0)
    approx = st.SmoothDistance(V, faces=F, alpha_rel=100, beta=0.5)
    s0, s5 = exact.value(P), approx.value(P)
    d, _, _ = exact.nearest(P)
    assert (s5 <= s0 + 1e-12 * np.abs(s0)).all()
    assert (s0 <= d + 1e-12).all()
    # value() and value_and_gradient() take different traversals (value only / with
    # gradient); they agree.
    s, _ = approx.value_and_gradient(P)
    np.testing.assert_allclose(s, s5, rtol=1e-12, atol=1e-14)


def test_a_tolerance_bounds_what_pruning_takes(torus_mesh, rng):
    # tolerance=0 sums every term (the exact sum at beta 0); a tolerance t lowers the
    # value by at most t, and the pruning takes most of it somewhere.
    V, F = torus_mesh
    P = queries(V, 300, rng, 0.1)
    exact = st.SmoothDistance(V, faces=F, alpha_rel=100, beta=0.0, tolerance=0.0)
    s0 = exact.value(P)
    default = st.SmoothDistance(V, faces=F, alpha_rel=100, beta=0.0).value(P)
    assert close(default, s0, exact.alpha).all()
    diag = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    for t in (1e-8 * diag, 1e-6 * diag):
        s = st.SmoothDistance(V, faces=F, alpha_rel=100, beta=0.0, tolerance=t).value(P)
        assert (s <= s0 + 1e-12 * np.abs(s0)).all()
        assert (s0 - s <= t * (1 + 1e-9)).all()
        assert (s0 - s).max() >= 0.5 * t


@pytest.mark.parametrize("kind", ["points", "edges", "triangles"])
def test_gradients_match_central_differences(torus_mesh, rng, kind):
    V, F = torus_mesh
    sd = st.SmoothDistance(V, faces=F, primitives=kind, alpha_rel=60, beta=0.0)
    P = queries(V, 40, rng, 0.05)
    s, g = sd.value_and_gradient(P)
    h = 1e-6
    num = np.empty_like(g)
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        num[:, k] = (sd.value(P + e) - sd.value(P - e)) / (2 * h)
    err = np.linalg.norm(g - num, axis=1)
    assert (err < 1e-5 * np.maximum(1.0, np.linalg.norm(num, axis=1))).all(), (
        f"{kind}: max |g - central difference| = {err.max():.3g}"
    )


def test_other_dtypes_are_converted(torus_mesh):
    V, F = torus_mesh
    ref = st.SmoothDistance(V, faces=F, alpha=10.0)
    P = np.array([[0.0, 1.0, 0.0], [2.0, 0.0, 1.0]])
    for sd in (
        st.SmoothDistance(V.astype(np.float32), faces=F.astype(np.int32), alpha=10),
        st.SmoothDistance(V.tolist(), faces=F.astype(np.uint16), alpha=np.float32(10.0)),
    ):
        np.testing.assert_array_equal(sd.value(P), ref.value(P))
    np.testing.assert_array_equal(ref.value(P.astype(np.int64)), ref.value(P))
    np.testing.assert_array_equal(ref.value(P.astype(np.float32)), ref.value(P.astype(np.float32).astype(np.float64)))
    # Non-contiguous views are copied.
    Q = np.asfortranarray(np.tile(P, (3, 1)))[::3]
    np.testing.assert_array_equal(ref.value(Q), ref.value(P))


def test_alpha_rel_and_threads(torus_mesh):
    V, F = torus_mesh
    diag = np.linalg.norm(as_stored(V).max(0) - as_stored(V).min(0))
    sd = st.SmoothDistance(V, faces=F, alpha_rel=300)
    assert sd.alpha == pytest.approx(300 / diag, rel=1e-12)
    assert sd.max_alpha == sd.alpha
    P = np.random.default_rng(1).normal(size=(500, 3))
    np.testing.assert_array_equal(sd.value(P, threads=1), sd.value(P, threads=0))
    np.testing.assert_array_equal(sd.value(P, threads=2), sd.value(P))


def test_several_sets_are_summed(torus_mesh, rng):
    V, F = torus_mesh
    P = queries(V, 30, rng)
    both = st.SmoothDistance(V, faces=F, primitives=["triangles", "points"], alpha=15.0, beta=0.0)
    assert both.primitives == ["triangles", "points"]
    tri = st.SmoothDistance(V, faces=F, alpha=15.0, beta=0.0)
    pts = st.SmoothDistance(V, primitives="points", alpha=15.0, beta=0.0)
    # LogSumExp of two sums: -1/a ln(exp(-a s1) + exp(-a s2)).
    s1, s2 = tri.value(P), pts.value(P)
    m = np.minimum(s1, s2)
    ref = m - np.log(np.exp(-15.0 * (s1 - m)) + np.exp(-15.0 * (s2 - m))) / 15.0
    np.testing.assert_allclose(both.value(P), ref, rtol=1e-9, atol=1e-10)


@pytest.mark.parametrize("kind", ["points", "edges", "triangles"])
def test_value_bounds_bracket_the_exact_value(torus_mesh, rng, kind):
    V, F = torus_mesh
    P = queries(V, 200, rng, 0.1)
    for alpha_rel in (20.0, 200.0):
        exact = st.SmoothDistance(V, faces=F, primitives=kind, alpha_rel=alpha_rel, beta=0.0)
        approx = st.SmoothDistance(V, faces=F, primitives=kind, alpha_rel=alpha_rel, beta=0.7)
        s0 = exact.value(P)
        lo, hi = approx.value_bounds(P)
        assert lo.shape == hi.shape == (len(P),) and lo.dtype == hi.dtype == np.float64
        slack = 1e-9 / approx.alpha + 1e-9 * np.abs(s0)
        assert (lo <= s0 + slack).all() and (s0 <= hi + slack).all()
        assert (hi - lo).max() > 1e-6 / approx.alpha  # beta 0.7 is not exact somewhere
        v = approx.value(P)
        assert (v <= s0 + slack).all()
        if kind != "points":
            np.testing.assert_array_equal(lo, v)
        # At beta 0 the interval closes (up to the pruning, a share 1e-10 of the sum).
        lo0, hi0 = exact.value_bounds(P)
        assert ((hi0 - lo0) * exact.alpha < 1e-8).all()
