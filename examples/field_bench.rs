//! Distance-field benchmark on the grid shapes of Sud et al. 2006 (SPEC 9), linfac
//! against one BVH query per voxel, with the paper's GPU timings beside them.
//!
//! ```text
//! cargo run --release --example field_bench -- [--csv out.csv] [--kinds triangles|all]
//!     [--band REL] [--repeat N] [--no-loose] [--loose-no-cull] [--no-bvh] [--only MODEL]
//!     [--verbose]
//! ```
//! Rows: `linfac` (tight domains and tile culling, the default), `linfac no-cull`
//! (tight domains only), `linfac loose` (SPEC 9's non-manifold domains, with culling),
//! `loose no-cull` (with `--loose-no-cull`), `bvh` (one exact nearest query per voxel).
//! `--band REL` adds runs with a narrow band of REL times the mesh diagonal (linfac does
//! not cull with a band). `--verbose` prints the site-slice candidates (domain
//! computations) and polygons rasterized. Timings are the best of `--repeat` runs.
//!
//! Data meshes come from `data/`; when a file is missing or cannot be read yet, a
//! procedural closed mesh (a torus) with about as many triangles stands in, and
//! the output says so.

use smoothtrace::field::{self, Domains, FieldOptions, FieldStats, Grid, Method};
use smoothtrace::mesh::Mesh;
use smoothtrace::primitives::PrimitiveKind;
use std::io::Write;
use std::path::PathBuf;

/// A row of the paper's table and the data mesh we use for it.
struct Case {
    paper_model: &'static str,
    paper_triangles: &'static str,
    res: [usize; 3],
    paper_seconds: f64,
    file: &'static str,
    /// Triangle count of the procedural stand-in.
    fallback_triangles: usize,
}

const CASES: [Case; 5] = [
    Case {
        paper_model: "bunny",
        paper_triangles: "1.5K",
        res: [256, 252, 196],
        paper_seconds: 0.772,
        file: "bunny-7k.obj",
        fallback_triangles: 6966,
    },
    Case {
        paper_model: "triceratops",
        paper_triangles: "5.6K",
        res: [256, 112, 84],
        paper_seconds: 0.768,
        file: "cow.obj",
        fallback_triangles: 5804,
    },
    Case {
        paper_model: "head",
        paper_triangles: "22K",
        res: [78, 105, 128],
        paper_seconds: 0.846,
        file: "bunny.obj",
        fallback_triangles: 22000,
    },
    Case {
        paper_model: "gargoyle",
        paper_triangles: "11K",
        res: [256, 103, 91],
        paper_seconds: 0.625,
        file: "fandisk.obj",
        fallback_triangles: 12946,
    },
    Case {
        paper_model: "shell",
        paper_triangles: "4.5K",
        res: [126, 128, 126],
        paper_seconds: 0.276,
        file: "teapot.obj",
        fallback_triangles: 6320,
    },
];

/// A closed procedural torus with about `triangles` triangles (2 x major x minor).
fn stand_in(triangles: usize) -> Mesh {
    let minor = ((triangles as f64 / 6.0).sqrt().round() as usize).max(3);
    let major = (triangles / (2 * minor)).max(3);
    smoothtrace::procedural::torus(1.0, 0.35, major, minor)
}

fn load(case: &Case) -> (Mesh, String) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(case.file);
    match Mesh::load(&path) {
        Ok(m) => {
            let note = format!("{} ({} tris)", case.file, m.triangles.len());
            (m, note)
        }
        Err(e) => {
            let m = stand_in(case.fallback_triangles);
            let note = format!(
                "procedural torus ({} tris) standing in for {}: {e}",
                m.triangles.len(),
                case.file
            );
            (m, note)
        }
    }
}

struct Args {
    csv: Option<PathBuf>,
    kinds: Vec<PrimitiveKind>,
    band: Option<f64>,
    repeat: usize,
    loose: bool,
    loose_nocull: bool,
    bvh: bool,
    only: Option<String>,
    verbose: bool,
}

fn parse_args() -> Args {
    let mut a = Args {
        csv: None,
        kinds: vec![PrimitiveKind::Triangles],
        band: None,
        repeat: 1,
        loose: true,
        loose_nocull: false,
        bvh: true,
        only: None,
        verbose: false,
    };
    let mut it = std::env::args().skip(1);
    while let Some(s) = it.next() {
        match s.as_str() {
            "--csv" => a.csv = it.next().map(PathBuf::from),
            "--kinds" => {
                a.kinds = match it.next().as_deref() {
                    Some("all") => vec![
                        PrimitiveKind::Triangles,
                        PrimitiveKind::Edges,
                        PrimitiveKind::Points,
                    ],
                    Some("edges") => vec![PrimitiveKind::Edges],
                    Some("points") => vec![PrimitiveKind::Points],
                    _ => vec![PrimitiveKind::Triangles],
                }
            }
            "--band" => a.band = it.next().and_then(|v| v.parse().ok()),
            "--repeat" => a.repeat = it.next().and_then(|v| v.parse().ok()).unwrap_or(1).max(1),
            "--no-loose" => a.loose = false,
            "--loose-no-cull" => a.loose_nocull = true,
            "--no-bvh" => a.bvh = false,
            "--verbose" => a.verbose = true,
            "--only" => a.only = it.next(),
            other => {
                eprintln!("unknown argument {other}");
                std::process::exit(2);
            }
        }
    }
    a
}

