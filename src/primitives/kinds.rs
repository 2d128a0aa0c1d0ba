//! The three primitive types and their terms of the smooth sum (SPEC 2, 3, 4).
//!
//! A primitive stores its vertex positions inline (f32) plus the valence data its
//! weight needs, so the evaluator touches one contiguous array in BVH order. Distances,
//! closest points and weights are computed in f64.

use super::lanes::{self, EdgeLanes, Lanes3, TermLanes};
use super::weights::{self, WeightScale};
use crate::geometry::closest::{
    TriangleClosest, closest_on_segment, closest_on_triangle_ordered, triangle_order,
};
use crate::mesh::Aabb;
use glam::{DVec3, Vec3};

/// `(d, w, a, l)` of [`Primitive::value_slope`].
pub type Slope = (f64, f64, f64, f64);

/// One term of the smooth sum at a query point `x`.
#[derive(Clone, Copy, Debug, Default)]
pub struct Term {
    /// Exact distance `d = |x - c|` to the closest point `c`.
    pub d: f64,
    /// Unit vector `(x - c) / d`, zero when `x` lies on the primitive.
    pub dir: DVec3,
    /// Weight `w >= 1`.
    pub w: f64,
    /// Gradient of `w` with respect to `x`.
    pub grad_w: DVec3,
}

/// What the BVH and the evaluator need of a primitive.
pub trait Primitive: Copy + Send + Sync + 'static {
    /// A point (its centroid): its set keeps second moments for the far field
    /// (`bvh::moments`).
    const IS_POINT: bool = false;
    fn bounds(&self) -> Aabb;
    fn centroid(&self) -> Vec3;
    fn closest_point(&self, x: DVec3) -> DVec3;
    /// The full term, with the direction and the weight gradient.
    fn term(&self, x: DVec3, scale: &WeightScale) -> Term;
    /// The evaluator takes a leaf's terms from [`Primitive::terms`], [`Primitive::values`]
    /// and [`Primitive::value_slopes`] (four at a time) rather than one by one: true
    /// where they compute several side by side (edges, `primitives::lanes`).
    const BATCHED: bool = false;
    /// [`Primitive::term`] of 1 ..= 4 primitives (a leaf's) into `out[..prims.len()]`,
    /// with the same results.
    #[inline]
    fn terms(prims: &[Self], x: DVec3, scale: &WeightScale, out: &mut [Term; 4]) {
        scalar_terms(prims, x, scale, out)
    }
    /// [`Primitive::value`] of 1 ..= 4 primitives into `out[..prims.len()]`.
    #[inline]
    fn values(prims: &[Self], x: DVec3, scale: &WeightScale, out: &mut [(f64, f64); 4]) {
        scalar_values(prims, x, scale, out)
    }
    /// [`Primitive::value_slope`] of 1 ..= 4 primitives into `out[..prims.len()]`.
    #[inline]
    fn value_slopes(prims: &[Self], x: DVec3, u: DVec3, scale: &WeightScale, out: &mut [Slope; 4]) {
        for (o, p) in out.iter_mut().zip(prims) {
            *o = p.value_slope(x, u, scale);
        }
    }
    /// `(d, w)` only: what a value-only evaluation (sphere-tracing steps) needs.
    fn value(&self, x: DVec3, scale: &WeightScale) -> (f64, f64);
    /// `(d, w, a, l)` with `a = u . (x - c) / d` the slope of the distance along unit `u`
    /// (0 on the primitive) and `l = u . grad w / w` that of `ln w`: for the free
    /// distance of `eval::reach`.
    #[inline]
    fn value_slope(&self, x: DVec3, u: DVec3, scale: &WeightScale) -> (f64, f64, f64, f64) {
        let t = self.term(x, scale);
        (t.d, t.w, t.dir.dot(u), t.grad_w.dot(u) / t.w)
    }
}

/// [`Primitive::terms`] one by one.
#[inline]
fn scalar_terms<P: Primitive>(prims: &[P], x: DVec3, scale: &WeightScale, out: &mut [Term; 4]) {
    for (o, p) in out.iter_mut().zip(prims) {
        *o = p.term(x, scale);
    }
}

