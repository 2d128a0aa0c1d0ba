//! `bench --matrix`: the speed matrix (issue 30). Every cell is one render of one mesh
//! of `../shared/data` as one primitive kind (points are the mesh's vertices) at one
//! `alpha * diagonal`, auto-framed from far (the whole reach box in view, `framing`) or
//! from close (the same camera moved to 0.4 of its distance from the target), at beta
//! 0.5 and the scene files' default epsilon (`4e-4` of the diagonal).
//!
//! Per cell it reports the tracing time, the work per ray (full evaluations per hit
//! ray, bound steps per hit ray, leaves per ray and per evaluation) and, when asked, the
//! depth error against the exact render (beta 0, hits in the band only) of the same
//! view at a smaller size (`|t - t_0|` over the rays hitting in both, relative to the
//! diagonal, as `sweep` measures it). The counts do not depend on the machine or the thread count, so a
//! committed baseline of them guards every cell (`check`): a cell whose leaves or
//! evaluations per ray rise by more than the tolerance fails.

use super::compare::{DepthDiff, compare_depths};
use super::table::{Cell, Table};
use super::{Progress, render_objects};
use crate::mesh::Mesh;
use crate::primitives::PrimitiveKind;
use crate::render::build::{BuildError, build_scene};
use crate::render::hit_gap::{self, HitGap};
use crate::render::image::ImageStats;
use crate::render::{Tracer, TracerOptions};
use crate::scene::{Scene, SceneError};
use std::path::PathBuf;

/// The meshes of the matrix: `(name, file in the data folder)`.
/// The deer of Table 1 is the Igea scan's vertices (as in `scenes/deer_alpha1.toml`).
pub const MESHES: [(&str, &str); 8] = [
    ("bunny-7k", "bunny-7k.obj"),
    ("bunny", "bunny.obj"),
    ("spot", "spot.obj"),
    ("fandisk", "fandisk.obj"),
    ("beast", "beast.obj"),
    ("rocker-arm", "rocker-arm.obj"),
    ("homer", "homer.obj"),
    ("deer", "igea-points-134k.ply"),
];

/// `alpha * diagonal` of the cells, soft to stiff.
pub const ALPHAS_REL: [f64; 5] = [100.0, 250.0, 1000.0, 3000.0, 10000.0];

/// The camera of a cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// Auto-framed: the whole reach box in view.
    Far,
    /// The far camera moved to [`CLOSE`] of its distance from the target.
    Close,
}

/// Share of the far camera's distance to the target that the close camera keeps.
pub const CLOSE: f64 = 0.4;

impl View {
    pub fn name(self) -> &'static str {
        match self {
            View::Far => "far",
            View::Close => "close",
        }
    }

    pub fn parse(s: &str) -> Option<View> {
        match s {
            "far" => Some(View::Far),
            "close" => Some(View::Close),
            _ => None,
        }
    }
}

/// One cell of the matrix.
#[derive(Clone, Debug, PartialEq)]
pub struct MatrixCell {
    pub mesh: String,
    pub kind: PrimitiveKind,
    pub alpha_rel: f64,
    pub view: View,
}

impl MatrixCell {
    /// The cell's key in baselines: `mesh/kind/alpha_rel/view`.
    pub fn key(&self) -> String {
        format!(
            "{}/{}/{}/{}",
            self.mesh,
            self.kind.name(),
            self.alpha_rel,
            self.view.name()
        )
    }
}

/// What to run.
#[derive(Clone, Debug)]
pub struct MatrixOptions {
    /// Folder holding the meshes (`data/`).
    pub data_dir: PathBuf,
    /// Mesh names (of [`MESHES`]); empty: all.
    pub meshes: Vec<String>,
    pub kinds: Vec<PrimitiveKind>,
    pub alphas_rel: Vec<f64>,
    pub views: Vec<View>,
    pub width: u32,
    pub height: u32,
    pub beta: f64,
    /// Size of the exact and approximate renders compared for the depth error (`None`:
    /// not measured).
    pub error_size: Option<(u32, u32)>,
    /// Renders per cell; the fastest is reported (counts are the same every time).
    pub repeat: usize,
    /// Hits certified within one epsilon of the exact sum (`TracerOptions::certified_hits`).
    pub certified_hits: bool,
}

