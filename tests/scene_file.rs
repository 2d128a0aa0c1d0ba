//! Scene files: parsing, defaults, path resolution, and every error with its location.

use glam::DVec3;
use smoothtrace::primitives::PrimitiveKind;
use smoothtrace::procedural::Generator;
use smoothtrace::scene::{
    AlphaSpec, Epsilon, Evaluation, Geometry, Location, MatCapSpec, Scene, SceneError, Transform,
};
use std::path::{Path, PathBuf};

/// Scene text used by most error tests; the path is only named in messages.
const PATH: &str = "scenes/x.toml";

fn parse(text: &str) -> Result<Scene, SceneError> {
    Scene::from_str(text, Path::new(PATH))
}

/// Parses `text`, expects an error, returns its message.
fn error(text: &str) -> String {
    match parse(text) {
        Ok(scene) => panic!("expected an error, got {scene:#?}"),
        Err(e) => e.to_string(),
    }
}

/// Asserts that `message` contains every one of `parts`.
#[track_caller]
fn assert_mentions(message: &str, parts: &[&str]) {
    for p in parts {
        assert!(
            message.contains(p),
            "message {message:?} should contain {p:?}"
        );
    }
}

const CAMERA: &str = "[camera]\norigin = [0.0, 1.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\n";

/// A valid scene: camera (lines 1-3) and a generator object (lines 4-7).
fn minimal() -> String {
    format!(
        "{CAMERA}[[object]]\ngenerator = {{ kind = \"torus\" }}\nprimitives = \"triangles\"\nalpha = 300\n"
    )
}

#[test]
fn full_example_parses_into_expected_values() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("scenes")).unwrap();
    std::fs::create_dir(dir.path().join("data")).unwrap();
    std::fs::write(dir.path().join("data/bunny.obj"), "v 0 0 0\n").unwrap();
    smoothtrace::matcap::save_builtin_png("blue", &dir.path().join("scenes/mine.png")).unwrap();
    let text = r##"
# The bunny and a hex torus.
[camera]
origin = [0.0, 1.0, 5.0]
target = [0, 0.5, 0]
up = [0.0, 0.0, 1.0]
fov = 40

[image]
width = 1920
height = 1080
background = "#203040"

[render]
beta = 0.25
epsilon = 1e-3
max_steps = 500
evaluation = "naive"
threads = 2
certified_hits = true

[[object]]
mesh = "../data/bunny.obj"
primitives = "triangles"
alpha = 100.0
max_alpha = 200.0
matcap = "mine.png"
[object.transform]
scale = 10.0
rotate = [0.0, 90.0, 0.0]
translate = [0.5, 0.0, -1]

