//! The suite's cases, on procedural geometry only (no data files; SPEC 2, 3, 4, 5): the
//! field cases of [`build_cases`] (alpha times the diagonal from 1 to 1e7 for points,
//! edges and triangles; queries from on the primitives to 1e6 diagonals away; scaled and
//! translated copies with the unscaled brute force to compare with; the degenerate and
//! high-valence meshes of [`degenerate_meshes`]; max_alpha below and above alpha) and the
//! render cases of [`render_cases`] (a stiff scene, and an unscaled, a tiny and a huge
//! copy of one scene). Queries come from a fixed-seed generator, so every run of the
//! suite asks the same questions.

use super::{Case, Compare, RenderCase, Size, diag_of, set};
use crate::eval::brute;
use crate::mesh::Mesh;
use crate::primitives::{AnySet, PrimitiveKind};
use crate::procedural::{sphere_points, torus};
use glam::{DVec3, Vec3};

/// A deterministic generator for the queries (fixed seed per case).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn unit(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(self.next(), self.next(), self.next()) * 2.0 - 1.0;
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                return v / l;
            }
        }
    }
}

/// Points on the mesh: vertices, edge midpoints, triangle centroids (in turn).
fn on_mesh(mesh: &Mesh, i: usize) -> DVec3 {
    let v = |k: u32| mesh.vertices[k as usize].as_dvec3();
    match (i % 3, mesh.triangles.is_empty(), mesh.segments.is_empty()) {
        (1, false, _) => {
            let t = mesh.triangles[(i / 3) % mesh.triangles.len()];
            0.5 * (v(t[0]) + v(t[1]))
        }
        (2, false, _) => {
            let t = mesh.triangles[(i / 3) % mesh.triangles.len()];
            (v(t[0]) + v(t[1]) + v(t[2])) / 3.0
        }
        (1 | 2, true, false) => {
            let s = mesh.segments[(i / 3) % mesh.segments.len()];
            0.5 * (v(s[0]) + v(s[1]))
        }
        _ => v((i * 7919 % mesh.vertices.len()) as u32),
    }
}

/// `n` queries: a quarter on the mesh, the rest on-mesh points moved by up to `spread`
/// times the diagonal in a random direction (fixed seed).
fn near_queries(mesh: &Mesh, n: usize, spread: f64, seed: u64) -> Vec<DVec3> {
    let diag = mesh.bounds().diagonal();
    let mut rng = Rng(seed.wrapping_mul(0x9E3779B97F4A7C15) | 1);
    (0..n)
        .map(|i| {
            let p = on_mesh(mesh, i);
            if i % 4 == 0 {
                p
            } else {
                p + rng.unit() * (spread * diag * rng.next())
            }
        })
        .collect()
}

/// On-mesh points moved by exactly `dist` diagonals (0: on the mesh).
fn queries_at(mesh: &Mesh, n: usize, dist: f64, seed: u64) -> Vec<DVec3> {
    let diag = mesh.bounds().diagonal();
    let mut rng = Rng(seed.wrapping_mul(0x9E3779B97F4A7C15) | 1);
    (0..n)
        .map(|i| on_mesh(mesh, i) + rng.unit() * (dist * diag))
        .collect()
}

fn scaled(mesh: &Mesh, k: f64, shift: DVec3) -> Mesh {
    let mut m = mesh.clone();
    for v in &mut m.vertices {
        *v = (v.as_dvec3() * k + shift).as_vec3();
    }
    m
}

fn case(
    group: &'static str,
    name: String,
    sets: Vec<AnySet>,
    alpha_diag: f64,
    max_alpha_factor: f64,
    queries: Vec<DVec3>,
) -> Case {
    let diag = diag_of(&sets);
    let alpha = alpha_diag / diag;
    Case {
        group,
        name,
        sets,
        alpha,
        max_alpha: alpha * max_alpha_factor,
        diag,
        queries,
        scale_ref: None,
    }
}

