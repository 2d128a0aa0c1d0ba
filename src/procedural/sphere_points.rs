//! Points spread evenly on a sphere by the Fibonacci lattice (vertices only).
//!
//! Point `i` of `n` has height `y = 1 - (2i + 1) / n` (equal-area bands) and azimuth
//! `i * pi (3 - sqrt 5)` (the golden angle), scaled to `radius`. The default gives 2000
//! points and no segments or triangles.

use crate::mesh::Mesh;
use glam::DVec3;
use std::f64::consts::{PI, TAU};

/// `count` points on the sphere of radius `radius` centred at the origin.
pub fn sphere_points(radius: f32, count: usize) -> Mesh {
    let golden_angle = PI * (3.0 - 5f64.sqrt());
    let n = count as f64;
    // f64 keeps i * golden_angle exact enough for millions of points.
    let vertices = (0..count)
        .map(|i| {
            let y = 1.0 - (2.0 * i as f64 + 1.0) / n;
            let ring = (1.0 - y * y).max(0.0).sqrt();
            let (s, c) = (i as f64 * golden_angle).rem_euclid(TAU).sin_cos();
            (f64::from(radius) * DVec3::new(ring * c, y, ring * s)).as_vec3()
        })
        .collect();
    Mesh {
        vertices,
        segments: Vec::new(),
        triangles: Vec::new(),
        name: "sphere_points".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::procedural::check::*;
    use glam::Vec3;

    #[test]
    fn counts_and_radius() {
        for (radius, count) in [(1.0, 2000), (2.5, 1), (0.1, 7), (1.0, 100_000)] {
            let m = sphere_points(radius, count);
            assert_eq!(m.vertices.len(), count);
            assert!(m.segments.is_empty() && m.triangles.is_empty());
            for v in &m.vertices {
                assert_close("radius", v.length(), radius, 1e-5 * radius);
            }
        }
    }

    #[test]
    fn evenly_spread() {
        let m = sphere_points(1.0, 2000);
        // Centred: the mean of an even spread is near the origin.
        let mean: Vec3 = m.vertices.iter().sum::<Vec3>() / 2000.0;
        assert!(mean.length() < 1e-3, "mean {mean}");
        // Well separated: the ideal spacing is sqrt(4 pi / n) ~ 0.079.
        let d = min_vertex_distance(&m.vertices);
        assert!(d > 0.04, "closest pair {d}");
        // Each octant gets about an eighth.
        let octant = m
            .vertices
            .iter()
            .filter(|v| v.x > 0.0 && v.y > 0.0 && v.z > 0.0)
            .count();
        assert!((230..=270).contains(&octant), "{octant}");
    }
}
