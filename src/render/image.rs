//! The image loop: samples traced in parallel by tiles of `TILE x TILE` pixels (each
//! marched as a cone first, `cone`; the heaviest tiles first, `schedule`), shaded with
//! the hit object's MatCap (SPEC 8) using the camera-space normal and the object's
//! colours (`albedo::shade_hit`), accumulated by the film (`crate::film`). A tile's
//! work does not depend on the other tiles, so the image does not depend on the thread
//! count or the order, and a crop traces the whole image's tiles that overlap it, so
//! its pixels are those of the whole render.
//!
//! - Uniform anti-aliasing: one `trace_tile` pass per position of the sample pattern
//!   (the same offset in every pixel, so the tile's cone holds).
//! - Adaptive: a pass at the pixel centres; then the pixels whose centre sample
//!   disagrees with a 4-neighbour's (hit or miss, object, normals more than
//!   [`NORMAL_ANGLE_DEG`] apart, a channel more than [`SHADE_DIFF`] levels apart) get the
//!   full pattern instead, traced ray by ray after a cone march of the pixel's own
//!   rays ([`Context::pixel_start`]). Their centre
//!   sample is dropped from the colour (the pixel is then exactly the uniform pixel) but
//!   still gives its AOV record.

use super::cone::{ConeStats, Tile, trace_tile};
use super::hit_gap;
pub use super::image_stats::{ImageStats, ValueTally};
use super::schedule;
use super::tracer::{Hit, RayResult, RayStats, Tracer};
use crate::camera::Camera;
use crate::film::accumulate::PixelAccum;
use crate::film::aov::{AovBuffers, PixelRecord};
use crate::film::pattern::{Sample, pattern, primary};
use crate::film::{AaMode, FilmOptions, Rect};
use crate::matcap::MatCap;
use glam::{DVec3, Vec3};
use image::{GrayImage, RgbImage};
use rayon::prelude::*;
use std::time::Instant;

/// Side of the square pixel tiles traced as a unit (and marched as one cone first).
pub const TILE: u32 = 16;

/// Adaptive sampling: neighbours whose normals are further apart than this (degrees)
/// disagree.
pub const NORMAL_ANGLE_DEG: f64 = 30.0;

/// Adaptive sampling: neighbours whose colours differ by more than this in a channel
/// (of 255) disagree.
pub const SHADE_DIFF: u8 = 32;

/// A rendered image (or crop) with its per-pixel hit distances and AOV records.
pub struct Rendered {
    /// The colours: composited over the background for an opaque render; the hits' own
    /// colour (straight alpha, the background where nothing hit) for a transparent one.
    pub image: RgbImage,
    /// Transparent renders: the alpha channel (the samples' hit share).
    pub alpha: Option<GrayImage>,
    /// Ray parameter `t` of the primary sample's hit per pixel (row-major), `+inf` for
    /// misses.
    pub depth: Vec<f32>,
    /// The AOV records, when [`FilmOptions::keep_aovs`].
    pub aovs: Option<AovBuffers>,
    /// The pixels of the full image these are.
    pub region: Rect,
    pub stats: ImageStats,
}

impl Rendered {
    /// The image as written: RGB, or straight-alpha RGBA for a transparent render.
    pub fn to_dynamic(&self) -> image::DynamicImage {
        match &self.alpha {
            None => image::DynamicImage::ImageRgb8(self.image.clone()),
            Some(alpha) => {
                let mut out = image::RgbaImage::new(self.image.width(), self.image.height());
                for (x, y, p) in out.enumerate_pixels_mut() {
                    let c = self.image.get_pixel(x, y).0;
                    *p = image::Rgba([c[0], c[1], c[2], alpha.get_pixel(x, y).0[0]]);
                }
                image::DynamicImage::ImageRgba8(out)
            }
        }
    }
}

/// Renders `camera`'s view, one ray per pixel centre. `progress` is called with the
/// number of rows finished so far.
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
    let options = FilmOptions {
        background,
        ..FilmOptions::default()
    };
    render_film(tracer, camera, shaders, &options, progress, cancelled)
}

