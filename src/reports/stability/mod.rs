//! `stability`: a fixed suite of hard inputs, each run with the stable evaluator (the
//! shifted sum with pruning, our default) and the naive one (the paper's: plain sum, no
//! pruning), on procedural geometry only (no data files).
//!
//! Cases (SPEC 2, 3, 4, 5): alpha times the diagonal from 1 to 1e7 for points, edges and
//! triangles; queries from on the primitives to 1e6 diagonals away; meshes scaled by
//! 1e-4 .. 1e4 (alpha divided by the scale) and translated 1e5 diagonals off the origin;
//! degenerate edges and triangles, duplicate vertices, an isolated triangle, a fan of
//! 1,000 triangles around one vertex; max_alpha below and above alpha; renders of a stiff
//! scene (alpha * diagonal = 1e4) and of a tiny and a huge copy of one scene.
//!
//! Per case and evaluator, over its queries:
//! - NaN and infinity counts of `s` and its gradient at beta = 0 and at beta = 0.5;
//! - conservativeness: `s > d_min` beyond rounding (`1e-12 max(|d_min|, 1/alpha)`), and
//!   the Barnes-Hut value at beta = 0.5 above the exact smooth distance (SPEC 6);
//! - the largest deviation at beta = 0 from the f64 brute force over the same f32
//!   primitives, relative to `max(|s|, 1/alpha)` (finite values only);
//! - alpha falloff: for every infinite value, the retries with alpha / 10 until finite
//!   that the tracer would make (SPEC 7.3);
//! - scaled copies: `s_k(k x) / k` against the unscaled brute force, same measure. The
//!   scaled vertices are the f32 roundings of `k v`, so they differ from `k` times the
//!   unscaled ones by f32 rounding (relative 6e-8): the tolerance is 1e-4. The copy
//!   translated by 1e5 diagonals loses more: f32 keeps about 1% of the diagonal there,
//!   so the brute force uses its own f32 vertices and the comparison with the untranslated
//!   copy is printed for information only.
//! - renders (at beta = 0): hits whose brute-force `|s|` exceeds 4 epsilon, rays out of
//!   steps, falloffs; the naive stiff render against the stable one, and the tiny and huge
//!   copies against the unscaled render of the same evaluator: rays that hit in one and
//!   not the other, depth difference (`t_k / k` against `t`) over the rays hitting in
//!   both relative to the diagonal, and colour difference. A render matches when at most
//!   0.5% of rays hit in only one, the 95th percentile depth difference is at most 2
//!   epsilon, and at most 1% of pixels differ by more than 16 levels.
//!
//! A violation of the stable evaluator is any NaN, infinity, falloff, conservativeness
//! failure, deviation above 1e-9 (scaled copies: 1e-4), bad hit, exhausted ray or render
//! mismatch. The naive evaluator is expected to give infinities far away (alpha d above
//! about 745): they are reported, not counted as failures of the suite.

mod cases;
mod renders;

use super::Progress;
use super::compare::{ColourDiff, DepthDiff};
use super::table::{Cell, Table};
use crate::eval::{self, Accumulation, EvalParams, brute};
use crate::mesh::Mesh;
use crate::primitives::{AnySet, PrimitiveKind};
use crate::render::image::Rendered;
use cases::{build_cases, render_cases};
use glam::DVec3;
use rayon::prelude::*;
use renders::{compare_renders, render_violations, run_render};

/// How big the suite is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Size {
    /// Small meshes, 64 queries per case, 64x36 renders (the test suite's size).
    Small,
    /// Table 1 torus, 1,000 queries per case, 320x180 renders.
    Full,
}

struct Dims {
    torus: (usize, usize),
    points: usize,
    queries: usize,
    image: (u32, u32),
}

impl Size {
    fn dims(self) -> Dims {
        match self {
            Size::Small => Dims {
                torus: (16, 8),
                points: 200,
                queries: 64,
                image: (64, 36),
            },
            Size::Full => Dims {
                torus: (32, 18),
                points: 2000,
                queries: 1000,
                image: (320, 180),
            },
        }
    }
}

/// The two evaluators.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Evaluator {
    /// Shifted sum with pruning (our default).
    Stable,
    /// Plain sum without pruning (the paper's).
    Naive,
}

impl Evaluator {
    pub fn name(self) -> &'static str {
        match self {
            Evaluator::Stable => "stable",
            Evaluator::Naive => "naive",
        }
    }

    fn params(self, alpha: f64, max_alpha: f64, beta: f64) -> EvalParams {
        let mut p = EvalParams::new(alpha, max_alpha, beta);
        if self == Evaluator::Naive {
            p.accumulation = Accumulation::Naive;
            p.prune = false;
            p.moments = false;
        }
        p
    }
}

