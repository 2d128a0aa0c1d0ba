//! The report commands run as the built binary in a temporary directory: `bench` on
//! procedural Table 1 rows, `sweep` (renders and the grid) on a small procedural scene,
//! `stability --size small`, and their command-line errors.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_smoothtrace"))
}

fn scenes_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

fn run(dir: &Path, args: &[&str]) -> Output {
    let out = bin()
        .current_dir(dir)
        .args(args)
        .output()
        .expect("run smoothtrace");
    eprintln!(
        "smoothtrace {}\nstatus {:?}\n--- stdout\n{}--- stderr\n{}",
        args.join(" "),
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Parses a CSV without quoted commas into (header, rows).
fn csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).expect("csv written");
    let mut lines = text.lines();
    let header = lines
        .next()
        .expect("header")
        .split(',')
        .map(String::from)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

fn col(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

fn num(s: &str) -> f64 {
    s.parse()
        .unwrap_or_else(|_| panic!("'{s}' is not a number"))
}

const SMALL_SCENE: &str = r#"
[camera]
origin = [0.0, 2.0, 2.6]
target = [0.0, -0.05, 0.0]

[image]
width = 48
height = 27

[render]
beta = 0.5
epsilon = 1e-3

[[object]]
generator = { kind = "torus", major_segments = 12, minor_segments = 6 }
primitives = "triangles"
alpha = 60.0
"#;

#[test]
fn bench_quick_on_procedural_rows_with_paper_mode() {
    let dir = tempfile::tempdir().unwrap();
    let scenes = scenes_dir();
    let out = run(
        dir.path(),
        &[
            "bench",
            "--quick",
            "--width",
            "64",
            "--height",
            "36",
            "--rows",
            "net,torus",
            "--paper-mode",
            "--repeat",
            "3",
            "--scenes-dir",
            scenes.to_str().unwrap(),
            "--csv",
            "out/bench.csv",
            "--json",
            "bench.json",
        ],
    );
    assert!(out.status.success());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("net") && stdout.contains("torus") && stdout.contains("speedup"));
    let (h, rows) = csv(&dir.path().join("out/bench.csv"));
    assert_eq!(rows.len(), 2, "{rows:?}");
    for name in [
        "name",
        "paper_n",
        "n",
        "paper_alpha",
        "alpha",
        "paper_seconds",
        "seconds",
        "evals_per_ray",
        "leaves_per_eval",
        "leaves_per_ray",
        "bvh_seconds",
        "peak_rss_mib",
        "paper_mode_seconds",
        "speedup",
        "skipped",
    ] {
        col(&h, name);
    }
    assert_eq!(rows[0][col(&h, "name")], "net");
    assert_eq!(rows[1][col(&h, "n")], "1152");
    assert_eq!(rows[1][col(&h, "paper_seconds")], "6.05");
    assert_eq!(rows[1][col(&h, "width")], "64");
    for r in &rows {
        assert!(num(&r[col(&h, "seconds")]) > 0.0);
        // The fastest of three renders, and their median.
        assert_eq!(r[col(&h, "runs")], "3");
        assert!(num(&r[col(&h, "seconds_median")]) >= num(&r[col(&h, "seconds")]));
        assert!(num(&r[col(&h, "speedup")]) > 0.0);
        assert!(num(&r[col(&h, "leaves_per_eval")]) >= 1.0);
        assert_eq!(r[col(&h, "skipped")], "");
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("bench.json")).unwrap())
            .unwrap();
    assert_eq!(json[1]["name"], "torus");
}

#[test]
fn bench_reports_rows_with_missing_data_as_skipped() {
    let dir = tempfile::tempdir().unwrap();
    let scenes = dir.path().join("scenes");
    std::fs::create_dir(&scenes).unwrap();
    // The bunny scene refers to ../data/bunny-7k.obj, absent here.
    std::fs::copy(scenes_dir().join("bunny.toml"), scenes.join("bunny.toml")).unwrap();
    let out = run(
        dir.path(),
        &["bench", "--quick", "--rows", "bunny,net", "--csv", "b.csv"],
    );
    assert!(out.status.success());
    let (h, rows) = csv(&dir.path().join("b.csv"));
    // Rows come in Table 1 order: net (no scene file here), then the bunny (no data).
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0][col(&h, "name")], "net");
    assert!(rows[0][col(&h, "skipped")].contains("not found"));
    let skipped = &rows[1][col(&h, "skipped")];
    assert!(skipped.contains("bunny-7k.obj does not exist"), "{skipped}");
    assert_eq!(rows[1][col(&h, "paper_seconds")], "16.96");
}

