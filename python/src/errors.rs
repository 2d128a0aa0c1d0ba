//! Library errors as Python exceptions, and the panic guard.
//!
//! An error whose cause chain holds an `std::io::Error` (a file that cannot be read)
//! becomes `FileNotFoundError` when the file is missing and `OSError` otherwise; every
//! other error (bad arrays, parameters, mesh or scene contents) becomes `ValueError`.
//! The message is the command line's: the error followed by its causes, joined by ": ".

use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::error::Error;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// The error and its causes, as the command line prints them, on one line.
fn message(e: &(dyn Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        let m = c.to_string();
        if !text.contains(&m) {
            text.push_str(": ");
            text.push_str(&m);
        }
        cause = c.source();
    }
    text
}

/// The I/O error in `e`'s cause chain, if any.
fn io_error<'a>(e: &'a (dyn Error + 'static)) -> Option<&'a std::io::Error> {
    let mut cur: Option<&(dyn Error + 'static)> = Some(e);
    while let Some(c) = cur {
        if let Some(io) = c.downcast_ref::<std::io::Error>() {
            return Some(io);
        }
        // `ImageError::source` skips its own I/O error.
        if let Some(image::ImageError::IoError(io)) = c.downcast_ref::<image::ImageError>() {
            return Some(io);
        }
        cur = c.source();
    }
    None
}

/// Converts a library error into the Python exception for its kind.
pub fn to_py(e: impl Error + 'static) -> PyErr {
    let text = message(&e);
    match io_error(&e) {
        Some(io) if io.kind() == std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(text),
        Some(_) => PyOSError::new_err(text),
        None => PyValueError::new_err(text),
    }
}

/// Runs `f`, turning a panic (here or on a worker thread) into a `RuntimeError` that says
/// it is a bug, instead of PyO3's `PanicException` (which derives from `BaseException`
/// and escapes `except Exception`).
pub fn guard<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".to_string());
            Err(PyRuntimeError::new_err(format!(
                "internal error in smoothtrace (a bug; please report it): {what}"
            )))
        }
    }
}

/// Panics on a rayon worker thread with the GIL released, inside [`guard`]: the tests
/// check that this surfaces as a `RuntimeError`.
#[pyfunction]
#[pyo3(name = "_panic_for_tests")]
pub fn panic_for_tests(py: Python<'_>, message: String) -> PyResult<()> {
    guard(|| {
        py.detach(|| {
            use rayon::prelude::*;
            (0..4).into_par_iter().for_each(|i| {
                if i == 3 {
                    panic!("{message}");
                }
            })
        });
        Ok(())
    })
}
