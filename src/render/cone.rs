//! Cone marching of primary-ray tiles (SPEC 7): one bound evaluation on a tile's axis
//! advances every ray of the tile while they are far from the surface.
//!
//! All rays of a tile leave the camera origin `o`. Take the tile's axis `a` (unit) and the
//! largest angle `theta` between `a` and a ray `d_i` of the tile (attained at a corner
//! pixel: the directions within an angle of `a` form a convex set on the image plane).
//! At parameter `t`, every ray's point lies within `c(t) = t |d_i - a| <= 2 t sin(theta/2)`
//! of the axis point `q = o + t a`. If the field is at least `r` at `q` (no surface in
//! the ball of radius `r` around `q`, the assumption every sphere-tracing step makes),
//! then each ray can advance by `r - c(t)`: its segment stays within `c(t) + (r - c(t))
//! = r` of `q`. So the whole tile advances by `r - c(t)` with one evaluation.
//!
//! The evaluation is a bound step (the tracer's coarsest Barnes-Hut level, a lower bound
//! of the scene's field), so the guarantee is the same as the per-ray steps'. When the
//! cone radius eats more than half of the step, the tile splits into four and each
//! quarter goes on from the same `t` with its narrower cone; single pixels (and tiles
//! whose cone no longer advances) are traced ray by ray from the tile's `t`, each past
//! the empty balls of the tile's rays traced just before it (`render::neighbours`).

use super::neighbours::Neighbours;
use super::step_beta::StepBeta;
use super::tracer::{RayResult, RayStats, Tracer};
use crate::camera::Camera;
use glam::DVec3;

/// A cone step is taken only while the cone radius leaves at least this share of the
/// axis value as the step.
const MIN_STEP_SHARE: f64 = 0.5;

/// Tiles narrower than this (in pixels, both ways) are traced ray by ray.
const MIN_TILE: u32 = 2;

/// Work done by the tile marches (shared by the rays of each tile).
#[derive(Clone, Copy, Debug, Default)]
pub struct ConeStats {
    /// Bound evaluations on tile axes.
    pub evals: u64,
    /// Leaves visited by them.
    pub leaves: u64,
    /// Nodes visited by them.
    pub nodes: u64,
}

/// A rectangle of pixels: `x0 .. x0 + w`, `y0 .. y0 + h`.
#[derive(Clone, Copy, Debug)]
pub struct Tile {
    pub x0: u32,
    pub y0: u32,
    pub w: u32,
    pub h: u32,
}

impl Tile {
    fn quarters(&self) -> impl Iterator<Item = Tile> {
        let (w0, h0) = (self.w.div_ceil(2), self.h.div_ceil(2));
        let me = *self;
        [
            (0, 0, w0, h0),
            (w0, 0, me.w - w0, h0),
            (0, h0, w0, me.h - h0),
            (w0, h0, me.w - w0, me.h - h0),
        ]
        .into_iter()
        .filter(|q| q.2 > 0 && q.3 > 0)
        .map(move |(dx, dy, w, h)| Tile {
            x0: me.x0 + dx,
            y0: me.y0 + dy,
            w,
            h,
        })
    }
}

/// Traces every pixel of `tile`, starting at `t_start` (the camera's own clearance), and
/// calls `out(px, py, result)` for each. The ray of pixel `(px, py)` passes through the
/// image-plane point `(px + sub[0], py + sub[1])` (`[0.5, 0.5]`: pixel centres; other
/// offsets in `[0, 1)` give one sub-pixel sample per pixel for anti-aliasing, the cone
/// built from the same rays). With `cone = false` every ray is traced from `t_start`
/// without the march and the neighbours' balls (the reference the cone march must
/// reproduce); the tile's step beta (`render::step_beta`) applies either way.
#[allow(clippy::too_many_arguments)]
pub fn trace_tile(
    tracer: &Tracer,
    camera: &Camera,
    tile: Tile,
    sub: [f64; 2],
    t_start: f64,
    cone: bool,
    stats: &mut ConeStats,
    out: &mut dyn FnMut(u32, u32, RayResult),
) {
    let mut steps = StepBeta::new(tracer.options().learn_step_beta);
    if !cone || tracer.options().coarse_beta <= 0.0 {
        return trace_rays(tracer, camera, tile, sub, t_start, None, &mut steps, out);
    }
    let mut near = tracer
        .options()
        .neighbours
        .then(|| Neighbours::new(pitch(camera, tile, sub)));
    let mut march = March {
        tracer,
        camera,
        sub,
        stats,
        near: near.as_mut(),
        steps: &mut steps,
        out,
    };
    march.tile(tile, t_start);
}

