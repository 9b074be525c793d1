//! The one regime palette of every figure, after the paper's Fig. 6: blue sinkage, red
//! slippage, yellow metastable, light green success.

use plotters::style::RGBColor;

use sandslope::Regime;

/// Sinkage: the paper's blue.
pub const SINKAGE: RGBColor = RGBColor(66, 110, 201);
/// Slippage: the paper's red.
pub const SLIPPAGE: RGBColor = RGBColor(214, 56, 48);
/// Metastable: the paper's yellow.
pub const METASTABLE: RGBColor = RGBColor(247, 214, 67);
/// Success: the paper's light green.
pub const SUCCESS: RGBColor = RGBColor(168, 226, 150);

/// The colour of a regime in every figure (phase diagrams, risk maps, routes).
pub fn regime_colour(r: Regime) -> RGBColor {
    match r {
        Regime::Sinkage => SINKAGE,
        Regime::Slippage => SLIPPAGE,
        Regime::Metastable => METASTABLE,
        Regime::Success => SUCCESS,
    }
}

/// The figures' other colours, by role (each was written inline in several figures).
/// Light grid lines.
pub const GRID: RGBColor = RGBColor(235, 235, 235);
/// Bold grid lines.
pub const GRID_BOLD: RGBColor = RGBColor(225, 225, 225);
/// Observations, reference lines and their labels.
pub const DATA_GREY: RGBColor = RGBColor(90, 90, 90);
/// Secondary marks: points off the front, bounds.
pub const MUTED_GREY: RGBColor = RGBColor(150, 150, 150);
/// Text-dark marks: "none safe", pulls within 2 SD.
pub const DARK_GREY: RGBColor = RGBColor(60, 60, 60);
/// Shading of excluded ranges and minor guide lines.
pub const SHADE_GREY: RGBColor = RGBColor(200, 200, 200);
/// The model's curves and bands.
pub const MODEL_BLUE: RGBColor = RGBColor(40, 90, 200);
/// A term that costs step (the inherited speed), distinct from the slippage regime's red.
pub const LOSS_RED: RGBColor = RGBColor(200, 40, 40);
/// A measurement with a warning.
pub const WARNING_RED: RGBColor = RGBColor(200, 30, 30);
