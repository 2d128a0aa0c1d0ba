//! The weighted support of an edge: for a direction `g` and sharpness `alpha`, an upper
//! bound of `max over p of alpha g . p + ln w(p)` over the edge's points `p`, `w(p)` the
//! weight the edge gives a query whose closest point is `p` (SPEC 4, 5). A subtree's
//! terms at `x` are at most `exp(-alpha g . x + D(g))` for `|g| <= 1`, `D` the log-sum of
//! its primitives' weighted supports: a far-field bound that knows both the directions
//! and the weights, convex in `g`, so it can be tabulated on `geometry::directions`'
//! grid (doc/performance-log.md, round twenty-eight, measures what it would buy; the
//! far-field oracle example builds its tables from this).
//!
//! Certain, not sampled: the edge is cut into [`EDGE_PIECES`] pieces; on each, the
//! linear part's largest value is at one of its ends, and the weight quartic `W(t) = c0 +
//! t^2 (c2 + t (c3 + t c4))` peaks at an end or where `W'(t) = t (2 c2 + 3 c3 t + 4 c4
//! t^2)` vanishes inside it. Both are rounded up; the weight is nondecreasing in `W`
//! ([`WeightScale::weight`]).

use super::kinds::Edge;
use super::weights::{WeightScale, edge_quartic, edge_w};
use glam::DVec3;

/// Pieces of an edge: at 32 the bound lies within 0.1-0.25 epsilons of the sampled
/// maximum on the soft full bunny's far-field terms (8 pieces: 0.4-0.8).
pub const EDGE_PIECES: usize = 32;

/// The largest `ln w` over each piece of `e` (computed once per edge).
pub fn edge_piece_log_weights(e: &Edge, scale: &WeightScale) -> [f64; EDGE_PIECES] {
    piece_log_weights(e.val_a, e.val_b, scale)
}

/// The largest `ln w` over each piece of an edge whose ends have valences `val_a` and
/// `val_b` (the weight knows nothing else of the edge).
pub fn piece_log_weights(val_a: f32, val_b: f32, scale: &WeightScale) -> [f64; EDGE_PIECES] {
    let c = edge_quartic(1.0 / val_a as f64, 1.0 / val_b as f64);
    let w = |t: f64| edge_w(t, c).0;
    // The roots of W'(t) / t = 4 c4 t^2 + 3 c3 t + 2 c2.
    let (qa, qb, qc) = (4.0 * c[3], 3.0 * c[2], 2.0 * c[1]);
    // In the form that loses no digits to cancellation (`q / qa` and `qc / q`).
    let mut roots = [f64::NAN; 2];
    let disc = qb * qb - 4.0 * qa * qc;
    if qa != 0.0 && disc >= 0.0 {
        let q = -0.5 * (qb + qb.signum() * disc.sqrt());
        roots = [q / qa, if q != 0.0 { qc / q } else { f64::NAN }];
    } else if qa == 0.0 && qb != 0.0 {
        roots[0] = -qc / qb;
    }
    std::array::from_fn(|k| {
        let (t0, t1) = (
            k as f64 / EDGE_PIECES as f64,
            (k + 1) as f64 / EDGE_PIECES as f64,
        );
        // A root just outside the piece by rounding still bounds it: the ends and any
        // root within a hair of them are all taken.
        let hair = 1e-9;
        let peak = roots
            .iter()
            .filter(|r| **r > t0 - hair && **r < t1 + hair)
            .map(|&r| w(r.clamp(0.0, 1.0)))
            .fold(w(t0).max(w(t1)), f64::max);
        let raw = peak * (1.0 + 1e-12) + 1e-15;
        scale.weight(raw).ln() * (1.0 + 1e-12) + 1e-15
    })
}

/// An edge's weight split into its ends' weight and the bump above it inside the edge:
/// `(ln w_E, b)` with `w_E` the larger of the weights at its two ends (the weight wherever
/// the closest point is an end) and `b >= 0` such that `w_E + b` is at least the weight
/// anywhere inside the edge (from the pieces' certain maxima, [`piece_log_weights`]).
/// `ln w_E` is rounded up; `b` covers the rest of the rounding.
pub fn edge_split(val_a: f32, val_b: f32, scale: &WeightScale) -> (f64, f64) {
    let c = edge_quartic(1.0 / val_a as f64, 1.0 / val_b as f64);
    let raw = edge_w(0.0, c).0.max(edge_w(1.0, c).0);
    let w_e = scale.weight(raw * (1.0 + 1e-12) + 1e-15);
    let peak = piece_log_weights(val_a, val_b, scale)
        .into_iter()
        .fold(f64::NEG_INFINITY, f64::max)
        .exp()
        * (1.0 + 1e-12);
    (w_e.ln() * (1.0 + 1e-12) + 1e-15, (peak - w_e).max(0.0))
}

