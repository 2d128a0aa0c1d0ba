//! Colour values, below everything that reads or draws them: linear RGB, the sRGB
//! transfer functions (IEC 61966-2-1), named colormaps for scalars and the ASPRS class
//! palette. The mesh and lidar readers store their colours with these; the colour field
//! of the data ([`crate::colour`]) and the film average and encode them.
//!
//! Colours are kept in linear RGB (`[f32; 3]`, 0..1) once they are attached to geometry,
//! so averages mix light, not sRGB codes; [`to_srgb8`] converts back for the image.
//!
//! - [`colormap`]: `viridis`, `magma`, `turbo`, ... (via the `colorous` crate), by name.
//! - [`palette`]: the ASPRS standard class colours (LAS 1.4 R15, table 17 classes).

pub mod colormap;
pub mod palette;

pub use colormap::Colormap;

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
