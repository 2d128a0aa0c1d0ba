//! The arithmetic of a query group ([`super::batch`]) over its [`GROUP`] lanes, written
//! as loops over fixed-size arrays that the compiler vectorizes: with AVX2 and FMA when
//! the processor has them (checked once per group at run time), else with the baseline
//! instructions.
//!
//! - Far fields ([`super::expansion::FarPoly`]) at every lane, in f32 about the group's
//!   first query (so the precision is that of the distances, not of the coordinates).
//!   `1 / |r|` comes from the `rsqrt` estimate and one Newton step
//!   `y (3 - d2 y^2) / 2` on AVX2 (relative error below 1e-6 instead of 2^-12; a far
//!   field's terms carry `|r|^-2` to `|r|^-4`, so each is off by a few 1e-6 of itself,
//!   far below the truncation error), and from `1 / sqrt` elsewhere.
//! - Leaves near the group: the same far field where a lane's own query meets the
//!   criterion `R^2 < beta^2 |r|^2`, and the lanes where it does not are listed with the
//!   leaf's triangles for the exact solid angles.
//! - Exact solid angles ([`super::exact::solid_angle`]) over a list of (lane, triangle)
//!   pairs, in f64 with [`atan2`]: Cephes' `atan` (Moshier, a
//!   rational approximation on `[0, 0.66]`, relative error about 1e-16) after the
//!   reduction to `[0, 1]` by `min / max` and `(a - 1) / (a + 1)` above 0.66 (one
//!   division for both).
//!
//! The results depend only on the order of the lists and on the instruction set, never
//! on the thread count.

use super::expansion::{FarField, FarPoly};
use crate::primitives::Triangle;
use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// Queries per group.
pub const GROUP: usize = 32;

/// A group's queries, structure of arrays, and their sums.
#[derive(Clone, Copy)]
pub struct Lanes {
    pub x: [f64; GROUP],
    pub y: [f64; GROUP],
    pub z: [f64; GROUP],
    /// The queries about `origin` (the first one) in f32, for the far fields.
    pub origin: DVec3,
    pub fx: [f32; GROUP],
    pub fy: [f32; GROUP],
    pub fz: [f32; GROUP],
    /// Far fields summed so far (f32, in [`far_fields`]).
    pub far: [f32; GROUP],
    /// Solid angles summed so far (f64, in [`solid_angles`]).
    pub angles: [f64; GROUP],
}

impl Default for Lanes {
    fn default() -> Self {
        Lanes {
            x: [0.0; GROUP],
            y: [0.0; GROUP],
            z: [0.0; GROUP],
            origin: DVec3::ZERO,
            fx: [0.0; GROUP],
            fy: [0.0; GROUP],
            fz: [0.0; GROUP],
            far: [0.0; GROUP],
            angles: [0.0; GROUP],
        }
    }
}

impl Lanes {
    /// Lanes for `points` (at most [`GROUP`]); unused lanes repeat the first point.
    pub fn new(points: impl ExactSizeIterator<Item = DVec3> + Clone) -> Lanes {
        let mut l = Lanes::default();
        let n = points.len();
        debug_assert!((1..=GROUP).contains(&n));
        for (k, p) in points.clone().enumerate() {
            (l.x[k], l.y[k], l.z[k]) = (p.x, p.y, p.z);
        }
        for k in n..GROUP {
            (l.x[k], l.y[k], l.z[k]) = (l.x[0], l.y[0], l.z[0]);
        }
        l.origin = l.get(0);
        for k in 0..GROUP {
            let r = l.get(k) - l.origin;
            (l.fx[k], l.fy[k], l.fz[k]) = (r.x as f32, r.y as f32, r.z as f32);
        }
        l
    }

    pub fn get(&self, k: usize) -> DVec3 {
        DVec3::new(self.x[k], self.y[k], self.z[k])
    }

    /// The winding number of lane `k`.
    pub fn sum(&self, k: usize) -> f64 {
        self.far[k] as f64 + self.angles[k] / (4.0 * PI)
    }
}

