//! Distance fields (SPEC 9): linfac against the BVH and brute force on every voxel, the
//! grid convention, sampling, the Lipschitz bound, validation and `.npy` output.

// `!(a <= b)` also fails on NaN, which is what the comparisons want.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod common;

use common::{Rng, bumpy_sphere, random_wire};
use glam::{DVec3, Vec3};
use smoothtrace::eval;
use smoothtrace::field::{self, DistanceField, Domains, FieldError, FieldOptions, Grid, Method};
use smoothtrace::mesh::Mesh;
use smoothtrace::primitives::{AnySet, PrimitiveKind};

const KINDS: [PrimitiveKind; 3] = [
    PrimitiveKind::Points,
    PrimitiveKind::Edges,
    PrimitiveKind::Triangles,
];

/// Relative tolerance of the comparisons, times the mesh diagonal.
const TOL: f64 = 1e-5;

fn opts(band: Option<f64>, domains: Domains) -> FieldOptions {
    FieldOptions {
        band,
        domains,
        ..FieldOptions::default()
    }
}

fn opts_nocull(band: Option<f64>, domains: Domains) -> FieldOptions {
    FieldOptions {
        cull: false,
        ..opts(band, domains)
    }
}

fn run(
    mesh: &Mesh,
    kind: PrimitiveKind,
    grid: &Grid,
    method: Method,
    o: &FieldOptions,
) -> DistanceField {
    field::compute(mesh, kind, grid, method, o)
        .unwrap_or_else(|e| panic!("{} {kind} {}: {e}", mesh.name, method.name()))
        .0
}

/// Every voxel of `got` equals `want` to `tol`; with a band, where `want <= band` (a
/// voxel within `tol` of the band edge may be on either side).
fn assert_same(got: &DistanceField, want: &DistanceField, tol: f64, what: &str) {
    assert_eq!(got.grid, want.grid);
    let band = want.band;
    let mut worst = (0.0f64, 0usize);
    for (n, (&g, &w)) in got.values.iter().zip(&want.values).enumerate() {
        let (g, w) = (g as f64, w as f64);
        let bad = match band {
            Some(b) if w.is_infinite() => !(g.is_infinite() || g >= b - tol),
            Some(b) if w > b - tol => !(g.is_infinite() || (g - w).abs() <= tol),
            _ => !((g - w).abs() <= tol),
        };
        if bad {
            let [nx, ny, _] = want.grid.res;
            let (i, j, k) = (n % nx, (n / nx) % ny, n / (nx * ny));
            panic!(
                "{what}: voxel ({i}, {j}, {k}) at {}: got {g}, want {w} (diff {}, tol {tol}, band {band:?})",
                want.grid.voxel_center(i, j, k),
                (g - w).abs()
            );
        }
        if g.is_finite() && w.is_finite() && (g - w).abs() > worst.0 {
            worst = ((g - w).abs(), n);
        }
    }
    assert!(worst.0 <= tol, "{what}: {worst:?}");
}

/// linfac (tight and loose) == bvh on every voxel, with and without band; optionally
/// also == brute.
fn check(mesh: &Mesh, kinds: &[PrimitiveKind], res: usize, with_brute: bool) {
    let diag = mesh.bounds().diagonal();
    let tol = TOL * diag;
    let grid = Grid::around(mesh.bounds(), res).unwrap();
    for &kind in kinds {
        let bvh = run(mesh, kind, &grid, Method::Bvh, &opts(None, Domains::Tight));
        assert!(bvh.values.iter().all(|v| v.is_finite()));
        if with_brute {
            let brute = run(
                mesh,
                kind,
                &grid,
                Method::Brute,
                &opts(None, Domains::Tight),
            );
            assert_same(
                &bvh,
                &brute,
                tol,
                &format!("{} {kind} bvh vs brute", mesh.name),
            );
        }
        for domains in [Domains::Tight, Domains::Loose] {
            let lf = run(mesh, kind, &grid, Method::Linfac, &opts(None, domains));
            assert_same(
                &lf,
                &bvh,
                tol,
                &format!("{} {kind} linfac {domains:?} vs bvh", mesh.name),
            );
        }
        for band in [0.03 * diag, 0.15 * diag] {
            let bvh_b = run(
                mesh,
                kind,
                &grid,
                Method::Bvh,
                &opts(Some(band), Domains::Tight),
            );
            assert_same(
                &bvh,
                &bvh_b,
                tol,
                &format!("{} {kind} bvh vs banded bvh", mesh.name),
            );
            for domains in [Domains::Tight, Domains::Loose] {
                let lf = run(
                    mesh,
                    kind,
                    &grid,
                    Method::Linfac,
                    &opts(Some(band), domains),
                );
                assert_same(
                    &lf,
                    &bvh_b,
                    tol,
                    &format!("{} {kind} linfac {domains:?} band {band} vs bvh", mesh.name),
                );
            }
        }
    }
}

