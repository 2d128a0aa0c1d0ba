//! Many winding-number queries at once: the queries are sorted along a Morton curve and
//! cut into groups of [`GROUP`] neighbours; each group walks the tree once, with the
//! far-field criterion taken against the group's box (`R < beta * dist(centre, box)`,
//! which implies the criterion of every query in the box, so no query is less accurate
//! than alone). The walk yields the group's far fields, summed for all its queries in
//! a loop over the queries that the compiler vectorizes, and the leaves near the box,
//! which each query finishes alone (far field or exact solid angles, as
//! [`super::tree`]).

use super::lanes::{self, GROUP, Lanes};
use super::tree::WindingTree;
use crate::geometry::morton::morton_order;
use crate::primitives::{PrimitiveSet, Triangle};
use glam::DVec3;
use rayon::prelude::*;

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
    let sorted: Vec<[f64; GROUP]> = order
        .par_chunks(GROUP)
        .map_init(Scratch::default, |scratch, idx| {
            let mut lanes = Lanes::new(idx.iter().map(|&i| points[i as usize]));
            group(tree, set, beta, &mut lanes, idx.len(), scratch);
            std::array::from_fn(|k| lanes.sum(k))
        })
        .collect();
    let mut out = vec![0.0; points.len()];
    for (&i, w) in order.iter().zip(sorted.iter().flatten()) {
        out[i as usize] = *w;
    }
    out
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
    lanes::far_fields(&tree.far, &tree.poly, &s.far, lanes);
    s.pairs.clear();
    let leaves = s.near.iter().map(|&i| {
        let n = &nodes[i as usize];
        (i, n.index..n.index + n.count)
    });
    lanes::near_leaves(
        &tree.far,
        &tree.poly,
        leaves,
        beta2,
        lanes,
        used,
        &mut s.pairs,
    );
    lanes::solid_angles(&set.prims, &s.pairs, lanes);
}
