//! Colour from the data for any object (issue 11 item 6): per-vertex colours read from
//! PLY and OBJ, `color_by = "vertex" | "height" | "normal"`, the smooth colour field at
//! and between coloured points, and the errors for bad colour input. Expected colours are
//! computed here from the written values (sRGB decoded in f64 by the formula of
//! IEC 61966-2-1), never copied from the reader's output. Tolerance for colours: 1e-6
//! (f32 linear colours; the softmax weights of far points are below exp(-60)).
//! The golden image of a colour-by-vertex scene is in tests/golden.rs.

mod common;

use glam::DVec3;
use smoothtrace::colour::SetColours;
use smoothtrace::eval::EvalParams;
use smoothtrace::eval::colour::colour_at;
use smoothtrace::mesh::Mesh;
use smoothtrace::primitives::{AnySet, PrimitiveKind};
use smoothtrace::render::Hit;
use smoothtrace::render::albedo::{shade_hit, tint};
use smoothtrace::render::build::build_scene;
use smoothtrace::rgb::{Colormap, to_srgb8};
use smoothtrace::scene::Scene;
use std::path::{Path, PathBuf};

const TOL: f32 = 1e-6;

/// sRGB fraction to linear, written out independently of the library.
fn linear(s: f64) -> f32 {
    (if s <= 0.04045 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }) as f32
}

fn close(a: [f32; 3], b: [f32; 3]) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= TOL)
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn ascii_ply(props: &str, rows: &[&str]) -> Vec<u8> {
    let mut s = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\n{props}end_header\n",
        rows.len()
    );
    for r in rows {
        s.push_str(r);
        s.push('\n');
    }
    s.into_bytes()
}

#[test]
fn ply_and_obj_colours_read_as_written() {
    let dir = tempfile::tempdir().unwrap();
    let uchar = "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    // (file name, bytes, the two vertices' colours as written, as fractions)
    type Case = (&'static str, Vec<u8>, [[f64; 3]; 2]);
    let cases: Vec<Case> = vec![
        (
            "uchar.ply",
            ascii_ply(uchar, &["0 0 0 255 0 128", "1 0 0 10 200 3"]),
            [
                [1.0, 0.0, 128.0 / 255.0],
                [10.0 / 255.0, 200.0 / 255.0, 3.0 / 255.0],
            ],
        ),
        (
            "float.ply",
            ascii_ply(
                "property float diffuse_red\nproperty float diffuse_green\nproperty float diffuse_blue\n",
                &["0 0 0 0.25 0.5 1", "1 0 0 0 0.01 0.99"],
            ),
            [[0.25, 0.5, 1.0], [0.0, 0.01, 0.99]],
        ),
        (
            "ushort.ply",
            ascii_ply(
                "property ushort r\nproperty ushort g\nproperty ushort b\nproperty uchar alpha\n",
                &["0 0 0 65535 0 32768 7", "1 0 0 1 2 3 7"],
            ),
            [
                [1.0, 0.0, 32768.0 / 65535.0],
                [1.0 / 65535.0, 2.0 / 65535.0, 3.0 / 65535.0],
            ],
        ),
        (
            "double.ply",
            ascii_ply(
                "property double red\nproperty double green\nproperty double blue\n",
                &["0 0 0 0.1 0.2 0.3", "1 0 0 0.4 0.5 0.6"],
            ),
            [[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]],
        ),
        (
            "rgb.obj",
            b"v 0 0 0 0.1 0.2 0.3\nv 1 0 0 1 0 0.5 # a comment\nf 1 2 1\n".to_vec(),
            [[0.1, 0.2, 0.3], [1.0, 0.0, 0.5]],
        ),
    ];
    for (name, bytes, want) in cases {
        let path = write(dir.path(), name, &bytes);
        let (mesh, colours) = Mesh::load_with_vertex_colours(&path).unwrap();
        let colours = colours.unwrap_or_else(|| panic!("{name}: no colours"));
        assert_eq!(mesh.vertices.len(), 2, "{name}");
        assert_eq!(mesh.vertices[1], glam::Vec3::X, "{name}");
        for (got, want) in colours.iter().zip(want) {
            let want = want.map(linear);
            assert!(close(*got, want), "{name}: {got:?} vs {want:?}");
        }
        // The plain loader reads the same geometry and ignores the colours.
        assert_eq!(Mesh::load(&path).unwrap().vertices, mesh.vertices);
    }
    // Binary PLY (the golden scene's torus): uchar colours, 648 vertices.
    let torus = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/colour_torus.ply");
    let (mesh, colours) = Mesh::load_with_vertex_colours(&torus).unwrap();
    let colours = colours.unwrap();
    assert_eq!((mesh.vertices.len(), mesh.triangles.len()), (648, 1296));
    // scripts/colour_torus.py: vertex 0 is in the first band, (230, 57, 70).
    let first = [230.0, 57.0, 70.0].map(|c: f64| linear(c / 255.0));
    assert!(close(colours[0], first), "{:?}", colours[0]);
    // Files without colours, or an STL, give none.
    let plain = write(dir.path(), "plain.obj", b"v 0 0 0\nv 1 0 0 1\n");
    assert!(Mesh::load_with_vertex_colours(&plain).unwrap().1.is_none());
}

/// Two coloured points read from a PLY: halfway between them the colour is their mean,
/// at each point it is that point's own colour (through the library's colour field).
#[test]
fn two_coloured_points_from_a_file_blend_halfway() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "two.ply",
        &ascii_ply(
            "property uchar red\nproperty uchar green\nproperty uchar blue\n",
            &["0 0 0 255 0 0", "2 0 0 0 64 255"],
        ),
    );
    let (mesh, colours) = Mesh::load_with_vertex_colours(&path).unwrap();
    let colours = colours.unwrap();
    let set = AnySet::build(&mesh, PrimitiveKind::Points).unwrap();
    let cols = SetColours::build(&set, &mesh, &colours);
    let a = [1.0, 0.0, 0.0].map(linear);
    let b = [0.0, 64.0 / 255.0, 1.0].map(linear);
    for beta in [0.0, 0.5] {
        let p = EvalParams::new(30.0, 30.0, beta);
        let at = |x: DVec3| colour_at(&[&set], &[&cols], x, &p).unwrap();
        // Halfway, on and off the segment: equal distances, equal weights.
        for y in [0.0, 0.7] {
            let mid = at(DVec3::new(1.0, y, 0.0));
            let mean: [f32; 3] = std::array::from_fn(|k| 0.5 * (a[k] + b[k]));
            assert!(close(mid, mean), "beta {beta}, y {y}: {mid:?} vs {mean:?}");
        }
        // At each point the other's weight is exp(-60) of its own.
        assert!(close(at(DVec3::ZERO), a), "{:?}", at(DVec3::ZERO));
        assert!(close(at(DVec3::X * 2.0), b), "{:?}", at(DVec3::X * 2.0));
    }
}

