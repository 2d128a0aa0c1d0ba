//! Sphere tracing of the zero set of the scene's smooth distance (SPEC 7).
//!
//! The scene's field is the minimum over objects of their smooth distances. Along a ray
//! `x(t) = o + t d` (unit `d`):
//! 1. Clip the ray to the union of the objects' boxes grown by their reach
//!    (`ln(N w_max) / alpha`, see [`TraceObject::reach`]): outside it the field is
//!    positive, so a ray missing it is a miss with no evaluation, and `t_max` is exact.
//! 2. Step `t += s(x(t))`. An object whose cheap lower bound (box distance minus reach)
//!    is already above the current minimum is not evaluated.
//! 3. Naive mode only: when an evaluation is `+inf` (the sum underflowed), retry with
//!    `alpha / 10` until finite and step by that smaller, safe value (alpha falloff).
//! 4. Hit when `|s| <= epsilon`. A step that lands below `-epsilon` (the smooth distance
//!    is not a lower bound of the distance to its own zero set) is backtracked: the
//!    crossing is bracketed by the last positive `t` and this one and found by the
//!    Illinois (safeguarded regula falsi) method to within `epsilon`
//!    (`render::backtrack`). A hit at a positive value `s` is moved on by one more
//!    step that needs no evaluation: the value is a lower bound of the exact smooth
//!    distance, which is 1-Lipschitz, so the ball of radius `s` around the sample holds
//!    no point of the exact zero set; the sample's free distance along the ray (item 8,
//!    `eval::reach`) certifies as much, often more, and the step takes it up to `2 s`
//!    ([`FINAL_REACH`](hit::FINAL_REACH)). The hit stays in front of the surface and
//!    comes closer to it.
//!    On edges and triangles the free distance holds to first order in the weights'
//!    change, and a step by it can land past the exact surface, in the band below zero:
//!    a hit at a negative value there is moved back by the crossing's first-order
//!    estimate `s / k` (`k` the field's fall along the ray, from the gradient), no
//!    farther than the last positive sample. (On points every step is certain, and a
//!    value below zero only says the Barnes-Hut sum is low there: the hit stays.) Both
//!    moves are made only where the gradient says the field falls along the ray (a ray
//!    past its closest approach to a thin tube would only climb away).
//!    The normal is the gradient at the sample (at most `2 epsilon` away).
//! 5. Far from the surface, steps are bound steps: a coarser Barnes-Hut sum
//!    (`coarse_beta`, cheaper, and a lower bound of the scene's sum, so the steps stay
//!    safe) until it falls below `coarse_threshold * epsilon` (`coarse_threshold_points`
//!    when every object is a point cloud: their full steps are made at the cheaper step
//!    beta, item 10, so they take over earlier); from there on the scene's own beta
//!    decides the hit. The bound value that falls through is still a safe step
//!    when it is above epsilon (no full value there could hit), and it is taken: on
//!    edges and triangles the coarse sum is nearly exact, and a full evaluation at the
//!    same point would only repeat it. (Not near soft triangle meshes, where its
//!    closest-box far terms put it 15-30 epsilons low: there its far terms take the
//!    directional tables too, `TraceObject::evaluate`, and the bound steps end nearer
//!    the surface; doc/performance-log.md, round thirty.) On edges and triangles the
//!    full value that follows a bound that fell through is taken at the hit beta, with
//!    the gradient (item 9): at the scene's beta it is several epsilons low near their
//!    surfaces and only takes a step the next, finer evaluation repeats
//!    (doc/performance-log.md, round twenty-six). The gap between that bound value and
//!    the full value that follows is kept: a later bound step is taken only where the
//!    full value minus the gap clears twice the threshold (near a soft point cloud the
//!    coarse sum is several epsilons low, and a bound step there would only fall
//!    through again).
//!    Primary rays reach this loop after their tile's cone march (`render::cone`), which
//!    takes the far steps once for a whole tile, and start past the stretch that the
//!    empty balls of the tile's last rays already certify (`render::neighbours`); a step
//!    whose own certified stretch (ball or free distance) reaches more of those balls
//!    goes on to the end of their chain.
//! 6. Full-accuracy evaluations prune with a tolerance tied to epsilon: subtrees whose
//!    terms hold together less than `tol = min(0.025 alpha epsilon, 1e-2)` of the sum
//!    are skipped and covered from above, which lowers `s` by at most `2 tol / alpha`, 5%
//!    of epsilon (`eval::smooth`; queries keep the default 1e-10). The cap binds where
//!    `alpha epsilon` exceeds 0.4. What each setting bought (leaves per ray against the
//!    accuracy at the hits) is in doc/performance-log.md, rounds ten and twelve.
//! 7. The normal is the normalised gradient at the hit. Steps need only the value, so
//!    they use value-only evaluations; an evaluation predicted to hit (its predecessor's
//!    value within two epsilons, or a linear extrapolation of the last two values
//!    within two; four where the tile's steps are made at the hit beta, item 10, and
//!    the gradient is all a prediction adds) carries the gradient, so most hits need
//!    no second traversal. Before
//!    two full values give a slope, point clouds guess that a step by the free distance
//!    halves the value (0.3-0.6 per step on logged lidar rays); a slope of 1 would
//!    predict a hit, and pay for a fine evaluation, after every first full step.
//! 8. Steps are over-relaxed (`render::stepper`): up to `2 s / (1 + k)` for a slope `k` of the
//!    field along the ray, kept only when the next sample's ball closes the gap (or its
//!    free distance behind it, asked for only then: `eval::reach`), else the ray
//!    returns to the plain step; a sample's free distance ahead, when longer, is the
//!    step. Same surface, fewer steps at grazing incidence.
//! 9. Hits are decided at a finer beta (`TracerOptions::hit_beta_scale` times the
//!    scene's, 0.6 by default; 0.8, `hit_beta_scale_soft_triangles`, for soft fields
//!    over triangle meshes, `TraceObject::soft_triangles`, where with the directional
//!    far field it keeps the hits within the accuracy goals with a quarter fewer leaves:
//!    doc/performance-log.md, rounds twenty-one and twenty-nine; 0.99,
//!    `hit_beta_scale_edges`, for objects made of edges alone, whose far terms split
//!    each edge's weight into its ends' and the bump inside it (`primitives::split`) and
//!    keep the hits closer to the exact surface there than the directional tables alone
//!    did at 0.8: round thirty-five): the Barnes-Hut sum is a lower bound of the exact one,
//!    but where `alpha` times the size of far-field nodes is large (soft point clouds,
//!    dense edge meshes at small `alpha`) it can be many epsilons low, and a ray that
//!    stops where it drops below epsilon stops short of the exact surface. Evaluations
//!    predicted to hit, and any whose value falls in the hit band or below, are taken at
//!    the finer beta (still a lower bound, so the step that got there stays safe); from
//!    the first such evaluation on, the ray's full evaluations stay fine (`sticky`). Steps far from
//!    the surface keep the scene's beta, where accuracy only shortens a step a little.
//!    Objects made of points alone keep the scene's beta for hits: their far-field
//!    terms come from second moments (`eval::smooth`), within 0.07% of the diagonal of
//!    the exact surface even on the deer at alpha 1 (1% with the closest-box terms).
//!    On edges and triangles whose hit band is narrow against the kernel (`alpha
//!    epsilon < 0.4`, where the pruning tolerance of item 6 is below its cap and a sum
//!    holds many terms), evaluations at the hit beta also take a subtree as one
//!    far-field term when its closest-box bound is at most `far_share alpha epsilon` of
//!    the sum (`TracerOptions::far_share`, 0.075; `eval::FarShare`): of the sum so far,
//!    or of the sum at the ray's last full value, which the new one is expected not to
//!    exceed (early in a walk the sum so far is small). Beta opens a subtree by its size
//!    against its distance; the share leaves it closed when its terms cannot weigh
//!    much: each such term lowers the value by at most `far_share` epsilons, as the
//!    pruning tolerance (item 6) is tied to epsilon. Still a lower bound. A fixed share
//!    of 4e-4 took a quarter off the leaves per ray of the softest cells of the speed
//!    matrix (doc/performance-log.md, round twenty-two); the share tied to epsilon takes
//!    11-30% more off the soft cells (`alpha * diag` 100-250), and no cell crosses an
//!    accuracy goal it met (round thirty-three). Off with certified hits (item 11),
//!    whose halvings must reach the exact sum.
//! 10. On point clouds, full evaluations that only take a step (not predicted to hit)
//!     are made at the coarser `TracerOptions::step_beta` (1 by default): a lower bound
//!     too, so the step is safe, at 60-75% of the terms near the surface; a value in
//!     the hit band or below is taken again at the hit beta before it decides anything.
//!     Where a refinement finds the step value one or more epsilons low (soft point
//!     clouds), the tile's later rays step at the hit beta (`render::step_beta`).
//! 11. With `TracerOptions::certified_hits` (`render --certified-hits`), on edges and
//!     triangles a value that would decide (in the hit band or below) also says how far
//!     the exact value may lie above it: the same walk sums each far-field subtree's
//!     lower bound (`n exp(-alpha r_far)`, `r_far` the distance to the box's farthest
//!     corner) beside its upper one, which bounds the exact smooth distance from above
//!     (`eval::smooth`). Where that gap exceeds [`GAP_MAX`] epsilons (soft fields over
//!     dense meshes, whose closest-box far field can be tens of epsilons low) the value
//!     is taken again at half the hit beta, and again, up to [`MAX_HALVINGS`] times and
//!     then exactly; the ray keeps the finer beta. Elsewhere the gap is a fraction of
//!     epsilon and nothing changes. Off by default: where it acts, the ray walks the
//!     last tens of epsilons with fine evaluations (doc/performance-log.md, round
//!     fifteen).
//! 12. On point clouds whose hit band is narrow against the kernel (`alpha epsilon <
//!     0.4`, where the pruning tolerance of item 6 is below its cap) a step from a value
//!     at the hit beta within [`AIM_MAX`](hit::AIM_MAX) epsilons (one at the coarser
//!     step beta of item 10 is an epsilon or more low) is aimed at where the field's
//!     second-order expansion along the ray crosses zero: `s - k L + c L^2 / 2` with
//!     `k` the field's fall along the ray (the terms' mean slope) and `c` its bend
//!     (`Slopes::derivatives`: the terms' distances bend away from their tangents, the log-sum
//!     the other way by the spread of their slopes), both from the free distance's bins
//!     at no cost per term (`eval::reach`). The step is taken where it is longer than
//!     the step, at most [`AIM_CAP`](hit::AIM_CAP) times it, short of the ray's end and
//!     `k` at least 0.3 (none where the expansion never reaches zero); its evaluation
//!     carries the gradient. The free distance is a bound: from 20 epsilons out it lands
//!     an epsilon or two short of the surface, and one more evaluation follows; the
//!     tangent alone (`c = 0`) lands in the band more often, and short of it where the
//!     field bends up (most rays onto a point cloud), the expansion more often still.
//!     The aimed step is a relaxed step (item 8): the next sample's free distance behind
//!     it must close the gap, else the ray goes back, except where it lands in the hit
//!     band: that is the hit, and at a negative value `s` it is moved back to the
//!     crossing's first-order estimate (as on edges and triangles, item 4), at most `2
//!     |s|` (as far as a final step moves on). On soft point clouds 22-23% fewer
//!     leaves per hit ray, the hits as close to the exact surface within an epsilon at
//!     the 99th percentile (doc/performance-log.md, round twenty-six). Where the band
//!     is wide against the kernel (stiff clouds, whose surface is a field of small
//!     bumps) aimed steps change which grazing rays come within epsilon of a bump (a
//!     tenth of the hits of the deer's far view at `alpha * diag` 3000), and are not
//!     taken; on edges and triangles the weights' change along the ray makes the
//!     tangent overshoot (more backtracks and rejected steps than evaluations spared, on
//!     four meshes).
//! 13. On edges and triangles whose hit band is narrow against the kernel (`alpha epsilon <
//!     0.4`, hits at the hit beta), a sample at the hit beta a few epsilons above the band
//!     (at most [`BAND_REACH_MAX`](hit::BAND_REACH_MAX), 6 on soft triangle meshes), with
//!     the gradient, is the hit when its final step (item 4: `s`, or the free distance up
//!     to `2 s`) is predicted to end within a quarter epsilon of zero: `s - k L + max(c, 0)
//!     L^2 / 2 <= epsilon / 4` for the step `L`, `k >= 0.1` the field's fall along the ray
//!     (from the gradient) and `c` its bend (item 12's estimate, counted only where it
//!     lifts the field). The step is the final step's, as certain as it is, so the hit
//!     stays in front of the surface; only its landing in the band is predicted, and the
//!     evaluation that would confirm it is spared. Near these surfaces the field falls
//!     slowly along the ray (`k` of 0.2-0.8) and the free distance lands a few epsilons
//!     short of the band, so most rays took one more fine evaluation there: 2-24% fewer
//!     full evaluations per hit ray on the soft cells of the speed matrix, the hits' 99th
//!     percentile depth error against the exact surface up to half an epsilon larger
//!     (doc/performance-log.md, round twenty-seven). Without the bend, a ray skimming a
//!     thin tube of the hex torus took a hit where the field rises again and the ray passes
//!     by. Off in the paper's mode, with certified hits (item 11), and in the speed
//!     matrix's exact reference (`TracerOptions::band_reach`).

