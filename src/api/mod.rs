//! Entry points for callers that hold their data in memory instead of files: the Python
//! bindings (`python/`) and Rust programs that embed the library.
//!
//! - [`arrays`]: a [`Mesh`](crate::mesh::Mesh) from flat vertex and index arrays, query
//!   points from a flat array, with errors that name the array and the row.
//! - [`params`]: alpha / alpha_rel, beta and thread-count checks with the command line's
//!   messages, and the scene overrides (`width`, `height`, `beta`, `alpha`, `threads`)
//!   the command line and the bindings both apply.
//! - [`queries`]: a [`TraceObject`](crate::render::TraceObject) (primitive sets plus
//!   evaluation parameters) from a mesh, and batch queries over many points (smooth
//!   distance, gradient, nearest primitive), in parallel with rayon.
//! - [`signed`]: winding numbers and signed distances of a triangle soup
//!   ([`crate::winding`]), many points at once.
//! - [`view`]: a default camera that frames an object, and rendering of in-memory objects
//!   through [`crate::render::pipeline::render_built`].
//!
//! Nothing here changes how anything is computed: every value comes from
//! [`crate::eval`], [`crate::field`] or [`crate::render::pipeline`].

pub mod arrays;
pub mod params;
pub mod queries;
pub mod signed;
pub mod view;

/// Bad input given as arrays or parameters (not files). The messages name the array or
/// parameter, the row where there is one, and what was expected.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    #[error("{array}[{row}] has a non-finite coordinate (NaN or infinity): {value:?}")]
    NonFinite {
        array: String,
        row: usize,
        value: [f64; 3],
    },
    #[error(
        "{array}[{row}] = {value:?} does not fit in 32-bit floats (|coordinate| > 3.4e38), the precision meshes are stored in"
    )]
    OutOfF32Range {
        array: String,
        row: usize,
        value: [f64; 3],
    },
    #[error("{array}[{row}] = {value:?}: query coordinate {problem}")]
    QueryOutOfRange {
        array: String,
        row: usize,
        value: [f64; 3],
        problem: String,
    },
    #[error(
        "{array}[{row}] holds vertex index {index}, out of range (there are {count} vertices, indices 0..{count})"
    )]
    IndexOutOfRange {
        array: String,
        row: usize,
        index: i64,
        count: usize,
    },
    #[error(
        "{array} has {len} values, not a multiple of {width}: expected an array of shape (n, {width})"
    )]
    Shape {
        array: String,
        len: usize,
        width: usize,
    },
    #[error("{0} has no vertices")]
    Empty(String),
    #[error("{0}")]
    Parameter(String),
    #[error(transparent)]
    Primitives(#[from] crate::primitives::PrimitiveError),
}

/// Runs `f` on `threads` worker threads (`Some(0)` = all cores) or, with `None`, in the
/// current rayon pool.
pub fn with_threads<R: Send>(
    threads: Option<usize>,
    f: impl FnOnce() -> R + Send,
) -> Result<R, InputError> {
    match threads {
        None => Ok(f()),
        Some(n) => {
            params::check_threads("threads", n as i64)?;
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| {
                    InputError::Parameter(format!("cannot start the worker threads: {e}"))
                })?;
            Ok(pool.install(f))
        }
    }
}
