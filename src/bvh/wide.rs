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

use super::Node;

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

/// Collapses a binary tree (depth-first layout: left child `i + 1`, right child
/// `index`) into wide nodes; the first wide node is the root's when the root is inner.
pub fn collapse(nodes: &[Node]) -> (Option<Root>, Vec<Node4>) {
    let Some(root) = nodes.first() else {
        return (None, Vec::new());
    };
    let mut wide = Vec::with_capacity(nodes.len() / 3 + 1);
    let child = if root.is_leaf() {
        root.index
    } else {
        push(nodes, 0, &mut wide)
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

/// Builds the wide node of binary inner node `i` (and those below it); returns its index.
fn push(nodes: &[Node], i: usize, wide: &mut Vec<Node4>) -> u32 {
    let at = wide.len();
    let mut out = Node4 {
        min: [[f32::INFINITY; 4]; 3],
        max: [[f32::NEG_INFINITY; 4]; 3],
        child: [0; 4],
        count: [EMPTY; 4],
        size: [0; 4],
        diam2: [0.0; 4],
        mid_diam2: [f32::INFINITY; 2],
        mid_size: [0; 2],
    };
    wide.push(out);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{BuildOptions, build};
    use crate::mesh::Aabb;
    use glam::Vec3;

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