mod hit;
mod ray;
mod sample;

pub use ray::{ByValue, Hit, RayResult, RayStats, VALUE_BINS, VALUE_EDGES};
use sample::MAX_HALVINGS;
pub(super) use sample::{FieldSample, Want};

use super::neighbours::Neighbours;
use super::object::TraceObject;
use super::options::{Backtrack, TracerOptions};
use super::step_beta::StepBeta;
use super::stepper::{Kind, Stepper};
use crate::eval::Along;
use crate::eval::params::MAX_PRUNE_TOLERANCE;
use crate::primitives::{AnySet, PrimitiveKind};
use glam::DVec3;

/// An evaluation is predicted to hit (and carries the gradient) when its predecessor's
/// value, or the value extrapolated from the last two, is within this many epsilons
/// (module docs, item 7).
const PREDICT: f64 = 2.0;

/// The same where the tile's steps are made at the hit beta (`render::step_beta`): the
/// gradient is all such a prediction adds, and fewer hits need a second traversal for
/// their normal (measured in doc/performance-log.md, round eleven).
const PREDICT_AT_HIT_BETA: f64 = 4.0;

/// A value in the hit band or below whose certified gap (how far the exact value may lie
/// above it) exceeds this many epsilons is evaluated again at half the hit beta (module
/// docs, item 11).
const GAP_MAX: f64 = 1.0;

