//! f64 brute-force references: every term of every primitive, summed by the two-pass
//! shifted LogSumExp (minimum first), and the exact minimum distance. For tests and the
//! reports' ground truth; O(n) per query.

use crate::primitives::{AnySet, Primitive, PrimitiveSet, WeightScale};
use glam::DVec3;

/// `(s, grad s, d_min)` by brute force over all primitives of `sets`.
pub fn smooth_distance(
    sets: &[&AnySet],
    x: DVec3,
    alpha: f64,
    max_alpha: f64,
) -> (f64, DVec3, f64) {
    let mut terms = Vec::new();
    for set in sets {
        crate::with_set!(set, s => collect(s, x, alpha, max_alpha, &mut terms));
    }
    let m = terms.iter().map(|t| t.d).fold(f64::INFINITY, f64::min);
    let mut sum = 0.0;
    let mut g = DVec3::ZERO;
    for t in &terms {
        let e = (-alpha * (t.d - m)).exp();
        sum += t.w * e;
        g += e * (t.w * t.dir - t.grad_w / alpha);
    }
    (m - sum.ln() / alpha, g / sum, m)
}

fn collect<P: Primitive>(
    set: &PrimitiveSet<P>,
    x: DVec3,
    alpha: f64,
    max_alpha: f64,
    out: &mut Vec<crate::primitives::Term>,
) {
    let scale = WeightScale::new(set.max_adj, alpha, max_alpha);
    out.extend(set.prims.iter().map(|p| p.term(x, &scale)));
}

/// Exact distance to the nearest primitive by brute force.
pub fn min_distance(sets: &[&AnySet], x: DVec3) -> f64 {
    let mut best = f64::INFINITY;
    for set in sets {
        crate::with_set!(set, s => {
            for p in &s.prims {
                best = best.min((x - p.closest_point(x)).length());
            }
        });
    }
    best
}
