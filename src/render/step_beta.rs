//! The opening parameter of a tile's step evaluations on point clouds, learned from its
//! rays' refinements (SPEC 7; `render::tracer` module docs, items 9 and 10).
//!
//! On point clouds the full evaluations that only take a step are made at the coarser
//! step beta `b_s` (1 by default) instead of the hit beta `b_h` (the scene's): every
//! Barnes-Hut sum is a lower bound of the exact one, so the step is safe, and near the
//! surface it visits 60-75% of the terms. Where a step value falls in the hit band or
//! below, the tracer evaluates the same point again at `b_h` (a refinement) before it
//! decides anything, and the difference `g = s_h - s_s` says how low the coarse sum is
//! there. On the lidar scan it is a fraction of epsilon (median 0.07), and the coarse
//! steps are as long as fine ones. On a soft point cloud, whose far-field nodes hold most
//! of the sum near the surface, it is several epsilons (the deer at alpha 1: median 4.6):
//! its coarse steps are short, land in the band early (nearly every hit ray then pays
//! a step and a refinement at the same point) and fail the over-relaxed steps'
//! certificate more often. (Edges and triangles step at the scene's beta and decide
//! hits at 0.6 of it, and refine in the same way; on the scenes of Table 1 their gaps
//! stay under half an epsilon, and they render as before.)
//!
//! The rays of a tile meet the same part of the surface, so the tile keeps the largest
//! gap its rays' refinements have measured, `G` (in epsilons), and makes its later step
//! evaluations at
//!
//!   `b = b_s - m (b_s - b_h)`,  `m = clamp((G - G_FREE) / (G_FULL - G_FREE), 0, 1)`:
//!
//! the coarse beta while the gaps stay under half an epsilon, the hit beta from two and a
//! half on (no refinement is needed then), in between a beta in between. Every such
//! sum is a Barnes-Hut sum, a lower bound of the exact one, so every step stays safe,
//! and hits are decided at `b_h` as before. Only the tile's own rays (same tile and sample pass) are used, so a
//! render does not depend on how tiles are spread over threads, and a crop traces its
//! tiles as the whole image does.

/// Gaps up to this many epsilons leave the coarse step beta alone.
const G_FREE: f64 = 0.5;
/// From a gap of this many epsilons on, steps are made at the hit beta.
const G_FULL: f64 = 2.5;

/// What a tile's rays have learned about its step evaluations.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepBeta {
    on: bool,
    /// `m`: how far from the step beta towards the hit beta the steps are made.
    share: f64,
}

impl StepBeta {
    /// A tile's start: steps at the coarse beta. With `on = false` nothing is learned.
    pub fn new(on: bool) -> StepBeta {
        StepBeta { on, share: 0.0 }
    }

    /// The share `m` of the way from the step beta to the hit beta (0 until learned).
    pub fn share(&self) -> f64 {
        self.share
    }

    /// The opening parameter of a step evaluation for an object whose step beta is
    /// `step` and hit beta `hit` (`hit <= step`).
    pub fn beta(&self, step: f64, hit: f64) -> f64 {
        if self.share >= 1.0 {
            hit
        } else {
            step - self.share * (step - hit)
        }
    }

    /// Records a refinement: at the same point, the step evaluation gave `coarse` and the
    /// one at the hit beta `fine` (`epsilon` the hit threshold).
    pub fn refined(&mut self, coarse: f64, fine: f64, epsilon: f64) {
        if !self.on {
            return;
        }
        let gap = (fine - coarse) / epsilon;
        let m = ((gap - G_FREE) / (G_FULL - G_FREE)).clamp(0.0, 1.0);
        // NaN (an infinite value) leaves the share as it was.
        if m > self.share {
            self.share = m;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_step_beta_moves_towards_the_hit_beta_with_the_largest_gap() {
        let eps = 1e-3;
        let mut s = StepBeta::new(true);
        assert_eq!(s.beta(1.0, 0.5), 1.0);
        // A gap under half an epsilon changes nothing.
        s.refined(0.0, 0.4 * eps, eps);
        assert_eq!(s.share(), 0.0);
        // 1.5 epsilons: half way.
        s.refined(-eps, 0.5 * eps, eps);
        assert!((s.share() - 0.5).abs() < 1e-12);
        assert!((s.beta(1.0, 0.5) - 0.75).abs() < 1e-12);
        // A smaller gap later does not undo it; a larger one goes on to the hit beta.
        s.refined(0.0, 0.6 * eps, eps);
        assert!((s.share() - 0.5).abs() < 1e-12);
        s.refined(-4.0 * eps, 0.0, eps);
        assert_eq!(s.share(), 1.0);
        assert_eq!(s.beta(1.0, 0.5), 0.5);
        // Never outside [hit, step].
        for share in [0.0, 0.3, 1.0] {
            let b = StepBeta { on: true, share }.beta(1.0, 0.5);
            assert!((0.5..=1.0).contains(&b));
        }
        // Infinite values teach nothing.
        let mut t = StepBeta::new(true);
        t.refined(f64::INFINITY, f64::INFINITY, eps);
        assert_eq!(t.share(), 0.0);
    }

    #[test]
    fn a_tile_that_does_not_learn_keeps_the_step_beta() {
        let mut s = StepBeta::new(false);
        s.refined(-10.0, 10.0, 1e-3);
        assert_eq!(s.share(), 0.0);
        assert_eq!(s.beta(1.0, 0.5), 1.0);
    }
}
