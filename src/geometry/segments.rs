//! The distance between two segments: the closest points of `p1 + s (q1 - p1)` and
//! `p2 + t (q2 - p2)` over `s, t` in `[0, 1]` (Ericson, *Real-Time Collision Detection*,
//! 5.1.9): the unconstrained minimum of the quadratic in `(s, t)`, then each parameter
//! clamped to `[0, 1]` and the other recomputed. The distance from a stretch of a ray to
//! an edge, what a segment evaluation would bound each term by (doc/performance-log.md,
//! round thirty-six; `examples/segment_oracle.rs`).

use glam::DVec3;

/// Segments shorter than this (squared) are taken as points.
const DEGENERATE2: f64 = 1e-30;

/// Segments whose angle's squared sine is below this are taken as parallel.
const PARALLEL: f64 = 1e-12;

/// The squared distance between segments `p1 q1` and `p2 q2`. It is the distance of a
/// pair of points of the two segments, so never below the minimum. It is within rounding
/// of the minimum, except for segments within 1e-6 radians of parallel, taken as
/// parallel: there it is within their length times that angle. A lower bound for a
/// certificate subtracts that.
pub fn segment_distance2(p1: DVec3, q1: DVec3, p2: DVec3, q2: DVec3) -> f64 {
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.dot(d1), d2.dot(d2), d2.dot(r));
    let (s, t) = if a <= DEGENERATE2 && e <= DEGENERATE2 {
        (0.0, 0.0)
    } else if a <= DEGENERATE2 {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(r);
        if e <= DEGENERATE2 {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            // Parallel segments (the denominator, `a e sin^2` of their angle, vanishes):
            // any `s`, here 0. Nearly parallel ones too: there the division amplifies the
            // cancellation in the denominator.
            let s = if denom > PARALLEL * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t = (b * s + f) / e;
            if t < 0.0 {
                ((-c / a).clamp(0.0, 1.0), 0.0)
            } else if t > 1.0 {
                (((b - c) / a).clamp(0.0, 1.0), 1.0)
            } else {
                (s, t)
            }
        }
    };
    ((p1 + d1 * s) - (p2 + d2 * t)).length_squared()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn random(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }

    /// The minimum over a fine grid of both parameters, refined around its best cell.
    fn sampled(p1: DVec3, q1: DVec3, p2: DVec3, q2: DVec3) -> f64 {
        let at = |s: f64, t: f64| ((p1 + (q1 - p1) * s) - (p2 + (q2 - p2) * t)).length_squared();
        let n = 200;
        let mut best = (f64::INFINITY, 0.0, 0.0);
        for i in 0..=n {
            for j in 0..=n {
                let (s, t) = (i as f64 / n as f64, j as f64 / n as f64);
                let d = at(s, t);
                if d < best.0 {
                    best = (d, s, t);
                }
            }
        }
        // A second grid as fine again over the best cell's neighbours.
        let (mut lo, s0, t0) = best;
        let h = 1.0 / n as f64;
        for i in 0..=n {
            for j in 0..=n {
                let s = (s0 + (i as f64 / n as f64 - 0.5) * 2.0 * h).clamp(0.0, 1.0);
                let t = (t0 + (j as f64 / n as f64 - 0.5) * 2.0 * h).clamp(0.0, 1.0);
                lo = lo.min(at(s, t));
            }
        }
        lo
    }

    #[test]
    fn matches_a_sampled_minimum_and_never_exceeds_it() {
        let mut seed = 7u64;
        let mut v = |scale: f64| {
            DVec3::new(random(&mut seed), random(&mut seed), random(&mut seed)) * scale
        };
        for k in 0..300 {
            let (p1, q1, p2) = (v(1.0), v(1.0), v(1.0));
            // Some nearly parallel and some degenerate second segments too.
            let q2 = match k % 3 {
                0 => v(1.0),
                1 => p2 + (q1 - p1) * 0.7 + v(1e-9),
                _ => p2,
            };
            let exact = segment_distance2(p1, q1, p2, q2);
            let sampled = sampled(p1, q1, p2, q2);
            // Not above any sampled pair (it is the minimum; the nearly parallel pairs,
            // 1e-9 radians apart, within their length times that), and within the
            // grid's resolution of the best one.
            let slack = if k % 3 == 1 { 1e-8 } else { 1e-12 };
            assert!(exact <= sampled + slack, "{k}: {exact} > {sampled}");
            assert!(
                (exact.sqrt() - sampled.sqrt()).abs() < 1e-4,
                "{k}: {} against {}",
                exact.sqrt(),
                sampled.sqrt()
            );
        }
    }

    #[test]
    fn known_cases() {
        let x = DVec3::X;
        let (y, z) = (DVec3::Y, DVec3::Z);
        // Crossing at right angles, one unit apart.
        assert!((segment_distance2(-x, x, z - y, z + y) - 1.0).abs() < 1e-15);
        // Parallel, overlapping, two apart.
        assert!((segment_distance2(-x, x, 2.0 * y, 2.0 * y + 3.0 * x) - 4.0).abs() < 1e-15);
        // End to end along a line.
        assert!((segment_distance2(-x, x, 3.0 * x, 5.0 * x) - 4.0).abs() < 1e-15);
        // A point and a segment.
        assert!((segment_distance2(y, y, -x, x) - 1.0).abs() < 1e-15);
        // Touching.
        assert_eq!(segment_distance2(-x, x, DVec3::ZERO, z), 0.0);
    }
}
