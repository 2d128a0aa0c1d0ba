//! The tracer's shortcuts against the plain tracer, and the scene's beta against the
//! exact sum (issue 9).
//!
//! - Cone marching of tiles (`render::cone`) must find the same surface as tracing every
//!   ray on its own: the same hit mask up to rays that graze the surface within epsilon
//!   (at most 0.5% of the rays), and depths that agree within the hit band (99% of the
//!   rays hitting in both within 4 epsilon). Thin features (the net's and hex torus'
//!   tubes, the bucky ball's struts, the spiky sphere's spikes) are where a skipped
//!   surface would show. Over-relaxed steps (`TracerOptions::relax`) likewise against
//!   plain sphere-tracing steps, steps by the free distance from the terms' slopes
//!   (`TracerOptions::reach_steps`, point clouds) against plain steps, relaxed steps
//!   certified by the free distance behind the next sample (`TracerOptions::reach_behind`,
//!   point clouds) against its ball alone, and rays started
//!   past their neighbours' empty balls (`TracerOptions::neighbours`) against rays that
//!   only use their own.
//! - At beta 0.5 the rendered surface stays close to the exact (beta 0) one: median depth
//!   error at most 0.1% of the scene's diagonal on the procedural scenes and the bunny,
//!   and on the full bunny's edges at its native size, whose hits are decided at a finer
//!   beta (`TracerOptions::hit_beta_scale_edges`): more than twice as close as at the
//!   scene's beta alone (0.9% with leaves of four edges, 0.016% with eight).
//! - Triangle meshes take at most two full evaluations per hit ray (issue 9).
//! - The final step (`TracerOptions::final_step`) moves hits closer to the exact zero
//!   set, never past it.
//! - The tracer's pruning tolerance (tied to epsilon) keeps every value a lower bound of
//!   the exact smooth distance, within `2 tol / alpha`.

mod common;

use glam::DVec3;
use smoothtrace::eval::{EvalParams, brute, evaluate_value};
use smoothtrace::render::TracerOptions;
use smoothtrace::render::build::{BuildError, build_scene};
use smoothtrace::render::image::Rendered;
use smoothtrace::render::pipeline::{in_pool, render_built, render_scene};
use smoothtrace::render::tracer::{RayStats, Tracer};
use smoothtrace::reports::compare::{DepthDiff, compare_depths};
use smoothtrace::scene::Scene;
use std::path::PathBuf;

fn scene(name: &str, width: u32, height: u32) -> Scene {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    let mut s = Scene::load(&path).unwrap();
    s.image.width = width;
    s.image.height = height;
    s.render.threads = 2;
    s.validate().unwrap();
    s
}

fn render(
    s: &Scene,
    options: impl Fn(TracerOptions) -> TracerOptions + Send + Sync,
) -> (f64, f64, Rendered) {
    let (built, r) = render_scene(s, options, &|_| {}).unwrap();
    (built.epsilon, built.bounds.diagonal(), r)
}

/// Procedural scenes with thin features, where a skipped surface would show.
const THIN: [&str; 6] = [
    "torus.toml",
    "net.toml",
    "hex_torus.toml",
    "bucky_ball.toml",
    "spiky_sphere.toml",
    "bowl.toml",
];

/// Renders `name` with the tracer defaults and with `off` applied (a shortcut turned
/// off): same hit mask up to grazing rays, same depths within the hit band. Returns both.
fn same_surface(
    name: &str,
    off: impl Fn(TracerOptions) -> TracerOptions + Send + Sync,
) -> (Rendered, Rendered) {
    same_surface_from(name, |o| o, off)
}

/// [`same_surface`] from the tracer settings `base` instead of the defaults.
fn same_surface_from(
    name: &str,
    base: impl Fn(TracerOptions) -> TracerOptions + Send + Sync + Copy,
    off: impl Fn(TracerOptions) -> TracerOptions + Send + Sync,
) -> (Rendered, Rendered) {
    let s = scene(name, 240, 135);
    let (eps, _, on) = render(&s, base);
    let (_, _, plain) = render(&s, |o| off(base(o)));
    // Depths in units of epsilon.
    let d = compare_depths(&on.depth, &plain.depth, 1.0, eps);
    let only_one = d.only_one_percent();
    assert!(
        only_one <= 0.5,
        "{name}: {only_one:.3}% of the rays hit in only one of the renders ({d:?})"
    );
    let p99 = d.p99.unwrap_or(0.0);
    assert!(
        p99 <= 4.0,
        "{name}: 99th percentile depth difference {p99} epsilon"
    );
    (on, plain)
}

