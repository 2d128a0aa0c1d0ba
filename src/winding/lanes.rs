//! The arithmetic of a query group ([`super::batch`]) over its [`GROUP`] lanes: with
//! AVX2 and FMA intrinsics when the processor has them (checked at run time), else as
//! loops over fixed-size arrays in the baseline instructions.
//!
//! - Far fields ([`FarNode`]: a node's centre, squared radius and the polynomial
//!   coefficients of [`super::expansion::FarPoly`] times `1 / (4 pi)`, in two aligned
//!   cache lines) at every lane, in f32 about the group's first query (so the precision
//!   is that of the distances, not of the coordinates). On AVX2 eight lanes at a time,
//!   two such chunks per pass over the group's list: the lanes' coordinates and sums stay
//!   in registers and each node's coefficients are broadcast from memory (the
//!   compiler's own vectorization of all 32 lanes at once spilled its registers).
//!   `1 / |r|` comes from the `rsqrt` estimate and one Newton step `y (3 - d2 y^2) / 2`
//!   on AVX2 (relative error below 1e-6 instead of 2^-12; a far field's terms carry
//!   `|r|^-2` to `|r|^-4`, so each is off by a few 1e-6 of itself, far below the
//!   truncation error), and from `1 / sqrt` elsewhere.
//! - [`all_far`]: whether every lane's query meets a node's criterion
//!   `R^2 < beta^2 |r|^2` (the walk's second chance for a node the group's box refuses).
//! - Leaves near the group: the same far field where a lane's own query meets the
//!   criterion, and the lanes where it does not are listed with the leaf's triangles for
//!   the exact solid angles.
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

/// A node's far field as the lanes read it: its centre and squared radius (as in
/// [`FarField`]), then the coefficients of [`FarPoly`] times `1 / (4 pi)`: 27 f32 in two
/// aligned cache lines.
#[repr(C, align(64))]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FarNode {
    pub centre: [f32; 3],
    pub r2: f32,
    pub p: FarPoly,
}

impl FarNode {
    /// The lanes' form of the far field `f`.
    pub fn new(f: &FarField) -> FarNode {
        let mut p = FarPoly::new(f);
        let scale = (1.0 / (4.0 * PI)) as f32;
        let coefficients = (p.n.iter_mut().chain(&mut p.a))
            .chain(p.cubic.iter_mut().chain(&mut p.g))
            .chain(std::iter::once(&mut p.trace));
        for x in coefficients {
            *x *= scale;
        }
        FarNode {
            centre: f.centre,
            r2: f.r2,
            p,
        }
    }

    /// The centre in f64.
    #[inline]
    pub fn centre(&self) -> DVec3 {
        glam::Vec3::from_array(self.centre).as_dvec3()
    }

    /// The centre relative to `origin`, in f32.
    #[inline(always)]
    fn relative(&self, origin: DVec3) -> [f32; 3] {
        let c = self.centre;
        [
            (c[0] as f64 - origin.x) as f32,
            (c[1] as f64 - origin.y) as f32,
            (c[2] as f64 - origin.z) as f32,
        ]
    }
}

/// Adds the far fields `list` (indices into `nodes`) at every lane to `lanes.far`.
pub fn far_fields(nodes: &[FarNode], list: &[u32], lanes: &mut Lanes) {
    #[cfg(target_arch = "x86_64")]
    if has_avx2() {
        // SAFETY: the processor supports the features the function is compiled for.
        return unsafe { avx2::far_fields(nodes, list, lanes) };
    }
    far_fields_base(nodes, list, lanes)
}

fn far_fields_base(nodes: &[FarNode], list: &[u32], lanes: &mut Lanes) {
    for &i in list {
        let node = &nodes[i as usize];
        let c = node.relative(lanes.origin);
        for k in 0..GROUP {
            let q = [lanes.fx[k], lanes.fy[k], lanes.fz[k]];
            lanes.far[k] += far_lane(&node.p, c, q).0;
        }
    }
}

