//! Per-image statistics: what the image loop (`render::image`) sums from its rays'
//! work (`RayStats`) and its tiles' marches (`ConeStats`), and the ratios the reports
//! print (SPEC 7: evaluations and leaves visited per ray).

use super::cone::ConeStats;
use super::hit_gap::HitGap;
use super::tracer::{ByValue, RayResult, VALUE_BINS, VALUE_EDGES};
use crate::film::AaMode;

/// Per-image statistics (SPEC 7).
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct ImageStats {
    pub width: u32,
    pub height: u32,
    /// Pixels rendered (the crop's, or the whole image's).
    pub pixels: u64,
    /// Samples per pixel asked for (per flagged pixel in adaptive mode).
    pub samples: u32,
    pub aa: AaMode,
    /// Adaptive mode: pixels that got the full pattern.
    pub adaptive_pixels: u64,
    /// Rays traced: every sample of every pixel (and the tiles' pixels outside a crop).
    pub rays: u64,
    pub hits: u64,
    pub misses: u64,
    /// Rays that ran out of steps (counted in `misses`).
    pub exhausted: u64,
    /// Field evaluations at the scene's beta over all rays.
    pub evals: u64,
    /// Coarse (far-from-surface) evaluations over all rays.
    pub coarse_evals: u64,
    /// Field evaluations over the rays that hit.
    pub hit_evals: u64,
    /// Full evaluations that only took a step, at the coarser step beta of point clouds
    /// (included in `evals`; `render::tracer` item 10).
    pub step_evals: u64,
    /// The same over the rays that hit (included in `hit_evals`).
    pub hit_step_evals: u64,
    pub max_evals_per_ray: u32,
    /// Exact plus far-field terms over all evaluations.
    pub leaves: u64,
    /// Leaves visited by the coarse evaluations (included in `leaves`).
    pub coarse_leaves: u64,
    /// Coarse evaluations over the rays that hit.
    pub hit_coarse_evals: u64,
    /// Leaves visited over the rays that hit.
    pub hit_leaves: u64,
    /// BVH nodes visited over all evaluations.
    pub nodes: u64,
    pub falloffs: u64,
    pub backtracks: u64,
    /// Over-relaxed steps the next sample did not certify (the ray went back to the
    /// plain step; their evaluations are counted in `evals` and `coarse_evals`).
    pub rejected_steps: u64,
    /// Accurate re-evaluations of samples whose Barnes-Hut value fell in the hit band
    /// or below (included in `evals`; see `render::tracer`).
    pub refinements: u64,
    /// The camera origin is inside the surface (the image is all background).
    pub camera_inside: bool,
    /// Bound evaluations on tile axes (cone marching), shared by the tile's rays;
    /// included in `coarse_evals` and their leaves in `leaves` and `coarse_leaves`.
    pub tile_evals: u64,
    /// CPU seconds spent shading hits (summed over threads; part of `seconds`' work).
    pub shade_cpu_seconds: f64,
    /// Wall-clock seconds of the tracing loop.
    pub seconds: f64,
    pub threads: usize,
    /// How far the exact smooth distance may lie above the value at a sample of the hits
    /// (`render::hit_gap`), when asked for (`FilmOptions::hit_gap`) and not certified.
    pub hit_gap: Option<HitGap>,
    /// Full evaluations by the value they returned (`full_evaluations_by_value` in the
    /// statistics JSON).
    #[serde(rename = "full_evaluations_by_value")]
    pub by_value: ValueTally,
}

/// Full evaluations by the value they returned, in epsilons, summed over rays
/// (`tracer::ByValue`): bin `k` holds the values from `edges_epsilons[k - 1]` (`-inf` for
/// the first) up to `edges_epsilons[k]` (`+inf` for the last). With the evaluations that
/// only took a hit's gradient they account for every full evaluation and its leaves:
/// `evals` and `leaves - coarse_leaves`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ValueTally {
    pub edges_epsilons: [f64; VALUE_BINS - 1],
    pub evaluations: [u64; VALUE_BINS],
    pub leaves: [u64; VALUE_BINS],
    pub gradient_evaluations: u64,
    pub gradient_leaves: u64,
}

impl Default for ValueTally {
    fn default() -> Self {
        ValueTally {
            edges_epsilons: VALUE_EDGES,
            evaluations: [0; VALUE_BINS],
            leaves: [0; VALUE_BINS],
            gradient_evaluations: 0,
            gradient_leaves: 0,
        }
    }
}

impl ValueTally {
    fn add_ray(&mut self, b: &ByValue) {
        for k in 0..VALUE_BINS {
            self.evaluations[k] += u64::from(b.evals[k]);
            self.leaves[k] += u64::from(b.leaves[k]);
        }
        self.gradient_evaluations += u64::from(b.gradient_evals);
        self.gradient_leaves += u64::from(b.gradient_leaves);
    }

