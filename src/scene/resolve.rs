//! From the raw file to a [`Scene`]: defaults, `x` / `x_rel` pairs, strings and numbers
//! that may take several forms, paths resolved against the scene's directory. Values that
//! cannot even be represented (a negative width, a bad colour) are rejected here; range
//! checks are left to [`super::validate`], which finds their locations in [`Origins`].

use super::error::{self, Location, SceneError};
use super::raw::{RawCamera, RawImage, RawObject, RawRender, RawScene, RawTransform};
use super::validate::{max_steps_error, size_error};
use super::{
    AlphaSpec, CameraSettings, Epsilon, Geometry, ImageSettings, Object, Origins, RenderSettings,
    Scene, Surface, Transform,
};
use crate::camera::Camera;
use crate::film::options::samples_error;
use crate::film::{AaMode, Filter};
use crate::framing::Framing;
use crate::matcap::MatCapSpec;
use crate::primitives::PrimitiveKind;
use glam::DVec3;
use std::fmt::Debug;
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::Spanned;

mod lidar;
mod surface;

/// Parses `text` (the contents of `path`) into an unvalidated scene.
pub(super) fn parse(text: &str, path: &Path) -> Result<Scene, SceneError> {
    let raw: RawScene = toml::from_str(text).map_err(|e| error::from_toml(path, text, &e))?;
    let mut r = Resolver {
        path,
        text,
        dir: path.parent().unwrap_or(Path::new("")).to_path_buf(),
        origins: Origins::default(),
    };
    let (camera, framing) = r.camera(raw.camera)?;
    let image = r.image(raw.image)?;
    let render = r.render(raw.render)?;
    let objects = raw
        .object
        .into_iter()
        .enumerate()
        .map(|(i, o)| r.object(i, o))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Scene {
        path: path.to_path_buf(),
        camera,
        framing,
        image,
        render,
        objects,
        origins: r.origins,
    })
}

struct Resolver<'a> {
    path: &'a Path,
    text: &'a str,
    dir: PathBuf,
    origins: Origins,
}

