//! Weight functions of edges and triangles (SPEC 4) and attenuation (SPEC 5).
//!
//! The unscaled weight `W` is a polynomial in the closest point's barycentric
//! coordinates; the used weight is `w = (max_adj * W)^q` with `q = min(alpha /
//! max_alpha, 1)`. `W` is clamped to `[1 / max_adj, 1]`, so that every weight lies in
//! `[1, max_adj^q]`: `w >= 1` keeps the smooth distance below the exact distance
//! (SPEC 2), and `w <= max_adj^q` keeps the Barnes-Hut far field above every term it
//! replaces (SPEC 6). The clamp never touches the polynomials' interpolation values; it
//! catches overshoot (the edge quartic with end valences 1 and 3 peaks at 1.09) and
//! undershoot, and it keeps weights finite and positive for degenerate input.
//!
//! Gradients are exact gradients of `w` with respect to the query point (the closest
//! point's barycentrics move with the query only on the feature it lies on), so the
//! gradient of the smooth distance agrees with finite differences.

use glam::DVec3;
use std::ops::{Add, Mul, Sub};

/// Coefficients of the degree-7 triangle weight (SPEC 4), `k = A/vmax + B/emax +
/// C (vmax-1)/vmax`, in the basis listed in [`tri_basis`].
pub const TRI_A: [f64; 13] = [
    1.0,
    -23.283836892152,
    54.732033227077,
    -28.569242218786,
    287.601694832154,
    -38.617847248620,
    -336.888198341906,
    60.434472706056,
    -96.244440388016,
    96.200755813732,
    -24.695579573574,
    140.043037325921,
    247.260054961339,
];
pub const TRI_B: [f64; 13] = [
    0.0,
    36.574687148269,
    -124.157891685314,
    111.016227590180,
    -806.922996604926,
    105.179057785262,
    1103.424425061952,
    -229.648667341166,
    256.853237918432,
    -385.711216189244,
    101.036586502767,
    -530.902091597253,
    -885.450169267657,
];
pub const TRI_C: [f64; 13] = [
    0.0,
    -13.290850256117,
    69.425858458238,
    -82.446985371394,
    519.321301772771,
    -66.561210536643,
    -766.536226720045,
    169.214194635110,
    -160.608797530416,
    289.510460375512,
    -76.341006929192,
    390.859054271332,
    638.190114306318,
];

/// The 13 basis functions of the triangle weight at `(s, t)` and their partial
/// derivatives with respect to `s` (the `t` partials follow by symmetry, swapping).
/// Basis: 1, s²+t², s³+t³, s⁴+t⁴, s²t², s⁵+t⁵, s²t³+s³t², s⁶+t⁶, s²t⁴+s⁴t², s³t³,
/// s⁷+t⁷, s²t⁵+s⁵t², s³t⁴+s⁴t³.
#[inline]
pub fn tri_basis(s: f64, t: f64) -> ([f64; 13], [f64; 13]) {
    let (s2, t2) = (s * s, t * t);
    let (s3, t3) = (s2 * s, t2 * t);
    let (s4, t4) = (s3 * s, t3 * t);
    let (s5, t5) = (s4 * s, t4 * t);
    let (s6, t6) = (s5 * s, t5 * t);
    let value = [
        1.0,
        s2 + t2,
        s3 + t3,
        s4 + t4,
        s2 * t2,
        s5 + t5,
        s2 * t3 + s3 * t2,
        s6 + t6,
        s2 * t4 + s4 * t2,
        s3 * t3,
        s6 * s + t6 * t,
        s2 * t5 + s5 * t2,
        s3 * t4 + s4 * t3,
    ];
    let ds = [
        0.0,
        2.0 * s,
        3.0 * s2,
        4.0 * s3,
        2.0 * s * t2,
        5.0 * s4,
        2.0 * s * t3 + 3.0 * s2 * t2,
        6.0 * s5,
        2.0 * s * t4 + 4.0 * s3 * t2,
        3.0 * s2 * t3,
        7.0 * s6,
        2.0 * s * t5 + 5.0 * s4 * t2,
        3.0 * s2 * t4 + 4.0 * s3 * t3,
    ];
    (value, ds)
}

