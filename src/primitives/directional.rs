//! Tables of a far-field bound that knows directions and weights, for the slots and
//! middles of an edge or triangle set's wide tree (doc/performance-log.md, rounds
//! twenty-eight and twenty-nine). A rendered object's edge and triangle sets carry them
//! (`render::object`), and the walk takes the smaller of a far term's box bound and
//! theirs (`eval::walk`), in the upper bound's walk too (its far terms' lower bounds stay
//! the boxes').
//!
//! For an entry (slot or middle) with box centre `c` and the primitives `T` below it, and
//! any unit `u`, each term is at most `exp(-alpha u . (x - c) + alpha s_T(u))` with `s_T`
//! the weighted support about `c` (`primitives::support`,
//! `primitives::triangle_support`), so the entry's terms sum to at most `exp(-alpha |x -
//! c| + D(u))` for `u = (x - c) / |x - c|`, `D(u) = ln sum_T
//! exp(alpha s_T(u))`. `D` is convex, and `geometry::directions` bounds it between its
//! values at the grid's scaled directions and at 0, which the table holds (rounded up to
//! f32). The values are summed about the origin up the tree by log-sum-exp and moved to
//! each entry's centre at the end: `alpha s_T(v)` about `c` is the value about the origin
//! minus `alpha v . c`.
//!
//! An edge set's tables also carry a second table of the same layout, its ends' weight's,
//! with what a far term needs to add the bumps inside the edges `x` projects inside
//! (`primitives::split`, round thirty-five): the walk takes that split bound where it is
//! the smaller.

use super::kinds::{Edge, Triangle};
use super::split::{SplitTables, ends_supports};
use super::support::{SupportEnvelope, edge_split, piece_log_weights};
use super::triangle_support::TriangleLattice;
use super::weights::WeightScale;
use crate::bvh::Node4;
use crate::bvh::moments::MIDDLE;
use crate::bvh::wide::EMPTY;
use crate::geometry::directions::{DirectionGrid, distinct_directions};
use glam::DVec3;
use rustc_hash::FxHashMap;

/// Entries per wide node: four slots, two middles (`bvh::MIDDLE`).
const ENTRIES: usize = 6;

/// The grid's side: `GRID * GRID` points (`geometry::directions`), 18 distinct
/// directions.
const GRID: usize = 5;

/// Values per entry: the grid's distinct directions, then the direction 0.
const VALUES: usize = distinct_directions(GRID) + 1;

/// The grid's directions in opposite pairs (`DirectionGrid::antipodal_pairs`).
const PAIRS: usize = (VALUES - 1) / 2;

/// An entry's values, before rounding to f32.
type Table = [f64; VALUES];

/// An edge set's tables at one `alpha`.
#[derive(Debug)]
pub struct DirectionalTables {
    pub grid: DirectionGrid,
    pub alpha: f64,
    /// The weights' attenuation exponent the tables were built with.
    pub q: f64,
    /// Per wide node and entry, the grid's values then the value at 0.
    values: Vec<f32>,
    /// Edges: their weights split into the ends' and the bumps (`primitives::split`).
    split: Option<SplitTables>,
}

