//! Second moments of the points below each slot of the wide tree, for the far-field
//! bound of point clouds (`eval::smooth` module docs, SPEC 6).
//!
//! For the `n` points `p_i` below a slot we keep a reference point `c` (their mean,
//! rounded to f32 and stored relative to the slot box's min corner, so the rounding is
//! at most `2^-24` of the box's extent per axis) and their second moment about it,
//! `M = (1/n) sum (p_i - c)(p_i - c)^T`, with its diagonal padded by `4e-7 trace(M)`
//! before rounding to f32, so that `u^T M_stored u >= u^T M u` for every unit `u` (each
//! entry rounds by at most `2^-24 |M_ij| <= 2^-24 trace`, and `(sum |u_a|)^2 <= 3`).
//! The mean is computed in f64 by merging the children's (n, mean, scatter) (Chan et
//! al.), which is exact to rounding for any coordinates.

use super::Node4;
use super::wide::EMPTY;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// The moments of the four slots of one wide node and of its two middles (pairs of
/// slots 0-1 and 2-3), at indices 0..4 and 4, 5. A middle's box is the union of its
/// slots' boxes. Entry by entry (36 bytes each): a far-field term reads one entry, mostly
/// within one cache line.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Moments4 {
    pub e: [MomentEntry; 6],
}

/// The moments of one slot or middle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MomentEntry {
    /// The reference point `c` minus the box's min corner.
    pub c: [f32; 3],
    /// The second moment about `c`, padded: xx, yy, zz, xy, xz, yz.
    pub m: [f32; 6],
}

/// Index of middle `j`'s entry in a [`Moments4`].
pub const MIDDLE: usize = 4;

/// `u^T M u` for a second moment `m` stored as xx, yy, zz, xy, xz, yz.
#[inline]
pub fn quadratic_form(m: &[f64; 6], u: DVec3) -> f64 {
    m[0] * u.x * u.x
        + m[1] * u.y * u.y
        + m[2] * u.z * u.z
        + 2.0 * (m[3] * u.x * u.y + m[4] * u.x * u.z + m[5] * u.y * u.z)
}

/// A bound of the distance from the reference point `c` (stored as `crel` from its
/// box's min corner) to the points' mean: the f32 rounding of `crel` (at most `2^-24`
/// of each component) and the f64 rounding of the mean.
#[inline]
pub fn lin_bound(crel: [f32; 3], c: DVec3) -> f64 {
    6e-8 * (crel[0].abs() + crel[1].abs() + crel[2].abs()) as f64 + 1e-15 * c.abs().max_element()
}

/// Count, mean and scatter (sum of outer products about the mean: xx, yy, zz, xy, xz,
/// yz) of a set of points, in f64.
#[derive(Clone, Copy, Debug, Default)]
struct Stats {
    n: f64,
    mean: DVec3,
    scatter: [f64; 6],
}

impl Stats {
    fn of(range: std::ops::Range<usize>, point: &impl Fn(usize) -> Vec3) -> Stats {
        let n = range.len() as f64;
        let mean = range.clone().map(|i| point(i).as_dvec3()).sum::<DVec3>() / n;
        let mut scatter = [0.0; 6];
        for i in range {
            add_outer(&mut scatter, point(i).as_dvec3() - mean, 1.0);
        }
        Stats { n, mean, scatter }
    }

    fn merge(a: Stats, b: Stats) -> Stats {
        if a.n == 0.0 {
            return b;
        }
        if b.n == 0.0 {
            return a;
        }
        let n = a.n + b.n;
        let delta = b.mean - a.mean;
        let mut scatter = [0.0; 6];
        for (s, (x, y)) in scatter.iter_mut().zip(a.scatter.iter().zip(&b.scatter)) {
            *s = x + y;
        }
        add_outer(&mut scatter, delta, a.n * b.n / n);
        Stats {
            n,
            mean: a.mean + delta * (b.n / n),
            scatter,
        }
    }
}

fn add_outer(s: &mut [f64; 6], d: DVec3, w: f64) {
    s[0] += w * d.x * d.x;
    s[1] += w * d.y * d.y;
    s[2] += w * d.z * d.z;
    s[3] += w * d.x * d.y;
    s[4] += w * d.x * d.z;
    s[5] += w * d.y * d.z;
}

