//! Exact nearest primitive on the wide BVH: depth-first, nearest slot first, pruning
//! boxes no closer than the best distance found (squared distances, no square root until
//! the end). A query may start from a hint, a primitive near it (the previous query's
//! answer in a batch sorted along a Morton curve, `api::queries`): its exact distance
//! is an upper bound of the answer from the start, so the walk opens only boxes closer
//! than it; the answer is the same primitive distance either way (ties may name another
//! primitive at the same distance).

use crate::bvh::wide::EMPTY;
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
    /// Position of the primitive in its set's leaf order (`u32::MAX` when none): the
    /// hint a next query can start from.
    pub leaf: u32,
}

impl Nearest {
    fn none(bound: f64) -> Nearest {
        Nearest {
            d: bound,
            point: DVec3::splat(f64::NAN),
            set: usize::MAX,
            index: u32::MAX,
            nodes: 0,
            leaf: u32::MAX,
        }
    }
}

/// Nearest primitive among `sets` (`d = +inf` if all sets are empty).
pub fn nearest(sets: &[&AnySet], x: DVec3) -> Nearest {
    nearest_within(sets, x, f64::INFINITY)
}

/// Nearest primitive closer than `bound` (returns `d = bound`, `index = u32::MAX` when
/// nothing is closer): a bounded query prunes more.
pub fn nearest_within(sets: &[&AnySet], x: DVec3, bound: f64) -> Nearest {
    let mut best = Nearest::none(bound);
    let mut d2 = bound * bound;
    let mut stack = Vec::new();
    for (k, set) in sets.iter().enumerate() {
        crate::with_set!(set, s => search(s, k, x, &mut best, &mut d2, &mut stack));
    }
    best.d = if best.leaf == u32::MAX {
        bound
    } else {
        d2.sqrt()
    };
    best
}

/// [`nearest`] starting from `hint` (an earlier answer among the same `sets`, or
/// [`Nearest::none`]-like with `leaf = u32::MAX`), with a reusable traversal stack.
pub fn nearest_from(
    sets: &[&AnySet],
    x: DVec3,
    hint: &Nearest,
    stack: &mut Vec<(u32, u32, f64)>,
) -> Nearest {
    let mut best = Nearest::none(f64::INFINITY);
    let mut d2 = f64::INFINITY;
    if let Some(set) = sets.get(hint.set).filter(|_| hint.leaf != u32::MAX) {
        crate::with_set!(set, s => consider(s, hint.set, hint.leaf as usize, x, &mut best, &mut d2));
    }
    for (k, set) in sets.iter().enumerate() {
        crate::with_set!(set, s => search(s, k, x, &mut best, &mut d2, stack));
    }
    best.d = d2.sqrt();
    best
}

/// Takes primitive `j` (leaf order) of set `k` if it is closer than the best so far.
#[inline]
fn consider<P: Primitive>(
    set: &PrimitiveSet<P>,
    k: usize,
    j: usize,
    x: DVec3,
    best: &mut Nearest,
    d2: &mut f64,
) {
    let c = set.prims[j].closest_point(x);
    let e2 = (x - c).length_squared();
    if e2 < *d2 {
        *d2 = e2;
        *best = Nearest {
            d: 0.0,
            point: c,
            set: k,
            index: set.source_index(j),
            nodes: best.nodes,
            leaf: j as u32,
        };
    }
}

/// The walk over one set's wide tree: stack entries are (node or first primitive,
/// primitive count or 0 for a node, squared distance to the box).
fn search<P: Primitive>(
    set: &PrimitiveSet<P>,
    k: usize,
    x: DVec3,
    best: &mut Nearest,
    d2: &mut f64,
    stack: &mut Vec<(u32, u32, f64)>,
) {
    let Some(root) = set.bvh.wide_root else {
        return;
    };
    let (lo, hi) = (
        DVec3::from(root.min.map(f64::from)),
        DVec3::from(root.max.map(f64::from)),
    );
    stack.clear();
    stack.push((
        root.child,
        root.count,
        (x - x.clamp(lo, hi)).length_squared(),
    ));
    let wide = &set.bvh.wide;
    while let Some((i, count, r2)) = stack.pop() {
        best.nodes += 1;
        if r2 >= *d2 {
            continue;
        }
        if count > 0 {
            for j in i as usize..(i + count) as usize {
                consider(set, k, j, x, best, d2);
            }
            continue;
        }
        let node = &wide[i as usize];
        let dist = node.distances2(x);
        // The slots to open, farthest first on the stack (the nearest is popped next).
        let mut open = [(0.0f64, 0usize); 4];
        let mut n = 0;
        for (s, &r) in dist.iter().enumerate() {
            if node.count[s] != EMPTY && r < *d2 {
                let mut h = n;
                while h > 0 && open[h - 1].0 < r {
                    open[h] = open[h - 1];
                    h -= 1;
                }
                open[h] = (r, s);
                n += 1;
            }
        }
        for &(r, s) in &open[..n] {
            stack.push((node.child[s], node.count[s], r));
        }
    }
}
