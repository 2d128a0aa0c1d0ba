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

use super::grid::Grid;
use super::sites::{SiteKind, Sites};
use crate::eval::nearest::nearest_within;
use crate::primitives::AnySet;
use glam::DVec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

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

/// Band-cut spans are widened by this many pixels (the band test has its own margin;
/// a wider span only costs evaluations).
const SPAN_SLACK: f64 = 1e-6;

/// Sites are processed in chunks of this many, so that a chunk's data stays in cache
/// while it is rasterized into every slice of a block.
const SITE_CHUNK: usize = 256;

/// Slice buffers of one block should fit in about this many bytes (a core's L2).
const BLOCK_BYTES: usize = 768 << 10;

/// Culling aims at about this many tiles per slice: finer tiles cull more but cost a
/// nearest query each and more tests per polygon. Measured best on the benchmark grids:
/// 64 for triangle sets, 128 for edges, 512 for points (whose whole-slice domains gain
/// the most).
fn tiles_per_slice(sites: &Sites) -> usize {
    match (sites.counts.faces, sites.counts.edges) {
        (0, 0) => 512,
        (0, _) => 128,
        _ => 64,
    }
}

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

    /// Fills `b` with the tile bounds of slices `k0 .. k0 + nk`: an exact nearest query
    /// at each tile centre (bounded by the previous tile's result moved by the distance
    /// between the centres), plus the tile's half diagonal, plus slack.
    #[inline(never)]
    fn tile_bounds(&self, k0: usize, nk: usize, b: &mut Bounds) {
        let Some(t) = &self.tiles else { return };
        let (ntx, nty) = (t.xs.len(), t.ys.len());
        b.u.clear();
        b.umax.clear();
        let eta = self.sites.eta;
        let band = self.sites.band.unwrap_or(f64::INFINITY);
        let mut prev: Option<(DVec3, f64)> = None;
        for dk in 0..nk {
            let z = self.grid.slice_z(k0 + dk);
            let mut umax = 0.0f64;
            let first = b.u.len();
            b.u.resize(first + ntx * nty, 0.0);
            for ty in 0..nty {
                for s in 0..ntx {
                    // Serpentine order keeps consecutive centres close.
                    let tx = if ty % 2 == 0 { s } else { ntx - 1 - s };
                    let (x0, x1) = t.xs[tx];
                    let (y0, y1) = t.ys[ty];
                    let c = DVec3::new(0.5 * (x0 + x1), 0.5 * (y0 + y1), z);
                    let r = 0.5 * ((x1 - x0).hypot(y1 - y0));
                    let bound = prev.map_or(f64::INFINITY, |(pc, pd)| {
                        (pd + (c - pc).length()) * (1.0 + 1e-9) + eta
                    });
                    let mut q = nearest_within(&[t.set], c, bound);
                    if q.index == u32::MAX {
                        q = nearest_within(&[t.set], c, f64::INFINITY);
                    }
                    prev = Some((c, q.d));
                    let u = ((q.d + r) * (1.0 + 1e-9) + eta).min(band);
                    b.u[first + ty * ntx + tx] = u;
                    umax = umax.max(u);
                }
            }
            b.umax.push(umax);
        }
    }

    /// Narrows `rect` to the band box of site `idx` at height `z` (the feature's box
    /// grown by the band; for a vertex, by the radius of its band disk on the slice).
    /// Returns false when the band misses the slice.
    fn band_rect(&self, idx: usize, z: f64, rect: &mut [f64; 4]) -> bool {
        let Some(band) = self.sites.band else {
            return true;
        };
        let site = &self.sites.sites[idx];
        let (lo, hi) = site.bounds;
        let r = if site.kind == SiteKind::Vertex {
            let dz = z - site.anchor.z;
            let r2 = band * band - dz * dz;
            if r2 < 0.0 {
                return false;
            }
            r2.sqrt()
        } else if z < lo.z - band || z > hi.z + band {
            return false;
        } else {
            band
        };
        self.narrow(rect, lo, hi, r)
    }

    /// Narrows `rect` to the xy box `[lo - r, hi + r]` (world units); false if empty.
    #[inline]
    fn narrow(&self, rect: &mut [f64; 4], lo: DVec3, hi: DVec3, r: f64) -> bool {
        rect[0] = rect[0].max((lo.x - r - self.o.x) / self.h.x);
        rect[2] = rect[2].min((hi.x + r - self.o.x) / self.h.x);
        rect[1] = rect[1].max((lo.y - r - self.o.y) / self.h.y);
        rect[3] = rect[3].min((hi.y + r - self.o.y) / self.h.y);
        rect[0] <= rect[2] && rect[1] <= rect[3]
    }

    /// Pushes the half-planes of site `idx` at height `z`. Returns false when one of
    /// them excludes the whole slice.
    fn push_halfplanes(&self, idx: usize, z: f64, out: &mut Vec<Hp>) -> bool {
        let site = &self.sites.sites[idx];
        for p in &self.planes[site.planes.0 as usize..site.planes.1 as usize] {
            let hp = Hp {
                a: p.a,
                b: p.b,
                c: p.c0 - p.cz * z,
                inv_a: p.inv_a,
            };
            if hp.a == 0.0 && hp.b == 0.0 && hp.c < 0.0 {
                return false;
            }
            out.push(hp);
        }
        true
    }

    /// Pixel bounding box of the triangle cut from a face's prism by the plane at
    /// height `z`, from its corners `p + ((z - p_z) / n_z) n` (`None` when the face is
    /// nearly vertical, `|n_z| < 1e-6`), and the signed plane distances of the corners.
    /// The box is widened by 1e-6 pixel; pixels that rounding could still drop lie on
    /// the prism's side planes, inside the (margin-widened) domains of its edges.
    #[inline]
    fn face_bbox(&self, idx: usize, z: f64) -> Option<([f64; 4], [f64; 3])> {
        let site = &self.sites.sites[idx];
        let n = site.rows[0];
        if !(n.z.abs() >= 1e-6) {
            return None;
        }
        let inv = 1.0 / n.z;
        let mut bb = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        let mut ts = [0.0; 3];
        for (c, p) in [site.anchor, site.rows[1], site.rows[2]]
            .into_iter()
            .enumerate()
        {
            let t = (z - p.z) * inv;
            ts[c] = t;
            let u = (p.x + t * n.x - self.o.x) / self.h.x;
            let v = (p.y + t * n.y - self.o.y) / self.h.y;
            bb = [bb[0].min(u), bb[1].min(v), bb[2].max(u), bb[3].max(v)];
        }
        const W: f64 = 1e-6;
        Some(([bb[0] - W, bb[1] - W, bb[2] + W, bb[3] + W], ts))
    }

    /// Whether the domain of site `idx` meets slice `k` inside the grid box (enlarged
    /// by half a voxel so the witness is strictly inside).
    fn meets_slice(&self, idx: usize, k: usize, s: &mut Scratch) -> bool {
        let mut rect = [-1.0, -1.0, self.nx as f64, self.ny as f64];
        s.hps.clear();
        let mut hps = std::mem::take(&mut s.hps);
        let z = self.grid.slice_z(k);
        let ok = self.band_rect(idx, z, &mut rect)
            && self.push_halfplanes(idx, z, &mut hps)
            && clip_bbox(rect, &hps, &mut s.poly, &mut s.poly2).is_some();
        s.hps = hps;
        ok
    }

    /// Inclusive slice range `(k0, k1)` met by the site's domain (`k0 > k1` when none).
    fn slice_range(&self, idx: usize, s: &mut Scratch) -> (usize, usize) {
        let grid = self.grid;
        let nz = grid.res[2];
        let w = self.sites.sites[idx].witness;
        let inside =
            w.x >= grid.min.x && w.x <= grid.max.x && w.y >= grid.min.y && w.y <= grid.max.y;
        if !inside {
            return (0, nz - 1);
        }
        let hz = grid.spacing().z;
        let kp = ((w.z - grid.min.z) / hz - 0.5)
            .floor()
            .clamp(-1.0, nz as f64 - 1.0) as isize;
        let mut test = |k: usize| self.meets_slice(idx, k, s);
        let lower = if kp >= 0 && test(kp as usize) {
            let (mut lo, mut hi) = (0usize, kp as usize);
            while lo < hi {
                let mid = (lo + hi) / 2;
                if test(mid) { hi = mid } else { lo = mid + 1 }
            }
            Some(lo)
        } else {
            None
        };
        let up0 = (kp + 1) as usize;
        let upper = if up0 < nz && test(up0) {
            let (mut lo, mut hi) = (up0, nz - 1);
            while lo < hi {
                let mid = (lo + hi).div_ceil(2);
                if test(mid) { lo = mid } else { hi = mid - 1 }
            }
            Some(lo)
        } else {
            None
        };
        match (lower, upper) {
            (Some(l), Some(h)) => (l, h),
            (Some(l), None) => (l, kp as usize),
            (None, Some(h)) => (up0, h),
            (None, None) => (1, 0),
        }
    }

    /// Affine distance-vector components of site `idx` at height `z`.
    fn job_coefficients(&self, idx: usize, z: f64) -> ([f64; 3], [f64; 3], f64) {
        let site = &self.sites.sites[idx];
        let d = DVec3::new(self.o.x, self.o.y, z) - site.anchor;
        let row = |w: DVec3| [w.dot(d), w.x * self.h.x, w.y * self.h.y];
        match site.kind {
            SiteKind::Face => (row(site.rows[0]), [0.0; 3], 0.0),
            SiteKind::Edge => {
                let (a, b) = (row(site.rows[0]), row(site.rows[1]));
                // A pixel-varying component first, so the cheaper loop applies more often.
                if a[1] == 0.0 {
                    (b, a, 0.0)
                } else {
                    (a, b, 0.0)
                }
            }
            SiteKind::Vertex => ([d.x, self.h.x, 0.0], [d.y, 0.0, self.h.y], d.z * d.z),
        }
    }

    /// Phase 1 of slice `k` (index `dk` in its block): the jobs of sites `first..`
    /// (with slice ranges `ranges`) whose domains meet it.
    #[inline(never)]
    fn slice_jobs(
        &self,
        k: usize,
        dk: usize,
        first: usize,
        ranges: &[(usize, usize)],
        bounds: &Bounds,
        s: &mut Scratch,
    ) {
        let z = self.grid.slice_z(k);
        let full = [0.0, 0.0, (self.nx - 1) as f64, (self.ny - 1) as f64];
        s.jobs.clear();
        s.hps.clear();
        s.lines.clear();
        s.tile_spans.clear();
        let mut hps = std::mem::take(&mut s.hps);
        let tile_u = self.tiles.as_ref().map(|t| {
            let n = t.xs.len() * t.ys.len();
            (&bounds.u[dk * n..(dk + 1) * n], bounds.umax[dk])
        });
        let band = self.sites.band.unwrap_or(f64::INFINITY);
        for (n, &(k0, k1)) in ranges.iter().enumerate() {
            if k < k0 || k > k1 {
                continue;
            }
            let idx = first + n;
            let site = &self.sites.sites[idx];
            let (lo, hi) = site.bounds;
            let gz = (lo.z - z).max(z - hi.z).max(0.0);
            let mut rect = full;
            // With culling, a site can only win where its box is within the largest
            // tile bound of the slice.
            let reach = tile_u.map_or(f64::INFINITY, |(_, umax)| umax);
            if gz > reach || !self.band_rect(idx, z, &mut rect) {
                continue;
            }
            if reach.is_finite()
                && !self.narrow(&mut rect, lo, hi, (reach * reach - gz * gz).sqrt())
            {
                continue;
            }
            let face = if site.kind == SiteKind::Face {
                self.face_bbox(idx, z)
            } else {
                None
            };
            if let Some((_, ts)) = face {
                // The face's distance on its polygon is |t|, affine: its minimum is at a
                // corner unless the polygon crosses the face's plane.
                let lim = reach.min(band);
                if ts.iter().all(|&t| t > lim) || ts.iter().all(|&t| t < -lim) {
                    continue;
                }
            }
            let bbox = match face {
                Some((bb, _)) => Some(bb),
                None => {
                    if !self.push_halfplanes(idx, z, &mut hps) {
                        hps.clear();
                        continue;
                    }
                    clip_bbox(rect, &hps, &mut s.poly, &mut s.poly2)
                }
            };
            let Some([umin, vmin, umax, vmax]) = bbox else {
                hps.clear();
                continue;
            };
            let mut j0 = fast_ceil(vmin.max(rect[1]));
            let mut j1 = fast_floor(vmax.min(rect[3]));
            let i0 = fast_ceil(umin.max(rect[0]));
            let i1 = fast_floor(umax.min(rect[2]));
            if j0 > j1 || i0 > i1 {
                hps.clear();
                continue;
            }
            let spans0 = s.tile_spans.len();
            let mut tile_spans = None;
            if let (Some(t), Some((u, _))) = (&self.tiles, tile_u) {
                // Lower bound of the site's distance over a tile: the gap between its box
                // and the tile's, and for a face the distance to its plane.
                let (tx0, tx1) = (i0 as usize / t.size, i1 as usize / t.size);
                let (ty0, ty1) = (j0 as usize / t.size, j1 as usize / t.size);
                let plane = (site.kind == SiteKind::Face).then(|| {
                    let n = site.rows[0];
                    (
                        n,
                        n.z * (z - site.anchor.z) - n.x * site.anchor.x - n.y * site.anchor.y,
                    )
                });
                let (mut first_row, mut last_row) = (usize::MAX, 0);
                for ty in ty0..=ty1 {
                    let (y0, y1) = t.ys[ty];
                    let gy = (lo.y - y1).max(y0 - hi.y).max(0.0);
                    let (mut a, mut b) = (usize::MAX, 0);
                    for tx in tx0..=tx1 {
                        let (x0, x1) = t.xs[tx];
                        let gx = (lo.x - x1).max(x0 - hi.x).max(0.0);
                        let mut l2 = gx * gx + gy * gy + gz * gz;
                        if let Some((n, s0)) = plane {
                            let c = s0 + n.x * 0.5 * (x0 + x1) + n.y * 0.5 * (y0 + y1);
                            let e = 0.5 * (n.x.abs() * (x1 - x0) + n.y.abs() * (y1 - y0));
                            let l = (c.abs() - e).max(0.0);
                            l2 = l2.max(l * l);
                        }
                        let ub = u[ty * t.xs.len() + tx];
                        if l2 <= ub * ub {
                            a = a.min(tx);
                            b = tx;
                        }
                    }
                    if a <= b {
                        s.tile_spans
                            .push(((a * t.size) as f64, ((b + 1) * t.size - 1) as f64));
                        first_row = first_row.min(ty);
                        last_row = ty;
                    } else {
                        s.tile_spans.push((1.0, 0.0));
                    }
                }
                if first_row > last_row {
                    hps.clear();
                    s.tile_spans.truncate(spans0);
                    continue;
                }
                j0 = j0.max((first_row * t.size) as i64);
                j1 = j1.min(((last_row + 1) * t.size - 1) as i64);
                tile_spans = Some((spans0 + (j0 as usize / t.size - ty0)) as u32);
            }
            if face.is_some() && !self.push_halfplanes(idx, z, &mut hps) {
                hps.clear();
                s.tile_spans.truncate(spans0);
                continue;
            }
            // Span ends as lines in j: left bounds `i >= u0 + du j`, then right bounds
            // `i <= u0 + du j`; half-planes that do not depend on `i` narrow the rows.
            let lines0 = s.lines.len();
            let mut n_left = 0u32;
            for pass in 0..2 {
                for hp in &hps {
                    if hp.inv_a != 0.0 {
                        if (hp.a < 0.0) == (pass == 0) {
                            s.lines.push((hp.c * hp.inv_a, -hp.b * hp.inv_a));
                            n_left += (pass == 0) as u32;
                        }
                    } else if pass == 0 {
                        // b j <= c.
                        if hp.b > 0.0 {
                            j1 = j1.min(fast_floor((hp.c / hp.b).clamp(-1.0, self.ny as f64)));
                        } else if hp.b < 0.0 {
                            j0 = j0.max(fast_ceil((hp.c / hp.b).clamp(-1.0, self.ny as f64)));
                        } else if hp.c < 0.0 {
                            j1 = -1;
                        }
                    }
                }
            }
            hps.clear();
            // The polygon's columns also bound the spans.
            s.lines.push((i0 as f64, 0.0));
            s.lines.push((i1 as f64, 0.0));
            let nl = s.lines.len();
            s.lines.swap(lines0 + n_left as usize, nl - 2);
            n_left += 1;
            if j0 > j1 {
                s.lines.truncate(lines0);
                s.tile_spans.truncate(spans0);
                continue;
            }
            let (a, b, g) = self.job_coefficients(idx, z);
            s.jobs.push(Job {
                rows: (j0 as usize, j1 as usize),
                lines: (lines0 as u32, s.lines.len() as u32),
                n_left,
                tile_spans,
                a,
                b,
                g,
            });
        }
        s.hps = hps;
    }

    /// Phase 2: scan-converts the jobs into the slice's squared-distance buffer;
    /// returns the number of pixel evaluations.
    #[inline(never)]
    fn slice_raster(&self, s: &Scratch, buf: &mut [f64]) -> u64 {
        let nx = self.nx;
        let band2 = self.sites.band.map(|b| b * b);
        let tile = self.tiles.as_ref().map_or(1, |t| t.size);
        let mut n_eval = 0u64;
        for job in &s.jobs {
            let lines = &s.lines[job.lines.0 as usize..job.lines.1 as usize];
            let (left, right) = lines.split_at(job.n_left as usize);
            for j in job.rows.0..=job.rows.1 {
                let jf = j as f64;
                let (mut lo, mut hi) = match job.tile_spans {
                    Some(t0) => s.tile_spans[t0 as usize + (j / tile - job.rows.0 / tile)],
                    None => (f64::NEG_INFINITY, f64::INFINITY),
                };
                for &(u0, du) in left {
                    lo = lo.max(u0 + du * jf);
                }
                for &(u0, du) in right {
                    hi = hi.min(u0 + du * jf);
                }
                if !(lo <= hi) {
                    continue;
                }
                let a = job.a[0] + job.a[2] * jf;
                let b = job.b[0] + job.b[2] * jf;
                if let Some(b2) = band2 {
                    // |D(i)|^2 = p i^2 + q i + r <= band^2 along the row.
                    let (au, bu) = (job.a[1], job.b[1]);
                    let p = au * au + bu * bu;
                    let q = 2.0 * (a * au + b * bu);
                    let r = a * a + b * b + job.g - b2;
                    if p > 0.0 {
                        let disc = q * q - 4.0 * p * r;
                        if disc < 0.0 {
                            continue;
                        }
                        let sq = disc.sqrt();
                        let t = -0.5 * (q + if q >= 0.0 { sq } else { -sq });
                        let x1 = t / p;
                        let x2 = if t != 0.0 { r / t } else { x1 };
                        let (r1, r2) = (x1.min(x2), x1.max(x2));
                        lo = lo.max(r1 - SPAN_SLACK * (1.0 + r1.abs()));
                        hi = hi.min(r2 + SPAN_SLACK * (1.0 + r2.abs()));
                        if !(lo <= hi) {
                            continue;
                        }
                    } else if r > 0.0 {
                        continue;
                    }
                }
                let (i0, i1) = (fast_ceil(lo), fast_floor(hi));
                if i0 > i1 {
                    continue;
                }
                let (i0, i1) = (i0 as usize, i1 as usize);
                n_eval += (i1 - i0 + 1) as u64;
                let row = &mut buf[j * nx + i0..=j * nx + i1];
                let a = a + job.a[1] * i0 as f64;
                let b = b + job.b[1] * i0 as f64;
                if job.b[1] == 0.0 {
                    span1(row, a, job.a[1], b * b + job.g);
                } else {
                    span2(row, a, job.a[1], b, job.b[1], job.g);
                }
            }
        }
        n_eval
    }
}

