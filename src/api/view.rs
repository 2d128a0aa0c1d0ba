//! Rendering objects built in memory: a default camera that frames the object, and the
//! same tracer and image loop as scene files ([`pipeline::render_built`]), with the
//! scene defaults for epsilon (`4e-4` of the diagonal) and max_steps.

use super::{InputError, with_threads};
use crate::camera::{Camera, CameraError};
use crate::matcap::{MatCap, MatCapError, MatCapSpec};
use crate::render::TraceObject;
use crate::render::build::BuiltScene;
use crate::render::image::Rendered;
use crate::render::pipeline;
use crate::scene::{CameraSettings, RenderSettings};
use glam::DVec3;

/// Why an in-memory object could not be rendered.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error(transparent)]
    Input(#[from] InputError),
    #[error("camera: {0}")]
    Camera(#[from] CameraError),
    #[error("matcap: {0}")]
    MatCap(#[from] MatCapError),
    #[error(
        "the camera at {origin} is inside the surface (the smooth distance there is <= 0): move it out, or raise alpha"
    )]
    CameraInside { origin: DVec3 },
}

/// Image settings of an in-memory render.
#[derive(Clone, Debug)]
pub struct ImageRequest {
    pub width: u32,
    pub height: u32,
    pub background: [u8; 3],
    /// `None`: [`default_camera`].
    pub camera: Option<CameraSettings>,
    pub matcap: MatCapSpec,
    /// Worker threads (`None`: the current pool, `Some(0)`: all cores).
    pub threads: Option<usize>,
}

/// Direction from the object's centre to the default camera: in front (+z), a little
/// above.
const VIEW_DIRECTION: DVec3 = DVec3::new(0.0, 0.35, 1.0);

/// A camera looking at the centre of the object's bounding box from the front and a
/// little above, far enough that the sphere holding everything the surface can reach
/// (the box's half diagonal plus [`TraceObject::reach`]) fits the vertical field of view.
pub fn default_camera(object: &TraceObject) -> CameraSettings {
    let b = object.bounds;
    let centre = b.center().as_dvec3();
    let radius = 0.5 * b.diagonal() + object.reach(object.params.alpha).max(0.0);
    let radius = if radius > 0.0 && radius.is_finite() {
        radius
    } else {
        1.0
    };
    let half_fov = 0.5 * Camera::DEFAULT_FOV_Y.to_radians();
    let distance = 1.05 * radius / half_fov.sin();
    CameraSettings::looking_at(centre + distance * VIEW_DIRECTION.normalize(), centre)
}

/// Renders one object with `matcap`; the camera must be outside the surface.
pub fn render_object(object: TraceObject, image: &ImageRequest) -> Result<Rendered, RenderError> {
    let settings = image.camera.unwrap_or_else(|| default_camera(&object));
    let camera = settings.build(image.width, image.height)?;
    let shader = MatCap::from_spec(&image.matcap)?;
    let render = RenderSettings::default();
    let bounds = object.bounds;
    let diagonal = bounds.diagonal();
    let built = BuiltScene {
        objects: vec![object],
        shaders: vec![shader],
        camera,
        epsilon: render.epsilon.resolve(bounds.diagonal()),
        bounds,
        steps: Vec::new(),
        diagonals: vec![diagonal],
        certified_hits: render.certified_hits,
    };
    let rendered = with_threads(image.threads, || {
        pipeline::render_built(&built, render.max_steps, image.background, |o| o, &|_| {})
    })?;
    if rendered.stats.camera_inside {
        return Err(RenderError::CameraInside {
            origin: settings.origin,
        });
    }
    Ok(rendered)
}
