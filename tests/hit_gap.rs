//! The render's report of how far the exact smooth distance may lie above the value its
//! hits were decided on (`render::hit_gap`): the interval it rests on brackets the exact
//! value (brute force) at the hit points; it flags a soft field over a dense mesh, whose
//! hits lie many epsilons outside the exact surface, and clears a stiff one; the CLI says
//! so in a note.

mod common;

use glam::{DVec3, Vec3};
use smoothtrace::eval::brute;
use smoothtrace::film::FilmOptions;
use smoothtrace::render::TracerOptions;
use smoothtrace::render::build::{BuiltScene, build_scene};
use smoothtrace::render::hit_gap::{HitGap, LOOSE};
use smoothtrace::render::image::{Rendered, render_film};
use smoothtrace::render::tracer::Tracer;
use smoothtrace::scene::Scene;
use std::path::Path;

/// A 96 x 48 torus (9,216 triangles) at `alpha_rel`, 96x54.
fn torus(alpha_rel: f64) -> Scene {
    let text = format!(
        "[[object]]\ngenerator = {{ kind = \"torus\", major_segments = 96, minor_segments = 48 }}\nprimitives = \"triangles\"\nalpha_rel = {alpha_rel}\n"
    );
    let mut s = Scene::from_str(&text, Path::new("torus.toml")).unwrap();
    s.image.width = 96;
    s.image.height = 54;
    s.render.threads = 2;
    s.validate().unwrap();
    s
}

/// Renders `s` with the hit gap asked for and the per-pixel records kept.
fn render(
    s: &Scene,
    options: impl Fn(TracerOptions) -> TracerOptions,
) -> (BuiltScene, Rendered, TracerOptions) {
    let built = build_scene(s).unwrap();
    let opts = options(built.tracer_options(s.render.max_steps));
    let tracer = Tracer::new(&built.objects, opts);
    let film = FilmOptions {
        keep_aovs: true,
        hit_gap: true,
        ..FilmOptions::default()
    };
    let r = render_film(
        &tracer,
        &built.camera,
        &built.shaders,
        &film,
        &|_| {},
        &|| false,
    )
    .unwrap();
    (built, r, opts)
}

fn gap(r: &Rendered) -> HitGap {
    r.stats.hit_gap.expect("a render with hits reports its gap")
}

#[test]
fn the_interval_brackets_the_exact_value_at_the_hits() {
    for alpha_rel in [60.0, 3000.0] {
        let s = torus(alpha_rel);
        let (built, r, opts) = render(&s, |o| o);
        let tracer = Tracer::new(&built.objects, opts);
        let obj = &built.objects[0];
        let sets = obj.set_refs();
        let records = &r.aovs.as_ref().unwrap().records;
        let hits: Vec<DVec3> = records
            .iter()
            .filter(|rec| rec.is_hit())
            .map(|rec| Vec3::from(rec.position).as_dvec3())
            .collect();
        assert!(hits.len() > 100, "{} hits", hits.len());
        for &x in hits.iter().step_by(hits.len() / 25) {
            let (lower, upper) = tracer.value_interval(x);
            let exact = brute::smooth_distance(&sets, x, obj.params.alpha, obj.params.max_alpha).0;
            let slack = 1e-9 * opts.epsilon;
            assert!(
                lower <= exact + slack && exact <= upper + slack,
                "alpha_rel {alpha_rel}: exact {exact} outside [{lower}, {upper}] at {x}"
            );
        }
    }
}

#[test]
fn a_soft_field_over_a_dense_mesh_is_flagged_and_a_stiff_one_is_not() {
    let (_, soft, _) = render(&torus(60.0), |o| o);
    let soft = gap(&soft);
    let (_, stiff, _) = render(&torus(3000.0), |o| o);
    let stiff = gap(&stiff);
    eprintln!("hit gap in epsilons: soft {soft:?}, stiff {stiff:?}");
    assert!(soft.loose() && soft.median > 5.0 * LOOSE, "soft: {soft:?}");
    assert!(!stiff.loose() && stiff.max < LOOSE, "stiff: {stiff:?}");
    assert!(soft.samples >= 20 && stiff.samples >= 20);
    // Certified hits are decided within an epsilon of the exact sum: no report.
    let (_, certified, _) = render(&torus(60.0), |o| TracerOptions {
        certified_hits: true,
        ..o
    });
    assert_eq!(certified.stats.hit_gap, None);
}

#[test]
fn the_cli_notes_loose_hits() {
    let dir = std::env::temp_dir().join(format!("smoothtrace_hit_gap_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("soft.toml");
    std::fs::write(
        &scene,
        "[image]\nwidth = 96\nheight = 54\n\n[[object]]\ngenerator = { kind = \"torus\", major_segments = 96, minor_segments = 48 }\nprimitives = \"triangles\"\nalpha_rel = 60\n",
    )
    .unwrap();
    let bin = || std::process::Command::new(env!("CARGO_BIN_EXE_smoothtrace"));
    let out = common::run_cli(
        bin(),
        &["render", "soft.toml", "-o", "soft.png"],
        &dir,
        None,
    );
    let text = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains("epsilons above the value they were decided on")
            && text.contains("--certified-hits"),
        "{text}"
    );
    let out = common::run_cli(
        bin(),
        &["render", "soft.toml", "-o", "soft.png", "--certified-hits"],
        &dir,
        None,
    );
    let text = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(
        out.status.success() && !text.contains("epsilons above"),
        "{text}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