/// The weighted support of `e` in direction `g` (any length) at sharpness `alpha`, from
/// its pieces' log-weights ([`edge_piece_log_weights`]): at least `alpha g . p + ln w(p)`
/// at every point `p` of the edge.
pub fn edge_weighted_support(
    e: &Edge,
    g: DVec3,
    alpha: f64,
    log_weights: &[f64; EDGE_PIECES],
) -> f64 {
    let (a, b) = (e.a.as_dvec3(), e.b.as_dvec3());
    let (ga, gd) = (alpha * g.dot(a), alpha * g.dot(b - a));
    let mut best = f64::NEG_INFINITY;
    let mut lin0 = ga;
    for (k, lw) in log_weights.iter().enumerate() {
        let lin1 = ga + gd * ((k + 1) as f64 / EDGE_PIECES as f64);
        best = best.max(lin0.max(lin1) + lw);
        lin0 = lin1;
    }
    // The products' rounding, relative to their size.
    best + 1e-12 * (ga.abs() + gd.abs() + 1.0)
}

/// [`edge_weighted_support`] for every edge of one pair of end valences, faster: with
/// `s = alpha g . (b - a)` the support is `alpha g . a + H(s)`, `H(s) = max_k lw_k + s
/// t_k` with `t_k` the end of piece `k` that lies farther along `s` (its far end for `s >=
/// 0`, its near end below). Each half keeps only the lines that are largest somewhere on
/// it: those of larger slope (in `|s|`) than the line largest at `s = 0`, and of those the
/// upper hull.
#[derive(Clone, Debug)]
pub struct SupportEnvelope {
    /// `(slope, intercept)` of the lines for `s >= 0`.
    rising: Vec<(f64, f64)>,
    /// The same for `s < 0`.
    falling: Vec<(f64, f64)>,
}

impl SupportEnvelope {
    /// The envelope of the pieces' log-weights ([`piece_log_weights`]).
    pub fn new(log_weights: &[f64; EDGE_PIECES]) -> SupportEnvelope {
        let t = |k: usize| k as f64 / EDGE_PIECES as f64;
        let rising = (0..EDGE_PIECES).map(|k| (t(k + 1), log_weights[k]));
        // For `s < 0` the lines in `-s` (slope `-t_k`), so that both halves are hulls
        // over `[0, inf)`; flipped back below.
        let falling = (0..EDGE_PIECES).map(|k| (-t(k), log_weights[k]));
        SupportEnvelope {
            rising: half_hull(rising.collect()),
            falling: half_hull(falling.collect())
                .into_iter()
                .map(|(m, b)| (-m, b))
                .collect(),
        }
    }

    /// At least [`edge_weighted_support`] of `e` in direction `g` at sharpness `alpha`
    /// (the same value up to rounding), for an edge of this envelope's valences.
    pub fn support(&self, e: &Edge, g: DVec3, alpha: f64) -> f64 {
        self.supports(e, &[g], alpha)[0]
    }

    /// [`SupportEnvelope::support`] in each of the directions `g` (written to run a line
    /// at a time over all directions).
    #[inline]
    pub fn supports<const N: usize>(&self, e: &Edge, g: &[DVec3; N], alpha: f64) -> [f64; N] {
        let a = e.a.as_dvec3();
        let d = e.b.as_dvec3() - a;
        let ga: [f64; N] = std::array::from_fn(|k| alpha * g[k].dot(a));
        let gd: [f64; N] = std::array::from_fn(|k| alpha * g[k].dot(d));
        // Both halves everywhere (no branch in the loops), then each direction's half.
        let half = |lines: &[(f64, f64)]| {
            let mut h = [f64::NEG_INFINITY; N];
            for &(m, b) in lines {
                for k in 0..N {
                    let v = b + m * gd[k];
                    h[k] = if v > h[k] { v } else { h[k] };
                }
            }
            h
        };
        let (rising, falling) = (half(&self.rising), half(&self.falling));
        let h: [f64; N] =
            std::array::from_fn(|k| if gd[k] >= 0.0 { rising[k] } else { falling[k] });
        // The products' rounding, relative to their size.
        std::array::from_fn(|k| rounded_up(ga[k], gd[k], h[k]))
    }

