//! `SmoothDistance`: primitive sets with their BVHs, built once, queried many times.

use crate::arrays::{kinds, mesh, output};
use crate::errors::{guard, to_py};
use numpy::ndarray::{Ix1, Ix2};
use numpy::{PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use smoothtrace::api::arrays::flat_indices;
use smoothtrace::api::params::{Naming, check_threads};
use smoothtrace::api::queries::{self, ObjectSpec};
use smoothtrace::api::{InputError, with_threads};
use smoothtrace::render::TraceObject;

/// The smooth distance of one or more primitive sets of a mesh (see the Python
/// package's docstrings).
#[pyclass(frozen, module = "smoothtrace._native")]
pub struct SmoothDistance {
    object: TraceObject,
    /// The edges the edge set was built from (the explicit ones, else the faces' unique
    /// edges), so that `nearest`'s indices can be looked up; empty without an edge set.
    edges: Vec<[u32; 2]>,
}

/// Thread count from Python (`None` = the current pool).
fn threads(t: Option<i64>) -> PyResult<Option<usize>> {
    t.map(|t| check_threads("threads", t).map_err(to_py))
        .transpose()
}

type Arr1<'py> = Bound<'py, PyArray1<f64>>;
type Arr2<'py> = Bound<'py, PyArray2<f64>>;

#[pymethods]
impl SmoothDistance {
    #[new]
    #[pyo3(signature = (vertices, faces, edges, primitives, alpha, alpha_rel, max_alpha, max_alpha_rel, beta, tolerance=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        vertices: PyReadonlyArray2<'_, f64>,
        faces: Option<PyReadonlyArray2<'_, i64>>,
        edges: Option<PyReadonlyArray2<'_, i64>>,
        primitives: Vec<String>,
        alpha: Option<f64>,
        alpha_rel: Option<f64>,
        max_alpha: Option<f64>,
        max_alpha_rel: Option<f64>,
        beta: f64,
        tolerance: Option<f64>,
    ) -> PyResult<SmoothDistance> {
        guard(|| {
            let m = mesh(&vertices, faces.as_ref(), edges.as_ref())?;
            let spec = ObjectSpec {
                kinds: kinds(&primitives)?,
                alpha,
                alpha_rel,
                max_alpha,
                max_alpha_rel,
                beta,
                tolerance,
            };
            py.detach(|| {
                let object = queries::build_object(&m, &spec, Naming::Keyword)?;
                let has_edges = object
                    .sets
                    .iter()
                    .any(|s| s.kind() == smoothtrace::primitives::PrimitiveKind::Edges);
                let edges = match (has_edges, m.segments.is_empty()) {
                    (false, _) => Vec::new(),
                    (true, true) => m.triangle_edges(),
                    (true, false) => m.segments.clone(),
                };
                Ok::<_, InputError>(SmoothDistance { object, edges })
            })
            .map_err(to_py)
        })
    }

    /// The smooth distance at each row of `points`.
    #[pyo3(signature = (points, threads=None))]
    fn value<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
        threads: Option<i64>,
    ) -> PyResult<Arr1<'py>> {
        guard(|| {
            let p = crate::arrays::points(&points, "points")?;
            let t = self::threads(threads)?;
            let s = py
                .detach(|| with_threads(t, || queries::values(&self.object, &p)))
                .map_err(to_py)?;
            output::<_, Ix1>(py, s.len(), s)
        })
    }

    /// The smooth distance at each row of `points` with a certified upper bound of the
    /// exact value: `(lower, upper)`.
    #[pyo3(signature = (points, threads=None))]
    fn value_bounds<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
        threads: Option<i64>,
    ) -> PyResult<(Arr1<'py>, Arr1<'py>)> {
        guard(|| {
            let p = crate::arrays::points(&points, "points")?;
            let t = self::threads(threads)?;
            let (lo, hi) = py
                .detach(|| with_threads(t, || queries::value_bounds(&self.object, &p)))
                .map_err(to_py)?;
            let n = lo.len();
            Ok((output::<_, Ix1>(py, n, lo)?, output::<_, Ix1>(py, n, hi)?))
        })
    }

    /// The smooth distance and its gradient at each row of `points`.
    #[pyo3(signature = (points, threads=None))]
    fn value_and_gradient<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
        threads: Option<i64>,
    ) -> PyResult<(Arr1<'py>, Arr2<'py>)> {
        guard(|| {
            let p = crate::arrays::points(&points, "points")?;
            let t = self::threads(threads)?;
            let (s, g) = py
                .detach(|| with_threads(t, || queries::values_and_gradients(&self.object, &p)))
                .map_err(to_py)?;
            let n = s.len();
            Ok((
                output::<_, Ix1>(py, n, s)?,
                output::<_, Ix2>(py, (n, 3), g)?,
            ))
        })
    }

    /// The exact nearest primitive to each row of `points`: distance, index of the
    /// primitive in its set, closest point, and which set (position in `primitives`).
    #[pyo3(signature = (points, threads=None))]
    #[allow(clippy::type_complexity)]
    fn nearest<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
        threads: Option<i64>,
    ) -> PyResult<(
        Arr1<'py>,
        Bound<'py, PyArray1<i64>>,
        Arr2<'py>,
        Bound<'py, PyArray1<i64>>,
    )> {
        guard(|| {
            let p = crate::arrays::points(&points, "points")?;
            let t = self::threads(threads)?;
            let near = py
                .detach(|| with_threads(t, || queries::nearest(&self.object, &p)))
                .map_err(to_py)?;
            let n = near.len();
            let d = near.iter().map(|r| r.d).collect();
            let idx = near.iter().map(|r| i64::from(r.index)).collect();
            let closest = near.iter().flat_map(|r| r.point.to_array()).collect();
            let set = near.iter().map(|r| r.set as i64).collect();
            Ok((
                output::<_, Ix1>(py, n, d)?,
                output::<_, Ix1>(py, n, idx)?,
                output::<_, Ix2>(py, (n, 3), closest)?,
                output::<_, Ix1>(py, n, set)?,
            ))
        })
    }

    /// Resolved alpha (1/length).
    #[getter]
    fn alpha(&self) -> f64 {
        self.object.params.alpha
    }

    #[getter]
    fn max_alpha(&self) -> f64 {
        self.object.params.max_alpha
    }

    #[getter]
    fn beta(&self) -> f64 {
        self.object.params.beta
    }

    /// The primitive sets, in order.
    #[getter]
    fn primitives(&self) -> Vec<&'static str> {
        self.object.sets.iter().map(|s| s.kind().name()).collect()
    }

    /// Primitives per set.
    #[getter]
    fn counts(&self) -> Vec<usize> {
        self.object.sets.iter().map(|s| s.len()).collect()
    }

    /// The `(k, 2)` vertex indices of the edge set's edges.
    #[getter]
    fn edges<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        output::<_, Ix2>(py, (self.edges.len(), 2), flat_indices(&self.edges))
    }
}
