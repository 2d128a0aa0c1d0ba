//! Exact distance fields on uniform grids (SPEC 9: Sud, Govindaraju, Gayle, Manocha
//! 2006, "Interactive 3D Distance Field Computation using Linear Factorization").
//!
//! A [`Grid`] is a box split into `NX x NY x NZ` voxels; the field holds, for each voxel
//! centre `x`, the exact unsigned distance `d(x) = min_i dist(x, p_i)` to the primitives
//! of one kind (points = all vertices, edges = the mesh's segments or else the unique
//! triangle edges, triangles), as f32 in C order with shape `(NZ, NY, NX)`.
//!
//! Methods ([`Method`]):
//! - `Linfac` (SPEC 9, the subject of this module): the set is split into *sites* whose
//!   closest point moves affinely with the query (vertices, segment interiors, triangle
//!   interiors). Inside the region where a site is the closest feature, the distance
//!   vector from the query `p` to it is affine in `p`:
//!   `p - v` (vertex), `(p - a) - ((p - a) . u) u` (segment with unit direction `u`),
//!   `((p - a) . n) n` (triangle with unit normal `n`). Slice by slice (`z = const`, in
//!   parallel), each site's *domain* (a convex polyhedron containing its region: prism,
//!   slab/wedge, polar cone; see [`sites`](self::Domains) for why the tight domains are
//!   safe on any topology) is cut by the slice into a convex polygon, the polygon is
//!   scan-converted over the voxel centres, and along each span the distance vector is
//!   interpolated linearly (its value at the span's start plus a constant increment per
//!   pixel); only its squared length is formed per pixel and min-ed into the slice. The
//!   minimum over sites whose domains cover a voxel is the exact distance, because the
//!   domain of the true closest feature always covers it and every site reports at
//!   least the distance to its own feature (minus a 1e-8 relative robustness margin).
//!   Culling ([`FieldOptions::cull`], without band): per-tile upper bounds of the
//!   distance (one nearest query at each tile centre, plus the tile's half diagonal)
//!   cut each polygon to the tiles its site can win; this never removes the closest
//!   feature, so the result stays exact. The algorithm is in `linfac/`, the domains
//!   in `sites.rs`.
//! - `Bvh`: one exact nearest-primitive query per voxel on the engine's BVH (bounded
//!   by the previous voxel's distance plus the spacing).
//! - `Brute`: every primitive at every voxel (tests, tiny inputs).
//! - `Smooth`: the smooth distance of SPEC 2 (Barnes-Hut, SPEC 6) per voxel.
//!
//! Narrow band ([`FieldOptions::band`]): voxels with `d <= band` hold the exact distance,
//! all others `+inf` (f32 `INFINITY`, also in the `.npy`); every linfac domain is cut to
//! the band (exactly, row by row), and the BVH query is bounded by it.
//!
//! Signed volumes ([`sign::sign_field`], issue 32): the exact distance negated inside
//! the solid (winding number above 1/2), the winding number evaluated only in blocks of
//! voxels where the sign can change.
//!
//! Boxes and chunks: [`FieldPlan`] prepares a field once (sites, BVH) and computes any
//! box of voxels of its grid ([`FieldSource`], `plan.rs`); [`zarr`] writes a volume as a
//! chunked Zarr v3 array one row of chunks at a time, so its memory is that of a row,
//! not of the volume.
//!
//! [`DistanceField::sample`] interpolates trilinearly; [`DistanceField::lower_bound`]
//! gives `d(x) >= d(v) - |x - v|` over the 8 surrounding voxel centres `v`, which a
//! sphere tracer can use to skip empty space (SPEC 7).

// `!(x > 0.0)` is the NaN policy of this module: a NaN takes the rejecting branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod error;
mod grid;
mod linfac;
mod output;
mod plan;
mod reference;
pub mod sign;
mod sites;
mod volume;
pub mod zarr;

pub use error::{FieldError, human_bytes};
pub use grid::{DEFAULT_MARGIN, Grid, MAX_RESOLUTION, MEMORY_CAP, default_memory_limit};
pub use output::PREVIEW_SLICES;
pub use plan::{FieldPlan, FieldSource, VoxelBox};
pub use sites::{Domains, SiteCounts};
pub use volume::DistanceField;

