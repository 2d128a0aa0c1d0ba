//! The binning pass of the SAH build (Wald 2007, "On fast construction of SAH-based
//! bounding volume hierarchies"): each primitive falls into one of [`BINS`] equal
//! slices of its range's centroid extent along one axis; the pass gathers, per bin, the
//! count, the primitive bounds and the centroid bounds, from which the split's cost and
//! both children's boxes follow.
//!
//! Build records ([`Item`]) carry their centroid, so the pass reads memory in order.
//! Points (every box is its centroid) are binned into four interleaved copies of the
//! bins, merged at the end: consecutive points of a scan often fall into the same bin,
//! and with a single copy each one waits for the previous one's store to that bin.

use crate::mesh::Aabb;
use glam::{Vec3, Vec4};

/// Number of bins per split.
pub(super) const BINS: usize = 16;

/// One primitive during the build: its centroid and its input index (16 bytes). The
/// partitions move these records rather than indices into a centroid array, so every
/// pass reads memory in order instead of gathering 12 bytes at random per primitive.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub(super) struct Item {
    pub c: [f32; 3],
    pub index: u32,
}

impl Item {
    #[inline]
    pub fn centroid(&self) -> Vec3 {
        Vec3::from_array(self.c)
    }
}

/// Which bin a centroid falls into along `axis`: bin `k` holds the scaled offsets
/// `(c - lo) * scale` in `[k, k + 1)`; below the range (and NaN) is bin 0, at or past
/// its end the last bin.
#[derive(Clone, Copy, Debug)]
pub(super) struct Binning {
    pub axis: usize,
    pub lo: f32,
    pub scale: f32,
}

impl Binning {
    #[inline]
    pub fn bin(&self, item: &Item) -> usize {
        (((item.c[self.axis] - self.lo) * self.scale) as usize).min(BINS - 1)
    }

    /// Whether `item` falls into a bin `< k` (for `1 <= k < BINS`), without the integer
    /// conversion: the bin index is the scaled offset truncated, NaN going to bin 0.
    #[inline]
    pub fn below(&self, item: &Item, k: usize) -> bool {
        let v = (item.c[self.axis] - self.lo) * self.scale;
        v < k as f32 || v.is_nan()
    }
}

/// Per-bin counts, primitive bounds and centroid bounds.
#[derive(Clone, Copy)]
pub(super) struct Bins {
    pub count: [usize; BINS],
    pub prims: [Aabb; BINS],
    pub centroids: [Aabb; BINS],
}

impl Bins {
    pub fn new() -> Bins {
        Bins {
            count: [0; BINS],
            prims: [Aabb::EMPTY; BINS],
            centroids: [Aabb::EMPTY; BINS],
        }
    }

    pub fn merge(mut self, o: Bins) -> Bins {
        for k in 0..BINS {
            self.count[k] += o.count[k];
            self.prims[k] = self.prims[k].union(o.prims[k]);
            self.centroids[k] = self.centroids[k].union(o.centroids[k]);
        }
        self
    }
}

/// Bins primitives whose boxes are given by input index (`bounds`).
pub(super) fn bin_boxes(items: &[Item], bounds: &[Aabb], binning: Binning) -> Bins {
    let mut b = Bins::new();
    for it in items {
        let k = binning.bin(it);
        b.count[k] += 1;
        b.prims[k] = b.prims[k].union(bounds[it.index as usize]);
        b.centroids[k] = b.centroids[k].grow(it.centroid());
    }
    b
}

/// Bins points (each box is its centroid; `prims` equals `centroids` in the result).
pub(super) fn bin_points(items: &[Item], binning: Binning) -> Bins {
    // Four copies cost 2 KiB to clear: not worth it for a handful of points.
    if items.len() >= 64 {
        bin_points_lanes::<4>(items, binning)
    } else {
        bin_points_lanes::<1>(items, binning)
    }
}

/// [`bin_points`] with `LANES` interleaved copies of the bins (item `i` of each group of
/// `LANES` goes to copy `i`), as 4-wide boxes so that growing one is two instructions.
fn bin_points_lanes<const LANES: usize>(items: &[Item], binning: Binning) -> Bins {
    let mut count = [[0usize; BINS]; LANES];
    let mut lo = [[Vec4::INFINITY; BINS]; LANES];
    let mut hi = [[Vec4::NEG_INFINITY; BINS]; LANES];
    let mut add = |lane: usize, it: &Item| {
        let k = binning.bin(it);
        let p = Vec4::new(it.c[0], it.c[1], it.c[2], 0.0);
        count[lane][k] += 1;
        lo[lane][k] = lo[lane][k].min(p);
        hi[lane][k] = hi[lane][k].max(p);
    };
    let mut groups = items.chunks_exact(LANES);
    for group in &mut groups {
        for (lane, it) in group.iter().enumerate() {
            add(lane, it);
        }
    }
    for it in groups.remainder() {
        add(0, it);
    }
    let mut out = Bins::new();
    for lane in 0..LANES {
        for k in 0..BINS {
            out.count[k] += count[lane][k];
            let b = Aabb {
                min: lo[lane][k].truncate(),
                max: hi[lane][k].truncate(),
            };
            out.centroids[k] = out.centroids[k].union(b);
        }
    }
    out.prims = out.centroids;
    out
}

/// A fixed-seed generator of floats in [0, 1) for the build's tests.
#[cfg(test)]
pub(super) fn test_random(seed: u32) -> impl FnMut() -> f32 {
    let mut s = seed;
    move || {
        s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (s >> 8) as f32 / (1 << 24) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Counts and boxes per bin computed the plain way, from each point's bin index.
    #[test]
    fn points_binning_matches_a_direct_count() {
        let mut r = test_random(5);
        for n in [1usize, 3, 63, 64, 67, 1000] {
            // Runs of equal points, as in a scan, and points outside the binned range.
            let items: Vec<Item> = (0..n)
                .map(|i| {
                    let v = if i % 5 < 2 { 0.25 } else { 2.0 * r() - 0.5 };
                    Item {
                        c: [v, r(), -r()],
                        index: i as u32,
                    }
                })
                .collect();
            let binning = Binning {
                axis: 0,
                lo: 0.0,
                scale: BINS as f32,
            };
            let bins = bin_points(&items, binning);
            for k in 0..BINS {
                let mine: Vec<&Item> = items.iter().filter(|it| binning.bin(it) == k).collect();
                let b = Aabb::from_points(mine.iter().map(|it| it.centroid()));
                assert_eq!(bins.count[k], mine.len(), "n = {n}, bin {k}");
                assert_eq!(bins.centroids[k], b, "n = {n}, bin {k}");
                assert_eq!(bins.prims[k], b, "n = {n}, bin {k}");
                for it in items.iter().filter(|_| k >= 1) {
                    assert_eq!(binning.below(it, k), binning.bin(it) < k, "{:?}", it.c);
                }
            }
        }
    }
}