/// Whether the processor has AVX2 and FMA (the standard library caches the answer).
#[inline]
pub fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// Adds the far fields `list` (indices into `far` and `poly`) at every lane to
/// `lanes.far`.
pub fn far_fields(far: &[FarField], poly: &[FarPoly], list: &[u32], lanes: &mut Lanes) {
    #[cfg(target_arch = "x86_64")]
    if has_avx2() {
        // SAFETY: the processor supports the features the function is compiled for.
        return unsafe { far_fields_avx2(far, poly, list, lanes) };
    }
    far_fields_base(far, poly, list, lanes)
}

fn far_fields_base(far: &[FarField], poly: &[FarPoly], list: &[u32], lanes: &mut Lanes) {
    let mut none = [false; GROUP];
    for &i in list {
        let (f, p) = (&far[i as usize], &poly[i as usize]);
        far_lanes::<false, false>(f, p, lanes, 0.0, &mut none);
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn far_fields_avx2(far: &[FarField], poly: &[FarPoly], list: &[u32], lanes: &mut Lanes) {
    let mut none = [false; GROUP];
    for &i in list {
        let (f, p) = (&far[i as usize], &poly[i as usize]);
        far_lanes::<true, false>(f, p, lanes, 0.0, &mut none);
    }
}

/// The leaves `list` near the group: each lane adds a leaf's far field where its own
/// query meets `r2 < beta2 d2`; the others are appended to `pairs` as (lane, triangle
/// index into `prims`) for [`solid_angles`].
#[allow(clippy::too_many_arguments)]
pub fn near_leaves(
    far: &[FarField],
    poly: &[FarPoly],
    ranges: impl Iterator<Item = (u32, std::ops::Range<u32>)>,
    beta2: f64,
    lanes: &mut Lanes,
    used: usize,
    pairs: &mut Vec<(u32, u32)>,
) {
    let beta2 = beta2 as f32;
    let avx2 = has_avx2();
    let mut exact = [false; GROUP];
    for (i, tris) in ranges {
        let (f, p) = (&far[i as usize], &poly[i as usize]);
        #[cfg(target_arch = "x86_64")]
        let any = if avx2 {
            // SAFETY: the processor supports the features the function is compiled for.
            unsafe { far_leaf_avx2(f, p, lanes, beta2, &mut exact) }
        } else {
            far_lanes::<false, true>(f, p, lanes, beta2, &mut exact)
        };
        #[cfg(not(target_arch = "x86_64"))]
        let any = {
            let _ = avx2;
            far_lanes::<false, true>(f, p, lanes, beta2, &mut exact)
        };
        if any {
            for k in (0..used).filter(|&k| exact[k]) {
                pairs.extend(tris.clone().map(|t| (k as u32, t)));
            }
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn far_leaf_avx2(
    f: &FarField,
    p: &FarPoly,
    lanes: &mut Lanes,
    beta2: f32,
    exact: &mut [bool; GROUP],
) -> bool {
    far_lanes::<true, true>(f, p, lanes, beta2, exact)
}

/// `a b + c`, fused when `FMA`.
#[inline(always)]
fn fma<const FMA: bool>(a: f32, b: f32, c: f32) -> f32 {
    if FMA { a.mul_add(b, c) } else { a * b + c }
}

/// `1 / |c - q_k|` for every lane (`|r|^2` floored at the smallest normal f32).
// One index over the lanes' arrays is the form the vectorizer takes.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn inverse_distances<const AVX2: bool>(c: [f32; 3], lanes: &Lanes, s: &mut [f32; GROUP]) {
    #[cfg(target_arch = "x86_64")]
    if AVX2 {
        // SAFETY: AVX2 is only set by the callers compiled for AVX2 and FMA, which run
        // after the run-time check.
        unsafe { inverse_distances_avx2(c, lanes, s) };
        return;
    }
    for k in 0..GROUP {
        let (rx, ry, rz) = (c[0] - lanes.fx[k], c[1] - lanes.fy[k], c[2] - lanes.fz[k]);
        let d2 = (rx * rx + ry * ry + rz * rz).max(f32::MIN_POSITIVE);
        s[k] = 1.0 / d2.sqrt();
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
fn inverse_distances_avx2(c: [f32; 3], lanes: &Lanes, s: &mut [f32; GROUP]) {
    use std::arch::x86_64::*;
    let (cx, cy, cz) = (
        _mm256_set1_ps(c[0]),
        _mm256_set1_ps(c[1]),
        _mm256_set1_ps(c[2]),
    );
    let (half, three, tiny) = (
        _mm256_set1_ps(0.5),
        _mm256_set1_ps(3.0),
        _mm256_set1_ps(f32::MIN_POSITIVE),
    );
    for j in (0..GROUP).step_by(8) {
        // SAFETY: j + 8 <= GROUP, in bounds of every array.
        unsafe {
            let rx = _mm256_sub_ps(cx, _mm256_loadu_ps(lanes.fx.as_ptr().add(j)));
            let ry = _mm256_sub_ps(cy, _mm256_loadu_ps(lanes.fy.as_ptr().add(j)));
            let rz = _mm256_sub_ps(cz, _mm256_loadu_ps(lanes.fz.as_ptr().add(j)));
            let d2 = _mm256_fmadd_ps(rx, rx, _mm256_fmadd_ps(ry, ry, _mm256_mul_ps(rz, rz)));
            let d2 = _mm256_max_ps(d2, tiny);
            let y = _mm256_rsqrt_ps(d2);
            // y (3 - d2 y^2) / 2
            let t = _mm256_fnmadd_ps(_mm256_mul_ps(d2, y), y, three);
            let y = _mm256_mul_ps(_mm256_mul_ps(half, y), t);
            _mm256_storeu_ps(s.as_mut_ptr().add(j), y);
        }
    }
}

/// Adds the far field `f` (as the polynomials `p`, [`FarPoly`]) at the lanes to
/// `lanes.far`: at every lane, or when `MASKED` only where `f.r2 < beta2 |r|^2`, marking
/// the others in `exact` and saying whether there are any.
// One index over the lanes' arrays is the form the vectorizer takes.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn far_lanes<const AVX2: bool, const MASKED: bool>(
    f: &FarField,
    p: &FarPoly,
    lanes: &mut Lanes,
    beta2: f32,
    exact: &mut [bool; GROUP],
) -> bool {
    let c = f.centre() - lanes.origin;
    let c = [c.x as f32, c.y as f32, c.z as f32];
    let mut s = [0.0f32; GROUP];
    inverse_distances::<AVX2>(c, lanes, &mut s);
    let scale = (1.0 / (4.0 * PI)) as f32;
    let r2 = f.r2;
    let fm = fma::<AVX2>;
    for k in 0..GROUP {
        let (rx, ry, rz) = (c[0] - lanes.fx[k], c[1] - lanes.fy[k], c[2] - lanes.fz[k]);
        let s = s[k];
        let (x, y, z) = (rx * s, ry * s, rz * s);
        let (xx, xy, xz, yy, yz, zz) = (x * x, x * y, x * z, y * y, y * z, z * z);
        let order0 = fm(p.n[0], x, fm(p.n[1], y, p.n[2] * z));
        let a = &p.a;
        let order1 = fm(
            a[0],
            xx,
            fm(
                a[1],
                xy,
                fm(a[2], xz, fm(a[3], yy, fm(a[4], yz, fm(a[5], zz, p.trace)))),
            ),
        );
        let c3 = &p.cubic;
        let qx = fm(
            c3[0],
            xx,
            fm(
                c3[1],
                xy,
                fm(c3[2], xz, fm(c3[3], yy, fm(c3[4], yz, c3[5] * zz))),
            ),
        );
        let qy = fm(c3[6], yy, fm(c3[7], yz, c3[8] * zz));
        let cubic = fm(x, qx, fm(y, qy, c3[9] * zz * z));
        let order2 = fm(p.g[0], x, fm(p.g[1], y, fm(p.g[2], z, cubic)));
        let v = s * s * scale * fm(s, fm(s, order2, order1), order0);
        if MASKED {
            let d2 = fm(rx, rx, fm(ry, ry, rz * rz));
            let far = r2 < beta2 * d2;
            exact[k] = !far;
            lanes.far[k] += if far { v } else { 0.0 };
        } else {
            lanes.far[k] += v;
        }
    }
    MASKED && exact.iter().any(|&e| e)
}

/// Solid angles computed together.
const BLOCK: usize = 64;

/// Adds the solid angles of the (lane, triangle) `pairs` to `lanes.angles`, in the
/// order of the list.
pub fn solid_angles(prims: &[Triangle], pairs: &[(u32, u32)], lanes: &mut Lanes) {
    #[cfg(target_arch = "x86_64")]
    if has_avx2() {
        // SAFETY: the processor supports the features the function is compiled for.
        return unsafe { solid_angles_avx2(prims, pairs, lanes) };
    }
    solid_angles_in(prims, pairs, lanes)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn solid_angles_avx2(prims: &[Triangle], pairs: &[(u32, u32)], lanes: &mut Lanes) {
    solid_angles_in(prims, pairs, lanes)
}

/// The corners of every pair's triangle relative to its query (a gather), then
/// [`super::exact::solid_angle`], [`BLOCK`] pairs at a time, one loop per step so that
/// each vectorizes.
#[inline(always)]
fn solid_angles_in(prims: &[Triangle], pairs: &[(u32, u32)], lanes: &mut Lanes) {
    for block in pairs.chunks(BLOCK) {
        let n = block.len();
        let mut rel = [[0.0f64; BLOCK]; 9];
        for (j, &(k, t)) in block.iter().enumerate() {
            let q = lanes.get(k as usize);
            let t = &prims[t as usize];
            for (c, corner) in [t.a, t.b, t.c].into_iter().enumerate() {
                let r = corner.as_dvec3() - q;
                (rel[3 * c][j], rel[3 * c + 1][j], rel[3 * c + 2][j]) = (r.x, r.y, r.z);
            }
        }
        let mut omega = [0.0f64; BLOCK];
        let [ax, ay, az, bx, by, bz, cx, cy, cz] = &rel;
        for j in 0..n {
            let (a, b, c) = (
                [ax[j], ay[j], az[j]],
                [bx[j], by[j], bz[j]],
                [cx[j], cy[j], cz[j]],
            );
            let dot = |u: [f64; 3], w: [f64; 3]| u[0] * w[0] + u[1] * w[1] + u[2] * w[2];
            let (la, lb, lc) = (dot(a, a).sqrt(), dot(b, b).sqrt(), dot(c, c).sqrt());
            let bc = [
                b[1] * c[2] - b[2] * c[1],
                b[2] * c[0] - b[0] * c[2],
                b[0] * c[1] - b[1] * c[0],
            ];
            let num = dot(a, bc);
            let den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
            omega[j] = 2.0 * atan2(num, den);
        }
        for (&(k, _), w) in block.iter().zip(&omega) {
            lanes.angles[k as usize] += w;
        }
    }
}

/// `atan2(y, x)` in a form the vectorizer takes (selects, no branches), within a few
/// 1e-16 of the standard library's; `(+-0, +-0)` gives `+-0` (a query on a vertex
/// counts nothing, as in [`super::exact::solid_angle`]).
#[inline(always)]
pub fn atan2(y: f64, x: f64) -> f64 {
    // Cephes atan.c (Moshier): atan(t) = t + t z P(z) / Q(z), z = t^2, on [0, 0.66].
    const P: [f64; 5] = [
        -8.750_608_600_031_904e-1,
        -1.615_753_718_733_365e1,
        -7.500_855_792_314_705e1,
        -1.228_866_684_490_136_2e2,
        -6.485_021_904_942_025e1,
    ];
    const Q: [f64; 5] = [
        2.485_846_490_142_306_4e1,
        1.650_270_098_316_988_6e2,
        4.328_810_604_912_903e2,
        4.853_903_996_359_137e2,
        1.945_506_571_482_614e2,
    ];
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = (ax.min(ay), ax.max(ay));
    // atan(lo / hi) in [0, pi/4]; above 0.66 as pi/4 + atan((lo - hi) / (lo + hi)).
    let upper = lo > 0.66 * hi;
    let (n, d) = if upper { (lo - hi, lo + hi) } else { (lo, hi) };
    let t = if d > 0.0 { n / d } else { 0.0 };
    let z = t * t;
    let p = (((P[0] * z + P[1]) * z + P[2]) * z + P[3]) * z + P[4];
    let q = ((((z + Q[0]) * z + Q[1]) * z + Q[2]) * z + Q[3]) * z + Q[4];
    let mut r = t + t * z * p / q + if upper { FRAC_PI_4 } else { 0.0 };
    if ay > ax {
        r = FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    r.copysign(y)
}

#[cfg(test)]
mod tests {
    use super::super::exact::solid_angle;
    use super::*;

    /// The solid angle of one (lane, triangle) pair as [`solid_angles`] computes it, for the
    /// tests.
    fn pair_angle(prims: &[Triangle], pair: (u32, u32), lanes: &Lanes) -> f64 {
        let mut l = *lanes;
        l.angles = [0.0; GROUP];
        solid_angles(prims, &[pair], &mut l);
        l.angles[pair.0 as usize]
    }

    /// [`super::exact::solid_angle`] of a leaf's triangle at a lane, the scalar reference.
    fn pair_angle_reference(prims: &[Triangle], pair: (u32, u32), lanes: &Lanes) -> f64 {
        let t = &prims[pair.1 as usize];
        solid_angle(
            lanes.get(pair.0 as usize),
            t.a.as_dvec3(),
            t.b.as_dvec3(),
            t.c.as_dvec3(),
        )
    }

    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn atan2_matches_the_standard_library() {
        let mut seed = 7;
        let mut worst = 0.0f64;
        for i in 0..200_000 {
            let scale = 10f64.powi(i % 13 - 6);
            let y = (lcg(&mut seed) - 0.5) * scale;
            let x = (lcg(&mut seed) - 0.5) * if i % 3 == 0 { scale * 1e-3 } else { scale };
            let (a, b) = (atan2(y, x), y.atan2(x));
            worst = worst.max((a - b).abs());
            assert!(
                (a - b).abs() <= 4e-16 * b.abs().max(1.0),
                "atan2({y}, {x}): {a} vs {b}"
            );
        }
        for (y, x) in [
            (0.0, 1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (1.0, 1.0),
            (-1.0, -1.0),
            (1e-300, -1.0),
            (1.0, 1e300),
            (3.0, -3.0),
        ] {
            let (a, b) = (atan2(y, x), f64::atan2(y, x));
            assert!((a - b).abs() <= 4e-16, "atan2({y}, {x}): {a} vs {b}");
        }
        assert_eq!(atan2(0.0, 0.0), 0.0);
        assert_eq!(atan2(0.0, -0.0), 0.0);
        eprintln!("largest difference {worst:e}");
    }

    #[test]
    #[allow(clippy::needless_range_loop)]
    fn solid_angles_in_chunks_equal_the_scalar_ones() {
        let mut seed = 3;
        let mut p = || glam::Vec3::new(lcg(&mut seed) as f32, lcg(&mut seed) as f32, 0.0);
        let prims: Vec<Triangle> = (0..20)
            .map(|_| {
                Triangle::new(
                    p(),
                    p() + glam::Vec3::Z * 0.3,
                    p() - glam::Vec3::Z * 0.2,
                    1.0,
                    1.0,
                )
            })
            .collect();
        let mut seed = 9;
        let pts: Vec<DVec3> = (0..GROUP)
            .map(|_| DVec3::new(lcg(&mut seed), lcg(&mut seed), lcg(&mut seed) - 0.5))
            .collect();
        let mut lanes = Lanes::new(pts.iter().copied());
        // A query on a vertex counts nothing.
        lanes.x[5] = prims[2].a.x as f64;
        lanes.y[5] = prims[2].a.y as f64;
        lanes.z[5] = prims[2].a.z as f64;
        let pairs: Vec<(u32, u32)> = (0..GROUP as u32)
            .flat_map(|k| (0..20).map(move |t| (k, (t * 7 + k) % 20)))
            .collect();
        let mut want = [0.0f64; GROUP];
        for &pair in &pairs {
            let a = pair_angle(&prims, pair, &lanes);
            let b = pair_angle_reference(&prims, pair, &lanes);
            assert!((a - b).abs() < 1e-14, "{pair:?}: {a} vs {b}");
            want[pair.0 as usize] += b;
        }
        assert_eq!(pair_angle(&prims, (5, 2), &lanes), 0.0);
        solid_angles(&prims, &pairs[..pairs.len() - 3], &mut lanes);
        for &pair in &pairs[pairs.len() - 3..] {
            want[pair.0 as usize] -= pair_angle_reference(&prims, pair, &lanes);
        }
        for k in 0..GROUP {
            let (a, b) = (lanes.angles[k], want[k]);
            assert!((a - b).abs() < 1e-12, "lane {k}: {a} vs {b}");
        }
    }
}
