//! Per-node moments for a tighter conservative far-field term (SPEC 6).
//!
//! SPEC 6 replaces a subtree by `n w_ff exp(-alpha r)` with `r` the distance to the
//! node's box: every primitive is at least `r` away. That bound treats all `n`
//! primitives as if they sat at the box's closest point, which overestimates the sum by
//! up to `exp(alpha * extent)` for soft fields (small `alpha` against the node size).
//!
//! A tighter bound from the node's centroid `c` and the spread of its primitives: with
//! `u = (x - c) / |x - c|` and any point `q` of primitive `i`,
//! `d_i >= u . (x - q) = R - u . (q - c)` (`R = |x - c|`). Write `m_i` for the
//! primitive's centroid, `rho_i` for its radius about `m_i`, `Z_i = u . (m_i - mean)`
//! and `delta = |mean - c|` (the stored centroid is the mean rounded to f32). Then
//! `d_i >= R - slack - Z_i` with `slack = max rho_i + delta`, and
//!
//! ```text
//! sum_i w_i exp(-alpha d_i) <= n w_ff exp(-alpha (R - slack)) * (1/n) sum_i exp(alpha Z_i)
//!                          <= n w_ff exp(-alpha (R - slack) + B),
//! B = (sigma^2 / b^2) (exp(alpha b) - 1 - alpha b)          (Bennett's inequality)
//! ```
//!
//! where the `Z_i` have mean 0, variance `sigma^2 <= lambda_max` (the largest eigenvalue
//! of the centroids' covariance, stored per node) and are at most `b` (the support of the
//! node's box in direction `u`, seen from `c`, plus the slack). Bennett's lemma: for
//! `Z <= b`, `E Z = 0`, `E Z^2 = sigma^2` and `lambda >= 0`,
//! `E exp(lambda Z) <= exp((sigma^2 / b^2)(exp(lambda b) - 1 - lambda b))`; it holds for
//! the empirical distribution of the node's primitives, so the bound is exact
//! arithmetic, not a probabilistic estimate. The far-field term then uses the distance
//! `max(r_box, R - slack - B / alpha)`: both bounds hold, so the larger distance does,
//! and the approximated `s` stays a lower bound of the exact one.
//!
//! For a node of diameter `D` at distance `r` seen along its length, the box bound loses
//! a factor up to `exp(alpha D / 2)`; this one about `exp(alpha^2 sigma^2 / 2)`, e.g.
//! `e^0.2` instead of `e^0.9` for `alpha D = 1.8` (points spread evenly).

use super::kinds::Primitive;
use crate::bvh::Node;
use glam::{DVec3, Vec3};

/// What a far-field term needs beyond the node's box (16 bytes).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NodeMoments {
    /// Mean of the primitives' centroids, rounded to f32.
    pub centroid: Vec3,
    /// Upper bound of the variance of the centroids along any direction (the largest
    /// eigenvalue of their covariance, rounded up).
    pub variance: f32,
    /// Largest primitive radius about its centroid plus the centroid's rounding error
    /// (rounded up); 0 for points up to rounding.
    pub slack: f32,
}

/// Running moments of a set of primitives, merged bottom-up (Chan et al.'s pairwise
/// update, stable when the points are far from the origin).
#[derive(Clone, Copy, Debug)]
struct Acc {
    n: f64,
    mean: DVec3,
    /// Sum of outer products of deviations from the mean: xx, yy, zz, xy, xz, yz.
    m2: [f64; 6],
    rho: f64,
}

impl Acc {
    fn one(m: DVec3, rho: f64) -> Acc {
        Acc {
            n: 1.0,
            mean: m,
            m2: [0.0; 6],
            rho,
        }
    }

