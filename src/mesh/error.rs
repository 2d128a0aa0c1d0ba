//! Typed errors of the mesh readers. Every variant names the file; parse errors name the
//! 1-based line where there is one.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("{}: cannot read file: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}: unknown mesh extension '{extension}' (expected .obj, .ply, .stl, .las or .laz)", path.display())]
    UnknownExtension { path: PathBuf, extension: String },
    #[error("{}:{line}: {message}", path.display())]
    Parse {
        path: PathBuf,
        line: usize,
        message: String,
    },
    #[error("{}: {message}", path.display())]
    Format { path: PathBuf, message: String },
    #[error("{}{}: vertex index {index} out of range (the file has {count} vertices)",
        path.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    IndexOutOfRange {
        path: PathBuf,
        line: Option<usize>,
        index: i64,
        count: usize,
    },
    #[error("{}: vertex {vertex} (counting from 0) has a non-finite coordinate (NaN, infinity, or a value beyond f32's range of +-3.4e38)", path.display())]
    NonFinite { path: PathBuf, vertex: usize },
    #[error("{}: vertex {vertex} (counting from 0): coordinate {problem}", path.display())]
    CoordinateOutOfRange {
        path: PathBuf,
        vertex: usize,
        problem: String,
    },
    #[error("{}: the mesh has no vertices", path.display())]
    Empty { path: PathBuf },
}
