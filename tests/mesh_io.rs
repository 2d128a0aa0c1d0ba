//! Behaviour tests of the mesh readers (`Mesh::load` on OBJ, PLY and STL files).
//!
//! Fixtures are written into a temp dir by the tests; the real data under `data/` is used
//! when present (tests print `skipping: ...` otherwise).

use glam::Vec3;
use smoothtrace::mesh::{Mesh, MeshError};
use std::path::{Path, PathBuf};
use std::time::Instant;
use tempfile::TempDir;

// ---------------------------------------------------------------------------------------
// Helpers

fn write(dir: &TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

fn load_text(name: &str, text: &str) -> Result<Mesh, MeshError> {
    let dir = TempDir::new().unwrap();
    Mesh::load(&write(&dir, name, text.as_bytes()))
}

fn load_bytes(name: &str, bytes: &[u8]) -> Result<Mesh, MeshError> {
    let dir = TempDir::new().unwrap();
    Mesh::load(&write(&dir, name, bytes))
}

/// The path of a real data file, or `None` (with a printed reason) when it is absent.
fn data(name: &str) -> Option<PathBuf> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(name);
    if path.is_file() {
        Some(path)
    } else {
        println!("skipping: data/{name} not found");
        None
    }
}

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

/// Asserts the error names `file` and (when given) carries `line` in its message.
fn assert_names(e: &MeshError, file: &str, line: Option<usize>) {
    let text = e.to_string();
    assert!(text.contains(file), "error does not name {file}: {text}");
    if let Some(line) = line {
        assert!(
            text.contains(&format!("{file}:{line}:")),
            "error does not name line {line}: {text}"
        );
    }
}

/// Compares a bounding box with the README's (rounded) numbers.
fn assert_bounds(mesh: &Mesh, min: [f32; 3], max: [f32; 3], tolerance: f32) {
    let b = mesh.bounds();
    for (got, want) in [(b.min, Vec3::from(min)), (b.max, Vec3::from(max))] {
        let diff = (got - want).abs().max_element();
        assert!(
            diff <= tolerance,
            "{}: bounds {got} vs README {want}: difference {diff} > tolerance {tolerance}",
            mesh.name
        );
    }
}

/// Little helper to write binary PLY/STL payloads in either byte order.
struct Bin {
    big: bool,
    buf: Vec<u8>,
}

impl Bin {
    fn new(big: bool, header: &str) -> Bin {
        Bin {
            big,
            buf: header.as_bytes().to_vec(),
        }
    }
    fn f32(&mut self, x: f32) -> &mut Self {
        let b = if self.big {
            x.to_be_bytes()
        } else {
            x.to_le_bytes()
        };
        self.buf.extend_from_slice(&b);
        self
    }
    fn f64(&mut self, x: f64) -> &mut Self {
        let b = if self.big {
            x.to_be_bytes()
        } else {
            x.to_le_bytes()
        };
        self.buf.extend_from_slice(&b);
        self
    }
    fn i32(&mut self, x: i32) -> &mut Self {
        let b = if self.big {
            x.to_be_bytes()
        } else {
            x.to_le_bytes()
        };
        self.buf.extend_from_slice(&b);
        self
    }
    fn u16(&mut self, x: u16) -> &mut Self {
        let b = if self.big {
            x.to_be_bytes()
        } else {
            x.to_le_bytes()
        };
        self.buf.extend_from_slice(&b);
        self
    }
    fn u8(&mut self, x: u8) -> &mut Self {
        self.buf.push(x);
        self
    }
}

const SQUARE: [[f32; 3]; 4] = [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]];

// ---------------------------------------------------------------------------------------
// OBJ

#[test]
fn obj_quads_and_pentagons_are_fan_triangulated() {
    let m = load_text(
        "poly.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv -1 0.5 0\n\
         f 1 2 3 4\n\
         f 1 2 3 4 5\n\
         f 3 4 5\n",
    )
    .unwrap();
    assert_eq!(m.vertices.len(), 5);
    assert_eq!(
        m.triangles,
        vec![
            [0, 1, 2],
            [0, 2, 3],
            [0, 1, 2],
            [0, 2, 3],
            [0, 3, 4],
            [2, 3, 4]
        ]
    );
    assert!(m.segments.is_empty());
    assert_eq!(m.name, "poly.obj");
}

