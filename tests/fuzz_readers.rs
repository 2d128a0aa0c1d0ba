//! Fuzzing that stays in the project (issue 10): property tests that feed generated,
//! mutated and random bytes to every reader and assert no panic, and either a clean
//! error naming the file or a result equal to an independent brute-force reading of the
//! same values.
//!
//! - Generated meshes are written by the encoders below (OBJ; PLY ASCII, binary LE and
//!   BE; STL ASCII and binary) and must read back to exactly the values written.
//! - Mutated files (byte flips, insertions, deletions, truncations, duplicated and
//!   dropped lines) of generated meshes and of slices of the real files in `data/`
//!   (when present): no panic; an accepted OBJ must equal the independent line reader
//!   [`naive_obj`] (which must reject what the reader rejects); an accepted PLY or STL
//!   must meet the mesh invariants; flips inside the vertex block of a binary PLY or STL
//!   must give exactly the brute-force decoding of the flipped floats, or an error when
//!   one is not finite or beyond the coordinate limit.
//! - Random bytes to each reader and to the scene loader: no panic.
//! - LAS/LAZ: mutated copies of the small files in `data/las/`, read through `Mesh::load`.
//!
//! Budget: `SMOOTHTRACE_FUZZ_CASES` cases per property (default 1000, a few seconds in
//! release; 5000 took 18 s on the project machine). The long run: `SMOOTHTRACE_FUZZ_CASES=100000 cargo test --release --test
//! fuzz_readers`.

mod common;

use proptest::prelude::*;
use proptest::sample::Index;
use smoothtrace::limits::MAX_COORD;
use smoothtrace::mesh::{Mesh, MeshError};
use std::path::Path;