fn mesh(name: &str, vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Mesh {
    Mesh {
        vertices,
        segments: Vec::new(),
        triangles,
        name: name.into(),
    }
}

/// Two triangles sharing an edge plus a third "fin" on the same edge (an edge of
/// valence 3), and a dangling triangle on a boundary edge.
fn fin() -> Mesh {
    let v = vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(1.0, 0.1, 0.5),
        Vec3::new(-0.8, 0.3, 0.4),
        Vec3::new(0.1, -0.9, 0.6),
        Vec3::new(1.2, 0.9, 0.9),
    ];
    mesh("fin", v, vec![[0, 1, 2], [1, 0, 3], [0, 1, 4], [1, 2, 5]])
}

/// A non-planar open fan around a vertex: a saddle-like apex.
fn fan() -> Mesh {
    let n = 7;
    let mut v = vec![Vec3::ZERO];
    for k in 0..n {
        let a = std::f32::consts::TAU * k as f32 / n as f32;
        v.push(Vec3::new(a.cos(), a.sin(), 0.4 * (2.0 * a).sin()));
    }
    let t = (0..n - 1).map(|k| [0, k + 1, k + 2]).collect();
    mesh("fan", v, t)
}

/// A saddle height field `z = x^2 - y^2` on a 6 x 6 grid of vertices.
fn saddle() -> Mesh {
    let n = 6;
    let mut v = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (
                i as f32 / (n - 1) as f32 * 2.0 - 1.0,
                j as f32 / (n - 1) as f32 * 2.0 - 1.0,
            );
            v.push(Vec3::new(x, y, 0.6 * (x * x - y * y)));
        }
    }
    let mut t = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = (j * n + i) as u32;
            t.push([a, a + 1, a + n as u32 + 1]);
            t.push([a, a + n as u32 + 1, a + n as u32]);
        }
    }
    mesh("saddle", v, t)
}

/// Two closed tetrahedra sharing one vertex (a pinched, non-manifold vertex), one of
/// them with the opposite orientation.
fn pinched() -> Mesh {
    let v = vec![
        Vec3::ZERO,
        Vec3::new(1.0, 0.2, 0.1),
        Vec3::new(0.3, 1.0, 0.2),
        Vec3::new(0.4, 0.3, 1.0),
        Vec3::new(-1.0, -0.1, -0.2),
        Vec3::new(-0.2, -1.0, 0.1),
        Vec3::new(-0.3, -0.2, -1.0),
    ];
    let t = vec![
        [0, 2, 1],
        [0, 1, 3],
        [0, 3, 2],
        [1, 2, 3],
        [0, 4, 5],
        [0, 6, 4],
        [0, 5, 6],
        [4, 6, 5],
    ];
    mesh("pinched", v, t)
}

/// An axis-aligned cube: faces exactly parallel and orthogonal to the slices, edges and
/// face planes through voxel centres.
fn cube() -> Mesh {
    let mut v = Vec::new();
    for k in 0..2 {
        for j in 0..2 {
            for i in 0..2 {
                v.push(Vec3::new(i as f32, j as f32, k as f32));
            }
        }
    }
    let q = |a: u32, b: u32, c: u32, d: u32| [[a, b, c], [a, c, d]];
    let mut t = Vec::new();
    for f in [
        q(0, 2, 3, 1),
        q(4, 5, 7, 6),
        q(0, 1, 5, 4),
        q(2, 6, 7, 3),
        q(0, 4, 6, 2),
        q(1, 3, 7, 5),
    ] {
        t.extend(f);
    }
    mesh("cube", v, t)
}