[[object]]
generator = { kind = "hex_torus", major_radius = 2.0 }
primitives = ["edges", "points"]
alpha_rel = 250.0
max_alpha_rel = 1000
matcap = "normal"
transform = { scale = [1, 2, 3] }
"##;
    let path = dir.path().join("scenes/example.toml");
    std::fs::write(&path, text).unwrap();
    let s = Scene::load(&path).unwrap();

    assert_eq!(s.path, path);
    assert_eq!(s.camera.origin, DVec3::new(0.0, 1.0, 5.0));
    assert_eq!(s.camera.target, DVec3::new(0.0, 0.5, 0.0));
    assert_eq!(s.camera.up, DVec3::Z);
    assert_eq!(s.camera.fov, 40.0);
    assert_eq!((s.image.width, s.image.height), (1920, 1080));
    assert_eq!(s.image.background, [0x20, 0x30, 0x40]);
    assert_eq!(s.render.beta, 0.25);
    assert_eq!(s.render.epsilon, Epsilon::Absolute(1e-3));
    assert_eq!(s.render.max_steps, 500);
    assert_eq!(s.render.evaluation, Evaluation::Naive);
    assert_eq!(s.render.threads, 2);
    assert!(s.render.certified_hits);
    assert_eq!(s.objects.len(), 2);

    let bunny = &s.objects[0];
    let scenes = dir.path().join("scenes");
    assert_eq!(
        bunny.geometry,
        Geometry::Mesh(scenes.join("../data/bunny.obj"))
    );
    assert_eq!(bunny.primitives, vec![PrimitiveKind::Triangles]);
    assert_eq!(bunny.alpha, AlphaSpec::Absolute(100.0));
    assert_eq!(bunny.max_alpha, Some(AlphaSpec::Absolute(200.0)));
    assert_eq!(bunny.matcap, MatCapSpec::File(scenes.join("mine.png")));
    assert_eq!(
        bunny.transform,
        Transform {
            scale: DVec3::splat(10.0),
            rotate: DVec3::new(0.0, 90.0, 0.0),
            translate: DVec3::new(0.5, 0.0, -1.0),
        }
    );
    assert_eq!(bunny.transform.uniform_scale(), Some(10.0));

    let torus = &s.objects[1];
    assert_eq!(
        torus.geometry,
        Geometry::Generator(Generator::HexTorus {
            major_radius: 2.0,
            minor_radius: 0.5
        })
    );
    assert_eq!(
        torus.primitives,
        vec![PrimitiveKind::Edges, PrimitiveKind::Points]
    );
    assert_eq!(torus.alpha, AlphaSpec::Relative(250.0));
    assert_eq!(torus.max_alpha, Some(AlphaSpec::Relative(1000.0)));
    assert_eq!(torus.matcap, MatCapSpec::Normal);
    assert_eq!(torus.transform.scale, DVec3::new(1.0, 2.0, 3.0));
    assert_eq!(torus.transform.uniform_scale(), None);

    // The camera it describes.
    let cam = s.camera().unwrap();
    assert_eq!((cam.width(), cam.height()), (1920, 1080));
}

#[test]
fn defaults() {
    let s = parse(&minimal()).unwrap();
    assert_eq!(s.camera.up, DVec3::Y);
    assert_eq!(s.camera.fov, 53.13);
    assert_eq!((s.image.width, s.image.height), (960, 540));
    assert_eq!(s.image.background, [255, 255, 255]);
    assert_eq!(s.render.beta, 0.5);
    assert_eq!(s.render.epsilon, Epsilon::Relative(4e-4));
    assert_eq!(s.render.max_steps, 1000);
    assert_eq!(s.render.evaluation, Evaluation::Stable);
    assert_eq!(s.render.threads, 0);
    assert!(!s.render.certified_hits);
    let o = &s.objects[0];
    assert_eq!(
        o.geometry,
        Geometry::Generator(Generator::Torus {
            major_radius: 1.0,
            minor_radius: 0.25,
            major_segments: 32,
            minor_segments: 18
        })
    );
    assert_eq!(o.alpha, AlphaSpec::Absolute(300.0));
    assert_eq!(o.max_alpha, None);
    assert_eq!(o.max_alpha_or_alpha(), AlphaSpec::Absolute(300.0));
    assert_eq!(o.transform, Transform::IDENTITY);
    assert_eq!(o.matcap, MatCapSpec::Builtin("clay".into()));
}

#[test]
fn resolved_parameters() {
    assert_eq!(AlphaSpec::Absolute(5.0).resolve(2.0), Some(5.0));
    assert_eq!(AlphaSpec::Relative(250.0).resolve(2.5), Some(100.0));
    assert_eq!(AlphaSpec::Relative(250.0).resolve(0.0), None);
    assert_eq!(Epsilon::Relative(4e-4).resolve(2.0), 8e-4);
    assert_eq!(Epsilon::Absolute(1e-3).resolve(2.0), 1e-3);
}

