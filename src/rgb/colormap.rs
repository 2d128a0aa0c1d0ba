//! Named colormaps for scalar attributes (intensity, elevation). The gradients are the
//! `colorous` crate's ports of d3-scale-chromatic (matplotlib's viridis family, Google's
//! turbo); this module only names them and maps a value range onto them.

use super::{Linear, srgb8_to_linear};

/// A named continuous colormap.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Colormap {
    Viridis,
    Magma,
    Inferno,
    Plasma,
    Cividis,
    Turbo,
}

impl Colormap {
    /// Every colormap, in the order the documentation lists them.
    pub const ALL: [Colormap; 6] = [
        Colormap::Viridis,
        Colormap::Magma,
        Colormap::Inferno,
        Colormap::Plasma,
        Colormap::Cividis,
        Colormap::Turbo,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Colormap::Viridis => "viridis",
            Colormap::Magma => "magma",
            Colormap::Inferno => "inferno",
            Colormap::Plasma => "plasma",
            Colormap::Cividis => "cividis",
            Colormap::Turbo => "turbo",
        }
    }

    /// The colormap called `name` (lower case), if there is one.
    pub fn from_name(name: &str) -> Option<Colormap> {
        Colormap::ALL.into_iter().find(|c| c.name() == name)
    }

    /// The names of all colormaps, comma-separated (for messages).
    pub fn names() -> String {
        Colormap::ALL.map(|c| c.name()).join(", ")
    }

    fn gradient(self) -> colorous::Gradient {
        match self {
            Colormap::Viridis => colorous::VIRIDIS,
            Colormap::Magma => colorous::MAGMA,
            Colormap::Inferno => colorous::INFERNO,
            Colormap::Plasma => colorous::PLASMA,
            Colormap::Cividis => colorous::CIVIDIS,
            Colormap::Turbo => colorous::TURBO,
        }
    }

    /// The sRGB colour at `t` in [0, 1] (clamped; NaN gives the low end).
    pub fn srgb8(self, t: f64) -> [u8; 3] {
        let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
        self.gradient().eval_continuous(t).as_array()
    }

    /// The linear colour of `value` on the range `[lo, hi]` (the low end when the range
    /// is empty).
    pub fn map(self, value: f64, lo: f64, hi: f64) -> Linear {
        let t = if hi > lo {
            (value - lo) / (hi - lo)
        } else {
            0.0
        };
        srgb8_to_linear(self.srgb8(t))
    }
}

impl std::fmt::Display for Colormap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The `lo`-th and `hi`-th quantiles (in [0, 1]) of `values` (`None` when empty). Used
/// to map a scalar with outliers (intensity) onto a colormap.
pub fn quantile_range(values: &[f64], lo: f64, hi: f64) -> Option<(f64, f64)> {
    if values.is_empty() {
        return None;
    }
    let mut v = values.to_vec();
    let pick = |v: &mut Vec<f64>, q: f64| {
        let k = ((v.len() - 1) as f64 * q).round() as usize;
        *v.select_nth_unstable_by(k, f64::total_cmp).1
    };
    let a = pick(&mut v, lo);
    let b = pick(&mut v, hi);
    Some((a, b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_ends() {
        for c in Colormap::ALL {
            assert_eq!(Colormap::from_name(c.name()), Some(c));
        }
        assert_eq!(Colormap::from_name("jet"), None);
        // viridis runs from dark purple (#440154) to yellow (#fde725).
        assert_eq!(Colormap::Viridis.srgb8(0.0), [0x44, 0x01, 0x54]);
        assert_eq!(Colormap::Viridis.srgb8(1.0), [0xfd, 0xe7, 0x25]);
        assert_eq!(Colormap::Viridis.srgb8(-5.0), Colormap::Viridis.srgb8(0.0));
        assert_eq!(
            Colormap::Viridis.srgb8(f64::NAN),
            Colormap::Viridis.srgb8(0.0)
        );
    }

    #[test]
    fn quantiles() {
        let v: Vec<f64> = (0..=100).map(|i| i as f64).collect();
        assert_eq!(quantile_range(&v, 0.01, 0.99), Some((1.0, 99.0)));
        assert_eq!(quantile_range(&[], 0.0, 1.0), None);
    }
}
