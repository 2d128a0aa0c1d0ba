//! Up-front checks of the report outputs (`--csv`, `--json`, `--plot`), so a bad path
//! fails before a long bench or sweep instead of after it (issue 10, defect 5). The
//! writes themselves go through `smoothtrace::output` (temporary file, then rename).

use anyhow::Result;
use smoothtrace::output::{IMAGE_8BIT, Kind, Output};
use smoothtrace::reports::table::create_parent;
use std::path::PathBuf;

/// Checks the table outputs and an optional plot (creating missing parent folders, as
/// the reports always did).
pub fn check_report_outputs(
    csv: &Option<PathBuf>,
    json: &Option<PathBuf>,
    plot: Option<&PathBuf>,
) -> Result<()> {
    for (p, kind) in [(csv, Kind::Csv), (json, Kind::Json)] {
        if let Some(p) = p {
            create_parent(p)?;
            Output::check_as(p, kind)?;
        }
    }
    if let Some(p) = plot {
        create_parent(p)?;
        Output::check(p, IMAGE_8BIT, "the plot")?;
    }
    Ok(())
}
