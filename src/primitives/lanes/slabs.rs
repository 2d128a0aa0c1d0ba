//! The slab kernel of `primitives::lanes` (AVX): which edges of a range `x` projects
//! inside (`Slabs::scan`), four at a time.

use super::Slabs;
use super::avx::F;
use glam::DVec3;

/// [`Slabs::scan`] on AVX: each four edges' projections at once, the edges inside
/// handed on in order.
///
/// # Safety
/// AVX must be available.
#[target_feature(enable = "avx")]
pub(super) unsafe fn scan(
    s: &Slabs,
    range: std::ops::Range<usize>,
    x: DVec3,
    lim: f64,
    mut inside: impl FnMut(usize) -> bool,
) -> bool {
    let (xs, lim4) = ([F::splat(x.x), F::splat(x.y), F::splat(x.z)], F::splat(lim));
    let lanes = |v: &[f64], k: usize| -> F {
        let four: &[f64; 4] = v[k..k + 4].try_into().expect("four lanes");
        F::load(four)
    };
    let mut k = range.start;
    while k + 4 <= range.end {
        let mut t = lanes(&s.n[0], k) * (xs[0] - lanes(&s.m[0], k));
        t = t + lanes(&s.n[1], k) * (xs[1] - lanes(&s.m[1], k));
        t = t + lanes(&s.n[2], k) * (xs[2] - lanes(&s.m[2], k));
        let mut mask = t.abs().lt(lim4).mask();
        while mask != 0 {
            let l = mask.trailing_zeros() as usize;
            if !inside(k + l) {
                return false;
            }
            mask &= mask - 1;
        }
        k += 4;
    }
    s.scan_scalar(k..range.end, x, lim, inside)
}
