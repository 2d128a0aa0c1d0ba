//! Icosphere with a radial spike at every vertex: a triangle mesh with extra edges.
//!
//! The icosahedron's 20 faces are split `subdivisions` times into four by their edge
//! midpoints (shared between the two faces of an edge), each new vertex pushed out to the
//! sphere of `radius`: `10 * 4^s + 2` vertices and `20 * 4^s` triangles, closed and wound
//! outward. Each sphere vertex then gets a segment to a new tip vertex `spike_length`
//! further out along its radius. The default (2 subdivisions) gives 162 sphere vertices +
//! 162 tips = 324 vertices, 320 triangles and 162 segments.

use crate::mesh::Mesh;
use glam::Vec3;
use std::collections::HashMap;

/// The icosahedron with vertices on the unit sphere, faces wound outward.
fn icosahedron() -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let phi = (1.0 + 5f32.sqrt()) / 2.0;
    let vertices = [
        [-1.0, phi, 0.0],
        [1.0, phi, 0.0],
        [-1.0, -phi, 0.0],
        [1.0, -phi, 0.0],
        [0.0, -1.0, phi],
        [0.0, 1.0, phi],
        [0.0, -1.0, -phi],
        [0.0, 1.0, -phi],
        [phi, 0.0, -1.0],
        [phi, 0.0, 1.0],
        [-phi, 0.0, -1.0],
        [-phi, 0.0, 1.0],
    ]
    .map(|p| Vec3::from_array(p).normalize())
    .to_vec();
    let faces = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    (vertices, faces)
}

/// Splits every triangle into four by its edge midpoints, projected to the unit sphere.
/// Midpoints are cached per undirected edge so neighbouring faces share them.
fn subdivide(vertices: &mut Vec<Vec3>, faces: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut midpoints: HashMap<(u32, u32), u32> = HashMap::with_capacity(faces.len() * 3 / 2);
    let mut midpoint = |a: u32, b: u32, vertices: &mut Vec<Vec3>| -> u32 {
        *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
            let m = (vertices[a as usize] + vertices[b as usize]).normalize();
            vertices.push(m);
            (vertices.len() - 1) as u32
        })
    };
    let mut out = Vec::with_capacity(faces.len() * 4);
    for &[a, b, c] in faces {
        let ab = midpoint(a, b, vertices);
        let bc = midpoint(b, c, vertices);
        let ca = midpoint(c, a, vertices);
        out.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
    }
    out
}

/// The spiky sphere: `10 * 4^s + 2` sphere vertices (indices first) then as many tips,
/// `20 * 4^s` triangles, one segment per sphere vertex.
///
/// Expects `radius > 0` and `spike_length > 0` (checked by [`super::Generator::build`]).
pub fn spiky_sphere(radius: f32, subdivisions: usize, spike_length: f32) -> Mesh {
    let (mut vertices, mut triangles) = icosahedron();
    for _ in 0..subdivisions {
        triangles = subdivide(&mut vertices, &triangles);
    }
    let n = vertices.len();
    for v in &mut vertices {
        *v *= radius;
    }
    let tip_scale = (radius + spike_length) / radius;
    vertices.extend_from_within(..);
    for tip in &mut vertices[n..] {
        *tip *= tip_scale;
    }
    let segments = (0..n as u32).map(|i| [i, i + n as u32]).collect();
    Mesh {
        vertices,
        segments,
        triangles,
        name: "spiky_sphere".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::procedural::check::*;

    #[test]
    fn default_counts() {
        let m = spiky_sphere(1.0, 2, 0.5);
        assert_eq!(m.vertices.len(), 2 * 162);
        assert_eq!(m.triangles.len(), 320);
        assert_eq!(m.segments.len(), 162);
        assert_eq!(m.triangle_edges().len(), 480);
    }

    #[test]
    fn closed_outward_on_the_sphere() {
        for s in 0..=4 {
            let radius = 2.0;
            let m = spiky_sphere(radius, s, 0.3);
            let sphere = 10 * 4usize.pow(s as u32) + 2;
            assert_eq!(m.vertices.len(), 2 * sphere, "s = {s}");
            assert_eq!(m.triangles.len(), 20 * 4usize.pow(s as u32));
            assert_closed_oriented(&m);
            assert!(signed_volume(&m) > 0.0, "s = {s}: wound inward");
            assert!(min_triangle_area(&m) > 1e-4, "s = {s}");
            for t in &m.triangles {
                assert!(t.iter().all(|&i| (i as usize) < sphere));
                // Outward: each face normal agrees with its centroid's direction.
                let [a, b, c] = t.map(|i| m.vertices[i as usize]);
                assert!((b - a).cross(c - a).dot(a + b + c) > 0.0);
            }
            for v in &m.vertices[..sphere] {
                assert_close("sphere radius", v.length(), radius, 1e-5);
            }
            if s <= 3 {
                assert!(min_vertex_distance(&m.vertices[..sphere]) > 1e-2);
            }
        }
    }

    #[test]
    fn spikes_are_radial() {
        let (radius, len) = (1.5, 0.5);
        let m = spiky_sphere(radius, 1, len);
        let n = m.vertices.len() / 2;
        assert_eq!(unique_segments(&m).len(), n);
        for (i, &[a, b]) in m.segments.iter().enumerate() {
            assert_eq!((a as usize, b as usize), (i, i + n));
            let (p, q) = (m.vertices[a as usize], m.vertices[b as usize]);
            assert_close("tip radius", q.length(), radius + len, 1e-5);
            assert_close("spike length", p.distance(q), len, 1e-5);
            assert!(p.normalize().dot(q.normalize()) > 1.0 - 1e-6);
        }
    }
}