/// Renders `camera`'s view with the film `options` (samples, adaptive sampling, filter,
/// transparency, crop, AOVs). `progress` is called with the number of the region's rows
/// finished; `cancelled` is checked before each tile (`None` when it turned true).
pub fn render_film(
    tracer: &Tracer,
    camera: &Camera,
    shaders: &[MatCap],
    options: &FilmOptions,
    progress: &(dyn Fn(u64) + Sync),
    cancelled: &(dyn Fn() -> bool + Sync),
) -> Option<Rendered> {
    let (w, h) = (camera.width(), camera.height());
    let start = Instant::now();
    let region = options.crop.unwrap_or(Rect::full(w, h));
    let n = region.area();
    let mut stats = ImageStats {
        width: w,
        height: h,
        pixels: n as u64,
        samples: options.samples.max(1),
        aa: options.aa,
        threads: rayon::current_num_threads(),
        ..Default::default()
    };
    let (s0, _) = tracer.field(camera.origin(), &mut Default::default());
    if s0 <= 0.0 {
        let film = RegionFilm::empty(region);
        stats.camera_inside = true;
        stats.rays = stats.pixels;
        stats.misses = stats.pixels;
        stats.seconds = start.elapsed().as_secs_f64();
        return Some(film.develop(options, stats));
    }
    let ctx = Context {
        tracer,
        camera,
        shaders,
        s0,
    };
    let samples = pattern(options.samples.max(1), options.filter);
    let adaptive = options.aa == AaMode::Adaptive && samples.len() > 1;
    // Adaptive decisions look at the neighbours: trace one more pixel around the crop.
    let traced = if adaptive {
        region.grown(1, w, h)
    } else {
        region
    };
    let first_pass: Vec<Sample> = if adaptive {
        vec![Sample {
            offset: [0.5, 0.5],
            weight: 1.0,
        }]
    } else {
        samples.clone()
    };
    let tiles = tiles_over(traced, w, h);
    let tiles_per_row = tiles_per_row(&tiles);
    let done = std::sync::atomic::AtomicU64::new(0);
    let order = schedule::heaviest_first(tracer.objects(), camera, &tiles, TILE);
    let results: Vec<TileResult> = schedule::run_in_order(&order, |i| {
        if cancelled() {
            return None;
        }
        let r = ctx.trace_tile_samples(tiles[i], &first_pass);
        let finished = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        if finished.is_multiple_of(tiles_per_row) {
            progress((finished / tiles_per_row * TILE as u64).min(region.height() as u64));
        }
        Some(r)
    })?;
    let mut centres = adaptive.then(|| NeighbourView::new(traced));
    for r in &results {
        stats.merge(&r.stats);
        if let Some(c) = &mut centres {
            for (i, (px, py)) in r.tile_pixels().enumerate() {
                c.put(px, py, r.accum[i].first(), &r.records[i]);
            }
        }
    }
    let mut film = RegionFilm::from_tiles(region, &results, tiles_per_row as usize);
    if let Some(centres) = centres {
        let flagged: Vec<(u32, u32)> = (region.y0..region.y1)
            .flat_map(|y| (region.x0..region.x1).map(move |x| (x, y)))
            .filter(|&(x, y)| centres.disagrees(x, y))
            .collect();
        stats.adaptive_pixels = flagged.len() as u64;
        let redone: Vec<(u32, u32, PixelAccum, u32, ImageStats)> = flagged
            .par_chunks(64)
            .map(|chunk| {
                if cancelled() {
                    return None;
                }
                Some(
                    chunk
                        .iter()
                        .map(|&(x, y)| {
                            let (acc, cost, st) = ctx.trace_pixel(x, y, &samples);
                            (x, y, acc, cost, st)
                        })
                        .collect::<Vec<_>>(),
                )
            })
            .collect::<Option<Vec<_>>>()?
            .into_iter()
            .flatten()
            .collect();
        for (x, y, acc, cost, st) in redone {
            stats.merge(&st);
            film.replace_colour(x, y, acc, cost);
        }
    }
    progress(region.height() as u64);
    stats.seconds = start.elapsed().as_secs_f64();
    if options.hit_gap && !tracer.options().certified_hits {
        stats.hit_gap = hit_gap::measure(tracer, &film.hit_points());
    }
    Some(film.develop(options, stats))
}

