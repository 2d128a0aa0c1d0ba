//! Primitive sets built from a mesh: points, edges, triangles (SPEC 1), their weights
//! (SPEC 4, 5), the weighted supports of edges and triangles and their tables over
//! directions (`support`, `triangle_support`, `directional`) and their BVHs (SPEC 6).

use serde::Deserialize;

pub mod directional;
mod kinds;
pub mod lanes;
mod sets;
pub mod split;
pub mod support;
pub mod triangle_support;
pub mod weights;

pub use kinds::{Edge, Point, Primitive, Slope, Term, Triangle};
pub use sets::{AnySet, BuildTimes, EDGE_LEAF_SIZE, PrimitiveError, PrimitiveSet};
pub use weights::WeightScale;

/// Which kind of primitive a set holds. Scene files and the command line name them
/// `points`, `edges`, `triangles`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum PrimitiveKind {
    Points,
    Edges,
    Triangles,
}

impl PrimitiveKind {
    pub fn name(self) -> &'static str {
        match self {
            PrimitiveKind::Points => "points",
            PrimitiveKind::Edges => "edges",
            PrimitiveKind::Triangles => "triangles",
        }
    }
}

impl std::fmt::Display for PrimitiveKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
