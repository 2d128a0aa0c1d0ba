//! The smooth-distance engine against f64 brute force and the properties of SPEC 2-6.

mod common;

use common::{Rng, angle, bumpy_sphere, random_wire, s_scale};
use glam::DVec3;
use smoothtrace::bvh;
use smoothtrace::eval::{self, Accumulation, EvalParams, brute};
use smoothtrace::mesh::Mesh;
use smoothtrace::primitives::{AnySet, Primitive, PrimitiveKind};

const KINDS: [PrimitiveKind; 3] = [
    PrimitiveKind::Points,
    PrimitiveKind::Edges,
    PrimitiveKind::Triangles,
];

/// Queries near the surface (on vertices, near faces) and far away.
fn queries(mesh: &Mesh, rng: &mut Rng, n: usize) -> Vec<DVec3> {
    let diag = mesh.bounds().diagonal();
    let c = mesh.bounds().center().as_dvec3();
    let mut q = Vec::new();
    for i in 0..n {
        let v = mesh.vertices
            [(rng.next_f64() * mesh.vertices.len() as f64) as usize % mesh.vertices.len()]
        .as_dvec3();
        q.push(match i % 4 {
            0 => v,
            1 => v + 0.01 * diag * rng.vec(),
            2 => v + 0.2 * diag * rng.vec(),
            _ => c + 3.0 * diag * rng.unit(),
        });
    }
    q
}

fn check_against_brute(mesh: &Mesh, kinds: &[PrimitiveKind], alpha_diag: &[f64], seed: u64) {
    let sets: Vec<AnySet> = kinds
        .iter()
        .map(|&k| AnySet::build(mesh, k).unwrap())
        .collect();
    let refs: Vec<&AnySet> = sets.iter().collect();
    let diag = mesh.bounds().diagonal();
    let mut rng = Rng::new(seed);
    let qs = queries(mesh, &mut rng, 200);
    for &ad in alpha_diag {
        let alpha = ad / diag;
        for max_alpha in [alpha, 2.0 * alpha] {
            let p = EvalParams::new(alpha, max_alpha, 0.0);
            for &x in &qs {
                let got = eval::evaluate(&refs, x, &p);
                let value_only = eval::evaluate_value(&refs, x, &p);
                assert!(
                    (got.s - value_only.s).abs() <= 1e-12 * s_scale(got.s, alpha),
                    "value-only evaluation {} differs from {} at {x}",
                    value_only.s,
                    got.s
                );
                let (s, g, dmin) = brute::smooth_distance(&refs, x, alpha, max_alpha);
                let tol = 1e-6 * s_scale(s, alpha);
                assert!(
                    (got.s - s).abs() <= tol,
                    "{} {kinds:?} alpha*diag {ad}: s = {} brute {} (diff {}, tol {tol}) at {x}",
                    mesh.name,
                    got.s,
                    s,
                    (got.s - s).abs()
                );
                if g.length() > 1e-6 {
                    let a = angle(got.grad, g);
                    assert!(
                        a <= 1e-4,
                        "gradient off by {a} rad at {x}: {} vs {g}",
                        got.grad
                    );
                }
                assert!(
                    got.s <= dmin * (1.0 + 1e-12) + 1e-300,
                    "s {} > dmin {dmin}",
                    got.s
                );
                let near = eval::nearest(&refs, x);
                assert!(
                    (near.d - dmin).abs() <= 1e-12 * dmin.max(diag * 1e-9),
                    "nearest {} vs {dmin}",
                    near.d
                );
            }
        }
    }
}

#[test]
fn beta0_matches_brute_force_on_procedural_meshes() {
    let sphere = bumpy_sphere(12, 20);
    for k in KINDS {
        check_against_brute(&sphere, &[k], &[3.0, 30.0, 300.0, 3000.0], 1);
    }
    check_against_brute(
        &sphere,
        &[PrimitiveKind::Triangles, PrimitiveKind::Points],
        &[50.0],
        2,
    );
    let wire = random_wire(&mut Rng::new(3), 8, 20);
    check_against_brute(&wire, &[PrimitiveKind::Edges], &[5.0, 100.0, 1000.0], 4);
    check_against_brute(&wire, &[PrimitiveKind::Points], &[5.0, 100.0], 5);
}

