//! A primitive set's colours in the layout the colour traversal reads: one linear colour
//! per primitive in BVH leaf order, and per BVH node the mean colour of the primitives
//! below it (what a far-field node contributes, SPEC 6's Barnes-Hut node term).
//!
//! Built only when an object is coloured; the geometry's own arrays are not touched.

use crate::mesh::Mesh;
use crate::primitives::{AnySet, PrimitiveKind};
use crate::rgb::Linear;

/// Colours of one primitive set.
#[derive(Clone, Debug, Default)]
pub struct SetColours {
    /// Colour of `set.prims[i]` (leaf order).
    pub prims: Vec<Linear>,
    /// Mean colour of the primitives below `set.bvh.nodes[k]`.
    pub nodes: Vec<Linear>,
}

/// Colours of every set of an object, in the object's set order.
#[derive(Clone, Debug, Default)]
pub struct ObjectColours {
    pub sets: Vec<SetColours>,
    /// Colour by the surface normal at the hit instead (`sets` is then empty).
    pub from_normal: bool,
}

impl SetColours {
    /// Colours for `set`, built from `mesh` (the mesh the set was built from) and one
    /// linear colour per vertex. A point takes its vertex's colour, an edge or triangle
    /// the mean of its vertices' colours.
    ///
    /// # Panics
    /// If `vertex_colours` does not have one entry per mesh vertex (a caller bug).
    pub fn build(set: &AnySet, mesh: &Mesh, vertex_colours: &[Linear]) -> SetColours {
        assert_eq!(vertex_colours.len(), mesh.vertices.len());
        let source: Vec<Linear> = match set.kind() {
            PrimitiveKind::Points => vertex_colours.to_vec(),
            PrimitiveKind::Edges => {
                // The same list, in the same order, that the edge set was built from.
                let list = if mesh.segments.is_empty() {
                    mesh.triangle_edges()
                } else {
                    mesh.segments.clone()
                };
                list.iter().map(|e| mean_of(e, vertex_colours)).collect()
            }
            PrimitiveKind::Triangles => mesh
                .triangles
                .iter()
                .map(|t| mean_of(t, vertex_colours))
                .collect(),
        };
        let order = &set.bvh().order;
        let prims: Vec<Linear> = order.iter().map(|&i| source[i as usize]).collect();
        let nodes = node_means(set, &prims);
        SetColours { prims, nodes }
    }
}

fn mean_of(indices: &[u32], colours: &[Linear]) -> Linear {
    let mut sum = [0.0f32; 3];
    for &i in indices {
        for (s, c) in sum.iter_mut().zip(colours[i as usize]) {
            *s += c;
        }
    }
    sum.map(|s| s / indices.len() as f32)
}

/// Each node's mean primitive colour. Nodes are in depth-first order (children after
/// their parent), so one pass from the back sees both children before the parent.
fn node_means(set: &AnySet, prims: &[Linear]) -> Vec<Linear> {
    let nodes = &set.bvh().nodes;
    // Sums in f64: a root over millions of primitives must not lose the small ones.
    let mut sums = vec![[0.0f64; 3]; nodes.len()];
    for k in (0..nodes.len()).rev() {
        let n = &nodes[k];
        let mut s = [0.0f64; 3];
        if n.is_leaf() {
            let first = n.index as usize;
            for c in &prims[first..first + n.count as usize] {
                for j in 0..3 {
                    s[j] += c[j] as f64;
                }
            }
        } else {
            let (l, r) = (sums[k + 1], sums[n.index as usize]);
            for j in 0..3 {
                s[j] = l[j] + r[j];
            }
        }
        sums[k] = s;
    }
    nodes
        .iter()
        .zip(&sums)
        .map(|(n, s)| s.map(|v| (v / n.size.max(1) as f64) as f32))
        .collect()
}
