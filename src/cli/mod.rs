//! Command-line parsing (clap derive) and dispatch. Each subcommand lives in its own
//! file, resolves and validates its flags into library types, and reports errors with
//! their cause chain and exit status 2.

mod bench;
pub(crate) mod console;
mod field;
mod matrix;
mod outputs;
mod progress;
mod query;
mod render;
mod serve;
mod stability;
mod stitch;
mod sweep;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser, Debug)]
#[command(
    name = "smoothtrace",
    version,
    about = "Sphere-trace smooth distance fields of point clouds, edge meshes and triangle meshes"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Evaluate the smooth distance, its gradient and the exact distance at query points.
    Query(query::QueryArgs),
    /// Render a scene file to a PNG image.
    Render(render::RenderArgs),
    /// Render the paper's Table 1 rows on this machine and print them beside the paper's.
    Bench(bench::BenchArgs),
    /// Render time against isosurface error over the Barnes-Hut parameter beta.
    Sweep(sweep::SweepArgs),
    /// Run the numerical stability suite with the stable and the naive evaluators.
    Stability(stability::StabilityArgs),
    /// Compute a distance field on a voxel grid (.npy), exact or smooth.
    Field(field::FieldArgs),
    /// Build a scene in the browser: a local web page with a live, progressive view.
    Serve(serve::ServeArgs),
    /// Assemble the crops written by `render --crop` into the full image.
    Stitch(stitch::StitchArgs),
}

/// Parses the command line, runs the command, and maps errors to exit status 2.
pub fn run() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Query(a) => query::run(a),
        Command::Render(a) => render::run(a),
        Command::Bench(a) => bench::run(a),
        Command::Sweep(a) => sweep::run(a),
        Command::Stability(a) => stability::run(a),
        Command::Field(a) => field::run(a),
        Command::Serve(a) => serve::run(a),
        Command::Stitch(a) => stitch::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            console::note!("smoothtrace: error: {e}");
            for cause in e.chain().skip(1) {
                console::note!("  caused by: {cause}");
            }
            ExitCode::from(2)
        }
    }
}
