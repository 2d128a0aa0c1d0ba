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
//!   subtrees much nearer (the lidar scan: 377 -> 269 leaves per ray; 183.7 -> 168.4 at
//!   1920x1080 with eighths instead of powers of two). Far fields are decided first: a
//!   far term costs no more than the charge, and the budget is kept for subtrees that
//!   would be opened. The union bound leaves most of its share unspent (its subtrees
//!   are far), the budget spends what it charges: moving three quarters of the first
//!   rule's share to the budget, the lidar at 960x540 visits 177.7 -> 169.6 leaves per
//!   ray (the deer and the meshes 0-2% fewer).
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
//! slots) that is far field adds its two slots' terms. Same nodes visited; `s` several
//! times closer to the exact value on soft clouds (`ln F` is about `alpha^2 sigma^2 / 2`
//! against `alpha diam` for the box).
//!
//! The walk runs on the BVH's 4-wide form (`bvh::wide`): opening a wide node tests the
//! four grandchildren of a binary node at once and makes the decisions above for the
//! two children between (far field at the distance of the nearer of their own
//! children's boxes, which bounds every primitive below from below, as the box does)
//! and then for the grandchildren. Far-field terms are added when their parent is
//! opened; the rest is pushed farthest first, so leaves are still met near to far.

use super::accumulate::{Accumulation, Accumulator};
use super::reach::Slopes;
use super::walk::{STACK, Walk};
use crate::primitives::{AnySet, Primitive, WeightScale};
use glam::DVec3;

/// Relative size of the sum that pruned subtrees may add up to at most, by default
/// (queries, reports, the Python API): `s` is then within `2e-10 / alpha` of the exact
/// value. The tracer passes a larger one tied to its hit threshold (see
/// `render::tracer`): for a step or a hit test only `s` to a small share of epsilon
/// matters, and pruning more is what makes soft point clouds cheaper.
pub const PRUNE_TOLERANCE: f64 = 1e-10;

/// Share of the tolerance the first pruning rule takes when a budget is kept; the budget
/// takes the rest of `2 tol` (module docs).
const FIRST_RULE_SHARE: f64 = 0.25;

/// The tolerances of the first pruning rule and of the budget (0: no budget), whose sum
/// bounds the share of the sum that pruning may skip (module docs).
fn rule_tolerances(p: &EvalParams) -> (f64, f64) {
    let tol = p.prune_tolerance;
    if p.budget && p.prune && p.accumulation == Accumulation::Stable {
        (FIRST_RULE_SHARE * tol, (2.0 - FIRST_RULE_SHARE) * tol)
    } else {
        (tol, 0.0)
    }
}

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
    /// Far-field terms of point clouds from the subtree's second moments (module docs;
    /// default on). Off, every far-field term is the closest-box one (the paper's).
    pub moments: bool,
    /// Prune against a budget as well (module docs; default on, only with `prune` and
    /// the stable sum): the same tolerance, far fewer leaves.
    pub budget: bool,
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
            moments: true,
            budget: true,
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
    /// Free distance along the direction given to [`evaluate_reach`]: the smooth
    /// distance stays positive on `x + [0, reach] u` (`eval::reach`); `s` otherwise.
    pub reach: f64,
    /// Free distance backwards, on `x - [0, reach_back] u`, when asked for by
    /// [`Along::back`] and `s` is below it (at most that length); `s` otherwise.
    pub reach_back: f64,
    pub stats: EvalStats,
}

/// `g(z) = (e^z - 1 - z) / z^2` for `z >= 0`, from above (to a relative 1e-11): its
/// Taylor series `sum z^k / (k + 2)!` to `k = 9` (remainder below `z^10 / 12!`) under
/// 0.5, else from `exp` (no cancellation there), `+inf` past 700.
#[inline]
pub(crate) fn bennett_g(z: f64) -> f64 {
    if z < 0.5 {
        const C: [f64; 10] = [
            1.0 / 2.0,
            1.0 / 6.0,
            1.0 / 24.0,
            1.0 / 120.0,
            1.0 / 720.0,
            1.0 / 5040.0,
            1.0 / 40320.0,
            1.0 / 362880.0,
            1.0 / 3628800.0,
            1.0 / 39916800.0,
        ];
        C.iter().rev().fold(0.0, |acc, &c| acc * z + c) + 1e-11
    } else if z < 700.0 {
        (z.exp() - 1.0 - z) / (z * z)
    } else {
        f64::INFINITY
    }
}

/// Grid step of [`bennett_g_chord`]'s table, and the grid's end.
const G_STEP: f64 = 0.25;
const G_END: f64 = 32.0;
const G_POINTS: usize = (G_END / G_STEP) as usize + 1;

