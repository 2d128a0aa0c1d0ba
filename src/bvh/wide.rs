//! A 4-wide copy of the binary BVH for the smooth-distance traversal (SPEC 6).
//!
//! A wide node stands for one inner node `b` of the binary tree. It stores `b`'s two
//! children (the "middles": subtree size and squared diagonal) and their children, up
//! to four slots side by side (structure of arrays): box, subtree size, squared
//! diagonal, and either the index of the wide node below or, for a leaf, its range of
//! primitives. Slots 0 and 1 belong to middle 0, slots 2 and 3 to middle 1; a middle
//! that is a binary leaf takes its first slot itself (the second is unused, and its
//! diagonal is `+inf`, so it is never a far-field term). One visit tests four boxes at
//! once, the traversal pops half as many nodes, and the boxes it tests next sit
//! together in memory.
//!
//! The traversal makes the binary tree's decisions: a middle is far field when its
//! diagonal is below `beta r`, with `r` the distance to the nearer of its two
//! children's boxes (every primitive below it lies in one of them, so the far term
//! `n w exp(-alpha r)` still dominates their sum, and `r` is at least the distance to
//! the middle's own box: a tighter term than the binary tree's).
//!
//! The wide nodes are laid out depth-first (a node, then its inner slots' subtrees in
//! slot order). Large subtrees are collapsed in parallel: their wide-node counts are
//! taken first, so each slot's subtree is written into its own part of the array, in
//! the same layout as one depth-first pass.

use super::Node;
use glam::DVec3;
use rayon::prelude::*;

/// A child slot: the child is a leaf when `count > 0`.
pub const EMPTY: u32 = u32::MAX;

/// Four children of a node, structure of arrays. Unused slots have `count = EMPTY` and
/// an empty (inverted) box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Node4 {
    pub min: [[f32; 4]; 3],
    pub max: [[f32; 4]; 3],
    /// Inner child: index of its wide node. Leaf child: index of its first primitive.
    pub child: [u32; 4],
    /// Leaf child: number of primitives (>= 1). Inner child: 0. Unused slot: `EMPTY`.
    pub count: [u32; 4],
    /// Number of primitives below the child.
    pub size: [u32; 4],
    /// Squared length of the child's box diagonal.
    pub diam2: [f32; 4],
    /// Squared diagonal of the middles (`+inf` for a middle that is a leaf in its slot).
    pub mid_diam2: [f32; 2],
    /// Number of primitives below each middle.
    pub mid_size: [u32; 2],
}

impl Node4 {
    /// The box of slot `k`, in f64.
    #[inline]
    pub fn slot_box(&self, k: usize) -> (DVec3, DVec3) {
        (
            DVec3::new(
                self.min[0][k] as f64,
                self.min[1][k] as f64,
                self.min[2][k] as f64,
            ),
            DVec3::new(
                self.max[0][k] as f64,
                self.max[1][k] as f64,
                self.max[2][k] as f64,
            ),
        )
    }

    /// Squared distances from `x` to the four child boxes of a wide node (0 inside; `+inf`
    /// for an unused slot, whose box is inverted), in f64, four lanes at a time.
    #[inline(always)]
    pub fn distances2(&self, x: DVec3) -> [f64; 4] {
        let mut d2 = [0.0f64; 4];
        for (a, xa) in x.to_array().into_iter().enumerate() {
            for (k, d2k) in d2.iter_mut().enumerate() {
                let below = self.min[a][k] as f64 - xa;
                let above = xa - self.max[a][k] as f64;
                let d = if below > above { below } else { above };
                let d = if d > 0.0 { d } else { 0.0 };
                *d2k += d * d;
            }
        }
        d2
    }
}

/// The root of the wide tree as a child slot (the traversal starts from it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Root {
    pub min: [f32; 3],
    pub max: [f32; 3],
    pub child: u32,
    pub count: u32,
    pub size: u32,
    pub diam2: f32,
}

/// Subtrees of at least this many primitives are collapsed in parallel: their slots'
/// wide subtrees are counted first, then written side by side into disjoint parts of
/// the output.
const PARALLEL_MIN: u32 = 64 * 1024;

/// Collapses a binary tree (depth-first layout: left child `i + 1`, right child
/// `index`) into wide nodes, laid out depth-first (a wide node, then the wide subtrees
/// of its inner slots in slot order); the first wide node is the root's when the root
/// is inner.
pub fn collapse(nodes: &[Node]) -> (Option<Root>, Vec<Node4>) {
    collapse_with(nodes, PARALLEL_MIN)
}