/// [`Primitive::values`] one by one.
#[inline]
fn scalar_values<P: Primitive>(
    prims: &[P],
    x: DVec3,
    scale: &WeightScale,
    out: &mut [(f64, f64); 4],
) {
    for (o, p) in out.iter_mut().zip(prims) {
        *o = p.value(x, scale);
    }
}

/// Lane `l` of four 3-vectors.
#[inline]
fn lane3(v: &Lanes3, l: usize) -> DVec3 {
    DVec3::new(v[0][l], v[1][l], v[2][l])
}

/// The first `n` of four terms computed in lanes.
#[inline]
fn fill_terms(t: &TermLanes, out: &mut [Term; 4], n: usize) {
    for (l, o) in out.iter_mut().enumerate().take(n) {
        *o = Term {
            d: t.d[l],
            dir: lane3(&t.dir, l),
            w: t.w[l],
            grad_w: lane3(&t.grad_w, l),
        };
    }
}

/// The slope `u . v / d` of a distance `d = |v|` along unit `u` (0 where `d = 0`).
#[inline]
fn slope(v: DVec3, d: f64, u: DVec3) -> f64 {
    if d > 0.0 { v.dot(u) / d } else { 0.0 }
}

#[inline]
fn unit_or_zero(v: DVec3, len: f64) -> DVec3 {
    if len > 0.0 { v / len } else { DVec3::ZERO }
}

/// A point primitive (weight 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    pub p: Vec3,
}

impl Primitive for Point {
    const IS_POINT: bool = true;
    fn bounds(&self) -> Aabb {
        Aabb {
            min: self.p,
            max: self.p,
        }
    }
    fn centroid(&self) -> Vec3 {
        self.p
    }
    fn closest_point(&self, _x: DVec3) -> DVec3 {
        self.p.as_dvec3()
    }
    #[inline]
    fn value(&self, x: DVec3, _scale: &WeightScale) -> (f64, f64) {
        ((x - self.p.as_dvec3()).length(), 1.0)
    }
    #[inline]
    fn value_slope(&self, x: DVec3, u: DVec3, _scale: &WeightScale) -> (f64, f64, f64, f64) {
        let v = x - self.p.as_dvec3();
        let d = v.length();
        (d, 1.0, slope(v, d, u), 0.0)
    }
    #[inline]
    fn term(&self, x: DVec3, _scale: &WeightScale) -> Term {
        let v = x - self.p.as_dvec3();
        let d = v.length();
        Term {
            d,
            dir: unit_or_zero(v, d),
            w: 1.0,
            grad_w: DVec3::ZERO,
        }
    }
}

/// A segment with the valences of its end vertices (edge quartic weight, SPEC 4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Edge {
    pub a: Vec3,
    pub b: Vec3,
    /// Number of edges incident on `a` and on `b` (>= 1).
    pub val_a: f32,
    pub val_b: f32,
}

impl Edge {
    /// Up to four edges in lanes (unused lanes repeat the last).
    #[inline]
    fn lanes(prims: &[Edge]) -> EdgeLanes {
        let mut e = EdgeLanes::default();
        for l in 0..4 {
            let p = &prims[l.min(prims.len() - 1)];
            for (k, (&a, &b)) in p.a.as_ref().iter().zip(p.b.as_ref()).enumerate() {
                e.a[k][l] = a as f64;
                e.b[k][l] = b as f64;
            }
            e.val_a[l] = p.val_a as f64;
            e.val_b[l] = p.val_b as f64;
        }
        e
    }
}

