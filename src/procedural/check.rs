//! Test-only checks shared by the generator tests: manifoldness, orientation, areas.

use crate::mesh::Mesh;
use glam::Vec3;
use std::collections::HashMap;

/// Asserts every undirected triangle edge is used by exactly two triangles and every
/// directed edge by exactly one (a closed, consistently oriented 2-manifold).
pub fn assert_closed_oriented(mesh: &Mesh) {
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for t in &mesh.triangles {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            *directed.entry((a, b)).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(n, 1, "{}: directed edge {a}->{b} used {n} times", mesh.name);
        assert_eq!(
            directed.get(&(b, a)).copied().unwrap_or(0),
            1,
            "{}: edge {a}-{b} has no opposite half-edge {b}->{a}",
            mesh.name
        );
    }
}

/// Area of a triangle of the mesh.
pub fn triangle_area(mesh: &Mesh, t: [u32; 3]) -> f32 {
    let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
    0.5 * (b - a).cross(c - a).length()
}

/// The smallest triangle area.
pub fn min_triangle_area(mesh: &Mesh) -> f32 {
    mesh.triangles
        .iter()
        .map(|&t| triangle_area(mesh, t))
        .fold(f32::INFINITY, f32::min)
}

/// Signed volume (divergence theorem) of a closed mesh: positive when wound outward.
pub fn signed_volume(mesh: &Mesh) -> f64 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.vertices[i as usize].as_dvec3());
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

/// Unique undirected segments as `[min, max]`, asserting none is repeated or degenerate.
pub fn unique_segments(mesh: &Mesh) -> Vec<[u32; 2]> {
    let mut s: Vec<[u32; 2]> = mesh
        .segments
        .iter()
        .map(|&[a, b]| {
            assert_ne!(a, b, "{}: degenerate segment {a}-{b}", mesh.name);
            [a.min(b), a.max(b)]
        })
        .collect();
    s.sort_unstable();
    let n = s.len();
    s.dedup();
    assert_eq!(s.len(), n, "{}: repeated segments", mesh.name);
    s
}

/// Number of segments at each vertex.
pub fn valences(mesh: &Mesh) -> Vec<usize> {
    let mut v = vec![0; mesh.vertices.len()];
    for s in &mesh.segments {
        v[s[0] as usize] += 1;
        v[s[1] as usize] += 1;
    }
    v
}

/// Asserts two floats agree within `tol`, printing both, the tolerance and the difference.
pub fn assert_close(what: &str, got: f32, want: f32, tol: f32) {
    let d = (got - want).abs();
    assert!(
        d <= tol,
        "{what}: got {got}, want {want}, |diff| {d} > tol {tol}"
    );
}

/// Smallest pairwise vertex distance (O(n^2): small meshes only); catches duplicates.
pub fn min_vertex_distance(vertices: &[Vec3]) -> f32 {
    let mut m = f32::INFINITY;
    for (i, a) in vertices.iter().enumerate() {
        for b in &vertices[i + 1..] {
            m = m.min(a.distance(*b));
        }
    }
    m
}
