//! `bench`: the rows of the paper's Table 1 (SPEC 10) rendered from `scenes/<row>.toml`
//! on this machine, beside the paper's figures.
//!
//! Per row: primitive type and count (ours and the paper's: procedural shapes and the
//! stand-in data differ), alpha (the paper's and ours, with `alpha * diagonal`), the
//! paper's time (4 cores, 2015) and ours (the tracing loop only), the work per ray
//! (evaluations per ray, leaves per evaluation, leaves per ray), the BVH build time and
//! the peak resident memory of the row. Optionally the same scene with the paper's
//! algorithm on our engine (naive sum, no pruning, `TracerOptions::paper`: no ray
//! clipping, no coarse steps, fixed-step backtracking), so the speedup of the method is
//! measured on one machine; it can run at a smaller resolution than ours (time per ray
//! is compared then). Rows whose data file is missing are reported as skipped.

use super::compare::{DepthDiff, compare_depths};
use super::table::{Cell, Table};
use super::{Progress, peak_rss_mib, quantile, render_objects, reset_peak_rss, rss_mib};
use crate::eval::Accumulation;
use crate::primitives::PrimitiveKind;
use crate::render::build::build_scene;
use crate::render::image::ImageStats;
use crate::render::{TraceObject, TracerOptions};
use crate::scene::{Scene, SceneError};
use std::path::PathBuf;
use std::time::Instant;

/// One row of the paper's Table 1.
#[derive(Clone, Copy, Debug)]
pub struct PaperRow {
    /// Scene file stem in the scenes directory.
    pub name: &'static str,
    pub label: &'static str,
    pub kind: PrimitiveKind,
    pub n: usize,
    pub alpha: f64,
    /// Seconds on a 2015 laptop with 4 cores at 1920x1080.
    pub seconds: f64,
}

const fn row(
    name: &'static str,
    label: &'static str,
    kind: PrimitiveKind,
    n: usize,
    alpha: f64,
    seconds: f64,
) -> PaperRow {
    PaperRow {
        name,
        label,
        kind,
        n,
        alpha,
        seconds,
    }
}

/// Table 1 of the paper (SPEC 10), in its order.
pub const TABLE1: [PaperRow; 10] = [
    row(
        "hex_torus",
        "Hex Torus",
        PrimitiveKind::Edges,
        72,
        2.0,
        7.256,
    ),
    row("net", "Net", PrimitiveKind::Edges, 156, 80.0, 3.424),
    row("bowl", "Bowl", PrimitiveKind::Edges, 736, 50.0, 15.948),
    row(
        "torus",
        "Torus",
        PrimitiveKind::Triangles,
        1152,
        300.0,
        6.050,
    ),
    row(
        "bunny",
        "Bunny",
        PrimitiveKind::Triangles,
        6966,
        1200.0,
        16.960,
    ),
    row(
        "bucky_ball",
        "Bucky Ball",
        PrimitiveKind::Triangles,
        12548,
        1500.0,
        84.393,
    ),
    row(
        "deer_alpha1",
        "Deer",
        PrimitiveKind::Points,
        165277,
        1.0,
        7.386,
    ),
    row(
        "deer_alpha2",
        "Deer",
        PrimitiveKind::Points,
        165277,
        2.0,
        8.648,
    ),
    row(
        "deer_alpha4",
        "Deer",
        PrimitiveKind::Points,
        165277,
        4.0,
        11.962,
    ),
    row(
        "lidar",
        "Lidar",
        PrimitiveKind::Points,
        6591087,
        100.0,
        11.679,
    ),
];

/// Why the options are unusable.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error("unknown Table 1 row '{0}'; the rows are: {rows}", rows = row_names().join(", "))]
    UnknownRow(String),
    #[error(transparent)]
    Scene(Box<SceneError>),
    #[error(transparent)]
    Build(Box<crate::render::build::BuildError>),
}

impl From<SceneError> for BenchError {
    fn from(e: SceneError) -> Self {
        BenchError::Scene(Box::new(e))
    }
}

impl From<crate::render::build::BuildError> for BenchError {
    fn from(e: crate::render::build::BuildError) -> Self {
        BenchError::Build(Box::new(e))
    }
}

/// The row names, in Table 1 order.
pub fn row_names() -> Vec<&'static str> {
    TABLE1.iter().map(|r| r.name).collect()
}