/// [`collapse`], in parallel for subtrees of at least `parallel_min` primitives (the
/// result does not depend on it).
fn collapse_with(nodes: &[Node], parallel_min: u32) -> (Option<Root>, Vec<Node4>) {
    let Some(root) = nodes.first() else {
        return (None, Vec::new());
    };
    let mut wide = Vec::new();
    let child = if root.is_leaf() {
        root.index
    } else {
        let plan = plan(nodes, 0, parallel_min);
        // Touched in parallel: the pages are faulted in by both threads at once.
        wide.par_extend(rayon::iter::repeat_n(UNUSED, plan.count()));
        write(nodes, 0, &plan, &mut wide, 0);
        0
    };
    let r = Root {
        min: root.min.to_array(),
        max: root.max.to_array(),
        child,
        count: root.count,
        size: root.size,
        diam2: root.diam * root.diam,
    };
    (Some(r), wide)
}

/// A wide node with every slot unused.
const UNUSED: Node4 = Node4 {
    min: [[f32::INFINITY; 4]; 3],
    max: [[f32::NEG_INFINITY; 4]; 3],
    child: [0; 4],
    count: [EMPTY; 4],
    size: [0; 4],
    diam2: [0.0; 4],
    mid_diam2: [f32::INFINITY; 2],
    mid_size: [0; 2],
};

/// The binary nodes in the slots of binary inner node `i`'s wide node, slot by slot
/// (`None` for an unused slot): its children's children, or a child itself when it is
/// a leaf.
fn slots(nodes: &[Node], i: usize) -> [Option<usize>; 4] {
    let mut out = [None; 4];
    for (j, m) in [i + 1, nodes[i].index as usize].into_iter().enumerate() {
        let mn = &nodes[m];
        if mn.is_leaf() {
            out[2 * j] = Some(m);
        } else {
            out[2 * j] = Some(m + 1);
            out[2 * j + 1] = Some(mn.index as usize);
        }
    }
    out
}

/// The binary inner nodes in the slots of binary inner node `i`'s wide node, in slot
/// order: each heads a wide subtree below it.
fn inner_slots(nodes: &[Node], i: usize) -> impl Iterator<Item = usize> + '_ {
    slots(nodes, i)
        .into_iter()
        .flatten()
        .filter(|&c| !nodes[c].is_leaf())
}

/// Binary inner node `i`'s wide node with its slots filled; `child(c)` gives the index
/// of the wide node of each inner slot's binary node `c`, called in slot order.
fn wide_node(nodes: &[Node], i: usize, mut child: impl FnMut(usize) -> u32) -> Node4 {
    let mut out = UNUSED;
    for (j, m) in [i + 1, nodes[i].index as usize].into_iter().enumerate() {
        let mn = &nodes[m];
        out.mid_size[j] = mn.size;
        if !mn.is_leaf() {
            out.mid_diam2[j] = mn.diam * mn.diam;
        }
    }
    for (k, c) in slots(nodes, i).into_iter().enumerate() {
        let Some(c) = c else { continue };
        let cn = &nodes[c];
        for a in 0..3 {
            out.min[a][k] = cn.min[a];
            out.max[a][k] = cn.max[a];
        }
        out.size[k] = cn.size;
        out.diam2[k] = cn.diam * cn.diam;
        if cn.is_leaf() {
            out.child[k] = cn.index;
            out.count[k] = cn.count;
        } else {
            out.count[k] = 0;
            out.child[k] = child(c);
        }
    }
    out
}

/// How the wide subtree of a binary inner node is written: serially, or (for large
/// subtrees) its inner slots' subtrees in parallel, each with its own plan.
enum Plan {
    Serial {
        count: usize,
    },
    Parallel {
        count: usize,
        below: Vec<(usize, Plan)>,
    },
}

impl Plan {
    /// Number of wide nodes in the subtree.
    fn count(&self) -> usize {
        match self {
            Plan::Serial { count } | Plan::Parallel { count, .. } => *count,
        }
    }
}

