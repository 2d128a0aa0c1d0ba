//! How far along a ray the smooth distance provably stays positive, from the slopes of
//! the terms of one evaluation (a second-order step bound for sphere tracing, SPEC 7).
//!
//! A Barnes-Hut evaluation at `x` sums terms `w_j exp(-alpha g_j(x))` where each `g_j`
//! is a distance to a point or to a box (a far-field term): convex along any line and
//! 1-Lipschitz, and every `g_j` is a lower bound of the distances it stands for, at
//! every position (not only at `x`). So along the ray `x + L u`, with `a_j` the slope of
//! `g_j` at `x` (`u . (x - c_j) / g_j`, in [-1, 1]), convexity gives
//! `g_j(x + L u) >= g_j(x) + a_j L`, and
//!
//!   `s(x + L u) >= m - ln( sum_j e_j exp(-alpha a_j L) ) / alpha`
//!
//! with `e_j = w_j exp(-alpha (g_j(x) - m))` the shifted terms. The terms are binned by
//! slope (8 bins of width 1/4 on [-1, 1]); within a bin, `exp(-alpha a L)` is convex in
//! `a`, so it is at most the chord through the bin's ends, and the bin's mass and mean
//! slope give an upper bound of its share. Subtrees skipped as negligible hold at most
//! `P` (the evaluation's pruning bound) and are counted at slope -1. The bound reads
//! `Q(L) = sum_k c_k exp(-alpha a_k L)` over the nine bin edges `a_k = -1 + k/4`, and
//! `s(x + L u) >= m - ln Q(L) / alpha`. `ln Q` is convex in `L` (a log-sum of
//! exponentials), so the bound is concave: positive on `[0, L]` once positive at `L`.
//! The free distance is its first zero, found safely from below: a Newton step from a
//! safe point overshoots a convex function's root, and the secant through a safe point
//! and an overshoot undershoots it. (Bennett's inequality from the slopes' mean and
//! variance alone, three sums instead of sixteen, certifies as much on exact sums but
//! less on Barnes-Hut sums, whose far-field slopes are bunched: 5.2 instead of 4.8 full
//! evaluations per hit ray on the deer, and more instructions in all.)
//!
//! The same bins give the free distance backwards, along `-u`: every slope negated, the
//! bins mirrored ([`Slopes::reversed`]). The tracer uses it to certify an over-relaxed
//! step from the far end (`render::stepper`): near a surface met at an angle the field
//! grows going back along the ray, so that reach is often several times `s`.
//!
//! The same bins give the derivative of `s` along the ray, `sum_j e_j a_j / sum_j e_j`,
//! and an estimate of its second derivative, `sum_j p_j (1 - a_j^2) / d_j - alpha
//! Var_p(a)` (`p_j = e_j / sum e`; the distances taken at the nearest one plus a kernel
//! width, the slopes' spread between the bins): the tracer aims steps on soft point
//! clouds at the crossing of that expansion (`render::tracer` item 12). Estimates, not
//! bounds: an aimed step is certified as any relaxed step.
//!
//! Where all terms come at slope -1 (the ray heads straight at everything) this gives
//! back the plain sphere-tracing step `s`; where the terms that matter are met at a
//! grazing angle, or spread in direction, it certifies much longer steps.
//!
//! Edges and triangles weigh their terms by `w_j(x)`, which changes along the ray with
//! the closest point: a term is `exp(-alpha (g_j - ln w_j / alpha))`, and its slope is
//! taken as `a_j - (u . grad w_j) / (alpha w_j)` (clamped to [-1, 1]), the exact slope
//! at `x`. `ln w_j` is neither convex nor concave, so there the bound holds to first
//! order in the step, not certainly: on a test sphere (`tests/engine.rs`) the exact
//! value within the free distance dips below zero by up to 7% of the step at `alpha *
//! diag` 30 with the weights attenuated by `q = 1/2`, not at all at 100 or with constant
//! weights. The tracer treats such a landing as any crossing: below `-epsilon` it is
//! backtracked, within the band a hit moved back to the crossing's estimate
//! (`render::tracer` item 4). (Freezing the weights instead put 24% of the hits on the
//! 7k-triangle bunny at the published scene's settings past the exact surface, the
//! slopes 7%, by at most an epsilon; 0.4% and 2% on the two bunnies once moved back,
//! by at most a tenth of an epsilon.) Points weigh 1: for them the bound is certain.

/// Number of slope bins on [-1, 1].
const BINS: usize = 8;
const WIDTH: f64 = 2.0 / BINS as f64;

/// Shifted term masses per slope bin, and their slope moments.
#[derive(Clone, Copy, Debug, Default)]
pub struct Slopes {
    mass: [f64; BINS],
    moment: [f64; BINS],
}

