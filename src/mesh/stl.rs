//! STL reader over `stl_io`: ASCII and binary.
//!
//! STL stores every triangle with its own three corner positions. We merge coincident
//! corners into shared vertices (exactly equal `f32` positions, with `-0.0` taken as
//! `0.0`), so that valences and edge adjacency mean something. `stl_io`'s
//! `IndexedMesh` merges by raw bit pattern, which would keep `-0.0` and `0.0` apart, so
//! we read its triangle iterator and merge ourselves. Facet normals are ignored.
//!
//! Binary or ASCII is decided from the bytes: a file whose size is exactly
//! `84 + 50 * n` for the triangle count `n` in its header is binary even when its
//! 80-byte header begins with `solid` (some exporters write that); otherwise a file
//! starting with `solid` is ASCII. A lone `solid` first line (no name) is accepted.
//! A binary file shorter than its header's triangle count says is reported as
//! truncated before any parsing (so a huge count in a header costs nothing).

use super::{Mesh, MeshError};
use glam::Vec3;
use std::collections::HashMap;
use std::io::Cursor;
use std::path::Path;

pub(super) fn parse_stl(mut bytes: Vec<u8>, path: &Path) -> Result<Mesh, MeshError> {
    if bytes.is_empty() {
        return Err(MeshError::Empty {
            path: path.to_path_buf(),
        });
    }
    let format_err = |message: String| MeshError::Format {
        path: path.to_path_buf(),
        message,
    };
    let binary_count = binary_triangle_count(&bytes);
    let ascii = bytes.starts_with(b"solid") && !matches!(binary_count, Some((_, true)));
    if ascii {
        if let Err(e) = std::str::from_utf8(&bytes) {
            let at = e.valid_up_to();
            return Err(MeshError::Parse {
                path: path.to_path_buf(),
                line: 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count(),
                message: format!(
                    "invalid UTF-8 at byte {at}: an ASCII STL must be text (or a binary STL \
                     of exactly 84 + 50 n bytes)"
                ),
            });
        }
        if matches!(bytes.get(5), None | Some(b'\n' | b'\r')) {
            // "solid\n" or "solid\r\n": stl_io wants "solid " before the name.
            bytes.splice(5..5, *b" ");
        }
    } else {
        // Checked here so a truncated file gets a clear message rather than an EOF error.
        let Some((count, _)) = binary_count else {
            return Err(format_err(format!(
                "not an STL file: {} bytes, too short for a binary STL (84-byte header) and \
                 not starting with 'solid'",
                bytes.len()
            )));
        };
        let need = 84 + 50 * count;
        if (bytes.len() as u64) < need {
            return Err(format_err(format!(
                "truncated binary STL: the header declares {count} triangles ({need} bytes), \
                 but the file has {} bytes",
                bytes.len()
            )));
        }
        // stl_io picks ASCII when the file starts with "solid "; in a binary file those
        // are header bytes, which are free text, so blank them out.
        bytes[..5].fill(b' ');
    }
    let mut cursor = Cursor::new(bytes);
    let io_err = |e: std::io::Error| format_err(format!("invalid STL: {e}"));
    let triangles = stl_io::create_stl_reader(&mut cursor).map_err(io_err)?;

    let mut mesh = Mesh::default();
    let mut index_of: HashMap<[u32; 3], u32> = HashMap::new();
    for triangle in triangles {
        let triangle = triangle.map_err(io_err)?;
        let mut corners = [0u32; 3];
        for (corner, v) in corners.iter_mut().zip(triangle.vertices) {
            // `x + 0.0` turns -0.0 into 0.0 and leaves everything else unchanged.
            let p = Vec3::from_array(v.0.map(|x| x + 0.0));
            let next = mesh.vertices.len();
            let index = *index_of
                .entry(p.to_array().map(f32::to_bits))
                .or_insert_with(|| {
                    mesh.vertices.push(p);
                    next as u32
                });
            *corner = index;
        }
        mesh.triangles.push(corners);
    }
    Ok(mesh)
}

/// The triangle count in a binary STL header, and whether the file size is exactly
/// `84 + 50 * count`; `None` when the file is shorter than the 84-byte header.
fn binary_triangle_count(bytes: &[u8]) -> Option<(u64, bool)> {
    let count = bytes.get(80..84)?;
    let count = u64::from(u32::from_le_bytes([count[0], count[1], count[2], count[3]]));
    Some((count, 84 + 50 * count == bytes.len() as u64))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn negative_zero_merges_with_zero() {
        let text = "solid t\n\
            facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n\
            endloop\nendfacet\n\
            facet normal 0 0 1\nouter loop\nvertex -0.0 0 -0\nvertex 0 1 0\nvertex 1 0 0\n\
            endloop\nendfacet\nendsolid t\n";
        let m = parse_stl(text.as_bytes().to_vec(), Path::new("t.stl")).unwrap();
        assert_eq!(m.vertices.len(), 3);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 1]]);
    }

    #[test]
    fn nameless_solid_line() {
        let text = "solid\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
            vertex 0 1 0\nendloop\nendfacet\nendsolid\n";
        let m = parse_stl(text.as_bytes().to_vec(), Path::new("t.stl")).unwrap();
        assert_eq!(m.triangles.len(), 1);
    }
}