/// Coefficients `k` of the triangle weight for a triangle whose largest vertex valence
/// is `vmax` and largest edge valence `emax`: `k = A/vmax + B/emax + C (vmax-1)/vmax`.
/// An isolated triangle (`vmax = 1`) gets `W = 1` (SPEC 4's trap: the centroid value
/// `(vmax-1)/vmax` would be 0 and leave a hole).
pub fn triangle_coefficients(vmax: f64, emax: f64) -> [f64; 13] {
    let mut k = [0.0; 13];
    if vmax <= 1.0 {
        k[0] = 1.0;
        return k;
    }
    let (fa, fb, fc) = (1.0 / vmax, 1.0 / emax, (vmax - 1.0) / vmax);
    for i in 0..13 {
        k[i] = fa * TRI_A[i] + fb * TRI_B[i] + fc * TRI_C[i];
    }
    k
}

const TABLE_VMAX: usize = 32;
const TABLE_EMAX: usize = 8;

/// Where [`triangle_k`] finds the coefficients of a triangle with valences `vmax`,
/// `emax`: its row of the table of the common valences (`vmax <= 32`, `emax <= 8`), or
/// [`NOT_TABULATED`]. Computed once per triangle (`primitives::Triangle`): the float
/// to index conversions cost as much as a tenth of a term.
pub fn triangle_table_row(vmax: f32, emax: f32) -> u16 {
    let (v, e) = (vmax as usize, emax as usize);
    if (1..=TABLE_VMAX).contains(&v) && (1..=TABLE_EMAX).contains(&e) {
        ((v - 1) * TABLE_EMAX + (e - 1)) as u16
    } else {
        NOT_TABULATED
    }
}

/// [`triangle_table_row`] of valences outside the table.
pub const NOT_TABULATED: u16 = u16::MAX;

/// The barycentrics `(s, t)` of a triangle's corners `a`, `b`, `c` (0, 1, 2).
pub const TRI_CORNERS: [(f64, f64); 3] = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)];

/// The triangle weight at one of its corners, as the general formulas give it there
/// (what a term whose closest point is a vertex needs; most are, for a query a few
/// triangles away): tabulated with the coefficients, so that such a term evaluates no
/// polynomial and its results are the general path's to the last bit.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TriCorner {
    /// [`triangle_w_grad`]'s `W` there.
    pub raw: f64,
    /// `ws * 0 + wt * 0` (per component, `ws`, `wt` its partials there): what the
    /// weight gradient's sum `ws grad s + wt grad t` is at a vertex, where both
    /// barycentric gradients are zero (its zeros' signs included).
    pub zero: DVec3,
    /// [`triangle_w_value`] there (the value paths sum the polynomial in another order,
    /// so it may round differently; [`triangle_w_directional`]'s `W` is the same sum).
    pub value: f64,
}

impl TriCorner {
    /// Corner `i` (0, 1, 2 for `a`, `b`, `c`) of the weight with coefficients `k`.
    pub fn of(k: &[f64; 13], i: usize) -> TriCorner {
        let (s, t) = TRI_CORNERS[i];
        let (raw, ws, wt) = triangle_w_grad(s, t, k);
        TriCorner {
            raw,
            zero: ws * DVec3::ZERO + wt * DVec3::ZERO,
            value: triangle_w_value(s, t, k),
        }
    }
}

/// A row of the coefficient table: `k` and its three corners.
struct TriRow {
    k: [f64; 13],
    corners: [TriCorner; 3],
}

/// The table of the common valences' coefficients, computed once.
#[inline]
fn triangle_table() -> &'static [TriRow] {
    static TABLE: std::sync::OnceLock<Vec<TriRow>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        (1..=TABLE_VMAX)
            .flat_map(|v| {
                (1..=TABLE_EMAX).map(move |e| {
                    let k = triangle_coefficients(v as f64, e as f64);
                    TriRow {
                        k,
                        corners: std::array::from_fn(|i| TriCorner::of(&k, i)),
                    }
                })
            })
            .collect()
    })
}

/// [`triangle_coefficients`] for valences `vmax`, `emax` whose [`triangle_table_row`] is
/// `row`: from a table computed once for the common valences, else into `buf`.
#[inline]
pub fn triangle_k(row: u16, vmax: f32, emax: f32, buf: &mut [f64; 13]) -> &[f64; 13] {
    if row != NOT_TABULATED {
        &triangle_table()[row as usize].k
    } else {
        *buf = triangle_coefficients(vmax as f64, emax as f64);
        buf
    }
}

