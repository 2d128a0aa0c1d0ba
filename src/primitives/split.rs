//! An edge set's weights split into its ends' weight and the bump inside each edge: a
//! far-field bound that knows where the closest points lie (SPEC 4, 6;
//! doc/performance-log.md, round thirty-five).
//!
//! The directional tables (`primitives::directional`) charge an edge, from any
//! direction, the largest weight anywhere on it. But an edge's weight rises inside it
//! (the quartic of SPEC 4 peaks between the ends, 5-6 times the ends' weight at the
//! valences of a dense mesh), and a query far from an edge almost always finds its
//! closest point at an end: only where `x` projects inside the edge, `0 < (x - a) . (b -
//! a) < |b - a|^2`, can its term weigh more than its ends do. So each edge's weight is
//! split (`primitives::support::edge_split`) into
//! - its ends' weight `w_E`, the larger of the weights at `a` and `b`: every term is at
//!   most `w_E exp(-alpha d)` where the closest point is an end. Constant along the
//!   edge, its weighted support in direction `g` is `max(alpha g . a, alpha g . b) + ln
//!   w_E`, tabulated per entry of the wide tree as the directional tables are (the
//!   *ends' table*, read by `DirectionalTables::bounds`);
//! - its bump `b >= 0`, with `w_E + b` at least the weight anywhere inside the edge
//!   (from the certain maxima of `primitives::support`'s pieces).
//!
//! For an entry with centre `c` at distance `l = |x - c|` along `u = (x - c) / l`, every
//! term is at most `w exp(-alpha u . (x - p))` for any point `p` of its edge, so the
//! entry's terms sum to at most `exp(-alpha l) (exp(D_E(u)) + sum_inside b
//! exp(alpha s(u)))`, `D_E` the ends' table and `s(u) = max(u . (a - c), u . (b - c))`
//! over the edges that `x` projects inside: the *split bound*, `ln` of the bracket
//! ([`SplitTables::bound`]). Which edges those are takes a test per edge: their slabs
//! (`lanes::Slabs`, four edges at a time) hold each edge's midpoint `m` and `n = (b - a)
//! / |b - a|^2`, and `x` projects inside exactly where `|n . (x - m)| < 1/2`. The test
//! counts an edge as inside below `1/2 + 1e-9`; its rounding stays below `1e-9` while
//! `|n| |x - m| <= ` [`REACH_MAX`], checked once per bound (beyond it the bound is not
//! taken). A test costs a fraction of a term, so entries of at most [`MAX_EDGES`] edges
//! take it.

use super::kinds::Edge;
use super::lanes::Slabs;
use crate::bvh::Node4;
use crate::bvh::moments::MIDDLE;
use crate::bvh::wide::EMPTY;
use glam::DVec3;

/// The split bound is taken for entries of at most this many edges (module docs).
pub const MAX_EDGES: usize = 32;

/// Largest `|n| |x - m|` at which the projections' rounding (about `1e-15` of it) stays
/// below the test's margin of `1e-9` (module docs).
pub const REACH_MAX: f64 = 1e5;

/// An edge counts as inside where its projection is below this in size.
const INSIDE: f64 = 0.5 + 1e-9;

/// An edge set's split: its bumps, its slabs, where each wide node's edges start, and
/// the ends' table (read by `DirectionalTables`).
#[derive(Debug)]
pub struct SplitTables {
    /// The ends' weight's table, in `DirectionalTables`' layout.
    pub(super) ends: Vec<f32>,
    /// Per edge, in the tree's order: its bump above its ends' weight.
    bumps: Vec<f64>,
    /// Per edge: `|b - a|^2`.
    len2: Vec<f64>,
    slabs: Slabs,
    /// Per wide node: its first edge.
    first: Vec<u32>,
    /// The centre of the edges' box, and the squared distance from it within which
    /// `|n| |x - m| <= REACH_MAX` for every edge: `|x - m|` is at most `|x - centre|`
    /// plus the box's half diagonal, `|n|` at most the largest.
    centre: DVec3,
    reach2: f64,
}

/// The weighted support of an edge of constant log-weight `ln_w` in each of the
/// directions `g` at sharpness `alpha`: `max(alpha g . a, alpha g . b) + ln_w`, rounded
/// up.
pub fn ends_supports<const N: usize>(e: &Edge, ln_w: f64, g: &[DVec3; N], alpha: f64) -> [f64; N] {
    let (a, b) = (e.a.as_dvec3(), e.b.as_dvec3());
    std::array::from_fn(|k| {
        let (ga, gb) = (alpha * g[k].dot(a), alpha * g[k].dot(b));
        ga.max(gb) + ln_w + 1e-12 * (ga.abs() + gb.abs() + ln_w.abs() + 1.0)
    })
}

