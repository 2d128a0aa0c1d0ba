//! The far field of a cluster of oriented surface elements (Barill, Dickson, Schmidt,
//! Levin and Jacobson, "Fast Winding Numbers for Soups and Clouds", SIGGRAPH 2018,
//! section 3.2; libigl's `FastWindingNumberForSoups.h` after the Houdini HDK's
//! `UT_SolidAngle`).
//!
//! The winding number of a surface `S` is the flux of a point source's field through it,
//! `w(q) = 1/(4 pi) int_S n(x) . g(x - q) dA` with `g(r) = r / |r|^3`. Around a centre
//! `p` (the area-weighted centroid) write `x = p + y`, `r0 = p - q`, and expand `g` to
//! second order in `y`:
//!
//! `4 pi w ~ N . g(r0) + sum_ij J_ij(r0) M_ij + 1/2 sum_ijk H_ijk(r0) T_ijk`
//!
//! with the cluster's moments `N = int n dA` (vector area), `M_ij = int n_i y_j dA` and
//! `T_ijk = int n_i y_j y_k dA`, and the derivatives of `g`:
//! `J_ij = d_ij / |r|^3 - 3 r_i r_j / |r|^5`,
//! `H_ijk = -3 (d_ij r_k + d_ik r_j + d_jk r_i) / |r|^5 + 15 r_i r_j r_k / |r|^7`.
//! For a triangle with vector area `a n` and vertices `v_k` (relative to `p`), `M = a n
//! (g - p)^T` with `g` its centroid and `int y y^T dA = a/12 (sum_k v_k v_k^T + s s^T)`,
//! `s = sum_k v_k`: the moments are exact, so the only error is the truncation, of
//! relative order `(R / |r0|)^3` for a cluster of radius `R`. A point with area-weighted
//! normal `a n` is a cluster of radius 0 (`M = T = 0` about itself).
//!
//! Moments are built in f64, shifted to a parent's centre (`y' = y + d`:
//! `M' = M + N d^T`, `T'_ijk = T_ijk + M_ij d_k + M_ik d_j + N_i d_j d_k`) and stored in
//! f32 ([`FarField`]) about a centre that is itself an f32 point, so the traversal reads
//! 136 bytes per node.

use glam::DVec3;
use std::f64::consts::PI;

/// The moments of a cluster about `centre`, in f64 (the build's form).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Moments {
    pub centre: DVec3,
    /// Total unsigned area (the weight of the centre when clusters merge).
    pub area: f64,
    /// Area-weighted centroid times the area (sum of `a_t g_t`).
    pub area_centroid: DVec3,
    /// `N = int n dA`.
    pub n: DVec3,
    /// `M[i][j] = int n_i y_j dA`.
    pub m: [[f64; 3]; 3],
    /// `T[i][j][k] = int n_i y_j y_k dA` (symmetric in `j, k`).
    pub t: [[[f64; 3]; 3]; 3],
}

impl Moments {
    /// The moments of triangle `(a, b, c)` about `centre`.
    // Tensor indices read as the formulas in the module docs.
    #[allow(clippy::needless_range_loop)]
    pub fn triangle(a: DVec3, b: DVec3, c: DVec3, centre: DVec3) -> Moments {
        let an = 0.5 * (b - a).cross(c - a);
        let area = an.length();
        let g = (a + b + c) / 3.0;
        let v = [a - centre, b - centre, c - centre];
        let s = v[0] + v[1] + v[2];
        let mut second = [[0.0; 3]; 3];
        for (j, row) in second.iter_mut().enumerate() {
            for (k, e) in row.iter_mut().enumerate() {
                let vv: f64 = v.iter().map(|x| x[j] * x[k]).sum();
                *e = (vv + s[j] * s[k]) / 12.0;
            }
        }
        let mut out = Moments {
            centre,
            area,
            area_centroid: area * g,
            n: an,
            ..Moments::default()
        };
        let y = g - centre;
        for i in 0..3 {
            for j in 0..3 {
                out.m[i][j] = an[i] * y[j];
                for k in 0..3 {
                    out.t[i][j][k] = an[i] * second[j][k];
                }
            }
        }
        out
    }

    /// A point with area-weighted normal `an` (`area = |an|`) about `centre`.
    pub fn point(p: DVec3, an: DVec3, centre: DVec3) -> Moments {
        let area = an.length();
        let at_p = Moments {
            centre: p,
            area,
            area_centroid: area * p,
            n: an,
            ..Moments::default()
        };
        at_p.shifted(centre)
    }

