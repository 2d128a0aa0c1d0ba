//! Exact winding numbers: the signed solid angle of a triangle (Van Oosterom and
//! Strackee, "The solid angle of a plane triangle", IEEE Trans. Biomed. Eng. 30(2), 1983)
//! summed over every triangle, `w(q) = sum_t Omega_t(q) / (4 pi)` (Jacobson, Kavan and
//! Sorkine-Hornung, "Robust inside-outside segmentation using generalized winding
//! numbers", SIGGRAPH 2013). O(n) per query: the reference of the tests and the leaves
//! of the fast sum.
//!
//! With `A = a - q`, `B = b - q`, `C = c - q`:
//! `tan(Omega / 2) = det[A, B, C] / (|A||B||C| + (A.B)|C| + (B.C)|A| + (C.A)|B|)`, and
//! `Omega = 2 atan2(num, den)` lies in `(-2 pi, 2 pi)`. It is positive when the triangle's
//! right-hand normal `(b - a) x (c - a)` points away from `q`, so a closed mesh with
//! outward normals has `w = 1` inside and `0` outside.
//!
//! NaN policy: a query on a vertex (`|A| = 0`) gives `atan2(0, 0) = 0`: no contribution,
//! never NaN. Degenerate triangles have `det = 0` and contribute 0 (or `+-2 pi` on the
//! segment itself, where the winding number is undefined anyway).

use glam::DVec3;
use std::f64::consts::PI;

/// Signed solid angle of triangle `(a, b, c)` seen from `q`, in `(-2 pi, 2 pi]`.
#[inline]
pub fn solid_angle(q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (x, y, z) = (a - q, b - q, c - q);
    let (lx, ly, lz) = (x.length(), y.length(), z.length());
    let num = x.dot(y.cross(z));
    let den = lx * ly * lz + x.dot(y) * lz + y.dot(z) * lx + z.dot(x) * ly;
    2.0 * num.atan2(den)
}

/// Exact winding number of triangles `tris` (vertex positions) at `q`.
pub fn winding_number(tris: &[[DVec3; 3]], q: DVec3) -> f64 {
    let sum: f64 = tris.iter().map(|t| solid_angle(q, t[0], t[1], t[2])).sum();
    sum / (4.0 * PI)
}

/// Exact winding number of an oriented point cloud (points with area-weighted normals,
/// `an = area * unit normal`) at `q`: the sum of dipoles
/// `an . (p - q) / (4 pi |p - q|^3)` (Barill et al. 2018, eq. 7). A query on a point gets
/// nothing from it.
pub fn point_winding_number(points: &[(DVec3, DVec3)], q: DVec3) -> f64 {
    points.iter().map(|&(p, an)| dipole(q, p, an)).sum()
}

/// One dipole `an . (p - q) / (4 pi |p - q|^3)`; 0 at `p` itself.
#[inline]
pub fn dipole(q: DVec3, p: DVec3, an: DVec3) -> f64 {
    let r = p - q;
    let r2 = r.length_squared();
    if r2 > 0.0 {
        an.dot(r) / (4.0 * PI * r2 * r2.sqrt())
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube with outward normals, as 12 triangles.
    pub fn cube() -> Vec<[DVec3; 3]> {
        let v = |i: usize| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64);
        let quads = [
            [0, 2, 3, 1], // z = 0, normal -z
            [4, 5, 7, 6], // z = 1, +z
            [0, 1, 5, 4], // y = 0, -y
            [2, 6, 7, 3], // y = 1, +y
            [0, 4, 6, 2], // x = 0, -x
            [1, 3, 7, 5], // x = 1, +x
        ];
        quads
            .iter()
            .flat_map(|q| [[v(q[0]), v(q[1]), v(q[2])], [v(q[0]), v(q[2]), v(q[3])]])
            .collect()
    }

    #[test]
    fn a_closed_cube_has_winding_number_one_inside_zero_outside() {
        let c = cube();
        for q in [
            DVec3::splat(0.5),
            DVec3::new(0.01, 0.99, 0.5),
            DVec3::new(0.9, 0.1, 0.2),
        ] {
            let w = winding_number(&c, q);
            assert!((w - 1.0).abs() < 1e-12, "inside {q}: {w}");
        }
        for q in [
            DVec3::new(1.5, 0.5, 0.5),
            DVec3::new(-3.0, 7.0, 0.2),
            DVec3::new(0.5, 0.5, 1.0001),
        ] {
            let w = winding_number(&c, q);
            assert!(w.abs() < 1e-12, "outside {q}: {w}");
        }
    }

    #[test]
    fn an_octant_triangle_subtends_an_eighth_of_the_sphere() {
        let o = DVec3::ZERO;
        let w = solid_angle(o, DVec3::X, DVec3::Y, DVec3::Z);
        assert!((w - PI / 2.0).abs() < 1e-14, "{w}");
        assert!((solid_angle(o, DVec3::X, DVec3::Z, DVec3::Y) + PI / 2.0).abs() < 1e-14);
        // On a vertex and on a degenerate triangle: finite.
        assert_eq!(solid_angle(DVec3::X, DVec3::X, DVec3::Y, DVec3::Z), 0.0);
        assert!(solid_angle(o, DVec3::X, DVec3::X, DVec3::Z).is_finite());
    }
}
