//! A field prepared once and computed box by box: the unit of chunked volumes (issue 33).
//!
//! A [`VoxelBox`] is a block of voxels `start .. start + size` of a grid. Its values are
//! those of the *sub-grid* over the box ([`Grid::sub_grid`]): the same voxel centres (up
//! to rounding of `min + i h`), so every method computes a box exactly as it computes a
//! whole grid, and a volume assembled from boxes equals the whole computation to within
//! rounding (linfac's spans start at other pixels, so its f64 interpolation differs by a
//! few ulps; the per-voxel methods evaluate the same points).
//!
//! [`FieldPlan::new`] does the work that does not depend on the box once: linfac's sites
//! (with the robustness margin of the *whole* grid's scales, SPEC 9 "Robustness") and its
//! culling BVH, or the primitive set and BVH of the other methods. [`FieldSource`] is the
//! interface the chunk writer (`field::zarr`) and the Python bindings call: any field
//! kind that can fill a box (the exact, smooth, and later signed distances) plugs in.
//!
//! Chunk-level culling (linfac on a box smaller than the grid): the box is split into up
//! to 4 x 4 x 4 parts; distance is 1-Lipschitz, so one exact nearest query at a part's
//! centre `c` bounds the distance over it by `U = d(c) + r` (`r` its half diagonal, plus
//! the domain margin). A site whose feature's bounding box is farther than `U` from every
//! part is not the closest feature of any voxel of the box and is left out before its
//! slice range is searched. This is the per-tile culling of `linfac/tiles.rs` one level
//! up: it keeps the result exact, and it keeps the per-box setup (the slice-range search
//! of every site) proportional to the sites near the box instead of all of them.

use super::grid::Grid;
use super::sites::{self, Sites};
use super::{FieldError, FieldOptions, FieldStats, Method, check_kind, linfac, reference};
use super::{scene_scales, validate};
use crate::eval::EvalParams;
use crate::eval::nearest::nearest_within;
use crate::mesh::Mesh;
use crate::primitives::{AnySet, PrimitiveKind};
use glam::DVec3;
use rayon::prelude::*;
use std::time::Instant;

/// A box of voxels of a grid: `start .. start + size` along x, y, z (as [`Grid::res`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VoxelBox {
    pub start: [usize; 3],
    pub size: [usize; 3],
}

impl VoxelBox {
    /// The whole grid.
    pub fn whole(grid: &Grid) -> VoxelBox {
        VoxelBox {
            start: [0; 3],
            size: grid.res,
        }
    }

    /// Number of voxels.
    pub fn len(&self) -> usize {
        self.size.iter().product()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether the box is non-empty and lies inside `grid`.
    pub fn fits(&self, grid: &Grid) -> bool {
        (0..3).all(|a| {
            self.size[a] > 0
                && self.start[a]
                    .checked_add(self.size[a])
                    .is_some_and(|e| e <= grid.res[a])
        })
    }
}

impl Grid {
    /// The grid of the voxels of box `b` (which must fit): bounds `min + start h ..
    /// min + (start + size) h`, resolution `size`, so its voxel centres are the box's
    /// (up to rounding); a side on the grid's boundary keeps the grid's bound exactly.
    pub fn sub_grid(&self, b: &VoxelBox) -> Grid {
        debug_assert!(b.fits(self), "{b:?} outside {:?}", self.res);
        let at = |a: usize, i: usize| {
            if i == 0 {
                self.min[a]
            } else if i == self.res[a] {
                self.max[a]
            } else {
                self.min[a] + (self.max[a] - self.min[a]) * (i as f64 / self.res[a] as f64)
            }
        };
        let corner = |f: &dyn Fn(usize) -> usize| DVec3::new(at(0, f(0)), at(1, f(1)), at(2, f(2)));
        Grid {
            min: corner(&|a| b.start[a]),
            max: corner(&|a| b.start[a] + b.size[a]),
            res: b.size,
        }
    }
}

/// Something that computes the values of any box of its grid, the unit of work of
/// chunked volumes (one call per chunk) and of `smoothtrace.dask` (one per block).
pub trait FieldSource: Sync {
    /// The whole grid.
    fn grid(&self) -> &Grid;
    /// Fills `out` (length `b.len()`, C order with shape `(size_z, size_y, size_x)`)
    /// with the values of box `b`, which fits the grid. Returns what it cost.
    fn compute_box(&self, b: &VoxelBox, out: &mut [f32]) -> FieldStats;
}

/// What each method keeps between boxes.
enum Prepared {
    Linfac {
        sites: Sites,
        /// Culling set (nearest queries for the tile and box bounds).
        cull: Option<AnySet>,
        /// The band as linfac uses it (dropped when it exceeds every distance).
        band: Option<f64>,
    },
    Set(AnySet),
}

/// An exact or smooth distance field of a mesh on a grid, prepared for computing boxes.
pub struct FieldPlan {
    grid: Grid,
    method: Method,
    band: Option<f64>,
    prepared: Prepared,
    setup_seconds: f64,
}

impl FieldPlan {
    /// Validates the options like [`super::compute`] and builds what every box needs.
    /// No memory check: a box's memory is the caller's (see [`Grid::check_memory`]).
    pub fn new(
        mesh: &Mesh,
        kind: PrimitiveKind,
        grid: &Grid,
        method: Method,
        options: &FieldOptions,
    ) -> Result<FieldPlan, FieldError> {
        validate(method, options)?;
        let grid = Grid::new(grid.min, grid.max, grid.res)?;
        let t = Instant::now();
        let prepared = match method {
            Method::Linfac => {
                check_kind(mesh, kind)?;
                let (reach, mag) = scene_scales(mesh, &grid);
                let eta = 1e-8 * reach + 1e-12 * mag;
                // No distance in the computation exceeds `reach`: a larger band changes
                // nothing (and its square could overflow).
                let band = options.band.filter(|&b| b <= 2.0 * reach);
                let sites = sites::build_sites(mesh, kind, options.domains, band, eta);
                // With a band every domain is already bounded by it; culling then costs
                // more than it saves (measured), so it only runs without a band.
                let cull = if options.cull && band.is_none() {
                    Some(AnySet::build(mesh, kind)?)
                } else {
                    None
                };
                Prepared::Linfac { sites, cull, band }
            }
            _ => Prepared::Set(AnySet::build(mesh, kind)?),
        };
        Ok(FieldPlan {
            grid,
            method,
            band: options.band,
            prepared,
            setup_seconds: t.elapsed().as_secs_f64(),
        })
    }