const DEVIATION_TOL: f64 = 1e-9;
const SCALE_TOL: f64 = 1e-4;

/// A case of field evaluations.
struct Case {
    group: &'static str,
    name: String,
    sets: Vec<AnySet>,
    alpha: f64,
    max_alpha: f64,
    diag: f64,
    queries: Vec<DVec3>,
    /// Unscaled brute-force values per query, the scale factor, and whether a deviation
    /// from them is a violation (false for the translated copy).
    scale_ref: Option<(Vec<f64>, f64, bool)>,
}

/// A render case.
struct RenderCase {
    name: String,
    /// Mesh, primitive kind, alpha times diagonal, scale factor of the copy.
    mesh: Mesh,
    kind: PrimitiveKind,
    alpha_diag: f64,
    scale: f64,
    /// Compare with the unscaled render of the same evaluator (scaled copies) or with
    /// the stable render (the naive stiff render).
    compare: Compare,
}

#[derive(Clone, Copy, PartialEq)]
enum Compare {
    Nothing,
    Unscaled,
    Stable,
}

/// What a render case measured.
#[derive(Clone, Debug, Default)]
pub struct RenderCheck {
    pub hits: u64,
    /// Hits where the brute-force `|s|` exceeds 4 epsilon.
    pub bad_hits: u64,
    pub exhausted: u64,
    pub camera_inside: bool,
    /// What the render was compared with, and how it differs.
    pub compared_with: Option<String>,
    pub depth: Option<DepthDiff>,
    pub colour: Option<ColourDiff>,
    pub matches: Option<bool>,
}

/// One case run with one evaluator.
#[derive(Clone, Debug)]
pub struct CaseResult {
    pub group: &'static str,
    pub case: String,
    pub evaluator: Evaluator,
    pub primitives: usize,
    pub alpha_diag: f64,
    pub queries: usize,
    pub nan: usize,
    pub inf: usize,
    /// `s > d_min` beyond rounding.
    pub not_conservative: usize,
    /// Barnes-Hut value (beta 0.5) above the exact smooth distance beyond rounding.
    pub above_exact: usize,
    /// Largest deviation from the brute force (relative to `max(|s|, 1/alpha)`).
    pub max_deviation: Option<f64>,
    /// Largest deviation of `s_k(k x) / k` from the unscaled brute force.
    pub scale_deviation: Option<f64>,
    pub falloffs: u64,
    pub render: Option<RenderCheck>,
    /// What is wrong (empty: nothing).
    pub violations: Vec<String>,
}

/// The suite's results.
#[derive(Clone, Debug)]
pub struct StabilityReport {
    pub size: Size,
    pub results: Vec<CaseResult>,
}

impl StabilityReport {
    /// The stable evaluator's violations, as `case: what` lines.
    pub fn stable_violations(&self) -> Vec<String> {
        self.results
            .iter()
            .filter(|r| r.evaluator == Evaluator::Stable)
            .flat_map(|r| r.violations.iter().map(move |v| format!("{}: {v}", r.case)))
            .collect()
    }
}

fn set(mesh: &Mesh, kind: PrimitiveKind) -> AnySet {
    AnySet::build(mesh, kind).expect("suite meshes have every primitive kind they are used as")
}

fn diag_of(sets: &[AnySet]) -> f64 {
    sets.iter()
        .fold(crate::mesh::Aabb::EMPTY, |b, s| b.union(s.bounds()))
        .diagonal()
}

