//! Locating the crossing after a sphere-tracing step lands below `-epsilon` (SPEC 7;
//! `render::tracer` module docs, item 4): the crossing is bracketed by the last positive
//! sample and this one and found by the Illinois method (safeguarded regula falsi) to
//! within epsilon, or, as in the paper's renderer, by marching back in steps of epsilon
//! until the value is above `-epsilon`. Every value is taken at the hit beta.

use super::step_beta::StepBeta;
use super::tracer::{FieldSample, Hit, RayStats, Tracer, Want};
use glam::DVec3;

impl Tracer<'_> {
    /// A value at the hit beta while locating a crossing, counted as a backtrack (its far
    /// terms by share against the sum alone: no level is known inside the bracket).
    fn backtrack_sample(&self, x: DVec3, stats: &mut RayStats) -> FieldSample {
        let before = stats.evals;
        let level = f64::INFINITY;
        let f = self.sample(
            x,
            stats,
            Want::Value,
            true,
            level,
            None,
            StepBeta::default(),
        );
        stats.backtracks += stats.evals - before;
        f
    }

    /// The paper's backtracking: from `t` (where `s < -epsilon`) march back by epsilon
    /// until `s >= -epsilon`.
    pub(super) fn step_back(
        &self,
        o: DVec3,
        d: DVec3,
        mut t: f64,
        stats: &mut RayStats,
    ) -> Option<Hit> {
        let eps = self.options().epsilon;
        while stats.evals + stats.coarse_evals < self.options().max_steps {
            t -= eps;
            let f = self.backtrack_sample(o + t * d, stats);
            if f.s >= -eps {
                return Some(self.hit(o, d, (t, t), &f, stats));
            }
        }
        stats.exhausted = true;
        None
    }

    /// Finds the crossing in `[lo, hi]` (`s(lo) > 0 > s(hi)`) by the Illinois method.
    pub(super) fn backtrack(
        &self,
        o: DVec3,
        d: DVec3,
        (mut lo, mut s_lo): (f64, f64),
        (mut hi, mut s_hi): (f64, f64),
        stats: &mut RayStats,
    ) -> Option<Hit> {
        let eps = self.options().epsilon;
        let mut side = 0i8;
        let mut last = None;
        for _ in 0..64 {
            if stats.evals + stats.coarse_evals >= self.options().max_steps {
                stats.exhausted = true;
                break;
            }
            let mut t = (lo * s_hi - hi * s_lo) / (s_hi - s_lo);
            if !(t > lo && t < hi) {
                t = 0.5 * (lo + hi);
            }
            let f = self.backtrack_sample(o + t * d, stats);
            if f.s.abs() <= eps || hi - lo <= eps {
                return Some(self.hit(o, d, (t, lo), &f, stats));
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
        last.map(|(t, f)| self.hit(o, d, (t, lo), &f, stats))
    }
}
