//! A grid of unit directions on which a convex function of a direction can be tabulated
//! and bounded everywhere (doc/performance-log.md, round twenty-eight: a far-field bound
//! of edges and triangles tabulated over directions).
//!
//! The parameter square `[-1, 1]^2` maps onto the octahedron `|x| + |y| + |z| = 1`:
//! `(px, py)` to `(px, py, 1 - |px| - |py|)` where that is at least 0, and folded below
//! (`((1 - |py|) sgn px, (1 - |px|) sgn py, 1 - |px| - |py|)`). Within one quadrant of the
//! square and one side of the fold lines `|px| + |py| = 1` the map is affine. The grid's
//! `n x n` points (`n` odd, so that the axes are grid lines) split each square into two
//! triangles along the diagonal that keeps them on one side of the fold. For a unit `u`
//! whose octahedron point `o_u = u / |u|_1` lies in the triangle with octahedron vertices
//! `o_1..3` at barycentrics `lambda`, `o_u = sum lambda_k o_k`, so
//!
//!   `u = sum mu_k g_k`, with `g_k = o_k / |o_k|` and `mu_k = lambda_k |o_k| / |o_u| >= 0`.
//!
//! `M = sum mu_k` is `1 / |p|` for `p = u / M`, the point where `u`'s ray meets the flat
//! triangle through `g_1..3`, so it is at most [`DirectionGrid::scale`] `S`, one over the
//! smallest distance from the origin to such a triangle. Then `u` is the convex
//! combination `sum (mu_k / S) (S g_k) + (1 - M / S) 0`, and any convex `f` satisfies
//!
//!   `f(u) <= sum (mu_k / S) f(S g_k) + (1 - M / S) f(0)`,
//!
//! which a table of `f` at the scaled grid directions and at 0 bounds.
//!
//! The fold maps the square's border onto itself (`(1, py)` and `(1, -py)` are one
//! direction, and so on each side; the four corners are all `-z`), so the grid keeps each
//! direction once: `n^2 - 2 n + 3` of them, 18 of the 25 points at `n = 5`.

use super::closest::closest_on_triangle;
use glam::DVec3;

/// The grid: its directions and scale.
#[derive(Clone, Debug)]
pub struct DirectionGrid {
    n: usize,
    /// The distinct unit directions of the grid points, in the order of their first
    /// point (row by row, `py` outer).
    unit: Vec<DVec3>,
    /// The lengths of their octahedron points.
    oct_len: Vec<f64>,
    /// Per square `(i, j)` (`j (n - 1) + i`): its two triangles' directions, lower then
    /// upper (`triangle`, each grid point as its direction's index).
    triangles: Vec<[usize; 3]>,
    /// Per square: px and py have one sign there (the fold runs along its anti-diagonal).
    anti: Vec<bool>,
    scale: f64,
}

/// The distinct directions of an `n x n` grid (`n` odd): the `(n - 2)^2` inner points,
/// `(n - 1) / 2` per side of the border (`(1, py)` and `(1, -py)` fold onto one) and
/// the corners' one, `-z`.
pub const fn distinct_directions(n: usize) -> usize {
    n * n - 2 * n + 3
}

/// The parameter coordinate of grid line `i` of `n`, `(2 i - (n - 1)) / (n - 1)`, one
/// quotient of integers: lines `i` and `n - 1 - i` get opposite values exactly, so the
/// fold's copies of a direction come out equal.
fn grid_coordinate(i: usize, n: usize) -> f64 {
    (2 * i as i64 - (n as i64 - 1)) as f64 / (n - 1) as f64
}

/// The octahedron point of the parameter point `(px, py)`.
fn decode(px: f64, py: f64) -> DVec3 {
    let z = 1.0 - px.abs() - py.abs();
    if z >= 0.0 {
        DVec3::new(px, py, z)
    } else {
        DVec3::new(
            (1.0 - py.abs()) * px.signum(),
            (1.0 - px.abs()) * py.signum(),
            z,
        )
    }
}

