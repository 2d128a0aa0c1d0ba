//! The font plotters draws text with (the sweep's plots, the cost heat map's colour
//! bar): DejaVu Sans, embedded (`assets/DejaVuSans.ttf`, license in
//! `assets/DejaVu-LICENSE.txt`) and registered once as "sans-serif". plotters panics on
//! text without a registered font, so every drawing calls [`register`] first.

use plotters::style::{FontStyle, register_font};
use std::sync::Once;

static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Registers the embedded font as "sans-serif" (once); needed before any text is drawn.
pub fn register() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The font is compiled in: it cannot fail to parse unless the asset is broken,
        // which the plot tests would show at once.
        if register_font("sans-serif", FontStyle::Normal, FONT).is_err() {
            panic!("assets/DejaVuSans.ttf is not a valid font");
        }
    });
}