/// A measured cell.
#[derive(Clone, Debug)]
pub struct Measured {
    pub n: usize,
    pub alpha: f64,
    /// `alpha` times the mesh's median edge length (`None` for a cloud without edges).
    pub alpha_edge: Option<f64>,
    pub stats: ImageStats,
    pub error: Option<DepthDiff>,
    /// How far the exact value may lie above the hits' (`render::hit_gap`; `None` with
    /// certified hits, for point clouds and without hits).
    pub gap: Option<HitGap>,
}

/// One row of the report: measured, or skipped with the reason (a missing mesh file).
#[derive(Clone, Debug)]
pub struct MatrixRow {
    pub cell: MatrixCell,
    pub result: Result<Measured, String>,
}

/// Errors that stop the matrix (a missing file only skips its cells).
#[derive(Debug, thiserror::Error)]
pub enum MatrixError {
    #[error("unknown mesh '{0}' (known: {known})", known = MESHES.map(|m| m.0).join(", "))]
    UnknownMesh(String),
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(transparent)]
    Build(#[from] BuildError),
}

/// The cells of `opts`, in report order (mesh, kind, alpha, view). A cloud without
/// edges or triangles (the deer) has points cells only.
pub fn cells(opts: &MatrixOptions) -> Result<Vec<MatrixCell>, MatrixError> {
    for m in &opts.meshes {
        if !MESHES.iter().any(|(name, _)| name == m) {
            return Err(MatrixError::UnknownMesh(m.clone()));
        }
    }
    let mut out = Vec::new();
    for (name, file) in MESHES {
        if !opts.meshes.is_empty() && !opts.meshes.iter().any(|m| m == name) {
            continue;
        }
        let cloud = file.ends_with(".ply");
        for &kind in &opts.kinds {
            if cloud && kind != PrimitiveKind::Points {
                continue;
            }
            for &alpha_rel in &opts.alphas_rel {
                for &view in &opts.views {
                    out.push(MatrixCell {
                        mesh: name.to_string(),
                        kind,
                        alpha_rel,
                        view,
                    });
                }
            }
        }
    }
    Ok(out)
}

fn file_of(mesh: &str) -> &'static str {
    MESHES
        .iter()
        .find(|(name, _)| *name == mesh)
        .map(|m| m.1)
        .expect("cells() checked the names")
}

/// The scene text of a cell (camera given, or auto-framed when `None`), resolved
/// relative to the data folder.
fn scene_text(
    c: &MatrixCell,
    beta: f64,
    camera: Option<(glam::DVec3, glam::DVec3, f64)>,
) -> String {
    let v = |v: glam::DVec3| format!("[{:?}, {:?}, {:?}]", v.x, v.y, v.z);
    let camera = match camera {
        Some((origin, target, fov)) => format!(
            "[camera]\norigin = {}\ntarget = {}\nfov = {fov:?}\n\n",
            v(origin),
            v(target)
        ),
        None => String::new(),
    };
    format!(
        "{camera}[render]\nbeta = {beta:?}\n\n[[object]]\nmesh = \"{}\"\nprimitives = \"{}\"\nalpha_rel = {:?}\n",
        file_of(&c.mesh),
        c.kind.name(),
        c.alpha_rel
    )
}

/// The median edge length of a mesh's triangles (`None` without triangles).
fn median_edge(mesh: &Mesh) -> Option<f64> {
    let v = &mesh.vertices;
    let mut lengths: Vec<f64> = mesh
        .triangles
        .iter()
        .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
        .map(|(i, j)| (v[i as usize] - v[j as usize]).length() as f64)
        .collect();
    super::quantile(&mut lengths, 0.5)
}

/// Runs the cells of `opts` in the current rayon pool; `on_row` sees each row as it is
/// measured.
pub fn run(
    opts: &MatrixOptions,
    progress: &dyn Progress,
    mut on_row: impl FnMut(&MatrixRow),
) -> Result<Vec<MatrixRow>, MatrixError> {
    let mut out = Vec::new();
    // The median edge length per mesh (of its triangles; `None` for a cloud).
    let mut edges: Vec<(String, Option<f64>)> = Vec::new();
    for cell in cells(opts)? {
        let path = opts.data_dir.join(file_of(&cell.mesh));
        let result = if path.exists() {
            let edge = match edges.iter().find(|(n, _)| *n == cell.mesh) {
                Some((_, e)) => *e,
                None => {
                    let e = Mesh::load(&path).ok().and_then(|m| median_edge(&m));
                    edges.push((cell.mesh.clone(), e));
                    e
                }
            };
            let mut measured = run_cell(opts, &cell, progress)?;
            measured.alpha_edge = edge.map(|e| e * measured.alpha);
            Ok(measured)
        } else {
            Err(format!("{} not found", path.display()))
        };
        let row = MatrixRow { cell, result };
        on_row(&row);
        out.push(row);
    }
    Ok(out)
}

