//! numpy arrays in and out: inputs are copied into Rust vectors (so the work can run
//! without the GIL while Python code may touch the arrays), outputs are moved into new
//! numpy arrays.

use crate::errors::to_py;
use glam::DVec3;
use numpy::ndarray::{Array, Dimension, IntoDimension};
use numpy::{Element, IntoPyArray, PyArray, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use smoothtrace::api::arrays::{mesh_from_arrays, points_from_array};
use smoothtrace::mesh::Mesh;
use smoothtrace::primitives::PrimitiveKind;

/// The values of an `(n, width)` array in row-major order.
pub fn rows<T: Element + Copy>(
    a: &PyReadonlyArray2<'_, T>,
    name: &str,
    width: usize,
) -> PyResult<Vec<T>> {
    let view = a.as_array();
    let shape = view.shape();
    if shape[1] != width {
        return Err(PyValueError::new_err(format!(
            "{name} must have shape (n, {width}), got ({}, {})",
            shape[0], shape[1]
        )));
    }
    Ok(view.iter().copied().collect())
}

/// A new numpy array of `shape` holding `values` (row-major).
pub fn output<'py, T: Element, D: Dimension>(
    py: Python<'py>,
    shape: impl IntoDimension<Dim = D>,
    values: Vec<T>,
) -> PyResult<Bound<'py, PyArray<T, D>>> {
    let a = Array::from_shape_vec(shape, values)
        .map_err(|e| PyValueError::new_err(format!("output shape: {e}")))?;
    Ok(a.into_pyarray(py))
}

/// A mesh from the vertex array `V` and the optional `faces` and `edges` index arrays.
pub fn mesh(
    vertices: &PyReadonlyArray2<'_, f64>,
    faces: Option<&PyReadonlyArray2<'_, i64>>,
    edges: Option<&PyReadonlyArray2<'_, i64>>,
) -> PyResult<Mesh> {
    let v = rows(vertices, "V", 3)?;
    let f = match faces {
        Some(f) => rows(f, "faces", 3)?,
        None => Vec::new(),
    };
    let e = match edges {
        Some(e) => rows(e, "edges", 2)?,
        None => Vec::new(),
    };
    mesh_from_arrays(&v, &f, &e, ["V", "faces", "edges"]).map_err(to_py)
}

/// Primitive kinds by name (`points`, `edges`, `triangles`).
pub fn kinds(names: &[String]) -> PyResult<Vec<PrimitiveKind>> {
    names
        .iter()
        .map(|n| match n.as_str() {
            "points" => Ok(PrimitiveKind::Points),
            "edges" => Ok(PrimitiveKind::Edges),
            "triangles" => Ok(PrimitiveKind::Triangles),
            _ => Err(PyValueError::new_err(format!(
                "unknown primitive type '{n}': expected points, edges or triangles"
            ))),
        })
        .collect()
}

/// Query points from an `(n, 3)` array (finite coordinates); a C-contiguous array is
/// read in place (no copy before the conversion).
pub fn points(p: &PyReadonlyArray2<'_, f64>, name: &str) -> PyResult<Vec<DVec3>> {
    let view = p.as_array();
    if let (3, Some(flat)) = (view.shape()[1], view.as_slice()) {
        return points_from_array(flat, name).map_err(to_py);
    }
    points_from_array(&rows(p, name, 3)?, name).map_err(to_py)
}
