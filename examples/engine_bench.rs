//! Engine benchmark (issue 2): queries per second and mean leaves visited for the
//! bunny's points, edges and triangles (`data/bunny-7k.obj` scaled by 10, like the
//! paper's bunny) at beta 0 and 0.5, with and without negligible-subtree pruning, and
//! BVH build time and peak memory for the 8-million-point lidar scan.
//!
//! Run: `cargo run --release --example engine_bench [-- --csv engine_bench.csv]`

use glam::Vec3;
use rayon::prelude::*;
use smoothtrace::eval::{self, EvalParams};
use smoothtrace::mesh::Mesh;
use smoothtrace::primitives::{AnySet, PrimitiveKind};
use std::io::Write;
use std::path::Path;
use std::time::Instant;

fn peak_rss_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map(|kb| kb / 1024.0)
        .unwrap_or(f64::NAN)
}

#[path = "common/queries.rs"]
mod queries;
use queries::queries;

fn main() {
    let csv = std::env::args().skip_while(|a| a != "--csv").nth(1);
    let mut rows = vec!["mesh,primitive,count,alpha,beta,prune,queries,seconds,queries_per_second,mean_leaves,mean_nodes".to_string()];
    let threads = rayon::current_num_threads();
    println!("threads: {threads}");
    let bunny = Path::new("data/bunny-7k.obj");
    if bunny.exists() {
        let mut mesh = Mesh::load(bunny).expect("bunny");
        mesh.transform(Vec3::splat(10.0), glam::Quat::IDENTITY, Vec3::ZERO);
        let qs = queries(&mesh, 200_000);
        println!(
            "{:<10} {:>6} {:>7} {:>5} {:>6} {:>12} {:>12} {:>10}",
            "primitive", "n", "alpha", "beta", "prune", "queries/s", "mean leaves", "mean nodes"
        );
        for kind in [
            PrimitiveKind::Points,
            PrimitiveKind::Edges,
            PrimitiveKind::Triangles,
        ] {
            let set = AnySet::build(&mesh, kind).unwrap();
            for alpha in [100.0, 1200.0] {
                for beta in [0.0, 0.5] {
                    for prune in [true, false] {
                        let mut p = EvalParams::new(alpha, alpha, beta);
                        p.prune = prune;
                        let n = if prune { qs.len() } else { qs.len() / 20 };
                        let t = Instant::now();
                        let stats: Vec<_> = qs[..n]
                            .par_iter()
                            .map(|&x| eval::evaluate(&[&set], x, &p).stats)
                            .collect();
                        let secs = t.elapsed().as_secs_f64();
                        let leaves =
                            stats.iter().map(|s| s.leaves() as f64).sum::<f64>() / n as f64;
                        let nodes = stats.iter().map(|s| s.nodes as f64).sum::<f64>() / n as f64;
                        println!(
                            "{:<10} {:>6} {:>7} {:>5} {:>6} {:>12.0} {:>12.1} {:>10.1}",
                            kind.name(),
                            set.len(),
                            alpha,
                            beta,
                            prune,
                            n as f64 / secs,
                            leaves,
                            nodes
                        );
                        rows.push(format!(
                            "bunny-7k x10,{},{},{alpha},{beta},{prune},{n},{secs},{},{leaves},{nodes}",
                            kind.name(), set.len(), n as f64 / secs
                        ));
                    }
                }
            }
        }
    } else {
        println!("skipping the bunny: data/bunny-7k.obj not found");
    }
    let lidar = Path::new("data/autzen-lidar-8m.ply");
    if lidar.exists() {
        let t = Instant::now();
        let mesh = Mesh::load(lidar).expect("lidar");
        let load = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let set = AnySet::build(&mesh, PrimitiveKind::Points).unwrap();
        let build = t.elapsed().as_secs_f64();
        println!(
            "lidar: {} points, load {load:.2} s, points + BVH build {build:.2} s (BVH {:.2} s), {} nodes, depth {}, set memory {:.0} MiB, peak RSS {:.0} MiB",
            set.len(),
            set.times().bvh,
            set.bvh().nodes.len(),
            set.bvh().depth(),
            set.memory_bytes() as f64 / 1048576.0,
            peak_rss_mib()
        );
        let qs = queries(&mesh, 100_000);
        let diag = mesh.bounds().diagonal();
        for (alpha_rel, beta) in [(1000.0, 0.5), (1000.0, 0.0)] {
            let p = EvalParams::new(alpha_rel / diag, alpha_rel / diag, beta);
            let t = Instant::now();
            let leaves: u64 = qs
                .par_iter()
                .map(|&x| eval::evaluate(&[&set], x, &p).stats.leaves() as u64)
                .sum();
            let secs = t.elapsed().as_secs_f64();
            println!(
                "lidar queries: alpha*diag {alpha_rel} beta {beta}: {:.0} queries/s, mean leaves {:.1}",
                qs.len() as f64 / secs,
                leaves as f64 / qs.len() as f64
            );
        }
    } else {
        println!("skipping the lidar: data/autzen-lidar-8m.ply not found");
    }
    if let Some(path) = csv {
        let mut f = std::fs::File::create(&path).expect("csv");
        for r in rows {
            writeln!(f, "{r}").unwrap();
        }
        println!("wrote {path}");
    }
}
