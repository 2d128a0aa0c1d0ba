//! The film's settings, one plain struct shared by the command line, the scene file and
//! library callers (the browser scene builder).

use super::crop::Rect;
use super::filter::Filter;

/// How samples are spread over the pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum AaMode {
    /// Every pixel gets the same `samples` positions.
    #[default]
    Uniform,
    /// One ray per pixel centre first; pixels whose neighbours disagree (hit or miss,
    /// object, normal angle, shade) get `samples` positions instead.
    Adaptive,
}

impl AaMode {
    pub const NAMES: &'static str = "\"uniform\" or \"adaptive\"";

    pub fn from_name(name: &str) -> Option<AaMode> {
        match name {
            "uniform" => Some(AaMode::Uniform),
            "adaptive" => Some(AaMode::Adaptive),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            AaMode::Uniform => "uniform",
            AaMode::Adaptive => "adaptive",
        }
    }
}

/// Everything about the film a caller chooses. `FilmOptions::default()` is today's
/// image: one ray per pixel centre, opaque background, the whole image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilmOptions {
    /// Samples per pixel (per flagged pixel in adaptive mode), at least 1.
    pub samples: u32,
    pub aa: AaMode,
    pub filter: Filter,
    /// Colour of rays that miss (opaque images; the colour of empty pixels otherwise).
    pub background: [u8; 3],
    /// Alpha 0 where every sample misses, the hit share of the samples on silhouettes.
    pub transparent: bool,
    /// Only these pixels of the full image (identical to the same pixels of the whole).
    pub crop: Option<Rect>,
    /// Keep the per-pixel records the AOVs need (normal, object, position, cost).
    pub keep_aovs: bool,
    /// Report how far the exact smooth distance may lie above the hits' values
    /// (`render::hit_gap`, in the image's statistics): a few more evaluations.
    pub hit_gap: bool,
}

impl Default for FilmOptions {
    fn default() -> Self {
        FilmOptions {
            samples: 1,
            aa: AaMode::Uniform,
            filter: Filter::Box,
            background: [255, 255, 255],
            transparent: false,
            crop: None,
            keep_aovs: false,
            hit_gap: false,
        }
    }
}

/// Largest accepted sample count per pixel.
pub const MAX_SAMPLES: u32 = 1024;

/// The message for a sample count out of range, if it is (`what` names the flag or key).
pub fn samples_error(what: &str, samples: i64) -> Option<String> {
    (!(1..=i64::from(MAX_SAMPLES)).contains(&samples))
        .then(|| format!("{what} must be in 1..={MAX_SAMPLES} samples per pixel (got {samples})"))
}
