//! Wavefront OBJ reader: a hand-written single pass over the file's lines.
//!
//! Supported statements:
//! - `v x y z [w ...]`: a vertex; anything after `z` (a rational weight or vertex
//!   colour components) is ignored, except `v x y z r g b` colours when they are asked
//!   for ([`parse_obj_coloured`], rules in `super::vertex_colours`).
//! - `f i j k ...`: a polygon of any size >= 3, fan-triangulated into
//!   [`Mesh::triangles`] as `(i, j, k), (i, k, l), ...`.
//! - `l i j k ...`: a polyline of >= 2 vertices, split into consecutive
//!   [`Mesh::segments`] `(i, j), (j, k), ...`.
//! - `p i j ...`: points. The point set of a mesh is all its vertices, so `p` adds
//!   nothing; its indices are still checked.
//!
//! Index forms are `v`, `v/vt`, `v//vn` and `v/vt/vn`; only `v` is used (the `vt`/`vn`
//! parts must be integers or empty). Indices are 1-based; negative indices count back
//! from the last vertex read so far (`-1` is the latest). An index refers to the
//! vertices defined *before* its line: 0, or beyond the vertices read so far, is
//! [`MeshError::IndexOutOfRange`] with the line number. Degenerate faces (repeated
//! indices) are kept as written.
//!
//! Ignored: `vn`, `vt`, `vp`, `o`, `g`, `s`, `usemtl`, `mtllib`, `#` comments (also at
//! the end of a line), blank lines, and any other statement. Not supported: `\`
//! line continuations, free-form geometry (`curv`, `surf`, ...).
//!
//! A file of bare `v` lines is a point cloud: vertices only. Coordinates must be
//! finite and within +-1e30 ([`crate::limits::MAX_COORD`]); a malformed, missing,
//! non-finite or too large coordinate is a [`MeshError::Parse`]
//! naming the 1-based line.
//!
//! The file is read whole and parsed as bytes, without a per-line allocation.

use super::{Mesh, MeshError, vertex_colours};
use crate::rgb::Linear;
use glam::Vec3;
use std::path::Path;

/// Parses OBJ text held in `bytes`; `path` is only used in errors.
pub(super) fn parse_obj(bytes: &[u8], path: &Path) -> Result<Mesh, MeshError> {
    Ok(parse_obj_coloured(bytes, path, false)?.0)
}

/// [`parse_obj`], plus the vertices' `r g b` colours (linear) when `colours` is set and
/// the file has them.
pub(super) fn parse_obj_coloured(
    bytes: &[u8],
    path: &Path,
    colours: bool,
) -> Result<(Mesh, Option<Vec<Linear>>), MeshError> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let mut mesh = Mesh::default();
    let mut rgb = ObjColours::default();
    for (i, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = i + 1;
        let content = match raw.iter().position(|&b| b == b'#') {
            Some(hash) => &raw[..hash],
            None => raw,
        };
        let mut tokens = content
            .split(|b| b.is_ascii_whitespace())
            .filter(|t| !t.is_empty());
        let Some(keyword) = tokens.next() else {
            continue;
        };
        let err = |message: String| MeshError::Parse {
            path: path.to_path_buf(),
            line,
            message,
        };
        match keyword {
            b"v" => {
                let mut xyz = [0.0f32; 3];
                for (k, c) in xyz.iter_mut().enumerate() {
                    let token = tokens.next().ok_or_else(|| {
                        err(format!("'v' needs 3 coordinates 'v x y z', found {k}"))
                    })?;
                    *c = parse_coordinate(token).map_err(err)?;
                }
                mesh.vertices.push(Vec3::from_array(xyz));
                if colours {
                    rgb.add(tokens, line).map_err(err)?;
                }
            }
            b"f" => {
                let count = mesh.vertices.len();
                let (mut first, mut prev, mut n) = (0, 0, 0usize);
                for token in tokens {
                    let v = resolve_index(token, count, "f", line, path)?;
                    match n {
                        0 => first = v,
                        1 => prev = v,
                        _ => {
                            mesh.triangles.push([first, prev, v]);
                            prev = v;
                        }
                    }
                    n += 1;
                }
                if n < 3 {
                    return Err(err(format!(
                        "'f' needs at least 3 vertex indices, found {n}"
                    )));
                }
            }
            b"l" => {
                let count = mesh.vertices.len();
                let (mut prev, mut n) = (0, 0usize);
                for token in tokens {
                    let v = resolve_index(token, count, "l", line, path)?;
                    if n > 0 {
                        mesh.segments.push([prev, v]);
                    }
                    prev = v;
                    n += 1;
                }
                if n < 2 {
                    return Err(err(format!(
                        "'l' needs at least 2 vertex indices, found {n}"
                    )));
                }
            }
            b"p" => {
                let count = mesh.vertices.len();
                let mut n = 0usize;
                for token in tokens {
                    resolve_index(token, count, "p", line, path)?;
                    n += 1;
                }
                if n == 0 {
                    return Err(err("'p' needs at least 1 vertex index, found 0".into()));
                }
            }
            _ => {}
        }
    }
    Ok((mesh, rgb.colours))
}

