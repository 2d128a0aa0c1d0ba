//! Slice-by-slice rasterization with linear factorization (SPEC 9).
//!
//! For slice `k` (plane `z = z_k`) a pixel `(i, j)` is the voxel centre
//! `o + (i hx, j hy, 0)` with `o = min + h / 2` at height `z_k`. Every 3D half-space
//! `n . p <= c` of a site's domain becomes the 2D half-plane
//! `(n_x hx) i + (n_y hy) j <= c - n . o`, and every row of the site's distance vector
//! `w . (p - anchor)` the affine function `w . (o - anchor) + (w_x hx) i + (w_y hy) j`.
//!
//! Per slice (slices in parallel):
//! 1. domains: for each site whose slice range contains `k`, the half-planes of its
//!    domain on the slice, clipped against the rectangle of pixel centres
//!    (Sutherland-Hodgman) to get the rows it covers or to reject it;
//! 2. rasterization: for each row, the span is the intersection of the half-planes with
//!    the row (exact scan conversion of a convex polygon, no accumulation across rows);
//!    along the span the distance-vector components start at their value at the left
//!    end and are advanced by one constant increment per pixel (the linear
//!    factorization); per pixel only the squared length `a^2 + b^2 (+ c)` is formed and
//!    min-ed into an f64 buffer of squared distances;
//! 3. the slice is written out as `sqrt` in f32 (`+inf` beyond the band).
//!
//! A site's slice range comes from convexity: its domain is convex and contains its
//! witness point, so the slices meeting it form an interval found by two binary
//! searches on "the clipped polygon is non-empty" (on the grid box, slightly enlarged).
//! With the f64 accumulation the interpolated components drift by at most `NX` ulps,
//! far below the 1e-5 tolerance.

use super::grid::Grid;
use super::sites::{SiteKind, Sites};
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
    /// Thread-summed seconds in domain clipping and in rasterization within the loop.
    pub domain_cpu: f64,
    pub raster_cpu: f64,
    /// Pixel evaluations (sum of span lengths).
    pub evaluations: u64,
    /// Site-slice pairs that produced a non-empty polygon.
    pub polygons: u64,
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

/// A site's work on one slice.
#[derive(Clone, Copy, Debug)]
struct Job {
    rows: (usize, usize),
    /// Range of the span-end lines in `Scratch::lines`, the first `n_left` bounding
    /// from the left.
    lines: (u32, u32),
    n_left: u32,
    /// Distance-vector components: `a(i, j) = a0 + au i + av j`, likewise `b`; `g` is a
    /// constant added to the squared length.
    a: [f64; 3],
    b: [f64; 3],
    g: f64,
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
}

