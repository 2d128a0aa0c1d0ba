//! Empty balls shared between neighbouring rays of a tile (SPEC 7, after the tile's cone
//! march): a ray starts past the stretch of it that the balls of the rays traced just
//! before it already certify, and moves on through them again wherever its own steps
//! reach them.
//!
//! Every sample a ray takes at `x` with a lower bound `s > 0` of the field certifies the
//! ball of radius `s` around `x` free of the surface (the assumption every
//! sphere-tracing step makes). The ball is not tied to the ray that took the sample: a
//! neighbouring ray `o + t d` (unit `d`) meets it on the chord `[t_c - h, t_c + h]`, `t_c =
//! (x - o) . d` the foot of the centre on the ray, `h = sqrt(s^2 - |x - o - t_c d|^2)`.
//! The new ray starts at `t0` (the tile's cone-marched start, itself certified); while a
//! chord contains `t0`, `t0` moves to the chord's end. The chords so chained are inside
//! the balls, so the skipped stretch is as safe as the tracer's own steps. Chords past a
//! gap are not lost: whenever the ray's own certified stretch reaches one (the end of a
//! step's ball or free distance), the ray moves on through the chain that starts there
//! ([`Neighbours::advance`]). Rays skimming a surface meet their neighbours' balls all
//! along it, not only at the start.
//!
//! Primary rays of neighbouring pixels are a pixel's footprint apart at the surface
//! (about 6 epsilons at 1920x1080 at the centre of the lidar scan), and the samples
//! before a hit have values of a few to tens of epsilons: the balls of the rays traced
//! just before (the tile's quarters are traced in Z order, so these are mostly the
//! pixels to the left and above) carry a ray past some of its bound steps and often its
//! first full evaluation (doc/performance-log.md, round eight).
//! The last axis sample of each cone march that encloses the ray (`render::cone`) is a
//! ball too: the march stops where the cone's radius eats half of its value, but a ray
//! off the axis by `c` still meets that ball on a chord of half-length `sqrt(s^2 - c^2)`.
//! Only balls of the same tile and sample pass are used, so a render does not depend on
//! how tiles are spread over threads (and a crop traces its tiles as the whole image does).
//!
//! On point clouds a sample certifies more than its ball: its free distance `R >= s`
//! along its own ray `u` (`eval::reach`) comes from a lower bound `b(L)` of the field at
//! `x + L u` that is concave in `L`, with `b(0) = s` and `b(R) >= 0`, so `b(L) >= s (1 -
//! L / R)` on `[0, R]` (above the chord), and the ball of that radius around `x + L u` is
//! empty too (the field is 1-Lipschitz). Together these balls make the convex hull of
//! the sample's ball and the point `x + R u`, an ice-cream cone pointing along the ray
//! (the sample's free cone), which reaches the neighbouring rays where the ball alone
//! does not (near the surface the steps are one to three times their value long, and
//! neighbouring rays a few epsilons apart). The free cone is kept as `FREE_CONE_BALLS`
//! balls inside it, at `L = R/4, R/2, 3R/4` with radii `3s/4, s/2, s/4`: a subset of it,
//! so as safe as the ball.
//!
//! A ball reaches another ray of the tile only if its radius exceeds its distance to
//! that ray, at least `t` times the tile's pixel pitch (the smallest distance per unit of
//! `t` between two of its rays) for a centre at distance `t` from the camera: narrower
//! balls are not kept (on the lidar scan, most of those near the surface), which keeps
//! the chords cheap while more rays are kept. Dropping a ball only forgoes a
//! certificate.

use glam::DVec3;

/// Rays whose balls are kept (the last ones traced; 960x540, leaves per ray with 4 / 8 /
/// 16 / 32: the deer at alpha 2 49.4 / 47.2 / 45.6 / 44.8, the bunny's points 106.9 /
/// 99.4 / 94.7 / 92.0, the lidar 147.9 / 147.8 / 147.7 / 147.6).
const KEPT_RAYS: usize = 16;

/// Share of the tile's pixel pitch under which a ball is not kept (module docs): a little
/// under the pitch, which is measured at the tile's corners.
const PITCH_SHARE: f64 = 0.9;

/// Balls kept inside the free cone of a sample's free distance along its ray (module docs;
/// the deer at alpha 2, 960x540, leaves per ray: 56.9 with none, 54.7 with one, 54.0
/// with three, 53.7 with seven; with 16 kept rays 46.0 / 45.6 / 45.4 for one, three,
/// seven, the trace as fast with one or three, 2-3% slower with seven).
const FREE_CONE_BALLS: usize = 3;