impl Resolver<'_> {
    fn location(&self, span: Range<usize>) -> Location {
        Location::from_offset(self.text, span.start)
    }

    fn invalid(&self, span: Range<usize>, field: &str, message: String) -> SceneError {
        SceneError::Invalid {
            path: self.path.to_path_buf(),
            location: Some(self.location(span)),
            field: field.to_string(),
            message,
        }
    }

    /// Remembers where `key` was read and the value it resolved to.
    fn record(&mut self, key: &str, span: Range<usize>, value: &dyn Debug) {
        let location = self.location(span);
        self.origins.record(key.to_string(), location, value);
    }

    fn vec3(&mut self, key: &str, v: &Spanned<[f64; 3]>) -> DVec3 {
        let value = DVec3::from_array(*v.get_ref());
        self.record(key, v.span(), &value);
        value
    }

    fn number(&mut self, key: &str, v: &Spanned<f64>) -> f64 {
        let value = *v.get_ref();
        self.record(key, v.span(), &value);
        value
    }

    /// The camera, or auto-framing (issue 11) when `[camera]` is absent or has
    /// `fit = true`: then `origin` and `target` are placeholders (the view direction and
    /// the point it starts from) that `render::build` replaces.
    fn camera(
        &mut self,
        raw: Option<RawCamera>,
    ) -> Result<(CameraSettings, Option<Framing>), SceneError> {
        let raw = raw.unwrap_or(RawCamera {
            origin: None,
            target: None,
            up: None,
            fov: None,
            fit: None,
            direction: None,
        });
        let up = raw.up.map_or(DVec3::Y, |v| self.vec3("camera.up", &v));
        let fov = raw
            .fov
            .map_or(Camera::DEFAULT_FOV_Y, |v| self.number("camera.fov", &v));
        let fit = match (&raw.fit, &raw.origin, &raw.target) {
            (Some(f), _, _) => *f.get_ref(),
            (None, None, None) => true,
            (None, _, _) => false,
        };
        if fit {
            if let Some(v) = raw.origin.as_ref().or(raw.target.as_ref()) {
                return Err(self.invalid(
                    v.span(),
                    "camera.fit",
                    "camera.fit = true places the camera itself: remove camera.origin and                      camera.target, or set fit = false"
                        .to_string(),
                ));
            }
            let direction = raw
                .direction
                .map_or(crate::framing::DEFAULT_DIRECTION, |v| {
                    self.vec3("camera.direction", &v)
                });
            let framing = Framing {
                direction,
                up,
                fov,
                margin: crate::framing::DEFAULT_MARGIN,
            };
            let camera = CameraSettings {
                origin: direction,
                target: DVec3::ZERO,
                up,
                fov,
            };
            return Ok((camera, Some(framing)));
        }
        if let Some(d) = &raw.direction {
            return Err(self.invalid(
                d.span(),
                "camera.direction",
                "camera.direction is the view direction of auto-framing: add fit = true, or                  remove it and keep origin and target"
                    .to_string(),
            ));
        }
        let (Some(origin), Some(target)) = (&raw.origin, &raw.target) else {
            let given = raw
                .origin
                .as_ref()
                .or(raw.target.as_ref())
                .expect("one is given");
            return Err(self.invalid(
                given.span(),
                "camera",
                "[camera] needs both origin and target, or fit = true (or no [camera] at                  all) to frame the scene automatically"
                    .to_string(),
            ));
        };
        let camera = CameraSettings {
            origin: self.vec3("camera.origin", origin),
            target: self.vec3("camera.target", target),
            up,
            fov,
        };
        Ok((camera, None))
    }

    fn image(&mut self, raw: RawImage) -> Result<ImageSettings, SceneError> {
        let defaults = ImageSettings::default();
        let mut size = |key: &str, v: Option<Spanned<i64>>, default: u32| match v {
            None => Ok(default),
            Some(v) => {
                let n = *v.get_ref();
                match (size_error(key, n), u32::try_from(n)) {
                    (None, Ok(n)) => {
                        self.record(key, v.span(), &n);
                        Ok(n)
                    }
                    (message, _) => Err(self.invalid(
                        v.span(),
                        key,
                        message.unwrap_or_else(|| format!("{key} is too large (got {n})")),
                    )),
                }
            }
        };
        let width = size("image.width", raw.width, defaults.width)?;
        let height = size("image.height", raw.height, defaults.height)?;
        let transparent = raw
            .background
            .as_ref()
            .is_some_and(|v| v.get_ref().as_str() == Some("transparent"));
        let background = match raw.background {
            None => defaults.background,
            Some(_) if transparent => defaults.background,
            Some(v) => colour(v.get_ref()).ok_or_else(|| {
                self.invalid(
                    v.span(),
                    "image.background",
                    format!(
                        "image.background must be [r, g, b] with integers in 0..=255, a hex \
                         colour like \"#ffffff\" or \"transparent\" (got {})",
                        v.get_ref()
                    ),
                )
            })?,
        };
        Ok(ImageSettings {
            width,
            height,
            background,
            transparent,
        })
    }

    fn render(&mut self, raw: RawRender) -> Result<RenderSettings, SceneError> {
        let defaults = RenderSettings::default();
        let (samples, aa, filter) = self.film(&raw)?;
        let beta = raw
            .beta
            .map_or(defaults.beta, |v| self.number("render.beta", &v));
        let epsilon = match (raw.epsilon, raw.epsilon_rel) {
            (Some(_), Some(rel)) => {
                return Err(self.invalid(
                    rel.span(),
                    "render.epsilon_rel",
                    "render: give either epsilon (world units) or epsilon_rel (times the scene's \
                     bounding-box diagonal), not both"
                        .to_string(),
                ));
            }
            (Some(e), None) => Epsilon::Absolute(self.number("render.epsilon", &e)),
            (None, Some(e)) => Epsilon::Relative(self.number("render.epsilon_rel", &e)),
            (None, None) => defaults.epsilon,
        };
        let max_steps = match raw.max_steps {
            None => defaults.max_steps,
            Some(v) => {
                let n = *v.get_ref();
                match max_steps_error(n) {
                    Some(message) => {
                        return Err(self.invalid(v.span(), "render.max_steps", message));
                    }
                    None => {
                        let n = u32::try_from(n).expect("checked by max_steps_error");
                        self.record("render.max_steps", v.span(), &n);
                        n
                    }
                }
            }
        };
        let threads = match raw.threads {
            None => defaults.threads,
            Some(v) => usize::try_from(*v.get_ref()).map_err(|_| {
                self.invalid(
                    v.span(),
                    "render.threads",
                    format!(
                        "render.threads must be >= 0, with 0 for all cores (got {})",
                        v.get_ref()
                    ),
                )
            })?,
        };
        Ok(RenderSettings {
            beta,
            epsilon,
            max_steps,
            evaluation: raw.evaluation.unwrap_or_default(),
            threads,
            samples,
            aa,
            filter,
            certified_hits: raw.certified_hits.unwrap_or(false),
        })
    }

    /// `samples`, `aa` and `filter` of `[render]` (issue 11).
    fn film(&mut self, raw: &RawRender) -> Result<(u32, AaMode, Filter), SceneError> {
        let defaults = RenderSettings::default();
        let samples = match &raw.samples {
            None => defaults.samples,
            Some(v) => {
                let n = *v.get_ref();
                if let Some(message) = samples_error("render.samples", n) {
                    return Err(self.invalid(v.span(), "render.samples", message));
                }
                let n = u32::try_from(n).expect("checked by samples_error");
                self.record("render.samples", v.span(), &n);
                n
            }
        };
        let named = |key: &str, v: &Spanned<String>, names: &str| {
            format!("{key} must be {names} (got \"{}\")", v.get_ref())
        };
        let aa = match &raw.aa {
            None => defaults.aa,
            Some(v) => AaMode::from_name(v.get_ref()).ok_or_else(|| {
                self.invalid(v.span(), "render.aa", named("render.aa", v, AaMode::NAMES))
            })?,
        };
        let filter = match &raw.filter {
            None => defaults.filter,
            Some(v) => Filter::from_name(v.get_ref()).ok_or_else(|| {
                self.invalid(
                    v.span(),
                    "render.filter",
                    named("render.filter", v, Filter::NAMES),
                )
            })?,
        };
        Ok((samples, aa, filter))
    }

    fn object(&mut self, i: usize, raw: Spanned<RawObject>) -> Result<Object, SceneError> {
        let name = format!("object[{i}]");
        let span = raw.span();
        let raw = raw.into_inner();
        let (las, colour) = self.lidar(&name, &raw)?;
        let surface = self.surface(&name, &raw)?;
        let geometry = match (raw.mesh, raw.generator) {
            (Some(_), Some(g)) => {
                return Err(self.invalid(
                    g.span(),
                    &format!("{name}.generator"),
                    format!("{name}: give either mesh or generator, not both"),
                ));
            }
            (None, None) => {
                return Err(self.invalid(
                    span,
                    &name,
                    format!(
                        "{name} needs a mesh (a file path) or a generator \
                         (e.g. generator = {{ kind = \"torus\" }})"
                    ),
                ));
            }
            (Some(m), None) => {
                let path = self.dir.join(m.get_ref());
                self.record(&format!("{name}.mesh"), m.span(), &path);
                Geometry::Mesh(path)
            }
            (None, Some(g)) => Geometry::Generator(g.into_inner()),
        };
        let primitives = self.primitives(&name, &raw.primitives)?;
        // A signed surface reads no alpha (`Surface`); the placeholder keeps the checks
        // of the smooth objects' alphas satisfied.
        let placeholder = (surface != Surface::Smooth).then_some(AlphaSpec::Relative(1.0));
        let alpha = self
            .alpha(&name, "alpha", raw.alpha, raw.alpha_rel)?
            .or(placeholder)
            .ok_or_else(|| {
                self.invalid(
                    span.clone(),
                    &format!("{name}.alpha"),
                    format!(
                        "{name} needs alpha (1/length, in world units) or alpha_rel (alpha times \
                         the object's bounding-box diagonal)"
                    ),
                )
            })?;
        let max_alpha = self.alpha(&name, "max_alpha", raw.max_alpha, raw.max_alpha_rel)?;
        let matcap = match raw.matcap {
            None => MatCapSpec::default(),
            Some(m) => {
                let spec = MatCapSpec::parse(m.get_ref(), &self.dir);
                self.record(&format!("{name}.matcap"), m.span(), &spec);
                spec
            }
        };
        let transform = match raw.transform {
            None => Transform::IDENTITY,
            Some(t) => self.transform(&name, t)?,
        };
        Ok(Object {
            geometry,
            primitives,
            alpha,
            max_alpha,
            transform,
            matcap,
            las,
            colour,
            surface,
        })
    }

    fn primitives(
        &mut self,
        name: &str,
        v: &Spanned<toml::Value>,
    ) -> Result<Vec<PrimitiveKind>, SceneError> {
        let key = format!("{name}.primitives");
        let kind = |value: &toml::Value| -> Result<PrimitiveKind, String> {
            let text = value.as_str().ok_or_else(|| {
                format!(
                    "{key} must be a primitive kind or a list of them (\"points\", \"edges\", \
                     \"triangles\") (got {})",
                    v.get_ref()
                )
            })?;
            ALL_KINDS
                .into_iter()
                .find(|k| k.name() == text)
                .ok_or_else(|| {
                    format!(
                        "{key}: unknown primitive kind \"{text}\" (expected \"points\", \
                         \"edges\" or \"triangles\")"
                    )
                })
        };
        let kinds = match v.get_ref() {
            toml::Value::Array(items) => items.iter().map(kind).collect(),
            single => kind(single).map(|k| vec![k]),
        };
        match kinds {
            Ok(kinds) => {
                self.record(&key, v.span(), &kinds);
                Ok(kinds)
            }
            Err(message) => Err(self.invalid(v.span(), &key, message)),
        }
    }

    /// `key` / `key_rel`: at most one of them.
    fn alpha(
        &mut self,
        name: &str,
        key: &str,
        absolute: Option<Spanned<f64>>,
        relative: Option<Spanned<f64>>,
    ) -> Result<Option<AlphaSpec>, SceneError> {
        Ok(match (absolute, relative) {
            (Some(_), Some(rel)) => {
                return Err(self.invalid(
                    rel.span(),
                    &format!("{name}.{key}_rel"),
                    format!(
                        "{name}: give either {key} (1/length, in world units) or {key}_rel \
                         (times the object's bounding-box diagonal), not both"
                    ),
                ));
            }
            (Some(a), None) => Some(AlphaSpec::Absolute(
                self.number(&format!("{name}.{key}"), &a),
            )),
            (None, Some(r)) => Some(AlphaSpec::Relative(
                self.number(&format!("{name}.{key}_rel"), &r),
            )),
            (None, None) => None,
        })
    }

    fn transform(&mut self, name: &str, raw: RawTransform) -> Result<Transform, SceneError> {
        let mut t = Transform::IDENTITY;
        if let Some(s) = raw.scale {
            let key = format!("{name}.transform.scale");
            t.scale = scale(s.get_ref()).ok_or_else(|| {
                self.invalid(
                    s.span(),
                    &key,
                    format!(
                        "{key} must be a number or [sx, sy, sz] (got {})",
                        s.get_ref()
                    ),
                )
            })?;
            self.record(&key, s.span(), &t.scale);
        }
        if let Some(r) = raw.rotate {
            t.rotate = self.vec3(&format!("{name}.transform.rotate"), &r);
        }
        if let Some(v) = raw.translate {
            t.translate = self.vec3(&format!("{name}.transform.translate"), &v);
        }
        Ok(t)
    }
}

