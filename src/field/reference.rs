//! Per-voxel methods: brute force, exact nearest queries on the BVH, and the smooth
//! distance. Slices in parallel; every voxel is independent.

use super::grid::Grid;
use crate::eval::{self, EvalParams, brute};
use crate::primitives::AnySet;
use rayon::prelude::*;

/// Fills `out` slice by slice with `f(voxel centre)`.
fn per_voxel(grid: &Grid, out: &mut [f32], f: impl Fn(glam::DVec3) -> f32 + Sync) {
    let [nx, ny, _] = grid.res;
    out.par_chunks_mut(grid.slice_len())
        .enumerate()
        .for_each(|(k, slice)| {
            for j in 0..ny {
                for i in 0..nx {
                    slice[j * nx + i] = f(grid.voxel_center(i, j, k));
                }
            }
        });
}

/// Maps an exact distance to the stored value: `+inf` beyond the band.
#[inline]
fn banded(d: f64, band: Option<f64>) -> f32 {
    match band {
        Some(b) if !(d <= b) => f32::INFINITY,
        _ => d as f32,
    }
}

/// Every primitive at every voxel (f64 closest points).
pub(crate) fn brute(set: &AnySet, grid: &Grid, band: Option<f64>, out: &mut [f32]) {
    per_voxel(grid, out, |x| banded(brute::min_distance(&[set], x), band));
}

/// One exact nearest query per voxel; with a band the query is bounded by it.
pub(crate) fn bvh(set: &AnySet, grid: &Grid, band: Option<f64>, out: &mut [f32]) {
    // Slightly above the band so a primitive at exactly `band` is still found.
    let bound = band.map_or(f64::INFINITY, |b| b * (1.0 + 1e-12));
    per_voxel(grid, out, |x| {
        banded(eval::nearest::nearest_within(&[set], x, bound).d, band)
    });
}

/// The smooth distance (Barnes-Hut evaluation) per voxel.
pub(crate) fn smooth(set: &AnySet, grid: &Grid, params: &EvalParams, out: &mut [f32]) {
    per_voxel(grid, out, |x| eval::evaluate(&[set], x, params).s as f32);
}