    fn merge(a: Acc, b: Acc) -> Acc {
        let n = a.n + b.n;
        let d = b.mean - a.mean;
        let f = a.n * b.n / n;
        let o = [
            d.x * d.x,
            d.y * d.y,
            d.z * d.z,
            d.x * d.y,
            d.x * d.z,
            d.y * d.z,
        ];
        let mut m2 = [0.0; 6];
        for k in 0..6 {
            m2[k] = a.m2[k] + b.m2[k] + f * o[k];
        }
        Acc {
            n,
            mean: a.mean + d * (b.n / n),
            m2,
            rho: a.rho.max(b.rho),
        }
    }

    fn moments(&self) -> NodeMoments {
        let c = self.mean.as_vec3();
        let delta = (self.mean - c.as_dvec3()).length();
        let cov = self.m2.map(|v| v / self.n);
        let trace = cov[0] + cov[1] + cov[2];
        // Relative slack for the eigenvalue's rounding; never above the trace, which
        // bounds the largest eigenvalue of a positive semi-definite matrix.
        let lambda = (largest_eigenvalue(cov) * (1.0 + 1e-9) + 1e-12 * trace).min(trace);
        NodeMoments {
            centroid: c,
            variance: round_up(lambda.max(0.0)),
            slack: round_up((self.rho + delta) * (1.0 + 1e-9)),
        }
    }
}

/// The smallest f32 not below `v` (v >= 0 and finite).
fn round_up(v: f64) -> f32 {
    let f = v as f32;
    if (f as f64) < v { f.next_up() } else { f }
}

/// Largest eigenvalue of the symmetric matrix `[xx, yy, zz, xy, xz, yz]` (closed form,
/// Smith 1961).
fn largest_eigenvalue(a: [f64; 6]) -> f64 {
    let [a11, a22, a33, a12, a13, a23] = a;
    let p1 = a12 * a12 + a13 * a13 + a23 * a23;
    if p1 == 0.0 {
        return a11.max(a22).max(a33);
    }
    let q = (a11 + a22 + a33) / 3.0;
    let p2 = (a11 - q).powi(2) + (a22 - q).powi(2) + (a33 - q).powi(2) + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    let (b11, b22, b33) = ((a11 - q) / p, (a22 - q) / p, (a33 - q) / p);
    let (b12, b13, b23) = (a12 / p, a13 / p, a23 / p);
    let det = b11 * (b22 * b33 - b23 * b23) - b12 * (b12 * b33 - b23 * b13)
        + b13 * (b12 * b23 - b22 * b13);
    let phi = (det / 2.0).clamp(-1.0, 1.0).acos() / 3.0;
    q + 2.0 * p * phi.cos()
}

/// Moments of every node of a BVH whose leaves cover `prims` (in leaf order). Leaves get
/// their moments too (unused by the traversal, kept so indices match the nodes).
pub fn node_moments<P: Primitive>(nodes: &[Node], prims: &[P]) -> Vec<NodeMoments> {
    let mut out = vec![NodeMoments::default(); nodes.len()];
    if !nodes.is_empty() {
        fill(nodes, prims, 0, &mut out, 0);
    }
    out
}

/// Fills `out[i - base]` for the subtree rooted at node `i`, whose nodes are the
/// contiguous range `i .. i + subtree size` in the depth-first layout; returns its
/// moments. The two subtrees are split off `out` and filled in parallel near the root.
fn fill<P: Primitive>(
    nodes: &[Node],
    prims: &[P],
    i: usize,
    out: &mut [NodeMoments],
    base: usize,
) -> Acc {
    let node = &nodes[i];
    let acc = if node.is_leaf() {
        let first = node.index as usize;
        prims[first..first + node.count as usize]
            .iter()
            .map(|p| Acc::one(p.centroid().as_dvec3(), p.radius()))
            .reduce(Acc::merge)
            .expect("a leaf holds at least one primitive")
    } else {
        let (l, r) = (i + 1, node.index as usize);
        // out[i - base] is this node, then the left subtree up to r, then the right one.
        let (_, rest) = out.split_at_mut(i + 1 - base);
        let (left, right) = rest.split_at_mut(r - (i + 1));
        let (a, b) = if node.size > 4096 {
            rayon::join(
                || fill(nodes, prims, l, left, l),
                || fill(nodes, prims, r, right, r),
            )
        } else {
            (
                fill(nodes, prims, l, left, l),
                fill(nodes, prims, r, right, r),
            )
        };
        Acc::merge(a, b)
    };
    out[i - base] = acc.moments();
    acc
}