/// [`TriCorner::of`] corner `i` of the weight of valences `vmax`, `emax` (table row
/// `row`, as [`triangle_k`]).
#[inline]
pub fn triangle_corner(row: u16, vmax: f32, emax: f32, i: usize) -> TriCorner {
    if row != NOT_TABULATED {
        triangle_table()[row as usize].corners[i]
    } else {
        TriCorner::of(&triangle_coefficients(vmax as f64, emax as f64), i)
    }
}

/// Triangle weight polynomial `W(s, t)` (unclamped) with coefficients `k`.
#[inline]
pub fn triangle_w_value(s: f64, t: f64, k: &[f64; 13]) -> f64 {
    let (s2, t2) = (s * s, t * t);
    let (s3, t3) = (s2 * s, t2 * t);
    let (s4, t4) = (s3 * s, t3 * t);
    let (s5, t5) = (s4 * s, t4 * t);
    let (s6, t6) = (s5 * s, t5 * t);
    let q = s2 * t2;
    let c = s3 * t3;
    let p2 = s2 + t2;
    let p3 = s3 + t3;
    k[0] + k[1] * p2
        + k[2] * p3
        + k[3] * (s4 + t4)
        + k[4] * q
        + k[5] * (s5 + t5)
        + k[6] * q * (s + t)
        + k[7] * (s6 + t6)
        + k[8] * q * p2
        + k[9] * c
        + k[10] * (s6 * s + t6 * t)
        + k[11] * q * p3
        + k[12] * c * (s + t)
}

/// Triangle weight polynomial `W(s, t)` and its derivative along `(ds, dt)`:
/// `W_s ds + W_t dt` (the value's formula in forward-mode derivatives, cheaper than the
/// two partials of [`triangle_w_grad`]).
#[inline]
pub fn triangle_w_directional(s: f64, t: f64, ds: f64, dt: f64, k: &[f64; 13]) -> (f64, f64) {
    let (s2, t2) = (s * s, t * t);
    let (s3, t3) = (s2 * s, t2 * t);
    let (s4, t4) = (s3 * s, t3 * t);
    let (s5, t5) = (s4 * s, t4 * t);
    let (s6, t6) = (s5 * s, t5 * t);
    let (ds2, dt2) = (2.0 * s * ds, 2.0 * t * dt);
    let (ds3, dt3) = (3.0 * s2 * ds, 3.0 * t2 * dt);
    let (ds4, dt4) = (4.0 * s3 * ds, 4.0 * t3 * dt);
    let (ds5, dt5) = (5.0 * s4 * ds, 5.0 * t4 * dt);
    let (ds6, dt6) = (6.0 * s5 * ds, 6.0 * t5 * dt);
    let (ds7, dt7) = (7.0 * s6 * ds, 7.0 * t6 * dt);
    let q = s2 * t2;
    let dq = ds2 * t2 + s2 * dt2;
    let c = s3 * t3;
    let dc = ds3 * t3 + s3 * dt3;
    let (p1, dp1) = (s + t, ds + dt);
    let (p2, dp2) = (s2 + t2, ds2 + dt2);
    let (p3, dp3) = (s3 + t3, ds3 + dt3);
    let w = k[0]
        + k[1] * p2
        + k[2] * p3
        + k[3] * (s4 + t4)
        + k[4] * q
        + k[5] * (s5 + t5)
        + k[6] * q * p1
        + k[7] * (s6 + t6)
        + k[8] * q * p2
        + k[9] * c
        + k[10] * (s6 * s + t6 * t)
        + k[11] * q * p3
        + k[12] * c * p1;
    let dw = k[1] * dp2
        + k[2] * dp3
        + k[3] * (ds4 + dt4)
        + k[4] * dq
        + k[5] * (ds5 + dt5)
        + k[6] * (dq * p1 + q * dp1)
        + k[7] * (ds6 + dt6)
        + k[8] * (dq * p2 + q * dp2)
        + k[9] * dc
        + k[10] * (ds7 + dt7)
        + k[11] * (dq * p3 + q * dp3)
        + k[12] * (dc * p1 + c * dp1);
    (w, dw)
}

