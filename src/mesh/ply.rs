//! PLY reader over `ply-rs-bw`: ASCII, binary little-endian and binary big-endian.
//!
//! Supported elements (others are read and skipped):
//! - `vertex` (required): scalar properties `x`, `y`, `z` of any scalar type (`char` ..
//!   `double`, converted to `f32`); other vertex properties (normals, colours, list
//!   properties) are ignored, except colours when they are asked for
//!   ([`parse_ply_coloured`]; accepted names and types in `super::vertex_colours`).
//! - `face` (optional): a list property `vertex_indices` or `vertex_index` with an
//!   integer item type; polygons of any size >= 3 are fan-triangulated into
//!   [`Mesh::triangles`].
//! - `edge` (optional): integer scalar properties `vertex1` and `vertex2`, giving
//!   [`Mesh::segments`].
//!
//! Elements are parsed into small typed structs (ply-rs-bw's `PropertyAccess`), not its
//! `DefaultElement` hash maps, which allocate a map per element. Binary files holding
//! only float vertices are decoded directly instead ([`super::ply_binary`]: bytes ->
//! `f32` at a fixed stride, in parallel), after the same header checks. (Timings of
//! both: `doc/performance-log.md`, "Notes moved from module docs".)
//!
//! Header errors and ASCII payload errors carry the 1-based line ([`MeshError::Parse`]);
//! binary payload errors (a truncated file) are [`MeshError::Format`]. Malformed files
//! that `ply-rs-bw` would accept (repeated names, a bad `format` line, extra values on
//! an ASCII line, data after the last element) are rejected by [`super::ply_check`].

use super::vertex_colours::{self, PLY_COLOUR_NAMES};
use super::{Mesh, MeshError, ply_binary, ply_check};
use crate::rgb::Linear;
use glam::Vec3;
use ply_rs_bw::parser::{ParseError, Parser, Reader};
use ply_rs_bw::ply::{
    BeginList, Encoding, Header, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType,
};
use std::path::Path;

/// Names of the face list property we accept (a face element with both is rejected).
const FACE_LIST_NAMES: [&str; 2] = ["vertex_indices", "vertex_index"];

/// Parses a whole PLY file held in `bytes`; `path` is only used in errors. The caller
/// reads the file whole rather than streaming it through a `BufReader` (faster, see the
/// performance log), so the file and the vertices are held at once.
pub(super) fn parse_ply(bytes: &[u8], path: &Path) -> Result<Mesh, MeshError> {
    Ok(parse_ply_coloured(bytes, path, false)?.0)
}