impl DirectionGrid {
    /// The grid of `n x n` parameter points, `n` odd and at least 3.
    pub fn new(n: usize) -> DirectionGrid {
        assert!(n >= 3 && n % 2 == 1, "a direction grid needs an odd n >= 3");
        let oct: Vec<DVec3> = (0..n * n)
            .map(|k| decode(grid_coordinate(k % n, n), grid_coordinate(k / n, n)))
            .collect();
        // The fold maps the square's border onto itself: `(1, py)` and `(1, -py)` are one
        // direction, and so on each side, and the four corners are `-z`. Each direction
        // is kept once, in the order of its first grid point.
        let mut distinct: Vec<DVec3> = Vec::new();
        let of_point: Vec<usize> = oct
            .iter()
            .map(|o| {
                // (`==` takes -0 for 0, which is all the fold's copies differ by.)
                distinct.iter().position(|d| d == o).unwrap_or_else(|| {
                    distinct.push(*o);
                    distinct.len() - 1
                })
            })
            .collect();
        let mut grid = DirectionGrid {
            n,
            unit: distinct.iter().map(|o| o.normalize()).collect(),
            oct_len: distinct.iter().map(|o| o.length()).collect(),
            triangles: Vec::new(),
            anti: Vec::new(),
            scale: 1.0,
        };
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                for upper in [false, true] {
                    let t = grid.triangle(i, j, upper);
                    grid.triangles.push(t.map(|k| of_point[k]));
                }
                grid.anti.push(grid.anti_square(i, j));
            }
        }
        let mut nearest = f64::INFINITY;
        for t in &grid.triangles {
            let [a, b, c] = t.map(|k| grid.unit[k]);
            let d = closest_on_triangle(DVec3::ZERO, a, b, c).point.length();
            nearest = nearest.min(d);
        }
        // Rounded up past the rounding of the distance and of `mu`.
        grid.scale = (1.0 / nearest) * (1.0 + 1e-12);
        grid
    }

    /// The number of distinct grid directions: `n^2 - 2 n + 3` ([`distinct_directions`]).
    pub fn len(&self) -> usize {
        self.unit.len()
    }

    /// Never empty (`n >= 3`).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// `S`: at least `sum mu_k` for every unit direction (module docs).
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// Distinct grid direction `k` (`k < len()`), unit length.
    pub fn direction(&self, k: usize) -> DVec3 {
        self.unit[k]
    }

    /// The grid's directions in opposite pairs `(k, l)`, `direction(l) = -direction(k)`
    /// exactly, `k < l`. The grid is symmetric through the origin (`(px, py)` and its
    /// fold's image of `(-px, -py)`), and where `n - 1` is a power of two the fold's
    /// arithmetic is exact, so every direction is in one pair; elsewhere (`n = 7`) the
    /// rounding of `1 - |py|` leaves some without theirs.
    pub fn antipodal_pairs(&self) -> Vec<(usize, usize)> {
        let mut pairs = Vec::new();
        for k in 0..self.len() {
            if let Some(l) = (k + 1..self.len()).find(|&l| self.unit[l] == -self.unit[k]) {
                pairs.push((k, l));
            }
        }
        pairs
    }

    /// Where px and py have one sign the fold line runs along the squares'
    /// anti-diagonals, elsewhere along their diagonals.
    fn anti_square(&self, i: usize, j: usize) -> bool {
        let h = 2.0 / (self.n - 1) as f64;
        let cx = -1.0 + (i as f64 + 0.5) * h;
        let cy = -1.0 + (j as f64 + 0.5) * h;
        cx * cy > 0.0
    }

    /// The grid points (`py` outer) of triangle `upper` (0 or 1) of square `(i, j)`.
    fn triangle(&self, i: usize, j: usize, upper: bool) -> [usize; 3] {
        let v = |a: usize, b: usize| (j + b) * self.n + i + a;
        match (self.anti_square(i, j), upper) {
            (true, false) => [v(0, 0), v(1, 0), v(0, 1)],
            (true, true) => [v(1, 1), v(1, 0), v(0, 1)],
            (false, false) => [v(0, 0), v(1, 0), v(1, 1)],
            (false, true) => [v(0, 0), v(0, 1), v(1, 1)],
        }
    }

    /// The grid directions `k` whose cone holds the unit direction `u` and `mu` (module
    /// docs: `u = sum mu_k g_k`, `mu_k >= 0`, `sum mu_k <= scale`).
    pub fn cone(&self, u: DVec3) -> ([usize; 3], [f64; 3]) {
        self.cone_of(u, 1.0)
    }

    /// [`DirectionGrid::cone`] of the unit direction `v / l`, for `v` nonzero and `l` its
    /// length. Without branches on the direction (far terms look in every direction, and
    /// a branch on it is a coin toss): both sides of every choice are computed and one is
    /// kept.
    #[inline(always)]
    pub fn cone_of(&self, v: DVec3, l: f64) -> ([usize; 3], [f64; 3]) {
        let a = v.abs();
        let norm1 = a.x + a.y + a.z;
        let o = v * (1.0 / norm1);
        // Below the fold: `((1 - |o_y|) sgn o_x, (1 - |o_x|) sgn o_y)` (`decode`'s inverse).
        let below = o.z < 0.0;
        let px = pick(below, (1.0 - o.y.abs()).copysign(o.x), o.x);
        let py = pick(below, (1.0 - o.x.abs()).copysign(o.y), o.y);
        let cells = (self.n - 1) as f64;
        let fi = ((px + 1.0) * 0.5 * cells).clamp(0.0, cells);
        let fj = ((py + 1.0) * 0.5 * cells).clamp(0.0, cells);
        let (i, j) = ((fi as usize).min(self.n - 2), (fj as usize).min(self.n - 2));
        let (fx, fy) = (fi - i as f64, fj - j as f64);
        let square = j * (self.n - 1) + i;
        // Along the anti-diagonal where px and py have one sign, else the diagonal.
        let anti = self.anti[square];
        let upper = (anti & (fx + fy > 1.0)) | (!anti & (fx < fy));
        let lambda = pick3(
            anti,
            pick3(
                upper,
                [fx + fy - 1.0, 1.0 - fy, 1.0 - fx],
                [1.0 - fx - fy, fx, fy],
            ),
            pick3(upper, [1.0 - fy, fy - fx, fx], [1.0 - fx, fx - fy, fy]),
        );
        let idx = self.triangles[2 * square + usize::from(upper)];
        // |o_u| = |u| / |u|_1 = l / |v|_1.
        let scale = norm1 / l;
        let mu = [0, 1, 2].map(|k| lambda[k].max(0.0) * self.oct_len[idx[k]] * scale);
        (idx, mu)
    }
}