#[test]
fn primitives_as_string_or_list() {
    let with = |p: &str| {
        let text = minimal().replace("primitives = \"triangles\"", &format!("primitives = {p}"));
        parse(&text).map(|s| s.objects[0].primitives.clone())
    };
    use PrimitiveKind::*;
    assert_eq!(with("\"edges\"").unwrap(), vec![Edges]);
    assert_eq!(with("[\"points\"]").unwrap(), vec![Points]);
    assert_eq!(
        with("[\"triangles\", \"edges\", \"points\"]").unwrap(),
        vec![Triangles, Edges, Points]
    );

    let msg = with("\"triangle\"").unwrap_err().to_string();
    assert_mentions(
        &msg,
        &[
            PATH,
            ":6:14:",
            "object[0].primitives",
            "\"triangle\"",
            "triangles",
        ],
    );
    let msg = with("[]").unwrap_err().to_string();
    assert_mentions(&msg, &[":6:14:", "object[0].primitives is empty"]);
    let msg = with("[\"edges\", \"edges\"]").unwrap_err().to_string();
    assert_mentions(&msg, &[":6:14:", "\"edges\" twice"]);
    let msg = with("3").unwrap_err().to_string();
    assert_mentions(
        &msg,
        &[":6:14:", "object[0].primitives must be a primitive kind"],
    );

    let text = format!("{CAMERA}[[object]]\ngenerator = {{ kind = \"torus\" }}\nalpha = 1\n");
    assert_mentions(
        &error(&text),
        &[":4:1:", "missing field `primitives` in [[object]]"],
    );
}

#[test]
fn generator_objects() {
    let text = format!(
        "{CAMERA}[[object]]\ngenerator = {{ kind = \"hex_torus\" }}\nprimitives = \"edges\"\nalpha = 2\nmax_alpha = 16\n\
         [[object]]\nprimitives = \"points\"\nalpha = 1\n[object.generator]\nkind = \"sphere_points\"\ncount = 50\n"
    );
    let s = parse(&text).unwrap();
    assert_eq!(
        s.objects[0].geometry,
        Geometry::Generator(Generator::HexTorus {
            major_radius: 1.0,
            minor_radius: 0.5
        })
    );
    assert_eq!(s.objects[0].max_alpha, Some(AlphaSpec::Absolute(16.0)));
    assert_eq!(
        s.objects[1].geometry,
        Geometry::Generator(Generator::SpherePoints {
            radius: 1.0,
            count: 50
        })
    );

    let bad_kind = minimal().replace("\"torus\"", "\"donut\"");
    assert_mentions(
        &error(&bad_kind),
        &[":5:22:", "unknown variant `donut`", "hex_torus"],
    );
    let no_kind = minimal().replace("kind = \"torus\"", "radius = 1");
    assert_mentions(
        &error(&no_kind),
        &[":5:13:", "missing field `kind` in `generator`"],
    );
}

#[test]
fn relative_mesh_path_resolved_against_scene_dir() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("a/b");
    std::fs::create_dir_all(&sub).unwrap();
    std::fs::write(sub.join("m.obj"), "v 0 0 0\n").unwrap();
    std::fs::write(dir.path().join("a/up.ply"), "").unwrap();
    let text = format!(
        "{CAMERA}[[object]]\nmesh = \"m.obj\"\nprimitives = \"points\"\nalpha = 1\n\
         [[object]]\nmesh = \"../up.ply\"\nprimitives = \"points\"\nalpha = 1\n"
    );
    let path = sub.join("scene.toml");
    std::fs::write(&path, &text).unwrap();
    let s = Scene::load(&path).unwrap();
    assert_eq!(s.objects[0].geometry, Geometry::Mesh(sub.join("m.obj")));
    assert_eq!(s.objects[1].geometry, Geometry::Mesh(sub.join("../up.ply")));
    assert_eq!(s.base_dir(), sub);

    // Relative to the scene file, not to the working directory: the same text at
    // another place does not find the mesh.
    let elsewhere = dir.path().join("scene.toml");
    let msg = Scene::from_str(&text, &elsewhere).unwrap_err().to_string();
    assert_mentions(
        &msg,
        &[
            "scene.toml:5:8:",
            "object[0].mesh",
            "m.obj",
            "does not exist",
        ],
    );

    // An absolute path stays as it is.
    let abs = sub.join("m.obj");
    let text = text.replace("\"m.obj\"", &format!("{:?}", abs.to_str().unwrap()));
    let s = Scene::from_str(&text, &elsewhere.with_file_name("x/scene.toml")).unwrap_err();
    // (the second object is still relative and missing there)
    assert_mentions(&s.to_string(), &["object[1].mesh", "up.ply"]);
}