/// Degenerate triangles: collinear, repeated indices, coincident positions, a sliver,
/// duplicated triangles, next to regular ones.
fn degenerate() -> Mesh {
    let v = vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.5, 1.0, 0.3),
        Vec3::new(1.0, 0.0, 0.0), // duplicate of 1
        Vec3::new(0.5, 0.5, 1.0),
        Vec3::new(1.5, 1e-7, 0.0), // sliver apex
        Vec3::new(-0.5, 0.8, -0.4),
    ];
    let t = vec![
        [0, 1, 2], // collinear
        [3, 3, 5], // repeated index
        [1, 4, 3], // coincident positions
        [0, 2, 6], // sliver
        [0, 3, 5],
        [0, 3, 5], // duplicate
        [7, 7, 7], // a point
        [0, 3, 7],
    ];
    mesh("degenerate", v, t)
}

fn soup(rng: &mut Rng, n: usize) -> Mesh {
    let mut v = Vec::new();
    let mut t = Vec::new();
    for k in 0..n {
        let c = rng.vec();
        for _ in 0..3 {
            v.push((c + 0.35 * rng.vec()).as_vec3());
        }
        let b = 3 * k as u32;
        t.push([b, b + 1, b + 2]);
    }
    mesh("soup", v, t)
}

#[test]
fn linfac_matches_bvh_and_brute_on_a_closed_mesh() {
    check(&bumpy_sphere(8, 12), &KINDS, 24, true);
}

#[test]
fn linfac_matches_on_non_manifold_and_open_meshes() {
    for m in [fin(), fan(), saddle(), pinched()] {
        check(&m, &KINDS, 24, true);
    }
}

#[test]
fn linfac_matches_on_axis_aligned_geometry() {
    // Grid planes through the cube's faces and edges: voxel centres exactly on domain
    // boundaries, faces exactly parallel and orthogonal to the slices.
    let m = cube();
    for kind in KINDS {
        let grid = Grid::new(DVec3::splat(-0.25), DVec3::splat(1.25), [12, 12, 12]).unwrap();
        let bvh = run(&m, kind, &grid, Method::Bvh, &opts(None, Domains::Tight));
        for d in [Domains::Tight, Domains::Loose] {
            for o in [opts(None, d), opts_nocull(None, d)] {
                let lf = run(&m, kind, &grid, Method::Linfac, &o);
                assert_same(&lf, &bvh, TOL * 1.7, &format!("cube {kind} {o:?}"));
            }
        }
    }
    check(&m, &KINDS, 20, false);
}

#[test]
fn linfac_matches_on_degenerate_triangles_and_soup() {
    check(&degenerate(), &KINDS, 24, true);
    let s = soup(&mut Rng::new(5), 40);
    check(&s, &KINDS, 24, true);
}

#[test]
fn linfac_matches_on_edge_meshes_and_point_clouds() {
    let mut rng = Rng::new(3);
    let mut wire = random_wire(&mut rng, 6, 12);
    // Self-loops, duplicates and a zero-length segment between coincident vertices.
    let n = wire.vertices.len() as u32;
    wire.vertices.push(wire.vertices[5]);
    wire.segments.extend([[2, 2], [3, 4], [4, 3], [5, n]]);
    check(
        &wire,
        &[PrimitiveKind::Edges, PrimitiveKind::Points],
        24,
        true,
    );
    let mut cloud = Mesh {
        vertices: (0..200).map(|_| rng.vec().as_vec3()).collect(),
        name: "cloud".into(),
        ..Mesh::default()
    };
    cloud.vertices.push(cloud.vertices[0]);
    check(&cloud, &[PrimitiveKind::Points], 24, true);
}

#[test]
fn linfac_handles_meshes_outside_the_grid_and_thin_grids() {
    let m = bumpy_sphere(8, 12);
    let diag = m.bounds().diagonal();
    // The grid covers only part of the mesh; sites outside it still count.
    for res in [[20, 14, 9], [1, 17, 12], [15, 1, 1], [9, 11, 1]] {
        let grid = Grid::new(DVec3::new(-0.3, 0.2, -1.4), DVec3::new(1.5, 1.1, 0.1), res).unwrap();
        for kind in KINDS {
            let bvh = run(&m, kind, &grid, Method::Bvh, &opts(None, Domains::Tight));
            let lf = run(&m, kind, &grid, Method::Linfac, &opts(None, Domains::Tight));
            assert_same(
                &lf,
                &bvh,
                TOL * diag,
                &format!("partial grid {res:?} {kind}"),
            );
        }
    }
}