#[test]
fn obj_index_forms() {
    let m = load_text(
        "forms.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\
         vt 0 0\nvt 1 0\nvt 0 1\n\
         vn 0 0 1\n\
         f 1/1/1 2/2/1 3/3/1\n\
         f 1//1 2//1 4//1\n\
         f 2/2 3/3 4/1\n",
    )
    .unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 1, 3], [1, 2, 3]]);
}

#[test]
fn obj_negative_indices_are_relative_to_vertices_so_far() {
    let m = load_text(
        "neg.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\n\
         f -3 -2 -1\n\
         v 0 0 1\n\
         f -4/1/1 -2//1 -1\n\
         l -1 -4\n",
    )
    .unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(m.segments, vec![[3, 0]]);
}

#[test]
fn obj_polylines_become_consecutive_segments() {
    let m = load_text(
        "lines.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
         l 1 2 3 4 1\n\
         l 2/1 4/2\n",
    )
    .unwrap();
    assert_eq!(m.segments, vec![[0, 1], [1, 2], [2, 3], [3, 0], [1, 3]]);
    assert!(m.triangles.is_empty());
}

#[test]
fn obj_points_add_no_primitives() {
    let m = load_text("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2\np -1\n").unwrap();
    assert_eq!(m.vertices.len(), 3);
    assert!(m.segments.is_empty() && m.triangles.is_empty());
    // ... but their indices are checked.
    let e = load_text("points.obj", "v 0 0 0\np 1 2\n").unwrap_err();
    assert!(
        matches!(
            e,
            MeshError::IndexOutOfRange {
                line: Some(2),
                index: 2,
                ..
            }
        ),
        "{e:?}"
    );
}

#[test]
fn obj_bare_vertices_are_a_point_cloud() {
    // Extra components (a weight, vertex colours) after x y z are ignored.
    let m = load_text(
        "cloud.obj",
        "# a point cloud\n\nv 1 2 3\nv 4 5 6 1.0\nv\t-7.5e-1  8 9 0.5 0.25 1\n",
    )
    .unwrap();
    assert_eq!(
        m.vertices,
        vec![v(1., 2., 3.), v(4., 5., 6.), v(-0.75, 8., 9.)]
    );
    assert!(m.segments.is_empty() && m.triangles.is_empty());
}

#[test]
fn obj_ignores_other_statements() {
    let m = load_text(
        "misc.obj",
        "mtllib a.mtl\no thing\ng group\ns 1\nusemtl red\n\
         v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\nvp 0.5\n\
         curv 0 1 1 2\nfoo bar\n  # indented comment\n\
         f 1 2 3\n",
    )
    .unwrap();
    assert_eq!(m.vertices.len(), 3);
    assert_eq!(m.triangles, vec![[0, 1, 2]]);
}

#[test]
fn obj_degenerate_faces_are_kept() {
    let m = load_text("degen.obj", "v 0 0 0\nv 1 0 0\nf 1 2 2\nf 1 1 1\n").unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 1], [0, 0, 0]]);
}

// ---------------------------------------------------------------------------------------
// PLY

const PLY_SQUARE_ASCII: &str = "ply\n\
format ascii 1.0\n\
comment a unit square and a triangle\n\
element vertex 5\n\
property float x\n\
property float y\n\
property float z\n\
property uchar red\n\
element face 2\n\
property list uchar int vertex_indices\n\
end_header\n\
0 0 0 255\n\
1 0 0 0\n\
1 1 0 0\n\
0 1 0 0\n\
0.5 0.5 2 0\n\
4 0 1 2 3\n\
3 0 1 4\n";