impl SplitTables {
    /// The split of `prims` (in the tree's order; per edge `(ln w_E, b)` from
    /// `support::edge_split`) over the wide nodes `wide`, with its ends' table `ends`.
    pub fn new(prims: &[Edge], wide: &[Node4], splits: &[(f64, f64)], ends: Vec<f32>) -> Self {
        let mut slabs = Slabs::default();
        let mut len2 = Vec::with_capacity(prims.len());
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        let mut n_max: f64 = 0.0;
        for e in prims {
            let (a, b) = (e.a.as_dvec3(), e.b.as_dvec3());
            let (m, ab) = (0.5 * (a + b), b - a);
            let l2 = ab.length_squared();
            let n = if l2 > 0.0 { ab / l2 } else { DVec3::ZERO };
            for k in 0..3 {
                slabs.m[k].push(m[k]);
                slabs.n[k].push(n[k]);
            }
            len2.push(l2);
            n_max = n_max.max(n.length());
            (lo, hi) = (lo.min(a.min(b)), hi.max(a.max(b)));
        }
        let reach = (REACH_MAX / n_max - 0.5 * (hi - lo).length()).max(0.0);
        SplitTables {
            ends,
            bumps: splits.iter().map(|s| s.1).collect(),
            len2,
            slabs,
            first: first_primitives(wide),
            centre: 0.5 * (lo + hi),
            reach2: reach * reach,
        }
    }

    /// The edges below entry `e` (a slot, or a middle: `bvh::MIDDLE`) of `node`, as a
    /// range of the tree's order.
    #[inline(always)]
    pub fn range(&self, node: &Node4, e: usize) -> std::ops::Range<usize> {
        let first_of = |k: usize| match node.count[k] {
            0 => self.first[node.child[k] as usize] as usize,
            _ => node.child[k] as usize,
        };
        let (first, n) = if e < MIDDLE {
            (first_of(e), node.size[e])
        } else {
            (first_of(2 * (e - MIDDLE)), node.mid_size[e - MIDDLE])
        };
        first..first + n as usize
    }

    /// The split bound (module docs) of the edges of `range` at `x`, for an entry with
    /// centre `c` at distance `l > 0` whose ends' table gives `d_ends`, as the log of the
    /// weight by which `exp(-alpha l)` is multiplied; `d` (a bound it would replace)
    /// where it would not be below `d`, where the entry holds more than [`MAX_EDGES`]
    /// edges, or beyond [`REACH_MAX`].
    #[inline]
    pub fn bound(
        &self,
        range: std::ops::Range<usize>,
        x: DVec3,
        (c, l): (DVec3, f64),
        (d_ends, d): (f64, f64),
        alpha: f64,
    ) -> f64 {
        if d_ends >= d
            || range.len() > MAX_EDGES
            || (x - self.centre).length_squared() > self.reach2
        {
            return d;
        }
        let u = (x - c) / l;
        let shift = alpha * u.dot(c) + d_ends;
        // The bumps may add up to `exp(d - d_ends) - 1` before the bound reaches `d`
        // (found at the first edge inside: most entries have none).
        let mut room = f64::NAN;
        let mut sum = 0.0;
        let slabs = &self.slabs;
        let below = slabs.scan(range, x, INSIDE, |k| {
            // `max(u . a, u . b)` from the midpoint and half the edge, and the
            // rounding of both.
            let (um, un) = (
                u.x * slabs.m[0][k] + u.y * slabs.m[1][k] + u.z * slabs.m[2][k],
                u.x * slabs.n[0][k] + u.y * slabs.n[1][k] + u.z * slabs.n[2][k],
            );
            let s = um + 0.5 * un.abs() * self.len2[k];
            let margin = 1e-12 * (alpha * (um.abs() + self.len2[k].sqrt()) + shift.abs() + 1.0);
            sum += self.bumps[k] * (alpha * s - shift + margin).exp();
            if room.is_nan() {
                room = (d - d_ends).exp_m1();
            }
            sum < room
        });
        match (below, sum) {
            (false, _) => d,
            (true, 0.0) => d_ends,
            (true, _) => d_ends + sum.ln_1p() + 1e-12 * (d_ends.abs() + 1.0),
        }
    }
}