/// Asserts that a shortcut does what it is for: fewer of `what` with it (`on`) than
/// without it (`off`).
fn fewer(name: &str, what: &str, on: u64, off: u64) {
    assert!(
        on < off,
        "{name}: {on} {what} with the shortcut, {off} without"
    );
}

/// Full evaluations and bound steps of a render, together.
fn all(r: &Rendered) -> u64 {
    r.stats.evals + r.stats.coarse_evals
}

#[test]
fn cone_marching_finds_the_surface_every_ray_finds() {
    for name in THIN {
        let (cone, plain) = same_surface(name, |o| TracerOptions { cone: false, ..o });
        assert!(cone.stats.tile_evals > 0, "{name}: no tile was marched");
        assert_eq!(plain.stats.tile_evals, 0);
        // The point of it: fewer bound evaluations per ray in all.
        fewer(
            name,
            "bound evaluations",
            cone.stats.coarse_evals,
            plain.stats.coarse_evals,
        );
    }
}

#[test]
fn neighbours_balls_find_the_surface_every_ray_finds() {
    for name in THIN {
        let (shared, own) = same_surface(name, |o| TracerOptions {
            neighbours: false,
            ..o
        });
        // The point of it: fewer evaluations per ray in all.
        fewer(name, "evaluations", all(&shared), all(&own));
    }
}

#[test]
fn relaxed_steps_find_the_surface_plain_steps_find() {
    for name in THIN {
        let (relaxed, plain) = same_surface(name, |o| TracerOptions { relax: false, ..o });
        fewer(name, "evaluations", all(&relaxed), all(&plain));
    }
}

/// The point-cloud scenes: the procedural sphere of points, and the bunny's and the
/// deer's points when their data files are there.
fn point_scenes() -> Vec<&'static str> {
    let mut names = vec!["sphere_points.toml"];
    if common::data_file("bunny-7k.obj").is_some() {
        names.push("bunny_points.toml");
    } else {
        eprintln!("skipping bunny_points.toml: data/bunny-7k.obj is absent");
    }
    if common::data_file("igea-points-134k.ply").is_some() {
        names.push("deer_alpha1.toml");
    } else {
        eprintln!("skipping deer_alpha1.toml: data/igea-points-134k.ply is absent");
    }
    names
}

#[test]
fn relaxed_steps_certified_from_behind_find_the_surface_on_point_clouds() {
    for name in point_scenes() {
        // At the fixed step beta, as on the lidar scan, whose tiles keep it: where the
        // tiles learn to step at the hit beta (`render::step_beta`), few steps fail.
        let fixed = |o| TracerOptions {
            learn_step_beta: false,
            ..o
        };
        let (behind, ball) = same_surface_from(name, fixed, |o| TracerOptions {
            reach_behind: false,
            ..o
        });
        // The point of it: fewer relaxed steps given up (each costs an evaluation).
        eprintln!(
            "{name}: rejected steps {} -> {}",
            ball.stats.rejected_steps, behind.stats.rejected_steps
        );
        fewer(
            name,
            "rejected steps",
            behind.stats.rejected_steps,
            ball.stats.rejected_steps,
        );
    }
}

/// Renders `s` with the tracer defaults (`on`) and with `off`, and the exact sum's
/// surface (beta 0) with `off`; returns both renders and their depth differences from
/// the exact one in epsilons.
fn against_exact(
    s: &Scene,
    off: impl Fn(TracerOptions) -> TracerOptions + Send + Sync + Copy,
) -> (Rendered, Rendered, DepthDiff, DepthDiff) {
    let (eps, _, on) = render(s, |o| o);
    let (_, _, plain) = render(s, off);
    let mut exact = s.clone();
    exact.render.beta = 0.0;
    let (_, _, exact) = render(&exact, off);
    let a = compare_depths(&on.depth, &exact.depth, 1.0, eps);
    let b = compare_depths(&plain.depth, &exact.depth, 1.0, eps);
    (on, plain, a, b)
}

