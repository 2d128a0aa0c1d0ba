//! The image loop: one ray per pixel centre, traced in parallel by tiles of
//! `TILE x TILE` pixels (each marched as a cone first, `cone`), shaded with the hit
//! object's MatCap (SPEC 8) using the camera-space normal. A tile's work does not depend
//! on the other tiles, so the image does not depend on the thread count.

use super::cone::{ConeStats, Tile, trace_tile};
use super::tracer::{RayResult, Tracer};
use crate::camera::Camera;
use crate::matcap::MatCap;
use image::RgbImage;
use rayon::prelude::*;
use std::time::Instant;

/// Side of the square pixel tiles traced as a unit (and marched as one cone first).
pub const TILE: u32 = 16;

/// Per-image statistics (SPEC 7).
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct ImageStats {
    pub width: u32,
    pub height: u32,
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
}

impl ImageStats {
    /// Adds one ray's work and outcome.
    fn tally(&mut self, r: &RayResult) {
        let st = &r.stats;
        self.evals += st.evals as u64;
        self.coarse_evals += st.coarse_evals as u64;
        self.max_evals_per_ray = self.max_evals_per_ray.max(st.evals + st.coarse_evals);
        self.leaves += st.eval.leaves() as u64;
        self.coarse_leaves += st.coarse_leaves as u64;
        self.nodes += st.eval.nodes as u64;
        self.falloffs += st.falloffs as u64;
        self.backtracks += st.backtracks as u64;
        self.exhausted += st.exhausted as u64;
        if r.hit.is_some() {
            self.hits += 1;
            self.hit_evals += st.evals as u64;
            self.hit_coarse_evals += st.coarse_evals as u64;
            self.hit_leaves += st.eval.leaves() as u64;
        } else {
            self.misses += 1;
        }
    }

    /// Adds the counts of another part of the image.
    fn merge(&mut self, o: &ImageStats) {
        self.hits += o.hits;
        self.misses += o.misses;
        self.exhausted += o.exhausted;
        self.evals += o.evals;
        self.coarse_evals += o.coarse_evals;
        self.hit_evals += o.hit_evals;
        self.max_evals_per_ray = self.max_evals_per_ray.max(o.max_evals_per_ray);
        self.leaves += o.leaves;
        self.coarse_leaves += o.coarse_leaves;
        self.hit_coarse_evals += o.hit_coarse_evals;
        self.hit_leaves += o.hit_leaves;
        self.nodes += o.nodes;
        self.falloffs += o.falloffs;
        self.backtracks += o.backtracks;
        self.tile_evals += o.tile_evals;
        self.shade_cpu_seconds += o.shade_cpu_seconds;
    }

    /// Adds the shared work of tile marches.
    fn add_cones(&mut self, c: &ConeStats) {
        self.tile_evals += c.evals;
        self.coarse_evals += c.evals;
        self.leaves += c.leaves;
        self.coarse_leaves += c.leaves;
        self.nodes += c.nodes;
    }

    pub fn evals_per_ray(&self) -> f64 {
        self.evals as f64 / self.rays.max(1) as f64
    }
    /// Full-accuracy evaluations per ray that hit.
    pub fn evals_per_hit(&self) -> f64 {
        self.hit_evals as f64 / self.hits.max(1) as f64
    }
    /// Bound steps (coarse evaluations) per ray that hit, its own only: the tile
    /// marches it shared are counted in [`ImageStats::tile_evals_per_ray`].
    pub fn bound_evals_per_hit(&self) -> f64 {
        self.hit_coarse_evals as f64 / self.hits.max(1) as f64
    }
    /// Bound steps per ray, the tile marches included.
    pub fn bound_evals_per_ray(&self) -> f64 {
        self.coarse_evals as f64 / self.rays.max(1) as f64
    }
    /// Tile-march evaluations per ray (each shared by a tile's rays).
    pub fn tile_evals_per_ray(&self) -> f64 {
        self.tile_evals as f64 / self.rays.max(1) as f64
    }
    /// Leaves visited per ray that hit, its own evaluations only.
    pub fn leaves_per_hit(&self) -> f64 {
        self.hit_leaves as f64 / self.hits.max(1) as f64
    }
    /// Leaves per evaluation, coarse and fine together.
    pub fn leaves_per_eval(&self) -> f64 {
        self.leaves as f64 / (self.evals + self.coarse_evals).max(1) as f64
    }
    /// Leaves visited per ray: the total work.
    pub fn leaves_per_ray(&self) -> f64 {
        self.leaves as f64 / self.rays.max(1) as f64
    }
    pub fn rays_per_second(&self) -> f64 {
        self.rays as f64 / self.seconds.max(1e-12)
    }
}

