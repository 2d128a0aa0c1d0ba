//! Many winding-number queries at once: the queries are sorted along a Morton curve and
//! cut into groups of [`GROUP`] neighbours; each group walks the tree once, with the
//! far-field criterion taken against the group's box (`R < beta * dist(centre, box)`,
//! which implies the criterion of every query in the box, so no query is less accurate
//! than alone). The walk yields the group's far fields, summed for all its queries in
//! a loop over the queries that the compiler vectorizes, and the leaves near the box,
//! which each query finishes alone (far field or exact solid angles, as
//! [`super::tree`]).

use super::exact::solid_angle;
use super::expansion::{FarField, FarPoly};
use super::tree::WindingTree;
use crate::geometry::morton::morton_order;
use crate::primitives::{PrimitiveSet, Triangle};
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Queries per group.
pub const GROUP: usize = 32;

/// The far-field parameter of the first, coarse pass of [`sign_winding_numbers`]
/// (libigl's default accuracy: largest error 3e-3 to 5e-3 on the test meshes).
pub const SIGN_BETA: f64 = 0.5;

/// Coarse winding numbers farther than this from 1/2 decide the sign without a second
/// pass: ten times the coarse pass's largest measured error.
pub const SIGN_MARGIN: f64 = 0.05;

/// Winding numbers for signs: a coarse pass at [`SIGN_BETA`] (when `beta` is finer),
/// then `beta` again only at the points whose coarse value lies within [`SIGN_MARGIN`]
/// of 1/2. The sign (`w > 1/2`) is the one the `beta` pass would give wherever the
/// coarse error stays below the margin; the values are the coarse ones elsewhere.
pub fn sign_winding_numbers(
    tree: &WindingTree,
    set: &PrimitiveSet<Triangle>,
    beta: f64,
    points: &[DVec3],
) -> Vec<f64> {
    if beta >= SIGN_BETA {
        return winding_numbers(tree, set, beta, points);
    }
    let mut w = winding_numbers(tree, set, SIGN_BETA, points);
    let redo: Vec<usize> = (0..w.len())
        .filter(|&i| (w[i] - 0.5).abs() <= SIGN_MARGIN)
        .collect();
    if !redo.is_empty() {
        let pts: Vec<DVec3> = redo.iter().map(|&i| points[i]).collect();
        let fine = winding_numbers(tree, set, beta, &pts);
        for (&i, f) in redo.iter().zip(fine) {
            w[i] = f;
        }
    }
    w
}

/// Scratch space of one worker.
#[derive(Default)]
pub struct Scratch {
    stack: Vec<u32>,
    far: Vec<u32>,
    near: Vec<u32>,
}

/// The fast winding number at every point of `points` (see [`WindingTree`]), in
/// parallel in the current rayon pool.
pub fn winding_numbers(
    tree: &WindingTree,
    set: &PrimitiveSet<Triangle>,
    beta: f64,
    points: &[DVec3],
) -> Vec<f64> {
    let order = morton_order(points);
    let sorted: Vec<f64> = order
        .par_chunks(GROUP)
        .map_init(Scratch::default, |scratch, idx| {
            let mut lanes = Lanes::default();
            for (k, &i) in idx.iter().enumerate() {
                lanes.set(k, points[i as usize]);
            }
            // Unused lanes repeat the first query.
            for k in idx.len()..GROUP {
                lanes.set(k, points[idx[0] as usize]);
            }
            lanes.relative();
            group(tree, set, beta, &mut lanes, idx.len(), scratch);
            lanes.acc
        })
        .flat_map_iter(|acc| acc.into_iter())
        .collect();
    let mut out = vec![0.0; points.len()];
    for (k, &i) in order.iter().enumerate() {
        out[i as usize] = sorted[k];
    }
    out
}

/// A group's queries, structure of arrays, and their sums.
#[derive(Clone, Copy)]
struct Lanes {
    x: [f64; GROUP],
    y: [f64; GROUP],
    z: [f64; GROUP],
    /// The queries about `origin` (the first one) in f32, for [`far_lanes32`].
    origin: DVec3,
    fx: [f32; GROUP],
    fy: [f32; GROUP],
    fz: [f32; GROUP],
    acc: [f64; GROUP],
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
            acc: [0.0; GROUP],
        }
    }
}

impl Lanes {
    fn set(&mut self, k: usize, p: DVec3) {
        (self.x[k], self.y[k], self.z[k]) = (p.x, p.y, p.z);
    }
    fn get(&self, k: usize) -> DVec3 {
        DVec3::new(self.x[k], self.y[k], self.z[k])
    }
    /// Sets the f32 copies about the first query.
    fn relative(&mut self) {
        self.origin = self.get(0);
        for k in 0..GROUP {
            let r = self.get(k) - self.origin;
            (self.fx[k], self.fy[k], self.fz[k]) = (r.x as f32, r.y as f32, r.z as f32);
        }
    }
}

