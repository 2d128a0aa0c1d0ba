//! `smoothtrace sweep SCENE...`: render time against isosurface error over beta, or the
//! Thingi10K-style query grid with `--grid N` (see `smoothtrace::reports::sweep`).

use super::console::{Stdout, note};
use super::progress::Bars;
use anyhow::{Context, Result, bail};
use clap::Args;
use smoothtrace::reports::sweep::{self, GridOptions, SweepOptions};
use smoothtrace::reports::table::{Table, write_file};
use smoothtrace::reports::{parse_list, plot};
use smoothtrace::scene::AlphaSpec;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct SweepArgs {
    /// Scene files; several (one model as points, edges, triangles) give one curve each.
    #[arg(required = true)]
    scenes: Vec<PathBuf>,
    /// Betas, comma-separated, in [0, 1] (default 0, 0.1, ..., 1).
    #[arg(long)]
    betas: Option<String>,
    /// Absolute alphas to sweep as well, comma-separated (default: each scene's own).
    #[arg(long, conflicts_with = "alphas_rel")]
    alphas: Option<String>,
    /// Alphas relative to each object's bounding-box diagonal, comma-separated.
    #[arg(long)]
    alphas_rel: Option<String>,
    /// Image width (default: the scene's).
    #[arg(long)]
    width: Option<i64>,
    /// Image height (default: the scene's).
    #[arg(long)]
    height: Option<i64>,
    /// Worker threads (0 = all cores).
    #[arg(long, default_value_t = 0)]
    threads: i64,
    /// Skip the naive-sum render at the scene's beta.
    #[arg(long)]
    no_naive: bool,
    /// Render with the paper's algorithm (naive sum, no pruning, no clipping, no coarse
    /// steps, fixed-step backtracking) instead of ours.
    #[arg(long)]
    paper_mode: bool,
    /// Grid mode: query the first object's mesh (scaled to a diagonal of 0.5) at the
    /// voxel centres of an N^3 grid instead of rendering.
    #[arg(long, value_name = "N")]
    grid: Option<i64>,
    /// Write the table as CSV.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Write the table as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Write the plot as PNG.
    #[arg(long)]
    plot: Option<PathBuf>,
}

fn list(flag: &str, text: &str) -> Result<Vec<f64>> {
    parse_list(text)
        .map_err(|e| anyhow::anyhow!("--{flag} {text:?}: {e} (write e.g. --{flag} 0,0.25,0.5)"))
}

fn size(name: &str, v: Option<i64>) -> Result<Option<u32>> {
    let max = smoothtrace::scene::MAX_IMAGE_SIZE as i64;
    match v {
        Some(v) if !(1..=max).contains(&v) => bail!("--{name} must be in 1..={max} (got {v})"),
        v => Ok(v.map(|v| v as u32)),
    }
}

fn write_outputs(a: &SweepArgs, table: &Table) -> Result<()> {
    let mut out = Stdout::open()?;
    out.write(&table.to_text())?;
    out.finish()?;
    if let Some(p) = &a.csv {
        table
            .write_csv(p)
            .with_context(|| format!("cannot write {}", p.display()))?;
    }
    if let Some(p) = &a.json {
        write_file(p, &serde_json::to_string_pretty(&table.to_json())?)
            .with_context(|| format!("cannot write {}", p.display()))?;
    }
    Ok(())
}

pub fn run(a: SweepArgs) -> Result<()> {
    let betas = match &a.betas {
        Some(t) => list("betas", t)?,
        None => sweep::default_betas(),
    };
    let alphas: Vec<AlphaSpec> = match (&a.alphas, &a.alphas_rel) {
        (Some(t), _) => list("alphas", t)?
            .into_iter()
            .map(AlphaSpec::Absolute)
            .collect(),
        (None, Some(t)) => list("alphas-rel", t)?
            .into_iter()
            .map(AlphaSpec::Relative)
            .collect(),
        _ => Vec::new(),
    };
    if !(0..=1024).contains(&a.threads) {
        bail!("--threads must be in 0..=1024 (got {})", a.threads);
    }
    let opts = SweepOptions {
        scenes: a.scenes.clone(),
        betas,
        alphas,
        width: size("width", a.width)?,
        height: size("height", a.height)?,
        threads: a.threads as usize,
        naive: !a.no_naive,
        paper_mode: a.paper_mode,
    };
    opts.validate()?;
    super::outputs::check_report_outputs(&a.csv, &a.json, a.plot.as_ref())?;
    let pool =
        smoothtrace::reports::pool(opts.threads).context("cannot start the worker threads")?;
    let bars = Bars::default();
    if let Some(n) = a.grid {
        if !(1..=1024).contains(&n) {
            bail!("--grid must be in 1..=1024 (got {n})");
        }
        let g = GridOptions {
            scenes: opts.scenes.clone(),
            betas: opts.betas.clone(),
            n: n as usize,
        };
        let rows = pool.install(|| {
            sweep::run_grid(&g, &bars, |r| {
                note!(
                    "{} beta {}: {:.2} us/query, {:.1} leaves/query",
                    r.scene,
                    r.beta,
                    r.us_per_query,
                    r.leaves_mean
                )
            })
        })?;
        write_outputs(&a, &sweep::grid_table(&rows))?;
        if let Some(p) = &a.plot {
            let title = format!(
                "Time per query against leaves visited ({n}^3 grid, diagonal 0.5, {} threads)",
                pool.current_num_threads()
            );
            plot::grid_plot(p, &title, &sweep::grid_series(&rows))?;
        }
        return Ok(());
    }
    let rows = pool.install(|| {
        sweep::run(&opts, &bars, |r| {
            note!(
                "{} beta {} {}: {:.3} s, mean error {:.2e}",
                r.scene,
                r.beta,
                r.evaluation,
                r.seconds,
                r.depth.mean.unwrap_or(0.0)
            )
        })
    })?;
    write_outputs(&a, &sweep::table(&rows))?;
    if let Some(p) = &a.plot {
        let (w, h) = rows.first().map(|r| (r.width, r.height)).unwrap_or((0, 0));
        let title = format!(
            "Render time and isosurface error against beta ({w}x{h}, {} threads)",
            pool.current_num_threads()
        );
        plot::sweep_plot(p, &title, &sweep::plot_series(&rows))?;
    }
    Ok(())
}
