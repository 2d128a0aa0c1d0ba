//! Morton (Z-order) sorting of query points: batches of queries visited in this order
//! meet the same parts of a BVH one after the other (caches stay warm, and a query can
//! start from its predecessor's answer, `eval::nearest`).

use glam::DVec3;
use rayon::prelude::*;

/// Indices of `points` sorted along a Morton curve over their bounding box (21 bits per
/// axis). Non-finite coordinates sort as the box's nearest corner.
pub fn morton_order(points: &[DVec3]) -> Vec<u32> {
    let empty = || (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    let (lo, hi) = points
        .par_iter()
        .filter(|p| p.is_finite())
        .fold(empty, |(lo, hi), &p| (lo.min(p), hi.max(p)))
        .reduce(empty, |a, b| (a.0.min(b.0), a.1.max(b.1)));
    const CELLS: f64 = ((1u32 << 21) - 1) as f64;
    let extent = (hi - lo).max_element();
    let scale = if extent > 0.0 && extent.is_finite() {
        CELLS / extent
    } else {
        0.0
    };
    let keys: Vec<u64> = points
        .par_iter()
        .map(|&p| {
            // NaN clamps to NaN, which the cast takes to 0.
            let c = ((p - lo) * scale).clamp(DVec3::ZERO, DVec3::splat(CELLS));
            spread(c.x as u64) | (spread(c.y as u64) << 1) | (spread(c.z as u64) << 2)
        })
        .collect();
    sort_by_key(&keys)
}

/// The indices `0..keys.len()` sorted by `(keys[i], i)`: a counting sort on the keys'
/// top bits (about [`PER_BUCKET`] points per bucket), then each bucket sorted alone, in
/// parallel. The same order as one sort of the pairs, at a fraction of its cost.
fn sort_by_key(keys: &[u64]) -> Vec<u32> {
    let n = keys.len();
    let bits = (n / PER_BUCKET).max(1).ilog2().min(MAX_BUCKET_BITS);
    let shift = 63 - bits;
    let bucket = |k: u64| (k >> shift) as usize;
    let mut start = vec![0usize; (1 << bits) + 1];
    for &k in keys {
        start[bucket(k) + 1] += 1;
    }
    for b in 1..start.len() {
        start[b] += start[b - 1];
    }
    let mut next = start.clone();
    let mut pairs = vec![(0u64, 0u32); n];
    for (i, &k) in keys.iter().enumerate() {
        let b = bucket(k);
        pairs[next[b]] = (k, i as u32);
        next[b] += 1;
    }
    let mut buckets = Vec::with_capacity(start.len());
    let mut rest = pairs.as_mut_slice();
    for w in start.windows(2) {
        let (head, tail) = rest.split_at_mut(w[1] - w[0]);
        buckets.push(head);
        rest = tail;
    }
    buckets
        .par_iter_mut()
        .with_min_len(64)
        .for_each(|b| b.sort_unstable());
    pairs.into_par_iter().map(|(_, i)| i).collect()
}

/// Points per bucket of [`sort_by_key`], on average.
const PER_BUCKET: usize = 16;

/// At most `2^MAX_BUCKET_BITS` buckets.
const MAX_BUCKET_BITS: u32 = 20;

/// The low 21 bits of `v` spread to every third bit.
fn spread(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | (x << 32)) & 0x001f_0000_0000_ffff;
    x = (x | (x << 16)) & 0x001f_0000_ff00_00ff;
    x = (x | (x << 8)) & 0x100f_00f0_0f00_f00f;
    x = (x | (x << 4)) & 0x10c3_0c30_c30c_30c3;
    x = (x | (x << 2)) & 0x1249_2492_4924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_order_is_a_permutation_along_the_curve() {
        let mut seed = 3u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut pts: Vec<DVec3> = (0..5000).map(|_| DVec3::new(rnd(), rnd(), rnd())).collect();
        pts.push(DVec3::new(f64::NAN, 0.5, 0.5));
        let order = morton_order(&pts);
        let mut seen = vec![false; pts.len()];
        for &i in &order {
            assert!(!seen[i as usize]);
            seen[i as usize] = true;
        }
        assert!(seen.iter().all(|&s| s));
        // Consecutive points are close: the mean step is a small share of the box.
        let steps: f64 = order
            .windows(2)
            .filter(|w| pts[w[0] as usize].is_finite() && pts[w[1] as usize].is_finite())
            .map(|w| (pts[w[0] as usize] - pts[w[1] as usize]).length())
            .sum();
        assert!(steps / 5000.0 < 0.1, "mean step {}", steps / 5000.0);
        // The spread bits interleave: x, y, z bit 0 land on bits 0, 1, 2.
        assert_eq!(spread(1) | (spread(1) << 1) | (spread(1) << 2), 0b111);
        assert_eq!(spread(0b10), 0b1000);
    }

    #[test]
    fn the_bucket_sort_equals_one_sort_of_the_pairs() {
        let mut seed = 5u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            seed >> 1
        };
        for n in [0, 1, 2, 17, 1000, 70_000] {
            // Distinct keys, repeated keys and clustered keys (one bucket).
            for kind in 0..3 {
                let keys: Vec<u64> = (0..n)
                    .map(|_| match kind {
                        0 => rnd(),
                        1 => (rnd() % 7) << 40,
                        _ => rnd() % 1000,
                    })
                    .collect();
                let mut want: Vec<(u64, u32)> = keys
                    .iter()
                    .enumerate()
                    .map(|(i, &k)| (k, i as u32))
                    .collect();
                want.sort_unstable();
                let want: Vec<u32> = want.into_iter().map(|(_, i)| i).collect();
                assert_eq!(sort_by_key(&keys), want, "n {n}, kind {kind}");
            }
        }
    }
}