fn expect_mesh_error(dir: &Path, name: &str, bytes: &[u8], needles: &[&str]) {
    let path = write(dir, name, bytes);
    let e = Mesh::load_with_vertex_colours(&path)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(name),
        "{name}: error does not name the file: {e}"
    );
    for n in needles {
        assert!(e.contains(n), "{name}: message lacks `{n}`: {e}");
    }
}

#[test]
fn bad_colour_properties_are_errors_naming_the_property() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let rgb = |t: &str| format!("property {t} red\nproperty {t} green\nproperty {t} blue\n");
    expect_mesh_error(
        d,
        "short.ply",
        &ascii_ply(&rgb("short"), &["0 0 0 1 2 3"]),
        &["'red'", "'short'", "uchar"],
    );
    expect_mesh_error(
        d,
        "int.ply",
        &ascii_ply(&rgb("int"), &["0 0 0 1 2 3"]),
        &["'red'", "'int'"],
    );
    expect_mesh_error(
        d,
        "list.ply",
        &ascii_ply(
            "property list uchar uchar red\nproperty uchar green\nproperty uchar blue\n",
            &["0 0 0 1 5 2 3"],
        ),
        &["'red'", "list"],
    );
    expect_mesh_error(
        d,
        "partial.ply",
        &ascii_ply("property uchar red\nproperty uchar green\n", &["0 0 0 1 2"]),
        &["\"red\"", "\"blue\""],
    );
    expect_mesh_error(
        d,
        "range.ply",
        &ascii_ply(&rgb("float"), &["0 0 0 0 0 0", "1 0 0 0.5 1.5 0"]),
        &["vertex 1", "'green'", "1.5", "0..1"],
    );
    // NaN needs a binary file (ASCII PLY has no spelling for it).
    let mut nan = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n\
         property float y\nproperty float z\n{}end_header\n",
        rgb("float")
    )
    .into_bytes();
    for v in [0.0, 0.0, 0.0, 0.5, f32::NAN, 0.5f32] {
        nan.extend(v.to_le_bytes());
    }
    expect_mesh_error(d, "nan.ply", &nan, &["vertex 0", "'green'", "NaN", "0..1"]);
    expect_mesh_error(
        d,
        "mixed.obj",
        b"v 0 0 0 1 0 0\nv 1 0 0\n",
        &["mixed.obj:2:", "line 1", "every vertex or none"],
    );
    expect_mesh_error(
        d,
        "range.obj",
        b"v 0 0 0 0 0 0\nv 1 0 0 0 255 0\n",
        &["range.obj:2:", "(g)", "255", "0..1"],
    );
    expect_mesh_error(
        d,
        "word.obj",
        b"v 0 0 0 red 0 0\n",
        &["word.obj:1:", "'red'"],
    );
    // Without color_by = "vertex" the colour properties are ignored, as before.
    let path = write(
        d,
        "short_plain.ply",
        &ascii_ply(&rgb("short"), &["0 0 0 1 2 3"]),
    );
    assert_eq!(Mesh::load(&path).unwrap().vertices.len(), 1);
}