/// The `r g b` of `v` lines, checked to be on every vertex or none.
#[derive(Default)]
struct ObjColours {
    /// One per vertex so far; `None` until the first `v` line, or when it had none.
    colours: Option<Vec<Linear>>,
    /// Vertices read so far and the first one's line.
    count: usize,
    first_line: usize,
}

impl ObjColours {
    /// The values after `z` on line `line`: exactly three are a colour.
    fn add<'a>(&mut self, rest: impl Iterator<Item = &'a [u8]>, line: usize) -> Result<(), String> {
        let rest: Vec<&[u8]> = rest.take(4).collect();
        let colour = if rest.len() == 3 {
            let mut c = [0.0f32; 3];
            for (k, (out, token)) in c.iter_mut().zip(&rest).enumerate() {
                let v = std::str::from_utf8(token)
                    .ok()
                    .and_then(|t| t.parse::<f32>().ok())
                    .ok_or_else(|| {
                        format!(
                            "malformed colour component '{}' in 'v x y z r g b' (expected a \
                             number in 0..1)",
                            show(token)
                        )
                    })?;
                *out = vertex_colours::channel(v).map_err(|m| {
                    format!(
                        "colour component {} ({}) of 'v x y z r g b': {m} (OBJ vertex \
                         colours are 0..1)",
                        k + 1,
                        ["r", "g", "b"][k]
                    )
                })?;
            }
            Some(c)
        } else {
            None
        };
        if self.count == 0 {
            self.first_line = line;
            self.colours = colour.map(|c| vec![c]);
        } else {
            match (&mut self.colours, colour) {
                (Some(list), Some(c)) => list.push(c),
                (None, None) => {}
                (Some(_), None) => {
                    return Err(format!(
                        "this vertex has no colour 'v x y z r g b', but the first one (line \
                         {}) has; colour every vertex or none",
                        self.first_line
                    ));
                }
                (None, Some(_)) => {
                    return Err(format!(
                        "this vertex has a colour, but the first one (line {}) has none; \
                         colour every vertex or none",
                        self.first_line
                    ));
                }
            }
        }
        self.count += 1;
        Ok(())
    }
}

/// A finite `f32` coordinate, or the message of a parse error.
fn parse_coordinate(token: &[u8]) -> Result<f32, String> {
    let value = std::str::from_utf8(token)
        .ok()
        .and_then(|s| s.parse::<f32>().ok())
        .ok_or_else(|| {
            format!(
                "malformed coordinate '{}' in 'v' (expected a number)",
                show(token)
            )
        })?;
    if !value.is_finite() {
        return Err(format!(
            "coordinate '{}' in 'v' is not finite (NaN or infinity, or too large for f32)",
            show(token)
        ));
    }
    if let Some(problem) = crate::limits::coordinate_problem(f64::from(value)) {
        return Err(format!("coordinate in 'v': {problem}"));
    }
    Ok(value)
}

