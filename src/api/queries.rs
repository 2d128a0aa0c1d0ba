//! A traceable object (primitive sets plus evaluation parameters) built from a mesh, and
//! batch queries over many points: the smooth distance (SPEC 2, 6), its gradient, and
//! the exact nearest primitive, evaluated in parallel in the current rayon pool.

use super::InputError;
use super::params::{Naming, apply_tolerance, check_beta, resolve_alpha};
use crate::eval::{self, EvalParams, Nearest};
use crate::geometry::morton::morton_order;
use crate::mesh::Mesh;
use crate::primitives::{AnySet, PrimitiveKind};
use crate::render::TraceObject;
use glam::DVec3;
use rayon::prelude::*;

/// What to build from a mesh and how to evaluate it.
#[derive(Clone, Debug)]
pub struct ObjectSpec {
    /// Primitive sets summed into one smooth distance (duplicates are built once).
    pub kinds: Vec<PrimitiveKind>,
    pub alpha: Option<f64>,
    /// Alpha times the mesh's bounding-box diagonal.
    pub alpha_rel: Option<f64>,
    /// Default: alpha.
    pub max_alpha: Option<f64>,
    pub max_alpha_rel: Option<f64>,
    pub beta: f64,
    /// How far pruning may lower the smooth distance at most (a length; 0: no pruning;
    /// default: a share 1e-10 of the sum, `params::apply_tolerance`).
    pub tolerance: Option<f64>,
}

impl ObjectSpec {
    /// `kinds` at `alpha_rel` (alpha times the diagonal) and `beta`; max_alpha and the
    /// tolerance at their defaults.
    pub fn relative(kinds: Vec<PrimitiveKind>, alpha_rel: f64, beta: f64) -> ObjectSpec {
        ObjectSpec {
            kinds,
            alpha: None,
            alpha_rel: Some(alpha_rel),
            max_alpha: None,
            max_alpha_rel: None,
            beta,
            tolerance: None,
        }
    }
}

/// Builds the primitive sets `spec` names (and nothing else) with their BVHs, and
/// resolves alpha and max_alpha against the mesh's diagonal, with the messages of
/// `naming`.
pub fn build_object(
    mesh: &Mesh,
    spec: &ObjectSpec,
    naming: Naming,
) -> Result<TraceObject, InputError> {
    let beta = check_beta(naming, spec.beta)?;
    let diag = mesh.bounds().diagonal();
    let alpha =
        resolve_alpha(naming, "alpha", spec.alpha, spec.alpha_rel, diag)?.ok_or_else(|| {
            InputError::Parameter(format!(
                "give {} or {}",
                naming.name("alpha"),
                naming.name("alpha_rel")
            ))
        })?;
    let max_alpha = resolve_alpha(
        naming,
        "max_alpha",
        spec.max_alpha,
        spec.max_alpha_rel,
        diag,
    )?
    .unwrap_or(alpha);
    if spec.kinds.is_empty() {
        return Err(InputError::Parameter(format!(
            "{} is empty: name at least one of points, edges, triangles",
            naming.name("primitives")
        )));
    }
    let mut sets: Vec<AnySet> = Vec::new();
    for &kind in &spec.kinds {
        if !sets.iter().any(|s| s.kind() == kind) {
            sets.push(AnySet::build(mesh, kind)?);
        }
    }
    let mut params = EvalParams::new(alpha, max_alpha, beta);
    apply_tolerance(naming, spec.tolerance, &mut params)?;
    Ok(TraceObject::new(sets, params))
}

/// Queries per batch along the Morton curve (in [`nearest`] each starts from its
/// predecessor's answer).
const BATCH: usize = 64;

/// `f(x)` at every point, evaluated along a Morton curve (neighbouring queries walk the
/// same parts of the tree one after the other, so its nodes and primitives stay in the
/// caches), the results in the input order.
fn in_morton_order<T: Send + Copy>(
    points: &[DVec3],
    f: impl Fn(DVec3) -> T + Send + Sync,
) -> Vec<T> {
    in_morton_batches(points, BATCH, |batch| {
        batch.iter().map(|&i| f(points[i as usize])).collect()
    })
}

/// `batch(indices)` for consecutive runs of `size` point indices along a Morton curve,
/// in parallel; its results (one per index) come back in the input order.
fn in_morton_batches<T: Send + Copy>(
    points: &[DVec3],
    size: usize,
    batch: impl Fn(&[u32]) -> Vec<T> + Send + Sync,
) -> Vec<T> {
    let order = morton_order(points);
    let found: Vec<T> = order.par_chunks(size).flat_map_iter(&batch).collect();
    // The answer to point `i` is `found[rank[i]]`.
    let mut rank = vec![0u32; points.len()];
    for (k, &i) in order.iter().enumerate() {
        rank[i as usize] = k as u32;
    }
    rank.into_iter().map(|k| found[k as usize]).collect()
}