impl Slopes {
    /// Adds a shifted term `e` at slope `a` in [-1, 1].
    #[inline]
    pub fn add(&mut self, e: f64, a: f64) {
        // floor((a + 1) / WIDTH) by rounding in the units place of 2^52 (a float-to-int
        // cast costs a dozen instructions here); a value on a bin edge may land in the
        // bin below, which holds it too.
        const MAGIC: f64 = 4_503_599_627_370_496.0;
        let t = (a + 1.0) * (1.0 / WIDTH) - 0.5 + MAGIC;
        let b = (t.to_bits() as i64 - MAGIC.to_bits() as i64).clamp(0, BINS as i64 - 1) as usize;
        self.mass[b] += e;
        self.moment[b] += e * a;
    }

    /// Multiplies every mass by `f` (the shift's reference moved).
    #[inline]
    pub fn rescale(&mut self, f: f64) {
        for k in 0..BINS {
            self.mass[k] *= f;
            self.moment[k] *= f;
        }
    }

    /// The same terms seen along `-u`: every slope negated, so the bins are mirrored
    /// (the pruned mass stays at slope -1, as `free_distance` counts it).
    pub fn reversed(&self) -> Slopes {
        let mut r = Slopes::default();
        for k in 0..BINS {
            r.mass[k] = self.mass[BINS - 1 - k];
            r.moment[k] = -self.moment[BINS - 1 - k];
        }
        r
    }

    /// The first two derivatives of the smooth distance along `u` at the evaluation
    /// point, for sharpness `alpha` and the terms' typical distance `dist > 0`; `None`
    /// without terms. The first is exact: the terms' slopes averaged with their shifted
    /// masses as weights, `ds/dL = sum_j p_j a_j` with `p_j = e_j / sum e` (pruned
    /// subtrees, whose slopes are unknown, left out). The second is an estimate, `sum_j
    /// p_j g_j'' - alpha Var_p(a)`: each term's distance bends away from its tangent
    /// (`g_j'' = (1 - a_j^2) / d_j`, taken at `dist`), the log-sum the other way by the
    /// slopes' spread (taken between the bins, each bin at its mean slope).
    pub fn derivatives(&self, alpha: f64, dist: f64) -> Option<(f64, f64)> {
        let mass: f64 = self.mass.iter().sum();
        let moment: f64 = self.moment.iter().sum();
        (mass > 0.0 && mass.is_finite()).then(|| {
            let mean = moment / mass;
            let square: f64 = (0..BINS)
                .filter(|&k| self.mass[k] > 0.0)
                .map(|k| self.moment[k] * self.moment[k] / self.mass[k])
                .sum::<f64>()
                / mass;
            (
                mean,
                (1.0 - square) / dist - alpha * (square - mean * mean).max(0.0),
            )
        })
    }

    /// The chord coefficients `c_k` of the bin edges `a_k = -1 + k WIDTH`, with the
    /// pruned mass `pruned` at slope -1.
    fn edge_weights(&self, pruned: f64) -> [f64; BINS + 1] {
        let mut c = [0.0; BINS + 1];
        c[0] = pruned;
        for k in 0..BINS {
            let lo = -1.0 + k as f64 * WIDTH;
            let hi = lo + WIDTH;
            // mass * (hi - mean) / WIDTH at lo, mass * (mean - lo) / WIDTH at hi.
            c[k] += ((self.mass[k] * hi - self.moment[k]) / WIDTH).max(0.0);
            c[k + 1] += ((self.moment[k] - self.mass[k] * lo) / WIDTH).max(0.0);
        }
        c
    }