/// Best of `repeat` runs (by total seconds).
fn best(
    mesh: &Mesh,
    kind: PrimitiveKind,
    grid: &Grid,
    method: Method,
    o: &FieldOptions,
    repeat: usize,
) -> FieldStats {
    (0..repeat)
        .map(|_| {
            field::compute(mesh, kind, grid, method, o)
                .expect("field")
                .1
        })
        .min_by(|a, b| a.seconds.total_cmp(&b.seconds))
        .unwrap()
}

fn main() {
    let args = parse_args();
    let mut csv = args.csv.as_ref().map(|p| {
        let mut f = std::io::BufWriter::new(std::fs::File::create(p).expect("cannot create the CSV file"));
        writeln!(
            f,
            "paper_model,paper_triangles,paper_gpu_seconds,mesh,kind,nx,ny,nz,voxels,method,band,seconds,setup_seconds,domain_seconds,raster_seconds,domain_share,mvoxels_per_second,sites,evaluations_per_voxel,candidates,polygons"
        )
        .unwrap();
        f
    });
    println!(
        "distance fields on the grid shapes of Sud et al. 2006 (GPU: GeForce 7800); {} threads",
        rayon::current_num_threads()
    );
    for case in &CASES {
        if args.only.as_ref().is_some_and(|o| o != case.paper_model) {
            continue;
        }
        let (mesh, note) = load(case);
        let diag = mesh.bounds().diagonal();
        let (min, max) = Grid::default_bounds(mesh.bounds()).expect("bounds");
        let grid = Grid::new(min, max, case.res).expect("grid");
        println!(
            "\n{} ({} tris, {}x{}x{}, paper GPU {:.3} s): {note}",
            case.paper_model,
            case.paper_triangles,
            case.res[0],
            case.res[1],
            case.res[2],
            case.paper_seconds
        );
        println!(
            "  {:<10} {:<16} {:>9} {:>8} {:>8} {:>8} {:>7} {:>9} {:>8} {:>9}",
            "kind",
            "method",
            "seconds",
            "setup",
            "domain",
            "raster",
            "dom %",
            "Mvox/s",
            "sites",
            "evals/vox"
        );
        for &kind in &args.kinds {
            let mut runs: Vec<(String, Method, FieldOptions)> = Vec::new();
            let o = |band: Option<f64>, domains, cull| FieldOptions {
                band,
                domains,
                cull,
                memory_limit: None,
            };
            runs.push((
                "linfac".into(),
                Method::Linfac,
                o(None, Domains::Tight, true),
            ));
            runs.push((
                "linfac no-cull".into(),
                Method::Linfac,
                o(None, Domains::Tight, false),
            ));
            if args.loose {
                runs.push((
                    "linfac loose".into(),
                    Method::Linfac,
                    o(None, Domains::Loose, true),
                ));
                if args.loose_nocull {
                    runs.push((
                        "loose no-cull".into(),
                        Method::Linfac,
                        o(None, Domains::Loose, false),
                    ));
                }
            }
            if args.bvh {
                runs.push(("bvh".into(), Method::Bvh, o(None, Domains::Tight, true)));
            }
            if let Some(rel) = args.band {
                let b = rel * diag;
                runs.push((
                    format!("linfac band {rel}"),
                    Method::Linfac,
                    o(Some(b), Domains::Tight, true),
                ));
                if args.bvh {
                    runs.push((
                        format!("bvh band {rel}"),
                        Method::Bvh,
                        o(Some(b), Domains::Tight, true),
                    ));
                }
            }
            for (label, method, opts) in runs {
                let s = best(&mesh, kind, &grid, method, &opts, args.repeat);
                println!(
                    "  {:<10} {:<16} {:>9.3} {:>8.3} {:>8.3} {:>8.3} {:>6.1}% {:>9.2} {:>8} {:>9.2}",
                    kind.name(),
                    label,
                    s.seconds,
                    s.setup_seconds,
                    s.domain_seconds,
                    s.raster_seconds,
                    100.0 * s.domain_share(),
                    s.voxels_per_second * 1e-6,
                    s.sites,
                    s.evaluations_per_voxel()
                );
                if args.verbose {
                    println!(
                        "    {} site-slice candidates, {} polygons ({:.2} per voxel, {:.1} evaluations per polygon)",
                        s.candidates,
                        s.polygons,
                        s.polygons as f64 / s.voxels as f64,
                        s.evaluations as f64 / s.polygons.max(1) as f64
                    );
                }
                if let Some(f) = csv.as_mut() {
                    writeln!(
                        f,
                        "{},{},{},{},{},{},{},{},{},{},{},{:.6},{:.6},{:.6},{:.6},{:.4},{:.4},{},{:.4},{},{}",
                        case.paper_model,
                        case.paper_triangles,
                        case.paper_seconds,
                        mesh.name,
                        kind.name(),
                        case.res[0],
                        case.res[1],
                        case.res[2],
                        grid.len(),
                        label,
                        opts.band.map_or(String::new(), |b| b.to_string()),
                        s.seconds,
                        s.setup_seconds,
                        s.domain_seconds,
                        s.raster_seconds,
                        s.domain_share(),
                        s.voxels_per_second * 1e-6,
                        s.sites,
                        s.evaluations_per_voxel(),
                        s.candidates,
                        s.polygons
                    )
                    .unwrap();
                }
            }
        }
    }
    if let (Some(f), Some(p)) = (csv.as_mut(), args.csv.as_ref()) {
        f.flush().unwrap();
        println!("\nwrote {}", p.display());
    }
}
