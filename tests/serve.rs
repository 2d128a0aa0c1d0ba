//! `smoothtrace serve` over HTTP on a loopback port (the built binary, `--port 0`, the
//! port read from the URL it prints): render passes are PNGs of the asked size, a probe
//! equals `smoothtrace query` at the hit point, bad values answer 400 with the command
//! line's messages, names outside the scene's folder 403, a newer view cancels an older
//! render (409), a saved TOML renders the image the server rendered, published JSON
//! scenes render like their TOML equivalents, Ctrl-C stops the server.

mod common;

use serde_json::{Value, json};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_smoothtrace");

/// A bumpy sphere (triangles) as OBJ text.
fn sphere_obj() -> String {
    let m = common::bumpy_sphere(12, 24);
    let mut s = String::new();
    for v in &m.vertices {
        s += &format!("v {} {} {}\n", v.x, v.y, v.z);
    }
    for t in &m.triangles {
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

const SCENE: &str = r#"
[camera]
origin = [0.3, 0.8, 3.5]
target = [0.0, 0.0, 0.0]

[image]
width = 160
height = 120

[render]
beta = 0.5
epsilon_rel = 4e-4

[[object]]
mesh = "sphere.obj"
primitives = "triangles"
alpha = 40.0
max_alpha = 80.0
matcap = "clay"
"#;

/// A folder with `sphere.obj` and `scene.toml`.
fn fixture() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("sphere.obj"), sphere_obj()).unwrap();
    std::fs::write(dir.path().join("scene.toml"), SCENE).unwrap();
    dir
}

/// A running `smoothtrace serve`, stopped with SIGINT when dropped.
struct Served {
    child: Child,
    addr: SocketAddr,
}

impl Served {
    fn start(dir: &Path, args: &[&str]) -> Served {
        let mut child = Command::new(BIN)
            .arg("serve")
            .args(args)
            .args(["--port", "0"])
            .current_dir(dir)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        let Some(url) = line.split_whitespace().find(|w| w.starts_with("http://")) else {
            let mut err = String::new();
            child
                .stderr
                .take()
                .unwrap()
                .read_to_string(&mut err)
                .unwrap();
            panic!("serve printed no URL: {line:?}, stderr: {err}");
        };
        let addr = url
            .trim_start_matches("http://")
            .trim_end_matches('/')
            .parse()
            .unwrap();
        Served { child, addr }
    }

    fn request(&self, method: &str, path: &str, body: &[u8]) -> (u16, String, Vec<u8>) {
        http(self.addr, method, path, body)
    }

    fn post(&self, path: &str, body: &Value) -> (u16, String, Vec<u8>) {
        self.request("POST", path, body.to_string().as_bytes())
    }

    /// The page's starting view.
    fn view(&self) -> Value {
        let (status, _, body) = self.request("GET", "/api/scene", b"");
        assert_eq!(status, 200);
        let info: Value = serde_json::from_slice(&body).unwrap();
        info["view"].clone()
    }

    /// Sends SIGINT and returns the exit status and standard error.
    fn interrupt(mut self) -> (std::process::ExitStatus, String) {
        interrupt(&self.child);
        let status = wait(&mut self.child);
        let mut err = String::new();
        self.child
            .stderr
            .take()
            .unwrap()
            .read_to_string(&mut err)
            .unwrap();
        (status, err)
    }
}

fn interrupt(child: &Child) {
    let ok = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(ok.success());
}

