//! Slice-by-slice rasterization with linear factorization (SPEC 9).
//!
//! For slice `k` (plane `z = z_k`) pixel `(i, j)` is the voxel centre
//! `o + (i hx, j hy, 0)` with `o = min + h / 2` at height `z_k`. Every 3D half-space
//! `n . p <= c` of a site's domain becomes the 2D half-plane
//! `(n_x hx) i + (n_y hy) j <= c - n . o`, and every row `w` of the site's distance
//! vector `w . (p - anchor)` the affine function
//! `w . (o - anchor) + (w_x hx) i + (w_y hy) j`.
//!
//! For a site on a slice:
//! 1. domain: the half-planes, clipped against the rectangle of pixel centres
//!    (Sutherland-Hodgman; for a face prism the three corners of its cross-section are
//!    computed directly) give the polygon's bounding rows and columns, or reject it;
//! 2. rasterization: on row `j` the span is the intersection of the half-planes with the
//!    row (each bounds `i` by a line `u0 + du j`: exact scan conversion of a convex
//!    polygon, no accumulation across rows); along the span the distance-vector
//!    components start at their value at the span's first pixel and are advanced by a
//!    constant increment per pixel (the linear factorization); per pixel only the
//!    squared length `a^2 + b^2 (+ c)` is formed and min-ed into an f64 buffer of
//!    squared distances. With a band, the row is first cut to the interval where that
//!    quadratic in `i` is `<= band^2` (so the band is exact, not a bounding polygon).
//!
//! Finally each slice is written out as `sqrt` in f32 (`+inf` beyond the band). With f64
//! accumulation the interpolated components drift by at most `NX` ulps along a span.
//!
//! A site's slice range comes from convexity: its domain is convex and contains its
//! witness point, so the slices meeting it form an interval found by two binary
//! searches on "the clipped polygon is non-empty" (on the grid box, slightly enlarged).
//!
//! Culling (optional): each slice is split into tiles, and an upper bound `U` of the
//! distance over each tile is taken from one exact nearest query at its centre
//! (`U = d(c) + ` the tile's half diagonal, distance being 1-Lipschitz). A site whose
//! bounding box is farther than `U` from a tile cannot be the closest feature anywhere
//! in it, so its polygon is cut to the tiles it can win. This keeps the exact result
//! (every skipped evaluation is of a site that is not the closest) and removes most
//! of the overlap of face prisms, edge slabs and vertex regions far from their feature.
//!
//! Work is organised in blocks of consecutive slices (in parallel, sized so their
//! buffers stay in cache) and, within a block, in chunks of sites that are turned into
//! polygons and rasterized slice by slice.
//!
//! Layout: this file holds the shared types, the conversion of the sites' half-spaces to
//! pixel coordinates and the block/chunk driver `run`; `range` finds each site's slice
//! range, `tiles` the culling bounds, `domain` a site's half-planes, band box and clipped
//! polygon on a slice, `jobs` turns the sites of a chunk into rasterization jobs (phase
//! 1) and `raster` holds the linear factorization and the span loops (phase 2).

mod domain;
mod jobs;
mod range;
mod raster;
mod tiles;

use super::grid::Grid;
use super::sites::Sites;
use crate::primitives::AnySet;
use glam::DVec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;
use tiles::tiles_per_slice;

/// Timings and counts of one linfac run.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct LinfacRun {
    /// Wall seconds of the per-site slice-range search.
    pub range_seconds: f64,
    /// Wall seconds of the slice loop.
    pub slice_seconds: f64,
    /// Thread-summed seconds in the slice loop: domains (tile bounds, clipping,
    /// culling) and rasterization (spans, evaluation, output).
    pub domain_cpu: f64,
    pub raster_cpu: f64,
    /// Pixel evaluations (sum of span lengths).
    pub evaluations: u64,
    /// Site-slice pairs rasterized.
    pub polygons: u64,
    /// Site-slice pairs within the sites' slice ranges (domain computations).
    pub candidates: u64,
}

/// 2D half-plane `a i + b j <= c` in pixel coordinates, with `inv_a = 1 / a` (0 when
/// the half-plane does not depend on `i`, see [`FLAT`]; `b` is 0 when it does not
/// depend on `j`).
#[derive(Clone, Copy, Debug)]
struct Hp {
    a: f64,
    b: f64,
    c: f64,
    inv_a: f64,
}

