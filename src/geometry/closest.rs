//! Closest points on segments, triangles and boxes (SPEC 3).
//!
//! All functions work in f64, use only relative tolerances (so results scale exactly
//! with the input, SPEC 3), and never divide by zero: a zero-length segment is a point,
//! a zero-area triangle falls back to the closest of its edges. Each returns the
//! barycentric coordinates of the closest point and the feature it lies on, which the
//! weight functions (SPEC 4) and their gradients need.

use glam::DVec3;

/// Below this squared sine of a triangle's *largest* angle, `|e1 x e2|^2 / (|e1|^2
/// |e2|^2)` with `e1`, `e2` the two edges that meet there (the two shortest), the
/// triangle is treated as degenerate. The largest angle is what makes the test
/// scale-free *and* shape-fair: a long thin triangle (one vertex 1e9 away, two close
/// together) has a tiny angle at its far vertex but a large one at the near vertices, so
/// it is not degenerate, while a collinear or zero-area triangle has a largest angle of
/// (nearly) 0 or 180 degrees. Below the threshold the triangle's width is under 1e-7 of
/// its two shorter edges, so its edges give the distance to that relative accuracy.
/// f64 rounding of the cross product of f32 inputs is about 1e-16 relative.
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

impl TriFeature {
    /// The vertex (0, 1, 2 for `a`, `b`, `c`) the feature is, if it is one: the closest
    /// point's barycentrics `(s, t)` are then exactly `(0, 0)`, `(1, 0)` or `(0, 1)`.
    #[inline]
    pub fn corner(self) -> Option<usize> {
        match self {
            TriFeature::VertexA => Some(0),
            TriFeature::VertexB => Some(1),
            TriFeature::VertexC => Some(2),
            _ => None,
        }
    }
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
/// Collision Detection, 5.1.5), with no absolute epsilon anywhere.
///
/// The regions are computed from the vertex with the largest angle (opposite the longest
/// edge): from there both spanning edges are the short ones, so a long thin triangle
/// with a far vertex loses no precision to products of huge dot products, and the
/// degeneracy test is the squared sine of that angle (see `DEGENERATE_SIN2`). The result
/// is expressed in the caller's order: `point = a + s (b - a) + t (c - a)`, with the
/// feature named for `a`, `b`, `c`. A degenerate triangle (zero area, coincident or
/// collinear vertices, NaN input) returns the closest point of its three edges, tagged
/// `Degenerate`.
#[inline]
pub fn closest_on_triangle(x: DVec3, a: DVec3, b: DVec3, c: DVec3) -> TriangleClosest {
    closest_on_triangle_ordered(x, a, b, c, triangle_order(a, b, c))
}

/// What [`closest_on_triangle`] decides about a triangle before it looks at the query:
/// the vertex with the largest angle (0, 1, 2 for `a`, `b`, `c`), or [`DEGENERATE`].
/// Computed once per triangle (`primitives::Triangle`), it spares every query three
/// edge lengths and the degeneracy test; the results are the same to the last bit.
#[inline]
pub fn triangle_order(a: DVec3, b: DVec3, c: DVec3) -> u8 {
    let order = largest_angle(a, b, c);
    let (o, p, q) = rotated(a, b, c, order);
    if is_degenerate(p - o, q - o) {
        DEGENERATE
    } else {
        order
    }
}

/// [`triangle_order`] of a triangle whose closest points take the edges' fallback.
pub const DEGENERATE: u8 = 3;

/// [`closest_on_triangle`] for a triangle whose [`triangle_order`] is `order`.
#[inline]
pub fn closest_on_triangle_ordered(
    x: DVec3,
    a: DVec3,
    b: DVec3,
    c: DVec3,
    order: u8,
) -> TriangleClosest {
    let solved = match order {
        // The largest angle is at `a`: no rotation.
        0 => closest_from_largest_angle::<0>(x, a, b, c),
        // Largest angle at `b`: solve for (b, c, a), results named back.
        1 => closest_from_largest_angle::<1>(x, b, c, a),
        // Largest angle at `c`: solve for (c, a, b), results named back.
        2 => closest_from_largest_angle::<2>(x, c, a, b),
        _ => None,
    };
    solved.unwrap_or_else(|| closest_on_degenerate_triangle(x, a, b, c))
}

/// A result of the solve rotated by `R` (0: none; 1: solved for `(b, c, a)`; 2: for `(c,
/// a, b)`), its barycentrics and feature in the solve's own names, expressed in the
/// caller's. Inlined at each of the solve's returns, where the feature is a constant,
/// so that the renaming costs nothing there.
#[inline(always)]
fn named<const R: u8>(point: DVec3, s: f64, t: f64, feature: TriFeature) -> TriangleClosest {
    let r = tri(point, s, t, feature);
    match R {
        0 => r,
        1 => {
            let [ub, uc, _] = weights_of(&r);
            let feature = rotate_feature(r.feature, [F::VertexB, F::VertexC, F::VertexA]);
            tri(r.point, ub, uc, feature)
        }
        _ => {
            let [uc, _, ub] = weights_of(&r);
            let feature = rotate_feature(r.feature, [F::VertexC, F::VertexA, F::VertexB]);
            tri(r.point, ub, uc, feature)
        }
    }
}

/// The vertex with the largest angle: the one opposite the longest edge (0, 1, 2).
#[inline]
fn largest_angle(a: DVec3, b: DVec3, c: DVec3) -> u8 {
    let l_bc = (c - b).length_squared();
    let l_ac = (c - a).length_squared();
    let l_ab = (b - a).length_squared();
    if l_bc >= l_ac && l_bc >= l_ab {
        0
    } else if l_ac >= l_ab {
        1
    } else {
        2
    }
}

/// The vertices from the one with the largest angle on, in the triangle's order.
#[inline]
fn rotated(a: DVec3, b: DVec3, c: DVec3, order: u8) -> (DVec3, DVec3, DVec3) {
    match order {
        0 => (a, b, c),
        1 => (b, c, a),
        _ => (c, a, b),
    }
}

/// The degeneracy test of the edges `e1`, `e2` that meet at the largest angle (see
/// `DEGENERATE_SIN2`; zero-length edges give 0 <= 0, NaN input is degenerate too).
#[inline]
fn is_degenerate(e1: DVec3, e2: DVec3) -> bool {
    let n2 = e1.cross(e2).length_squared();
    n2.is_nan() || n2 <= DEGENERATE_SIN2 * e1.length_squared() * e2.length_squared()
}

/// True when `closest_on_triangle` treats `(a, b, c)` as degenerate (the squared sine of
/// its largest angle is below 1e-14, or a coordinate is NaN).
pub fn triangle_is_degenerate(a: DVec3, b: DVec3, c: DVec3) -> bool {
    triangle_normal(a, b, c).is_none()
}

/// The (unnormalised) normal of a non-degenerate triangle, `(b - a) x (c - a)` computed
/// from its largest angle (same direction, better rounding); `None` when
/// `closest_on_triangle` treats the triangle as degenerate.
pub fn triangle_normal(a: DVec3, b: DVec3, c: DVec3) -> Option<DVec3> {
    let (o, p, q) = rotated(a, b, c, largest_angle(a, b, c));
    let (e1, e2) = (p - o, q - o);
    (!is_degenerate(e1, e2)).then(|| e1.cross(e2))
}

use TriFeature as F;

/// Barycentric weights `(u_a, u_b, u_c)` of a result in its own vertex order, with the
/// weights that are zero on its feature set exactly (not `1 - s - t` rounded).
#[inline(always)]
fn weights_of(r: &TriangleClosest) -> [f64; 3] {
    let ua = match r.feature {
        F::VertexB | F::VertexC | F::EdgeBC => 0.0,
        F::VertexA => 1.0,
        _ => 1.0 - r.s - r.t,
    };
    [ua, r.s, r.t]
}

/// The feature of a rotated solve in the caller's names; `v` names the rotated solve's
/// vertices A, B, C.
#[inline(always)]
fn rotate_feature(f: TriFeature, v: [TriFeature; 3]) -> TriFeature {
    let edge = |p: TriFeature, q: TriFeature| match (p, q) {
        (F::VertexA, F::VertexB) | (F::VertexB, F::VertexA) => F::EdgeAB,
        (F::VertexA, F::VertexC) | (F::VertexC, F::VertexA) => F::EdgeAC,
        _ => F::EdgeBC,
    };
    match f {
        F::VertexA => v[0],
        F::VertexB => v[1],
        F::VertexC => v[2],
        F::EdgeAB => edge(v[0], v[1]),
        F::EdgeAC => edge(v[0], v[2]),
        F::EdgeBC => edge(v[1], v[2]),
        other => other,
    }
}

/// Ericson's Voronoi-region solve with `a` at the triangle's largest angle, for a
/// triangle that [`triangle_order`] found not degenerate; `None` when the face solve is
/// not finite (which only rounding at the degeneracy threshold can cause).
#[inline(always)]
fn closest_from_largest_angle<const R: u8>(
    x: DVec3,
    a: DVec3,
    b: DVec3,
    c: DVec3,
) -> Option<TriangleClosest> {
    let ab = b - a;
    let ac = c - a;
    let ap = x - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return Some(named::<R>(a, 0.0, 0.0, F::VertexA));
    }
    let bp = x - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return Some(named::<R>(b, 1.0, 0.0, F::VertexB));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return Some(named::<R>(a + v * ab, v, 0.0, F::EdgeAB));
    }
    let cp = x - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return Some(named::<R>(c, 0.0, 1.0, F::VertexC));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return Some(named::<R>(a + w * ac, 0.0, w, F::EdgeAC));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return Some(named::<R>(b + w * (c - b), 1.0 - w, w, F::EdgeBC));
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    if !(v.is_finite() && w.is_finite()) {
        return None;
    }
    Some(named::<R>(a + ab * v + ac * w, v, w, F::Face))
}

