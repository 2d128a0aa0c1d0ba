//! Winding numbers and signed distances of a triangle soup at many points (issue 32):
//! a [`Solid`] (the triangles, their BVH and its far fields) built once, then batch
//! queries in the current rayon pool. The winding numbers come from
//! [`winding::batch`] (queries sorted along a Morton curve, one walk per group of
//! neighbours), the distances from [`eval::nearest`].

use super::InputError;
use crate::eval::{self, Nearest};
use crate::mesh::Mesh;
use crate::winding::{self, Solid, batch};
use glam::DVec3;
use rayon::prelude::*;

/// `beta` in `[0, 1)`: 0 is the exact sum; the far-field expansion converges only for
/// clusters smaller than their distance.
pub fn check_beta(name: &str, beta: f64) -> Result<f64, InputError> {
    if !(0.0..1.0).contains(&beta) {
        return Err(InputError::Parameter(format!(
            "{name} must be in [0, 1) (got {beta}); {} is the default, 0 the exact sum",
            winding::DEFAULT_BETA
        )));
    }
    Ok(beta)
}

/// The solid of `mesh`'s triangles (it must have some) with the far-field parameter
/// `beta` (checked, named `beta_name` in messages).
pub fn build_solid(mesh: &Mesh, beta: f64, beta_name: &str) -> Result<Solid, InputError> {
    let beta = check_beta(beta_name, beta)?;
    Ok(Solid::from_mesh(mesh, beta)?)
}

/// The fast winding number at every point.
pub fn winding_numbers(solid: &Solid, points: &[DVec3]) -> Vec<f64> {
    batch::winding_numbers(solid.tree(), solid.triangles(), solid.beta, points)
}

/// The signed distance at every point (negative inside: winding number > 1/2) and the
/// nearest triangle. The signs come from [`batch::sign_winding_numbers`] (a coarse pass,
/// refined near 1/2).
pub fn signed_distances(solid: &Solid, points: &[DVec3]) -> (Vec<f64>, Vec<Nearest>) {
    let w = batch::sign_winding_numbers(solid.tree(), solid.triangles(), solid.beta, points);
    let sets = [solid.set()];
    let near: Vec<Nearest> = points
        .par_iter()
        .map(|&x| eval::nearest(&sets, x))
        .collect();
    let s = near
        .iter()
        .zip(&w)
        .map(|(n, &w)| winding::sign(w) * n.d)
        .collect();
    (s, near)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::winding::exact;

    /// An octahedron with outward normals, scaled by `r`.
    fn octahedron(r: f32) -> Mesh {
        use glam::Vec3;
        let v = vec![
            Vec3::X * r,
            -Vec3::X * r,
            Vec3::Y * r,
            -Vec3::Y * r,
            Vec3::Z * r,
            -Vec3::Z * r,
        ];
        let mut triangles = Vec::new();
        for (a, b) in [(0, 2), (2, 1), (1, 3), (3, 0)] {
            triangles.push([a, b, 4]);
            triangles.push([b, a, 5]);
        }
        Mesh {
            vertices: v,
            segments: vec![],
            triangles,
            name: "octahedron".into(),
        }
    }

    #[test]
    fn signed_distances_are_negative_inside_an_octahedron() {
        let mesh = octahedron(1.0);
        let solid = build_solid(&mesh, winding::DEFAULT_BETA, "beta").unwrap();
        let pts: Vec<DVec3> = (0..200)
            .map(|i| {
                let t = i as f64 / 200.0;
                DVec3::new(2.4 * t - 1.2, 0.3 * (7.0 * t).sin(), 0.2 - 0.3 * t)
            })
            .collect();
        let (s, near) = signed_distances(&solid, &pts);
        let w = winding_numbers(&solid, &pts);
        let tris: Vec<[DVec3; 3]> = mesh
            .triangles
            .iter()
            .map(|t| t.map(|i| mesh.vertices[i as usize].as_dvec3()))
            .collect();
        for (k, &p) in pts.iter().enumerate() {
            // The octahedron is |x| + |y| + |z| <= 1.
            let inside = p.abs().element_sum() < 1.0;
            let we = exact::winding_number(&tris, p);
            assert!((w[k] - we).abs() < 1e-9, "{p}: {} vs exact {we}", w[k]);
            assert_eq!(s[k] < 0.0, inside, "{p}: s = {}", s[k]);
            assert_eq!(s[k].abs(), near[k].d);
        }
    }

    #[test]
    fn bad_beta_and_meshes_without_faces_are_named() {
        let mut mesh = octahedron(1.0);
        let e = build_solid(&mesh, 1.0, "beta").unwrap_err();
        assert!(
            e.to_string().starts_with("beta must be in [0, 1) (got 1)"),
            "{e}"
        );
        assert!(build_solid(&mesh, f64::NAN, "beta").is_err());
        mesh.triangles.clear();
        let e = build_solid(&mesh, 0.3, "beta").unwrap_err();
        assert!(e.to_string().contains("cannot build triangles"), "{e}");
    }
}
