"""winding_number and signed_distance (issue 32) against an exact numpy solid-angle sum,
and the ValueErrors for query points beyond the command line's limit (1e31)."""

import numpy as np
import pytest

import smoothtrace as st
from conftest import as_stored


def exact_winding(V, F, P):
    """Van Oosterom-Strackee solid angles summed over every face, / 4 pi."""
    A, B, C = (V[F[:, k]][None] - P[:, None] for k in range(3))
    la, lb, lc = (np.linalg.norm(X, axis=-1) for X in (A, B, C))
    num = np.einsum("nmi,nmi->nm", A, np.cross(B, C))
    den = (
        la * lb * lc
        + np.einsum("nmi,nmi->nm", A, B) * lc
        + np.einsum("nmi,nmi->nm", B, C) * la
        + np.einsum("nmi,nmi->nm", C, A) * lb
    )
    return (2 * np.arctan2(num, den)).sum(axis=1) / (4 * np.pi)


@pytest.fixture
def mesh(torus_mesh):
    V, F = torus_mesh
    return as_stored(V), F


def test_winding_numbers_match_the_exact_sum(mesh, rng):
    V, F = mesh
    P = rng.uniform(-1.6, 1.6, size=(400, 3))
    w = st.winding_number(V, F, P)
    exact = exact_winding(V, F, P)
    d, _, _ = st.SmoothDistance(V, faces=F, alpha=1.0).nearest(P)
    away = d > 1e-3 * np.linalg.norm(V.max(0) - V.min(0))
    assert away.sum() > 350
    err = np.abs(w - exact)[away]
    assert err.max() < 1e-3, err.max()
    # A closed torus: winding numbers are 0 or +-1.
    assert np.all(np.minimum(np.abs(exact), np.abs(np.abs(exact) - 1)) < 1e-9)
    assert np.allclose(st.winding_number(V, F, P, beta=0.0), exact, atol=1e-9)


def test_signed_distances_have_the_exact_magnitude_and_the_winding_sign(mesh, rng):
    V, F = mesh
    P = rng.uniform(-1.6, 1.6, size=(300, 3))
    S, idx, closest = st.signed_distance(V, F, P, threads=2)
    d, nidx, nclosest = st.SmoothDistance(V, faces=F, alpha=1.0).nearest(P)
    assert S.shape == (300,) and idx.dtype == np.int64 and closest.shape == (300, 3)
    assert np.array_equal(np.abs(S), d)
    # Where two triangles are equally near (a shared edge or vertex) the batch queries
    # may name either; the closest points are then at the same distance.
    same = idx == nidx
    assert same.mean() > 0.9
    assert np.array_equal(closest[same], nclosest[same])
    gap = np.abs(np.linalg.norm(P - closest, axis=1) - d)
    assert gap.max() <= 1e-12 * max(1.0, d.max())
    exact = exact_winding(V, F, P)
    # The torus' faces may face inwards: inside is |w| near 1 there, w > 1/2 either way
    # for outward faces. Compare with the exact winding number's own test.
    assert np.array_equal(S < 0, exact > 0.5)


@pytest.mark.parametrize("far", [1e200, -1e32, 2e31])
def test_query_points_beyond_the_limit_are_refused_everywhere(mesh, far):
    V, F = mesh
    P = np.array([[0.0, 0.0, 0.0], [far, 0.0, 0.0]])
    sd = st.SmoothDistance(V, faces=F, alpha=1.0)
    for call in (sd.value, sd.value_and_gradient, sd.nearest):
        with pytest.raises(ValueError, match=r"points\[1\] = .*query coordinate .* beyond the accepted"):
            call(P)
    for call in (st.winding_number, st.signed_distance):
        with pytest.raises(ValueError, match=r"P\[1\] = .*query coordinate .* beyond the accepted"):
            call(V, F, P)


def test_bad_arguments_are_named(mesh):
    V, F = mesh
    P = np.zeros((1, 3))
    with pytest.raises(ValueError, match=r"beta must be in \[0, 1\) \(got 1\)"):
        st.winding_number(V, F, P, beta=1.0)
    with pytest.raises(ValueError, match="F is required"):
        st.signed_distance(V, None, P)
    with pytest.raises(ValueError, match=r"F\[0\] holds vertex index 9999"):
        st.winding_number(V, [[0, 1, 9999]], P)
    with pytest.raises(ValueError, match=r"P\[0\] has a non-finite coordinate"):
        st.signed_distance(V, F, [[np.nan, 0, 0]])
    with pytest.raises(ValueError, match=r"threads must be in"):
        st.winding_number(V, F, P, threads=-2)


@pytest.mark.parametrize("bad", [np.inf, -np.inf, np.nan])
def test_non_finite_query_points_are_refused_everywhere(mesh, bad):
    V, F = mesh
    P = np.array([[0.0, 0.0, 0.0], [0.0, bad, 0.0]])
    sd = st.SmoothDistance(V, faces=F, alpha=1.0)
    for call in (sd.value, sd.value_and_gradient, sd.nearest):
        with pytest.raises(ValueError, match=r"points\[1\] has a non-finite coordinate"):
            call(P)
    for call in (st.winding_number, st.signed_distance):
        with pytest.raises(ValueError, match=r"P\[1\] has a non-finite coordinate"):
            call(V, F, P)
