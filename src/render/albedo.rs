//! Colour from the data at a hit: the object's smooth colour field
//! ([`crate::eval::colour`]) as the albedo, or for `color_by = "normal"` the hit's
//! normal as a colour ([`crate::colour::by_geometry`]), shaded by the MatCap.
//!
//! Shading: the MatCap's colour is reduced to its luminance (linear light), which scales
//! the albedo; a MatCap's lit areas are about 0.8, so the factor is divided by
//! [`MATCAP_WHITE`] to keep the data's colours at their recorded brightness there. The
//! MatCap's own hue is dropped: multiplying RGB by RGB would tint every data colour
//! with the clay's beige.

use super::object::TraceObject;
use super::tracer::Hit;
use crate::colour::SetColours;
use crate::colour::by_geometry::normal_colour;
use crate::eval::colour::colour_at;
use crate::rgb::{Linear, srgb8_to_linear, to_srgb8};

/// The MatCap luminance that shows the albedo unchanged.
pub const MATCAP_WHITE: f32 = 0.8;

/// The pixel colour of `hit` whose MatCap gave `shaded`: `shaded` itself for an object
/// without colours.
pub fn shade_hit(objects: &[TraceObject], hit: &Hit, shaded: [u8; 3]) -> [u8; 3] {
    let Some(obj) = objects.get(hit.object) else {
        return shaded;
    };
    let Some(colours) = &obj.colours else {
        return shaded;
    };
    if colours.from_normal {
        return tint(shaded, normal_colour(hit.normal));
    }
    let sets = obj.set_refs();
    let cols: Vec<&SetColours> = colours.sets.iter().collect();
    match colour_at(&sets, &cols, hit.point, &obj.params) {
        Some(albedo) => tint(shaded, albedo),
        None => shaded,
    }
}

/// `albedo` lit by the luminance of the MatCap colour `shaded` (see the module docs).
pub fn tint(shaded: [u8; 3], albedo: Linear) -> [u8; 3] {
    let [r, g, b] = srgb8_to_linear(shaded);
    let light = (0.2126 * r + 0.7152 * g + 0.0722 * b) / MATCAP_WHITE;
    to_srgb8(albedo.map(|c| c * light))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tint_keeps_hue_and_scales_by_light() {
        let white = to_srgb8([MATCAP_WHITE; 3]);
        let red = [0.5, 0.0, 0.0];
        let lit = tint(white, red);
        assert_eq!(lit[1..], [0, 0]);
        // Up to the rounding of the MatCap colour to 8 bits.
        assert!(
            (lit[0] as i32 - to_srgb8(red)[0] as i32).abs() <= 1,
            "{lit:?}"
        );
        assert_eq!(tint([0, 0, 0], red), [0, 0, 0]);
    }
}