/// Asserts that a render with a device on (depth differences `a` from the exact
/// surface, `rays` rays) is as close to the exact surface as the one without it (`b`):
/// at most a ray in 500 more hitting in only one of it and the exact render, the median
/// and 99th percentile within half an epsilon and one epsilon.
fn as_close_to_exact(name: &str, (on, off): (&str, &str), a: &DepthDiff, b: &DepthDiff, rays: u64) {
    eprintln!("{name}: vs exact, {on} {a:?}\n   {off} {b:?}");
    assert!(
        a.only_one <= b.only_one + rays as usize / 500,
        "{name}: {} rays hit in only one of the exact render and the one with {on}, {} with {off}",
        a.only_one,
        b.only_one
    );
    assert!(
        a.p50.unwrap() <= b.p50.unwrap() + 0.5 && a.p99.unwrap() <= b.p99.unwrap() + 1.0,
        "{name}: depth error against the exact surface, {on} {a:?} vs {off} {b:?}"
    );
}

#[test]
fn reach_steps_find_the_surface_plain_steps_find() {
    let names = point_scenes();
    let plain = |o| TracerOptions {
        reach_steps: false,
        ..o
    };
    for name in names {
        // Both against the exact sum's surface (beta 0, plain steps), in epsilons.
        let (reach, stepped, a, b) = against_exact(&scene(name, 240, 135), plain);
        as_close_to_exact(
            name,
            ("reach steps", "plain steps"),
            &a,
            &b,
            reach.stats.rays,
        );
        // The point of it: fewer full evaluations on the rays that hit.
        eprintln!(
            "{name}: full evaluations per hit ray {:.2} -> {:.2}",
            stepped.stats.evals_per_hit(),
            reach.stats.evals_per_hit()
        );
        assert!(
            reach.stats.evals_per_hit() < 0.8 * stepped.stats.evals_per_hit(),
            "{name}: {:.2} vs {:.2} full evaluations per hit ray",
            reach.stats.evals_per_hit(),
            stepped.stats.evals_per_hit()
        );
    }
}

/// Steps aimed at the crossing of the field's tangent (`render::tracer` item 12) land
/// on the surface that certified steps find, against the exact sum's, and spare work on
/// the rays that hit: fewer leaves per hit ray on every soft point cloud.
#[test]
fn aimed_steps_find_the_surface_certified_steps_find() {
    let certified = |o| TracerOptions { aim: false, ..o };
    for name in point_scenes() {
        let (aimed, plain, a, b) = against_exact(&scene(name, 240, 135), certified);
        as_close_to_exact(
            name,
            ("aimed steps", "certified steps"),
            &a,
            &b,
            aimed.stats.rays,
        );
        eprintln!(
            "{name}: leaves per hit ray {:.1} -> {:.1}, full evaluations {:.2} -> {:.2}",
            plain.stats.leaves_per_hit(),
            aimed.stats.leaves_per_hit(),
            plain.stats.evals_per_hit(),
            aimed.stats.evals_per_hit()
        );
        assert!(
            aimed.stats.leaves_per_hit() < plain.stats.leaves_per_hit(),
            "{name}: {:.1} vs {:.1} leaves per hit ray",
            aimed.stats.leaves_per_hit(),
            plain.stats.leaves_per_hit()
        );
    }
}

/// A tile's step beta switched to the hit beta where its refinements find the coarse
/// steps lagging by an epsilon or more (`render::step_beta`): as close to the exact
/// surface as steps at the fixed step beta, and on the soft point clouds (the sphere of
/// points, the deer at alpha 1) and the bunny's points (gaps of 1-3 epsilons), where
/// many hit rays paid a refinement, with fewer of them and at most 80% of the full
/// evaluations. The tiles of the edge and triangle scenes of `THIN` never switch and
/// render as before.
#[test]
fn learned_step_beta_finds_the_surface_the_fixed_one_finds() {
    let fixed = |o| TracerOptions {
        learn_step_beta: false,
        ..o
    };
    for name in point_scenes() {
        let (learned, steady, a, b) = against_exact(&scene(name, 240, 135), fixed);
        eprintln!(
            "{name}: vs exact, learned {a:?}\n   fixed {b:?}\n   refinements {} -> {}, \
             full evaluations per hit ray {:.2} -> {:.2}",
            steady.stats.refinements,
            learned.stats.refinements,
            steady.stats.evals_per_hit(),
            learned.stats.evals_per_hit()
        );
        assert!(
            a.only_one <= b.only_one + learned.stats.rays as usize / 500,
            "{name}: {} rays hit in only one of the learned and exact renders, {} fixed",
            a.only_one,
            b.only_one
        );
        assert!(
            a.p50.unwrap() <= b.p50.unwrap() + 0.1 && a.p99.unwrap() <= b.p99.unwrap() + 1.0,
            "{name}: depth error against the exact surface, learned {a:?} vs fixed {b:?}"
        );
        assert!(
            learned.stats.evals_per_hit() <= steady.stats.evals_per_hit(),
            "{name}: {:.2} vs {:.2} full evaluations per hit ray",
            learned.stats.evals_per_hit(),
            steady.stats.evals_per_hit()
        );
        fewer(
            name,
            "refinements",
            learned.stats.refinements,
            steady.stats.refinements,
        );
        assert!(
            learned.stats.evals_per_hit() < 0.8 * steady.stats.evals_per_hit(),
            "{name}: {:.2} vs {:.2} full evaluations per hit ray",
            learned.stats.evals_per_hit(),
            steady.stats.evals_per_hit()
        );
    }
    for name in THIN {
        let s = scene(name, 160, 90);
        let (_, _, learned) = render(&s, |o| o);
        let (_, _, steady) = render(&s, fixed);
        assert_eq!(learned.stats.hit_evals, steady.stats.hit_evals, "{name}");
        assert_eq!(learned.depth, steady.depth, "{name}");
    }
}