/// Degenerate and high-valence meshes of the suite: name, mesh, primitive kinds.
fn degenerate_meshes() -> Vec<(&'static str, Mesh, Vec<PrimitiveKind>)> {
    use PrimitiveKind::*;
    let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let mut out = Vec::new();
    // A polyline with zero-length segments: repeated indices and coincident vertices.
    out.push((
        "degenerate edges",
        Mesh {
            vertices: vec![
                v(0.0, 0.0, 0.0),
                v(1.0, 0.0, 0.0),
                v(1.0, 0.0, 0.0),
                v(1.0, 1.0, 0.0),
                v(1.0, 1.0, 0.0),
            ],
            segments: vec![[0, 1], [1, 1], [1, 2], [2, 3], [3, 4], [4, 4]],
            triangles: vec![],
            name: "degenerate-edges".into(),
        },
        vec![Edges, Points],
    ));
    // Zero-area triangles: collinear, a repeated index, three coincident vertices,
    // beside a proper one.
    out.push((
        "degenerate triangles",
        Mesh {
            vertices: vec![
                v(0.0, 0.0, 0.0),
                v(1.0, 0.0, 0.0),
                v(2.0, 0.0, 0.0),
                v(0.0, 1.0, 0.0),
                v(0.5, 0.5, 1.0),
                v(0.5, 0.5, 1.0),
                v(0.5, 0.5, 1.0),
            ],
            segments: vec![],
            triangles: vec![[0, 1, 2], [0, 0, 3], [4, 5, 6], [0, 1, 3], [1, 1, 1]],
            name: "degenerate-triangles".into(),
        },
        vec![Triangles, Edges],
    ));
    // A triangle soup of a grid: every triangle has its own (duplicate) vertices.
    let mut soup = Mesh {
        name: "duplicate-vertices".into(),
        ..Default::default()
    };
    for i in 0..4 {
        for j in 0..4 {
            let (x, y) = (i as f32, j as f32);
            for t in [
                [v(x, y, 0.0), v(x + 1.0, y, 0.0), v(x + 1.0, y + 1.0, 0.0)],
                [v(x, y, 0.0), v(x + 1.0, y + 1.0, 0.0), v(x, y + 1.0, 0.0)],
            ] {
                let k = soup.vertices.len() as u32;
                soup.vertices.extend(t);
                soup.triangles.push([k, k + 1, k + 2]);
            }
        }
    }
    out.push(("duplicate vertices", soup, vec![Triangles, Edges, Points]));
    out.push((
        "isolated triangle",
        Mesh {
            vertices: vec![v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.2, 0.9, 0.0)],
            segments: vec![],
            triangles: vec![[0, 1, 2]],
            name: "isolated-triangle".into(),
        },
        vec![Triangles, Edges, Points],
    ));
    // A shallow cone of 1,000 triangles around one apex: valence 1,000.
    let n = 1000;
    let mut fan = Mesh {
        vertices: vec![v(0.0, 0.0, 0.2)],
        name: "fan-1000".into(),
        ..Default::default()
    };
    for i in 0..n {
        let a = std::f32::consts::TAU * i as f32 / n as f32;
        fan.vertices.push(v(a.cos(), a.sin(), 0.0));
        fan.triangles
            .push([0, 1 + i as u32, 1 + ((i + 1) % n) as u32]);
    }
    out.push(("fan of 1000 triangles", fan, vec![Triangles, Edges]));
    out
}