/// Per value, `ln sum exp` over the tables, shifted by the largest (`-inf` for none);
/// rounded as well as [`lse`], up to a relative `tables.len() * 1e-16`. A value at a
/// time over all the tables, so the exponentials run side by side ([`exp_nonpositive`]).
fn log_sum_exp(tables: &[Table]) -> Table {
    #[cfg(target_arch = "x86_64")]
    if super::lanes::available_avx2() {
        // SAFETY: `lanes::available_avx2` found AVX2 on this CPU.
        return unsafe { log_sum_exp_avx2(tables) };
    }
    log_sum_exp_any(tables)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn log_sum_exp_avx2(tables: &[Table]) -> Table {
    log_sum_exp_any(tables)
}

#[inline(always)]
fn log_sum_exp_any(tables: &[Table]) -> Table {
    let mut m = [f64::NEG_INFINITY; VALUES];
    for t in tables {
        for d in 0..VALUES {
            m[d] = m[d].max(t[d]);
        }
    }
    let mut sum = [0.0; VALUES];
    for t in tables {
        for d in 0..VALUES {
            sum[d] += exp_nonpositive(t[d] - m[d]);
        }
    }
    std::array::from_fn(|d| {
        if m[d] == f64::NEG_INFINITY {
            m[d]
        } else {
            m[d] + sum[d].ln()
        }
    })
}

/// `1 / k!` for `k = 0 .. N` (each `k!` exact in f64 to `k = 22`, so each quotient is
/// correctly rounded).
const fn inverse_factorials<const N: usize>() -> [f64; N] {
    let mut c = [0.0; N];
    let mut f = 1.0;
    let mut k = 0;
    while k < N {
        if k > 0 {
            f *= k as f64;
        }
        c[k] = 1.0 / f;
        k += 1;
    }
    c
}

/// `exp(x)` for `x <= 0`, within 2 ulp of the exact value, without a branch or a call,
/// so that a loop over many of them runs in vector lanes (the tables' build spent a
/// quarter of its time in libm's `exp`): `2^k p(r)` with `k = round(x / ln 2)`, `r = x -
/// k ln 2` (ln 2 in two parts, the first exact times any `k` here) and `p` the Taylor
/// series of `exp` to degree 13 (`|r| <= ln 2 / 2`: remainder below 5e-18). Below -708,
/// where the result would be subnormal (at most 3.3e-308), and at `-inf` it gives 0; a
/// NaN stays NaN. (The tables are rounded up by far more than such a term,
/// `DirectionalTables::build`.)
#[inline(always)]
fn exp_nonpositive(x: f64) -> f64 {
    // 1.5 * 2^52: adding it rounds to an integer, kept in the low bits.
    const ROUND: f64 = 6_755_399_441_055_744.0;
    const LN2_HI: f64 = 0.693_147_180_369_123_8;
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    let low = x < -708.0;
    let xc = if low { -708.0 } else { x };
    let y = xc * std::f64::consts::LOG2_E + ROUND;
    let k = y - ROUND;
    let r = (xc - k * LN2_HI) - k * LN2_LO;
    const C: [f64; 14] = inverse_factorials();
    let mut p = C[13];
    for c in C[..13].iter().rev() {
        p = p * r + c;
    }
    // k in [-1022, 0]: 2^k from its biased exponent.
    let bits = (y.to_bits().wrapping_sub(ROUND.to_bits()) as i64 + 1023) << 52;
    let v = p * f64::from_bits(bits as u64);
    if low { 0.0 } else { v }
}

/// The distinct pairs of valences (`valences(p)`) among `prims`: the first primitive with
/// each pair, in order of first appearance, and each primitive's index into that list.
/// (Keyed by the valences' bits with rustc's hasher: a hundred thousand primitives with
/// a few dozen keys, where SipHash's resistance to chosen keys buys nothing.)
fn valence_pairs<P>(prims: &[P], valences: impl Fn(&P) -> (f32, f32)) -> (Vec<usize>, Vec<u32>) {
    let mut pairs: FxHashMap<(u32, u32), u32> = FxHashMap::default();
    let mut firsts = Vec::new();
    let index = prims
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let (a, b) = valences(p);
            *pairs.entry((a.to_bits(), b.to_bits())).or_insert_with(|| {
                firsts.push(i);
                firsts.len() as u32 - 1
            })
        })
        .collect();
    (firsts, index)
}

/// `ln(e^a + e^b)`, exact for infinities.
pub fn lse(a: f64, b: f64) -> f64 {
    let m = a.max(b);
    if m == f64::NEG_INFINITY {
        m
    } else {
        m + exp_nonpositive(a.min(b) - m).ln_1p()
    }
}

