//! A leaf's triangles or edges, four at a time: the terms of `primitives::kinds` (SPEC
//! 3, 4) computed in the four lanes of AVX registers (`avx`: the lane types), with the
//! same arithmetic in the same order as the scalar code, so every result is the same to
//! the last bit (the tests below compare the bits) and so is every image.
//!
//! The scalar closest points (`geometry::closest`: Ericson's Voronoi regions on a
//! triangle, the two ends and the inside of a segment) branch on the region, which near a
//! soft surface changes from one primitive to the next and costs the processor a
//! misprediction per term; here every lane computes the tests and candidates of all
//! regions and keeps the first that holds, in the scalar code's order (`triangles`,
//! `edges`). The weight polynomials, their derivatives, the barycentric gradients and
//! the attenuation follow the scalar formulas lane by lane; each lane divides only by
//! what its own region needs. Degenerate triangles and faces whose solve is not finite
//! take the scalar path. Without AVX (detected once per process), off x86-64, or with
//! [`SCALAR_ENV`] set, the scalar path does everything. The evaluator calls these for a
//! leaf's primitives (`eval::sink`, `Primitive::BATCHED`). What they bought:
//! doc/performance-log.md, round twenty.

use super::kinds::{Edge, Primitive, Slope, Term, Triangle};
use super::weights::WeightScale;
use glam::DVec3;

#[cfg(target_arch = "x86_64")]
mod avx;
#[cfg(target_arch = "x86_64")]
mod edges;
#[cfg(target_arch = "x86_64")]
mod triangles;

/// Setting this environment variable (to anything) keeps every term on the scalar
/// path: for profilers that cannot decode AVX (valgrind 3.19), and for comparisons.
pub const SCALAR_ENV: &str = "SMOOTHTRACE_SCALAR_TERMS";

/// True when the lanes run on AVX here (checked once per process).
pub fn available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        static AVX: std::sync::LazyLock<bool> = std::sync::LazyLock::new(|| {
            std::arch::is_x86_feature_detected!("avx") && std::env::var_os(SCALAR_ENV).is_none()
        });
        *AVX
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// `Primitive::term` of 1 ..= 4 triangles into `out[..tris.len()]`.
#[inline]
pub fn triangle_terms(tris: &[Triangle], x: DVec3, scale: &WeightScale, out: &mut [Term; 4]) {
    #[cfg(target_arch = "x86_64")]
    if available() {
        // SAFETY: AVX was detected.
        unsafe { triangles::terms(tris, x, scale, out) };
        return;
    }
    for (o, t) in out.iter_mut().zip(tris) {
        *o = t.term(x, scale);
    }
}

/// `Primitive::value` of 1 ..= 4 triangles into `out[..tris.len()]`.
#[inline]
pub fn triangle_values(
    tris: &[Triangle],
    x: DVec3,
    scale: &WeightScale,
    out: &mut [(f64, f64); 4],
) {
    #[cfg(target_arch = "x86_64")]
    if available() {
        // SAFETY: AVX was detected.
        unsafe { triangles::values(tris, x, scale, out) };
        return;
    }
    for (o, t) in out.iter_mut().zip(tris) {
        *o = t.value(x, scale);
    }
}

/// `Primitive::value_slope` of 1 ..= 4 triangles into `out[..tris.len()]`.
#[inline]
pub fn triangle_value_slopes(
    tris: &[Triangle],
    x: DVec3,
    u: DVec3,
    scale: &WeightScale,
    out: &mut [Slope; 4],
) {
    #[cfg(target_arch = "x86_64")]
    if available() {
        // SAFETY: AVX was detected.
        unsafe { triangles::value_slopes(tris, x, u, scale, out) };
        return;
    }
    for (o, t) in out.iter_mut().zip(tris) {
        *o = t.value_slope(x, u, scale);
    }
}

/// `Primitive::term` of 1 ..= 4 edges into `out[..edges.len()]`.
#[inline]
pub fn edge_terms(edges: &[Edge], x: DVec3, scale: &WeightScale, out: &mut [Term; 4]) {
    #[cfg(target_arch = "x86_64")]
    if available() {
        // SAFETY: AVX was detected.
        unsafe { edges::terms(edges, x, scale, out) };
        return;
    }
    for (o, e) in out.iter_mut().zip(edges) {
        *o = e.term(x, scale);
    }
}

