//! Fast winding numbers (issue 32): accuracy against the exact solid-angle sum and speed,
//! per `beta`, on data meshes.
//!
//! ```text
//! cargo run --release --example winding_bench -- [--threads N] [--points N]
//!     [--exact N] [--betas 0.3,0.5,0.7] [--single] [--csv out.csv] [MESH.obj ...]
//! ```
//! Query points are uniform in the mesh's box grown by 10% of its diagonal on every
//! side (fixed seed). For each mesh and beta: the time for `--points` queries
//! (default 1M), the largest and mean error against the exact sum on the first
//! `--exact` points (default 2000), counting only points farther than 1e-3 of the
//! diagonal from the surface, and the number of sign disagreements (`w > 1/2`) there.
//! `--single` times one walk per query instead of the grouped batch
//! (`winding::batch`); the accuracy columns are always the single walk's.

use glam::DVec3;
use rayon::prelude::*;
use smoothtrace::eval;
use smoothtrace::mesh::Mesh;
use smoothtrace::winding::{Solid, exact};
use std::io::Write;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let (mut threads, mut n, mut n_exact) = (2usize, 1_000_000usize, 2000usize);
    let mut betas = vec![0.3, 0.5, 0.7];
    let mut csv = None;
    let mut single = false;
    let mut meshes = Vec::new();
    while let Some(a) = args.next() {
        let mut val = || {
            args.next()
                .ok_or_else(|| anyhow::anyhow!("{a} needs a value"))
        };
        match a.as_str() {
            "--threads" => threads = val()?.parse()?,
            "--points" => n = val()?.parse()?,
            "--exact" => n_exact = val()?.parse()?,
            "--betas" => {
                betas = val()?
                    .split(',')
                    .map(|b| b.parse())
                    .collect::<Result<_, _>>()?
            }
            "--csv" => csv = Some(val()?),
            "--single" => single = true,
            _ => meshes.push(a),
        }
    }
    if meshes.is_empty() {
        meshes = ["bunny", "spot", "cow", "fandisk"]
            .iter()
            .map(|m| format!("data/{m}.obj"))
            .collect();
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let mut rows = vec![
        "mesh,triangles,beta,points,threads,build_s,query_s,us_per_point_thread,max_err,mean_err,sign_errors,checked".to_string(),
    ];
    for path in &meshes {
        let mesh = match Mesh::load(std::path::Path::new(path)) {
            Ok(m) => m,
            Err(e) => {
                eprintln!("skipping {path}: {e}");
                continue;
            }
        };
        let b = mesh.bounds();
        let diag = b.diagonal();
        let (lo, hi) = (b.min.as_dvec3() - 0.1 * diag, b.max.as_dvec3() + 0.1 * diag);
        let mut seed = 12345u64;
        let pts: Vec<DVec3> = (0..n.max(n_exact))
            .map(|_| {
                let mut u = || {
                    seed = seed
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    (seed >> 11) as f64 / (1u64 << 53) as f64
                };
                lo + (hi - lo) * DVec3::new(u(), u(), u())
            })
            .collect();
        let tris: Vec<[DVec3; 3]> = mesh
            .triangles
            .iter()
            .map(|t| t.map(|i| mesh.vertices[i as usize].as_dvec3()))
            .collect();
        let check: Vec<(DVec3, f64)> = pool.install(|| {
            pts[..n_exact]
                .par_iter()
                .map(|&q| (q, exact::winding_number(&tris, q)))
                .collect()
        });
        for &beta in &betas {
            let t = Instant::now();
            let solid = pool.install(|| Solid::from_mesh(&mesh, beta))?;
            let build = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let w: Vec<f64> = pool.install(|| {
                if single {
                    pts[..n]
                        .par_iter()
                        .map_init(Vec::new, |st, &q| solid.winding_number(q, st))
                        .collect()
                } else {
                    smoothtrace::winding::batch::winding_numbers(
                        solid.tree(),
                        solid.triangles(),
                        beta,
                        &pts[..n],
                    )
                }
            });
            let query = t.elapsed().as_secs_f64();

            let mut st = Vec::new();
            let diff = (0..1000.min(n))
                .map(|i| (w[i] - solid.winding_number(pts[i], &mut st)).abs())
                .fold(0.0, f64::max);
            eprintln!("  batch vs single: {diff:e}");
            let (mut fars, mut exacts) = (0u64, 0u64);
            let mut st = Vec::new();
            for &q in &pts[..n_exact] {
                let (_, f, e) =
                    solid
                        .tree()
                        .winding_number_counted(solid.triangles(), q, beta, &mut st);
                fars += f as u64;
                exacts += e as u64;
            }
            eprintln!(
                "  per point: {} far fields, {} exact triangles",
                fars as f64 / n_exact as f64,
                exacts as f64 / n_exact as f64
            );
            let (mut max, mut sum, mut count, mut signs) = (0.0f64, 0.0, 0usize, 0usize);
            let mut st = Vec::new();
            for &(q, we) in &check {
                if eval::nearest(&[solid.set()], q).d <= 1e-3 * diag {
                    continue;
                }
                let wf = solid.winding_number(q, &mut st);
                let e = (wf - we).abs();
                max = max.max(e);
                sum += e;
                count += 1;
                signs += usize::from((wf > 0.5) != (we > 0.5));
            }
            let row = format!(
                "{},{},{beta},{n},{threads},{build:.4},{query:.4},{:.3},{max:.2e},{:.2e},{signs},{count}",
                mesh.name,
                mesh.triangles.len(),
                query * 1e6 * threads as f64 / n as f64,
                sum / count.max(1) as f64,
            );
            println!("{row}");
            rows.push(row);
        }
    }
    if let Some(p) = csv {
        let mut f = std::fs::File::create(&p)?;
        for r in &rows {
            writeln!(f, "{r}")?;
        }
        eprintln!("wrote {p}");
    }
    Ok(())
}
