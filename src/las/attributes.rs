//! Colour from lidar attributes (`color_by`): the points' RGB, intensity, ASPRS class or
//! elevation. While the file streams, only the chosen attribute of the kept points is
//! stored; it becomes one linear colour per point at the end, when the value range of
//! the kept points is known.
//!
//! - `rgb`: LAS stores 16-bit channels, but many writers put 8-bit values in them; when
//!   no kept point has a channel above 255 the values are taken as 8-bit (as PDAL and
//!   CloudCompare do), otherwise they are divided by 257.
//! - `intensity`: the colormap spans the 1st to 99th percentile of the kept points (a
//!   few very bright returns would otherwise leave everything dark).
//! - `elevation`: the colormap spans the kept points' lowest to highest z.
//! - `classification`: the ASPRS palette ([`crate::rgb::palette`]).

use super::filter::Record;
use crate::rgb::colormap::quantile_range;
use crate::rgb::{Colormap, Linear, palette, srgb8_to_linear};

/// Which attribute gives a lidar point its colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorBy {
    Rgb,
    Intensity,
    Classification,
    Elevation,
}

impl ColorBy {
    pub const NAMES: &'static str = "\"rgb\", \"intensity\", \"classification\" or \"elevation\"";

    pub fn from_name(name: &str) -> Option<ColorBy> {
        match name {
            "rgb" => Some(ColorBy::Rgb),
            "intensity" => Some(ColorBy::Intensity),
            "classification" => Some(ColorBy::Classification),
            "elevation" => Some(ColorBy::Elevation),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            ColorBy::Rgb => "rgb",
            ColorBy::Intensity => "intensity",
            ColorBy::Classification => "classification",
            ColorBy::Elevation => "elevation",
        }
    }

    /// Whether a colormap applies (scalar attributes).
    pub fn is_scalar(self) -> bool {
        matches!(self, ColorBy::Intensity | ColorBy::Elevation)
    }

    /// Why a file of this point format cannot give this attribute, if it cannot.
    pub fn check_format(self, format: &las::point::Format) -> Result<(), String> {
        if self == ColorBy::Rgb && !format.has_color {
            let n = format.to_u8().unwrap_or(0);
            return Err(format!(
                "the file's point format {n} has no RGB (formats 2, 3, 5, 7, 8 and 10 have); \
                 use \"intensity\", \"classification\" or \"elevation\""
            ));
        }
        Ok(())
    }
}

/// The chosen attribute of the kept points, in order.
pub(super) enum AttributeColumn {
    Rgb(Vec<[u16; 3]>, Vec<[u16; 3]>),
    Intensity(Vec<u16>, Vec<u16>),
    Classification(Vec<u8>),
    Elevation(Vec<f64>),
}

impl AttributeColumn {
    pub fn new(by: ColorBy) -> AttributeColumn {
        match by {
            ColorBy::Rgb => AttributeColumn::Rgb(Vec::new(), Vec::new()),
            ColorBy::Intensity => AttributeColumn::Intensity(Vec::new(), Vec::new()),
            ColorBy::Classification => AttributeColumn::Classification(Vec::new()),
            ColorBy::Elevation => AttributeColumn::Elevation(Vec::new()),
        }
    }

    /// Decodes this batch's column (the second vector of `Rgb` and `Intensity`), so
    /// that [`Self::push`] can pick records by index.
    pub fn begin_batch(&mut self, data: &las::PointData) {
        match self {
            AttributeColumn::Rgb(_, batch) => {
                batch.clear();
                if let Some(rgb) = data.rgb() {
                    batch.extend(rgb.map(|(r, g, b)| [r, g, b]));
                }
            }
            AttributeColumn::Intensity(_, batch) => {
                batch.clear();
                batch.extend(data.intensity());
            }
            AttributeColumn::Classification(_) | AttributeColumn::Elevation(_) => {}
        }
    }

    /// Stores the attribute of record `k` of the current batch.
    pub fn push(&mut self, k: usize, r: &Record) {
        match self {
            AttributeColumn::Rgb(kept, batch) => kept.push(batch[k]),
            AttributeColumn::Intensity(kept, batch) => kept.push(batch[k]),
            AttributeColumn::Classification(kept) => kept.push(r.class),
            AttributeColumn::Elevation(kept) => kept.push(r.p.z),
        }
    }

    pub fn retain(&mut self, keep: &[bool]) {
        match self {
            AttributeColumn::Rgb(kept, _) => super::retain(kept, keep),
            AttributeColumn::Intensity(kept, _) => super::retain(kept, keep),
            AttributeColumn::Classification(kept) => super::retain(kept, keep),
            AttributeColumn::Elevation(kept) => super::retain(kept, keep),
        }
    }

    pub fn into_colours(self, colormap: Colormap) -> Vec<Linear> {
        match self {
            AttributeColumn::Rgb(kept, _) => rgb_colours(&kept),
            AttributeColumn::Intensity(kept, _) => {
                let values: Vec<f64> = kept.iter().map(|&v| v as f64).collect();
                let (lo, hi) = quantile_range(&values, 0.01, 0.99).unwrap_or((0.0, 0.0));
                values.iter().map(|&v| colormap.map(v, lo, hi)).collect()
            }
            AttributeColumn::Classification(kept) => kept
                .iter()
                .map(|&c| srgb8_to_linear(palette::class_colour(c)))
                .collect(),
            AttributeColumn::Elevation(kept) => {
                let lo = kept.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = kept.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                kept.iter().map(|&z| colormap.map(z, lo, hi)).collect()
            }
        }
    }
}

/// 16-bit (or 8-bit stored in 16) RGB to linear colours; see the module docs.
pub fn rgb_colours(rgb: &[[u16; 3]]) -> Vec<Linear> {
    let eight_bit = rgb.iter().flatten().all(|&c| c <= 255);
    rgb.iter()
        .map(|c| {
            srgb8_to_linear(c.map(|v| {
                if eight_bit {
                    v as u8
                } else {
                    ((v as u32 + 128) / 257).min(255) as u8
                }
            }))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgb_depth_is_detected() {
        let eight = rgb_colours(&[[255, 0, 128]]);
        let sixteen = rgb_colours(&[[65535, 0, 128 * 257], [256, 0, 0]]);
        assert_eq!(eight[0], sixteen[0]);
        assert_eq!(eight[0], srgb8_to_linear([255, 0, 128]));
    }
}