/// [`parse_ply`], plus the vertices' colours (linear) when `colours` is set and the
/// vertex element has them.
pub(super) fn parse_ply_coloured(
    bytes: &[u8],
    path: &Path,
    colours: bool,
) -> Result<(Mesh, Option<Vec<Linear>>), MeshError> {
    let format_err = |message: String| MeshError::Format {
        path: path.to_path_buf(),
        message,
    };
    if bytes.is_empty() {
        return Err(MeshError::Empty {
            path: path.to_path_buf(),
        });
    }
    if !bytes.starts_with(b"ply") {
        return Err(format_err(
            "not a PLY file (it does not start with 'ply')".into(),
        ));
    }
    let checked = ply_check::check_header(bytes, path)?;
    let mut reader = Reader::new(bytes);
    let header = Parser::<Skip>::new()
        .read_header(&mut reader)
        .map_err(|e| wrap(path, e, true, "invalid PLY header"))?;
    check_layout(&header).map_err(format_err)?;
    let spelling = if colours {
        colour_layout(&header).map_err(format_err)?
    } else {
        None
    };
    if spelling.is_none() {
        let fast = checked
            .as_ref()
            .and_then(|info| ply_binary::float_vertices(bytes, info, &header));
        if let Some(vertices) = fast {
            let mesh = Mesh {
                vertices,
                ..Mesh::default()
            };
            return Ok((mesh, None));
        }
    }
    let mut vertex_colours = None;
    if let Some(info) = checked.as_ref().filter(|i| i.ascii) {
        ply_check::check_ascii_lines(bytes, info, path)?;
    }

    let ascii = header.encoding == Encoding::Ascii;
    let mut mesh = Mesh::default();
    let (mut faces, mut edges) = (Vec::new(), Vec::new());
    for (name, def) in &header.elements {
        let context = format!("element '{name}'");
        let payload_err = |e| wrap(path, e, ascii, &context);
        match name.as_str() {
            "vertex" if spelling.is_some() => {
                let read = Parser::<PlyColouredVertex>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(payload_err)?;
                let k = spelling.unwrap_or(0);
                let mut linear = Vec::with_capacity(read.len());
                for (i, v) in read.iter().enumerate() {
                    let mut c = [0.0f32; 3];
                    for (ch, out) in c.iter_mut().enumerate() {
                        *out = vertex_colours::channel(v.colour[k][ch]).map_err(|m| {
                            format_err(format!(
                                "vertex {i} (counting from 0): colour property '{}' {m} \
                                 (float colours are 0..1)",
                                PLY_COLOUR_NAMES[k][ch]
                            ))
                        })?;
                    }
                    linear.push(c);
                }
                mesh.vertices = read.iter().map(|v| Vec3::from_array(v.position)).collect();
                vertex_colours = Some(linear);
            }
            "vertex" => {
                // Same size and alignment: the collect reuses the allocation.
                mesh.vertices = Parser::<PlyVertex>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(payload_err)?
                    .into_iter()
                    .map(|v| Vec3::from_array(v.0))
                    .collect();
            }
            "face" => {
                faces = Parser::<PlyFace>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(payload_err)?;
            }
            "edge" => {
                edges = Parser::<PlyEdge>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(payload_err)?;
            }
            _ => {
                Parser::<Skip>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(payload_err)?;
            }
        }
    }
    ply_check::check_trailing(bytes, reader.get_ref(), ascii, path)?;
    // Elements may come in any order, so indices are converted once all are read.
    let count = mesh.vertices.len();
    mesh.triangles = triangulate(&faces, count, path)?;
    mesh.segments = edges
        .iter()
        .map(|e| {
            Ok([
                to_index(e.0[0], count, path)?,
                to_index(e.0[1], count, path)?,
            ])
        })
        .collect::<Result<_, MeshError>>()?;
    Ok((mesh, vertex_colours))
}

/// Which spelling of the colour channels the vertex element has (an index into
/// [`PLY_COLOUR_NAMES`]), `None` when it has none; an error for a partial triple or a
/// type without an agreed range.
fn colour_layout(header: &Header) -> Result<Option<usize>, String> {
    let Some(vertex) = header.elements.get("vertex") else {
        return Ok(None);
    };
    for (k, names) in PLY_COLOUR_NAMES.iter().enumerate() {
        let found: Vec<&str> = names
            .iter()
            .copied()
            .filter(|n| vertex.properties.contains_key(*n))
            .collect();
        if found.is_empty() {
            continue;
        }
        if found.len() < 3 {
            return Err(format!(
                "element 'vertex' has colour properties {found:?} but not all of {names:?}"
            ));
        }
        for name in names {
            match &vertex.properties[*name].data_type {
                PropertyType::Scalar(
                    ScalarType::UChar | ScalarType::UShort | ScalarType::Float | ScalarType::Double,
                ) => {}
                other => {
                    return Err(format!(
                        "vertex colour property '{name}' is {}; colours must be uchar \
                         (0..255), ushort (0..65535), float or double (0..1)",
                        describe(other)
                    ));
                }
            }
        }
        return Ok(Some(k));
    }
    Ok(None)
}

/// A property type as the PLY header spells it.
fn describe(t: &PropertyType) -> String {
    let scalar = |s: &ScalarType| match s {
        ScalarType::Char => "char",
        ScalarType::UChar => "uchar",
        ScalarType::Short => "short",
        ScalarType::UShort => "ushort",
        ScalarType::Int => "int",
        ScalarType::UInt => "uint",
        ScalarType::Float => "float",
        ScalarType::Double => "double",
    };
    match t {
        PropertyType::Scalar(s) => format!("'{}'", scalar(s)),
        PropertyType::List(i, s) => format!("a list ('list {} {}')", scalar(i), scalar(s)),
    }
}

