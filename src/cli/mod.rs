//! Command-line parsing (clap derive) and dispatch. Each subcommand lives in its own
//! file, resolves and validates its flags into library types, and reports errors with
//! their cause chain and exit status 2.

mod field;
mod query;

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
    /// Compute a distance field on a voxel grid (.npy), exact or smooth.
    Field(field::FieldArgs),
}

/// Parses the command line, runs the command, and maps errors to exit status 2.
pub fn run() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Query(a) => query::run(a),
        Command::Field(a) => field::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("smoothtrace: error: {e}");
            for cause in e.chain().skip(1) {
                eprintln!("  caused by: {cause}");
            }
            ExitCode::from(2)
        }
    }
}
