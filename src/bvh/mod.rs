//! Bounding volume hierarchy over primitives (SPEC 6): binned-SAH build in parallel,
//! depth-first node layout, several primitives per leaf.
//!
//! Node `i`'s left child is `i + 1`, its right child `right`. A leaf covers the
//! primitives `first .. first + count` of the reordered primitive array. Every node
//! stores its primitive count (the `n` of a Barnes-Hut far-field term) and the length
//! of its box diagonal (the `diam(B)` of the opening criterion).

mod bins;
mod build;
pub mod moments;
mod range;
mod sweep;
mod validate;
pub mod wide;

pub use build::{
    BuildOptions, build, build_binary, build_binary_points, build_binary_points_with, build_with,
};
pub use moments::Moments4;
pub use validate::validate;
pub use wide::{Node4, Root};

use glam::{DVec3, Vec3};

/// One BVH node (40 bytes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Node {
    pub min: Vec3,
    pub max: Vec3,
    /// Leaf: index of the first primitive. Inner: index of the right child.
    pub index: u32,
    /// Leaf: number of primitives (>= 1). Inner: 0.
    pub count: u32,
    /// Number of primitives in the subtree.
    pub size: u32,
    /// Length of the box diagonal.
    pub diam: f32,
}

impl Node {
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }

    /// Squared distance from `x` to the box (0 inside), in f64: traversal decisions
    /// compare squares and take no square root.
    #[inline]
    pub fn distance_squared(&self, x: DVec3) -> f64 {
        let c = x.clamp(self.min.as_dvec3(), self.max.as_dvec3());
        (x - c).length_squared()
    }

    /// Distance from `x` to the box (0 inside) and the closest box point, in f64.
    #[inline]
    pub fn distance(&self, x: DVec3) -> (f64, DVec3) {
        crate::geometry::closest::closest_on_box(x, self.min.as_dvec3(), self.max.as_dvec3())
    }
}

/// A built hierarchy; `order[i]` is the input index of the `i`-th primitive in leaf
/// order.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    pub nodes: Vec<Node>,
    pub order: Vec<u32>,
    /// The same tree 4 wide, for the smooth-distance traversal (`wide`): its root as a
    /// child slot (`None` when empty) and its nodes.
    pub wide_root: Option<Root>,
    pub wide: Vec<Node4>,
    /// Second moments of each wide slot's points (`moments`; sets of points only, else
    /// empty): the far-field bound of point clouds.
    pub moments: Vec<Moments4>,
}

impl Bvh {
    pub fn root(&self) -> &Node {
        &self.nodes[0]
    }

    pub fn depth(&self) -> usize {
        fn rec(nodes: &[Node], i: usize) -> usize {
            let n = &nodes[i];
            if n.is_leaf() {
                1
            } else {
                1 + rec(nodes, i + 1).max(rec(nodes, n.index as usize))
            }
        }
        if self.nodes.is_empty() {
            0
        } else {
            rec(&self.nodes, 0)
        }
    }

    pub fn leaf_count(&self) -> usize {
        self.nodes.iter().filter(|n| n.is_leaf()).count()
    }

    /// Builds the 4-wide form the smooth-distance traversal walks (`wide`).
    pub fn make_wide(&mut self) {
        (self.wide_root, self.wide) = wide::collapse(&self.nodes);
    }

    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node>()
            + self.wide.len() * std::mem::size_of::<Node4>()
            + self.moments.len() * std::mem::size_of::<Moments4>()
            + self.order.len() * 4
    }
}
