//! The scene file as written: serde structs mirroring the TOML, with spans on every value
//! that is checked after parsing. Unknown keys are errors everywhere.

use super::Evaluation;
use crate::procedural::Generator;
use serde::Deserialize;
use toml::Spanned;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawScene {
    /// Absent: the camera frames the scene (`crate::framing`).
    pub camera: Option<RawCamera>,
    #[serde(default)]
    pub image: RawImage,
    #[serde(default)]
    pub render: RawRender,
    #[serde(default)]
    pub object: Vec<Spanned<RawObject>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawCamera {
    pub origin: Option<Spanned<[f64; 3]>>,
    pub target: Option<Spanned<[f64; 3]>>,
    pub up: Option<Spanned<[f64; 3]>>,
    pub fov: Option<Spanned<f64>>,
    // Auto-framing (issue 11): `fit = true` with an optional view direction.
    pub fit: Option<Spanned<bool>>,
    pub direction: Option<Spanned<[f64; 3]>>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawImage {
    pub width: Option<Spanned<i64>>,
    pub height: Option<Spanned<i64>>,
    /// `[r, g, b]` (0..255) or `"#rrggbb"`; checked when resolving.
    pub background: Option<Spanned<toml::Value>>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawRender {
    pub beta: Option<Spanned<f64>>,
    pub epsilon: Option<Spanned<f64>>,
    pub epsilon_rel: Option<Spanned<f64>>,
    pub max_steps: Option<Spanned<i64>>,
    pub evaluation: Option<Evaluation>,
    pub threads: Option<Spanned<i64>>,
    // Anti-aliasing (issue 11): checked when resolving.
    pub samples: Option<Spanned<i64>>,
    pub aa: Option<Spanned<String>>,
    pub filter: Option<Spanned<String>>,
    pub certified_hits: Option<bool>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawObject {
    pub mesh: Option<Spanned<String>>,
    pub generator: Option<Spanned<Generator>>,
    /// A kind name or a list of them; checked when resolving.
    pub primitives: Spanned<toml::Value>,
    pub alpha: Option<Spanned<f64>>,
    pub alpha_rel: Option<Spanned<f64>>,
    pub max_alpha: Option<Spanned<f64>>,
    pub max_alpha_rel: Option<Spanned<f64>>,
    pub matcap: Option<Spanned<String>>,
    pub transform: Option<RawTransform>,
    // Lidar (.las / .laz) filters and colour; checked when resolving.
    pub classes: Option<Spanned<Vec<i64>>>,
    pub exclude_classes: Option<Spanned<Vec<i64>>>,
    pub returns: Option<Spanned<String>>,
    pub crop: Option<Spanned<RawCrop>>,
    pub thin: Option<Spanned<RawThin>>,
    pub origin: Option<Spanned<[f64; 3]>>,
    pub color_by: Option<Spanned<String>>,
    pub colormap: Option<Spanned<String>>,
    // Signed offset surfaces (issue 32): checked when resolving.
    pub surface: Option<Spanned<String>>,
    pub offset: Option<Spanned<f64>>,
}

/// `crop = { min = [x, y, z], max = [x, y, z] }` in file coordinates.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawCrop {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

/// `thin = { voxel = size }` or `thin = { every = k }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawThin {
    pub voxel: Option<f64>,
    pub every: Option<i64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawTransform {
    /// A number or `[sx, sy, sz]`; checked when resolving.
    pub scale: Option<Spanned<toml::Value>>,
    pub rotate: Option<Spanned<[f64; 3]>>,
    pub translate: Option<Spanned<[f64; 3]>>,
}
