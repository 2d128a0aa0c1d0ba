use glam::DVec3;
use rayon::prelude::*;
use smoothtrace::eval::EvalParams;
use smoothtrace::primitives::{AnySet, PrimitiveKind};
use smoothtrace::procedural::Generator;
use smoothtrace::render::{TraceObject, Tracer, TracerOptions};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let which = args.get(1).map(|s| s.as_str()).unwrap_or("torus");
    let beta: f64 = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(0.5);
    let (mesh, kind, alpha, max_alpha) = match which {
        "torus" => (
            Generator::Torus {
                major_radius: 1.0,
                minor_radius: 0.25,
                major_segments: 32,
                minor_segments: 18,
            }
            .build()
            .unwrap(),
            PrimitiveKind::Triangles,
            300.0,
            600.0,
        ),
        "bucky" => (
            Generator::BuckyBall {
                radius: 1.0,
                tube_radius: 0.02,
                sides: 10,
                segments: 7,
            }
            .build()
            .unwrap(),
            PrimitiveKind::Triangles,
            1500.0,
            1500.0,
        ),
        "bowl" => (
            Generator::Bowl {
                radius: 1.0,
                rings: 12,
                segments: 32,
            }
            .build()
            .unwrap(),
            PrimitiveKind::Edges,
            50.0,
            50.0,
        ),
        "hex" => (
            Generator::HexTorus {
                major_radius: 1.0,
                minor_radius: 0.5,
            }
            .build()
            .unwrap(),
            PrimitiveKind::Edges,
            2.0,
            16.0,
        ),
        "points" => (
            Generator::SpherePoints {
                radius: 1.0,
                count: 100000,
            }
            .build()
            .unwrap(),
            PrimitiveKind::Points,
            50.0,
            50.0,
        ),
        _ => panic!(),
    };
    let set = AnySet::build(&mesh, kind).unwrap();
    let obj = TraceObject::new(vec![set], EvalParams::new(alpha, max_alpha, beta));
    let objs = [obj];
    let diag = objs[0].bounds.diagonal();
    let tracer = Tracer::new(&objs, TracerOptions::new(4e-4 * diag, 1000));
    let (w, h) = std::env::var("RES")
        .map(|v| {
            let p: Vec<u32> = v.split('x').map(|x| x.parse().unwrap()).collect();
            (p[0], p[1])
        })
        .unwrap_or((480u32, 270u32));
    let o = DVec3::new(0.0, 1.5, 3.5);
    let fwd = (DVec3::ZERO - o).normalize();
    let right = fwd.cross(DVec3::Y).normalize();
    let up = right.cross(fwd);
    let tanf = (53.13f64.to_radians() / 2.0).tan();
    let t0 = Instant::now();
    let res: Vec<_> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (px, py) = (i % w, i / w);
            let u = (2.0 * (px as f64 + 0.5) / w as f64 - 1.0) * tanf * w as f64 / h as f64;
            let v = (1.0 - 2.0 * (py as f64 + 0.5) / h as f64) * tanf;
            let d = (fwd + u * right + v * up).normalize();
            tracer.trace(o, d, 0.0)
        })
        .collect();
    let el = t0.elapsed().as_secs_f64();
    let hits = res.iter().filter(|r| r.hit.is_some()).count();
    let evals: u64 = res.iter().map(|r| r.stats.evals as u64).sum();
    let evals_hit: u64 = res
        .iter()
        .filter(|r| r.hit.is_some())
        .map(|r| r.stats.evals as u64)
        .sum();
    let leaves: u64 = res.iter().map(|r| r.stats.eval.leaves() as u64).sum();
    let nodes: u64 = res.iter().map(|r| r.stats.eval.nodes as u64).sum();
    let bt: u64 = res.iter().map(|r| r.stats.backtracks as u64).sum();
    let ex = res.iter().filter(|r| r.stats.exhausted).count();
    let maxe = res.iter().map(|r| r.stats.evals).max().unwrap();
    println!(
        "{which} beta {beta}: {el:.3}s  hits {hits}/{}  evals/ray {:.2} (hit rays {:.2}, max {maxe})  leaves/eval {:.1} nodes/eval {:.1} backtracks {bt} exhausted {ex}",
        res.len(),
        evals as f64 / res.len() as f64,
        evals_hit as f64 / hits.max(1) as f64,
        leaves as f64 / evals as f64,
        nodes as f64 / evals as f64
    );
    let mut hist = [0usize; 12];
    for r in res.iter().filter(|r| r.hit.is_some()) {
        hist[(r.stats.evals as usize).min(11)] += 1;
    }
    println!("hit-ray evals histogram (0..10, 11+): {:?}", hist);
    let mut img = image::RgbImage::new(w, h);
    for (i, r) in res.iter().enumerate() {
        let c = match r.hit {
            Some(hh) => {
                let n = hh.normal;
                [
                    ((n.x * 0.5 + 0.5) * 255.0) as u8,
                    ((n.y * 0.5 + 0.5) * 255.0) as u8,
                    ((n.z * 0.5 + 0.5) * 255.0) as u8,
                ]
            }
            None => [255, 255, 255],
        };
        img.put_pixel(i as u32 % w, i as u32 / w, image::Rgb(c));
    }
    img.save(format!("/tmp/probe-{which}.png")).unwrap();
}
#[allow(dead_code)]
fn unused() {}