/// The plan of binary inner node `i`'s wide subtree (counting it takes one pass over
/// the binary subtree, in parallel above `parallel_min` primitives).
fn plan(nodes: &[Node], i: usize, parallel_min: u32) -> Plan {
    if nodes[i].size < parallel_min {
        return Plan::Serial {
            count: count(nodes, i),
        };
    }
    let inner: Vec<usize> = inner_slots(nodes, i).collect();
    let below: Vec<(usize, Plan)> = inner
        .into_par_iter()
        .map(|c| (c, plan(nodes, c, parallel_min)))
        .collect();
    Plan::Parallel {
        count: 1 + below.iter().map(|(_, p)| p.count()).sum::<usize>(),
        below,
    }
}

/// Number of wide nodes made from binary inner node `i`'s subtree.
fn count(nodes: &[Node], i: usize) -> usize {
    1 + inner_slots(nodes, i)
        .map(|c| count(nodes, c))
        .sum::<usize>()
}

/// Writes binary inner node `i`'s wide subtree into `out` (exactly `plan.count()`
/// nodes), whose first node has index `at` in the whole array.
fn write(nodes: &[Node], i: usize, plan: &Plan, out: &mut [Node4], at: u32) {
    let below = match plan {
        Plan::Serial { .. } => {
            write_serial(nodes, i, out, at);
            return;
        }
        Plan::Parallel { below, .. } => below,
    };
    let (head, mut rest) = out.split_first_mut().expect("a wide node per plan");
    // Each inner slot's subtree takes the next `count` nodes, in slot order.
    let mut parts = Vec::with_capacity(below.len());
    let mut start = at + 1;
    for (c, p) in below {
        let (part, tail) = std::mem::take(&mut rest).split_at_mut(p.count());
        parts.push((*c, p, part, start));
        start += p.count() as u32;
        rest = tail;
    }
    let mut starts = parts.iter().map(|&(c, _, _, start)| (c, start));
    *head = wide_node(nodes, i, |c| {
        let (planned, start) = starts.next().expect("a plan per inner slot");
        debug_assert_eq!(planned, c);
        start
    });
    parts
        .into_par_iter()
        .for_each(|(c, p, part, start)| write(nodes, c, p, part, start));
}

