//! The Barnes-Hut walk over the wide BVH (SPEC 6): the decisions of `eval::smooth`'s
//! module docs, made for the four slots of a wide node at once.
//!
//! A walk decides, for every subtree it meets, one of: pruned (negligible, covered from
//! above by the caller), far field (one term `n w exp(-alpha r)`), exact (a leaf's
//! primitives) or opened.

use super::params::{EvalParams, EvalStats};
use super::sink::Sink;
use crate::bvh::moments::{MIDDLE, lin_bound, quadratic_form};
use crate::bvh::wide::{EMPTY, Root};
use crate::bvh::{Moments4, Node4};
use crate::primitives::directional::{DirectionalTables, entry_centre};
use crate::primitives::{Primitive, PrimitiveSet, WeightScale};
use glam::DVec3;

/// A traversal stack entry: wide node (or first primitive of a leaf), the leaf's
/// primitive count (0 for a wide node), squared distance to its box.
#[derive(Clone, Copy)]
pub(super) struct Entry {
    i: u32,
    count: u32,
    r2: f64,
}

thread_local! {
    /// Each thread's traversal stack, kept between evaluations (it holds at most three
    /// entries per level of the wide tree plus one).
    pub(super) static STACK: std::cell::RefCell<Vec<Entry>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Far-field terms whose closest-box value is below `exp(-SIGNIFICANT)` of the nearest
/// distance's term take the closest-box form even when moments are kept: their share of
/// the sum is too small for the tighter bound to move `s`.
const SIGNIFICANT: f64 = 2.0;

/// One walk over one set at `x`: its decisions go to the sink and the statistics.
/// `SHARE`: far terms by share are asked for (`EvalParams::far_share`); a walk without
/// them carries no test of it.
pub(super) struct Walk<'w, 'a, P, const GRAD: bool, const SLOPE: bool, const SHARE: bool> {
    set: &'w PrimitiveSet<P>,
    x: DVec3,
    scale: &'w WeightScale,
    sink: &'w mut Sink<'a, GRAD, SLOPE>,
    stats: &'w mut EvalStats,
    stack: &'w mut Vec<Entry>,
    prune_margin: f64,
    inv_alpha: f64,
    /// `beta^2`, or -1 when far fields are off (beta = 0).
    beta2: f64,
    /// Weight of a far-field term per primitive.
    w_ff: f64,
    /// Second moments per wide node, when far fields use them (points).
    moments: &'w [Moments4],
    /// Directional tables, where the set has them for this `alpha` and `q` and far
    /// fields may be tighter than the closest box (edges and triangles of a rendered
    /// object).
    directional: Option<&'w DirectionalTables>,
    /// Share of the sum that subtrees pruned against the budget may hold together (0 =
    /// off; `eval::smooth` module docs).
    budget: f64,
    ln2_over_alpha: f64,
    alpha_log2e: f64,
    /// `floor(log2 w_ff) + 1`: `2^e_w` bounds the weight of one primitive.
    e_w: i64,
    /// `log2` of the far-field share (`EvalParams::far_share`; read only when `SHARE`).
    share_log2: f64,
    /// `level - log2(share) ln 2 / alpha`: a subtree of bound weight `nw` is a far term
    /// by share against the floor `exp(-alpha level)` beyond
    /// `log2(nw) ln 2 / alpha + share_reach` (`+inf` without a level).
    share_reach: f64,
}

/// `floor(log2 v)` for a positive normal `v`.
#[inline(always)]
fn exponent(v: f64) -> i64 {
    ((v.to_bits() >> 52) & 0x7ff) as i64 - 1023
}

/// Steps of the budget's charges per octave: a charge is the subtree's bound rounded up
/// to a power of `2^(1/STEPS)` (at most 9% above it); coarser steps (powers of 2: up to
/// four times the bound) would spend the budget on fewer subtrees.
const STEPS: usize = 8;

/// `log2(1 + i / STEPS)`, `i = 0 .. STEPS` (the last is 1), to the nearest double
/// (`log2_down` and `log2_up` move off it by more than its rounding).
const LOG2_STEP: [f64; STEPS + 1] = [
    0.0,
    0.16992500144231237,
    0.32192809488736235,
    0.45943161863729726,
    0.5849625007211562,
    0.7004397181410922,
    0.8073549220576041,
    0.9068905956085185,
    1.0,
];

/// `2^(-i / STEPS)`, `i = 0 .. STEPS`, to the nearest double (the charge's last factor
/// covers its rounding).
const EXP2_NEG_STEP: [f64; STEPS] = [
    1.0,
    0.9170040432046712,
    0.8408964152537145,
    0.7711054127039704,
    std::f64::consts::FRAC_1_SQRT_2,
    0.6484197773255048,
    0.5946035575013605,
    0.5452538663326288,
];

/// The mantissa's place among the `STEPS` steps of its octave, `floor(STEPS (f - 1))`
/// for `v = 2^e f`, `f` in `[1, 2)` (positive normal `v`).
#[inline(always)]
fn step_of(v: f64) -> usize {
    ((v.to_bits() >> (52 - STEPS.trailing_zeros())) as usize) & (STEPS - 1)
}

/// A lower bound of `log2 v` (within `log2(1 + 1/STEPS)`), positive normal `v`.
#[inline(always)]
fn log2_down(v: f64) -> f64 {
    exponent(v) as f64 + LOG2_STEP[step_of(v)] - 1e-15
}

/// An upper bound of `log2 v` (within `log2(1 + 1/STEPS)`), positive normal `v`.
#[inline(always)]
fn log2_up(v: f64) -> f64 {
    exponent(v) as f64 + LOG2_STEP[step_of(v) + 1] + 1e-15
}

/// `nw exp(-alpha dr)` (`dr >= 0`, `alpha_log2e = alpha log2 e`) rounded up to the next
/// power of `2^(1/STEPS)` times `nw`: `nw 2^(-j / STEPS)` with `j = floor(STEPS alpha dr
/// log2 e)`, the product shortened by 1e-12 so that rounding cannot carry `j` over a
/// step, and the last factor covering the products' rounding.
#[inline(always)]
fn step_charge(nw: f64, alpha_log2e: f64, dr: f64) -> f64 {
    let j = (dr * (STEPS as f64 * alpha_log2e) * (1.0 - 1e-12)) as i64;
    nw * pow2(-(j / STEPS as i64))
        * EXP2_NEG_STEP[(j % STEPS as i64) as usize]
        * (1.0 + 4.0 * f64::EPSILON)
}

/// `2^e` for `e <= 1023` (0 below the normal range, where the charge is negligible).
#[inline(always)]
fn pow2(e: i64) -> f64 {
    if e < -1022 {
        0.0
    } else {
        f64::from_bits(((e + 1023).min(2046) as u64) << 52)
    }
}

impl<'w, 'a, P: Primitive, const GRAD: bool, const SLOPE: bool, const SHARE: bool>
    Walk<'w, 'a, P, GRAD, SLOPE, SHARE>
{
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        set: &'w PrimitiveSet<P>,
        x: DVec3,
        p: &EvalParams,
        scale: &'w WeightScale,
        prune_margin: f64,
        budget: f64,
        sink: &'w mut Sink<'a, GRAD, SLOPE>,
        stats: &'w mut EvalStats,
        stack: &'w mut Vec<Entry>,
    ) -> Self {
        // Read only by walks with `SHARE`, which run where the share is positive.
        let share_log2 = p.far_share.share.log2();
        Walk {
            set,
            x,
            scale,
            sink,
            stats,
            stack,
            prune_margin,
            inv_alpha: 1.0 / p.alpha,
            beta2: if p.beta > 0.0 { p.beta * p.beta } else { -1.0 },
            w_ff: scale.max_weight(),
            // A moment term has no lower bound beside it: an upper bound of the value
            // takes closest-box far fields (`EvalParams::upper_bound`).
            moments: if p.moments && !p.upper_bound {
                &set.bvh.moments
            } else {
                &[]
            },
            directional: set
                .directional
                .as_deref()
                .filter(|t| p.moments && t.alpha == p.alpha && t.q == scale.q),
            budget,
            ln2_over_alpha: std::f64::consts::LN_2 / p.alpha,
            alpha_log2e: p.alpha * std::f64::consts::LOG2_E,
            e_w: exponent(scale.max_weight()) + 1,
            share_log2,
            share_reach: p.far_share.level - share_log2 * std::f64::consts::LN_2 / p.alpha,
        }
    }

    /// Subtrees whose box is farther than this (squared) are negligible now (module docs
    /// of `eval::smooth`).
    #[inline(always)]
    fn reach2(&self) -> f64 {
        let acc = &self.sink.acc;
        let reach = acc.m + (self.prune_margin - acc.ln_sum_lower_bound() * self.inv_alpha);
        reach * reach
    }

    /// What is left of the budget, `tol S - P` (at most 0 when off or spent).
    #[inline(always)]
    fn budget_left(&self) -> f64 {
        self.budget * self.sink.acc.shifted_sum() - self.sink.acc.pruned
    }

    /// Below this squared distance no subtree fits in what is left of the budget, not
    /// even a single primitive (`+inf` when off or spent): one comparison spares the
    /// others the test.
    #[inline(always)]
    fn budget2(&self) -> f64 {
        let left = self.budget_left();
        if left > 0.0 {
            let k = (self.e_w - exponent(left)).max(0);
            let need = self.sink.acc.m + k as f64 * self.ln2_over_alpha;
            need * need
        } else {
            f64::INFINITY
        }
    }

    /// Prunes a subtree of `n` primitives at squared distance `r2` if its bound
    /// `b = n w exp(-alpha (r - m))` fits in what is left of the budget `tol S - P`.
    /// `b <= left` needs `alpha (r - m) >= ln(n w / left)`, tested first with bounds of
    /// both logarithms (mantissas looked up in `STEPS` steps per octave, no logarithm
    /// computed); then `P` grows by the charge `n w 2^(-j / STEPS)`, `j = floor(STEPS
    /// alpha (r - m) log2 e)`, which is `b` rounded up to the next step (at most 9%
    /// above it; the last factor covers the products' rounding) and is charged only if
    /// it still fits.
    #[inline(always)]
    fn budget_prune(&mut self, r2: f64, n: u32) -> bool {
        let left = self.budget_left();
        if left <= 0.0 {
            return false;
        }
        let acc = &mut *self.sink.acc;
        let nw = n as f64 * self.w_ff;
        let k = (log2_up(nw) - log2_down(left)).max(0.0);
        let need = acc.m + k * self.ln2_over_alpha;
        if r2 < need * need {
            return false;
        }
        let charge = step_charge(nw, self.alpha_log2e, r2.sqrt() - acc.m);
        if charge > left {
            return false;
        }
        acc.pruned += charge;
        self.stats.pruned += 1;
        true
    }

    /// A subtree of `n` primitives at squared distance `r2 > 0` whose bound `b = n w
    /// exp(-alpha r)` is at most the share of the larger of the sum so far and the
    /// level's floor (`EvalParams::far_share`), tested with bounds of the logarithms
    /// (as `budget_prune`): against the floor, `alpha r >= ln(n w) + alpha level - ln
    /// share`; against the shifted sum `S`, `alpha (r - m) >= ln(n w) - ln(share S)`.
    #[inline(always)]
    fn small_share(&self, r2: f64, n: u32) -> bool {
        if r2 <= 0.0 {
            return false;
        }
        let l = log2_up(n as f64 * self.w_ff);
        let floor = l * self.ln2_over_alpha + self.share_reach;
        if floor <= 0.0 || r2 >= floor * floor {
            return true;
        }
        let acc = &self.sink.acc;
        let sum = acc.shifted_sum();
        if sum <= 0.0 || !sum.is_normal() {
            return false;
        }
        let need = acc.m + (l - log2_down(sum) - self.share_log2) * self.ln2_over_alpha;
        need <= 0.0 || r2 >= need * need
    }

    #[inline(always)]
    fn far_ok(&self, diam2: f32, r2: f64) -> bool {
        (diam2 as f64) < self.beta2 * r2
    }

    /// A whole walk from the root.
    pub fn run(&mut self) {
        let Some(root) = self.set.bvh.wide_root else {
            return;
        };
        self.root(&root);
    }

    fn root(&mut self, root: &Root) {
        let (rmin, rmax) = (
            DVec3::from(root.min.map(f64::from)),
            DVec3::from(root.max.map(f64::from)),
        );
        let x = self.x;
        let r2 = (x - x.clamp(rmin, rmax)).length_squared();
        if root.count == 0 && self.far_ok(root.diam2, r2) {
            self.sink
                .far(x, r2, root.size as f64 * self.w_ff, (rmin, rmax), None);
            self.stats.far += 1;
            return;
        }
        self.stack.clear();
        self.stack.push(Entry {
            i: root.child,
            count: root.count,
            r2,
        });
        self.drain();
    }

    /// Pops and decides stack entries until the stack is empty.
    fn drain(&mut self) {
        let wide = &self.set.bvh.wide;
        while let Some(e) = self.stack.pop() {
            self.stats.nodes += 1;
            let reach2 = self.reach2();
            if e.r2 > reach2 {
                self.stats.pruned += 1;
                continue;
            }
            if e.count > 0 {
                let first = e.i as usize;
                let prims = &self.set.prims[first..first + e.count as usize];
                self.sink.exact_leaf(prims, self.x, self.scale);
                self.stats.exact += e.count;
                continue;
            }
            // (Only a wide node's slots need it: not computed for a leaf.)
            let budget2 = self.budget2();
            let node = &wide[e.i as usize];
            let d2 = node.distances2(self.x);
            // The children to open go on the stack above `open`, farthest first.
            let open = self.stack.len();
            for j in 0..2 {
                self.middle(node, e.i, j, &d2, (reach2, budget2), open);
            }
        }
    }

    /// Pushes slot `k` of `node` at squared distance `d2` among the children opened
    /// above stack position `open`, kept farthest first (a child as far as one already
    /// there goes above it), so that the nearest is popped first.
    #[inline(always)]
    fn open(&mut self, node: &Node4, k: usize, d2: f64, open: usize) {
        let e = Entry {
            i: node.child[k],
            count: node.count[k],
            r2: d2,
        };
        let stack = &mut *self.stack;
        stack.push(e);
        let mut h = stack.len() - 1;
        while h > open && stack[h - 1].r2 < d2 {
            stack[h] = stack[h - 1];
            h -= 1;
        }
        stack[h] = e;
    }

    /// Decides middle `j` of wide node `i`: pruned or far field as a whole, at the
    /// distance of its nearer child box (a lower bound of every distance below it), or
    /// its two slots one by one.
    #[inline(always)]
    fn middle(
        &mut self,
        node: &Node4,
        i: u32,
        j: usize,
        d2: &[f64; 4],
        (reach2, budget2): (f64, f64),
        open: usize,
    ) {
        let near = if d2[2 * j] <= d2[2 * j + 1] {
            2 * j
        } else {
            2 * j + 1
        };
        let r2m = d2[near];
        if r2m > reach2 {
            self.stats.pruned += 1;
            return;
        }
        if self.far_ok(node.mid_diam2[j], r2m) {
            // (A middle that is a leaf in its slot has an infinite diameter.)
            self.far_middle(node, i, j, (near, r2m));
            return;
        }
        if r2m >= budget2 && self.budget_prune(r2m, node.mid_size[j]) {
            return;
        }
        if SHARE && node.mid_diam2[j].is_finite() && self.small_share(r2m, node.mid_size[j]) {
            self.far_middle(node, i, j, (near, r2m));
            return;
        }
        for k in [2 * j, 2 * j + 1] {
            self.slot(node, i, k, d2[k], (reach2, budget2), open);
        }
    }

    /// The far-field term of slot `k` of wide node `i` at squared distance `d2k > 0`.
    #[inline(always)]
    fn far_slot(&mut self, node: &Node4, i: u32, k: usize, d2k: f64) {
        let bx = node.slot_box(k);
        let w = node.size[k] as f64 * self.w_ff;
        self.far_entry(i, k, bx, w, (d2k, bx, None));
    }

    /// The far-field term of middle `j` of wide node `i` (both slots in use), its nearer
    /// slot `near` at squared distance `r2m > 0`.
    #[inline(always)]
    fn far_middle(&mut self, node: &Node4, i: u32, j: usize, (near, r2m): (usize, f64)) {
        let w = node.mid_size[j] as f64 * self.w_ff;
        let (b1, b2) = (node.slot_box(2 * j), node.slot_box(2 * j + 1));
        let bx = (b1.0.min(b2.0), b1.1.max(b2.1));
        let (near_box, other) = if near == 2 * j { (b1, b2) } else { (b2, b1) };
        self.far_entry(i, MIDDLE + j, bx, w, (r2m, near_box, Some(other)));
    }

    /// A far-field term of weight `w` for entry `e` of wide node `i`'s moments (box
    /// `bx`): from its second moments if kept, else the closest-box term of `near`.
    #[inline(always)]
    fn far_entry(
        &mut self,
        i: u32,
        e: usize,
        bx: (DVec3, DVec3),
        w: f64,
        near: (f64, (DVec3, DVec3), Option<(DVec3, DVec3)>),
    ) {
        self.stats.far += 1;
        // Directional terms, as moment terms, only where the term can matter (within
        // `SIGNIFICANT` of the nearest distance seen, counting its weight).
        let ln_w = (((w.to_bits() >> 52) & 0x7ff) as f64 - 1022.0) * std::f64::consts::LN_2;
        if let Some(t) = self.directional {
            let reach = self.sink.acc.m + (SIGNIFICANT + ln_w.max(0.0)) * self.inv_alpha;
            if near.0 < reach * reach {
                let node = &self.set.bvh.wide[i as usize];
                let c = entry_centre(node, e);
                if let Some((l, d, ends)) = t.bounds(i as usize, e, c, self.x) {
                    // Edges: the split bound where it is the smaller (`primitives::split`).
                    let d = match (ends, t.split()) {
                        (Some(d_ends), Some(s)) => {
                            s.bound(s.range(node, e), self.x, (c, l), (d_ends, d), t.alpha)
                        }
                        _ => d,
                    };
                    let alpha = t.alpha;
                    // The smaller of the two bounds (either holds; `ln_w` is at least
                    // `ln w`).
                    if d - alpha * l < ln_w - alpha * near.0.sqrt() {
                        self.sink.far_directional(
                            self.x,
                            l - d / alpha,
                            (self.x - c) / l,
                            w,
                            near.1,
                            near.2,
                        );
                        return;
                    }
                }
            }
        }
        // Moment terms only where the term can matter: within `SIGNIFICANT` (in units
        // of alpha times distance) of the nearest distance seen, counting its weight.
        let reach = self.sink.acc.m + (SIGNIFICANT + ln_w.max(0.0)) * self.inv_alpha;
        match self
            .moments
            .get(i as usize)
            .filter(|_| near.0 < reach * reach)
        {
            Some(m) => {
                let entry = &m.e[e];
                let crel = entry.c;
                let c = bx.0 + DVec3::new(crel[0] as f64, crel[1] as f64, crel[2] as f64);
                let mm = entry.m.map(f64::from);
                let sigma2 = |u: DVec3| quadratic_form(&mm, u);
                let lin = lin_bound(crel, c);
                self.sink.far_moments(self.x, w, bx, c, sigma2, lin, near);
            }
            None => self.sink.far(self.x, near.0, w, near.1, near.2),
        }
    }

    /// Decides slot `k` of wide node `i` at squared distance `d2k`: pruned, far field,
    /// or to be opened (leaves too: they are summed when popped).
    #[inline(always)]
    fn slot(
        &mut self,
        node: &Node4,
        i: u32,
        k: usize,
        d2k: f64,
        (reach2, budget2): (f64, f64),
        open: usize,
    ) {
        let c = node.count[k];
        if c == EMPTY {
            return;
        }
        if d2k > reach2 {
            self.stats.pruned += 1;
            return;
        }
        if c == 0 && self.far_ok(node.diam2[k], d2k) {
            self.far_slot(node, i, k, d2k);
            return;
        }
        if d2k >= budget2 && self.budget_prune(d2k, node.size[k]) {
            return;
        }
        if SHARE && self.small_share(d2k, node.size[k]) {
            self.far_slot(node, i, k, d2k);
            return;
        }
        self.open(node, k, d2k, open);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values over the whole normal range, and every step of an octave.
    fn samples() -> impl Iterator<Item = f64> {
        let mut seed = 11u64;
        (0..20_000).map(move |k| {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            let f = 1.0 + (seed >> 11) as f64 / (1u64 << 53) as f64;
            f * 2f64.powi((k % 2000) - 1000)
        })
    }

    #[test]
    fn stepped_logarithms_bracket_log2_within_a_step() {
        let step = (1.0 + 1.0 / STEPS as f64).log2();
        for v in samples().chain((0..=STEPS).map(|i| 1.0 + i as f64 / STEPS as f64)) {
            let (lo, hi, l) = (log2_down(v), log2_up(v), v.log2());
            assert!(lo <= l && l <= hi, "{v}: {lo} {l} {hi}");
            assert!(hi - lo <= step + 1e-12, "{v}: {lo} {hi}");
        }
    }

    #[test]
    fn stepped_charges_bound_the_subtree_within_a_step() {
        let step = 2f64.powf(1.0 / STEPS as f64);
        let mut seed = 5u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..100_000 {
            let nw = (1.0 + 1e6 * rnd()).floor() * (0.5 + rnd());
            let alpha = 10f64.powf(4.0 * rnd() - 2.0);
            let dr = 600.0 * rnd() / alpha;
            let b = nw * (-alpha * dr).exp();
            let c = step_charge(nw, alpha * std::f64::consts::LOG2_E, dr);
            assert!(
                c >= b,
                "charge {c} below the bound {b} (nw {nw}, alpha dr {})",
                alpha * dr
            );
            assert!(
                c <= b * step * (1.0 + 1e-9),
                "charge {c} above a step over {b}"
            );
        }
        // On the steps themselves (where rounding could carry `j` over one).
        for j in 0..64 {
            let dr = j as f64 / STEPS as f64 * std::f64::consts::LN_2;
            let b = (-dr).exp();
            assert!(
                step_charge(1.0, std::f64::consts::LOG2_E, dr) >= b,
                "step {j}"
            );
        }
    }
}