    /// The free distance along the ray: a length `L >= s` such that the smooth distance
    /// stays positive on `[0, L]` (module docs), for an evaluation with value `s > 0`,
    /// shift reference `m`, sharpness `alpha` and pruned mass bound `pruned` (shifted,
    /// like the bins). At most `max_len`. Returns `s` when nothing better is certified.
    pub fn free_distance(&self, s: f64, m: f64, alpha: f64, pruned: f64, max_len: f64) -> f64 {
        if !(s > 0.0 && s.is_finite() && max_len > s) {
            return s;
        }
        let c = self.edge_weights(pruned);
        // h(L) = ln Q(L) - alpha m = alpha L + ln(sum_k c_k z^k) - alpha m, z = e^(-alpha W L)
        // (convex), and its derivative.
        let h = |l: f64| -> (f64, f64) {
            let z = (-alpha * WIDTH * l).exp();
            let (mut p, mut dp) = (0.0, 0.0);
            for k in (0..=BINS).rev() {
                dp = dp * z + p;
                p = p * z + c[k];
            }
            // d/dL ln p(z) = p'(z) / p(z) * dz/dL, dz/dL = -alpha W z.
            let value = alpha * l + p.ln() - alpha * m;
            let slope = alpha - dp / p * alpha * WIDTH * z;
            (value, slope)
        };
        let (mut lo, (mut h_lo, mut d_lo)) = (s, h(s));
        if h_lo.is_nan() || h_lo > 0.0 {
            return s;
        }
        for _ in 0..2 {
            // Newton from the safe side overshoots the root (or runs off: cap it).
            let hi = if d_lo > 0.0 {
                (lo - h_lo / d_lo).min(max_len)
            } else {
                max_len
            };
            if hi.is_nan() || hi <= lo {
                break;
            }
            let (h_hi, _) = h(hi);
            if !h_hi.is_finite() {
                break;
            }
            if h_hi <= 0.0 {
                // Still safe (only when capped): take it.
                lo = hi;
                break;
            }
            // The secant through a safe point and an overshoot undershoots the root.
            let next = lo - h_lo * (hi - lo) / (h_hi - h_lo);
            if !(next > lo && next < hi) {
                break;
            }
            let (h_next, d_next) = h(next);
            if h_next.is_nan() || h_next > 0.0 {
                break;
            }
            (lo, h_lo, d_lo) = (next, h_next, d_next);
        }
        lo
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exact smooth distance of unit-weight points along the ray `x + L u`.
    fn exact(points: &[[f64; 3]], x: [f64; 3], u: [f64; 3], l: f64, alpha: f64) -> f64 {
        let q = [x[0] + l * u[0], x[1] + l * u[1], x[2] + l * u[2]];
        let d: Vec<f64> = points
            .iter()
            .map(|p| ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) + (q[2] - p[2]).powi(2)).sqrt())
            .collect();
        let m = d.iter().cloned().fold(f64::INFINITY, f64::min);
        m - d
            .iter()
            .map(|di| (-alpha * (di - m)).exp())
            .sum::<f64>()
            .ln()
            / alpha
    }

    #[test]
    fn free_distance_ahead_and_behind_never_passes_a_zero_and_beats_the_plain_step() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut gain, mut gain_back, mut cases) = (0.0, 0.0, 0);
        for _ in 0..400 {
            let alpha = [0.5, 2.0, 10.0, 50.0][(rnd() * 4.0) as usize];
            // A cloud around the origin, a ray from outside towards it (or past it).
            let n = 1 + (rnd() * 60.0) as usize;
            let points: Vec<[f64; 3]> = (0..n)
                .map(|_| {
                    [
                        rnd() * 2.0 - 1.0,
                        (rnd() * 2.0 - 1.0) * 0.2,
                        rnd() * 2.0 - 1.0,
                    ]
                })
                .collect();
            let x = [rnd() * 6.0 - 3.0, 1.0 + 3.0 * rnd(), rnd() * 6.0 - 3.0];
            // Down at 5 to 90 degrees below the horizon, in any horizontal direction.
            let (phi, theta) = (
                std::f64::consts::TAU * rnd(),
                (5.0 + 85.0 * rnd()).to_radians(),
            );
            let u = [
                phi.cos() * theta.cos(),
                -theta.sin(),
                phi.sin() * theta.cos(),
            ];
            // The evaluation at x: exact terms, binned by slope.
            let mut slopes = Slopes::default();
            let d: Vec<(f64, f64)> = points
                .iter()
                .map(|p| {
                    let v = [x[0] - p[0], x[1] - p[1], x[2] - p[2]];
                    let di = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                    (di, (v[0] * u[0] + v[1] * u[1] + v[2] * u[2]) / di)
                })
                .collect();
            let m = d.iter().map(|t| t.0).fold(f64::INFINITY, f64::min);
            let mut sum = 0.0;
            for &(di, a) in &d {
                let e = (-alpha * (di - m)).exp();
                sum += e;
                slopes.add(e, a);
            }
            let s = m - sum.ln() / alpha;
            if s <= 0.0 {
                continue;
            }
            let pruned = if rnd() < 0.5 { 0.0 } else { 1e-3 * sum };
            let s = if pruned > 0.0 {
                m - (sum + pruned).ln() / alpha
            } else {
                s
            };
            let free = slopes.free_distance(s, m, alpha, pruned, 100.0 * s);
            assert!(free >= s, "free {free} below the plain step {s}");
            // Behind: the mirrored bins, checked along -u.
            let back = slopes
                .reversed()
                .free_distance(s, m, alpha, pruned, 100.0 * s);
            assert!(back >= s, "free behind {back} below the plain step {s}");
            for k in 0..=200 {
                let l = free * k as f64 / 200.0;
                let v = exact(&points, x, u, l, alpha);
                assert!(
                    v > -1e-9 * s,
                    "negative {v} at {l} of free distance {free} (s {s})"
                );
                let l = back * k as f64 / 200.0;
                let v = exact(&points, x, u, -l, alpha);
                assert!(
                    v > -1e-9 * s,
                    "negative {v} at {l} behind, free distance {back} (s {s})"
                );
            }
            gain += free / s;
            gain_back += back / s;
            cases += 1;
        }
        assert!(cases > 100, "{cases} cases");
        assert!(
            gain / cases as f64 > 1.2,
            "mean free / s = {}",
            gain / cases as f64
        );
        // The rays head down into the cloud: behind them the field grows.
        assert!(
            gain_back > gain,
            "mean free / s: behind {} against ahead {}",
            gain_back / cases as f64,
            gain / cases as f64
        );
    }
}
