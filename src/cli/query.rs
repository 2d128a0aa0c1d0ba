//! `smoothtrace query`: smooth distance, gradient, exact distance and leaves visited at
//! points read from a file or standard input.

use super::console::{Stdout, note};
use anyhow::{Context, Result, bail};
use clap::Args;
use glam::DVec3;
use smoothtrace::api::params::{self, Naming};
use smoothtrace::eval::{self, Accumulation, EvalParams};
use smoothtrace::limits;
use smoothtrace::primitives::{AnySet, PrimitiveKind};
use std::io::{BufRead, Read};
use std::path::PathBuf;

/// Longest accepted line of query points.
const MAX_LINE_BYTES: u64 = 64 * 1024;

/// Most query points per run: the points and their result lines are held in memory
/// (about 150 bytes each, 1.5 GB at this limit).
const MAX_QUERY_POINTS: usize = 10_000_000;

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
    /// How far pruning may lower the smooth distance at most (a length; 0 = no pruning;
    /// default: a share 1e-10 of the sum, within 2e-10 / alpha).
    #[arg(long, allow_negative_numbers = true)]
    tolerance: Option<f64>,
    /// Use the paper's naive (unshifted) accumulation; prints inf where it underflows.
    #[arg(long)]
    naive: bool,
    /// Signed exact distance: the fifth column is negative inside the solid (fast
    /// winding number of the mesh's triangles above 1/2) and a seventh column holds the
    /// winding number.
    #[arg(long)]
    signed: bool,
    /// Far-field parameter of the fast winding number, in [0, 1) (0 = exact sum).
    #[arg(long, requires = "signed", default_value_t = smoothtrace::winding::DEFAULT_BETA)]
    winding_beta: f64,
    /// File of whitespace-separated `x y z` lines (default: standard input).
    #[arg(long)]
    points: Option<PathBuf>,
}

pub fn run(a: QueryArgs) -> Result<()> {
    params::check_beta(Naming::Flag, a.beta)?;
    // Before any work: a closed standard output fails here.
    let mut out = Stdout::open()?;
    // Lidar coordinates are recentred on load; query points stay in file coordinates.
    let (mesh, origin) = smoothtrace::load::load_with_origin(&a.mesh, &a.primitive)?;
    let mut sets = Vec::new();
    for &kind in &a.primitive {
        if !sets.iter().any(|s: &AnySet| s.kind() == kind) {
            sets.push(AnySet::build(&mesh, kind)?);
        }
    }
    let diag = mesh.bounds().diagonal();
    let resolve = |key: &str, abs, rel| {
        params::resolve_alpha(Naming::Flag, key, abs, rel, diag)
            .with_context(|| a.mesh.display().to_string())
    };
    let alpha = resolve("alpha", a.alpha, a.alpha_rel)?.context("give --alpha or --alpha-rel")?;
    let max_alpha = resolve("max_alpha", a.max_alpha, a.max_alpha_rel)?.unwrap_or(alpha);
    let mut params = EvalParams::new(alpha, max_alpha, a.beta);
    params::apply_tolerance(Naming::Flag, a.tolerance, &mut params)?;
    if a.naive {
        params.accumulation = Accumulation::Naive;
    }
    let n: usize = sets.iter().map(|s| s.len()).sum();
    note!(
        "{}: {} {} ({} primitives), diagonal {diag}, alpha {alpha} (alpha * diagonal = {}), max_alpha {max_alpha}, beta {}, {}, {} accumulation",
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
        if params.prune {
            format!("pruning lowers s by at most {:.3e}", params.pruning_bound())
        } else {
            "no pruning".to_string()
        },
        if a.naive { "naive" } else { "stable" },
    );
    let solid = if a.signed {
        let beta = smoothtrace::api::signed::check_beta("--winding-beta", a.winding_beta)?;
        Some(
            smoothtrace::winding::Solid::from_mesh(&mesh, beta)
                .context("--signed needs the mesh's triangles")?,
        )
    } else {
        None
    };
    let queries: Vec<DVec3> = read_points(a.points.as_ref())?
        .into_iter()
        .map(|x| x - origin)
        .collect();
    let set_refs: Vec<&AnySet> = sets.iter().collect();
    let winding = solid
        .as_ref()
        .map(|s| smoothtrace::api::signed::winding_numbers(s, &queries));
    let results: Vec<String> = {
        use rayon::prelude::*;
        queries
            .par_iter()
            .enumerate()
            .map(|(i, &x)| {
                let s = eval::evaluate(&set_refs, x, &params);
                let d = eval::nearest(&set_refs, x).d;
                let line = format!("{} {} {} {}", s.s, s.grad.x, s.grad.y, s.grad.z);
                match &winding {
                    None => format!("{line} {d} {}", s.stats.leaves()),
                    Some(w) => format!(
                        "{line} {} {} {}",
                        smoothtrace::winding::sign(w[i]) * d,
                        s.stats.leaves(),
                        w[i]
                    ),
                }
            })
            .collect()
    };
    let underflows = results.iter().filter(|l| l.starts_with("inf")).count();
    for line in &results {
        out.write(line)?;
        out.write("\n")?;
    }
    out.finish()?;
    if a.naive && underflows > 0 {
        note!(
            "warning: the naive sum underflowed (s = inf) at {underflows} of {} queries; the stable evaluation (without --naive) does not",
            results.len()
        );
    }
    Ok(())
}

/// Reads `x y z` lines from a regular file or standard input, at most
/// [`limits::MAX_INPUT_BYTES`] in all and [`MAX_LINE_BYTES`] per line, so an endless
/// input (a device, a runaway pipe) fails instead of exhausting memory.
fn read_points(path: Option<&PathBuf>) -> Result<Vec<DVec3>> {
    let (name, reader): (String, Box<dyn Read>) = match path {
        Some(p) => (
            p.display().to_string(),
            Box::new(
                limits::open_input_file(p)
                    .with_context(|| format!("{}: cannot read query points", p.display()))?,
            ),
        ),
        None => ("<stdin>".into(), Box::new(std::io::stdin().lock())),
    };
    let mut reader = std::io::BufReader::new(reader.take(limits::MAX_INPUT_BYTES + 1));
    let mut out = Vec::new();
    let mut total = 0u64;
    let mut buf = Vec::new();
    for i in 0.. {
        buf.clear();
        let n = (&mut reader)
            .take(MAX_LINE_BYTES + 1)
            .read_until(b'\n', &mut buf)
            .with_context(|| format!("{name}: cannot read line {}", i + 1))?;
        if n == 0 {
            break;
        }
        total += n as u64;
        if total > limits::MAX_INPUT_BYTES {
            bail!(
                "{name}: more than {} bytes of query points; split the input",
                limits::MAX_INPUT_BYTES
            );
        }
        if buf.len() as u64 > MAX_LINE_BYTES {
            bail!(
                "{name}:{}: line longer than {MAX_LINE_BYTES} bytes (expected `x y z`)",
                i + 1
            );
        }
        let line = std::str::from_utf8(&buf)
            .map_err(|_| anyhow::anyhow!("{name}:{}: not UTF-8 text (expected `x y z`)", i + 1))?;
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
        if let Some(problem) = v.iter().find_map(|&c| limits::query_coordinate_problem(c)) {
            bail!("{name}:{}: query coordinate {problem}", i + 1);
        }
        if out.len() == MAX_QUERY_POINTS {
            bail!(
                "{name}:{}: more than {MAX_QUERY_POINTS} query points; split the input",
                i + 1
            );
        }
        out.push(DVec3::new(v[0], v[1], v[2]));
    }
    Ok(out)
}