#[test]
fn missing_mesh_and_matcap_files() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.toml");
    let text =
        format!("{CAMERA}[[object]]\nmesh = \"nope.obj\"\nprimitives = \"edges\"\nalpha = 1\n");
    let e = Scene::from_str(&text, &path).unwrap_err();
    assert_eq!(e.location(), Some(Location { line: 5, column: 8 }));
    assert_mentions(
        &e.to_string(),
        &[
            "s.toml:5:8:",
            "object[0].mesh",
            "nope.obj",
            "does not exist",
        ],
    );

    std::fs::create_dir(dir.path().join("dir.obj")).unwrap();
    let e = Scene::from_str(&text.replace("nope", "dir"), &path).unwrap_err();
    assert_mentions(&e.to_string(), &["s.toml:5:8:", "dir.obj is a directory"]);

    let text = format!("{}matcap = \"caps/red.png\"\n", minimal());
    let e = Scene::from_str(&text, &path).unwrap_err();
    assert_mentions(
        &e.to_string(),
        &[
            "s.toml:8:10:",
            "object[0].matcap",
            "red.png",
            "does not exist",
        ],
    );
}

#[test]
fn missing_scene_file_names_it() {
    let e = Scene::load(Path::new("/nonexistent/dir/scene.toml")).unwrap_err();
    assert!(matches!(e, SceneError::Read { .. }));
    assert_mentions(&e.to_string(), &["/nonexistent/dir/scene.toml"]);
    let source = std::error::Error::source(&e)
        .expect("io error as source")
        .to_string();
    assert!(!source.is_empty());
}

#[test]
fn malformed_toml() {
    let msg = error("[camera]\norigin = [0, 1, 5\ntarget = [0, 0, 0]\n");
    assert_mentions(&msg, &[PATH, ":3:"]);
    let msg = error("[camera\norigin = [0, 1, 5]\n");
    assert_mentions(&msg, &["scenes/x.toml:1:8:", "unclosed table"]);
    let msg = error(&format!("{}alpha = 4\n", minimal()));
    assert_mentions(&msg, &[":8:1:", "duplicate key `alpha`"]);
}

#[test]
fn unknown_keys() {
    // Top level.
    let msg = error(&format!("colour = 3\n{}", minimal()));
    assert_mentions(
        &msg,
        &["scenes/x.toml:1:1:", "unknown field `colour`", "camera"],
    );
    // A misspelt table.
    let msg = error(&format!("{}[[objects]]\n", minimal()));
    assert_mentions(&msg, &[":8:3:", "unknown field `objects`"]);
    // Inside [camera].
    let msg = error(&minimal().replace("[camera]\n", "[camera]\nfov_y = 40\n"));
    assert_mentions(&msg, &[":2:1:", "unknown field `fov_y`"]);
    // Inside [[object]].
    let msg = error(&format!("{}alhpa_rel = 4\n", minimal()));
    assert_mentions(&msg, &[":8:1:", "unknown field `alhpa_rel`", "alpha_rel"]);
    // Inside [object.transform].
    let msg = error(&format!(
        "{}[object.transform]\nrotation = [0, 0, 0]\n",
        minimal()
    ));
    assert_mentions(&msg, &[":9:1:", "unknown field `rotation`", "rotate"]);
    // Inside an inline generator table: the key itself is located.
    let msg = error(&minimal().replace("kind = \"torus\"", "kind = \"torus\", radius = 2"));
    assert_mentions(&msg, &[":5:31:", "unknown field `radius`", "major_radius"]);
    // Inside a [object.generator] table: the key's own line, not the header's.
    let text = format!(
        "{CAMERA}[[object]]\nprimitives = \"edges\"\nalpha = 1\n\n[object.generator]\nkind = \"bowl\"\n\n  ring = 3\n"
    );
    let msg = error(&text);
    assert_mentions(&msg, &[":11:3:", "unknown field `ring`", "rings"]);
}

