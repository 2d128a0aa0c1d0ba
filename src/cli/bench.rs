//! `smoothtrace bench`: the paper's Table 1 rendered on this machine (see
//! `smoothtrace::reports::bench`).

use super::console::{Stdout, note};
use super::progress::Bars;
use anyhow::{Context, Result, bail};
use clap::Args;
use smoothtrace::reports::bench::{self, BenchOptions};
use smoothtrace::reports::table::write_file;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Directory holding the Table 1 scene files (`<row>.toml`).
    #[arg(long, default_value = "scenes")]
    scenes_dir: PathBuf,
    /// Rows to run, comma-separated (default: all of Table 1).
    #[arg(long, value_delimiter = ',')]
    rows: Vec<String>,
    /// Image width (default 1920, like the reference renderer).
    #[arg(long)]
    width: Option<i64>,
    /// Image height (default 1080).
    #[arg(long)]
    height: Option<i64>,
    /// A small image (240x135) for CI; --width/--height still win.
    #[arg(long)]
    quick: bool,
    /// Worker threads (0 = all cores).
    #[arg(long, default_value_t = 0)]
    threads: i64,
    /// Also render each row with the paper's algorithm on our engine (naive sum, no
    /// pruning, no ray clipping, no coarse steps, fixed-step backtracking) and print the
    /// speedup per ray.
    #[arg(long)]
    paper_mode: bool,
    /// Size of the paper-mode renders, WIDTHxHEIGHT (default: the same as ours; a
    /// smaller one is faster, and the speedup is then per ray).
    #[arg(long, value_name = "WxH", requires = "paper_mode")]
    paper_size: Option<String>,
    /// Render each row this many times and report the fastest, with the median beside it
    /// (1..=20; a busy or virtual machine's noise then shows and mostly drops out).
    #[arg(long, default_value_t = 1)]
    repeat: i64,
    /// Write the table as CSV.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Write the table as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
    /// The speed matrix instead of Table 1 (issue 30): meshes x primitive kinds x alpha *
    /// diagonal x far/close views, auto-framed, 480x270 by default (`reports::matrix`).
    #[command(flatten)]
    matrix: super::matrix::MatrixArgs,
}

pub(super) fn size(name: &str, v: i64) -> Result<u32> {
    let max = smoothtrace::scene::MAX_IMAGE_SIZE as i64;
    if !(1..=max).contains(&v) {
        bail!("--{name} must be in 1..={max} (got {v})");
    }
    Ok(v as u32)
}

/// Parses `WxH`.
pub fn parse_size(text: &str) -> Result<(u32, u32)> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .with_context(|| format!("'{text}' is not a size: write WIDTHxHEIGHT, e.g. 480x270"))?;
    let p = |s: &str| {
        s.trim()
            .parse::<i64>()
            .with_context(|| format!("'{text}' is not a size: write WIDTHxHEIGHT, e.g. 480x270"))
    };
    Ok((
        size("paper-size width", p(w)?)?,
        size("paper-size height", p(h)?)?,
    ))
}

pub fn run(a: BenchArgs) -> Result<()> {
    if a.matrix.matrix {
        let (w, h) = (a.width.unwrap_or(480), a.height.unwrap_or(270));
        let (w, h) = (size("width", w)?, size("height", h)?);
        if !(0..=1024).contains(&a.threads) {
            bail!("--threads must be in 0..=1024 (got {})", a.threads);
        }
        if !(1..=20).contains(&a.repeat) {
            bail!("--repeat must be in 1..=20 (got {})", a.repeat);
        }
        let common = super::matrix::Common {
            width: w,
            height: h,
            threads: a.threads as usize,
            repeat: a.repeat as usize,
            csv: a.csv,
            json: a.json,
        };
        return super::matrix::run(a.matrix, common);
    }
    let (dw, dh) = if a.quick { (240, 135) } else { (1920, 1080) };
    let width = size("width", a.width.unwrap_or(dw))?;
    let height = size("height", a.height.unwrap_or(dh))?;
    if !(0..=1024).contains(&a.threads) {
        bail!("--threads must be in 0..=1024 (got {})", a.threads);
    }
    if !(1..=20).contains(&a.repeat) {
        bail!("--repeat must be in 1..=20 (got {})", a.repeat);
    }
    let paper_mode = match (&a.paper_size, a.paper_mode) {
        (Some(s), _) => Some(parse_size(s)?),
        (None, true) => Some((width, height)),
        (None, false) => None,
    };
    let opts = BenchOptions {
        scenes_dir: a.scenes_dir,
        rows: a.rows,
        width,
        height,
        threads: a.threads as usize,
        paper_mode,
        repeat: a.repeat as usize,
    };
    bench::select_rows(&opts.rows)?;
    super::outputs::check_report_outputs(&a.csv, &a.json, None)?;
    let pool =
        smoothtrace::reports::pool(opts.threads).context("cannot start the worker threads")?;
    let bars = Bars::default();
    let rows = pool.install(|| {
        bench::run(&opts, &bars, |r| match &r.result {
            Ok(m) => note!(
                "{}: {:.3} s ({} x {}, {} threads)",
                r.paper.name,
                m.stats.seconds,
                m.stats.width,
                m.stats.height,
                m.stats.threads
            ),
            Err(reason) => note!("{}: skipped: {reason}", r.paper.name),
        })
    })?;
    let table = bench::table(&rows);
    let mut out = Stdout::open()?;
    out.write(&bench::text(&table))?;
    out.write(&format!(
        "paper: 2015 laptop, 4 cores, 1920x1080; ours: {} threads; times are the tracing loop only\n",
        rayon_threads(&rows)
    ))?;
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

fn rayon_threads(rows: &[bench::BenchRow]) -> String {
    rows.iter()
        .find_map(|r| r.result.as_ref().ok().map(|m| m.stats.threads.to_string()))
        .unwrap_or_else(|| "-".into())
}