/// Traces every pixel of `tile` ray by ray from `t_start`, each past its neighbours'
/// balls if `near` is given, at the tile's step beta (`render::step_beta`).
#[allow(clippy::too_many_arguments)]
fn trace_rays(
    tracer: &Tracer,
    camera: &Camera,
    tile: Tile,
    sub: [f64; 2],
    t_start: f64,
    mut near: Option<&mut Neighbours>,
    steps: &mut StepBeta,
    out: &mut dyn FnMut(u32, u32, RayResult),
) {
    for py in tile.y0..tile.y0 + tile.h {
        for px in tile.x0..tile.x0 + tile.w {
            let (o, d) = ray(camera, px, py, sub);
            let r = tracer.trace_in_tile(o, d, t_start, near.as_deref_mut(), steps);
            out(px, py, r);
        }
    }
}

/// The smallest distance per unit of `t` between the rays of two neighbouring pixels of
/// `tile`, at its corners (the pitch shrinks away from the image centre).
fn pitch(camera: &Camera, tile: Tile, sub: [f64; 2]) -> f64 {
    let (x1, y1) = (tile.x0 + tile.w - 1, tile.y0 + tile.h - 1);
    [(tile.x0, tile.y0), (x1, tile.y0), (tile.x0, y1), (x1, y1)]
        .into_iter()
        .map(|(px, py)| {
            let d = ray(camera, px, py, sub).1;
            let across = ray(camera, px + 1, py, sub).1;
            let down = ray(camera, px, py + 1, sub).1;
            (across - d).length().min((down - d).length())
        })
        .fold(f64::INFINITY, f64::min)
}

/// The ray of pixel `(px, py)` through its sub-pixel position `sub`.
fn ray(camera: &Camera, px: u32, py: u32, sub: [f64; 2]) -> (DVec3, DVec3) {
    camera.ray_through(f64::from(px) + sub[0], f64::from(py) + sub[1])
}

/// A tile's march: its quarters recursively, then ray by ray.
struct March<'m, 't> {
    tracer: &'m Tracer<'t>,
    camera: &'m Camera,
    sub: [f64; 2],
    stats: &'m mut ConeStats,
    /// The balls of the tile's last rays (`render::neighbours`), if used.
    near: Option<&'m mut Neighbours>,
    /// The tile's step beta (`render::step_beta`).
    steps: &'m mut StepBeta,
    out: &'m mut dyn FnMut(u32, u32, RayResult),
}

