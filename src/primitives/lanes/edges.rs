//! The edge kernels of `primitives::lanes` (AVX): `Edge::term` and `value` of four
//! edges at once (`Edge`'s `value_slope` is its term's).

use super::avx::{F, V, apply};
use super::{EdgeLanes, Lanes, TermLanes};
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
fn closest(e: &EdgeLanes, x: DVec3) -> Closest {
    let (zero, one) = (F::splat(0.0), F::splat(1.0));
    let (a, b) = (V::load(&e.a), V::load(&e.b));
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
    let c = weights::edge_quartic(one / F::load(&e.val_a), one / F::load(&e.val_b));
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
pub(super) fn terms(e: &EdgeLanes, x: DVec3, scale: &WeightScale) -> TermLanes {
    let cl = closest(e, x);
    let (w, dw) = apply(scale, cl.raw);
    let zero = F::splat(0.0);
    let zv = V::splat(DVec3::ZERO);
    let grad = (dw * cl.draw / cl.ab.dot(cl.ab)) * cl.ab;
    TermLanes {
        d: cl.d.store(),
        dir: cl.d.gt(zero).sel3(cl.v / cl.d, zv).store(),
        w: w.store(),
        grad_w: cl.interior.and(dw.ne(zero)).sel3(grad, zv).store(),
    }
}

/// `Edge::value`, lane by lane: `(d, w)`.
#[target_feature(enable = "avx")]
pub(super) fn values(e: &EdgeLanes, x: DVec3, scale: &WeightScale) -> (Lanes, Lanes) {
    let cl = closest(e, x);
    (cl.d.store(), apply(scale, cl.raw).0.store())
}
