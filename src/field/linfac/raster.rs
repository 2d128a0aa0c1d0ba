//! Phase 2 of a slice: the linear factorization and the scan conversion (SPEC 9, "Key
//! fact (linear factorization)").
//!
//! Inside a site's domain its distance vector is affine in the pixel: with
//! `d = (o_x, o_y, z) - anchor`, every row `w` of the site gives the component
//! `w . d + (w_x hx) i + (w_y hy) j` (one for a face, two for an edge), and a vertex the
//! components `d_x + hx i`, `d_y + hy j` plus the constant `d_z^2`. On row `j` of a job
//! the span is the intersection of its span-end lines (and its tile interval); with a
//! band it is further cut to the interval where `p i^2 + q i + r <= 0`, the squared
//! distance minus `band^2` along the row (roots by the stable quadratic formula, widened
//! by `SPAN_SLACK`). Along the span the components start at their value at the first
//! pixel and advance by a constant increment per pixel; only the squared length is
//! formed and min-ed into the f64 buffer (`span1` for one varying component, `span2`
//! for two).

use super::{Raster, Scratch};
use crate::field::sites::SiteKind;
use glam::DVec3;

/// Band-cut spans are widened by this many pixels (the band test has its own margin;
/// a wider span only costs evaluations).
const SPAN_SLACK: f64 = 1e-6;

impl Raster<'_> {
    /// Affine distance-vector components of site `idx` at height `z`.
    pub(super) fn job_coefficients(&self, idx: usize, z: f64) -> ([f64; 3], [f64; 3], f64) {
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

    /// Phase 2: scan-converts the jobs into the slice's squared-distance buffer;
    /// returns the number of pixel evaluations.
    #[inline(never)]
    pub(super) fn slice_raster(&self, s: &Scratch, buf: &mut [f64]) -> u64 {
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
pub(super) fn fast_floor(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x { t - 1 } else { t }
}

/// `ceil` for finite values of moderate size.
#[inline]
pub(super) fn fast_ceil(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) < x { t + 1 } else { t }
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