/// Whether every lane's query meets the far-field criterion `r2 < beta2 |c - q|^2` of a
/// node with centre `centre` and squared radius `r2` (in f32 about the group's origin,
/// as the far fields are evaluated; `r2` is grown for that rounding). `AVX2` only from
/// code compiled for AVX2 and FMA.
#[inline(always)]
pub fn all_far<const AVX2: bool>(centre: DVec3, r2: f32, beta2: f64, lanes: &Lanes) -> bool {
    let c = centre - lanes.origin;
    // Most nodes fail at the first or the last query already.
    let last = centre - lanes.get(GROUP - 1);
    if (r2 as f64) >= beta2 * c.length_squared().min(last.length_squared()) {
        return false;
    }
    let c = [c.x as f32, c.y as f32, c.z as f32];
    let beta2 = beta2 as f32;
    #[cfg(target_arch = "x86_64")]
    if AVX2 {
        // SAFETY: AVX2 is only set by callers compiled for AVX2 and FMA.
        return unsafe { avx2::all_far(c, r2, beta2, lanes) };
    }
    (0..GROUP).all(|k| {
        let (rx, ry, rz) = (c[0] - lanes.fx[k], c[1] - lanes.fy[k], c[2] - lanes.fz[k]);
        r2 < beta2 * (rx * rx + ry * ry + rz * rz)
    })
}

/// The leaves `ranges` (node index, triangle range) near the group: each lane adds a
/// leaf's far field where its own query meets `r2 < beta2 |r|^2`; the others are
/// appended to `pairs` as (lane, triangle index into `prims`) for [`solid_angles`].
pub fn near_leaves(
    nodes: &[FarNode],
    ranges: impl Iterator<Item = (u32, std::ops::Range<u32>)>,
    beta2: f64,
    lanes: &mut Lanes,
    used: usize,
    pairs: &mut Vec<(u32, u32)>,
) {
    let beta2 = beta2 as f32;
    let avx2 = has_avx2();
    let used_bits = if used >= 32 {
        u32::MAX
    } else {
        (1u32 << used) - 1
    };
    for (i, tris) in ranges {
        let node = &nodes[i as usize];
        #[cfg(target_arch = "x86_64")]
        let far = if avx2 {
            // SAFETY: the processor supports the features the function is compiled for.
            unsafe { avx2::far_leaf(node, lanes, beta2) }
        } else {
            far_leaf_base(node, lanes, beta2)
        };
        #[cfg(not(target_arch = "x86_64"))]
        let far = {
            let _ = avx2;
            far_leaf_base(node, lanes, beta2)
        };
        let mut exact = !far & used_bits;
        while exact != 0 {
            let k = exact.trailing_zeros();
            exact &= exact - 1;
            pairs.extend(tris.clone().map(|t| (k, t)));
        }
    }
}

/// The leaf `node`'s far field at the lanes whose query meets `r2 < beta2 |r|^2`, added
/// to `lanes.far`; those lanes as bits.
fn far_leaf_base(node: &FarNode, lanes: &mut Lanes, beta2: f32) -> u32 {
    let c = node.relative(lanes.origin);
    let mut bits = 0;
    for k in 0..GROUP {
        let q = [lanes.fx[k], lanes.fy[k], lanes.fz[k]];
        let (v, d2) = far_lane(&node.p, c, q);
        if node.r2 < beta2 * d2 {
            lanes.far[k] += v;
            bits |= 1 << k;
        }
    }
    bits
}