/// [`write`] in one thread; returns the number of wide nodes written.
fn write_serial(nodes: &[Node], i: usize, out: &mut [Node4], at: u32) -> usize {
    let mut next = 1;
    let node = wide_node(nodes, i, |c| {
        let start = at + next as u32;
        next += write_serial(nodes, c, &mut out[next..], start);
        start
    });
    out[0] = node;
    next
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{BuildOptions, build};
    use crate::mesh::Aabb;
    use glam::Vec3;

    /// The collapse as first written, serial and recursive, pushing each node before
    /// its subtrees: the reference the parallel collapse must reproduce exactly.
    fn collapse_pushing(nodes: &[Node]) -> Vec<Node4> {
        fn push(nodes: &[Node], i: usize, wide: &mut Vec<Node4>) -> u32 {
            let at = wide.len();
            wide.push(UNUSED);
            let mut out = UNUSED;
            let n = &nodes[i];
            for (j, m) in [i + 1, n.index as usize].into_iter().enumerate() {
                let mn = &nodes[m];
                out.mid_size[j] = mn.size;
                let slots: &[usize] = if mn.is_leaf() {
                    &[m]
                } else {
                    out.mid_diam2[j] = mn.diam * mn.diam;
                    &[m + 1, mn.index as usize]
                };
                for (h, &c) in slots.iter().enumerate() {
                    let k = 2 * j + h;
                    let cn = &nodes[c];
                    for a in 0..3 {
                        out.min[a][k] = cn.min[a];
                        out.max[a][k] = cn.max[a];
                    }
                    out.size[k] = cn.size;
                    out.diam2[k] = cn.diam * cn.diam;
                    if cn.is_leaf() {
                        out.child[k] = cn.index;
                        out.count[k] = cn.count;
                    } else {
                        out.count[k] = 0;
                        out.child[k] = push(nodes, c, wide);
                    }
                }
            }
            wide[at] = out;
            at as u32
        }
        let mut wide = Vec::new();
        if nodes.first().is_some_and(|r| !r.is_leaf()) {
            push(nodes, 0, &mut wide);
        }
        wide
    }

    /// A random binary tree over `n` primitives in depth-first layout: random split
    /// positions (so chains, lopsided and balanced parts all occur), leaves of 1 to 4
    /// primitives, random boxes.
    fn random_tree(n: u32, rnd: &mut impl FnMut() -> f32) -> Vec<Node> {
        fn grow(first: u32, n: u32, rnd: &mut impl FnMut() -> f32, out: &mut Vec<Node>) {
            let lo = Vec3::new(rnd(), rnd(), rnd());
            let hi = lo + Vec3::new(rnd(), rnd(), rnd());
            let leaf = n <= 4 && (n == 1 || rnd() < 0.5);
            let here = out.len();
            out.push(Node {
                min: lo,
                max: hi,
                index: first,
                count: if leaf { n } else { 0 },
                size: n,
                diam: (hi - lo).length(),
            });
            if !leaf {
                let left = 1 + ((rnd() * (n - 1) as f32) as u32).min(n - 2);
                grow(first, left, rnd, out);
                out[here].index = out.len() as u32;
                grow(first + left, n - left, rnd, out);
            }
        }
        let mut out = Vec::new();
        grow(0, n, rnd, &mut out);
        out
    }

    #[test]
    fn parallel_collapse_equals_the_serial_one_on_random_trees() {
        let mut seed = 3u32;
        let mut rnd = move || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1 << 24) as f32
        };
        for n in [1u32, 2, 3, 4, 5, 9, 40, 1000, 20_000] {
            for _ in 0..3 {
                let nodes = random_tree(n, &mut rnd);
                let expected = collapse_pushing(&nodes);
                // Every split threshold, down to every node of the tree in parallel.
                for parallel_min in [1, 2, 5, 64, 1000, PARALLEL_MIN] {
                    let (root, wide) = collapse_with(&nodes, parallel_min);
                    assert_eq!(wide, expected, "n = {n}, parallel from {parallel_min}");
                    let root = root.unwrap();
                    // The root's wide node comes first; a leaf root's range starts at 0.
                    assert_eq!((root.child, root.size), (0, n));
                }
            }
        }
        // A built tree large enough for the default threshold to split it.
        let pts: Vec<Vec3> = (0..150_000)
            .map(|_| Vec3::new(rnd(), rnd(), 0.1 * rnd()))
            .collect();
        let bvh = crate::bvh::build_binary_points(&pts, BuildOptions::default());
        assert!(bvh.nodes[0].size >= 2 * PARALLEL_MIN);
        let expected = collapse_pushing(&bvh.nodes);
        for parallel_min in [1, 100, PARALLEL_MIN] {
            assert_eq!(collapse_with(&bvh.nodes, parallel_min).1, expected);
        }
    }

    #[test]
    fn wide_tree_covers_every_primitive_once_with_the_binary_boxes() {
        let mut seed = 7u32;
        let mut rnd = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1 << 24) as f32
        };
        for n in [1usize, 2, 3, 5, 17, 1000] {
            let pts: Vec<Vec3> = (0..n).map(|_| Vec3::new(rnd(), rnd(), rnd())).collect();
            let bounds: Vec<Aabb> = pts.iter().map(|&p| Aabb { min: p, max: p }).collect();
            let bvh = build(&bounds, &pts, BuildOptions::default());
            let (root, wide) = collapse(&bvh.nodes);
            let root = root.unwrap();
            assert_eq!(root.size as usize, n);
            let mut seen = vec![0u32; n];
            // Walk the wide tree; every child's box must contain its primitives and its
            // size must be the number of primitives below it.
            fn walk(wide: &[Node4], at: u32, seen: &mut [u32], pts: &[Vec3]) -> u32 {
                let node = &wide[at as usize];
                let mut total = 0;
                for k in 0..4 {
                    let below = match node.count[k] {
                        EMPTY => continue,
                        0 => walk(wide, node.child[k], seen, pts),
                        c => {
                            for i in node.child[k]..node.child[k] + c {
                                seen[i as usize] += 1;
                                let p = pts[i as usize];
                                for a in 0..3 {
                                    assert!(node.min[a][k] <= p[a] && p[a] <= node.max[a][k]);
                                }
                            }
                            c
                        }
                    };
                    assert_eq!(below, node.size[k]);
                    total += below;
                }
                total
            }
            let sorted: Vec<Vec3> = bvh.order.iter().map(|&i| pts[i as usize]).collect();
            if root.count == 0 {
                assert_eq!(walk(&wide, root.child, &mut seen, &sorted) as usize, n);
                assert!(wide.len() < bvh.nodes.len().max(1));
            } else {
                assert!(wide.is_empty());
                seen.iter_mut().for_each(|s| *s += 1);
            }
            assert!(seen.iter().all(|&s| s == 1), "n = {n}");
        }
    }
}
