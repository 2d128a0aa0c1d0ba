//! The smooth distance by a conservative Barnes-Hut traversal (SPEC 2, 6).
//!
//! Nodes are visited near to far (the shifted sum's reference settles on the first
//! leaves). At a node with box `B` at distance `r` (closest box point `c`):
//! - prune: if `r > m + (ln(N w_max / tol1) - ln S) / alpha`, where `m` is the smallest
//!   exact distance seen, `S` the shifted sum so far (a lower bound of `ln S` from its
//!   binary exponent) and `N` the total primitive count, every term below the node is
//!   smaller than `tol1 S / N`, so all such subtrees together hold less than `tol1` of
//!   the final sum. They are skipped, and when anything was pruned the sum is multiplied
//!   by `1 + tol1` to cover them from above. With the budget below, `tol1 = tol / 4`
//!   (`tol` is `EvalParams::prune_tolerance`, 1e-10 by default) and the budget takes
//!   `tol2 = 7 tol / 4`; without it, `tol1 = tol` (`rule_tolerances`).
//! - prune against a budget: a subtree of `n` primitives at distance `r` that would be
//!   opened (not a far field) holds at most `b = n w_max exp(-alpha (r - m))` (shifted);
//!   it is skipped when `b` fits in what is left of the budget `tol2 S - P`, and `P`, the
//!   pruned mass so far, grows by `b` rounded up to a power of `2^(1/8)` (at most 9%
//!   above `b`; the test and the charge look mantissas up in tables of eight steps per
//!   octave and cost no logarithm or exponential, `eval::walk`). `P` is shifted with
//!   `S` when `m` moves and added to the sum at the end, so it stays below `tol2` of the
//!   final sum. The union bound of the first rule charges each subtree for all `N`
//!   primitives; the budget charges what was actually skipped, so it skips whole
//!   subtrees much nearer. Far fields are decided first: a far term costs no more than
//!   the charge, and the budget is kept for subtrees that would be opened. The union
//!   bound leaves most of its share unspent (its subtrees are far), the budget spends
//!   what it charges, so the budget takes three quarters of the tolerance. (What each
//!   of these choices saved, scene by scene: `doc/performance-log.md`.)
//!
//!   Together (`tol1 + tol2 <= 2 tol`), `s` stays a lower bound of the exact value and
//!   within `2 tol / alpha` of it. The nearest primitive is never pruned by the first
//!   rule, so `s <= d_min` holds exactly (and always holds: `s` is below the exact
//!   smooth distance). This is what makes beta = 0 cheap at large alpha.
//!   `EvalParams::prune = false` turns both off (the paper's traversal).
//! - far field: if the node is not a leaf and `diam(B) < beta r`, add one term
//!   `n w_ff exp(-alpha r)` with direction `(x - c) / r` and `w_ff = max_adj^q`. Every
//!   primitive below is at least `r` away with weight at most `w_ff`, so the far term
//!   dominates the terms it replaces and the approximate `s` never exceeds the exact one.
//! - far field by share (`EvalParams::far_share`, off by default; the tracer's hit
//!   decisions on soft meshes): a subtree that beta would open and the budget did not
//!   prune is one far-field term as well when its bound `n w_ff exp(-alpha r)` is at
//!   most `share` times the larger of the shifted sum so far and the floor `exp(-alpha
//!   level)`, the sum where `s` equals a given `level` (tested with the budget's stepped
//!   logarithms, `eval::walk`). The term dominates the terms it replaces, as every far
//!   term does, so `s` stays a lower bound; what the share decides is how much work goes
//!   into accuracy (each such term lowers `s` by at most `share / alpha` when the
//!   value is not above `level`).
//! - otherwise descend; leaves add their primitives' exact terms.
//!
//! Far field of point clouds from second moments (`EvalParams::moments`, default on):
//! the closest-box term overestimates a subtree by up to `exp(alpha diam(B))`, several
//! epsilons of `s` near soft surfaces. For points `p_i` below the node, a reference
//! point `c` and any unit `u`, `|x - p_i| >= u . (x - p_i)`, so with `Y_i = u . (p_i - c)`
//! the subtree sums to at most `w exp(-alpha u . (x - c)) sum exp(alpha Y_i)`. Bennett's
//! bound `e^(a y) <= 1 + a y + a^2 y^2 g(a b)` for `y <= b`, `g(z) = (e^z - 1 - z) / z^2`
//! (increasing and convex: taken from above by the chords of a table, `bennett_g_chord`),
//! with `b` the largest `u . (q - c)` over the box, the second moment
//! `sigma^2 = u^T M u` about `c` (`bvh::moments`, rounded up) and `|mean - c| <= lin`,
//! gives, for `u = (x - c) / |x - c|`,
//! `n w F exp(-alpha |x - c|)`, `F = 1 + alpha lin + alpha^2 sigma^2 g(alpha b)`.
//! Where it is smaller than the box term (`ln F < alpha (|x - c| - r)`: nearly always
//! at the opening distances) it is the term, with direction `u`; along a ray `x + t d`
//! it is `n w F exp(-alpha (|x - c| + t u . d))` for the same `u`, an upper bound at
//! every `t` with the exact slope `u . d` (what `eval::reach` needs). A middle (pair of
//! slots) that is far field adds its two slots' terms. Same nodes visited; `s` closer to
//! the exact value on soft clouds (`ln F` is about `alpha^2 sigma^2 / 2` against
//! `alpha diam` for the box). The terms live in `eval::sink`, the walk in `eval::walk`,
//! the parameters and tolerances in `eval::params`.
//!
//! The walk runs on the BVH's 4-wide form (`bvh::wide`): opening a wide node tests the
//! four grandchildren of a binary node at once and makes the decisions above for the
//! two children between (far field at the distance of the nearer of their own
//! children's boxes, which bounds every primitive below from below, as the box does)
//! and then for the grandchildren. Far-field terms are added when their parent is
//! opened; the rest is pushed farthest first, so leaves are still met near to far.