/// The far field `p` (a [`FarNode`]'s, centre `c`) at the query `q` (both relative to
/// the group's origin), and `|r|^2`; `|r|^2` is floored at the smallest normal f32 for
/// the inverse.
#[inline(always)]
fn far_lane(p: &FarPoly, c: [f32; 3], q: [f32; 3]) -> (f32, f32) {
    let (rx, ry, rz) = (c[0] - q[0], c[1] - q[1], c[2] - q[2]);
    let d2 = rx * rx + ry * ry + rz * rz;
    let s = 1.0 / d2.max(f32::MIN_POSITIVE).sqrt();
    let (x, y, z) = (rx * s, ry * s, rz * s);
    let (xx, xy, xz, yy, yz, zz) = (x * x, x * y, x * z, y * y, y * z, z * z);
    let order0 = p.n[0] * x + p.n[1] * y + p.n[2] * z;
    let a = &p.a;
    let order1 = a[0] * xx + a[1] * xy + a[2] * xz + a[3] * yy + a[4] * yz + a[5] * zz + p.trace;
    let c3 = &p.cubic;
    let qx = c3[0] * xx + c3[1] * xy + c3[2] * xz + c3[3] * yy + c3[4] * yz + c3[5] * zz;
    let qy = c3[6] * yy + c3[7] * yz + c3[8] * zz;
    let cubic = x * qx + y * qy + c3[9] * zz * z;
    let order2 = p.g[0] * x + p.g[1] * y + p.g[2] * z + cubic;
    (s * s * (s * (s * order2 + order1) + order0), d2)
}

