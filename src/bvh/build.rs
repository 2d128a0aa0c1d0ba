//! Binned surface-area-heuristic build (Wald 2007), parallel with rayon (SPEC 6).
//!
//! The build works on 16-byte records (centroid + input index, [`Item`]) that the
//! partitions move, so every pass reads memory in order; `order` is read off the records
//! at the end. Each level makes two passes over its range: binning (`super::bins`),
//! which also gathers per bin the primitive bounds and the centroid bounds, from which
//! both children's boxes follow, and a branch-free partition. Ranges of at most
//! [`SWEEP_MAX`] primitives are split by sorting and sweeping all positions
//! (`super::sweep`) instead, which is cheaper there than clearing and scanning 16 bins.
//! Large ranges bin in parallel and build their halves in parallel; the serial pieces
//! are laid out depth-first at the end, in parallel. Degenerate inputs (all centroids
//! equal, e.g. duplicate points) fall back to splitting at the middle index, so the build
//! always ends with leaves of at most `leaf_size` primitives. Points (each box its
//! centroid) are built without a copy of their boxes.

use super::bins::{self, BINS, Binning, Bins, Item};
use super::range::{Input, RangeBounds, range_bounds};
use super::sweep::{SWEEP_MAX, half_area, sweep_split};
use super::{Bvh, Node};
use crate::mesh::Aabb;
use glam::Vec3;
use rayon::prelude::*;

/// Build parameters.
#[derive(Clone, Copy, Debug)]
pub struct BuildOptions {
    /// Largest number of primitives in a leaf.
    pub leaf_size: usize,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions { leaf_size: 4 }
    }
}

/// Ranges larger than this build their two halves in parallel.
const PARALLEL_MIN: usize = 16 * 1024;
/// Ranges larger than this are binned in parallel chunks.
const PARALLEL_BINNING_MIN: usize = 256 * 1024;
/// Chunk of items per parallel task in the passes over large ranges.
const CHUNK: usize = 64 * 1024;

/// Builds a BVH over primitives given their bounds and centroids, with its wide form.
pub fn build(bounds: &[Aabb], centroids: &[Vec3], options: BuildOptions) -> Bvh {
    let mut bvh = build_binary(bounds, centroids, options);
    bvh.make_wide();
    bvh
}

/// Builds the binary tree only: call [`Bvh::make_wide`] before evaluating with it
/// (after dropping the build's inputs, to keep the peak memory down).
pub fn build_binary(bounds: &[Aabb], centroids: &[Vec3], options: BuildOptions) -> Bvh {
    assert_eq!(bounds.len(), centroids.len());
    let points = bounds
        .par_iter()
        .zip(centroids.par_iter())
        .all(|(b, &c)| b.min == c && b.max == c);
    build_with(
        centroids.len(),
        |i| centroids[i],
        (!points).then_some(bounds),
        options,
    )
}

/// [`build_binary`] for points (every primitive's box is its centroid): the same tree,
/// without the boxes in memory.
pub fn build_binary_points(points: &[Vec3], options: BuildOptions) -> Bvh {
    build_with(points.len(), |i| points[i], None, options)
}

/// [`build_binary_points`] that also makes the points' primitives in leaf order
/// (`make(points[order[i]])` at `i`), from the build's records, which hold the points in
/// that order: no gather from `points`.
pub fn build_binary_points_with<P: Send>(
    points: &[Vec3],
    options: BuildOptions,
    make: impl Fn(Vec3) -> P + Sync + Send,
) -> (Bvh, Vec<P>) {
    let (nodes, items) = build_records(points.len(), |i| points[i], None, options);
    let (order, sorted) = items
        .par_iter()
        .map(|it| (it.index, make(it.centroid())))
        .unzip();
    let bvh = Bvh {
        nodes,
        order,
        ..Bvh::default()
    };
    (bvh, sorted)
}

/// [`build_binary`] over `n` primitives whose centroids are `centroid(i)`, with their
/// boxes in `bounds`, or `None` when every box is its centroid (points): callers that
/// hold their primitives need no copy of the centroids.
pub fn build_with(
    n: usize,
    centroid: impl Fn(usize) -> Vec3 + Sync,
    bounds: Option<&[Aabb]>,
    options: BuildOptions,
) -> Bvh {
    let (nodes, items) = build_records(n, centroid, bounds, options);
    let order = items.par_iter().map(|it| it.index).collect();
    Bvh {
        nodes,
        order,
        ..Bvh::default()
    }
}

