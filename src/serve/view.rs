//! What the page sends: the view (camera, image size, pass scale), the render settings
//! and each object's parameters, as JSON. [`ViewRequest::apply`] writes it into a copy
//! of the served scene and validates that copy, so bad values get the same messages as
//! the command line and scene files (`beta must be in [0, 1] (got 2)`,
//! `object[0].alpha must be > 0 (got -1)`).

use super::ServeError;
use super::paths::SceneFolder;
use crate::api::params::{Naming, SceneOverrides};
use crate::matcap::{MatCapSpec, builtin_names};
use crate::primitives::PrimitiveKind;
use crate::scene::{AlphaSpec, CameraSettings, Epsilon, Scene};
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Largest width or height the server renders (a full-resolution PNG included).
pub const MAX_VIEW_SIZE: u32 = 4096;
/// Largest samples per pixel accepted.
pub const MAX_SAMPLES: u32 = 64;
/// Largest progressive-pass divisor.
pub const MAX_SCALE: u32 = 16;

/// The camera as the page holds it.
#[derive(Clone, Copy, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ViewCamera {
    pub origin: [f64; 3],
    pub target: [f64; 3],
    pub up: [f64; 3],
    pub fov: f64,
}

/// One object's parameters.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ViewObject {
    #[serde(serialize_with = "kind_names")]
    pub primitives: Vec<PrimitiveKind>,
    /// Exactly one of `alpha` (1/length) and `alpha_rel` (times the diagonal).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alpha: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alpha_rel: Option<f64>,
    /// At most one of these; neither: the same as alpha.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_alpha: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_alpha_rel: Option<f64>,
    /// `normal`, a built-in name, or a PNG file inside the scene's folder.
    pub matcap: String,
}

/// What a pass shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Aov {
    /// The MatCap-shaded image.
    #[default]
    Shaded,
    /// Hit distance along the ray, near bright, far dark.
    Depth,
    /// World normals as colours (`0.5 + 0.5 n`).
    Normal,
    /// Object index as a palette.
    Id,
    /// Hit positions as colours, scaled over the box of the hits.
    Position,
    /// Evaluations per pixel as a heat map with its scale.
    Cost,
}

/// A request for a render, a probe or a save.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ViewRequest {
    pub camera: ViewCamera,
    pub width: i64,
    pub height: i64,
    /// This pass renders `ceil(width / scale) x ceil(height / scale)` pixels.
    #[serde(default = "one")]
    pub scale: u32,
    pub beta: f64,
    /// Exactly one of `epsilon` (world units) and `epsilon_rel` (times the diagonal).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub epsilon: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub epsilon_rel: Option<f64>,
    #[serde(default = "one")]
    pub samples: u32,
    #[serde(default)]
    pub aov: Aov,
    pub objects: Vec<ViewObject>,
    /// A full-resolution render that newer views do not cancel.
    #[serde(default)]
    pub keep: bool,
    /// Probe: the pixel (full-resolution coordinates).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y: Option<f64>,
    /// Save: also write the TOML on the server, under this name in the scene's folder.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub save_as: Option<String>,
}

fn kind_names<S: serde::Serializer>(kinds: &[PrimitiveKind], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(kinds.iter().map(|k| k.name()))
}

fn one() -> u32 {
    1
}

fn bad(message: impl Into<String>) -> ServeError {
    ServeError::BadRequest(message.into())
}

fn alpha_spec(
    name: &str,
    key: &str,
    abs: Option<f64>,
    rel: Option<f64>,
) -> Result<Option<AlphaSpec>, ServeError> {
    match (abs, rel) {
        (Some(_), Some(_)) => Err(bad(format!("{name}: give {key} or {key}_rel, not both"))),
        (Some(a), None) => Ok(Some(AlphaSpec::Absolute(a))),
        (None, Some(r)) => Ok(Some(AlphaSpec::Relative(r))),
        (None, None) => Ok(None),
    }
}

impl ViewRequest {
    /// Parses a request body.
    pub fn parse(body: &[u8]) -> Result<ViewRequest, ServeError> {
        serde_json::from_slice(body).map_err(|e| bad(format!("bad request body: {e}")))
    }

