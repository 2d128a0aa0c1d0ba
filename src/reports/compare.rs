//! Comparing two renders of the same view: per-pixel hit distances (the isosurface error
//! of the sweep, SPEC 10) and colours (the stability report's scaled renders).

use super::quantile;
use image::RgbImage;

/// How two depth buffers (ray parameter `t` per pixel, `+inf` for a miss) differ.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct DepthDiff {
    pub rays: usize,
    /// Rays that hit in both renders.
    pub both: usize,
    /// Rays that hit in exactly one of them.
    pub only_one: usize,
    /// `|t_a - t_b|` over the rays that hit in both, divided by `length`: mean, median,
    /// 95th and 99th percentiles and maximum (`None` when no ray hit in both).
    pub mean: Option<f64>,
    pub p50: Option<f64>,
    pub p95: Option<f64>,
    pub p99: Option<f64>,
    pub max: Option<f64>,
}

impl DepthDiff {
    /// Share of the rays that hit in one render and not the other, in percent.
    pub fn only_one_percent(&self) -> f64 {
        100.0 * self.only_one as f64 / self.rays.max(1) as f64
    }
}

/// Compares depth buffers `a` and `b`, `b`'s values multiplied by `b_scale` first (for a
/// render of a scaled copy of the scene), differences divided by `length` (the scene's
/// bounding-box diagonal, so errors are relative to the scene's size).
pub fn compare_depths(a: &[f32], b: &[f32], b_scale: f64, length: f64) -> DepthDiff {
    assert_eq!(a.len(), b.len(), "depth buffers of different sizes");
    let mut errs = Vec::new();
    let mut only_one = 0;
    for (&ta, &tb) in a.iter().zip(b) {
        match (ta.is_finite(), tb.is_finite()) {
            (true, true) => errs.push((ta as f64 - tb as f64 * b_scale).abs() / length),
            (false, false) => {}
            _ => only_one += 1,
        }
    }
    let mean = (!errs.is_empty()).then(|| errs.iter().sum::<f64>() / errs.len() as f64);
    let max = errs.iter().copied().reduce(f64::max);
    let both = errs.len();
    DepthDiff {
        rays: a.len(),
        both,
        only_one,
        mean,
        p50: quantile(&mut errs, 0.5),
        p95: quantile(&mut errs, 0.95),
        p99: quantile(&mut errs, 0.99),
        max,
    }
}

/// How two images of the same size differ, channel by channel (0..255).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct ColourDiff {
    /// Largest channel difference.
    pub max: u8,
    /// Mean absolute channel difference.
    pub mean: f64,
    /// Share of pixels whose largest channel difference exceeds `threshold`, percent.
    pub over_percent: f64,
    pub threshold: u8,
}

/// Compares two images pixel by pixel.
pub fn compare_images(a: &RgbImage, b: &RgbImage, threshold: u8) -> ColourDiff {
    assert_eq!(a.dimensions(), b.dimensions(), "images of different sizes");
    let (mut max, mut sum, mut over) = (0u8, 0u64, 0usize);
    for (pa, pb) in a.pixels().zip(b.pixels()) {
        let d = (0..3).map(|c| pa[c].abs_diff(pb[c])).max().unwrap_or(0);
        sum += (0..3).map(|c| pa[c].abs_diff(pb[c]) as u64).sum::<u64>();
        max = max.max(d);
        over += (d > threshold) as usize;
    }
    let n = (a.width() * a.height()).max(1) as f64;
    ColourDiff {
        max,
        mean: sum as f64 / (3.0 * n),
        over_percent: 100.0 * over as f64 / n,
        threshold,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_diff_counts_and_scales() {
        let inf = f32::INFINITY;
        let a = [1.0, 2.0, inf, inf, 4.0];
        let b = [10.0, 21.0, inf, 3.0, 40.0];
        let d = compare_depths(&a, &b, 0.1, 2.0);
        assert_eq!((d.rays, d.both, d.only_one), (5, 3, 1));
        assert!((d.max.unwrap() - 0.05).abs() < 1e-6, "{d:?}");
        assert_eq!(compare_depths(&a, &a, 1.0, 1.0).max, Some(0.0));
    }
}