/// The nodes of [`build_with`] and the build's records in leaf order.
fn build_records(
    n: usize,
    centroid: impl Fn(usize) -> Vec3 + Sync,
    bounds: Option<&[Aabb]>,
    options: BuildOptions,
) -> (Vec<Node>, Vec<Item>) {
    assert!(bounds.is_none_or(|b| b.len() == n));
    if n == 0 {
        return (Vec::new(), Vec::new());
    }
    let input = Input {
        bounds,
        leaf_size: options.leaf_size.max(1),
    };
    let mut items: Vec<Item> = (0..n)
        .into_par_iter()
        .map(|i| Item {
            c: centroid(i).to_array(),
            index: i as u32,
        })
        .collect();
    let rb = items
        .par_chunks(CHUNK)
        .map(|chunk| range_bounds(&input, chunk))
        .reduce(|| RangeBounds::EMPTY, RangeBounds::union);
    let built = build_range(&input, &mut items, 0, rb);
    (built.flatten(), items)
}

/// A subtree as built in parallel: serial pieces (child indices relative to the piece's
/// start) joined by the nodes above them, laid out depth-first once at the end
/// ([`Built::flatten`]), so each node is copied once rather than once per level.
enum Built {
    Serial(Vec<Node>),
    Split(Node, Box<Built>, Box<Built>),
}

impl Built {
    fn len(&self) -> usize {
        match self {
            Built::Serial(v) => v.len(),
            Built::Split(_, l, r) => 1 + l.len() + r.len(),
        }
    }

    /// Lays the subtree out depth-first, its pieces copied in parallel.
    fn flatten(self) -> Vec<Node> {
        let placeholder = make_node(Aabb::EMPTY, 0, 0, 0);
        let mut out = Vec::with_capacity(self.len());
        out.par_extend(rayon::iter::repeat_n(placeholder, self.len()));
        self.write(&mut out, 0);
        out
    }

    /// Writes the subtree depth-first into `out` (exactly [`Built::len`] nodes), whose
    /// first node has index `base` in the whole array, fixing the right-child indices.
    fn write(self, out: &mut [Node], base: u32) {
        match self {
            Built::Serial(v) => {
                for (o, mut n) in out.iter_mut().zip(v) {
                    if !n.is_leaf() {
                        n.index += base;
                    }
                    *o = n;
                }
            }
            Built::Split(mut node, l, r) => {
                let (head, rest) = out.split_at_mut(1);
                let (left, right) = rest.split_at_mut(l.len());
                node.index = base + 1 + left.len() as u32;
                head[0] = node;
                rayon::join(|| l.write(left, base + 1), || r.write(right, node.index));
            }
        }
    }
}

/// Builds the subtree over `items` (which start at `offset` in the final order), in
/// parallel above `PARALLEL_MIN` items.
fn build_range(input: &Input, items: &mut [Item], offset: usize, rb: RangeBounds) -> Built {
    if items.len() < PARALLEL_MIN {
        // At most 2n - 1 nodes; only the pages written are ever touched.
        let mut nodes = Vec::with_capacity(2 * items.len() - 1);
        build_serial(input, items, offset, rb, &mut nodes);
        return Built::Serial(nodes);
    }
    let (mid, left_rb, right_rb) = split(input, items, rb);
    let (left_items, right_items) = items.split_at_mut(mid);
    let (left, right) = rayon::join(
        || build_range(input, left_items, offset, left_rb),
        || build_range(input, right_items, offset + mid, right_rb),
    );
    let node = make_node(rb.prims, 0, 0, items.len());
    Built::Split(node, Box::new(left), Box::new(right))
}

fn build_serial(
    input: &Input,
    items: &mut [Item],
    offset: usize,
    rb: RangeBounds,
    nodes: &mut Vec<Node>,
) {
    if items.len() <= input.leaf_size {
        nodes.push(make_node(
            rb.prims,
            offset as u32,
            items.len() as u32,
            items.len(),
        ));
        return;
    }
    let here = nodes.len();
    nodes.push(make_node(rb.prims, 0, 0, items.len()));
    let (mid, left_rb, right_rb) = split(input, items, rb);
    let (left, right) = items.split_at_mut(mid);
    build_serial(input, left, offset, left_rb, nodes);
    nodes[here].index = nodes.len() as u32;
    build_serial(input, right, offset + mid, right_rb, nodes);
}

fn make_node(b: Aabb, index: u32, count: u32, size: usize) -> Node {
    Node {
        min: b.min,
        max: b.max,
        index,
        count,
        size: size as u32,
        diam: b.diagonal() as f32,
    }
}