impl Primitive for Edge {
    const BATCHED: bool = true;
    #[inline]
    fn terms(prims: &[Self], x: DVec3, scale: &WeightScale, out: &mut [Term; 4]) {
        match lanes::edge_terms(&Edge::lanes(prims), x, scale) {
            Some(t) => fill_terms(&t, out, prims.len()),
            None => scalar_terms(prims, x, scale, out),
        }
    }
    #[inline]
    fn values(prims: &[Self], x: DVec3, scale: &WeightScale, out: &mut [(f64, f64); 4]) {
        match lanes::edge_values(&Edge::lanes(prims), x, scale) {
            Some((d, w)) => {
                for (l, o) in out.iter_mut().enumerate().take(prims.len()) {
                    *o = (d[l], w[l]);
                }
            }
            None => scalar_values(prims, x, scale, out),
        }
    }
    /// From the terms, as [`Primitive::value_slope`]'s default does.
    #[inline]
    fn value_slopes(prims: &[Self], x: DVec3, u: DVec3, scale: &WeightScale, out: &mut [Slope; 4]) {
        let mut terms = [Term::default(); 4];
        Self::terms(prims, x, scale, &mut terms);
        for (o, t) in out.iter_mut().zip(&terms[..prims.len()]) {
            *o = (t.d, t.w, t.dir.dot(u), t.grad_w.dot(u) / t.w);
        }
    }
    fn bounds(&self) -> Aabb {
        Aabb {
            min: self.a.min(self.b),
            max: self.a.max(self.b),
        }
    }
    fn centroid(&self) -> Vec3 {
        0.5 * (self.a + self.b)
    }
    fn closest_point(&self, x: DVec3) -> DVec3 {
        closest_on_segment(x, self.a.as_dvec3(), self.b.as_dvec3()).point
    }
    #[inline]
    fn value(&self, x: DVec3, scale: &WeightScale) -> (f64, f64) {
        let (a, b) = (self.a.as_dvec3(), self.b.as_dvec3());
        let c = closest_on_segment(x, a, b);
        let coef = weights::edge_quartic(1.0 / self.val_a as f64, 1.0 / self.val_b as f64);
        (
            (x - c.point).length(),
            scale.weight(weights::edge_w(c.t, coef).0),
        )
    }
    #[inline]
    fn term(&self, x: DVec3, scale: &WeightScale) -> Term {
        let (a, b) = (self.a.as_dvec3(), self.b.as_dvec3());
        let c = closest_on_segment(x, a, b);
        let v = x - c.point;
        let d = v.length();
        let coef = weights::edge_quartic(1.0 / self.val_a as f64, 1.0 / self.val_b as f64);
        let (raw, draw) = weights::edge_w(c.t, coef);
        let (w, dw) = scale.apply(raw);
        let grad_w = if c.interior && dw != 0.0 {
            let ab = b - a;
            (dw * draw / ab.length_squared()) * ab
        } else {
            DVec3::ZERO
        };
        Term {
            d,
            dir: unit_or_zero(v, d),
            w,
            grad_w,
        }
    }
}

/// A triangle with its largest vertex and edge valences (degree-7 weight, SPEC 4). Made
/// by [`Triangle::new`], which also decides `order` and `row` once for every query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    pub a: Vec3,
    pub b: Vec3,
    pub c: Vec3,
    /// Largest number of triangles incident on one of its vertices (>= 1).
    pub vmax: f32,
    /// Largest number of triangles incident on one of its edges (>= 1).
    pub emax: f32,
    /// Its vertex with the largest angle, or that it is degenerate
    /// (`geometry::closest::triangle_order`), decided once for every query.
    pub order: u8,
    /// Where its weight's coefficients are tabulated (`weights::triangle_table_row`).
    pub row: u16,
}

impl Triangle {
    pub fn new(a: Vec3, b: Vec3, c: Vec3, vmax: f32, emax: f32) -> Triangle {
        Triangle {
            a,
            b,
            c,
            vmax,
            emax,
            order: triangle_order(a.as_dvec3(), b.as_dvec3(), c.as_dvec3()),
            row: weights::triangle_table_row(vmax, emax),
        }
    }

    /// The closest point to `x`.
    #[inline]
    fn closest(&self, x: DVec3) -> TriangleClosest {
        let (a, b, c) = (self.a.as_dvec3(), self.b.as_dvec3(), self.c.as_dvec3());
        closest_on_triangle_ordered(x, a, b, c, self.order)
    }

