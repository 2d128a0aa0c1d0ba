//! The fast winding number on the BVH of a triangle set (Barill et al. 2018, section 3.3):
//! each node of the set's binary BVH gets the far field of its triangles
//! ([`super::expansion`]), built bottom-up by shifting the children's moments; a query
//! walks the tree from the root and decides per node:
//!
//! - far field: the node's radius `R` (about its area-weighted centroid `p`) satisfies
//!   `R < beta |q - p|`; its second-order expansion stands for all of its triangles
//!   (error of relative order `beta^3`);
//! - exact: a leaf that is not far: the solid angles of its triangles
//!   ([`super::exact::solid_angle`]);
//! - opened: both children are visited.
//!
//! `beta = 0` is the exact sum; `beta` is the reciprocal of libigl's `accuracy_scale`
//! (its default 2 is `beta = 0.5`). Nothing is pruned: every triangle's solid angle
//! counts, however far.

use super::exact::solid_angle;
use super::expansion::{FarField, Moments};
use super::lanes::FarNode;
use crate::bvh::Node;
use crate::primitives::{PrimitiveSet, Triangle};
use glam::DVec3;
use std::f64::consts::PI;

/// The far fields of every node of a triangle set's BVH (indexed like `bvh.nodes`).
#[derive(Clone, Debug, Default)]
pub struct WindingTree {
    pub far: Vec<FarField>,
    /// The same far fields as the batch's lanes read them (`super::lanes`: centre,
    /// radius and polynomial coefficients in 128 bytes).
    pub poly: Vec<FarNode>,
    /// What the batch walk reads per node, in 24 bytes.
    pub walk: Vec<WalkNode>,
}

/// A node as the batch walk reads it (`super::batch`): the far field's centre and
/// squared radius (as in [`FarField`]), and the BVH node's `index` and `count` (leaf:
/// first triangle and number of triangles; inner: right child and 0).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WalkNode {
    pub centre: [f32; 3],
    pub r2: f32,
    pub index: u32,
    pub count: u32,
}

impl WalkNode {
    /// The centre in f64.
    #[inline]
    pub fn centre(&self) -> DVec3 {
        glam::Vec3::from_array(self.centre).as_dvec3()
    }
}

impl WindingTree {
    /// Builds the far fields of `set`'s BVH nodes, children before parents: subtrees
    /// side by side in parallel (the depth-first layout puts a node's subtree in one
    /// range, its left child right after it), each small subtree by one loop from its
    /// last node back to its root.
    pub fn build(set: &PrimitiveSet<Triangle>) -> WindingTree {
        let nodes = &set.bvh.nodes;
        let mut far = vec![FarField::default(); nodes.len()];
        if !nodes.is_empty() {
            subtree(set, 0, &mut far);
        }
        // The exact radius of each node about its centre (tighter than the children's
        // reach): every node's triangles are a contiguous range in leaf order.
        let mut first = vec![0u32; nodes.len()];
        for i in (0..nodes.len()).rev() {
            first[i] = if nodes[i].is_leaf() {
                nodes[i].index
            } else {
                first[i + 1]
            };
        }
        use rayon::prelude::*;
        far.par_iter_mut().enumerate().for_each(|(i, f)| {
            let c = f.centre();
            let lo = first[i] as usize;
            let r2 = set.prims[lo..lo + nodes[i].size as usize]
                .iter()
                .flat_map(|t| [t.a, t.b, t.c])
                .map(|v| (v.as_dvec3() - c).length_squared())
                .fold(0.0f64, f64::max);
            f.r2 = grow(r2) as f32;
        });
        let poly = far.par_iter().map(FarNode::new).collect();
        let walk = far
            .iter()
            .zip(nodes)
            .map(|(f, n)| WalkNode {
                centre: f.centre,
                r2: f.r2,
                index: n.index,
                count: n.count,
            })
            .collect();
        WindingTree { far, poly, walk }
    }

    /// Heap memory, bytes.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.far.as_slice())
            + std::mem::size_of_val(self.poly.as_slice())
            + std::mem::size_of_val(self.walk.as_slice())
    }

    /// The winding number of `set` (the set this tree was built from) at `q`, with the
    /// far-field criterion `beta`; `stack` is scratch space, reused between queries.
    pub fn winding_number(
        &self,
        set: &PrimitiveSet<Triangle>,
        q: DVec3,
        beta: f64,
        stack: &mut Vec<u32>,
    ) -> f64 {
        self.winding_number_counted(set, q, beta, stack).0
    }

    /// [`Self::winding_number`] with the number of far fields and of exact solid angles
    /// it summed.
    pub fn winding_number_counted(
        &self,
        set: &PrimitiveSet<Triangle>,
        q: DVec3,
        beta: f64,
        stack: &mut Vec<u32>,
    ) -> (f64, u32, u32) {
        debug_assert_eq!(self.far.len(), set.bvh.nodes.len());
        let nodes = &set.bvh.nodes;
        if nodes.is_empty() {
            return (0.0, 0, 0);
        }
        let (mut fars, mut exacts) = (0u32, 0u32);
        let beta2 = beta * beta;
        let mut far_sum = 0.0;
        let mut angles = 0.0;
        stack.clear();
        stack.push(0);
        while let Some(i) = stack.pop() {
            let f = &self.far[i as usize];
            let r = f.centre() - q;
            let d2 = r.length_squared();
            if (f.r2 as f64) < beta2 * d2 {
                far_sum += f.eval(r, d2);
                fars += 1;
                continue;
            }
            let node = &nodes[i as usize];
            if node.is_leaf() {
                let first = node.index as usize;
                exacts += node.count;
                for t in &set.prims[first..first + node.count as usize] {
                    angles += solid_angle(q, t.a.as_dvec3(), t.b.as_dvec3(), t.c.as_dvec3());
                }
            } else {
                stack.push(node.index);
                stack.push(i + 1);
            }
        }
        (far_sum + angles / (4.0 * PI), fars, exacts)
    }
}