/// `Primitive::value` of 1 ..= 4 edges into `out[..edges.len()]`.
#[inline]
pub fn edge_values(edges: &[Edge], x: DVec3, scale: &WeightScale, out: &mut [(f64, f64); 4]) {
    #[cfg(target_arch = "x86_64")]
    if available() {
        // SAFETY: AVX was detected.
        unsafe { edges::values(edges, x, scale, out) };
        return;
    }
    for (o, e) in out.iter_mut().zip(edges) {
        *o = e.value(x, scale);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// Every output of the lanes equals the scalar term's to the last bit: random
    /// triangles (skinny, collinear, coincident, untabulated valences among them), query
    /// points near and far, on the plane and on the vertices, every attenuation branch
    /// (`q` 1, 0.5 and other), leaves of 1 to 4 triangles. Every region is met.
    #[test]
    fn lanes_equal_the_scalar_terms_bit_for_bit() {
        if !available() {
            eprintln!("AVX not available here: the lanes fall back to the scalar terms");
        }
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut r = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut features = std::collections::HashSet::new();
        for (i, scale) in [
            WeightScale::new(11.0, 100.0, 200.0),
            WeightScale::new(7.0, 300.0, 200.0),
            WeightScale::new(40.0, 37.0, 100.0),
        ]
        .into_iter()
        .cycle()
        .take(600)
        .enumerate()
        {
            let n = 1 + i % 4;
            let tris: Vec<Triangle> = (0..n)
                .map(|j| {
                    let mut v = || Vec3::new(r() as f32, r() as f32, r() as f32);
                    let (a, mut b, mut c) = (v(), v(), v());
                    match (i + j) % 7 {
                        0 => c = a + 2.0 * (b - a),              // collinear
                        1 => b = a,                              // coincident
                        2 => c = b + (b - a) * 1e3,              // long and thin
                        3 => c = a + (b - a) * 0.5 + v() * 1e-4, // nearly collinear
                        _ => {}
                    }
                    let (vmax, emax) = match j % 3 {
                        0 => (6.0, 2.0),
                        1 => (40.0, 12.0),
                        _ => (1.0, 1.0),
                    };
                    Triangle::new(a, b, c, vmax, emax)
                })
                .collect();
            for q in 0..12 {
                let t0 = &tris[0];
                let x = match q {
                    0 => t0.a.as_dvec3(),
                    1 => ((t0.a + t0.b + t0.c) / 3.0).as_dvec3(),
                    2 => (t0.b * 0.3 + t0.c * 0.7).as_dvec3(),
                    3..=7 => DVec3::new(r(), r(), r()) * 0.5,
                    _ => DVec3::new(r(), r(), r()) * 8.0,
                };
                let u = DVec3::new(r(), r(), r()).normalize();
                let mut terms = [Term::default(); 4];
                let mut values = [(0.0, 0.0); 4];
                let mut slopes = [(0.0, 0.0, 0.0, 0.0); 4];
                triangle_terms(&tris, x, &scale, &mut terms);
                triangle_values(&tris, x, &scale, &mut values);
                triangle_value_slopes(&tris, x, u, &scale, &mut slopes);
                for (l, tri) in tris.iter().enumerate() {
                    let (want, got) = (tri.term(x, &scale), terms[l]);
                    let bits = |t: &Term| {
                        [
                            t.d, t.dir.x, t.dir.y, t.dir.z, t.w, t.grad_w.x, t.grad_w.y, t.grad_w.z,
                        ]
                        .map(f64::to_bits)
                    };
                    assert_eq!(bits(&got), bits(&want), "term, triangle {i}.{l} at {x}");
                    let (d, w) = tri.value(x, &scale);
                    assert_eq!(
                        [values[l].0, values[l].1].map(f64::to_bits),
                        [d, w].map(f64::to_bits),
                        "value, triangle {i}.{l} at {x}"
                    );
                    let s = tri.value_slope(x, u, &scale);
                    assert_eq!(
                        [slopes[l].0, slopes[l].1, slopes[l].2, slopes[l].3].map(f64::to_bits),
                        [s.0, s.1, s.2, s.3].map(f64::to_bits),
                        "value_slope, triangle {i}.{l} at {x}"
                    );
                    let (a, b, c) = (tri.a.as_dvec3(), tri.b.as_dvec3(), tri.c.as_dvec3());
                    features.insert(format!(
                        "{:?}",
                        crate::geometry::closest::closest_on_triangle(x, a, b, c).feature
                    ));
                }
            }
        }
        assert_eq!(features.len(), 8, "regions met: {features:?}");
    }

    /// The edges' lanes equal their scalar terms to the last bit: empty, short and long
    /// edges, queries before, past and beside them, valences 1 to 12, every attenuation
    /// branch, leaves of 1 to 4 edges.
    #[test]
    fn edge_lanes_equal_the_scalar_terms_bit_for_bit() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut r = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let (mut ends, mut inside) = (0, 0);
        for (i, scale) in [
            WeightScale::new(11.0, 100.0, 200.0),
            WeightScale::new(7.0, 300.0, 200.0),
            WeightScale::new(40.0, 37.0, 100.0),
        ]
        .into_iter()
        .cycle()
        .take(600)
        .enumerate()
        {
            let edges: Vec<Edge> = (0..1 + i % 4)
                .map(|j| {
                    let mut v = || Vec3::new(r() as f32, r() as f32, r() as f32);
                    let a = v();
                    let b = if (i + j) % 9 == 0 { a } else { v() };
                    let val = |k: usize| (1 + (i * 7 + j * 3 + k) % 12) as f32;
                    Edge {
                        a,
                        b,
                        val_a: val(0),
                        val_b: val(1),
                    }
                })
                .collect();
            for q in 0..8 {
                let e0 = &edges[0];
                let x = match q {
                    0 => e0.a.as_dvec3(),
                    1 => (0.5 * (e0.a + e0.b)).as_dvec3(),
                    _ => DVec3::new(r(), r(), r()) * (q as f64),
                };
                let u = DVec3::new(r(), r(), r()).normalize();
                let mut terms = [Term::default(); 4];
                let mut values = [(0.0, 0.0); 4];
                let mut slopes = [(0.0, 0.0, 0.0, 0.0); 4];
                edge_terms(&edges, x, &scale, &mut terms);
                edge_values(&edges, x, &scale, &mut values);
                Edge::value_slopes(&edges, x, u, &scale, &mut slopes);
                for (l, e) in edges.iter().enumerate() {
                    let (want, got) = (e.term(x, &scale), terms[l]);
                    let bits = |t: &Term| {
                        [
                            t.d, t.dir.x, t.dir.y, t.dir.z, t.w, t.grad_w.x, t.grad_w.y, t.grad_w.z,
                        ]
                        .map(f64::to_bits)
                    };
                    assert_eq!(bits(&got), bits(&want), "term, edge {i}.{l} at {x}");
                    let (d, w) = e.value(x, &scale);
                    assert_eq!(
                        [values[l].0, values[l].1].map(f64::to_bits),
                        [d, w].map(f64::to_bits),
                        "value, edge {i}.{l} at {x}"
                    );
                    let s = e.value_slope(x, u, &scale);
                    assert_eq!(
                        [slopes[l].0, slopes[l].1, slopes[l].2, slopes[l].3].map(f64::to_bits),
                        [s.0, s.1, s.2, s.3].map(f64::to_bits),
                        "value_slope, edge {i}.{l} at {x}"
                    );
                    let c = crate::geometry::closest::closest_on_segment(
                        x,
                        e.a.as_dvec3(),
                        e.b.as_dvec3(),
                    );
                    if c.interior {
                        inside += 1;
                    } else {
                        ends += 1;
                    }
                }
            }
        }
        assert!(ends > 500 && inside > 500, "ends {ends}, inside {inside}");
    }
}
