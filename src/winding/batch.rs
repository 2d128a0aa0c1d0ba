//! Many winding-number queries at once: the queries are sorted along a Morton curve and
//! cut into groups of [`GROUP`] neighbours; each group walks the tree once, with the
//! far-field criterion taken against the group's box (`R < beta * dist(centre, box)`,
//! which implies the criterion of every query in the box, so no query is less accurate
//! than alone); an inner node the box refuses is still taken whole when every query of
//! the group meets its own criterion ([`lanes::all_far`]: 116 far fields per group of 32
//! on the full bunny instead of 136). The walk yields the group's far fields, summed
//! for all its queries over the lanes ([`super::lanes`]), and the leaves near the box,
//! which each query finishes alone (far field or exact solid angles, as
//! [`super::tree`]). The points are gathered in Morton order in one pass before the
//! groups (a plain loop's loads overlap; a group's loads ahead of its arithmetic do
//! not), and each group stores its answers in place.

use super::lanes::{self, GROUP, Lanes};
use super::tree::WindingTree;
use crate::geometry::morton::morton_order;
use crate::primitives::{PrimitiveSet, Triangle};
use glam::DVec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

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
    pairs: Vec<(u32, u32)>,
    block: lanes::AngleBlock,
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
    // Gathered in one pass (the loads of a plain loop overlap; a group's loads before
    // its long arithmetic do not).
    let sorted: Vec<DVec3> = order.par_iter().map(|&i| points[i as usize]).collect();
    // Each group writes its answers to their places in `out` (a permutation: each
    // index once); relaxed atomic stores are plain stores.
    let out: Vec<AtomicU64> = (0..points.len())
        .into_par_iter()
        .map(|_| AtomicU64::new(0))
        .collect();
    order
        .par_chunks(GROUP)
        .zip(sorted.par_chunks(GROUP))
        .for_each_init(Scratch::default, |scratch, (idx, pts)| {
            let mut lanes = Lanes::new(pts.iter().copied());
            group(tree, set, beta, &mut lanes, idx.len(), scratch);
            for (k, &i) in idx.iter().enumerate() {
                out[i as usize].store(lanes.sum(k).to_bits(), Ordering::Relaxed);
            }
        });
    out.into_par_iter()
        .map(|w| f64::from_bits(w.into_inner()))
        .collect()
}

/// One group: the walk against the group's box, then the far fields at every lane, the
/// leaves near the box lane by lane, and the exact solid angles those leave.
fn group(
    tree: &WindingTree,
    set: &PrimitiveSet<Triangle>,
    beta: f64,
    lanes: &mut Lanes,
    used: usize,
    s: &mut Scratch,
) {
    if tree.walk.is_empty() {
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
    walk(tree, beta2, lo, hi, lanes, s);
    lanes::far_fields(&tree.poly, &s.far, lanes);
    s.pairs.clear();
    let leaves = s.near.iter().map(|&i| {
        let n = &tree.walk[i as usize];
        (i, n.index..n.index + n.count)
    });
    lanes::near_leaves(&tree.poly, leaves, beta2, lanes, used, &mut s.pairs);
    lanes::solid_angles(&set.prims, &s.pairs, lanes, &mut s.block);
}

/// The group's walk: nodes whose far field every query may take into `s.far` (the
/// criterion against the group's box, else at every lane), leaves near the group into
/// `s.near`.
fn walk(tree: &WindingTree, beta2: f64, lo: DVec3, hi: DVec3, lanes: &Lanes, s: &mut Scratch) {
    #[cfg(target_arch = "x86_64")]
    if lanes::has_avx2() {
        // SAFETY: the processor supports the features the function is compiled for.
        return unsafe { walk_avx2(tree, beta2, lo, hi, lanes, s) };
    }
    walk_in::<false>(tree, beta2, lo, hi, lanes, s)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn walk_avx2(tree: &WindingTree, beta2: f64, lo: DVec3, hi: DVec3, lanes: &Lanes, s: &mut Scratch) {
    walk_in::<true>(tree, beta2, lo, hi, lanes, s)
}

#[inline(always)]
fn walk_in<const AVX2: bool>(
    tree: &WindingTree,
    beta2: f64,
    lo: DVec3,
    hi: DVec3,
    lanes: &Lanes,
    s: &mut Scratch,
) {
    let walk = &tree.walk;
    s.far.clear();
    s.near.clear();
    s.stack.clear();
    s.stack.push(0);
    while let Some(i) = s.stack.pop() {
        let node = &walk[i as usize];
        let c = node.centre();
        let d2 = (c - c.clamp(lo, hi)).length_squared();
        if (node.r2 as f64) < beta2 * d2 {
            s.far.push(i);
        } else if node.count > 0 {
            s.near.push(i);
        } else if lanes::all_far::<AVX2>(c, node.r2, beta2, lanes) {
            s.far.push(i);
        } else {
            s.stack.push(node.index);
            s.stack.push(i + 1);
        }
    }
}