/// Renders one cell (its `alpha_edge` left for the caller).
fn run_cell(
    opts: &MatrixOptions,
    cell: &MatrixCell,
    progress: &dyn Progress,
) -> Result<Measured, MatrixError> {
    let base = opts.data_dir.join("matrix.toml");
    let load = |camera, beta, (w, h): (u32, u32)| -> Result<_, MatrixError> {
        let mut scene = Scene::from_str(&scene_text(cell, beta, camera), &base)?;
        scene.image.width = w;
        scene.image.height = h;
        scene.validate()?;
        let built = build_scene(&scene)?;
        Ok((scene, built))
    };
    let size = (opts.width, opts.height);
    let (mut scene, mut built) = load(None, opts.beta, size)?;
    let cam = &built.camera;
    let (origin, target, fov) = (cam.origin(), cam.target(), cam.fov_y_degrees());
    let camera = (
        match cell.view {
            View::Far => origin,
            View::Close => target + CLOSE * (origin - target),
        },
        target,
        fov,
    );
    if cell.view == View::Close {
        (scene, built) = load(Some(camera), opts.beta, size)?;
    }
    let obj = &built.objects[0];
    let n = obj.sets.iter().map(|s| s.len()).sum();
    let alpha = obj.params.alpha;
    let label = cell.key();
    // `strict`: the exact reference takes hits in the band only (`band_reach` off).
    let render = |built: &crate::render::build::BuiltScene, max_steps, strict: bool| {
        render_objects(
            &built.objects,
            TracerOptions {
                certified_hits: opts.certified_hits,
                band_reach: !strict,
                ..TracerOptions::new(built.epsilon, max_steps)
            },
            &built.camera,
            &built.shaders,
            [0, 0, 0],
            &label,
            progress,
        )
    };
    let mut rendered = render(&built, scene.render.max_steps, false);
    for _ in 1..opts.repeat {
        let r = render(&built, scene.render.max_steps, false);
        if r.stats.seconds < rendered.stats.seconds {
            rendered = r;
        }
    }
    // One sample per pixel: each hit lies on its pixel-centre ray at the recorded depth.
    let gap = (!opts.certified_hits).then(|| {
        let tracer = Tracer::new(
            &built.objects,
            TracerOptions::new(built.epsilon, scene.render.max_steps),
        );
        let w = built.camera.width() as usize;
        let hits: Vec<glam::DVec3> = (rendered.depth.iter().enumerate())
            .filter(|(_, t)| t.is_finite())
            .map(|(i, &t)| {
                let (o, d) = built.camera.ray((i % w) as u32, (i / w) as u32);
                o + f64::from(t) * d
            })
            .collect();
        hit_gap::measure(&tracer, &hits)
    });
    let error = match opts.error_size {
        None => None,
        Some(es) => {
            let (s_a, b_a) = load(Some(camera), opts.beta, es)?;
            let (s_e, b_e) = load(Some(camera), 0.0, es)?;
            let a = render(&b_a, s_a.render.max_steps, false);
            let e = render(&b_e, s_e.render.max_steps, true);
            Some(compare_depths(
                &a.depth,
                &e.depth,
                1.0,
                b_e.bounds.diagonal(),
            ))
        }
    };
    Ok(Measured {
        n,
        alpha,
        alpha_edge: None,
        stats: rendered.stats,
        error,
        gap: gap.flatten(),
    })
}