/// `bennett_g` at the grid points `k G_STEP`, rounded up.
static G_TABLE: std::sync::LazyLock<[f64; G_POINTS]> = std::sync::LazyLock::new(|| {
    std::array::from_fn(|k| bennett_g(k as f64 * G_STEP) * (1.0 + 1e-12))
});

/// An upper bound of `g(z)` for `z >= 0` that costs no exponential: `g` is convex (its
/// Taylor coefficients are positive), so on each grid interval the chord through its
/// ends lies above it (by at most 0.7%: `e^z` over a quarter bends that much); past the
/// grid, `bennett_g` itself (both rounded up by a relative 1e-12, above the rounding of
/// `exp`). Saves the far-field terms of point clouds one exponential each (deer alpha 1
/// trace 3-5% faster).
#[inline]
pub(crate) fn bennett_g_chord(z: f64) -> f64 {
    if z < G_END {
        let table = &*G_TABLE;
        let u = z.max(0.0) * (1.0 / G_STEP);
        let k = (u as usize).min(G_POINTS - 2);
        let (lo, hi) = (table[k], table[k + 1]);
        lo + (hi - lo) * (u - k as f64)
    } else {
        bennett_g(z) * (1.0 + 1e-12)
    }
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
/// `eval::reach`). Only sets of points have weights that do not vary along the ray: with
/// any other set, or the naive sum, `reach` is `s`.
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
    let points = sets.iter().all(|s| matches!(s, AnySet::Points(_)));
    let slope = points && p.accumulation == Accumulation::Stable;
    match (along.filter(|_| slope), grad) {
        (Some(a), true) => evaluate_impl::<true, true>(sets, x, a, p),
        (Some(a), false) => evaluate_impl::<false, true>(sets, x, a, p),
        (None, true) => evaluate_impl::<true, false>(sets, x, Along::NONE, p),
        (None, false) => evaluate_impl::<false, false>(sets, x, Along::NONE, p),
    }
}

/// `ln(N w_max / tol) / alpha` for the `N` primitives of `sets` and their largest
/// weight: a subtree farther than `m + margin - ln(S) / alpha` (module docs) holds less
/// than `tol S / N` per primitive, so all such subtrees together hold less than `tol` of
/// the sum. Shared with the colour traversal (`eval::colour`).
pub(crate) fn prune_margin(sets: &[&AnySet], p: &EvalParams, tol: f64) -> f64 {
    let total: usize = sets.iter().map(|s| s.len()).sum();
    let w_max = sets
        .iter()
        .map(|s| WeightScale::new(s.max_adj(), p.alpha, p.max_alpha).max_weight())
        .fold(1.0, f64::max);
    (total.max(1) as f64 * w_max / tol).ln() / p.alpha
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
            };
            crate::with_set!(set, s => {
                Walk::new(s, x, p, &sc, prune_margin, budget, &mut sink, &mut stats, stack).run()
            });
        }
    });
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
    Sample {
        s,
        grad,
        d_seen: acc.m,
        underflow,
        reach,
        reach_back,
        stats,
    }
}

/// Where a traversal's terms go: the accumulator, with the gradient if `GRAD`, and the
/// terms' slopes along `u`, binned for the free distance, if `SLOPE` (`eval::reach`).
pub(super) struct Sink<'a, const GRAD: bool, const SLOPE: bool> {
    pub acc: &'a mut Accumulator,
    pub slopes: &'a mut Slopes,
    pub u: DVec3,
}

