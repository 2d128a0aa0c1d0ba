//! `distance_field`: an exact (or smooth) distance volume of a mesh given as arrays
//! (SPEC 9), the same computation as `smoothtrace field`.

use crate::arrays::{kinds, mesh, output};
use crate::errors::{guard, to_py};
use glam::DVec3;
use numpy::ndarray::Ix3;
use numpy::{PyArray3, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use smoothtrace::api::params::{Naming, check_beta, check_threads, resolve_alpha};
use smoothtrace::api::with_threads;
use smoothtrace::field::{self, FieldOptions, Grid, Method};

type FieldResult<'py> = (Bound<'py, PyArray3<f64>>, [f64; 3], [f64; 3]);

/// Returns `(field (nz, ny, nx) float64, grid min, grid max)`.
#[pyfunction]
#[pyo3(signature = (vertices, faces, edges, primitive, bounds, resolution, method, smooth_alpha, smooth_alpha_rel, max_alpha, beta, band, threads))]
#[allow(clippy::too_many_arguments)]
pub fn distance_field<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: Option<PyReadonlyArray2<'py, i64>>,
    edges: Option<PyReadonlyArray2<'py, i64>>,
    primitive: String,
    bounds: Option<[f64; 6]>,
    resolution: Vec<i64>,
    method: String,
    smooth_alpha: Option<f64>,
    smooth_alpha_rel: Option<f64>,
    max_alpha: Option<f64>,
    beta: f64,
    band: Option<f64>,
    threads: Option<i64>,
) -> PyResult<FieldResult<'py>> {
    guard(|| {
        let m = mesh(&vertices, faces.as_ref(), edges.as_ref())?;
        let kind = kinds(&[primitive])?[0];
        let threads = threads
            .map(|t| check_threads("threads", t))
            .transpose()
            .map_err(to_py)?;
        let (min, max) = match bounds {
            Some(b) => (DVec3::new(b[0], b[1], b[2]), DVec3::new(b[3], b[4], b[5])),
            None => Grid::default_bounds(m.bounds()).map_err(to_py)?,
        };
        let mut res = [0usize; 3];
        for (r, &v) in res.iter_mut().zip(&resolution) {
            *r = usize::try_from(v).map_err(|_| {
                PyValueError::new_err(format!("resolution must hold positive integers (got {v})"))
            })?;
        }
        let grid = match resolution.len() {
            1 => Grid::cubic(min, max, res[0]),
            3 => Grid::new(min, max, res),
            n => {
                return Err(PyValueError::new_err(format!(
                    "resolution must be one integer (voxels along the longest axis) or three (nx, ny, nz); got {n} values"
                )));
            }
        }
        .map_err(to_py)?;
        let diag = m.bounds().diagonal();
        let smooth = resolve_alpha(
            Naming::Keyword,
            "smooth_alpha",
            smooth_alpha,
            smooth_alpha_rel,
            diag,
        )
        .map_err(to_py)?;
        let method = match (smooth, method.as_str()) {
            (Some(alpha), "linfac") => Method::Smooth {
                alpha,
                max_alpha: max_alpha.unwrap_or(alpha),
                beta: check_beta(Naming::Keyword, beta).map_err(to_py)?,
            },
            (Some(_), other) => {
                return Err(PyValueError::new_err(format!(
                    "smooth_alpha computes the smooth distance per voxel; drop method='{other}'"
                )));
            }
            (None, "linfac") => Method::Linfac,
            (None, "bvh") => Method::Bvh,
            (None, "brute") => Method::Brute,
            (None, other) => {
                return Err(PyValueError::new_err(format!(
                    "unknown method '{other}': expected linfac, bvh or brute"
                )));
            }
        };
        let options = FieldOptions {
            band,
            ..FieldOptions::default()
        };
        let (f, _) = py
            .detach(|| {
                with_threads(threads, || {
                    field::compute(&m, kind, &grid, method, &options)
                })
                .map_err(|e| e.to_string())
            })
            .map_err(PyValueError::new_err)?
            .map_err(to_py)?;
        let [nx, ny, nz] = grid.res;
        let values = f.values.iter().map(|&v| f64::from(v)).collect();
        Ok((
            output::<_, Ix3>(py, (nz, ny, nx), values)?,
            grid.min.to_array(),
            grid.max.to_array(),
        ))
    })
}
