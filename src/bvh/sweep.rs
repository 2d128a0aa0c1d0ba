//! The split of a small range: sort by centroid along one axis, then evaluate the
//! surface-area heuristic at every position (a full sweep, MacDonald and Booth 1990).
//!
//! Near the leaves a range holds a few dozen primitives; binning them costs a fixed
//! price per split (clearing and merging 16 bins, two passes over them) that exceeds the
//! work on the primitives themselves, and half the splits of a tree are of such ranges.
//! Sorting a few dozen records is cheaper, and the sweep finds the best SAH split on the
//! axis instead of the best bin boundary.

use super::bins::Item;
use super::range::{Input, RangeBounds, range_bounds};
use crate::mesh::Aabb;

/// Ranges up to this size are split by the sweep.
pub(super) const SWEEP_MAX: usize = 32;

/// Splits `items` (at most [`SWEEP_MAX`], at least 2) into two non-empty halves at the
/// position of least SAH cost along `axis`; returns the split position and the bounds of
/// both halves.
pub(super) fn sweep_split(
    input: &Input,
    items: &mut [Item],
    axis: usize,
) -> (usize, RangeBounds, RangeBounds) {
    let n = items.len();
    debug_assert!((2..=SWEEP_MAX).contains(&n));
    sort_along(items, axis);
    // SAH cost of every position: the suffixes' parts from the right, then the
    // prefixes' from the left (only costs are kept; the two halves' bounds are
    // gathered once the position is chosen).
    let mut cost = [0f32; SWEEP_MAX];
    let mut acc = Aabb::EMPTY;
    for i in (1..n).rev() {
        acc = acc.union(input.bounds_of(&items[i]));
        cost[i] = half_area(&acc) * (n - i) as f32;
    }
    let mut acc = Aabb::EMPTY;
    for i in 1..n {
        acc = acc.union(input.bounds_of(&items[i - 1]));
        cost[i] += half_area(&acc) * i as f32;
    }
    // Ties (coincident points cost 0 everywhere) go to the middle.
    let mut best = n / 2;
    for i in 1..n {
        if cost[i] < cost[best] {
            best = i;
        }
    }
    (
        best,
        range_bounds(input, &items[..best]),
        range_bounds(input, &items[best..]),
    )
}

/// Insertion sort by centroid along `axis` (few items; NaN keys stay where they are).
fn sort_along(items: &mut [Item], axis: usize) {
    for i in 1..items.len() {
        let x = items[i];
        let key = x.c[axis];
        let mut j = i;
        while j > 0 && items[j - 1].c[axis] > key {
            items[j] = items[j - 1];
            j -= 1;
        }
        items[j] = x;
    }
}

/// Half the surface area of a box (0 for an empty box).
pub(super) fn half_area(b: &Aabb) -> f32 {
    if b.is_empty() {
        return 0.0;
    }
    let e = b.extent();
    e.x * e.y + e.y * e.z + e.z * e.x
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// The sweep's split costs no more than any split of the items sorted along the axis,
    /// computed here from scratch for every position.
    #[test]
    fn sweep_finds_the_cheapest_position() {
        let mut r = super::super::bins::test_random(9);
        let input = Input {
            bounds: None,
            leaf_size: 1,
        };
        for n in 2..=SWEEP_MAX {
            for axis in 0..3 {
                let mut items: Vec<Item> = (0..n)
                    .map(|i| Item {
                        c: [r(), r() * 3.0, (r() * 4.0).floor()],
                        index: i as u32,
                    })
                    .collect();
                let (mid, left, right) = sweep_split(&input, &mut items, axis);
                assert!(0 < mid && mid < n);
                assert!(items.windows(2).all(|w| w[0].c[axis] <= w[1].c[axis]));
                let box_of = |s: &[Item]| Aabb::from_points(s.iter().map(Item::centroid));
                let cost = |m: usize| {
                    half_area(&box_of(&items[..m])) * m as f32
                        + half_area(&box_of(&items[m..])) * (n - m) as f32
                };
                let best = (1..n).map(cost).fold(f32::INFINITY, f32::min);
                assert!(
                    cost(mid) <= best * (1.0 + 1e-6),
                    "n {n}: {} > {best}",
                    cost(mid)
                );
                assert_eq!(left.prims, box_of(&items[..mid]));
                assert_eq!(right.centroids, box_of(&items[mid..]));
            }
        }
        // Coincident points cost nothing anywhere: split in the middle.
        let mut same = vec![
            Item {
                c: Vec3::ONE.to_array(),
                index: 0
            };
            9
        ];
        assert_eq!(sweep_split(&input, &mut same, 0).0, 4);
    }
}