/// The centre of entry `e` of `node` (a middle's: of its two slots' union; a middle that
/// is a leaf in its slot: that slot's).
pub fn entry_centre(node: &Node4, e: usize) -> DVec3 {
    let slot = |k: usize| node.slot_box(k);
    let (lo, hi) = if e < MIDDLE {
        slot(e)
    } else {
        let j = e - MIDDLE;
        let (a, b) = (slot(2 * j), slot(2 * j + 1));
        if node.count[2 * j + 1] == EMPTY {
            a
        } else {
            (a.0.min(b.0), a.1.max(b.1))
        }
    };
    0.5 * (lo + hi)
}

impl DirectionalTables {
    /// The tables of an edge set at sharpness `alpha` (weights by `scale`): `prims` are
    /// the edges in the tree's order and `wide` its nodes.
    pub fn for_edges(prims: &[Edge], wide: &[Node4], alpha: f64, scale: &WeightScale) -> Self {
        // One envelope and one split (`support::edge_split`) per pair of end valences.
        let (firsts, pair_of) = valence_pairs(prims, |e| (e.val_a, e.val_b));
        let envelopes: Vec<SupportEnvelope> = firsts
            .iter()
            .map(|&i| {
                let e = &prims[i];
                SupportEnvelope::new(&piece_log_weights(e.val_a, e.val_b, scale))
            })
            .collect();
        // The grid's directions come in opposite pairs (every one, at `GRID` 5:
        // `DirectionGrid::antipodal_pairs`): the envelope takes each pair at once
        // (`SupportEnvelope::supports_antipodal`), and the direction 0 apart.
        let grid = DirectionGrid::new(GRID);
        let pairs = grid.antipodal_pairs();
        assert_eq!(
            2 * pairs.len() + 1,
            VALUES,
            "the direction grid's opposite pairs"
        );
        let pairs: [(usize, usize); PAIRS] = std::array::from_fn(|i| pairs[i]);
        let ahead: [DVec3; PAIRS] =
            std::array::from_fn(|i| grid.scale() * grid.direction(pairs[i].0));
        // At 0 every edge of a pair of valences has the same support, its envelope's
        // largest intercept (rounded up).
        let at_zero: Vec<f64> = firsts
            .iter()
            .zip(&envelopes)
            .map(|(&i, envelope)| envelope.supports(&prims[i], &[DVec3::ZERO], alpha)[0])
            .collect();
        let mut tables = Self::build(wide, &grid, alpha, scale, |p, _| {
            let pair = pair_of[p] as usize;
            let (plus, minus) = envelopes[pair].supports_antipodal(&prims[p], &ahead, alpha);
            let mut t = [at_zero[pair]; VALUES];
            for (i, &(k, l)) in pairs.iter().enumerate() {
                (t[k], t[l]) = (plus[i], minus[i]);
            }
            t
        });
        let pair_splits: Vec<(f64, f64)> = firsts
            .iter()
            .map(|&i| edge_split(prims[i].val_a, prims[i].val_b, scale))
            .collect();
        let splits: Vec<(f64, f64)> = pair_of.iter().map(|&k| pair_splits[k as usize]).collect();
        let ends = Self::build(wide, &grid, alpha, scale, |p, dirs| {
            ends_supports(&prims[p], splits[p].0, dirs, alpha)
        });
        tables.split = Some(SplitTables::new(prims, wide, &splits, ends.values));
        tables
    }

    /// The tables of a triangle set, as [`DirectionalTables::for_edges`].
    pub fn for_triangles(
        prims: &[Triangle],
        wide: &[Node4],
        alpha: f64,
        scale: &WeightScale,
    ) -> Self {
        let (firsts, lattice_of) = valence_pairs(prims, |t| (t.vmax, t.emax));
        let lattices: Vec<TriangleLattice> = firsts
            .iter()
            .map(|&i| TriangleLattice::new(prims[i].vmax, prims[i].emax, scale))
            .collect();
        Self::build(wide, &DirectionGrid::new(GRID), alpha, scale, |p, dirs| {
            lattices[lattice_of[p] as usize].supports(&prims[p], dirs, alpha)
        })
    }

