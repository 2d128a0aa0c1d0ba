//! Oracle for a segment evaluation (doc/performance-log.md, round thirty-six): how many
//! exact evaluations a ray takes within 50 epsilons of the surface when it steps by the
//! exact smooth distance (sphere tracing), against the same march that also takes the
//! longest stretch `[x, x + L u]` on which no point can be within epsilon of the zero
//! set: `-ln(sum_j w_max exp(-alpha f_j)) / alpha > epsilon`, `f_j` the distance from the
//! stretch to edge `j` (every term at every point of the stretch is at most
//! `w_max exp(-alpha f_j)`), by brute force over every edge. Edges only; both marches
//! must agree on every hit. Every other pixel of a 160x90 image:
//! `cargo run --release --example segment_oracle -- SCENE.toml`
use glam::DVec3;
use rayon::prelude::*;
use smoothtrace::eval::evaluate_value;
use smoothtrace::geometry::segments::segment_distance2;
use smoothtrace::primitives::{AnySet, WeightScale};
use smoothtrace::render::build::build_scene;
use smoothtrace::scene::Scene;
use std::path::Path;

fn main() {
    if let Err(e) = run() {
        eprintln!("segment_oracle: {e}");
        std::process::exit(2);
    }
}

fn run() -> Result<(), String> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: segment_oracle SCENE.toml (one object of edges)")?;
    let mut scene = Scene::load(Path::new(&path)).map_err(|e| e.to_string())?;
    let (w, h) = (160u32, 90u32);
    scene.image.width = w;
    scene.image.height = h;
    let built = build_scene(&scene).map_err(|e| e.to_string())?;
    let eps = built.epsilon;
    let cam = &built.camera;
    let (obj, es) = match (
        built.objects.as_slice(),
        built.objects.first().map(|o| o.sets.as_slice()),
    ) {
        ([obj], Some([AnySet::Edges(es)])) => (obj, es),
        _ => return Err(format!("{path}: expected one object made of one edge set")),
    };
    let sets = obj.set_refs();
    let mut p = obj.params;
    p.beta = 0.0;
    let alpha = p.alpha;
    let edges: Vec<(DVec3, DVec3)> = es
        .prims
        .iter()
        .map(|e| (e.a.as_dvec3(), e.b.as_dvec3()))
        .collect();
    let wmax = WeightScale::new(es.max_adj, alpha, p.max_alpha).max_weight();
    let exact = |x: DVec3| evaluate_value(&sets, x, &p).s;
    // The segment bound: -ln(sum w_max exp(-alpha f_j)) / alpha, the sum shifted by its min.
    let seg_bound = |x: DVec3, y: DVec3| -> f64 {
        let f: Vec<f64> = edges
            .iter()
            .map(|&(a, b)| segment_distance2(x, y, a, b).sqrt())
            .collect();
        let m = f.iter().cloned().fold(f64::INFINITY, f64::min);
        let sum: f64 = f.iter().map(|&fj| (-alpha * (fj - m)).exp()).sum();
        m - (wmax * sum).ln() / alpha
    };
    let bounds = obj.bounds;
    let diag = (bounds.max - bounds.min).length() as f64;
    let rows: Vec<(bool, u32, u32)> = (0..h)
        .step_by(2)
        .flat_map(|py| (0..w).step_by(2).map(move |px| (px, py)))
        .collect::<Vec<_>>()
        .into_par_iter()
        .filter_map(|(px, py)| {
            let (o, d) = cam.ray(px, py);
            // Past the data's box by two diagonals: a miss.
            let t_end =
                (o - 0.5 * (bounds.min.as_dvec3() + bounds.max.as_dvec3())).length() + 2.0 * diag;
            let march = |seg: bool| -> (bool, u32) {
                let mut t = 0.0;
                let mut n = 0;
                let mut it = 0;
                while t < t_end && it < 2000 {
                    it += 1;
                    let x = o + t * d;
                    let s = exact(x);
                    if s <= 50.0 * eps {
                        n += 1;
                    }
                    if s <= eps {
                        return (true, n);
                    }
                    if s > 50.0 * eps || !seg {
                        t += s;
                        continue;
                    }
                    // longest certified stretch by doubling then bisection
                    let ok = |l: f64| seg_bound(x, x + l * d) > eps;
                    let mut lo = s;
                    let mut hi = 2.0 * s;
                    while hi < t_end - t && ok(hi) {
                        lo = hi;
                        hi *= 2.0;
                    }
                    for _ in 0..12 {
                        let mid = 0.5 * (lo + hi);
                        if ok(mid) { lo = mid } else { hi = mid }
                    }
                    t += lo.max(s);
                }
                (false, n)
            };
            let (hit0, n0) = march(false);
            // only rays that come within 50 eps matter
            if n0 == 0 {
                return None;
            }
            let (hit1, n1) = march(true);
            assert_eq!(hit0, hit1, "px {px} {py}");
            Some((hit0, n0, n1))
        })
        .collect();
    for hit in [true, false] {
        let sel: Vec<_> = rows.iter().filter(|r| r.0 == hit).collect();
        let n0: u32 = sel.iter().map(|r| r.1).sum();
        let n1: u32 = sel.iter().map(|r| r.2).sum();
        println!(
            "hit {hit}: rays {} exact steps {} ({:.2}/ray), with segment stretches {} ({:.2}/ray)",
            sel.len(),
            n0,
            n0 as f64 / sel.len().max(1) as f64,
            n1,
            n1 as f64 / sel.len().max(1) as f64
        );
    }
    Ok(())
}
