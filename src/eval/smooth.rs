//! The smooth distance by a conservative Barnes-Hut traversal (SPEC 2, 6).
//!
//! Nodes are visited near to far (the shifted sum's reference settles on the first
//! leaves). At a node with box `B` at distance `r` (closest box point `c`):
//! - prune: if `r > m + (ln(N w_max / tol) - ln S) / alpha`, where `m` is the smallest
//!   exact distance seen, `S` the shifted sum so far (a lower bound of `ln S` from its
//!   binary exponent) and `N` the total primitive count, every term below the node is
//!   smaller than `tol S / N`, so all pruned subtrees together hold less than `tol`
//!   (`EvalParams::prune_tolerance`, 1e-10 by default) of the final sum. They are skipped, and when anything was pruned the sum is
//!   multiplied by `1 + 2 tol` to cover them from above: `s` stays a lower bound of the
//!   exact value and within `2 tol / alpha` of it. The nearest primitive is never pruned,
//!   so `s <= d_min` holds exactly. This is what makes beta = 0 cheap at large alpha.
//!   `EvalParams::prune = false` turns it off (the paper's traversal).
//! - far field: if the node is not a leaf and `diam(B) < beta r`, add one term
//!   `n w_ff exp(-alpha r)` with direction `(x - c) / r` and `w_ff = max_adj^q`. Every
//!   primitive below is at least `r` away with weight at most `w_ff`, so the far term
//!   dominates the terms it replaces and the approximate `s` never exceeds the exact one.
//! - otherwise descend; leaves add their primitives' exact terms.

use super::accumulate::{Accumulation, Accumulator};
use crate::primitives::{AnySet, Primitive, PrimitiveSet, WeightScale};
use glam::DVec3;

/// Relative size of the sum that pruned subtrees may add up to at most, by default
/// (queries, reports, the Python API): `s` is then within `2e-10 / alpha` of the exact
/// value. The tracer passes a larger one tied to its hit threshold (see
/// `render::tracer`): for a step or a hit test only `s` to a small share of epsilon
/// matters, and pruning more is what makes soft point clouds cheaper.
pub const PRUNE_TOLERANCE: f64 = 1e-10;

/// Parameters of one smooth-distance evaluation.
#[derive(Clone, Copy, Debug)]
pub struct EvalParams {
    /// Sharpness (1/length).
    pub alpha: f64,
    /// Weights are attenuated by `q = min(alpha / max_alpha, 1)` (SPEC 5).
    pub max_alpha: f64,
    /// Barnes-Hut opening parameter in [0, 1]; 0 sums every term exactly.
    pub beta: f64,
    pub accumulation: Accumulation,
    /// Skip subtrees whose contribution is below `prune_tolerance` (default on).
    pub prune: bool,
    /// Share of the sum the pruned subtrees may hold together, in (0, 0.5]
    /// (`PRUNE_TOLERANCE` by default); `s` stays a lower bound of the exact value and
    /// within `2 prune_tolerance / alpha` of it.
    pub prune_tolerance: f64,
}

impl EvalParams {
    pub fn new(alpha: f64, max_alpha: f64, beta: f64) -> Self {
        EvalParams {
            alpha,
            max_alpha,
            beta,
            accumulation: Accumulation::Stable,
            prune: true,
            prune_tolerance: PRUNE_TOLERANCE,
        }
    }
}

/// Work done by one evaluation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EvalStats {
    /// Exact primitive terms.
    pub exact: u32,
    /// Far-field (approximated subtree) terms.
    pub far: u32,
    /// Nodes popped from the traversal stack.
    pub nodes: u32,
    /// Subtrees skipped as negligible.
    pub pruned: u32,
}

impl EvalStats {
    /// "Leaves visited": exact plus far-field terms (the paper's cost measure).
    pub fn leaves(&self) -> u32 {
        self.exact + self.far
    }

    pub fn add(&mut self, o: &EvalStats) {
        self.exact += o.exact;
        self.far += o.far;
        self.nodes += o.nodes;
        self.pruned += o.pruned;
    }
}

/// Result of one evaluation.
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    /// Smooth distance (`+inf` only in naive mode, when the sum underflows).
    pub s: f64,
    /// Gradient of `s`.
    pub grad: DVec3,
    /// Smallest exact distance among the primitives summed exactly (an upper bound of
    /// the distance to the nearest primitive; equal to it at beta = 0).
    pub d_seen: f64,
    /// The naive sum underflowed to zero.
    pub underflow: bool,
    pub stats: EvalStats,
}