fn cases() -> u32 {
    std::env::var("SMOOTHTRACE_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1000)
}

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: cases(),
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

// ---------------------------------------------------------------------------------
// Generated meshes and independent encoders.

#[derive(Clone, Debug)]
struct Gen {
    vertices: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
    segments: Vec<[u32; 2]>,
}

fn coordinate() -> impl Strategy<Value = f32> {
    prop_oneof![
        (-1000i32..1000).prop_map(|i| i as f32 / 8.0),
        any::<f32>().prop_filter("finite, within the limit", |v| v.is_finite()
            && (*v as f64).abs() <= MAX_COORD),
        Just(-0.0f32),
        Just(1e30f32),
        Just(-1e-30f32),
    ]
}

fn gen_mesh() -> impl Strategy<Value = Gen> {
    prop::collection::vec([coordinate(), coordinate(), coordinate()], 1..24).prop_flat_map(|v| {
        let n = v.len() as u32;
        (
            Just(v),
            prop::collection::vec([0..n, 0..n, 0..n], 0..16),
            prop::collection::vec([0..n, 0..n], 0..8),
        )
            .prop_map(|(vertices, triangles, segments)| Gen {
                vertices,
                triangles,
                segments,
            })
    })
}

fn obj_text(g: &Gen, style: u8) -> Vec<u8> {
    let mut s = String::from("# generated\no t\n");
    for v in &g.vertices {
        s += &format!("v {:?} {:?} {:?}\n", v[0], v[1], v[2]);
    }
    let n = g.vertices.len() as i64;
    // 0: 1-based, 1: negative (relative), 2: v//vn, 3: v/vt/vn
    let idx = |i: u32| match style % 4 {
        0 => format!("{}", i + 1),
        1 => format!("{}", i as i64 - n),
        2 => format!("{}//1", i + 1),
        _ => format!("{}/2/3", i + 1),
    };
    for t in &g.triangles {
        s += &format!("f {} {} {}\n", idx(t[0]), idx(t[1]), idx(t[2]));
    }
    for e in &g.segments {
        s += &format!("l {} {}\n", idx(e[0]), idx(e[1]));
    }
    s.into_bytes()
}

#[derive(Clone, Copy, Debug)]
enum PlyEnc {
    Ascii,
    Le,
    Be,
}

fn ply_bytes(g: &Gen, enc: PlyEnc) -> Vec<u8> {
    let format = match enc {
        PlyEnc::Ascii => "ascii",
        PlyEnc::Le => "binary_little_endian",
        PlyEnc::Be => "binary_big_endian",
    };
    let mut out = format!(
        "ply\nformat {format} 1.0\ncomment generated\nelement vertex {}\nproperty float x\n\
         property float y\nproperty float z\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        g.vertices.len(),
        g.triangles.len()
    )
    .into_bytes();
    let f = |x: f32| match enc {
        PlyEnc::Le => x.to_le_bytes(),
        _ => x.to_be_bytes(),
    };
    let i = |x: u32| match enc {
        PlyEnc::Le => (x as i32).to_le_bytes(),
        _ => (x as i32).to_be_bytes(),
    };
    for v in &g.vertices {
        match enc {
            PlyEnc::Ascii => out.extend(format!("{:?} {:?} {:?}\n", v[0], v[1], v[2]).bytes()),
            _ => v.iter().for_each(|&c| out.extend(f(c))),
        }
    }
    for t in &g.triangles {
        match enc {
            PlyEnc::Ascii => out.extend(format!("3 {} {} {}\n", t[0], t[1], t[2]).bytes()),
            _ => {
                out.push(3);
                t.iter().for_each(|&k| out.extend(i(k)));
            }
        }
    }
    out
}

fn stl_bytes(g: &Gen, ascii: bool) -> Vec<u8> {
    let corners = |t: &[u32; 3]| t.map(|k| g.vertices[k as usize]);
    if ascii {
        let mut s = String::from("solid gen\n");
        for t in &g.triangles {
            s += "facet normal 0 0 1\nouter loop\n";
            for c in corners(t) {
                s += &format!("vertex {:?} {:?} {:?}\n", c[0], c[1], c[2]);
            }
            s += "endloop\nendfacet\n";
        }
        s += "endsolid gen\n";
        s.into_bytes()
    } else {
        let mut out = vec![b'x'; 80];
        out.extend((g.triangles.len() as u32).to_le_bytes());
        for t in &g.triangles {
            out.extend([0u8; 12]);
            for c in corners(t) {
                c.iter().for_each(|x| out.extend(x.to_le_bytes()));
            }
            out.extend([0u8; 2]);
        }
        out
    }
}

fn same_f32(a: f32, b: f32) -> bool {
    a == b // -0.0 == 0.0; NaN never appears in an accepted mesh
}

fn assert_vertices(m: &Mesh, want: &[[f32; 3]]) {
    assert_eq!(m.vertices.len(), want.len());
    for (v, w) in m.vertices.iter().zip(want) {
        assert!(
            (0..3).all(|k| same_f32(v[k], w[k])),
            "vertex {v:?} read, {w:?} written"
        );
    }
}

/// STL keeps no vertex list: each triangle's corners must be the written positions.
fn assert_stl_corners(m: &Mesh, g: &Gen) {
    assert_eq!(m.triangles.len(), g.triangles.len());
    for (t, w) in m.triangles.iter().zip(&g.triangles) {
        for k in 0..3 {
            let got = m.vertices[t[k] as usize];
            let want = g.vertices[w[k] as usize];
            assert!(
                (0..3).all(|c| same_f32(got[c], want[c])),
                "{got:?} vs {want:?}"
            );
        }
    }
}

/// What every accepted mesh must satisfy, and every error: it names the file.
fn check_outcome(r: &Result<Mesh, MeshError>, path: &Path) {
    match r {
        Ok(m) => {
            assert!(!m.vertices.is_empty());
            for v in &m.vertices {
                assert!(v.is_finite() && v.abs().max_element() as f64 <= MAX_COORD * 1.0000001);
            }
            let n = m.vertices.len() as u32;
            assert!(m.triangles.iter().flatten().all(|&i| i < n));
            assert!(m.segments.iter().flatten().all(|&i| i < n));
        }
        Err(e) => {
            let msg = e.to_string();
            assert!(msg.contains(&path.display().to_string()), "{msg}");
        }
    }
}

// ---------------------------------------------------------------------------------
// An independent OBJ reader: the documented rules of `mesh::obj`, written as plainly
// as possible (lines, `#` comments, `v` with three finite coordinates within the
// limit, `f`/`l`/`p` with 1-based or negative indices `v`, `v/vt`, `v//vn`, `v/vt/vn`).

/// Vertices, triangles and segments.
type ObjValues = (Vec<[f32; 3]>, Vec<[u32; 3]>, Vec<[u32; 2]>);

fn naive_obj(bytes: &[u8]) -> Option<ObjValues> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let (mut v, mut f, mut l) = (Vec::new(), Vec::new(), Vec::new());
    for line in bytes.split(|&b| b == b'\n') {
        let line = match line.iter().position(|&b| b == b'#') {
            Some(k) => &line[..k],
            None => line,
        };
        let words: Vec<&[u8]> = line
            .split(|b| b.is_ascii_whitespace())
            .filter(|w| !w.is_empty())
            .collect();
        let Some((&key, rest)) = words.split_first() else {
            continue;
        };
        let index = |w: &[u8], count: usize| -> Option<u32> {
            let text = std::str::from_utf8(w).ok()?;
            let parts: Vec<&str> = text.split('/').collect();
            if parts.len() > 3 {
                return None;
            }
            let int_ok = |p: &str| p.parse::<i64>().is_ok();
            if !parts[1..].iter().all(|p| p.is_empty() || int_ok(p)) || !int_ok(parts[0]) {
                return None;
            }
            let i: i64 = parts[0].parse().ok()?;
            let r = if i > 0 {
                i - 1
            } else if i < 0 {
                count as i64 + i
            } else {
                return None;
            };
            (0..count as i64).contains(&r).then_some(r as u32)
        };
        match key {
            b"v" => {
                if rest.len() < 3 {
                    return None;
                }
                let mut p = [0f32; 3];
                for k in 0..3 {
                    let x: f32 = std::str::from_utf8(rest[k]).ok()?.parse().ok()?;
                    if !x.is_finite() || smoothtrace::limits::coordinate_problem(x as f64).is_some()
                    {
                        return None;
                    }
                    p[k] = x;
                }
                v.push(p);
            }
            b"f" | b"l" | b"p" => {
                let ids: Vec<u32> = rest
                    .iter()
                    .map(|w| index(w, v.len()))
                    .collect::<Option<_>>()?;
                match key {
                    b"f" if ids.len() >= 3 => {
                        for k in 2..ids.len() {
                            f.push([ids[0], ids[k - 1], ids[k]]);
                        }
                    }
                    b"l" if ids.len() >= 2 => {
                        l.extend(ids.windows(2).map(|w| [w[0], w[1]]));
                    }
                    b"p" if !ids.is_empty() => {}
                    _ => return None,
                }
            }
            _ => {}
        }
    }
    (!v.is_empty()).then_some((v, f, l))
}