/// The full image's tiles (the grid from the top-left corner) that overlap `rect`.
fn tiles_over(rect: Rect, w: u32, h: u32) -> Vec<Tile> {
    let (tx0, ty0) = (rect.x0 / TILE, rect.y0 / TILE);
    let (tx1, ty1) = (rect.x1.div_ceil(TILE), rect.y1.div_ceil(TILE));
    (ty0..ty1)
        .flat_map(|ty| {
            (tx0..tx1).map(move |tx| Tile {
                x0: tx * TILE,
                y0: ty * TILE,
                w: TILE.min(w - tx * TILE),
                h: TILE.min(h - ty * TILE),
            })
        })
        .collect()
}

/// Tiles in the first row of `tiles` (for progress in rows).
fn tiles_per_row(tiles: &[Tile]) -> u64 {
    let y0 = tiles.first().map_or(0, |t| t.y0);
    tiles.iter().filter(|t| t.y0 == y0).count().max(1) as u64
}

/// What tracing and shading need.
struct Context<'a> {
    tracer: &'a Tracer<'a>,
    camera: &'a Camera,
    shaders: &'a [MatCap],
    /// The camera's clearance: every ray starts there.
    s0: f64,
}

/// One traced tile: its pixels' accumulated samples and records, and its work.
struct TileResult {
    tile: Tile,
    accum: Vec<PixelAccum>,
    records: Vec<PixelRecord>,
    stats: ImageStats,
}

impl TileResult {
    /// The tile's pixels in its row-major order.
    fn tile_pixels(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        let t = self.tile;
        (t.y0..t.y0 + t.h).flat_map(move |y| (t.x0..t.x0 + t.w).map(move |x| (x, y)))
    }
}