/// Partitions `items` into two non-empty halves; returns the split position and the
/// bounds of both halves.
fn split(input: &Input, items: &mut [Item], rb: RangeBounds) -> (usize, RangeBounds, RangeBounds) {
    let ext = rb.centroids.extent();
    let axis = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    let width = ext[axis];
    if width.is_nan() || width <= 0.0 {
        return median_split(input, items, axis);
    }
    if items.len() <= SWEEP_MAX {
        return sweep_split(input, items, axis);
    }
    let binning = Binning {
        axis,
        lo: rb.centroids.min[axis],
        scale: BINS as f32 / width,
    };
    let bin_all = |chunk: &[Item]| match input.bounds {
        Some(bounds) => bins::bin_boxes(chunk, bounds, binning),
        None => bins::bin_points(chunk, binning),
    };
    let bins = if items.len() >= PARALLEL_BINNING_MIN {
        items
            .par_chunks(CHUNK)
            .map(bin_all)
            .reduce(Bins::new, Bins::merge)
    } else {
        bin_all(items)
    };
    // Suffix costs from the right, then the best split from the left.
    let mut right_cost = [0f32; BINS];
    let (mut acc_b, mut acc_n) = (Aabb::EMPTY, 0usize);
    for k in (1..BINS).rev() {
        acc_b = acc_b.union(bins.prims[k]);
        acc_n += bins.count[k];
        right_cost[k] = half_area(&acc_b) * acc_n as f32;
    }
    let (mut best, mut best_cost) = (0usize, f32::INFINITY);
    let (mut acc_b, mut acc_n) = (Aabb::EMPTY, 0usize);
    for k in 0..BINS - 1 {
        acc_b = acc_b.union(bins.prims[k]);
        acc_n += bins.count[k];
        if acc_n == 0 || acc_n == items.len() {
            continue;
        }
        let cost = half_area(&acc_b) * acc_n as f32 + right_cost[k + 1];
        if cost < best_cost {
            best_cost = cost;
            best = k;
        }
    }
    if !best_cost.is_finite() {
        return median_split(input, items, axis);
    }
    let gather = |range: std::ops::Range<usize>| {
        range.fold(RangeBounds::EMPTY, |acc, k| {
            acc.union(RangeBounds {
                prims: bins.prims[k],
                centroids: bins.centroids[k],
            })
        })
    };
    let mid: usize = bins.count[..=best].iter().sum();
    partition(items, |it| binning.below(it, best + 1));
    (mid, gather(0..best + 1), gather(best + 1..BINS))
}

/// In-place partition: items satisfying `left` first (unstable). Branch-free (Lomuto's
/// scheme with the swap done unconditionally): which side an item goes to is a coin
/// flip for the processor, and a mispredicted branch per item cost more than the extra
/// writes.
fn partition(items: &mut [Item], left: impl Fn(&Item) -> bool) {
    let mut l = 0;
    for i in 0..items.len() {
        let goes_left = left(&items[i]);
        items.swap(i, l);
        l += usize::from(goes_left);
    }
}