use super::accumulate::{Accumulation, Accumulator};
use super::params::{EvalParams, EvalStats, prune_margin, rule_tolerances};
use super::reach::Slopes;
use super::sink::Sink;
use super::walk::{STACK, Walk};
use crate::primitives::{AnySet, WeightScale};
use glam::DVec3;

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
    /// Free distance along the direction given to [`evaluate_reach`]: the smooth
    /// distance stays positive on `x + [0, reach] u` (`eval::reach`); `s` otherwise.
    pub reach: f64,
    /// Free distance backwards, on `x - [0, reach_back] u`, when asked for by
    /// [`Along::back`] and `s` is below it (at most that length); `s` otherwise.
    pub reach_back: f64,
    /// The derivative of `s` along the direction given to [`evaluate_reach`]
    /// (`eval::reach`, `Slopes::derivatives`); `None` without one.
    pub slope: Option<f64>,
    /// An estimate of the second derivative of `s` along that direction
    /// (`Slopes::derivatives`); `None` without one.
    pub bend: Option<f64>,
    pub stats: EvalStats,
    /// With `EvalParams::upper_bound`, an upper bound of the exact smooth distance
    /// (far-field terms at the lower bound of their subtrees, pruned ones at zero; point
    /// clouds' far terms then come from the closest box, not from second moments, which
    /// have no lower bound beside them); `+inf` otherwise.
    pub s_upper: f64,
}

/// Evaluates the smooth distance of the union of `sets` at `x`, with its gradient.
pub fn evaluate(sets: &[&AnySet], x: DVec3, p: &EvalParams) -> Sample {
    evaluate_impl::<true, false>(sets, x, Along::NONE, p)
}

/// Evaluates the smooth distance only (the returned gradient is zero): what a sphere
/// tracer needs for its steps, at about half the cost.
pub fn evaluate_value(sets: &[&AnySet], x: DVec3, p: &EvalParams) -> Sample {
    evaluate_impl::<false, false>(sets, x, Along::NONE, p)
}

/// A ray through the evaluation point, for free distances along it (`eval::reach`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Along {
    /// Unit direction.
    pub u: DVec3,
    /// The free distance ahead is wanted up to this length.
    pub max_len: f64,
    /// The free distance behind is wanted up to this length: computed only where `s` is
    /// shorter (0: not wanted).
    pub back: f64,
}

impl Along {
    /// No free distance wanted either way.
    pub const NONE: Along = Along {
        u: DVec3::ZERO,
        max_len: 0.0,
        back: 0.0,
    };

    /// Ahead only, up to `max_len`.
    pub fn ahead(u: DVec3, max_len: f64) -> Along {
        Along {
            u,
            max_len,
            back: 0.0,
        }
    }
}

