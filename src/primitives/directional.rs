//! Tables of a far-field bound that knows directions and weights, for the slots and
//! middles of an edge set's wide tree (doc/performance-log.md, round twenty-eight; not
//! yet read by the walk).
//!
//! For an entry (slot or middle) with box centre `c` and the primitives `T` below it, and
//! any unit `u`, each term is at most `exp(-alpha u . (x - c) + alpha s_T(u))` with `s_T`
//! the weighted support about `c` (`primitives::support`), so the entry's terms sum to at
//! most `exp(-alpha |x - c| + D(u))` for `u = (x - c) / |x - c|`, `D(u) = ln sum_T
//! exp(alpha s_T(u))`. `D` is convex, and `geometry::directions` bounds it between its
//! values at the grid's scaled directions and at 0, which the table holds (rounded up to
//! f32). The values are summed about the origin up the tree by log-sum-exp and moved to
//! each entry's centre at the end: `alpha s_T(v)` about `c` is the value about the origin
//! minus `alpha v . c`.

use super::kinds::Edge;
use super::sets::PrimitiveSet;
use super::support::{edge_piece_log_weights, edge_weighted_support};
use super::weights::WeightScale;
use crate::bvh::Node4;
use crate::bvh::moments::MIDDLE;
use crate::bvh::wide::EMPTY;
use crate::geometry::directions::DirectionGrid;
use glam::DVec3;

/// Entries per wide node: four slots, two middles (`bvh::MIDDLE`).
const ENTRIES: usize = 6;

/// An edge set's tables at one `alpha`.
pub struct DirectionalTables {
    pub grid: DirectionGrid,
    pub alpha: f64,
    /// Per wide node and entry, the grid's values then the value at 0.
    values: Vec<f32>,
}