#[test]
fn linfac_matches_on_data_meshes() {
    for (name, res) in [("bunny-7k.obj", 40), ("teapot.obj", 40), ("cow.obj", 40)] {
        let Some(path) = common::data_file(name) else {
            return;
        };
        let m = match Mesh::load(&path) {
            Ok(m) => m,
            Err(e) => {
                println!("skipping {name}: Mesh::load failed ({e})");
                continue;
            }
        };
        let diag = m.bounds().diagonal();
        let grid = Grid::around(m.bounds(), res).unwrap();
        for kind in KINDS {
            let bvh = run(&m, kind, &grid, Method::Bvh, &opts(None, Domains::Tight));
            for o in [
                opts(None, Domains::Tight),
                opts_nocull(None, Domains::Tight),
            ] {
                let lf = run(&m, kind, &grid, Method::Linfac, &o);
                assert_same(&lf, &bvh, TOL * diag, &format!("{name} {kind} {o:?}"));
            }
            let band = 0.05 * diag;
            let bvh_b = run(
                &m,
                kind,
                &grid,
                Method::Bvh,
                &opts(Some(band), Domains::Tight),
            );
            let lf_b = run(
                &m,
                kind,
                &grid,
                Method::Linfac,
                &opts(Some(band), Domains::Tight),
            );
            assert_same(&lf_b, &bvh_b, TOL * diag, &format!("{name} {kind} band"));
        }
        let lf = run(
            &m,
            PrimitiveKind::Triangles,
            &grid,
            Method::Linfac,
            &opts(None, Domains::Loose),
        );
        let bvh = run(
            &m,
            PrimitiveKind::Triangles,
            &grid,
            Method::Bvh,
            &opts(None, Domains::Loose),
        );
        assert_same(&lf, &bvh, TOL * diag, &format!("{name} triangles loose"));
    }
}

#[test]
fn grid_convention_and_exact_sampling_at_voxel_centres() {
    let m = bumpy_sphere(8, 12);
    let grid = Grid::new(
        DVec3::new(-1.5, -1.2, -1.3),
        DVec3::new(1.5, 1.4, 1.1),
        [7, 9, 5],
    )
    .unwrap();
    assert_eq!(
        grid.voxel_center(0, 0, 0),
        grid.min + 0.5 * (grid.max - grid.min) / DVec3::new(7.0, 9.0, 5.0)
    );
    assert_eq!(grid.shape(), [5, 9, 7]);
    let set = AnySet::build(&m, PrimitiveKind::Triangles).unwrap();
    let f = run(
        &m,
        PrimitiveKind::Triangles,
        &grid,
        Method::Linfac,
        &opts(None, Domains::Tight),
    );
    // C order: value (i, j, k) at (k * NY + j) * NX + i is the distance at its centre.
    for (i, j, k) in [(0, 0, 0), (6, 0, 0), (0, 8, 0), (0, 0, 4), (3, 5, 2)] {
        let x = grid.voxel_center(i, j, k);
        let d = eval::nearest(&[&set], x).d;
        let v = f.values[(k * 9 + j) * 7 + i] as f64;
        assert!(
            (v - d).abs() <= 1e-6 * d.max(1.0),
            "({i},{j},{k}): {v} vs {d}"
        );
        let s = f.sample(x);
        assert!(
            (s - v).abs() <= 1e-6 * v.max(1.0),
            "sample at centre: {s} vs {v}"
        );
    }
    // Midway between two centres along x: the average.
    let x = 0.5 * (grid.voxel_center(2, 3, 1) + grid.voxel_center(3, 3, 1));
    let want = 0.5 * (f.get(2, 3, 1) as f64 + f.get(3, 3, 1) as f64);
    assert!((f.sample(x) - want).abs() < 1e-6);
    // Clamped outside: far below the grid gives the value of the clamped centre.
    let below = grid.voxel_center(3, 4, 0) - DVec3::Z * 10.0;
    assert!((f.sample(below) - f.get(3, 4, 0) as f64).abs() < 1e-6);
}

