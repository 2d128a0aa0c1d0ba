//! Accumulating `sum_i w_i exp(-alpha d_i)` and its gradient (SPEC 2).
//!
//! Stable (default): keep a reference distance `m` (the smallest `d` seen) and the
//! shifted sums `S = sum w_i exp(-alpha (d_i - m))`, `G = sum exp(-alpha (d_i - m))
//! (w_i g_i - grad w_i / alpha)`, rescaling both by `exp(-alpha (m_old - m_new))` when `m`
//! decreases. Then `s = m - ln(S) / alpha` and `grad s = G / S`. Every exponent is <= 0
//! and `S >= 1` once a term is in, so nothing overflows, underflows to a zero sum, or
//! divides by zero, for any alpha and distance.
//!
//! Naive (the paper's): the unshifted sums; `s = -ln(S) / alpha` is `+inf` when every
//! term underflows (alpha d above about 745), which the sample reports.

use glam::DVec3;

/// Which accumulation to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Accumulation {
    #[default]
    Stable,
    Naive,
}

/// Running sums for one evaluation.
#[derive(Clone, Copy, Debug)]
pub struct Accumulator {
    alpha: f64,
    naive: bool,
    /// Smallest distance added so far (+inf before the first term).
    pub m: f64,
    s: f64,
    g: DVec3,
    naive_s: f64,
    naive_g: DVec3,
    /// Upper bound of the shifted mass of subtrees pruned against the budget (added to
    /// the sum at the end, so `s` stays a lower bound).
    pub pruned: f64,
    /// The terms added as exact (`add`, `add_value`) and, for far-field terms (`add_far`,
    /// `add_value_far`), the lower bounds of their subtrees given to `far_lower`, shifted
    /// like `s`: `m - ln(lower) / alpha` bounds the exact value from above. (Kept apart
    /// rather than as `s` minus the far terms: those can exceed the exact sum by many
    /// orders of magnitude, and the difference would be rounding.)
    lower: f64,
    /// `1 / alpha`, once.
    inv_alpha: f64,
}

impl Accumulator {
    pub fn new(alpha: f64, mode: Accumulation) -> Self {
        Accumulator {
            alpha,
            naive: mode == Accumulation::Naive,
            m: f64::INFINITY,
            s: 0.0,
            g: DVec3::ZERO,
            naive_s: 0.0,
            naive_g: DVec3::ZERO,
            pruned: 0.0,
            lower: 0.0,
            inv_alpha: 1.0 / alpha,
        }
    }

    /// Moves the reference down to `d` if it is below it, rescaling the shifted sums
    /// (the naive ones are not shifted).
    #[inline]
    fn shift(&mut self, d: f64) {
        if d < self.m {
            // exp(-inf) = 0 on the first term, when the sums are still zero.
            let rescale = (-self.alpha * (self.m - d)).exp();
            self.s *= rescale;
            self.g *= rescale;
            self.pruned *= rescale;
            self.lower *= rescale;
            self.m = d;
        }
    }

    /// Adds the term `w exp(-alpha d)` with unit direction `dir` (gradient of `d`) and
    /// weight gradient `grad_w`.
    /// Returns the term as added to the shifted sum, `w exp(-alpha (d - m))`.
    #[inline]
    pub fn add(&mut self, d: f64, w: f64, dir: DVec3, grad_w: DVec3) -> f64 {
        self.push::<true>(d, w, dir, grad_w)
    }

    /// [`Accumulator::add`] for a far-field term (an upper bound of its subtree's terms).
    #[inline]
    pub fn add_far(&mut self, d: f64, w: f64, dir: DVec3) -> f64 {
        self.push::<false>(d, w, dir, DVec3::ZERO)
    }

    #[inline]
    fn push<const EXACT: bool>(&mut self, d: f64, w: f64, dir: DVec3, grad_w: DVec3) -> f64 {
        self.shift(d);
        let e = (-self.alpha * (d - self.m)).exp();
        let gterm = w * dir - grad_w * self.inv_alpha;
        self.s += w * e;
        self.g += e * gterm;
        if EXACT {
            self.lower += w * e;
        }
        if self.naive {
            let e = (-self.alpha * d).exp();
            self.naive_s += w * e;
            self.naive_g += e * gterm;
        }
        w * e
    }

    /// Adds the term `w exp(-alpha d)` to the value sums only (no gradient); returns the
    /// term as added to the shifted sum, `w exp(-alpha (d - m))`.
    #[inline]
    pub fn add_value(&mut self, d: f64, w: f64) -> f64 {
        self.push_value::<true>(d, w)
    }

