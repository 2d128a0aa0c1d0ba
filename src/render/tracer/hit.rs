//! A ray's hit (SPEC 7; `render::tracer` items 4, 12 and 13): where a sample in the hit
//! band puts it (one more step, free, from a positive value; back to the crossing's
//! first-order estimate from a negative one where the step that got there was not
//! certain), the samples just above the band whose free step is predicted to end in it,
//! and the aimed steps that land samples in the band.

use super::Tracer;
use super::ray::{Hit, RayStats};
use super::sample::FieldSample;
use glam::DVec3;

/// Aimed steps (module docs, item 12) are taken from values within this many epsilons,
pub(super) const AIM_MAX: f64 = 40.0;

/// where the field falls along the ray at least this fast: a landing in the band at a
/// fall `k` may lie `epsilon / k` from the crossing along the ray (at 0.1 the 7k bunny's
/// points had the 99th percentile of their depth error 1.2-1.6 epsilons farther from the
/// exact surface; at 0.3 within 0.9, nearly all the leaves still spared:
/// doc/performance-log.md, round twenty-six),
const AIM_MIN_FALL: f64 = 0.3;

/// and at most this many times as long as the step they replace.
pub(super) const AIM_CAP: f64 = 2.0;

/// The final step's longest reach, in units of the hit's value `s` (module docs, item
/// 4): a ray that meets the surface at a slope of 1/2 or more (30 degrees) crosses it
/// within `2 s`. The free distance may certify more, but on a ray that skims bumpy ground
/// (the lidar scan's trees) a longer step carries the hit past its closest approach
/// (the exact value at the hits for caps of 1, 2 and 4 `s`: doc/performance-log.md,
/// round twelve).
pub(super) const FINAL_REACH: f64 = 2.0;

/// A sample at most this many epsilons above the hit band may be the hit (module docs,
/// item 13),
pub(super) const BAND_REACH_MAX: f64 = 8.0;

/// The same on soft triangle meshes (`TraceObject::soft_triangles`), whose hits are
/// decided at a coarser beta with the directional far field: from 8 epsilons out the
/// landings missed by up to 3 epsilons on more of their rays (doc/performance-log.md,
/// round twenty-nine).
pub(super) const BAND_REACH_MAX_SOFT_TRIANGLES: f64 = 6.0;

/// where its final step is predicted to end at most this many epsilons above zero
/// (first order, from the gradient),
const BAND_REACH_LAND: f64 = 0.25;

/// and the field falls along the ray at least this fast.
const BAND_REACH_MIN_FALL: f64 = 0.1;

impl Tracer<'_> {
    /// The hit at the sample `f` at `t`; `floor` is a parameter known to lie in front of
    /// the crossing (the last positive sample's, or `t`).
    pub(in crate::render) fn hit(
        &self,
        o: DVec3,
        d: DVec3,
        (t, floor): (f64, f64),
        f: &FieldSample,
        stats: &mut RayStats,
    ) -> Hit {
        self.hit_moved(o, d, (t, floor), f, self.weighted[f.object], stats)
    }

    /// The hit where an aimed step landed in the hit band (item 12): its gap behind is
    /// not covered, so at a negative value it is moved back to the crossing's estimate,
    /// at most as far as a final step moves on (`FINAL_REACH |s|`).
    pub(super) fn landing(
        &self,
        o: DVec3,
        d: DVec3,
        (t, floor): (f64, f64),
        f: &FieldSample,
        stats: &mut RayStats,
    ) -> Hit {
        let floor = floor.max(t + FINAL_REACH * f.s.min(0.0));
        self.hit_moved(o, d, (t, floor), f, true, stats)
    }

    /// Whether the sample `f`, above the hit band, is the hit all the same (module docs,
    /// item 13): on an object that takes such hits, within [`BAND_REACH_MAX`] epsilons
    /// ([`BAND_REACH_MAX_SOFT_TRIANGLES`] on soft triangle meshes),
    /// with the gradient, where the field falls along the ray at least
    /// [`BAND_REACH_MIN_FALL`] and its final step (`s`, or the free distance up to
    /// [`FINAL_REACH`] `s`) ends, to first order, within [`BAND_REACH_LAND`] epsilons
    /// of zero.
    pub(super) fn lands_in_band(&self, f: &FieldSample, d: DVec3) -> bool {
        let eps = self.options.epsilon;
        let most = self.band_reach[f.object];
        if most == 0.0 || f.s <= eps || f.s > most * eps {
            return false;
        }
        let Some(g) = f.grad else {
            return false;
        };
        let Some(bend) = f.bend else {
            return false;
        };
        let k = -g.dot(d);
        let len = f.reach.max(f.s).min(FINAL_REACH * f.s);
        // The bend only where it lifts the field: where it lowers it, the first order
        // alone decides.
        k >= BAND_REACH_MIN_FALL
            && f.s - k * len + 0.5 * bend.max(0.0) * len * len <= BAND_REACH_LAND * eps
    }

    /// The length of an aimed step from the sample `f` at `t` whose step is `step`, if
    /// one is taken (item 12): to where `s - k L + c L^2 / 2` crosses zero (`k` the
    /// field's fall along the ray, `c` its bend; `s / k` without a bend), the root
    /// `2 s / (k + sqrt(k^2 - 2 c s))`, where that is longer than the step, at most
    /// [`AIM_CAP`] times it, and short of `t_max`; none where the expansion stays above
    /// zero.
    pub(super) fn aimed_step(
        &self,
        f: &FieldSample,
        (t, t_max): (f64, f64),
        step: f64,
    ) -> Option<f64> {
        if !self.aims[f.object] || f.s > AIM_MAX * self.options.epsilon {
            return None;
        }
        let k = -f.slope?;
        let len = match f.bend {
            Some(c) => {
                let disc = k * k - 2.0 * c * f.s;
                if disc < 0.0 {
                    return None;
                }
                2.0 * f.s / (k + disc.sqrt())
            }
            None => f.s / k,
        };
        (k > AIM_MIN_FALL && len > step && len <= AIM_CAP * step && t + len < t_max).then_some(len)
    }

    /// [`Tracer::hit`], a hit at a negative value moved back to the crossing's estimate
    /// if `back` (edges and triangles, whose free distances hold to first order; an aimed
    /// step's landing, whose gap is not covered).
    fn hit_moved(
        &self,
        o: DVec3,
        d: DVec3,
        (t, floor): (f64, f64),
        f: &FieldSample,
        back: bool,
        stats: &mut RayStats,
    ) -> Hit {
        let grad = match f.grad {
            Some(g) => g,
            // At a hit the value is within epsilon.
            None => self.gradient(f.object, o + t * d, self.options.epsilon, stats),
        };
        // Where the field falls along the ray (`k > 0`): one more step, free, from a
        // positive value (the sample's ball, or its free distance along the ray, is
        // empty), or from a negative one back to the crossing's first-order estimate
        // (module docs, item 4). (A free distance is never below `s`, and never NaN;
        // `max` keeps it so.)
        let k = -grad.dot(d);
        let falls = k > 0.0;
        let t = if !self.options.final_step || !falls {
            t
        } else if f.s > 0.0 {
            t + f.reach.max(f.s).min(FINAL_REACH * f.s)
        } else if back {
            (t + f.s / k).max(floor).min(t)
        } else {
            t
        };
        let point = o + t * d;
        Hit {
            t,
            point,
            normal: grad.normalize_or_zero(),
            object: f.object,
        }
    }
}