/// The final step (`TracerOptions::final_step`): a hit at a positive value `s` is moved
/// on along the ray by its ball (or its free distance, up to `2 s`), at no cost. Against
/// the hits without it, ray by ray: at most two epsilons further (or back, from a value
/// below zero to the crossing's estimate),
/// never past the exact (beta 0) zero set where the hit without it was in front of it,
/// and closer to it on average (exact value at the hits, by a twentieth of epsilon or
/// more). Triangles (torus), edges (hex torus, thin tubes) and points.
#[test]
fn the_final_step_brings_hits_closer_to_the_exact_surface_never_past_it() {
    let mut names = vec!["torus.toml", "hex_torus.toml"];
    names.extend(point_scenes());
    for name in names {
        let s = scene(name, 120, 68);
        let built = in_pool(2, || build_scene(&s)).unwrap();
        let eps = built.epsilon;
        // Without aimed steps (tested on their own above): their landings in the band
        // leave the final step less to do on the point clouds.
        let options = TracerOptions {
            aim: false,
            ..TracerOptions::new(eps, s.render.max_steps)
        };
        let on = Tracer::new(&built.objects, options);
        let off = Tracer::new(
            &built.objects,
            TracerOptions {
                final_step: false,
                ..options
            },
        );
        let exact = |x: DVec3| {
            built
                .objects
                .iter()
                .map(|o| {
                    let mut p = o.params;
                    p.beta = 0.0;
                    evaluate_value(&o.set_refs(), x, &p).s
                })
                .fold(f64::INFINITY, f64::min)
        };
        let cam = &built.camera;
        let (s0, _) = on.field(cam.origin(), &mut RayStats::default());
        let (mut sum_on, mut sum_off, mut n) = (0.0, 0.0, 0);
        for py in 0..s.image.height {
            for px in 0..s.image.width {
                let (o, d) = cam.ray(px, py);
                let (Some(a), Some(b)) = (on.trace(o, d, s0).hit, off.trace(o, d, s0).hit) else {
                    continue;
                };
                assert!(
                    (a.t - b.t).abs() <= 2.0 * eps,
                    "{name} ({px}, {py}): hit at {} with the final step, {} without",
                    a.t,
                    b.t
                );
                let (ea, eb) = (exact(a.point), exact(b.point));
                assert!(
                    eb < 0.0 || ea >= -1e-9 * eps,
                    "{name} ({px}, {py}): the final step passed the exact surface ({ea:e})"
                );
                sum_on += ea / eps;
                sum_off += eb / eps;
                n += 1;
            }
        }
        let (mean_on, mean_off) = (sum_on / n as f64, sum_off / n as f64);
        eprintln!("{name}: {n} hits, exact value at them {mean_off:.3} -> {mean_on:.3} eps");
        assert!(n > 500, "{name}: {n} hits");
        assert!(
            mean_on < mean_off - 0.05,
            "{name}: exact value at the hits {mean_off:.3} -> {mean_on:.3} epsilons"
        );
    }
}

