//! The suite's render cases run and compared (at beta = 0): [`run_render`] renders a case
//! with one evaluator and counts hits whose brute-force `|s|` exceeds 4 epsilon, rays out
//! of steps and alpha falloffs (SPEC 7.3); [`compare_renders`] sets a render against the
//! stable render or the unscaled copy's (rays hitting in only one, depth and colour
//! differences); [`render_violations`] lists what fails. Thresholds: the parent module's
//! docs.

use super::{CaseResult, Evaluator, RenderCase, RenderCheck, diag_of, field_violations, set};
use crate::camera::Camera;
use crate::eval::brute;
use crate::matcap::MatCap;
use crate::primitives::AnySet;
use crate::render::image::Rendered;
use crate::render::{TraceObject, TracerOptions};
use crate::reports::compare::{compare_depths, compare_images};
use crate::reports::{Progress, render_objects};
use glam::DVec3;
use rayon::prelude::*;

/// Epsilon of the suite's renders, relative to the diagonal.
const RENDER_EPS_REL: f64 = 4e-4;

pub(super) fn run_render(
    rc: &RenderCase,
    ev: Evaluator,
    image: (u32, u32),
    progress: &dyn Progress,
) -> (CaseResult, Rendered, f64) {
    let sets = vec![set(&rc.mesh, rc.kind)];
    let diag = diag_of(&sets);
    let alpha = rc.alpha_diag / diag;
    let obj = TraceObject::new(sets, ev.params(alpha, alpha, 0.0));
    let k = rc.scale;
    let camera = Camera::new(
        DVec3::new(0.0, 2.0, 2.6) * k,
        DVec3::new(0.0, -0.05, 0.0) * k,
        DVec3::Y,
        Camera::DEFAULT_FOV_Y,
        image.0,
        image.1,
    )
    .expect("valid camera");
    let eps = RENDER_EPS_REL * diag;
    let objects = [obj];
    let r = render_objects(
        &objects,
        TracerOptions::new(eps, 1000),
        &camera,
        &[MatCap::Normal],
        [255, 255, 255],
        &format!("{} {}", rc.name, ev.name()),
        progress,
    );
    // Brute-force value at every hit.
    let refs: Vec<&AnySet> = objects[0].sets.iter().collect();
    let w = image.0 as usize;
    let bad_hits = r
        .depth
        .par_iter()
        .enumerate()
        .filter(|(_, t)| t.is_finite())
        .filter(|&(i, &t)| {
            let (o, d) = camera.ray((i % w) as u32, (i / w) as u32);
            let x = o + d * t as f64;
            let (s, _, _) = brute::smooth_distance(&refs, x, alpha, alpha);
            s.is_nan() || s.abs() > 4.0 * eps
        })
        .count() as u64;
    let st = &r.stats;
    let check = RenderCheck {
        hits: st.hits,
        bad_hits,
        exhausted: st.exhausted,
        camera_inside: st.camera_inside,
        ..Default::default()
    };
    let mut res = CaseResult {
        group: "render",
        case: rc.name.clone(),
        evaluator: ev,
        primitives: objects[0].sets[0].len(),
        alpha_diag: rc.alpha_diag,
        queries: st.rays as usize,
        nan: r.depth.iter().filter(|t| t.is_nan()).count(),
        inf: 0,
        not_conservative: 0,
        above_exact: 0,
        max_deviation: None,
        scale_deviation: None,
        falloffs: st.falloffs,
        render: Some(check),
        violations: Vec::new(),
    };
    res.violations = field_violations(&res, false);
    (res, r, diag)
}

/// Compares render `r` with `other`, of the same view of a copy of the scene scaled by
/// `1 / k` (`k` = 1: the same scene); `diag` is `r`'s scene diagonal.
pub(super) fn compare_renders(
    res: &mut CaseResult,
    r: &Rendered,
    other: &Rendered,
    k: f64,
    diag: f64,
    with: &str,
) {
    let depth = compare_depths(&other.depth, &r.depth, 1.0 / k, diag / k);
    let colour = compare_images(&other.image, &r.image, 16);
    let matches = depth.only_one_percent() <= 0.5
        && depth.p95.is_none_or(|p| p <= 2.0 * RENDER_EPS_REL)
        && colour.over_percent <= 1.0;
    let c = res.render.as_mut().expect("render case");
    c.compared_with = Some(with.to_string());
    c.depth = Some(depth);
    c.colour = Some(colour);
    c.matches = Some(matches);
}

pub(super) fn render_violations(res: &mut CaseResult) {
    let c = res.render.as_ref().expect("render case");
    let mut v = Vec::new();
    if c.bad_hits > 0 {
        v.push(format!("{} hits with |s| above 4 epsilon", c.bad_hits));
    }
    if c.exhausted > 0 {
        v.push(format!("{} rays ran out of steps", c.exhausted));
    }
    if c.camera_inside {
        v.push("camera inside the surface".into());
    }
    if c.hits == 0 {
        v.push("no ray hit".into());
    }
    if c.matches == Some(false) {
        v.push(format!(
            "render differs from the {}",
            c.compared_with.as_deref().unwrap_or("reference")
        ));
    }
    res.violations.extend(v);
}