use crate::mesh::Mesh;
use crate::primitives::{PrimitiveError, PrimitiveKind};
use std::time::Instant;

/// How the field is computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// Slice-by-slice linear factorization (SPEC 9).
    Linfac,
    /// One exact nearest query per voxel on the BVH.
    Bvh,
    /// Every primitive at every voxel.
    Brute,
    /// The smooth distance (SPEC 2) per voxel with the Barnes-Hut evaluator.
    Smooth {
        alpha: f64,
        max_alpha: f64,
        beta: f64,
    },
}

impl Method {
    pub fn name(&self) -> &'static str {
        match self {
            Method::Linfac => "linfac",
            Method::Bvh => "bvh",
            Method::Brute => "brute",
            Method::Smooth { .. } => "smooth",
        }
    }
}

/// Options shared by the methods.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldOptions {
    /// Narrow band: exact values where `d <= band`, `+inf` elsewhere. Exact methods only.
    pub band: Option<f64>,
    /// Linfac domains (tight by default).
    pub domains: Domains,
    /// Linfac: cut every polygon to the tiles of the slice it can win, using per-tile
    /// upper bounds from exact nearest queries at tile centres (default on; ignored with
    /// a band, which already bounds every domain).
    pub cull: bool,
    /// Memory limit in bytes (default: half the physical memory, at most 8 GiB).
    pub memory_limit: Option<u64>,
}

impl Default for FieldOptions {
    fn default() -> Self {
        FieldOptions {
            band: None,
            domains: Domains::Tight,
            cull: true,
            memory_limit: None,
        }
    }
}

/// What a computation cost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FieldStats {
    pub method: &'static str,
    pub voxels: usize,
    /// Wall seconds, everything included.
    pub seconds: f64,
    /// Building the sites (and, with culling, the BVH) for linfac, or the primitive set
    /// and its BVH for the other methods.
    pub setup_seconds: f64,
    /// Linfac: per-site slice ranges plus the per-slice domain clipping (the slice loop's
    /// wall time split in proportion to the thread-summed time of its two phases).
    pub domain_seconds: f64,
    /// Linfac: scan conversion, distance evaluation and output; other methods: the
    /// per-voxel loop.
    pub raster_seconds: f64,
    pub voxels_per_second: f64,
    /// Linfac sites (vertices + edges + faces) or primitives.
    pub sites: usize,
    /// Linfac sites by kind (zero for other methods).
    pub site_counts: SiteCounts,
    /// Distance evaluations: pixels rasterized (linfac) or voxels queried.
    pub evaluations: u64,
    /// Linfac: (site, slice) pairs rasterized (non-empty polygon, not culled).
    pub polygons: u64,
    /// Linfac: (site, slice) pairs within the sites' slice ranges, i.e. domain
    /// computations.
    pub candidates: u64,
}

impl FieldStats {
    /// Fraction of the computing time spent on domains (linfac).
    pub fn domain_share(&self) -> f64 {
        let t = self.domain_seconds + self.raster_seconds;
        if t > 0.0 {
            self.domain_seconds / t
        } else {
            0.0
        }
    }

    /// Average number of sites evaluated per voxel (linfac) or 1.
    pub fn evaluations_per_voxel(&self) -> f64 {
        self.evaluations as f64 / self.voxels.max(1) as f64
    }
}