fn run_case(c: &Case, ev: Evaluator) -> CaseResult {
    let refs: Vec<&AnySet> = c.sets.iter().collect();
    let p0 = ev.params(c.alpha, c.max_alpha, 0.0);
    let p5 = ev.params(c.alpha, c.max_alpha, 0.5);
    let inv = 1.0 / c.alpha;
    struct Q {
        nan: usize,
        inf: usize,
        not_cons: usize,
        above: usize,
        dev: Option<f64>,
        sdev: Option<f64>,
        falloffs: u64,
    }
    let per: Vec<Q> = c
        .queries
        .par_iter()
        .enumerate()
        .map(|(i, &x)| {
            let (s_ref, _, dmin) = brute::smooth_distance(&refs, x, c.alpha, c.max_alpha);
            let a = eval::evaluate(&refs, x, &p0);
            let b = eval::evaluate(&refs, x, &p5);
            let bad_nan = |s: &eval::Sample| s.s.is_nan() || s.grad.is_nan();
            let bad_inf = |s: &eval::Sample| {
                s.s.is_infinite() || s.grad.to_array().iter().any(|g| g.is_infinite())
            };
            let mut q = Q {
                nan: bad_nan(&a) as usize + bad_nan(&b) as usize,
                inf: bad_inf(&a) as usize + bad_inf(&b) as usize,
                not_cons: 0,
                above: 0,
                dev: None,
                sdev: None,
                falloffs: 0,
            };
            let tol = |v: f64| 1e-12 * v.abs().max(inv);
            for s in [a.s, b.s] {
                if s.is_finite() && s > dmin + tol(dmin) {
                    q.not_cons += 1;
                }
            }
            if b.s.is_finite() && b.s > s_ref + tol(s_ref) {
                q.above += 1;
            }
            if a.s.is_finite() {
                q.dev = Some((a.s - s_ref).abs() / s_ref.abs().max(inv));
                if let Some((base, k, _)) = &c.scale_ref {
                    let s1 = base[i];
                    q.sdev = Some((a.s / k - s1).abs() / s1.abs().max(inv * k.recip()));
                }
            }
            // The tracer's alpha falloff on an infinite value (naive sum underflow).
            for (s0, beta) in [(a.s, 0.0), (b.s, 0.5)] {
                let mut alpha = c.alpha;
                let mut v = s0;
                while v == f64::INFINITY && alpha > 1e-300 {
                    alpha /= 10.0;
                    let mut p = p0;
                    p.alpha = alpha;
                    p.beta = beta;
                    v = eval::evaluate_value(&refs, x, &p).s;
                    q.falloffs += 1;
                }
                if v.is_nan() {
                    q.nan += 1;
                }
            }
            q
        })
        .collect();
    let max_opt = |it: &mut dyn Iterator<Item = Option<f64>>| it.flatten().reduce(f64::max);
    let mut r = CaseResult {
        group: c.group,
        case: c.name.clone(),
        evaluator: ev,
        primitives: c.sets.iter().map(|s| s.len()).sum(),
        alpha_diag: c.alpha * c.diag,
        queries: c.queries.len(),
        nan: per.iter().map(|q| q.nan).sum(),
        inf: per.iter().map(|q| q.inf).sum(),
        not_conservative: per.iter().map(|q| q.not_cons).sum(),
        above_exact: per.iter().map(|q| q.above).sum(),
        max_deviation: max_opt(&mut per.iter().map(|q| q.dev)),
        scale_deviation: max_opt(&mut per.iter().map(|q| q.sdev)),
        falloffs: per.iter().map(|q| q.falloffs).sum(),
        render: None,
        violations: Vec::new(),
    };
    let scale_checked = c.scale_ref.as_ref().is_some_and(|s| s.2);
    r.violations = field_violations(&r, scale_checked);
    r
}

fn field_violations(r: &CaseResult, scale_checked: bool) -> Vec<String> {
    let mut v = Vec::new();
    if r.nan > 0 {
        v.push(format!("{} NaN values", r.nan));
    }
    if r.inf > 0 {
        v.push(format!("{} infinite values", r.inf));
    }
    if r.falloffs > 0 {
        v.push(format!("{} alpha falloffs", r.falloffs));
    }
    if r.not_conservative > 0 {
        v.push(format!("{} values above d_min", r.not_conservative));
    }
    if r.above_exact > 0 {
        v.push(format!(
            "{} Barnes-Hut values above the exact smooth distance",
            r.above_exact
        ));
    }
    if let Some(d) = r.max_deviation.filter(|&d| d.is_nan() || d > DEVIATION_TOL) {
        v.push(format!(
            "deviation {d:.3e} from the brute force (tolerance {DEVIATION_TOL:e})"
        ));
    }
    if let Some(d) = r
        .scale_deviation
        .filter(|&d| scale_checked && (d.is_nan() || d > SCALE_TOL))
    {
        v.push(format!(
            "scaled copy deviates {d:.3e} from the unscaled one (tolerance {SCALE_TOL:e})"
        ));
    }
    v
}

/// Runs the suite in the current rayon pool.
pub fn run(size: Size, progress: &dyn Progress) -> StabilityReport {
    let cases = build_cases(size);
    let mut results = Vec::new();
    progress.start("field cases", cases.len() as u64);
    for (i, c) in cases.iter().enumerate() {
        for ev in [Evaluator::Stable, Evaluator::Naive] {
            results.push(run_case(c, ev));
        }
        progress.set(i as u64 + 1);
    }
    progress.finish();
    let image = size.dims().image;
    let mut unscaled: Vec<Option<(Rendered, f64)>> = vec![None, None];
    for rc in render_cases(size) {
        let mut stable: Option<Rendered> = None;
        for (j, ev) in [Evaluator::Stable, Evaluator::Naive]
            .into_iter()
            .enumerate()
        {
            let (mut res, r, diag) = run_render(&rc, ev, image, progress);
            match rc.compare {
                Compare::Nothing => {}
                Compare::Stable => match &stable {
                    Some(s) if ev == Evaluator::Naive => {
                        compare_renders(&mut res, &r, s, 1.0, diag, "stable render");
                    }
                    _ => {}
                },
                Compare::Unscaled => {
                    if let Some((u, _)) = &unscaled[j] {
                        compare_renders(&mut res, &r, u, rc.scale, diag, "unscaled render");
                    }
                }
            }
            render_violations(&mut res);
            results.push(res);
            if rc.scale == 1.0 && rc.compare == Compare::Nothing {
                unscaled[j] = Some((r, diag));
            } else if ev == Evaluator::Stable {
                stable = Some(r);
            }
        }
    }
    StabilityReport { size, results }
}

