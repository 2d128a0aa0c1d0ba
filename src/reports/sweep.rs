//! `sweep`: what the Barnes-Hut parameter beta (SPEC 6) buys and costs.
//!
//! Render mode: for each scene (and each alpha, if several are given) render at every
//! beta and compare with the exact render (beta = 0): render time, speedup, the
//! isosurface error along each ray `|t_beta - t_0|` relative to the scene's bounding-box
//! diagonal over the rays that hit in both (mean, 95th percentile, max), the share of
//! rays that hit in one render and not the other, and the work (evaluations per ray,
//! leaves per evaluation). One more render with the naive sum at the scene's beta is
//! compared with the stable one at the same beta (time, the same error measures, alpha
//! falloff count). Several scenes of one model with different primitive types give the
//! paper's Figure 12.
//!
//! Grid mode (Thingi10K-style, SPEC 10): the first object's mesh centred and scaled to a
//! bounding-box diagonal of 0.5 (alpha scaled to keep `alpha * diagonal`), queried (value
//! and gradient) at the voxel centres of an `N^3` grid over its box grown by 5% of the
//! diagonal on each side: time per query, leaves per query, and the smooth distance's
//! error against beta = 0 relative to the diagonal.

use super::compare::{DepthDiff, compare_depths};
use super::table::{Cell, Table};
use super::{Progress, quantile, render_objects};
use crate::eval::{self, Accumulation, EvalParams};
use crate::mesh::Aabb;
use crate::primitives::AnySet;
use crate::render::TracerOptions;
use crate::render::build::{BuildError, BuiltScene, build_scene};
use crate::render::image::Rendered;
use crate::scene::{AlphaSpec, Geometry, Scene, SceneError};
use glam::DVec3;
use rayon::prelude::*;
use std::path::PathBuf;
use std::time::Instant;

/// Why a sweep could not run.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    #[error("{0}")]
    Options(String),
    #[error(transparent)]
    Scene(Box<SceneError>),
    #[error(transparent)]
    Build(Box<BuildError>),
    #[error("{scene}: {message}")]
    Geometry { scene: String, message: String },
}

impl From<SceneError> for SweepError {
    fn from(e: SceneError) -> Self {
        SweepError::Scene(Box::new(e))
    }
}

impl From<BuildError> for SweepError {
    fn from(e: BuildError) -> Self {
        SweepError::Build(Box::new(e))
    }
}

/// The default beta list: 0, 0.1, ..., 1.
pub fn default_betas() -> Vec<f64> {
    (0..=10).map(|i| i as f64 / 10.0).collect()
}

/// What to run.
#[derive(Clone, Debug)]
pub struct SweepOptions {
    pub scenes: Vec<PathBuf>,
    /// Betas in [0, 1]; beta = 0 (the reference) is rendered even if absent.
    pub betas: Vec<f64>,
    /// Alphas to override every object's with, one sweep each (empty: the scenes').
    pub alphas: Vec<AlphaSpec>,
    pub width: Option<u32>,
    pub height: Option<u32>,
    /// Worker threads (0 = all cores); the caller runs the sweep in such a pool.
    pub threads: usize,
    /// Also render with the naive sum at the scene's beta.
    pub naive: bool,
    /// Render with the paper's algorithm (naive sum, no pruning, `TracerOptions::paper`)
    /// instead of ours.
    pub paper_mode: bool,
}

impl SweepOptions {
    /// Checks the lists (betas in [0, 1], alphas positive and finite, a scene given).
    pub fn validate(&self) -> Result<(), SweepError> {
        let bad = |m: String| Err(SweepError::Options(m));
        if self.scenes.is_empty() {
            return bad("give at least one scene file".into());
        }
        if self.betas.is_empty() {
            return bad("the beta list is empty".into());
        }
        if let Some(b) = self.betas.iter().find(|b| !(0.0..=1.0).contains(*b)) {
            return bad(format!(
                "beta {b} is outside [0, 1] (write e.g. --betas 0,0.25,0.5)"
            ));
        }
        if let Some(a) = self
            .alphas
            .iter()
            .find(|a| !(a.value() > 0.0 && a.value().is_finite()))
        {
            return bad(format!("alpha {} must be positive and finite", a.value()));
        }
        Ok(())
    }
}