/// The report as a table (columns documented in `doc/reports.md`).
pub fn table(rows: &[MatrixRow]) -> Table {
    let mut t = Table::new(&[
        ("mesh", "mesh"),
        ("type", "type"),
        ("alpha_diag", "alpha*diag"),
        ("view", "view"),
        ("n", "n"),
        ("alpha", "alpha"),
        ("alpha_edge", "alpha*edge"),
        ("width", "width"),
        ("height", "height"),
        ("seconds", "time (s)"),
        ("hits_percent", "hits %"),
        ("evals_per_hit_ray", "full/hit"),
        ("bound_evals_per_hit_ray", "bound/hit"),
        ("leaves_per_eval", "leaves/eval"),
        ("leaves_per_ray", "leaves/ray"),
        ("leaves_per_hit_ray", "leaves/hit"),
        ("error_p50", "err p50"),
        ("error_p99", "err p99"),
        ("error_only_one_percent", "1-sided %"),
        ("gap_p50", "gap p50"),
        ("gap_max", "gap max"),
        ("skipped", "skipped"),
    ]);
    for r in rows {
        let c = &r.cell;
        let mut row = vec![
            Cell::text(&c.mesh),
            Cell::text(c.kind.name()),
            Cell::num(c.alpha_rel, 0),
            Cell::text(c.view.name()),
        ];
        match &r.result {
            Ok(m) => {
                let s = &m.stats;
                let e = m.error.as_ref();
                row.extend([
                    Cell::int(m.n as i64),
                    Cell::num(m.alpha, 3),
                    Cell::num(m.alpha_edge, 2),
                    Cell::int(s.width as i64),
                    Cell::int(s.height as i64),
                    Cell::num(s.seconds, 3),
                    Cell::num(100.0 * s.hits as f64 / s.rays.max(1) as f64, 1),
                    Cell::num(s.evals_per_hit(), 2),
                    Cell::num(s.bound_evals_per_hit(), 2),
                    Cell::num(s.leaves_per_eval(), 1),
                    Cell::num(s.leaves_per_ray(), 1),
                    Cell::num(s.leaves_per_hit(), 0),
                    Cell::sci(e.and_then(|e| e.p50)),
                    Cell::sci(e.and_then(|e| e.p99)),
                    Cell::num(
                        e.map(|e| 100.0 * e.only_one as f64 / e.rays.max(1) as f64),
                        3,
                    ),
                    Cell::num(m.gap.map(|g| g.median), 2),
                    Cell::num(m.gap.map(|g| g.max), 2),
                    Cell::Empty,
                ]);
            }
            Err(reason) => {
                row.extend((0..17).map(|_| Cell::Empty));
                row.push(Cell::text(reason));
            }
        }
        t.push(row);
    }
    t
}

/// The counts a baseline keeps per cell (deterministic for a given size).
pub const GUARDED: [&str; 3] = [
    "leaves_per_ray",
    "evals_per_hit_ray",
    "bound_evals_per_hit_ray",
];

/// A guarded count that rose past the tolerance.
#[derive(Clone, Debug, PartialEq)]
pub struct Regression {
    pub key: String,
    pub column: &'static str,
    pub baseline: f64,
    pub now: f64,
}

impl std::fmt::Display for Regression {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(
            f,
            "{}: {} rose from {:.3} to {:.3} ({:+.1}%)",
            self.key,
            self.column,
            self.baseline,
            self.now,
            100.0 * (self.now / self.baseline - 1.0)
        )
    }
}

/// The guarded counts of `table` per cell key, for a baseline file (JSON object).
pub fn baseline(table: &Table) -> serde_json::Value {
    let mut cells = serde_json::Map::new();
    for row in &table.rows {
        let Some(key) = row_key(table, row) else {
            continue;
        };
        let mut counts = serde_json::Map::new();
        for col in GUARDED {
            if let Some(v) = table.column(col).and_then(|j| row[j].as_f64()) {
                counts.insert(col.to_string(), v.into());
            }
        }
        if !counts.is_empty() {
            cells.insert(key, counts.into());
        }
    }
    serde_json::Value::Object(cells)
}

fn row_key(table: &Table, row: &[Cell]) -> Option<String> {
    let text = |name: &str| match table.column(name).map(|j| &row[j]) {
        Some(Cell::Text(s)) => Some(s.clone()),
        Some(c) => c.as_f64().map(|v| v.to_string()),
        None => None,
    };
    Some(format!(
        "{}/{}/{}/{}",
        text("mesh")?,
        text("type")?,
        text("alpha_diag")?,
        text("view")?
    ))
}

