//! `smoothtrace stitch`: assembles the crops written by `render --crop` into the full
//! image (`film::crop::stitch` checks sizes, overlaps and coverage).

use super::console::note;
use anyhow::Result;
use clap::Args;
use smoothtrace::output::{Kind, Output};
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct StitchArgs {
    /// The crops (PNG files written by `render --crop`), in any order.
    #[arg(required = true)]
    crops: Vec<PathBuf>,
    /// The full image (.png).
    #[arg(short, long)]
    output: PathBuf,
}

pub fn run(a: StitchArgs) -> Result<()> {
    let out = Output::check(&a.output, &[Kind::Png], "the stitched image")?;
    let img = smoothtrace::film::crop::stitch(&a.crops)?;
    out.write_image(&img)?;
    note!(
        "{} crops -> {} ({}x{})",
        a.crops.len(),
        a.output.display(),
        img.width(),
        img.height()
    );
    Ok(())
}
