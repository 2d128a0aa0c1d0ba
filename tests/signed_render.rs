//! Signed offset surfaces in scenes (issue 32): what the scene file accepts and refuses
//! (each error naming the object's field and its line), the refusal of open meshes when
//! the scene is built, and rays against the analytic offset torus. The golden image is
//! in `tests/golden.rs` (`signed_torus.toml`).

use glam::DVec3;
use smoothtrace::render::build::build_scene;
use smoothtrace::render::{Tracer, TracerOptions};
use smoothtrace::scene::{Scene, SceneError, Surface};
use std::path::Path;

fn parse(text: &str) -> Result<Scene, SceneError> {
    Scene::from_str(text, Path::new("scenes/x.toml"))
}

const CAMERA: &str = "[camera]\norigin = [0.0, 1.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\n";

/// A torus object (lines 4-) with `extra` keys.
fn torus(extra: &str) -> String {
    format!(
        "{CAMERA}[[object]]\ngenerator = {{ kind = \"torus\" }}\nprimitives = \"triangles\"\n{extra}"
    )
}

#[track_caller]
fn refused(text: &str, parts: &[&str]) {
    let e = parse(text).map(|_| ()).unwrap_err().to_string();
    for p in parts {
        assert!(e.contains(p), "{e:?} should contain {p:?}");
    }
}

#[test]
fn scenes_ask_for_signed_surfaces() {
    let s = parse(&torus("surface = \"signed\"\noffset = -0.05\n")).unwrap();
    assert_eq!(s.objects[0].surface, Surface::Signed { offset: -0.05 });
    let s = parse(&torus("surface = \"signed\"\n")).unwrap();
    assert_eq!(s.objects[0].surface, Surface::Signed { offset: 0.0 });
    let s = parse(&torus("alpha = 300\nsurface = \"smooth\"\n")).unwrap();
    assert_eq!(s.objects[0].surface, Surface::Smooth);
}

#[test]
fn bad_signed_surfaces_are_named() {
    refused(
        &torus("surface = \"sdf\"\n"),
        &[
            ":7:",
            "object[0].surface",
            "\"smooth\"",
            "\"signed\"",
            "sdf",
        ],
    );
    refused(
        &torus("alpha = 300\noffset = 0.1\n"),
        &[":8:", "object[0].offset", "surface = \"signed\""],
    );
    refused(
        &torus("surface = \"signed\"\nalpha = 300\n"),
        &[":8:", "object[0].alpha", "drop alpha"],
    );
    refused(
        &torus("surface = \"signed\"\noffset = nan\n"),
        &[":8:", "object[0].offset", "finite"],
    );
    refused(
        &torus("surface = \"signed\"\n").replace("\"triangles\"", "[\"triangles\", \"edges\"]"),
        &[":6:", "object[0].primitives", "triangles"],
    );
    let points = format!(
        "{CAMERA}[[object]]\ngenerator = {{ kind = \"sphere_points\" }}\nprimitives = \"points\"\nsurface = \"signed\"\n"
    );
    refused(&points, &["object[0].primitives", "winding number"]);
}

#[test]
fn open_meshes_are_refused_when_built() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("open.obj");
    std::fs::write(
        &mesh,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n",
    )
    .unwrap();
    let text = format!(
        "{CAMERA}[[object]]\nmesh = \"open.obj\"\nprimitives = \"triangles\"\nsurface = \"signed\"\n"
    );
    let scene = Scene::from_str(&text, &dir.path().join("s.toml")).unwrap();
    let e = build_scene(&scene).map(|_| ()).unwrap_err().to_string();
    for p in ["object[0]", "closed triangle mesh", "3 boundary edges"] {
        assert!(e.contains(p), "{e:?} should contain {p:?}");
    }
}

/// Rays towards the torus (major radius 1, tube 0.25, in the xz plane) stop on the
/// offset tube `|x - ring| = 0.25 + offset` (the polygon lies within 1% of the tube).
#[test]
fn rays_hit_the_offset_tube() {
    for offset in [-0.1, 0.0, 0.2] {
        let text = torus(&format!("surface = \"signed\"\noffset = {offset}\n"));
        let scene = parse(&text).unwrap();
        scene.validate().unwrap();
        let built = build_scene(&scene).unwrap();
        let options = TracerOptions::new(built.epsilon, scene.render.max_steps);
        let tracer = Tracer::new(&built.objects, options);
        for (o, d) in [
            (DVec3::new(1.0, 3.0, 0.0), -DVec3::Y),
            (DVec3::new(3.0, 0.05, 0.1), -DVec3::X),
            (DVec3::new(0.7, 2.0, 0.7), DVec3::new(0.0, -1.0, 0.0)),
        ] {
            let hit = tracer.trace(o, d, 0.0).hit.expect("a hit");
            let ring = DVec3::new(hit.point.x, 0.0, hit.point.z).normalize();
            let tube = (hit.point - ring).length();
            assert!(
                (tube - (0.25 + offset)).abs() < 0.01,
                "offset {offset}, ray from {o}: hit at {} is {tube} from the ring",
                hit.point
            );
            assert!(hit.normal.dot((hit.point - ring).normalize()) > 0.98);
        }
    }
}