/// Subtrees with more nodes than this build their two halves in parallel.
const PARALLEL_MIN: usize = 2048;

/// Fills `far` (the far fields of the subtree of node `i`, which starts at `i` and spans
/// `far.len()` nodes) and returns the moments of node `i`.
fn subtree(set: &PrimitiveSet<Triangle>, i: usize, far: &mut [FarField]) -> Moments {
    let node = &set.bvh.nodes[i];
    if node.is_leaf() || far.len() <= PARALLEL_MIN {
        return serial(set, i, far);
    }
    let right = node.index as usize;
    let (head, rest) = far.split_at_mut(1);
    let (lf, rf) = rest.split_at_mut(right - i - 1);
    let (l, r) = rayon::join(|| subtree(set, i + 1, lf), || subtree(set, right, rf));
    let (m, r2) = inner(node, &l, &r, &lf[0], &rf[0]);
    head[0] = m.far_field(grow(r2));
    m
}

/// [`subtree`] in one loop over the nodes, last to first.
fn serial(set: &PrimitiveSet<Triangle>, root: usize, far: &mut [FarField]) -> Moments {
    let nodes = &set.bvh.nodes[root..root + far.len()];
    let mut moments: Vec<Moments> = vec![Moments::default(); far.len()];
    for k in (0..nodes.len()).rev() {
        let node = &nodes[k];
        let (m, r2) = if node.is_leaf() {
            leaf(set, node)
        } else {
            let right = node.index as usize - root;
            inner(
                node,
                &moments[k + 1],
                &moments[right],
                &far[k + 1],
                &far[right],
            )
        };
        far[k] = m.far_field(grow(r2));
        moments[k] = m;
    }
    moments[0]
}

/// The moments of an inner node from its children's (moments and far fields) and a
/// bound on its squared radius: every triangle lies within a child's radius of its
/// centre, and in the node's box.
fn inner(node: &Node, l: &Moments, r: &Moments, fl: &FarField, fr: &FarField) -> (Moments, f64) {
    let centre = centre_of(l.area_centroid + r.area_centroid, l.area + r.area, node);
    let mut m = l.shifted(centre);
    m.add(&r.shifted(centre));
    let reach = |f: &FarField| (f.centre() - centre).length() + (f.r2 as f64).sqrt();
    let radius = reach(fl).max(reach(fr));
    (m, radius.min(box_reach(node, centre)).powi(2))
}

/// The moments and squared radius of a leaf's triangles about their area-weighted
/// centroid (rounded to f32, the precision the far field stores it in).
fn leaf(set: &PrimitiveSet<Triangle>, node: &Node) -> (Moments, f64) {
    let first = node.index as usize;
    let tris = &set.prims[first..first + node.count as usize];
    let corners = |t: &Triangle| [t.a.as_dvec3(), t.b.as_dvec3(), t.c.as_dvec3()];
    let mut area = 0.0;
    let mut area_centroid = DVec3::ZERO;
    for t in tris {
        let [a, b, c] = corners(t);
        let ar = 0.5 * (b - a).cross(c - a).length();
        area += ar;
        area_centroid += ar * (a + b + c) / 3.0;
    }
    let centre = centre_of(area_centroid, area, node);
    let mut m = Moments {
        centre,
        ..Moments::default()
    };
    let mut r2 = 0.0f64;
    for t in tris {
        let [a, b, c] = corners(t);
        m.add(&Moments::triangle(a, b, c, centre));
        for v in [a, b, c] {
            r2 = r2.max((v - centre).length_squared());
        }
    }
    (m, r2)
}

/// The area-weighted centroid (the box centre when the area is 0), rounded to f32.
fn centre_of(area_centroid: DVec3, area: f64, node: &Node) -> DVec3 {
    let c = if area > 0.0 {
        area_centroid / area
    } else {
        (node.min.as_dvec3() + node.max.as_dvec3()) / 2.0
    };
    c.as_vec3().as_dvec3()
}

/// Distance from `c` to the farthest corner of the node's box.
fn box_reach(node: &Node, c: DVec3) -> f64 {
    let far = (c - node.min.as_dvec3())
        .abs()
        .max((node.max.as_dvec3() - c).abs());
    far.length()
}

/// A squared radius grown so that its f32 rounding (and the f32 centre) stays an upper
/// bound.
fn grow(r2: f64) -> f64 {
    r2 * (1.0 + 1e-5)
}