/// Triangle weight polynomial and its partials `(W, dW/ds, dW/dt)` with coefficients `k`.
/// The basis of [`tri_basis`] grouped as `W = k0 + f(s) + f(t) + s^2 t^2 h(s, t)`, with
/// the one-variable part `f(x) = k1 x^2 + k2 x^3 + k3 x^4 + k5 x^5 + k7 x^6 + k10 x^7` and
/// `h = k4 + k6 (s+t) + k8 (s^2+t^2) + k9 st + k11 (s^3+t^3) + k12 st (s+t)`, each in
/// Horner form: `dW/ds = f'(s) + 2 s t^2 h + s^2 t^2 dh/ds` (and `t` likewise): less
/// than half the arithmetic of summing the 13 basis functions and their two partials.
#[inline]
pub fn triangle_w_grad(s: f64, t: f64, k: &[f64; 13]) -> (f64, f64, f64) {
    let f = |x: f64| x * x * (k[1] + x * (k[2] + x * (k[3] + x * (k[5] + x * (k[7] + x * k[10])))));
    let df = |x: f64| {
        x * (2.0 * k[1]
            + x * (3.0 * k[2]
                + x * (4.0 * k[3] + x * (5.0 * k[5] + x * (6.0 * k[7] + x * 7.0 * k[10])))))
    };
    let (s2, t2, st) = (s * s, t * t, s * t);
    let q = s2 * t2;
    let h = k[4]
        + k[6] * (s + t)
        + k[8] * (s2 + t2)
        + k[9] * st
        + k[11] * (s2 * s + t2 * t)
        + k[12] * st * (s + t);
    // dh/ds and dh/dt share everything but their own variable's terms.
    let common = k[6] + 2.0 * k[12] * st;
    let hs = common + 2.0 * k[8] * s + k[9] * t + 3.0 * k[11] * s2 + k[12] * t2;
    let ht = common + 2.0 * k[8] * t + k[9] * s + 3.0 * k[11] * t2 + k[12] * s2;
    let w = k[0] + f(s) + f(t) + q * h;
    let ws = df(s) + 2.0 * s * t2 * h + q * hs;
    let wt = df(t) + 2.0 * t * s2 * h + q * ht;
    (w, ws, wt)
}

/// `(W, dW/ds, dW/dt)` for a triangle with valences `vmax`, `emax` (tests, reports).
pub fn triangle_w(s: f64, t: f64, vmax: f64, emax: f64) -> (f64, f64, f64) {
    triangle_w_grad(s, t, &triangle_coefficients(vmax, emax))
}

/// What the edge weight's polynomial needs of a number: `f64`, or four of them in the
/// lanes of `primitives::lanes`, which evaluate the same formulas (each operation rounds
/// as on `f64`, so the lanes' weights equal the scalar ones to the last bit). Constant
/// factors are written on the right (`x * 2.0`): an IEEE product or sum does not depend
/// on the order of its two operands.
pub trait Real:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Mul<f64, Output = Self>
{
    /// The constant `v`.
    fn lit(v: f64) -> Self;
}

impl Real for f64 {
    #[inline(always)]
    fn lit(v: f64) -> f64 {
        v
    }
}

/// Coefficients `(c0, c2, c3, c4)` of the edge quartic `W(t) = c0 + c2 t² + c3 t³ + c4 t⁴`
/// with `W(0) = a`, `W(1) = b`, `W(1/2) = 1`, `W'(0) = W'(1) = 0` (SPEC 4), where
/// `a = 1/val(v0)`, `b = 1/val(v1)`. Solved in closed form: with `D = b - a` and
/// `E = 16 (1 - a)`: `c2 = E - 5D`, `c3 = 14D - 2E`, `c4 = E - 8D`. An isolated edge
/// (`a = b = 1`) gets `W = 1`.
#[inline(always)]
pub fn edge_quartic<T: Real>(a: T, b: T) -> [T; 4] {
    let d = b - a;
    let e = (T::lit(1.0) - a) * 16.0;
    [a, e - d * 5.0, d * 14.0 - e * 2.0, e - d * 8.0]
}

/// Edge weight polynomial value and derivative at `t`.
#[inline(always)]
pub fn edge_w<T: Real>(t: T, c: [T; 4]) -> (T, T) {
    let t2 = t * t;
    let w = c[0] + t2 * (c[1] + t * (c[2] + t * c[3]));
    let dw = t * (c[1] * 2.0 + t * (c[2] * 3.0 + t * 4.0 * c[3]));
    (w, dw)
}