/// A site half-space in pixel coordinates for every slice: `a i + b j <= c0 - cz z`.
#[derive(Clone, Copy, Debug)]
struct Plane2 {
    a: f64,
    b: f64,
    inv_a: f64,
    c0: f64,
    cz: f64,
}

/// A half-plane whose unit normal has `|n_x|` (`|n_y|`) below this is treated as
/// independent of `i` (`j`): the neglected term is below 1e-12 of the grid extent, far
/// inside the domain margin.
const FLAT: f64 = 1e-12;

/// Sites are processed in chunks of this many, so that a chunk's data stays in cache
/// while it is rasterized into every slice of a block.
const SITE_CHUNK: usize = 256;

/// Slice buffers of one block should fit in about this many bytes (a core's L2).
const BLOCK_BYTES: usize = 768 << 10;

/// A site's work on one slice.
#[derive(Clone, Copy, Debug)]
struct Job {
    rows: (usize, usize),
    /// Range of the span-end lines in `Scratch::lines`, the first `n_left` bounding
    /// from the left.
    lines: (u32, u32),
    n_left: u32,
    /// With culling: index in `Scratch::tile_spans` of the allowed column interval of
    /// tile row `rows.0 / tile` (one entry per tile row of the job).
    tile_spans: Option<u32>,
    /// Distance-vector components: `a(i, j) = a0 + au i + av j`, likewise `b`; `g` is a
    /// constant added to the squared length.
    a: [f64; 3],
    b: [f64; 3],
    g: f64,
}

#[derive(Default)]
struct Scratch {
    hps: Vec<Hp>,
    lines: Vec<(f64, f64)>,
    tile_spans: Vec<(f64, f64)>,
    jobs: Vec<Job>,
    poly: Vec<(f64, f64)>,
    poly2: Vec<(f64, f64)>,
}

/// Tile layout and the per-tile upper bounds of one block of slices.
struct Tiles<'a> {
    set: &'a AnySet,
    size: usize,
    /// World x range of the pixel centres of each tile column, y of each tile row.
    xs: Vec<(f64, f64)>,
    ys: Vec<(f64, f64)>,
}

/// The grid in pixel coordinates and the sites' half-spaces converted to it.
struct Raster<'a> {
    sites: &'a Sites,
    grid: &'a Grid,
    planes: Vec<Plane2>,
    /// `o = min + h / 2` (z unused) and `h`.
    o: DVec3,
    h: DVec3,
    nx: usize,
    ny: usize,
    tiles: Option<Tiles<'a>>,
}

/// Upper bounds of the distance per tile for the slices of a block (`u[dk][tile]`, tile
/// `ty * ntx + tx`), and their maximum per slice.
#[derive(Default)]
struct Bounds {
    u: Vec<f64>,
    umax: Vec<f64>,
}

