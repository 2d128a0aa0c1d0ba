//! `load_mesh`: a mesh file (OBJ, PLY, STL) as vertex, triangle and segment arrays.

use crate::arrays::output;
use crate::errors::{guard, to_py};
use numpy::{PyArray2, ndarray::Ix2};
use pyo3::prelude::*;
use smoothtrace::api::arrays::{flat_indices, flat_vertices};
use std::path::PathBuf;

type MeshArrays<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray2<i64>>,
);

/// Reads a mesh file: `(V (n, 3) float64, F (m, 3) int64, E (k, 2) int64)`.
#[pyfunction]
pub fn load_mesh<'py>(py: Python<'py>, path: PathBuf) -> PyResult<MeshArrays<'py>> {
    guard(|| {
        let mesh = py
            .detach(|| smoothtrace::load::load_mesh(&path))
            .map_err(to_py)?;
        Ok((
            output::<_, Ix2>(py, (mesh.vertices.len(), 3), flat_vertices(&mesh.vertices))?,
            output::<_, Ix2>(py, (mesh.triangles.len(), 3), flat_indices(&mesh.triangles))?,
            output::<_, Ix2>(py, (mesh.segments.len(), 2), flat_indices(&mesh.segments))?,
        ))
    })
}
