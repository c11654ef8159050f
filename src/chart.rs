//! What the plots share (`nadf sweep`, `nadf scen`): the bundled font, registered once, the
//! line colours and axis padding. Plots are drawn with plotters into an RGB buffer with the
//! DejaVu Sans font in `assets/fonts` (no system fonts needed) and encoded as PNG.

use std::sync::Once;

use plotters::style::{FontStyle, RGBColor, register_font as register};

/// The bundled font (DejaVu Sans; its licence is beside it).
const FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");

/// Line colours, cycled.
pub const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

/// Makes the bundled font the `sans-serif` of every plot (once).
pub fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // Cannot fail on the bundled file; a failure would show as missing text, not a crash.
        let _ = register("sans-serif", FontStyle::Normal, FONT);
    });
}

/// An axis range around `[lo, hi]` with a little room on both sides.
pub fn padded(lo: f64, hi: f64) -> (f64, f64) {
    let span = if hi > lo { hi - lo } else { lo.abs().max(1.0) };
    (lo - 0.03 * span, hi + 0.03 * span)
}