#[test]
fn beta0_matches_brute_force_on_data_meshes() {
    for name in ["bunny-7k.obj", "teapot.obj", "cow.obj", "suzanne.obj"] {
        let Some(path) = common::data_file(name) else {
            return;
        };
        let mesh = Mesh::load(&path).unwrap();
        for k in KINDS {
            check_against_brute(&mesh, &[k], &[100.0, 1000.0], 7);
        }
    }
}

#[test]
fn barnes_hut_never_exceeds_exact_and_is_conservative() {
    let sphere = bumpy_sphere(16, 24);
    let mut rng = Rng::new(9);
    let qs = queries(&sphere, &mut rng, 300);
    let diag = sphere.bounds().diagonal();
    for k in KINDS {
        let set = AnySet::build(&sphere, k).unwrap();
        for ad in [5.0, 100.0, 2000.0] {
            let alpha = ad / diag;
            let exact = EvalParams::new(alpha, alpha, 0.0);
            for &x in &qs {
                let s0 = eval::evaluate(&[&set], x, &exact).s;
                let dmin = eval::nearest(&[&set], x).d;
                let (s_exact, _, _) = brute::smooth_distance(&[&set], x, alpha, alpha);
                let rounding = 1e-12 * s_scale(s_exact, alpha);
                assert!(s0 <= dmin * (1.0 + 1e-12), "s {s0} > dmin {dmin}");
                // Pruning lowers s by at most 2e-10 / alpha and never raises it.
                assert!(
                    s0 <= s_exact + rounding,
                    "beta 0: {s0} above the exact {s_exact}"
                );
                assert!(
                    s0 >= s_exact - 3e-10 / alpha,
                    "beta 0: {s0} far below {s_exact}"
                );
                for beta in [0.1, 0.5, 1.0] {
                    let p = EvalParams::new(alpha, alpha, beta);
                    let sb = eval::evaluate(&[&set], x, &p).s;
                    let sv = eval::evaluate_value(&[&set], x, &p).s;
                    assert!(
                        (sb - sv).abs() <= 1e-12 * s_scale(sb, alpha),
                        "{sb} vs {sv}"
                    );
                    assert!(
                        sb <= s_exact + rounding,
                        "{k} beta {beta}: {sb} > exact {s_exact} at {x}"
                    );
                }
            }
        }
    }
}

