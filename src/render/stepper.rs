//! Over-relaxed sphere-tracing steps and their certificate (SPEC 7; Keinert et al. 2014,
//! "Enhanced sphere tracing"): the step lengths the tracer (`render::tracer`) takes,
//! each kept only when the next sample's ball closes the gap it leaves.

/// Which evaluation a sample came from (slopes are only estimated between samples of
/// the same kind: a bound and a full value of the same point differ).
#[derive(Clone, Copy, PartialEq)]
pub(super) enum Kind {
    Bound,
    /// A full value at the scene's (step) beta.
    Full,
    /// A full value at the finer hit beta, where that differs (tracer item 9).
    Fine,
}

/// Over-relaxed step lengths with their certificate (Keinert et al. 2014, "Enhanced
/// sphere tracing"). A sample at `t` with a lower bound `s` of the field certifies the
/// ball of radius `s` around it, so the ray is free of the surface on `[t, t + s]`; a
/// step longer than `s`, to `t + L`, is kept only if the next sample's ball reaches back
/// over the gap: `s + s_next >= L`. Otherwise the ray returns to `t + s` (the plain step)
/// and goes on from there: every accepted step is as safe as a plain one. On point
/// clouds both ends certify more than their balls: the free distance ahead of the first
/// sample (`eval::reach`, the step it takes when longer) and the free distance behind
/// the next one (the same bound along `-u`, asked for only when its ball falls short,
/// [`Stepper::needed`]). Near a surface met at an angle the field grows going back along
/// the ray, and that reach is often several times `s_next`.
///
/// The length is chosen from the slope `k` of the field along the ray, estimated from
/// the last two samples: if the field keeps it, `s_next = s - k L`, and the largest `L`
/// with overlap is `2 s / (1 + k)`. A factor `RELAX_MARGIN` below that absorbs
/// curvature; at grazing incidence (`k` small), where plain sphere tracing needs the
/// most steps (each removes only a share `k` of the value), steps nearly double.
pub(super) struct Stepper {
    on: bool,
    /// Slope of the field along the ray (decrease per unit of `t`) from the last two
    /// samples of the same kind, in `[0, 1]`; 1 (no relaxation) until known.
    pub(super) slope: f64,
    /// `slope` was measured (the last two samples were of the same kind), not assumed.
    pub(super) slope_known: bool,
    last: Option<(f64, f64, Kind)>,
    /// The last step was longer than its sample's value.
    relaxed: bool,
    /// The last step was aimed at the crossing (`Stepper::aim`).
    pub(super) aimed: bool,
}

/// Share of the overlap limit `2 s / (1 + k)` a relaxed step takes.
const RELAX_MARGIN: f64 = 0.9;

impl Stepper {
    pub(super) fn new(on: bool) -> Stepper {
        Stepper {
            on,
            slope: 1.0,
            slope_known: false,
            last: None,
            relaxed: false,
            aimed: false,
        }
    }

    /// How far behind `t` the sample there must certify the ray free for the last step
    /// to stand: the gap the last step left past its sample's certified distance (0 when
    /// the step was not relaxed).
    pub(super) fn needed(&self, prev: Option<(f64, f64, f64)>, t: f64) -> f64 {
        match prev {
            Some((tp, _, sp)) if self.relaxed => t - tp - sp,
            _ => 0.0,
        }
    }

    /// If the last step was relaxed and the sample at `t` (free distance `back >= 0`
    /// behind it: its lower bound `s`, or more on point clouds) does not close the gap,
    /// the plain step's end to go back to (the slope is forgotten).
    pub(super) fn uncovered(
        &mut self,
        prev: Option<(f64, f64, f64)>,
        t: f64,
        back: f64,
    ) -> Option<f64> {
        let (tp, _, sp) = prev?;
        if !self.relaxed || back >= self.needed(prev, t) {
            return None;
        }
        self.relaxed = false;
        self.aimed = false;
        self.slope = 1.0;
        self.slope_known = false;
        self.last = None;
        Some(tp + sp)
    }