/// Checks the header declares what we read, with messages that say what is missing.
fn check_layout(header: &Header) -> Result<(), String> {
    let vertex = header
        .elements
        .get("vertex")
        .ok_or("the header declares no 'vertex' element")?;
    for axis in ["x", "y", "z"] {
        match vertex.properties.get(axis).map(|p| &p.data_type) {
            Some(PropertyType::Scalar(_)) => {}
            Some(PropertyType::List(..)) => {
                return Err(format!(
                    "vertex property '{axis}' is a list; x, y and z must be scalars"
                ));
            }
            None => {
                return Err(format!(
                    "element 'vertex' has no property '{axis}' (x, y and z are required)"
                ));
            }
        }
    }
    if let Some(face) = header.elements.get("face") {
        let lists: Vec<_> = FACE_LIST_NAMES
            .iter()
            .filter_map(|n| face.properties.get(*n))
            .collect();
        match lists.as_slice() {
            [] => {
                return Err(
                    "element 'face' has no list property 'vertex_indices' or 'vertex_index'".into(),
                );
            }
            [p] => match &p.data_type {
                PropertyType::List(_, t) if is_integer(t) => {}
                other => {
                    return Err(format!(
                        "face property '{}' must be a list of integers, found {other:?}",
                        p.name
                    ));
                }
            },
            _ => {
                return Err(
                    "element 'face' has both 'vertex_indices' and 'vertex_index'; which one \
                     holds the polygons is ambiguous"
                        .into(),
                );
            }
        }
    }
    if let Some(edge) = header.elements.get("edge") {
        for name in ["vertex1", "vertex2"] {
            match edge.properties.get(name).map(|p| &p.data_type) {
                Some(PropertyType::Scalar(t)) if is_integer(t) => {}
                Some(other) => {
                    return Err(format!(
                        "edge property '{name}' must be an integer scalar, found {other:?}"
                    ));
                }
                None => {
                    return Err(format!(
                        "element 'edge' has no property '{name}' (vertex1 and vertex2 are \
                         required)"
                    ));
                }
            }
        }
    }
    Ok(())
}

fn is_integer(t: &ScalarType) -> bool {
    !matches!(t, ScalarType::Float | ScalarType::Double)
}

/// Fan-triangulates the face lists, rejecting faces of fewer than 3 vertices and
/// negative indices (indices past the end are caught by [`Mesh::validate`]).
fn triangulate(faces: &[PlyFace], count: usize, path: &Path) -> Result<Vec<[u32; 3]>, MeshError> {
    let mut triangles = Vec::with_capacity(faces.iter().map(|f| f.len().saturating_sub(2)).sum());
    for (i, face) in faces.iter().enumerate() {
        if face.len() < 3 {
            return Err(MeshError::Format {
                path: path.to_path_buf(),
                message: format!(
                    "face {i} (counting from 0) has {} vertex indices (a face needs at least 3)",
                    face.len()
                ),
            });
        }
        let at = |k: usize| -> Result<u32, MeshError> {
            match (&face.ints, &face.uints) {
                (ints, _) if !ints.is_empty() => to_index(i64::from(ints[k]), count, path),
                (_, uints) => Ok(uints[k]),
            }
        };
        let first = at(0)?;
        let mut prev = at(1)?;
        for k in 2..face.len() {
            let v = at(k)?;
            triangles.push([first, prev, v]);
            prev = v;
        }
    }
    Ok(triangles)
}

/// A PLY index as `u32`; negative or huge values are out of range (indices past the
/// `count` vertices are left to [`Mesh::validate`]).
fn to_index(i: i64, count: usize, path: &Path) -> Result<u32, MeshError> {
    u32::try_from(i).map_err(|_| MeshError::IndexOutOfRange {
        path: path.to_path_buf(),
        line: None,
        index: i,
        count,
    })
}

