//! `render` (a scene file, as `smoothtrace render`) and `render_arrays` (a mesh given as
//! arrays): images as `(height, width, 4)` uint8 RGBA arrays, alpha 255 everywhere.

use crate::arrays::{kinds, mesh, output};
use crate::errors::{guard, to_py};
use glam::DVec3;
use numpy::ndarray::Ix3;
use numpy::{PyArray3, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use smoothtrace::api::params::{Naming, SceneOverrides, check_image_size, check_threads};
use smoothtrace::api::queries::{self, ObjectSpec};
use smoothtrace::api::view::{ImageRequest, RenderError, render_object};
use smoothtrace::matcap::MatCapSpec;
use smoothtrace::render::image::Rendered;
use smoothtrace::render::pipeline;
use smoothtrace::scene::{AlphaSpec, CameraSettings, Scene};
use std::path::{Path, PathBuf};

type Image<'py> = Bound<'py, PyArray3<u8>>;

/// A camera from Python: origin, target, up, vertical field of view in degrees.
type CameraArgs = ([f64; 3], [f64; 3], [f64; 3], f64);

fn rgba<'py>(py: Python<'py>, r: &Rendered) -> PyResult<Image<'py>> {
    let (w, h) = (r.image.width() as usize, r.image.height() as usize);
    // Straight alpha from a transparent scene, 255 otherwise.
    let values = r.to_dynamic().to_rgba8().into_raw();
    output::<_, Ix3>(py, (h, w, 4), values)
}

/// Renders a scene file; the keyword arguments override the scene's values.
#[pyfunction]
#[pyo3(signature = (scene, width=None, height=None, beta=None, alpha=None, alpha_rel=None, threads=None))]
#[allow(clippy::too_many_arguments)]
pub fn render<'py>(
    py: Python<'py>,
    scene: PathBuf,
    width: Option<i64>,
    height: Option<i64>,
    beta: Option<f64>,
    alpha: Option<f64>,
    alpha_rel: Option<f64>,
    threads: Option<i64>,
) -> PyResult<Image<'py>> {
    guard(|| {
        if alpha.is_some() && alpha_rel.is_some() {
            return Err(PyValueError::new_err("give alpha or alpha_rel, not both"));
        }
        let overrides = SceneOverrides {
            width,
            height,
            beta,
            alpha: alpha
                .map(AlphaSpec::Absolute)
                .or(alpha_rel.map(AlphaSpec::Relative)),
            threads,
        };
        let mut s = Scene::load(&scene).map_err(to_py)?;
        overrides.apply(&mut s, Naming::Keyword).map_err(to_py)?;
        s.validate().map_err(to_py)?;
        let (_, rendered) = py
            .detach(|| pipeline::render_scene(&s, |o| o, &|_| {}))
            .map_err(to_py)?;
        if rendered.stats.camera_inside {
            return Err(to_py(RenderError::CameraInside {
                origin: s.camera.origin,
            }));
        }
        rgba(py, &rendered)
    })
}

/// Renders the smooth surface of a mesh given as arrays.
#[pyfunction]
#[pyo3(signature = (vertices, faces, edges, primitives, alpha, alpha_rel, max_alpha, max_alpha_rel, beta, camera, matcap, width, height, background, threads))]
#[allow(clippy::too_many_arguments)]
pub fn render_arrays<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: Option<PyReadonlyArray2<'py, i64>>,
    edges: Option<PyReadonlyArray2<'py, i64>>,
    primitives: Vec<String>,
    alpha: Option<f64>,
    alpha_rel: Option<f64>,
    max_alpha: Option<f64>,
    max_alpha_rel: Option<f64>,
    beta: f64,
    camera: Option<CameraArgs>,
    matcap: String,
    width: i64,
    height: i64,
    background: [u8; 3],
    threads: Option<i64>,
) -> PyResult<Image<'py>> {
    guard(|| {
        let m = mesh(&vertices, faces.as_ref(), edges.as_ref())?;
        let spec = ObjectSpec {
            kinds: kinds(&primitives)?,
            alpha,
            alpha_rel,
            max_alpha,
            max_alpha_rel,
            beta,
            tolerance: None,
        };
        let request = ImageRequest {
            width: check_image_size("width", width).map_err(to_py)?,
            height: check_image_size("height", height).map_err(to_py)?,
            background,
            camera: camera.map(|(o, t, u, fov)| CameraSettings {
                origin: DVec3::from(o),
                target: DVec3::from(t),
                up: DVec3::from(u),
                fov,
            }),
            matcap: MatCapSpec::parse(&matcap, Path::new("")),
            threads: threads
                .map(|t| check_threads("threads", t))
                .transpose()
                .map_err(to_py)?,
        };
        let rendered = py
            .detach(|| {
                let object = queries::build_object(&m, &spec, Naming::Keyword)?;
                render_object(object, &request)
            })
            .map_err(to_py)?;
        rgba(py, &rendered)
    })
}
