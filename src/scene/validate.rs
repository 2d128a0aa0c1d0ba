//! Range and consistency checks of a resolved [`Scene`]; see the README (section "Scene files").
//!
//! Messages name the field by its dotted key (`object[2].alpha`). The location is
//! attached when the field still holds the value read from the file.

use super::{AlphaSpec, Epsilon, Geometry, MAX_IMAGE_SIZE, Scene, SceneError};
use crate::camera::{CameraError, check_view};
use crate::matcap::{MatCapSpec, builtin_names};
use crate::primitives::PrimitiveKind;
use glam::DVec3;
use std::fmt::Debug;
use std::path::Path;

pub(super) fn validate(scene: &Scene) -> Result<(), SceneError> {
    let c = Checker { scene };
    c.camera()?;
    c.image()?;
    c.render()?;
    c.objects()
}

/// The message for an image size out of range, if it is.
pub(super) fn size_error(field: &str, value: i64) -> Option<String> {
    (!(1..=i64::from(MAX_IMAGE_SIZE)).contains(&value))
        .then(|| format!("{field} must be in 1..={MAX_IMAGE_SIZE} (got {value})"))
}

/// The message for a step count out of range, if it is.
pub(super) fn max_steps_error(value: i64) -> Option<String> {
    if value < 1 {
        Some(format!("render.max_steps must be >= 1 (got {value})"))
    } else if value > i64::from(u32::MAX) {
        Some(format!(
            "render.max_steps must be at most {} (got {value})",
            u32::MAX
        ))
    } else {
        None
    }
}

/// The message for a value that must be finite and positive, if it is not.
fn positive_error(field: &str, value: f64) -> Option<String> {
    if value.is_nan() || value.is_infinite() {
        Some(format!("{field} must be a finite number > 0 (got {value})"))
    } else if value <= 0.0 {
        Some(format!("{field} must be > 0 (got {value})"))
    } else {
        None
    }
}

fn fmt_vec(v: DVec3) -> String {
    format!("[{}, {}, {}]", v.x, v.y, v.z)
}

struct Checker<'a> {
    scene: &'a Scene,
}

