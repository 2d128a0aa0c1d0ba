//! `value_and_gradient` through the Rust API, to compare with the Python package's
//! (`examples/python/bench_value_and_gradient.py`, README "Python"): the smooth distance
//! and its gradient at N fixed-seed points (half near the surface, half in the box grown
//! by 10%) on a mesh's triangles, with `eval::evaluate` in a rayon `par_iter`, timed
//! without loading and building. The points are written to (or, when the file exists,
//! read from) a raw little-endian f64 file so the Python script queries the same ones.
//!
//! Run: `cargo run --release --example api_bench -- [MESH] [--points FILE] [--n N]
//! [--alpha-rel R] [--beta B] [--repeat K]` (defaults: data/bunny.obj, /tmp/smoothtrace_points.f64,
//! 1,000,000, 1000, 0.5, 1).

use glam::DVec3;
use rayon::prelude::*;
use smoothtrace::eval::{self, EvalParams};
use smoothtrace::mesh::Mesh;
use smoothtrace::primitives::{AnySet, PrimitiveKind};
use std::path::PathBuf;
use std::time::Instant;

#[path = "common/args.rs"]
mod args;
use args::arg;

/// CPU seconds of this process so far (all threads; user + system), from
/// `/proc/self/stat`; NaN where that file does not exist.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the parenthesised command name; utime and stime are the 12th and 13th.
    let rest = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = rest
        .split_whitespace()
        .skip(11)
        .take(2)
        .filter_map(|v| v.parse().ok())
        .collect();
    if f.len() == 2 {
        (f[0] + f[1]) / 100.0 // USER_HZ is 100 on Linux.
    } else {
        f64::NAN
    }
}

#[path = "common/queries.rs"]
mod queries;

fn main() {
    let mesh_path = std::env::args()
        .nth(1)
        .filter(|a| !a.starts_with("--"))
        .unwrap_or_else(|| "data/bunny.obj".into());
    let file: PathBuf = arg("--points", PathBuf::from("/tmp/smoothtrace_points.f64"));
    let n: usize = arg("--n", 1_000_000);
    let alpha_rel: f64 = arg("--alpha-rel", 1000.0);
    let beta: f64 = arg("--beta", 0.5);
    let repeat: usize = arg("--repeat", 1);
    let mesh = Mesh::load(mesh_path.as_ref()).unwrap_or_else(|e| {
        eprintln!("api_bench: {e}");
        std::process::exit(2)
    });
    let set = AnySet::build(&mesh, PrimitiveKind::Triangles).expect("a mesh with faces");
    let alpha = alpha_rel / mesh.bounds().diagonal();
    let params = EvalParams::new(alpha, alpha, beta);
    let queries = match std::fs::read(&file) {
        Ok(bytes) => bytes
            .chunks_exact(24)
            .map(|c| {
                let f = |k: usize| f64::from_le_bytes(c[8 * k..8 * k + 8].try_into().unwrap());
                DVec3::new(f(0), f(1), f(2))
            })
            .collect(),
        Err(_) => {
            let q = queries::queries(&mesh, n);
            let bytes: Vec<u8> = q
                .iter()
                .flat_map(|p| p.to_array())
                .flat_map(f64::to_le_bytes)
                .collect();
            std::fs::write(&file, bytes).expect("write the points file");
            q
        }
    };
    let sets = [&set];
    let mut best = f64::INFINITY;
    let mut best_cpu = f64::INFINITY;
    let mut checksum = 0.0;
    for _ in 0..repeat {
        let t = Instant::now();
        let c = cpu_seconds();
        let out: Vec<(f64, DVec3)> = queries
            .par_iter()
            .map(|&x| {
                let s = eval::evaluate(&sets, x, &params);
                (s.s, s.grad)
            })
            .collect();
        best = best.min(t.elapsed().as_secs_f64());
        best_cpu = best_cpu.min(cpu_seconds() - c);
        checksum = out.iter().map(|(s, _)| s).sum::<f64>();
    }
    println!(
        "rust api: {} points, {} triangles, alpha_rel {alpha_rel}, beta {beta}, {} threads: {best:.3} s wall, {best_cpu:.2} s CPU (best of {repeat}), sum of s {checksum:.9e}",
        queries.len(),
        set.len(),
        rayon::current_num_threads()
    );
}
