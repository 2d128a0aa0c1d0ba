//! Times loading a mesh and building a primitive set's BVH, step by step, with the
//! process CPU time beside the wall time (the machine is shared: CPU time is steadier).
//!
//!     cargo run --release --example build_bench -- data/autzen-lidar-8m.ply [points|edges|triangles] [repeats]

use smoothtrace::bvh::{self, BuildOptions};
use smoothtrace::mesh::Mesh;
use smoothtrace::primitives::{AnySet, PrimitiveKind};
use std::time::Instant;

/// User + system CPU seconds of this process so far (from /proc, 10 ms resolution).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command name (which is in parentheses): utime is the 12th, stime the 13th.
    let rest = stat.rsplit_once(')').map(|(_, r)| r).unwrap_or("");
    let f: Vec<f64> = rest
        .split_whitespace()
        .map(|x| x.parse().unwrap_or(0.0))
        .collect();
    (f.get(11).unwrap_or(&0.0) + f.get(12).unwrap_or(&0.0)) / 100.0
}

fn timed<T>(what: &str, f: impl FnOnce() -> T) -> T {
    let (t, c) = (Instant::now(), cpu_seconds());
    let out = f();
    eprintln!(
        "{what}: {:.3} s wall, {:.2} s CPU",
        t.elapsed().as_secs_f64(),
        cpu_seconds() - c
    );
    out
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .first()
        .map(String::as_str)
        .unwrap_or("data/autzen-lidar-8m.ply");
    let kind = args.get(1).map(String::as_str).unwrap_or("points");
    let kind = <PrimitiveKind as clap::ValueEnum>::from_str(kind, true)
        .map_err(|e| anyhow::anyhow!("primitive kind: {e}"))?;
    let repeats: usize = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(3);
    for _ in 0..repeats {
        let mesh = timed("load", || Mesh::load(std::path::Path::new(path)))?;
        let set = timed("primitive set (primitives + BVH + wide)", || {
            AnySet::build(&mesh, kind)
        })?;
        if kind == PrimitiveKind::Points {
            // The steps of the points build, one by one.
            let mut bvh = timed("  binary BVH of the vertices", || {
                bvh::build_binary_points(&mesh.vertices, BuildOptions::default())
            });
            timed("  wide form", || bvh.make_wide());
        }
        eprintln!(
            "  {} primitives, BVH {:.3} s, {} nodes, depth {}",
            set.len(),
            set.times().bvh,
            set.bvh().nodes.len(),
            set.bvh().depth()
        );
    }
    Ok(())
}