/// Resolves an index token (`v`, `v/vt`, `v//vn`, `v/vt/vn`) of statement `keyword`
/// against the `count` vertices read so far, giving a 0-based vertex index.
fn resolve_index(
    token: &[u8],
    count: usize,
    keyword: &str,
    line: usize,
    path: &Path,
) -> Result<u32, MeshError> {
    let mut parts = token.split(|&b| b == b'/');
    let vertex = parts.next().and_then(parse_int);
    // The texture / normal parts are unused but must still be well formed.
    let mut extra = 0;
    let rest_ok = parts.all(|p| {
        extra += 1;
        p.is_empty() || parse_int(p).is_some()
    });
    let Some(index) = vertex.filter(|_| rest_ok && extra <= 2) else {
        return Err(MeshError::Parse {
            path: path.to_path_buf(),
            line,
            message: format!(
                "malformed vertex index '{}' in '{keyword}' (expected v, v/vt, v//vn or v/vt/vn)",
                show(token)
            ),
        });
    };
    let resolved = match index {
        i if i > 0 => Some(i - 1),
        i if i < 0 => Some(count as i64 + i),
        _ => None,
    };
    match resolved {
        Some(r) if r >= 0 && (r as u64) < count as u64 => {
            u32::try_from(r).map_err(|_| out_of_range(path, line, index, count))
        }
        _ => Err(out_of_range(path, line, index, count)),
    }
}

fn out_of_range(path: &Path, line: usize, index: i64, count: usize) -> MeshError {
    MeshError::IndexOutOfRange {
        path: path.to_path_buf(),
        line: Some(line),
        index,
        count,
    }
}

/// A decimal integer with an optional sign; `None` when malformed or beyond `i64`.
fn parse_int(token: &[u8]) -> Option<i64> {
    let (negative, digits) = match token.first()? {
        b'-' => (true, &token[1..]),
        b'+' => (false, &token[1..]),
        _ => (false, token),
    };
    if digits.is_empty() {
        return None;
    }
    let mut value: i64 = 0;
    for &d in digits {
        if !d.is_ascii_digit() {
            return None;
        }
        value = value.checked_mul(10)?.checked_add(i64::from(d - b'0'))?;
    }
    Some(if negative { -value } else { value })
}

/// A token for an error message, lossily decoded and cut to a readable length.
fn show(token: &[u8]) -> String {
    const MAX: usize = 40;
    let text = String::from_utf8_lossy(token);
    if text.chars().count() > MAX {
        let cut: String = text.chars().take(MAX).collect();
        format!("{cut}...")
    } else {
        text.into_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Mesh, MeshError> {
        parse_obj(text.as_bytes(), Path::new("t.obj"))
    }

    #[test]
    fn parse_int_forms() {
        assert_eq!(parse_int(b"12"), Some(12));
        assert_eq!(parse_int(b"-3"), Some(-3));
        assert_eq!(parse_int(b"+4"), Some(4));
        assert_eq!(parse_int(b""), None);
        assert_eq!(parse_int(b"-"), None);
        assert_eq!(parse_int(b"1.0"), None);
        assert_eq!(parse_int(b"99999999999999999999"), None);
    }

    #[test]
    fn fan_and_relative_indices() {
        let m = parse("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4 -3 -2 -1\n").unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn forward_reference_is_out_of_range() {
        let e = parse("v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n").unwrap_err();
        assert!(
            matches!(
                e,
                MeshError::IndexOutOfRange {
                    line: Some(3),
                    index: 3,
                    count: 2,
                    ..
                }
            ),
            "{e:?}"
        );
    }

    #[test]
    fn trailing_comment_crlf_and_bom() {
        let m = parse("\u{feff}v 0 0 0\r\nv 1 0 0 # x\r\nv 0 1 0\r\nf 1 2 3 # tri\r\n").unwrap();
        assert_eq!(m.vertices.len(), 3);
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn malformed_extra_index_part() {
        for bad in ["f 1/x 2 3", "f 1/2/3/4 2 3", "f a 2 3", "f 1 2"] {
            let text = format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{bad}\n");
            let e = parse(&text).unwrap_err();
            assert!(
                matches!(e, MeshError::Parse { line: 4, .. }),
                "{bad}: {e:?}"
            );
        }
    }
}
