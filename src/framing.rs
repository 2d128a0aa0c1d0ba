//! Auto-framing: a camera that shows the whole scene (issue 11, item 3).
//!
//! The scene's bounding sphere is taken around the centre of the objects' boxes, each
//! box grown by how far its surface can reach (the quantity the tracer clips rays with,
//! SPEC 7; the renderer passes the grown boxes in,
//! `crate::render::TraceObject::reach_bounds`): radius = half the diagonal of their
//! union. The
//! camera looks at the centre from `direction` at the distance where the sphere fits
//! both the vertical and the horizontal field of view with `margin` to spare
//! (`distance = (1 + margin) radius / sin(half angle)`).

use crate::camera::CameraSettings;
use glam::DVec3;

/// The default view direction (from the centre towards the camera): a three-quarter
/// view from the front right and above, with +y up.
pub const DEFAULT_DIRECTION: DVec3 = DVec3::new(1.0, 0.7, 1.6);

/// The default share of the radius left free around the sphere.
pub const DEFAULT_MARGIN: f64 = 0.05;

/// How to frame a scene; see the module docs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Framing {
    /// From the scene's centre towards the camera (any length but zero).
    pub direction: DVec3,
    pub up: DVec3,
    /// Vertical field of view, degrees.
    pub fov: f64,
    pub margin: f64,
}

/// The box everything the surfaces can reach lies in, the union of the objects' boxes
/// grown by their reach (`(min, max)` each); `None` without objects or when a bound is
/// not finite.
pub fn reach_box(grown: impl IntoIterator<Item = (DVec3, DVec3)>) -> Option<(DVec3, DVec3)> {
    let mut min = DVec3::splat(f64::INFINITY);
    let mut max = DVec3::splat(f64::NEG_INFINITY);
    let mut any = false;
    for (lo, hi) in grown {
        any = true;
        min = min.min(lo);
        max = max.max(hi);
    }
    (any && min.is_finite() && max.is_finite()).then_some((min, max))
}

/// The camera framing a sphere of `radius` around `centre` for an image of `aspect`
/// (width over height).
pub fn fit_sphere(centre: DVec3, radius: f64, aspect: f64, f: &Framing) -> CameraSettings {
    let radius = if radius > 0.0 && radius.is_finite() {
        radius
    } else {
        1.0
    };
    let half_v = 0.5 * f.fov.to_radians();
    let half_h = (half_v.tan() * aspect).atan();
    let half = half_v.min(half_h);
    let distance = (1.0 + f.margin) * radius / half.sin();
    let dir = f.direction.normalize_or(DEFAULT_DIRECTION.normalize());
    CameraSettings {
        origin: centre + distance * dir,
        target: centre,
        up: f.up,
        fov: f.fov,
    }
}

/// The camera framing the objects whose grown boxes are `grown` (see the module docs);
/// `None` without objects.
pub fn fit_boxes(
    grown: impl IntoIterator<Item = (DVec3, DVec3)>,
    aspect: f64,
    f: &Framing,
) -> Option<CameraSettings> {
    let (min, max) = reach_box(grown)?;
    Some(fit_sphere(
        0.5 * (min + max),
        0.5 * (max - min).length(),
        aspect,
        f,
    ))
}

/// The camera as TOML that can be pasted into a scene file.
pub fn camera_toml(c: &CameraSettings) -> String {
    // `{:?}` prints the shortest decimal that reads back as the same f64, with a point.
    let v = |v: DVec3| format!("[{:?}, {:?}, {:?}]", v.x, v.y, v.z);
    format!(
        "[camera]\norigin = {}\ntarget = {}\nup = {}\nfov = {:?}",
        v(c.origin),
        v(c.target),
        v(c.up),
        c.fov
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sphere_touches_the_frame_with_the_margin() {
        let f = Framing {
            direction: DVec3::new(0.0, 0.0, 2.0),
            up: DVec3::Y,
            fov: 60.0,
            margin: 0.1,
        };
        // Wide image: the vertical field of view decides.
        let c = fit_sphere(DVec3::ONE, 2.0, 16.0 / 9.0, &f);
        let d = (c.origin - c.target).length();
        let angle = (2.0 / d).asin().to_degrees();
        assert!((angle * 1.1 - 30.0).abs() < 1.0, "{angle}");
        assert!((2.0 * 1.1 / d - 0.5).abs() < 1e-12);
        assert_eq!(c.target, DVec3::ONE);
        assert!((c.origin - DVec3::new(1.0, 1.0, 1.0 + d)).length() < 1e-12);
        // Tall image: the horizontal one, narrower, puts the camera farther away.
        let tall = fit_sphere(DVec3::ONE, 2.0, 0.5, &f);
        assert!((tall.origin - tall.target).length() > d * 1.5);
    }

    #[test]
    fn toml_round_trips_through_a_scene_file() {
        let c = fit_sphere(
            DVec3::ZERO,
            1.0,
            1.5,
            &Framing {
                direction: DEFAULT_DIRECTION,
                up: DVec3::Y,
                fov: 45.0,
                margin: DEFAULT_MARGIN,
            },
        );
        let text = camera_toml(&c);
        let t: toml::Table = toml::from_str(&text).unwrap();
        let cam = t["camera"].as_table().unwrap();
        let origin: Vec<f64> = cam["origin"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_float().unwrap())
            .collect();
        assert_eq!(origin, c.origin.to_array());
        assert_eq!(cam["fov"].as_float(), Some(45.0));
    }
}
