//! Signs for a distance volume (issue 32): the exact distance stays as computed, and
//! voxels inside the solid (fast winding number above 1/2, [`crate::winding`]) are
//! negated. The winding number is evaluated only where the sign can change.
//!
//! The grid is cut into blocks of voxels (an octree over index ranges, 16^3 at the top).
//! A block is one ball's worth of empty space when the distance `d` at its middle voxel
//! exceeds the block's radius `r` about that voxel (the farthest of its corner voxel
//! centres): the ball of radius `d` holds no triangle and contains every voxel centre of
//! the block. There the winding number is harmonic, and by the boundary-curve bound
//! ([`crate::winding::boundary`]) it moves by at most `r G` with `G = L / (4 pi (d_b -
//! r)^2)` (`L` the boundary length, `d_b` the distance to the boundary curve); on a closed
//! mesh `G = 0` and it is constant. So one evaluation `w` at the middle voxel signs the
//! whole block when `|w - 1/2| > r G + m`, where `w` is taken at the coarse accuracy
//! [`batch::SIGN_BETA`] and `m` = [`batch::SIGN_MARGIN`] is ten times its largest
//! measured error. Otherwise the block is split in eight, down to single voxels, which
//! are evaluated in one batch ([`batch::sign_winding_numbers`]: coarse, then at `beta`
//! where the coarse value is within the margin of 1/2), as `signed_distance` does. Blocks far from the surface
//! take one evaluation each; only voxels within about a voxel of the surface (and, on
//! open meshes, near where `w` crosses 1/2) take their own.
//!
//! Voxels outside a narrow band (`+inf`) count as at least `band` from the surface and
//! become `-inf` inside.

use super::plan::{FieldPlan, FieldSource, VoxelBox};
use super::volume::DistanceField;
use super::{FieldError, FieldStats, Method, grid::Grid};
use crate::mesh::Mesh;
use crate::winding::{Solid, batch, boundary::Boundary, sign};
use glam::DVec3;
use rayon::prelude::*;
use std::time::Instant;

/// Edge of the top blocks, voxels.
const TOP: usize = 16;

/// What signing a volume cost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SignStats {
    /// Winding-number evaluations: blocks and single voxels.
    pub block_evaluations: u64,
    pub voxel_evaluations: u64,
    /// Voxels negated (inside).
    pub inside: u64,
    /// Boundary edges of the soup (0: closed).
    pub boundary_edges: usize,
    /// Building the far fields and the boundary, seconds.
    pub setup_seconds: f64,
    /// Everything, seconds.
    pub seconds: f64,
}

/// A range of voxel indices per axis, `lo..hi`.
#[derive(Clone, Copy, Debug)]
struct Block {
    lo: [usize; 3],
    hi: [usize; 3],
}

/// The far fields and the boundary of a triangle soup, built once and used to sign any
/// number of volumes or boxes of one.
pub struct Signer {
    solid: Solid,
    boundary: Boundary,
    setup_seconds: f64,
}

impl Signer {
    /// The signer of `mesh`'s triangles with the far-field parameter `beta`.
    pub fn new(mesh: &Mesh, beta: f64) -> Result<Signer, FieldError> {
        let t = Instant::now();
        let solid = Solid::from_mesh(mesh, beta)?;
        let boundary = Boundary::of(mesh);
        Ok(Signer {
            solid,
            boundary,
            setup_seconds: t.elapsed().as_secs_f64(),
        })
    }

    /// Seconds spent building the far fields and the boundary.
    pub fn setup_seconds(&self) -> f64 {
        self.setup_seconds
    }

    /// Negates the values (exact unsigned distances on `grid`, C order, `+inf` beyond
    /// `band`) that lie inside the solid. `setup_seconds` is left at 0.
    pub fn sign(&self, grid: &Grid, values: &mut [f32], band: Option<f64>) -> SignStats {
        let t_all = Instant::now();
        let (solid, boundary) = (&self.solid, &self.boundary);
        let mut stats = SignStats {
            boundary_edges: boundary.edges,
            ..SignStats::default()
        };
        let tops = top_blocks(grid);
        let view = Values {
            grid,
            values: &*values,
            band,
        };
        let results: Vec<Outcome> = tops
            .par_iter()
            .map_init(Vec::new, |stack, &b| {
                let mut out = Outcome::default();
                split(&view, solid, boundary, b, stack, &mut out);
                out
            })
            .collect();
        let mut leaves = Vec::new();
        for r in &results {
            stats.block_evaluations += r.evaluations;
            for &(b, inside) in &r.filled {
                if inside {
                    for k in b.lo[2]..b.hi[2] {
                        for j in b.lo[1]..b.hi[1] {
                            let row = grid.index(0, j, k);
                            for v in &mut values[row + b.lo[0]..row + b.hi[0]] {
                                *v = -*v;
                            }
                            stats.inside += (b.hi[0] - b.lo[0]) as u64;
                        }
                    }
                }
            }
            leaves.extend_from_slice(&r.leaves);
        }
        let centres: Vec<DVec3> = leaves
            .par_iter()
            .map(|&[i, j, k]| grid.voxel_center(i as usize, j as usize, k as usize))
            .collect();
        let w = batch::sign_winding_numbers(solid.tree(), solid.triangles(), solid.beta, &centres);
        stats.voxel_evaluations = leaves.len() as u64;
        for (&[i, j, k], &w) in leaves.iter().zip(&w) {
            if sign(w) < 0.0 {
                let v = &mut values[grid.index(i as usize, j as usize, k as usize)];
                *v = -*v;
                stats.inside += 1;
            }
        }
        stats.seconds = t_all.elapsed().as_secs_f64();
        stats
    }
}

