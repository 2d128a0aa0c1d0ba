//! Closest points on segments, triangles and boxes (SPEC 3).
//!
//! All functions work in f64, use only relative tolerances (so results scale exactly
//! with the input, SPEC 3), and never divide by zero: a zero-length segment is a point,
//! a zero-area triangle falls back to the closest of its edges. Each returns the
//! barycentric coordinates of the closest point and the feature it lies on, which the
//! weight functions (SPEC 4) and their gradients need.

use glam::DVec3;

/// Below this `|ab x ac|^2 / (|ab|^2 |ac|^2)` (the squared sine of the angle at `a`) a
/// triangle is treated as degenerate. f64 rounding of the cross product of f32 inputs
/// is about 1e-16 relative, far below this.
const DEGENERATE_SIN2: f64 = 1e-14;

/// Closest point on segment `[a, b]` to `x`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentClosest {
    pub point: DVec3,
    /// Parameter along the segment: `point = a + t (b - a)`, in [0, 1].
    pub t: f64,
    /// True when `t` is strictly inside (0, 1), i.e. the point moves with `x`.
    pub interior: bool,
}

/// Closest point on the segment `[a, b]`. A zero-length segment returns `a` with `t = 0`.
/// Source: Ericson, Real-Time Collision Detection, 5.1.2.
#[inline]
pub fn closest_on_segment(x: DVec3, a: DVec3, b: DVec3) -> SegmentClosest {
    let ab = b - a;
    let len2 = ab.length_squared();
    if len2 <= 0.0 {
        return SegmentClosest {
            point: a,
            t: 0.0,
            interior: false,
        };
    }
    let t = (x - a).dot(ab) / len2;
    if t <= 0.0 {
        SegmentClosest {
            point: a,
            t: 0.0,
            interior: false,
        }
    } else if t >= 1.0 {
        SegmentClosest {
            point: b,
            t: 1.0,
            interior: false,
        }
    } else {
        SegmentClosest {
            point: a + t * ab,
            t,
            interior: true,
        }
    }
}

/// The feature of a triangle `(a, b, c)` a closest point lies on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TriFeature {
    VertexA,
    VertexB,
    VertexC,
    /// Edge a-b (barycentric `t = 0`).
    EdgeAB,
    /// Edge a-c (barycentric `s = 0`).
    EdgeAC,
    /// Edge b-c (`s + t = 1`).
    EdgeBC,
    Face,
    /// The triangle has (near) zero area; the point is on its closest edge.
    Degenerate,
}

/// Closest point on a triangle with barycentrics `point = a + s (b - a) + t (c - a)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleClosest {
    pub point: DVec3,
    pub s: f64,
    pub t: f64,
    pub feature: TriFeature,
}

/// Closest point on triangle `(a, b, c)` to `x`, by Voronoi regions (Ericson, Real-Time
/// Collision Detection, 5.1.5), with no absolute epsilon anywhere. A triangle whose
/// angle at `a` has a squared sine below 1e-14 (zero area, coincident or collinear
/// vertices) returns the closest point of its three edges, tagged `Degenerate`.
#[inline]
pub fn closest_on_triangle(x: DVec3, a: DVec3, b: DVec3, c: DVec3) -> TriangleClosest {
    let ab = b - a;
    let ac = c - a;
    let n2 = ab.cross(ac).length_squared();
    // Zero-length edges give 0 <= 0; NaN input is degenerate too.
    if n2.is_nan() || n2 <= DEGENERATE_SIN2 * ab.length_squared() * ac.length_squared() {
        return closest_on_degenerate_triangle(x, a, b, c);
    }
    let ap = x - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return tri(a, 0.0, 0.0, TriFeature::VertexA);
    }
    let bp = x - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return tri(b, 1.0, 0.0, TriFeature::VertexB);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return tri(a + v * ab, v, 0.0, TriFeature::EdgeAB);
    }
    let cp = x - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return tri(c, 0.0, 1.0, TriFeature::VertexC);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return tri(a + w * ac, 0.0, w, TriFeature::EdgeAC);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return tri(b + w * (c - b), 1.0 - w, w, TriFeature::EdgeBC);
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    tri(a + ab * v + ac * w, v, w, TriFeature::Face)
}

#[inline]
fn tri(point: DVec3, s: f64, t: f64, feature: TriFeature) -> TriangleClosest {
    TriangleClosest {
        point,
        s,
        t,
        feature,
    }
}