/// Attenuated, clamped weight of one primitive: `w = (max_adj * clamp(W))^q` and the
/// factor `dw/dW` (zero where the clamp is active), from the raw polynomial value.
/// Made by [`WeightScale::new`] (which also computes `max_adj^q`; the fields are read,
/// not changed, after it).
#[derive(Clone, Copy, Debug)]
pub struct WeightScale {
    /// Largest valence of the primitive set (SPEC 1).
    pub max_adj: f64,
    /// Attenuation exponent `q = min(alpha / max_alpha, 1)` (SPEC 5).
    pub q: f64,
    /// `max_adj^q` ([`WeightScale::max_weight`]), once: every leaf of a walk may need
    /// it (a weight clamped from above), and the compiler hoists its `powf` out of a
    /// leaf's loop, so it was computed once per leaf.
    w_max: f64,
    /// `1 / max_adj`, the floor of `W`, once (not a division per term).
    lo: f64,
}

impl WeightScale {
    pub fn new(max_adj: f64, alpha: f64, max_alpha: f64) -> WeightScale {
        let max_adj = max_adj.max(1.0);
        let mut scale = WeightScale {
            max_adj,
            q: (alpha / max_alpha).min(1.0),
            w_max: 0.0,
            lo: 1.0 / max_adj,
        };
        scale.w_max = scale.pow(scale.max_adj);
        scale
    }

    /// The largest weight any primitive of the set can have, `max_adj^q`: the weight of
    /// a Barnes-Hut far-field term (SPEC 6).
    #[inline]
    pub fn max_weight(&self) -> f64 {
        self.w_max
    }

    #[inline]
    fn pow(&self, v: f64) -> f64 {
        if self.q == 1.0 {
            v
        } else if self.q == 0.5 {
            v.sqrt()
        } else {
            v.powf(self.q)
        }
    }

    /// `w` alone for the raw polynomial value `raw` (same as `apply(raw).0`).
    #[inline]
    pub fn weight(&self, raw: f64) -> f64 {
        if raw <= self.lo {
            1.0
        } else if raw >= 1.0 || raw.is_nan() {
            self.max_weight()
        } else {
            self.pow(self.max_adj * raw)
        }
    }

    /// `(w, dw/dW)` for the raw polynomial value `raw`.
    #[inline]
    pub fn apply(&self, raw: f64) -> (f64, f64) {
        if raw <= self.lo {
            (1.0, 0.0)
        } else if raw >= 1.0 || raw.is_nan() {
            (self.max_weight(), 0.0)
        } else {
            let w = self.pow(self.max_adj * raw);
            (w, self.q * w / raw)
        }
    }
}

