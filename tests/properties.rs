//! Property tests (proptest) of the invariants on random small inputs.

use glam::{DVec3, Vec3};
use proptest::prelude::*;
use smoothtrace::eval::{self, EvalParams, brute};
use smoothtrace::geometry::closest::closest_on_triangle;
use smoothtrace::mesh::Mesh;
use smoothtrace::primitives::{AnySet, PrimitiveKind};

fn v3() -> impl Strategy<Value = [f32; 3]> {
    [-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0]
}

fn soup() -> impl Strategy<Value = Mesh> {
    prop::collection::vec((v3(), v3(), v3()), 1..12).prop_map(|tris| {
        let mut m = Mesh {
            name: "soup".into(),
            ..Default::default()
        };
        for (a, b, c) in tris {
            let n = m.vertices.len() as u32;
            m.vertices
                .extend([Vec3::from(a), Vec3::from(b), Vec3::from(c)]);
            m.triangles.push([n, n + 1, n + 2]);
            m.segments.push([n, n + 1]);
        }
        m
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The closest point lies on the triangle and is no farther than any vertex or a
    /// sample of the triangle.
    #[test]
    fn closest_point_is_closest(a in v3(), b in v3(), c in v3(), x in v3(), s in 0.0f64..1.0, t in 0.0f64..1.0) {
        let (a, b, c, x) = (Vec3::from(a).as_dvec3(), Vec3::from(b).as_dvec3(), Vec3::from(c).as_dvec3(), Vec3::from(x).as_dvec3() * 2.0);
        let r = closest_on_triangle(x, a, b, c);
        let d = (x - r.point).length();
        prop_assert!(r.s >= -1e-12 && r.t >= -1e-12 && r.s + r.t <= 1.0 + 1e-12);
        let (s, t) = if s + t > 1.0 { (1.0 - s, 1.0 - t) } else { (s, t) };
        let sample = a + s * (b - a) + t * (c - a);
        for p in [a, b, c, sample] {
            prop_assert!(d <= (x - p).length() + 1e-12);
        }
    }

    /// Conservative and Barnes-Hut bounded by the exact sum, for every primitive type.
    #[test]
    fn smooth_distance_is_conservative(mesh in soup(), x in v3(), alpha in 0.5f64..500.0, beta in 0.0f64..1.0) {
        let x = Vec3::from(x).as_dvec3() * 1.5;
        for kind in [PrimitiveKind::Points, PrimitiveKind::Edges, PrimitiveKind::Triangles] {
            let set = AnySet::build(&mesh, kind).unwrap();
            let exact = eval::evaluate(&[&set], x, &EvalParams::new(alpha, alpha, 0.0));
            let approx = eval::evaluate(&[&set], x, &EvalParams::new(alpha, alpha, beta));
            let dmin = brute::min_distance(&[&set], x);
            prop_assert!(exact.s.is_finite() && exact.grad.is_finite());
            prop_assert!(exact.s <= dmin * (1.0 + 1e-12) + 1e-300, "{} > {}", exact.s, dmin);
            let (s, _, _) = brute::smooth_distance(&[&set], x, alpha, alpha);
            let rounding = 1e-12 * s.abs().max(1.0 / alpha);
            prop_assert!(approx.s <= s + rounding, "Barnes-Hut {} above exact {}", approx.s, s);
            prop_assert!(exact.s <= s + rounding, "beta 0 {} above exact {}", exact.s, s);
            prop_assert!((exact.s - s).abs() <= 1e-9 * s.abs().max(1.0 / alpha));
        }
    }
}

#[test]
fn empty_direction_on_the_primitive_is_zero_not_nan() {
    let m = Mesh {
        vertices: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        triangles: vec![[0, 1, 2]],
        name: "tri".into(),
        ..Default::default()
    };
    let set = AnySet::build(&m, PrimitiveKind::Triangles).unwrap();
    let s = eval::evaluate(
        &[&set],
        DVec3::new(0.2, 0.2, 0.0),
        &EvalParams::new(10.0, 10.0, 0.0),
    );
    assert!(s.s.is_finite() && s.grad.is_finite());
}