#[test]
fn ply_ascii_with_faces() {
    let m = load_text("square.ply", PLY_SQUARE_ASCII).unwrap();
    let mut want: Vec<Vec3> = SQUARE.iter().map(|p| Vec3::from(*p)).collect();
    want.push(v(0.5, 0.5, 2.));
    assert_eq!(m.vertices, want);
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 4]]);
    assert!(m.segments.is_empty());
    // Windows line ends read the same.
    let crlf = load_text("square.ply", &PLY_SQUARE_ASCII.replace('\n', "\r\n")).unwrap();
    assert_eq!((crlf.vertices, crlf.triangles), (m.vertices, m.triangles));
}

/// A binary PLY: a square (quad face) with float x, an extra normal, double y, int z.
fn ply_binary_square(big: bool) -> Vec<u8> {
    let format = if big {
        "binary_big_endian"
    } else {
        "binary_little_endian"
    };
    let header = format!(
        "ply\nformat {format} 1.0\n\
         element vertex 4\n\
         property float x\nproperty float nx\nproperty double y\nproperty int z\n\
         element face 1\n\
         property list uchar uint vertex_index\n\
         end_header\n"
    );
    let mut b = Bin::new(big, &header);
    for p in SQUARE {
        b.f32(p[0]).f32(9.0).f64(f64::from(p[1])).i32(p[2] as i32);
    }
    b.u8(4);
    for i in 0..4 {
        let i: i32 = i;
        b.i32(i);
    }
    b.buf
}

#[test]
fn ply_binary_little_and_big_endian_with_faces() {
    for big in [false, true] {
        let m = load_bytes("square.ply", &ply_binary_square(big)).unwrap();
        let want: Vec<Vec3> = SQUARE.iter().map(|p| Vec3::from(*p)).collect();
        assert_eq!(m.vertices, want, "big endian: {big}");
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]], "big endian: {big}");
    }
}

#[test]
fn ply_double_coordinates() {
    for big in [false, true] {
        let format = if big {
            "binary_big_endian"
        } else {
            "binary_little_endian"
        };
        let header = format!(
            "ply\nformat {format} 1.0\nelement vertex 2\n\
             property double x\nproperty double y\nproperty double z\nend_header\n"
        );
        let mut b = Bin::new(big, &header);
        b.f64(0.1).f64(-2.5).f64(1e10).f64(3.0).f64(4.0).f64(5.0);
        let m = load_bytes("double.ply", &b.buf).unwrap();
        assert_eq!(
            m.vertices,
            vec![v(0.1, -2.5, 1e10), v(3., 4., 5.)],
            "big: {big}"
        );
    }
    let m = load_text(
        "double.ply",
        "ply\nformat ascii 1.0\nelement vertex 1\n\
         property double x\nproperty double y\nproperty double z\nend_header\n\
         0.1 -2.5 1e10\n",
    )
    .unwrap();
    assert_eq!(m.vertices, vec![v(0.1, -2.5, 1e10)]);
}

#[test]
fn ply_edge_element_gives_segments() {
    let m = load_text(
        "edges.ply",
        "ply\nformat ascii 1.0\n\
         element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
         element edge 2\nproperty int vertex1\nproperty int vertex2\nproperty uchar red\n\
         end_header\n\
         0 0 0\n1 0 0\n0 1 0\n\
         0 1 255\n1 2 0\n",
    )
    .unwrap();
    assert_eq!(m.segments, vec![[0, 1], [1, 2]]);
    assert!(m.triangles.is_empty());

    // The same in binary, with an unknown element in between (it is skipped).
    let header = "ply\nformat binary_little_endian 1.0\n\
         element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
         element material 1\nproperty list uchar float values\n\
         element edge 2\nproperty ushort vertex1\nproperty ushort vertex2\n\
         end_header\n";
    let mut b = Bin::new(false, header);
    for p in [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]] {
        b.f32(p[0]).f32(p[1]).f32(p[2]);
    }
    b.u8(2).f32(1.0).f32(2.0);
    b.u16(0).u16(1).u16(1).u16(2);
    let m = load_bytes("edges.ply", &b.buf).unwrap();
    assert_eq!(m.vertices.len(), 3);
    assert_eq!(m.segments, vec![[0, 1], [1, 2]]);
}