    /// [`Accumulator::add_value`] for a far-field term.
    #[inline]
    pub fn add_value_far(&mut self, d: f64, w: f64) -> f64 {
        self.push_value::<false>(d, w)
    }

    #[inline]
    fn push_value<const EXACT: bool>(&mut self, d: f64, w: f64) -> f64 {
        self.shift(d);
        let e = w * (-self.alpha * (d - self.m)).exp();
        self.s += e;
        if EXACT {
            self.lower += e;
        }
        if self.naive {
            self.naive_s += w * (-self.alpha * d).exp();
        }
        e
    }

    /// Records the lower bound `n exp(-alpha d_far)` of a far-field subtree.
    #[inline]
    pub fn far_lower(&mut self, n: f64, d_far: f64) {
        self.lower += n * (-self.alpha * (d_far - self.m)).exp();
    }

    /// An upper bound of the exact smooth distance: far terms at their lower bounds,
    /// pruned subtrees at zero.
    pub fn upper(&self) -> f64 {
        if self.lower > 0.0 {
            self.m - self.lower.ln() / self.alpha
        } else {
            f64::INFINITY
        }
    }

    #[inline]
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// `1 / alpha`, kept: a product costs less than a division.
    #[inline]
    pub fn inv_alpha(&self) -> f64 {
        self.inv_alpha
    }

    /// The shifted sum `S` (before any [`Accumulator::inflate`] it is the sum of the
    /// added terms, relative to `exp(-alpha m)`).
    #[inline]
    pub fn shifted_sum(&self) -> f64 {
        self.s
    }

    /// Multiplies the sums by `factor >= 1`: accounts, from above, for terms that were
    /// skipped as negligible (their total is known to be below a fraction of the sum), so
    /// that `s` stays a lower bound of the exact value.
    #[inline]
    pub fn inflate(&mut self, factor: f64) {
        self.s *= factor;
        self.naive_s *= factor;
    }

    /// A lower bound of `ln S` for the shifted sum `S` (0 before the first term), from
    /// the binary exponent of `S`: `S >= 2^e`, so `ln S >= e ln 2`. Costs no logarithm.
    #[inline]
    pub fn ln_sum_lower_bound(&self) -> f64 {
        if self.s >= 1.0 {
            let e = ((self.s.to_bits() >> 52) & 0x7ff) as i64 - 1023;
            e as f64 * std::f64::consts::LN_2
        } else {
            0.0
        }
    }

    /// `(s, grad s, underflow)` (the gradient is zero if only `add_value` was used). With no term at all, `s = +inf`.
    pub fn finish(&self) -> (f64, DVec3, bool) {
        if self.naive {
            if self.naive_s > 0.0 {
                (
                    -self.naive_s.ln() / self.alpha,
                    self.naive_g / self.naive_s,
                    false,
                )
            } else {
                (f64::INFINITY, DVec3::ZERO, true)
            }
        } else if self.s > 0.0 {
            let total = self.s + self.pruned;
            (self.m - total.ln() / self.alpha, self.g / total, false)
        } else {
            (f64::INFINITY, DVec3::ZERO, false)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stable_matches_closed_form_and_survives_huge_alpha() {
        let d = [1.0, 1.5, 3.0];
        for alpha in [0.1, 1.0, 10.0, 1e3, 1e6] {
            let mut acc = Accumulator::new(alpha, Accumulation::Stable);
            for &di in d.iter().rev() {
                acc.add(di, 1.0, DVec3::X, DVec3::ZERO);
            }
            let (s, g, under) = acc.finish();
            let m = 1.0;
            let want = m - d
                .iter()
                .map(|&di| (-alpha * (di - m)).exp())
                .sum::<f64>()
                .ln()
                / alpha;
            assert!(
                (s - want).abs() <= 1e-14 * want.abs().max(1.0),
                "{s} vs {want}"
            );
            assert!((g - DVec3::X).length() < 1e-12 && !under);
        }
    }

    #[test]
    fn naive_underflows_to_infinity() {
        let mut acc = Accumulator::new(1e4, Accumulation::Naive);
        acc.add(1.0, 1.0, DVec3::X, DVec3::ZERO);
        let (s, g, under) = acc.finish();
        assert!(s.is_infinite() && under && g == DVec3::ZERO);
        let mut acc = Accumulator::new(1e4, Accumulation::Stable);
        acc.add(1.0, 1.0, DVec3::X, DVec3::ZERO);
        assert_eq!(acc.finish().0, 1.0);
    }
}
