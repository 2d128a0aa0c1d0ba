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
//!    Illinois (safeguarded regula falsi) method to within `epsilon`.
//! 5. Far from the surface, steps use a coarser Barnes-Hut sum (`coarse_beta`, cheaper,
//!    and a lower bound of the scene's sum, so the steps stay safe) until it falls below
//!    `coarse_threshold * epsilon`; from there on the scene's own beta decides the hit.
//!    On the Table 1 scenes this cut the leaves visited per ray by 15-50% at beta 0.5 and
//!    changed no pixel beyond silhouette rays that pass within epsilon (measured on bowl,
//!    bunny, torus, points and lidar scenes at 320x180 with `--coarse-beta 0` and 4).
//! 6. The normal is the normalised gradient at the hit. Steps need only the value, so
//!    they use value-only evaluations; one evaluation with the gradient is made at the
//!    hit (the ideal ray costs one such evaluation plus its steps).

use super::object::TraceObject;
use crate::eval::EvalStats;
use crate::primitives::AnySet;
use glam::DVec3;

/// Tracer settings.
#[derive(Clone, Copy, Debug)]
pub struct TracerOptions {
    /// Hit threshold in world units.
    pub epsilon: f64,
    /// Largest number of field evaluations per ray before giving up (a miss).
    pub max_steps: u32,
    /// Opening parameter of the cheap evaluations used for steps far from the surface
    /// (0 = off). Any Barnes-Hut sum coarser than the scene's is a lower bound of it
    /// (a parent's far-field term dominates everything below it), so these steps are as
    /// safe as the scene's own; the hit itself is always decided at the scene's beta.
    pub coarse_beta: f64,
    /// Coarse steps are taken while the coarse value exceeds this many epsilons.
    pub coarse_threshold: f64,
    /// Clip rays to the grown scene box (misses outside it cost no evaluation). Off,
    /// rays start at the camera's smooth distance and march to the box's far side, as
    /// in the paper's renderer.
    pub clip: bool,
    pub backtrack: Backtrack,
}

/// How a step that overshoots into the negative band is resolved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backtrack {
    /// Safeguarded regula falsi on the bracket (default).
    Illinois,
    /// March back in steps of epsilon until the value is above -epsilon (the paper's).
    FixedStep,
}

impl TracerOptions {
    /// Defaults for a hit threshold `epsilon`.
    pub fn new(epsilon: f64, max_steps: u32) -> TracerOptions {
        TracerOptions {
            epsilon,
            max_steps,
            coarse_beta: 4.0,
            coarse_threshold: 4.0,
            clip: true,
            backtrack: Backtrack::Illinois,
        }
    }

    /// The paper's tracer: every step at the scene's beta, no ray clipping, fixed-step
    /// backtracking. (Pair with `EvalParams::prune = false` and the naive sum for the
    /// paper's evaluator.)
    pub fn paper(epsilon: f64, max_steps: u32) -> TracerOptions {
        TracerOptions {
            coarse_beta: 0.0,
            clip: false,
            backtrack: Backtrack::FixedStep,
            ..TracerOptions::new(epsilon, max_steps)
        }
    }
}

/// A ray's intersection with the zero set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f64,
    pub point: DVec3,
    /// Unit normal in world space (zero if the gradient vanished).
    pub normal: DVec3,
    /// Index of the object whose smooth distance is smallest at the hit.
    pub object: usize,
}

/// Work done for one ray.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RayStats {
    /// Field evaluations at the scene's beta (one per object evaluated per step, plus
    /// the gradient evaluation at the hit).
    pub evals: u32,
    /// Cheaper evaluations at the coarse beta (far-from-surface steps).
    pub coarse_evals: u32,
    /// Sum of the evaluations' statistics (leaves, nodes).
    pub eval: EvalStats,
    /// Retries with a smaller alpha after an infinite (underflowed) naive evaluation.
    pub falloffs: u32,
    /// Evaluations spent locating a crossing after overshooting into the negative band.
    pub backtracks: u32,
    /// The ray ran out of steps (counted as a miss).
    pub exhausted: bool,
}

/// The result of tracing one ray.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RayResult {
    pub hit: Option<Hit>,
    pub stats: RayStats,
}

#[derive(Clone, Copy)]
struct FieldSample {
    s: f64,
    object: usize,
}