/// One traced tile: its colours and depths (row-major within the tile) and its work.
type TileResult = (Tile, Vec<[u8; 3]>, Vec<f32>, ImageStats);

/// A rendered image with its per-pixel hit distances.
pub struct Rendered {
    pub image: RgbImage,
    /// Ray parameter `t` of the hit per pixel (row-major), `+inf` for misses.
    pub depth: Vec<f32>,
    pub stats: ImageStats,
}

/// Renders `camera`'s view. `progress` is called with the number of rows finished so far.
pub fn render(
    tracer: &Tracer,
    camera: &Camera,
    shaders: &[MatCap],
    background: [u8; 3],
    progress: &(dyn Fn(u64) + Sync),
) -> Rendered {
    render_cancellable(tracer, camera, shaders, background, progress, &|| false)
        .expect("a render that is never cancelled finishes")
}

/// [`render`] that gives up when `cancelled()` turns true (checked before each tile):
/// `None` then. An interactive view calls it with a check of its newest request.
pub fn render_cancellable(
    tracer: &Tracer,
    camera: &Camera,
    shaders: &[MatCap],
    background: [u8; 3],
    progress: &(dyn Fn(u64) + Sync),
    cancelled: &(dyn Fn() -> bool + Sync),
) -> Option<Rendered> {
    let (w, h) = (camera.width(), camera.height());
    let start = Instant::now();
    let mut stats = ImageStats {
        width: w,
        height: h,
        rays: w as u64 * h as u64,
        threads: rayon::current_num_threads(),
        ..Default::default()
    };
    let origin = camera.origin();
    let mut probe = Default::default();
    let (s0, _) = tracer.field(origin, &mut probe);
    let mut image = RgbImage::from_pixel(w, h, image::Rgb(background));
    let mut depth = vec![f32::INFINITY; (w * h) as usize];
    if s0 <= 0.0 {
        stats.camera_inside = true;
        stats.misses = stats.rays;
        stats.seconds = start.elapsed().as_secs_f64();
        return Some(Rendered {
            image,
            depth,
            stats,
        });
    }
    let cone = tracer.options().cone;
    let tiles: Vec<Tile> = (0..h.div_ceil(TILE))
        .flat_map(|ty| {
            (0..w.div_ceil(TILE)).map(move |tx| Tile {
                x0: tx * TILE,
                y0: ty * TILE,
                w: TILE.min(w - tx * TILE),
                h: TILE.min(h - ty * TILE),
            })
        })
        .collect();
    let tiles_per_row = w.div_ceil(TILE) as u64;
    let done = std::sync::atomic::AtomicU64::new(0);
    // Each tile is traced, shaded and tallied on its own, so only its pixels are kept.
    let results: Vec<TileResult> = tiles
        .into_par_iter()
        .map(|tile| {
            if cancelled() {
                return None;
            }
            let n = (tile.w * tile.h) as usize;
            let mut colours = vec![background; n];
            let mut tile_depth = vec![f32::INFINITY; n];
            let mut tile_stats = ImageStats::default();
            let mut cones = ConeStats::default();
            trace_tile(
                tracer,
                camera,
                tile,
                [0.5, 0.5],
                s0,
                cone,
                &mut cones,
                &mut |px, py, r| {
                    tile_stats.tally(&r);
                    if let Some(hit) = r.hit {
                        let shading = Instant::now();
                        let i = ((py - tile.y0) * tile.w + (px - tile.x0)) as usize;
                        let n = camera.to_camera_space(hit.normal);
                        let shaded = shaders
                            .get(hit.object)
                            .map(|m| m.shade(n))
                            .unwrap_or([255, 0, 255]);
                        colours[i] = super::albedo::shade_hit(tracer.objects(), &hit, shaded);
                        tile_depth[i] = hit.t as f32;
                        tile_stats.shade_cpu_seconds += shading.elapsed().as_secs_f64();
                    }
                },
            );
            tile_stats.add_cones(&cones);
            // Progress in rows: a row of tiles counts once all its tiles are done.
            let finished = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            if finished.is_multiple_of(tiles_per_row) {
                progress((finished / tiles_per_row * TILE as u64).min(h as u64));
            }
            Some((tile, colours, tile_depth, tile_stats))
        })
        .collect::<Option<_>>()?;
    for (tile, colours, tile_depth, tile_stats) in results {
        for (i, (c, d)) in colours.into_iter().zip(tile_depth).enumerate() {
            let (px, py) = (tile.x0 + i as u32 % tile.w, tile.y0 + i as u32 / tile.w);
            image.put_pixel(px, py, image::Rgb(c));
            depth[(py * w + px) as usize] = d;
        }
        stats.merge(&tile_stats);
    }
    progress(h as u64);
    stats.seconds = start.elapsed().as_secs_f64();
    Some(Rendered {
        image,
        depth,
        stats,
    })
}