#[test]
fn far_terms_by_share_stay_conservative_and_spare_terms_on_soft_fields() {
    // A dense sphere (2,376 triangles) at soft and stiff alphas: far terms by share keep
    // the value below the exact one for any level (even one below the value, which
    // loosens the rule) and its gradient finite; with a level at the value they cost
    // little accuracy and spare exact terms where the field is soft.
    use smoothtrace::eval::FarShare;
    let sphere = bumpy_sphere(34, 36);
    let mut rng = Rng::new(31);
    let qs = queries(&sphere, &mut rng, 120);
    let diag = sphere.bounds().diagonal();
    for k in [PrimitiveKind::Edges, PrimitiveKind::Triangles] {
        let set = AnySet::build(&sphere, k).unwrap();
        for ad in [30.0, 100.0, 1000.0] {
            let alpha = ad / diag;
            let (mut exact_off, mut exact_on) = (0u64, 0u64);
            for &x in &qs {
                let (s_exact, _, _) = brute::smooth_distance(&[&set], x, alpha, alpha);
                let rounding = 1e-12 * s_scale(s_exact, alpha);
                for beta in [0.0, 0.3] {
                    let off = EvalParams {
                        prune_tolerance: 2.5e-3,
                        ..EvalParams::new(alpha, alpha, beta)
                    };
                    let base = eval::evaluate(&[&set], x, &off);
                    for (share, level) in [
                        (4e-4, f64::INFINITY),
                        (4e-4, s_exact.max(0.0)),
                        (4e-3, s_exact - 10.0 / alpha),
                        (0.2, -1.0),
                    ] {
                        let p = EvalParams {
                            far_share: FarShare { share, level },
                            ..off
                        };
                        let got = eval::evaluate(&[&set], x, &p);
                        assert!(
                            got.s <= s_exact + rounding,
                            "{k} alpha*diag {ad} beta {beta} share {share} level {level}: {} above the exact {s_exact} at {x}",
                            got.s
                        );
                        assert!(got.grad.is_finite(), "gradient {:?}", got.grad);
                        if share == 4e-4 && level.is_finite() && beta == 0.3 {
                            exact_on += got.stats.exact as u64;
                            exact_off += base.stats.exact as u64;
                            // A share of 4e-4 per term, with a level at the value: the
                            // value within a few hundredths of a kernel width.
                            assert!(
                                got.s >= base.s - 0.05 / alpha,
                                "{k} alpha*diag {ad}: {} far below {} without the rule",
                                got.s,
                                base.s
                            );
                        }
                    }
                }
            }
            assert!(
                exact_on <= exact_off,
                "{k} alpha*diag {ad}: {exact_on} exact terms with the rule, {exact_off} without"
            );
            if ad <= 100.0 {
                assert!(
                    exact_on * 10 <= exact_off * 9,
                    "{k} alpha*diag {ad}: {exact_on} exact terms with the rule, {exact_off} without"
                );
            }
        }
    }
}

#[test]
fn pruning_off_gives_the_same_values() {
    let sphere = bumpy_sphere(10, 16);
    let set = AnySet::build(&sphere, PrimitiveKind::Triangles).unwrap();
    let mut rng = Rng::new(11);
    for x in queries(&sphere, &mut rng, 100) {
        let mut p = EvalParams::new(80.0, 80.0, 0.0);
        let a = eval::evaluate(&[&set], x, &p);
        p.prune = false;
        let b = eval::evaluate(&[&set], x, &p);
        // Pruning drops less than 1e-10 of the sum and covers it from above.
        assert!(
            a.s <= b.s + 1e-12 * s_scale(b.s, 80.0),
            "{} above {}",
            a.s,
            b.s
        );
        assert!(b.s - a.s <= 3e-10 / 80.0, "{} vs {}", a.s, b.s);
        assert!(a.stats.leaves() <= b.stats.leaves());
        assert_eq!(b.stats.exact as usize, set.len());
    }
}