fn group(
    tree: &WindingTree,
    set: &PrimitiveSet<Triangle>,
    beta: f64,
    lanes: &mut Lanes,
    used: usize,
    s: &mut Scratch,
) {
    let nodes = &set.bvh.nodes;
    if nodes.is_empty() {
        return;
    }
    let beta2 = beta * beta;
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for k in 0..used {
        let p = lanes.get(k);
        lo = lo.min(p);
        hi = hi.max(p);
    }
    s.far.clear();
    s.near.clear();
    s.stack.clear();
    s.stack.push(0);
    while let Some(i) = s.stack.pop() {
        let f = &tree.far[i as usize];
        let c = f.centre();
        let d2 = (c - c.clamp(lo, hi)).length_squared();
        let node = &nodes[i as usize];
        if (f.r2 as f64) < beta2 * d2 {
            s.far.push(i);
        } else if node.is_leaf() {
            s.near.push(i);
        } else {
            s.stack.push(node.index);
            s.stack.push(i + 1);
        }
    }
    far_all(tree, &s.far, lanes);
    near_all(tree, set, beta2, &s.near, lanes, used);
}

/// The leaves near the group's box: each lane takes a leaf's far field where the
/// criterion holds for its own query (all lanes at once, as [`far_lanes`] with a mask),
/// and the exact solid angles of its triangles where it does not.
fn near_all(
    tree: &WindingTree,
    set: &PrimitiveSet<Triangle>,
    beta2: f64,
    list: &[u32],
    lanes: &mut Lanes,
    used: usize,
) {
    let nodes = &set.bvh.nodes;
    let mut exact = [false; GROUP];
    let mut angles = [0.0f64; GROUP];
    for &i in list {
        let f = &tree.far[i as usize];
        if !far_lanes_where(f, lanes, beta2, &mut exact) {
            continue;
        }
        let node = &nodes[i as usize];
        let first = node.index as usize;
        let tris = &set.prims[first..first + node.count as usize];
        for k in (0..used).filter(|&k| exact[k]) {
            let q = lanes.get(k);
            for t in tris {
                angles[k] += solid_angle(q, t.a.as_dvec3(), t.b.as_dvec3(), t.c.as_dvec3());
            }
        }
    }
    for (a, angle) in lanes.acc.iter_mut().zip(&angles).take(used) {
        *a += angle / (4.0 * PI);
    }
}

/// [`far_lanes`] for the lanes whose own query meets the far-field criterion; marks
/// the others in `exact` and says whether there are any.
fn far_lanes_where(f: &FarField, lanes: &mut Lanes, beta2: f64, exact: &mut [bool; GROUP]) -> bool {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the processor supports the features the function is compiled for.
        return unsafe { far_lanes_where_avx2(f, lanes, beta2, exact) };
    }
    far_lanes_masked(f, lanes, beta2, exact)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn far_lanes_where_avx2(
    f: &FarField,
    lanes: &mut Lanes,
    beta2: f64,
    exact: &mut [bool; GROUP],
) -> bool {
    far_lanes_masked(f, lanes, beta2, exact)
}

/// Adds the far fields `list` at every lane's query, in f32 ([`far_lanes32`]): with AVX2
/// and FMA when the processor has them (checked once at run time), else with the
/// baseline instructions.
fn far_all(tree: &WindingTree, list: &[u32], lanes: &mut Lanes) {
    let mut acc = [0.0f32; GROUP];
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the processor supports the features the function is compiled for.
        unsafe { far_all_avx2(tree, list, lanes, &mut acc) };
    } else {
        far_all_base(tree, list, lanes, &mut acc);
    }
    #[cfg(not(target_arch = "x86_64"))]
    far_all_base(tree, list, lanes, &mut acc);
    for (a, &v) in lanes.acc.iter_mut().zip(&acc) {
        *a += v as f64;
    }
}

