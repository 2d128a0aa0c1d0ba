"""numpy brute-force references, written independently of the Rust code from SPEC 2-4:
exact distances to points, segments and triangles, the edge weight quartic, and the
LogSumExp sum at beta 0."""

import numpy as np


def point_distances(P, V):
    """(n, m) distances from queries P to points V."""
    return np.linalg.norm(P[:, None, :] - V[None, :, :], axis=-1)


def segment_closest(P, A, B):
    """(n, m) distances and parameters t of the closest points on segments A-B."""
    AB = B - A
    L2 = np.einsum("ij,ij->i", AB, AB)
    t = np.einsum("nmj,mj->nm", P[:, None, :] - A[None], AB) / np.where(L2 > 0, L2, 1.0)
    t = np.clip(t, 0.0, 1.0)
    C = A[None] + t[..., None] * AB[None]
    return np.linalg.norm(P[:, None, :] - C, axis=-1), t


def triangle_closest(p, A, B, C):
    """Closest points on triangles (A, B, C) (m, 3) to one point p: (m, 3).

    Ericson, Real-Time Collision Detection, 5.1.5, vectorised over triangles."""
    ab, ac, ap = B - A, C - A, p - A
    d1, d2 = np.einsum("ij,ij->i", ab, ap), np.einsum("ij,ij->i", ac, ap)
    bp = p - B
    d3, d4 = np.einsum("ij,ij->i", ab, bp), np.einsum("ij,ij->i", ac, bp)
    cp = p - C
    d5, d6 = np.einsum("ij,ij->i", ab, cp), np.einsum("ij,ij->i", ac, cp)
    vc = d1 * d4 - d3 * d2
    vb = d5 * d2 - d1 * d6
    va = d3 * d6 - d5 * d4
    denom = va + vb + vc
    with np.errstate(divide="ignore", invalid="ignore"):
        v = vb / denom
        w = vc / denom
        out = A + ab * v[:, None] + ac * w[:, None]
        # Edge regions.
        t_ab = d1 / (d1 - d3)
        e_ab = (vc <= 0) & (d1 >= 0) & (d3 <= 0)
        out = np.where(e_ab[:, None], A + t_ab[:, None] * ab, out)
        t_ac = d2 / (d2 - d6)
        e_ac = (vb <= 0) & (d2 >= 0) & (d6 <= 0)
        out = np.where(e_ac[:, None], A + t_ac[:, None] * ac, out)
        t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        e_bc = (va <= 0) & ((d4 - d3) >= 0) & ((d5 - d6) >= 0)
        out = np.where(e_bc[:, None], B + t_bc[:, None] * (C - B), out)
    # Vertex regions last (they take precedence).
    out = np.where(((d6 >= 0) & (d5 <= d6))[:, None], C, out)
    out = np.where(((d3 >= 0) & (d4 <= d3))[:, None], B, out)
    out = np.where(((d1 <= 0) & (d2 <= 0))[:, None], A, out)
    return out


def triangle_distances(P, V, F):
    """(n, m) exact distances from queries P to triangles F of V."""
    A, B, C = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    return np.stack([np.linalg.norm(p - triangle_closest(p, A, B, C), axis=-1) for p in P])


def edge_weights(t, val_a, val_b, max_adj, q):
    """SPEC 4 edge weights: the quartic W(t) with W(0) = 1/val_a, W(1) = 1/val_b,
    W(1/2) = 1, W'(0) = W'(1) = 0, clamped to [1/max_adj, 1], then (max_adj W)^q."""
    a, b = 1.0 / val_a, 1.0 / val_b
    # Solve for c1..c4 in W = a + c1 t + c2 t^2 + c3 t^3 + c4 t^4 (c1 = 0 from W'(0) = 0).
    M = np.array([[1.0, 1.0, 1.0], [0.25, 0.125, 0.0625], [2.0, 3.0, 4.0]])
    coef = np.stack(
        [np.linalg.solve(M, [bb - aa, 1.0 - aa, 0.0]) for aa, bb in zip(np.ravel(a), np.ravel(b))]
    )
    W = a + t**2 * coef[:, 0] + t**3 * coef[:, 1] + t**4 * coef[:, 2]
    W = np.clip(W, 1.0 / max_adj, 1.0)
    return (max_adj * W) ** q


def lse(D, alpha, W=None):
    """The smooth distance -(1/alpha) ln sum_i w_i exp(-alpha d_i), row by row, shifted by
    the row minimum so nothing underflows."""
    W = np.ones_like(D) if W is None else W
    m = D.min(axis=1)
    return m - np.log((W * np.exp(-alpha * (D - m[:, None]))).sum(axis=1)) / alpha