/// Zero-area triangle: the closest of its three edges (each possibly a point).
#[cold]
fn closest_on_degenerate_triangle(x: DVec3, a: DVec3, b: DVec3, c: DVec3) -> TriangleClosest {
    let e_ab = closest_on_segment(x, a, b);
    let e_ac = closest_on_segment(x, a, c);
    let e_bc = closest_on_segment(x, b, c);
    let d_ab = (x - e_ab.point).length_squared();
    let d_ac = (x - e_ac.point).length_squared();
    let d_bc = (x - e_bc.point).length_squared();
    let (point, s, t) = if d_ab <= d_ac && d_ab <= d_bc {
        (e_ab.point, e_ab.t, 0.0)
    } else if d_ac <= d_bc {
        (e_ac.point, 0.0, e_ac.t)
    } else {
        (e_bc.point, 1.0 - e_bc.t, e_bc.t)
    };
    tri(point, s, t, TriFeature::Degenerate)
}

/// Distance from `x` to the axis-aligned box `[min, max]` (0 inside), and the closest
/// box point.
#[inline]
pub fn closest_on_box(x: DVec3, min: DVec3, max: DVec3) -> (f64, DVec3) {
    let c = x.clamp(min, max);
    ((x - c).length(), c)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute_triangle(x: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
        // Dense barycentric sampling plus exact edges: an upper bound close to the truth.
        let n = 200;
        let mut best = f64::INFINITY;
        for i in 0..=n {
            for j in 0..=(n - i) {
                let s = i as f64 / n as f64;
                let t = j as f64 / n as f64;
                let p = a + s * (b - a) + t * (c - a);
                best = best.min((x - p).length());
            }
        }
        for (p, q) in [(a, b), (b, c), (c, a)] {
            best = best.min((x - closest_on_segment(x, p, q).point).length());
        }
        best
    }

    #[test]
    fn triangle_matches_dense_sampling() {
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        for _ in 0..300 {
            let a = DVec3::new(rnd(), rnd(), rnd());
            let b = DVec3::new(rnd(), rnd(), rnd());
            let c = DVec3::new(rnd(), rnd(), rnd());
            let x = DVec3::new(rnd(), rnd(), rnd()) * 1.5;
            let r = closest_on_triangle(x, a, b, c);
            let d = (x - r.point).length();
            let brute = brute_triangle(x, a, b, c);
            // The sampled distance is an upper bound within the sampling resolution.
            assert!(d <= brute + 1e-12, "closest {d} above sampled {brute}");
            assert!(brute - d < 2e-2, "closest {d} far below sampled {brute}");
            // Barycentrics reproduce the point.
            let p = a + r.s * (b - a) + r.t * (c - a);
            assert!((p - r.point).length() < 1e-12);
            assert!(r.s >= 0.0 && r.t >= 0.0 && r.s + r.t <= 1.0 + 1e-12);
        }
    }

    #[test]
    fn face_region_is_orthogonal_projection() {
        let a = DVec3::ZERO;
        let b = DVec3::X;
        let c = DVec3::Y;
        let r = closest_on_triangle(DVec3::new(0.25, 0.25, 3.0), a, b, c);
        assert_eq!(r.feature, TriFeature::Face);
        assert!((r.point - DVec3::new(0.25, 0.25, 0.0)).length() < 1e-15);
        assert!((r.s - 0.25).abs() < 1e-15 && (r.t - 0.25).abs() < 1e-15);
    }

    #[test]
    fn degenerate_triangles_fall_back_to_edges() {
        let x = DVec3::new(0.5, 1.0, 0.0);
        // Collinear.
        let r = closest_on_triangle(x, DVec3::ZERO, DVec3::X, DVec3::X * 2.0);
        assert_eq!(r.feature, TriFeature::Degenerate);
        assert!((r.point - DVec3::new(0.5, 0.0, 0.0)).length() < 1e-15);
        // All three vertices coincide.
        let r = closest_on_triangle(x, DVec3::ONE, DVec3::ONE, DVec3::ONE);
        assert_eq!(r.point, DVec3::ONE);
        assert!(r.s.is_finite() && r.t.is_finite());
    }

    #[test]
    fn scale_invariant_at_extreme_scales() {
        let a = DVec3::new(0.1, 0.2, 0.3);
        let b = DVec3::new(1.1, -0.2, 0.5);
        let c = DVec3::new(0.4, 0.9, -0.3);
        let x = DVec3::new(0.3, 0.3, 0.8);
        let r1 = closest_on_triangle(x, a, b, c);
        for k in [1e-4, 1e-2, 1e2, 1e4] {
            let rk = closest_on_triangle(x * k, a * k, b * k, c * k);
            assert_eq!(rk.feature, r1.feature);
            assert!((rk.point / k - r1.point).length() < 1e-12);
        }
    }

    #[test]
    fn zero_length_segment_is_a_point() {
        let r = closest_on_segment(DVec3::ONE, DVec3::ZERO, DVec3::ZERO);
        assert_eq!(r.point, DVec3::ZERO);
        assert!(!r.interior);
    }
}