#[test]
fn wrong_types() {
    let msg = error(&format!("{}[image]\nwidth = \"big\"\n", minimal()));
    assert_mentions(
        &msg,
        &[":9:9:", "`width`", "invalid type", "expected an integer"],
    );
    let msg = error(&format!("{}[image]\nwidth = 960.0\n", minimal()));
    assert_mentions(&msg, &[":9:9:", "`width`", "floating point"]);
    let msg = error(&minimal().replace("alpha = 300", "alpha = \"300\""));
    assert_mentions(&msg, &[":7:9:", "`alpha`", "expected a number"]);
    let msg = error(&minimal().replace("[0.0, 1.0, 5.0]", "[0.0, 1.0]"));
    assert_mentions(&msg, &[":2:10:", "`origin`", "length 2"]);
    let msg = error(&format!(
        "{}[render]\ncertified_hits = \"yes\"\n",
        minimal()
    ));
    assert_mentions(&msg, &[":9:18:", "`certified_hits`", "expected a boolean"]);
    let msg = error(&format!("{}[render]\nevaluation = \"fast\"\n", minimal()));
    assert_mentions(
        &msg,
        &[":9:14:", "unknown variant `fast`", "stable", "naive"],
    );
    let msg =
        error(&minimal().replace("kind = \"torus\"", "kind = \"torus\", major_segments = 2.5"));
    assert_mentions(
        &msg,
        &[":5:48:", "`major_segments`", "floating point `2.5`"],
    );
    // The same in a [object.generator] table: the value's own line.
    let text = format!(
        "{CAMERA}[[object]]\nprimitives = \"edges\"\nalpha = 1\n[object.generator]\nkind = \"bowl\"\nrings = -3\nradius = \"big\"\n"
    );
    assert_mentions(
        &error(&text.replace("\"big\"", "2")),
        &[":9:9:", "`rings`", "integer `-3`"],
    );
    let msg = error(&text.replace("rings = -3", "rings = 3"));
    assert_mentions(
        &msg,
        &[":10:10:", "`radius`", "string \"big\"", "expected a number"],
    );
    let msg = error(&format!("{}[image]\nbackground = [255, 255]\n", minimal()));
    assert_mentions(&msg, &[":9:14:", "image.background", "#ffffff"]);
    let msg = error(&format!("{}[image]\nbackground = \"white\"\n", minimal()));
    assert_mentions(&msg, &[":9:14:", "image.background"]);
}

#[test]
fn background_forms() {
    let bg = |v: &str| {
        parse(&format!("{}[image]\nbackground = {v}\n", minimal()))
            .unwrap()
            .image
            .background
    };
    assert_eq!(bg("[0, 128, 255]"), [0, 128, 255]);
    assert_eq!(bg("\"#ff8000\""), [255, 128, 0]);
    assert_eq!(bg("\"#fff\""), [255, 255, 255]);
}

#[test]
fn image_size_range() {
    let msg = error(&format!("{}[image]\nwidth = -5\n", minimal()));
    assert_mentions(
        &msg,
        &[
            "scenes/x.toml:9:9:",
            "image.width must be in 1..=16384 (got -5)",
        ],
    );
    let msg = error(&format!("{}[image]\nheight = 0\n", minimal()));
    assert_mentions(
        &msg,
        &[":9:10:", "image.height must be in 1..=16384 (got 0)"],
    );
    let msg = error(&format!("{}[image]\nheight = 20000\n", minimal()));
    assert_mentions(&msg, &[":9:10:", "(got 20000)"]);
    let msg = error(&format!("{}[image]\nheight = 99999999999\n", minimal()));
    assert_mentions(&msg, &[":9:10:", "image.height"]);
}

