//! The one regime palette of every figure, after the paper's Fig. 6: blue sinkage, red
//! slippage, yellow metastable, light green success.

use plotters::style::{RGBAColor, RGBColor};

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
/// Light grid lines drawn fully transparent (the figures of measurements and gait).
pub const NO_GRID: RGBAColor = RGBAColor(255, 255, 255, 0.0);

/// `c` as an opaque [`RGBAColor`] (what plotters makes of an [`RGBColor`] style).
pub const fn opaque(c: RGBColor) -> RGBAColor {
    RGBAColor(c.0, c.1, c.2, 1.0)
}
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

/// The colours one figure each uses, by role, so that every colour of the tool is named here.
/// The terrain's own (k_n, k_s): the star on phase diagrams, risk maps and the design front.
pub const STAR_GREEN: RGBColor = RGBColor(0, 100, 0);
/// The band of pulls within one SD (calibration figure).
pub const PULL_BAND: RGBColor = RGBColor(120, 170, 220);
/// The terrain table's k_s beside the inferred one (inference figure).
pub const TABLE_GREY: RGBColor = RGBColor(110, 110, 110);
/// P(not success) beside p_fail (risk curve).
pub const NOT_SUCCESS_ORANGE: RGBColor = RGBColor(230, 150, 30);
/// Routes (plan figure): the fastest, the safest, the shortest.
pub const ROUTE_TIME: RGBColor = RGBColor(0, 90, 220);
/// The safest route.
pub const ROUTE_RISK: RGBColor = RGBColor(170, 0, 200);
/// The shortest route.
pub const ROUTE_DISTANCE: RGBColor = RGBColor(0, 0, 0);
/// Plan figure: cells without a slope (the border), as mid grey.
pub const NO_SLOPE: RGBColor = RGBColor(190, 190, 190);
/// Plan figure: cells without data.
pub const NODATA: RGBColor = RGBColor(255, 255, 255);
/// Plan figure: no heading with P(fail) < 0.5. Charcoal, not a dark red: on the hillshade a
/// dark red is lost beside slippage red.
pub const NO_SAFE_HEADING: RGBColor = RGBColor(55, 55, 62);
/// Simulation figure: the step marks of a walk.
pub const STEP_MARK_GREY: RGBColor = RGBColor(170, 170, 170);
/// Simulation figure: the simulated speeds.
pub const SIMULATED_BLUE: RGBColor = RGBColor(31, 90, 180);
/// Simulation figure: a walk whose body pitched over.
pub const TUMBLE_ORANGE: RGBColor = RGBColor(230, 120, 0);
/// Simulation animation: the sand.
pub const SAND: RGBColor = RGBColor(230, 205, 150);
/// Simulation animation: the sand's surface.
pub const SAND_SURFACE: RGBColor = RGBColor(150, 120, 60);
/// Step budget: the net step.
pub const NET_STEP: RGBColor = RGBColor(20, 20, 20);
/// Step budget: the backward slip.
pub const SLIP_ORANGE: RGBColor = RGBColor(230, 150, 20);
/// The closed-form model's curves and points beside measured or simulated ones, the anchoring
/// time t1 and the legs' sand forces (plotters' pure red).
pub const CLOSED_FORM_RED: RGBColor = RGBColor(255, 0, 0);
/// The tracked stride-averaged speed and its band (plotters' pure blue).
pub const TRACKED_BLUE: RGBColor = RGBColor(0, 0, 255);
