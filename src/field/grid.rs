//! The voxel grid: bounds, resolution, voxel centres, and the memory check.
//!
//! Voxel `(i, j, k)` is the box `min + [(i, j, k), (i, j, k) + 1] * h` with spacing
//! `h = (max - min) / (NX, NY, NZ)`; its value is the distance at its centre
//! `min + ((i, j, k) + 0.5) * h`. Values are stored in C order with shape `(NZ, NY, NX)`:
//! index `(k * NY + j) * NX + i`, so one z slice is a contiguous `NX * NY` block.

use super::error::FieldError;
use crate::mesh::Aabb;
use glam::DVec3;

/// Largest number of voxels along one axis.
pub const MAX_RESOLUTION: usize = 1 << 16;

/// Default bounds grow the mesh's bounding box by this fraction of its diagonal on every
/// side.
pub const DEFAULT_MARGIN: f64 = 0.1;

/// Fixed cap of the memory check, used when `/proc/meminfo` cannot be read and as an
/// upper limit otherwise.
pub const MEMORY_CAP: u64 = 8 << 30;

const AXES: [char; 3] = ['x', 'y', 'z'];

/// A uniform grid of voxels over an axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    pub min: DVec3,
    pub max: DVec3,
    /// Voxels along x, y, z: `[NX, NY, NZ]`.
    pub res: [usize; 3],
}

impl Grid {
    /// A grid with exactly these bounds and resolution, after validating both.
    pub fn new(min: DVec3, max: DVec3, res: [usize; 3]) -> Result<Grid, FieldError> {
        check_bounds(min, max)?;
        for (a, &n) in res.iter().enumerate() {
            if n == 0 {
                return Err(FieldError::ZeroResolution { axis: AXES[a] });
            }
            if n > MAX_RESOLUTION {
                return Err(FieldError::ResolutionTooLarge {
                    axis: AXES[a],
                    value: n,
                    max: MAX_RESOLUTION,
                });
            }
        }
        Ok(Grid { min, max, res })
    }

    /// Cubic voxels with `n` voxels along the longest axis of `[min, max]`; the other axes
    /// get `ceil(extent / h)` voxels and their extent grows (symmetrically about the
    /// centre) to a whole number of voxels.
    pub fn cubic(min: DVec3, max: DVec3, n: usize) -> Result<Grid, FieldError> {
        check_bounds(min, max)?;
        if n == 0 {
            return Err(FieldError::ZeroResolution { axis: 'x' });
        }
        let ext = max - min;
        let longest = ext.max_element();
        let h = longest / n as f64;
        let mut res = [0usize; 3];
        let (mut lo, mut hi) = (min, max);
        for a in 0..3 {
            if ext[a] == longest {
                res[a] = n;
                continue;
            }
            // The small slack keeps an exact multiple from rounding up to one more voxel.
            let m = ((ext[a] / h) * (1.0 - 1e-12)).ceil().max(1.0);
            res[a] = if m > MAX_RESOLUTION as f64 {
                MAX_RESOLUTION + 1
            } else {
                m as usize
            };
            let c = 0.5 * (min[a] + max[a]);
            lo[a] = c - 0.5 * m * h;
            hi[a] = c + 0.5 * m * h;
        }
        Grid::new(lo, hi, res)
    }

    /// The default bounds of a mesh: its bounding box grown by 10% of its diagonal on
    /// every side.
    pub fn default_bounds(bounds: Aabb) -> Result<(DVec3, DVec3), FieldError> {
        let diag = bounds.diagonal();
        if bounds.is_empty() || !(diag > 0.0) || !diag.is_finite() {
            return Err(FieldError::NoDefaultBounds);
        }
        let m = DEFAULT_MARGIN * diag;
        Ok((bounds.min.as_dvec3() - m, bounds.max.as_dvec3() + m))
    }

    /// Cubic voxels, `n` along the longest axis of the mesh's default bounds.
    pub fn around(bounds: Aabb, n: usize) -> Result<Grid, FieldError> {
        let (min, max) = Grid::default_bounds(bounds)?;
        Grid::cubic(min, max, n)
    }

    /// Voxel spacing `(max - min) / res` per axis.
    pub fn spacing(&self) -> DVec3 {
        (self.max - self.min)
            / DVec3::new(self.res[0] as f64, self.res[1] as f64, self.res[2] as f64)
    }

    /// Centre of voxel `(i, j, k)`.
    #[inline]
    pub fn voxel_center(&self, i: usize, j: usize, k: usize) -> DVec3 {
        let h = self.spacing();
        self.min + (DVec3::new(i as f64, j as f64, k as f64) + 0.5) * h
    }

    /// z of the centres of slice `k`.
    #[inline]
    pub fn slice_z(&self, k: usize) -> f64 {
        self.min.z + (k as f64 + 0.5) * self.spacing().z
    }

