//! Signed offset surfaces (issue 32): a scene object with `surface = "signed"` draws the
//! set `S(x) = offset` of the signed distance `S` of a closed triangle mesh (the exact
//! distance to the nearest triangle, negative inside where the fast winding number
//! exceeds 1/2: [`crate::winding`]). Negative offsets lie inside the solid.
//!
//! The tracer steps by the object's value `S(x) - offset`. `S` is 1-Lipschitz, so the
//! distance from `x` to the offset surface is at least `|S(x) - offset|`: every step the
//! tracer takes with it is safe, bound steps and tile cone marches included (they ask
//! for a lower bound, and the exact value is one). The gradient is `sign(S) (x - c) /
//! |x - c|` with `c` the closest point on the mesh: the unit normal of the offset surface,
//! pointing outwards. The offset surface can reach `max(offset, 0)` beyond the mesh's box
//! (the object's reach). On a closed, consistently oriented mesh the winding number is
//! 0 or 1 away from the surface, so the sign only changes across the mesh; an open mesh's
//! winding number crosses 1/2 away from it, where `S` would jump, so signed surfaces
//! are refused on meshes with boundary edges (`render::build`).

use crate::eval::{EvalStats, Sample};
use crate::mesh::Mesh;
use crate::primitives::PrimitiveError;
use crate::winding::{DEFAULT_BETA, Solid};
use glam::DVec3;

/// A closed triangle mesh's signed distance, offset.
#[derive(Clone, Debug)]
pub struct SignedSurface {
    solid: Solid,
    /// The drawn level `S = offset` (world units, negative inside).
    pub offset: f64,
}

impl SignedSurface {
    /// The signed distance of `mesh`'s triangles (winding numbers at the default
    /// far-field parameter), drawn at `offset`.
    pub fn new(mesh: &Mesh, offset: f64) -> Result<SignedSurface, PrimitiveError> {
        Ok(SignedSurface {
            solid: Solid::from_mesh(mesh, DEFAULT_BETA)?,
            offset,
        })
    }

    /// How far beyond the mesh's box the offset surface can reach.
    pub fn reach(&self) -> f64 {
        self.offset.max(0.0)
    }

    /// `S(x) - offset` and, if `grad`, its gradient, as a tracer sample (the free
    /// distances along the ray are the value itself).
    pub fn sample(&self, x: DVec3, grad: bool) -> Sample {
        let mut stack = Vec::new();
        let signed = self.solid.signed_distance(x, &mut stack);
        let s = signed.s - self.offset;
        let gradient = if grad && signed.nearest.d > 0.0 {
            (x - signed.nearest.point) / signed.nearest.d * signed.s.signum()
        } else {
            DVec3::ZERO
        };
        Sample {
            s,
            grad: gradient,
            d_seen: signed.nearest.d,
            underflow: false,
            reach: s,
            reach_back: s,
            slope: None,
            bend: None,
            // The distance is exact: nothing to certify (`render::tracer` item 11).
            s_upper: s,
            stats: EvalStats {
                nodes: signed.nearest.nodes,
                exact: 1,
                ..EvalStats::default()
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::procedural::Generator;

    #[test]
    fn the_sample_of_a_torus_is_its_offset_signed_distance() {
        // Major radius 1, tube radius 0.25; the polygonal tube lies within 1% of it.
        let mesh = Generator::Torus {
            major_radius: 1.0,
            minor_radius: 0.25,
            major_segments: 64,
            minor_segments: 32,
        }
        .build()
        .unwrap();
        let surface = SignedSurface::new(&mesh, -0.1).unwrap();
        assert_eq!(surface.reach(), 0.0);
        for x in [
            DVec3::X,
            DVec3::new(0.0, 0.1, 1.05),
            DVec3::new(1.2, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.5),
        ] {
            let ring = DVec3::new(x.x, 0.0, x.z).normalize();
            let tube = x - ring;
            let want = tube.length() - 0.25 + 0.1;
            let sample = surface.sample(x, true);
            assert!(
                (sample.s - want).abs() < 0.01,
                "{x}: {} vs {want}",
                sample.s
            );
            if tube.length() > 0.05 {
                assert!(
                    sample.grad.dot(tube.normalize()) > 0.99,
                    "{x}: {}",
                    sample.grad
                );
            }
        }
    }
}