/// Evaluates the smooth distance of the union of `sets` at `x`, with its gradient.
pub fn evaluate(sets: &[&AnySet], x: DVec3, p: &EvalParams) -> Sample {
    evaluate_impl::<true>(sets, x, p)
}

/// Evaluates the smooth distance only (the returned gradient is zero): what a sphere
/// tracer needs for its steps, at about half the cost.
pub fn evaluate_value(sets: &[&AnySet], x: DVec3, p: &EvalParams) -> Sample {
    evaluate_impl::<false>(sets, x, p)
}

fn evaluate_impl<const GRAD: bool>(sets: &[&AnySet], x: DVec3, p: &EvalParams) -> Sample {
    let mut acc = Accumulator::new(p.alpha, p.accumulation);
    let mut stats = EvalStats::default();
    let total: usize = sets.iter().map(|s| s.len()).sum();
    let scale = |s: &AnySet| WeightScale::new(s.max_adj(), p.alpha, p.max_alpha);
    let w_max = sets
        .iter()
        .map(|s| scale(s).max_weight())
        .fold(1.0, f64::max);
    let prune_margin = if p.prune {
        (total.max(1) as f64 * w_max / p.prune_tolerance).ln() / p.alpha
    } else {
        f64::INFINITY
    };
    for set in sets {
        let sc = scale(set);
        crate::with_set!(set, s => traverse::<_, GRAD>(s, x, p, &sc, prune_margin, &mut acc, &mut stats));
    }
    if stats.pruned > 0 {
        // The pruned subtrees hold less than the tolerance of the final sum (see the
        // module docs): add that bound back so s never exceeds the exact value.
        acc.inflate(1.0 + 2.0 * p.prune_tolerance);
    }
    let (s, grad, underflow) = acc.finish();
    Sample {
        s,
        grad,
        d_seen: acc.m,
        underflow,
        stats,
    }
}

/// Depth of the traversal stack: the BVH depth is far below this for any input that
/// fits in memory (binned SAH with a median fallback).
const STACK: usize = 128;

fn traverse<P: Primitive, const GRAD: bool>(
    set: &PrimitiveSet<P>,
    x: DVec3,
    p: &EvalParams,
    scale: &WeightScale,
    prune_margin: f64,
    acc: &mut Accumulator,
    stats: &mut EvalStats,
) {
    let nodes = &set.bvh.nodes;
    if nodes.is_empty() {
        return;
    }
    let w_ff = scale.max_weight();
    let beta2 = p.beta * p.beta;
    let inv_alpha = 1.0 / p.alpha;
    // The stack holds squared box distances; square roots are taken only for far terms.
    let mut stack: [(u32, f64); STACK] = [(0, 0.0); STACK];
    let mut top = 1;
    stack[0] = (0, nodes[0].distance_squared(x));
    while top > 0 {
        top -= 1;
        let (i, r2) = stack[top];
        let node = &nodes[i as usize];
        stats.nodes += 1;
        let reach = acc.m + (prune_margin - acc.ln_sum_lower_bound() * inv_alpha);
        if r2 > reach * reach {
            stats.pruned += 1;
            continue;
        }
        if node.is_leaf() {
            let first = node.index as usize;
            for prim in &set.prims[first..first + node.count as usize] {
                if GRAD {
                    let t = prim.term(x, scale);
                    acc.add(t.d, t.w, t.dir, t.grad_w);
                } else {
                    let (d, w) = prim.value(x, scale);
                    acc.add_value(d, w);
                }
            }
            stats.exact += node.count;
            continue;
        }
        let diam = node.diam as f64;
        if p.beta > 0.0 && diam * diam < beta2 * r2 {
            let r = r2.sqrt();
            if GRAD {
                let (_, c) = node.distance(x);
                acc.add(r, node.size as f64 * w_ff, (x - c) / r, DVec3::ZERO);
            } else {
                acc.add_value(r, node.size as f64 * w_ff);
            }
            stats.far += 1;
            continue;
        }
        let (l, rr) = (i + 1, node.index);
        let dl = nodes[l as usize].distance_squared(x);
        let dr = nodes[rr as usize].distance_squared(x);
        // Push the farther child first so the nearer one is popped next.
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
