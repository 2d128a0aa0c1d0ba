//! `distance_field`: an exact (or smooth) distance volume of a mesh given as arrays
//! (SPEC 9), the same computation as `smoothtrace field`; `FieldPlan`: the same field
//! prepared once and computed box by box (the blocks of `smoothtrace.dask`, issue 33).

use crate::arrays::{kinds, mesh, output};
use crate::errors::{guard, to_py};
use glam::DVec3;
use numpy::ndarray::Ix3;
use numpy::{PyArray3, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use smoothtrace::api::params::{Naming, check_beta, check_threads, resolve_alpha};
use smoothtrace::api::with_threads;
use smoothtrace::field::{self, FieldOptions, FieldSource, Grid, Method, VoxelBox};
use smoothtrace::mesh::Mesh;
use smoothtrace::primitives::PrimitiveKind;

type FieldResult<'py> = (Bound<'py, PyArray3<f64>>, [f64; 3], [f64; 3]);

/// The field's inputs, checked: the mesh, primitive, grid, method, options, threads.
type Resolved = (
    Mesh,
    PrimitiveKind,
    Grid,
    Method,
    FieldOptions,
    Option<usize>,
);

/// Checks and converts the arguments shared by `distance_field` and `FieldPlan`.
#[allow(clippy::too_many_arguments)]
fn resolve(
    vertices: &PyReadonlyArray2<'_, f64>,
    faces: Option<&PyReadonlyArray2<'_, i64>>,
    edges: Option<&PyReadonlyArray2<'_, i64>>,
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
) -> PyResult<Resolved> {
    let m = mesh(vertices, faces, edges)?;
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
    Ok((m, kind, grid, method, options, threads))
}

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
        let (m, kind, grid, method, options, threads) = resolve(
            &vertices,
            faces.as_ref(),
            edges.as_ref(),
            primitive,
            bounds,
            resolution,
            method,
            smooth_alpha,
            smooth_alpha_rel,
            max_alpha,
            beta,
            band,
            threads,
        )?;
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

/// A field prepared once (sites or BVH built) whose boxes are computed on demand, with
/// the GIL released. Built with the arguments of `distance_field`.
#[pyclass(frozen, module = "smoothtrace._native")]
pub struct FieldPlan {
    plan: field::FieldPlan,
    threads: Option<usize>,
}

#[pymethods]
impl FieldPlan {
    #[new]
    #[pyo3(signature = (vertices, faces, edges, primitive, bounds, resolution, method, smooth_alpha, smooth_alpha_rel, max_alpha, beta, band, threads))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        vertices: PyReadonlyArray2<'_, f64>,
        faces: Option<PyReadonlyArray2<'_, i64>>,
        edges: Option<PyReadonlyArray2<'_, i64>>,
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
    ) -> PyResult<FieldPlan> {
        guard(|| {
            let (m, kind, grid, method, options, threads) = resolve(
                &vertices,
                faces.as_ref(),
                edges.as_ref(),
                primitive,
                bounds,
                resolution,
                method,
                smooth_alpha,
                smooth_alpha_rel,
                max_alpha,
                beta,
                band,
                threads,
            )?;
            let plan = py
                .detach(|| {
                    with_threads(threads, || {
                        field::FieldPlan::new(&m, kind, &grid, method, &options)
                    })
                    .map_err(|e| e.to_string())
                })
                .map_err(PyValueError::new_err)?
                .map_err(to_py)?;
            Ok(FieldPlan { plan, threads })
        })
    }

    /// `(min, max, (nx, ny, nz))` of the grid.
    fn grid(&self) -> ([f64; 3], [f64; 3], [usize; 3]) {
        let g = self.plan.grid();
        (g.min.to_array(), g.max.to_array(), g.res)
    }

    /// The float32 values of voxels `start .. start + size` (x, y, z), shape
    /// `(size_z, size_y, size_x)`.
    fn compute_box<'py>(
        &self,
        py: Python<'py>,
        start: [usize; 3],
        size: [usize; 3],
    ) -> PyResult<Bound<'py, PyArray3<f32>>> {
        guard(|| {
            let b = VoxelBox { start, size };
            if !b.fits(self.plan.grid()) {
                return Err(PyValueError::new_err(format!(
                    "box start {start:?} size {size:?} (x, y, z) is empty or outside the grid of {:?} voxels",
                    self.plan.grid().res
                )));
            }
            let values = py
                .detach(|| {
                    with_threads(self.threads, || {
                        let mut v = vec![0.0f32; b.len()];
                        self.plan.compute_box(&b, &mut v);
                        v
                    })
                    .map_err(|e| e.to_string())
                })
                .map_err(PyValueError::new_err)?;
            output::<_, Ix3>(py, (size[2], size[1], size[0]), values)
        })
    }
}
