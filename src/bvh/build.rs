//! Binned surface-area-heuristic build (Wald 2007), parallel with rayon. Each level makes
//! one pass over its primitives: the binning pass also gathers, per bin, the primitive
//! bounds and the centroid bounds, from which both children's boxes follow, so no extra
//! bounds passes are needed. Large ranges bin in parallel and build their halves in
//! parallel. Degenerate inputs (all centroids equal, e.g. duplicate points) fall back to
//! splitting at the middle index, so the build always ends with leaves of at most
//! `leaf_size` primitives.

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

const BINS: usize = 16;
/// Ranges larger than this build their two halves in parallel.
const PARALLEL_MIN: usize = 16 * 1024;
/// Ranges larger than this are binned in parallel chunks.
const PARALLEL_BINNING_MIN: usize = 256 * 1024;

struct Input<'a> {
    bounds: &'a [Aabb],
    centroids: &'a [Vec3],
    leaf_size: usize,
    /// Every primitive's box is its centroid (points): binning skips the boxes.
    points: bool,
}

/// Bounds of a range: of its primitives and of their centroids.
#[derive(Clone, Copy)]
struct RangeBounds {
    prims: Aabb,
    centroids: Aabb,
}

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
    if bounds.is_empty() {
        return Bvh::default();
    }
    let points = bounds
        .par_iter()
        .zip(centroids.par_iter())
        .all(|(b, &c)| b.min == c && b.max == c);
    let input = Input {
        bounds,
        centroids,
        leaf_size: options.leaf_size.max(1),
        points,
    };
    let mut order: Vec<u32> = (0..bounds.len() as u32).collect();
    let rb = bounds
        .par_iter()
        .zip(centroids.par_iter())
        .fold(
            || RangeBounds {
                prims: Aabb::EMPTY,
                centroids: Aabb::EMPTY,
            },
            |acc, (b, &c)| RangeBounds {
                prims: acc.prims.union(*b),
                centroids: acc.centroids.grow(c),
            },
        )
        .reduce(
            || RangeBounds {
                prims: Aabb::EMPTY,
                centroids: Aabb::EMPTY,
            },
            |a, b| RangeBounds {
                prims: a.prims.union(b.prims),
                centroids: a.centroids.union(b.centroids),
            },
        );
    let built = build_range(&input, &mut order, 0, rb);
    let mut nodes = Vec::with_capacity(built.len());
    built.flatten(&mut nodes);
    Bvh {
        nodes,
        order,
        ..Bvh::default()
    }
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

    /// Appends the subtree depth-first to `out`, fixing the right-child indices.
    fn flatten(self, out: &mut Vec<Node>) {
        match self {
            Built::Serial(v) => {
                let base = out.len() as u32;
                out.extend(v.into_iter().map(|mut n| {
                    if !n.is_leaf() {
                        n.index += base;
                    }
                    n
                }));
            }
            Built::Split(node, l, r) => {
                let here = out.len();
                out.push(node);
                l.flatten(out);
                out[here].index = out.len() as u32;
                r.flatten(out);
            }
        }
    }
}

