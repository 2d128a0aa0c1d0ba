//! A leaf's edges, four at a time: `Edge::term` and `Edge::value` (SPEC 3, 4) computed
//! in the four lanes of AVX registers (`avx`: the lane types; `edges`: the kernels), with
//! the same arithmetic in the same order as the scalar code, so every result is the same
//! to the last bit (the test below compares the bits) and so is every image.
//!
//! The scalar closest point on a segment (`geometry::closest::closest_on_segment`)
//! branches on where the query projects (before, past or inside the edge), which near a
//! soft surface changes from one edge to the next, and each scalar term divides three
//! times in a row (the two valences' reciprocals, then the projection); here the lanes
//! compute every case and keep the first that holds, in the scalar code's order, and four
//! terms share each division. The weight's quartic is the scalar one (`weights::edge_w`,
//! generic over `weights::Real`). Without AVX (detected once per process), off x86-64, or
//! with [`SCALAR_ENV`] set, the scalar path does everything. The evaluator calls these
//! for a leaf's primitives (`eval::sink`, `Primitive::BATCHED`). What they bought, and
//! why triangles are not among them: doc/performance-log.md, round twenty.

use super::kinds::{Edge, Primitive, Term};
use super::weights::WeightScale;
use glam::DVec3;

#[cfg(target_arch = "x86_64")]
mod avx;
#[cfg(target_arch = "x86_64")]
mod edges;

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
