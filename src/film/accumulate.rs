//! Accumulating weighted samples into a pixel and developing it (linear light).
//!
//! Colours are averaged in linear light: an anti-aliased edge between black and white is
//! the grey that emits half the light, not the sRGB code 128 (which emits about a fifth).
//! A pixel keeps the weighted sum of its hits' linear colours, the hits' weight and all
//! samples' weight. Developed opaque, the misses' share shows the background; developed
//! with straight (not premultiplied) alpha, the colour is the hits' own mean and alpha
//! their share of the weight. A pixel of one sample keeps its 8-bit colour exactly, so
//! one sample per pixel gives today's images bit for bit.

use crate::rgb::{Linear, srgb8_to_linear, to_srgb8};

/// One pixel's samples so far.
#[derive(Clone, Copy, Debug, Default)]
pub struct PixelAccum {
    /// Weighted sum of the hit samples' linear colours.
    hit_colour: [f64; 3],
    /// Weight of the samples that hit.
    hit_weight: f64,
    /// Weight of all samples.
    weight: f64,
    /// Samples added.
    count: u32,
    /// The colour of the first sample (`None`: it missed), kept exactly.
    first: Option<[u8; 3]>,
}

impl PixelAccum {
    /// Adds a sample of weight `w`: `Some(colour)` for a hit, `None` for a miss.
    pub fn add(&mut self, colour: Option<[u8; 3]>, w: f64) {
        if self.count == 0 {
            self.first = colour;
        }
        self.count += 1;
        self.weight += w;
        if let Some(c) = colour {
            let lin: Linear = srgb8_to_linear(c);
            for (acc, v) in self.hit_colour.iter_mut().zip(lin) {
                *acc += w * f64::from(v);
            }
            self.hit_weight += w;
        }
    }

    /// The first sample's colour (`None`: it missed or there is none).
    pub fn first(&self) -> Option<[u8; 3]> {
        self.first
    }

    /// Samples added so far.
    pub fn count(&self) -> u32 {
        self.count
    }

    /// The share of the weight that hit (1 for an empty pixel's complement: 0).
    pub fn coverage(&self) -> f64 {
        if self.weight > 0.0 {
            self.hit_weight / self.weight
        } else {
            0.0
        }
    }

    /// The opaque colour: hits and `background` mixed by their weights.
    pub fn opaque(&self, background: [u8; 3]) -> [u8; 3] {
        if self.count <= 1 {
            return self.first.unwrap_or(background);
        }
        let bg = srgb8_to_linear(background);
        let miss = self.weight - self.hit_weight;
        let lin: Linear = std::array::from_fn(|k| {
            ((self.hit_colour[k] + miss * f64::from(bg[k])) / self.weight) as f32
        });
        to_srgb8(lin)
    }

    /// Straight-alpha RGBA: the hits' mean colour (`background` where nothing hit) and
    /// their share of the weight as alpha.
    pub fn straight(&self, background: [u8; 3]) -> [u8; 4] {
        let alpha = (255.0 * self.coverage()).round() as u8;
        let rgb = if self.count <= 1 {
            self.first.unwrap_or(background)
        } else if self.hit_weight > 0.0 {
            to_srgb8(std::array::from_fn(|k| {
                (self.hit_colour[k] / self.hit_weight) as f32
            }))
        } else {
            background
        };
        [rgb[0], rgb[1], rgb[2], alpha]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_sample_keeps_its_colour_exactly() {
        for c in [[0, 0, 0], [1, 2, 3], [200, 17, 255], [128, 128, 128]] {
            let mut p = PixelAccum::default();
            p.add(Some(c), 0.7);
            assert_eq!(p.opaque([9, 9, 9]), c);
            assert_eq!(p.straight([9, 9, 9]), [c[0], c[1], c[2], 255]);
        }
        let mut p = PixelAccum::default();
        p.add(None, 1.0);
        assert_eq!(p.opaque([9, 8, 7]), [9, 8, 7]);
        assert_eq!(p.straight([9, 8, 7]), [9, 8, 7, 0]);
    }

    #[test]
    fn half_black_half_white_is_half_the_light() {
        let mut p = PixelAccum::default();
        p.add(Some([0, 0, 0]), 1.0);
        p.add(Some([255, 255, 255]), 1.0);
        // Linear 0.5 is sRGB 0.7354 -> 188.
        assert_eq!(p.opaque([0, 0, 0]), [188, 188, 188]);
        // The same through the background.
        let mut q = PixelAccum::default();
        q.add(None, 1.0);
        q.add(Some([255, 255, 255]), 1.0);
        assert_eq!(q.opaque([0, 0, 0]), [188, 188, 188]);
    }

    #[test]
    fn straight_alpha_is_the_hit_share_and_colour_the_hits_own() {
        let mut p = PixelAccum::default();
        p.add(Some([200, 100, 50]), 1.0);
        p.add(None, 1.0);
        p.add(None, 2.0);
        p.add(Some([200, 100, 50]), 0.0);
        assert!((p.coverage() - 0.25).abs() < 1e-12);
        let [r, g, b, a] = p.straight([255, 255, 255]);
        assert_eq!([r, g, b], [200, 100, 50]);
        assert_eq!(a, 64);
        // Opaque: a quarter of the colour's light over three quarters of black.
        let o = p.opaque([0, 0, 0]);
        let want = to_srgb8(srgb8_to_linear([200, 100, 50]).map(|v| v * 0.25));
        assert_eq!(o, want);
    }
}
