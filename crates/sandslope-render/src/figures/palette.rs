//! The one palette of every figure and page, after the paper's Fig. 6: blue sinkage, red
//! slippage, yellow metastable, light green success; then every other colour by its role.

use plotters::style::colors::colormaps::{ColorMap, ViridisRGB};
use plotters::style::colors::{BLACK, WHITE};
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
/// The figures' black (plotters' `BLACK`): axes and ticks, the zero line of a chart against
/// slope, markers and their outlines (the terrain's star, the plan figure's start and goal, the
/// simulated body's centre), the borders of colour keys. The explorer's page draws the same
/// marks in it.
pub const FIGURE_INK: RGBColor = BLACK;
/// The figures' white (plotters' `WHITE`): the ground they are drawn on, legend boxes, the plan
/// figure's start marker. The explorer's panels, cards and charts are drawn on it too.
pub const PAPER: RGBColor = WHITE;
/// Light grid lines (charts against slope; the explorer's charts).
pub const GRID: RGBColor = RGBColor(235, 235, 235);
/// Bold grid lines.
pub const GRID_BOLD: RGBColor = RGBColor(225, 225, 225);
/// Light grid lines drawn fully transparent (the figures of measurements and gait).
pub const NO_GRID: RGBAColor = RGBAColor(255, 255, 255, 0.0);

/// `c` as an opaque [`RGBAColor`] (what plotters makes of an [`RGBColor`] style).
pub const fn opaque(c: RGBColor) -> RGBAColor {
    RGBAColor(c.0, c.1, c.2, 1.0)
}
/// Observations, reference lines and their labels (the risk threshold on the risk curve).
pub const DATA_GREY: RGBColor = RGBColor(90, 90, 90);
/// Secondary marks: points off the front, bounds.
pub const MUTED_GREY: RGBColor = RGBColor(150, 150, 150);
/// Text-dark marks: "none safe", pulls within 2 SD.
pub const DARK_GREY: RGBColor = RGBColor(60, 60, 60);
/// Shading of excluded ranges and minor guide lines.
pub const SHADE_GREY: RGBColor = RGBColor(200, 200, 200);
/// The model's curves and bands; the safe-slope (p_fail) limit on the risk curve.
pub const MODEL_BLUE: RGBColor = RGBColor(40, 90, 200);
/// A term that costs step (the inherited speed), distinct from the slippage regime's red.
pub const LOSS_RED: RGBColor = RGBColor(200, 40, 40);
/// A measurement with a warning.
pub const WARNING_RED: RGBColor = RGBColor(200, 30, 30);

/// The colours one figure each uses, by role, so that every colour of the tool is named here.
/// The terrain's own (k_n, k_s): the star on phase diagrams, risk maps and the design front,
/// and the marker of the explorer's phase diagram.
pub const STAR_GREEN: RGBColor = RGBColor(0, 100, 0);
/// The band of pulls within one SD (calibration figure).
pub const PULL_BAND: RGBColor = RGBColor(120, 170, 220);
/// The terrain table's k_s beside the inferred one (inference figure).
pub const TABLE_GREY: RGBColor = RGBColor(110, 110, 110);
/// P(not success) beside p_fail (risk curve) and the success limit on it.
pub const NOT_SUCCESS_ORANGE: RGBColor = RGBColor(230, 150, 30);
/// Routes (plan figure): the fastest, the safest, the shortest.
pub const ROUTE_TIME: RGBColor = RGBColor(0, 90, 220);
/// The safest route.
pub const ROUTE_RISK: RGBColor = RGBColor(170, 0, 200);
/// The shortest route.
pub const ROUTE_DISTANCE: RGBColor = RGBColor(0, 0, 0);
/// Plan figure: cells without a slope (the border), as mid grey.
pub const NO_SLOPE: RGBColor = RGBColor(190, 190, 190);
/// Plan figure and the explorer's routes map: cells without data.
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

/// The colour map of p_fail in the risk map (`risk --map`) and its colour bar: plotters'
/// viridis, from dark purple at 0 to yellow at 1. The explorer's risk overlay on its routes map
/// draws in the same colours, from [`p_fail_stops`].
pub fn p_fail_colour(p: f64) -> RGBColor {
    ViridisRGB.get_color(p as f32)
}

/// How many stops [`p_fail_stops`] gives.
pub const P_FAIL_STOPS: usize = 8;

/// [`p_fail_colour`] at p_fail = k / 7, k = 0..8: the colour map's own stops, between which it
/// is linear, so a page that interpolates linearly between these draws the risk map's colours
/// (within rounding); the explorer reads them as `--p-fail-0` ... `--p-fail-7`.
pub fn p_fail_stops() -> [RGBColor; P_FAIL_STOPS] {
    std::array::from_fn(|k| p_fail_colour(k as f64 / (P_FAIL_STOPS - 1) as f64))
}

