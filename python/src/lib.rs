//! The `smoothtrace._native` Python extension: a thin layer over the library's
//! [`smoothtrace::api`] entry points. Arrays arrive as C-contiguous float64 / int64 numpy
//! arrays (the Python package `python/smoothtrace/__init__.py` converts and checks dtypes
//! and shapes first), are copied into Rust vectors, and the work runs with the GIL
//! released on rayon threads. Every library error becomes a Python exception carrying
//! the command line's message ([`errors`]); a Rust panic becomes a `RuntimeError`, never
//! a `PanicException` ([`errors::guard`]).

mod arrays;
mod errors;
mod field;
mod mesh;
mod render;
mod signed;
mod smooth;

use pyo3::prelude::*;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<smooth::SmoothDistance>()?;
    m.add_class::<field::FieldPlan>()?;
    m.add_function(wrap_pyfunction!(mesh::load_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(field::distance_field, m)?)?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add_function(wrap_pyfunction!(render::render_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(signed::winding_number, m)?)?;
    m.add_function(wrap_pyfunction!(signed::signed_distance, m)?)?;
    m.add_function(wrap_pyfunction!(errors::panic_for_tests, m)?)?;
    Ok(())
}
