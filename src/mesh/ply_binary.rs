//! Direct decoding of the commonest binary PLY point file: a single `vertex` element of
//! fixed-size scalar properties with `float` x, y, z (lidar exports, scanner output),
//! read as bytes -> `f32` at a fixed stride, in parallel.
//!
//! It only takes files that the general reader (`super::ply`, over `ply-rs-bw`) would
//! read without complaint: the header has passed the same checks, and the payload is
//! exactly `count * stride` bytes. Anything else (other elements, list properties,
//! another coordinate type, a truncated or over-long payload) returns `None` and goes
//! through the general reader, so every error message stays what it was.

use super::ply_check::HeaderInfo;
use glam::Vec3;
use ply_rs_bw::ply::{Encoding, Header, PropertyType, ScalarType};
use rayon::prelude::*;

/// The vertex positions of `bytes` when the file has the layout above, else `None`.
/// `info` and `header` are the checked header of the same bytes.
pub(super) fn float_vertices(
    bytes: &[u8],
    info: &HeaderInfo,
    header: &Header,
) -> Option<Vec<Vec3>> {
    let big = match header.encoding {
        Encoding::BinaryLittleEndian => false,
        Encoding::BinaryBigEndian => true,
        Encoding::Ascii => return None,
    };
    let [element] = info.elements.as_slice() else {
        return None;
    };
    let declared = header.elements.get("vertex")?;
    if element.name != "vertex" || declared.properties.len() != element.properties.len() {
        return None;
    }
    // Byte offsets of x, y, z within a vertex record, in file order of the properties.
    let mut offsets = [usize::MAX; 3];
    let mut stride = 0;
    for (name, _) in &element.properties {
        let PropertyType::Scalar(t) = &declared.properties.get(name)?.data_type else {
            return None;
        };
        if let Some(axis) = ["x", "y", "z"].iter().position(|a| a == name) {
            if *t != ScalarType::Float {
                return None;
            }
            offsets[axis] = stride;
        }
        stride += scalar_size(t);
    }
    if offsets.contains(&usize::MAX) {
        return None;
    }
    let count = usize::try_from(element.count).ok()?;
    let payload = bytes.get(info.end..)?;
    if count.checked_mul(stride)? != payload.len() || count == 0 {
        return None;
    }
    let read = |b: &[u8], at: usize| {
        let word = [b[at], b[at + 1], b[at + 2], b[at + 3]];
        if big {
            f32::from_be_bytes(word)
        } else {
            f32::from_le_bytes(word)
        }
    };
    Some(
        payload
            .par_chunks_exact(stride)
            .map(|v| {
                Vec3::new(
                    read(v, offsets[0]),
                    read(v, offsets[1]),
                    read(v, offsets[2]),
                )
            })
            .collect(),
    )
}

/// Size in bytes of a PLY scalar type.
fn scalar_size(t: &ScalarType) -> usize {
    match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;
    use ply_rs_bw::parser::{Parser, Reader};
    use std::path::Path;

    /// A point file with float x, y, z among other scalar properties, in `format`;
    /// `values[i]` are vertex i's x, y, z.
    fn file(format: &str, values: &[[f32; 3]]) -> Vec<u8> {
        let mut out = format!(
            "ply\nformat {format} 1.0\ncomment fast path\nelement vertex {}\nproperty float x\n\
             property uchar red\nproperty float y\nproperty double nx\nproperty float z\n\
             end_header\n",
            values.len()
        )
        .into_bytes();
        for (i, v) in values.iter().enumerate() {
            let (red, nx) = ((i % 256) as u8, -0.5 * i as f64);
            match format {
                "ascii" => out.extend(format!("{} {red} {} {nx} {}\n", v[0], v[1], v[2]).bytes()),
                "binary_little_endian" => {
                    out.extend(v[0].to_le_bytes());
                    out.push(red);
                    out.extend(v[1].to_le_bytes());
                    out.extend(nx.to_le_bytes());
                    out.extend(v[2].to_le_bytes());
                }
                _ => {
                    out.extend(v[0].to_be_bytes());
                    out.push(red);
                    out.extend(v[1].to_be_bytes());
                    out.extend(nx.to_be_bytes());
                    out.extend(v[2].to_be_bytes());
                }
            }
        }
        out
    }

    fn direct(bytes: &[u8]) -> Option<Vec<Vec3>> {
        let info = super::super::ply_check::check_header(bytes, Path::new("t.ply"))
            .unwrap()
            .unwrap();
        let header = Parser::<ply_rs_bw::ply::DefaultElement>::new()
            .read_header(&mut Reader::new(bytes))
            .unwrap();
        float_vertices(bytes, &info, &header)
    }

    #[test]
    fn direct_decoding_matches_the_general_reader() {
        let mut s = 1u32;
        let mut r = move || {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            ((s >> 8) as f32 / (1 << 24) as f32 - 0.5) * 3.0e4
        };
        let values: Vec<[f32; 3]> = (0..1000).map(|_| [r(), r(), r()]).collect();
        // The ASCII file goes through ply-rs-bw (f32 printed with `{}` reads back exactly).
        let ascii = file("ascii", &values);
        assert!(direct(&ascii).is_none());
        let general = Mesh::from_bytes(ascii, Path::new("a.ply"))
            .unwrap()
            .vertices;
        for format in ["binary_little_endian", "binary_big_endian"] {
            let bytes = file(format, &values);
            assert_eq!(direct(&bytes).as_ref(), Some(&general), "{format}");
            let mesh = Mesh::from_bytes(bytes.clone(), Path::new("b.ply")).unwrap();
            assert_eq!(mesh.vertices, general, "{format}");
            // A trailing newline is not the direct layout, but the same file.
            let mut newline = bytes.clone();
            newline.push(b'\n');
            assert!(direct(&newline).is_none());
            let mesh = Mesh::from_bytes(newline, Path::new("b.ply")).unwrap();
            assert_eq!(mesh.vertices, general, "{format} + newline");
            // Truncated: the general reader's error, naming the file.
            let short = bytes[..bytes.len() - 3].to_vec();
            assert!(direct(&short).is_none());
            let e = Mesh::from_bytes(short, Path::new("short.ply")).unwrap_err();
            assert!(e.to_string().contains("short.ply"), "{e}");
        }
    }

    #[test]
    fn other_layouts_take_the_general_reader() {
        let header = |props: &str| {
            format!("ply\nformat binary_little_endian 1.0\nelement vertex 1\n{props}end_header\n")
                .into_bytes()
        };
        // Double coordinates, a list property, a second element.
        let mut doubles = header("property double x\nproperty double y\nproperty double z\n");
        doubles.extend([0u8; 24]);
        assert!(direct(&doubles).is_none());
        let mut list = header(
            "property float x\nproperty float y\nproperty float z\nproperty list uchar int n\n",
        );
        list.extend([0u8; 13]);
        assert!(direct(&list).is_none());
        let mut faces = b"ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n\
            property float y\nproperty float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n"
            .to_vec();
        faces.extend([0u8; 12]);
        assert!(direct(&faces).is_none());
        for bytes in [doubles, list, faces] {
            let m = Mesh::from_bytes(bytes, Path::new("o.ply")).unwrap();
            assert_eq!(m.vertices, vec![Vec3::ZERO]);
        }
    }
}
