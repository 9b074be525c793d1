//! The one palette of every figure and page, after the paper's Fig. 6: blue sinkage, red
//! slippage, yellow metastable, light green success; then every other colour by its role.

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
/// Simulation figures and animation: the first tripod's legs (the simulated speeds' blue).
pub const TRIPOD_A: RGBColor = SIMULATED_BLUE;
/// Simulation figures and animation: the second tripod's legs.
pub const TRIPOD_B: RGBColor = RGBColor(230, 120, 20);
/// Simulation animation: the sand.
pub const SAND: RGBColor = RGBColor(230, 205, 150);
/// Simulation animation: the trace of the body's centre (the safest route's purple: apart
/// from the tripods' blue and orange, the forces' red and the sand).
pub const BODY_TRACE: RGBColor = ROUTE_RISK;
/// Simulation animation: the sand's surface and the marks on it.
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

/// The pages' colours (the report page's CSS, the explorer's custom properties), by role.
/// Body text.
pub const PAGE_INK: RGBColor = RGBColor(34, 34, 34);
/// Secondary text: figure captions.
pub const PAGE_CAPTION: RGBColor = RGBColor(68, 68, 68);
/// Rules: table borders, under section headings.
pub const PAGE_RULE: RGBColor = RGBColor(204, 204, 204);
/// The border of an embedded figure.
pub const PAGE_FIGURE_BORDER: RGBColor = RGBColor(238, 238, 238);
/// Table header cells.
pub const PAGE_HEADER_BG: RGBColor = RGBColor(243, 243, 243);
/// Inline code.
pub const PAGE_CODE_BG: RGBColor = RGBColor(244, 244, 244);
/// A table row where the model and the evidence disagree (a light tint of slippage red).
pub const PAGE_DISAGREE_BG: RGBColor = RGBColor(253, 236, 234);
/// A verdict cell where they agree (a dark tint of success green).
pub const PAGE_AGREE_INK: RGBColor = RGBColor(27, 110, 42);
/// Where the simulator and the closed form part (a dark tint of slippage red, for text).
pub const PAGE_PART_INK: RGBColor = RGBColor(165, 40, 34);
/// A warning box's background.
pub const PAGE_WARN_BG: RGBColor = RGBColor(255, 248, 225);
/// A warning box's bar.
pub const PAGE_WARN_BAR: RGBColor = RGBColor(224, 168, 0);

/// `c` as a CSS hex colour, in the three-digit form when it has one (`#ccc`, `#1b6e2a`).
pub fn css(c: RGBColor) -> String {
    let RGBColor(r, g, b) = c;
    let short = |v: u8| v >> 4 == v & 15;
    if short(r) && short(g) && short(b) {
        format!("#{:x}{:x}{:x}", r & 15, g & 15, b & 15)
    } else {
        format!("#{r:02x}{g:02x}{b:02x}")
    }
}

/// The colours a web page draws in, as CSS custom properties on `:root` (`--sinkage: #426ec9;`
/// ...), always as six hex digits: the regimes, the routes and the other roles a page shares
/// with the figures. The explorer's page reads them with `getComputedStyle`, so it restates
/// no colour.
pub fn css_custom_properties() -> String {
    let roles: [(&str, RGBColor); 15] = [
        ("sinkage", SINKAGE),
        ("slippage", SLIPPAGE),
        ("metastable", METASTABLE),
        ("success", SUCCESS),
        ("route-time", ROUTE_TIME),
        ("route-risk", ROUTE_RISK),
        ("route-distance", ROUTE_DISTANCE),
        ("not-success", NOT_SUCCESS_ORANGE),
        ("model", MODEL_BLUE),
        ("closed-form", CLOSED_FORM_RED),
        ("data", DATA_GREY),
        ("sand", SAND),
        ("sand-surface", SAND_SURFACE),
        ("tripod-a", TRIPOD_A),
        ("tripod-b", TRIPOD_B),
    ];
    let mut s = String::from(":root {");
    for (name, RGBColor(r, g, b)) in roles {
        s.push_str(&format!(" --{name}: #{r:02x}{g:02x}{b:02x};"));
    }
    s.push_str(" }\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn css_colours_use_the_short_form_only_when_exact() {
        assert_eq!(css(PAGE_RULE), "#ccc");
        assert_eq!(css(RGBColor(0, 0, 0)), "#000");
        assert_eq!(css(PAGE_AGREE_INK), "#1b6e2a");
        // 0x0b is not 0xbb: no short form.
        assert_eq!(css(RGBColor(11, 110, 47)), "#0b6e2f");
        assert_eq!(css(SINKAGE), "#426ec9");
    }

    #[test]
    fn custom_properties_carry_the_figures_colours() {
        let p = css_custom_properties();
        assert!(p.starts_with(":root {"), "{p}");
        assert!(p.contains("--sinkage: #426ec9;"), "{p}");
        // The fastest route: the plan figure's blue (0, 90, 220), not a green.
        assert!(p.contains("--route-time: #005adc;"), "{p}");
        // Six digits even where a short form exists (the page parses them as #rrggbb).
        assert!(p.contains("--route-distance: #000000;"), "{p}");
    }
}
