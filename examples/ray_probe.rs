//! Ray probe: replays the tracer's march on a sample of hit rays and prints, per step,
//! the bound value (coarse beta), the full value and the exact (beta 0) value, so the
//! final approach can be studied. Run:
//! `cargo run --release --example ray_probe -- scenes/deer_alpha1.toml [W H]`
//! Other modes, after `W H`: `PX PY` (one pixel with and without relaxed steps, and the
//! field around its hit), `evalstats` (exact, far, pruned terms and nodes per full
//! evaluation near hits), `histogram` (full evaluations per hit ray), `cgf` (points only:
//! step length over `s` before hits from the quadratic bound, Bennett's inequality,
//! `eval::reach` and the exact per-term bound, against the distance left to the hit),
//! `cost` (microseconds per evaluation: value, value with free distance, gradient; at
//! points far apart, and at the same point again, whose data the caches then hold),
//! `hitcheck` (every pixel's ray traced by tiles, as renders trace them; the exact
//! value, beta 0, at each hit point in epsilons: how far the hits sit from the exact
//! zero set, and the share outside the hit band). A last argument `fixed-step-beta`
//! turns the tiles' learned step beta (`render::step_beta`) off. `betas [B1,B2,...]`: at
//! points of the exact surface, how far each beta's sum lies below the exact value, and its leaves.
use glam::DVec3;
use rayon::prelude::*;
use smoothtrace::eval::evaluate_value;
use smoothtrace::render::TracerOptions;
use smoothtrace::render::build::build_scene;
use smoothtrace::render::cone::{ConeStats, Tile, trace_tile};
use smoothtrace::render::image::TILE;
use smoothtrace::render::tracer::{RayResult, RayStats, Tracer};
use smoothtrace::reports::quantile;
use smoothtrace::scene::Scene;
use std::path::Path;