#[test]
fn alpha_errors() {
    let msg = error(&minimal().replace("alpha = 300", "alpha = -1"));
    assert_mentions(
        &msg,
        &["scenes/x.toml:7:9:", "object[0].alpha must be > 0 (got -1)"],
    );
    let msg = error(&minimal().replace("alpha = 300", "alpha = 0"));
    assert_mentions(&msg, &[":7:9:", "object[0].alpha must be > 0 (got 0)"]);
    let msg = error(&minimal().replace("alpha = 300", "alpha_rel = nan"));
    assert_mentions(
        &msg,
        &[":7:13:", "object[0].alpha_rel must be a finite number"],
    );
    let msg = error(&minimal().replace("alpha = 300", "alpha = 300\nalpha_rel = 3"));
    assert_mentions(&msg, &[":8:13:", "either alpha", "alpha_rel", "not both"]);
    let msg = error(&minimal().replace("alpha = 300", "max_alpha = 3"));
    assert_mentions(&msg, &[":4:1:", "object[0] needs alpha"]);
    let msg = error(&format!("{}max_alpha_rel = -2\n", minimal()));
    assert_mentions(
        &msg,
        &[":8:17:", "object[0].max_alpha_rel must be > 0 (got -2)"],
    );
    let msg = error(&format!("{}max_alpha = 2\nmax_alpha_rel = 2\n", minimal()));
    assert_mentions(&msg, &[":9:17:", "max_alpha", "not both"]);

    // Objects are counted from 0 in messages; the second object is object[1].
    let text = format!(
        "{}{}",
        minimal(),
        "[[object]]\ngenerator = { kind = \"net\" }\nprimitives = \"edges\"\nalpha = -3\n"
    );
    assert_mentions(
        &error(&text),
        &[":11:9:", "object[1].alpha must be > 0 (got -3)"],
    );
}

#[test]
fn render_errors() {
    for beta in ["-0.1", "1.5", "nan"] {
        let msg = error(&format!("{}[render]\nbeta = {beta}\n", minimal()));
        assert_mentions(
            &msg,
            &[
                ":9:8:",
                "render.beta must be in [0, 1]",
                &format!("(got {})", beta.replace("nan", "NaN")),
            ],
        );
    }
    for beta in ["0", "1", "0.5"] {
        assert!(parse(&format!("{}[render]\nbeta = {beta}\n", minimal())).is_ok());
    }
    let msg = error(&format!(
        "{}[render]\nepsilon = 1e-3\nepsilon_rel = 1e-4\n",
        minimal()
    ));
    assert_mentions(&msg, &[":10:15:", "either epsilon", "not both"]);
    let msg = error(&format!("{}[render]\nepsilon = 0\n", minimal()));
    assert_mentions(&msg, &[":9:11:", "render.epsilon must be > 0 (got 0)"]);
    let msg = error(&format!("{}[render]\nepsilon_rel = -1\n", minimal()));
    assert_mentions(&msg, &[":9:15:", "render.epsilon_rel must be > 0"]);
    let msg = error(&format!("{}[render]\nmax_steps = 0\n", minimal()));
    assert_mentions(&msg, &[":9:13:", "render.max_steps must be >= 1 (got 0)"]);
    let msg = error(&format!("{}[render]\nthreads = -2\n", minimal()));
    assert_mentions(&msg, &[":9:11:", "render.threads must be >= 0"]);
}

#[test]
fn empty_object_list() {
    let msg = error(CAMERA);
    assert_eq!(
        msg,
        "scenes/x.toml: no [[object]] in scene: add at least one [[object]] table with a mesh or a generator"
    );
    let msg = error(&format!("object = []\n{CAMERA}"));
    assert_mentions(&msg, &["no [[object]] in scene"]);
}