#[test]
fn bench_rejects_an_unknown_row() {
    let dir = tempfile::tempdir().unwrap();
    let out = run(dir.path(), &["bench", "--quick", "--rows", "torus,teapot"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("unknown Table 1 row 'teapot'") && err.contains("hex_torus"),
        "{err}"
    );
    for bad in ["0", "21"] {
        let out = run(dir.path(), &["bench", "--quick", "--repeat", bad]);
        assert_eq!(out.status.code(), Some(2), "--repeat {bad}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("--repeat must be in 1..=20"), "{err}");
    }
}

#[test]
fn sweep_two_betas_on_a_small_scene() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("t.toml"), SMALL_SCENE).unwrap();
    let out = run(
        dir.path(),
        &[
            "sweep",
            "t.toml",
            "--betas",
            "0,0.5",
            "--csv",
            "s.csv",
            "--json",
            "s.json",
            "--plot",
            "plots/s.png",
        ],
    );
    assert!(out.status.success());
    let (h, rows) = csv(&dir.path().join("s.csv"));
    for name in [
        "scene",
        "type",
        "beta",
        "evaluation",
        "seconds",
        "speedup",
        "error_mean",
        "error_p95",
        "error_max",
        "only_one_percent",
        "leaves_per_eval",
        "falloffs",
    ] {
        col(&h, name);
    }
    // beta 0, beta 0.5, and the naive render at the scene's beta 0.5.
    assert_eq!(rows.len(), 3, "{rows:?}");
    let r0 = &rows[0];
    assert_eq!(num(&r0[col(&h, "beta")]), 0.0);
    assert_eq!(num(&r0[col(&h, "speedup")]), 1.0);
    assert_eq!(num(&r0[col(&h, "error_max")]), 0.0);
    assert_eq!(num(&r0[col(&h, "only_one_percent")]), 0.0);
    assert_eq!(rows[2][col(&h, "evaluation")], "naive");
    assert_eq!(rows[2][col(&h, "reference")], "stable");
    let err = num(&rows[1][col(&h, "error_max")]);
    assert!((0.0..0.1).contains(&err), "{err}");
    let png = std::fs::read(dir.path().join("plots/s.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
}

#[test]
fn sweep_grid_mode() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("t.toml"), SMALL_SCENE).unwrap();
    let out = run(
        dir.path(),
        &[
            "sweep", "t.toml", "--grid", "6", "--betas", "0,0.5", "--csv", "g.csv", "--plot",
            "g.png",
        ],
    );
    assert!(out.status.success());
    let (h, rows) = csv(&dir.path().join("g.csv"));
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0][col(&h, "queries")], "216");
    assert_eq!(num(&rows[0][col(&h, "error_max")]), 0.0);
    assert_eq!(
        num(&rows[0][col(&h, "alpha_diag")]),
        num(&rows[1][col(&h, "alpha_diag")])
    );
    assert_eq!(rows[1][col(&h, "above_exact")], "0");
    assert!(num(&rows[1][col(&h, "leaves_mean")]) <= num(&rows[0][col(&h, "leaves_mean")]));
    assert!(dir.path().join("g.png").exists());
}

#[test]
fn sweep_rejects_bad_beta_lists() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("t.toml"), SMALL_SCENE).unwrap();
    for (list, want) in [
        ("0,abc", "'abc' is not a number"),
        ("0,1.5", "beta 1.5 is outside [0, 1]"),
        ("", "not a number"),
    ] {
        let out = run(dir.path(), &["sweep", "t.toml", "--betas", list]);
        assert_eq!(out.status.code(), Some(2), "--betas {list:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(want), "--betas {list:?}: {err}");
    }
    let out = run(dir.path(), &["sweep", "missing.toml"]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn stability_small_passes() {
    let dir = tempfile::tempdir().unwrap();
    let out = run(
        dir.path(),
        &["stability", "--size", "small", "--csv", "st.csv"],
    );
    assert_eq!(out.status.code(), Some(0));
    let (h, rows) = csv(&dir.path().join("st.csv"));
    assert!(rows.len() > 50);
    let st = col(&h, "status");
    let ev = col(&h, "evaluator");
    assert!(
        rows.iter()
            .filter(|r| r[ev] == "stable")
            .all(|r| r[st] == "ok")
    );
}