/// The tracer's pruning tolerance is `min(PRUNE_SHARE alpha epsilon, MAX_PRUNE_TOLERANCE)`
/// (module docs, item 6): values lower by at most `2 PRUNE_SHARE epsilon`.
const PRUNE_SHARE: f64 = 0.025;

/// Where the neighbours' balls (if any) carry a ray certified free up to `t`.
fn advance(balls: Option<&mut Neighbours>, t: f64) -> f64 {
    balls.map_or(t, |n| n.advance(t))
}

/// The step from a sample at `t` whose certified free distance is `free` (its value, or
/// its free distance along the ray), lengthened where the neighbours' balls carry the ray
/// on from there past the stepper's `step` (module docs, item 5). A lengthened step is
/// certified all along: the stepper has no gap left to check.
fn through_chords(
    balls: Option<&mut Neighbours>,
    stepper: &mut Stepper,
    t: f64,
    free: f64,
    step: f64,
) -> f64 {
    let end = advance(balls, t + free);
    if end > t + step {
        stepper.certified();
        end - t
    } else {
        step
    }
}

/// Traces rays against a set of objects.
pub struct Tracer<'a> {
    objects: &'a [TraceObject],
    sets: Vec<Vec<&'a AnySet>>,
    reach: Vec<f64>,
    /// Pruning tolerance per object: subtrees holding together less than this share of
    /// the sum are skipped, which lowers `s` by at most `2 tol / alpha`; chosen so that
    /// is at most 5% of epsilon (and at most 1e-2 of the sum).
    tolerance: Vec<f64>,
    /// Opening parameter per object of the evaluations that decide hits (item 9).
    hit_beta: Vec<f64>,
    /// Opening parameter per object of the full evaluations that only take a step.
    step_beta: Vec<f64>,
    /// Share per object of the far terms by share at the hit beta (0: off; item 9).
    far_share: Vec<f64>,
    /// Some object decides hits at a finer beta than its steps.
    refine: bool,
    /// Some object decides hits at a finer beta than the scene's (edges, triangles): from
    /// the first evaluation at the hit beta on, the ray's full evaluations stay there
    /// (the scene's beta is several epsilons low near their surfaces, item 9).
    sticky: bool,
    /// Bound steps are taken while the bound value exceeds this (item 5).
    tau: f64,
    /// Per object: its terms have weights that vary along a ray (edges, triangles), so
    /// its free distances hold to first order only (item 4).
    weighted: Vec<bool>,
    /// Per object: its steps near the surface are aimed at the crossing (item 12).
    aims: Vec<bool>,
    /// Per object: a sample this many epsilons above the hit band, or fewer, may be the
    /// hit (item 13; 0: none).
    band_reach: Vec<f64>,
    /// Union of the grown object boxes.
    min: DVec3,
    max: DVec3,
    options: TracerOptions,
}

