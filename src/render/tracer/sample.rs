//! The tracer's samples of the scene field (SPEC 6, 7): the minimum over objects of their
//! smooth distances at a point, each evaluated at the Barnes-Hut opening parameter its
//! purpose calls for (`render::tracer` items 5, 9 and 10): a bound step's coarser beta
//! (a lower bound, cheaper), the hit beta (finer, for values that decide a hit), or the
//! step beta of the ray's tile (`render::step_beta`). An object whose cheap lower bound
//! (box distance minus reach) is already above the current minimum is not evaluated.
//! Naive sums that underflow to `+inf` are retried at `alpha / 10` (alpha falloff, item
//! 3). With one object a sample also carries its free distances along the ray
//! (`eval::reach`), which steps and neighbours' free cones use.

use super::Tracer;
use super::ray::RayStats;
use crate::eval::{Along, FarShare};
use crate::render::step_beta::StepBeta;
use glam::DVec3;

/// Halvings of the hit beta after which a hit is decided by the exact sum.
pub(super) const MAX_HALVINGS: u32 = 4;

/// A sample of the scene field: its lower bound `s`, the object attaining it, and what
/// was asked for besides.
#[derive(Clone, Copy)]
pub(in crate::render) struct FieldSample {
    pub(in crate::render) s: f64,
    pub(super) object: usize,
    /// Gradient of the winning object's smooth distance, when it was asked for.
    pub(super) grad: Option<DVec3>,
    /// Free distance along the ray (`eval::reach`; `s` when not asked for).
    pub(super) reach: f64,
    /// Free distance back along the ray (`s` when not asked for, or not shorter).
    pub(super) reach_back: f64,
    /// The derivative of `s` along the ray (`eval::reach`), when free distances were
    /// asked for.
    pub(super) slope: Option<f64>,
    /// An estimate of its second derivative along the ray (`eval::reach`), likewise.
    pub(super) bend: Option<f64>,
    /// How far the winning object's exact value may lie above `s` (its certified upper
    /// bound minus `s`, `eval::smooth`); 0 for objects whose hits keep the scene's beta
    /// (point clouds), whose far terms the bound does not cover.
    pub(super) gap: f64,
}

/// What an evaluation is for: a bound step at a coarser beta, or a full-accuracy value
/// with or without the gradient.
#[derive(Clone, Copy, PartialEq)]
pub(in crate::render) enum Want {
    Bound(f64),
    Value,
    Gradient,
}

impl<'a> Tracer<'a> {
    /// The scene field at `x` (the minimum over objects) and the object attaining it.
    pub fn field(&self, x: DVec3, stats: &mut RayStats) -> (f64, usize) {
        let f = self.sample(
            x,
            stats,
            Want::Value,
            false,
            f64::INFINITY,
            None,
            StepBeta::default(),
        );
        (f.s, f.object)
    }

    /// A lower bound of the scene field at `x` from a Barnes-Hut sum at opening
    /// parameter `beta` (at least the scene's): cheaper than [`Tracer::field`] for a
    /// larger `beta`, counted as a bound step.
    pub fn bound(&self, x: DVec3, beta: f64, stats: &mut RayStats) -> f64 {
        self.sample(
            x,
            stats,
            Want::Bound(beta),
            false,
            f64::INFINITY,
            None,
            StepBeta::default(),
        )
        .s
    }

    /// Object `k`'s hit beta after the ray halved it `halvings` times (a certified gap
    /// above epsilon, `render::tracer` item 11); 0 (exact) past [`MAX_HALVINGS`].
    pub(super) fn hit_beta_now(&self, k: usize, halvings: u32) -> f64 {
        if halvings > MAX_HALVINGS {
            0.0
        } else {
            self.hit_beta[k] * 0.5f64.powi(halvings as i32)
        }
    }

    /// Object `k`'s far terms by share (`TracerOptions::far_share`, module docs item 9)
    /// in an evaluation at the hit beta whose value is expected not to exceed `level`.
    fn far_share(&self, k: usize, level: f64) -> FarShare {
        if self.far_share[k] > 0.0 {
            FarShare {
                share: self.far_share[k],
                level,
            }
        } else {
            FarShare::OFF
        }
    }

    /// The gradient of object `k`'s smooth distance at `x` (one evaluation, at the hit
    /// beta; its far terms by share against the floor of `level`, which the value there is
    /// expected not to exceed).
    pub fn gradient(&self, k: usize, x: DVec3, level: f64, stats: &mut RayStats) -> DVec3 {
        let obj = &self.objects[k];
        let mut alpha = obj.params.alpha;
        loop {
            let sample = obj.evaluate(
                &self.sets[k],
                x,
                alpha,
                self.hit_beta_now(k, stats.hit_halvings),
                self.tolerance[k],
                true,
                None,
                false,
                false,
                self.far_share(k, level),
            );
            stats.evals += 1;
            stats.eval.add(&sample.stats);
            stats.by_value.gradient_evals += 1;
            stats.by_value.gradient_leaves += sample.stats.leaves();
            if sample.s.is_finite() || alpha <= 1e-300 {
                return sample.grad;
            }
            alpha /= 10.0;
            stats.falloffs += 1;
        }
    }

