//! The opening parameter of a tile's step evaluations, switched to the hit beta where its
//! rays' refinements show the coarse steps lagging (SPEC 7; `render::tracer` module
//! docs, items 9 and 10).
//!
//! On point clouds the full evaluations that only take a step are made at the coarser
//! step beta `b_s` (1 by default) instead of the hit beta `b_h` (the scene's): every
//! Barnes-Hut sum is a lower bound of the exact one, so the step is safe, and near the
//! surface it visits 60-75% of the terms. Where a step value falls in the hit band or
//! below, the tracer evaluates the same point again at `b_h` (a refinement) before it
//! decides anything, and the difference `g = s_h - s_s` says how low the coarse sum is
//! there. On the lidar scan it is a fraction of epsilon (median 0.07), on the bunny's
//! points 1-3 epsilons, on a soft point cloud, whose far-field nodes hold most of the sum
//! near the surface, more (the deer at alpha 1: median 4.6, the procedural sphere of
//! points alike). There the coarse steps are short, land in the band while the hit
//! beta's value is still epsilons above it (nearly every hit ray pays a step and a
//! refinement at the same point, then more fine steps) and fail the over-relaxed
//! steps' certificate more often.
//!
//! The rays of a tile meet the same part of the surface, so once a refinement in the
//! tile finds a gap of at least `G_SWITCH` epsilons, the tile's later rays make their
//! step evaluations at the hit beta: no refinement is needed then. Below that gap the
//! coarse steps pay (the lidar scan's gaps are a fraction of epsilon, and steps at the
//! hit beta everywhere would visit more leaves). Every step is still a Barnes-Hut sum, a
//! lower bound of the exact one, so every step stays safe, and hits are decided at `b_h`
//! as before. Only the tile's own rays (same tile and sample pass) teach it, so a render
//! does not depend on how tiles are spread over threads, and a crop traces its tiles as
//! the whole image does. (Edges and triangles step at the scene's beta and decide hits
//! at 0.6 of it, and refine in the same way.) What the switch and its threshold bought,
//! scene by scene: doc/performance-log.md, round eleven.

/// A refinement that finds the step value this many epsilons below the hit beta's
/// switches the tile's steps to the hit beta (1 rather than 4: fewer full evaluations
/// per hit ray on the bunny's points and the deer at alpha 2, while the deer at alpha 4
/// and the lidar scan keep their coarse steps; round eleven of the performance log).
const G_SWITCH: f64 = 1.0;

/// What a tile's rays have learned about its step evaluations.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepBeta {
    on: bool,
    /// The tile's steps are made at the hit beta.
    at_hit_beta: bool,
}

impl StepBeta {
    /// A tile's start: steps at the step beta. With `on = false` nothing is learned.
    pub fn new(on: bool) -> StepBeta {
        StepBeta {
            on,
            at_hit_beta: false,
        }
    }

    /// The tile's steps are made at the hit beta (no refinement is needed).
    pub fn at_hit_beta(&self) -> bool {
        self.at_hit_beta
    }

    /// The opening parameter of a step evaluation for an object whose step beta is
    /// `step` and hit beta `hit`.
    pub fn beta(&self, step: f64, hit: f64) -> f64 {
        if self.at_hit_beta { hit } else { step }
    }

    /// Records a refinement: at the same point, the step evaluation gave `coarse` and the
    /// one at the hit beta `fine` (`epsilon` the hit threshold).
    pub fn refined(&mut self, coarse: f64, fine: f64, epsilon: f64) {
        // NaN (infinite values) does not switch.
        if self.on && fine - coarse >= G_SWITCH * epsilon {
            self.at_hit_beta = true;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_large_gap_switches_the_tile_to_the_hit_beta_for_good() {
        let eps = 1e-3;
        let mut s = StepBeta::new(true);
        assert_eq!(s.beta(1.0, 0.5), 1.0);
        // Gaps below the switch change nothing, however many.
        for gap in [0.0, 0.5, 0.9] {
            s.refined(-gap * eps, 0.0, eps);
            assert!(!s.at_hit_beta(), "{gap}");
        }
        assert_eq!(s.beta(1.0, 0.5), 1.0);
        s.refined(-0.5 * eps, 0.5 * eps, eps);
        assert!(s.at_hit_beta());
        assert_eq!(s.beta(1.0, 0.5), 0.5);
        // A small gap later does not switch back.
        s.refined(0.0, 0.0, eps);
        assert!(s.at_hit_beta());
        // Infinite values teach nothing.
        let mut t = StepBeta::new(true);
        t.refined(f64::INFINITY, f64::INFINITY, eps);
        assert!(!t.at_hit_beta());
    }

    #[test]
    fn a_tile_that_does_not_learn_keeps_the_step_beta() {
        let mut s = StepBeta::new(false);
        s.refined(-10.0, 10.0, 1e-3);
        assert!(!s.at_hit_beta());
        assert_eq!(s.beta(1.0, 0.5), 1.0);
    }
}