/// Prints `message` and exits with status 2 (bad arguments or input).
fn fail(message: String) -> ! {
    eprintln!("ray_probe: {message}");
    std::process::exit(2);
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1) else {
        fail("usage: ray_probe SCENE.toml [W H] [MODE ...] (modes: see the file's docs)".into())
    };
    let mut scene = Scene::load(Path::new(path)).unwrap_or_else(|e| fail(e.to_string()));
    let size = |i: usize, default: u32| match args.get(i) {
        None => default,
        Some(v) => match v.parse::<u32>() {
            Ok(n) if n > 0 => n,
            _ => fail(format!(
                "argument {i}: expected an image size >= 1, got '{v}'"
            )),
        },
    };
    let (w, h) = (size(2, 160), size(3, 90));
    scene.image.width = w;
    scene.image.height = h;
    let built = build_scene(&scene).unwrap_or_else(|e| fail(format!("{path}: {e}")));
    // A last argument `fixed-step-beta` turns the tiles' learned step beta off.
    let learn_step_beta = args.last().map(String::as_str) != Some("fixed-step-beta");
    let opts = TracerOptions {
        learn_step_beta,
        ..TracerOptions::new(built.epsilon, scene.render.max_steps)
    };
    let tracer = Tracer::new(&built.objects, opts);
    let eps = built.epsilon;
    let cam = &built.camera;
    let obj = &built.objects[0];
    let sets = obj.set_refs();
    let pixel = |i: usize| args.get(i).and_then(|a| a.parse::<u32>().ok());
    if let (Some(px), Some(py)) = (pixel(4), pixel(5)) {
        let (o, d) = cam.ray(px, py);
        let mut p = obj.params;
        p.beta = 0.0;
        let exact = |x: DVec3| evaluate_value(&sets, x, &p).s;
        for relax in [false, true] {
            let tr = Tracer::new(&built.objects, TracerOptions { relax, ..opts });
            let mut st = RayStats::default();
            let (s0, _) = tr.field(o, &mut st);
            let r = tr.trace(o, d, s0);
            println!(
                "relax {relax}: hit {:?} evals {} bound {}",
                r.hit.map(|h| h.t),
                r.stats.evals,
                r.stats.coarse_evals
            );
            if let Some(h) = r.hit {
                let mut line = String::new();
                for k in -20..=20 {
                    let t = h.t + k as f64 * 0.5 * eps;
                    let mut st = RayStats::default();
                    line += &format!(
                        " {:.2}/{:.2}",
                        tr.field(o + t * d, &mut st).0 / eps,
                        exact(o + t * d) / eps
                    );
                }
                println!("  s_BH/s_exact around the hit, steps of eps/2 (in eps): {line}");
            }
        }
        return;
    }
    if args.get(4).map(String::as_str) == Some("betas") {
        // At points of the exact surface (an exact march, beta 0, on every ninth pixel
        // of every ninth row), how far below the exact value each beta's sum lies, in
        // epsilons, and its leaves: the far field's deficit (performance log, round
        // fifteen). The tracer's pruning tolerance throughout.
        let ev = |x: DVec3, beta: f64| {
            let mut p = obj.params;
            p.beta = beta;
            p.prune_tolerance = (0.025 * p.alpha * eps).min(1e-2);
            let r = evaluate_value(&sets, x, &p);
            (r.s / eps, r.stats.leaves(), (r.s_upper - r.s) / eps)
        };
        // The betas: a comma-separated list after `betas`, or these.
        let betas: Vec<f64> = args.get(5).map_or(vec![0.0, 0.1, 0.3, 0.5, 1.0, 4.0], |a| {
            a.split(',')
                .map(|b| b.parse().expect("betas: a list like 0,0.3,0.5"))
                .collect()
        });
        let mut rows: Vec<Vec<(f64, u32, f64)>> = Vec::new();
        for py in (0..h).step_by(9) {
            for px in (0..w).step_by(9) {
                let (o, d) = cam.ray(px, py);
                let mut t = 0.0;
                let mut hit = false;
                for _ in 0..5000 {
                    let s = ev(o + t * d, 0.0).0 * eps;
                    if s < eps {
                        hit = true;
                        break;
                    }
                    t += s;
                    if t > tracer.farthest(o) {
                        break;
                    }
                }
                if hit {
                    rows.push(betas.iter().map(|&b| ev(o + t * d, b)).collect());
                }
            }
        }
        println!(
            "alpha {:.4} (alpha x epsilon {:.3}), {} exact hit points: median deficit below the exact value (epsilons) / mean leaves",
            obj.params.alpha,
            obj.params.alpha * eps,
            rows.len()
        );
        for (k, b) in betas.iter().enumerate() {
            let mut def: Vec<f64> = rows.iter().map(|r| r[0].0 - r[k].0).collect();
            let leaves = rows.iter().map(|r| r[k].1 as f64).sum::<f64>() / rows.len().max(1) as f64;
            let mut gap: Vec<f64> = rows.iter().map(|r| r[k].2).collect();
            println!(
                "beta {b}: {:.2} / {leaves:.0}; certified gap median {:.2} max {:.2}",
                quantile(&mut def, 0.5).unwrap_or(f64::NAN),
                quantile(&mut gap, 0.5).unwrap_or(f64::NAN),
                quantile(&mut gap, 1.0).unwrap_or(f64::NAN)
            );
        }
        return;
    }
    if args.get(4).map(String::as_str) == Some("hitcheck") {
        let mut p = obj.params;
        p.beta = 0.0;
        // Traced by tiles from the camera's clearance, as renders trace them (cone
        // marches, neighbours' balls, the tile's learned step beta).
        let (s0, _) = tracer.field(cam.origin(), &mut RayStats::default());
        let tiles: Vec<Tile> = (0..h.div_ceil(TILE))
            .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx, ty)))
            .map(|(tx, ty)| Tile {
                x0: tx * TILE,
                y0: ty * TILE,
                w: TILE.min(w - tx * TILE),
                h: TILE.min(h - ty * TILE),
            })
            .collect();
        let mut v: Vec<f64> = tiles
            .into_par_iter()
            .flat_map_iter(|tile| {
                let mut values = Vec::new();
                let mut out = |_, _, r: RayResult| {
                    if let Some(hit) = r.hit {
                        values.push(evaluate_value(&sets, hit.point, &p).s / eps);
                    }
                };
                let mut cones = ConeStats::default();
                let sub = [0.5, 0.5];
                trace_tile(&tracer, cam, tile, sub, s0, true, &mut cones, &mut out);
                values
            })
            .collect();
        if v.is_empty() {
            println!("no ray hits");
            return;
        }
        let mut q = |f: f64| quantile(&mut v, f).unwrap_or(f64::NAN);
        let (p1, p50, p99, p999, max) = (q(0.01), q(0.5), q(0.99), q(0.999), q(1.0));
        let outside = v.iter().filter(|x| x.abs() > 1.0).count();
        println!(
            "hits {}: exact value at the hit points (epsilons) mean {:.3}, p1 {p1:.3}, median {p50:.3}, p99 {p99:.3}, p99.9 {p999:.3}, max {max:.3}; outside the band {} ({:.2}%)",
            v.len(),
            v.iter().sum::<f64>() / v.len() as f64,
            outside,
            100.0 * outside as f64 / v.len() as f64
        );
        return;
    }
    if args.get(4).map(String::as_str) == Some("histogram") {
        // Full evaluations per hit ray, traced alone from the camera's clearance.
        let mut hist = [0u32; 12];
        let mut st = RayStats::default();
        let (s0, _) = tracer.field(cam.origin(), &mut st);
        for py in 0..h {
            for px in 0..w {
                let (o, d) = cam.ray(px, py);
                let r = tracer.trace(o, d, s0);
                if r.hit.is_some() {
                    hist[(r.stats.evals as usize).min(11)] += 1;
                }
            }
        }
        println!("full evaluations per hit ray (0..10, 11+): {hist:?}");
        return;
    }
    if args.get(4).map(String::as_str) == Some("cgf") {
        // Step bounds at points before the hit, from the exact sum over all points:
        // plain s, the Hoeffding quadratic root, the exact cumulant bound
        // s + K(L) > 0 (K(L) = -ln E_p[exp(-alpha a L)] / alpha, a = d/dt of each
        // distance), and the distance left to the hit.
        let smoothtrace::primitives::AnySet::Points(ps) = sets[0] else {
            panic!("points only")
        };
        let alpha = obj.params.alpha;
        let pts: Vec<DVec3> = ps.prims.iter().map(|q| q.p.as_dvec3()).collect();
        let mut rows: Vec<[f64; 7]> = Vec::new();
        for py in (0..h).step_by(6) {
            for px in (0..w).step_by(6) {
                let (o, d) = cam.ray(px, py);
                let Some(hit) = tracer.trace(o, d, 0.0).hit else {
                    continue;
                };
                for back in [1.5, 3.0, 6.0, 12.0, 24.0, 48.0, 96.0] {
                    let t = hit.t - back * eps;
                    let x = o + t * d;
                    let ds: Vec<(f64, f64)> = pts
                        .iter()
                        .map(|q| {
                            let v = x - *q;
                            let l = v.length();
                            (l, v.dot(d) / l.max(1e-300))
                        })
                        .collect();
                    let m = ds.iter().map(|e| e.0).fold(f64::INFINITY, f64::min);
                    let sum: f64 = ds.iter().map(|e| (-alpha * (e.0 - m)).exp()).sum();
                    let s0 = m - sum.ln() / alpha;
                    if s0 <= 0.0 {
                        continue;
                    }
                    let mu: f64 = ds
                        .iter()
                        .map(|e| (-alpha * (e.0 - m)).exp() * e.1)
                        .sum::<f64>()
                        / sum;
                    let bound = |l: f64| {
                        let e: f64 = ds
                            .iter()
                            .map(|e| (-alpha * (e.0 - m) - alpha * e.1 * l).exp())
                            .sum::<f64>()
                            / sum;
                        s0 - e.ln() / alpha
                    };
                    let (mut lo, mut hi) = (0.0, 2.0 * (hit.t - t) + 4.0 * s0);
                    for _ in 0..40 {
                        let mid = 0.5 * (lo + hi);
                        if bound(mid) > 0.0 { lo = mid } else { hi = mid }
                    }
                    let quad = (mu + (mu * mu + 2.0 * alpha * s0).sqrt()) / alpha;
                    // Bennett: E exp(-aL A) <= exp(-aL mu + var/b^2 (e^{aLb} - 1 - aLb)),
                    // b = 1 + mu.
                    let var: f64 = ds
                        .iter()
                        .map(|e| (-alpha * (e.0 - m)).exp() * (e.1 - mu) * (e.1 - mu))
                        .sum::<f64>()
                        / sum;
                    let bb = (1.0 + mu).max(1e-12);
                    let bennett = |l: f64| {
                        let y = alpha * l * bb;
                        s0 + mu * l - var / (alpha * bb * bb) * (y.exp() - 1.0 - y)
                    };
                    let (mut blo, mut bhi) = (0.0, 2.0 * (hit.t - t) + 4.0 * s0);
                    for _ in 0..60 {
                        let mid = 0.5 * (blo + bhi);
                        if bennett(mid) > 0.0 {
                            blo = mid
                        } else {
                            bhi = mid
                        }
                    }
                    // What the evaluator computes (eval::reach).
                    let mut slopes = smoothtrace::eval::reach::Slopes::default();
                    for e in &ds {
                        slopes.add((-alpha * (e.0 - m)).exp(), e.1);
                    }
                    let binned = slopes.free_distance(s0, m, alpha, 0.0, 1e9);
                    rows.push([
                        s0 / eps,
                        quad.max(s0) / s0,
                        lo / s0,
                        (hit.t - t) / s0,
                        -mu,
                        blo.max(s0) / s0,
                        binned / s0,
                    ]);
                }
            }
        }
        for (lo, hi) in [
            (1.0, 2.0),
            (2.0, 4.0),
            (4.0, 8.0),
            (8.0, 16.0),
            (16.0, 32.0),
            (32.0, 64.0),
            (64.0, 1e9),
        ] {
            let sel: Vec<&[f64; 7]> = rows.iter().filter(|r| r[0] >= lo && r[0] < hi).collect();
            let n = sel.len() as f64;
            if n == 0.0 {
                continue;
            }
            let mean = |k: usize| sel.iter().map(|r| r[k]).sum::<f64>() / n;
            println!(
                "s/eps in [{lo}, {hi}): {n} samples; step / s: quadratic {:.2}, Bennett {:.2}, eval::reach {:.2}, cumulant {:.2}, to the hit {:.2}; slope -mu {:.2}",
                mean(1),
                mean(5),
                mean(6),
                mean(2),
                mean(3),
                mean(4)
            );
        }
        return;
    }
    if args.get(4).map(String::as_str) == Some("cost") {
        // Time per evaluation near hits: value only, value with the free distance,
        // with the gradient.
        let mut xs = Vec::new();
        for py in (0..h).step_by(2) {
            for px in (0..w).step_by(2) {
                let (o, d) = cam.ray(px, py);
                if let Some(hit) = tracer.trace(o, d, 0.0).hit {
                    for back in [2.0, 8.0, 32.0] {
                        xs.push((hit.point - back * eps * d, d));
                    }
                }
            }
        }
        let mut p = obj.params;
        p.prune_tolerance = (0.005 * p.alpha * eps).min(1e-2);
        let eval = |mode: usize, x: DVec3, d: DVec3| match mode {
            0 => evaluate_value(&sets, x, &p).s,
            1 => smoothtrace::eval::evaluate_reach(&sets, x, d, &p, 1e9, false).reach,
            _ => smoothtrace::eval::evaluate(&sets, x, &p).s,
        };
        for mode in [0, 1, 2, 0, 1, 2] {
            let start = std::time::Instant::now();
            let mut acc = 0.0;
            for _ in 0..3 {
                for &(x, d) in &xs {
                    acc += eval(mode, x, d);
                }
            }
            let cold = start.elapsed().as_secs_f64() * 1e6 / (3 * xs.len()) as f64;
            // The same point again right away: its data is in the caches.
            let mut warm = 0.0;
            for &(x, d) in &xs {
                acc += eval(mode, x, d);
                let t = std::time::Instant::now();
                acc += eval(mode, x, d);
                warm += t.elapsed().as_secs_f64();
            }
            println!(
                "{}: {cold:.3} us per evaluation, {:.3} us on the same point again ({acc:.1})",
                ["value", "value+reach", "gradient"][mode],
                warm * 1e6 / xs.len() as f64
            );
        }
        return;
    }
    if args.get(4).map(String::as_str) == Some("evalstats") {
        let mut sum = [0f64; 5];
        let mut n = 0.0;
        let tol = (0.005 * obj.params.alpha * eps).min(1e-2);
        for py in (0..h).step_by(2) {
            for px in (0..w).step_by(2) {
                let (o, d) = cam.ray(px, py);
                let Some(hit) = tracer.trace(o, d, 0.0).hit else {
                    continue;
                };
                for back in [0.0, 4.0, 16.0] {
                    let x = hit.point - back * eps * d;
                    let e = obj.evaluate(
                        &sets,
                        x,
                        obj.params.alpha,
                        obj.params.beta,
                        tol,
                        false,
                        None,
                        false,
                        false,
                        smoothtrace::eval::FarShare::OFF,
                    );
                    let st = e.stats;
                    sum[0] += st.exact as f64;
                    sum[1] += st.far as f64;
                    sum[2] += st.pruned as f64;
                    sum[3] += st.nodes as f64;
                    n += 1.0;
                }
            }
        }
        println!(
            "per full eval near hits: exact {:.1} far {:.1} pruned {:.1} nodes {:.1}",
            sum[0] / n,
            sum[1] / n,
            sum[2] / n,
            sum[3] / n
        );
        return;
    }
    let mut printed = 0;
    let mut hist_start = Vec::new();
    for py in (0..h).step_by(3) {
        for px in (0..w).step_by(3) {
            let (o, d) = cam.ray(px, py);
            let r = tracer.trace(o, d, 0.0);
            let Some(hit) = r.hit else { continue };
            // Replay: plain march by the full value from well before the hit.
            let mut p = obj.params;
            p.beta = 0.0;
            let exact = |x: DVec3| evaluate_value(&sets, x, &p).s;
            let slope = {
                let a = exact(o + (hit.t - 2.0 * eps) * d);
                let b = exact(o + (hit.t - 12.0 * eps) * d);
                (b - a) / (10.0 * eps)
            };
            let mut st = RayStats::default();
            // where does the bound drop below 4 eps
            let mut t = 0.0f64.max(hit.t - 200.0 * (1.0 / obj.params.alpha));
            let mut line = String::new();
            let mut first_full = None;
            for _ in 0..60 {
                let x = o + t * d;
                let c = tracer.bound(x, opts.coarse_beta, &mut st);
                let (f, _) = tracer.field(x, &mut st);
                if c <= 4.0 * eps && first_full.is_none() {
                    first_full = Some(f / eps);
                }
                if printed < 12 && c <= 50.0 * eps {
                    line += &format!(" [{:.1} {:.1} {:.1}]", c / eps, f / eps, exact(x) / eps);
                }
                if f.abs() <= eps {
                    break;
                }
                t += if c > 4.0 * eps { c } else { f };
            }
            if printed < 12 {
                println!(
                    "px {px} {py}: evals {} bound {} slope {slope:.3} |grad.d| {:.3}\n  {line}",
                    r.stats.evals,
                    r.stats.coarse_evals,
                    hit.normal.dot(d).abs()
                );
                printed += 1;
            }
            hist_start.push((first_full.unwrap_or(f64::NAN), r.stats.evals, slope));
        }
    }
    let n = hist_start.len() as f64;
    let mut s: Vec<f64> = hist_start.iter().map(|x| x.0).collect();
    s.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let mut sl: Vec<f64> = hist_start.iter().map(|x| x.2).collect();
    sl.sort_by(|a, b| a.partial_cmp(b).unwrap());
    println!(
        "rays {n}: full value (in eps) where the bound first <= 4 eps: p10 {:.1} p50 {:.1} p90 {:.1}; evals mean {:.2}; slope p10 {:.2} p50 {:.2} p90 {:.2}",
        s[(0.1 * n) as usize],
        s[(0.5 * n) as usize],
        s[(0.9 * n) as usize],
        hist_start.iter().map(|x| x.1 as f64).sum::<f64>() / n,
        sl[(0.1 * n) as usize],
        sl[(0.5 * n) as usize],
        sl[(0.9 * n) as usize],
    );
}