/// The far fields over eight lanes at a time with AVX2 and FMA intrinsics: the lanes'
/// coordinates and sums stay in registers while the nodes' coefficients are broadcast
/// from memory.
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{BLOCK, FarNode, FarPoly, GROUP, Lanes};
    use std::arch::x86_64::*;

    /// [`super::far_fields`].
    #[target_feature(enable = "avx2,fma")]
    pub fn far_fields(nodes: &[FarNode], list: &[u32], lanes: &mut Lanes) {
        let mut rel = [[0.0f32; 3]; BLOCK];
        for block in list.chunks(BLOCK) {
            for (r, &i) in rel.iter_mut().zip(block) {
                *r = nodes[i as usize].relative(lanes.origin);
            }
            // Two chunks of eight lanes per pass: two independent chains per node
            // (one alone is latency-bound).
            for j in (0..GROUP).step_by(16) {
                let (ax, ay, az) = queries(lanes, j);
                let (bx, by, bz) = queries(lanes, j + 8);
                // SAFETY: j + 16 <= GROUP.
                let (mut acc_a, mut acc_b) = unsafe {
                    (
                        _mm256_loadu_ps(lanes.far.as_ptr().add(j)),
                        _mm256_loadu_ps(lanes.far.as_ptr().add(j + 8)),
                    )
                };
                for (c, &i) in rel.iter().zip(block) {
                    let p = &nodes[i as usize].p;
                    acc_a = _mm256_add_ps(acc_a, far8(p, c, ax, ay, az).0);
                    acc_b = _mm256_add_ps(acc_b, far8(p, c, bx, by, bz).0);
                }
                // SAFETY: j + 16 <= GROUP.
                unsafe {
                    _mm256_storeu_ps(lanes.far.as_mut_ptr().add(j), acc_a);
                    _mm256_storeu_ps(lanes.far.as_mut_ptr().add(j + 8), acc_b);
                }
            }
        }
    }

    /// [`super::far_leaf_base`].
    #[target_feature(enable = "avx2,fma")]
    pub fn far_leaf(node: &FarNode, lanes: &mut Lanes, beta2: f32) -> u32 {
        let c = node.relative(lanes.origin);
        let (r2, beta2) = (_mm256_set1_ps(node.r2), _mm256_set1_ps(beta2));
        let mut bits = 0;
        for j in (0..GROUP).step_by(8) {
            let (qx, qy, qz) = queries(lanes, j);
            let (v, d2) = far8(&node.p, &c, qx, qy, qz);
            let far = _mm256_cmp_ps::<_CMP_LT_OQ>(r2, _mm256_mul_ps(beta2, d2));
            // SAFETY: j + 8 <= GROUP.
            unsafe {
                let p = lanes.far.as_mut_ptr().add(j);
                _mm256_storeu_ps(p, _mm256_add_ps(_mm256_loadu_ps(p), _mm256_and_ps(far, v)));
            }
            bits |= (_mm256_movemask_ps(far) as u32) << j;
        }
        bits
    }

    /// [`super::all_far`]'s test at every lane.
    ///
    /// # Safety
    /// Only from functions compiled for AVX2 and FMA.
    #[inline(always)]
    pub unsafe fn all_far(c: [f32; 3], r2: f32, beta2: f32, lanes: &Lanes) -> bool {
        // SAFETY: the caller runs compiled for AVX2 and FMA.
        unsafe {
            let (cx, cy, cz) = (
                _mm256_set1_ps(c[0]),
                _mm256_set1_ps(c[1]),
                _mm256_set1_ps(c[2]),
            );
            let r2 = _mm256_set1_ps(r2);
            let beta2 = _mm256_set1_ps(beta2);
            let mut all = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
            for j in (0..GROUP).step_by(8) {
                let (qx, qy, qz) = queries(lanes, j);
                let (rx, ry, rz) = (
                    _mm256_sub_ps(cx, qx),
                    _mm256_sub_ps(cy, qy),
                    _mm256_sub_ps(cz, qz),
                );
                let d2 = _mm256_fmadd_ps(rx, rx, _mm256_fmadd_ps(ry, ry, _mm256_mul_ps(rz, rz)));
                let far = _mm256_cmp_ps::<_CMP_LT_OQ>(r2, _mm256_mul_ps(beta2, d2));
                all = _mm256_and_ps(all, far);
            }
            _mm256_movemask_ps(all) == 0xff
        }
    }

    /// Lanes `j..j + 8`'s coordinates.
    #[inline(always)]
    fn queries(lanes: &Lanes, j: usize) -> (__m256, __m256, __m256) {
        assert!(j + 8 <= GROUP);
        // SAFETY: in bounds (checked above); the caller is compiled for AVX2.
        unsafe {
            (
                _mm256_loadu_ps(lanes.fx.as_ptr().add(j)),
                _mm256_loadu_ps(lanes.fy.as_ptr().add(j)),
                _mm256_loadu_ps(lanes.fz.as_ptr().add(j)),
            )
        }
    }

    /// [`super::far_lane`] at eight lanes, `1 / |r|` from `rsqrt` and one Newton step
    /// `y (3 - d2 y^2) / 2`.
    #[inline(always)]
    fn far8(p: &FarPoly, c: &[f32; 3], qx: __m256, qy: __m256, qz: __m256) -> (__m256, __m256) {
        // SAFETY: only called from functions compiled for AVX2 and FMA.
        unsafe {
            let b = |x: f32| _mm256_set1_ps(x);
            let (mul, fma) = (
                |a, b| _mm256_mul_ps(a, b),
                |a, b, c| _mm256_fmadd_ps(a, b, c),
            );
            let rx = _mm256_sub_ps(b(c[0]), qx);
            let ry = _mm256_sub_ps(b(c[1]), qy);
            let rz = _mm256_sub_ps(b(c[2]), qz);
            let d2 = fma(rx, rx, fma(ry, ry, mul(rz, rz)));
            let dm = _mm256_max_ps(d2, b(f32::MIN_POSITIVE));
            let y = _mm256_rsqrt_ps(dm);
            let s = mul(mul(b(0.5), y), _mm256_fnmadd_ps(mul(dm, y), y, b(3.0)));
            let (x, y, z) = (mul(rx, s), mul(ry, s), mul(rz, s));
            let (xx, xy, xz) = (mul(x, x), mul(x, y), mul(x, z));
            let (yy, yz, zz) = (mul(y, y), mul(y, z), mul(z, z));
            let order0 = fma(b(p.n[0]), x, fma(b(p.n[1]), y, mul(b(p.n[2]), z)));
            // `c0 xx + c1 xy + c2 xz + c3 yy + c4 yz + c5 zz + tail`, by fused steps.
            let form = |c: &[f32], tail| {
                let q = fma(b(c[3]), yy, fma(b(c[4]), yz, fma(b(c[5]), zz, tail)));
                fma(b(c[0]), xx, fma(b(c[1]), xy, fma(b(c[2]), xz, q)))
            };
            let order1 = form(&p.a, b(p.trace));
            let c3 = &p.cubic;
            let cx = form(&c3[..6], _mm256_setzero_ps());
            let cy = fma(b(c3[6]), yy, fma(b(c3[7]), yz, mul(b(c3[8]), zz)));
            let cubic = fma(x, cx, fma(y, cy, mul(mul(b(c3[9]), zz), z)));
            let order2 = fma(b(p.g[0]), x, fma(b(p.g[1]), y, fma(b(p.g[2]), z, cubic)));
            let v = mul(mul(s, s), fma(s, fma(s, order2, order1), order0));
            (v, d2)
        }
    }
}