// ---------------------------------------------------------------------------------
// Mutations.

#[derive(Clone, Debug)]
enum Mutation {
    Flip(Index, u8),
    Insert(Index, u8),
    Delete(Index, usize),
    Truncate(Index),
    DuplicateLine(Index),
    DropLine(Index),
    InsertToken(Index, &'static str),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<Index>(), any::<u8>()).prop_map(|(i, b)| Mutation::Flip(i, b)),
        (any::<Index>(), any::<u8>()).prop_map(|(i, b)| Mutation::Insert(i, b)),
        (any::<Index>(), 1usize..16).prop_map(|(i, n)| Mutation::Delete(i, n)),
        any::<Index>().prop_map(Mutation::Truncate),
        any::<Index>().prop_map(Mutation::DuplicateLine),
        any::<Index>().prop_map(Mutation::DropLine),
        (
            any::<Index>(),
            prop::sample::select(vec![
                " ",
                "\n",
                "-",
                "0",
                "1e39",
                "nan",
                "inf",
                "-1",
                "/",
                "#",
                "f ",
                "v ",
                "l ",
                "p ",
                "element ",
                "property ",
                "end_header\n",
                "4294967295",
                "solid",
                "\r\n",
                "\u{feff}",
                "\u{ff}",
            ])
        )
            .prop_map(|(i, t)| Mutation::InsertToken(i, t)),
    ]
}