fn far_all_base(tree: &WindingTree, list: &[u32], lanes: &Lanes, acc: &mut [f32; GROUP]) {
    for &i in list {
        far_lanes32::<false>(&tree.far[i as usize], &tree.poly[i as usize], lanes, acc);
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn far_all_avx2(tree: &WindingTree, list: &[u32], lanes: &Lanes, acc: &mut [f32; GROUP]) {
    for &i in list {
        far_lanes32::<true>(&tree.far[i as usize], &tree.poly[i as usize], lanes, acc);
    }
}

/// `a b + c`, fused when `FMA`.
#[inline(always)]
fn fma<const FMA: bool>(a: f32, b: f32, c: f32) -> f32 {
    if FMA { a.mul_add(b, c) } else { a * b + c }
}

/// Adds the far field `f` (as the polynomials `p`) at every lane's query to `acc`, in
/// f32 about the lanes' origin (so the precision is that of the distances, not of the
/// coordinates).
// One index over the lanes' arrays is the form the vectorizer takes.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn far_lanes32<const FMA: bool>(f: &FarField, p: &FarPoly, lanes: &Lanes, acc: &mut [f32; GROUP]) {
    let c = f.centre() - lanes.origin;
    let c = [c.x as f32, c.y as f32, c.z as f32];
    let scale = (1.0 / (4.0 * PI)) as f32;
    let fm = fma::<FMA>;
    for k in 0..GROUP {
        let (rx, ry, rz) = (c[0] - lanes.fx[k], c[1] - lanes.fy[k], c[2] - lanes.fz[k]);
        let d2 = fm(rx, rx, fm(ry, ry, rz * rz)).max(f32::MIN_POSITIVE);
        let s = 1.0 / d2.sqrt();
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
        let c = &p.cubic;
        let qx = fm(
            c[0],
            xx,
            fm(
                c[1],
                xy,
                fm(c[2], xz, fm(c[3], yy, fm(c[4], yz, c[5] * zz))),
            ),
        );
        let qy = fm(c[6], yy, fm(c[7], yz, c[8] * zz));
        let cubic = fm(x, qx, fm(y, qy, c[9] * zz * z));
        let order2 = fm(p.g[0], x, fm(p.g[1], y, fm(p.g[2], z, cubic)));
        acc[k] = fm(s * s * scale, fm(s, fm(s, order2, order1), order0), acc[k]);
    }
}

/// Adds the far field `f` ([`FarField::eval`], in f64, written over the lanes for the
/// vectorizer) at the lanes whose query meets `r2 < beta2 d2`, marks the others in
/// `exact`, and says whether it marked any.
// One index over the lanes' arrays is the form the vectorizer takes.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn far_lanes_masked(
    f: &FarField,
    lanes: &mut Lanes,
    beta2: f64,
    exact: &mut [bool; GROUP],
) -> bool {
    let r2 = f.r2 as f64;
    let g = |x: f32| x as f64;
    let (cx, cy, cz) = (g(f.centre[0]), g(f.centre[1]), g(f.centre[2]));
    let (nx, ny, nz) = (g(f.n[0]), g(f.n[1]), g(f.n[2]));
    let m = f.m.map(g);
    let t = f.t.map(g);
    let trace = m[0] + m[4] + m[8];
    // sum_j T_ijj per i.
    let tdiag = [
        t[0] + t[3] + t[5],
        t[6] + t[9] + t[11],
        t[12] + t[15] + t[17],
    ];
    let scale = 1.0 / (4.0 * PI);
    for k in 0..GROUP {
        let (rx, ry, rz) = (cx - lanes.x[k], cy - lanes.y[k], cz - lanes.z[k]);
        let d2 = rx * rx + ry * ry + rz * rz;
        let inv2 = 1.0 / d2;
        let inv = inv2.sqrt();
        let inv3 = inv * inv2;
        let inv5 = inv3 * inv2;
        let inv7 = inv5 * inv2;
        let order0 = nx * rx + ny * ry + nz * rz;
        let mrx = m[0] * rx + m[1] * ry + m[2] * rz;
        let mry = m[3] * rx + m[4] * ry + m[5] * rz;
        let mrz = m[6] * rx + m[7] * ry + m[8] * rz;
        let rmr = rx * mrx + ry * mry + rz * mrz;
        let order1 = trace * inv3 - 3.0 * rmr * inv5;
        // T_i r for each i, its i-th entry, and r . T_i r.
        let tr = |o: usize| {
            let a = t[o] * rx + t[o + 1] * ry + t[o + 2] * rz;
            let b = t[o + 1] * rx + t[o + 3] * ry + t[o + 4] * rz;
            let c = t[o + 2] * rx + t[o + 4] * ry + t[o + 5] * rz;
            (a, b, c, a * rx + b * ry + c * rz)
        };
        let (a0, _, _, q0) = tr(0);
        let (_, b1, _, q1) = tr(6);
        let (_, _, c2, q2) = tr(12);
        let cubic = rx * q0 + ry * q1 + rz * q2;
        let sum_iik = a0 + b1 + c2;
        let sum_diag = rx * tdiag[0] + ry * tdiag[1] + rz * tdiag[2];
        let order2 = 0.5 * (15.0 * cubic * inv7 - 3.0 * (2.0 * sum_iik + sum_diag) * inv5);
        let v = (order0 * inv3 + order1 + order2) * scale;
        let far = r2 < beta2 * d2;
        exact[k] = !far;
        lanes.acc[k] += if far { v } else { 0.0 };
    }
    exact.iter().any(|&e| e)
}