/// Solid angles computed together.
const BLOCK: usize = 64;

/// Scratch space of [`solid_angles`]: one block of pairs, the corners relative to their
/// queries (kept between calls, so not cleared for every block).
#[derive(Clone)]
pub struct AngleBlock {
    rel: [[f64; BLOCK]; 9],
    omega: [f64; BLOCK],
}

impl Default for AngleBlock {
    fn default() -> Self {
        AngleBlock {
            rel: [[0.0; BLOCK]; 9],
            omega: [0.0; BLOCK],
        }
    }
}

/// Adds the solid angles of the (lane, triangle) `pairs` to `lanes.angles`, in the
/// order of the list.
pub fn solid_angles(
    prims: &[Triangle],
    pairs: &[(u32, u32)],
    lanes: &mut Lanes,
    block: &mut AngleBlock,
) {
    #[cfg(target_arch = "x86_64")]
    if has_avx2() {
        // SAFETY: the processor supports the features the function is compiled for.
        return unsafe { solid_angles_avx2(prims, pairs, lanes, block) };
    }
    solid_angles_in(prims, pairs, lanes, block)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn solid_angles_avx2(
    prims: &[Triangle],
    pairs: &[(u32, u32)],
    lanes: &mut Lanes,
    block: &mut AngleBlock,
) {
    solid_angles_in(prims, pairs, lanes, block)
}

/// The corners of every pair's triangle relative to its query (a gather), then
/// [`super::exact::solid_angle`], [`BLOCK`] pairs at a time, one loop per step so that
/// each vectorizes.
#[inline(always)]
fn solid_angles_in(
    prims: &[Triangle],
    pairs: &[(u32, u32)],
    lanes: &mut Lanes,
    scratch: &mut AngleBlock,
) {
    let AngleBlock { rel, omega } = scratch;
    for block in pairs.chunks(BLOCK) {
        let n = block.len();
        for (j, &(k, t)) in block.iter().enumerate() {
            let q = lanes.get(k as usize);
            let t = &prims[t as usize];
            for (c, corner) in [t.a, t.b, t.c].into_iter().enumerate() {
                let r = corner.as_dvec3() - q;
                (rel[3 * c][j], rel[3 * c + 1][j], rel[3 * c + 2][j]) = (r.x, r.y, r.z);
            }
        }
        let [ax, ay, az, bx, by, bz, cx, cy, cz] = &*rel;
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
        for (&(k, _), w) in block.iter().zip(omega.iter()) {
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
        solid_angles(prims, &[pair], &mut l, &mut AngleBlock::default());
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
        solid_angles(
            &prims,
            &pairs[..pairs.len() - 3],
            &mut lanes,
            &mut AngleBlock::default(),
        );
        for &pair in &pairs[pairs.len() - 3..] {
            want[pair.0 as usize] -= pair_angle_reference(&prims, pair, &lanes);
        }
        for k in 0..GROUP {
            let (a, b) = (lanes.angles[k], want[k]);
            assert!((a - b).abs() < 1e-12, "lane {k}: {a} vs {b}");
        }
    }

    /// Far fields of random clusters of triangles about `[0.4, 0.4, 0.4]` (radius
    /// about 0.35), and a group of queries in the unit cube shifted by `offset`.
    fn far_nodes_and_lanes(seed: u64, offset: f64) -> (Vec<FarNode>, Vec<FarField>, Lanes) {
        use super::super::expansion::Moments;
        let mut seed = seed;
        let mut nodes = Vec::new();
        let mut fars = Vec::new();
        for _ in 0..40 {
            let centre = DVec3::splat(0.4);
            let mut m = Moments {
                centre,
                ..Moments::default()
            };
            for _ in 0..5 {
                let mut p = || {
                    let r = DVec3::new(lcg(&mut seed), lcg(&mut seed), lcg(&mut seed));
                    centre + (r - 0.5) * 0.4
                };
                m.add(&Moments::triangle(p(), p(), p(), centre));
            }
            let f = m.far_field(0.35f64.powi(2));
            nodes.push(FarNode::new(&f));
            fars.push(f);
        }
        let pts: Vec<DVec3> = (0..GROUP)
            .map(|_| {
                let r = DVec3::new(lcg(&mut seed), lcg(&mut seed), lcg(&mut seed));
                r + DVec3::splat(offset)
            })
            .collect();
        (nodes, fars, Lanes::new(pts.iter().copied()))
    }

    #[test]
    #[allow(clippy::needless_range_loop)]
    fn the_far_fields_over_the_lanes_equal_the_far_field() {
        let (nodes, fars, lanes) = far_nodes_and_lanes(5, 1.0);
        let list: Vec<u32> = (0..nodes.len() as u32).collect();
        let (mut fast, mut base) = (lanes, lanes);
        far_fields(&nodes, &list, &mut fast);
        far_fields_base(&nodes, &list, &mut base);
        for k in 0..GROUP {
            let q = lanes.get(k);
            let want: f64 = fars
                .iter()
                .map(|f| {
                    let r = f.centre() - q;
                    f.eval(r, r.length_squared())
                })
                .sum();
            for (what, got) in [("dispatched", fast.far[k]), ("base", base.far[k])] {
                let got = got as f64;
                assert!(
                    (got - want).abs() < 1e-5 * want.abs().max(1e-2),
                    "lane {k} ({what}): {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn the_per_lane_criteria_agree_between_the_paths() {
        let beta2 = 0.3f64 * 0.3;
        // Offsets from all far (the queries beyond 1.2 of the centre) to all near.
        let (mut all_seen, mut mixed_seen) = (0, 0);
        for (seed, offset) in [(1, 1.0), (2, 0.0), (3, 0.2), (4, 0.45), (5, 0.6), (6, 3.0)] {
            let (nodes, _, lanes) = far_nodes_and_lanes(seed, offset);
            for node in &nodes {
                let (mut fast, mut base) = (lanes, lanes);
                let mut pairs_fast = Vec::new();
                let tris = 0..3;
                near_leaves(
                    std::slice::from_ref(node),
                    std::iter::once((0, tris.clone())),
                    beta2,
                    &mut fast,
                    GROUP,
                    &mut pairs_fast,
                );
                let bits = far_leaf_base(node, &mut base, beta2 as f32);
                let want: Vec<(u32, u32)> = (0..GROUP as u32)
                    .filter(|&k| bits & (1 << k) == 0)
                    .flat_map(|k| tris.clone().map(move |t| (k, t)))
                    .collect();
                assert_eq!(pairs_fast, want);
                for k in 0..GROUP {
                    let (a, b) = (fast.far[k], base.far[k]);
                    assert!((a - b).abs() <= 1e-5 * b.abs().max(1e-2), "{a} vs {b}");
                }
                let all = all_far_dispatched(node.centre(), node.r2, beta2, &lanes);
                assert_eq!(all, bits == u32::MAX, "offset {offset}");
                assert_eq!(all_far::<false>(node.centre(), node.r2, beta2, &lanes), all);
                all_seen += usize::from(all);
                mixed_seen += usize::from(bits != 0 && bits != u32::MAX);
            }
        }
        assert!(all_seen > 0 && mixed_seen > 0, "{all_seen} {mixed_seen}");
    }

    /// [`all_far`] as the walk calls it on this processor.
    fn all_far_dispatched(c: DVec3, r2: f32, beta2: f64, lanes: &Lanes) -> bool {
        #[cfg(target_arch = "x86_64")]
        if has_avx2() {
            // SAFETY: the processor supports the features the function is compiled for.
            return unsafe { all_far_avx2(c, r2, beta2, lanes) };
        }
        all_far::<false>(c, r2, beta2, lanes)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn all_far_avx2(c: DVec3, r2: f32, beta2: f64, lanes: &Lanes) -> bool {
        all_far::<true>(c, r2, beta2, lanes)
    }
}