/// The smallest f32 at or above `v` (finite `v >= 0`).
fn f32_up(v: f64) -> f32 {
    let f = v as f32;
    // Both candidates are computed and one is selected without a branch: whether `v`
    // rounded down is a coin flip, and a mispredicted branch per entry cost more than
    // a quarter of the moments' build time.
    let up = f.next_up();
    if (f as f64) < v { up } else { f }
}

/// Moments of every wide node's slots (`wide` as made by `wide::collapse`, depth-first:
/// a node's subtree occupies the indices from it to its next sibling's), for the points
/// in leaf order (`point(i)` is the `i`-th).
pub fn build(wide: &[Node4], point: impl Fn(usize) -> Vec3 + Sync) -> Vec<Moments4> {
    // Zeroed in parallel: the pages are touched by both threads at once.
    let mut out: Vec<Moments4> = (0..wide.len())
        .into_par_iter()
        .map(|_| Moments4::default())
        .collect();
    if !wide.is_empty() {
        node(wide, &point, 0, &mut out, 0);
    }
    out
}

/// Fills `out[0]` (node `i`) and the rest of `out` (its subtree, from index `i + 1`);
/// returns the statistics of all its points.
fn node(
    wide: &[Node4],
    point: &(impl Fn(usize) -> Vec3 + Sync),
    i: usize,
    out: &mut [Moments4],
    depth: u32,
) -> Stats {
    let w = &wide[i];
    let end_all = i + out.len();
    let (here, mut rest) = out.split_first_mut().expect("a slot per node");
    // Inner children own consecutive ranges of `rest`, in slot order.
    let mut parts: [Option<&mut [Moments4]>; 4] = [None, None, None, None];
    for (k, part) in parts.iter_mut().enumerate() {
        if w.count[k] != 0 {
            continue;
        }
        let end = (k + 1..4)
            .find(|&k2| w.count[k2] == 0)
            .map(|k2| w.child[k2] as usize)
            .unwrap_or(end_all);
        let (head, tail) = std::mem::take(&mut rest).split_at_mut(end - w.child[k] as usize);
        *part = Some(head);
        rest = tail;
    }
    let mut slots = [Stats::default(); 4];
    let run = |k: usize, o: &mut [Moments4]| node(wide, point, w.child[k] as usize, o, depth + 1);
    if depth < 6 {
        rayon::scope(|scope| {
            for ((k, part), slot) in parts.iter_mut().enumerate().zip(slots.iter_mut()) {
                if let Some(o) = part.take() {
                    scope.spawn(move |_| *slot = run(k, o));
                }
            }
        });
    } else {
        for ((k, part), slot) in parts.iter_mut().enumerate().zip(slots.iter_mut()) {
            if let Some(o) = part.take() {
                *slot = run(k, o);
            }
        }
    }
    for (k, slot) in slots.iter_mut().enumerate() {
        let c = w.count[k];
        if c != EMPTY && c > 0 {
            let first = w.child[k] as usize;
            *slot = Stats::of(first..first + c as usize, point);
        }
    }
    let mut total = Stats::default();
    for (k, s) in slots.iter().enumerate() {
        if w.count[k] == EMPTY || s.n == 0.0 {
            continue;
        }
        store(here, k, slot_min(w, k), s);
        total = Stats::merge(total, *s);
    }
    for j in 0..2 {
        let (a, b) = (2 * j, 2 * j + 1);
        if w.count[a] != EMPTY && w.count[b] != EMPTY {
            let min = slot_min(w, a).min(slot_min(w, b));
            store(here, MIDDLE + j, min, &Stats::merge(slots[a], slots[b]));
        }
    }
    total
}

fn slot_min(w: &Node4, k: usize) -> DVec3 {
    DVec3::new(w.min[0][k] as f64, w.min[1][k] as f64, w.min[2][k] as f64)
}