    /// The closest point to `x`, the offset `x - c` from it and its length `d`.
    #[inline]
    fn offset(&self, x: DVec3) -> (TriangleClosest, DVec3, f64) {
        let cl = self.closest(x);
        let v = x - cl.point;
        (cl, v, v.length())
    }

    /// Its weight at its vertex `i` (0, 1, 2 for `a`, `b`, `c`).
    #[inline]
    fn corner(&self, i: usize) -> weights::TriCorner {
        weights::triangle_corner(self.row, self.vmax, self.emax, i)
    }

    /// The edges `b - a` and `c - a` (the barycentric gradients' basis).
    #[inline]
    fn e1(&self) -> DVec3 {
        self.b.as_dvec3() - self.a.as_dvec3()
    }

    #[inline]
    fn e2(&self) -> DVec3 {
        self.c.as_dvec3() - self.a.as_dvec3()
    }
}

impl Primitive for Triangle {
    fn bounds(&self) -> Aabb {
        Aabb {
            min: self.a.min(self.b).min(self.c),
            max: self.a.max(self.b).max(self.c),
        }
    }
    fn centroid(&self) -> Vec3 {
        (self.a + self.b + self.c) / 3.0
    }
    fn closest_point(&self, x: DVec3) -> DVec3 {
        self.closest(x).point
    }
    #[inline]
    fn value(&self, x: DVec3, scale: &WeightScale) -> (f64, f64) {
        let cl = self.closest(x);
        let raw = match cl.feature.corner() {
            Some(i) => self.corner(i).value,
            None => {
                let mut buf = [0.0; 13];
                let k = weights::triangle_k(self.row, self.vmax, self.emax, &mut buf);
                weights::triangle_w_value(cl.s, cl.t, k)
            }
        };
        ((x - cl.point).length(), scale.weight(raw))
    }
    #[inline]
    fn value_slope(&self, x: DVec3, u: DVec3, scale: &WeightScale) -> (f64, f64, f64, f64) {
        let (cl, v, d) = self.offset(x);
        if let Some(i) = cl.feature.corner() {
            // Both barycentric gradients are zero at a vertex: so is the log-weight's
            // slope (the general path gives a zero of either sign there).
            let w = scale.apply(self.corner(i).value).0;
            return (d, w, slope(v, d, u), 0.0);
        }
        let mut buf = [0.0; 13];
        let k = weights::triangle_k(self.row, self.vmax, self.emax, &mut buf);
        let (gs, gt) = weights::triangle_bary_gradients(cl.feature, self.e1(), self.e2());
        let (raw, draw) = weights::triangle_w_directional(cl.s, cl.t, gs.dot(u), gt.dot(u), k);
        let (w, dw) = scale.apply(raw);
        (d, w, slope(v, d, u), dw * draw / w)
    }
    /// Inlined where the sink takes the term (most terms are at a vertex: their term
    /// stays in registers), the rest of the weight out of line.
    #[inline(always)]
    fn term(&self, x: DVec3, scale: &WeightScale) -> Term {
        let (cl, v, d) = self.offset(x);
        if let Some(i) = cl.feature.corner() {
            // The weight at a vertex, tabulated (`weights::TriCorner`): the general
            // path's results to the last bit, without its polynomial.
            let c = self.corner(i);
            let (w, dw) = scale.apply(c.raw);
            return Term {
                d,
                dir: unit_or_zero(v, d),
                w,
                grad_w: if dw != 0.0 { dw * c.zero } else { DVec3::ZERO },
            };
        }
        self.term_on_edge_or_face(&cl, v, d, scale)
    }
}

