//! How far the exact smooth distance may lie above the value a render's hits were decided
//! on (SPEC 6, 7; `render::tracer` items 9 and 11).
//!
//! A hit is where the Barnes-Hut sum at the hit beta falls within epsilon of zero. Its far
//! terms bound their subtrees from above (closest box point, largest weight), so the value
//! is a lower bound of the exact smooth distance; the same walk also bounds each far term
//! from below (farthest box corner, weight 1) and so the exact value from above
//! (`eval::smooth`, `s_upper`). The gap between the two at a hit point, in epsilons, says
//! how far outside the exact surface the hit may lie, measured along the field: a fraction
//! of an epsilon where the kernel is narrow against the mesh's detail, tens of epsilons
//! where it is wide (`alpha` times the median edge well below 1: the far field's largest
//! weight and closest corner overstate many subtrees at once). The render's hits are
//! sampled evenly in raster order, at most [`MAX_SAMPLES`] of them, and each is evaluated
//! once more with its upper bound ([`Tracer::value_interval`]): a report, not a step of
//! the tracer, and not counted in the image's statistics.

use super::tracer::Tracer;
use glam::DVec3;
use rayon::prelude::*;

/// Largest number of hits sampled.
pub const MAX_SAMPLES: usize = 128;

/// At most one hit in this many is sampled: a hit ray takes two to five full
/// evaluations, so the report adds at most about 3% of them on a small image (0.6% of
/// the instructions on the published full bunny at 480x270, round twenty-three).
pub const MIN_STRIDE: usize = 16;

/// Median above which a render's hits are reported as loose (the CLI's note): one
/// epsilon, the width of the hit band.
pub const LOOSE: f64 = 1.0;

/// The gap at a sample of a render's hits, in epsilons.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct HitGap {
    /// Hits sampled.
    pub samples: usize,
    pub median: f64,
    pub max: f64,
}

impl HitGap {
    /// Whether the median hit may lie more than [`LOOSE`] epsilons outside the exact
    /// surface.
    pub fn loose(&self) -> bool {
        self.median > LOOSE
    }
}

/// The gap at up to [`MAX_SAMPLES`] of `hits` (points where the tracer stopped), one in
/// [`MIN_STRIDE`] or fewer, taken evenly; `None` without hits, or where no object's upper bound covers them (point
/// clouds, whose far terms come from moments).
pub fn measure(tracer: &Tracer, hits: &[DVec3]) -> Option<HitGap> {
    if hits.is_empty() || !tracer.covers_gaps() {
        return None;
    }
    let stride = hits.len().div_ceil(MAX_SAMPLES).max(MIN_STRIDE);
    let eps = tracer.options().epsilon;
    let mut gaps: Vec<f64> = hits
        .par_iter()
        .step_by(stride)
        .map(|&x| {
            let (lower, upper) = tracer.value_interval(x);
            (upper - lower).max(0.0) / eps
        })
        .filter(|g| g.is_finite())
        .collect();
    if gaps.is_empty() {
        return None;
    }
    gaps.sort_by(f64::total_cmp);
    let n = gaps.len();
    Some(HitGap {
        samples: n,
        median: gaps[(n - 1) / 2],
        max: gaps[n - 1],
    })
}
