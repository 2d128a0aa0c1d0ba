//! The cost heat map: evaluations per pixel through the inferno colormap, with a colour
//! bar and its scale written beside the image (plotters, with the embedded DejaVu Sans
//! font of [`crate::font`]), so the picture says where the renderer spends its time.
//!
//! The scale runs from 0 to the 99.5th percentile of the pixels' counts (at least 1):
//! a handful of pathological rays would otherwise wash the picture out. Pixels above it
//! take the top colour, and the top label says "≥".

use crate::rgb::Colormap;
use plotters::prelude::*;

/// Width of the panel holding the colour bar and its labels, in pixels.
pub const PANEL: u32 = 96;

/// Share of the pixels below the top of the scale.
const TOP_QUANTILE: f64 = 0.995;

/// The top of the scale: the [`TOP_QUANTILE`] quantile of `costs`, at least 1.
pub fn scale_top(costs: &[u32]) -> u32 {
    if costs.is_empty() {
        return 1;
    }
    let mut sorted = costs.to_vec();
    sorted.sort_unstable();
    let i = ((sorted.len() - 1) as f64 * TOP_QUANTILE).round() as usize;
    sorted[i].max(1)
}

/// The heat map of `costs` (row-major, `width x height`) with its colour bar on the
/// right: an RGB image `width + PANEL` wide.
pub fn heat_map(costs: &[u32], width: u32, height: u32) -> Result<image::RgbImage, String> {
    let top = scale_top(costs);
    let map = Colormap::Inferno;
    let full_w = width + PANEL;
    let mut buf = vec![255u8; (full_w * height * 3) as usize];
    for y in 0..height {
        for x in 0..width {
            let c = costs[(y * width + x) as usize];
            let rgb = map.srgb8(f64::from(c) / f64::from(top));
            let i = ((y * full_w + x) * 3) as usize;
            buf[i..i + 3].copy_from_slice(&rgb);
        }
    }
    crate::font::register();
    {
        let root = BitMapBackend::with_buffer(&mut buf, (full_w, height)).into_drawing_area();
        let err = |e: DrawingAreaErrorKind<_>| e.to_string();
        let (bar_x0, bar_x1) = (width as i32 + 8, width as i32 + 26);
        let (bar_y0, bar_y1) = (22i32, height as i32 - 10);
        let text = ("sans-serif", 12).into_font().color(&BLACK);
        root.draw(&Text::new(
            "evals/pixel",
            (width as i32 + 4, 4),
            text.clone(),
        ))
        .map_err(err)?;
        if bar_y1 > bar_y0 + 4 {
            let span = f64::from(bar_y1 - bar_y0);
            for y in bar_y0..=bar_y1 {
                let t = f64::from(bar_y1 - y) / span;
                let [r, g, b] = map.srgb8(t);
                root.draw(&PathElement::new(
                    vec![(bar_x0, y), (bar_x1, y)],
                    RGBColor(r, g, b),
                ))
                .map_err(err)?;
            }
            root.draw(&Rectangle::new([(bar_x0, bar_y0), (bar_x1, bar_y1)], BLACK))
                .map_err(err)?;
            let labels = [
                (bar_y0, format!("≥{top}")),
                ((bar_y0 + bar_y1) / 2, format!("{}", top / 2)),
                (bar_y1, "0".to_string()),
            ];
            for (y, label) in labels {
                root.draw(&Text::new(label, (bar_x1 + 4, y - 6), text.clone()))
                    .map_err(err)?;
            }
        }
        root.present().map_err(err)?;
    }
    Ok(image::RgbImage::from_raw(full_w, height, buf).expect("size"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_is_a_high_quantile() {
        let mut costs = vec![10u32; 1000];
        costs[0] = 100_000;
        assert_eq!(scale_top(&costs), 10);
        assert_eq!(scale_top(&[0, 0]), 1);
        assert_eq!(scale_top(&[]), 1);
    }

    #[test]
    fn heat_map_colours_pixels_by_cost_and_draws_a_bar() {
        let (w, h) = (64, 80);
        let costs: Vec<u32> = (0..w * h)
            .map(|i| if i % w < 32 { 0 } else { 50 })
            .collect();
        let img = heat_map(&costs, w, h).unwrap();
        assert_eq!(img.dimensions(), (w + PANEL, h));
        let map = Colormap::Inferno;
        assert_eq!(img.get_pixel(0, 0).0, map.srgb8(0.0));
        assert_eq!(img.get_pixel(40, 10).0, map.srgb8(1.0));
        // The bar: top colour near its top, bottom colour near its bottom.
        // The bar runs from y 22 (top of the scale) to y h - 10 = 70 (zero).
        assert_eq!(img.get_pixel(w + 16, 24).0, map.srgb8(46.0 / 48.0));
        assert_eq!(img.get_pixel(w + 16, h - 11).0, map.srgb8(1.0 / 48.0));
        // Some label text (dark pixels) right of the bar.
        let dark = (w + 28..w + PANEL)
            .flat_map(|x| (0..h).map(move |y| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0.iter().all(|&c| c < 100))
            .count();
        assert!(dark > 20, "{dark} dark pixels");
    }
}