/// `floor` for finite values of moderate size (no libm call on baseline x86-64).
#[inline]
fn fast_floor(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x { t - 1 } else { t }
}

/// `ceil` for finite values of moderate size.
#[inline]
fn fast_ceil(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) < x { t + 1 } else { t }
}

/// Clips the rectangle `[u0, v0, u1, v1]` by `hps` (Sutherland-Hodgman); returns the
/// bounding box `[u_min, v_min, u_max, v_max]` of the result, `None` when empty.
fn clip_bbox(
    rect: [f64; 4],
    hps: &[Hp],
    poly: &mut Vec<(f64, f64)>,
    tmp: &mut Vec<(f64, f64)>,
) -> Option<[f64; 4]> {
    let [u0, v0, u1, v1] = rect;
    if !(u0 <= u1 && v0 <= v1) {
        return None;
    }
    poly.clear();
    poly.extend_from_slice(&[(u0, v0), (u1, v0), (u1, v1), (u0, v1)]);
    for hp in hps {
        tmp.clear();
        let f = |p: (f64, f64)| hp.a * p.0 + hp.b * p.1 - hp.c;
        let mut p = poly[poly.len() - 1];
        let mut fp = f(p);
        for &q in poly.iter() {
            let fq = f(q);
            if fp <= 0.0 {
                tmp.push(p);
            }
            if (fp <= 0.0) != (fq <= 0.0) {
                let t = fp / (fp - fq);
                tmp.push((p.0 + t * (q.0 - p.0), p.1 + t * (q.1 - p.1)));
            }
            p = q;
            fp = fq;
        }
        std::mem::swap(poly, tmp);
        if poly.is_empty() {
            return None;
        }
    }
    let mut bb = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for &(u, v) in poly.iter() {
        bb = [bb[0].min(u), bb[1].min(v), bb[2].max(u), bb[3].max(v)];
    }
    Some(bb)
}