const ALL_KINDS: [PrimitiveKind; 3] = [
    PrimitiveKind::Points,
    PrimitiveKind::Edges,
    PrimitiveKind::Triangles,
];

/// `[r, g, b]` with integers in 0..=255, or `"#rrggbb"` / `"#rgb"`.
fn colour(v: &toml::Value) -> Option<[u8; 3]> {
    match v {
        toml::Value::Array(items) if items.len() == 3 => {
            let mut c = [0u8; 3];
            for (out, item) in c.iter_mut().zip(items) {
                *out = u8::try_from(item.as_integer()?).ok()?;
            }
            Some(c)
        }
        toml::Value::String(s) => {
            let hex = s.strip_prefix('#')?;
            if !hex.chars().all(|c| c.is_ascii_hexdigit()) {
                return None;
            }
            let digit = |i: usize| u8::from_str_radix(&hex[i..i + 1], 16).ok();
            match hex.len() {
                6 => Some(std::array::from_fn(|k| {
                    u8::from_str_radix(&hex[2 * k..2 * k + 2], 16).unwrap_or(0)
                })),
                3 => {
                    let mut c = [0u8; 3];
                    for (k, out) in c.iter_mut().enumerate() {
                        *out = digit(k)? * 17;
                    }
                    Some(c)
                }
                _ => None,
            }
        }
        _ => None,
    }
}