/// Negates the voxels of `field` (exact unsigned distances of `mesh`'s triangles) that
/// lie inside the solid, with the far-field parameter `beta`.
pub fn sign_field(
    mesh: &Mesh,
    field: &mut DistanceField,
    beta: f64,
) -> Result<SignStats, FieldError> {
    let t = Instant::now();
    let signer = Signer::new(mesh, beta)?;
    let mut stats = signer.sign(&field.grid, &mut field.values, field.band);
    stats.setup_seconds = signer.setup_seconds;
    stats.seconds = t.elapsed().as_secs_f64();
    Ok(stats)
}

/// A signed field prepared for computing boxes ([`FieldSource`]): the exact distance of
/// the plan, signed box by box. A box's blocks start at its own corner, so a voxel's
/// sign is decided by the same winding-number tests as in a whole volume, up to which
/// block holds it (a block is signed only where its test is conclusive: module docs).
pub struct SignedPlan {
    plan: FieldPlan,
    signer: Signer,
}

impl SignedPlan {
    /// The exact-distance `plan` of `mesh`'s triangles, signed with far-field `beta`.
    pub fn new(plan: FieldPlan, mesh: &Mesh, beta: f64) -> Result<SignedPlan, FieldError> {
        if matches!(plan.method(), Method::Smooth { .. }) {
            return Err(FieldError::SmoothNotSigned);
        }
        Ok(SignedPlan {
            plan,
            signer: Signer::new(mesh, beta)?,
        })
    }

    /// Seconds spent preparing the distances and the far fields.
    pub fn setup_seconds(&self) -> f64 {
        self.plan.setup_seconds() + self.signer.setup_seconds
    }
}

impl FieldSource for SignedPlan {
    fn grid(&self) -> &Grid {
        self.plan.grid()
    }

    fn compute_box(&self, b: &VoxelBox, out: &mut [f32]) -> FieldStats {
        let mut stats = self.plan.compute_box(b, out);
        let sub = self.plan.grid().sub_grid(b);
        let signed = self.signer.sign(&sub, out, self.plan.band());
        stats.seconds += signed.seconds;
        stats.voxels_per_second = b.len() as f64 / stats.seconds.max(1e-12);
        stats
    }
}

/// The values a block test reads: a grid's C-order values and its band.
struct Values<'a> {
    grid: &'a Grid,
    values: &'a [f32],
    band: Option<f64>,
}

impl Values<'_> {
    fn get(&self, i: usize, j: usize, k: usize) -> f32 {
        self.values[self.grid.index(i, j, k)]
    }
}

/// The blocks of one top block: filled with a sign, or single voxels left to evaluate.
#[derive(Default)]
struct Outcome {
    filled: Vec<(Block, bool)>,
    leaves: Vec<[u32; 3]>,
    evaluations: u64,
}

fn top_blocks(grid: &Grid) -> Vec<Block> {
    let mut out = Vec::new();
    for k in (0..grid.res[2]).step_by(TOP) {
        for j in (0..grid.res[1]).step_by(TOP) {
            for i in (0..grid.res[0]).step_by(TOP) {
                let lo = [i, j, k];
                let hi = [0, 1, 2].map(|a| (lo[a] + TOP).min(grid.res[a]));
                out.push(Block { lo, hi });
            }
        }
    }
    out
}

fn split(
    field: &Values<'_>,
    solid: &Solid,
    boundary: &Boundary,
    b: Block,
    stack: &mut Vec<u32>,
    out: &mut Outcome,
) {
    let grid = field.grid;
    let single = (0..3).all(|a| b.hi[a] - b.lo[a] == 1);
    if single {
        out.leaves.push(b.lo.map(|v| v as u32));
        return;
    }
    let mid = [0, 1, 2].map(|a| (b.lo[a] + b.hi[a]) / 2);
    let c = grid.voxel_center(mid[0], mid[1], mid[2]);
    let far = grid.voxel_center(b.lo[0], b.lo[1], b.lo[2]) - c;
    let far2 = grid.voxel_center(b.hi[0] - 1, b.hi[1] - 1, b.hi[2] - 1) - c;
    let r = far.abs().max(far2.abs()).length();
    let stored = field.get(mid[0], mid[1], mid[2]) as f64;
    // The stored f32 value, rounded down; beyond the band, at least the band.
    let d = if stored.is_finite() {
        stored.abs() * (1.0 - 1e-6)
    } else {
        field.band.unwrap_or(0.0)
    };
    if d > r {
        let beta = solid.beta.max(batch::SIGN_BETA);
        let w = solid
            .tree()
            .winding_number(solid.triangles(), c, beta, stack);
        out.evaluations += 1;
        let slack = if boundary.is_closed() {
            0.0
        } else {
            r * boundary.gradient_bound(boundary.distance(c) - r)
        };
        if (w - 0.5).abs() > slack + batch::SIGN_MARGIN {
            out.filled.push((b, sign(w) < 0.0));
            return;
        }
    }
    for kz in [(b.lo[2], mid[2]), (mid[2], b.hi[2])] {
        for jy in [(b.lo[1], mid[1]), (mid[1], b.hi[1])] {
            for ix in [(b.lo[0], mid[0]), (mid[0], b.hi[0])] {
                let child = Block {
                    lo: [ix.0, jy.0, kz.0],
                    hi: [ix.1, jy.1, kz.1],
                };
                if (0..3).all(|a| child.hi[a] > child.lo[a]) {
                    split(field, solid, boundary, child, stack, out);
                }
            }
        }
    }
}