/// Computes the field into `out` (length `grid.len()`, C order) from `sites`; `cull`
/// is the primitive set whose nearest queries bound the tiles (no culling if `None`).
pub(crate) fn run(
    sites: &Sites,
    grid: &Grid,
    band: Option<f64>,
    cull: Option<&AnySet>,
    out: &mut [f32],
) -> LinfacRun {
    let t = Instant::now();
    let raster = Raster::new(sites, grid, cull);
    let ranges: Vec<(usize, usize)> = (0..sites.sites.len())
        .into_par_iter()
        .map_init(Scratch::default, |s, idx| raster.slice_range(idx, s))
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

/// `buf[i] = min(buf[i], (a + i da)^2 + c)`: one varying component (faces, vertices).
#[inline]
fn span1(row: &mut [f64], mut a: f64, da: f64, c: f64) {
    for px in row {
        let d2 = a * a + c;
        let old = *px;
        *px = if d2 < old { d2 } else { old };
        a += da;
    }
}

/// `buf[i] = min(buf[i], (a + i da)^2 + (b + i db)^2 + g)`: two varying components
/// (edges).
#[inline]
fn span2(row: &mut [f64], mut a: f64, da: f64, mut b: f64, db: f64, g: f64) {
    for px in row {
        let d2 = a * a + b * b + g;
        let old = *px;
        *px = if d2 < old { d2 } else { old };
        a += da;
        b += db;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clip_square_by_diagonal() {
        let hps = [Hp {
            a: 1.0,
            b: 1.0,
            c: 1.0,
            inv_a: 1.0,
        }];
        let (mut p, mut q) = (Vec::new(), Vec::new());
        let r = clip_bbox([0.0, 0.0, 2.0, 2.0], &hps, &mut p, &mut q).unwrap();
        assert_eq!(r, [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(p.len(), 3);
        let hps = [Hp {
            a: 1.0,
            b: 1.0,
            c: -0.5,
            inv_a: 1.0,
        }];
        assert!(clip_bbox([0.0, 0.0, 2.0, 2.0], &hps, &mut p, &mut q).is_none());
    }
}
