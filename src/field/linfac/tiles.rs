//! Culling bounds: an upper bound of the distance over every tile of a slice (SPEC 9,
//! opening paragraph: a site's polygon need only contain the part of its Voronoi region
//! on the slice, so it may be cut to where the site can be the closest feature).
//!
//! Each slice is split into square tiles of `size` pixels a side (4 to 32, for about
//! `tiles_per_slice` tiles per slice; the layout is built in `Raster::new`). Distance
//! is 1-Lipschitz, so one exact nearest query at a tile's centre `c` bounds it over the
//! whole tile: `U = d(c) + r`, `r` the tile's half diagonal (times `1 + 1e-9`, plus the
//! domain margin `eta`, capped at the band). A site whose box is farther than `U` from a
//! tile is not the closest feature anywhere in it; `jobs` uses the bounds to cut the
//! polygons. Centres are visited in serpentine order and each query is bounded by the
//! previous result plus the distance between the centres (unbounded again when that
//! finds nothing).

use super::{Bounds, Raster};
use crate::eval::nearest::nearest_within;
use crate::field::sites::Sites;
use glam::DVec3;

/// Culling aims at about this many tiles per slice: finer tiles cull more but cost a
/// nearest query each and more tests per polygon. Measured best on the benchmark grids:
/// 64 for triangle sets, 128 for edges, 512 for points (whose whole-slice domains gain
/// the most).
pub(super) fn tiles_per_slice(sites: &Sites) -> usize {
    match (sites.counts.faces, sites.counts.edges) {
        (0, 0) => 512,
        (0, _) => 128,
        _ => 64,
    }
}

impl Raster<'_> {
    /// Fills `b` with the tile bounds of slices `k0 .. k0 + nk`: an exact nearest query
    /// at each tile centre (bounded by the previous tile's result moved by the distance
    /// between the centres), plus the tile's half diagonal, plus slack.
    #[inline(never)]
    pub(super) fn tile_bounds(&self, k0: usize, nk: usize, b: &mut Bounds) {
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
}