/// Traces rays against a set of objects.
pub struct Tracer<'a> {
    objects: &'a [TraceObject],
    sets: Vec<Vec<&'a AnySet>>,
    reach: Vec<f64>,
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
        Tracer {
            objects,
            sets: objects.iter().map(|o| o.set_refs()).collect(),
            reach,
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

    /// The scene field at `x` (the minimum over objects) and the object attaining it.
    pub fn field(&self, x: DVec3, stats: &mut RayStats) -> (f64, usize) {
        let f = self.sample(x, stats, None);
        (f.s, f.object)
    }

    /// The gradient of object `k`'s smooth distance at `x` (one evaluation).
    pub fn gradient(&self, k: usize, x: DVec3, stats: &mut RayStats) -> DVec3 {
        let obj = &self.objects[k];
        let mut alpha = obj.params.alpha;
        loop {
            let sample = obj.evaluate(&self.sets[k], x, alpha, None, true);
            stats.evals += 1;
            stats.eval.add(&sample.stats);
            if sample.s.is_finite() || alpha <= 1e-300 {
                return sample.grad;
            }
            alpha /= 10.0;
            stats.falloffs += 1;
        }
    }

    fn sample(&self, x: DVec3, stats: &mut RayStats, coarse: Option<f64>) -> FieldSample {
        let mut best = FieldSample {
            s: f64::INFINITY,
            object: 0,
        };
        for (k, obj) in self.objects.iter().enumerate() {
            if self.objects.len() > 1 && obj.lower_bound(x, self.reach[k]) >= best.s {
                continue;
            }
            let mut alpha = obj.params.alpha;
            let evaluate = |alpha: f64, stats: &mut RayStats| {
                let sample = obj.evaluate(&self.sets[k], x, alpha, coarse, false);
                if coarse.is_some() {
                    stats.coarse_evals += 1;
                } else {
                    stats.evals += 1;
                }
                stats.eval.add(&sample.stats);
                sample
            };
            let mut sample = evaluate(alpha, stats);
            // Alpha falloff (naive mode): a smaller alpha gives a smaller, finite s.
            while sample.s == f64::INFINITY && alpha > 1e-300 {
                alpha /= 10.0;
                stats.falloffs += 1;
                sample = evaluate(alpha, stats);
            }
            if sample.s < best.s {
                best = FieldSample {
                    s: sample.s,
                    object: k,
                };
            }
        }
        best
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
        let mut prev: Option<(f64, f64)> = None;
        let coarse = (self.options.coarse_beta > 0.0).then_some(self.options.coarse_beta);
        let tau = self.options.coarse_threshold * eps;
        let mut near = false;
        while t <= t_max {
            if stats.evals + stats.coarse_evals >= self.options.max_steps {
                stats.exhausted = true;
                return RayResult { hit: None, stats };
            }
            if let (Some(_), false) = (coarse, near) {
                let c = self.sample(o + t * d, &mut stats, coarse);
                if c.s > tau {
                    prev = Some((t, c.s));
                    t += c.s;
                    continue;
                }
            }
            let f = self.sample(o + t * d, &mut stats, None);
            near = f.s < 2.0 * tau;
            if f.s.abs() <= eps {
                let hit = self.hit(o, d, t, &f, &mut stats);
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
                    Some((tp, sp)) => self.backtrack(o, d, (tp, sp), (t, f.s), &mut stats),
                    // Negative at the first sample: the ray starts inside the band.
                    None => Some(self.hit(o, d, t, &f, &mut stats)),
                };
                return RayResult { hit, stats };
            }
            prev = Some((t, f.s));
            t += f.s;
        }
        RayResult { hit: None, stats }
    }

    fn hit(&self, o: DVec3, d: DVec3, t: f64, f: &FieldSample, stats: &mut RayStats) -> Hit {
        let point = o + t * d;
        Hit {
            t,
            point,
            normal: self.gradient(f.object, point, stats).normalize_or_zero(),
            object: f.object,
        }
    }

    /// The paper's backtracking: from `t` (where `s < -epsilon`) march back by epsilon
    /// until `s >= -epsilon`.
    fn step_back(&self, o: DVec3, d: DVec3, mut t: f64, stats: &mut RayStats) -> Option<Hit> {
        let eps = self.options.epsilon;
        while stats.evals + stats.coarse_evals < self.options.max_steps {
            t -= eps;
            let before = stats.evals;
            let f = self.sample(o + t * d, stats, None);
            stats.backtracks += stats.evals - before;
            if f.s >= -eps {
                return Some(self.hit(o, d, t, &f, stats));
            }
        }
        stats.exhausted = true;
        None
    }

    /// Finds the crossing in `[lo, hi]` (`s(lo) > 0 > s(hi)`) by the Illinois method.
    fn backtrack(
        &self,
        o: DVec3,
        d: DVec3,
        (mut lo, mut s_lo): (f64, f64),
        (mut hi, mut s_hi): (f64, f64),
        stats: &mut RayStats,
    ) -> Option<Hit> {
        let eps = self.options.epsilon;
        let mut side = 0i8;
        let mut last = None;
        for _ in 0..64 {
            if stats.evals + stats.coarse_evals >= self.options.max_steps {
                stats.exhausted = true;
                break;
            }
            let mut t = (lo * s_hi - hi * s_lo) / (s_hi - s_lo);
            if !(t > lo && t < hi) {
                t = 0.5 * (lo + hi);
            }
            let before = stats.evals;
            let f = self.sample(o + t * d, stats, None);
            stats.backtracks += stats.evals - before;
            if f.s.abs() <= eps || hi - lo <= eps {
                return Some(self.hit(o, d, t, &f, stats));
            }
            last = Some((t, f));
            if f.s > 0.0 {
                lo = t;
                s_lo = f.s;
                if side == 1 {
                    s_hi *= 0.5;
                }
                side = 1;
            } else {
                hi = t;
                s_hi = f.s;
                if side == -1 {
                    s_lo *= 0.5;
                }
                side = -1;
            }
        }
        last.map(|(t, f)| self.hit(o, d, t, &f, stats))
    }
}