/// Pruning at the tracer's tolerances (up to 1e-2 of the sum), where the budget rule
/// skips whole subtrees (`eval::smooth` module docs): never above the exact value, never
/// more than `2 tol / alpha` below it at beta 0 (pruning alone), with the free distance
/// along a ray keeping the exact value positive; and with far fields (beta 1), fewer
/// leaves than the union-bound rule alone visits at the same tolerance.
#[test]
fn budget_pruning_is_conservative_and_within_its_tolerance() {
    let mut rng = Rng::new(31);
    // A lidar-like ground patch with trees: many primitives within the pruning reach.
    let mut pts: Vec<DVec3> = (0..20_000)
        .map(|_| DVec3::new(rng.sym(), rng.sym(), 0.005 * rng.sym()))
        .collect();
    pts.extend((0..2000).map(|i| {
        DVec3::new(0.25 * (i % 5) as f64 - 0.5, 0.1, 0.15 * rng.next_f64()) + 0.02 * rng.vec()
    }));
    let mesh = Mesh {
        vertices: pts.iter().map(|p| p.as_vec3()).collect(),
        segments: Vec::new(),
        triangles: Vec::new(),
        name: "ground".to_string(),
    };
    let set = AnySet::build(&mesh, PrimitiveKind::Points).unwrap();
    let diag = mesh.bounds().diagonal();
    let (mut leaves_union, mut leaves_budget) = (0u64, 0u64);
    for ad in [100.0, 300.0, 1000.0] {
        let alpha = ad / diag;
        for _ in 0..60 {
            let x = DVec3::new(0.8 * rng.sym(), 0.8 * rng.sym(), 0.2 * rng.next_f64());
            let (exact, _, _) = brute::smooth_distance(&[&set], x, alpha, alpha);
            let rounding = 1e-12 * s_scale(exact, alpha);
            for tol in [1e-3, 1e-2] {
                let p = EvalParams {
                    prune_tolerance: tol,
                    ..EvalParams::new(alpha, alpha, 0.0)
                };
                let got = eval::evaluate(&[&set], x, &p);
                // With far fields (the tracer's step beta), against the first rule alone.
                let far = EvalParams { beta: 1.0, ..p };
                let union_only = EvalParams {
                    budget: false,
                    ..far
                };
                let with_far = eval::evaluate_value(&[&set], x, &far);
                assert!(
                    with_far.s <= exact + rounding,
                    "alpha*diag {ad} tol {tol} beta 1: {} above the exact {exact}",
                    with_far.s
                );
                leaves_budget += with_far.stats.leaves() as u64;
                leaves_union += eval::evaluate_value(&[&set], x, &union_only).stats.leaves() as u64;
                assert!(
                    got.s <= exact + rounding,
                    "alpha*diag {ad} tol {tol}: {} above the exact {exact} at {x}",
                    got.s
                );
                assert!(
                    got.s >= exact - 2.0 * tol / alpha - rounding,
                    "alpha*diag {ad} tol {tol}: {} more than 2 tol / alpha below {exact}",
                    got.s
                );
                let u = rng.unit();
                let r = eval::evaluate_reach(&[&set], x, u, &p, diag, false);
                if exact > 0.0 {
                    for k in 1..=8 {
                        let y = x + u * (r.reach * k as f64 / 8.0);
                        let (e, _, _) = brute::smooth_distance(&[&set], y, alpha, alpha);
                        assert!(
                            e > -rounding,
                            "alpha*diag {ad} tol {tol}: exact {e} < 0 within the free distance {} (s {})",
                            r.reach,
                            r.s
                        );
                    }
                }
            }
        }
    }
    assert!(
        leaves_budget * 20 < leaves_union * 19,
        "{leaves_budget} leaves with the budget against {leaves_union} without"
    );
}

#[test]
fn nesting_in_alpha_with_unit_weights() {
    let sphere = bumpy_sphere(10, 16);
    let set = AnySet::build(&sphere, PrimitiveKind::Points).unwrap();
    let mut rng = Rng::new(13);
    for x in queries(&sphere, &mut rng, 100) {
        let mut last = f64::NEG_INFINITY;
        for alpha in [0.5, 1.0, 4.0, 16.0, 64.0, 256.0] {
            let s = eval::evaluate(&[&set], x, &EvalParams::new(alpha, alpha, 0.0)).s;
            assert!(s >= last - 1e-12, "alpha {alpha}: s {s} < {last}");
            last = s;
        }
    }
}

#[test]
fn gradients_match_central_differences() {
    let sphere = bumpy_sphere(10, 16);
    let diag = sphere.bounds().diagonal();
    let mut rng = Rng::new(17);
    for k in KINDS {
        let set = AnySet::build(&sphere, k).unwrap();
        for (alpha, max_alpha) in [(10.0, 10.0), (40.0, 80.0), (5.0, 50.0)] {
            let p = EvalParams::new(alpha, max_alpha, 0.0);
            for _ in 0..60 {
                let x = rng.vec() * 1.6;
                let h = 1e-6 * diag;
                let f = |d: DVec3| eval::evaluate(&[&set], x + d, &p).s;
                let fd = DVec3::new(
                    f(DVec3::X * h) - f(-DVec3::X * h),
                    f(DVec3::Y * h) - f(-DVec3::Y * h),
                    f(DVec3::Z * h) - f(-DVec3::Z * h),
                ) / (2.0 * h);
                let g = eval::evaluate(&[&set], x, &p).grad;
                assert!(
                    (g - fd).length() <= 1e-4 * g.length().max(1e-3),
                    "{k} alpha {alpha}/{max_alpha}: grad {g} vs fd {fd} at {x}"
                );
            }
        }
    }
}

