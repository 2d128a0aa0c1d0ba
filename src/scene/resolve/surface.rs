//! `surface = "signed"` and `offset = d` of a scene object (issue 32): the offset surface
//! of a closed triangle mesh's signed distance instead of the smooth distance's zero
//! set. Checked here: the name, the offset (finite, only with a signed surface), and
//! what a signed surface cannot take (primitive kinds other than triangles, alpha). That
//! the mesh is closed is checked when it is loaded (`render::build`).

use super::super::Surface;
use super::super::error::SceneError;
use super::super::raw::RawObject;
use super::Resolver;
use crate::primitives::PrimitiveKind;

impl Resolver<'_> {
    pub(super) fn surface(&mut self, name: &str, raw: &RawObject) -> Result<Surface, SceneError> {
        let signed = match &raw.surface {
            None => false,
            Some(s) => match s.get_ref().as_str() {
                "smooth" => false,
                "signed" => true,
                other => {
                    return Err(self.invalid(
                        s.span(),
                        &format!("{name}.surface"),
                        format!(
                            "{name}.surface must be \"smooth\" (the smooth distance's zero set, \
                             the default) or \"signed\" (an offset surface of a closed triangle \
                             mesh's signed distance) (got \"{other}\")"
                        ),
                    ));
                }
            },
        };
        if !signed {
            if let Some(o) = &raw.offset {
                return Err(self.invalid(
                    o.span(),
                    &format!("{name}.offset"),
                    format!(
                        "{name}.offset applies to signed surfaces; add surface = \"signed\" \
                         (on a closed triangle mesh)"
                    ),
                ));
            }
            return Ok(Surface::Smooth);
        }
        let offset = match &raw.offset {
            None => 0.0,
            Some(o) => {
                let v = self.number(&format!("{name}.offset"), o);
                if !v.is_finite() || v.abs() > crate::limits::MAX_COORD {
                    return Err(self.invalid(
                        o.span(),
                        &format!("{name}.offset"),
                        format!(
                            "{name}.offset must be a finite distance in world units, negative \
                             inside the solid (got {v})"
                        ),
                    ));
                }
                v
            }
        };
        let kinds = raw.primitives.get_ref();
        let triangles = match kinds {
            toml::Value::String(s) => s == PrimitiveKind::Triangles.name(),
            toml::Value::Array(a) => {
                a.len() == 1 && a[0].as_str() == Some(PrimitiveKind::Triangles.name())
            }
            _ => false,
        };
        if !triangles {
            return Err(self.invalid(
                raw.primitives.span(),
                &format!("{name}.primitives"),
                format!(
                    "{name}.primitives: surface = \"signed\" takes its sign from the triangles' winding \
                     number; give primitives = \"triangles\" (got {kinds})"
                ),
            ));
        }
        for (key, given) in [
            ("alpha", raw.alpha.as_ref().map(|a| a.span())),
            ("alpha_rel", raw.alpha_rel.as_ref().map(|a| a.span())),
            ("max_alpha", raw.max_alpha.as_ref().map(|a| a.span())),
            (
                "max_alpha_rel",
                raw.max_alpha_rel.as_ref().map(|a| a.span()),
            ),
        ] {
            if let Some(at) = given {
                return Err(self.invalid(
                    at,
                    &format!("{name}.{key}"),
                    format!(
                        "{name}.{key} sets the smooth distance's sharpness; a signed surface is \
                         the exact signed distance: drop {key}"
                    ),
                ));
            }
        }
        Ok(Surface::Signed { offset })
    }
}