/// What to run.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    pub scenes_dir: PathBuf,
    /// Row names to run (empty: all of Table 1).
    pub rows: Vec<String>,
    pub width: u32,
    pub height: u32,
    /// Worker threads (0 = all cores).
    pub threads: usize,
    /// Also render with the paper's algorithm, at this size (`None`: not at all).
    pub paper_mode: Option<(u32, u32)>,
    /// Renders per row (at least 1): the fastest is reported, with the median beside
    /// it, so that a busy machine's noise shows and mostly drops out.
    pub repeat: usize,
}

/// The paper's algorithm on our engine, for one row.
#[derive(Clone, Debug)]
pub struct PaperMode {
    pub stats: ImageStats,
    /// Compared with our render (only when both have the same size).
    pub depth: Option<DepthDiff>,
}

/// A measured row.
#[derive(Clone, Debug)]
pub struct Measured {
    /// Primitive kinds rendered, `+`-joined.
    pub kinds: String,
    pub n: usize,
    /// The first object's alpha (1/world unit) and alpha times its bounding-box diagonal.
    pub alpha: f64,
    pub alpha_diag: f64,
    /// The fastest of the row's renders.
    pub stats: ImageStats,
    /// Tracing time of every render of the row, in the order run.
    pub runs: Vec<f64>,
    /// BVH builds (seconds, all sets) and the whole scene build (loading included).
    pub bvh_seconds: f64,
    pub build_seconds: f64,
    /// Peak resident memory during the row (MiB) and its growth over the resident
    /// memory before the row.
    pub peak_rss_mib: Option<f64>,
    pub rss_growth_mib: Option<f64>,
    pub paper_mode: Option<PaperMode>,
}

/// One row of the report: measured, or skipped with the reason.
#[derive(Clone, Debug)]
pub struct BenchRow {
    pub paper: PaperRow,
    pub result: Result<Measured, String>,
}

/// Checks the row names (an unknown name is an error listing the known ones) and returns
/// the selected rows in Table 1 order.
pub fn select_rows(names: &[String]) -> Result<Vec<PaperRow>, BenchError> {
    for n in names {
        if !TABLE1.iter().any(|r| r.name == n) {
            return Err(BenchError::UnknownRow(n.clone()));
        }
    }
    Ok(TABLE1
        .iter()
        .filter(|r| names.is_empty() || names.iter().any(|n| n == r.name))
        .copied()
        .collect())
}

/// Runs the selected rows in the current rayon pool (see [`super::pool`]).
pub fn run(
    opts: &BenchOptions,
    progress: &dyn Progress,
    mut on_row: impl FnMut(&BenchRow),
) -> Result<Vec<BenchRow>, BenchError> {
    let rows = select_rows(&opts.rows)?;
    let mut out = Vec::new();
    for paper in rows {
        let result = run_row(opts, &paper, progress)?;
        let r = BenchRow { paper, result };
        on_row(&r);
        out.push(r);
    }
    Ok(out)
}