/// Splits at the middle index after ordering by centroid along `axis`; the halves'
/// bounds are computed directly (this path is rare: coincident centroids).
fn median_split(
    input: &Input,
    items: &mut [Item],
    axis: usize,
) -> (usize, RangeBounds, RangeBounds) {
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |a, b| a.c[axis].total_cmp(&b.c[axis]));
    (
        mid,
        range_bounds(input, &items[..mid]),
        range_bounds(input, &items[mid..]),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::bins::test_random as random;
    use crate::bvh::validate;

    /// Point sets of every shape the build meets: uniform, on a line (two empty extents),
    /// clustered with many exact duplicates, all coincident.
    fn point_sets(n: usize) -> Vec<(&'static str, Vec<Vec3>)> {
        let mut r = random(n as u32 + 11);
        let uniform = (0..n).map(|_| Vec3::new(r(), r(), r())).collect();
        let line = (0..n).map(|_| Vec3::new(r() * 100.0, 2.0, -3.0)).collect();
        let dup = (0..n)
            .map(|i| match i % 3 {
                0 => Vec3::new(0.5, 0.5, 0.5),
                _ => Vec3::new((r() * 4.0).floor(), (r() * 4.0).floor(), 0.0),
            })
            .collect();
        let same = vec![Vec3::new(-1.0, 7.0, 1e-3); n];
        vec![
            ("uniform", uniform),
            ("line", line),
            ("duplicates", dup),
            ("coincident", same),
        ]
    }

    const SIZES: [usize; 9] = [0, 1, 2, 3, 5, 17, 33, 1000, 70_000];

    /// Checks what `validate` does, plus: every node's box is exactly the box of the
    /// primitives below it (tight), and leaves hold 1 ..= leaf_size primitives.
    fn check(bvh: &Bvh, bounds: &[Aabb], leaf_size: usize, what: &str) {
        validate(bvh, bounds).unwrap_or_else(|e| panic!("{what}: {e}"));
        if bounds.is_empty() {
            assert!(bvh.nodes.is_empty(), "{what}");
            return;
        }
        fn tight(bvh: &Bvh, bounds: &[Aabb], i: usize, leaf_size: usize, what: &str) -> Aabb {
            let n = &bvh.nodes[i];
            let b = if n.is_leaf() {
                assert!(
                    (1..=leaf_size as u32).contains(&n.count),
                    "{what}: leaf {i}"
                );
                let (f, c) = (n.index as usize, n.count as usize);
                bvh.order[f..f + c]
                    .iter()
                    .fold(Aabb::EMPTY, |acc, &o| acc.union(bounds[o as usize]))
            } else {
                let l = tight(bvh, bounds, i + 1, leaf_size, what);
                l.union(tight(bvh, bounds, n.index as usize, leaf_size, what))
            };
            assert_eq!((n.min, n.max), (b.min, b.max), "{what}: node {i} not tight");
            assert_eq!(n.diam, b.diagonal() as f32, "{what}: node {i} diameter");
            b
        }
        tight(bvh, bounds, 0, leaf_size, what);
    }

    #[test]
    fn point_builds_are_valid_for_every_size_and_shape() {
        for n in SIZES {
            for (shape, pts) in point_sets(n) {
                let bounds: Vec<Aabb> = pts.iter().map(|&p| Aabb { min: p, max: p }).collect();
                for leaf_size in [1, 4] {
                    let options = BuildOptions { leaf_size };
                    let what = format!("{shape}, n = {n}, leaf size {leaf_size}");
                    let points = build_binary_points(&pts, options);
                    check(&points, &bounds, leaf_size, &what);
                    // The points read off the records are the inputs in leaf order, to
                    // the bit, with the same tree.
                    let (with, sorted) = build_binary_points_with(&pts, options, |p| p);
                    assert_eq!((&with.nodes, &with.order), (&points.nodes, &points.order));
                    let bits = |p: &Vec3| p.to_array().map(f32::to_bits);
                    let expected = points.order.iter().map(|&i| bits(&pts[i as usize]));
                    assert!(sorted.iter().map(bits).eq(expected), "{what}");
                    // The general entry point detects points and builds the same tree.
                    let general = build_binary(&bounds, &pts, options);
                    assert_eq!(points.nodes, general.nodes, "{what}");
                    assert_eq!(points.order, general.order, "{what}");
                }
            }
        }
    }

    #[test]
    fn box_builds_are_valid_for_every_size_and_shape() {
        for n in SIZES {
            for (shape, pts) in point_sets(n) {
                // Boxes of random size around the points, some flat, centroid off-centre.
                let mut r = random(n as u32);
                let bounds: Vec<Aabb> = pts
                    .iter()
                    .map(|&p| {
                        let e = Vec3::new(r(), r() * 0.1, if r() < 0.3 { 0.0 } else { r() });
                        Aabb {
                            min: p - 0.25 * e,
                            max: p + e,
                        }
                    })
                    .collect();
                let what = format!("{shape} boxes, n = {n}");
                let bvh = build_binary(&bounds, &pts, BuildOptions::default());
                check(&bvh, &bounds, 4, &what);
            }
        }
    }

    #[test]
    fn partition_puts_exactly_the_left_items_first() {
        let mut r = random(3);
        let mut items: Vec<Item> = (0..1000)
            .map(|i| Item {
                c: [r(), r(), r()],
                index: i,
            })
            .collect();
        let left = |it: &Item| it.c[1] < 0.3;
        let expected = items.iter().filter(|it| left(it)).count();
        partition(&mut items, left);
        assert!(items[..expected].iter().all(left));
        assert!(!items[expected..].iter().any(left));
        let mut seen: Vec<u32> = items.iter().map(|it| it.index).collect();
        seen.sort_unstable();
        assert!(seen.iter().copied().eq(0..1000));
    }
}
