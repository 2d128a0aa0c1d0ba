//! Wireframe torus whose major and minor rings are hexagons (SPEC 10, "Hex Torus": 72
//! edges).
//!
//! Six hexagonal cross-sections of radius `minor_radius`, centred on a hexagon of radius
//! `major_radius` around the y axis: 6 x 6 = 36 vertices joined by 36 edges around the
//! major direction and 36 around the minor one, 72 segments, every vertex of valence 4.

use crate::mesh::Mesh;

/// Sides of each ring.
const SIDES: usize = 6;

/// The hexagonal wireframe torus: 36 vertices, 72 segments, no triangles.
///
/// Expects `0 < minor_radius < major_radius` (checked by [`super::Generator::build`]).
pub fn hex_torus(major_radius: f32, minor_radius: f32) -> Mesh {
    // The vertices are those of a 6 x 6 torus grid (vertex (i, j) at index i * 6 + j);
    // the wireframe keeps its grid edges instead of its triangles.
    let grid = super::torus(major_radius, minor_radius, SIDES, SIDES);
    let index = |i: usize, j: usize| ((i % SIDES) * SIDES + (j % SIDES)) as u32;
    let mut segments = Vec::with_capacity(2 * SIDES * SIDES);
    for i in 0..SIDES {
        for j in 0..SIDES {
            segments.push([index(i, j), index(i + 1, j)]);
            segments.push([index(i, j), index(i, j + 1)]);
        }
    }
    Mesh {
        vertices: grid.vertices,
        segments,
        triangles: Vec::new(),
        name: "hex_torus".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::procedural::check::*;
    use glam::Vec3;

    #[test]
    fn counts_and_valence() {
        let h = hex_torus(1.0, 0.5);
        assert_eq!(h.vertices.len(), 36);
        assert_eq!(h.segments.len(), 72);
        assert!(h.triangles.is_empty());
        assert_eq!(unique_segments(&h).len(), 72);
        assert!(valences(&h).iter().all(|&v| v == 4), "{:?}", valences(&h));
        assert!(min_vertex_distance(&h.vertices) > 0.1);
    }

    #[test]
    fn rings_are_regular_hexagons() {
        let (r_major, r_minor) = (2.0, 0.5);
        let h = hex_torus(r_major, r_minor);
        for v in &h.vertices {
            let ring = Vec3::new(v.x, 0.0, v.z).length();
            let d = ((ring - r_major).powi(2) + v.y * v.y).sqrt();
            assert_close("distance to the core circle", d, r_minor, 1e-5);
        }
        // A regular hexagon's side equals its circumradius: every minor edge is r_minor.
        for s in &h.segments {
            let [a, b] = s.map(|i| h.vertices[i as usize]);
            let (ia, ib) = (s[0] as usize / SIDES, s[1] as usize / SIDES);
            if ia == ib {
                assert_close("minor edge", a.distance(b), r_minor, 1e-5);
            }
        }
    }
}