#[test]
fn scale_invariance() {
    let base = bumpy_sphere(10, 16);
    let mut rng = Rng::new(19);
    let qs = queries(&base, &mut rng, 80);
    for kind in KINDS {
        let set1 = AnySet::build(&base, kind).unwrap();
        let alpha = 60.0;
        let p1 = EvalParams::new(alpha, 2.0 * alpha, 0.0);
        for k in [1e-4f64, 1e-2, 1e2, 1e4] {
            let mut m = base.clone();
            for v in &mut m.vertices {
                *v *= k as f32;
            }
            let setk = AnySet::build(&m, kind).unwrap();
            let pk = EvalParams::new(alpha / k, 2.0 * alpha / k, 0.0);
            for &x in &qs {
                // Queries scaled like the mesh: through f32 so both see the same geometry.
                let x = x.as_vec3().as_dvec3();
                let s1 = eval::evaluate(&[&set1], x, &p1).s;
                let sk = eval::evaluate(&[&setk], x * k, &pk).s;
                assert!(
                    (sk / k - s1).abs() <= 1e-5 * s_scale(s1, alpha),
                    "{kind} k {k}: {} vs {s1}",
                    sk / k
                );
            }
        }
    }
}

/// The published code drifts by percents at the bunny's native size (an absolute epsilon
/// in its closest-point code); ours scales exactly. Two checks: (1) at every decimal
/// scale k in 1e-4..1e4, beta = 0 equals the f64 brute force on the scaled mesh to 1e-6;
/// (2) scaling by the power of two nearest each k (exact in f32, so the scaled mesh is
/// the same geometry) gives k times the same s to 1e-10. A decimal k rounds the f32
/// vertices by up to 6e-8 relative, which moves s near the surface by a few 1e-5 of
/// itself: that is the data changing, not the evaluator.
#[test]
fn scale_invariance_and_exactness_at_every_scale_on_the_bunny() {
    let Some(path) = common::data_file("bunny-7k.obj") else {
        return;
    };
    let base = Mesh::load(&path).unwrap();
    let diag = base.bounds().diagonal();
    let mut rng = Rng::new(29);
    let qs: Vec<DVec3> = queries(&base, &mut rng, 60)
        .iter()
        .map(|x| x.as_vec3().as_dvec3())
        .collect();
    let scaled = |k: f64| {
        let mut m = base.clone();
        for v in &mut m.vertices {
            *v *= k as f32;
        }
        m
    };
    for kind in KINDS {
        let set1 = AnySet::build(&base, kind).unwrap();
        let alpha = 300.0 / diag;
        let p1 = EvalParams::new(alpha, alpha, 0.0);
        for k in [1e-4f64, 1e-2, 1e2, 1e4] {
            let setk = AnySet::build(&scaled(k), kind).unwrap();
            let pk = EvalParams::new(alpha / k, alpha / k, 0.0);
            for &x in &qs {
                let got = eval::evaluate(&[&setk], x * k, &pk).s;
                let (want, _, _) = brute::smooth_distance(&[&setk], x * k, alpha / k, alpha / k);
                assert!(
                    (got - want).abs() <= 1e-6 * s_scale(want, alpha / k),
                    "{kind} k {k}: {got} vs brute force {want}"
                );
            }
            let k2 = 2f64.powi(k.log2().round() as i32);
            let setk = AnySet::build(&scaled(k2), kind).unwrap();
            let pk = EvalParams::new(alpha / k2, alpha / k2, 0.0);
            for &x in &qs {
                let s1 = eval::evaluate(&[&set1], x, &p1).s;
                let sk = eval::evaluate(&[&setk], x * k2, &pk).s;
                assert!(
                    (sk / k2 - s1).abs() <= 1e-10 * s_scale(s1, alpha),
                    "{kind} k {k2}: {} vs {s1}",
                    sk / k2
                );
            }
        }
    }
}

