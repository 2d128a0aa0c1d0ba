//! Input limits shared by the mesh readers, the scene loader, the field grid and the
//! command line: the largest coordinate and the range of alpha for which every
//! computation stays finite, and how input files are read (regular files only, with a
//! size cap, streamed through that cap).
//!
//! Why these numbers:
//! - Coordinates `|c| <= 1e30`. Vertices are stored in `f32` (largest 3.4e38); boxes,
//!   diagonals (x 3.5), the field's 10% margins and the tracer's clipping box are `f32`
//!   too, so 1e30 leaves eight orders of magnitude of headroom there. In `f64` the
//!   closest-point tests form products of two dot products of coordinate differences,
//!   about `(4e30)^4 = 3e122`, far below `f64::MAX` (1.8e308), and squared distances
//!   stay below 1e62. Query points and field bounds may reach ten times further
//!   ([`MAX_QUERY_COORD`]), so that the default field bounds (the mesh box grown by 10%
//!   of its diagonal) of any accepted mesh are accepted too.
//! - `1e-30 <= alpha <= 1e30`. The smooth distance reaches `-ln(N w_max) / alpha` below
//!   the data (about `-1e32` at the smallest alpha, still a finite `f32` in a `.npy`
//!   volume), and `alpha * d` stays below 1e61 for every distance above.
//! - Input files: at most [`MAX_INPUT_BYTES`]; a path that is not a regular file (a
//!   device such as `/dev/zero`, a FIFO, a directory) is refused before reading.

use std::io::Read;
use std::path::Path;

/// Largest accepted coordinate magnitude of mesh vertices.
pub const MAX_COORD: f64 = 1e30;

/// Largest accepted coordinate magnitude of query points and field bounds.
pub const MAX_QUERY_COORD: f64 = 1e31;

/// Smallest accepted alpha (1/length).
pub const MIN_ALPHA: f64 = 1e-30;

/// Largest accepted alpha (1/length).
pub const MAX_ALPHA: f64 = 1e30;

/// Largest input file read (meshes, scene files, query points): 4 GiB.
pub const MAX_INPUT_BYTES: u64 = 4 << 30;

/// Most points a LAZ chunk may announce: LASzip and PDAL write 50 000, COPC nodes hold
/// about 100 000; the parallel decoder allocates a whole chunk's records at once, so a
/// corrupt count must not reach it (`las::layout_check`).
pub const MAX_LAZ_CHUNK_POINTS: u64 = 1 << 22;

/// `None` when `v` is an accepted vertex coordinate, else why not.
pub fn coordinate_problem(v: f64) -> Option<String> {
    limit_problem(v, MAX_COORD)
}

/// `None` when `v` is an accepted query or field-bounds coordinate, else why not.
pub fn query_coordinate_problem(v: f64) -> Option<String> {
    limit_problem(v, MAX_QUERY_COORD)
}

fn limit_problem(v: f64, limit: f64) -> Option<String> {
    if v.is_nan() {
        Some("is NaN".into())
    } else if v.is_infinite() {
        Some(format!("is {v} (coordinates must be finite)"))
    } else if v.abs() as f32 > limit as f32 {
        // Compared at f32 precision: `1e30` written in a file is stored as the nearest
        // f32, 1.00000002e30, and must be accepted.
        Some(format!(
            "{v:e} is beyond the accepted +-{limit:e} (larger values overflow the f32 \
             bounding boxes or the f64 squared distances)"
        ))
    } else {
        None
    }
}

/// `None` when `alpha` is in the accepted range, else why not.
pub fn alpha_problem(alpha: f64) -> Option<String> {
    if !(alpha > 0.0 && alpha.is_finite()) {
        Some(format!("must be a positive number (got {alpha})"))
    } else if alpha < MIN_ALPHA {
        Some(format!(
            "{alpha:e} is below {MIN_ALPHA:e}: the smooth distance would reach \
             -ln(N w)/alpha, beyond what f32 volumes and boxes hold"
        ))
    } else if alpha > MAX_ALPHA {
        Some(format!(
            "{alpha:e} is above {MAX_ALPHA:e}: alpha times a distance would overflow"
        ))
    } else {
        None
    }
}

/// Reads a whole input file after checking that it is a regular file of at most
/// [`MAX_INPUT_BYTES`], through a reader capped at that size (so a file that grows while
/// it is read cannot exhaust memory either). Errors are `std::io::Error`s whose message
/// says what was wrong; callers add the path.
pub fn read_input_file(path: &Path) -> std::io::Result<Vec<u8>> {
    let file = open_input_file(path)?;
    let size = file.metadata()?.len();
    let mut bytes = Vec::with_capacity(size as usize);
    file.take(MAX_INPUT_BYTES + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_INPUT_BYTES {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

/// Opens an input file after the same checks as [`read_input_file`], for callers that
/// stream it (they must still cap what they read at [`MAX_INPUT_BYTES`]).
pub fn open_input_file(path: &Path) -> std::io::Result<std::fs::File> {
    let file = std::fs::File::open(path)?;
    let meta = file.metadata()?;
    let kind = meta.file_type();
    if !kind.is_file() {
        let what = if kind.is_dir() {
            "a directory"
        } else {
            "a device, FIFO or socket"
        };
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("not a regular file ({what}); give a path to a file"),
        ));
    }
    if meta.len() > MAX_INPUT_BYTES {
        return Err(too_large(meta.len()));
    }
    Ok(file)
}

fn too_large(bytes: u64) -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::InvalidInput,
        format!(
            "the file has {bytes} bytes or more, above the limit of {MAX_INPUT_BYTES} bytes \
             (4 GiB) for an input file"
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coordinate_limits() {
        assert_eq!(coordinate_problem(0.0), None);
        assert_eq!(coordinate_problem(-MAX_COORD), None);
        assert!(coordinate_problem(1.0001e30).is_some());
        assert_eq!(coordinate_problem(f64::from(1e30f32)), None);
        assert_eq!(query_coordinate_problem(5e30), None);
        assert!(query_coordinate_problem(1e160).is_some());
        assert!(coordinate_problem(f64::NAN).is_some());
        assert!(coordinate_problem(f64::NEG_INFINITY).is_some());
    }

    #[test]
    fn alpha_limits() {
        assert_eq!(alpha_problem(1.0), None);
        assert_eq!(alpha_problem(MIN_ALPHA), None);
        assert_eq!(alpha_problem(MAX_ALPHA), None);
        for bad in [0.0, -1.0, 1e-300, 1e300, f64::NAN, f64::INFINITY] {
            assert!(alpha_problem(bad).is_some(), "{bad}");
        }
    }

    #[test]
    fn devices_and_directories_are_refused() {
        for p in ["/dev/zero", "/dev/null", "/"] {
            if !Path::new(p).exists() {
                eprintln!("skipping {p}: not on this system");
                continue;
            }
            let e = read_input_file(Path::new(p)).unwrap_err();
            assert!(e.to_string().contains("not a regular file"), "{p}: {e}");
        }
    }
}