/// Wraps a ply-rs-bw error. Its line numbers are file lines only in the header and in
/// ASCII payloads (`lines_are_real`); in binary payloads they count elements.
fn wrap(path: &Path, e: ParseError, lines_are_real: bool, context: &str) -> MeshError {
    // ply-rs-bw's Display prefixes "Line N: " and spreads details over "\n\t" lines.
    let text = e.to_string();
    let text = match (e.line(), text.split_once(": ")) {
        (Some(_), Some((head, tail))) if head.starts_with("Line ") => tail.to_string(),
        _ => text,
    };
    let text = text.replace(".\n\t", "; ").replace("\n\t", "; ");
    let message = format!("{context}: {}", text.replace(['\n', '\r'], "").trim_end());
    match e.line() {
        Some(line) if lines_are_real => MeshError::Parse {
            path: path.to_path_buf(),
            line,
            message,
        },
        _ => MeshError::Format {
            path: path.to_path_buf(),
            message,
        },
    }
}

/// An element whose properties are all ignored (unknown elements, and the header).
struct Skip;

impl PropertyAccess for Skip {
    fn new() -> Self {
        Skip
    }
}

/// Position of a `vertex` element, whatever the scalar types.
#[derive(Clone, Copy, Default)]
struct PlyVertex([f32; 3]);

impl PlyVertex {
    fn set(&mut self, name: &str, value: f32) -> PropertyAccessResult {
        PlyVertex::store(&mut self.0, name, value)
    }

    /// Stores `value` as coordinate `name` of `position` if it is one.
    fn store(position: &mut [f32; 3], name: &str, value: f32) -> PropertyAccessResult {
        let axis = match name {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return PropertyAccessResult::Ignored,
        };
        position[axis] = value;
        PropertyAccessResult::Set
    }
}

impl PropertyAccess for PlyVertex {
    fn new() -> Self {
        Self::default()
    }
    fn set_char(&mut self, name: &str, value: i8) -> PropertyAccessResult {
        self.set(name, f32::from(value))
    }
    fn set_uchar(&mut self, name: &str, value: u8) -> PropertyAccessResult {
        self.set(name, f32::from(value))
    }
    fn set_short(&mut self, name: &str, value: i16) -> PropertyAccessResult {
        self.set(name, f32::from(value))
    }
    fn set_ushort(&mut self, name: &str, value: u16) -> PropertyAccessResult {
        self.set(name, f32::from(value))
    }
    fn set_int(&mut self, name: &str, value: i32) -> PropertyAccessResult {
        self.set(name, value as f32)
    }
    fn set_uint(&mut self, name: &str, value: u32) -> PropertyAccessResult {
        self.set(name, value as f32)
    }
    fn set_float(&mut self, name: &str, value: f32) -> PropertyAccessResult {
        self.set(name, value)
    }
    fn set_double(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        self.set(name, value as f32)
    }
}

/// Position and colour of a `vertex` element when colours are asked for: each
/// spelling of [`PLY_COLOUR_NAMES`] as fractions (integer types divided by their
/// maximum; types without a range are rejected by [`colour_layout`] before reading).
#[derive(Clone, Copy, Default)]
struct PlyColouredVertex {
    position: [f32; 3],
    colour: [[f32; 3]; 3],
}

impl PlyColouredVertex {
    fn set(&mut self, name: &str, value: f32, fraction: f32) -> PropertyAccessResult {
        if let PropertyAccessResult::Set = PlyVertex::store(&mut self.position, name, value) {
            return PropertyAccessResult::Set;
        }
        for (k, names) in PLY_COLOUR_NAMES.iter().enumerate() {
            if let Some(ch) = names.iter().position(|n| *n == name) {
                self.colour[k][ch] = fraction;
                return PropertyAccessResult::Set;
            }
        }
        PropertyAccessResult::Ignored
    }
}