    /// The tables from each primitive's weighted supports (`supports(p, dirs)` for
    /// primitive `p` in the tree's order), on `grid` (of side [`GRID`]). The leaves'
    /// slots are summed in parallel, then the tree a level at a time.
    fn build(
        wide: &[Node4],
        grid: &DirectionGrid,
        alpha: f64,
        scale: &WeightScale,
        supports: impl Fn(usize, &[DVec3; VALUES]) -> Table + Sync,
    ) -> Self {
        use rayon::prelude::*;
        assert_eq!(grid.len() + 1, VALUES, "the direction grid's size");
        // The grid's scaled directions, then 0.
        let dirs: [DVec3; VALUES] = std::array::from_fn(|k| {
            if k + 1 < VALUES {
                grid.scale() * grid.direction(k)
            } else {
                DVec3::ZERO
            }
        });
        // The leaf slots' tables about the origin: per direction the largest support,
        // then one exponential per primitive and one logarithm.
        thread_local! {
            /// A leaf's primitives' tables (each thread's, kept between leaves).
            static LEAF: std::cell::RefCell<Vec<Table>> = const { std::cell::RefCell::new(Vec::new()) };
        }
        let leaf_slot = |first: usize, count: usize| -> Table {
            LEAF.with_borrow_mut(|s| {
                s.clear();
                s.extend((first..first + count).map(|p| supports(p, &dirs)));
                log_sum_exp(s)
            })
        };
        let slot_tables: Vec<[Option<Table>; 4]> = wide
            .par_iter()
            .map(|node| {
                std::array::from_fn(|k| {
                    let count = node.count[k];
                    (count != EMPTY && count > 0)
                        .then(|| leaf_slot(node.child[k] as usize, count as usize))
                })
            })
            .collect();
        // Every inner slot's table about the origin, a level of the tree at a time,
        // deepest first: the sum over its child's slots.
        let mut depth = vec![0usize; wide.len()];
        for (i, node) in wide.iter().enumerate() {
            for k in 0..4 {
                if node.count[k] == 0 {
                    // Depth-first layout: a child's index is above its parent's.
                    depth[node.child[k] as usize] = depth[i] + 1;
                }
            }
        }
        let mut levels: Vec<Vec<usize>> = vec![Vec::new(); depth.iter().max().map_or(0, |d| d + 1)];
        for (i, &d) in depth.iter().enumerate() {
            levels[d].push(i);
        }
        let mut total: Vec<Table> = vec![[f64::NEG_INFINITY; VALUES]; wide.len()];
        let mut values = vec![0.0f32; wide.len() * ENTRIES * VALUES];
        for level in levels.iter().rev() {
            let done: Vec<(Box<[f32; ENTRIES * VALUES]>, Table)> = level
                .par_iter()
                .map(|&i| {
                    let node = &wide[i];
                    let slots: [Option<Table>; 4] = std::array::from_fn(|k| match node.count[k] {
                        EMPTY => None,
                        0 => Some(total[node.child[k] as usize]),
                        _ => slot_tables[i][k],
                    });
                    let pair = |a: Option<Table>, b: Option<Table>| match (a, b) {
                        (Some(a), Some(b)) => Some(std::array::from_fn(|d| lse(a[d], b[d]))),
                        (a, None) => a,
                        (None, b) => b,
                    };
                    let middles = [pair(slots[0], slots[1]), pair(slots[2], slots[3])];
                    let sum = pair(middles[0], middles[1]).unwrap_or([f64::NEG_INFINITY; VALUES]);
                    // Each entry about its centre, rounded up to f32.
                    let mut out = Box::new([0.0f32; ENTRIES * VALUES]);
                    for e in 0..ENTRIES {
                        let t = if e < MIDDLE {
                            slots[e]
                        } else {
                            middles[e - MIDDLE]
                        };
                        let Some(t) = t else { continue };
                        let c = entry_centre(node, e);
                        let out = &mut out[e * VALUES..(e + 1) * VALUES];
                        for ((o, &t), g) in out.iter_mut().zip(&t).zip(&dirs) {
                            let shift = alpha * g.dot(c);
                            let v = t - shift;
                            // The subtraction's rounding, then f32 rounded up.
                            let v = v + 1e-12 * (t.abs() + shift.abs() + 1.0);
                            let f = v as f32;
                            *o = if (f as f64) < v { f.next_up() } else { f };
                        }
                    }
                    (out, sum)
                })
                .collect();
            for (&i, (out, sum)) in level.iter().zip(done) {
                values[i * ENTRIES * VALUES..(i + 1) * ENTRIES * VALUES].copy_from_slice(&*out);
                total[i] = sum;
            }
        }
        DirectionalTables {
            grid: grid.clone(),
            alpha,
            q: scale.q,
            values,
            split: None,
        }
    }