    /// [`SupportEnvelope::supports`] in the directions `g` and in their opposites `-g`, in
    /// half the work: `-g` gives `-g . a` and `-g . d` exactly, so each pair needs one
    /// half's lines at `|g . d|` and the other's at `-|g . d|` (the same values as
    /// `supports` over both, bit for bit).
    #[inline]
    pub fn supports_antipodal<const N: usize>(
        &self,
        e: &Edge,
        g: &[DVec3; N],
        alpha: f64,
    ) -> ([f64; N], [f64; N]) {
        let a = e.a.as_dvec3();
        let d = e.b.as_dvec3() - a;
        let ga: [f64; N] = std::array::from_fn(|k| alpha * g[k].dot(a));
        let gd: [f64; N] = std::array::from_fn(|k| alpha * g[k].dot(d));
        let half = |lines: &[(f64, f64)], sign: f64| {
            let mut h = [f64::NEG_INFINITY; N];
            for &(m, b) in lines {
                for k in 0..N {
                    let v = b + m * (sign * gd[k].abs());
                    h[k] = if v > h[k] { v } else { h[k] };
                }
            }
            h
        };
        let (rising, falling) = (half(&self.rising, 1.0), half(&self.falling, -1.0));
        // `supports` takes the rising half where `g . d >= 0` (-0 included), the falling
        // one elsewhere; for `-g` the same test on `-(g . d)`.
        let pick = |gd: f64, k: usize| if gd >= 0.0 { rising[k] } else { falling[k] };
        (
            std::array::from_fn(|k| rounded_up(ga[k], gd[k], pick(gd[k], k))),
            std::array::from_fn(|k| rounded_up(-ga[k], -gd[k], pick(-gd[k], k))),
        )
    }
}

/// A support `g . a + h` (scaled by `alpha`), rounded up past the products' rounding,
/// relative to their size.
#[inline(always)]
fn rounded_up(ga: f64, gd: f64, h: f64) -> f64 {
    ga + h + 1e-12 * (ga.abs() + gd.abs() + h.abs() + 1.0)
}