impl PropertyAccess for PlyColouredVertex {
    fn new() -> Self {
        Self::default()
    }
    fn set_char(&mut self, name: &str, value: i8) -> PropertyAccessResult {
        self.set(name, f32::from(value), f32::NAN)
    }
    fn set_uchar(&mut self, name: &str, value: u8) -> PropertyAccessResult {
        self.set(name, f32::from(value), f32::from(value) / 255.0)
    }
    fn set_short(&mut self, name: &str, value: i16) -> PropertyAccessResult {
        self.set(name, f32::from(value), f32::NAN)
    }
    fn set_ushort(&mut self, name: &str, value: u16) -> PropertyAccessResult {
        self.set(name, f32::from(value), f32::from(value) / 65535.0)
    }
    fn set_int(&mut self, name: &str, value: i32) -> PropertyAccessResult {
        self.set(name, value as f32, f32::NAN)
    }
    fn set_uint(&mut self, name: &str, value: u32) -> PropertyAccessResult {
        self.set(name, value as f32, f32::NAN)
    }
    fn set_float(&mut self, name: &str, value: f32) -> PropertyAccessResult {
        self.set(name, value, value)
    }
    fn set_double(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        self.set(name, value as f32, value as f32)
    }
}

/// The vertex list of a `face` element: `int` and `uint` lists are filled in place,
/// narrower integer types are widened into `ints`.
#[derive(Default)]
struct PlyFace {
    ints: Vec<i32>,
    uints: Vec<u32>,
}

impl PlyFace {
    fn len(&self) -> usize {
        self.ints.len().max(self.uints.len())
    }
    fn widen<T: Into<i32>>(&mut self, name: &str, values: Vec<T>) -> PropertyAccessResult {
        if !FACE_LIST_NAMES.contains(&name) {
            return PropertyAccessResult::Ignored;
        }
        self.ints = values.into_iter().map(Into::into).collect();
        PropertyAccessResult::Set
    }
}

impl PropertyAccess for PlyFace {
    fn new() -> Self {
        Self::default()
    }
    fn begin_list_int(&mut self, name: &str, _len: usize) -> BeginList<'_, i32> {
        if FACE_LIST_NAMES.contains(&name) {
            BeginList::Fill(&mut self.ints)
        } else {
            BeginList::UseSetter
        }
    }
    fn begin_list_uint(&mut self, name: &str, _len: usize) -> BeginList<'_, u32> {
        if FACE_LIST_NAMES.contains(&name) {
            BeginList::Fill(&mut self.uints)
        } else {
            BeginList::UseSetter
        }
    }
    fn set_list_char(&mut self, name: &str, value: Vec<i8>) -> PropertyAccessResult {
        self.widen(name, value)
    }
    fn set_list_uchar(&mut self, name: &str, value: Vec<u8>) -> PropertyAccessResult {
        self.widen(name, value)
    }
    fn set_list_short(&mut self, name: &str, value: Vec<i16>) -> PropertyAccessResult {
        self.widen(name, value)
    }
    fn set_list_ushort(&mut self, name: &str, value: Vec<u16>) -> PropertyAccessResult {
        self.widen(name, value)
    }
}

/// The two vertex indices of an `edge` element.
#[derive(Default)]
struct PlyEdge([i64; 2]);

impl PlyEdge {
    fn set(&mut self, name: &str, value: i64) -> PropertyAccessResult {
        let end = match name {
            "vertex1" => 0,
            "vertex2" => 1,
            _ => return PropertyAccessResult::Ignored,
        };
        self.0[end] = value;
        PropertyAccessResult::Set
    }
}

impl PropertyAccess for PlyEdge {
    fn new() -> Self {
        Self::default()
    }
    fn set_char(&mut self, name: &str, value: i8) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_uchar(&mut self, name: &str, value: u8) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_short(&mut self, name: &str, value: i16) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_ushort(&mut self, name: &str, value: u16) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_int(&mut self, name: &str, value: i32) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_uint(&mut self, name: &str, value: u32) -> PropertyAccessResult {
        self.set(name, value.into())
    }
}