/// The smooth distance at every point (value only: the cheaper traversal).
pub fn values(object: &TraceObject, points: &[DVec3]) -> Vec<f64> {
    let sets = object.set_refs();
    in_morton_order(points, |x| eval::evaluate_value(&sets, x, &object.params).s)
}

/// The smooth distance at every point with a certified interval around the exact value:
/// `(lower, upper)`, `lower` the value of [`values`] (the Barnes-Hut sum is a lower bound)
/// and `upper` from the same walk with every far-field subtree at its lower bound (its
/// farthest corner, weight 1; pruned ones at zero: `eval::smooth`, `s_upper`). Point
/// clouds' far terms are then the closest box's rather than their moments, so `lower`
/// may be below [`values`]' there.
pub fn value_bounds(object: &TraceObject, points: &[DVec3]) -> (Vec<f64>, Vec<f64>) {
    let sets = object.set_refs();
    let mut p = object.params;
    p.upper_bound = true;
    let both = in_morton_order(points, |x| {
        let r = eval::evaluate_value(&sets, x, &p);
        (r.s, r.s_upper)
    });
    both.into_iter().unzip()
}

/// The smooth distance and its gradient at every point; gradients as a flat `(n, 3)`
/// array.
pub fn values_and_gradients(object: &TraceObject, points: &[DVec3]) -> (Vec<f64>, Vec<f64>) {
    let sets = object.set_refs();
    let both = in_morton_order(points, |x| {
        let r = eval::evaluate(&sets, x, &object.params);
        (r.s, r.grad)
    });
    let s = both.iter().map(|b| b.0).collect();
    let g = both.iter().flat_map(|b| b.1.to_array()).collect();
    (s, g)
}

