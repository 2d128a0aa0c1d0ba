//! The parameters of a smooth-distance evaluation and the work it reports (SPEC 2, 5,
//! 6), and the pruning tolerances they imply (`eval::smooth` module docs): shared by the
//! evaluation (`smooth`), its walk (`walk`) and the colour traversal (`colour`).

use crate::primitives::{AnySet, WeightScale};

use super::accumulate::Accumulation;

/// Relative size of the sum that pruned subtrees may add up to at most, by default
/// (queries, reports, the Python API): `s` is then within `2e-10 / alpha` of the exact
/// value. The tracer passes a larger one tied to its hit threshold (see
/// `render::tracer`): for a step or a hit test only `s` to a small share of epsilon
/// matters, and pruning more is what makes soft point clouds cheaper.
pub const PRUNE_TOLERANCE: f64 = 1e-10;

/// The largest share a caller asks for: the tracer's tolerance tied to epsilon and a
/// query's tolerance given as a length (`api::params::apply_tolerance`) stop here.
pub const MAX_PRUNE_TOLERANCE: f64 = 1e-2;

/// Share of the tolerance the first pruning rule takes when a budget is kept; the budget
/// takes the rest of `2 tol` (module docs).
const FIRST_RULE_SHARE: f64 = 0.25;

/// The tolerances of the first pruning rule and of the budget (0: no budget), whose sum
/// bounds the share of the sum that pruning may skip (module docs).
pub(super) fn rule_tolerances(p: &EvalParams) -> (f64, f64) {
    let tol = p.prune_tolerance;
    if p.budget && p.prune && p.accumulation == Accumulation::Stable {
        (FIRST_RULE_SHARE * tol, (2.0 - FIRST_RULE_SHARE) * tol)
    } else {
        (tol, 0.0)
    }
}

/// Far-field terms by their share of the sum (`eval::smooth` module docs): a subtree that
/// beta would open is also taken as one far-field term when its bound `n w exp(-alpha r)`
/// is at most `share` times the larger of the sum so far and `exp(-alpha level)`, the
/// sum where `s` equals `level` (an estimate from above of the value being computed: the
/// sum so far is small early in the walk). The term bounds its subtree from above, so
/// `s` stays a lower bound of the exact value; the share only decides how much work the
/// evaluation spends on accuracy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FarShare {
    /// At most this share of the sum per term, in `[0, 1)`; 0 turns the rule off.
    pub share: f64,
    /// The value `s` is expected not to exceed (`+inf`: unknown, the sum so far alone).
    pub level: f64,
}

impl FarShare {
    /// The rule off (the default): far fields by beta alone.
    pub const OFF: FarShare = FarShare {
        share: 0.0,
        level: f64::INFINITY,
    };
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
    /// Far-field terms of point clouds from the subtree's second moments (module docs),
    /// and edge and triangle sets' from their directional tables where they carry them
    /// for this `alpha` (`primitives::directional`); default on. Off, every far-field
    /// term is the closest-box one (the paper's).
    pub moments: bool,
    /// Also bound the exact value from above (`Sample::s_upper`; far-field subtrees at
    /// their lower bounds): one more exponential per far-field term, and point clouds'
    /// far fields from the closest box instead of moments (a moment term has no lower
    /// bound beside it). Default off.
    pub upper_bound: bool,
    /// Prune against a budget as well (module docs; default on, only with `prune` and
    /// the stable sum): the same tolerance, far fewer leaves.
    pub budget: bool,
    /// Far-field terms by their share of the sum as well as by beta ([`FarShare`];
    /// default off).
    pub far_share: FarShare,
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
            upper_bound: false,
            budget: true,
            far_share: FarShare::OFF,
        }
    }

    /// How far pruning may lower `s` at most: `2 prune_tolerance / alpha` (0 when off).
    pub fn pruning_bound(&self) -> f64 {
        if self.prune {
            2.0 * self.prune_tolerance / self.alpha
        } else {
            0.0
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