/// Issue 9's target for triangle meshes: at most two full evaluations per hit ray (one
/// to land in the hit band, one to decide the hit with the gradient). It holds because a
/// bound value that falls below the coarse threshold but stays above epsilon takes its
/// own (safe) step instead of being repeated by a full evaluation at the same point: on
/// these meshes the coarse sum is nearly exact (2.2-2.6 per hit ray before).
#[test]
fn triangle_meshes_take_at_most_two_full_evaluations_per_hit_ray() {
    for name in ["torus.toml", "bucky_ball.toml"] {
        let s = scene(name, 240, 135);
        let (_, _, r) = render(&s, |o| o);
        let per_hit = r.stats.evals_per_hit();
        assert!(
            per_hit > 0.0 && per_hit <= 2.0,
            "{name}: {per_hit:.2} full evaluations per hit ray"
        );
    }
}

fn exact_vs_beta(s: &Scene) -> (f64, f64, f64) {
    exact_vs_beta_with(s, |o| o)
}

fn exact_vs_beta_with(
    s: &Scene,
    options: impl Fn(TracerOptions) -> TracerOptions + Send + Sync,
) -> (f64, f64, f64) {
    let (_, diag, fast) = render(s, options);
    let mut exact = s.clone();
    exact.render.beta = 0.0;
    let (_, _, exact) = render(&exact, |o| o);
    let d = compare_depths(&fast.depth, &exact.depth, 1.0, diag);
    (d.p50.unwrap(), d.p99.unwrap(), d.only_one_percent())
}

#[test]
fn beta_half_stays_within_a_thousandth_of_the_diagonal() {
    let mut names = vec!["torus.toml", "net.toml", "bucky_ball.toml", "bowl.toml"];
    if common::data_file("bunny-7k.obj").is_some() {
        names.extend(["bunny.toml", "bunny_edges.toml", "bunny_points.toml"]);
    } else {
        eprintln!("skipping the bunny scenes: data/bunny-7k.obj is absent");
    }
    for name in names {
        let s = scene(name, 160, 90);
        let (p50, p99, only_one) = exact_vs_beta(&s);
        eprintln!(
            "{name}: median {p50:.2e}, p99 {p99:.2e} of the diagonal, {only_one:.2}% one-sided"
        );
        assert!(
            p50 <= 1e-3,
            "{name}: median depth error {p50:e} of the diagonal"
        );
    }
}

#[test]
fn tracer_pruning_tolerance_keeps_a_close_lower_bound() {
    let mesh = common::bumpy_sphere(24, 48);
    let set = smoothtrace::primitives::AnySet::build(
        &mesh,
        smoothtrace::primitives::PrimitiveKind::Points,
    )
    .unwrap();
    let mut rng = common::Rng::new(11);
    for alpha in [5.0, 40.0, 300.0] {
        for tol in [1e-10, 1e-6, 1e-3, 1e-2] {
            let mut p = EvalParams::new(alpha, alpha, 0.0);
            p.prune_tolerance = tol;
            for _ in 0..200 {
                let x: DVec3 = 1.5 * rng.vec();
                let fast = evaluate_value(&[&set], x, &p).s;
                let exact = brute::smooth_distance(&[&set], x, alpha, alpha).0;
                assert!(
                    fast <= exact + 1e-12 * exact.abs().max(1.0 / alpha),
                    "alpha {alpha} tol {tol}: {fast} above the exact {exact}"
                );
                assert!(
                    exact - fast <= 2.0 * tol / alpha + 1e-9 / alpha,
                    "alpha {alpha} tol {tol}: {fast} more than 2 tol / alpha below {exact}"
                );
            }
        }
    }
}

#[test]
fn full_bunny_edges_hit_within_a_thousandth_of_the_diagonal() {
    if common::data_file("bunny.obj").is_none() {
        eprintln!("skipping: data/bunny.obj is absent");
        return;
    }
    let s = scene("full_bunny_edges.toml", 160, 90);
    // The finer hit beta (0.99 of the scene's) and the devices it enables (far terms by
    // share, hits from above the band) keep the hits within the goal and near the scene's
    // beta alone, for far fewer leaves per hit ray (with leaves of four edges the scene's
    // beta alone missed the goal: 0.9%; with the split far terms of round thirty-five it
    // is the closer, 4.1e-5 against 5.6e-5, for 1.55x the leaves). Each render once: the
    // defaults, the scene's beta for hits, the exact sum (beta 0).
    let plain = |o| TracerOptions {
        hit_beta_scale_edges: 1.0,
        ..o
    };
    let (_, diag, finer) = render(&s, |o| o);
    let (_, _, at_beta) = render(&s, plain);
    let mut exact = s.clone();
    exact.render.beta = 0.0;
    let (_, _, exact) = render(&exact, |o| o);
    let d = compare_depths(&finer.depth, &exact.depth, 1.0, diag);
    let (p50, p99, only_one) = (d.p50.unwrap(), d.p99.unwrap(), d.only_one_percent());
    eprintln!("hits at 0.99 of beta: median {p50:.2e}, p99 {p99:.2e}, {only_one:.2}% one-sided");
    assert!(p50 <= 1e-3, "median depth error {p50:e} of the diagonal");
    let p50_plain = compare_depths(&at_beta.depth, &exact.depth, 1.0, diag)
        .p50
        .unwrap();
    let (leaves, leaves_plain) = (finer.stats.leaves_per_hit(), at_beta.stats.leaves_per_hit());
    eprintln!(
        "hits at beta: median {p50_plain:.2e}; leaves per hit ray {leaves_plain:.1} -> {leaves:.1}"
    );
    assert!(
        p50 <= 1.5 * p50_plain,
        "scene beta alone: median {p50_plain:e}, finer hits {p50:e}"
    );
    assert!(
        leaves < 0.8 * leaves_plain,
        "leaves per hit ray: {leaves:.1} at the finer beta, {leaves_plain:.1} at the scene's"
    );
}

