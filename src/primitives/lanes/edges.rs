//! The edge kernels of `primitives::lanes` (AVX): `Edge::term` and `value` of four
//! edges at once (`value_slope` is the term's, `Primitive`'s default).

use super::avx::{F, V, apply};
use crate::primitives::kinds::{Edge, Term};
use crate::primitives::weights::{self, WeightScale};
use glam::DVec3;

/// Four edges' closest points to `x` (`geometry::closest::closest_on_segment`, each
/// case computed and the first that holds kept) and their quartic weights' raw value
/// and derivative in `t` (`weights::edge_quartic`, `weights::edge_w`).
struct Closest {
    ab: V,
    v: V,
    d: F,
    /// The closest point is inside the segment (all bits set), not an end.
    interior: F,
    raw: F,
    draw: F,
}

#[inline(always)]
fn closest(edges: &[Edge], x: DVec3) -> Closest {
    let n = edges.len();
    let mut ends = [[[0.0; 4]; 3]; 2];
    let mut val = [[0.0; 4]; 2];
    for l in 0..4 {
        let e = &edges[l.min(n - 1)];
        for (k, (&pa, &pb)) in e.a.as_ref().iter().zip(e.b.as_ref()).enumerate() {
            ends[0][k][l] = pa as f64;
            ends[1][k][l] = pb as f64;
        }
        val[0][l] = e.val_a as f64;
        val[1][l] = e.val_b as f64;
    }
    let (zero, one) = (F::splat(0.0), F::splat(1.0));
    let (a, b) = (V::load(&ends[0]), V::load(&ends[1]));
    let xv = V::splat(x);
    let ab = b - a;
    let len2 = ab.dot(ab);
    let tr = (xv - a).dot(ab) / len2;
    // In the scalar order: an empty segment, then t <= 0, then t >= 1, else inside.
    let at_a = len2.le(zero).or(tr.le(zero));
    let at_b = at_a.not().and(tr.ge(one));
    let interior = at_a.or(at_b).not();
    let t = at_a.sel(zero, at_b.sel(one, tr));
    let p = at_a.sel3(a, at_b.sel3(b, a + t * ab));
    let c = weights::edge_quartic(one / F::load(&val[0]), one / F::load(&val[1]));
    let (raw, draw) = weights::edge_w(t, c);
    let v = xv - p;
    Closest {
        ab,
        d: v.dot(v).sqrt(),
        v,
        interior,
        raw,
        draw,
    }
}

/// `Edge::term`, lane by lane.
#[target_feature(enable = "avx")]
pub(super) fn terms(edges: &[Edge], x: DVec3, scale: &WeightScale, out: &mut [Term; 4]) {
    let cl = closest(edges, x);
    let (w, dw) = apply(scale, cl.raw);
    let zero = F::splat(0.0);
    let zv = V::splat(DVec3::ZERO);
    let grad = (dw * cl.draw / cl.ab.dot(cl.ab)) * cl.ab;
    let grad_w = cl.interior.and(dw.ne(zero)).sel3(grad, zv);
    let dir = cl.d.gt(zero).sel3(cl.v / cl.d, zv);
    let (d, w) = (cl.d.store(), w.store());
    for l in 0..edges.len() {
        out[l] = Term {
            d: d[l],
            dir: dir.lane(l),
            w: w[l],
            grad_w: grad_w.lane(l),
        };
    }
}

/// `Edge::value`, lane by lane.
#[target_feature(enable = "avx")]
pub(super) fn values(edges: &[Edge], x: DVec3, scale: &WeightScale, out: &mut [(f64, f64); 4]) {
    let cl = closest(edges, x);
    let (w, _) = apply(scale, cl.raw);
    let (d, w) = (cl.d.store(), w.store());
    for l in 0..edges.len() {
        out[l] = (d[l], w[l]);
    }
}
