//! `smoothtrace stability`: the numerical stability suite (see
//! `smoothtrace::reports::stability`). Exit status 1 when the stable evaluator violates
//! anything (the naive one's infinities are expected and only reported).

use super::console::{Stdout, note};
use super::progress::Bars;
use anyhow::{Context, Result, bail};
use clap::Args;
use smoothtrace::reports::stability::{self, Size};
use smoothtrace::reports::table::write_file;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct StabilityArgs {
    /// Suite size: small (seconds; what the test suite runs) or full.
    #[arg(long, value_enum, default_value_t = Size::Full)]
    size: Size,
    /// Worker threads (0 = all cores).
    #[arg(long, default_value_t = 0)]
    threads: i64,
    /// Write the table as CSV.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Write the table as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
}

pub fn run(a: StabilityArgs) -> Result<()> {
    if !(0..=1024).contains(&a.threads) {
        bail!("--threads must be in 0..=1024 (got {})", a.threads);
    }
    let pool = smoothtrace::reports::pool(a.threads as usize)
        .context("cannot start the worker threads")?;
    super::outputs::check_report_outputs(&a.csv, &a.json, None)?;
    let report = pool.install(|| stability::run(a.size, &Bars::default()));
    let table = stability::table(&report);
    let mut out = Stdout::open()?;
    out.write(&stability::text(&table))?;
    if let Some(p) = &a.csv {
        table
            .write_csv(p)
            .with_context(|| format!("cannot write {}", p.display()))?;
    }
    if let Some(p) = &a.json {
        write_file(p, &serde_json::to_string_pretty(&table.to_json())?)
            .with_context(|| format!("cannot write {}", p.display()))?;
    }
    let naive = report
        .results
        .iter()
        .filter(|r| r.evaluator == stability::Evaluator::Naive && !r.violations.is_empty())
        .count();
    let bad = report.stable_violations();
    out.write(&format!(
        "stable evaluator: {} violation(s); naive evaluator: {naive} case(s) with infinities, NaN or other failures (expected far away and at stiff alpha)\n",
        bad.len()
    ))?;
    out.finish()?;
    if !bad.is_empty() {
        for v in &bad {
            note!("smoothtrace: stable evaluator: {v}");
        }
        std::process::exit(1);
    }
    Ok(())
}
