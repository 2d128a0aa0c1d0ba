//! The command line as a user runs it: the built binary in a temp directory.

mod common;

use std::path::Path;
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_smoothtrace"))
}

fn run(args: &[&str], dir: &Path, stdin: Option<&str>) -> Output {
    common::run_cli(bin(), args, dir, stdin)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Runs and expects exit status 2 with every `needles` in the message, and no panic.
fn expect_error(args: &[&str], dir: &Path, stdin: Option<&str>, needles: &[&str]) {
    let o = run(args, dir, stdin);
    let e = stderr(&o);
    assert_eq!(
        o.status.code(),
        Some(2),
        "{args:?}: status {:?}, stderr: {e}",
        o.status
    );
    assert!(!e.contains("panicked"), "{args:?} panicked: {e}");
    for n in needles {
        assert!(e.contains(n), "{args:?}: message lacks `{n}`: {e}");
    }
}

const TETRA: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n";

fn tempdir_with(files: &[(&str, &str)]) -> tempfile::TempDir {
    let d = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(d.path().join(name), text).unwrap();
    }
    d
}

#[test]
fn query_prints_six_columns_per_point() {
    let d = tempdir_with(&[
        ("t.obj", TETRA),
        ("q.txt", "0.2 0.2 0.2\n3 3 3\n# comment\n\n0 0 0\n"),
    ]);
    for prim in ["points", "edges", "triangles", "triangles,edges"] {
        let o = run(
            &[
                "query",
                "t.obj",
                "--primitive",
                prim,
                "--alpha",
                "20",
                "--beta",
                "0",
                "--points",
                "q.txt",
            ],
            d.path(),
            None,
        );
        assert!(o.status.success(), "{}", stderr(&o));
        let out = String::from_utf8(o.stdout.clone()).unwrap();
        let lines: Vec<&str> = out.lines().collect();
        assert_eq!(lines.len(), 3, "{out}");
        for l in lines {
            let v: Vec<f64> = l.split(' ').map(|w| w.parse().unwrap()).collect();
            assert_eq!(v.len(), 6);
            assert!(v[0] <= v[4] + 1e-12, "s {} above dmin {}", v[0], v[4]);
        }
        assert!(stderr(&o).contains("alpha 20"), "resolved values on stderr");
    }
    // Standard input and a relative alpha.
    let o = run(
        &["query", "t.obj", "-p", "points", "--alpha-rel", "100"],
        d.path(),
        Some("0 0 0\n"),
    );
    assert!(o.status.success());
    assert!(
        stderr(&o).contains("alpha * diagonal = 100"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn query_naive_underflow_prints_inf_and_says_so() {
    let d = tempdir_with(&[("t.obj", TETRA)]);
    let o = run(
        &[
            "query", "t.obj", "-p", "points", "--alpha", "1e5", "--naive",
        ],
        d.path(),
        Some("50 0 0\n"),
    );
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stdout).starts_with("inf "));
    assert!(stderr(&o).contains("underflowed"));
    let o = run(
        &["query", "t.obj", "-p", "points", "--alpha", "1e5"],
        d.path(),
        Some("50 0 0\n"),
    );
    assert!(!String::from_utf8_lossy(&o.stdout).contains("inf"));
}

#[test]
fn query_bad_input_exits_2_with_a_clear_message() {
    let d = tempdir_with(&[
        ("t.obj", TETRA),
        ("bad.obj", "v 0 0 0\nv 1 x 0\n"),
        ("range.obj", "v 0 0 0\nv 1 0 0\nf 1 2 9\n"),
        ("nan.obj", "v 0 0 0\nv nan 0 0\n"),
        ("empty.obj", "# nothing\n"),
        ("cloud.obj", "v 0 0 0\nv 1 0 0\n"),
        ("mesh.xyz", "1 2 3\n"),
        ("badq.txt", "0 0 0\n1 2\n"),
    ]);
    let q = Some("0 0 0\n");
    let base = ["--alpha", "10"];
    let with = |mesh: &str, prim: &str| -> Vec<String> {
        let mut v: Vec<String> = vec!["query".into(), mesh.into(), "-p".into(), prim.into()];
        v.extend(base.iter().map(|s| s.to_string()));
        v
    };
    let e = |args: Vec<String>, needles: &[&str]| {
        let a: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
        expect_error(&a, d.path(), q, needles);
    };
    e(
        with("missing.obj", "points"),
        &["missing.obj", "cannot read"],
    );
    e(
        with("mesh.xyz", "points"),
        &["mesh.xyz", "unknown mesh extension"],
    );
    e(with("bad.obj", "points"), &["bad.obj:2"]);
    e(
        with("range.obj", "triangles"),
        &["range.obj", "out of range"],
    );
    e(with("nan.obj", "points"), &["nan.obj"]);
    e(with("empty.obj", "points"), &["empty.obj", "no vertices"]);
    e(
        with("cloud.obj", "triangles"),
        &["cannot build triangles", "no faces"],
    );
    let mut a = with("t.obj", "points");
    a[5] = "0".into();
    e(a, &["--alpha", "positive"]);
    let mut a = with("t.obj", "points");
    a.extend(["--beta".into(), "1.5".into()]);
    e(a, &["--beta", "[0, 1]"]);
    let mut a = with("t.obj", "points");
    a.extend(["--points".into(), "badq.txt".into()]);
    e(a, &["badq.txt:2", "three numbers"]);
    for bad in ["-0.001", "nan", "inf"] {
        let mut a = with("t.obj", "triangles");
        a.extend(["--tolerance".into(), bad.into()]);
        e(a, &["--tolerance must be a length >= 0"]);
    }
}

const SCENE: &str = r#"
[camera]
origin = [0.0, 0.5, 4.0]
target = [0.0, 0.0, 0.0]
[image]
width = 48
height = 32
[[object]]
generator = { kind = "sphere_points", count = 300 }
primitives = "points"
alpha = 10.0
"#;

#[test]
fn render_writes_png_stats_and_depth() {
    let d = tempdir_with(&[("s.toml", SCENE)]);
    let o = run(
        &[
            "render",
            "s.toml",
            "-o",
            "out.png",
            "--stats",
            "st.json",
            "--depth",
            "depth.exr",
            "--threads",
            "1",
        ],
        d.path(),
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(d.path().join("out.png")).unwrap();
    assert_eq!((img.width(), img.height()), (48, 32));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.path().join("st.json")).unwrap()).unwrap();
    assert_eq!(json["image"]["rays"], 48 * 32);
    assert!(json["image"]["hits"].as_u64().unwrap() > 0);
    // A point cloud: full evaluations that only take a step run at the coarser step
    // beta, and are counted apart as well as among the full ones.
    let (evals, steps) = (
        json["evals_per_hit_ray"].as_f64().unwrap(),
        json["step_evals_per_hit_ray"].as_f64().unwrap(),
    );
    assert!(
        steps > 0.0 && steps < evals,
        "{steps} step of {evals} evaluations"
    );
    // The full evaluations by value account for every full evaluation and its leaves
    // (with those that only took a hit's gradient), one bin more than the edges.
    let image = &json["image"];
    let by = &image["full_evaluations_by_value"];
    let sum = |key: &str| -> u64 {
        by[key]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_u64().unwrap())
            .sum()
    };
    let bins = by["evaluations"].as_array().unwrap().len();
    assert_eq!(bins, by["edges_epsilons"].as_array().unwrap().len() + 1);
    assert_eq!(
        sum("evaluations") + by["gradient_evaluations"].as_u64().unwrap(),
        image["evals"].as_u64().unwrap()
    );
    assert_eq!(
        sum("leaves") + by["gradient_leaves"].as_u64().unwrap(),
        image["leaves"].as_u64().unwrap() - image["coarse_leaves"].as_u64().unwrap()
    );
    // Rays that hit end at a value within the band or just above it.
    assert!(by["evaluations"][1].as_u64().unwrap() > 0, "{by}");
    let depth = image::open(d.path().join("depth.exr")).unwrap().to_rgb32f();
    let centre = depth.get_pixel(24, 16)[0];
    assert!(centre > 2.0 && centre < 4.0, "depth at the centre {centre}");
    // One short line by default: scene, size, time, rays/s, output; no counters.
    let e = stderr(&o);
    let line = e.lines().last().unwrap_or_default();
    assert!(
        line.starts_with("s.toml: 48x32 in ")
            && line.contains(" s, ")
            && line.contains(" rays/s -> out.png")
            && !line.contains("evaluations"),
        "summary line: {e}"
    );
    assert!(
        line.len() < 100,
        "summary line of {} characters: {line}",
        line.len()
    );
}