    /// Seconds spent building the sites or the primitive set and BVH.
    pub fn setup_seconds(&self) -> f64 {
        self.setup_seconds
    }

    pub fn method(&self) -> Method {
        self.method
    }

    /// The narrow band, if any (exact methods).
    pub fn band(&self) -> Option<f64> {
        self.band
    }
}

impl FieldSource for FieldPlan {
    fn grid(&self) -> &Grid {
        &self.grid
    }

    fn compute_box(&self, b: &VoxelBox, out: &mut [f32]) -> FieldStats {
        assert!(
            b.fits(&self.grid),
            "box {b:?} outside the grid {:?}",
            self.grid.res
        );
        assert_eq!(out.len(), b.len(), "output length of box {b:?}");
        let t = Instant::now();
        let sub = self.grid.sub_grid(b);
        let mut stats = FieldStats {
            method: self.method.name(),
            voxels: b.len(),
            ..FieldStats::default()
        };
        match &self.prepared {
            Prepared::Linfac { sites, cull, band } => {
                let whole = *b == VoxelBox::whole(&self.grid);
                let active = match cull {
                    Some(set) if !whole => Some(near_sites(sites, set, &sub)),
                    _ => None,
                };
                let run = linfac::run(sites, &sub, *band, cull.as_ref(), active.as_deref(), out);
                let cpu = run.domain_cpu + run.raster_cpu;
                let share = if cpu > 0.0 { run.domain_cpu / cpu } else { 0.0 };
                stats.domain_seconds = run.range_seconds + run.slice_seconds * share;
                stats.raster_seconds = run.slice_seconds * (1.0 - share);
                stats.sites = sites.counts.total();
                stats.site_counts = sites.counts;
                stats.evaluations = run.evaluations;
                stats.polygons = run.polygons;
                stats.candidates = run.candidates;
            }
            Prepared::Set(set) => {
                stats.sites = set.len();
                match self.method {
                    Method::Bvh => reference::bvh(set, &sub, self.band, out),
                    Method::Brute => reference::brute(set, &sub, self.band, out),
                    Method::Smooth {
                        alpha,
                        max_alpha,
                        beta,
                    } => {
                        reference::smooth(set, &sub, &EvalParams::new(alpha, max_alpha, beta), out)
                    }
                    Method::Linfac => unreachable!("linfac is prepared as sites"),
                }
                stats.raster_seconds = t.elapsed().as_secs_f64();
                stats.evaluations = b.len() as u64;
            }
        }
        stats.seconds = t.elapsed().as_secs_f64();
        stats.voxels_per_second = b.len() as f64 / stats.seconds.max(1e-12);
        stats
    }
}

/// Parts per axis of the chunk-level culling (module docs).
const PARTS: usize = 4;

/// Which sites can be the closest feature of some voxel of `sub` (module docs).
fn near_sites(sites: &Sites, set: &AnySet, sub: &Grid) -> Vec<bool> {
    let h = sub.spacing();
    let mut parts: Vec<(DVec3, DVec3, f64)> = Vec::new();
    let splits = |n: usize| -> Vec<(usize, usize)> {
        let p = PARTS.min(n);
        (0..p).map(|t| (t * n / p, (t + 1) * n / p - 1)).collect()
    };
    let (sx, sy, sz) = (splits(sub.res[0]), splits(sub.res[1]), splits(sub.res[2]));
    let band = sites.band.unwrap_or(f64::INFINITY);
    for &(k0, k1) in &sz {
        for &(j0, j1) in &sy {
            for &(i0, i1) in &sx {
                let lo = sub.min + (DVec3::new(i0 as f64, j0 as f64, k0 as f64) + 0.5) * h;
                let hi = sub.min + (DVec3::new(i1 as f64, j1 as f64, k1 as f64) + 0.5) * h;
                let c = 0.5 * (lo + hi);
                let d = nearest_within(&[set], c, f64::INFINITY).d;
                let u = ((d + 0.5 * (hi - lo).length()) * (1.0 + 1e-9) + sites.eta).min(band);
                parts.push((lo, hi, u * u));
            }
        }
    }
    sites
        .sites
        .par_iter()
        .map(|s| {
            let (slo, shi) = s.bounds;
            parts.iter().any(|&(lo, hi, u2)| {
                let gap = (lo - shi).max(slo - hi).max(DVec3::ZERO);
                gap.length_squared() <= u2
            })
        })
        .collect()
}