/// Builds the subtree over `items` (which start at `offset` in the final order), in
/// parallel above `PARALLEL_MIN` items.
fn build_range(input: &Input, items: &mut [u32], offset: usize, rb: RangeBounds) -> Built {
    if items.len() < PARALLEL_MIN {
        let mut nodes = Vec::with_capacity(2 * items.len() / input.leaf_size + 1);
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
    items: &mut [u32],
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

fn half_area(b: &Aabb) -> f32 {
    if b.is_empty() {
        return 0.0;
    }
    let e = b.extent();
    e.x * e.y + e.y * e.z + e.z * e.x
}

/// Per-bin counts, primitive bounds and centroid bounds.
#[derive(Clone, Copy)]
struct Bins {
    count: [usize; BINS],
    prims: [Aabb; BINS],
    centroids: [Aabb; BINS],
}

impl Bins {
    fn new() -> Bins {
        Bins {
            count: [0; BINS],
            prims: [Aabb::EMPTY; BINS],
            centroids: [Aabb::EMPTY; BINS],
        }
    }
    fn merge(mut self, o: Bins) -> Bins {
        for k in 0..BINS {
            self.count[k] += o.count[k];
            self.prims[k] = self.prims[k].union(o.prims[k]);
            self.centroids[k] = self.centroids[k].union(o.centroids[k]);
        }
        self
    }
}

/// Partitions `items` into two non-empty halves; returns the split position and the
/// bounds of both halves.
fn split(input: &Input, items: &mut [u32], rb: RangeBounds) -> (usize, RangeBounds, RangeBounds) {
    let ext = rb.centroids.extent();
    let axis = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    let lo = rb.centroids.min[axis];
    let width = ext[axis];
    if width.is_nan() || width <= 0.0 {
        return median_split(input, items, axis);
    }
    let scale = BINS as f32 / width;
    let bin_of = |i: u32| -> usize {
        let c = input.centroids[i as usize][axis];
        (((c - lo) * scale) as usize).min(BINS - 1)
    };
    let bin_all = |chunk: &[u32]| {
        let mut b = Bins::new();
        for &i in chunk {
            let k = bin_of(i);
            b.count[k] += 1;
            if !input.points {
                b.prims[k] = b.prims[k].union(input.bounds[i as usize]);
            }
            b.centroids[k] = b.centroids[k].grow(input.centroids[i as usize]);
        }
        b
    };
    let mut bins = if items.len() >= PARALLEL_BINNING_MIN {
        items
            .par_chunks(64 * 1024)
            .map(bin_all)
            .reduce(Bins::new, Bins::merge)
    } else {
        bin_all(items)
    };
    if input.points {
        bins.prims = bins.centroids;
    }
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
        range.fold(
            RangeBounds {
                prims: Aabb::EMPTY,
                centroids: Aabb::EMPTY,
            },
            |acc, k| RangeBounds {
                prims: acc.prims.union(bins.prims[k]),
                centroids: acc.centroids.union(bins.centroids[k]),
            },
        )
    };
    let mid: usize = bins.count[..=best].iter().sum();
    // `bin_of(i) <= best` without the integer conversion: the bin index is the scaled
    // offset truncated (0 below the range, NaN included), and best + 1 < BINS.
    let cut = (best + 1) as f32;
    partition(items, |i| {
        let v = (input.centroids[i as usize][axis] - lo) * scale;
        v < cut || v.is_nan()
    });
    (mid, gather(0..best + 1), gather(best + 1..BINS))
}

/// In-place partition: items satisfying `left` first (unstable).
fn partition(items: &mut [u32], left: impl Fn(u32) -> bool) {
    let (mut i, mut j) = (0usize, items.len());
    loop {
        while i < j && left(items[i]) {
            i += 1;
        }
        while i < j && !left(items[j - 1]) {
            j -= 1;
        }
        if i >= j {
            break;
        }
        items.swap(i, j - 1);
        i += 1;
        j -= 1;
    }
}

/// Splits at the middle index after ordering by centroid along `axis`; the halves'
/// bounds are computed directly (this path is rare: coincident centroids).
fn median_split(
    input: &Input,
    items: &mut [u32],
    axis: usize,
) -> (usize, RangeBounds, RangeBounds) {
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |&a, &b| {
        let ca = input.centroids[a as usize][axis];
        let cb = input.centroids[b as usize][axis];
        ca.total_cmp(&cb)
    });
    let bounds_of = |s: &[u32]| {
        s.iter().fold(
            RangeBounds {
                prims: Aabb::EMPTY,
                centroids: Aabb::EMPTY,
            },
            |acc, &i| RangeBounds {
                prims: acc.prims.union(input.bounds[i as usize]),
                centroids: acc.centroids.grow(input.centroids[i as usize]),
            },
        )
    };
    (mid, bounds_of(&items[..mid]), bounds_of(&items[mid..]))
}