fn wait(child: &mut Child) -> std::process::ExitStatus {
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        if start.elapsed() > Duration::from_secs(60) {
            child.kill().unwrap();
            panic!("serve did not stop within 60 s of SIGINT");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

impl Drop for Served {
    fn drop(&mut self) {
        if self.child.try_wait().unwrap().is_none() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// One HTTP/1.1 request (`Connection: close`): status, headers, body.
fn http(addr: SocketAddr, method: &str, path: &str, body: &[u8]) -> (u16, String, Vec<u8>) {
    let mut s = TcpStream::connect(addr).unwrap();
    write!(
        s,
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\nContent-Length: {}\r\n\r\n",
        body.len()
    )
    .unwrap();
    s.write_all(body).unwrap();
    let mut raw = Vec::new();
    s.read_to_end(&mut raw).unwrap();
    let split = raw
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .expect("a complete HTTP response");
    let head = String::from_utf8_lossy(&raw[..split]).to_string();
    let status = head.split_whitespace().nth(1).unwrap().parse().unwrap();
    (status, head, raw[split + 4..].to_vec())
}

fn text(body: &[u8]) -> String {
    String::from_utf8_lossy(body).to_string()
}

fn png(body: &[u8]) -> image::RgbImage {
    image::load_from_memory_with_format(body, image::ImageFormat::Png)
        .expect("a PNG")
        .to_rgb8()
}

fn with(view: &Value, patch: Value) -> Value {
    let mut v = view.clone();
    for (k, x) in patch.as_object().unwrap() {
        v[k] = x.clone();
    }
    v
}

fn render_cli(dir: &Path, args: &[&str]) -> std::process::Output {
    common::run_cli(Command::new(BIN), args, dir, None)
}

#[test]
fn render_returns_a_png_of_the_asked_size() {
    let dir = fixture();
    let s = Served::start(dir.path(), &["scene.toml"]);
    let view = s.view();
    for (w, h, scale, ew, eh) in [
        (200, 100, 1, 200, 100),
        (200, 100, 8, 25, 13),
        (37, 5, 2, 19, 3),
    ] {
        let (status, head, body) = s.post(
            "/api/render",
            &with(&view, json!({"width": w, "height": h, "scale": scale})),
        );
        assert_eq!(status, 200, "{}", text(&body));
        assert!(head.contains("image/png"), "{head}");
        let img = png(&body);
        assert_eq!(img.dimensions(), (ew, eh), "{w}x{h} at 1/{scale}");
    }
    // The full pass shows the sphere: the centre is shaded, a corner is background.
    let (_, _, body) = s.post("/api/render", &with(&view, json!({"scale": 1})));
    let img = png(&body);
    assert_ne!(img.get_pixel(80, 60).0, [255, 255, 255]);
    assert_eq!(img.get_pixel(0, 0).0, [255, 255, 255]);
    // The depth view: hits in grey, nearer brighter.
    let (status, _, body) = s.post("/api/render", &with(&view, json!({"aov": "depth"})));
    assert_eq!(status, 200, "{}", text(&body));
    let d = png(&body);
    let c = d.get_pixel(80, 60).0;
    assert!(c[0] == c[1] && c[1] == c[2] && c[0] > 100, "{c:?}");
    // Anti-aliasing and the AOV views are the command line's images.
    let cli = render_cli(
        dir.path(),
        &[
            "render",
            "scene.toml",
            "-o",
            "aa.png",
            "--samples",
            "4",
            "--aov",
            "normal=n.png",
            "--aov",
            "id=id.png",
            "--aov",
            "cost=cost.png",
        ],
    );
    assert!(cli.status.success(), "{}", text(&cli.stderr));
    let rgba = |body: &[u8]| {
        image::load_from_memory_with_format(body, image::ImageFormat::Png)
            .expect("a PNG")
            .to_rgba8()
    };
    let file = |name: &str| image::open(dir.path().join(name)).unwrap().to_rgba8();
    for (patch, name) in [
        (json!({"scale": 1, "samples": 4}), "aa.png"),
        (json!({"scale": 1, "samples": 4, "aov": "normal"}), "n.png"),
        (json!({"scale": 1, "samples": 4, "aov": "id"}), "id.png"),
        (json!({"scale": 1, "samples": 4, "aov": "cost"}), "cost.png"),
    ] {
        let (status, _, body) = s.post("/api/render", &with(&view, patch.clone()));
        assert_eq!(status, 200, "{patch}: {}", text(&body));
        assert!(rgba(&body) == file(name), "{patch} differs from {name}");
    }
    // Positions as colours: opaque on the sphere, transparent where rays miss.
    let (status, _, body) = s.post(
        "/api/render",
        &with(&view, json!({"scale": 1, "aov": "position"})),
    );
    assert_eq!(status, 200, "{}", text(&body));
    let p = rgba(&body);
    assert_eq!((p.get_pixel(80, 60).0[3], p.get_pixel(0, 0).0[3]), (255, 0));
}

#[test]
fn probe_equals_query_at_the_hit_point() {
    let dir = fixture();
    let s = Served::start(dir.path(), &["scene.toml"]);
    let view = s.view();
    for (x, y) in [(80.5, 60.5), (60.25, 40.75), (101.5, 77.5)] {
        let (status, _, body) = s.post("/api/probe", &with(&view, json!({"x": x, "y": y})));
        assert_eq!(status, 200, "{}", text(&body));
        let p: Value = serde_json::from_slice(&body).unwrap();
        assert_eq!(p["hit"], true, "{p}");
        let point: Vec<f64> = serde_json::from_value(p["point"].clone()).unwrap();
        assert!(p["evals"].as_u64().unwrap() >= 1 && p["leaves"].as_u64().unwrap() >= 1);
        assert_eq!(p["nearest_kind"], "triangles");
        // The hit is on the surface: |s| within the hit threshold (4e-4 of the diagonal).
        let sval = p["s"].as_f64().unwrap();
        assert!(sval.abs() <= 4e-4 * 2.0 * 3f64.sqrt() * 1.2, "s = {sval}");
        let stdin_query = {
            let mut child = Command::new(BIN)
                .args([
                    "query",
                    "sphere.obj",
                    "--primitive",
                    "triangles",
                    "--alpha",
                    "40",
                    "--max-alpha",
                    "80",
                    "--beta",
                    "0.5",
                ])
                .current_dir(dir.path())
                .stdin(Stdio::piped())
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap();
            writeln!(
                child.stdin.take().unwrap(),
                "{:?} {:?} {:?}",
                point[0],
                point[1],
                point[2]
            )
            .unwrap();
            child.wait_with_output().unwrap()
        };
        assert!(
            stdin_query.status.success(),
            "{}",
            text(&stdin_query.stderr)
        );
        let out: Vec<f64> = text(&stdin_query.stdout)
            .split_whitespace()
            .map(|w| w.parse().unwrap())
            .collect();
        let probe = [
            sval,
            p["gradient"][0].as_f64().unwrap(),
            p["gradient"][1].as_f64().unwrap(),
            p["gradient"][2].as_f64().unwrap(),
            p["distance"].as_f64().unwrap(),
            p["query_leaves"].as_f64().unwrap(),
        ];
        for (name, (a, b)) in ["s", "gx", "gy", "gz", "distance", "leaves"]
            .iter()
            .zip(probe.iter().zip(&out))
        {
            assert!(
                (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1e-300),
                "{name}: probe {a}, query {b}, difference {}",
                a - b
            );
        }
        // The nearest point is at the exact distance from the hit.
        let np: Vec<f64> = serde_json::from_value(p["nearest_point"].clone()).unwrap();
        let d =
            ((np[0] - point[0]).powi(2) + (np[1] - point[1]).powi(2) + (np[2] - point[2]).powi(2))
                .sqrt();
        assert!((d - probe[4]).abs() <= 1e-9, "{d} vs {}", probe[4]);
    }
    // A ray into the empty corner misses.
    let (_, _, body) = s.post("/api/probe", &with(&view, json!({"x": 0.5, "y": 0.5})));
    let p: Value = serde_json::from_slice(&body).unwrap();
    assert_eq!(p["hit"], false, "{p}");
}

#[test]
fn bad_values_get_400_with_the_command_lines_messages() {
    let dir = fixture();
    let s = Served::start(dir.path(), &["scene.toml"]);
    let view = s.view();
    // The same check as `render --beta 2`, named as a key instead of a flag.
    let (status, _, body) = s.post("/api/render", &with(&view, json!({"beta": 2.0})));
    assert_eq!(status, 400);
    let cli = render_cli(
        dir.path(),
        &["render", "scene.toml", "-o", "x.png", "--beta", "2"],
    );
    assert_eq!(cli.status.code(), Some(2));
    let message = text(&body);
    assert_eq!(message, "beta must be in [0, 1] (got 2)");
    assert!(
        text(&cli.stderr).contains(&format!("--{message}")),
        "{}",
        text(&cli.stderr)
    );
    let (status, _, body) = s.post("/api/render", &with(&view, json!({"width": 0})));
    assert_eq!(
        (status, text(&body).as_str()),
        (400, "width must be in 1..=16384 (got 0)")
    );
    let cli = render_cli(
        dir.path(),
        &["render", "scene.toml", "-o", "x.png", "--width", "0"],
    );
    assert!(text(&cli.stderr).contains("--width must be in 1..=16384 (got 0)"));
    let mut bad_alpha = view.clone();
    bad_alpha["objects"][0]["alpha"] = json!(-1.0);
    let (status, _, body) = s.post("/api/render", &bad_alpha);
    assert_eq!(status, 400);
    assert_eq!(text(&body), "object[0].alpha must be > 0 (got -1)");
    let cases = [
        (
            json!({"width": 5000}),
            "width must be in 1..=4096 here (got 5000)",
        ),
        (
            json!({"samples": 1000}),
            "samples must be in 1..=64 (got 1000)",
        ),
        (json!({"aov": "albedo"}), "unknown variant `albedo`"),
        (json!({"scale": 0}), "scale must be in 1..=16 (got 0)"),
        (
            json!({"camera": {"origin": [0, 0, 0], "target": [0, 0, 0], "up": [0, 1, 0], "fov": 50}}),
            "camera.origin and camera.target are the same point",
        ),
        (
            json!({"objects": []}),
            "the scene has 1 object(s), the request gives 0",
        ),
    ];
    for (patch, expected) in cases {
        let (status, _, body) = s.post("/api/render", &with(&view, patch.clone()));
        assert_eq!(status, 400, "{patch}");
        assert!(text(&body).contains(expected), "{patch}: {}", text(&body));
    }
    let (status, _, body) = s.request("POST", "/api/render", b"{not json");
    assert_eq!(status, 400);
    assert!(
        text(&body).starts_with("bad request body:"),
        "{}",
        text(&body)
    );
    let (status, _, _) = s.request("POST", "/api/render", &vec![b' '; 100_000]);
    assert_eq!(status, 413);
    let (status, _, _) = s.request("GET", "/nothing", b"");
    assert_eq!(status, 404);
    let (status, _, _) = s.request("GET", "/api/render", b"");
    assert_eq!(status, 405);
    // A MatCap that fails to load is a 400 too, and the server goes on.
    std::fs::write(dir.path().join("broken.png"), b"not a png").unwrap();
    let mut broken = view.clone();
    broken["objects"][0]["matcap"] = json!("broken.png");
    let (status, _, body) = s.post("/api/render", &broken);
    assert_eq!(status, 400, "{}", text(&body));
    assert!(text(&body).contains("broken.png"), "{}", text(&body));
    let (status, _, _) = s.post("/api/render", &with(&view, json!({"scale": 8})));
    assert_eq!(status, 200);
}

#[test]
fn names_outside_the_scene_folder_are_refused() {
    let dir = fixture();
    let outside = tempfile::tempdir().unwrap();
    let matcap = image::RgbImage::from_pixel(4, 4, image::Rgb([200, 10, 10]));
    matcap.save(outside.path().join("red.png")).unwrap();
    matcap.save(dir.path().join("red.png")).unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink(outside.path().join("red.png"), dir.path().join("link.png"))
        .unwrap();
    let s = Served::start(dir.path(), &["scene.toml", "--save", "saved.toml"]);
    let view = s.view();
    let abs = outside.path().join("red.png").display().to_string();
    let escape = format!(
        "../{}/red.png",
        outside.path().file_name().unwrap().to_string_lossy()
    );
    let mut names = vec![abs.as_str(), escape.as_str()];
    if cfg!(unix) {
        names.push("link.png");
    }
    for name in names {
        let mut v = view.clone();
        v["objects"][0]["matcap"] = json!(name);
        let (status, _, body) = s.post("/api/render", &v);
        assert_eq!(status, 403, "{name}: {}", text(&body));
        assert!(
            text(&body).contains("only files inside the scene's folder"),
            "{}",
            text(&body)
        );
    }
    // A MatCap inside the folder is used.
    let mut v = view.clone();
    v["objects"][0]["matcap"] = json!("red.png");
    let (status, _, body) = s.post("/api/render", &v);
    assert_eq!(status, 200, "{}", text(&body));
    let c = png(&body).get_pixel(80, 60).0;
    assert_eq!(c, [200, 10, 10]);
    for name in [
        "../escape.toml",
        "/tmp/escape.toml",
        "sub/../../escape.toml",
    ] {
        let (status, _, body) = s.post("/api/save", &with(&view, json!({"save_as": name})));
        assert_eq!(status, 403, "{name}: {}", text(&body));
    }
    assert!(!dir.path().parent().unwrap().join("escape.toml").exists());
    // Without --save nothing is written on the server.
    let s2 = Served::start(dir.path(), &["scene.toml"]);
    let (status, _, body) = s2.post("/api/save", &with(&view, json!({"save_as": "saved.toml"})));
    assert_eq!(status, 403, "{}", text(&body));
    assert!(!dir.path().join("saved.toml").exists());
    // `--save` itself must be inside the folder.
    let bad = render_cli(
        dir.path(),
        &["serve", "scene.toml", "--port", "0", "--save", "../x.toml"],
    );
    assert_eq!(bad.status.code(), Some(2));
    assert!(
        text(&bad.stderr).contains("--save ../x.toml"),
        "{}",
        text(&bad.stderr)
    );
}

#[test]
fn a_newer_view_cancels_an_older_render() {
    let dir = fixture();
    let s = Served::start(dir.path(), &["scene.toml"]);
    let view = s.view();
    let status = |s: &Served| -> Value {
        let (_, _, body) = s.request("GET", "/api/status", b"");
        serde_json::from_slice(&body).unwrap()
    };
    // A slow pass: 4096 x 4096 with every step at the exact sum.
    let slow = with(&view, json!({"width": 4096, "height": 4096, "beta": 0.0}));
    let addr = s.addr;
    let older =
        std::thread::spawn(move || http(addr, "POST", "/api/render", slow.to_string().as_bytes()));
    let start = Instant::now();
    while status(&s)["renders_started"].as_u64() != Some(1) {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "the slow render did not start"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    let (newer, _, body) = s.post("/api/render", &with(&view, json!({"scale": 8})));
    assert_eq!(newer, 200, "{}", text(&body));
    let (older_status, _, body) = older.join().unwrap();
    assert_eq!(older_status, 409, "{}", text(&body));
    assert_eq!(text(&body), "cancelled: a newer view was requested");
    let st = status(&s);
    assert_eq!(st["renders_cancelled"], 1, "{st}");
    assert_eq!(st["renders_finished"], 1, "{st}");
    // A "keep" render (the full PNG download) is not cancelled by newer views.
    let kept = with(
        &view,
        json!({"width": 1024, "height": 1024, "beta": 0.0, "keep": true}),
    );
    let kept =
        std::thread::spawn(move || http(addr, "POST", "/api/render", kept.to_string().as_bytes()));
    let start = Instant::now();
    while status(&s)["renders_started"].as_u64() != Some(3) {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "the kept render did not start"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    assert_eq!(
        s.post("/api/render", &with(&view, json!({"scale": 8}))).0,
        200
    );
    let (kept_status, _, body) = kept.join().unwrap();
    assert_eq!(kept_status, 200, "{}", text(&body));
    assert_eq!(png(&body).dimensions(), (1024, 1024));
    assert_eq!(status(&s)["renders_cancelled"], 1);
    // Parameter changes reuse the build; a new primitive kind rebuilds it.
    assert_eq!(st["builds"], 1, "{st}");
    let mut v = with(&view, json!({"scale": 8}));
    v["objects"][0]["alpha"] = json!(60.0);
    assert_eq!(s.post("/api/render", &v).0, 200);
    assert_eq!(status(&s)["builds"], 1);
    v["objects"][0]["primitives"] = json!(["triangles", "edges"]);
    assert_eq!(s.post("/api/render", &v).0, 200);
    assert_eq!(status(&s)["builds"], 2);
}

#[test]
fn a_saved_scene_renders_the_image_the_server_rendered() {
    let dir = fixture();
    let s = Served::start(dir.path(), &["scene.toml", "--save", "saved.toml"]);
    let (_, _, info) = s.request("GET", "/api/scene", b"");
    let info: Value = serde_json::from_slice(&info).unwrap();
    assert_eq!(info["save_as"], "saved.toml", "the page's suggested name");
    let mut view = s.view();
    view["camera"]["origin"] = json!([2.0, 1.5, 2.5]);
    view["objects"][0]["alpha"] = json!(25.0);
    view["objects"][0]["matcap"] = json!("gold");
    view["beta"] = json!(0.3);
    let (status, head, served) = s.post("/api/render", &with(&view, json!({"keep": true})));
    assert_eq!(status, 200, "{head}");
    let (status, head, downloaded) = s.post("/api/save", &view);
    assert_eq!(status, 200, "{head}");
    assert!(head.contains("attachment"), "{head}");
    let (status, _, written) = s.post("/api/save", &with(&view, json!({"save_as": "saved.toml"})));
    assert_eq!(status, 200);
    assert_eq!(
        std::fs::read(dir.path().join("saved.toml")).unwrap(),
        written
    );
    assert_eq!(downloaded, written, "download and server copy differ");
    let out = render_cli(dir.path(), &["render", "saved.toml", "-o", "cli.png"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let cli = image::open(dir.path().join("cli.png")).unwrap().to_rgb8();
    assert_eq!(cli, png(&served), "the saved scene renders differently");
    // And it differs from the starting view (the edits were saved).
    let start = render_cli(dir.path(), &["render", "scene.toml", "-o", "start.png"]);
    assert!(start.status.success());
    assert_ne!(
        image::open(dir.path().join("start.png")).unwrap().to_rgb8(),
        cli
    );
}

const JSON_SCENE: &str = r#"{"camera":{"dest":[0.0,0.0,0.0],"origin":[0.3,0.8,3.5],"up":[0.0,1.0,0.0]},"objects":[{"alpha":40.0,"bvh_type":"faces","matcap":"","max_alpha":80.0,"path":"sphere.obj"}]}"#;

#[test]
fn published_json_scenes_render_like_their_toml() {
    let dir = fixture();
    std::fs::write(dir.path().join("published.json"), JSON_SCENE).unwrap();
    // The same scene in TOML: the JSON gives no size, fov or settings (the defaults).
    std::fs::write(
        dir.path().join("same.toml"),
        "[camera]\norigin = [0.3, 0.8, 3.5]\ntarget = [0.0, 0.0, 0.0]\n\n[[object]]\nmesh = \"sphere.obj\"\nprimitives = \"triangles\"\nalpha = 40.0\nmax_alpha = 80.0\n",
    )
    .unwrap();
    let size = ["--width", "160", "--height", "90"];
    let a = render_cli(
        dir.path(),
        &[&["render", "published.json", "-o", "a.png"][..], &size].concat(),
    );
    assert!(a.status.success(), "{}", text(&a.stderr));
    let b = render_cli(
        dir.path(),
        &[&["render", "same.toml", "-o", "b.png"][..], &size].concat(),
    );
    assert!(b.status.success(), "{}", text(&b.stderr));
    let (a, b) = (
        image::open(dir.path().join("a.png")).unwrap().to_rgb8(),
        image::open(dir.path().join("b.png")).unwrap().to_rgb8(),
    );
    assert_eq!(a, b);
    assert!(a.pixels().any(|p| p.0 != [255, 255, 255]), "nothing drawn");
    // serve opens it too, and saves it as TOML.
    let s = Served::start(dir.path(), &["published.json"]);
    let (status, _, toml) = s.post("/api/save", &s.view());
    assert_eq!(status, 200);
    assert!(
        text(&toml).contains("mesh = \"sphere.obj\""),
        "{}",
        text(&toml)
    );
    // A bad JSON scene names the file, line and key.
    std::fs::write(dir.path().join("bad.json"), "{\"camera\":{\"dest\":[0,0,0],\"origin\":[0,0,1]},\n\"objects\":[{\"alpha\":1,\"bvh_type\":\"cubes\",\"path\":\"sphere.obj\"}]}").unwrap();
    let bad = render_cli(dir.path(), &["render", "bad.json", "-o", "c.png"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(
        text(&bad.stderr).contains("bad.json:2:"),
        "{}",
        text(&bad.stderr)
    );
    assert!(text(&bad.stderr).contains("cubes"), "{}", text(&bad.stderr));
}

#[test]
fn the_example_json_scene_renders_like_the_bunny_toml() {
    let Some(bunny) = common::data_file("bunny-7k.obj") else {
        return;
    };
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    let json: Value = serde_json::from_str(
        &std::fs::read_to_string(root.join("scenes/bunny_published.json")).unwrap(),
    )
    .unwrap();
    let o = &json["objects"][0];
    let c = &json["camera"];
    let toml = format!(
        "[camera]\norigin = {}\ntarget = {}\nup = {}\n\n[[object]]\nmesh = {:?}\nprimitives = \"triangles\"\nalpha = {}\nmax_alpha = {}\n",
        c["origin"],
        c["dest"],
        c["up"],
        bunny.display().to_string(),
        o["alpha"],
        o["max_alpha"]
    );
    std::fs::write(dir.path().join("bunny.toml"), toml).unwrap();
    let size = ["--width", "120", "--height", "90"];
    let json_png = dir.path().join("a.png").display().to_string();
    let a = render_cli(
        &root,
        &[
            &["render", "scenes/bunny_published.json", "-o", &json_png][..],
            &size,
        ]
        .concat(),
    );
    assert!(a.status.success(), "{}", text(&a.stderr));
    let b = render_cli(
        dir.path(),
        &[&["render", "bunny.toml", "-o", "b.png"][..], &size].concat(),
    );
    assert!(b.status.success(), "{}", text(&b.stderr));
    let (a, b) = (
        image::open(&json_png).unwrap().to_rgb8(),
        image::open(dir.path().join("b.png")).unwrap().to_rgb8(),
    );
    assert_eq!(a, b);
    assert!(
        a.pixels().filter(|p| p.0 != [255, 255, 255]).count() > 500,
        "no bunny"
    );
}

#[test]
fn a_bare_mesh_is_framed_and_ctrl_c_stops_the_server() {
    let dir = fixture();
    let s = Served::start(dir.path(), &["sphere.obj", "--host", "0.0.0.0"]);
    let view = s.view();
    assert_eq!(view["objects"][0]["primitives"], json!(["triangles"]));
    let (status, _, body) = s.post(
        "/api/render",
        &with(&view, json!({"width": 160, "height": 120})),
    );
    assert_eq!(status, 200, "{}", text(&body));
    let img = png(&body);
    // The default camera frames the whole object: hits at the centre, none on the border.
    assert_ne!(img.get_pixel(80, 60).0, [255, 255, 255]);
    let (w, h) = img.dimensions();
    let border = (0..w)
        .flat_map(|x| [(x, 0), (x, h - 1)])
        .chain((0..h).flat_map(|y| [(0, y), (w - 1, y)]));
    for (x, y) in border {
        assert_eq!(
            img.get_pixel(x, y).0,
            [255, 255, 255],
            "hit on the border at ({x}, {y})"
        );
    }
    let (status, err) = s.interrupt();
    assert!(status.success(), "{status:?}: {err}");
    assert!(err.contains("warning: listening on 0.0.0.0"), "{err}");
    assert!(err.contains("smoothtrace serve: stopped"), "{err}");
}