/// The pages' colours (the report page's CSS, the explorer's custom properties), by role.
/// Body text (the explorer's too, and the labels of its charts).
pub const PAGE_INK: RGBColor = RGBColor(34, 34, 34);
/// Secondary text: figure captions (the explorer's captions, hints and card keys).
pub const PAGE_CAPTION: RGBColor = RGBColor(68, 68, 68);
/// Rules: table borders, under section headings (the explorer's borders and chart frames).
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
/// The explorer's page behind its panels.
pub const PAGE_BACKGROUND: RGBColor = RGBColor(247, 248, 250);
/// The explorer's active tab button (its background and border).
pub const PAGE_ACCENT: RGBColor = RGBColor(43, 108, 176);
/// The explorer's status line (a refused input) and its Drive tab's stop button: the report's
/// dark red for text.
pub const PAGE_ALERT_INK: RGBColor = PAGE_PART_INK;

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

/// The roles a web page draws in, by the name of their CSS custom property: the regimes, the
/// routes, the other roles a page shares with the figures, and the explorer's page roles.
pub const CSS_ROLES: [(&str, RGBColor); 26] = [
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
    ("figure-ink", FIGURE_INK),
    ("paper", PAPER),
    ("grid", GRID),
    ("star", STAR_GREEN),
    ("nodata", NODATA),
    ("page-ink", PAGE_INK),
    ("page-caption", PAGE_CAPTION),
    ("page-rule", PAGE_RULE),
    ("page-background", PAGE_BACKGROUND),
    ("page-accent", PAGE_ACCENT),
    ("page-alert-ink", PAGE_ALERT_INK),
];

/// The colours a web page draws in, as CSS custom properties on `:root` (`--sinkage: #426ec9;`
/// ...), always as six hex digits: [`CSS_ROLES`], then the stops of the risk map's colour map
/// ([`p_fail_stops`]) as `--p-fail-0` ... The explorer's style sheet uses them with `var()` and
/// its script reads them with `getComputedStyle`, so the page restates no colour.
pub fn css_custom_properties() -> String {
    let stops = p_fail_stops();
    let stops = stops.iter().enumerate().map(|(k, c)| (format!("p-fail-{k}"), *c));
    let roles = CSS_ROLES.iter().map(|(name, c)| (name.to_string(), *c)).chain(stops);
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
        // The page's own roles: its ink is the report's (#222), not a blue-black of its own.
        assert!(p.contains("--page-ink: #222222;"), "{p}");
        assert!(p.contains("--figure-ink: #000000;"), "{p}");
        assert!(p.contains("--paper: #ffffff;"), "{p}");
        // The risk map's colour map, its ends viridis' dark purple and yellow.
        assert!(p.contains("--p-fail-0: #440154;"), "{p}");
        assert!(p.contains("--p-fail-7: #fee825;"), "{p}");
        assert!(!p.contains("--p-fail-8:"), "{p}");
        // Every role once, each a property of its own.
        let names: Vec<&str> = CSS_ROLES.iter().map(|(n, _)| *n).collect();
        for (i, name) in names.iter().enumerate() {
            assert!(!names[..i].contains(name), "{name} twice");
            assert_eq!(p.matches(&format!(" --{name}: #")).count(), 1, "{name}: {p}");
        }
        assert_eq!(p.matches(": #").count(), CSS_ROLES.len() + P_FAIL_STOPS, "{p}");
    }

    /// A page that interpolates linearly between the stops, as the explorer's risk overlay
    /// does, draws the risk map's colours: the stops are the colour map's own.
    #[test]
    fn p_fail_stops_interpolate_to_the_risk_maps_colours() {
        let stops = p_fail_stops();
        assert_eq!(stops[0], p_fail_colour(0.0));
        assert_eq!(stops[P_FAIL_STOPS - 1], p_fail_colour(1.0));
        for i in 0..=1400 {
            let p = i as f64 / 1400.0;
            let x = p * (P_FAIL_STOPS - 1) as f64;
            let k = (x.floor() as usize).min(P_FAIL_STOPS - 2);
            let f = x - k as f64;
            let (a, b) = (stops[k], stops[k + 1]);
            let lerp = |u: u8, v: u8| f64::from(u) + f * (f64::from(v) - f64::from(u));
            let page = [lerp(a.0, b.0), lerp(a.1, b.1), lerp(a.2, b.2)];
            let RGBColor(r, g, bl) = p_fail_colour(p);
            for (want, got) in [r, g, bl].into_iter().zip(page) {
                assert!((f64::from(want) - got).abs() <= 1.0, "p_fail {p}: {want} against {got}");
            }
        }
    }
}
