//! `smoothtrace bench --matrix`: the speed matrix (see `smoothtrace::reports::matrix`),
//! its baseline of counts and the check against it.

use super::console::{Stdout, note};
use super::progress::Bars;
use anyhow::{Context, Result, bail};
use clap::Args;
use smoothtrace::primitives::PrimitiveKind;
use smoothtrace::reports::matrix::{self, MatrixOptions, View};
use smoothtrace::reports::table::write_file;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct MatrixArgs {
    /// Run the speed matrix instead of Table 1.
    #[arg(long)]
    pub matrix: bool,
    /// Folder holding the meshes (the shared data, linked as `data/`).
    #[arg(long, default_value = "data", requires = "matrix")]
    data_dir: PathBuf,
    /// Meshes, comma-separated (default: bunny-7k, bunny, spot, fandisk, beast,
    /// rocker-arm, homer, deer).
    #[arg(long, value_delimiter = ',', requires = "matrix")]
    meshes: Vec<String>,
    /// Primitive kinds, comma-separated (default: points, edges, triangles).
    #[arg(long, value_delimiter = ',', requires = "matrix")]
    kinds: Vec<String>,
    /// Alpha times each mesh's bounding-box diagonal, comma-separated (default 100, 250,
    /// 1000, 3000, 10000).
    #[arg(long, value_delimiter = ',', requires = "matrix")]
    alphas_rel: Vec<f64>,
    /// Views, comma-separated: far (auto-framed), close (0.4 of the distance).
    #[arg(long, value_delimiter = ',', requires = "matrix")]
    views: Vec<String>,
    /// Barnes-Hut opening parameter of the renders.
    #[arg(long, default_value_t = 0.5, requires = "matrix")]
    beta: f64,
    /// Also measure the depth error against the exact (beta 0) render of each cell, at
    /// this size WIDTHxHEIGHT (e.g. 120x68).
    #[arg(long, value_name = "WxH", requires = "matrix")]
    error_size: Option<String>,
    /// Write the cells' counts (leaves per ray, full evaluations and bound steps per hit
    /// ray) as a baseline JSON file.
    #[arg(long, requires = "matrix")]
    write_baseline: Option<PathBuf>,
    /// Compare the cells' counts with this baseline: an error (exit status 2) when any
    /// rose by more than --tolerance.
    #[arg(long, requires = "matrix")]
    check: Option<PathBuf>,
    /// Relative rise of a count that --check tolerates.
    #[arg(long, default_value_t = 0.03, requires = "matrix")]
    tolerance: f64,
}

/// The flags the matrix shares with Table 1's bench.
pub struct Common {
    pub width: u32,
    pub height: u32,
    pub threads: usize,
    pub repeat: usize,
    pub csv: Option<PathBuf>,
    pub json: Option<PathBuf>,
}

fn kind(s: &str) -> Result<PrimitiveKind> {
    Ok(match s {
        "points" => PrimitiveKind::Points,
        "edges" => PrimitiveKind::Edges,
        "triangles" => PrimitiveKind::Triangles,
        _ => bail!("--kinds: '{s}' is not a primitive kind (points, edges, triangles)"),
    })
}

pub fn run(a: MatrixArgs, c: Common) -> Result<()> {
    let kinds = if a.kinds.is_empty() {
        vec![
            PrimitiveKind::Points,
            PrimitiveKind::Edges,
            PrimitiveKind::Triangles,
        ]
    } else {
        a.kinds.iter().map(|k| kind(k)).collect::<Result<_>>()?
    };
    let views = if a.views.is_empty() {
        vec![View::Far, View::Close]
    } else {
        a.views
            .iter()
            .map(|v| View::parse(v).with_context(|| format!("--views: '{v}' is not far or close")))
            .collect::<Result<_>>()?
    };
    let alphas_rel = if a.alphas_rel.is_empty() {
        matrix::ALPHAS_REL.to_vec()
    } else {
        a.alphas_rel.clone()
    };
    if let Some(bad) = alphas_rel.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
        bail!("--alphas-rel: {bad} is not a positive number");
    }
    if !(0.0..=1.0).contains(&a.beta) {
        bail!("--beta must be in [0, 1] (got {})", a.beta);
    }
    if !(a.tolerance.is_finite() && a.tolerance >= 0.0) {
        bail!("--tolerance must be a number >= 0 (got {})", a.tolerance);
    }
    let error_size = a
        .error_size
        .as_deref()
        .map(super::bench::parse_size)
        .transpose()?;
    if !a.data_dir.is_dir() {
        bail!(
            "--data-dir {}: no such folder (link the shared meshes: ln -s ../shared/data data)",
            a.data_dir.display()
        );
    }
    let baseline = match &a.check {
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .with_context(|| format!("cannot read the baseline {}", p.display()))?;
            Some(
                serde_json::from_str::<serde_json::Value>(&text)
                    .with_context(|| format!("{}: not a JSON baseline", p.display()))?,
            )
        }
        None => None,
    };
    let opts = MatrixOptions {
        data_dir: a.data_dir,
        meshes: a.meshes,
        kinds,
        alphas_rel,
        views,
        width: c.width,
        height: c.height,
        beta: a.beta,
        error_size,
        repeat: c.repeat,
    };
    let cells = matrix::cells(&opts)?;
    super::outputs::check_report_outputs(&c.csv, &c.json, None)?;
    let pool = smoothtrace::reports::pool(c.threads).context("cannot start the worker threads")?;
    let bars = Bars::default();
    let total = cells.len();
    let mut done = 0;
    let rows = pool.install(|| {
        matrix::run(&opts, &bars, |r| {
            done += 1;
            match &r.result {
                Ok(m) => note!(
                    "[{done}/{total}] {}: {:.3} s, {:.2} full evaluations per hit ray, {:.1} leaves per ray",
                    r.cell.key(),
                    m.stats.seconds,
                    m.stats.evals_per_hit(),
                    m.stats.leaves_per_ray()
                ),
                Err(reason) => note!("[{done}/{total}] {}: skipped: {reason}", r.cell.key()),
            }
        })
    })?;
    let table = matrix::table(&rows);
    let mut out = Stdout::open()?;
    out.write(&table.to_text())?;
    out.finish()?;
    if let Some(p) = &c.csv {
        table
            .write_csv(p)
            .with_context(|| format!("cannot write {}", p.display()))?;
    }
    if let Some(p) = &c.json {
        write_file(p, &serde_json::to_string_pretty(&table.to_json())?)
            .with_context(|| format!("cannot write {}", p.display()))?;
    }
    if let Some(p) = &a.write_baseline {
        write_file(p, &serde_json::to_string_pretty(&matrix::baseline(&table))?)
            .with_context(|| format!("cannot write {}", p.display()))?;
    }
    if let Some(b) = &baseline {
        let (compared, bad) = matrix::check(&table, b, a.tolerance);
        for r in &bad {
            note!("regression: {r}");
        }
        if !bad.is_empty() {
            bail!(
                "{} of {compared} cells rose by more than {:.1}% against the baseline",
                bad.len(),
                100.0 * a.tolerance
            );
        }
        note!(
            "{compared} cells within {:.1}% of the baseline",
            100.0 * a.tolerance
        );
    }
    Ok(())
}
