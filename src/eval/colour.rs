//! The smooth colour field: at `x`, the average of the primitives' colours weighted by
//! their share of the LogSumExp sum (SPEC 2), i.e. their softmax weights
//! `w_i exp(-alpha d_i) / sum_j w_j exp(-alpha d_j)`.
//!
//! The traversal is the Barnes-Hut one of [`super::smooth`] (SPEC 6) with the same three
//! decisions per node: a far node (`diam < beta r`) contributes its mean colour with the
//! far-field weight `n w_ff exp(-alpha r)`; a subtree whose terms together are below
//! [`COLOUR_TOLERANCE`] of the sum is skipped; leaves add their primitives' exact terms.
//! Sums are shifted by the smallest distance seen (rescaled when it drops), so nothing
//! underflows at any alpha. Two coloured points give their mean colour halfway between
//! them and each point's own colour at (and near) the point.

use crate::colour::{Linear, SetColours};
use crate::primitives::{AnySet, Primitive, PrimitiveSet, WeightScale};
use glam::DVec3;

use super::EvalParams;

/// Largest share of the weight that skipped subtrees may hold together.
pub const COLOUR_TOLERANCE: f64 = 1e-6;

/// The softmax-weighted colour of `sets` at `x` with the evaluation parameters `p`
/// (`alpha`, `max_alpha`, `beta`). `colours[k]` belongs to `sets[k]`. `None` when there
/// is nothing to average (no primitives).
pub fn colour_at(
    sets: &[&AnySet],
    colours: &[&SetColours],
    x: DVec3,
    p: &EvalParams,
) -> Option<Linear> {
    let scale = |s: &AnySet| WeightScale::new(s.max_adj(), p.alpha, p.max_alpha);
    let prune_margin = super::params::prune_margin(sets, p, COLOUR_TOLERANCE);
    let mut acc = Blend::new(p.alpha);
    for (set, cols) in sets.iter().zip(colours) {
        let sc = scale(set);
        crate::with_set!(set, s => traverse(s, cols, x, p, &sc, prune_margin, &mut acc));
    }
    acc.finish()
}

/// Running shifted sums `S = sum w exp(-alpha (d - m))` and `C = sum c w exp(...)`,
/// with `m` the smallest distance added so far.
struct Blend {
    alpha: f64,
    m: f64,
    sum: f64,
    colour: [f64; 3],
}

impl Blend {
    fn new(alpha: f64) -> Blend {
        Blend {
            alpha,
            m: f64::INFINITY,
            sum: 0.0,
            colour: [0.0; 3],
        }
    }

    fn add(&mut self, d: f64, w: f64, c: Linear) {
        if d < self.m {
            // Rescale what was summed relative to the new, smaller reference.
            let k = if self.m.is_finite() {
                (-self.alpha * (self.m - d)).exp()
            } else {
                0.0
            };
            self.sum *= k;
            self.colour = self.colour.map(|v| v * k);
            self.m = d;
        }
        let t = w * (-self.alpha * (d - self.m)).exp();
        self.sum += t;
        for (sum, &c) in self.colour.iter_mut().zip(&c) {
            *sum += t * c as f64;
        }
    }

    fn finish(&self) -> Option<Linear> {
        (self.sum > 0.0).then(|| self.colour.map(|v| (v / self.sum) as f32))
    }
}

const STACK: usize = 128;

fn traverse<P: Primitive>(
    set: &PrimitiveSet<P>,
    cols: &SetColours,
    x: DVec3,
    p: &EvalParams,
    scale: &WeightScale,
    prune_margin: f64,
    acc: &mut Blend,
) {
    let nodes = &set.bvh.nodes;
    if nodes.is_empty() {
        return;
    }
    let w_ff = scale.max_weight();
    let beta2 = p.beta * p.beta;
    let mut stack = [(0u32, 0.0f64); STACK];
    let mut top = 1;
    stack[0] = (0, nodes[0].distance_squared(x));
    while top > 0 {
        top -= 1;
        let (i, r2) = stack[top];
        let node = &nodes[i as usize];
        // Every term below is at most w_max exp(-alpha r) per primitive: relative to the
        // nearest term seen (>= exp(-alpha m)), all skipped subtrees together hold less
        // than COLOUR_TOLERANCE of the sum.
        let reach = acc.m + prune_margin;
        if r2 > reach * reach {
            continue;
        }
        if node.is_leaf() {
            let first = node.index as usize;
            let range = first..first + node.count as usize;
            for (prim, &c) in set.prims[range.clone()].iter().zip(&cols.prims[range]) {
                let (d, w) = prim.value(x, scale);
                acc.add(d, w, c);
            }
            continue;
        }
        let diam = node.diam as f64;
        if p.beta > 0.0 && diam * diam < beta2 * r2 {
            acc.add(r2.sqrt(), node.size as f64 * w_ff, cols.nodes[i as usize]);
            continue;
        }
        let (l, rr) = (i + 1, node.index);
        let dl = nodes[l as usize].distance_squared(x);
        let dr = nodes[rr as usize].distance_squared(x);
        let (first, second) = if dl <= dr {
            ((rr, dr), (l, dl))
        } else {
            ((l, dl), (rr, dr))
        };
        debug_assert!(top + 2 <= STACK);
        stack[top] = first;
        stack[top + 1] = second;
        top += 2;
    }
}