/// Gradient with respect to the query of the triangle barycentrics `(s, t)` of the
/// closest point, on the feature where it lies (zero on vertices and for degenerate
/// triangles). `e1 = b - a`, `e2 = c - a`.
#[inline]
pub fn triangle_bary_gradients(
    feature: crate::geometry::closest::TriFeature,
    e1: DVec3,
    e2: DVec3,
) -> (DVec3, DVec3) {
    use crate::geometry::closest::TriFeature as F;
    match feature {
        F::Face => {
            // Dual basis in the plane: grad s . e1 = 1, grad s . e2 = 0.
            let p1 = e1 - e2 * (e1.dot(e2) / e2.length_squared());
            let p2 = e2 - e1 * (e2.dot(e1) / e1.length_squared());
            (p1 / p1.length_squared(), p2 / p2.length_squared())
        }
        F::EdgeAB => (e1 / e1.length_squared(), DVec3::ZERO),
        F::EdgeAC => (DVec3::ZERO, e2 / e2.length_squared()),
        F::EdgeBC => {
            let bc = e2 - e1;
            let gu = bc / bc.length_squared();
            (-gu, gu)
        }
        _ => (DVec3::ZERO, DVec3::ZERO),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_value_conditions() {
        for (vmax, emax) in [(6.0, 2.0), (3.0, 1.0), (12.0, 3.0), (2.0, 2.0)] {
            let corner = 1.0 / vmax;
            let third = 1.0 / emax;
            let centre = (vmax - 1.0) / vmax;
            let check = |s: f64, t: f64, want: f64| {
                let (w, _, _) = triangle_w(s, t, vmax, emax);
                assert!(
                    (w - want).abs() < 1e-6,
                    "vmax {vmax} emax {emax} W({s},{t}) = {w}, want {want}"
                );
            };
            check(0.0, 0.0, corner);
            check(1.0, 0.0, corner);
            check(0.0, 1.0, corner);
            for (s, t) in [
                (1.0 / 3.0, 0.0),
                (2.0 / 3.0, 0.0),
                (0.0, 1.0 / 3.0),
                (0.0, 2.0 / 3.0),
                (1.0 / 3.0, 2.0 / 3.0),
                (2.0 / 3.0, 1.0 / 3.0),
            ] {
                check(s, t, third);
            }
            check(1.0 / 3.0, 1.0 / 3.0, centre);
        }
    }

    #[test]
    fn triangle_normal_derivatives_vanish_on_edges() {
        let (vmax, emax) = (6.0, 2.0);
        for i in 0..=20 {
            let u = i as f64 / 20.0;
            // Across s = 0 the normal derivative is dW/ds; across t = 0 it is dW/dt.
            let (_, ws, _) = triangle_w(0.0, u, vmax, emax);
            let (_, _, wt) = triangle_w(u, 0.0, vmax, emax);
            assert!(ws.abs() < 1e-9, "dW/ds at (0,{u}) = {ws}");
            assert!(wt.abs() < 1e-9, "dW/dt at ({u},0) = {wt}");
            // Across s + t = 1 the normal direction is (1, 1).
            let (_, ws, wt) = triangle_w(u, 1.0 - u, vmax, emax);
            assert!(
                (ws + wt).abs() < 1e-6,
                "dW/dn at ({u},{}) = {}",
                1.0 - u,
                ws + wt
            );
            // Numerically too, with a one-sided difference into the triangle.
            let h = 1e-6;
            let (w0, _, _) = triangle_w(0.0, u * 0.999, vmax, emax);
            let (w1, _, _) = triangle_w(h, u * 0.999, vmax, emax);
            assert!(((w1 - w0) / h).abs() < 1e-4);
        }
    }

    #[test]
    fn triangle_range_matches_spec() {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let n = 300;
        for i in 0..=n {
            for j in 0..=(n - i) {
                let (w, _, _) = triangle_w(i as f64 / n as f64, j as f64 / n as f64, 6.0, 2.0);
                lo = lo.min(w);
                hi = hi.max(w);
            }
        }
        assert!(
            (lo - 0.1665).abs() < 2e-3 && (hi - 0.850).abs() < 2e-3,
            "[{lo}, {hi}]"
        );
    }

    #[test]
    fn triangle_partials_match_finite_differences() {
        let h = 1e-6;
        for &(s, t) in &[(0.2, 0.3), (0.6, 0.1), (0.1, 0.8)] {
            let (_, ws, wt) = triangle_w(s, t, 7.0, 2.0);
            let fs =
                (triangle_w(s + h, t, 7.0, 2.0).0 - triangle_w(s - h, t, 7.0, 2.0).0) / (2.0 * h);
            let ft =
                (triangle_w(s, t + h, 7.0, 2.0).0 - triangle_w(s, t - h, 7.0, 2.0).0) / (2.0 * h);
            assert!((ws - fs).abs() < 1e-6 && (wt - ft).abs() < 1e-6);
        }
    }

    /// The grouped Horner form of `triangle_w_grad` is the sum of the 13 basis functions
    /// and of their partials, for coefficient sets of the table and arbitrary ones.
    #[test]
    fn grouped_partials_are_the_basis_sums() {
        let mut seed = 3u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let arbitrary: [f64; 13] = std::array::from_fn(|_| 20.0 * rnd() - 10.0);
        let sets = [
            triangle_coefficients(6.0, 2.0),
            triangle_coefficients(11.0, 3.0),
            [0.0; 13],
            arbitrary,
        ];
        for k in &sets {
            for _ in 0..200 {
                let s = rnd();
                let t = (1.0 - s) * rnd();
                let (bs, dbs) = tri_basis(s, t);
                let (_, dbt) = tri_basis(t, s);
                let dot = |b: &[f64; 13]| b.iter().zip(k).map(|(b, k)| b * k).sum::<f64>();
                let (w, ws, wt) = triangle_w_grad(s, t, k);
                let scale = 1.0 + k.iter().map(|v| v.abs()).sum::<f64>();
                assert!((w - dot(&bs)).abs() <= 1e-13 * scale, "{s} {t}");
                assert!((ws - dot(&dbs)).abs() <= 1e-12 * scale, "{s} {t}");
                assert!((wt - dot(&dbt)).abs() <= 1e-12 * scale, "{s} {t}");
            }
        }
    }

    #[test]
    fn directional_derivative_matches_partials() {
        let k = triangle_coefficients(6.0, 2.0);
        for &(s, t, ds, dt) in &[
            (0.2, 0.3, 1.0, -0.5),
            (0.0, 0.0, 0.3, 0.7),
            (0.7, 0.1, -2.0, 1.5),
            (1.0 / 3.0, 1.0 / 3.0, 0.1, 0.1),
        ] {
            let (w, ws, wt) = triangle_w_grad(s, t, &k);
            let (w2, dw) = triangle_w_directional(s, t, ds, dt, &k);
            assert!((w - w2).abs() < 1e-12, "{w} {w2}");
            assert!(
                (ws * ds + wt * dt - dw).abs() < 1e-10,
                "{} {dw}",
                ws * ds + wt * dt
            );
        }
    }

    #[test]
    fn value_path_matches_gradient_path_and_table() {
        let mut buf = [0.0; 13];
        for (v, e) in [(1.0f32, 1.0f32), (6.0, 2.0), (40.0, 3.0), (5.0, 12.0)] {
            let k = *triangle_k(triangle_table_row(v, e), v, e, &mut buf);
            assert_eq!(k, triangle_coefficients(v as f64, e as f64));
            for &(s, t) in &[(0.1, 0.2), (0.5, 0.5), (0.0, 1.0), (0.3, 0.0)] {
                let a = triangle_w_value(s, t, &k);
                let b = triangle_w_grad(s, t, &k).0;
                assert!((a - b).abs() < 1e-12, "{a} vs {b}");
            }
        }
        let ws = WeightScale::new(6.0, 1.0, 2.0);
        for raw in [0.1, 0.3, 0.9] {
            assert_eq!(ws.weight(raw), ws.apply(raw).0);
        }
    }

    #[test]
    fn isolated_triangle_has_unit_weight() {
        assert_eq!(triangle_w(1.0 / 3.0, 1.0 / 3.0, 1.0, 1.0), (1.0, 0.0, 0.0));
    }

    #[test]
    fn edge_quartic_conditions() {
        for (va, vb) in [(1.0, 1.0), (2.0, 2.0), (1.0, 3.0), (4.0, 2.0), (6.0, 1.0)] {
            let (a, b) = (1.0 / va, 1.0 / vb);
            let c = edge_quartic(a, b);
            let (w0, d0) = edge_w(0.0, c);
            let (w1, d1) = edge_w(1.0, c);
            let (wh, _) = edge_w(0.5, c);
            assert!((w0 - a).abs() < 1e-12 && (w1 - b).abs() < 1e-12 && (wh - 1.0).abs() < 1e-12);
            assert!(d0.abs() < 1e-12 && d1.abs() < 1e-12);
        }
        assert_eq!(edge_quartic(1.0, 1.0), [1.0, 0.0, 0.0, 0.0]);
    }

    /// `max_weight` (computed once by `new`) is `max_adj^q` on each of `pow`'s branches.
    #[test]
    fn max_weight_is_max_adj_to_the_q() {
        for (max_adj, alpha, max_alpha) in [(12.0, 5.0, 5.0), (12.0, 1.0, 2.0), (7.0, 3.0, 10.0)] {
            let ws = WeightScale::new(max_adj, alpha, max_alpha);
            let want = match ws.q {
                1.0 => max_adj,
                0.5 => max_adj.sqrt(),
                q => max_adj.powf(q),
            };
            assert_eq!(
                ws.max_weight().to_bits(),
                want.to_bits(),
                "{max_adj} {alpha}"
            );
            assert_eq!(ws.apply(2.0).0, want);
        }
    }

    #[test]
    fn weights_stay_in_bounds() {
        let ws = WeightScale::new(6.0, 50.0, 100.0);
        for raw in [-1.0, 0.0, 0.1, 0.5, 0.99, 1.0, 1.5, f64::NAN] {
            let (w, _) = ws.apply(raw);
            assert!((1.0..=ws.max_weight()).contains(&w), "w({raw}) = {w}");
        }
    }
}