/// The deer at alpha 1 (a soft cloud: far-field nodes are wide in units of 1/alpha)
/// hits within a thousandth of the diagonal of the exact surface at the scene's beta with
/// the moment far fields (`eval::smooth`); with the closest-box terms (the paper's) it is
/// about 1% off.
#[test]
fn soft_point_clouds_hit_within_a_thousandth_with_moment_far_fields() {
    if common::data_file("igea-points-134k.ply").is_none() {
        eprintln!("skipping: data/igea-points-134k.ply is absent");
        return;
    }
    let s = scene("deer_alpha1.toml", 160, 90);
    let (p50, p99, only_one) = exact_vs_beta(&s);
    eprintln!("moments: median {p50:.2e}, p99 {p99:.2e}, {only_one:.2}% one-sided");
    assert!(p50 <= 1e-3, "median depth error {p50:e} of the diagonal");
    let boxes = in_pool(2, || -> Result<_, BuildError> {
        let mut built = build_scene(&s)?;
        for o in &mut built.objects {
            o.params.moments = false;
        }
        Ok(render_built(
            &built,
            s.render.max_steps,
            [0; 3],
            |o| o,
            &|_| {},
        ))
    })
    .unwrap();
    let (_, diag, exact) = {
        let mut e = s.clone();
        e.render.beta = 0.0;
        render(&e, |o| o)
    };
    let d = compare_depths(&boxes.depth, &exact.depth, 1.0, diag);
    let p50_box = d.p50.unwrap();
    eprintln!("closest-box terms: median {p50_box:.2e}");
    assert!(
        p50_box > 3.0 * p50 && p50_box > 1e-3,
        "box terms: median {p50_box:e}, moments {p50:e}"
    );
}

/// A soft field over a dense procedural torus (alpha x diagonal 60, 9,216 triangles,
/// alpha times the median edge about 1): the closest-box far field is many epsilons low
/// there, so hits decided at the hit beta sit off the exact surface; with certified hits
/// (`TracerOptions::certified_hits`, `render::tracer` item 11) they sit on it, and the
/// gap the hits were certified by is never above a few epsilons of depth.
#[test]
fn certified_hits_put_a_soft_dense_mesh_on_its_exact_surface() {
    let text = "[[object]]\ngenerator = { kind = \"torus\", major_segments = 96, minor_segments = 48 }\nprimitives = \"triangles\"\nalpha_rel = 60\n";
    let mut s = Scene::from_str(text, std::path::Path::new("soft_torus.toml")).unwrap();
    s.image.width = 96;
    s.image.height = 54;
    s.render.threads = 2;
    s.validate().unwrap();
    let (p50_plain, _, _) = exact_vs_beta(&s);
    let (p50, p99, only_one) = exact_vs_beta_with(&s, |o| TracerOptions {
        certified_hits: true,
        ..o
    });
    eprintln!(
        "soft torus: median depth error {p50_plain:.2e} of the diagonal at the hit beta, {p50:.2e} certified (p99 {p99:.2e}, {only_one:.2}% one-sided)"
    );
    assert!(p50 <= 1e-4, "certified: median depth error {p50:e}");
    assert!(only_one <= 0.5, "certified: {only_one}% one-sided");
    assert!(
        p50_plain > 10.0 * p50.max(1e-6),
        "the scene should need it: {p50_plain:e} at the hit beta against {p50:e}"
    );
    // The scene's own key (`[render] certified_hits = true`) turns the same on.
    let mut keyed = s.clone();
    keyed.render.certified_hits = true;
    let (_, _, by_key) = render(&keyed, |o| o);
    let (_, _, by_option) = render(&s, |o| TracerOptions {
        certified_hits: true,
        ..o
    });
    // (The certified render differs from the plain one: the medians above.)
    assert_eq!(by_key.depth, by_option.depth);
}