#[test]
fn ply_integer_coordinates_and_other_lists() {
    let m = load_text(
        "ints.ply",
        "ply\nformat ascii 1.0\n\
         element vertex 3\nproperty short x\nproperty uchar y\nproperty uint z\n\
         property list uchar float weights\n\
         element face 1\nproperty list uchar float texcoord\n\
         property list ushort ushort vertex_indices\n\
         end_header\n\
         -3 4 5 2 0.5 0.5\n1 2 3 0\n0 0 7 1 1\n\
         6 0 0 1 1 0 1 3 0 1 2\n",
    )
    .unwrap();
    assert_eq!(
        m.vertices,
        vec![v(-3., 4., 5.), v(1., 2., 3.), v(0., 0., 7.)]
    );
    assert_eq!(m.triangles, vec![[0, 1, 2]]);
}

#[test]
fn ply_missing_coordinate_is_a_clear_error() {
    let e = load_text(
        "noy.ply",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float z\n\
         end_header\n0 0\n",
    )
    .unwrap_err();
    assert!(matches!(e, MeshError::Format { .. }), "{e:?}");
    assert_names(&e, "noy.ply", None);
    assert!(e.to_string().contains("no property 'y'"), "{e}");

    let e = load_text("novertex.ply", "ply\nformat ascii 1.0\nend_header\n").unwrap_err();
    assert!(e.to_string().contains("no 'vertex' element"), "{e}");
}

#[test]
fn ply_ascii_payload_error_names_the_line() {
    let text = PLY_SQUARE_ASCII.replace("1 1 0 0\n", "1 oops 0 0\n");
    let e = load_text("bad.ply", &text).unwrap_err();
    // The header has 11 lines; the third vertex is on line 14.
    assert!(matches!(e, MeshError::Parse { line: 14, .. }), "{e:?}");
    assert_names(&e, "bad.ply", Some(14));
    assert!(!e.to_string().contains('\n'), "multi-line message: {e}");
}

#[test]
fn ply_negative_and_out_of_range_face_indices() {
    for (face, index) in [("3 0 1 -1", -1), ("3 0 1 7", 7)] {
        let text = format!(
            "ply\nformat ascii 1.0\nelement vertex 3\n\
             property float x\nproperty float y\nproperty float z\n\
             element face 1\nproperty list uchar int vertex_indices\nend_header\n\
             0 0 0\n1 0 0\n0 1 0\n{face}\n"
        );
        let e = load_text("idx.ply", &text).unwrap_err();
        assert!(
            matches!(e, MeshError::IndexOutOfRange { index: i, count: 3, .. } if i == index),
            "{e:?}"
        );
        assert_names(&e, "idx.ply", None);
    }
}

// ---------------------------------------------------------------------------------------
// STL

/// The 12 triangles of the unit cube, as corner positions.
fn cube_triangles() -> Vec<[[f32; 3]; 3]> {
    let c = |i: usize| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32];
    // Quads of corner numbers (bit 0 = x, bit 1 = y, bit 2 = z).
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    quads
        .iter()
        .flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]])
        .collect()
}

fn stl_ascii(triangles: &[[[f32; 3]; 3]]) -> String {
    let mut s = String::from("solid cube\n");
    for (k, t) in triangles.iter().enumerate() {
        s += "  facet normal 0 0 0\n    outer loop\n";
        for p in t {
            // Write some zeros as "-0": they must merge with "0".
            let f = |x: f32| {
                if x == 0.0 && k % 2 == 1 {
                    "-0".to_string()
                } else {
                    format!("{x:e}")
                }
            };
            s += &format!("      vertex {} {} {}\n", f(p[0]), f(p[1]), f(p[2]));
        }
        s += "    endloop\n  endfacet\n";
    }
    s + "endsolid cube\n"
}

fn stl_binary(triangles: &[[[f32; 3]; 3]], header_text: &str) -> Vec<u8> {
    let mut header = [b' '; 80];
    header[..header_text.len()].copy_from_slice(header_text.as_bytes());
    let mut b = Bin {
        big: false,
        buf: header.to_vec(),
    };
    b.buf
        .extend_from_slice(&(triangles.len() as u32).to_le_bytes());
    for t in triangles {
        b.f32(0.).f32(0.).f32(0.);
        for p in t {
            b.f32(p[0]).f32(p[1]).f32(p[2]);
        }
        b.u16(0);
    }
    b.buf
}