#[test]
fn lipschitz_lower_bound_never_exceeds_the_distance() {
    let m = fin();
    let set = AnySet::build(&m, PrimitiveKind::Triangles).unwrap();
    let grid = Grid::around(m.bounds(), 16).unwrap();
    let diag = m.bounds().diagonal();
    let exact = run(
        &m,
        PrimitiveKind::Triangles,
        &grid,
        Method::Linfac,
        &opts(None, Domains::Tight),
    );
    let banded = run(
        &m,
        PrimitiveKind::Triangles,
        &grid,
        Method::Linfac,
        &opts(Some(0.1 * diag), Domains::Tight),
    );
    let smooth = run(
        &m,
        PrimitiveKind::Triangles,
        &grid,
        Method::Smooth {
            alpha: 20.0 / diag,
            max_alpha: 20.0 / diag,
            beta: 0.5,
        },
        &opts(None, Domains::Tight),
    );
    let mut rng = Rng::new(77);
    let c = grid.min.lerp(grid.max, 0.5);
    let mut useful = 0;
    for n in 0..3000 {
        let x = c + rng.vec() * (grid.max - grid.min) * if n % 10 == 0 { 2.0 } else { 0.55 };
        let d = eval::nearest(&[&set], x).d;
        for f in [&exact, &banded, &smooth] {
            let lb = f.lower_bound(x);
            assert!(
                lb <= d,
                "lower bound {lb} > distance {d} at {x} (band {:?})",
                f.band
            );
        }
        if exact.lower_bound(x) > 0.5 * d {
            useful += 1;
        }
    }
    assert!(
        useful > 1500,
        "the bound is too weak: useful at {useful} of 3000 points"
    );
}

#[test]
fn smooth_method_matches_the_evaluator() {
    let m = bumpy_sphere(6, 10);
    let grid = Grid::around(m.bounds(), 10).unwrap();
    let set = AnySet::build(&m, PrimitiveKind::Edges).unwrap();
    let p = eval::EvalParams::new(15.0, 30.0, 0.5);
    let f = run(
        &m,
        PrimitiveKind::Edges,
        &grid,
        Method::Smooth {
            alpha: 15.0,
            max_alpha: 30.0,
            beta: 0.5,
        },
        &opts(None, Domains::Tight),
    );
    for (i, j, k) in [(0, 0, 0), (4, 5, 6), (9, 9, 9)] {
        let s = eval::evaluate(&[&set], grid.voxel_center(i, j, k), &p).s;
        assert_eq!(f.get(i, j, k), s as f32);
    }
}