/// Each wide node's first primitive (its slots' primitives follow one another in the
/// tree's order).
fn first_primitives(wide: &[Node4]) -> Vec<u32> {
    let mut first = vec![u32::MAX; wide.len()];
    // Depth-first layout: a child's index is above its parent's.
    for i in (0..wide.len()).rev() {
        let node = &wide[i];
        first[i] = (0..4)
            .filter(|&k| node.count[k] != EMPTY)
            .map(|k| match node.count[k] {
                0 => first[node.child[k] as usize],
                _ => node.child[k],
            })
            .min()
            .unwrap_or(u32::MAX);
    }
    first
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::support::edge_split;
    use crate::primitives::weights::WeightScale;
    use crate::primitives::weights::{edge_quartic, edge_w};
    use crate::testing::uniform;
    use glam::Vec3;

    /// `w_E` is at least the weight at both ends, `w_E + b` at least the weight anywhere
    /// inside, at every pair of valences of a dense mesh and beyond.
    #[test]
    fn the_split_covers_the_weight_along_the_edge() {
        for (alpha, max_alpha) in [(20.0, 40.0), (150.0, 100.0), (1000.0, 2000.0)] {
            let scale = WeightScale::new(14.0, alpha, max_alpha);
            for val_a in 1..=14 {
                for val_b in 1..=14 {
                    let (ln_w, b) = edge_split(val_a as f32, val_b as f32, &scale);
                    let c = edge_quartic(1.0 / val_a as f64, 1.0 / val_b as f64);
                    let w = |t: f64| scale.weight(edge_w(t, c).0);
                    assert!(ln_w >= w(0.0).ln() && ln_w >= w(1.0).ln());
                    let peak = (0..=2000).map(|i| w(i as f64 / 2000.0)).fold(0.0, f64::max);
                    assert!(ln_w.exp() + b >= peak, "{val_a} {val_b}: {ln_w} {b} {peak}");
                    assert!(b >= 0.0);
                }
            }
        }
    }

    /// The slabs' scan, on AVX where there is and in scalar code, hands on exactly the
    /// edges that `x` projects inside (points off the slabs' faces), in order, for
    /// ranges of every length and start, and stops where asked to.
    #[test]
    fn the_scan_finds_the_edges_x_projects_inside() {
        let mut r = uniform(41);
        let mut v = || Vec3::new(r() as f32, r() as f32, r() as f32);
        let prims: Vec<Edge> = (0..61)
            .map(|_| {
                let a = v();
                Edge {
                    a,
                    b: a + (v() - Vec3::splat(0.5)) * 0.6,
                    val_a: 3.0,
                    val_b: 5.0,
                }
            })
            .collect();
        let splits = vec![(0.0, 1.0); prims.len()];
        let split = SplitTables::new(&prims, &[], &splits, Vec::new());
        let mut seen_inside = 0;
        for q in 0..50 {
            let x = v().as_dvec3() * 1.4 - DVec3::splat(0.2);
            for (start, end) in [(0, 61), (3, 10), (5, 6), (17, 17), (20, 59)] {
                let want: Vec<usize> = (start..end)
                    .filter(|&k| {
                        let (a, b) = (prims[k].a.as_dvec3(), prims[k].b.as_dvec3());
                        let t = (x - a).dot(b - a) / (b - a).length_squared();
                        assert!(
                            (t.abs() > 1e-6) && ((t - 1.0).abs() > 1e-6),
                            "point {q} on a face"
                        );
                        t > 0.0 && t < 1.0
                    })
                    .collect();
                let (mut got, mut scalar) = (Vec::new(), Vec::new());
                assert!(split.slabs.scan(start..end, x, INSIDE, |k| {
                    got.push(k);
                    true
                }));
                assert!(split.slabs.scan_scalar(start..end, x, INSIDE, |k| {
                    scalar.push(k);
                    true
                }));
                assert_eq!(got, want, "point {q}, edges {start}..{end}");
                assert_eq!(scalar, want, "point {q}, edges {start}..{end}, scalar");
                seen_inside += got.len();
                // Stopped at the first edge inside.
                let mut first = None;
                let all = split.slabs.scan(start..end, x, INSIDE, |k| {
                    first = Some(k);
                    false
                });
                assert_eq!((all, first), (want.is_empty(), want.first().copied()));
            }
        }
        assert!(seen_inside > 100, "{seen_inside} edges inside");
    }
}