fn apply(bytes: &mut Vec<u8>, m: &Mutation) {
    let at = |i: &Index, len: usize| if len == 0 { 0 } else { i.index(len + 1) };
    match m {
        Mutation::Flip(i, b) if !bytes.is_empty() => {
            let k = i.index(bytes.len());
            bytes[k] ^= b | 1;
        }
        Mutation::Insert(i, b) => {
            let k = at(i, bytes.len());
            bytes.insert(k, *b);
        }
        Mutation::Delete(i, n) if !bytes.is_empty() => {
            let k = i.index(bytes.len());
            let end = (k + n).min(bytes.len());
            bytes.drain(k..end);
        }
        Mutation::Truncate(i) => {
            let k = at(i, bytes.len());
            bytes.truncate(k);
        }
        Mutation::DuplicateLine(i) | Mutation::DropLine(i) => {
            let mut lines: Vec<Vec<u8>> =
                bytes.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
            let k = i.index(lines.len());
            if matches!(m, Mutation::DuplicateLine(_)) {
                let l = lines[k].clone();
                lines.insert(k, l);
            } else {
                lines.remove(k);
            }
            *bytes = lines.join(&b'\n');
        }
        Mutation::InsertToken(i, t) => {
            let k = at(i, bytes.len());
            bytes.splice(k..k, t.bytes());
        }
        _ => {}
    }
}

fn read(bytes: Vec<u8>, name: &str) -> Result<Mesh, MeshError> {
    Mesh::from_bytes(bytes, Path::new(name))
}

/// An accepted mutated OBJ equals the independent reading; a rejected one is rejected
/// by it too.
fn check_obj_against_naive(bytes: &[u8]) {
    let path = Path::new("fuzz.obj");
    let r = read(bytes.to_vec(), "fuzz.obj");
    check_outcome(&r, path);
    let naive = naive_obj(bytes);
    match (&r, &naive) {
        (Ok(m), Some((v, f, l))) => {
            assert_vertices(m, v);
            assert_eq!(&m.triangles, f);
            assert_eq!(&m.segments, l);
        }
        (Err(_), None) => {}
        (Ok(_), None) => panic!(
            "reader accepted what the independent reading rejects:\n{}",
            String::from_utf8_lossy(bytes)
        ),
        (Err(e), Some(_)) => panic!(
            "reader rejected ({e}) what the independent reading accepts:\n{}",
            String::from_utf8_lossy(bytes)
        ),
    }
}

// ---------------------------------------------------------------------------------
// Seeds from the real files (small slices), when data/ is present.

/// The first `n` vertices of an OBJ and the faces that use only them.
fn obj_slice(name: &str, n: usize) -> Option<Vec<u8>> {
    let path = common::data_file(name)?;
    let text = std::fs::read_to_string(path).ok()?;
    let mut out = String::new();
    let mut v = 0;
    for line in text.lines() {
        if line.starts_with("v ") {
            if v < n {
                out += line;
                out.push('\n');
            }
            v += 1;
        } else if line.starts_with("f ") {
            let ok = line.split_whitespace().skip(1).all(|t| {
                t.split('/')
                    .next()
                    .and_then(|i| i.parse::<usize>().ok())
                    .is_some_and(|i| i >= 1 && i <= n.min(v))
            });
            if ok {
                out += line;
                out.push('\n');
            }
        }
    }
    Some(out.into_bytes())
}

