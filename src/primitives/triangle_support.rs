//! The weighted support of a triangle (the triangles' counterpart of `support`): for a
//! direction `g` and sharpness `alpha`, an upper bound of `max over p of alpha g . p + ln
//! w(p)` over the triangle's points `p`, `w(p)` the weight the triangle gives a query
//! whose closest point is `p` (SPEC 4, 5). `primitives::directional` sums it into far-field
//! tables (doc/performance-log.md, rounds twenty-eight and twenty-nine).
//!
//! Certain, not sampled: the triangle's barycentric domain `(s, t)` is cut into
//! `SIDE^2` sub-triangles of a regular lattice. On each, the degree-7 weight `W(s, t)` is
//! at most its largest Bernstein-Bezier coefficient over that sub-triangle (the Bernstein
//! basis is nonnegative and sums to 1). The coefficient of index `(i, j, k)` is the
//! polynomial's blossom at the sub-triangle's corners taken `i`, `j` and `k` times; the
//! blossom of `s^a t^b` in degree `n` averages, over the ways to give `a` of the `n`
//! arguments to `s` and `b` others to `t`, the product of those coordinates. The linear
//! part `alpha g . p` is largest at one of a sub-triangle's corners, so the support is at
//! most the largest over lattice points `q` of `alpha g . p(q) + LW(q)`, `LW(q)` the
//! largest log-weight bound of the sub-triangles that have `q` as a corner.

use super::kinds::Triangle;
use super::weights::{WeightScale, triangle_coefficients};
use glam::DVec3;

/// Lattice steps per side of the barycentric triangle (`SIDE^2` sub-triangles).
pub const SIDE: usize = 8;

/// Lattice points: `(SIDE + 1)(SIDE + 2) / 2`.
const POINTS: usize = (SIDE + 1) * (SIDE + 2) / 2;

/// The weight's degree (SPEC 4).
const DEGREE: usize = 7;

/// Bernstein coefficients per sub-triangle: `(DEGREE + 1)(DEGREE + 2) / 2`.
const COEFFICIENTS: usize = (DEGREE + 1) * (DEGREE + 2) / 2;

/// The monomials `s^a t^b` of each of the weight's 13 coefficients (the basis of SPEC 4,
/// as `weights::triangle_w_value` sums it).
const GROUPS: [&[(usize, usize)]; 13] = [
    &[(0, 0)],
    &[(2, 0), (0, 2)],
    &[(3, 0), (0, 3)],
    &[(4, 0), (0, 4)],
    &[(2, 2)],
    &[(5, 0), (0, 5)],
    &[(2, 3), (3, 2)],
    &[(6, 0), (0, 6)],
    &[(2, 4), (4, 2)],
    &[(3, 3)],
    &[(7, 0), (0, 7)],
    &[(2, 5), (5, 2)],
    &[(3, 4), (4, 3)],
];

/// The lattice point `(i, j)` (`s = i / SIDE`, `t = j / SIDE`, `i + j <= SIDE`) as an index.
fn point(i: usize, j: usize) -> usize {
    // Rows of constant `j` hold `SIDE + 1 - j` points.
    j * (SIDE + 1) - j * (j.saturating_sub(1)) / 2 + i
}

/// The sub-triangles, as their three lattice corners `(i, j)`.
fn sub_triangles() -> Vec<[(usize, usize); 3]> {
    let mut subs = Vec::new();
    for j in 0..SIDE {
        for i in 0..SIDE - j {
            subs.push([(i, j), (i + 1, j), (i, j + 1)]);
            if i + j + 2 <= SIDE {
                subs.push([(i + 1, j), (i, j + 1), (i + 1, j + 1)]);
            }
        }
    }
    subs
}

fn binomial(n: usize, k: usize) -> f64 {
    if k > n {
        return 0.0;
    }
    (0..k).fold(1.0, |c, m| c * (n - m) as f64 / (m + 1) as f64)
}

/// `binomial(n, k)` for `n, k <= DEGREE`, and each corner's coordinates' powers up to
/// `DEGREE` (`powi`): what [`blossom`] multiplies, looked up instead of recomputed in its
/// innermost loop (the same values, so the same sums).
struct BlossomParts {
    binomial: [[f64; DEGREE + 1]; DEGREE + 1],
    /// Per corner: `(s^k, t^k)`.
    powers: [[(f64, f64); DEGREE + 1]; 3],
}

impl BlossomParts {
    fn new(corners: &[(f64, f64); 3]) -> BlossomParts {
        BlossomParts {
            binomial: std::array::from_fn(|n| std::array::from_fn(|k| binomial(n, k))),
            powers: std::array::from_fn(|m| {
                let (s, t) = corners[m];
                std::array::from_fn(|k| (s.powi(k as i32), t.powi(k as i32)))
            }),
        }
    }
}

