//! Per-vertex colours stored in mesh files: the channel decoding both readers call
//! ([`channel`], [`PLY_COLOUR_NAMES`]). They are read only when a scene colours an
//! object by them (`color_by = "vertex"`, [`Mesh::load_with_vertex_colours`]);
//! [`Mesh::load`] ignores them.
//!
//! The colours are kept beside the [`Mesh`] (one linear RGB colour per vertex), not in
//! it: a mesh is built in many places (generators, the Python arrays, transforms) that
//! have no colours, and only this one caller wants them.
//!
//! What the readers accept (values are sRGB-encoded, as every viewer writes them, and
//! converted to linear light once here):
//! - **PLY**: vertex properties `red`, `green`, `blue` (also spelled `diffuse_red`,
//!   `diffuse_green`, `diffuse_blue`, or `r`, `g`, `b`; the first complete triple in that
//!   order is used). Types: `uchar` (0..255), `ushort` (0..65535, as PDAL writes LAS
//!   colours), `float` or `double` (0..1). Other types (signed or 32-bit integers, lists)
//!   have no agreed range and are errors naming the property; so is a triple with a
//!   channel missing, and a float outside 0..1 or NaN (naming the vertex). `alpha` is
//!   ignored.
//! - **OBJ**: `v x y z r g b` with `r g b` in 0..1 (the MeshLab / tobj convention). With
//!   colours asked for, a file must colour every vertex or none; a `v` line with another
//!   number of values after `z` (a `w`) has no colour. Values outside 0..1 are errors
//!   naming the line.
//! - Other formats (STL) have no per-vertex colours.

#[cfg(doc)]
use super::Mesh;
use crate::rgb::srgb_to_linear;

/// The PLY spellings of the three colour channels, in the order they are looked for.
pub(super) const PLY_COLOUR_NAMES: [[&str; 3]; 3] = [
    ["red", "green", "blue"],
    ["diffuse_red", "diffuse_green", "diffuse_blue"],
    ["r", "g", "b"],
];

/// A colour channel read as a fraction (0..1 nominal) to linear light, or why not.
pub(super) fn channel(value: f32) -> Result<f32, String> {
    if (0.0..=1.0).contains(&value) {
        Ok(srgb_to_linear(value))
    } else {
        Err(format!("{value} is outside 0..1"))
    }
}