#[test]
fn geometry_errors() {
    let msg = error(&minimal().replace("generator = { kind = \"torus\" }\n", ""));
    assert_mentions(&msg, &[":4:1:", "object[0] needs a mesh", "or a generator"]);
    let msg = error(&minimal().replace("[[object]]\n", "[[object]]\nmesh = \"a.obj\"\n"));
    assert_mentions(&msg, &[":6:13:", "either mesh or generator, not both"]);
}

#[test]
fn matcap_names() {
    for (name, spec) in [
        ("clay", MatCapSpec::Builtin("clay".into())),
        ("gold", MatCapSpec::Builtin("gold".into())),
        ("normal", MatCapSpec::Normal),
    ] {
        let s = parse(&format!("{}matcap = \"{name}\"\n", minimal())).unwrap();
        assert_eq!(s.objects[0].matcap, spec);
    }
    let msg = error(&format!("{}matcap = \"chalk\"\n", minimal()));
    assert_mentions(
        &msg,
        &[
            ":8:10:",
            "object[0].matcap",
            "unknown MatCap \"chalk\"",
            "clay",
            "blue",
            "normal",
        ],
    );
}

#[test]
fn transform_errors() {
    let with = |t: &str| error(&format!("{}[object.transform]\n{t}\n", minimal()));
    assert_mentions(
        &with("scale = 0"),
        &[
            ":9:9:",
            "object[0].transform.scale must be finite and non-zero",
            "[0, 0, 0]",
        ],
    );
    assert_mentions(&with("scale = [1, 0, 1]"), &[":9:9:", "(got [1, 0, 1])"]);
    assert_mentions(
        &with("scale = [1, 2]"),
        &[":9:9:", "must be a number or [sx, sy, sz]"],
    );
    assert_mentions(
        &with("rotate = [0, inf, 0]"),
        &[":9:10:", "object[0].transform.rotate must be finite"],
    );
    assert_mentions(
        &with("translate = [nan, 0, 0]"),
        &[":9:13:", "object[0].transform.translate must be finite"],
    );
    let s = parse(&format!("{}[object.transform]\nscale = -2\n", minimal())).unwrap();
    assert_eq!(s.objects[0].transform.scale, DVec3::splat(-2.0));
}

#[test]
fn degenerate_camera() {
    let msg = error(&minimal().replace("target = [0.0, 0.0, 0.0]", "target = [0.0, 1.0, 5.0]"));
    assert_mentions(
        &msg,
        &[
            "scenes/x.toml:3:10:",
            "camera.origin and camera.target are the same point",
        ],
    );

    // Default up (not in the file): located at the target.
    let looking_down = minimal().replace("[0.0, 1.0, 5.0]", "[0.0, 5.0, 0.0]");
    let msg = error(&looking_down);
    assert_mentions(
        &msg,
        &[
            ":3:10:",
            "camera.up [0, 1, 0] is zero or parallel",
            "[0, 0, 1]",
        ],
    );
    // An explicit up: located at it.
    let msg = error(&looking_down.replace("[camera]\n", "[camera]\nup = [0, -2, 0]\n"));
    assert_mentions(&msg, &[":2:6:", "camera.up [0, -2, 0]"]);
    let msg = error(&minimal().replace("[camera]\n", "[camera]\nup = [0, 0, 0]\n"));
    assert_mentions(&msg, &[":2:6:", "camera.up [0, 0, 0] is zero"]);
    assert!(parse(&looking_down.replace("[camera]\n", "[camera]\nup = [0, 0, -1]\n")).is_ok());

    for fov in ["0", "180", "-5", "200.5"] {
        let msg = error(&minimal().replace("[camera]\n", &format!("[camera]\nfov = {fov}\n")));
        assert_mentions(&msg, &[":2:7:", "camera.fov must be in (0, 180) degrees"]);
    }
    let msg = error(&minimal().replace("[0.0, 1.0, 5.0]", "[0.0, inf, 5.0]"));
    assert_mentions(&msg, &[":2:10:", "camera.origin must be finite"]);
    // Without origin and target the camera is auto-framed (issue 11); half of them is
    // an error that says what to add.
    let msg = error("[camera]\ntarget = [0, 0, 0]\n");
    assert_mentions(
        &msg,
        &[
            ":2:10:",
            "[camera] needs both origin and target, or fit = true",
        ],
    );
    let msg = error(&minimal().replace("[camera]\n", "[camera]\nfit = true\n"));
    assert_mentions(&msg, &["camera.fit = true places the camera itself"]);
    let msg = error(&minimal().replace("[camera]\n", "[camera]\ndirection = [1, 0, 0]\n"));
    assert_mentions(&msg, &[":2:13:", "camera.direction", "add fit = true"]);
    let msg = error("[image]\nwidth = 10\n");
    assert_mentions(&msg, &["scenes/x.toml:", "no [[object]] in scene"]);
}