impl<'a> Raster<'a> {
    fn new(sites: &'a Sites, grid: &'a Grid, cull: Option<&'a AnySet>) -> Raster<'a> {
        let h = grid.spacing();
        let o = grid.min + 0.5 * h;
        let planes = sites
            .planes
            .iter()
            .map(|s| {
                let a = s.n.x * h.x;
                Plane2 {
                    a,
                    b: if s.n.y.abs() > FLAT { s.n.y * h.y } else { 0.0 },
                    inv_a: if s.n.x.abs() > FLAT { 1.0 / a } else { 0.0 },
                    c0: s.c - s.n.x * o.x - s.n.y * o.y,
                    cz: s.n.z,
                }
            })
            .collect();
        let (nx, ny) = (grid.res[0], grid.res[1]);
        let tiles = cull.map(|set| {
            let per_slice = tiles_per_slice(sites) as f64;
            let size = (((nx * ny) as f64 / per_slice).sqrt().round() as usize).clamp(4, 32);
            let span = |n: usize, o: f64, h: f64| -> Vec<(f64, f64)> {
                (0..n.div_ceil(size))
                    .map(|t| {
                        let (i0, i1) = (t * size, ((t + 1) * size).min(n) - 1);
                        (o + i0 as f64 * h, o + i1 as f64 * h)
                    })
                    .collect()
            };
            Tiles {
                set,
                size,
                xs: span(nx, o.x, h.x),
                ys: span(ny, o.y, h.y),
            }
        });
        Raster {
            sites,
            grid,
            planes,
            o,
            h,
            nx,
            ny,
            tiles,
        }
    }
}

/// Computes the field into `out` (length `grid.len()`, C order) from `sites`; `cull`
/// is the primitive set whose nearest queries bound the tiles (no culling if `None`);
/// `active`, if given, leaves out the sites marked `false` (sites that cannot be the
/// closest feature anywhere in the grid, see `field::plan`).
pub(crate) fn run(
    sites: &Sites,
    grid: &Grid,
    band: Option<f64>,
    cull: Option<&AnySet>,
    active: Option<&[bool]>,
    out: &mut [f32],
) -> LinfacRun {
    let t = Instant::now();
    let raster = Raster::new(sites, grid, cull);
    let ranges: Vec<(usize, usize)> = (0..sites.sites.len())
        .into_par_iter()
        .map_init(Scratch::default, |s, idx| {
            if active.is_none_or(|a| a[idx]) {
                raster.slice_range(idx, s)
            } else {
                (1, 0)
            }
        })
        .collect();
    let candidates: u64 = ranges
        .iter()
        .map(|&(a, b)| if a <= b { (b - a + 1) as u64 } else { 0 })
        .sum();
    // Slice range of each chunk of sites.
    let chunk_ranges: Vec<(usize, usize)> = ranges
        .chunks(SITE_CHUNK)
        .map(|c| {
            c.iter().fold((usize::MAX, 0), |(a, b), &(k0, k1)| {
                if k0 <= k1 {
                    (a.min(k0), b.max(k1))
                } else {
                    (a, b)
                }
            })
        })
        .collect();
    let range_seconds = t.elapsed().as_secs_f64();

    let slice_len = grid.slice_len();
    let nz = grid.res[2];
    let tasks = 4 * rayon::current_num_threads();
    let block = (BLOCK_BYTES / (8 * slice_len)).clamp(1, nz.div_ceil(tasks).max(1));
    let dom_ns = AtomicU64::new(0);
    let ras_ns = AtomicU64::new(0);
    let evals = AtomicU64::new(0);
    let polys = AtomicU64::new(0);
    let t = Instant::now();
    out.par_chunks_mut(block * slice_len)
        .enumerate()
        .for_each_init(
            || (Scratch::default(), Vec::new(), Bounds::default()),
            |(s, buf, bounds), (b, out_block)| {
                let k_first = b * block;
                let nk = out_block.len() / slice_len;
                let t0 = Instant::now();
                buf.clear();
                buf.resize(nk * slice_len, f64::INFINITY);
                raster.tile_bounds(k_first, nk, bounds);
                let mut dom = t0.elapsed().as_nanos() as u64;
                let (mut ras, mut n_eval, mut n_poly) = (0u64, 0u64, 0u64);
                for (c, (chunk, &(c0, c1))) in
                    ranges.chunks(SITE_CHUNK).zip(&chunk_ranges).enumerate()
                {
                    for dk in 0..nk {
                        let k = k_first + dk;
                        if k < c0 || k > c1 {
                            continue;
                        }
                        let t0 = Instant::now();
                        raster.slice_jobs(k, dk, c * SITE_CHUNK, chunk, bounds, s);
                        let t1 = Instant::now();
                        n_eval +=
                            raster.slice_raster(s, &mut buf[dk * slice_len..(dk + 1) * slice_len]);
                        let t2 = Instant::now();
                        n_poly += s.jobs.len() as u64;
                        dom += (t1 - t0).as_nanos() as u64;
                        ras += (t2 - t1).as_nanos() as u64;
                    }
                }
                let t0 = Instant::now();
                for (o, &d2) in out_block.iter_mut().zip(buf.iter()) {
                    let d = d2.sqrt();
                    *o = match band {
                        Some(b) if !(d <= b) => f32::INFINITY,
                        _ => d as f32,
                    };
                }
                ras += t0.elapsed().as_nanos() as u64;
                dom_ns.fetch_add(dom, Ordering::Relaxed);
                ras_ns.fetch_add(ras, Ordering::Relaxed);
                evals.fetch_add(n_eval, Ordering::Relaxed);
                polys.fetch_add(n_poly, Ordering::Relaxed);
            },
        );
    LinfacRun {
        range_seconds,
        slice_seconds: t.elapsed().as_secs_f64(),
        domain_cpu: dom_ns.into_inner() as f64 * 1e-9,
        raster_cpu: ras_ns.into_inner() as f64 * 1e-9,
        evaluations: evals.into_inner(),
        polygons: polys.into_inner(),
        candidates,
    }
}