fn assert_is_cube(m: &Mesh) {
    assert_eq!(m.vertices.len(), 8, "merged vertex count");
    assert_eq!(m.triangles.len(), 12);
    // Every corner is shared by the same positions: rebuild the triangles' positions.
    let got: Vec<[[f32; 3]; 3]> = m
        .triangles
        .iter()
        .map(|t| t.map(|i| m.vertices[i as usize].to_array()))
        .collect();
    assert_eq!(got, cube_triangles());
    // A closed cube: 18 unique edges, each used twice.
    assert_eq!(m.triangle_edges().len(), 18);
}

#[test]
fn stl_ascii_cube_merges_vertices() {
    let m = load_text("cube.stl", &stl_ascii(&cube_triangles())).unwrap();
    assert_is_cube(&m);
}

#[test]
fn stl_binary_cube_merges_vertices() {
    let m = load_bytes("cube.stl", &stl_binary(&cube_triangles(), "binary cube")).unwrap();
    assert_is_cube(&m);
    // A binary header starting with "solid" (as some exporters write) is still binary.
    let m = load_bytes("cube.STL", &stl_binary(&cube_triangles(), "solid cube")).unwrap();
    assert_is_cube(&m);
}

// ---------------------------------------------------------------------------------------
// Errors

#[test]
fn missing_file_is_an_io_error_naming_it() {
    for name in ["nope.obj", "nope.ply", "nope.stl"] {
        let e = Mesh::load(Path::new(name)).unwrap_err();
        assert!(matches!(e, MeshError::Io { .. }), "{e:?}");
        assert_names(&e, name, None);
    }
}

#[test]
fn unknown_extension() {
    let e = load_text("mesh.off", "OFF\n").unwrap_err();
    assert!(
        matches!(&e, MeshError::UnknownExtension { extension, .. } if extension == "off"),
        "{e:?}"
    );
    assert_names(&e, "mesh.off", None);
    let e = load_text("noext", "v 0 0 0\n").unwrap_err();
    assert!(matches!(e, MeshError::UnknownExtension { .. }), "{e:?}");
}

#[test]
fn obj_malformed_vertex_names_file_and_line() {
    let e = load_text("bad.obj", "# header\nv 0 0 0\nv 1 zero 0\nv 0 1 0\n").unwrap_err();
    assert!(matches!(e, MeshError::Parse { line: 3, .. }), "{e:?}");
    assert_names(&e, "bad.obj", Some(3));
    let text = e.to_string();
    assert!(
        text.contains("'zero'") && text.contains("expected a number"),
        "{text}"
    );

    let e = load_text("short.obj", "v 0 0 0\n\nv 1 2\n").unwrap_err();
    assert!(matches!(e, MeshError::Parse { line: 3, .. }), "{e:?}");
    assert_names(&e, "short.obj", Some(3));
    assert!(e.to_string().contains("3 coordinates"), "{e}");
}

