//! The boundary curve of a triangle soup, and how fast the winding number can change
//! away from the surface.
//!
//! Each triangle's solid angle has the gradient of the Biot-Savart field of a unit
//! current around its edges, `grad Omega_t(q) = oint_{dt} (y - q) x dl / |y - q|^3` (up to
//! sign), so in the sum over a soup the edges traversed once in each direction cancel:
//! only the *boundary curve* is left, the edges whose directed counts do not cancel,
//! each with its net multiplicity `m_e`. Hence, off the surface,
//!
//! `|grad w(q)| <= 1/(4 pi) sum_e |m_e| int_e dl / |y - q|^2 <= L / (4 pi d(q)^2)`
//!
//! with `L = sum_e |m_e| |e|` and `d(q)` the distance from `q` to the curve. A closed,
//! consistently oriented mesh has no boundary (`L = 0`): its winding number is constant
//! (0 or 1) on each component of the complement of the surface. Vertices are matched by
//! position, so duplicated vertices do not make a seam look like a boundary.

use crate::bvh::BuildOptions;
use crate::eval;
use crate::mesh::Mesh;
use crate::primitives::{AnySet, Edge, PrimitiveSet};
use glam::{DVec3, Vec3};
use std::collections::HashMap;
use std::f64::consts::PI;

/// The boundary curve: its edges (with multiplicity folded into the length) and a BVH
/// over them for distance queries.
#[derive(Clone, Debug)]
pub struct Boundary {
    /// Net multiplicity times length, summed over the boundary edges.
    pub length: f64,
    /// Number of boundary edges.
    pub edges: usize,
    /// The edges as a primitive set (`None` when there are none).
    set: Option<AnySet>,
}

impl Boundary {
    /// The boundary curve of `mesh`'s triangles.
    pub fn of(mesh: &Mesh) -> Boundary {
        // Canonical vertex: the first with the same position.
        let mut first: HashMap<[u32; 3], u32> = HashMap::new();
        let canon: Vec<u32> = mesh
            .vertices
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let key = (*v + Vec3::ZERO).to_array().map(f32::to_bits); // -0 as +0
                *first.entry(key).or_insert(i as u32)
            })
            .collect();
        let mut net: HashMap<(u32, u32), i64> = HashMap::new();
        for t in &mesh.triangles {
            for k in 0..3 {
                let (u, v) = (canon[t[k] as usize], canon[t[(k + 1) % 3] as usize]);
                if u == v {
                    continue;
                }
                let (key, s) = if u < v { ((u, v), 1) } else { ((v, u), -1) };
                *net.entry(key).or_insert(0) += s;
            }
        }
        let mut length = 0.0;
        let mut prims = Vec::new();
        let mut keys: Vec<_> = net.into_iter().filter(|&(_, m)| m != 0).collect();
        keys.sort_unstable();
        for ((u, v), m) in keys {
            let (a, b) = (mesh.vertices[u as usize], mesh.vertices[v as usize]);
            length += m.unsigned_abs() as f64 * (b - a).as_dvec3().length();
            prims.push(Edge {
                a,
                b,
                val_a: 1.0,
                val_b: 1.0,
            });
        }
        let edges = prims.len();
        let set = (!prims.is_empty())
            .then(|| AnySet::Edges(PrimitiveSet::new(prims, 1.0, BuildOptions::default(), 0.0)));
        Boundary { length, edges, set }
    }

    /// True when the soup is closed (every edge cancels).
    pub fn is_closed(&self) -> bool {
        self.set.is_none()
    }

    /// Distance from `q` to the boundary curve (`+inf` when closed).
    pub fn distance(&self, q: DVec3) -> f64 {
        match &self.set {
            Some(s) => eval::nearest(&[s], q).d,
            None => f64::INFINITY,
        }
    }

    /// An upper bound of `|grad w|` at points at least `d` from the boundary curve.
    pub fn gradient_bound(&self, d: f64) -> f64 {
        if self.length == 0.0 {
            0.0
        } else if d > 0.0 {
            self.length / (4.0 * PI * d * d)
        } else {
            f64::INFINITY
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Mesh {
        Mesh {
            vertices,
            segments: vec![],
            triangles,
            name: "test".into(),
        }
    }

    #[test]
    fn a_tetrahedron_is_closed_and_one_face_has_its_perimeter() {
        let v = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        let tet = mesh(v.clone(), vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]);
        let b = Boundary::of(&tet);
        assert!(b.is_closed());
        assert_eq!(b.gradient_bound(0.0), 0.0);
        let one = mesh(v, vec![[0, 1, 2]]);
        let b = Boundary::of(&one);
        assert_eq!(b.edges, 3);
        assert!((b.length - (2.0 + 2f64.sqrt())).abs() < 1e-6);
        // Nearest boundary point: (0.25, 0, 0) on the edge along x.
        assert!((b.distance(DVec3::new(0.25, 0.25, 1.0)) - 1.0625f64.sqrt()).abs() < 1e-9);
    }

    #[test]
    fn duplicated_vertices_do_not_open_a_seam_and_doubled_faces_do_not_cancel() {
        // A tetrahedron whose face 3 uses copies of vertices 0 and 2.
        let v = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::ZERO, Vec3::Y];
        let tet = mesh(v.clone(), vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [4, 3, 5]]);
        assert!(Boundary::of(&tet).is_closed());
        let twice = mesh(v, vec![[0, 1, 2], [0, 1, 2]]);
        let b = Boundary::of(&twice);
        assert!((b.length - 2.0 * (2.0 + 2f64.sqrt())).abs() < 1e-6);
    }
}