impl Context<'_> {
    /// The colour of a hit: its MatCap, through the object's colours.
    fn shade(&self, hit: &Hit, stats: &mut ImageStats) -> [u8; 3] {
        let shading = Instant::now();
        let n = self.camera.to_camera_space(hit.normal);
        let shaded = self
            .shaders
            .get(hit.object)
            .map(|m| m.shade(n))
            .unwrap_or([255, 0, 255]);
        let c = super::albedo::shade_hit(self.tracer.objects(), hit, shaded);
        stats.shade_cpu_seconds += shading.elapsed().as_secs_f64();
        c
    }

    /// Traces every pixel of `tile` at each position of `samples`, one cone march each.
    fn trace_tile_samples(&self, tile: Tile, samples: &[Sample]) -> TileResult {
        let n = (tile.w * tile.h) as usize;
        let mut accum = vec![PixelAccum::default(); n];
        let mut records = vec![PixelRecord::default(); n];
        let mut stats = ImageStats::default();
        let mut cones = ConeStats::default();
        let primary = primary(samples);
        let cone = self.tracer.options().cone;
        for (k, s) in samples.iter().enumerate() {
            trace_tile(
                self.tracer,
                self.camera,
                tile,
                s.offset,
                self.s0,
                cone,
                &mut cones,
                &mut |px, py, r| {
                    let i = ((py - tile.y0) * tile.w + (px - tile.x0)) as usize;
                    stats.tally(&r);
                    records[i].cost += r.stats.evals + r.stats.coarse_evals;
                    let colour = r.hit.map(|hit| self.shade(&hit, &mut stats));
                    if let (true, Some(hit)) = (k == primary, r.hit) {
                        records[i].set_hit(hit.t, hit.normal, hit.point, hit.object);
                    }
                    accum[i].add(colour, s.weight);
                },
            );
        }
        stats.add_cones(&cones);
        TileResult {
            tile,
            accum,
            records,
            stats,
        }
    }

    /// Traces pixel `(x, y)` at each position of `samples`, ray by ray from the pixel's
    /// own cone march ([`Context::pixel_start`]): its colour, the evaluations it took
    /// and the work.
    fn trace_pixel(&self, x: u32, y: u32, samples: &[Sample]) -> (PixelAccum, u32, ImageStats) {
        let mut acc = PixelAccum::default();
        let mut stats = ImageStats::default();
        let mut cost = 0;
        let rays: Vec<(DVec3, DVec3)> = samples
            .iter()
            .map(|s| {
                self.camera
                    .ray_through(f64::from(x) + s.offset[0], f64::from(y) + s.offset[1])
            })
            .collect();
        let start = self.pixel_start(x, y, &rays, &mut stats);
        for (s, &(o, d)) in samples.iter().zip(&rays) {
            let r = match start {
                Some(t) => self.tracer.trace(o, d, t),
                None => RayResult::default(),
            };
            stats.tally(&r);
            cost += r.stats.evals + r.stats.coarse_evals;
            let colour = r.hit.map(|hit| self.shade(&hit, &mut stats));
            acc.add(colour, s.weight);
        }
        (acc, cost, stats)
    }

    /// Where the sample rays of pixel `(x, y)` can start: a cone march around the pixel
    /// centre's ray, the argument of `render::cone` (SPEC 7) for one pixel's rays. At
    /// parameter `t` every ray is within `spread * t` of the axis point, so a bound `r`
    /// there lets all of them advance by `r - spread * t`; the march stops when that is
    /// less than half of `r`. `None`: past the scene box, every ray misses. Without cone
    /// marching (or bound steps) the rays start at the camera's clearance, as every
    /// other ray does then.
    fn pixel_start(
        &self,
        x: u32,
        y: u32,
        rays: &[(DVec3, DVec3)],
        stats: &mut ImageStats,
    ) -> Option<f64> {
        let opts = self.tracer.options();
        if !opts.cone || opts.coarse_beta <= 0.0 {
            return Some(self.s0);
        }
        let (o, axis) = self
            .camera
            .ray_through(f64::from(x) + 0.5, f64::from(y) + 0.5);
        let spread = rays
            .iter()
            .map(|&(_, d)| (d - axis).length())
            .fold(0.0, f64::max);
        let t_far = self.tracer.farthest(o);
        let mut t = self.s0;
        let mut cones = ConeStats::default();
        while t <= t_far {
            let mut ray = RayStats::default();
            let r = self.tracer.bound(o + t * axis, opts.coarse_beta, &mut ray);
            cones.evals += ray.coarse_evals as u64;
            cones.leaves += ray.eval.leaves() as u64;
            cones.nodes += ray.eval.nodes as u64;
            let step = r - spread * t;
            if step.is_nan() || step <= 0.5 * r {
                break;
            }
            t += step;
        }
        stats.add_cones(&cones);
        (t <= t_far).then_some(t)
    }
}

/// The centre samples of the traced pixels, for the adaptive decisions.
struct NeighbourView {
    rect: Rect,
    colour: Vec<Option<[u8; 3]>>,
    records: Vec<PixelRecord>,
}

impl NeighbourView {
    fn new(rect: Rect) -> NeighbourView {
        let n = rect.area();
        NeighbourView {
            rect,
            colour: vec![None; n],
            records: vec![PixelRecord::default(); n],
        }
    }

    fn put(&mut self, x: u32, y: u32, colour: Option<[u8; 3]>, record: &PixelRecord) {
        if let Some(i) = self.rect.index(x, y) {
            self.colour[i] = colour;
            self.records[i] = *record;
        }
    }

    /// Whether pixel `(x, y)`'s centre sample disagrees with a 4-neighbour's.
    fn disagrees(&self, x: u32, y: u32) -> bool {
        let Some(i) = self.rect.index(x, y) else {
            return false;
        };
        let neighbours = [
            (x.wrapping_sub(1), y),
            (x + 1, y),
            (x, y.wrapping_sub(1)),
            (x, y + 1),
        ];
        let cos_max = NORMAL_ANGLE_DEG.to_radians().cos() as f32;
        neighbours.into_iter().any(|(nx, ny)| {
            let Some(j) = self.rect.index(nx, ny) else {
                return false;
            };
            let (a, b) = (&self.records[i], &self.records[j]);
            if a.is_hit() != b.is_hit() || a.object != b.object {
                return true;
            }
            let (Some(ca), Some(cb)) = (self.colour[i], self.colour[j]) else {
                return false;
            };
            let dot: f32 = a.normal.iter().zip(&b.normal).map(|(p, q)| p * q).sum();
            dot < cos_max || ca.iter().zip(&cb).any(|(p, q)| p.abs_diff(*q) > SHADE_DIFF)
        })
    }
}