#[test]
fn bad_inputs_are_refused_with_clear_errors() {
    let m = bumpy_sphere(6, 10);
    let (lo, hi) = (DVec3::splat(-1.0), DVec3::splat(1.0));
    let e = Grid::new(lo, hi, [0, 4, 4]).unwrap_err();
    assert!(matches!(e, FieldError::ZeroResolution { axis: 'x' }), "{e}");
    let e = Grid::new(lo, hi, [4, 1 << 20, 4]).unwrap_err();
    assert!(
        matches!(e, FieldError::ResolutionTooLarge { axis: 'y', .. }),
        "{e}"
    );
    let e = Grid::new(hi, lo, [4, 4, 4]).unwrap_err();
    assert!(
        matches!(e, FieldError::InvertedBounds { axis: 'x', .. }),
        "{e}"
    );
    assert!(e.to_string().contains("inverted"));
    let e = Grid::new(lo, DVec3::new(1.0, 1.0, -1.0), [4, 4, 4]).unwrap_err();
    assert!(
        matches!(e, FieldError::DegenerateBounds { axis: 'z', .. }),
        "{e}"
    );
    let e = Grid::new(lo, DVec3::new(f64::NAN, 1.0, 1.0), [4, 4, 4]).unwrap_err();
    assert!(matches!(e, FieldError::NonFiniteBounds { .. }), "{e}");
    let point = Mesh {
        vertices: vec![Vec3::ONE],
        ..Mesh::default()
    };
    assert!(matches!(
        Grid::around(point.bounds(), 8),
        Err(FieldError::NoDefaultBounds)
    ));

    let grid = Grid::around(m.bounds(), 8).unwrap();
    for band in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = field::compute(
            &m,
            PrimitiveKind::Triangles,
            &grid,
            Method::Linfac,
            &opts(Some(band), Domains::Tight),
        )
        .unwrap_err();
        assert!(matches!(e, FieldError::BadBand(_)), "{e}");
    }
    // Memory: a grid within the per-axis limits but far too large.
    let huge = Grid::new(lo, hi, [40000, 40000, 40000]).unwrap();
    let e = field::compute(
        &m,
        PrimitiveKind::Points,
        &huge,
        Method::Linfac,
        &FieldOptions::default(),
    )
    .unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(e, FieldError::TooMuchMemory { .. }) && msg.contains("TiB"),
        "{msg}"
    );
    let small_limit = FieldOptions {
        memory_limit: Some(1000),
        ..FieldOptions::default()
    };
    let e =
        field::compute(&m, PrimitiveKind::Points, &grid, Method::Bvh, &small_limit).unwrap_err();
    assert!(e.to_string().contains("configured limit"), "{e}");
    // Smooth parameters.
    for (alpha, beta) in [(0.0, 0.5), (f64::NAN, 0.5), (3.0, 1.5)] {
        let e = field::compute(
            &m,
            PrimitiveKind::Points,
            &grid,
            Method::Smooth {
                alpha,
                max_alpha: 3.0,
                beta,
            },
            &FieldOptions::default(),
        )
        .unwrap_err();
        assert!(matches!(e, FieldError::BadSmoothParameters(_)), "{e}");
    }
    // A mesh without the requested simplices.
    let cloud = Mesh {
        vertices: m.vertices.clone(),
        name: "cloud".into(),
        ..Mesh::default()
    };
    for method in [Method::Linfac, Method::Bvh] {
        for kind in [PrimitiveKind::Edges, PrimitiveKind::Triangles] {
            let e =
                field::compute(&cloud, kind, &grid, method, &FieldOptions::default()).unwrap_err();
            assert!(matches!(e, FieldError::Primitive(_)), "{e}");
        }
    }
}

