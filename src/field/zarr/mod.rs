//! Chunked distance volumes as Zarr v3 arrays on the file system (issue 33).
//!
//! The array has the `.npy` layout: float32, shape `(NZ, NY, NX)` (C order, `x`
//! fastest), split by a regular chunk grid of `(cz, cy, cx)` voxels. The format is the
//! Zarr v3 core specification's subset that every reader knows:
//! - `OUT.zarr/zarr.json`: `zarr_format` 3, `node_type` "array", `shape`, `data_type`
//!   "float32", the `regular` chunk grid, the `default` chunk key encoding with "/"
//!   (chunk `(kz, ky, kx)` is the file `OUT.zarr/c/kz/ky/kx`), `fill_value` NaN (a chunk
//!   that was never written reads as NaN), the codecs `bytes` (little endian) and
//!   optionally `gzip`, `dimension_names` `["z", "y", "x"]`, and the grid in
//!   `attributes` (see [`grid_attributes`]).
//! - Each chunk is its full chunk shape, also at the array's far edges (the voxels past
//!   the edge hold NaN), as the specification requires.
//!
//! Chunks are numbered in C order over the chunk grid, `index = (kz * GY + ky) * GX +
//! kx`; `--chunks I:J` selects indices. A chunk file is written to a temporary name in
//! its folder and renamed when complete, so a chunk file that exists is whole: a run
//! that stops (Ctrl-C, a killed job, a full disk) leaves an array whose missing chunks
//! are exactly the absent files ([`ZarrArray::missing`]), which a later run computes.
//!
//! Why not the `zarrs` crate: it is the well-kept Rust implementation, but with minimal
//! features (`filesystem` only, no async, no codecs) it still adds about 70 crates
//! (futures, regex, moka, derive_more, a second `syn`) and measured 375 s of compile
//! units on this machine, against a 5-minute fresh build of the whole project; writing
//! one fixed, specification-conformant layout takes the few functions below (serde_json
//! and flate2 are already dependencies). Reading is left to the readers (zarr-python,
//! zarrs, tensorstore); [`ZarrArray::read_all`] exists for tests and small arrays.

mod store;
mod write;

pub use store::{Codec, ZarrArray, ZarrError, ZarrSpec};
pub use write::{ChunkRun, index_ranges, parse_chunks, write_chunks};

impl From<ZarrError> for super::FieldError {
    fn from(e: ZarrError) -> Self {
        super::FieldError::Zarr(Box::new(e))
    }
}

use super::grid::Grid;
use serde_json::{Value, json};

/// The array attributes that describe the grid: `bounds` (`[[xmin, ymin, zmin],
/// [xmax, ymax, zmax]]`), `voxel_size` (`[hx, hy, hz]`), `resolution` (`[NX, NY, NZ]`),
/// the voxel centre formula, and `field`, the caller's description of what was computed
/// (method, primitive, mesh...). Two runs that must write into one array need equal
/// attributes.
pub fn grid_attributes(grid: &Grid, field: Value) -> Value {
    let h = grid.spacing();
    json!({
        "bounds": [grid.min.to_array(), grid.max.to_array()],
        "voxel_size": h.to_array(),
        "resolution": grid.res,
        "voxel_centre": "array[k, j, i] is the value at bounds[0] + ((i, j, k) + 0.5) * voxel_size (x, y, z)",
        "generator": "smoothtrace field",
        "field": field,
    })
}
