//! The triangle kernels of `primitives::lanes` (AVX): `Triangle::term`, `value` and
//! `value_slope` of four triangles at once.

use super::avx::{F, V, apply};
use crate::geometry::closest::DEGENERATE;
use crate::primitives::kinds::{Primitive, Slope, Term, Triangle};
use crate::primitives::weights::{self, WeightScale};
use glam::DVec3;

// Features as small integers (f64 lanes), in the caller's names after `REMAP`.
const FA: f64 = 0.0;
const FB: f64 = 1.0;
const FC: f64 = 2.0;
const FAB: f64 = 3.0;
const FAC: f64 = 4.0;
const FBC: f64 = 5.0;
const FF: f64 = 6.0;
/// The feature of a solve rotated by `order` (0, 1, 2), in the caller's names
/// (`geometry::closest::closest_on_triangle_ordered`).
const REMAP: [[f64; 7]; 3] = [
    [FA, FB, FC, FAB, FAC, FBC, FF],
    [FB, FC, FA, FBC, FAB, FAC, FF],
    [FC, FA, FB, FAC, FBC, FAB, FF],
];

/// Four triangles' closest points to `x`, lane by lane.
struct Closest {
    /// Vertices in the caller's order.
    a: V,
    b: V,
    c: V,
    /// `x - point` and its length.
    v: V,
    d: F,
    /// Barycentrics of `b` and `c` in the caller's order, and the feature.
    s: F,
    t: F,
    feat: F,
    /// Lanes the scalar path must redo (degenerate, or a face solve not finite).
    scalar: [bool; 4],
}

/// The triangles' coefficient rows (`weights::triangle_k`), lane by lane.
#[inline(always)]
fn coefficients(tris: &[Triangle]) -> [F; 13] {
    let n = tris.len();
    let mut kk = [[0.0; 4]; 13];
    let mut buf = [0.0; 13];
    for l in 0..4 {
        let t = &tris[l.min(n - 1)];
        let k = weights::triangle_k(t.row, t.vmax, t.emax, &mut buf);
        for j in 0..13 {
            kk[j][l] = k[j];
        }
    }
    let mut k = [F::splat(0.0); 13];
    for j in 0..13 {
        k[j] = F::load(&kk[j]);
    }
    k
}

