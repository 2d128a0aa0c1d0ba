//! Exact nearest primitive on the BVH: depth-first, near child first, pruning boxes no
//! closer than the best distance found.

use crate::primitives::{AnySet, Primitive, PrimitiveSet};
use glam::DVec3;

/// The nearest primitive to a query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest {
    /// Exact distance.
    pub d: f64,
    /// Closest point on the primitive.
    pub point: DVec3,
    /// Which of the queried sets holds it.
    pub set: usize,
    /// Source index of the primitive in its set (vertex, edge or triangle index).
    pub index: u32,
    /// Nodes visited.
    pub nodes: u32,
}

/// Nearest primitive among `sets` (`d = +inf` if all sets are empty).
pub fn nearest(sets: &[&AnySet], x: DVec3) -> Nearest {
    nearest_within(sets, x, f64::INFINITY)
}

/// Nearest primitive closer than `bound` (returns `d = bound`, `index = u32::MAX` when
/// nothing is closer): a bounded query prunes more.
pub fn nearest_within(sets: &[&AnySet], x: DVec3, bound: f64) -> Nearest {
    let mut best = Nearest {
        d: bound,
        point: DVec3::splat(f64::NAN),
        set: usize::MAX,
        index: u32::MAX,
        nodes: 0,
    };
    for (k, set) in sets.iter().enumerate() {
        crate::with_set!(set, s => search(s, k, x, &mut best));
    }
    best
}

fn search<P: Primitive>(set: &PrimitiveSet<P>, k: usize, x: DVec3, best: &mut Nearest) {
    let nodes = &set.bvh.nodes;
    if nodes.is_empty() {
        return;
    }
    let mut stack: [(u32, f64); 128] = [(0, 0.0); 128];
    let mut top = 1;
    stack[0] = (0, nodes[0].distance(x).0);
    while top > 0 {
        top -= 1;
        let (i, r) = stack[top];
        best.nodes += 1;
        if r >= best.d {
            continue;
        }
        let node = &nodes[i as usize];
        if node.is_leaf() {
            let first = node.index as usize;
            for j in first..first + node.count as usize {
                let c = set.prims[j].closest_point(x);
                let d = (x - c).length();
                if d < best.d {
                    *best = Nearest {
                        d,
                        point: c,
                        set: k,
                        index: set.source_index(j),
                        nodes: best.nodes,
                    };
                }
            }
            continue;
        }
        let (l, rr) = (i + 1, node.index);
        let dl = nodes[l as usize].distance(x).0;
        let dr = nodes[rr as usize].distance(x).0;
        let (first, second) = if dl <= dr {
            ((rr, dr), (l, dl))
        } else {
            ((l, dl), (rr, dr))
        };
        stack[top] = first;
        stack[top + 1] = second;
        top += 2;
    }
}