/// The region's pixels as they are traced.
struct RegionFilm {
    rect: Rect,
    accum: Vec<PixelAccum>,
    records: Vec<PixelRecord>,
}

impl RegionFilm {
    /// A region where no ray was traced.
    fn empty(rect: Rect) -> RegionFilm {
        let n = rect.area();
        RegionFilm {
            rect,
            accum: vec![PixelAccum::default(); n],
            records: vec![PixelRecord::default(); n],
        }
    }

    /// The region's pixels from the traced tiles (`tiles_over` the region, in their
    /// order, `columns` to a row: every pixel of the region lies in one), assembled in
    /// parallel: the
    /// buffers' pages are first written there, by all threads (at 1920x1080 filling
    /// them one thread after the trace took 65 ms of a 0.5 s render).
    fn from_tiles(rect: Rect, tiles: &[TileResult], columns: usize) -> RegionFilm {
        let (tx0, ty0) = tiles.first().map_or((0, 0), |t| (t.tile.x0, t.tile.y0));
        let w = rect.width() as usize;
        // The tile holding pixel `i` of the region, and the pixel's index in it.
        let locate = |i: usize| {
            let (x, y) = (rect.x0 + (i % w) as u32, rect.y0 + (i / w) as u32);
            let k = ((y - ty0) / TILE) as usize * columns + ((x - tx0) / TILE) as usize;
            let t = &tiles[k];
            debug_assert!(t.tile.x0 <= x && x < t.tile.x0 + t.tile.w);
            debug_assert!(t.tile.y0 <= y && y < t.tile.y0 + t.tile.h);
            (t, ((y - t.tile.y0) * t.tile.w + (x - t.tile.x0)) as usize)
        };
        let n = rect.area();
        RegionFilm {
            rect,
            accum: (0..n)
                .into_par_iter()
                .map(|i| {
                    let (t, j) = locate(i);
                    t.accum[j]
                })
                .collect(),
            records: (0..n)
                .into_par_iter()
                .map(|i| {
                    let (t, j) = locate(i);
                    t.records[j]
                })
                .collect(),
        }
    }

    /// The hit points of the pixels' primary samples, row by row.
    fn hit_points(&self) -> Vec<DVec3> {
        self.records
            .iter()
            .filter(|r| r.is_hit())
            .map(|r| Vec3::from(r.position).as_dvec3())
            .collect()
    }

    /// Replaces a pixel's colour samples, adding the new rays' cost.
    fn replace_colour(&mut self, x: u32, y: u32, accum: PixelAccum, cost: u32) {
        if let Some(i) = self.rect.index(x, y) {
            self.accum[i] = accum;
            self.records[i].cost += cost;
        }
    }

    fn develop(self, options: &FilmOptions, stats: ImageStats) -> Rendered {
        let (w, h) = (self.rect.width(), self.rect.height());
        let bg = options.background;
        let mut image = RgbImage::new(w, h);
        let mut alpha = options.transparent.then(|| GrayImage::new(w, h));
        for (i, a) in self.accum.iter().enumerate() {
            let (x, y) = (i as u32 % w, i as u32 / w);
            if let Some(alpha) = &mut alpha {
                let [r, g, b, al] = a.straight(bg);
                image.put_pixel(x, y, image::Rgb([r, g, b]));
                alpha.put_pixel(x, y, image::Luma([al]));
            } else {
                image.put_pixel(x, y, image::Rgb(a.opaque(bg)));
            }
        }
        let depth = self.records.iter().map(|r| r.t).collect();
        Rendered {
            image,
            alpha,
            depth,
            aovs: options.keep_aovs.then_some(AovBuffers {
                width: w,
                height: h,
                records: self.records,
            }),
            region: self.rect,
            stats,
        }
    }
}
