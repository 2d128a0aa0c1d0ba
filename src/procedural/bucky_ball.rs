//! The truncated icosahedron's 90 edges as thin triangulated tubes (SPEC 10, "Bucky
//! Ball": the paper's has 12,548 triangles; the default here has 12,600).
//!
//! Skeleton: the 60 vertices are the even (cyclic) permutations of `(0, +-1, +-3 phi)`,
//! `(+-1, +-(2 + phi), +-2 phi)` and `(+-phi, +-2, +-(2 phi + 1))` (edge length 2,
//! circumradius `sqrt(9 phi + 10)`), scaled so they lie at `radius`; the 90 edges are the
//! vertex pairs at distance 2, every vertex of degree 3.
//!
//! Tube per edge: `segments` rings of `sides` vertices from one vertex centre to the other
//! (`segments - 1` quad bands of `2 * sides` triangles) and at each end a cone of `sides`
//! triangles to a tip `tube_radius / 2` beyond the vertex. Each tube is a closed,
//! outward-wound surface with `2 * sides * segments` triangles and `sides * segments + 2`
//! vertices; the tubes share no vertices (a soup of 90 closed tubes). Ending the rings at
//! the vertex centres makes the three tubes of a joint overlap into one solid knot; the
//! cones fill the sliver on the outside of the joint that open tube ends would leave
//! (edges lean ~12 deg inward, so the neighbours do not quite cover a mouth), and the
//! tips themselves lie inside the neighbouring tubes. Defaults 10 sides x 7 segments:
//! 90 * 140 = 12,600 triangles, 90 * 72 = 6480 vertices.

use crate::mesh::Mesh;
use glam::{DVec3, Vec3};
use std::f32::consts::TAU;

/// The truncated icosahedron with circumradius 1: 60 vertices and its 90 edges.
pub fn truncated_icosahedron() -> (Vec<Vec3>, Vec<[u32; 2]>) {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let bases = [
        [0.0, 1.0, 3.0 * phi],
        [1.0, 2.0 + phi, 2.0 * phi],
        [phi, 2.0, 2.0 * phi + 1.0],
    ];
    let mut points: Vec<DVec3> = Vec::with_capacity(60);
    for base in bases {
        for signs in 0..8u32 {
            let mut p = base;
            for (axis, c) in p.iter_mut().enumerate() {
                if signs & (1 << axis) != 0 {
                    if *c == 0.0 {
                        // +0 and -0 are the same point: keep one sign pattern only.
                        p = [f64::NAN; 3];
                        break;
                    }
                    *c = -*c;
                }
            }
            if p[0].is_nan() {
                continue;
            }
            for shift in 0..3 {
                points.push(DVec3::new(p[shift], p[(shift + 1) % 3], p[(shift + 2) % 3]));
            }
        }
    }
    debug_assert_eq!(points.len(), 60);
    let circumradius = (9.0 * phi + 10.0).sqrt();
    // Edges have length 2; the next distances (pentagon and hexagon diagonals) are
    // 2 phi ~ 3.24 and 2 sqrt 3 ~ 3.46, so 2.5 separates them safely.
    let mut edges = Vec::with_capacity(90);
    for i in 0..points.len() {
        for j in i + 1..points.len() {
            if points[i].distance(points[j]) < 2.5 {
                edges.push([i as u32, j as u32]);
            }
        }
    }
    let vertices = points
        .iter()
        .map(|p| (*p / circumradius).as_vec3())
        .collect();
    (vertices, edges)
}

