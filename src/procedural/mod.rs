//! Procedural geometry for tests and built-in scenes (SPEC 10 sizes).
//!
//! Each generator returns a [`Mesh`] holding only the simplices its shape has: wireframes
//! fill `segments`, surfaces fill `triangles`, point sets only `vertices`. The
//! [`Generator`] enum is what a scene file names (`generator = { kind = "torus", ... }`);
//! every parameter has a default that gives the Table 1 size.

mod bowl;
mod bucky_ball;
mod hex_torus;
mod net;
mod sphere_points;
mod spiky_sphere;
mod torus;
mod validate;

#[cfg(test)]
mod check;
#[cfg(test)]
mod tests;

pub use bowl::bowl;
pub use bucky_ball::{bucky_ball, truncated_icosahedron};
pub use hex_torus::hex_torus;
pub use net::net;
pub use sphere_points::sphere_points;
pub use spiky_sphere::spiky_sphere;
pub use torus::torus;
pub use validate::MAX_PRIMITIVES;

use crate::mesh::Mesh;
use serde::{Deserialize, Serialize};
use validate::Check;

/// A procedural shape and its parameters, as written in a scene file.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Generator {
    /// Triangle torus in the xz plane (axis y). Default 32 x 18 quads = 1152 triangles.
    Torus {
        #[serde(default = "one")]
        major_radius: f32,
        #[serde(default = "quarter")]
        minor_radius: f32,
        #[serde(default = "d32")]
        major_segments: usize,
        #[serde(default = "d18")]
        minor_segments: usize,
    },
    /// Wireframe torus whose rings are hexagons: 6 x 6 vertices, 72 edges.
    HexTorus {
        #[serde(default = "one")]
        major_radius: f32,
        #[serde(default = "half")]
        minor_radius: f32,
    },
    /// Wireframe hemispherical bowl (opening up, +y): latitude rings and meridians.
    /// Default 12 rings x 32 segments = 736 edges.
    Bowl {
        #[serde(default = "one")]
        radius: f32,
        #[serde(default = "d12")]
        rings: usize,
        #[serde(default = "d32")]
        segments: usize,
    },
    /// A rectangular net of edges in the xz plane, sagging in y like a hammock.
    Net {
        #[serde(default = "two")]
        width: f32,
        #[serde(default = "two")]
        depth: f32,
        #[serde(default = "d13")]
        nx: usize,
        #[serde(default = "d7")]
        nz: usize,
        #[serde(default = "quarter")]
        sag: f32,
    },
    /// The truncated icosahedron's 90 edges as thin triangulated tubes (~12,500 triangles).
    BuckyBall {
        #[serde(default = "one")]
        radius: f32,
        #[serde(default = "tube")]
        tube_radius: f32,
        #[serde(default = "d10")]
        sides: usize,
        #[serde(default = "d7")]
        segments: usize,
    },
    /// Points spread evenly on a sphere (Fibonacci lattice).
    SpherePoints {
        #[serde(default = "one")]
        radius: f32,
        #[serde(default = "d2000")]
        count: usize,
    },
    /// An icosphere (triangles) with radial spikes (segments) at its vertices: the
    /// paper's "spiky sphere", a triangle mesh with extra edges.
    SpikySphere {
        #[serde(default = "one")]
        radius: f32,
        #[serde(default = "d2")]
        subdivisions: usize,
        #[serde(default = "half")]
        spike_length: f32,
    },
}

fn one() -> f32 {
    1.0
}
fn two() -> f32 {
    2.0
}
fn half() -> f32 {
    0.5
}
fn quarter() -> f32 {
    0.25
}
fn tube() -> f32 {
    0.02
}
fn d2() -> usize {
    2
}
fn d7() -> usize {
    7
}
fn d10() -> usize {
    10
}
fn d12() -> usize {
    12
}
fn d13() -> usize {
    13
}
fn d18() -> usize {
    18
}
fn d32() -> usize {
    32
}
fn d2000() -> usize {
    2000
}

/// Error for generator parameters out of their valid range.
#[derive(Debug, thiserror::Error)]
#[error("generator '{generator}': {message}")]
pub struct GeneratorError {
    pub generator: &'static str,
    pub message: String,
}

