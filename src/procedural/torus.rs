//! Triangle torus around the y axis (SPEC 10, "Torus": 1152 triangles).
//!
//! `major_segments x minor_segments` vertices on the surface
//! `((R + r cos t) cos p, r sin t, (R + r cos t) sin p)`, every vertex shared by its six
//! triangles, two triangles per grid quad, wound so normals point out of the tube. The
//! defaults 32 x 18 give 576 vertices and 1152 triangles; the mesh is closed (every edge
//! in exactly two triangles).

use crate::mesh::Mesh;
use glam::Vec3;
use std::f32::consts::TAU;

/// A closed torus of `2 * major_segments * minor_segments` triangles.
///
/// Expects `0 < minor_radius < major_radius` and both counts `>= 3` (checked by
/// [`super::Generator::build`]); panics if a count is below 3.
pub fn torus(
    major_radius: f32,
    minor_radius: f32,
    major_segments: usize,
    minor_segments: usize,
) -> Mesh {
    assert!(
        major_segments >= 3 && minor_segments >= 3,
        "torus needs >= 3 segments"
    );
    let (m, n) = (major_segments, minor_segments);
    let index = |i: usize, j: usize| ((i % m) * n + (j % n)) as u32;

    let mut vertices = Vec::with_capacity(m * n);
    for i in 0..m {
        let (sp, cp) = (TAU * i as f32 / m as f32).sin_cos();
        for j in 0..n {
            let (st, ct) = (TAU * j as f32 / n as f32).sin_cos();
            let ring = major_radius + minor_radius * ct;
            vertices.push(Vec3::new(ring * cp, minor_radius * st, ring * sp));
        }
    }

    // d/dt x d/dp points out of the tube, so each quad goes (i,j) -> (i,j+1) -> (i+1,j+1).
    let mut triangles = Vec::with_capacity(2 * m * n);
    for i in 0..m {
        for j in 0..n {
            let (a, b, c, d) = (
                index(i, j),
                index(i, j + 1),
                index(i + 1, j + 1),
                index(i + 1, j),
            );
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }

    Mesh {
        vertices,
        segments: Vec::new(),
        triangles,
        name: "torus".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::procedural::check::*;

    #[test]
    fn default_counts() {
        let t = torus(1.0, 0.25, 32, 18);
        assert_eq!(t.vertices.len(), 576);
        assert_eq!(t.triangles.len(), 1152);
        assert!(t.segments.is_empty());
        // Euler characteristic of a torus: V - E + F = 0.
        assert_eq!(t.triangle_edges().len(), 576 + 1152);
    }

    #[test]
    fn closed_outward_and_not_degenerate() {
        for (m, n) in [(32, 18), (3, 3), (7, 5)] {
            let t = torus(1.0, 0.25, m, n);
            assert_eq!(t.vertices.len(), m * n);
            assert_eq!(t.triangles.len(), 2 * m * n);
            assert_closed_oriented(&t);
            assert!(min_triangle_area(&t) > 1e-4, "{m}x{n}");
            assert!(signed_volume(&t) > 0.0, "{m}x{n}: wound inward");
            assert!(min_vertex_distance(&t.vertices) > 1e-3);
        }
    }

    #[test]
    fn normals_point_away_from_the_tube_centre() {
        let (r_major, r_minor) = (2.0, 0.5);
        let t = torus(r_major, r_minor, 12, 8);
        for tri in &t.triangles {
            let [a, b, c] = tri.map(|i| t.vertices[i as usize]);
            let centroid = (a + b + c) / 3.0;
            let axis = Vec3::new(centroid.x, 0.0, centroid.z).normalize() * r_major;
            let n = (b - a).cross(c - a);
            assert!(n.dot(centroid - axis) > 0.0, "inward triangle {tri:?}");
        }
    }

    #[test]
    fn vertices_on_the_tube() {
        let (r_major, r_minor) = (1.5, 0.4);
        let t = torus(r_major, r_minor, 10, 6);
        for v in &t.vertices {
            let ring = Vec3::new(v.x, 0.0, v.z).length();
            let d = ((ring - r_major).powi(2) + v.y * v.y).sqrt();
            assert_close("distance to the core circle", d, r_minor, 1e-5);
        }
    }
}