/// The bucky ball: 90 closed tubes of `2 * sides * segments` triangles each.
///
/// Expects `0 < tube_radius < radius`, `sides >= 3` and `segments >= 2` (checked by
/// [`super::Generator::build`]); panics if a count is below that.
pub fn bucky_ball(radius: f32, tube_radius: f32, sides: usize, segments: usize) -> Mesh {
    assert!(
        sides >= 3 && segments >= 2,
        "bucky_ball needs sides >= 3, segments >= 2"
    );
    let (skeleton, edges) = truncated_icosahedron();
    let per_tube_vertices = sides * segments + 2;
    let mut vertices = Vec::with_capacity(edges.len() * per_tube_vertices);
    let mut triangles = Vec::with_capacity(edges.len() * 2 * sides * segments);
    let ring_dirs: Vec<(f32, f32)> = (0..sides)
        .map(|j| (TAU * j as f32 / sides as f32).sin_cos())
        .collect();
    for &[ia, ib] in &edges {
        let (a, b) = (
            radius * skeleton[ia as usize],
            radius * skeleton[ib as usize],
        );
        let d = (b - a).normalize();
        // (u, w, d) right-handed, so d/dtheta x d/dt points out of the tube.
        let u = d.any_orthonormal_vector();
        let w = d.cross(u);
        let base = vertices.len() as u32;
        let ring = |k: usize, j: usize| base + (k * sides + j % sides) as u32;
        for k in 0..segments {
            let centre = a.lerp(b, k as f32 / (segments - 1) as f32);
            for &(s, c) in &ring_dirs {
                vertices.push(centre + tube_radius * (c * u + s * w));
            }
        }
        let start_tip = vertices.len() as u32;
        vertices.push(a - 0.5 * tube_radius * d);
        let end_tip = start_tip + 1;
        vertices.push(b + 0.5 * tube_radius * d);
        for k in 0..segments - 1 {
            for j in 0..sides {
                let (p, q, r, s) = (
                    ring(k, j),
                    ring(k, j + 1),
                    ring(k + 1, j + 1),
                    ring(k + 1, j),
                );
                triangles.push([p, q, r]);
                triangles.push([p, r, s]);
            }
        }
        for j in 0..sides {
            triangles.push([start_tip, ring(0, j + 1), ring(0, j)]);
            triangles.push([end_tip, ring(segments - 1, j), ring(segments - 1, j + 1)]);
        }
    }
    Mesh {
        vertices,
        segments: Vec::new(),
        triangles,
        name: "bucky_ball".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::procedural::check::*;

    #[test]
    fn skeleton_is_the_truncated_icosahedron() {
        let (v, e) = truncated_icosahedron();
        assert_eq!(v.len(), 60);
        assert_eq!(e.len(), 90);
        assert!(min_vertex_distance(&v) > 0.3, "duplicate vertices");
        for p in &v {
            assert_close("circumradius", p.length(), 1.0, 1e-6);
        }
        let len0 = v[e[0][0] as usize].distance(v[e[0][1] as usize]);
        // Edge / circumradius = 2 / sqrt(9 phi + 10) ~ 0.4035.
        assert_close("edge length", len0, 0.403548, 1e-5);
        for &[a, b] in &e {
            let len = v[a as usize].distance(v[b as usize]);
            assert_close("edge length", len, len0, 1e-6);
        }
        let mesh = Mesh {
            vertices: v,
            segments: e,
            ..Mesh::default()
        };
        assert_eq!(unique_segments(&mesh).len(), 90);
        assert!(valences(&mesh).iter().all(|&d| d == 3));
        // Euler: V - E + F = 2 with 12 pentagons and 20 hexagons.
        assert_eq!(60 - 90 + 32, 2);
    }

    #[test]
    fn default_counts() {
        let m = bucky_ball(1.0, 0.02, 10, 7);
        assert_eq!(m.triangles.len(), 12_600);
        assert_eq!(m.vertices.len(), 6480);
        assert!(m.segments.is_empty());
    }

    #[test]
    fn tubes_closed_outward_and_not_degenerate() {
        for (sides, segments) in [(10, 7), (3, 2), (6, 4)] {
            let r = 0.05;
            let m = bucky_ball(1.0, r, sides, segments);
            let per_tube = 2 * sides * segments;
            assert_eq!(m.triangles.len(), 90 * per_tube);
            assert_eq!(m.vertices.len(), 90 * (sides * segments + 2));
            assert_closed_oriented(&m);
            assert!(min_triangle_area(&m) > 1e-6);
            for tube in m.triangles.chunks(per_tube) {
                let one = Mesh {
                    vertices: m.vertices.clone(),
                    triangles: tube.to_vec(),
                    ..Mesh::default()
                };
                assert!(signed_volume(&one) > 0.0, "tube wound inward");
            }
        }
    }

    #[test]
    fn tubes_run_between_vertex_centres() {
        let (radius, r, sides, segments) = (2.0, 0.04, 10, 7);
        let (skeleton, edges) = truncated_icosahedron();
        let m = bucky_ball(radius, r, sides, segments);
        let per_tube = sides * segments + 2;
        for (e, &[ia, ib]) in edges.iter().enumerate() {
            let (a, b) = (
                radius * skeleton[ia as usize],
                radius * skeleton[ib as usize],
            );
            let verts = &m.vertices[e * per_tube..(e + 1) * per_tube];
            let first: Vec3 = verts[..sides].iter().sum::<Vec3>() / sides as f32;
            let last: Vec3 = verts[(segments - 1) * sides..segments * sides]
                .iter()
                .sum::<Vec3>()
                / sides as f32;
            assert!(first.distance(a) < 1e-5 && last.distance(b) < 1e-5);
            // Ring vertices are at the tube radius from the axis.
            let d = (b - a).normalize();
            for p in &verts[..segments * sides] {
                let off = *p - a;
                let radial = (off - off.dot(d) * d).length();
                assert_close("tube radius", radial, r, 1e-5);
            }
        }
    }

    #[test]
    fn cap_tips_hide_inside_neighbouring_tubes() {
        let (radius, r) = (1.0, 0.02);
        let (skeleton, edges) = truncated_icosahedron();
        for (i, v) in skeleton.iter().enumerate() {
            let v = radius * *v;
            let dirs: Vec<Vec3> = edges
                .iter()
                .filter_map(|&[a, b]| match (a as usize == i, b as usize == i) {
                    (true, _) => Some(radius * skeleton[b as usize] - v),
                    (_, true) => Some(radius * skeleton[a as usize] - v),
                    _ => None,
                })
                .map(Vec3::normalize)
                .collect();
            assert_eq!(dirs.len(), 3);
            for (k, d) in dirs.iter().enumerate() {
                let tip = v - 0.5 * r * *d;
                let hidden = dirs.iter().enumerate().any(|(l, e)| {
                    let off = tip - v;
                    l != k && off.dot(*e) > 0.0 && (off - off.dot(*e) * *e).length() < r
                });
                assert!(hidden, "tip of the tube along {d} at vertex {i} sticks out");
            }
        }
    }
}