#[test]
fn stable_evaluator_never_returns_nan_or_inf() {
    let mut mesh = bumpy_sphere(8, 12);
    // Degenerate triangles and edges, duplicate and coincident vertices.
    let n = mesh.vertices.len() as u32;
    mesh.vertices.push(mesh.vertices[3]);
    mesh.triangles.push([1, 1, 2]);
    mesh.triangles.push([3, n, 4]);
    mesh.triangles.push([5, 5, 5]);
    let diag = mesh.bounds().diagonal();
    let wire = Mesh {
        segments: vec![[0, 0], [1, 2], [2, 1], [3, n]],
        ..mesh.clone()
    };
    let mut rng = Rng::new(23);
    for (m, kind) in [
        (&mesh, PrimitiveKind::Triangles),
        (&wire, PrimitiveKind::Edges),
        (&mesh, PrimitiveKind::Points),
    ] {
        let set = AnySet::build(m, kind).unwrap();
        for ad in [1.0, 1e2, 1e4, 1e7] {
            let p = EvalParams::new(ad / diag, ad / diag, 0.5);
            let mut xs: Vec<DVec3> = m.vertices.iter().map(|v| v.as_dvec3()).collect();
            for t in &m.triangles {
                let [a, b, c] = t.map(|i| m.vertices[i as usize].as_dvec3());
                xs.push((a + b) / 2.0);
                xs.push((a + b + c) / 3.0);
            }
            for _ in 0..20 {
                xs.push(rng.unit() * 1e6 * diag);
            }
            for x in xs {
                let s = eval::evaluate(&[&set], x, &p);
                assert!(
                    s.s.is_finite() && s.grad.is_finite(),
                    "{kind} alpha*diag {ad} at {x}: {s:?}"
                );
            }
        }
    }
}

#[test]
fn naive_mode_underflows_to_infinity_and_says_so() {
    let mesh = bumpy_sphere(8, 12);
    let set = AnySet::build(&mesh, PrimitiveKind::Points).unwrap();
    let mut p = EvalParams::new(1e4, 1e4, 0.0);
    p.accumulation = Accumulation::Naive;
    let s = eval::evaluate(&[&set], DVec3::new(0.0, 5.0, 0.0), &p);
    assert!(s.s == f64::INFINITY && s.underflow);
    // Where it does not underflow it agrees with the stable sum.
    p.alpha = 3.0;
    p.max_alpha = 3.0;
    let a = eval::evaluate(&[&set], DVec3::new(0.0, 2.0, 0.0), &p);
    p.accumulation = Accumulation::Stable;
    let b = eval::evaluate(&[&set], DVec3::new(0.0, 2.0, 0.0), &p);
    assert!((a.s - b.s).abs() < 1e-12 && !a.underflow);
}

#[test]
fn bvh_is_valid_including_duplicate_points() {
    let mut mesh = bumpy_sphere(20, 30);
    for _ in 0..1000 {
        mesh.vertices.push(mesh.vertices[7]);
    }
    for k in KINDS {
        let set = AnySet::build(&mesh, k).unwrap();
        smoothtrace::with_set!(&set, s => {
            // Bounds in source order, from the reordered primitives.
            let mut src = vec![s.prims[0].bounds(); s.prims.len()];
            for (i, &o) in s.bvh.order.iter().enumerate() {
                src[o as usize] = s.prims[i].bounds();
            }
            bvh::validate(&s.bvh, &src).unwrap();
        });
    }
}

