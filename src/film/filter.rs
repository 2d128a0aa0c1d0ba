//! Reconstruction filters: how much a sample at offset `(dx, dy)` from its pixel's
//! centre counts in that pixel.
//!
//! Samples are not splatted into neighbouring pixels: each pixel is the weighted mean of
//! its own samples, so a pixel depends on nothing outside itself (crops stay exact, see
//! [`super::crop`]). Within the pixel, `box` weighs every sample alike and `gaussian`
//! favours the centre (sigma half a pixel, truncated at the pixel's edges), which
//! sharpens edges a little against the box.

/// A pixel reconstruction filter.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Filter {
    #[default]
    Box,
    Gaussian,
}

/// Standard deviation of the Gaussian filter, in pixels.
const SIGMA: f64 = 0.5;

impl Filter {
    pub const NAMES: &'static str = "\"box\" or \"gaussian\"";

    pub fn from_name(name: &str) -> Option<Filter> {
        match name {
            "box" => Some(Filter::Box),
            "gaussian" => Some(Filter::Gaussian),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Filter::Box => "box",
            Filter::Gaussian => "gaussian",
        }
    }

    /// The weight of a sample `(dx, dy)` pixels from the pixel centre (|dx|, |dy| <= 0.5).
    pub fn weight(self, dx: f64, dy: f64) -> f64 {
        match self {
            Filter::Box => 1.0,
            Filter::Gaussian => (-(dx * dx + dy * dy) / (2.0 * SIGMA * SIGMA)).exp(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaussian_favours_the_centre_and_is_symmetric() {
        let g = Filter::Gaussian;
        assert_eq!(g.weight(0.0, 0.0), 1.0);
        assert!(g.weight(0.25, 0.0) > g.weight(0.45, 0.0));
        assert_eq!(g.weight(0.3, -0.1), g.weight(-0.3, 0.1));
        assert!((g.weight(0.5, 0.0) - (-0.5f64).exp()).abs() < 1e-15);
        assert_eq!(Filter::Box.weight(0.49, 0.49), 1.0);
    }
}