impl<'a> Raster<'a> {
    fn new(sites: &'a Sites, grid: &'a Grid) -> Raster<'a> {
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
        Raster {
            sites,
            grid,
            planes,
            o,
            h,
            nx: grid.res[0],
            ny: grid.res[1],
        }
    }

    /// Pushes the half-planes of site `idx` at height `z` and narrows `rect` to its band
    /// box. Returns false when the domain misses the slice.
    fn site_halfplanes(&self, idx: usize, z: f64, rect: &mut [f64; 4], out: &mut Vec<Hp>) -> bool {
        let site = &self.sites.sites[idx];
        if let Some(band) = self.sites.band {
            let (lo, hi) = site.bounds;
            let (mut rx, mut ry) = (band, band);
            if site.kind == SiteKind::Vertex {
                let dz = z - site.anchor.z;
                let r2 = band * band - dz * dz;
                if r2 < 0.0 {
                    return false;
                }
                rx = r2.sqrt();
                ry = rx;
            } else if z < lo.z - band || z > hi.z + band {
                return false;
            }
            rect[0] = rect[0].max((lo.x - rx - self.o.x) / self.h.x);
            rect[2] = rect[2].min((hi.x + rx - self.o.x) / self.h.x);
            rect[1] = rect[1].max((lo.y - ry - self.o.y) / self.h.y);
            rect[3] = rect[3].min((hi.y + ry - self.o.y) / self.h.y);
            if !(rect[0] <= rect[2] && rect[1] <= rect[3]) {
                return false;
            }
        }
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

    /// Whether the domain of site `idx` meets slice `k` inside the grid box (enlarged
    /// by half a voxel so the witness is strictly inside).
    fn meets_slice(&self, idx: usize, k: usize, s: &mut Scratch) -> bool {
        let mut rect = [-1.0, -1.0, self.nx as f64, self.ny as f64];
        s.hps.clear();
        let mut hps = std::mem::take(&mut s.hps);
        let ok = self.site_halfplanes(idx, self.grid.slice_z(k), &mut rect, &mut hps)
            && clip(rect, &hps, &mut s.poly, &mut s.poly2).is_some();
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

    /// Phase 1 of slice `k`: the jobs (rows, half-planes, coefficients) of the sites
    /// `first..` (with slice ranges `ranges`) whose domains meet it.
    fn slice_jobs(&self, k: usize, first: usize, ranges: &[(usize, usize)], s: &mut Scratch) {
        let z = self.grid.slice_z(k);
        let full = [0.0, 0.0, (self.nx - 1) as f64, (self.ny - 1) as f64];
        s.jobs.clear();
        s.hps.clear();
        s.lines.clear();
        let mut hps = std::mem::take(&mut s.hps);
        for (n, &(k0, k1)) in ranges.iter().enumerate() {
            if k < k0 || k > k1 {
                continue;
            }
            let idx = first + n;
            let first = hps.len();
            let mut rect = full;
            if !self.site_halfplanes(idx, z, &mut rect, &mut hps) {
                hps.truncate(first);
                continue;
            }
            let own = &hps[first..];
            let vrange = if self.sites.sites[idx].kind == SiteKind::Face {
                prism_rows(own, &rect).unwrap_or_else(|| clip(rect, own, &mut s.poly, &mut s.poly2))
            } else {
                clip(rect, own, &mut s.poly, &mut s.poly2)
            };
            let Some((vmin, vmax)) = vrange else {
                hps.truncate(first);
                continue;
            };
            let mut j0 = fast_ceil(vmin.max(rect[1]).max(0.0));
            let mut j1 = fast_floor(vmax.min(rect[3]).min((self.ny - 1) as f64));
            // Span ends as lines in j: left bounds `i >= u0 + du j`, then right bounds
            // `i <= u0 + du j`; half-planes that do not depend on `i` narrow the rows.
            let lines0 = s.lines.len();
            let mut n_left = 0u32;
            for pass in 0..2 {
                for hp in &hps[first..] {
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
            hps.truncate(first);
            if j0 > j1 {
                s.lines.truncate(lines0);
                continue;
            }
            let (a, b, g) = self.job_coefficients(idx, z);
            s.jobs.push(Job {
                rows: (j0 as usize, j1 as usize),
                lines: (lines0 as u32, s.lines.len() as u32),
                n_left,
                a,
                b,
                g,
            });
        }
        s.hps = hps;
    }

    /// Phase 2: scan-converts the jobs into the slice's squared-distance buffer;
    /// returns the number of pixel evaluations.
    fn slice_raster(&self, s: &Scratch, buf: &mut [f64]) -> u64 {
        let nx = self.nx;
        let umax = (nx - 1) as f64;
        let band2 = self.sites.band.map(|b| b * b);
        let mut n_eval = 0u64;
        for job in &s.jobs {
            let lines = &s.lines[job.lines.0 as usize..job.lines.1 as usize];
            let (left, right) = lines.split_at(job.n_left as usize);
            for j in job.rows.0..=job.rows.1 {
                let jf = j as f64;
                let mut lo = 0.0f64;
                for &(u0, du) in left {
                    lo = lo.max(u0 + du * jf);
                }
                let mut hi = umax;
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

#[derive(Default)]
struct Scratch {
    hps: Vec<Hp>,
    lines: Vec<(f64, f64)>,
    jobs: Vec<Job>,
    poly: Vec<(f64, f64)>,
    poly2: Vec<(f64, f64)>,
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

/// Row range of the triangle cut from a face's prism by the slice: its three corners are
/// the pairwise intersections of the first three half-planes. `Some(None)` when the
/// triangle misses the rectangle; `None` when two of the planes are (nearly) parallel
/// (prism nearly parallel to the slice), and the caller clips instead.
fn prism_rows(h: &[Hp], rect: &[f64; 4]) -> Option<Option<(f64, f64)>> {
    let (mut umin, mut umax, mut vmin, mut vmax) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for (p, q) in [(h[0], h[1]), (h[1], h[2]), (h[2], h[0])] {
        let det = p.a * q.b - q.a * p.b;
        let scale = (p.a.abs() + p.b.abs()) * (q.a.abs() + q.b.abs());
        if !(det.abs() > 1e-9 * scale) {
            return None;
        }
        let u = (p.c * q.b - q.c * p.b) / det;
        let v = (p.a * q.c - q.a * p.c) / det;
        umin = umin.min(u);
        umax = umax.max(u);
        vmin = vmin.min(v);
        vmax = vmax.max(v);
    }
    if umax < rect[0] || umin > rect[2] || vmax < rect[1] || vmin > rect[3] {
        return Some(None);
    }
    Some(Some((vmin, vmax)))
}

/// Clips the rectangle `[u0, u1] x [v0, v1]` by `hps`; returns the row range
/// `(v_min, v_max)` of the result, `None` when empty.
fn clip(
    rect: [f64; 4],
    hps: &[Hp],
    poly: &mut Vec<(f64, f64)>,
    tmp: &mut Vec<(f64, f64)>,
) -> Option<(f64, f64)> {
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
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &(_, v) in poly.iter() {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    Some((lo, hi))
}

/// Sites are processed in chunks of this many, so that a chunk's data stays in cache
/// while it is rasterized into every slice of a block.
const SITE_CHUNK: usize = 256;

/// Slice buffers of one block should fit in about this many bytes (a core's L2).
const BLOCK_BYTES: usize = 768 << 10;

/// Computes the field into `out` (length `grid.len()`, C order) from `sites`.
///
/// Slices are grouped into blocks of consecutive slices (in parallel); within a block
/// the sites are taken in chunks, and each chunk is turned into polygons and
/// rasterized slice by slice, so site data and slice buffers stay in cache.
pub(crate) fn run(sites: &Sites, grid: &Grid, band: Option<f64>, out: &mut [f32]) -> LinfacRun {
    let t = Instant::now();
    let raster = Raster::new(sites, grid);
    let ranges: Vec<(usize, usize)> = (0..sites.sites.len())
        .into_par_iter()
        .map_init(Scratch::default, |s, idx| raster.slice_range(idx, s))
        .collect();
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
            || (Scratch::default(), Vec::new()),
            |(s, buf), (b, out_block)| {
                let k_first = b * block;
                let nk = out_block.len() / slice_len;
                buf.clear();
                buf.resize(nk * slice_len, f64::INFINITY);
                let (mut dom, mut ras, mut n_eval, mut n_poly) = (0u64, 0u64, 0u64, 0u64);
                for (c, (chunk, &(c0, c1))) in
                    ranges.chunks(SITE_CHUNK).zip(&chunk_ranges).enumerate()
                {
                    for dk in 0..nk {
                        let k = k_first + dk;
                        if k < c0 || k > c1 {
                            continue;
                        }
                        let t0 = Instant::now();
                        raster.slice_jobs(k, c * SITE_CHUNK, chunk, s);
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
        let r = clip([0.0, 0.0, 2.0, 2.0], &hps, &mut p, &mut q).unwrap();
        assert_eq!(r, (0.0, 1.0));
        assert_eq!(p.len(), 3);
        let hps = [Hp {
            a: 1.0,
            b: 1.0,
            c: -0.5,
            inv_a: 1.0,
        }];
        assert!(clip([0.0, 0.0, 2.0, 2.0], &hps, &mut p, &mut q).is_none());
    }
}