#[test]
fn validate_after_overrides() {
    let mut s = parse(&minimal()).unwrap();
    s.validate().unwrap();

    // A value changed after loading is reported without a location.
    s.image.width = 0;
    let e = s.validate().unwrap_err();
    assert_eq!(e.location(), None);
    assert_eq!(
        e.to_string(),
        "scenes/x.toml: image.width must be in 1..=16384 (got 0)"
    );
    match &e {
        SceneError::Invalid { field, .. } => assert_eq!(field, "image.width"),
        other => panic!("{other:?}"),
    }
    s.image.width = 4000;
    s.validate().unwrap();

    s.render.beta = 2.0;
    assert_mentions(
        &s.validate().unwrap_err().to_string(),
        &["render.beta", "(got 2)"],
    );
    s.render.beta = 0.0;
    s.render.threads = 3;

    s.objects[0].alpha = AlphaSpec::Absolute(-1.0);
    let e = s.validate().unwrap_err();
    assert_eq!(e.location(), None);
    assert_mentions(&e.to_string(), &["object[0].alpha must be > 0 (got -1)"]);
    s.objects[0].alpha = AlphaSpec::Relative(100.0);
    s.validate().unwrap();

    // A value from the file is still located after other fields changed.
    let mut s = parse(&format!("{}[image]\nheight = 100\n", minimal())).unwrap();
    s.image.width = 17000;
    let e = s.validate().unwrap_err();
    assert_eq!(e.location(), None);
    s.image.width = 100;
    s.camera.target = s.camera.origin;
    let e = s.validate().unwrap_err();
    // The camera origin is still the one from line 2.
    assert_eq!(
        e.location(),
        Some(Location {
            line: 2,
            column: 10
        })
    );

    // A scene built in code has no file to name.
    let mut s = Scene::new(
        smoothtrace::scene::CameraSettings::looking_at(DVec3::Z * 3.0, DVec3::ZERO),
        vec![],
    );
    assert_eq!(
        s.validate().unwrap_err().to_string(),
        "no [[object]] in scene: add at least one [[object]] table with a mesh or a generator"
    );
    s.objects = parse(&minimal()).unwrap().objects;
    s.validate().unwrap();
    assert_eq!(s.path, PathBuf::new());
}

/// Every TOML example in the README (the scene format reference) parses and validates.
#[test]
fn documented_examples_parse() {
    let doc =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("scenes")).unwrap();
    std::fs::create_dir_all(dir.path().join("data")).unwrap();
    std::fs::write(dir.path().join("data/bunny-7k.obj"), "v 0 0 0\n").unwrap();
    let mut count = 0;
    for block in doc.split("```toml\n").skip(1) {
        let text = block.split("```").next().unwrap();
        let path = dir.path().join(format!("scenes/example{count}.toml"));
        if let Err(e) = Scene::from_str(text, &path) {
            panic!("example {count} of README.md: {e}\n{text}");
        }
        count += 1;
    }
    assert!(
        count >= 2,
        "expected at least the complete and the minimal example"
    );
}