/// `Err(reason)` inside `Ok` for a skipped row; outer errors abort the report.
fn run_row(
    opts: &BenchOptions,
    paper: &PaperRow,
    progress: &dyn Progress,
) -> Result<Result<Measured, String>, BenchError> {
    let path = opts.scenes_dir.join(format!("{}.toml", paper.name));
    if !path.exists() {
        return Ok(Err(format!("scene file {} not found", path.display())));
    }
    let mut scene = match Scene::load(&path) {
        Ok(s) => s,
        Err(e) if is_missing_mesh(&e) => return Ok(Err(e.to_string())),
        Err(e) => return Err(e.into()),
    };
    scene.image.width = opts.width;
    scene.image.height = opts.height;
    scene.render.threads = opts.threads;
    scene.validate()?;
    let rss_before = rss_mib();
    let reset = reset_peak_rss();
    let t = Instant::now();
    let mut built = build_scene(&scene)?;
    let build_seconds = t.elapsed().as_secs_f64();
    let bvh_seconds = built
        .objects
        .iter()
        .flat_map(|o| &o.sets)
        .map(|s| s.times().bvh)
        .sum();
    let kinds = kinds_of(&built.objects);
    let n = built
        .objects
        .iter()
        .flat_map(|o| &o.sets)
        .map(|s| s.len())
        .sum();
    let first = &built.objects[0];
    let alpha = first.params.alpha;
    let alpha_diag = alpha * first.bounds.diagonal();
    let render = || {
        render_objects(
            &built.objects,
            built.tracer_options(scene.render.max_steps),
            &built.camera,
            &built.shaders,
            scene.image.background,
            paper.name,
            progress,
        )
    };
    let mut rendered = render();
    let mut runs = vec![rendered.stats.seconds];
    for _ in 1..opts.repeat {
        // The same image and counts every time: only the time differs.
        let r = render();
        runs.push(r.stats.seconds);
        if r.stats.seconds < rendered.stats.seconds {
            rendered = r;
        }
    }
    let peak = peak_rss_mib();
    let paper_mode = match opts.paper_mode {
        None => None,
        Some((w, h)) => {
            for o in &mut built.objects {
                o.params.accumulation = Accumulation::Naive;
                o.params.prune = false;
                o.params.moments = false;
            }
            let camera = scene.camera.build(w, h).map_err(|source| {
                crate::render::build::BuildError::Camera {
                    scene: path.display().to_string(),
                    source,
                }
            })?;
            let r = render_objects(
                &built.objects,
                TracerOptions::paper(built.epsilon, scene.render.max_steps),
                &camera,
                &built.shaders,
                scene.image.background,
                &format!("{} (paper's algorithm)", paper.name),
                progress,
            );
            let depth = ((w, h) == (opts.width, opts.height))
                .then(|| compare_depths(&rendered.depth, &r.depth, 1.0, built.bounds.diagonal()));
            Some(PaperMode {
                stats: r.stats,
                depth,
            })
        }
    };
    Ok(Ok(Measured {
        kinds,
        n,
        alpha,
        alpha_diag,
        stats: rendered.stats,
        runs,
        bvh_seconds,
        build_seconds,
        peak_rss_mib: peak,
        rss_growth_mib: match (reset, peak, rss_before) {
            (true, Some(p), Some(b)) => Some(p - b),
            _ => None,
        },
        paper_mode,
    }))
}

fn is_missing_mesh(e: &SceneError) -> bool {
    matches!(e, SceneError::Invalid { field, message, .. }
        if field.ends_with(".mesh") && message.contains("does not exist"))
}

fn kinds_of(objects: &[TraceObject]) -> String {
    let mut kinds: Vec<&str> = objects
        .iter()
        .flat_map(|o| &o.sets)
        .map(|s| s.kind().name())
        .collect();
    kinds.dedup();
    kinds.join("+")
}

/// The text form: three narrower tables (Table 1 beside ours; the work per ray, build
/// and memory; the paper's algorithm on our engine, when it ran).
pub fn text(table: &Table) -> String {
    let mut out = table
        .select(&[
            "name",
            "type",
            "paper_n",
            "n",
            "paper_alpha",
            "alpha",
            "alpha_diag",
            "paper_seconds",
            "seconds",
            "seconds_median",
            "runs",
            "threads",
            "width",
            "height",
            "hits_percent",
            "skipped",
        ])
        .to_text();
    out.push('\n');
    out += &table
        .select(&[
            "name",
            "evals_per_ray",
            "coarse_evals_per_ray",
            "leaves_per_eval",
            "leaves_per_ray",
            "bvh_seconds",
            "build_seconds",
            "peak_rss_mib",
            "rss_growth_mib",
        ])
        .to_text();
    let pm = table.column("paper_mode_seconds");
    if table
        .rows
        .iter()
        .any(|r| pm.is_some_and(|j| r[j] != Cell::Empty))
    {
        out.push('\n');
        out += &table
            .select(&[
                "name",
                "seconds",
                "paper_mode_seconds",
                "paper_mode_width",
                "paper_mode_height",
                "paper_mode_evals_per_ray",
                "paper_mode_leaves_per_eval",
                "paper_mode_falloffs",
                "speedup",
                "paper_mode_only_one_percent",
                "paper_mode_depth_max",
            ])
            .to_text();
    }
    out
}

