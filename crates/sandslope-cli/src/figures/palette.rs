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