/// Compares `table` with a baseline made by [`baseline`]: every guarded count of every
/// cell in both must stay within `1 + tolerance` of the baseline's (a count of zero
/// may not rise by more than `tolerance` in absolute terms). Returns the cells compared
/// and the regressions.
pub fn check(
    table: &Table,
    baseline: &serde_json::Value,
    tolerance: f64,
) -> (usize, Vec<Regression>) {
    let mut compared = 0;
    let mut bad = Vec::new();
    let fresh = self::baseline(table);
    let (Some(now), Some(base)) = (fresh.as_object(), baseline.as_object()) else {
        return (0, bad);
    };
    for (key, counts) in now {
        let Some(old) = base.get(key) else { continue };
        compared += 1;
        for col in GUARDED {
            let (Some(v), Some(b)) = (
                counts.get(col).and_then(|v| v.as_f64()),
                old.get(col).and_then(|v| v.as_f64()),
            ) else {
                continue;
            };
            if v > b * (1.0 + tolerance) + if b == 0.0 { tolerance } else { 0.0 } {
                bad.push(Regression {
                    key: key.clone(),
                    column: col,
                    baseline: b,
                    now: v,
                });
            }
        }
    }
    (compared, bad)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(leaves: f64, evals: f64) -> Table {
        let mut t = Table::new(&[
            ("mesh", "mesh"),
            ("type", "type"),
            ("alpha_diag", "alpha*diag"),
            ("view", "view"),
            ("leaves_per_ray", "leaves/ray"),
            ("evals_per_hit_ray", "full/hit"),
            ("bound_evals_per_hit_ray", "bound/hit"),
        ]);
        t.push(vec![
            Cell::text("bunny"),
            Cell::text("triangles"),
            Cell::num(250.0, 0),
            Cell::text("far"),
            Cell::num(leaves, 1),
            Cell::num(evals, 2),
            Cell::num(1.5, 2),
        ]);
        t
    }

    #[test]
    fn check_flags_a_rise_past_the_tolerance_and_only_that() {
        let base = baseline(&table(100.0, 4.0));
        assert_eq!(
            base["bunny/triangles/250/far"]["leaves_per_ray"].as_f64(),
            Some(100.0)
        );
        // Within 3%, or lower: fine.
        assert_eq!(check(&table(102.9, 4.1), &base, 0.03), (1, vec![]));
        assert_eq!(check(&table(50.0, 2.0), &base, 0.03), (1, vec![]));
        // Leaves up 3.5%: flagged, with both values.
        let (n, bad) = check(&table(103.5, 4.0), &base, 0.03);
        assert_eq!(n, 1);
        assert_eq!(bad.len(), 1);
        assert_eq!(bad[0].column, "leaves_per_ray");
        assert_eq!((bad[0].baseline, bad[0].now), (100.0, 103.5));
        assert!(bad[0].to_string().contains("+3.5%"), "{}", bad[0]);
        // Evaluations per hit ray up: flagged too.
        let (_, bad) = check(&table(100.0, 4.2), &base, 0.03);
        assert_eq!(bad.len(), 1);
        assert_eq!(bad[0].column, "evals_per_hit_ray");
        // A cell missing from the baseline is not compared.
        let other = baseline(&Table::new(&[("mesh", "mesh")]));
        assert_eq!(check(&table(1e9, 1e9), &other, 0.03), (0, vec![]));
    }

    #[test]
    fn cells_cover_every_mesh_kind_alpha_and_view_and_the_cloud_as_points_only() {
        let opts = MatrixOptions {
            data_dir: PathBuf::from("data"),
            meshes: Vec::new(),
            kinds: vec![
                PrimitiveKind::Points,
                PrimitiveKind::Edges,
                PrimitiveKind::Triangles,
            ],
            alphas_rel: ALPHAS_REL.to_vec(),
            views: vec![View::Far, View::Close],
            width: 96,
            height: 54,
            beta: 0.5,
            error_size: None,
            certified_hits: false,
            repeat: 1,
        };
        let cells = cells(&opts).unwrap();
        assert_eq!(cells.len(), (7 * 3 + 1) * 5 * 2);
        assert!(
            cells
                .iter()
                .filter(|c| c.mesh == "deer")
                .all(|c| c.kind == PrimitiveKind::Points)
        );
        let keys: std::collections::HashSet<String> = cells.iter().map(|c| c.key()).collect();
        assert_eq!(keys.len(), cells.len(), "keys are unique");
        let bad = MatrixOptions {
            meshes: vec!["teapot".into()],
            ..opts
        };
        assert!(matches!(cells_err(&bad), Some(MatrixError::UnknownMesh(m)) if m == "teapot"));
    }

    fn cells_err(o: &MatrixOptions) -> Option<MatrixError> {
        cells(o).err()
    }
}