    /// The area-weighted centroid (`None` when the area is 0).
    pub fn centroid(&self) -> Option<DVec3> {
        (self.area > 0.0).then(|| self.area_centroid / self.area)
    }

    /// The same moments about `centre`.
    pub fn shifted(&self, centre: DVec3) -> Moments {
        let d = self.centre - centre;
        let mut out = *self;
        out.centre = centre;
        for i in 0..3 {
            for j in 0..3 {
                out.m[i][j] += self.n[i] * d[j];
                for k in 0..3 {
                    out.t[i][j][k] +=
                        self.m[i][j] * d[k] + self.m[i][k] * d[j] + self.n[i] * d[j] * d[k];
                }
            }
        }
        out
    }

    /// Adds `o` (about the same centre).
    pub fn add(&mut self, o: &Moments) {
        debug_assert_eq!(self.centre, o.centre);
        self.area += o.area;
        self.area_centroid += o.area_centroid;
        self.n += o.n;
        for i in 0..3 {
            for j in 0..3 {
                self.m[i][j] += o.m[i][j];
                for k in 0..3 {
                    self.t[i][j][k] += o.t[i][j][k];
                }
            }
        }
    }

    /// The compact far field with squared radius `r2`.
    pub fn far_field(&self, r2: f64) -> FarField {
        let t = &self.t;
        let mut ts = [0.0f32; 18];
        for i in 0..3 {
            for (s, &(j, k)) in SYM.iter().enumerate() {
                ts[6 * i + s] = t[i][j][k] as f32;
            }
        }
        let mut m = [0.0f32; 9];
        for i in 0..3 {
            for j in 0..3 {
                m[3 * i + j] = self.m[i][j] as f32;
            }
        }
        FarField {
            centre: self.centre.as_vec3().to_array(),
            r2: r2 as f32,
            n: self.n.as_vec3().to_array(),
            m,
            t: ts,
        }
    }
}

/// The index pairs of a symmetric 3x3 matrix's six entries.
const SYM: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

/// A node's far field in f32: centre, squared radius (every element of the cluster lies
/// within `sqrt(r2)` of the centre), `N`, `M` (row-major) and `T` (`t[6 i + s]` for the
/// symmetric pair `s` of `(j, k)`: 00, 01, 02, 11, 12, 22).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FarField {
    pub centre: [f32; 3],
    pub r2: f32,
    pub n: [f32; 3],
    pub m: [f32; 9],
    pub t: [f32; 18],
}

impl FarField {
    /// The centre in f64.
    #[inline]
    pub fn centre(&self) -> DVec3 {
        glam::Vec3::from_array(self.centre).as_dvec3()
    }

    /// The second-order far-field winding number at the query `q` with `r = centre - q`
    /// and `d2 = |r|^2 > 0`.
    #[inline]
    pub fn eval(&self, r: DVec3, d2: f64) -> f64 {
        let inv2 = 1.0 / d2;
        let inv = inv2.sqrt();
        let inv3 = inv * inv2;
        let inv5 = inv3 * inv2;
        let inv7 = inv5 * inv2;
        let f = |x: f32| x as f64;
        let n = DVec3::new(f(self.n[0]), f(self.n[1]), f(self.n[2]));
        let m = &self.m;
        let mrow = |i: usize| DVec3::new(f(m[3 * i]), f(m[3 * i + 1]), f(m[3 * i + 2]));
        // M r and r^T M r.
        let mr = DVec3::new(mrow(0).dot(r), mrow(1).dot(r), mrow(2).dot(r));
        let trace = f(m[0]) + f(m[4]) + f(m[8]);
        let order1 = trace * inv3 - 3.0 * r.dot(mr) * inv5;
        let (rx, ry, rz) = (r.x, r.y, r.z);
        let mut order2 = 0.0;
        let mut sum_diag = 0.0; // sum_i r_i sum_j T_ijj
        let mut sum_iik = 0.0; // sum_ik T_iik r_k
        for i in 0..3 {
            let t = &self.t[6 * i..6 * i + 6];
            let (t00, t01, t02, t11, t12, t22) =
                (f(t[0]), f(t[1]), f(t[2]), f(t[3]), f(t[4]), f(t[5]));
            // T_i r (a vector over j) and T_i(r, r).
            let trx = t00 * rx + t01 * ry + t02 * rz;
            let try_ = t01 * rx + t11 * ry + t12 * rz;
            let trz = t02 * rx + t12 * ry + t22 * rz;
            let trr = trx * rx + try_ * ry + trz * rz;
            order2 += r[i] * trr;
            sum_diag += r[i] * (t00 + t11 + t22);
            sum_iik += [trx, try_, trz][i];
        }
        let order2 = 0.5 * (15.0 * order2 * inv7 - 3.0 * (2.0 * sum_iik + sum_diag) * inv5);
        (n.dot(r) * inv3 + order1 + order2) / (4.0 * PI)
    }
}