    /// Whether object `k`'s hits can be given an interval by [`Tracer::value_interval`]
    /// (not made of points alone).
    fn gap_covered(&self, k: usize) -> bool {
        self.weighted[k] || self.objects[k].signed.is_some()
    }

    /// Whether some object's hits can be given an interval ([`Tracer::value_interval`]
    /// gives `upper = +inf` everywhere otherwise).
    pub fn covers_gaps(&self) -> bool {
        (0..self.objects.len()).any(|k| self.gap_covered(k))
    }

    /// The scene field at `x` as a hit decides it (each object at its hit beta, pruning
    /// tolerance and far terms by share, the level at epsilon as for a hit's gradient),
    /// with a certified upper bound of the exact field (`eval::smooth`, `s_upper`): the
    /// exact smooth distance lies in `[lower, upper]`. Point clouds decide hits on far
    /// terms from moments, and an upper bound takes closest-box ones (`eval::smooth`),
    /// whose interval is much wider than the value's error: where an object made of
    /// points attains `lower`, `upper` is `+inf` (another object's upper bound would hold,
    /// but would say how far that object is, not how loose the value is).
    pub fn value_interval(&self, x: DVec3) -> (f64, f64) {
        let (mut lower, mut upper) = (f64::INFINITY, f64::INFINITY);
        let mut lowest_covered = true;
        for (k, obj) in self.objects.iter().enumerate() {
            let sample = obj.evaluate(
                &self.sets[k],
                x,
                obj.params.alpha,
                self.hit_beta[k],
                self.tolerance[k],
                false,
                None,
                false,
                true,
                self.far_share(k, self.options.epsilon),
            );
            let covered = self.gap_covered(k);
            if sample.s < lower {
                lower = sample.s;
                lowest_covered = covered;
            }
            if covered {
                upper = upper.min(sample.s_upper);
            }
        }
        (lower, if lowest_covered { upper } else { f64::INFINITY })
    }

    /// The scene field at `x` for `want`; full evaluations at the hit beta if `accurate`.
    /// Full evaluations at a beta finer than the scene's (the hit beta, or a tile's
    /// steps there) take far terms by share too, against the floor of `level`, which
    /// the value is expected not to exceed (the ray's last full value; `+inf` when
    /// unknown).
    #[allow(clippy::too_many_arguments)]
    pub(in crate::render) fn sample(
        &self,
        x: DVec3,
        stats: &mut RayStats,
        want: Want,
        accurate: bool,
        level: f64,
        along: Option<Along>,
        step_beta: StepBeta,
    ) -> FieldSample {
        let mut best = FieldSample {
            s: f64::INFINITY,
            object: 0,
            grad: None,
            reach: f64::INFINITY,
            reach_back: f64::INFINITY,
            slope: None,
            bend: None,
            gap: 0.0,
        };
        // With several objects a step is the smallest value (no free distance).
        let along = along.filter(|_| self.objects.len() == 1 && !matches!(want, Want::Bound(_)));
        let (coarse, grad) = match want {
            Want::Bound(beta) => (Some(beta), false),
            Want::Value => (None, false),
            Want::Gradient => (None, true),
        };
        for (k, obj) in self.objects.iter().enumerate() {
            if self.objects.len() > 1 && obj.lower_bound(x, self.reach[k]) >= best.s {
                continue;
            }
            let mut alpha = obj.params.alpha;
            let evaluate = |alpha: f64, stats: &mut RayStats| {
                let beta = match coarse {
                    Some(b) => b.max(obj.params.beta),
                    None if accurate => self.hit_beta_now(k, stats.hit_halvings),
                    None => step_beta.beta(self.step_beta[k], self.hit_beta[k]),
                };
                let sample = obj.evaluate(
                    &self.sets[k],
                    x,
                    alpha,
                    beta,
                    self.tolerance[k],
                    grad,
                    along,
                    coarse.is_some(),
                    self.options.certified_hits && coarse.is_none(),
                    if coarse.is_none() && beta < obj.params.beta {
                        self.far_share(k, level)
                    } else {
                        FarShare::OFF
                    },
                );
                if coarse.is_some() {
                    stats.coarse_evals += 1;
                    stats.coarse_leaves += sample.stats.leaves();
                } else {
                    stats.evals += 1;
                    stats.step_evals += u32::from(!accurate && beta > obj.params.beta);
                    stats
                        .by_value
                        .add(sample.s / self.options.epsilon, sample.stats.leaves());
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
                // A falloff's gradient and free distances are those of a smaller alpha:
                // the gradient is recomputed at the hit, the steps are plain.
                let own_alpha = alpha == obj.params.alpha;
                let free = |len: f64| {
                    if own_alpha {
                        len.max(sample.s)
                    } else {
                        sample.s
                    }
                };
                best = FieldSample {
                    s: sample.s,
                    object: k,
                    grad: (grad && own_alpha).then_some(sample.grad),
                    reach: free(sample.reach),
                    reach_back: free(sample.reach_back),
                    slope: sample.slope.filter(|_| own_alpha),
                    bend: sample.bend.filter(|_| own_alpha),
                    gap: if self.hit_beta[k] < obj.params.beta {
                        (sample.s_upper - sample.s).max(0.0)
                    } else {
                        0.0
                    },
                };
            }
        }
        best
    }
}