/// The header and the first `n` vertices of a binary PLY of `x y z` floats.
fn ply_slice(name: &str, n: usize) -> Option<Vec<u8>> {
    let path = common::data_file(name)?;
    let bytes = std::fs::read(path).ok()?;
    let end = bytes.windows(11).position(|w| w == b"end_header\n")? + 11;
    let header = String::from_utf8(bytes[..end].to_vec()).ok()?;
    if !header.contains("element vertex") || header.matches("property").count() != 3 {
        return None;
    }
    let header: String = header
        .lines()
        .map(|l| {
            if l.starts_with("element vertex") {
                format!("element vertex {n}\n")
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let mut out = header.into_bytes();
    out.extend(&bytes[end..end + 12 * n]);
    Some(out)
}

/// The seed slices, read once.
fn seeds() -> &'static [(String, Vec<u8>)] {
    static SEEDS: std::sync::OnceLock<Vec<(String, Vec<u8>)>> = std::sync::OnceLock::new();
    SEEDS.get_or_init(read_seeds)
}

fn read_seeds() -> Vec<(String, Vec<u8>)> {
    let mut s = Vec::new();
    for name in ["bunny-7k.obj", "cow.obj", "teapot.obj"] {
        if let Some(b) = obj_slice(name, 60) {
            s.push((name.to_string(), b));
        }
    }
    if let Some(b) = ply_slice("igea-points-134k.ply", 40) {
        s.push(("igea.ply".into(), b));
    }
    s
}

#[test]
fn seed_slices_read_like_their_source() {
    let seeds = seeds();
    if seeds.is_empty() {
        eprintln!("skipping: data/ is absent (see README), the generated inputs still run");
        return;
    }
    for (name, bytes) in seeds {
        if name.ends_with(".obj") {
            check_obj_against_naive(bytes);
        } else {
            let m = read(bytes.clone(), name).unwrap();
            // Brute force: the floats after the header.
            let end = bytes
                .windows(11)
                .position(|w| w == b"end_header\n")
                .unwrap()
                + 11;
            let want: Vec<[f32; 3]> = bytes[end..]
                .chunks(12)
                .map(|c| [0, 4, 8].map(|k| f32::from_le_bytes(c[k..k + 4].try_into().unwrap())))
                .collect();
            assert_vertices(&m, &want);
        }
    }
}

// ---------------------------------------------------------------------------------
// Properties.

proptest! {
    #![proptest_config(config())]

    #[test]
    fn generated_meshes_read_back_exactly(g in gen_mesh(), style in 0u8..4) {
        let m = read(obj_text(&g, style), "g.obj").unwrap();
        assert_vertices(&m, &g.vertices);
        prop_assert_eq!(&m.triangles, &g.triangles);
        prop_assert_eq!(&m.segments, &g.segments);
        for enc in [PlyEnc::Ascii, PlyEnc::Le, PlyEnc::Be] {
            let m = read(ply_bytes(&g, enc), "g.ply").unwrap();
            assert_vertices(&m, &g.vertices);
            prop_assert_eq!(&m.triangles, &g.triangles);
        }
        if !g.triangles.is_empty() {
            for ascii in [true, false] {
                let m = read(stl_bytes(&g, ascii), "g.stl").unwrap();
                assert_stl_corners(&m, &g);
            }
        }
    }

    #[test]
    fn mutated_obj_is_an_error_or_its_independent_reading(
        g in gen_mesh(), style in 0u8..4, seed in any::<Index>(),
        muts in prop::collection::vec(mutation(), 1..5),
    ) {
        let seeds = seeds();
        let obj_seeds: Vec<&Vec<u8>> = seeds.iter().filter(|(n, _)| n.ends_with(".obj")).map(|(_, b)| b).collect();
        let mut bytes = if !obj_seeds.is_empty() && seed.index(3) == 0 {
            obj_seeds[seed.index(obj_seeds.len())].clone()
        } else {
            obj_text(&g, style)
        };
        for m in &muts {
            apply(&mut bytes, m);
        }
        check_obj_against_naive(&bytes);
    }

    #[test]
    fn mutated_ply_and_stl_never_panic(
        g in gen_mesh(), which in 0usize..6,
        muts in prop::collection::vec(mutation(), 1..5),
    ) {
        let (mut bytes, name) = match which {
            0 => (ply_bytes(&g, PlyEnc::Ascii), "m.ply"),
            1 => (ply_bytes(&g, PlyEnc::Le), "m.ply"),
            2 => (ply_bytes(&g, PlyEnc::Be), "m.ply"),
            3 => (stl_bytes(&g, true), "m.stl"),
            4 => (stl_bytes(&g, false), "m.stl"),
            _ => match seeds().iter().find(|(n, _)| n.ends_with(".ply")) {
                Some((_, b)) => (b.clone(), "m.ply"),
                None => (ply_bytes(&g, PlyEnc::Le), "m.ply"),
            },
        };
        for m in &muts {
            apply(&mut bytes, m);
        }
        let r = read(bytes, name);
        check_outcome(&r, Path::new(name));
    }

    /// Flips inside the vertex block of a binary file keep the layout, so the result
    /// is known exactly: the brute-force decoding of the flipped floats, or an error
    /// when one of them is not finite or beyond the limit.
    #[test]
    fn flipped_binary_vertices_read_as_decoded(
        g in gen_mesh(), which in 0usize..3,
        flips in prop::collection::vec((any::<Index>(), 1u8..=255), 1..6),
    ) {
        let (mut bytes, name, start, stride, big) = match which {
            0 | 1 => {
                let enc = if which == 0 { PlyEnc::Le } else { PlyEnc::Be };
                let b = ply_bytes(&g, enc);
                let end = b.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
                (b, "f.ply", end, 12, which == 1)
            }
            _ => (stl_bytes(&g, false), "f.stl", 84, 50, false),
        };
        let blocks = if which == 2 { g.triangles.len() } else { g.vertices.len() };
        prop_assume!(blocks > 0);
        for (i, x) in &flips {
            // A byte of a coordinate (STL: of the 9 corner floats after the normal).
            let k = i.index(blocks * if which == 2 { 36 } else { 12 });
            let off = if which == 2 { start + (k / 36) * stride + 12 + k % 36 } else { start + k };
            bytes[off] ^= x;
        }
        let decode = |c: &[u8]| -> f32 {
            let a: [u8; 4] = c.try_into().unwrap();
            if big { f32::from_be_bytes(a) } else { f32::from_le_bytes(a) }
        };
        let floats: Vec<f32> = if which == 2 {
            (0..blocks)
                .flat_map(|t| (0..9).map(move |j| (t, j)))
                .map(|(t, j)| decode(&bytes[start + t * stride + 12 + 4 * j..][..4]))
                .collect()
        } else {
            (0..blocks * 3).map(|j| decode(&bytes[start + 4 * j..][..4])).collect()
        };
        let bad = floats.iter().any(|&x| !x.is_finite() || smoothtrace::limits::coordinate_problem(x as f64).is_some());
        let r = read(bytes.clone(), name);
        check_outcome(&r, Path::new(name));
        match r {
            Err(e) => prop_assert!(bad, "rejected valid floats: {e}"),
            Ok(m) => {
                prop_assert!(!bad, "accepted a bad coordinate");
                let want: Vec<[f32; 3]> = floats.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
                if which == 2 {
                    for (t, tri) in m.triangles.iter().enumerate() {
                        for k in 0..3 {
                            let got = m.vertices[tri[k] as usize];
                            prop_assert!((0..3).all(|c| same_f32(got[c], want[3 * t + k][c])));
                        }
                    }
                } else {
                    assert_vertices(&m, &want);
                }
            }
        }
    }

    #[test]
    fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..512), prefix in 0usize..6) {
        // Random tails behind each format's magic, so the parsers get past the first check.
        let head: &[u8] = [
            &b""[..], b"ply\nformat ascii 1.0\n", b"ply\nformat binary_little_endian 1.0\n",
            b"solid x\n", b"v 0 0 0\n", b"ply\nformat binary_big_endian 1.0\nelement vertex 2\n",
        ][prefix];
        for name in ["r.obj", "r.ply", "r.stl"] {
            let mut b = head.to_vec();
            b.extend(&bytes);
            check_outcome(&read(b, name), Path::new(name));
        }
    }

    /// The scene loader: mutated real scene files and random text give a result or an
    /// error, never a panic.
    #[test]
    fn mutated_scenes_never_panic(which in any::<Index>(), muts in prop::collection::vec(mutation(), 0..5)) {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
        let mut files: Vec<_> = std::fs::read_dir(&dir).unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        files.sort();
        let path = &files[which.index(files.len())];
        let mut bytes = std::fs::read(path).unwrap();
        for m in &muts {
            apply(&mut bytes, m);
        }
        let text = String::from_utf8_lossy(&bytes);
        let _ = smoothtrace::scene::Scene::from_str(&text, path);
    }
}

