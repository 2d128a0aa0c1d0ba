//! The lidar keys of an `[[object]]`: filters (`classes`, `exclude_classes`, `returns`,
//! `crop`, `thin`), `origin`, and colour (`color_by`, `colormap`), resolved into
//! [`LasOptions`]; `color_by` also takes the colourings of any object (`vertex`,
//! `height`, `normal`: [`GeometryColouring`]). Values that make no sense on their own (a
//! class above 255, a voxel of size 0, an unknown name) are rejected here with their
//! location; whether the object is a lidar file at all is checked by the validator.

use super::super::error::SceneError;
use super::super::raw::{RawCrop, RawObject, RawThin};
use super::Resolver;
use crate::colour::{GeometryColorBy, GeometryColouring};
use crate::las::{ColorBy, LasFilters, LasOptions, NOISE_CLASSES, Returns, Thin};
use crate::rgb::Colormap;
use glam::DVec3;
use toml::Spanned;

/// A lidar attribute and its colormap, or a geometric colouring (at most one is set).
type ColourKeys = (Option<ColorBy>, Option<Colormap>, Option<GeometryColouring>);

impl Resolver<'_> {
    pub(super) fn lidar(
        &mut self,
        name: &str,
        raw: &RawObject,
    ) -> Result<(LasOptions, Option<GeometryColouring>), SceneError> {
        let classes = match &raw.classes {
            None => None,
            Some(v) => Some(self.class_list(name, "classes", v)?),
        };
        let exclude_classes = match &raw.exclude_classes {
            Some(v) => self.class_list(name, "exclude_classes", v)?,
            // Naming the classes to keep replaces the default noise exclusion.
            None if classes.is_some() => Vec::new(),
            None => NOISE_CLASSES.to_vec(),
        };
        let returns = match &raw.returns {
            None => Returns::All,
            Some(v) => self.named(name, "returns", v, Returns::from_name, || {
                format!("must be {}", Returns::NAMES)
            })?,
        };
        let crop = match &raw.crop {
            None => None,
            Some(c) => Some(self.crop(name, c)?),
        };
        let thin = match &raw.thin {
            None => None,
            Some(t) => Some(self.thin(name, t)?),
        };
        let origin = match &raw.origin {
            None => None,
            Some(o) => {
                let key = format!("{name}.origin");
                let v = DVec3::from_array(*o.get_ref());
                if !v.is_finite() {
                    return Err(self.invalid(
                        o.span(),
                        &key,
                        format!("{key} must be finite (got {:?})", o.get_ref()),
                    ));
                }
                self.record(&key, o.span(), &Some(v));
                Some(v)
            }
        };
        let (color_by, colormap, geometry) = self.colour_keys(name, raw)?;
        let options = LasOptions {
            filters: LasFilters {
                classes,
                exclude_classes,
                returns,
                crop,
                thin,
            },
            color_by,
            colormap,
            origin,
        };
        Ok((options, geometry))
    }

    /// `color_by` and `colormap`: a lidar attribute (with its colormap, checked against
    /// the file by the validator) or a geometric colouring for any object.
    fn colour_keys(&mut self, name: &str, raw: &RawObject) -> Result<ColourKeys, SceneError> {
        let colormap = match &raw.colormap {
            None => None,
            Some(v) => Some(self.named(name, "colormap", v, Colormap::from_name, || {
                format!(
                    "names an unknown colormap; expected one of {}",
                    Colormap::names()
                )
            })?),
        };
        let Some(v) = &raw.color_by else {
            if let Some(map) = &raw.colormap {
                let key = format!("{name}.colormap");
                return Err(self.invalid(
                    map.span(),
                    &key,
                    format!(
                        "{key} colours a scalar: give color_by = \"height\" (or \"intensity\" \
                         or \"elevation\" for lidar files) with it"
                    ),
                ));
            }
            return Ok((None, None, None));
        };
        let key = format!("{name}.color_by");
        if let Some(by) = GeometryColorBy::from_name(v.get_ref()) {
            self.record(&key, v.span(), &Some(by));
            let is_lidar = raw
                .mesh
                .as_ref()
                .is_some_and(|m| crate::las::is_lidar_path(std::path::Path::new(m.get_ref())));
            if by == GeometryColorBy::Vertex && (is_lidar || raw.mesh.is_none()) {
                let why = if is_lidar {
                    "a lidar file's colours are color_by = \"rgb\""
                } else {
                    "a generated shape has no vertex colours; use \"height\" or \"normal\""
                };
                return Err(self.invalid(
                    v.span(),
                    &key,
                    format!("{key} = \"vertex\" reads a PLY or OBJ file's colours: {why}"),
                ));
            }
            if let (Some(map), false) = (&raw.colormap, by == GeometryColorBy::Height) {
                let key = format!("{name}.colormap");
                return Err(self.invalid(
                    map.span(),
                    &key,
                    format!(
                        "{key} colours a scalar: it needs color_by = \"height\" (got color_by \
                         = \"{}\")",
                        by.name()
                    ),
                ));
            }
            let colouring = GeometryColouring {
                by,
                colormap: colormap.unwrap_or(Colormap::Viridis),
            };
            return Ok((None, None, Some(colouring)));
        }
        let Some(by) = ColorBy::from_name(v.get_ref()) else {
            return Err(self.invalid(
                v.span(),
                &key,
                format!(
                    "{key} must be {} (any object) or {} (lidar files) (got \"{}\")",
                    GeometryColorBy::NAMES,
                    ColorBy::NAMES,
                    v.get_ref()
                ),
            ));
        };
        self.record(&key, v.span(), &Some(by));
        Ok((Some(by), colormap, None))
    }

    /// A name looked up by `parse`, recorded under `name.key` (as an `Option`, the way
    /// the validator sees `color_by` and `colormap`; `returns` is recorded bare).
    fn named<T: std::fmt::Debug + Copy>(
        &mut self,
        name: &str,
        key: &str,
        v: &Spanned<String>,
        parse: impl Fn(&str) -> Option<T>,
        expected: impl Fn() -> String,
    ) -> Result<T, SceneError> {
        let key = format!("{name}.{key}");
        let Some(value) = parse(v.get_ref()) else {
            return Err(self.invalid(
                v.span(),
                &key,
                format!("{key} {} (got \"{}\")", expected(), v.get_ref()),
            ));
        };
        if key.ends_with(".returns") {
            self.record(&key, v.span(), &value);
        } else {
            self.record(&key, v.span(), &Some(value));
        }
        Ok(value)
    }

    /// A list of ASPRS classes (0..=255), recorded under `name.key`.
    fn class_list(
        &mut self,
        name: &str,
        key: &str,
        v: &Spanned<Vec<i64>>,
    ) -> Result<Vec<u8>, SceneError> {
        let key = format!("{name}.{key}");
        let classes = v
            .get_ref()
            .iter()
            .map(|&c| u8::try_from(c).ok())
            .collect::<Option<Vec<u8>>>()
            .ok_or_else(|| {
                self.invalid(
                    v.span(),
                    &key,
                    format!(
                        "{key} must list ASPRS class numbers in 0..=255 (got {:?})",
                        v.get_ref()
                    ),
                )
            })?;
        if key.ends_with(".classes") {
            self.record(&key, v.span(), &Some(classes.clone()));
        } else {
            self.record(&key, v.span(), &classes);
        }
        Ok(classes)
    }

    fn crop(&mut self, name: &str, c: &Spanned<RawCrop>) -> Result<[DVec3; 2], SceneError> {
        let key = format!("{name}.crop");
        let (min, max) = (
            DVec3::from_array(c.get_ref().min),
            DVec3::from_array(c.get_ref().max),
        );
        if !(min.is_finite() && max.is_finite() && min.cmple(max).all()) {
            return Err(self.invalid(
                c.span(),
                &key,
                format!(
                    "{key} needs finite min and max with min <= max in every coordinate (got \
                     min = {:?}, max = {:?})",
                    c.get_ref().min,
                    c.get_ref().max
                ),
            ));
        }
        self.record(&key, c.span(), &Some([min, max]));
        Ok([min, max])
    }

    fn thin(&mut self, name: &str, t: &Spanned<RawThin>) -> Result<Thin, SceneError> {
        let key = format!("{name}.thin");
        let raw = t.get_ref();
        let thin = match (raw.voxel, raw.every) {
            (Some(v), None) if v > 0.0 && v.is_finite() => Thin::Voxel(v),
            (Some(v), None) => {
                return Err(self.invalid(
                    t.span(),
                    &key,
                    format!("{key}.voxel must be a finite size > 0 (got {v})"),
                ));
            }
            (None, Some(k)) if k >= 1 => Thin::Every(k as u64),
            (None, Some(k)) => {
                return Err(self.invalid(
                    t.span(),
                    &key,
                    format!("{key}.every must be an integer >= 1 (got {k})"),
                ));
            }
            _ => {
                return Err(self.invalid(
                    t.span(),
                    &key,
                    format!(
                        "{key} needs exactly one of voxel (a cube size, e.g. thin = {{ voxel = \
                         1.0 }}) or every (keep one point in k, e.g. thin = {{ every = 4 }})"
                    ),
                ));
            }
        };
        self.record(&key, t.span(), &Some(thin));
        Ok(thin)
    }
}