/// Radii are shrunk by this share before use: the chord's end is computed in floating
/// point from a difference of squares, and must not leave the ball.
const RADIUS_MARGIN: f64 = 1e-9;

/// A certified empty ball: the field is at least `radius` at `centre`.
#[derive(Clone, Copy, Debug)]
struct Ball {
    centre: DVec3,
    radius: f64,
}

/// The balls of the last rays traced in a tile, and those of the ray being traced.
#[derive(Default)]
pub struct Neighbours {
    /// Balls of the kept rays, oldest ray first.
    balls: Vec<Ball>,
    /// How many of `balls` each kept ray contributed, oldest first.
    counts: std::collections::VecDeque<usize>,
    /// Balls of the ray being traced.
    current: Vec<Ball>,
    /// Balls of the cone marches enclosing the rays being traced (a stack: one per
    /// level of the tile's quarters).
    cones: Vec<Ball>,
    /// Scratch: chords of the kept balls on the ray being started.
    chords: Vec<(f64, f64)>,
    /// Balls narrower than this many times their distance from `origin` are not kept.
    min_share: f64,
    /// The origin of the ray being traced (the camera).
    origin: DVec3,
    /// The first of `chords` (sorted by start) not yet chained.
    next: usize,
    /// The end of the last chain: `[t, reached]` is certified for every certified `t`
    /// at or past the point the chain started from.
    reached: f64,
}

impl Neighbours {
    /// The balls of a tile whose rays are at least `pitch` apart per unit of distance from
    /// the camera (0: every ball is kept).
    pub fn new(pitch: f64) -> Neighbours {
        Neighbours {
            min_share: PITCH_SHARE * pitch,
            ..Neighbours::default()
        }
    }

    /// Starts the ray `o + t d` (unit `d`) at a certified `t0`: the farthest `t >= t0`
    /// such that `[t0, t]` lies in a chain of the kept balls (`t0` if no ball contains
    /// it). Their chords further on are kept for [`Neighbours::advance`].
    pub fn start(&mut self, o: DVec3, d: DVec3, t0: f64) -> f64 {
        self.origin = o;
        self.chords.clear();
        for b in self.balls.iter().chain(&self.cones) {
            let r = b.radius * (1.0 - RADIUS_MARGIN);
            let tc = (b.centre - o).dot(d);
            let off2 = (b.centre - o - tc * d).length_squared();
            if r * r > off2 {
                let h = (r * r - off2).sqrt();
                if tc + h > t0 {
                    self.chords.push((tc - h, tc + h));
                }
            }
        }
        self.chords.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        self.next = 0;
        self.reached = t0;
        self.advance(t0)
    }

    /// The farthest point the ray being traced reaches from `t` through the chords of
    /// the kept balls, for a `t` up to which the ray is certified free (the end of a
    /// sample's ball or free distance), and never behind a `t` given before (the
    /// tracer's certified stretch only grows; a rejected relaxed step goes back to its
    /// end, which this call then moves on again to where the chain reached).
    pub fn advance(&mut self, t: f64) -> f64 {
        // A chain reached from an earlier certified point covers `[t, reached]`.
        let mut t = t.max(self.reached);
        while let Some(&(a, b)) = self.chords.get(self.next) {
            if a > t {
                break;
            }
            t = t.max(b);
            self.next += 1;
        }
        self.reached = t;
        t
    }

    /// Records a sample of the ray being traced: the field is at least `s` at `x`. Its ball
    /// is kept for the next rays if it can reach one (module docs).
    pub fn note(&mut self, x: DVec3, s: f64) {
        if s > 0.0 && s > self.min_share * (x - self.origin).length() {
            self.current.push(Ball {
                centre: x,
                radius: s,
            });
        }
    }

    /// Records a sample of the ray being traced whose free distance along the ray's unit
    /// direction `u` is `reach >= s`: its ball and the balls inside the free cone that
    /// distance certifies (module docs).
    pub fn note_along(&mut self, x: DVec3, s: f64, u: DVec3, reach: f64) {
        self.note(x, s);
        if s > 0.0 && reach > s {
            for j in 1..=FREE_CONE_BALLS {
                let share = j as f64 / (FREE_CONE_BALLS + 1) as f64;
                self.note(x + share * reach * u, (1.0 - share) * s);
            }
        }
    }