/// A scene of one mesh object with extra `object` lines.
fn scene(mesh: &str, object: &str) -> String {
    format!(
        "[camera]\norigin = [0, 0, 5]\ntarget = [0, 0, 0]\n\n[image]\nwidth = 32\nheight = 24\n\n\
         [[object]]\n{mesh}\nprimitives = \"points\"\nalpha = 20.0\n{object}"
    )
}

fn scene_error(text: &str) -> String {
    match Scene::from_str(text, Path::new("c.toml")) {
        Err(e) => e.to_string(),
        Ok(s) => match build_scene(&s) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("accepted: {text}"),
        },
    }
}

#[test]
fn bad_colour_keys_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let plain = write(dir.path(), "plain.ply", &ascii_ply("", &["0 0 0", "1 0 0"]));
    let mesh = format!("mesh = {:?}", plain.to_str().unwrap());
    let generator = "generator = { kind = \"sphere_points\" }";
    for (geometry, lines, needles) in [
        (
            &mesh[..],
            "color_by = \"rainbow\"",
            &[
                "c.toml:13:",
                "object[0].color_by",
                "\"height\"",
                "\"rgb\"",
                "rainbow",
            ][..],
        ),
        (
            &mesh,
            "color_by = \"height\"\ncolormap = \"jet\"",
            &[
                "c.toml:14:",
                "object[0].colormap",
                "unknown colormap",
                "viridis",
                "turbo",
            ],
        ),
        (
            &mesh,
            "color_by = \"vertex\"\ncolormap = \"magma\"",
            &["c.toml:14:", "object[0].colormap", "\"height\""],
        ),
        (
            &mesh,
            "colormap = \"magma\"",
            &["c.toml:13:", "object[0].colormap", "color_by"],
        ),
        (
            generator,
            "color_by = \"vertex\"",
            &["c.toml:13:", "object[0].color_by", "generated shape"],
        ),
        (
            "mesh = \"x.laz\"",
            "color_by = \"vertex\"",
            &["c.toml:13:", "object[0].color_by", "\"rgb\""],
        ),
        (
            &mesh,
            "color_by = \"vertex\"",
            &[
                "object[0].color_by",
                "plain.ply",
                "no vertex colours",
                "red, green, blue",
            ],
        ),
    ] {
        let e = scene_error(&scene(geometry, lines));
        for n in needles {
            assert!(e.contains(n), "{lines}: message lacks `{n}`: {e}");
        }
    }
}