impl<'a> Tracer<'a> {
    pub fn new(objects: &'a [TraceObject], options: TracerOptions) -> Tracer<'a> {
        let reach: Vec<f64> = objects.iter().map(|o| o.reach(o.params.alpha)).collect();
        let mut min = DVec3::splat(f64::INFINITY);
        let mut max = DVec3::splat(f64::NEG_INFINITY);
        for (o, &r) in objects.iter().zip(&reach) {
            min = min.min(o.bounds.min.as_dvec3() - r);
            max = max.max(o.bounds.max.as_dvec3() + r);
        }
        let tolerance: Vec<f64> = objects
            .iter()
            .map(|o| (PRUNE_SHARE * o.params.alpha * options.epsilon).min(MAX_PRUNE_TOLERANCE))
            .collect();
        // Objects made of points only: hits at the scene's beta (item 9), coarser steps
        // (item 10) and an earlier end of the bound steps (item 5).
        let points_only: Vec<bool> = objects
            .iter()
            .map(|o| o.only(PrimitiveKind::Points))
            .collect();
        let hit_beta: Vec<f64> = objects
            .iter()
            .zip(&points_only)
            .map(|(o, &points)| {
                // Certified hits start from the meshes' hit beta on soft triangles and
                // edges too: their halvings reach the exact sum from there (item 11).
                let scale = if points {
                    1.0
                } else if options.certified_hits {
                    options.hit_beta_scale
                } else if o.soft_triangles() {
                    options.hit_beta_scale_soft_triangles
                } else if o.only(PrimitiveKind::Edges) {
                    options.hit_beta_scale_edges
                } else {
                    options.hit_beta_scale
                };
                o.params.beta * scale.clamp(0.0, 1.0)
            })
            .collect();
        // Coarser steps pay on point clouds only (on edges and triangles the scene's beta
        // is already several epsilons low near the surface, item 9).
        let step_beta: Vec<f64> = objects
            .iter()
            .zip(&points_only)
            .map(|(o, &points)| {
                if points {
                    o.params.beta.max(options.step_beta)
                } else {
                    o.params.beta
                }
            })
            .collect();
        // Per object: its hit band is narrow against the kernel (`alpha epsilon < 0.4`,
        // the pruning tolerance of item 6 below its cap), where a sum holds many terms.
        // Far terms by share (item 9), aimed steps (item 12) and hits from above the band
        // (item 13) are taken only there.
        let narrow: Vec<bool> = tolerance
            .iter()
            .map(|&tol| tol < MAX_PRUNE_TOLERANCE)
            .collect();
        // Far terms by share on narrow edges and triangles. Where the tolerance is
        // capped, pruning already takes shares of 1% (item 9; doc/performance-log.md,
        // round twenty-two). Not with certified hits, whose halvings of the hit beta must
        // reach the exact sum (item 11).
        let far_share = points_only
            .iter()
            .zip(&narrow)
            .zip(objects)
            .map(|((&points, &narrow), o)| {
                if points || !narrow || options.certified_hits {
                    0.0
                } else {
                    options.far_share * o.params.alpha * options.epsilon
                }
            })
            .collect();
        // Aimed steps on narrow point clouds (item 12).
        let aims = points_only
            .iter()
            .zip(&narrow)
            .map(|(&points, &narrow)| options.aim && options.reach_steps && points && narrow)
            .collect();
        // Hits from above the band on narrow edges and triangles whose hits are decided
        // at the hit beta (`sticky`; item 13), from at most this many epsilons above it
        // (0: none).
        let band_reach = points_only
            .iter()
            .zip(&narrow)
            .zip(objects.iter().zip(&hit_beta))
            .map(|((&points, &narrow), (o, &h))| {
                let on = options.band_reach
                    && !options.certified_hits
                    && options.final_step
                    && options.reach_steps
                    && !points
                    && narrow
                    && h < o.params.beta;
                match (on, o.soft_triangles()) {
                    (false, _) => 0.0,
                    (true, true) => hit::BAND_REACH_MAX_SOFT_TRIANGLES,
                    (true, false) => hit::BAND_REACH_MAX,
                }
            })
            .collect();
        let refine = step_beta.iter().zip(&hit_beta).any(|(s, h)| s != h);
        let tau = options.epsilon
            * if points_only.iter().all(|&p| p) {
                options.coarse_threshold_points
            } else {
                options.coarse_threshold
            };
        let sticky = objects
            .iter()
            .zip(&hit_beta)
            .any(|(o, &h)| h < o.params.beta);
        Tracer {
            objects,
            sets: objects.iter().map(|o| o.set_refs()).collect(),
            reach,
            tolerance,
            hit_beta,
            step_beta,
            far_share,
            refine,
            sticky,
            tau,
            weighted: points_only.iter().map(|&p| !p).collect(),
            aims,
            band_reach,
            min,
            max,
            options,
        }
    }

    /// The objects traced (for shading a hit).
    pub fn objects(&self) -> &'a [TraceObject] {
        self.objects
    }

