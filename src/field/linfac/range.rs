//! The slice range of a site: the inclusive interval of slices its domain meets (SPEC 9,
//! "Domains"; computed once per site before the slice loop).
//!
//! A domain is convex and contains the site's witness point `w`, so the slices it meets
//! form an interval, and a non-empty one contains `kp` or `kp + 1`, the slices just
//! below and above `w` (`kp = floor((w_z - min_z) / hz - 1/2)`). Two binary searches on
//! the monotone test "the domain meets slice `k`" find its lowest slice in `0..=kp` and
//! its highest in `kp + 1..nz`. The test cuts the grid's pixel rectangle (enlarged by
//! half a voxel, so that the witness is strictly inside) to the site's band box and
//! clips it by the site's half-planes (`domain`). A witness outside the grid's xy box
//! gives the full range: the part of the domain over the box need not contain it.

use super::domain::clip_bbox;
use super::{Raster, Scratch};

impl Raster<'_> {
    /// Whether the domain of site `idx` meets slice `k` inside the grid box (enlarged
    /// by half a voxel so the witness is strictly inside).
    fn meets_slice(&self, idx: usize, k: usize, s: &mut Scratch) -> bool {
        let mut rect = [-1.0, -1.0, self.nx as f64, self.ny as f64];
        s.hps.clear();
        let mut hps = std::mem::take(&mut s.hps);
        let z = self.grid.slice_z(k);
        let ok = self.band_rect(idx, z, &mut rect)
            && self.push_halfplanes(idx, z, &mut hps)
            && clip_bbox(rect, &hps, &mut s.poly, &mut s.poly2).is_some();
        s.hps = hps;
        ok
    }

    /// Inclusive slice range `(k0, k1)` met by the site's domain (`k0 > k1` when none).
    pub(super) fn slice_range(&self, idx: usize, s: &mut Scratch) -> (usize, usize) {
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
}