/// Writes entry `k`'s reference point (relative to its box's min corner `min`) and
/// padded second moment.
fn store(m: &mut Moments4, k: usize, min: DVec3, s: &Stats) {
    let rel = s.mean - min;
    let crel = [rel.x as f32, rel.y as f32, rel.z as f32];
    let c = min + DVec3::new(crel[0] as f64, crel[1] as f64, crel[2] as f64);
    let inv_n = 1.0 / s.n;
    let mut second = s.scatter.map(|v| v * inv_n);
    add_outer(&mut second, s.mean - c, 1.0);
    let pad = 4e-7 * (second[0] + second[1] + second[2]);
    let entry = &mut m.e[k];
    for a in 0..3 {
        entry.c[a] = crel[a];
        entry.m[a] = f32_up(second[a].max(0.0) + pad);
    }
    for (a, v) in second.iter().enumerate().skip(3) {
        entry.m[a] = *v as f32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{BuildOptions, build_binary_points};

    /// Every slot's stored moments bound the exact second moment about the stored
    /// reference point from above in every direction, and the reference point is the
    /// mean to the stated rounding.
    #[test]
    fn stored_moments_bound_the_exact_ones() {
        let mut seed = 11u32;
        let mut rnd = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1 << 24) as f32
        };
        for (n, offset, spread) in [
            (1usize, 0.0, 1.0),
            (7, 1e4, 1.0),
            (3000, -3e3, 50.0),
            (500, 1e6, 1e-3),
        ] {
            let pts: Vec<Vec3> = (0..n)
                .map(|_| Vec3::splat(offset) + Vec3::new(rnd(), rnd(), 0.1 * rnd()) * spread)
                .collect();
            let mut bvh = build_binary_points(&pts, BuildOptions::default());
            bvh.make_wide();
            let sorted: Vec<Vec3> = bvh.order.iter().map(|&i| pts[i as usize]).collect();
            let moments = build(&bvh.wide, |i| sorted[i]);
            for (i, w) in bvh.wide.iter().enumerate() {
                for e in 0..6 {
                    let slots: Vec<usize> = if e < MIDDLE {
                        vec![e]
                    } else {
                        vec![2 * (e - MIDDLE), 2 * (e - MIDDLE) + 1]
                    };
                    if slots.iter().any(|&k| w.count[k] == EMPTY) {
                        continue;
                    }
                    let below: Vec<Vec3> = slots
                        .iter()
                        .flat_map(|&k| slot_points(&bvh.wide, &sorted, i, k))
                        .collect();
                    let min = slots
                        .iter()
                        .map(|&k| slot_min(w, k))
                        .fold(DVec3::INFINITY, DVec3::min);
                    let m = &moments[i];
                    let crel = m.e[e].c;
                    let c = min + DVec3::from(crel.map(f64::from));
                    let mean =
                        below.iter().map(|p| p.as_dvec3()).sum::<DVec3>() / below.len() as f64;
                    assert!(
                        (mean - c).length() <= lin_bound(crel, c),
                        "node {i} entry {e}"
                    );
                    for _ in 0..50 {
                        let u =
                            DVec3::new(rnd() as f64 - 0.5, rnd() as f64 - 0.5, rnd() as f64 - 0.5)
                                .normalize();
                        let exact = below
                            .iter()
                            .map(|p| (u.dot(p.as_dvec3() - c)).powi(2))
                            .sum::<f64>()
                            / below.len() as f64;
                        let mm = m.e[e].m.map(f64::from);
                        let stored = quadratic_form(&mm, u);
                        assert!(
                            stored >= exact,
                            "n {n} node {i} entry {e}: {stored} < {exact}"
                        );
                        assert!(stored <= exact * 1.001 + 2e-6 * (mm[0] + mm[1] + mm[2]));
                    }
                }
            }
        }
    }

    /// `f32_up` is the smallest f32 at or above its argument, for values that round
    /// either way, exact ones, zero, tiny and huge ones.
    #[test]
    fn f32_up_is_the_least_f32_not_below() {
        let mut seed = 5u64;
        let mut values = vec![0.0, 1.0, 0.1, 1e-50, 1e-40, 3.4e38, f32::MAX as f64];
        for _ in 0..10_000 {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let mantissa = (seed >> 11) as f64 / (1u64 << 53) as f64;
            let exponent = ((seed >> 3) % 200) as i32 - 100;
            values.push(mantissa * 2f64.powi(exponent));
        }
        for v in values {
            let f = f32_up(v);
            assert!(f as f64 >= v, "{v}: {f}");
            assert!((f.next_down() as f64) < v, "{v}: {f}");
        }
    }

    fn slot_points(wide: &[Node4], pts: &[Vec3], i: usize, k: usize) -> Vec<Vec3> {
        let w = &wide[i];
        if w.count[k] > 0 {
            let f = w.child[k] as usize;
            return pts[f..f + w.count[k] as usize].to_vec();
        }
        let c = w.child[k] as usize;
        (0..4)
            .filter(|&j| wide[c].count[j] != EMPTY)
            .flat_map(|j| slot_points(wide, pts, c, j))
            .collect()
    }
}
