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
}

/// The result of tracing one ray.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RayResult {
    pub hit: Option<Hit>,
    pub stats: RayStats,
}