impl NodeMoments {
    /// The far-field distance of a node at `x` (see the module docs): at least the box
    /// distance `r_box`, and the direction of the bound that gave it (unit; from the
    /// centroid or the closest box point).
    #[inline]
    pub fn far_distance(&self, node: &Node, x: DVec3, r_box: f64, alpha: f64) -> f64 {
        let c = self.centroid.as_dvec3();
        let v = x - c;
        let big_r = v.length();
        let slack = self.slack as f64;
        if big_r - slack <= r_box {
            return r_box;
        }
        // Bennett's exponent is at least alpha^2 sigma^2 / 2: when even that loses to the
        // box, skip the rest (the common case for nodes large against 1/alpha).
        let sigma2 = self.variance as f64;
        if big_r - slack - 0.5 * alpha * sigma2 <= r_box {
            return r_box;
        }
        let u = v / big_r;
        let lo = u * (node.min.as_dvec3() - c);
        let hi = u * (node.max.as_dvec3() - c);
        let b = lo.max(hi).element_sum() + slack;
        let bennett = bennett_exponent(alpha, sigma2, b);
        r_box.max(big_r - slack - bennett / alpha)
    }

    /// The node's centroid (for the far-field term's gradient direction).
    #[inline]
    pub fn centroid(&self) -> DVec3 {
        self.centroid.as_dvec3()
    }
}

