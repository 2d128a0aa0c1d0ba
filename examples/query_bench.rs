//! Batch queries through the Rust API, timed without loading and building: the exact
//! nearest triangle and the smooth distance (value only) at fixed-seed points, either
//! near the surface (a vertex plus a Gaussian offset of sigma 0.005 of the diagonal) or
//! uniform in the box grown by 10% of the diagonal. The Python benchmark
//! (`examples/python/bench_queries.py`) compares the package with Open3D on the same
//! kinds of points.
//!
//! Run: `cargo run --release --example query_bench -- [MESH] [--n N] [--where near|box]
//! [--alpha-rel R] [--beta B] [--repeat K] [--tol SHARE]` (defaults: data/bunny.obj,
//! 500,000, near, 1000, 0.5, 3, 1e-10).

use glam::DVec3;
use smoothtrace::api::params::Naming;
use smoothtrace::api::queries::{self, ObjectSpec};
use smoothtrace::mesh::Mesh;
use smoothtrace::primitives::PrimitiveKind;
use std::time::Instant;

#[path = "common/args.rs"]
mod args;
use args::arg;

fn points(mesh: &Mesh, n: usize, near: bool) -> Vec<DVec3> {
    let b = mesh.bounds();
    let diag = b.diagonal();
    let mut seed = 0x5EEDu64;
    let mut rnd = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            if near {
                let v = mesh.vertices
                    [(rnd() * mesh.vertices.len() as f64) as usize % mesh.vertices.len()];
                // Box-Muller.
                let g = |u1: f64, u2: f64| {
                    (-2.0 * (1.0 - u1).ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
                };
                let o = DVec3::new(g(rnd(), rnd()), g(rnd(), rnd()), g(rnd(), rnd()));
                v.as_dvec3() + 0.005 * diag * o
            } else {
                let lo = b.min.as_dvec3() - 0.1 * diag;
                let hi = b.max.as_dvec3() + 0.1 * diag;
                lo + (hi - lo) * DVec3::new(rnd(), rnd(), rnd())
            }
        })
        .collect()
}

fn best<T>(repeat: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut out = None;
    let mut t_best = f64::INFINITY;
    for _ in 0..repeat {
        let t = Instant::now();
        let r = f();
        t_best = t_best.min(t.elapsed().as_secs_f64());
        out = Some(r);
    }
    (t_best, out.unwrap())
}

fn main() {
    let mesh_path = std::env::args()
        .nth(1)
        .filter(|a| !a.starts_with("--"))
        .unwrap_or_else(|| "data/bunny.obj".into());
    let n: usize = arg("--n", 500_000);
    let near = arg("--where", "near".to_string()) == "near";
    let alpha_rel: f64 = arg("--alpha-rel", 1000.0);
    let beta: f64 = arg("--beta", 0.5);
    let repeat: usize = arg("--repeat", 3);
    let mesh = Mesh::load(mesh_path.as_ref()).expect("mesh");
    let spec = ObjectSpec::relative(vec![PrimitiveKind::Triangles], alpha_rel, beta);
    let mut object = queries::build_object(&mesh, &spec, Naming::Keyword).expect("object");
    // `--tol`: the share of the sum pruning may skip (`EvalParams::prune_tolerance`).
    object.params.prune_tolerance = arg("--tol", object.params.prune_tolerance);
    let p = points(&mesh, n, near);
    let (t_near, nn) = best(repeat, || queries::nearest(&object, &p));
    let (t_val, vals) = best(repeat, || queries::values(&object, &p));
    {
        let sets = object.set_refs();
        let mut st = smoothtrace::eval::EvalStats::default();
        for x in p.iter().take(2000) {
            st.add(&smoothtrace::eval::evaluate_value(&sets, *x, &object.params).stats);
        }
        println!(
            "per query: exact {:.1} far {:.1} nodes {:.1} pruned {:.1}",
            st.exact as f64 / 2000.0,
            st.far as f64 / 2000.0,
            st.nodes as f64 / 2000.0,
            st.pruned as f64 / 2000.0
        );
    }
    let dsum: f64 = nn.iter().map(|x| x.d).sum();
    let ssum: f64 = vals.iter().sum();
    println!(
        "{n} points ({}), {} threads: nearest {t_near:.3} s (sum d {dsum:.9e}); value alpha_rel {alpha_rel} beta {beta} {t_val:.3} s ({:.1}x nearest; sum s {ssum:.9e})",
        if near { "near" } else { "box" },
        rayon::current_num_threads(),
        t_val / t_near
    );
}