/// Far-field terms of point clouds from second moments (`eval::smooth` module docs):
/// never above the exact value, at any opening parameter the tracer uses (the scene's,
/// its step beta and its coarse bound steps), at any sharpness and offset, on flat,
/// clustered and coincident points; never below the closest-box terms by more than the
/// pruning slack, and much closer to the exact value on soft clouds. The free distance
/// along a ray (`eval::reach`) keeps the exact value positive (this found middles' slopes
/// taken from the nearer child's box alone, wrong at beta 4).
#[test]
fn moment_far_fields_are_conservative_and_tighter_than_boxes() {
    let mut rng = Rng::new(21);
    let clouds: Vec<(&str, Vec<DVec3>)> = vec![
        // A lidar-like ground patch with a few trees.
        ("ground", {
            let mut v: Vec<DVec3> = (0..4000)
                .map(|_| DVec3::new(rng.sym(), rng.sym(), 0.01 * rng.sym()))
                .collect();
            v.extend((0..600).map(|i| {
                DVec3::new(0.3 * (i % 3) as f64 - 0.3, 0.2, 0.2 * rng.next_f64()) + 0.03 * rng.vec()
            }));
            v
        }),
        // Tight clusters far from the origin, and coincident points.
        ("clusters", {
            let centres: Vec<DVec3> = (0..12).map(|_| rng.vec()).collect();
            let mut v: Vec<DVec3> = (0..3000)
                .map(|i| DVec3::splat(1e3) + centres[i % 12] + 0.02 * rng.vec())
                .collect();
            v.extend(std::iter::repeat_n(DVec3::splat(1e3) + centres[0], 50));
            v
        }),
    ];
    for (name, pts) in clouds {
        let mesh = Mesh {
            vertices: pts.iter().map(|p| p.as_vec3()).collect(),
            segments: Vec::new(),
            triangles: Vec::new(),
            name: name.to_string(),
        };
        let set = AnySet::build(&mesh, PrimitiveKind::Points).unwrap();
        let bounds = mesh.bounds();
        let (centre, diag) = (bounds.center().as_dvec3(), bounds.diagonal());
        let (mut gain, mut count) = (0.0, 0);
        for ad in [3.0, 30.0, 300.0, 3000.0] {
            let alpha = ad / diag;
            for _ in 0..150 {
                let x = centre + 0.7 * diag * rng.vec() * rng.next_f64();
                let (exact, _, _) = brute::smooth_distance(&[&set], x, alpha, alpha);
                let rounding = 1e-12 * s_scale(exact, alpha);
                for beta in [0.5, 1.0, 4.0] {
                    let p = EvalParams::new(alpha, alpha, beta);
                    let box_p = EvalParams {
                        moments: false,
                        ..p
                    };
                    let sm = eval::evaluate_value(&[&set], x, &p).s;
                    let sb = eval::evaluate_value(&[&set], x, &box_p).s;
                    assert!(sm.is_finite(), "{name}: {sm} at alpha {alpha}");
                    assert!(
                        sm <= exact + rounding,
                        "{name} alpha*diag {ad} beta {beta}: {sm} above the exact {exact}"
                    );
                    assert!(
                        sm >= sb - 3e-10 / alpha,
                        "{name} alpha*diag {ad} beta {beta}: {sm} below the box value {sb}"
                    );
                    // The free distance along a ray (eval::reach) holds with moment terms:
                    // the exact value stays positive over it.
                    // So does the free distance behind (asked for up to the diagonal).
                    let u = rng.unit();
                    let along = eval::Along {
                        u,
                        max_len: diag,
                        back: diag,
                    };
                    let r = eval::evaluate_along(&[&set], x, Some(along), &p, false);
                    if exact > 0.0 && r.reach.max(r.reach_back) > r.s {
                        for k in 1..=8 {
                            for (free, sign) in [(r.reach, 1.0), (r.reach_back, -1.0)] {
                                let t = sign * free * k as f64 / 8.0;
                                let (e, _, _) =
                                    brute::smooth_distance(&[&set], x + t * u, alpha, alpha);
                                assert!(
                                    e >= -1e-12 * s_scale(e, alpha),
                                    "{name} alpha*diag {ad} beta {beta}: exact {e} at {t} of free {free}",
                                );
                            }
                        }
                    }
                    if ad <= 30.0 && beta == 1.0 && exact - sb > 1e-6 / alpha {
                        gain += (exact - sm) / (exact - sb);
                        count += 1;
                    }
                }
            }
        }
        // On soft clouds the moment terms close most of the box terms' error.
        let mean = gain / count as f64;
        eprintln!("{name}: moment error / box error, mean {mean:.3} over {count}");
        assert!(count > 50 && mean < 0.5, "{name}: {mean} over {count}");
    }
}

