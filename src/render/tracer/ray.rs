//! What tracing one ray found and did (`render::tracer`): its hit, and the work counted
//! on the way, which the image loop sums into `render::image::ImageStats`.

use crate::eval::EvalStats;
use glam::DVec3;

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
    /// Full-accuracy field evaluations, at the scene's beta (one per object evaluated
    /// per step; those near the surface carry the gradient the hit is shaded with).
    pub evals: u32,
    /// Bound steps: cheaper evaluations at a coarser beta (far from the surface).
    pub coarse_evals: u32,
    /// Sum of the evaluations' statistics (leaves, nodes), coarse and full together.
    pub eval: EvalStats,
    /// Leaves visited by the coarse evaluations alone (included in `eval`).
    pub coarse_leaves: u32,
    /// Full evaluations that only took a step, made at the coarser step beta (point
    /// clouds, `render::tracer` item 10; counted in `evals` too).
    pub step_evals: u32,
    /// Retries with a smaller alpha after an infinite (underflowed) naive evaluation.
    pub falloffs: u32,
    /// Evaluations spent locating a crossing after overshooting into the negative band.
    pub backtracks: u32,
    /// Over-relaxed steps whose gap the next sample did not cover (the ray went back to
    /// the plain step; the sample's evaluation is counted in `evals`/`coarse_evals`).
    pub rejected_steps: u32,
    /// Re-evaluations at the finer hit beta of a sample whose value at the scene's beta
    /// fell in the hit band or below (counted in `evals` too).
    pub refinements: u32,
    /// Times the ray's hit beta was halved because a value in the hit band or below
    /// had a certified gap above `GAP_MAX` epsilons (`render::tracer` item 11; the
    /// re-evaluations are counted in `evals` and `refinements` too).
    pub hit_halvings: u32,
    /// The ray ran out of steps (counted as a miss).
    pub exhausted: bool,
    /// Its full evaluations by the value they returned (`render --stats`).
    pub by_value: ByValue,
}

/// Upper edges of the bins of [`ByValue`], in epsilons: the bins are `(-inf, 0)`, `[0,
/// 1)`, `[1, 2)`, ... `[32, 64)` and `[64, inf)` (NaN and `+inf` in the last).
pub const VALUE_EDGES: [f64; 8] = [0.0, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0];

/// Bins of [`ByValue`].
pub const VALUE_BINS: usize = VALUE_EDGES.len() + 1;

/// Full evaluations by the value they returned, in epsilons, and the leaves they
/// visited; apart, the evaluations that only took a hit's gradient (no value). Where a
/// ray's work goes: at values far above the band a full evaluation only takes a step
/// (doc/performance-log.md, round thirty-four).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ByValue {
    pub evals: [u32; VALUE_BINS],
    pub leaves: [u32; VALUE_BINS],
    pub gradient_evals: u32,
    pub gradient_leaves: u32,
}

impl ByValue {
    /// The bin of a value of `v` epsilons.
    pub fn bin(v: f64) -> usize {
        VALUE_EDGES
            .iter()
            .take_while(|&&e| v >= e || v.is_nan())
            .count()
    }

    /// Counts a full evaluation that returned `v` epsilons after visiting `leaves`.
    #[inline]
    pub fn add(&mut self, v: f64, leaves: u32) {
        let b = Self::bin(v);
        self.evals[b] += 1;
        self.leaves[b] += leaves;
    }
}

/// The result of tracing one ray.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RayResult {
    pub hit: Option<Hit>,
    pub stats: RayStats,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_fall_in_the_bin_their_edges_bound() {
        assert_eq!(ByValue::bin(-0.5), 0);
        assert_eq!(ByValue::bin(f64::NEG_INFINITY), 0);
        assert_eq!(ByValue::bin(0.0), 1);
        assert_eq!(ByValue::bin(0.99), 1);
        assert_eq!(ByValue::bin(1.0), 2);
        assert_eq!(ByValue::bin(20.0), 6);
        assert_eq!(ByValue::bin(64.0), VALUE_BINS - 1);
        assert_eq!(ByValue::bin(f64::INFINITY), VALUE_BINS - 1);
        assert_eq!(ByValue::bin(f64::NAN), VALUE_BINS - 1);
        let mut b = ByValue::default();
        b.add(3.0, 10);
        b.add(3.5, 5);
        assert_eq!((b.evals[3], b.leaves[3]), (2, 15));
    }
}