    /// The bound of the terms below entry `e` of wide node `i` (centre `c`,
    /// [`entry_centre`]) at `x`, as `(|x - c|, ln of the weight)`: the terms sum to at
    /// most `exp(-alpha |x - c|)` times that weight. `None` at the centre.
    pub fn bound(&self, i: usize, e: usize, c: DVec3, x: DVec3) -> Option<(f64, f64)> {
        self.bounds(i, e, c, x).map(|(l, d, _)| (l, d))
    }

    /// [`DirectionalTables::bound`], with the ends' table's value where the set has a
    /// split (edges, `primitives::split`): `(|x - c|, ln of the weight, ln of the ends'
    /// weight)`.
    #[inline(always)]
    pub fn bounds(
        &self,
        i: usize,
        e: usize,
        c: DVec3,
        x: DVec3,
    ) -> Option<(f64, f64, Option<f64>)> {
        let v = x - c;
        let l = v.length();
        if l.is_nan() || l == 0.0 {
            return None;
        }
        let cone = self.grid.cone_of(v, l);
        let d = self.on_grid(&self.values, i, e, cone);
        let ends = self
            .split
            .as_ref()
            .map(|s| self.on_grid(&s.ends, i, e, cone));
        Some((l, d, ends))
    }

    /// The edges' split (`primitives::split`), if these are an edge set's tables.
    pub fn split(&self) -> Option<&SplitTables> {
        self.split.as_ref()
    }

