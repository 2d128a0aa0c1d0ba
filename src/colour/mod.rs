//! Colour from the data: per-vertex colours (`color_by = "vertex" | "height" |
//! "normal"`) and their per-primitive / per-node averages for the smooth colour field.
//! The colour values themselves (linear RGB, sRGB conversions, colormaps, the ASPRS
//! palette) are [`crate::rgb`]'s, which the readers below this module use too.
//!
//! Colours are stored in linear RGB (`[f32; 3]`, 0..1) once they are attached to
//! geometry, so averages (softmax-weighted at a hit, node means in the far field) mix
//! light, not sRGB codes; [`crate::rgb::to_srgb8`] converts back for the image.
//!
//! - [`by_geometry`]: `color_by = "vertex" | "height" | "normal"` for any object.
//! - [`set_colours`]: a primitive set's colours in BVH leaf order plus each node's mean:
//!   what the colour traversal (`crate::eval::colour`) reads.

pub mod by_geometry;
pub mod set_colours;

pub use by_geometry::{GeometryColorBy, GeometryColouring};
pub use set_colours::{ObjectColours, SetColours};

/// The colour values, for the colour traversal's callers (`crate::eval::colour`).
pub use crate::rgb::Linear;