    pub fn options(&self) -> &TracerOptions {
        &self.options
    }

    /// An upper bound of the ray parameter at which any ray from `o` leaves the grown
    /// scene box: the distance to its farthest corner.
    pub fn farthest(&self, o: DVec3) -> f64 {
        (o - self.min).abs().max((o - self.max).abs()).length()
    }

    /// The parameter interval where the ray is inside the grown scene box, if any.
    fn clip(&self, o: DVec3, d: DVec3) -> Option<(f64, f64)> {
        let inv = d.recip();
        let t1 = (self.min - o) * inv;
        let t2 = (self.max - o) * inv;
        // NaN from 0 * inf (ray in a box plane) is dropped by min/max.
        let tmin = t1.min(t2).max_element().max(0.0);
        let tmax = t1.max(t2).min_element();
        (tmin <= tmax).then_some((tmin, tmax))
    }

    /// Traces the ray from `o` along unit `d`, starting no earlier than `t_start`.
    pub fn trace(&self, o: DVec3, d: DVec3, t_start: f64) -> RayResult {
        self.trace_impl(o, d, t_start, None, None)
    }

    /// [`Tracer::trace`] for a ray of a tile: it starts past the stretch that the empty
    /// balls of the tile's last rays certify, and leaves its own balls for the next
    /// (`render::neighbours`), if `near` is given; its step evaluations are made at the
    /// tile's step beta, and its refinement, if any, may switch the tile's steps to the
    /// hit beta (`render::step_beta`).
    pub fn trace_in_tile(
        &self,
        o: DVec3,
        d: DVec3,
        t_start: f64,
        mut near: Option<&mut Neighbours>,
        steps: &mut StepBeta,
    ) -> RayResult {
        let r = self.trace_impl(o, d, t_start, near.as_deref_mut(), Some(steps));
        if let Some(n) = near {
            n.finish_ray();
        }
        r
    }