/// The evaluation's upper bound (`EvalParams::upper_bound`: far-field subtrees at their
/// lower bounds, pruned ones at zero) lies above the exact smooth distance, as the value
/// lies below it, on triangles, edges and points (whose far terms then come from the
/// closest box, not from moments) at every beta and pruning tolerance.
#[test]
fn the_certified_upper_bound_lies_above_the_exact_value() {
    let mesh = common::bumpy_sphere(24, 48);
    let mut rng = common::Rng::new(5);
    for kind in [
        smoothtrace::primitives::PrimitiveKind::Triangles,
        smoothtrace::primitives::PrimitiveKind::Edges,
        smoothtrace::primitives::PrimitiveKind::Points,
    ] {
        let set = smoothtrace::primitives::AnySet::build(&mesh, kind).unwrap();
        for alpha in [3.0, 30.0, 300.0] {
            for (beta, tol) in [(0.3, 1e-10), (0.5, 1e-3), (1.0, 1e-2), (4.0, 1e-6)] {
                let mut p = EvalParams::new(alpha, alpha, beta);
                p.prune_tolerance = tol;
                p.upper_bound = true;
                for _ in 0..100 {
                    let x: DVec3 = 1.5 * rng.vec();
                    let r = evaluate_value(&[&set], x, &p);
                    let exact = brute::smooth_distance(&[&set], x, alpha, alpha).0;
                    let slack = 1e-12 * exact.abs().max(1.0 / alpha);
                    assert!(
                        r.s <= exact + slack,
                        "{kind:?} alpha {alpha} beta {beta}: {} above {exact}",
                        r.s
                    );
                    assert!(
                        r.s_upper >= exact - slack,
                        "{kind:?} alpha {alpha} beta {beta}: upper {} below {exact}",
                        r.s_upper
                    );
                }
            }
        }
    }
}

/// Soft fields over triangle meshes (`TraceObject::soft_triangles`: triangles alone,
/// `alpha` times the median edge at most `SOFT_MAX_ALPHA_EDGE`) decide hits at
/// `hit_beta_scale_soft_triangles` of the scene's beta; stiffer fields keep
/// `hit_beta_scale` (edges alone: `hit_beta_scale_edges`; points: the scene's beta).
/// The median edge of a grid of unit squares cut into triangles (legs 1, diagonals sqrt
/// 2) is 1.
#[test]
fn soft_triangle_meshes_are_told_apart_by_alpha_times_the_median_edge() {
    use smoothtrace::mesh::Mesh;
    use smoothtrace::primitives::{AnySet, PrimitiveKind};
    use smoothtrace::render::object::{SOFT_MAX_ALPHA_EDGE, TraceObject};
    let n = 6;
    let vertices: Vec<glam::Vec3> = (0..=n)
        .flat_map(|j| (0..=n).map(move |i| glam::Vec3::new(i as f32, j as f32, 0.0)))
        .collect();
    let id = |i: u32, j: u32| j * (n + 1) + i;
    let triangles: Vec<[u32; 3]> = (0..n)
        .flat_map(|j| {
            (0..n).flat_map(move |i| {
                [
                    [id(i, j), id(i + 1, j), id(i + 1, j + 1)],
                    [id(i, j), id(i + 1, j + 1), id(i, j + 1)],
                ]
            })
        })
        .collect();
    let mesh = Mesh {
        vertices,
        segments: Vec::new(),
        triangles,
        name: "grid".into(),
    };
    let tris = AnySet::build(&mesh, PrimitiveKind::Triangles).unwrap();
    assert_eq!(tris.median_edge(), Some(1.0));
    let edges = AnySet::build(&mesh, PrimitiveKind::Edges).unwrap();
    assert_eq!(edges.median_edge(), Some(1.0));
    assert_eq!(
        AnySet::build(&mesh, PrimitiveKind::Points)
            .unwrap()
            .median_edge(),
        None
    );
    let object = |set: &AnySet, alpha: f64| {
        TraceObject::new(vec![set.clone()], EvalParams::new(alpha, alpha, 0.5))
    };
    assert!(object(&tris, SOFT_MAX_ALPHA_EDGE).soft_triangles());
    assert!(!object(&tris, SOFT_MAX_ALPHA_EDGE * 1.01).soft_triangles());
    assert!(!object(&edges, 1.0).soft_triangles());
    let both = TraceObject::new(vec![tris.clone(), edges], EvalParams::new(1.0, 1.0, 0.5));
    assert!(!both.soft_triangles());
}