impl Checker<'_> {
    /// An error about `field`, located at the first of `candidates` (key, current value)
    /// that still holds its value from the file.
    fn fail_at(
        &self,
        candidates: &[(&str, &dyn Debug)],
        field: &str,
        message: String,
    ) -> SceneError {
        let location = candidates
            .iter()
            .find_map(|(key, value)| self.scene.origins.find(key, *value));
        SceneError::Invalid {
            path: self.scene.path.clone(),
            location,
            field: field.to_string(),
            message,
        }
    }

    fn fail(&self, field: &str, value: &dyn Debug, message: String) -> SceneError {
        self.fail_at(&[(field, value)], field, message)
    }

    /// Auto-framing: the view direction must be finite, non-zero and across `up`.
    fn framing(&self, f: &crate::framing::Framing) -> Result<(), SceneError> {
        let Err(e) = check_view(f.direction, DVec3::ZERO, f.up, f.fov) else {
            return Ok(());
        };
        let d = &f.direction;
        Err(match e {
            CameraError::NonFinite { what: "up", .. } => self.fail(
                "camera.up",
                &f.up,
                format!("camera.up must be finite (got {})", fmt_vec(f.up)),
            ),
            CameraError::NonFinite { .. } | CameraError::OriginIsTarget { .. } => self.fail(
                "camera.direction",
                d,
                format!(
                    "camera.direction must be a finite, non-zero vector (got {})",
                    fmt_vec(*d)
                ),
            ),
            CameraError::UpParallel { .. } => self.fail_at(
                &[("camera.up", &f.up), ("camera.direction", d)],
                "camera.up",
                format!(
                    "camera.up {} is zero or parallel to camera.direction {}; choose a \
                     direction across up",
                    fmt_vec(f.up),
                    fmt_vec(*d)
                ),
            ),
            CameraError::FieldOfView(fov) => self.fail(
                "camera.fov",
                &f.fov,
                format!("camera.fov must be in (0, 180) degrees (got {fov})"),
            ),
            other @ CameraError::EmptyImage { .. } => self.fail("camera", &(), other.to_string()),
        })
    }

    fn camera(&self) -> Result<(), SceneError> {
        if let Some(f) = &self.scene.framing {
            return self.framing(f);
        }
        let c = &self.scene.camera;
        let Err(e) = check_view(c.origin, c.target, c.up, c.fov) else {
            return Ok(());
        };
        Err(match e {
            CameraError::NonFinite { what, .. } => {
                let (field, value) = match what {
                    "origin" => ("camera.origin", c.origin),
                    "target" => ("camera.target", c.target),
                    _ => ("camera.up", c.up),
                };
                self.fail(
                    field,
                    &value,
                    format!("{field} must be finite (got {})", fmt_vec(value)),
                )
            }
            CameraError::OriginIsTarget { .. } => self.fail_at(
                &[("camera.target", &c.target), ("camera.origin", &c.origin)],
                "camera.target",
                format!(
                    "camera.origin and camera.target are the same point ({}); the camera must \
                     look at a point away from itself",
                    fmt_vec(c.origin)
                ),
            ),
            CameraError::UpParallel { .. } => self.fail_at(
                &[("camera.up", &c.up), ("camera.target", &c.target)],
                "camera.up",
                format!(
                    "camera.up {} is zero or parallel to the view direction {} (from origin to \
                     target); set camera.up to a direction across the view, e.g. [0, 0, 1]",
                    fmt_vec(c.up),
                    fmt_vec(c.target - c.origin)
                ),
            ),
            CameraError::FieldOfView(fov) => self.fail(
                "camera.fov",
                &c.fov,
                format!("camera.fov must be in (0, 180) degrees (got {fov})"),
            ),
            // check_view does not look at the image size; keep its message if that changes.
            other @ CameraError::EmptyImage { .. } => self.fail("camera", &(), other.to_string()),
        })
    }

    fn image(&self) -> Result<(), SceneError> {
        let im = &self.scene.image;
        for (field, value) in [("image.width", im.width), ("image.height", im.height)] {
            if let Some(message) = size_error(field, i64::from(value)) {
                return Err(self.fail(field, &value, message));
            }
        }
        Ok(())
    }

    fn render(&self) -> Result<(), SceneError> {
        let r = &self.scene.render;
        if !(0.0..=1.0).contains(&r.beta) {
            return Err(self.fail(
                "render.beta",
                &r.beta,
                format!(
                    "render.beta must be in [0, 1] (0 = exact sum, 0.5 = the paper's value) \
                     (got {})",
                    r.beta
                ),
            ));
        }
        let (field, value) = match r.epsilon {
            Epsilon::Absolute(e) => ("render.epsilon", e),
            Epsilon::Relative(e) => ("render.epsilon_rel", e),
        };
        if let Some(message) = positive_error(field, value) {
            return Err(self.fail(field, &value, message));
        }
        if let Some(message) = max_steps_error(i64::from(r.max_steps)) {
            return Err(self.fail("render.max_steps", &r.max_steps, message));
        }
        if let Some(message) =
            crate::film::options::samples_error("render.samples", r.samples.into())
        {
            return Err(self.fail("render.samples", &r.samples, message));
        }
        Ok(())
    }

    fn objects(&self) -> Result<(), SceneError> {
        if self.scene.objects.is_empty() {
            return Err(self.fail(
                "object",
                &(),
                "no [[object]] in scene: add at least one [[object]] table with a mesh or a \
                 generator"
                    .to_string(),
            ));
        }
        for (i, o) in self.scene.objects.iter().enumerate() {
            let name = format!("object[{i}]");
            if let Geometry::Mesh(path) = &o.geometry {
                let field = format!("{name}.mesh");
                if let Some(problem) = file_problem(path) {
                    return Err(self.fail(&field, path, format!("{field}: {problem}")));
                }
            }
            self.primitives(&name, &o.primitives)?;
            self.alpha(&name, "", o.alpha)?;
            if let Some(max) = o.max_alpha {
                self.alpha(&name, "max_", max)?;
            }
            self.transform(&name, &o.transform)?;
            self.matcap(&name, &o.matcap)?;
            self.lidar(&name, o)?;
        }
        Ok(())
    }

    /// Lidar objects give points only; the lidar keys need a lidar file; a colormap
    /// needs a scalar `color_by`.
    fn lidar(&self, name: &str, o: &super::Object) -> Result<(), SceneError> {
        let las = &o.las;
        let is_lidar = matches!(&o.geometry, Geometry::Mesh(p) if crate::las::is_lidar_path(p));
        if is_lidar {
            if let Some(kind) = o.primitives.iter().find(|k| **k != PrimitiveKind::Points) {
                let field = format!("{name}.primitives");
                return Err(self.fail(
                    &field,
                    &o.primitives,
                    format!(
                        "{field}: a .las/.laz file holds points only, so it cannot give {kind};                          use primitives = \"points\""
                    ),
                ));
            }
            if let Some(map) = las.colormap
                && !las.color_by.is_some_and(|c| c.is_scalar())
            {
                let field = format!("{name}.colormap");
                return Err(self.fail(
                    &field,
                    &Some(map),
                    format!(
                        "{field} colours a scalar: it needs color_by = \"intensity\" or                          \"elevation\" (got color_by = {})",
                        las.color_by
                            .map_or("none".to_string(), |c| format!("\"{}\"", c.name()))
                    ),
                ));
            }
            return Ok(());
        }
        let d = crate::las::LasOptions::default();
        let f = &las.filters;
        let given: [(&str, &dyn Debug, bool); 8] = [
            ("classes", &f.classes, f.classes != d.filters.classes),
            (
                "exclude_classes",
                &f.exclude_classes,
                f.exclude_classes != d.filters.exclude_classes,
            ),
            ("returns", &f.returns, f.returns != d.filters.returns),
            ("crop", &f.crop, f.crop != d.filters.crop),
            ("thin", &f.thin, f.thin != d.filters.thin),
            ("origin", &las.origin, las.origin.is_some()),
            ("color_by", &las.color_by, las.color_by.is_some()),
            ("colormap", &las.colormap, las.colormap.is_some()),
        ];
        if let Some((key, value, _)) = given.iter().find(|g| g.2) {
            let field = format!("{name}.{key}");
            return Err(self.fail(
                &field,
                *value,
                format!(
                    "{field} applies to lidar point clouds only (mesh = \"....las\" or                      \".laz\"); this object is not one"
                ),
            ));
        }
        Ok(())
    }

    fn primitives(
        &self,
        name: &str,
        kinds: &[crate::primitives::PrimitiveKind],
    ) -> Result<(), SceneError> {
        let field = format!("{name}.primitives");
        if kinds.is_empty() {
            return Err(self.fail(
                &field,
                &kinds,
                format!(
                    "{field} is empty: name at least one of \"points\", \"edges\", \"triangles\""
                ),
            ));
        }
        for (j, k) in kinds.iter().enumerate() {
            if kinds[..j].contains(k) {
                return Err(self.fail(
                    &field,
                    &kinds,
                    format!("{field} lists \"{k}\" twice; each primitive set can be summed once"),
                ));
            }
        }
        Ok(())
    }

    /// `prefix` is `""` for alpha and `"max_"` for max_alpha.
    fn alpha(&self, name: &str, prefix: &str, alpha: AlphaSpec) -> Result<(), SceneError> {
        let field = format!("{name}.{prefix}{}", alpha.key());
        let problem = positive_error(&field, alpha.value()).or_else(|| {
            // The limits apply to absolute alphas; a relative one is checked once the
            // object's diagonal is known (render::build).
            match alpha {
                AlphaSpec::Absolute(v) => {
                    crate::limits::alpha_problem(v).map(|p| format!("{field} {p}"))
                }
                AlphaSpec::Relative(_) => None,
            }
        });
        match problem {
            Some(message) => Err(self.fail(&field, &alpha.value(), message)),
            None => Ok(()),
        }
    }

    fn transform(&self, name: &str, t: &super::Transform) -> Result<(), SceneError> {
        let field = format!("{name}.transform.scale");
        if !t.scale.is_finite() || t.scale.cmpeq(DVec3::ZERO).any() {
            return Err(self.fail(
                &field,
                &t.scale,
                format!(
                    "{field} must be finite and non-zero in every component (got {})",
                    fmt_vec(t.scale)
                ),
            ));
        }
        for (what, v) in [("rotate", t.rotate), ("translate", t.translate)] {
            let field = format!("{name}.transform.{what}");
            if !v.is_finite() {
                return Err(self.fail(
                    &field,
                    &v,
                    format!("{field} must be finite (got {})", fmt_vec(v)),
                ));
            }
        }
        Ok(())
    }

    fn matcap(&self, name: &str, spec: &MatCapSpec) -> Result<(), SceneError> {
        let field = format!("{name}.matcap");
        match spec {
            MatCapSpec::Normal => Ok(()),
            MatCapSpec::Builtin(b) if builtin_names().contains(&b.as_str()) => Ok(()),
            MatCapSpec::Builtin(b) => Err(self.fail(
                &field,
                spec,
                format!(
                    "{field}: unknown MatCap \"{b}\"; use a built-in ({}), \"normal\", or a path \
                     to a PNG image",
                    builtin_names().join(", ")
                ),
            )),
            MatCapSpec::File(path) => match file_problem(path) {
                Some(problem) => Err(self.fail(&field, spec, format!("{field}: {problem}"))),
                None => Ok(()),
            },
        }
    }
}

/// Why `path` is not a readable regular file, if it is not (checked, not read).
fn file_problem(path: &Path) -> Option<String> {
    match std::fs::metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            Some(format!("file {} does not exist", path.display()))
        }
        Err(e) => Some(format!("cannot access {}: {e}", path.display())),
        Ok(m) if m.is_dir() => Some(format!("{} is a directory, not a file", path.display())),
        Ok(_) => None,
    }
}