/// `height` colours each vertex by its `y` after the transform, on the colormap from the
/// lowest to the highest vertex; `normal` colours a hit by its normal.
#[test]
fn height_and_normal_colourings() {
    let dir = tempfile::tempdir().unwrap();
    // z runs 0, 1, 4 in the file; rotating by -90 degrees about x takes z to +y.
    let path = write(
        dir.path(),
        "pts.ply",
        &ascii_ply("", &["0 0 0", "1 0 1", "2 0 4"]),
    );
    let text = scene(
        &format!("mesh = {:?}", path.to_str().unwrap()),
        "color_by = \"height\"\ncolormap = \"magma\"\n[object.transform]\nrotate = [-90.0, 0.0, 0.0]\n",
    );
    let s = Scene::from_str(&text, Path::new("c.toml")).unwrap();
    let built = build_scene(&s).unwrap();
    let obj = &built.objects[0];
    let cols = &obj.colours.as_ref().unwrap().sets[0];
    let set = &obj.sets[0];
    for (k, &i) in set.bvh().order.iter().enumerate() {
        let t = [0.0, 0.25, 1.0][i as usize];
        assert_eq!(
            cols.prims[k],
            Colormap::Magma.map(t, 0.0, 1.0),
            "vertex {i}"
        );
    }
    // At the highest point the field gives the top of the colormap.
    let top = DVec3::new(2.0, 4.0, 0.0);
    let got = colour_at(&obj.set_refs(), &[cols], top, &obj.params).unwrap();
    assert!(close(got, Colormap::Magma.map(1.0, 0.0, 1.0)), "{got:?}");

    let text = scene(
        "generator = { kind = \"sphere_points\" }",
        "color_by = \"normal\"",
    );
    let s = Scene::from_str(&text, Path::new("c.toml")).unwrap();
    let built = build_scene(&s).unwrap();
    let shaded = to_srgb8([0.8; 3]);
    for n in [DVec3::X, -DVec3::Y, DVec3::new(0.0, 0.6, 0.8)] {
        let hit = Hit {
            t: 1.0,
            point: DVec3::ZERO,
            normal: n,
            object: 0,
        };
        let want = tint(shaded, (0.5 + 0.5 * n).as_vec3().to_array());
        assert_eq!(shade_hit(&built.objects, &hit, shaded), want, "{n}");
    }
    // Without color_by the MatCap colour is left alone.
    let s = Scene::from_str(
        &scene("generator = { kind = \"sphere_points\" }", ""),
        Path::new("c.toml"),
    )
    .unwrap();
    let built = build_scene(&s).unwrap();
    let hit = Hit {
        t: 1.0,
        point: DVec3::ZERO,
        normal: DVec3::X,
        object: 0,
    };
    assert_eq!(shade_hit(&built.objects, &hit, shaded), shaded);
}

/// The command line: bad colour input exits with status 2 and a message naming the
/// field or property; a good one renders.
#[test]
fn render_exits_2_on_bad_colour_input() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write(d, "plain.obj", b"v 0 0 0\nv 1 0 0\n");
    write(d, "rgb.obj", b"v 0 0 0 1 0 0\nv 1 0 0 0 0 1\n");
    write(
        d,
        "short.ply",
        &ascii_ply(
            "property short red\nproperty short green\nproperty short blue\n",
            &["0 0 0 1 2 3"],
        ),
    );
    let bin = || std::process::Command::new(env!("CARGO_BIN_EXE_smoothtrace"));
    for (mesh, extra, code, needles) in [
        (
            "plain.obj",
            "color_by = \"vertex\"",
            2,
            &["object[0].color_by", "no vertex colours"][..],
        ),
        (
            "plain.obj",
            "color_by = \"hue\"",
            2,
            &["s.toml:11:", "object[0].color_by"],
        ),
        (
            "plain.obj",
            "color_by = \"height\"\ncolormap = \"rainbow\"",
            2,
            &["s.toml:12:", "object[0].colormap"],
        ),
        (
            "short.ply",
            "color_by = \"vertex\"",
            2,
            &["short.ply", "'red'", "'short'"],
        ),
        ("rgb.obj", "color_by = \"vertex\"", 0, &[]),
    ] {
        let text = format!(
            "[camera]\norigin = [0.5, 0, 3]\ntarget = [0.5, 0, 0]\n[image]\nwidth = 16\n\
             height = 12\n[[object]]\nmesh = \"{mesh}\"\nprimitives = \"points\"\n\
             alpha = 20.0\n{extra}\n"
        );
        write(d, "s.toml", text.as_bytes());
        let out = common::run_cli(bin(), &["render", "s.toml", "-o", "o.png"], d, None);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(code), "{extra}: {err}");
        for n in needles {
            assert!(err.contains(n), "{extra}: message lacks `{n}`: {err}");
        }
    }
    // The good render has the two colours: red on the left point, blue on the right.
    let img = image::open(d.join("o.png")).unwrap().to_rgb8();
    let (mut red, mut blue) = (0, 0);
    for p in img.pixels() {
        red += (p[0] > 2 * p[2].max(8)) as usize;
        blue += (p[2] > 2 * p[0].max(8)) as usize;
    }
    assert!(red > 0 && blue > 0, "red pixels {red}, blue pixels {blue}");
}