    /// Entry `e` of wide node `i` in `values` (a table's layout) at the direction of
    /// `cone` (`DirectionGrid::cone_of`): bounded by convexity between the grid's values
    /// and the value at 0.
    #[inline(always)]
    fn on_grid(
        &self,
        values: &[f32],
        i: usize,
        e: usize,
        (idx, mu): ([usize; 3], [f64; 3]),
    ) -> f64 {
        let t = &values[(i * ENTRIES + e) * VALUES..(i * ENTRIES + e + 1) * VALUES];
        let s = self.grid.scale();
        let m: f64 = mu.iter().sum();
        let mut d = (1.0 - m / s).max(0.0) * t[VALUES - 1] as f64;
        for k in 0..3 {
            d += mu[k] / s * t[idx[k]] as f64;
        }
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::BuildOptions;
    use crate::primitives::Primitive;
    use crate::primitives::PrimitiveSet;
    use crate::testing::uniform;
    use glam::Vec3;

    /// A random point of the slab `[0, 1]^2 x [0, 0.2]`.
    fn anchor(r: &mut impl FnMut() -> f64) -> Vec3 {
        Vec3::new(r() as f32, r() as f32, 0.2 * r() as f32)
    }

    /// A random offset within 0.05 in each coordinate.
    fn offset(r: &mut impl FnMut() -> f64) -> Vec3 {
        Vec3::new(r() as f32 - 0.5, r() as f32 - 0.5, r() as f32 - 0.5) * 0.1
    }

    /// Every entry's bound is at least its primitives' exact sum, at points near and
    /// far, on a random wireframe.
    #[test]
    fn every_entry_bounds_its_terms_on_edges() {
        let mut r = uniform(5);
        let mut prims = Vec::new();
        for i in 0..600 {
            let a = anchor(&mut r);
            let b = a + offset(&mut r);
            prims.push(Edge {
                a,
                b,
                val_a: (1 + i % 6) as f32,
                val_b: (1 + i % 4) as f32,
            });
        }
        let set = PrimitiveSet::new(prims, 6.0, BuildOptions::default(), 0.0);
        check_every_entry(&set, &mut r, |alpha, scale| {
            DirectionalTables::for_edges(&set.prims, &set.bvh.wide, alpha, scale)
        });
    }

    /// The branch-free `exp` against libm's over the whole range it takes, its ends and
    /// its edge cases.
    #[test]
    fn exp_nonpositive_is_within_two_ulp_of_libm() {
        let mut worst: f64 = 0.0;
        for i in 0..=200_000 {
            // A fine sweep of [-708, 0], plus the ends of the reduction's intervals.
            let x = -708.0 * (i as f64 / 200_000.0).powf(1.7);
            for x in [x, x.next_up().min(0.0), x.next_down().max(-708.0)] {
                let (a, b) = (exp_nonpositive(x), x.exp());
                let rel = ((a - b) / b).abs();
                worst = worst.max(rel);
                assert!(rel <= 4.5e-16, "exp({x}) = {a}, libm {b}: relative {rel:e}");
            }
        }
        assert!(
            worst > 0.0,
            "identical everywhere: the test would not see an error"
        );
        for x in [-708.5, -745.2, -1e300, f64::NEG_INFINITY] {
            assert_eq!(exp_nonpositive(x), 0.0, "exp({x})");
        }
        assert_eq!(exp_nonpositive(0.0), 1.0);
        assert!(exp_nonpositive(f64::NAN).is_nan());
    }

    /// The leaves' sums in lanes (where this CPU has AVX2) give the bits of the scalar
    /// code, including `-inf` and tables of one.
    #[test]
    fn log_sum_exp_in_lanes_is_the_scalar_code_bit_for_bit() {
        let mut r = uniform(4);
        for n in [1usize, 2, 5, 8, 16, 23] {
            let tables: Vec<Table> = (0..n)
                .map(|i| {
                    std::array::from_fn(|d| match (i + d) % 11 {
                        0 => f64::NEG_INFINITY,
                        _ => 400.0 * r() - 200.0,
                    })
                })
                .collect();
            let (a, b) = (log_sum_exp(&tables), log_sum_exp_any(&tables));
            for d in 0..VALUES {
                assert_eq!(
                    a[d].to_bits(),
                    b[d].to_bits(),
                    "n {n} value {d}: {} {}",
                    a[d],
                    b[d]
                );
            }
        }
    }

    /// The same on a random triangle soup, valences 1 to 12 (the table's and beyond).
    #[test]
    fn every_entry_bounds_its_terms_on_triangles() {
        let mut r = uniform(9);
        let mut prims = Vec::new();
        for i in 0..500 {
            let a = anchor(&mut r);
            let (b, c) = (a + offset(&mut r), a + offset(&mut r));
            prims.push(Triangle::new(
                a,
                b,
                c,
                (1 + i % 12) as f32,
                (1 + i % 3) as f32,
            ));
        }
        let set = PrimitiveSet::new(prims, 12.0, BuildOptions::default(), 0.0);
        check_every_entry(&set, &mut r, |alpha, scale| {
            DirectionalTables::for_triangles(&set.prims, &set.bvh.wide, alpha, scale)
        });
    }

    /// At 40 random points and two `alpha`s, every entry of every node bounds the exact
    /// sum of its primitives' terms.
    fn check_every_entry<P: Primitive>(
        set: &PrimitiveSet<P>,
        r: &mut impl FnMut() -> f64,
        tables: impl Fn(f64, &WeightScale) -> DirectionalTables,
    ) {
        for (alpha, max_alpha) in [(20.0, 40.0), (150.0, 100.0)] {
            // Entries whose split bound is below the table's (edges).
            let mut tighter = 0;
            let scale = WeightScale::new(set.max_adj, alpha, max_alpha);
            let tables = tables(alpha, &scale);
            for _ in 0..40 {
                let x = DVec3::new(r() * 1.6 - 0.3, r() * 1.6 - 0.3, r() * 0.8 - 0.3);
                for (i, node) in set.bvh.wide.iter().enumerate() {
                    for e in 0..ENTRIES {
                        let slots: Vec<usize> = if e < MIDDLE {
                            vec![e]
                        } else {
                            vec![2 * (e - MIDDLE), 2 * (e - MIDDLE) + 1]
                        };
                        let exact = exact_sum(set, node, &slots, x, alpha, &scale);
                        if exact == 0.0 {
                            continue;
                        }
                        let c = entry_centre(node, e);
                        let Some((l, d)) = tables.bound(i, e, c, x) else {
                            continue;
                        };
                        let bound = (-alpha * l + d).exp();
                        assert!(
                            bound >= exact * (1.0 - 1e-9),
                            "node {i} entry {e}: bound {bound} below the exact {exact}"
                        );
                        // Edges: the split bound too, over the entry's range (which must
                        // hold its primitives: the same exact sum).
                        let (Some(split), Some((_, _, Some(d_ends)))) =
                            (tables.split(), tables.bounds(i, e, c, x))
                        else {
                            continue;
                        };
                        let range = split.range(node, e);
                        let in_range: f64 = set.prims[range.clone()]
                            .iter()
                            .map(|p| {
                                let (d, w) = p.value(x, &scale);
                                w * (-alpha * d).exp()
                            })
                            .sum();
                        assert!(
                            (in_range - exact).abs() <= 1e-12 * exact,
                            "node {i} entry {e}: its range sums {in_range}, its slots {exact}"
                        );
                        let ds = split.bound(range, x, (c, l), (d_ends, d), alpha);
                        let split_bound = (-alpha * l + ds).exp();
                        assert!(
                            ds <= d && split_bound >= exact * (1.0 - 1e-9),
                            "node {i} entry {e}: split bound {split_bound} below the exact \
                             {exact} (or above the table's {bound})"
                        );
                        if ds < d - 1e-9 {
                            tighter += 1;
                        }
                    }
                }
            }
            if tables.split().is_some() {
                assert!(
                    tighter > 0,
                    "no split bound below the table's at alpha {alpha}"
                );
            }
        }
    }

    /// The exact sum of the terms below `slots` of `node`.
    fn exact_sum<P: Primitive>(
        set: &PrimitiveSet<P>,
        node: &Node4,
        slots: &[usize],
        x: DVec3,
        alpha: f64,
        scale: &WeightScale,
    ) -> f64 {
        let mut sum = 0.0;
        for &k in slots {
            let count = node.count[k];
            if count == EMPTY {
                continue;
            }
            if count > 0 {
                let first = node.child[k] as usize;
                for p in &set.prims[first..first + count as usize] {
                    let (d, w) = p.value(x, scale);
                    sum += w * (-alpha * d).exp();
                }
            } else {
                let child = &set.bvh.wide[node.child[k] as usize];
                sum += exact_sum(set, child, &[0, 1, 2, 3], x, alpha, scale);
            }
        }
        sum
    }
}