#[test]
fn verbose_adds_the_counters_after_the_summary() {
    let d = tempdir_with(&[("s.toml", SCENE)]);
    let o = run(
        &[
            "render",
            "s.toml",
            "-o",
            "out.png",
            "--verbose",
            "--threads",
            "1",
        ],
        d.path(),
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    let lines: Vec<&str> = e.lines().collect();
    let at = lines
        .iter()
        .position(|l| l.contains(" rays/s -> out.png"))
        .unwrap_or_else(|| panic!("no summary line: {e}"));
    let counters = lines.get(at + 1).copied().unwrap_or_default();
    for part in [
        "1 threads",
        "evaluations/ray",
        "per hit ray",
        "bound steps",
        "leaves/ray",
        "% hits",
    ] {
        assert!(counters.contains(part), "counters line lacks {part:?}: {e}");
    }
}

#[test]
fn verbose_shows_that_only_the_needed_structures_are_built() {
    let d = tempdir_with(&[("s.toml", SCENE)]);
    let o = run(
        &["render", "s.toml", "-o", "out.png", "--verbose"],
        d.path(),
        None,
    );
    let e = stderr(&o);
    assert!(o.status.success(), "{e}");
    assert!(e.contains("points: 300 primitives"), "{e}");
    assert!(
        !e.contains("edges:") && !e.contains("triangles:"),
        "built more than needed: {e}"
    );
    assert_eq!(e.matches("matcap clay").count(), 1, "{e}");
    // A triangle scene with two objects sharing a MatCap builds it once, and no edges.
    let two = r#"
[camera]
origin = [0.0, 0.5, 6.0]
target = [0.0, 0.0, 0.0]
[image]
width = 32
height = 24
[[object]]
generator = { kind = "torus" }
primitives = "triangles"
alpha = 50.0
matcap = "blue"
[[object]]
generator = { kind = "torus" }
primitives = "triangles"
alpha = 50.0
matcap = "blue"
[object.transform]
translate = [0.0, 1.0, 0.0]
"#;
    std::fs::write(d.path().join("two.toml"), two).unwrap();
    let e = stderr(&run(
        &["render", "two.toml", "-o", "two.png", "-v"],
        d.path(),
        None,
    ));
    assert_eq!(e.matches("triangles: 1152 primitives").count(), 2, "{e}");
    assert_eq!(e.matches("matcap blue").count(), 1, "{e}");
    assert!(!e.contains("edges:") && !e.contains("points:"), "{e}");
}

#[test]
fn render_bad_input_exits_2_with_a_clear_message() {
    // On the shell of points (the hollow centre would be outside the surface).
    let inside = SCENE.replace("origin = [0.0, 0.5, 4.0]", "origin = [1.0, 0.0, 0.0]");
    let d = tempdir_with(&[
        ("s.toml", SCENE),
        ("broken.toml", "[camera\norigin = [0, 0, 1]\n"),
        (
            "typed.toml",
            &SCENE.replace("width = 48", "width = \"wide\""),
        ),
        ("unknown.toml", &SCENE.replace("width = 48", "widht = 48")),
        ("alpha.toml", &SCENE.replace("alpha = 10.0", "alpha = -1.0")),
        ("beta.toml", &format!("{SCENE}\n[render]\nbeta = 2.0\n")),
        (
            "noobj.toml",
            "[camera]\norigin = [0.0, 0.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\n",
        ),
        ("inside.toml", &inside),
        (
            "nomesh.toml",
            &SCENE.replace(
                "generator = { kind = \"sphere_points\", count = 300 }",
                "mesh = \"absent.obj\"",
            ),
        ),
        (
            "degenerate.toml",
            &SCENE.replace("target = [0.0, 0.0, 0.0]", "target = [0.0, 0.5, 4.0]"),
        ),
    ]);
    let e = |args: &[&str], needles: &[&str]| expect_error(args, d.path(), None, needles);
    e(
        &["render", "missing.toml", "-o", "o.png"],
        &["missing.toml"],
    );
    e(
        &["render", "broken.toml", "-o", "o.png"],
        &["broken.toml:1"],
    );
    e(
        &["render", "typed.toml", "-o", "o.png"],
        &["typed.toml:6", "width"],
    );
    e(
        &["render", "unknown.toml", "-o", "o.png"],
        &["unknown.toml:6", "widht"],
    );
    e(
        &["render", "alpha.toml", "-o", "o.png"],
        &["alpha.toml:", "alpha"],
    );
    e(
        &["render", "beta.toml", "-o", "o.png"],
        &["beta.toml:", "beta"],
    );
    e(
        &["render", "noobj.toml", "-o", "o.png"],
        &["noobj.toml", "object"],
    );
    e(
        &["render", "nomesh.toml", "-o", "o.png"],
        &["nomesh.toml", "absent.obj"],
    );
    e(
        &["render", "degenerate.toml", "-o", "o.png"],
        &["degenerate.toml"],
    );
    e(
        &["render", "s.toml", "-o", "o.png", "--width", "-3"],
        &["--width", "-3"],
    );
    e(
        &["render", "s.toml", "-o", "o.png", "--beta", "1.5"],
        &["--beta"],
    );
    e(
        &["render", "s.toml", "-o", "o.png", "--alpha", "0"],
        &["--alpha"],
    );
    e(
        &["render", "inside.toml", "-o", "o.png"],
        &["inside the surface"],
    );
    assert!(
        !d.path().join("o.png").exists(),
        "no image is written for bad input"
    );
}
