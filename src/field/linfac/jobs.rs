//! Phase 1 of a slice: the sites of a chunk turned into rasterization jobs (SPEC 9,
//! opening paragraph, one convex polygon per site and slice, and "Domains").
//!
//! For each site whose slice range contains the slice, the pixel rectangle is cut to the
//! site's band box and, with culling, to its box grown by `sqrt(umax^2 - gz^2)` (`umax`
//! the slice's largest tile bound, `gz` the z gap between the slice and the box). A face
//! whose cross-section corners all lie farther than `min(umax, band)` on the same side of
//! its plane is skipped (its distance `|t|` is affine on the triangle). The polygon's
//! bounding box (direct for a face, clipped otherwise) gives its rows and columns. With
//! culling each tile row keeps the column interval of the tiles where a lower bound of
//! the site's distance (the gap between the boxes, and for a face the distance to its
//! plane over the tile) is within the tile's bound `U`. A half-plane `a i + b j <= c`
//! that depends on `i` (see `FLAT`) becomes a span end `i >= u0 + du j` (`a < 0`, left)
//! or `i <= u0 + du j` (`a > 0`, right) with `u0 = c / a`, `du = -b / a`, exact on every
//! row; the others bound the rows. The job takes the site's affine distance-vector
//! coefficients (`raster`).

use super::domain::clip_bbox;
use super::raster::{fast_ceil, fast_floor};
use super::{Bounds, Job, Raster, Scratch};
use crate::field::sites::SiteKind;

impl Raster<'_> {
    /// Phase 1 of slice `k` (index `dk` in its block): the jobs of sites `first..`
    /// (with slice ranges `ranges`) whose domains meet it.
    #[inline(never)]
    pub(super) fn slice_jobs(
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
}