/// One render of the sweep.
#[derive(Clone, Debug)]
pub struct SweepRow {
    /// Scene file stem.
    pub scene: String,
    pub kinds: String,
    pub n: usize,
    pub alpha: f64,
    pub alpha_diag: f64,
    pub beta: f64,
    /// `"stable"` or `"naive"` (`"paper"` in paper mode).
    pub evaluation: &'static str,
    pub width: u32,
    pub height: u32,
    pub seconds: f64,
    /// Time of the beta = 0 render over this one's.
    pub speedup: f64,
    /// What the depth error is measured against: `"beta=0"` or `"stable"` (the stable
    /// render at the same beta, for the naive row).
    pub reference: &'static str,
    pub depth: DepthDiff,
    pub evals_per_ray: f64,
    pub leaves_per_eval: f64,
    pub leaves_per_ray: f64,
    pub falloffs: u64,
    pub hits_percent: f64,
}

fn load(
    path: &std::path::Path,
    o: &SweepOptions,
    alpha: Option<AlphaSpec>,
) -> Result<Scene, SweepError> {
    let mut scene = Scene::load(path)?;
    if let Some(w) = o.width {
        scene.image.width = w;
    }
    if let Some(h) = o.height {
        scene.image.height = h;
    }
    scene.render.threads = o.threads;
    if let Some(a) = alpha {
        for obj in &mut scene.objects {
            obj.alpha = a;
        }
    }
    scene.validate()?;
    Ok(scene)
}

fn stem(path: &std::path::Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// Runs the render sweep in the current rayon pool; `on_row` sees each row as it is done.
pub fn run(
    o: &SweepOptions,
    progress: &dyn Progress,
    mut on_row: impl FnMut(&SweepRow),
) -> Result<Vec<SweepRow>, SweepError> {
    o.validate()?;
    let alphas: Vec<Option<AlphaSpec>> = if o.alphas.is_empty() {
        vec![None]
    } else {
        o.alphas.iter().copied().map(Some).collect()
    };
    // Load every scene first, so a bad file fails before minutes of rendering.
    for path in &o.scenes {
        load(path, o, alphas[0])?;
    }
    let mut rows = Vec::new();
    for path in &o.scenes {
        for &alpha in &alphas {
            let scene = load(path, o, alpha)?;
            let mut built = build_scene(&scene)?;
            let name = stem(path);
            let mut push = |r: SweepRow| {
                on_row(&r);
                rows.push(r);
            };
            let diag = built.bounds.diagonal();
            let render_at = |built: &mut BuiltScene, beta: f64, naive: bool| -> Rendered {
                for obj in &mut built.objects {
                    obj.params.beta = beta;
                    obj.params.accumulation = if naive || o.paper_mode {
                        Accumulation::Naive
                    } else {
                        Accumulation::Stable
                    };
                    obj.params.prune = !o.paper_mode;
                    obj.params.moments = !o.paper_mode;
                }
                let options = if o.paper_mode {
                    TracerOptions::paper(built.epsilon, scene.render.max_steps)
                } else {
                    built.tracer_options(scene.render.max_steps)
                };
                let label = format!("{name} beta {beta}{}", if naive { " naive" } else { "" });
                render_objects(
                    &built.objects,
                    options,
                    &built.camera,
                    &built.shaders,
                    scene.image.background,
                    &label,
                    progress,
                )
            };
            let reference = render_at(&mut built, 0.0, false);
            let t0 = reference.stats.seconds;
            let first = &built.objects[0];
            let kinds = first
                .sets
                .iter()
                .map(|s| s.kind().name())
                .collect::<Vec<_>>()
                .join("+");
            let n: usize = built
                .objects
                .iter()
                .flat_map(|o| &o.sets)
                .map(|s| s.len())
                .sum();
            let (alpha, alpha_diag) = (
                first.params.alpha,
                first.params.alpha * first.bounds.diagonal(),
            );
            let row = |r: &Rendered, beta: f64, evaluation, reference: &'static str, depth| {
                let st = &r.stats;
                SweepRow {
                    scene: name.clone(),
                    kinds: kinds.clone(),
                    n,
                    alpha,
                    alpha_diag,
                    beta,
                    evaluation,
                    width: st.width,
                    height: st.height,
                    seconds: st.seconds,
                    speedup: t0 / st.seconds.max(1e-12),
                    reference,
                    depth,
                    evals_per_ray: st.evals_per_ray(),
                    leaves_per_eval: st.leaves_per_eval(),
                    leaves_per_ray: st.leaves_per_ray(),
                    falloffs: st.falloffs,
                    hits_percent: 100.0 * st.hits as f64 / st.rays.max(1) as f64,
                }
            };
            let stable_name = if o.paper_mode { "paper" } else { "stable" };
            let scene_beta = scene.render.beta;
            let mut at_scene_beta: Option<Vec<f32>> = None;
            let mut betas = o.betas.clone();
            if o.naive && !o.paper_mode && !betas.contains(&scene_beta) {
                betas.push(scene_beta);
            }
            for &beta in &betas {
                let r = if beta == 0.0 {
                    None
                } else {
                    Some(render_at(&mut built, beta, false))
                };
                let r = r.as_ref().unwrap_or(&reference);
                let depth = compare_depths(&reference.depth, &r.depth, 1.0, diag);
                push(row(r, beta, stable_name, "beta=0", depth));
                if beta == scene_beta {
                    at_scene_beta = Some(r.depth.clone());
                }
            }
            if !o.betas.contains(&0.0) {
                // The reference was rendered but not asked for: report it all the same,
                // since every other row is measured against it.
                let depth = compare_depths(&reference.depth, &reference.depth, 1.0, diag);
                let r = row(&reference, 0.0, stable_name, "beta=0", depth);
                push(r);
            }
            if o.naive && !o.paper_mode {
                let r = render_at(&mut built, scene_beta, true);
                let stable = at_scene_beta.as_ref().expect("rendered above");
                let depth = compare_depths(stable, &r.depth, 1.0, diag);
                push(row(&r, scene_beta, "naive", "stable", depth));
            }
        }
    }
    Ok(rows)
}