/// Hits taken a few epsilons above the band on soft edge and triangle meshes, where the
/// final step is predicted to end in it (`render::tracer` item 13), find the surface
/// that hits in the band find: on the thin procedural scenes the same rays hit at the
/// same depths, and against the exact sum's surface they are as close as band hits, on
/// the soft ones and on the bunnies at the published renderer's settings; and they
/// spare work on the rays that hit.
#[test]
fn hits_from_above_the_band_find_the_surface_band_hits_find() {
    let strict = |o| TracerOptions {
        band_reach: false,
        ..o
    };
    // Soft: alpha epsilon below 0.4 (the bucky ball is stiff, and unchanged).
    for name in [
        "torus.toml",
        "net.toml",
        "hex_torus.toml",
        "spiky_sphere.toml",
        "bowl.toml",
    ] {
        let (wide, band) = same_surface(name, strict);
        eprintln!(
            "{name}: leaves per hit ray {:.1} -> {:.1}, full evaluations {:.2} -> {:.2}",
            band.stats.leaves_per_hit(),
            wide.stats.leaves_per_hit(),
            band.stats.evals_per_hit(),
            wide.stats.evals_per_hit()
        );
        fewer(name, "evaluations", all(&wide), all(&band));
    }
    let (wide, band) = same_surface("bucky_ball.toml", strict);
    assert_eq!(
        (wide.stats.evals, wide.stats.leaves),
        (band.stats.evals, band.stats.leaves),
        "bucky_ball.toml is stiff: nothing changes"
    );
    let mut soft = vec![("torus.toml", None)];
    for kind in ["triangles", "edges"] {
        for mesh in ["bunny-7k.obj", "bunny.obj"] {
            if common::data_file(mesh).is_some() {
                soft.push((mesh, Some(kind)));
            } else {
                eprintln!("skipping the published settings on {mesh}: data/{mesh} is absent");
            }
        }
    }
    for (name, kind) in soft {
        let s = match kind {
            None => scene(name, 240, 135),
            Some(kind) => published_settings(name, kind),
        };
        let (wide, band, a, b) = against_exact(&s, strict);
        let label = format!("{name} {}", kind.unwrap_or(""));
        as_close_to_exact(
            &label,
            ("hits above the band", "band hits"),
            &a,
            &b,
            wide.stats.rays,
        );
        eprintln!(
            "{label}: leaves per hit ray {:.1} -> {:.1}, full evaluations {:.2} -> {:.2}",
            band.stats.leaves_per_hit(),
            wide.stats.leaves_per_hit(),
            band.stats.evals_per_hit(),
            wide.stats.evals_per_hit()
        );
        assert!(
            wide.stats.leaves_per_hit() < band.stats.leaves_per_hit(),
            "{label}: {:.1} vs {:.1} leaves per hit ray",
            wide.stats.leaves_per_hit(),
            band.stats.leaves_per_hit()
        );
    }
}

/// The published renderer's bunny scene (`scenes/bunny.json` there: the mesh scaled by
/// 10, alpha 100, max_alpha 200, its far camera) on `mesh` as `kind`, at 480x270
/// (the side by side's size: the full bunny's far view then has about 3,400 hits, and a
/// 99th percentile of them is not one of a handful of rays, as at 240x135).
fn published_settings(mesh: &str, kind: &str) -> Scene {
    let path = common::data_file(mesh).unwrap();
    let text = format!(
        "[camera]\norigin = [-0.1687, 0.8903, 6.2380]\ntarget = [-0.1687, 1.1013, -0.0155]\n\
         [render]\nbeta = 0.5\nepsilon = 1e-3\n\
         [[object]]\nmesh = {path:?}\nprimitives = {kind:?}\nalpha = 100\nmax_alpha = 200\n\
         [object.transform]\nscale = 10.0\n"
    );
    let mut s = Scene::from_str(&text, std::path::Path::new("published.toml")).unwrap();
    s.image.width = 480;
    s.image.height = 270;
    s.render.threads = 2;
    s.validate().unwrap();
    s
}
