//! `winding_number` and `signed_distance`: a triangle soup's fast winding numbers and
//! signed distances at many points (issue 32), through [`smoothtrace::api::signed`].

use crate::arrays::{output, rows};
use crate::errors::{guard, to_py};
use numpy::ndarray::{Ix1, Ix2};
use numpy::{PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use smoothtrace::api::arrays::mesh_from_arrays;
use smoothtrace::api::params::check_threads;
use smoothtrace::api::{InputError, signed, with_threads};
use smoothtrace::mesh::Mesh;

type Arr1<'py> = Bound<'py, PyArray1<f64>>;
type Arr2<'py> = Bound<'py, PyArray2<f64>>;

/// Thread count from Python (`None` = the current pool).
fn threads(t: Option<i64>) -> PyResult<Option<usize>> {
    t.map(|t| check_threads("threads", t).map_err(to_py))
        .transpose()
}

/// The mesh `(V, F)`, errors naming `V` and `F` as the Python functions do.
fn mesh(vertices: &PyReadonlyArray2<'_, f64>, faces: &PyReadonlyArray2<'_, i64>) -> PyResult<Mesh> {
    let v = rows(vertices, "V", 3)?;
    let f = rows(faces, "F", 3)?;
    mesh_from_arrays(&v, &f, &[], ["V", "F", "edges"]).map_err(to_py)
}

/// The fast winding number of the triangles `(V, F)` at each row of `P`.
#[pyfunction]
#[pyo3(signature = (vertices, faces, points, beta, threads=None))]
pub fn winding_number<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, i64>,
    points: PyReadonlyArray2<'py, f64>,
    beta: f64,
    threads: Option<i64>,
) -> PyResult<Arr1<'py>> {
    guard(|| {
        let m = mesh(&vertices, &faces)?;
        let p = crate::arrays::points(&points, "P")?;
        let t = self::threads(threads)?;
        let w = py
            .detach(|| {
                with_threads(t, || {
                    let solid = signed::build_solid(&m, beta, "beta")?;
                    Ok::<_, InputError>(signed::winding_numbers(&solid, &p))
                })?
            })
            .map_err(to_py)?;
        output::<_, Ix1>(py, w.len(), w)
    })
}

/// The signed distance of the triangles `(V, F)` at each row of `P`: `(S, idx, closest)`.
#[pyfunction]
#[pyo3(signature = (vertices, faces, points, beta, threads=None))]
#[allow(clippy::type_complexity)]
pub fn signed_distance<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, i64>,
    points: PyReadonlyArray2<'py, f64>,
    beta: f64,
    threads: Option<i64>,
) -> PyResult<(Arr1<'py>, Bound<'py, PyArray1<i64>>, Arr2<'py>)> {
    guard(|| {
        let m = mesh(&vertices, &faces)?;
        let p = crate::arrays::points(&points, "P")?;
        let t = self::threads(threads)?;
        let (s, near) = py
            .detach(|| {
                with_threads(t, || {
                    let solid = signed::build_solid(&m, beta, "beta")?;
                    Ok::<_, InputError>(signed::signed_distances(&solid, &p))
                })?
            })
            .map_err(to_py)?;
        let n = s.len();
        let idx = near.iter().map(|r| i64::from(r.index)).collect();
        let closest = near.iter().flat_map(|r| r.point.to_array()).collect();
        Ok((
            output::<_, Ix1>(py, n, s)?,
            output::<_, Ix1>(py, n, idx)?,
            output::<_, Ix2>(py, (n, 3), closest)?,
        ))
    })
}
