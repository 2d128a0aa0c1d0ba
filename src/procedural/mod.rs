//! Procedural geometry for tests and built-in scenes (SPEC 10 sizes).
//!
//! Each generator returns a [`Mesh`] holding only the simplices its shape has: wireframes
//! fill `segments`, surfaces fill `triangles`, point sets only `vertices`. The
//! [`Generator`] enum is what a scene file names (`generator = { kind = "torus", ... }`);
//! every parameter has a default that gives the Table 1 size.

use crate::mesh::Mesh;
use serde::Deserialize;

/// A procedural shape and its parameters, as written in a scene file.
#[derive(Clone, Debug, Deserialize, PartialEq)]
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

    /// Builds the mesh, after checking the parameters (positive radii, enough segments).
    pub fn build(&self) -> Result<Mesh, GeneratorError> {
        unimplemented!("procedural generators are being written")
    }
}