impl Triangle {
    /// [`Primitive::term`] where the closest point is not a vertex.
    #[inline(never)]
    fn term_on_edge_or_face(
        &self,
        cl: &TriangleClosest,
        v: DVec3,
        d: f64,
        scale: &WeightScale,
    ) -> Term {
        let mut buf = [0.0; 13];
        let k = weights::triangle_k(self.row, self.vmax, self.emax, &mut buf);
        let (raw, ws, wt) = weights::triangle_w_grad(cl.s, cl.t, k);
        let (w, dw) = scale.apply(raw);
        let grad_w = if dw != 0.0 {
            let (gs, gt) = weights::triangle_bary_gradients(cl.feature, self.e1(), self.e2());
            dw * (ws * gs + wt * gt)
        } else {
            DVec3::ZERO
        };
        Term {
            d,
            dir: unit_or_zero(v, d),
            w,
            grad_w,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What `Triangle::new` decides once (the vertex with the largest angle or
    /// degeneracy, the weight's table row) gives what deciding it per query gives, to the
    /// last bit: skinny, degenerate and untabulated triangles included.
    #[test]
    fn stored_decisions_give_the_per_query_results() {
        use crate::geometry::closest::closest_on_triangle;
        let mut seed = 7u64;
        let mut r = move || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f32 / (1u64 << 53) as f32 - 0.5
        };
        let scale = WeightScale::new(40.0, 100.0, 200.0);
        for i in 0..300 {
            let mut v = || Vec3::new(r(), r(), r());
            let (a, mut b, mut c) = (v(), v(), v());
            match i % 5 {
                0 => c = a + 2.0 * (b - a), // collinear
                1 => b = a,                 // coincident
                2 => c = b + (b - a) * 1e3, // long and thin
                _ => {}
            }
            let (vmax, emax) = if i % 3 == 0 { (40.0, 12.0) } else { (6.0, 2.0) };
            let tri = Triangle::new(a, b, c, vmax, emax);
            let k = weights::triangle_coefficients(vmax as f64, emax as f64);
            for _ in 0..10 {
                let x = DVec3::new(r() as f64, r() as f64, r() as f64) * 3.0;
                let cl = closest_on_triangle(x, a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
                assert_eq!(tri.closest_point(x), cl.point, "triangle {i}");
                let want = scale.weight(weights::triangle_w_value(cl.s, cl.t, &k));
                assert_eq!(
                    tri.value(x, &scale),
                    ((x - cl.point).length(), want),
                    "triangle {i}"
                );
            }
        }
    }

    /// A term, a value and a value with slopes by the general formulas (the polynomial
    /// at the closest point's barycentrics, whatever its feature): what the vertices'
    /// tabulated weights (`weights::TriCorner`) must give.
    fn general(
        tri: &Triangle,
        x: DVec3,
        u: DVec3,
        scale: &WeightScale,
    ) -> (Term, (f64, f64), Slope) {
        let (cl, v, d) = tri.offset(x);
        let k = weights::triangle_coefficients(tri.vmax as f64, tri.emax as f64);
        let (raw, ws, wt) = weights::triangle_w_grad(cl.s, cl.t, &k);
        let (w, dw) = scale.apply(raw);
        let (gs, gt) = weights::triangle_bary_gradients(cl.feature, tri.e1(), tri.e2());
        let grad_w = if dw != 0.0 {
            dw * (ws * gs + wt * gt)
        } else {
            DVec3::ZERO
        };
        let term = Term {
            d,
            dir: unit_or_zero(v, d),
            w,
            grad_w,
        };
        let value = (d, scale.weight(weights::triangle_w_value(cl.s, cl.t, &k)));
        let (raw, draw) = weights::triangle_w_directional(cl.s, cl.t, gs.dot(u), gt.dot(u), &k);
        let (w, dw) = scale.apply(raw);
        (term, value, (d, w, slope(v, d, u), dw * draw / w))
    }

    /// A triangle's terms, values and slopes equal the general formulas' to the last bit
    /// (the log-weight's slope up to the sign of a zero, which the sink reads as zero),
    /// at vertices (tabulated weights), edges and faces, for tabulated and untabulated
    /// valences, isolated triangles and every attenuation branch.
    #[test]
    fn vertex_weights_give_the_general_results() {
        let mut r = rng(0x9e37_79b9_7f4a_7c15);
        let mut corners = 0;
        for (i, scale) in scales().take(900).enumerate() {
            let mut v = || Vec3::new(r() as f32, r() as f32, r() as f32);
            let (a, b, c) = (v(), v(), v());
            let (vmax, emax) = [
                (6.0, 2.0),
                (1.0, 1.0),
                (32.0, 8.0),
                (40.0, 3.0),
                (5.0, 12.0),
            ][i % 5];
            let tri = Triangle::new(a, b, c, vmax, emax);
            for q in 0..12 {
                let x = match q {
                    0 => a.as_dvec3(),
                    1 => b.as_dvec3(),
                    _ => DVec3::new(r(), r(), r()) * (0.5 + q as f64),
                };
                let u = DVec3::new(r(), r(), r()).normalize();
                let (term, value, slopes) = general(&tri, x, u, &scale);
                let bits = |t: &Term| {
                    [
                        t.d, t.dir.x, t.dir.y, t.dir.z, t.w, t.grad_w.x, t.grad_w.y, t.grad_w.z,
                    ]
                    .map(f64::to_bits)
                };
                assert_eq!(bits(&tri.term(x, &scale)), bits(&term), "term {i} {q}");
                let got = tri.value(x, &scale);
                assert_eq!(
                    [got.0, got.1].map(f64::to_bits),
                    [value.0, value.1].map(f64::to_bits)
                );
                let got = tri.value_slope(x, u, &scale);
                assert_eq!(
                    [got.0, got.1, got.2].map(f64::to_bits),
                    [slopes.0, slopes.1, slopes.2].map(f64::to_bits),
                    "value_slope {i} {q}"
                );
                assert!(
                    got.3 == slopes.3,
                    "log-weight slope {} against {}",
                    got.3,
                    slopes.3
                );
                corners += usize::from(tri.closest(x).feature.corner().is_some());
            }
        }
        assert!(corners > 3000, "{corners} vertex terms");
    }

    /// `value_slope` agrees with `term`: the distance's slope is `dir . u` and the
    /// log-weight's `grad w . u / w`, which a central difference of `ln w` confirms.
    #[test]
    fn value_slope_matches_term_and_finite_differences() {
        let scale = WeightScale::new(6.0, 100.0, 200.0);
        let tri = Triangle::new(
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.1, 0.0),
            Vec3::new(0.2, 0.9, 0.1),
            6.0,
            2.0,
        );
        let edge = Edge {
            a: Vec3::new(0.0, 0.0, 0.0),
            b: Vec3::new(1.0, 0.3, -0.2),
            val_a: 3.0,
            val_b: 5.0,
        };
        let u = DVec3::new(0.3, -0.5, 0.8).normalize();
        let (mut checked, mut varying) = (0, 0);
        for i in 0..40 {
            let f = i as f64 / 40.0;
            let x = DVec3::new(0.9 * f - 0.1, 0.4 + 0.3 * (7.0 * f).sin(), 0.3 - 0.5 * f);
            let tri_term = |y: DVec3| tri.term(y, &scale);
            let edge_term = |y: DVec3| edge.term(y, &scale);
            let cases: [(&dyn Fn(DVec3) -> Term, _); 2] = [
                (&tri_term, tri.value_slope(x, u, &scale)),
                (&edge_term, edge.value_slope(x, u, &scale)),
            ];
            for (term, (d, w, a, l)) in cases {
                let t = term(x);
                assert!((t.d - d).abs() < 1e-12 && (t.w - w).abs() < 1e-12);
                assert!((t.dir.dot(u) - a).abs() < 1e-12);
                assert!(
                    (t.grad_w.dot(u) / t.w - l).abs() < 1e-9,
                    "{} {l}",
                    t.grad_w.dot(u) / t.w
                );
                varying += usize::from(l.abs() > 1e-3);
                let h = 1e-6;
                let fd = (term(x + h * u).w.ln() - term(x - h * u).w.ln()) / (2.0 * h);
                if (fd - l).abs() < 1e-4 * (1.0 + l.abs()) {
                    checked += 1;
                }
            }
        }
        // Central differences straddle a feature change (face to edge) at a few points.
        assert!(
            checked >= 76,
            "{checked} of 80 agree with finite differences"
        );
        assert!(
            varying >= 40,
            "the weights vary at {varying} of 80 points only"
        );
    }

    // The batches of `primitives::lanes`, bit for bit.

    /// A xorshift generator of values in [-0.5, 0.5).
    fn rng(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        }
    }

    /// Scales covering the attenuation's three branches (`q` 1, 0.5 and other).
    fn scales() -> impl Iterator<Item = WeightScale> {
        [
            WeightScale::new(11.0, 100.0, 200.0),
            WeightScale::new(7.0, 300.0, 200.0),
            WeightScale::new(40.0, 37.0, 100.0),
        ]
        .into_iter()
        .cycle()
    }

    /// The batch of `prims` (1 ..= 4) at `x` equals their scalar terms, values and
    /// slopes along `u` to the last bit.
    fn assert_same_bits<P: Primitive>(prims: &[P], x: DVec3, u: DVec3, scale: &WeightScale) {
        let mut terms = [Term::default(); 4];
        let mut values = [(0.0, 0.0); 4];
        let mut slopes = [(0.0, 0.0, 0.0, 0.0); 4];
        P::terms(prims, x, scale, &mut terms);
        P::values(prims, x, scale, &mut values);
        P::value_slopes(prims, x, u, scale, &mut slopes);
        let bits = |t: &Term| {
            [
                t.d, t.dir.x, t.dir.y, t.dir.z, t.w, t.grad_w.x, t.grad_w.y, t.grad_w.z,
            ]
            .map(f64::to_bits)
        };
        for (l, p) in prims.iter().enumerate() {
            assert_eq!(bits(&terms[l]), bits(&p.term(x, scale)), "term {l} at {x}");
            let (d, w) = p.value(x, scale);
            let want = [d, w].map(f64::to_bits);
            assert_eq!(
                [values[l].0, values[l].1].map(f64::to_bits),
                want,
                "value {l} at {x}"
            );
            let (s, t) = (p.value_slope(x, u, scale), slopes[l]);
            assert_eq!(
                [t.0, t.1, t.2, t.3].map(f64::to_bits),
                [s.0, s.1, s.2, s.3].map(f64::to_bits),
                "value_slope {l} at {x}"
            );
        }
    }

    /// The edges' lanes (`primitives::lanes`) equal their scalar terms to the last bit: empty, short and long
    /// edges, queries before, past and beside them, valences 1 to 12, every attenuation
    /// branch, leaves of 1 to 4 edges.
    #[test]
    fn edge_lanes_equal_the_scalar_terms_bit_for_bit() {
        if !lanes::available() {
            eprintln!("no AVX here: the batch is the scalar path");
        }
        let mut r = rng(0x2545_f491_4f6c_dd1d);
        let (mut ends, mut inside) = (0, 0);
        for (i, scale) in scales().take(600).enumerate() {
            let edges: Vec<Edge> = (0..1 + i % 4)
                .map(|j| {
                    let mut v = || Vec3::new(r() as f32, r() as f32, r() as f32);
                    let a = v();
                    let b = if (i + j) % 9 == 0 { a } else { v() };
                    let val = |k: usize| (1 + (i * 7 + j * 3 + k) % 12) as f32;
                    Edge {
                        a,
                        b,
                        val_a: val(0),
                        val_b: val(1),
                    }
                })
                .collect();
            for q in 0..8 {
                let e0 = &edges[0];
                let x = match q {
                    0 => e0.a.as_dvec3(),
                    1 => (0.5 * (e0.a + e0.b)).as_dvec3(),
                    _ => DVec3::new(r(), r(), r()) * (q as f64),
                };
                let u = DVec3::new(r(), r(), r()).normalize();
                assert_same_bits(&edges, x, u, &scale);
                for e in &edges {
                    let (a, b) = (e.a.as_dvec3(), e.b.as_dvec3());
                    if crate::geometry::closest::closest_on_segment(x, a, b).interior {
                        inside += 1;
                    } else {
                        ends += 1;
                    }
                }
            }
        }
        assert!(ends > 500 && inside > 500, "ends {ends}, inside {inside}");
    }
}