pub(super) fn build_cases(size: Size) -> Vec<Case> {
    use PrimitiveKind::*;
    let d = size.dims();
    let tor = torus(1.0, 0.25, d.torus.0, d.torus.1);
    let pts = sphere_points(1.0, d.points);
    let mut cases = Vec::new();
    // alpha * diagonal from 1 to 1e7, each primitive type.
    for (mesh, kind) in [(&pts, Points), (&tor, Edges), (&tor, Triangles)] {
        for e in 0..=7 {
            let ad = 10f64.powi(e);
            cases.push(case(
                "alpha",
                format!("{kind} alpha*diag 1e{e}"),
                vec![set(mesh, kind)],
                ad,
                1.0,
                near_queries(mesh, d.queries, 0.5, 100 + e as u64),
            ));
        }
    }
    // Query distance from on the primitive to 1e6 diagonals.
    for (label, dist) in [
        ("0", 0.0),
        ("1e-6", 1e-6),
        ("1e-3", 1e-3),
        ("1", 1.0),
        ("1e2", 1e2),
        ("1e4", 1e4),
        ("1e6", 1e6),
    ] {
        for kind in [Points, Triangles] {
            let mesh = if kind == Points { &pts } else { &tor };
            cases.push(case(
                "distance",
                format!("{kind} at {label} diagonals"),
                vec![set(mesh, kind)],
                100.0,
                1.0,
                queries_at(mesh, d.queries, dist, 200),
            ));
        }
    }
    // Scaled copies 1e-4 .. 1e4 (alpha / k), and a copy 1e5 diagonals off the origin.
    let base_queries = near_queries(&tor, d.queries, 0.5, 300);
    let base = case(
        "scale",
        "unscaled".into(),
        vec![set(&tor, Triangles)],
        100.0,
        1.0,
        base_queries.clone(),
    );
    let base_refs: Vec<&AnySet> = base.sets.iter().collect();
    let base_s: Vec<f64> = base_queries
        .iter()
        .map(|&x| brute::smooth_distance(&base_refs, x, base.alpha, base.max_alpha).0)
        .collect();
    let base_alpha = base.alpha;
    let tor_diag = tor.bounds().diagonal();
    for (label, k) in [("1e-4", 1e-4), ("1e-2", 1e-2), ("1e2", 1e2), ("1e4", 1e4)] {
        let m = scaled(&tor, k, DVec3::ZERO);
        let sets = vec![set(&m, Triangles)];
        cases.push(Case {
            group: "scale",
            name: format!("triangles scaled by {label}"),
            diag: diag_of(&sets),
            sets,
            alpha: base_alpha / k,
            max_alpha: base_alpha / k,
            queries: base_queries.iter().map(|&x| x * k).collect(),
            scale_ref: Some((base_s.clone(), k, true)),
        });
    }
    let shift = DVec3::ONE.normalize() * (1e5 * tor_diag);
    let m = scaled(&tor, 1.0, shift);
    let sets = vec![set(&m, Triangles)];
    cases.push(Case {
        group: "scale",
        name: "triangles translated 1e5 diagonals".into(),
        diag: diag_of(&sets),
        sets,
        alpha: base_alpha,
        max_alpha: base_alpha,
        queries: base_queries.iter().map(|&x| x + shift).collect(),
        scale_ref: Some((base_s, 1.0, false)),
    });
    cases.push(base);
    // Degenerate input and a vertex of valence 1,000, at a moderate and a stiff alpha.
    for (name, mesh, kinds) in degenerate_meshes() {
        for kind in kinds {
            for ad in [1e2, 1e5] {
                cases.push(case(
                    "degenerate",
                    format!("{name}: {kind} alpha*diag {ad:e}"),
                    vec![set(&mesh, kind)],
                    ad,
                    1.0,
                    near_queries(&mesh, d.queries, 0.3, 400),
                ));
            }
        }
    }
    // max_alpha below alpha (full weights) and above it (attenuated).
    for (label, f) in [("below", 0.1), ("above", 10.0)] {
        for kind in [Edges, Triangles] {
            cases.push(case(
                "max_alpha",
                format!("{kind} max_alpha {label} alpha"),
                vec![set(&tor, kind)],
                100.0,
                f,
                near_queries(&tor, d.queries, 0.5, 500),
            ));
        }
    }
    cases
}

pub(super) fn render_cases(size: Size) -> Vec<RenderCase> {
    let d = size.dims();
    let tor = torus(1.0, 0.25, d.torus.0, d.torus.1);
    let mut out = vec![RenderCase {
        name: "render: stiff (alpha*diag 1e4)".into(),
        mesh: tor.clone(),
        kind: PrimitiveKind::Triangles,
        alpha_diag: 1e4,
        scale: 1.0,
        compare: Compare::Stable,
    }];
    for (label, k) in [
        ("unscaled", 1.0),
        ("tiny (x1e-4)", 1e-4),
        ("huge (x1e4)", 1e4),
    ] {
        out.push(RenderCase {
            name: format!("render: {label}"),
            mesh: scaled(&tor, k, DVec3::ZERO),
            kind: PrimitiveKind::Triangles,
            alpha_diag: 300.0,
            scale: k,
            compare: if k == 1.0 {
                Compare::Nothing
            } else {
                Compare::Unscaled
            },
        });
    }
    out
}