/// `ln(e^a + e^b)`, exact for infinities.
pub fn lse(a: f64, b: f64) -> f64 {
    let m = a.max(b);
    if m == f64::NEG_INFINITY {
        m
    } else {
        m + ((a - m).exp() + (b - m).exp()).ln()
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
    /// The tables of `set` at sharpness `alpha` (weights by `scale`), on a 5 x 5 grid.
    pub fn for_edges(set: &PrimitiveSet<Edge>, alpha: f64, scale: &WeightScale) -> Self {
        let grid = DirectionGrid::new(5);
        let n = grid.len() + 1;
        let dirs: Vec<DVec3> = (0..grid.len())
            .map(|k| grid.scale() * grid.direction(k))
            .collect();
        let prim_table = |e: &Edge| {
            let lw = edge_piece_log_weights(e, scale);
            let mut t: Vec<f64> = dirs
                .iter()
                .map(|&g| edge_weighted_support(e, g, alpha, &lw))
                .collect();
            t.push(edge_weighted_support(e, DVec3::ZERO, alpha, &lw));
            t
        };
        let wide = &set.bvh.wide;
        let mut values = vec![0.0f32; wide.len() * ENTRIES * n];
        // Each node's slots' tables about the origin, children first (depth-first
        // layout: a child's index is above its parent's).
        let mut about_origin: Vec<[Option<Vec<f64>>; 4]> = vec![Default::default(); wide.len()];
        for i in (0..wide.len()).rev() {
            let node = &wide[i];
            let mut slots: [Option<Vec<f64>>; 4] = Default::default();
            for (k, slot) in slots.iter_mut().enumerate() {
                let count = node.count[k];
                if count == EMPTY {
                    continue;
                }
                let mut t = vec![f64::NEG_INFINITY; n];
                if count > 0 {
                    let first = node.child[k] as usize;
                    for e in &set.prims[first..first + count as usize] {
                        for (a, b) in t.iter_mut().zip(prim_table(e)) {
                            *a = lse(*a, b);
                        }
                    }
                } else {
                    for c in about_origin[node.child[k] as usize].iter().flatten() {
                        for (a, b) in t.iter_mut().zip(c) {
                            *a = lse(*a, *b);
                        }
                    }
                }
                *slot = Some(t);
            }
            for e in 0..ENTRIES {
                let t = if e < MIDDLE {
                    slots[e].clone()
                } else {
                    let j = e - MIDDLE;
                    match (&slots[2 * j], &slots[2 * j + 1]) {
                        (Some(a), Some(b)) => {
                            Some(a.iter().zip(b).map(|(x, y)| lse(*x, *y)).collect())
                        }
                        (Some(a), None) => Some(a.clone()),
                        _ => None,
                    }
                };
                let Some(t) = t else { continue };
                let c = entry_centre(node, e);
                let out = &mut values[(i * ENTRIES + e) * n..(i * ENTRIES + e + 1) * n];
                for (k, o) in out.iter_mut().enumerate() {
                    let shift = if k < dirs.len() {
                        alpha * dirs[k].dot(c)
                    } else {
                        0.0
                    };
                    let v = t[k] - shift;
                    // The subtraction's rounding, then f32 rounded up.
                    let v = v + 1e-12 * (t[k].abs() + shift.abs() + 1.0);
                    let f = v as f32;
                    *o = if (f as f64) < v { f.next_up() } else { f };
                }
            }
            about_origin[i] = slots;
        }
        DirectionalTables {
            grid,
            alpha,
            values,
        }
    }

    /// The bound of the terms below entry `e` of wide node `i` (centre `c`,
    /// [`entry_centre`]) at `x`, as `(|x - c|, ln of the weight)`: the terms sum to at
    /// most `exp(-alpha |x - c|)` times that weight. `None` at the centre.
    pub fn bound(&self, i: usize, e: usize, c: DVec3, x: DVec3) -> Option<(f64, f64)> {
        let v = x - c;
        let l = v.length();
        if l.is_nan() || l == 0.0 {
            return None;
        }
        let n = self.grid.len() + 1;
        let t = &self.values[(i * ENTRIES + e) * n..(i * ENTRIES + e + 1) * n];
        let (idx, mu) = self.grid.cone(v / l);
        let s = self.grid.scale();
        let m: f64 = mu.iter().sum();
        let mut d = (1.0 - m / s).max(0.0) * t[n - 1] as f64;
        for k in 0..3 {
            d += mu[k] / s * t[idx[k]] as f64;
        }
        Some((l, d))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::BuildOptions;
    use crate::primitives::Primitive;
    use glam::Vec3;

    /// Every entry's bound is at least its primitives' exact sum, at points near and
    /// far, on a random wireframe.
    #[test]
    fn every_entry_bounds_its_terms() {
        let mut seed = 5u64;
        let mut r = move || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut prims = Vec::new();
        for i in 0..600 {
            let a = Vec3::new(r() as f32, r() as f32, 0.2 * r() as f32);
            let b = a + Vec3::new(r() as f32 - 0.5, r() as f32 - 0.5, r() as f32 - 0.5) * 0.1;
            prims.push(Edge {
                a,
                b,
                val_a: (1 + i % 6) as f32,
                val_b: (1 + i % 4) as f32,
            });
        }
        let set = PrimitiveSet::new(prims, 6.0, BuildOptions::default(), 0.0);
        for (alpha, max_alpha) in [(20.0, 40.0), (150.0, 100.0)] {
            let scale = WeightScale::new(set.max_adj, alpha, max_alpha);
            let tables = DirectionalTables::for_edges(&set, alpha, &scale);
            for _ in 0..40 {
                let x = DVec3::new(r() * 1.6 - 0.3, r() * 1.6 - 0.3, r() * 0.8 - 0.3);
                for (i, node) in set.bvh.wide.iter().enumerate() {
                    for e in 0..ENTRIES {
                        let slots: Vec<usize> = if e < MIDDLE {
                            vec![e]
                        } else {
                            vec![2 * (e - MIDDLE), 2 * (e - MIDDLE) + 1]
                        };
                        let exact = exact_sum(&set, node, &slots, x, alpha, &scale);
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
                    }
                }
            }
        }
    }

    /// The exact sum of the terms below `slots` of `node`.
    fn exact_sum(
        set: &PrimitiveSet<Edge>,
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