#[inline(always)]
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

    /// A fixed-seed LCG, uniform in [-1, 1].
    fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        }
    }

    /// The rotated solves name their results back at each return (`named`): the same
    /// as solving unrotated on the rotated vertices and renaming the result afterwards,
    /// to the last bit, at every feature (queries near vertices, edges and the face).
    #[test]
    fn rotated_solves_rename_as_renaming_afterwards() {
        let mut r = uniform(99);
        let rename = |res: TriangleClosest, order: u8| match order {
            1 => {
                let [ub, uc, _] = weights_of(&res);
                let f = rotate_feature(res.feature, [F::VertexB, F::VertexC, F::VertexA]);
                tri(res.point, ub, uc, f)
            }
            _ => {
                let [uc, _, ub] = weights_of(&res);
                let f = rotate_feature(res.feature, [F::VertexC, F::VertexA, F::VertexB]);
                tri(res.point, ub, uc, f)
            }
        };
        let mut features = Vec::new();
        for _ in 0..20_000 {
            let p: [f64; 15] = std::array::from_fn(|_| r());
            let v = |i: usize| DVec3::new(p[i], p[i + 1], p[i + 2]);
            let (a, b, c) = (v(0), v(3), v(6));
            let x = if p[9] < 0.0 {
                // Near the triangle: inside its prism at times.
                a + (b - a) * (0.5 + 0.7 * p[10]) + (c - a) * (0.5 + 0.7 * p[11]) + v(12) * 0.1
            } else {
                v(12) * 3.0
            };
            let bits = |t: &TriangleClosest| {
                (
                    [t.point.x, t.point.y, t.point.z, t.s, t.t].map(f64::to_bits),
                    t.feature,
                )
            };
            let got1 = closest_from_largest_angle::<1>(x, b, c, a);
            let want1 = closest_from_largest_angle::<0>(x, b, c, a).map(|t| rename(t, 1));
            assert_eq!(got1.map(|t| bits(&t)), want1.map(|t| bits(&t)));
            let got2 = closest_from_largest_angle::<2>(x, c, a, b);
            let want2 = closest_from_largest_angle::<0>(x, c, a, b).map(|t| rename(t, 2));
            assert_eq!(got2.map(|t| bits(&t)), want2.map(|t| bits(&t)));
            if let Some(t) = got1.filter(|t| !features.contains(&t.feature)) {
                features.push(t.feature);
            }
        }
        assert_eq!(features.len(), 7, "features met: {features:?}");
    }

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
        let mut rnd = uniform(12345);
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

    /// Issue 10, defect 1: a triangle with one vertex ~2e9 or 5e11 away and two near
    /// the query was judged degenerate (by the angle at its first vertex) and measured
    /// by its edges: 0.14 instead of 0.10. The triangles lie in a coordinate plane, so
    /// the exact distance is known independently: the offset from the plane when the
    /// query projects inside (with a margin of ~0.05), the distance to the short edge's
    /// midpoint when it lies behind that edge. Every vertex order and every plane.
    #[test]
    fn long_skinny_triangle_regression() {
        for far in [2e9f32, 5e11] {
            // Stored in f32, as meshes are.
            let near0 = glam::Vec3::new(0.0, 0.0, 0.0);
            let near1 = glam::Vec3::new(0.0, 0.2, 0.0);
            let distant = glam::Vec3::new(far, 0.1, 0.0);
            // (query, exact distance, whether the closest point is inside the face)
            let cases = [
                (DVec3::new(0.05, 0.1, 0.1), 0.1, true),
                (DVec3::new(0.05, 0.1, -0.37), 0.37, true),
                (DVec3::new(-0.3, 0.1, 0.4), 0.5, false),
            ];
            let orders = [
                [0, 1, 2],
                [0, 2, 1],
                [1, 0, 2],
                [1, 2, 0],
                [2, 0, 1],
                [2, 1, 0],
            ];
            for axes in [[0, 1, 2], [1, 2, 0], [2, 0, 1]] {
                let permute = |v: DVec3| {
                    let a = v.to_array();
                    DVec3::new(a[axes[0]], a[axes[1]], a[axes[2]])
                };
                let verts = [near0, near1, distant].map(|v| permute(v.as_dvec3()));
                for (q, want, on_face) in cases {
                    let q = permute(q);
                    for o in orders {
                        let (a, b, c) = (verts[o[0]], verts[o[1]], verts[o[2]]);
                        let r = closest_on_triangle(q, a, b, c);
                        let d = (q - r.point).length();
                        assert!(
                            (d - want).abs() <= 1e-12 * want,
                            "far {far}, axes {axes:?}, order {o:?}: distance {d}, exact {want}, diff {}",
                            d - want
                        );
                        assert_eq!(r.feature == TriFeature::Face, on_face, "order {o:?}");
                        // The barycentrics reproduce the point to the triangle's scale.
                        let p = a + r.s * (b - a) + r.t * (c - a);
                        assert!((p - r.point).length() <= 1e-15 * far as f64 + 1e-12);
                        assert!(!triangle_is_degenerate(a, b, c));
                    }
                }
            }
        }
    }

    /// The rotation to the largest angle must not change the answer: every vertex order
    /// of a triangle gives the same point, and features and barycentrics that name the
    /// same vertex, edge or point.
    #[test]
    fn vertex_order_does_not_change_the_result() {
        let mut rnd = uniform(777);
        for _ in 0..500 {
            let v = [(); 3].map(|_| DVec3::new(rnd(), rnd(), rnd()));
            let x = DVec3::new(rnd(), rnd(), rnd()) * 1.5;
            let base = closest_on_triangle(x, v[0], v[1], v[2]);
            let weights = |r: &TriangleClosest| [1.0 - r.s - r.t, r.s, r.t];
            let wb = weights(&base);
            for o in [[1, 2, 0], [2, 0, 1], [0, 2, 1], [2, 1, 0], [1, 0, 2]] {
                let r = closest_on_triangle(x, v[o[0]], v[o[1]], v[o[2]]);
                assert!((r.point - base.point).length() < 1e-12);
                let w = weights(&r);
                for k in 0..3 {
                    assert!(
                        (w[k] - wb[o[k]]).abs() < 1e-9,
                        "order {o:?}: {w:?} vs {wb:?}"
                    );
                }
                assert_eq!(
                    r.feature == TriFeature::Face,
                    base.feature == TriFeature::Face
                );
            }
        }
    }

    #[test]
    fn rotated_features_name_the_caller_vertices() {
        // Longest edge a-b, so the largest angle is at c and the solve is rotated.
        let (a, b, c) = (
            DVec3::ZERO,
            DVec3::new(4.0, 0.0, 0.0),
            DVec3::new(2.0, 1.0, 0.0),
        );
        let at = |x: DVec3| closest_on_triangle(x, a, b, c);
        assert_eq!(at(DVec3::new(-1.0, -1.0, 0.0)).feature, TriFeature::VertexA);
        assert_eq!(at(DVec3::new(5.0, -1.0, 0.0)).feature, TriFeature::VertexB);
        assert_eq!(at(DVec3::new(2.0, 3.0, 0.0)).feature, TriFeature::VertexC);
        let r = at(DVec3::new(1.0, -2.0, 0.0));
        assert_eq!((r.feature, r.s, r.t), (TriFeature::EdgeAB, 0.25, 0.0));
        let r = at(DVec3::new(0.0, 2.0, 0.0));
        assert_eq!(r.feature, TriFeature::EdgeAC);
        assert_eq!(r.s, 0.0);
        let r = at(DVec3::new(4.0, 2.0, 0.0));
        assert_eq!(r.feature, TriFeature::EdgeBC);
        assert!((r.s + r.t - 1.0).abs() < 1e-15);
    }

    #[test]
    fn zero_length_segment_is_a_point() {
        let r = closest_on_segment(DVec3::ONE, DVec3::ZERO, DVec3::ZERO);
        assert_eq!(r.point, DVec3::ZERO);
        assert!(!r.interior);
    }
}