impl<const GRAD: bool, const SLOPE: bool> Sink<'_, GRAD, SLOPE> {
    /// The slope bins follow the accumulator's shift when a term lowers it.
    #[inline]
    fn add_slope(&mut self, m_before: f64, e: f64, a: f64) {
        if self.acc.m < m_before {
            let alpha = self.acc.alpha();
            self.slopes
                .rescale((-alpha * (m_before - self.acc.m)).exp());
        }
        self.slopes.add(e, a);
    }

    /// The far-field term of a subtree with box `min..max` at squared distance `r2 > 0`.
    /// A middle (`other` = its farther child's box, the term at the nearer one's
    /// distance) takes the smaller of the two boxes' slopes along the ray: each child's
    /// distance is at least its own box's linear bound, and the nearer box's distance at
    /// the sample is the smaller, so that line bounds both ahead (`eval::reach`).
    #[inline]
    pub fn far(
        &mut self,
        x: DVec3,
        r2: f64,
        weight: f64,
        (min, max): (DVec3, DVec3),
        other: Option<(DVec3, DVec3)>,
    ) {
        let r = r2.sqrt();
        let m = self.acc.m;
        let slope_other = |u: DVec3| {
            other.map_or(1.0, |(lo, hi)| {
                let v = x - x.clamp(lo, hi);
                let d = v.length();
                if d > 0.0 { v.dot(u) / d } else { -1.0 }
            })
        };
        if GRAD {
            let dir = (x - x.clamp(min, max)) / r;
            let e = self.acc.add(r, weight, dir, DVec3::ZERO);
            if SLOPE {
                self.add_slope(m, e, dir.dot(self.u).min(slope_other(self.u)));
            }
        } else if SLOPE {
            let a = (x - x.clamp(min, max)).dot(self.u) / r;
            let e = self.acc.add_value(r, weight);
            self.add_slope(m, e, a.min(slope_other(self.u)));
        } else {
            self.acc.add_value(r, weight);
        }
    }

    /// The far-field term of a subtree of `n` points of weight at most `w` (`weight =
    /// n w`) in the box `bx` at squared distance `r2 > 0` from `x` (closest-box term in
    /// `near`: its squared distance, box and, for a middle, the farther child's box),
    /// from their second moment about the
    /// reference point `c` (`sigma2(u) >= u^T M u`) whose distance to their mean is at
    /// most `lin` (module docs): the moment bound where it is below the box term.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn far_moments(
        &mut self,
        x: DVec3,
        weight: f64,
        bx: (DVec3, DVec3),
        c: DVec3,
        sigma2: impl Fn(DVec3) -> f64,
        lin: f64,
        (r2, near, other): (f64, (DVec3, DVec3), Option<(DVec3, DVec3)>),
    ) {
        let v = x - c;
        let l2 = v.length_squared();
        if l2 > 0.0 {
            let alpha = self.acc.alpha();
            let l = l2.sqrt();
            let u = v * (1.0 / l);
            // The largest u . (q - c) over the box bounds every point's.
            let far_corner = DVec3::select(u.cmpge(DVec3::ZERO), bx.1, bx.0);
            let z = alpha * u.dot(far_corner - c).max(0.0);
            let f = (1.0 + alpha * lin + alpha * alpha * sigma2(u).max(0.0) * bennett_g_chord(z))
                * (1.0 + 1e-9);
            // ln f <= f - 1: where `f - 1 <= alpha (l - r)` the moment term is the smaller.
            let reach = l - (f - 1.0) / alpha;
            if reach >= 0.0 && reach * reach >= r2 {
                self.term(l, weight * f, u);
                return;
            }
        }
        self.far(x, r2, weight, near, other);
    }

    /// A far-field term at distance `d` with unit direction `dir` (the gradient of `d`,
    /// and its slope along the ray is `dir . u` exactly).
    #[inline]
    fn term(&mut self, d: f64, weight: f64, dir: DVec3) {
        let m = self.acc.m;
        if GRAD {
            let e = self.acc.add(d, weight, dir, DVec3::ZERO);
            if SLOPE {
                self.add_slope(m, e, dir.dot(self.u));
            }
        } else if SLOPE {
            let e = self.acc.add_value(d, weight);
            self.add_slope(m, e, dir.dot(self.u));
        } else {
            self.acc.add_value(d, weight);
        }
    }

    /// A primitive's exact term.
    #[inline]
    pub fn exact<P: Primitive>(&mut self, prim: &P, x: DVec3, scale: &WeightScale) {
        let m = self.acc.m;
        if GRAD {
            let t = prim.term(x, scale);
            let e = self.acc.add(t.d, t.w, t.dir, t.grad_w);
            if SLOPE {
                self.add_slope(m, e, t.dir.dot(self.u));
            }
        } else if SLOPE {
            let (d, w, a) = prim.value_slope(x, self.u, scale);
            let e = self.acc.add_value(d, w);
            self.add_slope(m, e, a);
        } else {
            let (d, w) = prim.value(x, scale);
            self.acc.add_value(d, w);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `g(z)` in long arithmetic: its series to convergence (all terms positive).
    fn g_series(z: f64) -> f64 {
        let (mut term, mut sum, mut k) = (0.5f64, 0.0f64, 0.0f64);
        while term > 1e-18 * sum.max(1e-300) || k < 3.0 {
            sum += term;
            k += 1.0;
            term *= z / (k + 2.0);
        }
        sum
    }

    #[test]
    fn bennett_g_chord_bounds_g_from_above_and_stays_close() {
        let mut worst: f64 = 0.0;
        for i in 0..=40_000 {
            let z = i as f64 * 1e-3;
            let g = g_series(z);
            let chord = bennett_g_chord(z);
            assert!(chord >= g, "z {z}: chord {chord} below g {g}");
            assert!(
                bennett_g(z) >= g * (1.0 - 1e-14),
                "z {z}: bennett_g below g"
            );
            worst = worst.max(chord / g - 1.0);
        }
        // Chords of a convex function on steps of 1/4 (g bends like e^z for large z).
        assert!(worst < 7e-3, "chord up to {worst} above g");
        assert!(bennett_g_chord(1e3).is_infinite() && bennett_g_chord(0.0) >= 0.5);
    }
}