/// A far field as polynomials in the unit vector `u` from the query to its centre (f32,
/// the form `winding::batch` evaluates over many queries): with `s = 1 / |r|`,
/// `4 pi w = s^2 (N . u + s (tr M + A(u, u)) + s^2 (C(u, u, u) + g . u))`,
/// [`FarField::eval`] regrouped: `A(u, u) = -3 u.M u` (its six monomial coefficients),
/// `C(u, u, u) = 15/2 T(u, u, u)` (ten), `g = -3/2 (2 T_iik + T_kjj)`. No power of `s`
/// above the fourth, kept finite by a floor on `|r|^2`; rounding is relative 1e-7 per
/// term, far below the truncation error.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FarPoly {
    pub n: [f32; 3],
    pub trace: f32,
    pub a: [f32; 6],
    pub cubic: [f32; 10],
    pub g: [f32; 3],
}

/// Index of the cubic monomial `u_a u_b u_c` (`a <= b <= c`) in [`FarPoly::cubic`].
const MONO: [[[usize; 3]; 3]; 3] = [
    [[0, 1, 2], [0, 3, 4], [0, 0, 5]],
    [[0, 0, 0], [0, 6, 7], [0, 0, 8]],
    [[0, 0, 0], [0, 0, 0], [0, 0, 9]],
];

/// Index of the symmetric pair `(j, k)` in [`FarField::t`]'s rows.
const PAIR: [[usize; 3]; 3] = [[0, 1, 2], [1, 3, 4], [2, 4, 5]];