impl March<'_, '_> {
    /// Marches `tile` from `t_start` and traces its rays.
    fn tile(&mut self, tile: Tile, t_start: f64) {
        if tile.w < MIN_TILE || tile.h < MIN_TILE {
            return self.rays(tile, t_start);
        }
        let (tracer, sub) = (self.tracer, self.sub);
        let (o, _) = ray(self.camera, tile.x0, tile.y0, sub);
        let (x1, y1) = (tile.x0 + tile.w - 1, tile.y0 + tile.h - 1);
        let corners = [(tile.x0, tile.y0), (x1, tile.y0), (tile.x0, y1), (x1, y1)]
            .map(|(px, py)| ray(self.camera, px, py, sub).1);
        let axis = corners.iter().copied().sum::<DVec3>().normalize();
        // |d_i - a| for the widest ray: the cone radius per unit of t.
        let spread = corners
            .iter()
            .map(|&d| (d - axis).length())
            .fold(0.0, f64::max);
        // Start from the camera's own clearance (every ray's start) and let the march skip
        // the empty space before the scene box.
        let mut t = t_start;
        let t_far = tracer.farthest(o);
        let beta = tracer.options().coarse_beta;
        let mut advanced = false;
        // The last axis sample: its ball outlasts the march (`render::neighbours`).
        let mut last = None;
        while t <= t_far {
            let mut ray = RayStats::default();
            let r = tracer.bound(o + t * axis, beta, &mut ray);
            last = Some((o + t * axis, r));
            self.stats.evals += ray.coarse_evals as u64;
            self.stats.leaves += ray.eval.leaves() as u64;
            self.stats.nodes += ray.eval.nodes as u64;
            let step = r - spread * t;
            if step.is_nan() || step <= MIN_STEP_SHARE * r {
                break;
            }
            t += step;
            advanced = true;
        }
        if t > t_far {
            // Past every ray's exit from the scene box: all of them miss.
            for py in tile.y0..tile.y0 + tile.h {
                for px in tile.x0..tile.x0 + tile.w {
                    (self.out)(px, py, RayResult::default());
                }
            }
            return;
        }
        let mark = match (self.near.as_deref_mut(), last) {
            (Some(n), Some((x, r))) => Some(n.enter_cone(x, r)),
            _ => None,
        };
        if !advanced && tile.w <= 2 * MIN_TILE && tile.h <= 2 * MIN_TILE {
            self.rays(tile, t);
        } else {
            for q in tile.quarters() {
                self.tile(q, t);
            }
        }
        if let (Some(n), Some(mark)) = (self.near.as_deref_mut(), mark) {
            n.leave_cone(mark);
        }
    }

    /// Traces the rays of `tile` one by one from `t_start`.
    fn rays(&mut self, tile: Tile, t_start: f64) {
        let near = self.near.as_deref_mut();
        trace_rays(
            self.tracer,
            self.camera,
            tile,
            self.sub,
            t_start,
            near,
            self.steps,
            self.out,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pitch_is_the_smallest_step_between_neighbouring_pixel_rays() {
        // 100x100 pixels over 90 degrees: at the centre neighbouring rays are 2/100 apart
        // per unit of distance, towards the corners less.
        let cam = Camera::new(DVec3::ZERO, DVec3::NEG_Z, DVec3::Y, 90.0, 100, 100).unwrap();
        let sub = [0.5, 0.5];
        let centre = Tile {
            x0: 48,
            y0: 48,
            w: 4,
            h: 4,
        };
        let corner = Tile {
            x0: 0,
            y0: 0,
            w: 4,
            h: 4,
        };
        let (p_centre, p_corner) = (pitch(&cam, centre, sub), pitch(&cam, corner, sub));
        assert!((p_centre - 0.02).abs() < 0.01 * 0.02, "{p_centre}");
        assert!(p_corner < 0.7 * p_centre, "{p_corner} vs {p_centre}");
        // No two pixels' rays of a tile are closer than its pitch.
        for (tile, p) in [(centre, p_centre), (corner, p_corner)] {
            let pixels: Vec<(u32, u32)> = (tile.y0..tile.y0 + tile.h)
                .flat_map(|y| (tile.x0..tile.x0 + tile.w).map(move |x| (x, y)))
                .collect();
            for (i, &a) in pixels.iter().enumerate() {
                for &b in &pixels[i + 1..] {
                    let gap = (ray(&cam, a.0, a.1, sub).1 - ray(&cam, b.0, b.1, sub).1).length();
                    assert!(gap >= p * (1.0 - 1e-9), "{a:?} {b:?}: {gap} < {p}");
                }
            }
        }
    }
}