    /// Enters a cone march's sub-tiles: the field is at least `s` at `x` on its axis.
    /// Returns the mark to [`Neighbours::leave_cone`] with.
    pub fn enter_cone(&mut self, x: DVec3, s: f64) -> usize {
        let mark = self.cones.len();
        if s > 0.0 {
            self.cones.push(Ball {
                centre: x,
                radius: s,
            });
        }
        mark
    }

    /// Leaves the cone march entered with `mark`.
    pub fn leave_cone(&mut self, mark: usize) {
        self.cones.truncate(mark);
    }

    /// Ends the ray being traced: its balls are kept, the oldest ray's dropped.
    pub fn finish_ray(&mut self) {
        self.counts.push_back(self.current.len());
        self.balls.append(&mut self.current);
        while self.counts.len() > KEPT_RAYS {
            let n = self.counts.pop_front().unwrap_or(0);
            self.balls.drain(..n);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chained_chords_stay_inside_the_balls() {
        let mut n = Neighbours::new(0.0);
        // A ray along x at height 0.3: balls of radius 1 at x = 0, 1.5 and 4 (a gap
        // between the second and the third).
        for x in [0.0, 1.5, 4.0] {
            n.note(DVec3::new(x, 0.3, 0.0), 1.0);
        }
        n.finish_ray();
        let (o, d) = (DVec3::new(-10.0, 0.0, 0.0), DVec3::X);
        let h = (1.0f64 - 0.09).sqrt();
        let t = n.start(o, d, 10.0 - 0.5);
        assert!((t - (10.0 + 1.5 + h)).abs() < 1e-6, "{t}");
        // Every point of [t0, t] is inside some ball.
        let inside = |t: f64| {
            n.balls
                .iter()
                .any(|b| (o + t * d - b.centre).length() <= b.radius)
        };
        assert!((0..=1000).all(|k| inside(9.5 + (t - 9.5) * k as f64 / 1000.0)));
        // A start outside every ball does not move; nor does one past the chords.
        assert_eq!(n.start(o, d, 5.0), 5.0);
        assert_eq!(n.start(o, d, 20.0), 20.0);
        // A ray farther than the radius meets no ball.
        assert_eq!(n.start(DVec3::new(-10.0, 1.4, 0.0), d, 10.0), 10.0);
    }

    #[test]
    fn chords_past_a_gap_are_chained_when_the_ray_reaches_them() {
        let mut n = Neighbours::new(0.0);
        // Balls of radius 1 at x = 0, 1.5 (a chain), 4 and 5.5 (another, past a gap), 9.
        for x in [0.0, 1.5, 4.0, 5.5, 9.0] {
            n.note(DVec3::new(x, 0.3, 0.0), 1.0);
        }
        n.finish_ray();
        let (o, d) = (DVec3::new(-10.0, 0.0, 0.0), DVec3::X);
        let h = (1.0f64 - 0.09).sqrt();
        let first = n.start(o, d, 9.5);
        assert!((first - (11.5 + h)).abs() < 1e-6, "{first}");
        // A step certified to a point in the gap moves nowhere.
        assert_eq!(n.advance(12.8), 12.8);
        // One certified into the second chain moves to its end.
        let second = n.advance(14.0 - h + 0.01);
        assert!((second - (15.5 + h)).abs() < 1e-6, "{second}");
        // A rejected relaxed step goes back to a certified point inside that chain: the
        // chain's end still stands.
        assert_eq!(n.advance(14.5), second);
        // Chains consumed are not walked again; the last ball is reached on its own.
        assert_eq!(n.advance(17.0), 17.0);
        let last = n.advance(19.0 - h + 0.01);
        assert!((last - (19.0 + h)).abs() < 1e-6, "{last}");
        // Everything between a certified point and where it was moved is inside a ball.
        let inside = |t: f64| {
            n.balls
                .iter()
                .any(|b| (o + t * d - b.centre).length() <= b.radius)
        };
        for (a, b) in [
            (9.5, first),
            (14.0 - h + 0.01, second),
            (19.0 - h + 0.01, last),
        ] {
            assert!((0..=1000).all(|k| inside(a + (b - a) * k as f64 / 1000.0)));
        }
    }

    #[test]
    fn the_free_cone_of_a_sample_reaches_a_neighbour_the_ball_does_not() {
        // A sample at the origin with value 1 and free distance 4 along x; a parallel
        // ray at a lateral offset of 0.6.
        let (o, d) = (DVec3::new(-10.0, 0.6, 0.0), DVec3::X);
        let mut ball = Neighbours::new(0.0);
        ball.note(DVec3::ZERO, 1.0);
        ball.finish_ray();
        let mut free = Neighbours::new(0.0);
        free.note_along(DVec3::ZERO, 1.0, DVec3::X, 4.0);
        free.finish_ray();
        let t_ball = ball.start(o, d, 10.0);
        let t_free = free.start(o, d, 10.0);
        assert!((t_ball - 10.8).abs() < 1e-6, "{t_ball}");
        assert!(t_free > t_ball + 0.5, "{t_free} vs {t_ball}");
        // Every point of the stretch is inside the free cone: within s (1 - L / R) of some
        // point x + L u of the sample's free stretch.
        for k in 0..=1000 {
            let y = o + (10.0 + (t_free - 10.0) * k as f64 / 1000.0) * d;
            let inside = (0..=4000).any(|i| {
                let l = 4.0 * i as f64 / 4000.0;
                (y - l * DVec3::X).length() <= 1.0 - l / 4.0 + 1e-9
            });
            assert!(inside, "{y} outside the free cone");
        }
        // No free distance beyond the ball: the ball alone.
        let mut plain = Neighbours::new(0.0);
        plain.note_along(DVec3::ZERO, 1.0, DVec3::X, 1.0);
        plain.finish_ray();
        assert_eq!(plain.balls.len(), 1);
    }

    #[test]
    fn cone_balls_last_until_their_march_is_left() {
        let mut n = Neighbours::new(0.0);
        let (o, d) = (DVec3::ZERO, DVec3::Z);
        let outer = n.enter_cone(DVec3::new(0.0, 0.0, 10.0), 2.0);
        let inner = n.enter_cone(DVec3::new(0.1, 0.0, 11.5), 1.0);
        // A ray's own balls come and go; the cones' stay.
        n.note(DVec3::new(0.0, 0.0, 50.0), 1.0);
        n.finish_ray();
        let t = n.start(o, d, 9.0);
        assert!((t - (11.5 + (1.0f64 - 0.01).sqrt())).abs() < 1e-6, "{t}");
        n.leave_cone(inner);
        assert!((n.start(o, d, 9.0) - 12.0).abs() < 1e-6);
        n.leave_cone(outer);
        assert_eq!(n.start(o, d, 9.0), 9.0);
        // A march whose axis value certifies nothing pushes no ball.
        let mark = n.enter_cone(DVec3::ZERO, f64::NAN);
        assert!(n.cones.is_empty());
        n.leave_cone(mark);
    }

    #[test]
    fn only_the_last_rays_are_kept() {
        let mut n = Neighbours::new(0.0);
        let rays = KEPT_RAYS + 6;
        for k in 0..rays {
            n.note(DVec3::new(k as f64, 0.0, 0.0), 0.25);
            n.note(DVec3::new(k as f64, 1.0, 0.0), 0.25);
            n.finish_ray();
        }
        assert_eq!(n.balls.len(), 2 * KEPT_RAYS);
        assert_eq!(n.balls[0].centre.x, (rays - KEPT_RAYS) as f64);
        // Non-positive values certify nothing.
        n.note(DVec3::ZERO, 0.0);
        n.note(DVec3::ZERO, -1.0);
        assert!(n.current.is_empty());
    }

    #[test]
    fn balls_narrower_than_the_pixel_pitch_are_not_kept() {
        // Rays from the origin 0.01 apart per unit of distance: at distance 10 a ball
        // must be wider than 0.09 to be kept.
        let mut n = Neighbours::new(0.01);
        let (o, d) = (DVec3::ZERO, DVec3::Z);
        n.start(o, d, 0.0);
        n.note(DVec3::new(0.0, 0.0, 10.0), 0.05);
        assert!(n.current.is_empty());
        n.note(DVec3::new(0.0, 0.0, 10.0), 0.2);
        assert_eq!(n.current.len(), 1);
        // The free cone's balls likewise, each by its own distance: of radii 0.15, 0.1
        // and 0.05 at distances 10.5 to 11.5, the first two are kept.
        n.note_along(DVec3::new(0.0, 0.0, 10.0), 0.2, d, 2.0);
        assert_eq!(n.current.len(), 1 + 1 + 2);
        // A neighbouring ray 0.01 per unit away meets the kept ball at distance 10.
        n.finish_ray();
        let t = n.start(o, DVec3::new(0.01, 0.0, 1.0).normalize(), 9.9);
        assert!(t > 10.1, "{t}");
    }
}