#[test]
fn obj_malformed_face_names_file_and_line() {
    for (face, what) in [
        ("f 1 2", "at least 3"),
        ("f 1 x 3", "malformed vertex index"),
    ] {
        let e = load_text("face.obj", &format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{face}\n")).unwrap_err();
        assert!(
            matches!(e, MeshError::Parse { line: 4, .. }),
            "{face}: {e:?}"
        );
        assert_names(&e, "face.obj", Some(4));
        assert!(e.to_string().contains(what), "{e}");
    }
    let e = load_text("line.obj", "v 0 0 0\nl 1\n").unwrap_err();
    assert!(matches!(e, MeshError::Parse { line: 2, .. }), "{e:?}");
}

#[test]
fn obj_index_out_of_range_names_line() {
    let e = load_text("oor.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n").unwrap_err();
    assert!(
        matches!(
            e,
            MeshError::IndexOutOfRange {
                line: Some(4),
                index: 4,
                count: 3,
                ..
            }
        ),
        "{e:?}"
    );
    assert_names(&e, "oor.obj", Some(4));

    let e = load_text("oor.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 1 2\n").unwrap_err();
    assert!(
        matches!(
            e,
            MeshError::IndexOutOfRange {
                line: Some(4),
                index: -4,
                ..
            }
        ),
        "{e:?}"
    );
}

#[test]
fn obj_index_zero_is_out_of_range() {
    let e = load_text("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n").unwrap_err();
    assert!(
        matches!(
            e,
            MeshError::IndexOutOfRange {
                line: Some(4),
                index: 0,
                ..
            }
        ),
        "{e:?}"
    );
    assert_names(&e, "zero.obj", Some(4));
}

#[test]
fn non_finite_coordinates_are_errors() {
    for bad in ["nan", "NaN", "inf", "-infinity", "1e39"] {
        let e = load_text("nan.obj", &format!("v 0 0 0\nv 1 {bad} 0\n")).unwrap_err();
        assert!(
            matches!(e, MeshError::Parse { line: 2, .. }),
            "{bad}: {e:?}"
        );
        assert_names(&e, "nan.obj", Some(2));
        assert!(e.to_string().contains("not finite"), "{e}");
    }
    // Binary formats cannot reject while parsing; the mesh validation names the vertex.
    let header = "ply\nformat binary_little_endian 1.0\nelement vertex 2\n\
        property float x\nproperty float y\nproperty float z\nend_header\n";
    let mut b = Bin::new(false, header);
    b.f32(0.).f32(0.).f32(0.).f32(1.).f32(f32::NAN).f32(0.);
    let e = load_bytes("nan.ply", &b.buf).unwrap_err();
    assert!(matches!(e, MeshError::NonFinite { vertex: 1, .. }), "{e:?}");
    assert_names(&e, "nan.ply", None);

    let mut tris = cube_triangles();
    tris[3][1][2] = f32::INFINITY;
    let e = load_bytes("inf.stl", &stl_binary(&tris, "")).unwrap_err();
    assert!(matches!(e, MeshError::NonFinite { .. }), "{e:?}");
}

#[test]
fn empty_files_are_empty_errors() {
    for name in ["empty.obj", "empty.ply", "empty.stl"] {
        let e = load_bytes(name, b"").unwrap_err();
        assert!(matches!(e, MeshError::Empty { .. }), "{name}: {e:?}");
        assert_names(&e, name, None);
    }
    // An OBJ with statements but no vertices is empty too.
    let e = load_text("novert.obj", "# nothing\no thing\n").unwrap_err();
    assert!(matches!(e, MeshError::Empty { .. }), "{e:?}");
}

#[test]
fn truncated_binary_ply_is_an_error() {
    let full = ply_binary_square(false);
    let header_len = full.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    // Cut inside the vertex block, at the face count, and inside the face list.
    for cut in [header_len + 5, header_len + 4 * 20, full.len() - 1] {
        let e = load_bytes("cut.ply", &full[..cut]).unwrap_err();
        assert!(matches!(e, MeshError::Format { .. }), "cut at {cut}: {e:?}");
        assert_names(&e, "cut.ply", None);
    }
    // Cut inside the header.
    let e = load_bytes("cut.ply", &full[..header_len - 4]).unwrap_err();
    assert_names(&e, "cut.ply", None);
}

#[test]
fn truncated_binary_stl_is_an_error() {
    let full = stl_binary(&cube_triangles(), "cube");
    for cut in [10, 83, 84 + 50 * 5 + 7, full.len() - 1] {
        let e = load_bytes("cut.stl", &full[..cut]).unwrap_err();
        assert!(matches!(e, MeshError::Format { .. }), "cut at {cut}: {e:?}");
        assert_names(&e, "cut.stl", None);
        let what = if cut < 84 { "too short" } else { "truncated" };
        assert!(e.to_string().contains(what), "cut at {cut}: {e}");
    }
}

#[test]
fn huge_counts_in_headers_do_not_allocate_or_panic() {
    // A PLY promising 4 billion vertices, and an STL promising 4 billion triangles.
    let header = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n\
        property float x\nproperty float y\nproperty float z\nend_header\n";
    let mut b = Bin::new(false, header);
    b.f32(1.).f32(2.).f32(3.);
    let e = load_bytes("huge.ply", &b.buf).unwrap_err();
    assert_names(&e, "huge.ply", None);

    let header = "ply\nformat ascii 1.0\nelement vertex 3\n\
        property float x\nproperty float y\nproperty float z\n\
        element face 4000000000\nproperty list uint int vertex_indices\nend_header\n\
        0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n";
    let e = load_text("huge.ply", header).unwrap_err();
    assert_names(&e, "huge.ply", None);

    let mut stl = stl_binary(&cube_triangles(), "huge");
    stl[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = load_bytes("huge.stl", &stl).unwrap_err();
    assert_names(&e, "huge.stl", None);
}

#[test]
fn garbage_and_truncations_never_panic() {
    // Every prefix of every fixture, plus bytes flipped: errors are fine, panics are not.
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1 2//1 -1\nl 1 2\np 3\n".to_vec();
    let fixtures: Vec<(&str, Vec<u8>)> = vec![
        ("f.obj", obj),
        ("f.ply", PLY_SQUARE_ASCII.as_bytes().to_vec()),
        ("f.ply", ply_binary_square(false)),
        ("f.ply", ply_binary_square(true)),
        ("f.stl", stl_ascii(&cube_triangles()[..2]).into_bytes()),
        ("f.stl", stl_binary(&cube_triangles()[..2], "solid x")),
    ];
    let dir = TempDir::new().unwrap();
    let mut seed = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    for (name, bytes) in &fixtures {
        let path = dir.path().join(name);
        for cut in 0..bytes.len() {
            std::fs::write(&path, &bytes[..cut]).unwrap();
            let _ = Mesh::load(&path);
        }
        for _ in 0..300 {
            let mut b = bytes.clone();
            for _ in 0..1 + next() % 4 {
                let i = (next() % b.len() as u64) as usize;
                b[i] = next() as u8;
            }
            std::fs::write(&path, &b).unwrap();
            if let Err(e) = Mesh::load(&path) {
                assert!(e.to_string().contains(name), "{e}");
            }
        }
    }
    for name in ["g.obj", "g.ply", "g.stl"] {
        let path = dir.path().join(name);
        for len in [1, 7, 84, 200, 5000] {
            let b: Vec<u8> = (0..len).map(|_| next() as u8).collect();
            std::fs::write(&path, &b).unwrap();
            let _ = Mesh::load(&path);
        }
    }
}

// ---------------------------------------------------------------------------------------
// Real data (data/ README)

/// A row of the data README: counts, bounding box and diagonal.
struct Expected {
    file: &'static str,
    vertices: usize,
    triangles: usize,
    min: [f32; 3],
    max: [f32; 3],
    diag: f32,
}

#[test]
fn data_obj_counts_and_bounds() {
    let table = [
        Expected {
            file: "bunny-7k.obj",
            vertices: 3485,
            triangles: 6966,
            min: [-0.0947455, 0.0329874, -0.061928],
            max: [0.061013, 0.187267, 0.0588187],
            diag: 0.250285,
        },
        Expected {
            file: "bunny.obj",
            vertices: 35947,
            triangles: 69451,
            min: [-0.09469, 0.032987, -0.061874],
            max: [0.061009, 0.187321, 0.0588],
            diag: 0.250247,
        },
        Expected {
            file: "suzanne.obj",
            vertices: 507,
            triangles: 968,
            min: [-3.86125, 0.267311, 3.25233],
            max: [-1.12688, 2.23606, 4.95545],
            diag: 3.77537,
        },
        Expected {
            file: "teapot.obj",
            vertices: 3644,
            triangles: 6320,
            min: [-3., 0., -2.],
            max: [3.434, 3.15, 2.],
            diag: 8.20481,
        },
        Expected {
            file: "spot.obj",
            vertices: 2930,
            triangles: 5856,
            min: [-0.471552, -0.736784, -0.668909],
            max: [0.471552, 0.953646, 1.049],
            diag: 2.58809,
        },
        Expected {
            file: "fandisk.obj",
            vertices: 6475,
            triangles: 12946,
            min: [0., 12.6055, -2.68026],
            max: [4.8279, 17.85, 0.],
            diag: 7.61559,
        },
        Expected {
            file: "cow.obj",
            vertices: 2903,
            triangles: 5804,
            min: [-4.44583, -3.63704, -1.70141],
            max: [5.99809, 2.75972, 1.70141],
            diag: 12.7111,
        },
    ];
    for e in table {
        let Some(path) = data(e.file) else { continue };
        let start = Instant::now();
        let m = Mesh::load(&path).unwrap();
        let name = e.file;
        println!(
            "{name}: loaded in {:.1} ms",
            start.elapsed().as_secs_f64() * 1e3
        );
        assert_eq!(m.vertices.len(), e.vertices, "{name} vertices");
        assert_eq!(m.triangles.len(), e.triangles, "{name} triangles");
        assert!(m.segments.is_empty(), "{name} segments");
        assert_bounds(&m, e.min, e.max, 1e-5 * e.diag);
        let (d, want) = (m.bounds().diagonal(), f64::from(e.diag));
        assert!(
            (d - want).abs() <= 1e-5 * want,
            "{name}: diagonal {d} vs README {want}: difference {} > tolerance {}",
            (d - want).abs(),
            1e-5 * want
        );
    }
}

#[test]
fn data_igea_point_cloud() {
    let Some(path) = data("igea-points-134k.ply") else {
        return;
    };
    let m = Mesh::load(&path).unwrap();
    assert_eq!(m.vertices.len(), 134_345);
    assert!(m.triangles.is_empty() && m.segments.is_empty());
    assert_bounds(
        &m,
        [-0.034556, -0.049669, -0.049538],
        [0.034556, 0.049669, 0.049538],
        1e-5 * 0.156399,
    );
}

#[test]
fn data_obj_triangles_match_tobj() {
    let files = [
        "bunny-7k.obj",
        "bunny.obj",
        "spot.obj",
        "fandisk.obj",
        "teapot.obj",
        "suzanne.obj",
        "cow.obj",
    ];
    for name in files {
        let Some(path) = data(name) else { continue };
        let ours = Mesh::load(&path).unwrap();
        let ours: Vec<[Vec3; 3]> = ours
            .triangles
            .iter()
            .map(|t| t.map(|i| ours.vertices[i as usize]))
            .collect();
        // tobj re-indexes (single index over position/uv/normal), so compare positions.
        let (models, _) = tobj::load_obj(&path, &tobj::GPU_LOAD_OPTIONS).unwrap();
        let theirs: Vec<[Vec3; 3]> = models
            .iter()
            .flat_map(|model| {
                let m = &model.mesh;
                let p = |i: u32| Vec3::from_slice(&m.positions[3 * i as usize..][..3]);
                m.indices
                    .chunks_exact(3)
                    .map(move |t| [p(t[0]), p(t[1]), p(t[2])])
            })
            .collect();
        assert_eq!(ours.len(), theirs.len(), "{name}: triangle count vs tobj");
        if let Some(k) = (0..ours.len()).find(|&k| ours[k] != theirs[k]) {
            panic!(
                "{name}: triangle {k} differs from tobj: {:?} vs {:?}",
                ours[k], theirs[k]
            );
        }
    }
}

#[test]
fn data_lidar_point_cloud() {
    if cfg!(debug_assertions) {
        println!("skipping: the 8M-point lidar test runs only in release builds");
        return;
    }
    let Some(path) = data("autzen-lidar-8m.ply") else {
        return;
    };
    let start = Instant::now();
    let m = Mesh::load(&path).unwrap();
    println!(
        "autzen-lidar-8m.ply: loaded in {:.0} ms",
        start.elapsed().as_secs_f64() * 1e3
    );
    assert_eq!(m.vertices.len(), 8_000_000);
    assert!(m.triangles.is_empty() && m.segments.is_empty());
    assert_bounds(
        &m,
        [-1713.21, -2327.85, -104.86],
        [1712.73, 2327.66, 104.26],
        0.01,
    );
}