    /// Flat index of voxel `(i, j, k)` in C order `(NZ, NY, NX)`.
    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        (k * self.res[1] + j) * self.res[0] + i
    }

    /// Number of voxels.
    pub fn len(&self) -> usize {
        self.res[0] * self.res[1] * self.res[2]
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Voxels in one z slice.
    pub fn slice_len(&self) -> usize {
        self.res[0] * self.res[1]
    }

    /// Shape of the stored array, `[NZ, NY, NX]`.
    pub fn shape(&self) -> [usize; 3] {
        [self.res[2], self.res[1], self.res[0]]
    }

    /// Length of the diagonal of the bounds.
    pub fn diagonal(&self) -> f64 {
        (self.max - self.min).length()
    }

    /// Estimated peak memory of computing a field on this grid, bytes: the f32 values
    /// plus one f64 slice buffer per thread (the linfac accumulator) and a second copy of
    /// a slice per thread for output conversion.
    pub fn memory_estimate(&self, threads: usize) -> Option<u64> {
        let voxels = (self.res[0] as u64)
            .checked_mul(self.res[1] as u64)?
            .checked_mul(self.res[2] as u64)?;
        let slice = (self.res[0] as u64).checked_mul(self.res[1] as u64)?;
        voxels
            .checked_mul(4)?
            .checked_add(slice.checked_mul(12)?.checked_mul(threads.max(1) as u64)?)
    }

    /// Refuses a grid whose memory estimate plus `extra` bytes exceeds `limit` (or, by
    /// default, half of the physical memory capped at 8 GiB).
    pub fn check_memory(&self, limit: Option<u64>, extra: u64) -> Result<(), FieldError> {
        let (limit, why) = match limit {
            Some(l) => (l, "the configured limit".to_string()),
            None => default_memory_limit(),
        };
        let threads = rayon::current_num_threads();
        let voxels = (self.res[0] as u64)
            .saturating_mul(self.res[1] as u64)
            .saturating_mul(self.res[2] as u64);
        let bytes = self
            .memory_estimate(threads)
            .map_or(u64::MAX, |b| b.saturating_add(extra));
        if bytes > limit {
            return Err(FieldError::TooMuchMemory {
                nx: self.res[0],
                ny: self.res[1],
                nz: self.res[2],
                voxels,
                bytes,
                limit,
                why,
            });
        }
        Ok(())
    }
}

/// Half of `MemTotal` from `/proc/meminfo`, at most [`MEMORY_CAP`]; the cap alone when
/// the file cannot be read. Returns the limit and a phrase saying where it came from.
pub fn default_memory_limit() -> (u64, String) {
    let total = std::fs::read_to_string("/proc/meminfo").ok().and_then(|s| {
        s.lines()
            .find(|l| l.starts_with("MemTotal:"))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|kb| kb.parse::<u64>().ok())
            .map(|kb| kb * 1024)
    });
    match total {
        Some(t) if t / 2 < MEMORY_CAP => (t / 2, "half of the physical memory".into()),
        Some(_) => (MEMORY_CAP, "the fixed cap".into()),
        None => (
            MEMORY_CAP,
            "the fixed cap; /proc/meminfo was not readable".into(),
        ),
    }
}

fn check_bounds(min: DVec3, max: DVec3) -> Result<(), FieldError> {
    if !min.is_finite() || !max.is_finite() {
        return Err(FieldError::NonFiniteBounds {
            min: min.to_array(),
            max: max.to_array(),
        });
    }
    for (corner, v) in [("min", min), ("max", max)] {
        for a in 0..3 {
            if let Some(problem) = crate::limits::query_coordinate_problem(v[a]) {
                return Err(FieldError::BoundsTooLarge {
                    corner,
                    axis: AXES[a],
                    problem,
                });
            }
        }
    }
    for a in 0..3 {
        if min[a] > max[a] {
            return Err(FieldError::InvertedBounds {
                axis: AXES[a],
                min: min[a],
                max: max[a],
            });
        }
        if min[a] == max[a] {
            return Err(FieldError::DegenerateBounds {
                axis: AXES[a],
                value: min[a],
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cubic_rounds_up_and_keeps_voxels_cubic() {
        let g = Grid::cubic(DVec3::ZERO, DVec3::new(2.0, 1.0, 0.55), 20).unwrap();
        assert_eq!(g.res, [20, 10, 6]);
        let h = g.spacing();
        assert!(
            (h.x - 0.1).abs() < 1e-15 && (h.y - 0.1).abs() < 1e-15 && (h.z - 0.1).abs() < 1e-15
        );
        // Centred growth of the short axis.
        assert!((g.min.z + 0.025).abs() < 1e-15 && (g.max.z - 0.575).abs() < 1e-15);
    }

    #[test]
    fn voxel_zero_center() {
        let g = Grid::new(
            DVec3::new(-1.0, 0.0, 2.0),
            DVec3::new(1.0, 4.0, 3.0),
            [4, 8, 2],
        )
        .unwrap();
        assert_eq!(g.voxel_center(0, 0, 0), DVec3::new(-0.75, 0.25, 2.25));
        assert_eq!(g.index(1, 2, 1), (8 + 2) * 4 + 1);
    }
}