/// The render sweep as a table (columns documented in `doc/reports.md`).
pub fn table(rows: &[SweepRow]) -> Table {
    let mut t = Table::new(&[
        ("scene", "scene"),
        ("type", "type"),
        ("n", "n"),
        ("alpha", "alpha"),
        ("alpha_diag", "alpha*diag"),
        ("beta", "beta"),
        ("evaluation", "eval"),
        ("width", "width"),
        ("height", "height"),
        ("seconds", "time (s)"),
        ("speedup", "speedup"),
        ("reference", "vs"),
        ("error_mean", "err mean"),
        ("error_p50", "err p50"),
        ("error_p95", "err p95"),
        ("error_p99", "err p99"),
        ("error_max", "err max"),
        ("only_one_percent", "1-sided %"),
        ("evals_per_ray", "evals/ray"),
        ("leaves_per_eval", "leaves/eval"),
        ("leaves_per_ray", "leaves/ray"),
        ("falloffs", "falloffs"),
        ("hits_percent", "hits %"),
    ]);
    for r in rows {
        t.push(vec![
            Cell::text(r.scene.clone()),
            Cell::text(r.kinds.clone()),
            Cell::int(r.n as i64),
            Cell::num(r.alpha, 2),
            Cell::num(r.alpha_diag, 1),
            Cell::num(r.beta, 2),
            Cell::text(r.evaluation),
            Cell::int(r.width as i64),
            Cell::int(r.height as i64),
            Cell::num(r.seconds, 3),
            Cell::num(r.speedup, 2),
            Cell::text(r.reference),
            Cell::sci(r.depth.mean),
            Cell::sci(r.depth.p50),
            Cell::sci(r.depth.p95),
            Cell::sci(r.depth.p99),
            Cell::sci(r.depth.max),
            Cell::num(r.depth.only_one_percent(), 3),
            Cell::num(r.evals_per_ray, 2),
            Cell::num(r.leaves_per_eval, 1),
            Cell::num(r.leaves_per_ray, 0),
            Cell::int(r.falloffs as i64),
            Cell::num(r.hits_percent, 1),
        ]);
    }
    t
}