/// Evaluates the smooth distance (with the gradient if `grad`) and how far along the
/// unit direction `u` it provably stays positive (`Sample::reach`, at most `max_len`;
/// `eval::reach`; on edges and triangles to first order in the weights' change). With
/// the naive sum `reach` is `s`.
pub fn evaluate_reach(
    sets: &[&AnySet],
    x: DVec3,
    u: DVec3,
    p: &EvalParams,
    max_len: f64,
    grad: bool,
) -> Sample {
    evaluate_along(sets, x, Some(Along::ahead(u, max_len)), p, grad)
}

/// The general evaluation: with the gradient if `grad`, and with the free distances
/// along a ray if `along` is given (as [`evaluate_reach`], and behind as asked).
pub fn evaluate_along(
    sets: &[&AnySet],
    x: DVec3,
    along: Option<Along>,
    p: &EvalParams,
    grad: bool,
) -> Sample {
    let slope = p.accumulation == Accumulation::Stable;
    match (along.filter(|_| slope), grad) {
        (Some(a), true) => evaluate_impl::<true, true>(sets, x, a, p),
        (Some(a), false) => evaluate_impl::<false, true>(sets, x, a, p),
        (None, true) => evaluate_impl::<true, false>(sets, x, Along::NONE, p),
        (None, false) => evaluate_impl::<false, false>(sets, x, Along::NONE, p),
    }
}

fn evaluate_impl<const GRAD: bool, const SLOPE: bool>(
    sets: &[&AnySet],
    x: DVec3,
    along: Along,
    p: &EvalParams,
) -> Sample {
    let u = along.u;
    let mut acc = Accumulator::new(p.alpha, p.accumulation);
    let mut slopes = Slopes::default();
    let mut stats = EvalStats::default();
    let scale = |s: &AnySet| WeightScale::new(s.max_adj(), p.alpha, p.max_alpha);
    // The first rule's share of the tolerance and the budget's, once per evaluation.
    let (first_tol, budget) = rule_tolerances(p);
    let prune_margin = if p.prune {
        prune_margin(sets, p, first_tol)
    } else {
        f64::INFINITY
    };
    STACK.with_borrow_mut(|stack| {
        for set in sets {
            let sc = scale(set);
            let mut sink = Sink::<GRAD, SLOPE> {
                acc: &mut acc,
                slopes: &mut slopes,
                u,
                w_ff: sc.max_weight(),
                upper: p.upper_bound,
            };
            let share = p.far_share.share > 0.0;
            crate::with_set!(set, s => {
                if share {
                    Walk::<_, GRAD, SLOPE, true>::new(s, x, p, &sc, prune_margin, budget, &mut sink, &mut stats, stack).run()
                } else {
                    Walk::<_, GRAD, SLOPE, false>::new(s, x, p, &sc, prune_margin, budget, &mut sink, &mut stats, stack).run()
                }
            });
        }
    });
    let s_upper = if p.upper_bound {
        acc.upper()
    } else {
        f64::INFINITY
    };
    let kept = acc.shifted_sum();
    let pruned = if stats.pruned > 0 {
        // Subtrees pruned by the first rule hold less than the tolerance of the final
        // sum (module docs): add that bound back so s never exceeds the exact value.
        // Those pruned against the budget are in `acc.pruned` (added by `finish`).
        acc.inflate(1.0 + first_tol);
        first_tol * kept + acc.pruned
    } else {
        0.0
    };
    let (s, grad, underflow) = acc.finish();
    let reach = if SLOPE {
        slopes.free_distance(s, acc.m, p.alpha, pruned, along.max_len)
    } else {
        s
    };
    let reach_back = if SLOPE && s < along.back {
        slopes
            .reversed()
            .free_distance(s, acc.m, p.alpha, pruned, along.back)
    } else {
        s
    };
    // The terms that matter lie within a kernel width or so of the nearest.
    let derivatives = if SLOPE {
        slopes.derivatives(p.alpha, acc.m + 1.0 / p.alpha)
    } else {
        None
    };
    Sample {
        s,
        grad,
        d_seen: acc.m,
        underflow,
        reach,
        reach_back,
        slope: derivatives.map(|(slope, _)| slope),
        bend: derivatives.map(|(_, bend)| bend),
        stats,
        s_upper,
    }
}