impl Generator {
    /// The generator's name as written in scene files.
    pub fn name(&self) -> &'static str {
        match self {
            Generator::Torus { .. } => "torus",
            Generator::HexTorus { .. } => "hex_torus",
            Generator::Bowl { .. } => "bowl",
            Generator::Net { .. } => "net",
            Generator::BuckyBall { .. } => "bucky_ball",
            Generator::SpherePoints { .. } => "sphere_points",
            Generator::SpikySphere { .. } => "spiky_sphere",
        }
    }

    /// Builds the mesh, after checking the parameters (positive finite radii, minor radius
    /// below the major one, enough segments, at most [`MAX_PRIMITIVES`] primitives).
    pub fn build(&self) -> Result<Mesh, GeneratorError> {
        let c = Check::new(self.name());
        // Products of two counts fit in u128; constant factors saturate.
        let n = |x: usize| x as u128;
        let mut mesh = match *self {
            Generator::Torus {
                major_radius,
                minor_radius,
                major_segments,
                minor_segments,
            } => {
                c.positive("major_radius", major_radius)?;
                c.positive("minor_radius", minor_radius)?;
                c.smaller("minor_radius", minor_radius, "major_radius", major_radius)?;
                c.at_least("major_segments", major_segments, 3)?;
                c.at_least("minor_segments", minor_segments, 3)?;
                c.primitives(
                    (n(major_segments) * n(minor_segments)).saturating_mul(2),
                    &format!("2 x `major_segments` = {major_segments} x `minor_segments` = {minor_segments} triangles"),
                )?;
                torus(major_radius, minor_radius, major_segments, minor_segments)
            }
            Generator::HexTorus {
                major_radius,
                minor_radius,
            } => {
                c.positive("major_radius", major_radius)?;
                c.positive("minor_radius", minor_radius)?;
                c.smaller("minor_radius", minor_radius, "major_radius", major_radius)?;
                hex_torus(major_radius, minor_radius)
            }
            Generator::Bowl {
                radius,
                rings,
                segments,
            } => {
                c.positive("radius", radius)?;
                c.at_least("rings", rings, 2)?;
                c.at_least("segments", segments, 3)?;
                c.primitives(
                    (n(rings) * n(segments)).saturating_mul(2) - n(segments),
                    &format!("(2 x `rings` = {rings} - 1) x `segments` = {segments} edges"),
                )?;
                bowl(radius, rings, segments)
            }
            Generator::Net {
                width,
                depth,
                nx,
                nz,
                sag,
            } => {
                c.positive("width", width)?;
                c.positive("depth", depth)?;
                c.finite("sag", sag)?;
                c.at_least("nx", nx, 2)?;
                c.at_least("nz", nz, 2)?;
                c.primitives(
                    (n(nx) * n(nz)).saturating_mul(2) - n(nx) - n(nz),
                    &format!("2 x `nx` = {nx} x `nz` = {nz} - nx - nz edges"),
                )?;
                net(width, depth, nx, nz, sag)
            }
            Generator::BuckyBall {
                radius,
                tube_radius,
                sides,
                segments,
            } => {
                c.positive("radius", radius)?;
                c.positive("tube_radius", tube_radius)?;
                c.smaller("tube_radius", tube_radius, "radius", radius)?;
                c.at_least("sides", sides, 3)?;
                c.at_least("segments", segments, 2)?;
                c.primitives(
                    (n(sides) * n(segments)).saturating_mul(180),
                    &format!("90 x 2 x `sides` = {sides} x `segments` = {segments} triangles"),
                )?;
                bucky_ball(radius, tube_radius, sides, segments)
            }
            Generator::SpherePoints { radius, count } => {
                c.positive("radius", radius)?;
                c.at_least("count", count, 1)?;
                c.primitives(n(count), &format!("`count` = {count} points"))?;
                sphere_points(radius, count)
            }
            Generator::SpikySphere {
                radius,
                subdivisions,
                spike_length,
            } => {
                c.positive("radius", radius)?;
                c.positive("spike_length", spike_length)?;
                // 20 * 4^s triangles + 10 * 4^s + 2 spikes; 4^s overflows u128 past s = 63.
                let faces = 1u128
                    .checked_shl(2 * subdivisions.min(64) as u32)
                    .unwrap_or(u128::MAX);
                c.primitives(
                    faces.saturating_mul(30).saturating_add(2),
                    &format!(
                        "`subdivisions` = {subdivisions}: 20 x 4^s triangles + 10 x 4^s + 2 spikes"
                    ),
                )?;
                spiky_sphere(radius, subdivisions, spike_length)
            }
        };
        mesh.name = self.name().to_string();
        Ok(mesh)
    }
}
