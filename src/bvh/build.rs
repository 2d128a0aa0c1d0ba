//! Binned surface-area-heuristic build (Wald 2007), parallel with rayon above a size
//! threshold. Degenerate inputs (all centroids equal, e.g. duplicate points) fall back
//! to splitting at the middle index, so the build always terminates with leaves of at
//! most `leaf_size` primitives.

use super::{Bvh, Node};
use crate::mesh::Aabb;
use glam::Vec3;

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

struct Input<'a> {
    bounds: &'a [Aabb],
    centroids: &'a [Vec3],
    leaf_size: usize,
}

/// Builds a BVH over primitives given their bounds and centroids.
pub fn build(bounds: &[Aabb], centroids: &[Vec3], options: BuildOptions) -> Bvh {
    assert_eq!(bounds.len(), centroids.len());
    if bounds.is_empty() {
        return Bvh::default();
    }
    let input = Input {
        bounds,
        centroids,
        leaf_size: options.leaf_size.max(1),
    };
    let mut order: Vec<u32> = (0..bounds.len() as u32).collect();
    let nodes = build_range(&input, &mut order, 0);
    Bvh { nodes, order }
}

/// Builds the subtree over `items` (which start at `offset` in the final order) into a
/// fresh vector whose child indices are relative to its start.
fn build_range(input: &Input, items: &mut [u32], offset: usize) -> Vec<Node> {
    if items.len() < PARALLEL_MIN {
        let mut nodes = Vec::with_capacity(2 * items.len() / input.leaf_size + 1);
        build_serial(input, items, offset, &mut nodes);
        return nodes;
    }
    let (node, mid) = split(input, items);
    let (left_items, right_items) = items.split_at_mut(mid);
    let (left, right) = rayon::join(
        || build_range(input, left_items, offset),
        || build_range(input, right_items, offset + mid),
    );
    let mut nodes = Vec::with_capacity(1 + left.len() + right.len());
    nodes.push(Node {
        index: (1 + left.len()) as u32,
        ..node
    });
    append_shifted(&mut nodes, left);
    append_shifted(&mut nodes, right);
    nodes
}

/// Appends a subtree vector, shifting its inner nodes' right-child indices.
fn append_shifted(nodes: &mut Vec<Node>, sub: Vec<Node>) {
    let base = nodes.len() as u32;
    nodes.extend(sub.into_iter().map(|mut n| {
        if !n.is_leaf() {
            n.index += base;
        }
        n
    }));
}

fn build_serial(input: &Input, items: &mut [u32], offset: usize, nodes: &mut Vec<Node>) {
    let here = nodes.len();
    if items.len() <= input.leaf_size {
        let b = range_bounds(input, items);
        nodes.push(make_node(b, offset as u32, items.len() as u32, items.len()));
        return;
    }
    let (node, mid) = split(input, items);
    nodes.push(node);
    let (left, right) = items.split_at_mut(mid);
    build_serial(input, left, offset, nodes);
    nodes[here].index = nodes.len() as u32;
    build_serial(input, right, offset + mid, nodes);
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

fn range_bounds(input: &Input, items: &[u32]) -> Aabb {
    items
        .iter()
        .fold(Aabb::EMPTY, |b, &i| b.union(input.bounds[i as usize]))
}

fn half_area(b: &Aabb) -> f32 {
    if b.is_empty() {
        return 0.0;
    }
    let e = b.extent();
    e.x * e.y + e.y * e.z + e.z * e.x
}

/// Partitions `items` into two non-empty halves and returns the inner node (its
/// right-child index to be filled in) and the split position.
fn split(input: &Input, items: &mut [u32]) -> (Node, usize) {
    let b = range_bounds(input, items);
    let node = make_node(b, 0, 0, items.len());
    let cb = items
        .iter()
        .fold(Aabb::EMPTY, |b, &i| b.grow(input.centroids[i as usize]));
    let ext = cb.extent();
    let axis = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    let lo = cb.min[axis];
    let width = ext[axis];
    if !(width > 0.0) {
        return (node, items.len() / 2);
    }
    let scale = BINS as f32 / width;
    let bin_of = |i: u32| -> usize {
        let c = input.centroids[i as usize][axis];
        (((c - lo) * scale) as usize).min(BINS - 1)
    };
    let mut counts = [0usize; BINS];
    let mut boxes = [Aabb::EMPTY; BINS];
    for &i in items.iter() {
        let k = bin_of(i);
        counts[k] += 1;
        boxes[k] = boxes[k].union(input.bounds[i as usize]);
    }
    // Sweep from the right to get suffix areas, then from the left.
    let mut right_cost = [0f32; BINS];
    let (mut acc_b, mut acc_n) = (Aabb::EMPTY, 0usize);
    for k in (1..BINS).rev() {
        acc_b = acc_b.union(boxes[k]);
        acc_n += counts[k];
        right_cost[k] = half_area(&acc_b) * acc_n as f32;
    }
    let (mut best, mut best_cost) = (0usize, f32::INFINITY);
    let (mut acc_b, mut acc_n) = (Aabb::EMPTY, 0usize);
    for k in 0..BINS - 1 {
        acc_b = acc_b.union(boxes[k]);
        acc_n += counts[k];
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
        return (node, median_split(input, items, axis));
    }
    // In-place partition: bins 0..=best to the left.
    let mut mid = 0;
    for j in 0..items.len() {
        if bin_of(items[j]) <= best {
            items.swap(mid, j);
            mid += 1;
        }
    }
    if mid == 0 || mid == items.len() {
        mid = median_split(input, items, axis);
    }
    (node, mid)
}

fn median_split(input: &Input, items: &mut [u32], axis: usize) -> usize {
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |&a, &b| {
        let ca = input.centroids[a as usize][axis];
        let cb = input.centroids[b as usize][axis];
        ca.total_cmp(&cb)
    });
    mid
}