/// Free distances on edges and triangles (`eval::reach`): with weights that do not vary
/// (`max_alpha` far above `alpha`, so `q` is nearly 0) the exact smooth distance stays
/// positive all along every free distance, as on points; with the weights attenuated by
/// `q = 1/2` (the published scenes' setting) the bound holds to first order, and the
/// exact value within it dips below zero by at most a tenth of the step (7% measured at
/// `alpha * diag` 30, none at 100; the plain step's ball, checked alike, never dips). The
/// free distance is never shorter than the plain step `s`, and longer on average.
#[test]
fn mesh_free_distances_hold_and_beat_the_plain_step() {
    let sphere = bumpy_sphere(12, 18);
    let diag = sphere.bounds().diagonal();
    let mut rng = Rng::new(29);
    for kind in [PrimitiveKind::Edges, PrimitiveKind::Triangles] {
        let set = AnySet::build(&sphere, kind).unwrap();
        for (ad, q) in [(30.0, 1e-9), (100.0, 1e-9), (30.0, 0.5), (100.0, 0.5)] {
            let alpha = ad / diag;
            let p = EvalParams::new(alpha, alpha / q, 0.3);
            let (mut worst, mut gain, mut n) = (0.0f64, 0.0, 0);
            let mut worst_ball = 0.0f64;
            for _ in 0..150 {
                // From outside the surface towards (or past) it.
                let x = rng.unit() * (1.2 + 0.6 * rng.next_f64());
                let u = (rng.unit() * 0.6 - x.normalize()).normalize();
                let r = eval::evaluate_reach(&[&set], x, u, &p, diag, false);
                assert!(
                    r.reach >= r.s,
                    "{kind:?}: reach {} below s {}",
                    r.reach,
                    r.s
                );
                if r.s.is_nan() || r.s <= 0.0 {
                    continue;
                }
                for k in 1..=8 {
                    let y = x + u * (r.reach * k as f64 / 8.0);
                    let (e, _, _) = brute::smooth_distance(&[&set], y, alpha, alpha / q);
                    worst = worst.min(e / r.reach);
                    let y = x + u * (r.s * k as f64 / 8.0);
                    let (e, _, _) = brute::smooth_distance(&[&set], y, alpha, alpha / q);
                    worst_ball = worst_ball.min(e / r.s);
                }
                gain += r.reach / r.s;
                n += 1;
            }
            let gain = gain / n as f64;
            eprintln!(
                "{kind:?} alpha*diag {ad} q {q}: worst {worst:.2e} of the step, ball {worst_ball:.2e}, mean gain {gain:.2}"
            );
            let allowed = if q < 1e-6 { -1e-9 } else { -0.1 };
            assert!(
                worst >= allowed,
                "{kind:?} alpha*diag {ad} q {q}: the exact value fell to {worst:e} of the step"
            );
            assert!(
                worst_ball >= -1e-9,
                "{kind:?} alpha*diag {ad} q {q}: ball {worst_ball:e}"
            );
            assert!(
                gain > 1.05,
                "{kind:?} alpha*diag {ad} q {q}: mean reach / s {gain}"
            );
        }
    }
}
