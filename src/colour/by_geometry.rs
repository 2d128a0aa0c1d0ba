//! Colour from the geometry itself, for any object (`color_by` in a scene):
//! - `vertex`: the file's per-vertex colours (PLY, OBJ; `crate::mesh`'s
//!   `load_with_vertex_colours`);
//! - `height`: each vertex's world height (`y` after the object's transform, the scene's
//!   up axis) on a colormap spanning the object's lowest to highest vertex. Heights go
//!   through the smooth colour field like every other colour (the softmax average of the
//!   primitives' colours, `crate::eval::colour`): the colour at a hit says where the
//!   nearby data lies, so a puffy low-alpha surface does not invent heights the data
//!   does not have, lidar `elevation` and mesh `height` agree, and far-field nodes carry
//!   their mean like any attribute;
//! - `normal`: the unit surface normal at the hit, `0.5 + 0.5 n` in world space (no
//!   traversal: the normal is the smooth distance's gradient, already computed).
//!
//! The lidar attributes (`rgb`, `intensity`, ...) are `crate::las::ColorBy`.

use crate::mesh::Mesh;
use crate::rgb::{Colormap, Linear};

/// Which geometric quantity colours an object.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GeometryColorBy {
    Vertex,
    Height,
    Normal,
}

impl GeometryColorBy {
    pub const NAMES: &'static str = "\"vertex\", \"height\" or \"normal\"";

    pub fn from_name(name: &str) -> Option<GeometryColorBy> {
        match name {
            "vertex" => Some(GeometryColorBy::Vertex),
            "height" => Some(GeometryColorBy::Height),
            "normal" => Some(GeometryColorBy::Normal),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            GeometryColorBy::Vertex => "vertex",
            GeometryColorBy::Height => "height",
            GeometryColorBy::Normal => "normal",
        }
    }
}

/// An object's geometric colouring: what, and the colormap of `height`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GeometryColouring {
    pub by: GeometryColorBy,
    /// Used by `height` only (default viridis).
    pub colormap: Colormap,
}

/// One linear colour per vertex of `mesh`: its `y` on `map`, from the lowest to the
/// highest vertex (the low end for a flat mesh).
pub fn height_colours(mesh: &Mesh, map: Colormap) -> Vec<Linear> {
    let (lo, hi) = mesh
        .vertices
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v.y as f64), hi.max(v.y as f64))
        });
    mesh.vertices
        .iter()
        .map(|v| map.map(v.y as f64, lo, hi))
        .collect()
}

/// The albedo `color_by = "normal"` gives a unit world normal: `0.5 + 0.5 n` (mid grey
/// for a zero normal).
pub fn normal_colour(n: glam::DVec3) -> Linear {
    (0.5 + 0.5 * n.normalize_or_zero()).as_vec3().to_array()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DVec3, Vec3};

    #[test]
    fn heights_span_the_colormap() {
        let mesh = Mesh {
            vertices: vec![Vec3::new(5.0, -1.0, 0.0), Vec3::Y * 3.0, Vec3::ONE],
            ..Default::default()
        };
        let c = height_colours(&mesh, Colormap::Magma);
        assert_eq!(c[0], Colormap::Magma.map(0.0, 0.0, 1.0));
        assert_eq!(c[1], Colormap::Magma.map(1.0, 0.0, 1.0));
        assert_eq!(c[2], Colormap::Magma.map(0.5, 0.0, 1.0));
        for n in ["vertex", "height", "normal"] {
            assert_eq!(GeometryColorBy::from_name(n).unwrap().name(), n);
        }
        assert_eq!(normal_colour(DVec3::X * 2.0), [1.0, 0.5, 0.5]);
        assert_eq!(normal_colour(DVec3::ZERO), [0.5; 3]);
    }
}