/// The lines `(slope, intercept)` that are largest somewhere on `s >= 0`, slopes
/// ascending: none of smaller slope than the largest at 0, then the upper hull. A line
/// is dropped only when the others lie above it by more than rounding everywhere.
fn half_hull(mut lines: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    lines.sort_by(|p, q| p.0.total_cmp(&q.0).then(p.1.total_cmp(&q.1)));
    // The largest at 0 (the steepest of equal intercepts) and the steeper lines.
    let top = lines.iter().enumerate().fold(
        0,
        |best, (k, l)| if l.1 >= lines[best].1 { k } else { best },
    );
    let mut hull: Vec<(f64, f64)> = Vec::new();
    for &l in &lines[top..] {
        // Of equal slopes the last (largest intercept) stays.
        if hull.last().is_some_and(|h| h.0 == l.0) {
            hull.pop();
        }
        // The middle of the last two is dropped when the outer two meet above it.
        while hull.len() >= 2 {
            let (p, q) = (hull[hull.len() - 2], hull[hull.len() - 1]);
            let above = (l.1 - p.1) * (q.0 - p.0) - (q.1 - p.1) * (l.0 - p.0);
            let tolerance = 1e-12 * (p.1.abs() + q.1.abs() + l.1.abs() + 1.0);
            if above > tolerance {
                hull.pop();
            } else {
                break;
            }
        }
        hull.push(l);
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::uniform;
    use glam::Vec3;

    /// An edge with ends in the cube `[-1, 1]^3` and valences 1-12 and 1-7 by `case`.
    fn random_edge(r: &mut impl FnMut() -> f64, case: usize) -> Edge {
        let mut v = || Vec3::new(r() as f32, r() as f32, r() as f32) * 2.0 - Vec3::ONE;
        Edge {
            a: v(),
            b: v(),
            val_a: (1 + case % 12) as f32,
            val_b: (1 + (case / 12) % 7) as f32,
        }
    }

    #[test]
    fn the_bound_covers_every_point_and_stays_close() {
        let mut r = uniform(17);
        let mut worst_gap: f64 = 0.0;
        for case in 0..400 {
            let e = random_edge(&mut r, case);
            let (max_adj, alpha) = (12.0, 1.0 + 200.0 * r());
            let scale = WeightScale::new(max_adj, alpha, 100.0 + 200.0 * r());
            let lw = edge_piece_log_weights(&e, &scale);
            let g = DVec3::new(r() - 0.5, r() - 0.5, r() - 0.5) * 2.6;
            let bound = edge_weighted_support(&e, g, alpha, &lw);
            let (a, b) = (e.a.as_dvec3(), e.b.as_dvec3());
            let c = edge_quartic(1.0 / e.val_a as f64, 1.0 / e.val_b as f64);
            let sampled = (0..=4000)
                .map(|i| i as f64 / 4000.0)
                .map(|t| alpha * g.dot(a + (b - a) * t) + scale.weight(edge_w(t, c).0).ln())
                .fold(f64::NEG_INFINITY, f64::max);
            assert!(
                bound >= sampled,
                "case {case}: bound {bound} below {sampled}"
            );
            // Within a piece's spread of the linear part (and the weight's).
            let spread = (alpha * g.dot(b - a)).abs() / EDGE_PIECES as f64;
            worst_gap = worst_gap.max((bound - sampled) / (spread + 0.05));
        }
        assert!(
            worst_gap <= 1.0,
            "the bound runs {worst_gap} pieces' spread above"
        );
    }

    /// The envelope gives the pieces' support, with fewer lines.
    #[test]
    fn the_envelope_matches_the_pieces() {
        let mut r = uniform(29);
        let mut lines = 0;
        for case in 0..600 {
            let e = random_edge(&mut r, case);
            let alpha = 1.0 + 300.0 * r();
            let scale = WeightScale::new(12.0, alpha, 50.0 + 200.0 * r());
            let lw = edge_piece_log_weights(&e, &scale);
            let env = SupportEnvelope::new(&lw);
            lines += env.rising.len() + env.falling.len();
            for _ in 0..8 {
                let g = DVec3::new(r() - 0.5, r() - 0.5, r() - 0.5) * 2.6;
                let pieces = edge_weighted_support(&e, g, alpha, &lw);
                let fast = env.support(&e, g, alpha);
                let size = 1e-11 * (pieces.abs() + alpha * 4.0 + 1.0);
                assert!(
                    fast >= pieces && fast <= pieces + size,
                    "case {case}: envelope {fast} against the pieces' {pieces}"
                );
            }
        }
        assert!(
            lines < 600 * EDGE_PIECES,
            "{lines} lines kept of {}",
            1200 * EDGE_PIECES
        );
    }

    /// A direction and its opposite at once give `supports`' bits for both, including
    /// directions at right angles to the edge (`g . d` of either sign of zero), and the
    /// support at 0 is the same for every edge of one envelope.
    #[test]
    fn opposite_directions_at_once_match_one_by_one() {
        let mut r = uniform(31);
        for case in 0..400 {
            let e = random_edge(&mut r, case);
            let alpha = 1.0 + 300.0 * r();
            let scale = WeightScale::new(12.0, alpha, 50.0 + 200.0 * r());
            let env = SupportEnvelope::new(&edge_piece_log_weights(&e, &scale));
            let d = (e.b - e.a).as_dvec3();
            let mut g: [DVec3; 5] =
                std::array::from_fn(|_| DVec3::new(r() - 0.5, r() - 0.5, r() - 0.5) * 2.6);
            // At right angles to the edge (`g . d` zero), and 0 with a negative zero.
            g[3] = d.any_orthonormal_vector();
            g[4] = DVec3::new(0.0, -0.0, 0.0);
            let (plus, minus) = env.supports_antipodal(&e, &g, alpha);
            let one = env.supports(&e, &g, alpha);
            let other = env.supports(&e, &g.map(|v| -v), alpha);
            for k in 0..5 {
                assert_eq!(plus[k].to_bits(), one[k].to_bits(), "case {case} dir {k}");
                assert_eq!(
                    minus[k].to_bits(),
                    other[k].to_bits(),
                    "case {case} -dir {k}"
                );
            }
            // At 0 the support is the envelope's alone: any edge of these valences gives
            // its bits (the tables take it once per pair of valences).
            let twin = Edge {
                val_a: e.val_a,
                val_b: e.val_b,
                ..random_edge(&mut r, case)
            };
            assert_eq!(
                env.supports(&e, &[DVec3::ZERO], alpha)[0].to_bits(),
                env.supports(&twin, &[DVec3::ZERO], alpha)[0].to_bits(),
                "case {case}: at 0"
            );
        }
    }
}
