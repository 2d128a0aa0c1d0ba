//! Where a Barnes-Hut walk's terms go (SPEC 2, 6): the accumulator, with the gradient,
//! and the terms' slopes along a ray (`eval::reach`). Far-field terms are the closest-box
//! term or, for point clouds, the second-moment bound (Bennett's inequality; the
//! `eval::smooth` module docs state both and why each dominates the terms it replaces).

use super::accumulate::Accumulator;
use super::reach::Slopes;
use crate::primitives::{Primitive, Term, WeightScale};
use glam::DVec3;

/// `g(z) = (e^z - 1 - z) / z^2` for `z >= 0`, from above (to a relative 1e-11): its
/// Taylor series `sum z^k / (k + 2)!` to `k = 9` (remainder below `z^10 / 12!`) under
/// 0.5, else from `exp` (no cancellation there), `+inf` past 700.
#[inline]
pub(crate) fn bennett_g(z: f64) -> f64 {
    if z < 0.5 {
        const C: [f64; 10] = [
            1.0 / 2.0,
            1.0 / 6.0,
            1.0 / 24.0,
            1.0 / 120.0,
            1.0 / 720.0,
            1.0 / 5040.0,
            1.0 / 40320.0,
            1.0 / 362880.0,
            1.0 / 3628800.0,
            1.0 / 39916800.0,
        ];
        C.iter().rev().fold(0.0, |acc, &c| acc * z + c) + 1e-11
    } else if z < 700.0 {
        (z.exp() - 1.0 - z) / (z * z)
    } else {
        f64::INFINITY
    }
}

/// Grid step of [`bennett_g_chord`]'s table, and the grid's end.
const G_STEP: f64 = 0.25;
const G_END: f64 = 32.0;
const G_POINTS: usize = (G_END / G_STEP) as usize + 1;

/// `bennett_g` at the grid points `k G_STEP`, rounded up.
static G_TABLE: std::sync::LazyLock<[f64; G_POINTS]> = std::sync::LazyLock::new(|| {
    std::array::from_fn(|k| bennett_g(k as f64 * G_STEP) * (1.0 + 1e-12))
});

/// An upper bound of `g(z)` for `z >= 0` that costs no exponential: `g` is convex (its
/// Taylor coefficients are positive), so on each grid interval the chord through its
/// ends lies above it (by at most 0.7%: `e^z` over a quarter bends that much); past the
/// grid, `bennett_g` itself (both rounded up by a relative 1e-12, above the rounding of
/// `exp`). Saves the far-field terms of point clouds one exponential each.
#[inline]
pub(crate) fn bennett_g_chord(z: f64) -> f64 {
    if z < G_END {
        let table = &*G_TABLE;
        let u = z.max(0.0) * (1.0 / G_STEP);
        let k = (u as usize).min(G_POINTS - 2);
        let (lo, hi) = (table[k], table[k + 1]);
        lo + (hi - lo) * (u - k as f64)
    } else {
        bennett_g(z) * (1.0 + 1e-12)
    }
}

/// Where a traversal's terms go: the accumulator, with the gradient if `GRAD`, and the
/// terms' slopes along `u`, binned for the free distance, if `SLOPE` (`eval::reach`).
pub(crate) struct Sink<'a, const GRAD: bool, const SLOPE: bool> {
    pub acc: &'a mut Accumulator,
    pub slopes: &'a mut Slopes,
    pub u: DVec3,
    /// Weight of a far-field term per primitive (for its lower bound).
    pub w_ff: f64,
    /// Far-field terms also give their subtrees' lower bounds to the accumulator
    /// (`EvalParams::upper_bound`).
    pub upper: bool,
}