/// `geometry::closest::closest_on_triangle_ordered` for 1 ..= 4 triangles (the last
/// repeated in unused lanes): `closest_from_largest_angle` with every region's test
/// and candidate computed and the first region that holds kept, in the order of its
/// `if`s.
#[inline(always)]
fn closest(tris: &[Triangle], x: DVec3) -> Closest {
    let n = tris.len();
    let mut vx = [[[0.0; 4]; 3]; 3];
    let mut ord = [0usize; 4];
    for l in 0..4 {
        let t = &tris[l.min(n - 1)];
        let vs = [t.a, t.b, t.c];
        let r = (t.order as usize).min(2);
        ord[l] = r;
        let rot = [vs[r], vs[(r + 1) % 3], vs[(r + 2) % 3]];
        for (j, v) in rot.iter().enumerate() {
            for k in 0..3 {
                vx[j][k][l] = v[k] as f64;
            }
        }
    }
    // Rotated so that `a` has the largest angle.
    let (a, b, c) = (V::load(&vx[0]), V::load(&vx[1]), V::load(&vx[2]));
    let xv = V::splat(x);
    let (zero, one) = (F::splat(0.0), F::splat(1.0));
    let ab = b - a;
    let ac = c - a;
    let ap = xv - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    let bp = xv - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    let vc = d1 * d4 - d3 * d2;
    let cp = xv - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    let vb = d5 * d2 - d1 * d6;
    let va = d3 * d6 - d5 * d4;
    let r_a = d1.le(zero).and(d2.le(zero));
    let r_b = d3.ge(zero).and(d4.le(d3));
    let r_ab = vc.le(zero).and(d1.ge(zero)).and(d3.le(zero));
    let r_c = d6.ge(zero).and(d5.le(d6));
    let r_ac = vb.le(zero).and(d2.ge(zero)).and(d6.le(zero));
    let (d43, d56) = (d4 - d3, d5 - d6);
    let r_bc = va.le(zero).and(d43.ge(zero)).and(d56.ge(zero));
    // The face, then each region from the last test to the first, so that the
    // first that holds is kept. `u` is the weight of `a` (`weights_of`).
    let denom = one / (va + vb + vc);
    let fv = vb * denom;
    let fw = vc * denom;
    let mut p = a + ab * fv + ac * fw;
    let (mut s, mut t, mut u) = (fv, fw, one - fv - fw);
    let mut feat = F::splat(FF);
    macro_rules! region {
        ($m:expr, $pm:expr, ($sm:expr, $tm:expr, $um:expr), $f:expr) => {{
            let m = $m;
            p = m.sel3($pm, p);
            s = m.sel($sm, s);
            t = m.sel($tm, t);
            u = m.sel($um, u);
            feat = m.sel(F::splat($f), feat);
        }};
    }
    let w = d43 / (d43 + d56);
    region!(r_bc, b + w * (c - b), (one - w, w, zero), FBC);
    let w = d2 / (d2 - d6);
    region!(r_ac, a + w * ac, (zero, w, one - w), FAC);
    region!(r_c, c, (zero, one, zero), FC);
    let v = d1 / (d1 - d3);
    region!(r_ab, a + v * ab, (v, zero, one - v), FAB);
    region!(r_b, b, (one, zero, zero), FB);
    region!(r_a, a, (zero, zero, one), FA);
    let any = r_a.or(r_b).or(r_ab.or(r_c)).or(r_ac.or(r_bc)).store();
    let (fv, fw) = (fv.store(), fw.store());
    // Back to the caller's order: (u, s, t) weigh the rotated (a, b, c).
    let (u, s, t, feat) = (u.store(), s.store(), t.store(), feat.store());
    let (mut ss, mut tt, mut ff) = ([0.0; 4], [0.0; 4], [0.0; 4]);
    let mut scalar = [false; 4];
    let mut unrot = [[[0.0; 4]; 3]; 3];
    for l in 0..4 {
        (ss[l], tt[l]) = match ord[l] {
            1 => (u[l], s[l]),
            2 => (t[l], u[l]),
            _ => (s[l], t[l]),
        };
        ff[l] = REMAP[ord[l]][feat[l] as usize];
        let tri = &tris[l.min(n - 1)];
        let face_bad = any[l].to_bits() == 0 && !(fv[l].is_finite() && fw[l].is_finite());
        scalar[l] = tri.order == DEGENERATE || face_bad;
        for (j, v) in [tri.a, tri.b, tri.c].iter().enumerate() {
            for k in 0..3 {
                unrot[j][k][l] = v[k] as f64;
            }
        }
    }
    let v = xv - p;
    Closest {
        a: V::load(&unrot[0]),
        b: V::load(&unrot[1]),
        c: V::load(&unrot[2]),
        d: v.dot(v).sqrt(),
        v,
        s: F::load(&ss),
        t: F::load(&tt),
        feat: F::load(&ff),
        scalar,
    }
}

/// `weights::triangle_bary_gradients` on each lane's feature (zero on vertices).
/// Each lane divides only the vector its feature needs, by the same divisor as the
/// scalar code.
#[inline(always)]
fn bary_gradients(cl: &Closest) -> (V, V) {
    let (zero, one) = (F::splat(0.0), F::splat(1.0));
    let zv = V {
        x: zero,
        y: zero,
        z: zero,
    };
    let e1 = cl.b - cl.a;
    let e2 = cl.c - cl.a;
    let (l11, l22) = (e1.dot(e1), e2.dot(e2));
    let p1 = e1 - e2 * (e1.dot(e2) / l22);
    let p2 = e2 - e1 * (e2.dot(e1) / l11);
    let bc = e2 - e1;
    let bc2 = bc.dot(bc);
    let (m_f, m_ab, m_ac, m_bc) = (
        cl.feat.eq(F::splat(FF)),
        cl.feat.eq(F::splat(FAB)),
        cl.feat.eq(F::splat(FAC)),
        cl.feat.eq(F::splat(FBC)),
    );
    let gs_num = m_f.sel3(p1, m_ab.sel3(e1, m_bc.sel3(-bc, zv)));
    let gs_den = m_f.sel(p1.dot(p1), m_ab.sel(l11, m_bc.sel(bc2, one)));
    let gt_num = m_f.sel3(p2, m_ac.sel3(e2, m_bc.sel3(bc, zv)));
    let gt_den = m_f.sel(p2.dot(p2), m_ac.sel(l22, m_bc.sel(bc2, one)));
    (gs_num / gs_den, gt_num / gt_den)
}

