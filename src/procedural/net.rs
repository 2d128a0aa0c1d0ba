//! Wireframe net: a rectangular grid of edges in the xz plane, sagging like a hammock
//! (SPEC 10, "Net": the paper's has 156 edges; the default here has 162).
//!
//! `nx x nz` vertices spanning `[-width/2, width/2] x [-depth/2, depth/2]`, each lowered by
//! `sag * (1 - (2x/width)^2) * (1 - (2z/depth)^2)`: the border stays at y = 0 and the
//! centre hangs `sag` below it (a negative `sag` bulges up). Edges join grid neighbours:
//! `(nx - 1) * nz + nx * (nz - 1)`; the defaults 13 x 7 give 91 vertices and
//! 84 + 78 = 162 segments. No full grid has exactly 156 edges
//! (`(2 nx - 1)(2 nz - 1) = 313` is prime), so the paper's net was built otherwise.

use crate::mesh::Mesh;
use glam::Vec3;

/// The net: `nx * nz` vertices, `2 nx nz - nx - nz` segments.
///
/// Expects `width, depth > 0`, finite `sag` and `nx, nz >= 2` (checked by
/// [`super::Generator::build`]); panics if a count is below 2.
pub fn net(width: f32, depth: f32, nx: usize, nz: usize, sag: f32) -> Mesh {
    assert!(nx >= 2 && nz >= 2, "net needs nx, nz >= 2");
    let index = |i: usize, k: usize| (k * nx + i) as u32;
    let mut vertices = Vec::with_capacity(nx * nz);
    for k in 0..nz {
        // u, w in [-1, 1]: the position across the net relative to its half-size.
        let w = 2.0 * k as f32 / (nz - 1) as f32 - 1.0;
        for i in 0..nx {
            let u = 2.0 * i as f32 / (nx - 1) as f32 - 1.0;
            let y = -sag * (1.0 - u * u) * (1.0 - w * w);
            vertices.push(Vec3::new(0.5 * width * u, y, 0.5 * depth * w));
        }
    }
    let mut segments = Vec::with_capacity(2 * nx * nz - nx - nz);
    for k in 0..nz {
        for i in 0..nx {
            if i + 1 < nx {
                segments.push([index(i, k), index(i + 1, k)]);
            }
            if k + 1 < nz {
                segments.push([index(i, k), index(i, k + 1)]);
            }
        }
    }
    Mesh {
        vertices,
        segments,
        triangles: Vec::new(),
        name: "net".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::procedural::check::*;

    #[test]
    fn default_counts() {
        let n = net(2.0, 2.0, 13, 7, 0.25);
        assert_eq!(n.vertices.len(), 91);
        assert_eq!(n.segments.len(), 162);
        assert!(n.triangles.is_empty());
        assert_eq!(unique_segments(&n).len(), 162);
    }

    #[test]
    fn other_sizes_and_neighbour_edges() {
        for (nx, nz) in [(2, 2), (3, 9), (20, 11)] {
            let (width, depth) = (3.0, 1.0);
            let n = net(width, depth, nx, nz, 0.1);
            assert_eq!(n.vertices.len(), nx * nz);
            assert_eq!(unique_segments(&n).len(), 2 * nx * nz - nx - nz);
            let (dx, dz) = (width / (nx - 1) as f32, depth / (nz - 1) as f32);
            for s in &n.segments {
                let [a, b] = s.map(|i| n.vertices[i as usize]);
                let (ddx, ddz) = ((a.x - b.x).abs(), (a.z - b.z).abs());
                let along_x = (ddx - dx).abs() < 1e-5 && ddz == 0.0;
                let along_z = (ddz - dz).abs() < 1e-5 && ddx == 0.0;
                assert!(along_x || along_z, "{a} - {b} is not a grid edge");
            }
        }
    }

    #[test]
    fn bounds_and_sag() {
        let (width, depth, sag) = (2.0, 1.0, 0.3);
        let n = net(width, depth, 13, 7, sag);
        let b = n.bounds();
        assert_close("min x", b.min.x, -1.0, 1e-6);
        assert_close("max x", b.max.x, 1.0, 1e-6);
        assert_close("min z", b.min.z, -0.5, 1e-6);
        assert_close("max z", b.max.z, 0.5, 1e-6);
        assert_eq!(b.max.y, 0.0);
        // Odd counts put a vertex at the centre, which hangs the full sag.
        assert_close("lowest point", b.min.y, -sag, 1e-6);
        for v in &n.vertices {
            let border = v.x.abs() == 1.0 || v.z.abs() == 0.5;
            assert_eq!(border, v.y == 0.0, "{v}");
        }
    }
}