fn as_number(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Float(f) => Some(*f),
        toml::Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

/// A number (uniform) or `[sx, sy, sz]`.
fn scale(v: &toml::Value) -> Option<DVec3> {
    match v {
        toml::Value::Array(items) if items.len() == 3 => Some(DVec3::new(
            as_number(&items[0])?,
            as_number(&items[1])?,
            as_number(&items[2])?,
        )),
        other => as_number(other).map(DVec3::splat),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours() {
        let v = |s: &str| toml::from_str::<toml::Table>(&format!("c = {s}")).unwrap()["c"].clone();
        assert_eq!(colour(&v("[0, 128, 255]")), Some([0, 128, 255]));
        assert_eq!(colour(&v("\"#ff8000\"")), Some([255, 128, 0]));
        assert_eq!(colour(&v("\"#FfF\"")), Some([255, 255, 255]));
        assert_eq!(colour(&v("\"#f80\"")), Some([255, 136, 0]));
        for bad in [
            "[0, 256, 0]",
            "[0, -1, 0]",
            "[0, 0]",
            "[0.5, 0, 0]",
            "\"ffffff\"",
            "\"#fffff\"",
            "\"#ggg\"",
            "\"#ééé\"",
            "7",
        ] {
            assert_eq!(colour(&v(bad)), None, "{bad}");
        }
    }

    #[test]
    fn scales() {
        let v = |s: &str| toml::from_str::<toml::Table>(&format!("c = {s}")).unwrap()["c"].clone();
        assert_eq!(scale(&v("10")), Some(DVec3::splat(10.0)));
        assert_eq!(scale(&v("0.5")), Some(DVec3::splat(0.5)));
        assert_eq!(scale(&v("[1, 2.5, -3]")), Some(DVec3::new(1.0, 2.5, -3.0)));
        assert_eq!(scale(&v("[1, 2]")), None);
        assert_eq!(scale(&v("\"big\"")), None);
    }
}