/// Options of the grid mode.
#[derive(Clone, Debug)]
pub struct GridOptions {
    pub scenes: Vec<PathBuf>,
    pub betas: Vec<f64>,
    /// Voxels per side.
    pub n: usize,
}

/// Bounding-box diagonal the grid mode scales every model to (as the paper's Thingi10K
/// experiment).
pub const GRID_DIAGONAL: f64 = 0.5;

/// One beta of the grid mode for one scene.
#[derive(Clone, Debug)]
pub struct GridRow {
    pub scene: String,
    pub kinds: String,
    pub n: usize,
    pub alpha: f64,
    pub alpha_diag: f64,
    pub beta: f64,
    pub grid: usize,
    pub queries: usize,
    /// Wall-clock seconds for all queries (in parallel).
    pub seconds: f64,
    /// Mean and median of the per-query times, microseconds (one thread each).
    pub us_per_query: f64,
    pub us_median: f64,
    pub leaves_mean: f64,
    pub leaves_median: f64,
    pub leaves_max: u32,
    /// `|s_beta - s_0| / diagonal`: mean and max.
    pub error_mean: f64,
    pub error_max: f64,
    /// Queries where `s_beta > s_0` beyond rounding (the approximation must not raise s).
    pub above_exact: usize,
    /// Per-query (leaves, microseconds), a sample for the plot.
    pub samples: Vec<(u32, f64)>,
}

/// The first object's mesh, transformed, centred and scaled to [`GRID_DIAGONAL`], with its
/// primitive sets and its alpha and max_alpha rescaled to keep `alpha * diagonal`.
fn grid_object(scene: &Scene) -> Result<(Vec<AnySet>, f64, f64), SweepError> {
    let name = scene.path.display().to_string();
    let fail = |message: String| SweepError::Geometry {
        scene: name.clone(),
        message,
    };
    let obj = &scene.objects[0];
    let mut mesh = match &obj.geometry {
        Geometry::Mesh(p) => {
            crate::load::load_scene_mesh(p, &obj.las).map_err(|e| fail(e.to_string()))?
        }
        Geometry::Generator(g) => g.build().map_err(|e| fail(e.to_string()))?,
    };
    if !obj.transform.is_identity() {
        obj.transform.apply_to_mesh(&mut mesh);
    }
    let b = mesh.bounds();
    let diag = b.diagonal();
    if !(diag > 0.0 && diag.is_finite()) {
        return Err(fail(format!("object[0] has no size (diagonal {diag})")));
    }
    let alpha = obj
        .alpha
        .resolve(diag)
        .ok_or_else(|| fail("alpha".into()))?;
    let max_alpha = obj
        .max_alpha_or_alpha()
        .resolve(diag)
        .ok_or_else(|| fail("max_alpha".into()))?;
    let k = GRID_DIAGONAL / diag;
    let c = b.center();
    for v in &mut mesh.vertices {
        *v = ((*v - c).as_dvec3() * k).as_vec3();
    }
    let sets = obj
        .primitives
        .iter()
        .map(|&kind| AnySet::build(&mesh, kind).map_err(|e| fail(e.to_string())))
        .collect::<Result<Vec<_>, _>>()?;
    Ok((sets, alpha / k, max_alpha / k))
}

/// Voxel centres of an `n^3` grid over `b` grown by 5% of its diagonal on each side, in
/// z-major slices.
pub fn grid_points(b: Aabb, n: usize) -> Vec<DVec3> {
    let grow = 0.05 * b.diagonal();
    let lo = b.min.as_dvec3() - grow;
    let size = (b.max.as_dvec3() + grow) - lo;
    let mut out = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let f = (DVec3::new(i as f64, j as f64, k as f64) + 0.5) / n as f64;
                out.push(lo + f * size);
            }
        }
    }
    out
}

