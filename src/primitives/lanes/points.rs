//! The point kernels of `primitives::lanes` (AVX): `Point::term`, `value` and
//! `value_slope` of four points at once.

use super::avx::{F, V};
use super::{Lanes, Lanes3};
use glam::DVec3;

/// `x - p` and its length.
#[inline(always)]
fn offsets(p: &Lanes3, x: DVec3) -> (V, F) {
    let v = V::splat(x) - V::load(p);
    (v, v.dot(v).sqrt())
}

/// `Point::term`, lane by lane: the distances and directions.
#[target_feature(enable = "avx")]
pub(super) fn terms(p: &Lanes3, x: DVec3) -> (Lanes, Lanes3) {
    let (v, d) = offsets(p, x);
    let dir = d.gt(F::splat(0.0)).sel3(v / d, V::splat(DVec3::ZERO));
    (d.store(), dir.store())
}

/// `Point::value`, lane by lane: the distances.
#[target_feature(enable = "avx")]
pub(super) fn values(p: &Lanes3, x: DVec3) -> Lanes {
    offsets(p, x).1.store()
}

/// `Point::value_slope`, lane by lane: the distances and their slopes along `u`.
#[target_feature(enable = "avx")]
pub(super) fn value_slopes(p: &Lanes3, x: DVec3, u: DVec3) -> (Lanes, Lanes) {
    let (v, d) = offsets(p, x);
    let zero = F::splat(0.0);
    (
        d.store(),
        d.gt(zero).sel(v.dot(V::splat(u)) / d, zero).store(),
    )
}