impl<const GRAD: bool, const SLOPE: bool> Sink<'_, GRAD, SLOPE> {
    /// The slope bins follow the accumulator's shift when a term lowers it.
    #[inline]
    fn add_slope(&mut self, m_before: f64, e: f64, a: f64) {
        if self.acc.m < m_before {
            let alpha = self.acc.alpha();
            self.slopes
                .rescale((-alpha * (m_before - self.acc.m)).exp());
        }
        self.slopes.add(e, a);
    }

    /// The far-field term of a subtree with box `min..max` at squared distance `r2 > 0`.
    /// A middle (`other` = its farther child's box, the term at the nearer one's
    /// distance) takes the smaller of the two boxes' slopes along the ray: each child's
    /// distance is at least its own box's linear bound, and the nearer box's distance at
    /// the sample is the smaller, so that line bounds both ahead (`eval::reach`).
    #[inline]
    pub fn far(
        &mut self,
        x: DVec3,
        r2: f64,
        weight: f64,
        (min, max): (DVec3, DVec3),
        other: Option<(DVec3, DVec3)>,
    ) {
        let r = r2.sqrt();
        let m = self.acc.m;
        let slope_other = |u: DVec3| {
            other.map_or(1.0, |(lo, hi)| {
                let v = x - x.clamp(lo, hi);
                let d = v.length();
                if d > 0.0 { v.dot(u) / d } else { -1.0 }
            })
        };
        if GRAD {
            let dir = (x - x.clamp(min, max)) / r;
            let e = self.acc.add_far(r, weight, dir);
            if SLOPE {
                self.add_slope(m, e, dir.dot(self.u).min(slope_other(self.u)));
            }
        } else if SLOPE {
            let a = (x - x.clamp(min, max)).dot(self.u) / r;
            let e = self.acc.add_value_far(r, weight);
            self.add_slope(m, e, a.min(slope_other(self.u)));
        } else {
            self.acc.add_value_far(r, weight);
        }
        self.far_upper(x, weight, (min, max), other);
    }

    /// With `upper`, a far-field subtree's part of the upper bound: every primitive
    /// below lies in the box (the union of a middle's two), within the distance of its
    /// farthest corner, with a weight of at least 1 (`weight` is `n w_ff`).
    #[inline]
    fn far_upper(
        &mut self,
        x: DVec3,
        weight: f64,
        (min, max): (DVec3, DVec3),
        other: Option<(DVec3, DVec3)>,
    ) {
        if self.upper {
            let (lo, hi) = other.map_or((min, max), |(a, b)| (min.min(a), max.max(b)));
            let far_corner = DVec3::select((x - 0.5 * (lo + hi)).cmpge(DVec3::ZERO), lo, hi);
            self.acc
                .far_lower(weight / self.w_ff, (x - far_corner).length());
        }
    }

    /// The far-field term of a subtree of `n` points of weight at most `w` (`weight =
    /// n w`) in the box `bx` at squared distance `r2 > 0` from `x` (closest-box term in
    /// `near`: its squared distance, box and, for a middle, the farther child's box),
    /// from their second moment about the
    /// reference point `c` (`sigma2(u) >= u^T M u`) whose distance to their mean is at
    /// most `lin` (module docs): the moment bound where it is below the box term.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn far_moments(
        &mut self,
        x: DVec3,
        weight: f64,
        bx: (DVec3, DVec3),
        c: DVec3,
        sigma2: impl Fn(DVec3) -> f64,
        lin: f64,
        (r2, near, other): (f64, (DVec3, DVec3), Option<(DVec3, DVec3)>),
    ) {
        let v = x - c;
        let l2 = v.length_squared();
        if l2 > 0.0 {
            let alpha = self.acc.alpha();
            let l = l2.sqrt();
            let u = v * (1.0 / l);
            // The largest u . (q - c) over the box bounds every point's.
            let far_corner = DVec3::select(u.cmpge(DVec3::ZERO), bx.1, bx.0);
            let z = alpha * u.dot(far_corner - c).max(0.0);
            let f = (1.0 + alpha * lin + alpha * alpha * sigma2(u).max(0.0) * bennett_g_chord(z))
                * (1.0 + 1e-9);
            // ln f <= f - 1: where `f - 1 <= alpha (l - r)` the moment term is the smaller.
            let reach = l - (f - 1.0) / alpha;
            if reach >= 0.0 && reach * reach >= r2 {
                self.far_term(l, weight * f, u);
                return;
            }
        }
        self.far(x, r2, weight, near, other);
    }

    /// The far-field term of a subtree from its directional tables
    /// (`primitives::directional`): `exp(-alpha d)` with `d = |x - c| - D / alpha` and
    /// `dir = (x - c) / |x - c|`. For the fixed direction the bound is linear in the
    /// query point, so its slope along the ray is `dir . u` and it holds all along.
    /// Its part of the upper bound is the box's (`weight`, the box and `other` as in
    /// [`Sink::far`]).
    #[inline]
    pub fn far_directional(
        &mut self,
        x: DVec3,
        d: f64,
        dir: DVec3,
        weight: f64,
        bx: (DVec3, DVec3),
        other: Option<(DVec3, DVec3)>,
    ) {
        self.far_term(d, 1.0, dir);
        self.far_upper(x, weight, bx, other);
    }

    /// A far-field term (an upper bound of its subtree's terms, not part of the exact
    /// sum's lower end) at distance `d` with unit direction `dir` (the gradient of `d`,
    /// and its slope along the ray is `dir . u` exactly).
    #[inline]
    fn far_term(&mut self, d: f64, weight: f64, dir: DVec3) {
        let m = self.acc.m;
        if GRAD {
            let e = self.acc.add_far(d, weight, dir);
            if SLOPE {
                self.add_slope(m, e, dir.dot(self.u));
            }
        } else if SLOPE {
            let e = self.acc.add_value_far(d, weight);
            self.add_slope(m, e, dir.dot(self.u));
        } else {
            self.acc.add_value_far(d, weight);
        }
    }

    /// The slope along the ray of an exact term's `-ln(w exp(-alpha d)) / alpha`, from
    /// that of its distance (`a`) and of its log-weight (`l`), in [-1, 1] (`eval::reach`:
    /// to first order; the weight's own slope is `l / alpha`, zero for points).
    #[inline]
    fn term_slope(&self, a: f64, l: f64) -> f64 {
        if l == 0.0 {
            a
        } else {
            (a - l * self.acc.inv_alpha()).clamp(-1.0, 1.0)
        }
    }

    /// The exact terms of a leaf's primitives (at most `leaf_size` of them): in fours
    /// from the primitive's batch where it has one (`Primitive::BATCHED`), else one by
    /// one; added in the same order either way.
    #[inline]
    pub fn exact_leaf<P: Primitive>(&mut self, prims: &[P], x: DVec3, scale: &WeightScale) {
        if !P::BATCHED {
            for prim in prims {
                self.exact(prim, x, scale);
            }
            return;
        }
        for chunk in prims.chunks(4) {
            if GRAD {
                let mut out = [Term::default(); 4];
                P::terms(chunk, x, scale, &mut out);
                for t in &out[..chunk.len()] {
                    self.exact_term(t);
                }
            } else if SLOPE {
                let mut out = [(0.0, 0.0, 0.0, 0.0); 4];
                P::value_slopes(chunk, x, self.u, scale, &mut out);
                for &(d, w, a, l) in &out[..chunk.len()] {
                    self.exact_value_slope(d, w, a, l);
                }
            } else {
                let mut out = [(0.0, 0.0); 4];
                P::values(chunk, x, scale, &mut out);
                for &(d, w) in &out[..chunk.len()] {
                    self.acc.add_value(d, w);
                }
            }
        }
    }

    /// An exact term computed with its gradient (`GRAD`).
    #[inline]
    fn exact_term(&mut self, t: &Term) {
        let m = self.acc.m;
        let e = self.acc.add(t.d, t.w, t.dir, t.grad_w);
        if SLOPE {
            // A zero slope of the weight along the ray (every term at a vertex) gives
            // the distance's slope without the division: `term_slope` of a zero `l`.
            let (a, gu) = (t.dir.dot(self.u), t.grad_w.dot(self.u));
            let a = if gu == 0.0 {
                a
            } else {
                self.term_slope(a, gu / t.w)
            };
            self.add_slope(m, e, a);
        }
    }

    /// An exact term's value and slopes (`SLOPE` without `GRAD`).
    #[inline]
    fn exact_value_slope(&mut self, d: f64, w: f64, a: f64, l: f64) {
        let m = self.acc.m;
        let e = self.acc.add_value(d, w);
        let a = self.term_slope(a, l);
        self.add_slope(m, e, a);
    }

    /// A primitive's exact term.
    #[inline]
    fn exact<P: Primitive>(&mut self, prim: &P, x: DVec3, scale: &WeightScale) {
        if GRAD {
            self.exact_term(&prim.term(x, scale));
        } else if SLOPE {
            let (d, w, a, l) = prim.value_slope(x, self.u, scale);
            self.exact_value_slope(d, w, a, l);
        } else {
            let (d, w) = prim.value(x, scale);
            self.acc.add_value(d, w);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `g(z)` in long arithmetic: its series to convergence (all terms positive).
    fn g_series(z: f64) -> f64 {
        let (mut term, mut sum, mut k) = (0.5f64, 0.0f64, 0.0f64);
        while term > 1e-18 * sum.max(1e-300) || k < 3.0 {
            sum += term;
            k += 1.0;
            term *= z / (k + 2.0);
        }
        sum
    }

    #[test]
    fn bennett_g_chord_bounds_g_from_above_and_stays_close() {
        let mut worst: f64 = 0.0;
        for i in 0..=40_000 {
            let z = i as f64 * 1e-3;
            let g = g_series(z);
            let chord = bennett_g_chord(z);
            assert!(chord >= g, "z {z}: chord {chord} below g {g}");
            assert!(
                bennett_g(z) >= g * (1.0 - 1e-14),
                "z {z}: bennett_g below g"
            );
            worst = worst.max(chord / g - 1.0);
        }
        // Chords of a convex function on steps of 1/4 (g bends like e^z for large z).
        assert!(worst < 7e-3, "chord up to {worst} above g");
        assert!(bennett_g_chord(1e3).is_infinite() && bennett_g_chord(0.0) >= 0.5);
    }
}