/// `(sigma^2 / b^2) (exp(lambda b) - 1 - lambda b)`: the log of Bennett's bound of
/// `E exp(lambda Z)` for `Z <= b`, `E Z = 0`, `E Z^2 <= sigma^2`; rounded up.
#[inline]
pub fn bennett_exponent(lambda: f64, sigma2: f64, b: f64) -> f64 {
    if sigma2 <= 0.0 || b <= 0.0 {
        return 0.0;
    }
    let x = lambda * b;
    // exp(x) - 1 - x without cancellation: below 1/2 its Taylor series to x^6 with the
    // remainder bounded by x^7/7! e^x <= x^7 / 3000 (rounded up), above by exp.
    let f = if x < 0.5 {
        let x2 = x * x;
        x2 * (0.5
            + x * (1.0 / 6.0
                + x * (1.0 / 24.0 + x * (1.0 / 120.0 + x * (1.0 / 720.0 + x / 3000.0)))))
    } else {
        x.exp() - 1.0 - x
    };
    (sigma2 / (b * b)) * f * (1.0 + 1e-12)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{BuildOptions, build};
    use crate::mesh::Aabb;
    use crate::primitives::Point;

    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn eigenvalue_matches_power_iteration() {
        let mut seed = 7;
        for _ in 0..200 {
            let g: Vec<f64> = (0..9).map(|_| lcg(&mut seed) - 0.5).collect();
            // A = G G^T is symmetric positive semi-definite.
            let m = |i: usize, j: usize| (0..3).map(|k| g[3 * i + k] * g[3 * j + k]).sum::<f64>();
            let a = [m(0, 0), m(1, 1), m(2, 2), m(0, 1), m(0, 2), m(1, 2)];
            let mut v = DVec3::new(1.0, 0.7, 0.3);
            for _ in 0..2000 {
                v = DVec3::new(
                    a[0] * v.x + a[3] * v.y + a[4] * v.z,
                    a[3] * v.x + a[1] * v.y + a[5] * v.z,
                    a[4] * v.x + a[5] * v.y + a[2] * v.z,
                )
                .normalize();
            }
            let av = DVec3::new(
                a[0] * v.x + a[3] * v.y + a[4] * v.z,
                a[3] * v.x + a[1] * v.y + a[5] * v.z,
                a[4] * v.x + a[5] * v.y + a[2] * v.z,
            );
            let want = v.dot(av);
            let got = largest_eigenvalue(a);
            assert!(
                (got - want).abs() <= 1e-9 * want.max(1e-12),
                "{got} vs {want}"
            );
        }
    }

    #[test]
    fn bennett_exponent_is_continuous_and_bounds_the_mgf() {
        // Two-point distributions are the extreme case of Bennett's lemma.
        for &(b, lambda) in &[
            (1.0f64, 0.5f64),
            (0.3, 10.0),
            (1e-5, 1.0),
            (2.0, 1e-4),
            (0.4, 1.0),
        ] {
            let p = 0.2; // Z = b with probability p, else -b p / (1 - p): mean 0
            let lo = -b * p / (1.0 - p);
            let var = p * b * b + (1.0 - p) * lo * lo;
            // ln E exp(lambda Z), computed without cancellation near 1.
            let ln_mgf = (p * (lambda * b).exp_m1() + (1.0 - p) * (lambda * lo).exp_m1()).ln_1p();
            let bound = bennett_exponent(lambda, var, b);
            assert!(ln_mgf <= bound, "b {b} lambda {lambda}: {ln_mgf} > {bound}");
        }
        let x = 1e-3;
        let below = bennett_exponent(1.0, 1.0, x * (1.0 - 1e-9));
        let above = bennett_exponent(1.0, 1.0, x * (1.0 + 1e-9));
        assert!((below - above).abs() <= 1e-9 * above, "{below} vs {above}");
    }

    /// Every node's far-field distance is a valid bound: the far term is at least the
    /// exact sum of the node's terms, at many query points and sharpnesses.
    #[test]
    fn far_term_dominates_the_exact_sum() {
        let mut seed = 3;
        let pts: Vec<Point> = (0..2000)
            .map(|_| {
                // A noisy sheet far from the origin, like a scan patch.
                let (a, b) = (lcg(&mut seed), lcg(&mut seed));
                Point {
                    p: Vec3::new(
                        1000.0 + 10.0 * a as f32,
                        -500.0 + 10.0 * b as f32,
                        0.05 * lcg(&mut seed) as f32,
                    ),
                }
            })
            .collect();
        let bounds: Vec<Aabb> = pts.iter().map(|p| p.bounds()).collect();
        let cents: Vec<Vec3> = pts.iter().map(|p| p.p).collect();
        let bvh = build(&bounds, &cents, BuildOptions::default());
        let sorted: Vec<Point> = bvh.order.iter().map(|&i| pts[i as usize]).collect();
        let mom = node_moments(&bvh.nodes, &sorted);
        let mut tighter = 0;
        for (k, node) in bvh.nodes.iter().enumerate() {
            if node.is_leaf() {
                continue;
            }
            let first = first_prim(&bvh.nodes, k);
            let sub = &sorted[first..first + node.size as usize];
            for _ in 0..20 {
                let x = DVec3::new(
                    1000.0 + 40.0 * lcg(&mut seed) - 15.0,
                    -500.0 + 40.0 * lcg(&mut seed) - 15.0,
                    20.0 * lcg(&mut seed) - 10.0,
                );
                for alpha in [0.1, 1.0, 10.0, 100.0] {
                    let (r_box, _) = node.distance(x);
                    let d = mom[k].far_distance(node, x, r_box, alpha);
                    let far = node.size as f64 * (-alpha * (d - r_box)).exp();
                    let exact: f64 = sub
                        .iter()
                        .map(|p| (-alpha * ((x - p.p.as_dvec3()).length() - r_box)).exp())
                        .sum();
                    assert!(
                        far >= exact * (1.0 - 1e-12),
                        "node {k} alpha {alpha}: far {far} < exact {exact}"
                    );
                    tighter += (d > r_box) as usize;
                }
            }
        }
        assert!(tighter > 0, "the centroid bound never beat the box bound");
    }

    fn first_prim(nodes: &[Node], mut k: usize) -> usize {
        while !nodes[k].is_leaf() {
            k += 1;
        }
        nodes[k].index as usize
    }
}
