//! A traceable object (primitive sets plus evaluation parameters) built from a mesh, and
//! batch queries over many points: the smooth distance (SPEC 2, 6), its gradient, and
//! the exact nearest primitive, evaluated in parallel in the current rayon pool.

use super::InputError;
use super::params::{Naming, check_beta, resolve_alpha};
use crate::eval::{self, EvalParams, Nearest};
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
    Ok(TraceObject::new(
        sets,
        EvalParams::new(alpha, max_alpha, beta),
    ))
}

/// The smooth distance at every point (value only: the cheaper traversal).
pub fn values(object: &TraceObject, points: &[DVec3]) -> Vec<f64> {
    let sets = object.set_refs();
    points
        .par_iter()
        .map(|&x| eval::evaluate_value(&sets, x, &object.params).s)
        .collect()
}

/// The smooth distance and its gradient at every point; gradients as a flat `(n, 3)`
/// array.
pub fn values_and_gradients(object: &TraceObject, points: &[DVec3]) -> (Vec<f64>, Vec<f64>) {
    let sets = object.set_refs();
    let mut s = vec![0.0; points.len()];
    let mut g = vec![0.0; 3 * points.len()];
    s.par_iter_mut()
        .zip(g.par_chunks_mut(3))
        .zip(points.par_iter())
        .for_each(|((s, g), &x)| {
            let r = eval::evaluate(&sets, x, &object.params);
            *s = r.s;
            g.copy_from_slice(&r.grad.to_array());
        });
    (s, g)
}

/// The exact nearest primitive to every point.
pub fn nearest(object: &TraceObject, points: &[DVec3]) -> Vec<Nearest> {
    let sets = object.set_refs();
    points
        .par_iter()
        .map(|&x| eval::nearest(&sets, x))
        .collect()
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

    #[test]
    fn batch_values_match_single_queries_and_brute_force() {
        let mesh = square();
        let spec = ObjectSpec {
            kinds: vec![PrimitiveKind::Triangles],
            alpha: None,
            alpha_rel: Some(20.0),
            max_alpha: None,
            max_alpha_rel: None,
            beta: 0.0,
        };
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
        };
        let e = build_object(&mesh, &spec, Naming::Keyword).err().unwrap();
        assert!(e.to_string().starts_with("primitives is empty"), "{e}");
        spec.kinds = vec![PrimitiveKind::Points];
        spec.alpha = None;
        let e = build_object(&mesh, &spec, Naming::Flag).err().unwrap();
        assert_eq!(e.to_string(), "give --alpha or --alpha-rel");
    }
}
