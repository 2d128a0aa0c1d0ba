//! Regression tests for the defects of issue 10 (hardening), one test per defect, named
//! after the bug. The command line runs as the built binary in a temp directory.

use smoothtrace::mesh::Mesh;
use std::path::Path;
use std::process::{Command, Output, Stdio};

mod common;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_smoothtrace"))
}

fn run_in(dir: &Path, args: &[&str], stdin: &str) -> Output {
    common::run_cli(bin(), args, dir, Some(stdin))
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Exit status 2 and every needle in the message.
fn expect_error(o: &Output, needles: &[&str]) {
    let e = stderr(o);
    assert_eq!(o.status.code(), Some(2), "status {:?}: {e}", o.status);
    for n in needles {
        assert!(e.contains(n), "'{n}' not in: {e}");
    }
}

/// Whether a device the test needs exists (prints why the test skips when not).
fn device_present(path: &str) -> bool {
    let present = Path::new(path).exists();
    if !present {
        eprintln!("skipping: {path} is absent on this system");
    }
    present
}

/// `query MESH -p points --alpha 1` without query points: loads the mesh, prints nothing.
fn load_with_query(dir: &Path, mesh: &str) -> Output {
    run_in(dir, &["query", mesh, "-p", "points", "--alpha", "1"], "")
}

/// The `query` columns `s gx gy gz dmin leaves` of each output line.
fn columns(o: &Output) -> Vec<Vec<f64>> {
    assert!(o.status.success(), "{}", stderr(o));
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .map(|l| l.split_whitespace().map(|w| w.parse().unwrap()).collect())
        .collect()
}

/// Defect 1: a triangle with one vertex at 2e9 or 5e11 and two near the query was
/// measured by its edges (0.14 instead of 0.10). The triangle lies in the plane z = 0
/// and the query projects inside it, so the exact distance is its height, 0.1.
#[test]
fn long_skinny_triangle_distance_is_exact() {
    let dir = tempfile::tempdir().unwrap();
    for far in ["2e9", "5e11"] {
        // The far vertex first: the old test looked at the angle there.
        std::fs::write(
            dir.path().join("thin.obj"),
            format!("v {far} 0.1 0\nv 0 0 0\nv 0 0.2 0\nf 1 2 3\n"),
        )
        .unwrap();
        let o = run_in(
            dir.path(),
            &[
                "query",
                "thin.obj",
                "-p",
                "triangles",
                "--alpha",
                "100",
                "--beta",
                "0",
            ],
            "0.05 0.1 0.1\n0.05 0.1 -0.37\n",
        );
        let rows = columns(&o);
        for (row, want) in rows.iter().zip([0.1, 0.37]) {
            let d = row[4];
            assert!(
                (d - want).abs() <= 1e-12 * want,
                "far {far}: dmin {d}, exact {want}, diff {}",
                d - want
            );
            // The smooth distance of a single triangle never exceeds the exact one.
            assert!(row[0] <= d && row[0].is_finite());
        }
    }
    // Coordinates that do not fit f32, or are beyond the limit, are refused by name.
    std::fs::write(dir.path().join("huge.obj"), "v 0 0 0\nv 1e39 0 0\n").unwrap();
    let o = load_with_query(dir.path(), "huge.obj");
    expect_error(&o, &["huge.obj:2", "not finite"]);
    std::fs::write(dir.path().join("big.obj"), "v 0 0 0\nv 0 -2e31 0\n").unwrap();
    let o = load_with_query(dir.path(), "big.obj");
    expect_error(&o, &["big.obj:2", "beyond the accepted"]);
    let ply = "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty double y\n\
               property double z\nend_header\n0 0 0\n1e300 0 0\n";
    std::fs::write(dir.path().join("big.ply"), ply).unwrap();
    let e = Mesh::load(&dir.path().join("big.ply"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("big.ply") && e.contains("vertex 1"), "{e}");
}

/// Defect 2: `query` at (1e308, 0, 0) printed `inf`; field bounds of +-1e308 and
/// `--alpha 1e-300` wrote NaN/inf volumes. Now: refused up front with the reason, and
/// the largest accepted inputs give finite values.
#[test]
fn infinite_results_for_finite_queries_are_refused_or_finite() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("t.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let q = ["query", "t.obj", "-p", "triangles", "--alpha", "10"];
    for x in ["1e308 0 0", "0 1e160 0", "0 0 -2e31"] {
        let o = run_in(dir.path(), &q, &format!("{x}\n"));
        expect_error(&o, &["<stdin>:1", "beyond the accepted"]);
    }
    // At the limit every column is finite and the distance is right (to 1e-12 relative).
    let o = run_in(dir.path(), &q, "1e31 0 0\n0 0 -1e31\n");
    let rows = columns(&o);
    for (row, want) in rows.iter().zip([1e31 - 1.0, 1e31]) {
        assert!(row.iter().all(|v| v.is_finite()), "{row:?}");
        assert!((row[4] - want).abs() <= 1e-12 * want, "{row:?}");
    }
    let field = |extra: &[&str]| {
        let mut args = vec![
            "field",
            "t.obj",
            "-p",
            "triangles",
            "--res",
            "6",
            "-o",
            "f.npy",
        ];
        args.extend(extra);
        run_in(dir.path(), &args, "")
    };
    let o = field(&["--bounds", "-1e308", "-1", "-1", "1e308", "1", "1"]);
    expect_error(&o, &["bounds", "-1e308", "beyond the accepted"]);
    let o = field(&["--smooth", "--alpha", "1e-300"]);
    expect_error(&o, &["alpha", "below 1e-30"]);
    assert!(!dir.path().join("f.npy").exists());
    // The smallest accepted alpha on the three points: s = d - ln(sum of 3 terms) / alpha
    // is about -ln(3) * 1e30 everywhere, finite in the f32 volume.
    let o = run_in(
        dir.path(),
        &[
            "field", "t.obj", "-p", "points", "--res", "6", "-o", "f.npy", "--smooth", "--alpha",
            "1e-30",
        ],
        "",
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(dir.path().join("f.npy")).unwrap();
    let values: Vec<f32> = npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap();
    let want = -(3f64.ln()) * 1e30;
    let bad: Vec<_> = values
        .iter()
        .filter(|&&v| !(v.is_finite() && (v as f64 - want).abs() <= 1e-6 * want.abs()))
        .collect();
    assert!(
        !values.is_empty() && bad.is_empty(),
        "{} of {}: {:?}",
        bad.len(),
        values.len(),
        &bad[..bad.len().min(8)]
    );
}

/// Defect 3: `query` and `render` panicked (exit 101) with standard error on /dev/full;
/// a closed standard output made `query` exit 0 with its results lost.
#[test]
fn printing_never_panics_and_lost_output_is_an_error() {
    if !device_present("/dev/full") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("t.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let full = || Stdio::from(std::fs::File::create("/dev/full").unwrap());
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/torus.toml");
    let runs: [Vec<String>; 3] = [
        vec![
            "query".into(),
            "t.obj".into(),
            "-p".into(),
            "points".into(),
            "--alpha".into(),
            "1".into(),
        ],
        vec![
            "render".into(),
            scene.display().to_string(),
            "-o".into(),
            "x.png".into(),
            "--width".into(),
            "32".into(),
            "--height".into(),
            "24".into(),
        ],
        // An error message to a full stderr: still exit 2, no panic.
        vec![
            "query".into(),
            "missing.obj".into(),
            "-p".into(),
            "points".into(),
            "--alpha".into(),
            "1".into(),
        ],
    ];
    for (args, code) in runs.iter().zip([0, 0, 2]) {
        let o = bin()
            .args(args)
            .current_dir(dir.path())
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(full())
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(code), "{args:?}: {:?}", o.status);
    }
    assert!(dir.path().join("x.png").exists());
    // One query with standard output redirected by the shell.
    let query_with = |redirect: &str| {
        Command::new("sh")
            .arg("-c")
            .arg(format!(
                "echo '0 0 0' | \"$0\" query t.obj -p points --alpha 1 {redirect}"
            ))
            .arg(env!("CARGO_BIN_EXE_smoothtrace"))
            .current_dir(dir.path())
            .output()
            .unwrap()
    };
    // Closed standard output: exit 2 with a message.
    expect_error(&query_with(">&-"), &["standard output is closed"]);
    // Standard output sent to /dev/null on purpose is fine.
    let o = query_with(">/dev/null");
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Defect 4: a mesh or `--points` file that is not a regular file (`/dev/zero`) was read
/// until memory ran out.
#[test]
fn unbounded_reads_of_devices_are_refused() {
    if !device_present("/dev/zero") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink("/dev/zero", dir.path().join("zero.ply")).unwrap();
    std::fs::write(dir.path().join("t.obj"), "v 0 0 0\n").unwrap();
    let o = load_with_query(dir.path(), "zero.ply");
    expect_error(&o, &["zero.ply", "not a regular file"]);
    let o = run_in(
        dir.path(),
        &[
            "query",
            "t.obj",
            "-p",
            "points",
            "--alpha",
            "1",
            "--points",
            "/dev/zero",
        ],
        "",
    );
    expect_error(&o, &["/dev/zero", "not a regular file"]);
    std::fs::create_dir(dir.path().join("d.obj")).unwrap();
    let o = load_with_query(dir.path(), "d.obj");
    expect_error(&o, &["d.obj", "directory"]);
    // A query line without an end is cut at 64 KiB, not read whole.
    let long = "1".repeat(100_000);
    let o = run_in(
        dir.path(),
        &["query", "t.obj", "-p", "points", "--alpha", "1"],
        &long,
    );
    expect_error(&o, &["<stdin>:1", "longer than"]);
}

/// Defect 5: `render -o x.jpg` rendered the whole image, then failed and left an empty
/// file. Now JPEG and WebP are written, unknown formats fail before rendering, and an
/// existing image is never replaced by a broken one.
#[test]
fn half_written_outputs_are_never_left() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/torus.toml");
    let scene = scene.to_str().unwrap();
    let render = |out: &str, extra: &[&str]| {
        let mut args = vec![
            "render", scene, "-o", out, "--width", "40", "--height", "30",
        ];
        args.extend(extra);
        run_in(dir.path(), &args, "")
    };
    for name in ["x.jpg", "x.webp", "x.png"] {
        let o = render(name, &[]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let img = image::open(dir.path().join(name)).unwrap();
        assert_eq!((img.width(), img.height()), (40, 30), "{name}");
    }
    let before = std::fs::read(dir.path().join("x.png")).unwrap();
    // Bad outputs fail before the render: no summary line, nothing written.
    for (out, extra, needle) in [
        ("x.gif", vec![], "'.gif'"),
        ("x.png", vec!["--depth", "d.png"], "d.png"),
        ("x.png", vec!["--stats", "no/such/dir/s.json"], "s.json"),
        ("no/such/dir/y.png", vec![], "y.png"),
    ] {
        let o = render(out, &extra);
        expect_error(&o, &[needle]);
        assert!(
            !stderr(&o).contains("rays/s"),
            "rendered before failing: {}",
            stderr(&o)
        );
    }
    assert!(!dir.path().join("x.gif").exists());
    assert_eq!(std::fs::read(dir.path().join("x.png")).unwrap(), before);
    // No temporary files are left behind.
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.ends_with(".tmp")), "{names:?}");
}

/// Defect 6: malformed PLY was accepted silently (repeated names, extra values, trailing
/// data, a bad `format` line), and an ASCII STL with invalid UTF-8.
#[test]
fn lenient_ply_and_stl_are_rejected_with_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                end_header\n";
    let body = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    let cases: Vec<(String, &str)> = vec![
        (
            head.replace("ascii 1.0", "ascii 2.0") + body,
            ":2: bad format line",
        ),
        (
            head.replace("ascii 1.0", "ascii 1.0 x") + body,
            ":2: bad format line",
        ),
        (
            head.replace("property float z\n", "property float z\nproperty float x\n") + body,
            ":7: element 'vertex' declares property 'x' twice",
        ),
        (
            head.replace(
                "end_header",
                "element face 1\nproperty list uchar int vertex_indices\nend_header",
            ) + body,
            ":9: element 'face' is declared twice",
        ),
        (
            format!("{head}0 0 0\n1 0 0 5\n0 1 0\n3 0 1 2\n"),
            ":11: element 'vertex' number 1",
        ),
        (
            format!("{head}{body}9 9 9\n"),
            ":14: 6 byte(s) of data after the last element",
        ),
    ];
    for (k, (text, needle)) in cases.iter().enumerate() {
        let path = dir.path().join(format!("c{k}.ply"));
        std::fs::write(&path, text).unwrap();
        let e = Mesh::load(&path).unwrap_err().to_string();
        assert!(e.contains(&format!("c{k}.ply{needle}")), "case {k}: {e}");
    }
    // A final newline and blank lines after the last element are fine (writers add them).
    let path = dir.path().join("ok.ply");
    std::fs::write(&path, format!("{head}{body}\n\n")).unwrap();
    assert_eq!(Mesh::load(&path).unwrap().triangles, vec![[0, 1, 2]]);
    // Binary: bytes after the last element are an error (whitespace is not).
    let bin = |tail: &[u8]| {
        let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n\
                      property float y\nproperty float z\nend_header\n"
            .to_vec();
        b.extend([1f32, 2.0, 3.0].iter().flat_map(|x| x.to_le_bytes()));
        b.extend(tail);
        let path = dir.path().join("b.ply");
        std::fs::write(&path, b).unwrap();
        Mesh::load(&path)
    };
    assert_eq!(bin(b"\n").unwrap().vertices.len(), 1);
    let e = bin(b"\x01\x02").unwrap_err().to_string();
    assert!(
        e.contains("b.ply: at byte") && e.contains("after the last element"),
        "{e}"
    );
    // ASCII STL with invalid UTF-8 on line 4.
    let path = dir.path().join("bad.stl");
    std::fs::write(
        &path,
        b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0 \xff\nvertex 1 0 0\nvertex 0 1 0\n\
          endloop\nendfacet\nendsolid t\n",
    )
    .unwrap();
    let e = Mesh::load(&path).unwrap_err().to_string();
    assert!(e.contains("bad.stl:4: invalid UTF-8"), "{e}");
}

/// Defect 7: `--alpha-rel` on a one-vertex mesh did not name the file; coordinates near
/// +-3e38 failed with "--alpha must be a positive number (got 0)"; `field --preview
/// x.jpg` exited 0 without writing a JPEG.
#[test]
fn smaller_messages_name_the_real_problem() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("one.obj"), "v 1 2 3\n").unwrap();
    let o = run_in(
        dir.path(),
        &["query", "one.obj", "-p", "points", "--alpha-rel", "1"],
        "",
    );
    expect_error(&o, &["one.obj", "--alpha-rel", "non-zero bounding box"]);
    std::fs::write(dir.path().join("wide.obj"), "v 3e38 0 0\nv -3e38 1 1\n").unwrap();
    let o = run_in(
        dir.path(),
        &["query", "wide.obj", "-p", "points", "--alpha-rel", "1"],
        "",
    );
    expect_error(&o, &["wide.obj:1", "beyond the accepted"]);
    assert!(!stderr(&o).contains("got 0"));
    std::fs::write(
        dir.path().join("t.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let field = |preview: &str| {
        run_in(
            dir.path(),
            &[
                "field",
                "t.obj",
                "-p",
                "triangles",
                "--res",
                "8",
                "-o",
                "f.npy",
                "--preview",
                preview,
            ],
            "",
        )
    };
    let o = field("p.jpg");
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(dir.path().join("p.jpg")).unwrap();
    assert_eq!(
        image::guess_format(&bytes).unwrap(),
        image::ImageFormat::Jpeg
    );
    let o = field("p.gif");
    expect_error(&o, &["p.gif", "unsupported output format"]);
    assert!(
        !stderr(&o).contains("voxels"),
        "worked before failing: {}",
        stderr(&o)
    );
}