// ---------------------------------------------------------------------------------
// LAS/LAZ: mutated copies of the small files in `data/las/` (a LAS 1.2 file of 100
// points and a small LAZ), read through `Mesh::load` from a temporary file (the lidar
// reader streams from a file): no panic, and either an error naming the file or points
// meeting `check_outcome`. A tenth of the other properties' cases: each one writes and
// reads a file. (Corrupt and truncated real files are also in tests/las.rs.)

fn las_seed(name: &str) -> Option<Vec<u8>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data/las")
        .join(name);
    std::fs::read(path).ok()
}

fn fuzz_lidar(name: &str, ext: &str, muts: &[Mutation]) {
    let Some(mut bytes) = las_seed(name) else {
        return;
    };
    for m in muts {
        apply(&mut bytes, m);
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(format!("fuzzed.{ext}"));
    std::fs::write(&path, &bytes).unwrap();
    check_outcome(&smoothtrace::load::load_mesh(&path), &path);
}

#[test]
fn lidar_seeds_are_present_or_the_skip_says_why() {
    if las_seed("100-points.las").is_none() {
        eprintln!(
            "skipping the LAS/LAZ fuzzing: data/las/ is absent (link ../shared/data to data)"
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: (cases() / 10).max(20), ..config() })]

    #[test]
    fn mutated_las_never_panics(muts in proptest::collection::vec(mutation(), 1..4)) {
        fuzz_lidar("100-points.las", "las", &muts);
    }

    // Found by this property on its first run: a mutated LAZ chunk count made the laz
    // decoder reserve 44 GB and abort; `las::layout_check` now bounds the header's and
    // the chunk table's counts by the file size before the decoder sees them.
    #[test]
    fn mutated_laz_never_panics(muts in proptest::collection::vec(mutation(), 1..4)) {
        fuzz_lidar("simple.laz", "laz", &muts);
    }
}

