//! Sample positions within a pixel, shared by every pixel of the image.
//!
//! One pattern for all pixels keeps the tile cone march valid (every ray of a tile goes
//! through the same offset of its pixel, `render::cone`) and makes a pixel's samples
//! independent of where a crop starts. `n = k * k` samples form a stratified k x k grid
//! of cell centres; other counts take the first `n` points of the R2 sequence (Roberts
//! 2018, the additive recurrence on the plastic number), which are well spread for every
//! `n`. One sample is the pixel centre, today's image.

/// A sample offset in `[0, 1)^2` from the pixel's top-left corner, with its filter
/// weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    pub offset: [f64; 2],
    pub weight: f64,
}

/// The `n` sample offsets of every pixel, weighted by `filter`.
pub fn pattern(n: u32, filter: super::Filter) -> Vec<Sample> {
    let k = (n as f64).sqrt().round() as u32;
    let offsets: Vec<[f64; 2]> = if k * k == n {
        (0..n)
            .map(|i| {
                let (ix, iy) = (i % k, i / k);
                [
                    (f64::from(ix) + 0.5) / f64::from(k),
                    (f64::from(iy) + 0.5) / f64::from(k),
                ]
            })
            .collect()
    } else {
        // The plastic number g solves g^3 = g + 1.
        let g = 1.324_717_957_244_746_f64;
        let (a1, a2) = (1.0 / g, 1.0 / (g * g));
        (0..n)
            .map(|i| {
                let i = f64::from(i);
                [(0.5 + a1 * i).fract(), (0.5 + a2 * i).fract()]
            })
            .collect()
    };
    offsets
        .into_iter()
        .map(|offset| Sample {
            offset,
            weight: filter.weight(offset[0] - 0.5, offset[1] - 0.5),
        })
        .collect()
}

/// The index of the sample nearest the pixel centre (the first of equals): the one whose
/// depth, normal, object and position the AOVs record.
pub fn primary(samples: &[Sample]) -> usize {
    let d = |s: &Sample| (s.offset[0] - 0.5).powi(2) + (s.offset[1] - 0.5).powi(2);
    let mut best = 0;
    for (i, s) in samples.iter().enumerate() {
        if d(s) < d(&samples[best]) {
            best = i;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::Filter;

    #[test]
    fn one_sample_is_the_centre() {
        assert_eq!(
            pattern(1, Filter::Box),
            vec![Sample {
                offset: [0.5, 0.5],
                weight: 1.0
            }]
        );
    }

    #[test]
    fn square_counts_are_stratified_grids() {
        let p = pattern(4, Filter::Box);
        let offs: Vec<_> = p.iter().map(|s| s.offset).collect();
        assert_eq!(
            offs,
            vec![[0.25, 0.25], [0.75, 0.25], [0.25, 0.75], [0.75, 0.75]]
        );
        // Every cell of a 3 x 3 grid holds exactly one of 9 samples.
        let p = pattern(9, Filter::Box);
        for cx in 0..3 {
            for cy in 0..3 {
                let inside = p
                    .iter()
                    .filter(|s| {
                        (s.offset[0] * 3.0) as i32 == cx && (s.offset[1] * 3.0) as i32 == cy
                    })
                    .count();
                assert_eq!(inside, 1, "cell {cx},{cy}");
            }
        }
    }

    #[test]
    fn other_counts_are_spread_over_the_pixel() {
        for n in [2, 3, 5, 6, 7, 8, 12] {
            let p = pattern(n, Filter::Gaussian);
            assert_eq!(p.len(), n as usize);
            // The closest pair is not much closer than a grid of n points would have.
            let mut closest = f64::INFINITY;
            for (i, a) in p.iter().enumerate() {
                assert!(
                    a.offset.iter().all(|&c| (0.0..1.0).contains(&c)),
                    "{n}: {a:?}"
                );
                assert!(a.weight > 0.0 && a.weight <= 1.0);
                for b in &p[i + 1..] {
                    let d = ((a.offset[0] - b.offset[0]).powi(2)
                        + (a.offset[1] - b.offset[1]).powi(2))
                    .sqrt();
                    closest = closest.min(d);
                }
            }
            assert!(
                closest > 0.4 / (n as f64).sqrt(),
                "{n}: closest pair {closest}"
            );
        }
    }

    #[test]
    fn primary_is_the_sample_nearest_the_centre() {
        assert_eq!(primary(&pattern(1, Filter::Box)), 0);
        assert_eq!(primary(&pattern(9, Filter::Box)), 4);
        let p = pattern(5, Filter::Box);
        // R2 starts at the centre.
        assert_eq!(primary(&p), 0);
    }
}