/// `Triangle::term`, lane by lane.
#[target_feature(enable = "avx")]
pub(super) fn terms(tris: &[Triangle], x: DVec3, scale: &WeightScale, out: &mut [Term; 4]) {
    let cl = closest(tris, x);
    let k = coefficients(tris);
    let (raw, ws, wt) = w_grad(cl.s, cl.t, &k);
    let (w, dw) = apply(scale, raw);
    let (gs, gt) = bary_gradients(&cl);
    let zero = F::splat(0.0);
    let zv = V {
        x: zero,
        y: zero,
        z: zero,
    };
    let grad_w = dw.ne(zero).sel3(dw * (ws * gs + wt * gt), zv);
    let dir = cl.d.gt(zero).sel3(cl.v / cl.d, zv);
    let (d, w) = (cl.d.store(), w.store());
    for (l, tri) in tris.iter().enumerate() {
        out[l] = if cl.scalar[l] {
            tri.term(x, scale)
        } else {
            Term {
                d: d[l],
                dir: dir.lane(l),
                w: w[l],
                grad_w: grad_w.lane(l),
            }
        };
    }
}

/// `Triangle::value`, lane by lane.
#[target_feature(enable = "avx")]
pub(super) fn values(tris: &[Triangle], x: DVec3, scale: &WeightScale, out: &mut [(f64, f64); 4]) {
    let cl = closest(tris, x);
    let k = coefficients(tris);
    let (w, _) = apply(scale, w_value(cl.s, cl.t, &k));
    let (d, w) = (cl.d.store(), w.store());
    for (l, tri) in tris.iter().enumerate() {
        out[l] = if cl.scalar[l] {
            tri.value(x, scale)
        } else {
            (d[l], w[l])
        };
    }
}

/// `Triangle::value_slope`, lane by lane.
#[target_feature(enable = "avx")]
pub(super) fn value_slopes(
    tris: &[Triangle],
    x: DVec3,
    u: DVec3,
    scale: &WeightScale,
    out: &mut [Slope; 4],
) {
    let cl = closest(tris, x);
    let k = coefficients(tris);
    let (gs, gt) = bary_gradients(&cl);
    let uv = V::splat(u);
    let (raw, draw) = w_directional(cl.s, cl.t, gs.dot(uv), gt.dot(uv), &k);
    let (w, dw) = apply(scale, raw);
    let zero = F::splat(0.0);
    let a = cl.d.gt(zero).sel(cl.v.dot(uv) / cl.d, zero);
    let l_w = dw * draw / w;
    let (d, w, a, l_w) = (cl.d.store(), w.store(), a.store(), l_w.store());
    for (l, tri) in tris.iter().enumerate() {
        out[l] = if cl.scalar[l] {
            tri.value_slope(x, u, scale)
        } else {
            (d[l], w[l], a[l], l_w[l])
        };
    }
}

/// `weights::triangle_w_value`, lane by lane.
#[inline(always)]
fn w_value(s: F, t: F, k: &[F; 13]) -> F {
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

/// `weights::triangle_w_directional`, lane by lane.
#[inline(always)]
fn w_directional(s: F, t: F, ds: F, dt: F, k: &[F; 13]) -> (F, F) {
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

/// `f` and `df` of `weights::triangle_w_grad`.
#[inline(always)]
fn f(x: F, k: &[F; 13]) -> F {
    x * x * (k[1] + x * (k[2] + x * (k[3] + x * (k[5] + x * (k[7] + x * k[10])))))
}
#[inline(always)]
fn df(x: F, k: &[F; 13]) -> F {
    x * (2.0 * k[1]
        + x * (3.0 * k[2]
            + x * (4.0 * k[3] + x * (5.0 * k[5] + x * (6.0 * k[7] + x * 7.0 * k[10])))))
}

/// `weights::triangle_w_grad`, lane by lane.
#[inline(always)]
fn w_grad(s: F, t: F, k: &[F; 13]) -> (F, F, F) {
    let (s2, t2, st) = (s * s, t * t, s * t);
    let q = s2 * t2;
    let h = k[4]
        + k[6] * (s + t)
        + k[8] * (s2 + t2)
        + k[9] * st
        + k[11] * (s2 * s + t2 * t)
        + k[12] * st * (s + t);
    let common = k[6] + 2.0 * k[12] * st;
    let hs = common + 2.0 * k[8] * s + k[9] * t + 3.0 * k[11] * s2 + k[12] * t2;
    let ht = common + 2.0 * k[8] * t + k[9] * s + 3.0 * k[11] * t2 + k[12] * s2;
    let w = k[0] + f(s, k) + f(t, k) + q * h;
    let ws = df(s, k) + 2.0 * s * t2 * h + q * hs;
    let wt = df(t, k) + 2.0 * t * s2 * h + q * ht;
    (w, ws, wt)
}