    /// Lengthens the step just returned by [`Stepper::step`] to `len`, aimed at where the
    /// field's tangent along the ray crosses zero (`render::tracer` item 12): past the
    /// sample's free distance `reach` it is a relaxed step, whose gap the next sample
    /// must close as any other (or land in the hit band).
    pub(super) fn aim(&mut self, len: f64, reach: f64) {
        self.relaxed = len > reach;
        self.aimed = true;
    }

    /// The step just returned by [`Stepper::step`] was lengthened to a point certified
    /// by other means (the neighbours' balls): nothing is left for the next sample to
    /// cover. The slope stays: it was measured between samples.
    pub(super) fn certified(&mut self) {
        self.relaxed = false;
    }

    /// The step to take from `t`, where the field is at least `s > 0`.
    /// `reach >= s` is the sample's certified free distance (`s` for a plain sample).
    pub(super) fn step(
        &mut self,
        prev: Option<(f64, f64, f64)>,
        t: f64,
        s: f64,
        reach: f64,
        kind: Kind,
    ) -> f64 {
        if let (Some((tl, sl, kl)), Some(_)) = (self.last, prev)
            && kl == kind
            && t > tl
        {
            self.slope = ((sl - s) / (t - tl)).clamp(0.0, 1.0);
            self.slope_known = true;
        } else {
            self.slope = 1.0;
            self.slope_known = false;
        }
        self.last = Some((t, s, kind));
        self.aimed = false;
        let factor = if self.on {
            (RELAX_MARGIN * 2.0 / (1.0 + self.slope)).max(1.0)
        } else {
            1.0
        };
        let relaxed = factor * s;
        self.relaxed = relaxed > reach;
        relaxed.max(reach)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Marches a 1-D field (`lower(t)` a lower bound of a 1-Lipschitz `f`) the way the
    /// tracer does, returning the hit `t` and the number of samples.
    fn march(lower: impl Fn(f64) -> f64, eps: f64, relax: bool) -> (f64, u32) {
        let mut stepper = Stepper::new(relax);
        let (mut t, mut prev, mut n) = (0.0, None, 0);
        loop {
            let s = lower(t);
            n += 1;
            assert!(n < 10_000, "no convergence");
            if let Some(back) = stepper.uncovered(prev, t, s) {
                t = back;
                continue;
            }
            if s <= eps {
                return (t, n);
            }
            let step = stepper.step(prev, t, s, s, Kind::Full);
            prev = Some((t, s, s));
            t += step;
        }
    }

    #[test]
    fn relaxed_steps_never_pass_the_first_zero() {
        // Fields with zeros at random places, reached at random slopes, some of them
        // isolated points (a thin feature the ray only touches); the samples are a
        // random share (60-100%) of the field, as Barnes-Hut lower bounds are.
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut plain_n, mut relaxed_n) = (0, 0);
        for _ in 0..2000 {
            let zeros: Vec<(f64, f64)> = (0..4)
                .map(|_| (1.0 + 99.0 * rnd(), 0.02 + 0.98 * rnd()))
                .collect();
            let first = zeros.iter().map(|z| z.0).fold(f64::INFINITY, f64::min);
            let f = |t: f64| {
                zeros
                    .iter()
                    .map(|&(z, k)| k * (z - t).abs())
                    .fold(f64::INFINITY, f64::min)
            };
            let share = 0.6 + 0.4 * rnd();
            let wobble = rnd();
            let lower = |t: f64| f(t) * (share + (1.0 - share) * (t * wobble).sin().abs());
            let eps = 1e-3;
            for relax in [false, true] {
                let (t, n) = march(lower, eps, relax);
                assert!(
                    t <= first,
                    "passed the first zero {first} at {t} (relax {relax})"
                );
                // The sample there was at most eps, and at least 60% of the field.
                assert!(
                    f(t) <= eps / 0.6,
                    "stopped at {t} where the field is {}",
                    f(t)
                );
                if relax {
                    relaxed_n += n;
                } else {
                    plain_n += n;
                }
            }
        }
        assert!(
            relaxed_n < plain_n * 9 / 10,
            "relaxed {relaxed_n} vs plain {plain_n} samples"
        );
    }
}