/// `if c { a } else { b }` for doubles, as a select.
#[inline(always)]
fn pick(c: bool, a: f64, b: f64) -> f64 {
    let m = (c as u64).wrapping_neg();
    f64::from_bits((a.to_bits() & m) | (b.to_bits() & !m))
}

/// [`pick`] of three.
#[inline(always)]
fn pick3(c: bool, a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|k| pick(c, a[k], b[k]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn random_units(count: usize, seed: u64) -> Vec<DVec3> {
        let mut s = seed;
        let mut r = move || {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut out = Vec::new();
        while out.len() < count {
            let v = DVec3::new(r(), r(), r());
            if v.length() > 0.05 && v.length() <= 1.0 {
                out.push(v.normalize());
            }
        }
        // The axes, the fold and the octant corners, where cells meet.
        for a in [DVec3::X, DVec3::Y, DVec3::Z] {
            out.push(a);
            out.push(-a);
        }
        out.push(DVec3::new(1.0, 1.0, -1.0).normalize());
        out.push(DVec3::new(-1.0, 0.5, 0.0).normalize());
        out.push(DVec3::new(0.3, -0.7, 0.0).normalize());
        out
    }

    /// The fold's copies are kept once: as many directions as `distinct_directions`
    /// says, all different, and every grid point's direction among them.
    #[test]
    fn the_grid_keeps_each_direction_once() {
        for n in [3, 5, 7, 9] {
            let grid = DirectionGrid::new(n);
            assert_eq!(grid.len(), distinct_directions(n), "n {n}");
            for a in 0..grid.len() {
                for b in 0..a {
                    assert!(grid.direction(a) != grid.direction(b), "n {n}: {a} and {b}");
                }
            }
            for k in 0..n * n {
                let o = decode(grid_coordinate(k % n, n), grid_coordinate(k / n, n));
                let u = o.normalize();
                assert!(
                    (0..grid.len()).any(|d| grid.direction(d) == u),
                    "n {n}: point {k} ({u}) has no direction"
                );
            }
        }
    }

    /// Every direction has its opposite in the grid, to the bit, where `n - 1` is a power
    /// of two (the tables' `n = 5` among them).
    #[test]
    fn the_grid_pairs_up_through_the_origin() {
        for n in [3, 5, 9, 17] {
            let grid = DirectionGrid::new(n);
            let pairs = grid.antipodal_pairs();
            assert_eq!(2 * pairs.len(), grid.len(), "n {n}");
            let mut seen = vec![false; grid.len()];
            for (k, l) in pairs {
                assert_eq!(grid.direction(l), -grid.direction(k), "n {n}");
                assert!(!seen[k] && !seen[l], "n {n}: {k} or {l} twice");
                (seen[k], seen[l]) = (true, true);
            }
        }
    }

    #[test]
    fn every_direction_is_a_nonnegative_combination_within_the_scale() {
        for n in [3, 5, 9] {
            let grid = DirectionGrid::new(n);
            let mut widest: f64 = 0.0;
            for u in random_units(20_000, n as u64) {
                let (idx, mu) = grid.cone(u);
                let back: DVec3 = (0..3).map(|k| mu[k] * grid.direction(idx[k])).sum();
                assert!((back - u).length() < 1e-12, "n {n}: {u} rebuilt as {back}");
                // The same cone from the direction unnormalised, with its length.
                let len = 3.7e-3;
                let (idx_of, mu_of) = grid.cone_of(u * len, len);
                let back_of: DVec3 = (0..3).map(|k| mu_of[k] * grid.direction(idx_of[k])).sum();
                assert!(
                    (back_of - u).length() < 1e-12,
                    "n {n}: {u} unnormalised rebuilt as {back_of}"
                );
                assert!(mu.iter().all(|&m| m >= 0.0));
                let m: f64 = mu.iter().sum();
                assert!(
                    m <= grid.scale(),
                    "n {n}: sum mu {m} above {}",
                    grid.scale()
                );
                widest = widest.max(m);
            }
            // The scale is the cells' own, not a loose guess.
            assert!(
                widest > grid.scale() * 0.98,
                "n {n}: {widest} against {}",
                grid.scale()
            );
        }
        // The far-field oracle's grid (doc/performance-log.md, round twenty-eight).
        let s5 = DirectionGrid::new(5).scale();
        assert!(s5 > 1.2 && s5 < 1.25, "n 5: scale {s5}");
    }

    /// A log-sum-exp of supports, the convex function the far-field tables hold: its
    /// value at any direction is at most the grid's interpolation.
    #[test]
    fn a_convex_function_is_bounded_by_its_table() {
        let grid = DirectionGrid::new(5);
        let points = random_units(50, 99);
        let alpha = 7.0;
        let f = |v: DVec3| {
            points
                .iter()
                .map(|p| (alpha * v.dot(*p)).exp())
                .sum::<f64>()
                .ln()
        };
        let table: Vec<f64> = (0..grid.len())
            .map(|k| f(grid.scale() * grid.direction(k)))
            .collect();
        let at_zero = f(DVec3::ZERO);
        for u in random_units(5_000, 3) {
            let (idx, mu) = grid.cone(u);
            let m: f64 = mu.iter().sum();
            let bound = (0..3)
                .map(|k| mu[k] / grid.scale() * table[idx[k]])
                .sum::<f64>()
                + (1.0 - m / grid.scale()) * at_zero;
            assert!(f(u) <= bound + 1e-9, "{u}: {} above {bound}", f(u));
        }
    }
}