#[test]
fn npy_round_trip_and_preview() {
    let m = fin();
    let grid = Grid::new(DVec3::splat(-1.0), DVec3::new(1.5, 1.2, 1.4), [11, 7, 5]).unwrap();
    let diag = m.bounds().diagonal();
    let f = run(
        &m,
        PrimitiveKind::Triangles,
        &grid,
        Method::Linfac,
        &opts(Some(0.2 * diag), Domains::Tight),
    );
    assert!(f.values.iter().any(|v| v.is_infinite()) && f.values.iter().any(|v| v.is_finite()));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("field.npy");
    f.write_npy(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let npy = npyz::NpyFile::new(&bytes[..]).unwrap();
    assert_eq!(npy.shape(), &[5, 7, 11]);
    assert_eq!(npy.order(), npyz::Order::C);
    assert_eq!(npy.dtype(), npyz::DType::Plain("<f4".parse().unwrap()));
    let back: Vec<f32> = npy.into_vec().unwrap();
    assert_eq!(back.len(), f.values.len());
    for (a, b) in back.iter().zip(&f.values) {
        assert!(a == b || (a.is_infinite() && b.is_infinite()), "{a} vs {b}");
    }
    assert_eq!(back[grid.index(3, 2, 4)], f.get(3, 2, 4));

    let png = dir.path().join("slices.png");
    f.write_preview(&png).unwrap();
    let img = image::open(&png).unwrap().to_rgb8();
    assert!(
        img.width() > 3 * img.height() && img.height() >= 100,
        "{}x{}",
        img.width(),
        img.height()
    );
    let e = f
        .write_npy(&dir.path().join("missing/dir/x.npy"))
        .unwrap_err();
    assert!(e.to_string().contains("cannot write"), "{e}");
}

/// The long sweep: every data mesh at 64^3 (or 96^3), every kind, both domain types,
/// with and without band. Run with `cargo test --release --test field -- --ignored`.
#[test]
#[ignore]
fn linfac_matches_on_all_data_meshes_at_high_resolution() {
    for (name, res) in [
        ("bunny-7k.obj", 96),
        ("teapot.obj", 96),
        ("cow.obj", 96),
        ("spot.obj", 64),
        ("fandisk.obj", 64),
        ("suzanne.obj", 64),
        ("bunny.obj", 64),
    ] {
        let Some(path) = common::data_file(name) else {
            return;
        };
        let m = match Mesh::load(&path) {
            Ok(m) => m,
            Err(e) => {
                println!("skipping {name}: Mesh::load failed ({e})");
                continue;
            }
        };
        let diag = m.bounds().diagonal();
        let grid = Grid::around(m.bounds(), res).unwrap();
        for kind in [PrimitiveKind::Triangles, PrimitiveKind::Edges] {
            for band in [None, Some(0.04 * diag)] {
                let bvh = run(&m, kind, &grid, Method::Bvh, &opts(band, Domains::Tight));
                for o in [
                    opts(band, Domains::Tight),
                    opts_nocull(band, Domains::Tight),
                    opts(band, Domains::Loose),
                ] {
                    let lf = run(&m, kind, &grid, Method::Linfac, &o);
                    assert_same(&lf, &bvh, TOL * diag, &format!("{name} {kind} {o:?}"));
                }
            }
        }
        println!("{name}: ok");
    }
}

/// Runs the built binary with `args`, returning (status code, stdout, stderr).
fn smoothtrace(args: &[&str]) -> (i32, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_smoothtrace"))
        .args(args)
        .output()
        .expect("cannot run smoothtrace");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn cli_refuses_bad_flags() {
    let (code, _, err) = smoothtrace(&["field", "x.obj", "-p", "triangles", "-o", "x.npy"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--res"), "{err}");
    let (code, _, err) = smoothtrace(&[
        "field",
        "x.obj",
        "-p",
        "triangles",
        "--res",
        "8",
        "--smooth",
        "-o",
        "x.npy",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--alpha"), "{err}");
    let (code, _, err) = smoothtrace(&[
        "field",
        "x.obj",
        "-p",
        "triangles",
        "--res",
        "8",
        "--res-xyz",
        "4",
        "4",
        "4",
        "-o",
        "x.npy",
    ]);
    assert_eq!(code, 2, "{err}");
}

#[test]
fn cli_writes_npy_and_preview() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("tet.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 2 0\nv 0 0 3\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    )
    .unwrap();
    if let Err(e) = Mesh::load(&obj) {
        println!("skipping: Mesh::load cannot read OBJ yet ({e})");
        return;
    }
    let npy = dir.path().join("tet.npy");
    let png = dir.path().join("tet.png");
    let (code, _, err) = smoothtrace(&[
        "field",
        obj.to_str().unwrap(),
        "-p",
        "triangles",
        "--res",
        "16",
        "-o",
        npy.to_str().unwrap(),
        "--preview",
        png.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("bounds") && err.contains("spacing") && err.contains("voxels/s"),
        "{err}"
    );
    let bytes = std::fs::read(&npy).unwrap();
    let f = npyz::NpyFile::new(&bytes[..]).unwrap();
    // Longest axis z (extent 3 * 1.2 + ...): 16 voxels; the others rounded up.
    assert_eq!(f.shape()[0], 16, "{:?}", f.shape());
    assert!(png.exists());
    // Bounds, band and the bvh method; a bad band is refused with the library's message.
    let (code, _, err) = smoothtrace(&[
        "field",
        obj.to_str().unwrap(),
        "-p",
        "edges",
        "--res-xyz",
        "5",
        "6",
        "7",
        "--bounds",
        "-1",
        "-1",
        "-1",
        "2",
        "3",
        "4",
        "--band",
        "0.5",
        "--method",
        "bvh",
        "-o",
        npy.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let bytes = std::fs::read(&npy).unwrap();
    assert_eq!(npyz::NpyFile::new(&bytes[..]).unwrap().shape(), &[7, 6, 5]);
    let (code, _, err) = smoothtrace(&[
        "field",
        obj.to_str().unwrap(),
        "-p",
        "points",
        "--res",
        "8",
        "--band=-1",
        "-o",
        npy.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("band must be a positive"), "{err}");
    let (code, _, err) = smoothtrace(&[
        "field",
        obj.to_str().unwrap(),
        "-p",
        "points",
        "--res",
        "8",
        "--bounds",
        "1",
        "0",
        "0",
        "0",
        "1",
        "1",
        "-o",
        npy.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("inverted along x"), "{err}");
}

/// A rotated copy of `m` (random rotation) moved by `shift`.
fn rotated(m: &Mesh, rng: &mut Rng, shift: DVec3) -> Mesh {
    let axis = rng.unit().as_vec3();
    let q = glam::Quat::from_axis_angle(axis, (rng.next_f64() * std::f64::consts::TAU) as f32);
    let mut r = m.clone();
    r.transform(Vec3::ONE, q, shift.as_vec3());
    r.name = format!("{} rotated", m.name);
    r
}

#[test]
fn random_sweep_of_meshes_grids_and_rotations() {
    let mut rng = Rng::new(2024);
    let bases = [
        bumpy_sphere(6, 9),
        fin(),
        fan(),
        saddle(),
        pinched(),
        degenerate(),
        cube(),
    ];
    for round in 0..60 {
        let base = &bases[round % bases.len()];
        let shift = 3.0 * rng.vec();
        let m = if round % 3 == 2 {
            soup(&mut rng, 25)
        } else {
            rotated(base, &mut rng, shift)
        };
        let b = m.bounds();
        let (c, e) = (b.center().as_dvec3(), b.extent().as_dvec3().max_element());
        // Random bounds that may cut the mesh, random non-cubic resolutions.
        let lo = c - e * DVec3::new(
            0.4 + rng.next_f64(),
            0.4 + rng.next_f64(),
            0.4 + rng.next_f64(),
        );
        let hi = c + e * DVec3::new(
            0.4 + rng.next_f64(),
            0.4 + rng.next_f64(),
            0.4 + rng.next_f64(),
        );
        let res = [
            6 + (rng.next_f64() * 20.0) as usize,
            6 + (rng.next_f64() * 20.0) as usize,
            3 + (rng.next_f64() * 20.0) as usize,
        ];
        let grid = Grid::new(lo, hi, res).unwrap();
        let tol = TOL * b.diagonal();
        for kind in KINDS {
            for band in [None, Some(0.1 * e)] {
                let bvh = run(&m, kind, &grid, Method::Bvh, &opts(band, Domains::Tight));
                for o in [
                    opts(band, Domains::Tight),
                    opts_nocull(band, Domains::Tight),
                    opts(band, Domains::Loose),
                ] {
                    let lf = run(&m, kind, &grid, Method::Linfac, &o);
                    assert_same(
                        &lf,
                        &bvh,
                        tol,
                        &format!("round {round} {} {kind} {res:?} {o:?}", m.name),
                    );
                }
            }
        }
    }
}

#[test]
fn a_band_beyond_every_distance_changes_nothing() {
    let m = fin();
    let grid = Grid::around(m.bounds(), 12).unwrap();
    for kind in KINDS {
        let exact = run(&m, kind, &grid, Method::Linfac, &opts(None, Domains::Tight));
        for band in [1e3, 1e200, f64::MAX] {
            let f = run(
                &m,
                kind,
                &grid,
                Method::Linfac,
                &opts(Some(band), Domains::Tight),
            );
            assert_eq!(f.values, exact.values, "{kind} band {band}");
            assert_eq!(f.band, Some(band));
        }
    }
}

#[test]
fn far_from_the_origin() {
    // Coordinates around 1e4 with a mesh of diagonal ~3: the margin must not be taken
    // relative to the coordinates' size.
    let mut m = bumpy_sphere(8, 12);
    m.transform(
        Vec3::ONE,
        glam::Quat::from_rotation_y(0.3),
        Vec3::new(1.0e4, -2.0e4, 5.0e3),
    );
    let grid = Grid::around(m.bounds(), 20).unwrap();
    let tol = TOL * m.bounds().diagonal();
    for kind in KINDS {
        let bvh = run(&m, kind, &grid, Method::Bvh, &opts(None, Domains::Tight));
        for o in [
            opts(None, Domains::Tight),
            opts_nocull(None, Domains::Loose),
        ] {
            let lf = run(&m, kind, &grid, Method::Linfac, &o);
            assert_same(&lf, &bvh, tol, &format!("far {kind} {o:?}"));
        }
    }
}
