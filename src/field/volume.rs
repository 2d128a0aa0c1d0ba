//! A computed distance field: values on the grid, trilinear sampling and a Lipschitz
//! lower bound for skipping empty space.

use super::grid::Grid;
use glam::DVec3;

/// Interpolation weights below this are ignored, so that sampling exactly at a voxel
/// centre (up to rounding) never picks up a neighbour outside the band (`+inf`).
const NEGLIGIBLE_WEIGHT: f64 = 1e-12;

/// Relative slack of the lower bound: covers the f32 rounding of stored values
/// (2^-24) with a wide margin.
const STORE_SLACK: f64 = 1e-6;

/// Distances on a grid, f32 in C order with shape `(NZ, NY, NX)`.
#[derive(Clone, Debug, PartialEq)]
pub struct DistanceField {
    pub grid: Grid,
    /// `values[grid.index(i, j, k)]` is the distance at the centre of voxel `(i, j, k)`.
    pub values: Vec<f32>,
    /// Narrow band: voxels farther than this from the data hold `+inf`.
    pub band: Option<f64>,
}

/// The eight voxels around a point (clamped to the grid) and its trilinear weights.
struct Cell {
    idx: [[usize; 2]; 3],
    t: [f64; 3],
}

impl DistanceField {
    /// Value at voxel `(i, j, k)`.
    pub fn get(&self, i: usize, j: usize, k: usize) -> f32 {
        self.values[self.grid.index(i, j, k)]
    }

    /// One z slice, `NX * NY` values, row `j` at `j * NX`.
    pub fn slice(&self, k: usize) -> &[f32] {
        let n = self.grid.slice_len();
        &self.values[k * n..(k + 1) * n]
    }

    /// Largest finite value (0 if none).
    pub fn max_finite(&self) -> f32 {
        self.values
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .fold(0.0, f32::max)
    }

    fn cell(&self, x: DVec3) -> Cell {
        let h = self.grid.spacing();
        let mut idx = [[0usize; 2]; 3];
        let mut t = [0.0; 3];
        for a in 0..3 {
            let n = self.grid.res[a];
            let g = ((x[a] - self.grid.min[a]) / h[a] - 0.5).clamp(0.0, (n - 1) as f64);
            let g = if g.is_nan() { 0.0 } else { g };
            let i0 = (g.floor() as usize).min(n.saturating_sub(2));
            idx[a] = [i0, (i0 + 1).min(n - 1)];
            t[a] = (g - i0 as f64).clamp(0.0, 1.0);
        }
        Cell { idx, t }
    }

    /// Trilinear interpolation of the voxel-centre values, clamped at the border (a
    /// point outside the grid gets the value of the nearest point of the box of voxel
    /// centres). Exact at voxel centres. In a banded field the result is `+inf` if a
    /// voxel with a non-negligible weight is outside the band.
    pub fn sample(&self, x: DVec3) -> f64 {
        let c = self.cell(x);
        let mut sum = 0.0;
        for dk in 0..2 {
            let wk = if dk == 0 { 1.0 - c.t[2] } else { c.t[2] };
            if wk <= NEGLIGIBLE_WEIGHT {
                continue;
            }
            for dj in 0..2 {
                let wj = wk * if dj == 0 { 1.0 - c.t[1] } else { c.t[1] };
                if wj <= NEGLIGIBLE_WEIGHT {
                    continue;
                }
                for di in 0..2 {
                    let w = wj * if di == 0 { 1.0 - c.t[0] } else { c.t[0] };
                    if w <= NEGLIGIBLE_WEIGHT {
                        continue;
                    }
                    let v = self.get(c.idx[0][di], c.idx[1][dj], c.idx[2][dk]) as f64;
                    if v.is_infinite() {
                        return f64::INFINITY;
                    }
                    sum += w * v;
                }
            }
        }
        sum
    }

    /// A lower bound of the exact distance to the data at `x`:
    /// `max over the 8 surrounding voxel centres v of d(v) - |x - v|` (distance is
    /// 1-Lipschitz), never negative. Stored values are shrunk by a relative 1e-6 to
    /// cover their f32 rounding (and by 1e-9 of the grid diagonal for values near 0); a
    /// voxel outside the band contributes `band - |x - v|`.
    /// Also valid for a smooth field (which underestimates the exact distance).
    pub fn lower_bound(&self, x: DVec3) -> f64 {
        let c = self.cell(x);
        let abs_slack = STORE_SLACK * 1e-3 * self.grid.diagonal();
        let mut best = 0.0f64;
        for &k in &c.idx[2] {
            for &j in &c.idx[1] {
                for &i in &c.idx[0] {
                    let v = self.get(i, j, k) as f64;
                    let dv = if v.is_finite() {
                        v - STORE_SLACK * v.abs() - abs_slack
                    } else if v > 0.0 {
                        self.band.unwrap_or(0.0) * (1.0 - STORE_SLACK) - abs_slack
                    } else {
                        0.0
                    };
                    best = best.max(dv - (x - self.grid.voxel_center(i, j, k)).length());
                }
            }
        }
        best
    }
}