/// Runs the grid mode in the current rayon pool.
pub fn run_grid(
    o: &GridOptions,
    progress: &dyn Progress,
    mut on_row: impl FnMut(&GridRow),
) -> Result<Vec<GridRow>, SweepError> {
    if o.n == 0 {
        return Err(SweepError::Options("--grid must be at least 1".into()));
    }
    let check = SweepOptions {
        scenes: o.scenes.clone(),
        betas: o.betas.clone(),
        alphas: Vec::new(),
        width: None,
        height: None,
        threads: 0,
        naive: false,
        paper_mode: false,
    };
    check.validate()?;
    let scenes = o
        .scenes
        .iter()
        .map(|p| Scene::load(p))
        .collect::<Result<Vec<_>, _>>()?;
    let mut rows = Vec::new();
    for (path, scene) in o.scenes.iter().zip(&scenes) {
        let (sets, alpha, max_alpha) = grid_object(scene)?;
        let refs: Vec<&AnySet> = sets.iter().collect();
        let bounds = sets.iter().fold(Aabb::EMPTY, |b, s| b.union(s.bounds()));
        let queries = grid_points(bounds, o.n);
        let slice = o.n * o.n;
        let name = stem(path);
        let mut betas = vec![0.0];
        betas.extend(o.betas.iter().copied().filter(|&b| b != 0.0));
        let mut s0: Vec<f64> = Vec::new();
        for beta in betas {
            let p = EvalParams::new(alpha, max_alpha, beta);
            progress.start(&format!("{name} grid beta {beta}"), o.n as u64);
            let done = std::sync::atomic::AtomicU64::new(0);
            let t = Instant::now();
            let results: Vec<(f64, u32, f64)> = queries
                .par_chunks(slice)
                .flat_map_iter(|chunk| {
                    let v: Vec<(f64, u32, f64)> = chunk
                        .iter()
                        .map(|&x| {
                            let t = Instant::now();
                            let s = eval::evaluate(&refs, x, &p);
                            let us = t.elapsed().as_secs_f64() * 1e6;
                            (s.s, s.stats.leaves(), us)
                        })
                        .collect();
                    let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                    progress.set(k);
                    v
                })
                .collect();
            let seconds = t.elapsed().as_secs_f64();
            progress.finish();
            if beta == 0.0 {
                s0 = results.iter().map(|r| r.0).collect();
            }
            let nq = results.len() as f64;
            let errs: Vec<f64> = results
                .iter()
                .zip(&s0)
                .map(|(r, &e)| (r.0 - e).abs() / GRID_DIAGONAL)
                .collect();
            let above_exact = results
                .iter()
                .zip(&s0)
                .filter(|(r, e)| r.0 > **e + 1e-12 * e.abs().max(1.0 / alpha))
                .count();
            let stride = (results.len() / 4000).max(1);
            let row = GridRow {
                scene: name.clone(),
                kinds: sets
                    .iter()
                    .map(|s| s.kind().name())
                    .collect::<Vec<_>>()
                    .join("+"),
                n: sets.iter().map(|s| s.len()).sum(),
                alpha,
                alpha_diag: alpha * GRID_DIAGONAL,
                beta,
                grid: o.n,
                queries: results.len(),
                seconds,
                us_per_query: results.iter().map(|r| r.2).sum::<f64>() / nq,
                us_median: quantile(&mut results.iter().map(|r| r.2).collect::<Vec<_>>(), 0.5)
                    .unwrap_or(0.0),
                leaves_median: quantile(
                    &mut results.iter().map(|r| r.1 as f64).collect::<Vec<_>>(),
                    0.5,
                )
                .unwrap_or(0.0),
                leaves_mean: results.iter().map(|r| r.1 as f64).sum::<f64>() / nq,
                leaves_max: results.iter().map(|r| r.1).max().unwrap_or(0),
                error_mean: errs.iter().sum::<f64>() / nq,
                error_max: errs.iter().copied().fold(0.0, f64::max),
                above_exact,
                samples: results.iter().step_by(stride).map(|r| (r.1, r.2)).collect(),
            };
            on_row(&row);
            rows.push(row);
        }
    }
    Ok(rows)
}