/// The blossom of `s^a t^b` in degree [`DEGREE`] at the points `corners` (their parts in
/// `parts`) taken `mult` times each (module docs).
fn blossom(a: usize, b: usize, parts: &BlossomParts, mult: [usize; 3]) -> f64 {
    let c = &parts.binomial;
    let p = &parts.powers;
    let mut sum = 0.0;
    // `a_m` of corner m's copies go to `s`, `b_m` of the rest to `t`.
    for a0 in 0..=a.min(mult[0]) {
        for a1 in 0..=(a - a0).min(mult[1]) {
            let a2 = a - a0 - a1;
            if a2 > mult[2] {
                continue;
            }
            for b0 in 0..=b.min(mult[0] - a0) {
                for b1 in 0..=(b - b0).min(mult[1] - a1) {
                    let b2 = b - b0 - b1;
                    if b2 > mult[2] - a2 {
                        continue;
                    }
                    let ways = c[mult[0]][a0]
                        * c[mult[0] - a0][b0]
                        * c[mult[1]][a1]
                        * c[mult[1] - a1][b1]
                        * c[mult[2]][a2]
                        * c[mult[2] - a2][b2];
                    sum += ways
                        * p[0][a0].0
                        * p[1][a1].0
                        * p[2][a2].0
                        * p[0][b0].1
                        * p[1][b1].1
                        * p[2][b2].1;
                }
            }
        }
    }
    sum / (c[DEGREE][a] * c[DEGREE - a][b])
}

/// The Bernstein indices `(i, j, k)`, `i + j + k = DEGREE`.
fn indices() -> impl Iterator<Item = [usize; 3]> {
    (0..=DEGREE).flat_map(|i| (0..=DEGREE - i).map(move |j| [i, j, DEGREE - i - j]))
}

/// Per sub-triangle and Bernstein index, the coefficient of each of the 13 groups
/// (the weight's Bernstein coefficient is their sum weighted by `k`); computed once.
fn bernstein_tables() -> &'static [[[f64; 13]; COEFFICIENTS]] {
    static TABLES: std::sync::OnceLock<Vec<[[f64; 13]; COEFFICIENTS]>> = std::sync::OnceLock::new();
    TABLES.get_or_init(|| {
        use rayon::prelude::*;
        let h = 1.0 / SIDE as f64;
        // Sub-triangles in parallel (each its own sums; about 90 M instructions in all).
        sub_triangles()
            .par_iter()
            .map(|sub| {
                let corners = sub.map(|(i, j)| (i as f64 * h, j as f64 * h));
                let parts = BlossomParts::new(&corners);
                let mut table = [[0.0; 13]; COEFFICIENTS];
                for (row, mult) in table.iter_mut().zip(indices()) {
                    for (g, monomials) in GROUPS.iter().enumerate() {
                        row[g] = monomials
                            .iter()
                            .map(|&(a, b)| blossom(a, b, &parts, mult))
                            .sum();
                    }
                }
                table
            })
            .collect()
    })
}

/// A triangle's weighted support for every triangle of one pair of valences: the
/// largest log-weight next to each lattice point (module docs).
#[derive(Clone, Debug)]
pub struct TriangleLattice {
    /// `(s, t, LW)` per lattice point.
    points: Vec<(f64, f64, f64)>,
}

impl TriangleLattice {
    /// The lattice of valences `vmax`, `emax` with weights by `scale`.
    pub fn new(vmax: f32, emax: f32, scale: &WeightScale) -> TriangleLattice {
        let k = triangle_coefficients(vmax as f64, emax as f64);
        let h = 1.0 / SIDE as f64;
        let mut lw = [f64::NEG_INFINITY; POINTS];
        for (sub, table) in sub_triangles().iter().zip(bernstein_tables()) {
            let (top, size) = table.iter().fold((f64::NEG_INFINITY, 0.0f64), |(m, z), c| {
                let v: f64 = c.iter().zip(&k).map(|(c, k)| c * k).sum();
                let size: f64 = c.iter().zip(&k).map(|(c, k)| (c * k).abs()).sum();
                (m.max(v), z.max(size))
            });
            // The sums' rounding, relative to their terms' size, then the weight's.
            let raw = top + 1e-12 * (size + 1.0);
            let l = scale.weight(raw).ln() * (1.0 + 1e-12) + 1e-15;
            for &(i, j) in sub {
                let p = &mut lw[point(i, j)];
                *p = p.max(l);
            }
        }
        let mut points = Vec::with_capacity(POINTS);
        for j in 0..=SIDE {
            for i in 0..=SIDE - j {
                points.push((i as f64 * h, j as f64 * h, lw[point(i, j)]));
            }
        }
        TriangleLattice { points }
    }