/// The text form: the field cases, then the render cases, each with its own columns.
pub fn text(table: &Table) -> String {
    let g = table.column("group").expect("group column");
    let is_render = |r: &[Cell]| r[g] == Cell::text("render");
    let mut out = table
        .filter(|r| !is_render(r))
        .select(&[
            "group",
            "case",
            "evaluator",
            "primitives",
            "alpha_diag",
            "queries",
            "nan",
            "inf",
            "not_conservative",
            "above_exact",
            "max_deviation",
            "scale_deviation",
            "falloffs",
            "status",
        ])
        .to_text();
    out.push('\n');
    out += &table
        .filter(is_render)
        .select(&[
            "case",
            "evaluator",
            "primitives",
            "alpha_diag",
            "queries",
            "nan",
            "falloffs",
            "render_hits",
            "render_bad_hits",
            "render_exhausted",
            "render_compared_with",
            "render_only_one_percent",
            "render_depth_p95",
            "render_depth_max",
            "render_colour_over_percent",
            "render_matches",
            "status",
        ])
        .to_text();
    out
}

/// The suite as a table, one row per case and evaluator (columns in `doc/reports.md`).
pub fn table(report: &StabilityReport) -> Table {
    let mut t = Table::new(&[
        ("group", "group"),
        ("case", "case"),
        ("evaluator", "eval"),
        ("primitives", "n"),
        ("alpha_diag", "alpha*diag"),
        ("queries", "queries"),
        ("nan", "NaN"),
        ("inf", "inf"),
        ("not_conservative", "s>dmin"),
        ("above_exact", "BH>exact"),
        ("max_deviation", "max dev"),
        ("scale_deviation", "scale dev"),
        ("falloffs", "falloffs"),
        ("render_hits", "hits"),
        ("render_bad_hits", "bad hits"),
        ("render_exhausted", "exhausted"),
        ("render_compared_with", "vs"),
        ("render_only_one_percent", "1-sided %"),
        ("render_depth_p95", "depth p95"),
        ("render_depth_max", "depth max"),
        ("render_colour_over_percent", "colour>16 %"),
        ("render_matches", "match"),
        ("status", "status"),
    ]);
    for r in &report.results {
        let rc = r.render.as_ref();
        let status = if r.violations.is_empty() {
            "ok".to_string()
        } else if r.evaluator == Evaluator::Naive {
            format!("(naive) {}", r.violations.join("; "))
        } else {
            format!("VIOLATION: {}", r.violations.join("; "))
        };
        t.push(vec![
            Cell::text(r.group),
            Cell::text(r.case.clone()),
            Cell::text(r.evaluator.name()),
            Cell::int(r.primitives as i64),
            Cell::sci(r.alpha_diag),
            Cell::int(r.queries as i64),
            Cell::int(r.nan as i64),
            Cell::int(r.inf as i64),
            Cell::int(r.not_conservative as i64),
            Cell::int(r.above_exact as i64),
            Cell::sci(r.max_deviation),
            Cell::sci(r.scale_deviation),
            Cell::int(r.falloffs as i64),
            rc.map_or(Cell::Empty, |c| Cell::int(c.hits as i64)),
            rc.map_or(Cell::Empty, |c| Cell::int(c.bad_hits as i64)),
            rc.map_or(Cell::Empty, |c| Cell::int(c.exhausted as i64)),
            rc.and_then(|c| c.compared_with.clone())
                .map_or(Cell::Empty, Cell::text),
            Cell::num(rc.and_then(|c| c.depth).map(|d| d.only_one_percent()), 2),
            Cell::sci(rc.and_then(|c| c.depth).and_then(|d| d.p95)),
            Cell::sci(rc.and_then(|c| c.depth).and_then(|d| d.max)),
            Cell::num(rc.and_then(|c| c.colour).map(|c| c.over_percent), 2),
            rc.and_then(|c| c.matches)
                .map_or(Cell::Empty, |m| Cell::text(if m { "yes" } else { "no" })),
            Cell::text(status),
        ]);
    }
    t
}
