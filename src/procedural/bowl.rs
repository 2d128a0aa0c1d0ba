//! Wireframe hemispherical bowl, the lower half of a sphere opening up (+y) (SPEC 10,
//! "Bowl": 736 edges).
//!
//! `rings` latitude circles of `segments` vertices at polar angles (from the bottom pole)
//! `k / rings * 90 deg`, `k = 1..=rings`: the last is the rim on the equator (y = 0); there
//! is no pole vertex. Each ring is a closed loop (`rings * segments` edges) and meridians
//! join consecutive rings (`(rings - 1) * segments` edges). The defaults 12 x 32 give 384
//! vertices and 384 + 352 = 736 segments.

use crate::mesh::Mesh;
use glam::Vec3;
use std::f32::consts::{FRAC_PI_2, TAU};

/// The bowl: `rings * segments` vertices, `(2 * rings - 1) * segments` segments.
///
/// Expects `radius > 0`, `rings >= 2` and `segments >= 3` (checked by
/// [`super::Generator::build`]); panics if `rings == 0` or `segments < 3`.
pub fn bowl(radius: f32, rings: usize, segments: usize) -> Mesh {
    assert!(
        rings >= 1 && segments >= 3,
        "bowl needs rings >= 1, segments >= 3"
    );
    let index = |k: usize, j: usize| (k * segments + j % segments) as u32;
    let mut vertices = Vec::with_capacity(rings * segments);
    for k in 1..=rings {
        let (sa, ca) = (FRAC_PI_2 * k as f32 / rings as f32).sin_cos();
        // The rim (k == rings) is exactly on the equator, not at cos(pi/2) ~ -4e-8.
        let y = if k == rings { 0.0 } else { -radius * ca };
        for j in 0..segments {
            let (sp, cp) = (TAU * j as f32 / segments as f32).sin_cos();
            vertices.push(Vec3::new(radius * sa * cp, y, radius * sa * sp));
        }
    }
    let mut segs = Vec::with_capacity((2 * rings - 1) * segments);
    for k in 0..rings {
        for j in 0..segments {
            segs.push([index(k, j), index(k, j + 1)]);
            if k + 1 < rings {
                segs.push([index(k, j), index(k + 1, j)]);
            }
        }
    }
    Mesh {
        vertices,
        segments: segs,
        triangles: Vec::new(),
        name: "bowl".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::procedural::check::*;

    #[test]
    fn default_counts() {
        let b = bowl(1.0, 12, 32);
        assert_eq!(b.vertices.len(), 384);
        assert_eq!(b.segments.len(), 736);
        assert!(b.triangles.is_empty());
        assert_eq!(unique_segments(&b).len(), 736);
    }

    #[test]
    fn other_sizes() {
        for (rings, segments) in [(2, 3), (5, 8), (40, 100)] {
            let b = bowl(2.0, rings, segments);
            assert_eq!(b.vertices.len(), rings * segments);
            assert_eq!(unique_segments(&b).len(), (2 * rings - 1) * segments);
            // Rim vertices have valence 3, inner rings 4, the lowest ring 3.
            let v = valences(&b);
            assert!(v.iter().all(|&d| d == 3 || d == 4), "{v:?}");
        }
    }

    #[test]
    fn lower_hemisphere_with_rim_on_the_equator() {
        let r = 1.5;
        let b = bowl(r, 12, 32);
        for v in &b.vertices {
            assert_close("distance to the centre", v.length(), r, 1e-5);
            assert!(v.y <= 0.0, "{v} above the rim");
        }
        let rim = &b.vertices[11 * 32..];
        assert!(rim.iter().all(|v| v.y == 0.0));
        // No pole: the lowest ring is above the bottom point.
        let lowest = b.vertices.iter().map(|v| v.y).fold(f32::INFINITY, f32::min);
        assert!(lowest > -r + 1e-3, "{lowest}");
        assert!(min_vertex_distance(&b.vertices) > 1e-3);
    }
}