// ---------------------------------------------------------------------------------
// Vertex colours (`color_by = "vertex"`): mutated copies of the coloured torus PLY and
// of a coloured OBJ, read with `Mesh::load_with_vertex_colours` from a temporary file:
// no panic, and either an error naming the file or one colour per vertex, each channel
// in linear 0..=1.

fn fuzz_coloured(seed: &[u8], ext: &str, muts: &[Mutation]) {
    let mut bytes = seed.to_vec();
    for m in muts {
        apply(&mut bytes, m);
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(format!("fuzzed.{ext}"));
    std::fs::write(&path, &bytes).unwrap();
    let r = Mesh::load_with_vertex_colours(&path);
    match r {
        Ok((mesh, colours)) => {
            if let Some(c) = colours {
                assert_eq!(c.len(), mesh.vertices.len());
                assert!(c.iter().flatten().all(|v| (0.0..=1.0).contains(v)));
            }
            check_outcome(&Ok(mesh), &path);
        }
        Err(e) => check_outcome(&Err(e), &path),
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: (cases() / 10).max(20), ..config() })]

    #[test]
    fn mutated_coloured_files_never_panic(obj in any::<bool>(), muts in proptest::collection::vec(mutation(), 1..4)) {
        if obj {
            let seed = b"v 0 0 0 1 0 0\nv 1 0 0 0 0.5 1\nv 0 1 0 0.2 0.2 0.2\nf 1 2 3\n";
            fuzz_coloured(seed, "obj", &muts);
        } else {
            let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/colour_torus.ply");
            fuzz_coloured(&std::fs::read(path).unwrap(), "ply", &muts);
        }
    }
}