/// The grid mode as a table (columns documented in `doc/reports.md`).
pub fn grid_table(rows: &[GridRow]) -> Table {
    let mut t = Table::new(&[
        ("scene", "scene"),
        ("type", "type"),
        ("n", "n"),
        ("alpha", "alpha"),
        ("alpha_diag", "alpha*diag"),
        ("beta", "beta"),
        ("grid", "grid"),
        ("queries", "queries"),
        ("seconds", "time (s)"),
        ("us_per_query", "us/query"),
        ("us_median", "median us"),
        ("speedup", "speedup"),
        ("leaves_mean", "leaves"),
        ("leaves_median", "median leaves"),
        ("leaves_max", "max leaves"),
        ("error_mean", "err mean"),
        ("error_max", "err max"),
        ("above_exact", "above exact"),
    ]);
    for r in rows {
        let base = rows
            .iter()
            .find(|b| b.scene == r.scene && b.beta == 0.0)
            .map(|b| b.us_per_query / r.us_per_query.max(1e-12));
        t.push(vec![
            Cell::text(r.scene.clone()),
            Cell::text(r.kinds.clone()),
            Cell::int(r.n as i64),
            Cell::num(r.alpha, 2),
            Cell::num(r.alpha_diag, 1),
            Cell::num(r.beta, 2),
            Cell::int(r.grid as i64),
            Cell::int(r.queries as i64),
            Cell::num(r.seconds, 3),
            Cell::num(r.us_per_query, 2),
            Cell::num(r.us_median, 2),
            Cell::num(base, 2),
            Cell::num(r.leaves_mean, 1),
            Cell::num(r.leaves_median, 0),
            Cell::int(r.leaves_max as i64),
            Cell::sci(r.error_mean),
            Cell::sci(r.error_max),
            Cell::int(r.above_exact as i64),
        ]);
    }
    t
}

/// The render sweep's curves: one per scene and alpha (stable or paper rows, by beta),
/// labelled by primitive type (and alpha when a scene has several).
pub fn plot_series(rows: &[SweepRow]) -> Vec<super::plot::SweepSeries> {
    let mut keys: Vec<(String, f64)> = Vec::new();
    for r in rows {
        if r.reference == "beta=0" && !keys.iter().any(|k| k.0 == r.scene && k.1 == r.alpha) {
            keys.push((r.scene.clone(), r.alpha));
        }
    }
    let several_alphas = |scene: &str| keys.iter().filter(|k| k.0 == scene).count() > 1;
    keys.iter()
        .map(|(scene, alpha)| {
            let mut pts: Vec<&SweepRow> = rows
                .iter()
                .filter(|r| &r.scene == scene && r.alpha == *alpha && r.reference == "beta=0")
                .collect();
            pts.sort_by(|a, b| a.beta.total_cmp(&b.beta));
            let first = pts[0];
            let mut label = format!("{} ({}, n={})", first.kinds, scene, first.n);
            if several_alphas(scene) {
                label = format!("{} alpha {}", label, alpha);
            }
            super::plot::SweepSeries {
                label,
                points: pts
                    .iter()
                    .map(|r| {
                        (
                            r.beta,
                            r.seconds,
                            r.depth.mean.unwrap_or(0.0),
                            r.depth.p95.unwrap_or(0.0),
                        )
                    })
                    .collect(),
            }
        })
        .collect()
}

/// The grid mode's curves, one per scene.
pub fn grid_series(rows: &[GridRow]) -> Vec<super::plot::GridSeries> {
    let mut scenes: Vec<&str> = Vec::new();
    for r in rows {
        if !scenes.contains(&r.scene.as_str()) {
            scenes.push(&r.scene);
        }
    }
    scenes
        .iter()
        .map(|&scene| {
            let mut rs: Vec<&GridRow> = rows.iter().filter(|r| r.scene == scene).collect();
            rs.sort_by(|a, b| a.beta.total_cmp(&b.beta));
            super::plot::GridSeries {
                label: format!("{} ({}, n={})", rs[0].kinds, scene, rs[0].n),
                per_beta: rs
                    .iter()
                    .map(|r| (r.beta, r.leaves_median, r.us_median))
                    .collect(),
                samples: rs
                    .iter()
                    .flat_map(|r| r.samples.iter().map(|&(l, t)| (l as f64, t)))
                    .collect(),
            }
        })
        .collect()
}
