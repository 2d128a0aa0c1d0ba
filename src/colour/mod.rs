//! Colour from the data: named colormaps for scalars, the ASPRS class palette, per-vertex
//! colours and their per-primitive / per-node averages for the smooth colour field.
//!
//! Colours are stored in linear RGB (`[f32; 3]`, 0..1) once they are attached to
//! geometry, so averages (softmax-weighted at a hit, node means in the far field) mix
//! light, not sRGB codes; [`to_srgb8`] converts back for the image.
//!
//! - [`colormap`]: `viridis`, `magma`, `turbo`, ... (via the `colorous` crate), by name.
//! - [`palette`]: the ASPRS standard class colours (LAS 1.4 R15, table 17 classes).
//! - [`by_geometry`]: `color_by = "vertex" | "height" | "normal"` for any object.
//! - [`set_colours`]: a primitive set's colours in BVH leaf order plus each node's mean:
//!   what the colour traversal (`crate::eval::colour`) reads.

pub mod by_geometry;
pub mod colormap;
pub mod palette;
pub mod set_colours;

pub use by_geometry::{GeometryColorBy, GeometryColouring};
pub use colormap::Colormap;
pub use set_colours::{ObjectColours, SetColours};

/// A colour in linear RGB, components in 0..=1.
pub type Linear = [f32; 3];

/// sRGB code (0..=255) to linear light (IEC 61966-2-1).
pub fn srgb8_to_linear(c: [u8; 3]) -> Linear {
    c.map(|v| srgb_to_linear(v as f32 / 255.0))
}

/// One sRGB-encoded channel in 0..1 to linear light (IEC 61966-2-1).
pub fn srgb_to_linear(s: f32) -> f32 {
    if s <= 0.04045 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear light to sRGB code, clamped to 0..=255 (NaN gives 0).
pub fn to_srgb8(c: Linear) -> [u8; 3] {
    c.map(|v| {
        let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        let s = if v <= 0.003_130_8 {
            12.92 * v
        } else {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        };
        (s * 255.0).round().clamp(0.0, 255.0) as u8
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trip() {
        for v in 0..=255u8 {
            let c = [v, 255 - v, v / 2];
            assert_eq!(to_srgb8(srgb8_to_linear(c)), c);
        }
        assert_eq!(to_srgb8([f32::NAN, -1.0, 2.0]), [0, 0, 255]);
    }
}