    /// The served scene with this request's values, validated; image size is the full
    /// resolution (not the pass's).
    pub fn apply(&self, base: &Scene, folder: &SceneFolder) -> Result<Scene, ServeError> {
        let mut scene = base.clone();
        let input = |e: crate::api::InputError| bad(e.to_string());
        SceneOverrides {
            width: Some(self.width),
            height: Some(self.height),
            beta: Some(self.beta),
            ..Default::default()
        }
        .apply(&mut scene, Naming::Keyword)
        .map_err(input)?;
        for (key, v) in [("width", scene.image.width), ("height", scene.image.height)] {
            if v > MAX_VIEW_SIZE {
                return Err(bad(format!(
                    "{key} must be in 1..={MAX_VIEW_SIZE} here (got {v}); render larger images with `smoothtrace render`"
                )));
            }
        }
        if !(1..=MAX_SAMPLES).contains(&self.samples) {
            return Err(bad(format!(
                "samples must be in 1..={MAX_SAMPLES} (got {})",
                self.samples
            )));
        }
        if !(1..=MAX_SCALE).contains(&self.scale) {
            return Err(bad(format!(
                "scale must be in 1..={MAX_SCALE} (got {})",
                self.scale
            )));
        }
        scene.render.epsilon = match (self.epsilon, self.epsilon_rel) {
            (Some(_), Some(_)) => return Err(bad("give epsilon or epsilon_rel, not both")),
            (Some(e), None) => Epsilon::Absolute(e),
            (None, Some(r)) => Epsilon::Relative(r),
            (None, None) => scene.render.epsilon,
        };
        let c = self.camera;
        scene.camera = CameraSettings {
            origin: DVec3::from_array(c.origin),
            target: DVec3::from_array(c.target),
            up: DVec3::from_array(c.up),
            fov: c.fov,
        };
        if self.objects.len() != scene.objects.len() {
            return Err(bad(format!(
                "objects: the scene has {} object(s), the request gives {}",
                scene.objects.len(),
                self.objects.len()
            )));
        }
        for (k, (o, v)) in scene.objects.iter_mut().zip(&self.objects).enumerate() {
            let name = format!("object[{k}]");
            if v.primitives.is_empty() {
                return Err(bad(format!("{name}.primitives: choose at least one kind")));
            }
            o.primitives = v.primitives.clone();
            o.primitives.dedup();
            o.alpha = alpha_spec(&name, "alpha", v.alpha, v.alpha_rel)?
                .ok_or_else(|| bad(format!("{name} needs alpha or alpha_rel")))?;
            o.max_alpha = alpha_spec(&name, "max_alpha", v.max_alpha, v.max_alpha_rel)?;
            o.matcap = matcap(&name, &v.matcap, &o.matcap, folder)?;
        }
        // The values come from the request, not the file: validated without the file's
        // name, so no message points at a line of it.
        let mut unnamed = scene.clone();
        unnamed.path = std::path::PathBuf::new();
        unnamed.validate().map_err(|e| bad(e.to_string()))?;
        Ok(scene)
    }

    /// This pass's image size.
    pub fn pass_size(&self, scene: &Scene) -> (u32, u32) {
        (
            scene.image.width.div_ceil(self.scale),
            scene.image.height.div_ceil(self.scale),
        )
    }
}

/// The MatCap a request names: the scene's own (unchanged text), `normal`, a built-in,
/// or a PNG file inside the scene's folder.
fn matcap(
    name: &str,
    text: &str,
    current: &MatCapSpec,
    folder: &SceneFolder,
) -> Result<MatCapSpec, ServeError> {
    if text == current.to_string() {
        return Ok(current.clone());
    }
    if text == "normal" {
        return Ok(MatCapSpec::Normal);
    }
    if builtin_names().contains(&text) {
        return Ok(MatCapSpec::Builtin(text.to_string()));
    }
    if text.to_ascii_lowercase().ends_with(".png") {
        let path = folder
            .resolve(text, true)
            .map_err(|e| ServeError::Forbidden(format!("{name}.matcap: {e}")))?;
        return Ok(MatCapSpec::File(path));
    }
    Err(bad(format!(
        "{name}.matcap: unknown MatCap \"{text}\" (expected normal, one of {}, or a .png file in the scene's folder)",
        builtin_names().join(", ")
    )))
}

/// The page's starting state for a scene: its camera, size, settings and objects.
pub fn initial_view(scene: &Scene) -> ViewRequest {
    let c = scene.camera;
    ViewRequest {
        camera: ViewCamera {
            origin: c.origin.to_array(),
            target: c.target.to_array(),
            up: c.up.to_array(),
            fov: c.fov,
        },
        width: i64::from(scene.image.width),
        height: i64::from(scene.image.height),
        scale: 1,
        beta: scene.render.beta,
        epsilon: match scene.render.epsilon {
            Epsilon::Absolute(e) => Some(e),
            Epsilon::Relative(_) => None,
        },
        epsilon_rel: match scene.render.epsilon {
            Epsilon::Relative(r) => Some(r),
            Epsilon::Absolute(_) => None,
        },
        samples: 1,
        aov: Aov::Shaded,
        objects: scene
            .objects
            .iter()
            .map(|o| {
                let (alpha, alpha_rel) = split(o.alpha);
                let (max_alpha, max_alpha_rel) = o.max_alpha.map_or((None, None), split);
                ViewObject {
                    primitives: o.primitives.clone(),
                    alpha,
                    alpha_rel,
                    max_alpha,
                    max_alpha_rel,
                    matcap: o.matcap.to_string(),
                }
            })
            .collect(),
        keep: false,
        x: None,
        y: None,
        save_as: None,
    }
}

fn split(a: AlphaSpec) -> (Option<f64>, Option<f64>) {
    match a {
        AlphaSpec::Absolute(v) => (Some(v), None),
        AlphaSpec::Relative(v) => (None, Some(v)),
    }
}

/// Checks a pixel coordinate of a probe.
pub fn probe_pixel(v: Option<f64>, key: &str, size: u32) -> Result<f64, ServeError> {
    match v {
        Some(p) if p.is_finite() && (0.0..f64::from(size)).contains(&p) => Ok(p),
        Some(p) => Err(bad(format!("{key} must be in [0, {size}) (got {p})"))),
        None => Err(bad(format!("a probe needs the pixel's {key}"))),
    }
}
