//! An object's placement: scale, then rotate, then translate.

use crate::mesh::Mesh;
use glam::{DAffine3, DQuat, DVec3};

/// `p -> R (S p) + t`, with `S = diag(scale)` and `R` the rotation by `rotate.x` degrees
/// about x, then `rotate.y` about y, then `rotate.z` about z (fixed axes), i.e.
/// `R = Rz * Ry * Rx`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Per-axis scale; components must be finite and non-zero (negative mirrors).
    pub scale: DVec3,
    /// Rotation angles in degrees about x, then y, then z.
    pub rotate: DVec3,
    pub translate: DVec3,
}

impl Default for Transform {
    fn default() -> Self {
        Transform::IDENTITY
    }
}

impl Transform {
    pub const IDENTITY: Transform = Transform {
        scale: DVec3::ONE,
        rotate: DVec3::ZERO,
        translate: DVec3::ZERO,
    };

    pub fn is_identity(&self) -> bool {
        *self == Transform::IDENTITY
    }

    /// The rotation `Rz * Ry * Rx`.
    pub fn rotation(&self) -> DQuat {
        let r = self.rotate * (std::f64::consts::PI / 180.0);
        DQuat::from_rotation_z(r.z) * DQuat::from_rotation_y(r.y) * DQuat::from_rotation_x(r.x)
    }

    /// The whole map as an affine matrix.
    pub fn matrix(&self) -> DAffine3 {
        DAffine3::from_scale_rotation_translation(self.scale, self.rotation(), self.translate)
    }

    /// Maps a point.
    pub fn apply(&self, p: DVec3) -> DVec3 {
        self.rotation() * (self.scale * p) + self.translate
    }

    /// Transforms a mesh's vertices in place (in `f32`, as the mesh stores them).
    pub fn apply_to_mesh(&self, mesh: &mut Mesh) {
        if !self.is_identity() {
            mesh.transform(
                self.scale.as_vec3(),
                self.rotation().as_quat(),
                self.translate.as_vec3(),
            );
        }
    }

    /// The factor by which every length grows when the scale is uniform (`|s|`; mirrors
    /// do not change lengths), `None` for a non-uniform scale. Lengths in object space
    /// times this factor are lengths in world space (so `alpha_world = alpha_object / s`).
    pub fn uniform_scale(&self) -> Option<f64> {
        let a = self.scale.abs();
        let (lo, hi) = (a.min_element(), a.max_element());
        (hi - lo <= 1e-12 * hi).then_some(hi)
    }

    /// The largest factor by which any length can grow (`max |s_i|`); with
    /// [`Transform::min_scale`] it bounds length changes under a non-uniform scale.
    pub fn max_scale(&self) -> f64 {
        self.scale.abs().max_element()
    }

    /// The smallest factor by which any length can grow (`min |s_i|`).
    pub fn min_scale(&self) -> f64 {
        self.scale.abs().min_element()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DVec3, b: DVec3) {
        assert!(
            a.distance(b) <= 1e-12,
            "expected {b}, got {a} (tolerance 1e-12, difference {})",
            a.distance(b)
        );
    }

    #[test]
    fn order_is_scale_rotate_translate() {
        let t = Transform {
            scale: DVec3::new(2.0, 1.0, 1.0),
            rotate: DVec3::new(0.0, 0.0, 90.0),
            translate: DVec3::new(0.0, 0.0, 5.0),
        };
        // x is scaled to 2, rotated about z onto y, then moved along z.
        close(t.apply(DVec3::X), DVec3::new(0.0, 2.0, 5.0));
        close(t.matrix().transform_point3(DVec3::X), t.apply(DVec3::X));
    }

    #[test]
    fn rotations_about_x_then_y_then_z() {
        let t = Transform {
            rotate: DVec3::new(90.0, 90.0, 0.0),
            ..Transform::IDENTITY
        };
        // Rx(90): y -> z; then Ry(90): z -> x.
        close(t.apply(DVec3::Y), DVec3::X);
        let t = Transform {
            rotate: DVec3::new(0.0, 90.0, 90.0),
            ..Transform::IDENTITY
        };
        // Ry(90): z -> x; then Rz(90): x -> y.
        close(t.apply(DVec3::Z), DVec3::Y);
    }

    #[test]
    fn scale_factors() {
        let mut t = Transform::IDENTITY;
        assert!(t.is_identity());
        assert_eq!(t.uniform_scale(), Some(1.0));
        t.scale = DVec3::new(-10.0, 10.0, 10.0);
        assert_eq!(t.uniform_scale(), Some(10.0));
        t.scale = DVec3::new(1.0, 2.0, 3.0);
        assert_eq!(t.uniform_scale(), None);
        assert_eq!((t.min_scale(), t.max_scale()), (1.0, 3.0));
    }

    #[test]
    fn mesh_is_transformed_like_points() {
        let t = Transform {
            scale: DVec3::splat(2.0),
            rotate: DVec3::new(10.0, 20.0, 30.0),
            translate: DVec3::new(1.0, -1.0, 0.5),
        };
        let p = glam::Vec3::new(0.3, -0.7, 1.1);
        let mut mesh = Mesh {
            vertices: vec![p],
            ..Mesh::default()
        };
        t.apply_to_mesh(&mut mesh);
        let expected = t.apply(p.as_dvec3());
        assert!(
            mesh.vertices[0].as_dvec3().distance(expected) < 1e-5,
            "{} vs {expected}",
            mesh.vertices[0]
        );
    }
}