    /// At least `max over p of alpha g . p + ln w(p)` over triangle `tri` (of this
    /// lattice's valences), in each of the directions `g` (in AVX lanes where the CPU has
    /// them, the same arithmetic, so the same bits: `primitives::lanes`).
    #[inline]
    pub fn supports<const N: usize>(&self, tri: &Triangle, g: &[DVec3; N], alpha: f64) -> [f64; N] {
        #[cfg(target_arch = "x86_64")]
        if super::lanes::available() {
            // SAFETY: `lanes::available` found AVX on this CPU.
            return unsafe { self.supports_avx(tri, g, alpha) };
        }
        self.supports_any(tri, g, alpha)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn supports_avx<const N: usize>(&self, tri: &Triangle, g: &[DVec3; N], alpha: f64) -> [f64; N] {
        self.supports_any(tri, g, alpha)
    }

    #[inline(always)]
    fn supports_any<const N: usize>(&self, tri: &Triangle, g: &[DVec3; N], alpha: f64) -> [f64; N] {
        let a = tri.a.as_dvec3();
        let (e1, e2) = (tri.b.as_dvec3() - a, tri.c.as_dvec3() - a);
        let ga: [f64; N] = std::array::from_fn(|k| alpha * g[k].dot(a));
        let g1: [f64; N] = std::array::from_fn(|k| alpha * g[k].dot(e1));
        let g2: [f64; N] = std::array::from_fn(|k| alpha * g[k].dot(e2));
        let mut h = [f64::NEG_INFINITY; N];
        for &(s, t, lw) in &self.points {
            for k in 0..N {
                let v = lw + s * g1[k] + t * g2[k];
                h[k] = if v > h[k] { v } else { h[k] };
            }
        }
        // The products' rounding, relative to their size.
        std::array::from_fn(|k| {
            ga[k] + h[k] + 1e-12 * (ga[k].abs() + g1[k].abs() + g2[k].abs() + h[k].abs() + 1.0)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::weights::triangle_w_value;
    use crate::testing::uniform;
    use glam::Vec3;

    /// The blossom as first written, every binomial and power computed where it is used.
    fn blossom_direct(a: usize, b: usize, corners: &[(f64, f64); 3], mult: [usize; 3]) -> f64 {
        let mut sum = 0.0;
        for a0 in 0..=a.min(mult[0]) {
            for a1 in 0..=(a - a0).min(mult[1]) {
                let a2 = a - a0 - a1;
                if a2 > mult[2] {
                    continue;
                }
                for b0 in 0..=b.min(mult[0] - a0) {
                    for b1 in 0..=(b - b0).min(mult[1] - a1) {
                        let b2 = b - b0 - b1;
                        if b2 > mult[2] - a2 {
                            continue;
                        }
                        let ways = binomial(mult[0], a0)
                            * binomial(mult[0] - a0, b0)
                            * binomial(mult[1], a1)
                            * binomial(mult[1] - a1, b1)
                            * binomial(mult[2], a2)
                            * binomial(mult[2] - a2, b2);
                        let (p0, p1, p2) = (corners[0], corners[1], corners[2]);
                        sum += ways
                            * p0.0.powi(a0 as i32)
                            * p1.0.powi(a1 as i32)
                            * p2.0.powi(a2 as i32)
                            * p0.1.powi(b0 as i32)
                            * p1.1.powi(b1 as i32)
                            * p2.1.powi(b2 as i32);
                    }
                }
            }
        }
        sum / (binomial(DEGREE, a) * binomial(DEGREE - a, b))
    }

    /// The looked-up parts give the direct blossom's bits on every sub-triangle, index
    /// and monomial the tables use.
    #[test]
    fn blossoms_from_looked_up_parts_are_the_direct_ones() {
        let h = 1.0 / SIDE as f64;
        for sub in sub_triangles() {
            let corners = sub.map(|(i, j)| (i as f64 * h, j as f64 * h));
            let parts = BlossomParts::new(&corners);
            for mult in indices() {
                for &(a, b) in GROUPS.iter().flat_map(|g| g.iter()) {
                    let (fast, direct) = (
                        blossom(a, b, &parts, mult),
                        blossom_direct(a, b, &corners, mult),
                    );
                    assert_eq!(
                        fast.to_bits(),
                        direct.to_bits(),
                        "{sub:?} {mult:?} s^{a} t^{b}"
                    );
                }
            }
        }
    }

    /// The supports in lanes (where this CPU has AVX) are the scalar code's bits.
    #[test]
    fn supports_in_lanes_are_the_scalar_code_bit_for_bit() {
        let mut r = uniform(5);
        let scale = WeightScale::new(9.0, 80.0, 120.0);
        let lattice = TriangleLattice::new(7.0, 2.0, &scale);
        for _ in 0..50 {
            let mut v = || Vec3::new(r() as f32, r() as f32, r() as f32);
            let tri = Triangle::new(v(), v(), v(), 7.0, 2.0);
            let g: [DVec3; 26] =
                std::array::from_fn(|_| DVec3::new(r() - 0.5, r() - 0.5, r() - 0.5) * 3.0);
            let (a, b) = (
                lattice.supports(&tri, &g, 80.0),
                lattice.supports_any(&tri, &g, 80.0),
            );
            for k in 0..26 {
                assert_eq!(a[k].to_bits(), b[k].to_bits(), "direction {k}");
            }
        }
    }

    /// The Bernstein coefficients rebuild the weight: at random points of each
    /// sub-triangle the Bernstein sum equals `triangle_w_value`.
    #[test]
    fn the_bernstein_form_is_the_weight() {
        let mut r = uniform(3);
        let h = 1.0 / SIDE as f64;
        for (vmax, emax) in [(6.0, 2.0), (3.0, 1.0), (11.0, 4.0), (40.0, 9.0)] {
            let k = triangle_coefficients(vmax, emax);
            for (sub, table) in sub_triangles().iter().zip(bernstein_tables()) {
                let corners = sub.map(|(i, j)| (i as f64 * h, j as f64 * h));
                for _ in 0..3 {
                    let (mut l1, mut l2) = (r(), r());
                    if l1 + l2 > 1.0 {
                        (l1, l2) = (1.0 - l1, 1.0 - l2);
                    }
                    let l = [1.0 - l1 - l2, l1, l2];
                    let s = l[0] * corners[0].0 + l[1] * corners[1].0 + l[2] * corners[2].0;
                    let t = l[0] * corners[0].1 + l[1] * corners[1].1 + l[2] * corners[2].1;
                    let bern: f64 = indices()
                        .zip(table)
                        .map(|(m, c)| {
                            let coef: f64 = c.iter().zip(&k).map(|(c, k)| c * k).sum();
                            let multinomial = (1..=DEGREE).product::<usize>() as f64
                                / m.iter()
                                    .map(|&x| (1..=x).product::<usize>() as f64)
                                    .product::<f64>();
                            coef * multinomial
                                * l[0].powi(m[0] as i32)
                                * l[1].powi(m[1] as i32)
                                * l[2].powi(m[2] as i32)
                        })
                        .sum();
                    let w = triangle_w_value(s, t, &k);
                    assert!((bern - w).abs() < 1e-9, "{vmax} {emax}: {bern} vs {w}");
                }
            }
        }
    }

    /// The support is at least the sampled maximum over the triangle, and within the
    /// lattice's spread of it.
    #[test]
    fn the_bound_covers_every_point_and_stays_close() {
        let mut r = uniform(41);
        let mut worst_gap: f64 = 0.0;
        for case in 0..150 {
            let mut v = || Vec3::new(r() as f32, r() as f32, r() as f32) * 2.0 - Vec3::ONE;
            let (a, b, c) = (v(), v(), v());
            let vmax = [1.0, 3.0, 6.0, 7.0, 12.0, 40.0][case % 6];
            let emax = [1.0, 2.0, 3.0, 9.0][(case / 6) % 4];
            let tri = Triangle::new(a, b, c, vmax, emax);
            let alpha = 1.0 + 100.0 * r();
            let scale = WeightScale::new(40.0, alpha, 50.0 + 200.0 * r());
            let lattice = TriangleLattice::new(vmax, emax, &scale);
            let g = [DVec3::new(r() - 0.5, r() - 0.5, r() - 0.5) * 2.6];
            let bound = lattice.supports(&tri, &g, alpha)[0];
            let k = triangle_coefficients(vmax as f64, emax as f64);
            let (a, e1, e2) = (
                a.as_dvec3(),
                b.as_dvec3() - a.as_dvec3(),
                c.as_dvec3() - a.as_dvec3(),
            );
            let n = 120;
            let mut sampled = f64::NEG_INFINITY;
            for i in 0..=n {
                for j in 0..=n - i {
                    let (s, t) = (i as f64 / n as f64, j as f64 / n as f64);
                    let p = a + s * e1 + t * e2;
                    let w = scale.weight(triangle_w_value(s, t, &k)).ln();
                    sampled = sampled.max(alpha * g[0].dot(p) + w);
                }
            }
            assert!(
                bound >= sampled,
                "case {case}: bound {bound} below {sampled}"
            );
            let spread = (alpha * g[0].dot(e1)).abs() + (alpha * g[0].dot(e2)).abs();
            worst_gap = worst_gap.max((bound - sampled) / (spread / SIDE as f64 + 0.1));
        }
        assert!(worst_gap <= 1.5, "the bound runs {worst_gap} spreads above");
    }
}