/// The exact nearest primitive to every point. The points are taken along a Morton curve
/// in batches, each query starting from the previous one's nearest primitive
/// (`eval::nearest`); the answers come back in the input order.
pub fn nearest(object: &TraceObject, points: &[DVec3]) -> Vec<Nearest> {
    let sets = object.set_refs();
    in_morton_batches(points, BATCH, |batch| {
        let mut stack = Vec::new();
        let mut hint: Option<Nearest> = None;
        batch
            .iter()
            .map(|&i| {
                let x = points[i as usize];
                let n = match &hint {
                    Some(h) => eval::nearest::nearest_from(&sets, x, h, &mut stack),
                    None => eval::nearest(&sets, x),
                };
                hint = Some(n);
                n
            })
            .collect()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::brute;

    fn square() -> Mesh {
        let v = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0];
        super::super::arrays::mesh_from_arrays(&v, &[0, 1, 2, 0, 2, 3], &[], ["V", "F", "E"])
            .unwrap()
    }

    /// One primitive kind at `alpha_rel` and `beta`, the default tolerance.
    fn spec_rel(kind: PrimitiveKind, alpha_rel: f64, beta: f64) -> ObjectSpec {
        ObjectSpec::relative(vec![kind], alpha_rel, beta)
    }

    /// A stream of uniform numbers in [0, 1) from `seed` (a linear congruential generator).
    fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// `n` separate triangles at random places in the unit cube, their vertices within
    /// `size / 2` of a random centre each.
    fn soup(n: u32, size: f64, rnd: &mut impl FnMut() -> f64) -> Mesh {
        let mut v = Vec::new();
        let mut f = Vec::new();
        for t in 0..n as i64 {
            let c = [rnd(), rnd(), rnd()];
            for _ in 0..3 {
                v.extend(c.iter().map(|&a| a + size * (rnd() - 0.5)));
            }
            f.extend([3 * t, 3 * t + 1, 3 * t + 2]);
        }
        super::super::arrays::mesh_from_arrays(&v, &f, &[], ["V", "F", "E"]).unwrap()
    }

    #[test]
    fn batch_values_match_single_queries_and_brute_force() {
        let mesh = square();
        let spec = spec_rel(PrimitiveKind::Triangles, 20.0, 0.0);
        let obj = build_object(&mesh, &spec, Naming::Keyword).unwrap();
        assert_eq!(obj.params.alpha, 20.0 / 2f64.sqrt());
        let pts: Vec<DVec3> = (0..50)
            .map(|i| DVec3::new(0.03 * i as f64 - 0.2, 0.5, 0.1 + 0.01 * i as f64))
            .collect();
        let (s, g) = values_and_gradients(&obj, &pts);
        let v = values(&obj, &pts);
        let sets = obj.set_refs();
        for (i, &x) in pts.iter().enumerate() {
            let (bs, bg, _) =
                brute::smooth_distance(&sets, x, obj.params.alpha, obj.params.max_alpha);
            assert!(
                (s[i] - bs).abs() <= 1e-9 * bs.abs().max(1e-3),
                "{} vs {bs}",
                s[i]
            );
            assert!((v[i] - s[i]).abs() <= 1e-12 * s[i].abs().max(1e-3));
            let gr = DVec3::from_slice(&g[3 * i..3 * i + 3]);
            assert!((gr - bg).length() < 1e-6, "{gr} vs {bg}");
        }
        let n = nearest(&obj, &pts);
        for (i, &x) in pts.iter().enumerate() {
            // Distance to the unit square in the z = 0 plane.
            let dx = (-x.x).max(x.x - 1.0).max(0.0);
            let d = (dx * dx + x.z * x.z).sqrt();
            assert!((n[i].d - d).abs() < 1e-6, "{} vs {d}", n[i].d);
            assert!((n[i].point - x).length() - n[i].d < 1e-9);
        }
    }

    /// `value_bounds` brackets the exact (brute-force) value on triangles, edges and
    /// points at soft and stiff alphas and several betas, its lower end is `values`' on
    /// meshes, and the interval closes as beta goes to 0.
    #[test]
    fn value_bounds_bracket_the_exact_value() {
        let mut rnd = uniform(11);
        let mesh = soup(120, 0.2, &mut rnd);
        let pts: Vec<DVec3> = (0..150)
            .map(|_| DVec3::new(rnd(), rnd(), rnd()) * 1.4 - 0.2)
            .collect();
        for kind in [
            PrimitiveKind::Triangles,
            PrimitiveKind::Edges,
            PrimitiveKind::Points,
        ] {
            for alpha_rel in [10.0, 100.0, 1000.0] {
                let mut widths = Vec::new();
                for beta in [0.0, 0.5, 1.0] {
                    let spec = spec_rel(kind, alpha_rel, beta);
                    let obj = build_object(&mesh, &spec, Naming::Keyword).unwrap();
                    let (lo, hi) = value_bounds(&obj, &pts);
                    let v = values(&obj, &pts);
                    let sets = obj.set_refs();
                    let mut width: f64 = 0.0;
                    for (i, &x) in pts.iter().enumerate() {
                        let exact = brute::smooth_distance(
                            &sets,
                            x,
                            obj.params.alpha,
                            obj.params.max_alpha,
                        )
                        .0;
                        let slack = 1e-9 * exact.abs().max(1e-3);
                        let at = format!("{kind:?} alpha_rel {alpha_rel} beta {beta} at {x}");
                        assert!(lo[i] <= exact + slack, "{at}: lower {} > {exact}", lo[i]);
                        assert!(hi[i] >= exact - slack, "{at}: upper {} < {exact}", hi[i]);
                        assert!(v[i] <= exact + slack, "{at}: value {} > {exact}", v[i]);
                        if kind != PrimitiveKind::Points {
                            assert_eq!(lo[i], v[i], "{at}");
                        }
                        width = width.max(hi[i] - lo[i]);
                    }
                    widths.push(width * obj.params.alpha);
                }
                // Exact at beta 0 up to the pruning (a share 1e-10 of the sum), and
                // wider at a coarser beta, beyond what pruning alone moves (where no
                // far term is taken, as on stiff edges, whose leaves hold eight, the
                // widths are pruning's at every beta).
                assert!(widths[0] < 1e-8, "{kind:?} {alpha_rel}: {widths:?}");
                assert!(
                    widths[2] + 1e-8 >= widths[1],
                    "{kind:?} {alpha_rel}: {widths:?}"
                );
            }
        }
    }

    #[test]
    fn batch_nearest_matches_brute_force_on_a_soup_in_any_order() {
        // 200 random triangles (their edges and vertices too), queries near and far
        // given in random order: the Morton batches and their hints change nothing.
        let mut rnd = uniform(17);
        let mesh = soup(200, 0.1, &mut rnd);
        let pts: Vec<DVec3> = (0..3000)
            .map(|i| {
                let s = if i % 3 == 0 { 3.0 } else { 1.2 };
                DVec3::new(rnd(), rnd(), rnd()) * s - 0.1 * s
            })
            .collect();
        for kinds in [
            vec![PrimitiveKind::Triangles],
            vec![PrimitiveKind::Edges, PrimitiveKind::Points],
        ] {
            let spec = ObjectSpec {
                kinds,
                alpha: Some(10.0),
                alpha_rel: None,
                max_alpha: None,
                max_alpha_rel: None,
                beta: 0.5,
                tolerance: None,
            };
            let obj = build_object(&mesh, &spec, Naming::Keyword).unwrap();
            let sets = obj.set_refs();
            let n = nearest(&obj, &pts);
            for (i, &x) in pts.iter().enumerate() {
                let d = brute::min_distance(&sets, x);
                assert!(
                    (n[i].d - d).abs() <= 1e-12 * d.max(1.0),
                    "{i}: {} vs {d}",
                    n[i].d
                );
                assert!(((n[i].point - x).length() - n[i].d).abs() <= 1e-12);
                // Ties (a vertex shared by edges) may name another primitive.
                assert_eq!(n[i].d, eval::nearest(&sets, x).d);
            }
        }
    }

    #[test]
    fn a_tolerance_bounds_what_pruning_takes() {
        // A soup of 300 small triangles in the unit cube, queries near and inside it.
        let mut rnd = uniform(29);
        let mesh = soup(300, 0.05, &mut rnd);
        let pts: Vec<DVec3> = (0..400)
            .map(|_| DVec3::new(rnd(), rnd(), rnd()) * 1.2 - 0.1)
            .collect();
        let spec = |alpha: f64, beta: f64, tolerance: Option<f64>| ObjectSpec {
            kinds: vec![PrimitiveKind::Triangles],
            alpha: Some(alpha),
            alpha_rel: None,
            max_alpha: None,
            max_alpha_rel: None,
            beta,
            tolerance,
        };
        for alpha in [20.0, 200.0] {
            // No pruning at beta 0: the exact sum.
            let exact = build_object(&mesh, &spec(alpha, 0.0, Some(0.0)), Naming::Keyword).unwrap();
            assert!(!exact.params.prune);
            let s0 = values(&exact, &pts);
            let sets = exact.set_refs();
            for (i, &x) in pts.iter().enumerate() {
                let (bs, _, _) = brute::smooth_distance(&sets, x, alpha, alpha);
                assert!(
                    (s0[i] - bs).abs() <= 1e-12 * bs.abs().max(1.0),
                    "{} vs {bs}",
                    s0[i]
                );
            }
            for beta in [0.0, 0.5] {
                let unpruned = values(
                    &build_object(&mesh, &spec(alpha, beta, Some(0.0)), Naming::Keyword).unwrap(),
                    &pts,
                );
                for tolerance in [1e-6, 1e-4, 1e-2] {
                    let obj =
                        build_object(&mesh, &spec(alpha, beta, Some(tolerance)), Naming::Keyword)
                            .unwrap();
                    let s = values(&obj, &pts);
                    // Where the share is not capped, pruning takes most of what it may
                    // (93-96% here): the bound is the tolerance, not a multiple of it.
                    let most = (0..pts.len())
                        .map(|i| unpruned[i] - s[i])
                        .fold(0.0, f64::max);
                    if 0.5 * alpha * tolerance < crate::eval::params::MAX_PRUNE_TOLERANCE {
                        assert!(
                            most >= 0.5 * tolerance,
                            "alpha {alpha} beta {beta} tol {tolerance}: {most}"
                        );
                    }
                    for i in 0..pts.len() {
                        // Below the unpruned sum (a lower bound still), by at most the tolerance.
                        let (a, b) = (s[i], unpruned[i]);
                        let round = 1e-12 * b.abs().max(1.0);
                        assert!(
                            a <= b + round,
                            "alpha {alpha} beta {beta} tol {tolerance}: {a} > {b}"
                        );
                        assert!(
                            b - a <= tolerance + round,
                            "alpha {alpha} beta {beta} tol {tolerance}: {a} vs {b}"
                        );
                    }
                }
            }
        }
        for bad in [-1e-3, f64::NAN, f64::INFINITY] {
            let e = build_object(&mesh, &spec(1.0, 0.5, Some(bad)), Naming::Flag)
                .err()
                .unwrap();
            assert!(
                e.to_string()
                    .starts_with("--tolerance must be a length >= 0"),
                "{e}"
            );
        }
    }

    #[test]
    fn missing_alpha_and_empty_kinds_are_named() {
        let mesh = square();
        let mut spec = ObjectSpec {
            kinds: vec![],
            alpha: Some(1.0),
            alpha_rel: None,
            max_alpha: None,
            max_alpha_rel: None,
            beta: 0.5,
            tolerance: None,
        };
        let e = build_object(&mesh, &spec, Naming::Keyword).err().unwrap();
        assert!(e.to_string().starts_with("primitives is empty"), "{e}");
        spec.kinds = vec![PrimitiveKind::Points];
        spec.alpha = None;
        let e = build_object(&mesh, &spec, Naming::Flag).err().unwrap();
        assert_eq!(e.to_string(), "give --alpha or --alpha-rel");
    }
}
