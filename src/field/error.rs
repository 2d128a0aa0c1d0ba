//! Typed errors of the distance-field module: every variant says what was wrong and how
//! to fix it.

use crate::primitives::PrimitiveError;

#[derive(Debug, thiserror::Error)]
pub enum FieldError {
    #[error("the resolution along {axis} is 0; every axis needs at least one voxel")]
    ZeroResolution { axis: char },
    #[error(
        "the resolution along {axis} is {value}, above the limit of {max} voxels per axis; lower the resolution"
    )]
    ResolutionTooLarge {
        axis: char,
        value: usize,
        max: usize,
    },
    #[error("the bounds must be finite numbers (got min {min:?}, max {max:?})")]
    NonFiniteBounds { min: [f64; 3], max: [f64; 3] },
    #[error("the bounds' {corner} {axis} {problem}")]
    BoundsTooLarge {
        corner: &'static str,
        axis: char,
        problem: String,
    },
    #[error(
        "the bounds are inverted along {axis}: min {min} > max {max}; give the minimum corner first"
    )]
    InvertedBounds { axis: char, min: f64, max: f64 },
    #[error(
        "the bounds have zero extent along {axis} (min = max = {value}); give bounds with a positive extent on every axis"
    )]
    DegenerateBounds { axis: char, value: f64 },
    #[error(
        "the mesh's bounding box is a single point or empty, so there are no default bounds; give the bounds explicitly"
    )]
    NoDefaultBounds,
    #[error("the band must be a positive, finite distance (got {0})")]
    BadBand(f64),
    #[error(
        "a {nx}x{ny}x{nz} grid ({voxels} voxels) and its mesh would need {} of memory, above the limit of {} ({why}); lower the resolution or shrink the bounds",
        human_bytes(*bytes), human_bytes(*limit)
    )]
    TooMuchMemory {
        nx: usize,
        ny: usize,
        nz: usize,
        voxels: u64,
        bytes: u64,
        limit: u64,
        why: String,
    },
    #[error("smooth distance: {0}")]
    BadSmoothParameters(String),
    #[error("signed volumes hold exact distances; the smooth distance has no sign (drop --smooth)")]
    SmoothNotSigned,
    #[error(transparent)]
    Primitive(#[from] PrimitiveError),
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
    /// A chunked array could not be written (`field::zarr`'s error, boxed so that this
    /// module does not reach up into the writer that returns it).
    #[error(transparent)]
    Zarr(Box<dyn std::error::Error + Send + Sync>),
}

/// `1.5 GiB`-style rendering of a byte count.
pub fn human_bytes(b: u64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut v = b as f64;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < UNITS.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{b} B")
    } else {
        format!("{v:.1} {}", UNITS[u])
    }
}