/// Computes the distance field of the `kind` primitives of `mesh` on `grid`.
///
/// Validates the options (band > 0, smooth parameters), refuses grids above the memory
/// limit, and fails like [`crate::primitives::AnySet::build`] when the mesh lacks the requested simplices.
/// The same as a [`FieldPlan`] computing the grid's whole box.
pub fn compute(
    mesh: &Mesh,
    kind: PrimitiveKind,
    grid: &Grid,
    method: Method,
    options: &FieldOptions,
) -> Result<(DistanceField, FieldStats), FieldError> {
    let t_all = Instant::now();
    validate(method, options)?;
    // Re-validate in case the grid was built by hand.
    let grid = Grid::new(grid.min, grid.max, grid.res)?;
    grid.check_memory(options.memory_limit, setup_bytes(mesh))?;
    let plan = FieldPlan::new(mesh, kind, &grid, method, options)?;
    let mut values = vec![0.0f32; grid.len()];
    let mut stats = plan.compute_box(&VoxelBox::whole(&grid), &mut values);
    stats.setup_seconds = plan.setup_seconds();
    stats.seconds = t_all.elapsed().as_secs_f64();
    stats.voxels_per_second = grid.len() as f64 / stats.seconds.max(1e-12);
    Ok((
        DistanceField {
            grid,
            values,
            band: options.band,
        },
        stats,
    ))
}

/// Memory of the sites (linfac) or primitives and BVH (the others): a few hundred bytes
/// per simplex.
pub fn setup_bytes(mesh: &Mesh) -> u64 {
    let simplices = mesh.vertices.len() + mesh.segments.len() + 3 * mesh.triangles.len();
    256 * simplices as u64
}

/// Refuses a band that is not a positive finite distance and bad smooth parameters.
pub(crate) fn validate(method: Method, options: &FieldOptions) -> Result<(), FieldError> {
    if let Some(b) = options.band
        && !(b > 0.0 && b.is_finite())
    {
        return Err(FieldError::BadBand(b));
    }
    if let Method::Smooth {
        alpha,
        max_alpha,
        beta,
    } = method
    {
        if let Some(problem) = crate::limits::alpha_problem(alpha) {
            return Err(FieldError::BadSmoothParameters(format!("alpha {problem}")));
        }
        if let Some(problem) = crate::limits::alpha_problem(max_alpha) {
            return Err(FieldError::BadSmoothParameters(format!(
                "max_alpha {problem}"
            )));
        }
        if !(0.0..=1.0).contains(&beta) {
            return Err(FieldError::BadSmoothParameters(format!(
                "beta must be in [0, 1] (got {beta})"
            )));
        }
        if options.band.is_some() {
            return Err(FieldError::BadSmoothParameters(
                "a band applies to exact distances only; drop the band or the smooth method".into(),
            ));
        }
    }
    Ok(())
}

/// The same refusals as [`crate::primitives::AnySet::build`], without building the set.
fn check_kind(mesh: &Mesh, kind: PrimitiveKind) -> Result<(), PrimitiveError> {
    let reason = if mesh.vertices.is_empty() {
        Some("the mesh has no vertices")
    } else {
        match kind {
            PrimitiveKind::Points => None,
            PrimitiveKind::Edges if mesh.segments.is_empty() && mesh.triangles.is_empty() => {
                Some("it has no edges (no `l` segments and no faces); use points")
            }
            PrimitiveKind::Triangles if mesh.triangles.is_empty() => {
                Some("it has no faces; use points or edges")
            }
            _ => None,
        }
    };
    match reason {
        Some(r) => Err(PrimitiveError {
            mesh: mesh.name.clone(),
            kind,
            reason: r.to_string(),
        }),
        None => Ok(()),
    }
}

/// Scales of the computation: an upper bound of every distance between a voxel centre
/// and a mesh point, and the largest coordinate magnitude. The linfac robustness margin
/// is relative to the first (domain directions err by up to 1e-9 rad on nearly
/// degenerate triangles) plus a tiny multiple of the second (rounding of coordinates).
fn scene_scales(mesh: &Mesh, grid: &Grid) -> (f64, f64) {
    let b = mesh.bounds();
    let (mmin, mmax) = if b.is_empty() {
        (glam::DVec3::ZERO, glam::DVec3::ZERO)
    } else {
        (b.min.as_dvec3(), b.max.as_dvec3())
    };
    let reach = (0.5 * (grid.min + grid.max) - 0.5 * (mmin + mmax)).length()
        + 0.5 * (grid.diagonal() + (mmax - mmin).length());
    let mag = grid
        .min
        .abs()
        .max(grid.max.abs())
        .max(mmin.abs())
        .max(mmax.abs())
        .length();
    (reach, mag)
}