    fn trace_impl(
        &self,
        o: DVec3,
        d: DVec3,
        t_start: f64,
        mut balls: Option<&mut Neighbours>,
        mut steps: Option<&mut StepBeta>,
    ) -> RayResult {
        let mut stats = RayStats::default();
        let eps = self.options.epsilon;
        // The zero set at the object's own alpha lies inside the grown box in both
        // modes (falloff only shortens steps), so the clip holds for the naive sum too.
        let (t_enter, t_max) = if self.options.clip {
            match self.clip(o, d) {
                Some(range) => range,
                None => return RayResult { hit: None, stats },
            }
        } else {
            let c = 0.5 * (self.min + self.max);
            (0.0, (o - c).length() + 0.5 * (self.max - self.min).length())
        };
        let mut t = t_enter.max(t_start);
        if let Some(n) = balls.as_deref_mut() {
            t = n.start(o, d, t);
        }
        // The last certified sample: (t, a lower bound of the field there, the free
        // distance from it). Everything up to `t + free` is free of the surface.
        let mut prev: Option<(f64, f64, f64)> = None;
        let mut stepper = Stepper::new(self.options.relax);
        let coarse = (self.options.coarse_beta > 0.0).then_some(self.options.coarse_beta);
        let tau = self.tau;
        let mut near = false;
        // How far the bound step's value fell below the full value that followed it
        // (module docs, item 5; at the next point, so about the gap there): a bound step
        // is only worth taking where the full value minus this gap stays above the
        // threshold.
        let mut coarse_at: Option<f64> = None;
        let mut gap = 0.0f64;
        // Full-accuracy evaluations carry the gradient when they are predicted to hit,
        // so the hit needs no second traversal to be shaded: the next value is guessed
        // from the slope of the last two values (sphere tracing converges about
        // geometrically), or from the value itself.
        let mut want = Want::Value;
        // Once set, every full evaluation of the ray is accurate (module docs, item 9).
        let mut accurate = false;
        // The ray's last full value: the next is expected below it (module docs, item
        // 9: the floor of the far terms by share).
        let mut level = f64::INFINITY;
        // The tile's step beta (`render::step_beta`): at the hit beta, no refinement.
        let step_beta = steps.as_deref().copied().unwrap_or_default();
        let refine = self.refine && !step_beta.at_hit_beta();
        while t <= t_max {
            if stats.evals + stats.coarse_evals >= self.options.max_steps {
                stats.exhausted = true;
                return RayResult { hit: None, stats };
            }
            let x = o + t * d;
            if let (Some(beta), false) = (coarse, near) {
                let c = self.sample(
                    x,
                    &mut stats,
                    Want::Bound(beta),
                    false,
                    f64::INFINITY,
                    None,
                    StepBeta::default(),
                );
                if c.s > eps {
                    if let Some(n) = balls.as_deref_mut() {
                        n.note(x, c.s);
                    }
                    // Outside the hit band the bound's own step is safe: taken here even
                    // when the value fell below the threshold (a full value at this
                    // point could not hit either, and where the bound is tight it would
                    // only repeat it). The next sample is then a full one.
                    if let Some(back) = stepper.uncovered(prev, t, c.s) {
                        stats.rejected_steps += 1;
                        t = advance(balls.as_deref_mut(), back);
                        continue;
                    }
                    let step = stepper.step(prev, t, c.s, c.s, Kind::Bound);
                    let step = through_chords(balls.as_deref_mut(), &mut stepper, t, c.s, step);
                    prev = Some((t, c.s, c.s));
                    t += step;
                    if c.s <= tau {
                        near = true;
                        coarse_at = Some(c.s);
                        // Edges and triangles: a full value after a bound step that fell
                        // through is usually in the band (their bound is nearly exact).
                        want = if self.sticky {
                            Want::Gradient
                        } else {
                            Want::Value
                        };
                    }
                    continue;
                }
                // A coarse value already within the hit band is usually a hit (where
                // the coarse sum is loose it is far below zero instead). On edges and
                // triangles (`sticky`) the full value after any bound that fell through
                // is taken at the hit beta, with the gradient: at the scene's beta it is
                // several epsilons low there, and only takes a step that the next
                // evaluation, at the hit beta, has to repeat (item 9).
                if c.s.abs() <= eps || self.sticky {
                    want = Want::Gradient;
                }
                coarse_at = Some(c.s);
            }
            // An evaluation predicted to hit is made at the hit beta.
            let fine = accurate || (refine && want == Want::Gradient);
            accurate |= fine && self.sticky;
            let along = self.options.reach_steps.then_some(Along {
                u: d,
                max_len: t_max - t,
                back: if self.options.reach_behind {
                    stepper.needed(prev, t)
                } else {
                    0.0
                },
            });
            let mut f = self.sample(x, &mut stats, want, fine, level, along, step_beta);
            // Whether `f` is at the hit beta. On edges and triangles (`sticky`) a slope is
            // only measured between values of one beta: the scene's is lower there by a
            // share that changes along the ray, and a slope across the switch (0.2 where
            // the field falls by 0.8) sent relaxed steps past the next sample's reach.
            // Point clouds keep measuring across it (their steps took 3-75% more full
            // evaluations per hit ray on 17 of the matrix's cells otherwise).
            let mut f_fine = fine;
            if let Some(c) = coarse_at.take() {
                gap = (f.s - c).max(0.0);
            }
            // An aimed step that landed in the hit band decides the hit there (item 12).
            let landed = stepper.aimed && f.s.abs() <= eps;
            if let Some(back) = stepper.uncovered(prev, t, f.reach_back).filter(|_| !landed) {
                // An over-relaxed step left a gap: go back to the plain step's end.
                stats.rejected_steps += 1;
                t = advance(balls.as_deref_mut(), back);
                want = Want::Value;
                continue;
            }
            if refine && !fine && f.s <= eps {
                // In the hit band or below at the scene's beta: decide at the hit beta
                // (a lower bound too, so the step that got here stays safe).
                accurate = true;
                stats.refinements += 1;
                let coarse = f.s;
                f = self.sample(x, &mut stats, Want::Gradient, true, level, along, step_beta);
                f_fine = true;
                if let Some(st) = steps.as_deref_mut() {
                    st.refined(coarse, f.s, eps);
                }
            }
            // A value that would decide (a hit, or a crossing) whose exact value may lie
            // more than GAP_MAX epsilons above it is taken again at half the hit beta
            // (item 11).
            while self.options.certified_hits
                && self.sticky
                && f.s <= eps
                && f.gap > GAP_MAX * eps
                && stats.hit_halvings <= MAX_HALVINGS
            {
                accurate = true;
                stats.hit_halvings += 1;
                stats.refinements += 1;
                f = self.sample(x, &mut stats, Want::Gradient, true, level, along, step_beta);
            }
            near = f.s - gap < 2.0 * tau;
            if f.s.abs() <= eps || (f_fine && self.lands_in_band(&f, d)) {
                let floor = prev.map_or(t, |p| p.0);
                let hit = if landed {
                    self.landing(o, d, (t, floor), &f, &mut stats)
                } else {
                    self.hit(o, d, (t, floor), &f, &mut stats)
                };
                return RayResult {
                    hit: Some(hit),
                    stats,
                };
            }
            if f.s < 0.0 {
                let hit = match prev {
                    Some(_) if self.options.backtrack == Backtrack::FixedStep => {
                        self.step_back(o, d, t, &mut stats)
                    }
                    Some((tp, sp, _)) => self.backtrack(o, d, (tp, sp), (t, f.s), &mut stats),
                    // Negative at the first sample: the ray starts inside the band.
                    None => Some(self.hit(o, d, (t, t), &f, &mut stats)),
                };
                return RayResult { hit, stats };
            }
            if let Some(n) = balls.as_deref_mut() {
                n.note_along(x, f.s, d, f.reach);
            }
            let kind = if f_fine && refine && self.sticky {
                Kind::Fine
            } else {
                Kind::Full
            };
            let step = stepper.step(prev, t, f.s, f.reach, kind);
            let mut step = through_chords(balls.as_deref_mut(), &mut stepper, t, f.reach, step);
            // (Aimed from values at the hit beta: one at the coarser step beta is an
            // epsilon or more low on soft clouds, item 10.)
            if let Some(len) = self
                .aimed_step(&f, (t, t_max), step)
                .filter(|_| f_fine || !refine)
            {
                step = len;
                stepper.aim(len, f.reach);
            }
            // The value at the next sample, if the field keeps its slope along the ray.
            // Before the slope is known (the first full value after bound steps), a step
            // by the free distance is taken to about halve the value (point clouds); the
            // plain guess (slope 1) would predict a hit after every such step. Objects
            // whose hits take a finer beta (`sticky`) keep the plain guess: their first
            // fine evaluation is better early than late.
            let predicted = if stepper.slope_known || self.sticky {
                f.s - stepper.slope * step
            } else {
                0.5 * f.s
            };
            // A step evaluation at the hit beta (the tile's steps switched, item 10)
            // costs what a hit evaluation costs but for the gradient: it asks for it
            // sooner, so that fewer hits need a second traversal for the normal.
            let within = if step_beta.at_hit_beta() {
                PREDICT_AT_HIT_BETA
            } else {
                PREDICT
            } * eps;
            want = if predicted <= within || f.s <= within || stepper.aimed {
                Want::Gradient
            } else {
                Want::Value
            };
            prev = Some((t, f.s, f.reach));
            level = f.s;
            t += step;
        }
        RayResult { hit: None, stats }
    }
}