/// The report as a table (columns documented in `doc/reports.md`).
pub fn table(rows: &[BenchRow]) -> Table {
    let mut t = Table::new(&[
        ("name", "name"),
        ("type", "type"),
        ("paper_n", "paper n"),
        ("n", "n"),
        ("paper_alpha", "paper alpha"),
        ("alpha", "alpha"),
        ("alpha_diag", "alpha*diag"),
        ("paper_seconds", "paper (s)"),
        ("seconds", "ours (s)"),
        ("seconds_median", "median (s)"),
        ("runs", "runs"),
        ("threads", "thr"),
        ("width", "width"),
        ("height", "height"),
        ("evals_per_ray", "evals/ray"),
        ("coarse_evals_per_ray", "coarse/ray"),
        ("leaves_per_eval", "leaves/eval"),
        ("leaves_per_ray", "leaves/ray"),
        ("hits_percent", "hits %"),
        ("bvh_seconds", "BVH (s)"),
        ("build_seconds", "build (s)"),
        ("peak_rss_mib", "peak MiB"),
        ("rss_growth_mib", "+MiB"),
        ("paper_mode_seconds", "paper-mode (s)"),
        ("paper_mode_width", "pm width"),
        ("paper_mode_height", "pm height"),
        ("paper_mode_evals_per_ray", "pm evals/ray"),
        ("paper_mode_leaves_per_eval", "pm leaves/eval"),
        ("paper_mode_falloffs", "pm falloffs"),
        ("speedup", "speedup"),
        ("paper_mode_only_one_percent", "pm miss %"),
        ("paper_mode_depth_max", "pm depth err"),
        ("skipped", "skipped"),
    ]);
    for r in rows {
        let p = &r.paper;
        let mut row = vec![
            Cell::text(p.name),
            Cell::text(p.kind.name()),
            Cell::int(p.n as i64),
        ];
        match &r.result {
            Err(reason) => {
                row.extend([
                    Cell::Empty,
                    Cell::num(p.alpha, 0),
                    Cell::Empty,
                    Cell::Empty,
                    Cell::num(p.seconds, 3),
                ]);
                let fill = t.columns.len() - row.len() - 1;
                row.extend(std::iter::repeat_n(Cell::Empty, fill));
                row.push(Cell::text(reason.clone()));
            }
            Ok(m) => {
                let st = &m.stats;
                row[1] = Cell::text(m.kinds.clone());
                row.extend([
                    Cell::int(m.n as i64),
                    Cell::num(p.alpha, 0),
                    Cell::num(m.alpha, 3),
                    Cell::num(m.alpha_diag, 1),
                    Cell::num(p.seconds, 3),
                    Cell::num(st.seconds, 3),
                    Cell::num(quantile(&mut m.runs.clone(), 0.5), 3),
                    Cell::int(m.runs.len() as i64),
                    Cell::int(st.threads as i64),
                    Cell::int(st.width as i64),
                    Cell::int(st.height as i64),
                    Cell::num(st.evals_per_ray(), 2),
                    Cell::num(st.coarse_evals as f64 / st.rays.max(1) as f64, 2),
                    Cell::num(st.leaves_per_eval(), 1),
                    Cell::num(st.leaves_per_ray(), 0),
                    Cell::num(100.0 * st.hits as f64 / st.rays.max(1) as f64, 1),
                    Cell::num(m.bvh_seconds, 3),
                    Cell::num(m.build_seconds, 3),
                    Cell::num(m.peak_rss_mib, 0),
                    Cell::num(m.rss_growth_mib, 0),
                ]);
                match &m.paper_mode {
                    None => row.extend(std::iter::repeat_n(Cell::Empty, 9)),
                    Some(pm) => {
                        let ps = &pm.stats;
                        // Time per ray, so a paper-mode render at a smaller size compares.
                        let speedup = (ps.seconds / ps.rays.max(1) as f64)
                            / (st.seconds / st.rays.max(1) as f64);
                        row.extend([
                            Cell::num(ps.seconds, 3),
                            Cell::int(ps.width as i64),
                            Cell::int(ps.height as i64),
                            Cell::num(ps.evals_per_ray(), 2),
                            Cell::num(ps.leaves_per_eval(), 1),
                            Cell::int(ps.falloffs as i64),
                            Cell::num(speedup, 1),
                            Cell::num(pm.depth.map(|d| d.only_one_percent()), 3),
                            Cell::sci(pm.depth.and_then(|d| d.max)),
                        ]);
                    }
                }
                row.push(Cell::Empty);
            }
        }
        t.push(row);
    }
    t
}
