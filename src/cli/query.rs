//! `smoothtrace query`: smooth distance, gradient, exact distance and leaves visited at
//! points read from a file or standard input.

use anyhow::{Context, Result, bail};
use clap::Args;
use glam::DVec3;
use smoothtrace::api::params::{self, Naming};
use smoothtrace::eval::{self, Accumulation, EvalParams};
use smoothtrace::primitives::{AnySet, PrimitiveKind};
use std::io::{BufRead, BufWriter, Write};
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct QueryArgs {
    /// Mesh file (.obj, .ply, .stl), or a lidar point cloud (.las, .laz; query points in
    /// its file coordinates).
    mesh: PathBuf,
    /// Primitive set(s) to use; repeat or comma-separate to sum several.
    #[arg(long, short, value_delimiter = ',', required = true)]
    primitive: Vec<PrimitiveKind>,
    /// Sharpness alpha (1/length).
    #[arg(
        long,
        conflicts_with = "alpha_rel",
        required_unless_present = "alpha_rel"
    )]
    alpha: Option<f64>,
    /// Sharpness relative to the bounding-box diagonal: alpha = ALPHA_REL / diagonal.
    #[arg(long, allow_negative_numbers = true)]
    alpha_rel: Option<f64>,
    /// Weight attenuation threshold (default: alpha).
    #[arg(long, conflicts_with = "max_alpha_rel", allow_negative_numbers = true)]
    max_alpha: Option<f64>,
    /// max_alpha relative to the diagonal.
    #[arg(long)]
    max_alpha_rel: Option<f64>,
    /// Barnes-Hut opening parameter in [0, 1] (0 = exact sum).
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true)]
    beta: f64,
    /// Use the paper's naive (unshifted) accumulation; prints inf where it underflows.
    #[arg(long)]
    naive: bool,
    /// File of whitespace-separated `x y z` lines (default: standard input).
    #[arg(long)]
    points: Option<PathBuf>,
}

pub fn run(a: QueryArgs) -> Result<()> {
    params::check_beta(Naming::Flag, a.beta)?;
    // Lidar coordinates are recentred on load; query points stay in file coordinates.
    let (mesh, origin) = smoothtrace::las::load_mesh(&a.mesh, &a.primitive)?;
    let mut sets = Vec::new();
    for &kind in &a.primitive {
        if !sets.iter().any(|s: &AnySet| s.kind() == kind) {
            sets.push(AnySet::build(&mesh, kind)?);
        }
    }
    let diag = mesh.bounds().diagonal();
    let alpha = params::resolve_alpha(Naming::Flag, "alpha", a.alpha, a.alpha_rel, diag)?
        .context("give --alpha or --alpha-rel")?;
    let max_alpha = params::resolve_alpha(
        Naming::Flag,
        "max_alpha",
        a.max_alpha,
        a.max_alpha_rel,
        diag,
    )?
    .unwrap_or(alpha);
    let mut params = EvalParams::new(alpha, max_alpha, a.beta);
    if a.naive {
        params.accumulation = Accumulation::Naive;
    }
    let n: usize = sets.iter().map(|s| s.len()).sum();
    eprintln!(
        "{}: {} {} ({} primitives), diagonal {diag}, alpha {alpha} (alpha * diagonal = {}), max_alpha {max_alpha}, beta {}, {} accumulation",
        a.mesh.display(),
        mesh.name,
        a.primitive
            .iter()
            .map(|k| k.name())
            .collect::<Vec<_>>()
            .join("+"),
        n,
        alpha * diag,
        a.beta,
        if a.naive { "naive" } else { "stable" },
    );
    let queries: Vec<DVec3> = read_points(a.points.as_ref())?
        .into_iter()
        .map(|x| x - origin)
        .collect();
    let set_refs: Vec<&AnySet> = sets.iter().collect();
    let results: Vec<String> = {
        use rayon::prelude::*;
        queries
            .par_iter()
            .map(|&x| {
                let s = eval::evaluate(&set_refs, x, &params);
                let d = eval::nearest(&set_refs, x).d;
                format!(
                    "{} {} {} {} {} {}",
                    s.s,
                    s.grad.x,
                    s.grad.y,
                    s.grad.z,
                    d,
                    s.stats.leaves()
                )
            })
            .collect()
    };
    let underflows = results.iter().filter(|l| l.starts_with("inf")).count();
    let stdout = std::io::stdout();
    let mut out = BufWriter::new(stdout.lock());
    for line in &results {
        writeln!(out, "{line}")?;
    }
    out.flush()?;
    if underflows > 0 {
        eprintln!(
            "warning: the naive sum underflowed (s = inf) at {underflows} of {} queries; the stable evaluation (without --naive) does not",
            results.len()
        );
    }
    Ok(())
}

fn read_points(path: Option<&PathBuf>) -> Result<Vec<DVec3>> {
    let (name, reader): (String, Box<dyn BufRead>) = match path {
        Some(p) => (
            p.display().to_string(),
            Box::new(std::io::BufReader::new(
                std::fs::File::open(p)
                    .with_context(|| format!("{}: cannot open query points", p.display()))?,
            )),
        ),
        None => ("<stdin>".into(), Box::new(std::io::stdin().lock())),
    };
    let mut out = Vec::new();
    for (i, line) in reader.lines().enumerate() {
        let line = line.with_context(|| format!("{name}: cannot read line {}", i + 1))?;
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let v: Vec<f64> = t
            .split_whitespace()
            .map(|w| w.parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| {
                anyhow::anyhow!(
                    "{name}:{}: expected three numbers `x y z`, got `{t}`",
                    i + 1
                )
            })?;
        if v.len() != 3 {
            bail!(
                "{name}:{}: expected three numbers `x y z`, got {} values",
                i + 1,
                v.len()
            );
        }
        if v.iter().any(|c| !c.is_finite()) {
            bail!(
                "{name}:{}: query coordinates must be finite, got `{t}`",
                i + 1
            );
        }
        out.push(DVec3::new(v[0], v[1], v[2]));
    }
    Ok(out)
}
