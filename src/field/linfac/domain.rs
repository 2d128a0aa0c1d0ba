//! A site's domain on one slice, in pixel coordinates (SPEC 9, "Domains": the prism,
//! slab, wedge or cone of the site cut by the plane `z = z_k`, and the narrow band that
//! bounds every domain).
//!
//! - Half-planes: the 3D half-space `n . p <= c` is `a i + b j <= c0 - cz z` on every
//!   slice, with `a = n_x hx`, `b = n_y hy`, `c0 = c - n_x o_x - n_y o_y`, `cz = n_z`
//!   (`Plane2`, built in `Raster::new`); `push_halfplanes` evaluates it at a height.
//! - Band box: the feature's bounding box grown by the band (for a vertex, by the
//!   radius `sqrt(band^2 - dz^2)` of its band disk on the slice) narrows the pixel
//!   rectangle, or rejects the slice.
//! - Face cross-section: a face's prism cut at height `z` is the triangle with corners
//!   `p + ((z - p_z) / n_z) n` over the face's corners `p`; its box is taken directly.
//! - Clipping: Sutherland-Hodgman cuts the rectangle by each half-plane in turn (a
//!   vertex `p` is kept when `f(p) = a u + b v - c <= 0`, an edge `pq` crossing the line
//!   is cut at `t = f(p) / (f(p) - f(q))`) and returns the bounding box of the convex
//!   polygon left.

use super::{Hp, Raster};
use crate::field::sites::SiteKind;
use glam::DVec3;

impl Raster<'_> {
    /// Narrows `rect` to the band box of site `idx` at height `z` (the feature's box
    /// grown by the band; for a vertex, by the radius of its band disk on the slice).
    /// Returns false when the band misses the slice.
    pub(super) fn band_rect(&self, idx: usize, z: f64, rect: &mut [f64; 4]) -> bool {
        let Some(band) = self.sites.band else {
            return true;
        };
        let site = &self.sites.sites[idx];
        let (lo, hi) = site.bounds;
        let r = if site.kind == SiteKind::Vertex {
            let dz = z - site.anchor.z;
            let r2 = band * band - dz * dz;
            if r2 < 0.0 {
                return false;
            }
            r2.sqrt()
        } else if z < lo.z - band || z > hi.z + band {
            return false;
        } else {
            band
        };
        self.narrow(rect, lo, hi, r)
    }

    /// Narrows `rect` to the xy box `[lo - r, hi + r]` (world units); false if empty.
    #[inline]
    pub(super) fn narrow(&self, rect: &mut [f64; 4], lo: DVec3, hi: DVec3, r: f64) -> bool {
        rect[0] = rect[0].max((lo.x - r - self.o.x) / self.h.x);
        rect[2] = rect[2].min((hi.x + r - self.o.x) / self.h.x);
        rect[1] = rect[1].max((lo.y - r - self.o.y) / self.h.y);
        rect[3] = rect[3].min((hi.y + r - self.o.y) / self.h.y);
        rect[0] <= rect[2] && rect[1] <= rect[3]
    }

    /// Pushes the half-planes of site `idx` at height `z`. Returns false when one of
    /// them excludes the whole slice.
    pub(super) fn push_halfplanes(&self, idx: usize, z: f64, out: &mut Vec<Hp>) -> bool {
        let site = &self.sites.sites[idx];
        for p in &self.planes[site.planes.0 as usize..site.planes.1 as usize] {
            let hp = Hp {
                a: p.a,
                b: p.b,
                c: p.c0 - p.cz * z,
                inv_a: p.inv_a,
            };
            if hp.a == 0.0 && hp.b == 0.0 && hp.c < 0.0 {
                return false;
            }
            out.push(hp);
        }
        true
    }

    /// Pixel bounding box of the triangle cut from a face's prism by the plane at
    /// height `z`, from its corners `p + ((z - p_z) / n_z) n` (`None` when the face is
    /// nearly vertical, `|n_z| < 1e-6`), and the signed plane distances of the corners.
    /// The box is widened by 1e-6 pixel; pixels that rounding could still drop lie on
    /// the prism's side planes, inside the (margin-widened) domains of its edges.
    #[inline]
    pub(super) fn face_bbox(&self, idx: usize, z: f64) -> Option<([f64; 4], [f64; 3])> {
        let site = &self.sites.sites[idx];
        let n = site.rows[0];
        if !(n.z.abs() >= 1e-6) {
            return None;
        }
        let inv = 1.0 / n.z;
        let mut bb = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        let mut ts = [0.0; 3];
        for (c, p) in [site.anchor, site.rows[1], site.rows[2]]
            .into_iter()
            .enumerate()
        {
            let t = (z - p.z) * inv;
            ts[c] = t;
            let u = (p.x + t * n.x - self.o.x) / self.h.x;
            let v = (p.y + t * n.y - self.o.y) / self.h.y;
            bb = [bb[0].min(u), bb[1].min(v), bb[2].max(u), bb[3].max(v)];
        }
        const W: f64 = 1e-6;
        Some(([bb[0] - W, bb[1] - W, bb[2] + W, bb[3] + W], ts))
    }
}

/// Clips the rectangle `[u0, v0, u1, v1]` by `hps` (Sutherland-Hodgman); returns the
/// bounding box `[u_min, v_min, u_max, v_max]` of the result, `None` when empty.
pub(super) fn clip_bbox(
    rect: [f64; 4],
    hps: &[Hp],
    poly: &mut Vec<(f64, f64)>,
    tmp: &mut Vec<(f64, f64)>,
) -> Option<[f64; 4]> {
    let [u0, v0, u1, v1] = rect;
    if !(u0 <= u1 && v0 <= v1) {
        return None;
    }
    poly.clear();
    poly.extend_from_slice(&[(u0, v0), (u1, v0), (u1, v1), (u0, v1)]);
    for hp in hps {
        tmp.clear();
        let f = |p: (f64, f64)| hp.a * p.0 + hp.b * p.1 - hp.c;
        let mut p = poly[poly.len() - 1];
        let mut fp = f(p);
        for &q in poly.iter() {
            let fq = f(q);
            if fp <= 0.0 {
                tmp.push(p);
            }
            if (fp <= 0.0) != (fq <= 0.0) {
                let t = fp / (fp - fq);
                tmp.push((p.0 + t * (q.0 - p.0), p.1 + t * (q.1 - p.1)));
            }
            p = q;
            fp = fq;
        }
        std::mem::swap(poly, tmp);
        if poly.is_empty() {
            return None;
        }
    }
    let mut bb = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for &(u, v) in poly.iter() {
        bb = [bb[0].min(u), bb[1].min(v), bb[2].max(u), bb[3].max(v)];
    }
    Some(bb)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clip_square_by_diagonal() {
        let hps = [Hp {
            a: 1.0,
            b: 1.0,
            c: 1.0,
            inv_a: 1.0,
        }];
        let (mut p, mut q) = (Vec::new(), Vec::new());
        let r = clip_bbox([0.0, 0.0, 2.0, 2.0], &hps, &mut p, &mut q).unwrap();
        assert_eq!(r, [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(p.len(), 3);
        let hps = [Hp {
            a: 1.0,
            b: 1.0,
            c: -0.5,
            inv_a: 1.0,
        }];
        assert!(clip_bbox([0.0, 0.0, 2.0, 2.0], &hps, &mut p, &mut q).is_none());
    }
}