impl FarPoly {
    /// The polynomials of the far field `f`.
    pub fn new(f: &FarField) -> FarPoly {
        let (m, t) = (&f.m, &f.t);
        let mut a = [0.0f32; 6];
        for i in 0..3 {
            for j in 0..3 {
                a[PAIR[i.min(j)][i.max(j)]] -= 3.0 * m[3 * i + j];
            }
        }
        // Cubic monomials u_a u_b u_c, a <= b <= c, in the order 000 001 002 011 012 022
        // 111 112 122 222.
        let mono = |x: usize, y: usize, z: usize| {
            let (lo, hi) = (x.min(y).min(z), x.max(y).max(z));
            let mid = x + y + z - lo - hi;
            MONO[lo][mid][hi]
        };
        let mut cubic = [0.0f32; 10];
        let mut g = [0.0f32; 3];
        for i in 0..3 {
            for j in 0..3 {
                for k in 0..3 {
                    cubic[mono(i, j, k)] += 7.5 * t[6 * i + PAIR[j][k]];
                }
                // 2 T_iij (sum over i, per j) + T_jkk (sum over k, per j).
                g[j] -= 1.5 * (2.0 * t[6 * i + PAIR[i][j]] + t[6 * j + PAIR[i][i]]);
            }
        }
        FarPoly {
            n: f.n,
            trace: m[0] + m[4] + m[8],
            a,
            cubic,
            g,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::exact;
    use super::*;

    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    fn soup(n: usize, seed: u64) -> Vec<[DVec3; 3]> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                let mut p = || DVec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) - 0.5;
                [p(), p(), p()]
            })
            .collect()
    }

    fn moments_of(tris: &[[DVec3; 3]], centre: DVec3) -> Moments {
        let mut m = Moments {
            centre,
            ..Moments::default()
        };
        for t in tris {
            m.add(&Moments::triangle(t[0], t[1], t[2], centre));
        }
        m
    }

    #[test]
    fn the_polynomial_form_equals_the_far_field() {
        let tris = soup(9, 5);
        let c = DVec3::new(0.05, -0.02, 0.01);
        let f = moments_of(&tris, c).far_field(1.0);
        let p = FarPoly::new(&f);
        let mut seed = 11;
        for _ in 0..50 {
            let dir = DVec3::new(lcg(&mut seed), lcg(&mut seed), lcg(&mut seed)) - 0.5;
            let r = dir.normalize() * (2.0 + 5.0 * lcg(&mut seed));
            let s = 1.0 / r.length();
            let u = r * s;
            let g = |v: [f32; 3]| DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
            let [x, y, z] = u.to_array();
            let quad = [x * x, x * y, x * z, y * y, y * z, z * z];
            let a: f64 = (0..6).map(|k| p.a[k] as f64 * quad[k]).sum();
            let cube = [
                x * x * x,
                x * x * y,
                x * x * z,
                x * y * y,
                x * y * z,
                x * z * z,
                y * y * y,
                y * y * z,
                y * z * z,
                z * z * z,
            ];
            let cubic: f64 = (0..10).map(|k| p.cubic[k] as f64 * cube[k]).sum();
            let w =
                s * s * (g(p.n).dot(u) + s * (p.trace as f64 + a + s * (cubic + g(p.g).dot(u))))
                    / (4.0 * PI);
            let want = f.eval(r, r.length_squared());
            assert!(
                (w - want).abs() < 1e-6 * want.abs().max(1e-3),
                "{w} vs {want}"
            );
        }
    }

    #[test]
    fn shifting_equals_recomputing_about_the_new_centre() {
        let tris = soup(7, 3);
        let a = moments_of(&tris, DVec3::new(0.1, -0.2, 0.3));
        let b = moments_of(&tris, DVec3::new(-0.4, 0.5, 0.05));
        let s = a.shifted(b.centre);
        for i in 0..3 {
            for j in 0..3 {
                assert!((s.m[i][j] - b.m[i][j]).abs() < 1e-12);
                for k in 0..3 {
                    let (x, y) = (s.t[i][j][k], b.t[i][j][k]);
                    assert!((x - y).abs() < 1e-12, "T{i}{j}{k}: {x} vs {y}");
                }
            }
        }
    }

    #[test]
    fn the_far_field_converges_to_the_exact_winding_number_at_third_order() {
        let tris = soup(20, 11);
        let m = moments_of(&tris, DVec3::ZERO);
        let centre = m.centroid().unwrap().as_vec3().as_dvec3();
        let far = m.shifted(centre).far_field(1.0);
        let dir = DVec3::new(0.3, -0.8, 0.52).normalize();
        let mut last = f64::INFINITY;
        for dist in [4.0, 8.0, 16.0, 32.0] {
            let q = centre + dist * dir;
            let exact = exact::winding_number(&tris, q);
            let r = far.centre() - q;
            let err = (far.eval(r, r.length_squared()) - exact).abs();
            // The truncation error falls like |r|^-5 (the order-3 term); allow for the
            // f32 storage at the longest distance.
            assert!(
                err < last / 16.0 || err < 1e-9,
                "at {dist}: error {err:e}, before {last:e}"
            );
            last = err;
        }
    }

    #[test]
    #[allow(clippy::needless_range_loop)]
    fn the_second_moment_of_a_triangle_matches_quadrature() {
        let (a, b, c) = (
            DVec3::new(0.2, 0.1, -0.3),
            DVec3::new(1.1, 0.4, 0.2),
            DVec3::new(-0.1, 0.9, 0.7),
        );
        let m = Moments::triangle(a, b, c, DVec3::ZERO);
        // Midpoint rule on a fine barycentric grid.
        let n = 200;
        let mut t = [[[0.0; 3]; 3]; 3];
        let an = 0.5 * (b - a).cross(c - a);
        let cell = 1.0 / (n * n) as f64;
        for i in 0..n {
            for j in 0..n - i {
                let mut add = |u: f64, v: f64, w: f64| {
                    let y = a + u * (b - a) + v * (c - a);
                    for p in 0..3 {
                        for q in 0..3 {
                            for r in 0..3 {
                                t[p][q][r] += w * an[p] * y[q] * y[r] * 2.0 * cell;
                            }
                        }
                    }
                };
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                let h = 1.0 / n as f64;
                add(u + h / 3.0, v + h / 3.0, 0.5);
                if i + j + 1 < n {
                    add(u + 2.0 * h / 3.0, v + 2.0 * h / 3.0, 0.5);
                }
            }
        }
        for p in 0..3 {
            for q in 0..3 {
                for r in 0..3 {
                    let (x, y) = (m.t[p][q][r], t[p][q][r]);
                    assert!((x - y).abs() < 1e-4, "T{p}{q}{r}: {x} vs {y}");
                }
            }
        }
    }
}