    fn merge(&mut self, o: &ValueTally) {
        for k in 0..VALUE_BINS {
            self.evaluations[k] += o.evaluations[k];
            self.leaves[k] += o.leaves[k];
        }
        self.gradient_evaluations += o.gradient_evaluations;
        self.gradient_leaves += o.gradient_leaves;
    }
}

impl ImageStats {
    /// Adds one ray's work and outcome.
    pub(super) fn tally(&mut self, r: &RayResult) {
        let st = &r.stats;
        self.rays += 1;
        self.evals += st.evals as u64;
        self.coarse_evals += st.coarse_evals as u64;
        self.step_evals += st.step_evals as u64;
        self.max_evals_per_ray = self.max_evals_per_ray.max(st.evals + st.coarse_evals);
        self.leaves += st.eval.leaves() as u64;
        self.coarse_leaves += st.coarse_leaves as u64;
        self.nodes += st.eval.nodes as u64;
        self.falloffs += st.falloffs as u64;
        self.backtracks += st.backtracks as u64;
        self.rejected_steps += st.rejected_steps as u64;
        self.refinements += st.refinements as u64;
        self.exhausted += st.exhausted as u64;
        self.by_value.add_ray(&st.by_value);
        if r.hit.is_some() {
            self.hits += 1;
            self.hit_evals += st.evals as u64;
            self.hit_step_evals += st.step_evals as u64;
            self.hit_coarse_evals += st.coarse_evals as u64;
            self.hit_leaves += st.eval.leaves() as u64;
        } else {
            self.misses += 1;
        }
    }

    /// Adds the counts of another part of the image.
    pub(super) fn merge(&mut self, o: &ImageStats) {
        self.rays += o.rays;
        self.hits += o.hits;
        self.misses += o.misses;
        self.exhausted += o.exhausted;
        self.evals += o.evals;
        self.coarse_evals += o.coarse_evals;
        self.hit_evals += o.hit_evals;
        self.step_evals += o.step_evals;
        self.hit_step_evals += o.hit_step_evals;
        self.max_evals_per_ray = self.max_evals_per_ray.max(o.max_evals_per_ray);
        self.leaves += o.leaves;
        self.coarse_leaves += o.coarse_leaves;
        self.hit_coarse_evals += o.hit_coarse_evals;
        self.hit_leaves += o.hit_leaves;
        self.nodes += o.nodes;
        self.falloffs += o.falloffs;
        self.backtracks += o.backtracks;
        self.rejected_steps += o.rejected_steps;
        self.refinements += o.refinements;
        self.tile_evals += o.tile_evals;
        self.shade_cpu_seconds += o.shade_cpu_seconds;
        self.by_value.merge(&o.by_value);
    }

    /// Adds the shared work of tile marches.
    pub(super) fn add_cones(&mut self, c: &ConeStats) {
        self.tile_evals += c.evals;
        self.coarse_evals += c.evals;
        self.leaves += c.leaves;
        self.coarse_leaves += c.leaves;
        self.nodes += c.nodes;
    }

    pub fn evals_per_ray(&self) -> f64 {
        per(self.evals, self.rays)
    }
    /// Full-accuracy evaluations per ray that hit.
    pub fn evals_per_hit(&self) -> f64 {
        per(self.hit_evals, self.hits)
    }
    /// Full evaluations per ray that hit that only took a step at the coarser step beta
    /// (part of [`ImageStats::evals_per_hit`]).
    pub fn step_evals_per_hit(&self) -> f64 {
        per(self.hit_step_evals, self.hits)
    }
    /// Bound steps (coarse evaluations) per ray that hit, its own only: the tile
    /// marches it shared are counted in [`ImageStats::tile_evals_per_ray`].
    pub fn bound_evals_per_hit(&self) -> f64 {
        per(self.hit_coarse_evals, self.hits)
    }
    /// Bound steps per ray, the tile marches included.
    pub fn bound_evals_per_ray(&self) -> f64 {
        per(self.coarse_evals, self.rays)
    }
    /// Tile-march evaluations per ray (each shared by a tile's rays).
    pub fn tile_evals_per_ray(&self) -> f64 {
        per(self.tile_evals, self.rays)
    }
    /// Leaves visited per ray that hit, its own evaluations only.
    pub fn leaves_per_hit(&self) -> f64 {
        per(self.hit_leaves, self.hits)
    }
    /// Leaves per evaluation, coarse and fine together.
    pub fn leaves_per_eval(&self) -> f64 {
        per(self.leaves, self.evals + self.coarse_evals)
    }
    /// Leaves visited per ray: the total work.
    pub fn leaves_per_ray(&self) -> f64 {
        per(self.leaves, self.rays)
    }
    /// Rays per rendered pixel.
    pub fn samples_per_pixel(&self) -> f64 {
        per(self.rays, self.pixels)
    }
    pub fn rays_per_second(&self) -> f64 {
        self.rays as f64 / self.seconds.max(1e-12)
    }
}

/// `n / d` as a ratio, 0 when `d` is 0 (an image with no rays, hits or evaluations).
fn per(n: u64, d: u64) -> f64 {
    n as f64 / d.max(1) as f64
}
