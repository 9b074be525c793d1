//! The explorer page: one HTML file, its scripts (`app.js`: helpers, Explore and Risk;
//! `routes.js`: Routes, Simulate and the wiring; `drive.js`: Drive) and its style sheet,
//! embedded in the binary (docs/serve.md). The scripts draw every chart themselves on SVG and
//! canvas, so nothing is fetched from anywhere but this server. The style sheet opens with the palette's colours
//! as CSS custom properties (`sandslope_render::figures::palette::css_custom_properties`),
//! which the script reads, so the page draws in the figures' colours and restates none.

use std::sync::LazyLock;

use sandslope::robot::STANCE_LEGS_RANGE;
use sandslope::RobotKey;
use sandslope_request::field::{Bound, Field, Table};
use sandslope_request::scenario::{robot_fields, ROBOT_QUANTITIES};
use sandslope_request::{plan, predict, risk, simulate};

use crate::served::Served;

const INDEX: &str = include_str!("page/index.html");
const SCRIPT: &str = include_str!("page/app.js");
const ROUTES_SCRIPT: &str = include_str!("page/routes.js");
const DRIVE_SCRIPT: &str = include_str!("page/drive.js");
const STYLE: &str = include_str!("page/style.css");

/// The page's file at `path`, with its content type, or `None` (404).
pub fn asset(path: &str, _served: &Served) -> Option<(Vec<u8>, &'static str)> {
    match path {
        "/" | "/index.html" => Some((FILLED_INDEX.as_bytes().to_vec(), "text/html; charset=utf-8")),
        "/app.js" => Some((SCRIPT.as_bytes().to_vec(), "text/javascript; charset=utf-8")),
        "/routes.js" => Some((ROUTES_SCRIPT.as_bytes().to_vec(), "text/javascript; charset=utf-8")),
        "/drive.js" => Some((DRIVE_SCRIPT.as_bytes().to_vec(), "text/javascript; charset=utf-8")),
        "/style.css" => {
            let css = sandslope_render::figures::palette::css_custom_properties() + STYLE;
            Some((css.into_bytes(), "text/css; charset=utf-8"))
        }
        _ => None,
    }
}

/// The page with every input bound to a field given its start and range from the tables.
static FILLED_INDEX: LazyLock<String> = LazyLock::new(|| fill_inputs(INDEX));

/// What the page chooses itself where no table gives a number: a slider's span (a slider
/// needs both ends; the slope sliders' span is also the sweep chart's slope axis, which the
/// script reads from the slider) and where an input without a default starts.
struct View {
    /// The input's id.
    id: &'static str,
    /// Where it starts, when its field has no default.
    start: Option<f64>,
    /// Its lower end, narrower than the field's.
    min: Option<f64>,
    /// Its upper end, narrower than the field's (or where the field has none).
    max: Option<f64>,
}

/// The slope the Explore and Simulate tabs open at, degrees.
const START_SLOPE_DEG: f64 = 10.0;
/// The slope sliders' span, degrees: the slopes a sand robot is tried on, a little beyond the
/// repose angle (about 30 degrees), and descents.
const SLOPE_VIEW_DEG: (f64, f64) = (-30.0, 40.0);
/// The longest walk the Simulate tab animates, s (a page's wait, well inside
/// `/data/simulation`'s cap of [`crate::data::MAX_SIM_SAMPLES`] samples).
const LONGEST_ANIMATION_S: f64 = 60.0;

const VIEWS: &[View] = &[
    View {
        id: "slope",
        start: Some(START_SLOPE_DEG),
        min: Some(SLOPE_VIEW_DEG.0),
        max: Some(SLOPE_VIEW_DEG.1),
    },
    View { id: "slope-num", start: Some(START_SLOPE_DEG), min: None, max: None },
    View {
        id: "sim-slope",
        start: Some(START_SLOPE_DEG),
        min: Some(SLOPE_VIEW_DEG.0),
        max: Some(SLOPE_VIEW_DEG.1),
    },
    View { id: "sim-slope-num", start: Some(START_SLOPE_DEG), min: None, max: None },
    // The CV sliders start at the library's defaults (docs/model.md §9), which the risk
    // answer's CVs show until the box "CVs from the terrain" is cleared; a CV past 1 (a
    // spread as large as the value) is typed in no box, so the slider ends there.
    View { id: "cv-n", start: Some(sandslope::risk::DEFAULT_CV_N), min: None, max: Some(1.0) },
    View { id: "cv-s", start: Some(sandslope::risk::DEFAULT_CV_S), min: None, max: Some(1.0) },
    View { id: "sim-duration", start: None, min: None, max: Some(LONGEST_ANIMATION_S) },
];

/// The tables an input may name in `data-field="COMMAND:FLAG"`.
const TABLES: [Table; 5] = [predict::FIELDS, risk::FIELDS, plan::FIELDS, simulate::FIELDS, ROBOT_QUANTITIES];

/// The field an input names, `COMMAND:FLAG` (`risk:max-risk`), or a robot quantity's flag
/// (`data-flag="mass"`).
fn field_named(name: &str) -> Option<&'static Field> {
    let (command, flag) = name.split_once(':')?;
    TABLES.iter().filter(|t| t.command == command).flat_map(|t| t.fields.iter()).find(|f| f.flag == flag)
}

/// The range of a robot quantity's input: the library's plausible range of its key (or the
/// stance legs' whole numbers), else its field's words (`hip-height`: at least 0).
fn robot_bounds(flag: &str, field: &Field) -> (Option<Bound>, Option<Bound>) {
    let inclusive = |value: f64| Some(Bound { value, inclusive: true });
    match robot_fields().find(|(_, f)| *f == flag).map(|(k, _)| k) {
        Some(RobotKey::StanceLegs) => {
            (inclusive(f64::from(STANCE_LEGS_RANGE.0)), inclusive(f64::from(STANCE_LEGS_RANGE.1)))
        }
        Some(k) => match k.plausible() {
            Some(p) => (inclusive(p.min), inclusive(p.max)),
            None => field.bounds(),
        },
        None => field.bounds(),
    }
}

/// The value of attribute `name` in the opening tag `tag`.
fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let marker = format!(" {name}=\"");
    let at = tag.find(&marker)? + marker.len();
    Some(&tag[at..at + tag[at..].find('"')?])
}

/// `html` with `value`, `min` and `max` written into every `<input>` bound to a field
/// (`data-field="COMMAND:FLAG"`, or a robot quantity's `data-flag="FLAG"`): its start is the
/// field's default (else the page's [`VIEWS`]), its ends the field's range (a robot
/// quantity's: the library's plausible range), narrowed by the page's view. An end the range
/// excludes (`strictly between 0 and 1`) is written too: the server's check refuses it by
/// name. A field name no table has is a mistake in the page (panics, and a test loads it).
fn fill_inputs(html: &str) -> String {
    let mut out = String::with_capacity(html.len() + 1024);
    let mut rest = html;
    while let Some(at) = rest.find("<input ") {
        let close = at + rest[at..].find('>').expect("an <input> tag is closed");
        let tag = &rest[at..close];
        out.push_str(&rest[..close]);
        let (field, bounds) = if let Some(name) = attribute(tag, "data-field") {
            let f = field_named(name).unwrap_or_else(|| panic!("index.html names no field {name}"));
            (Some(f), f.bounds())
        } else if let Some(flag) = attribute(tag, "data-flag") {
            let f = ROBOT_QUANTITIES.field(flag);
            (Some(f), robot_bounds(flag, f))
        } else {
            (None, (None, None))
        };
        if let Some(field) = field {
            let view = attribute(tag, "id").and_then(|id| VIEWS.iter().find(|v| v.id == id));
            let start = field
                .default
                .map(str::to_string)
                .or_else(|| view.and_then(|v| v.start).map(|v| v.to_string()));
            let min = view.and_then(|v| v.min).or(bounds.0.map(|b| b.value));
            let max = view.and_then(|v| v.max).or(bounds.1.map(|b| b.value));
            for (name, value) in
                [("value", start), ("min", min.map(|v| v.to_string())), ("max", max.map(|v| v.to_string()))]
            {
                if let Some(v) = value {
                    out.push_str(&format!(" {name}=\"{v}\""));
                }
            }
        }
        rest = &rest[close..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use sandslope_render::figures::palette;

    /// The page's files as they are embedded, by name.
    const FILES: [(&str, &str); 5] = [
        ("index.html", INDEX),
        ("app.js", SCRIPT),
        ("routes.js", ROUTES_SCRIPT),
        ("drive.js", DRIVE_SCRIPT),
        ("style.css", STYLE),
    ];

    /// `text` without its comments: `/* ... */`, `<!-- ... -->`, and `//` to the end of the line
    /// where it follows a space or starts one (not the `//` of a URL).
    fn without_comments(text: &str) -> String {
        let mut out = String::with_capacity(text.len());
        let mut rest = text;
        loop {
            let block = rest.find("/*").map(|i| (i, "*/"));
            let html = rest.find("<!--").map(|i| (i, "-->"));
            let line = rest
                .match_indices("//")
                .find(|(i, _)| *i == 0 || rest[..*i].ends_with([' ', '\n']))
                .map(|(i, _)| (i, "\n"));
            let Some((at, end)) = [block, html, line].into_iter().flatten().min_by_key(|(i, _)| *i) else {
                out.push_str(rest);
                return out;
            };
            out.push_str(&rest[..at]);
            rest = match rest[at..].find(end) {
                Some(j) => &rest[at + j + end.len()..],
                None => "",
            };
            out.push('\n');
        }
    }

    /// The colour literals of `code`: `#` and three to eight hex digits not followed by a name's
    /// character (`#fff`, `#1d2430`, not `#drive-stop`), and `rgb(`, `rgba(`, `hsl(`, `hsla(`.
    fn colour_literals(code: &str) -> Vec<String> {
        let mut found = Vec::new();
        for (i, _) in code.match_indices('#') {
            let tail = &code[i + 1..];
            let hex = tail.chars().take_while(|c| c.is_ascii_hexdigit()).count();
            let next = tail[hex..].chars().next();
            let ends = !next.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '-');
            if (3..=8).contains(&hex) && ends {
                found.push(code[i..i + 1 + hex].to_string());
            }
        }
        let lower = code.to_ascii_lowercase();
        for f in ["rgb(", "rgba(", "hsl(", "hsla("] {
            found.extend(lower.match_indices(f).map(|(_, s)| s.to_string()));
        }
        found
    }

    #[test]
    fn the_literal_finder_finds_colours_and_not_ids() {
        let code = without_comments(
            "a { color: #fff; } /* #123456 */ #drive-stop { x: #b83227 }\n\
             const u = \"http://x/#map\"; // #eee\nf(\"#aab\", `rgb(${c})`, \"#deadbeef\")",
        );
        assert_eq!(colour_literals(&code), ["#fff", "#b83227", "#aab", "#deadbeef", "rgb("]);
    }

    /// The opening `<input>` tag of the element `id` in the served page.
    fn input_tag(id: &str) -> String {
        let at = FILLED_INDEX.find(&format!("<input id=\"{id}\"")).unwrap_or_else(|| panic!("no #{id}"));
        FILLED_INDEX[at..at + FILLED_INDEX[at..].find('>').unwrap()].to_string()
    }

    /// The served page's inputs start and end where the tables say, values worked out from the
    /// docs: max risk 0.05 strictly between 0 and 1 (docs/model.md §9), max roll 20 degrees
    /// strictly between 0 and 90, the CVs at 0.1 and 0.2 (docs/model.md §9), the simulated
    /// time 10 s, a prediction's slope -90 to 90 (docs/model.md §8), the mass's plausible 1 g
    /// to 250 kg and the stance legs 1 to 128.
    #[test]
    fn the_served_inputs_carry_the_tables_starts_and_ranges() {
        let has = |id: &str, want: &[(&str, Option<&str>)]| {
            let tag = input_tag(id);
            for (name, value) in want {
                assert_eq!(attribute(&tag, name), *value, "#{id} {name}: {tag}");
                assert!(tag.matches(&format!(" {name}=")).count() <= 1, "{tag}");
            }
        };
        has("max-risk", &[("value", Some("0.05")), ("min", Some("0")), ("max", Some("1"))]);
        has("max-roll", &[("value", Some("20")), ("min", Some("0")), ("max", Some("90"))]);
        has("cv-n", &[("value", Some("0.1")), ("min", Some("0")), ("max", Some("1"))]);
        has("cv-s", &[("value", Some("0.2")), ("min", Some("0")), ("max", Some("1"))]);
        has("sim-duration", &[("value", Some("10")), ("min", None), ("max", Some("60"))]);
        has("slope", &[("value", Some("10")), ("min", Some("-30")), ("max", Some("40"))]);
        has("slope-num", &[("value", Some("10")), ("min", Some("-90")), ("max", Some("90"))]);
        has("sim-slope-num", &[("value", Some("10")), ("min", Some("-90")), ("max", Some("90"))]);
        has("mass", &[("value", None), ("min", Some("0.001")), ("max", Some("250"))]);
        has("stance-legs", &[("min", Some("1")), ("max", Some("128"))]);
        has("hip-height", &[("min", Some("0")), ("max", None)]);
        // An input bound to no field is left as written.
        let original = &INDEX[INDEX.find("<input id=\"mass-slider\"").unwrap()..];
        assert_eq!(input_tag("mass-slider"), original[..original.find('>').unwrap()]);
    }

    /// The page's own spans lie inside their fields' ranges, and each names an input of the page.
    #[test]
    fn the_pages_views_lie_inside_the_fields_ranges() {
        for v in VIEWS {
            let tag = input_tag(v.id);
            let field = field_named(attribute(&tag, "data-field").expect("a view of a field")).unwrap();
            let (lo, hi) = field.bounds();
            for x in [v.start, v.min, v.max].into_iter().flatten() {
                assert!(lo.is_none_or(|b| x >= b.value) && hi.is_none_or(|b| x <= b.value), "{}: {x}", v.id);
            }
        }
    }

    /// The page writes no colour of its own: every colour of its style sheet, scripts and HTML is
    /// a custom property of the palette (`var(--page-ink)`, `palette("figure-ink")`), outside
    /// comments. A colour the page needs that the palette lacks is a new role in palette.rs.
    #[test]
    fn the_pages_files_hold_no_colour_literal() {
        for (name, text) in FILES {
            let found = colour_literals(&without_comments(text));
            assert!(found.is_empty(), "{name} writes colours of its own: {found:?}");
        }
    }

    /// Every custom property the page names is one the palette serves (a misspelt role would
    /// draw in the browser's default and no test would see it).
    #[test]
    fn every_role_the_page_names_is_served() {
        let served = palette::css_custom_properties();
        let css = without_comments(STYLE);
        let mut named: Vec<String> = css
            .match_indices("var(--")
            .map(|(i, m)| css[i + m.len()..].split(')').next().unwrap().to_string())
            .collect();
        let script = [SCRIPT, ROUTES_SCRIPT, DRIVE_SCRIPT].map(without_comments).concat();
        for open in ["palette(\"", "palette(`"] {
            for (i, m) in script.match_indices(open) {
                let name: String =
                    script[i + m.len()..].chars().take_while(|c| c.is_alphanumeric() || *c == '-').collect();
                // `palette(`route-${r}`)`, `palette(`p-fail-${k}`)`: a prefix of served names.
                named.push(name);
            }
        }
        assert!(named.len() > 10, "{named:?}");
        for name in named {
            assert!(
                served.contains(&format!(" --{name}")),
                "the page names --{name}, which the palette lacks"
            );
        }
    }

    /// The page draws in the figures' palette: the style sheet carries it (the fastest route
    /// in the plan figure's blue, not the green the page once wrote), and the script names no
    /// regime, route or simulation colour of its own.
    #[test]
    fn the_page_takes_its_colours_from_the_palette() {
        let served = Served::load("paper-hexapod".into(), "glass-beads-300um".into(), None).unwrap();
        let (css, _) = asset("/style.css", &served).unwrap();
        let css = String::from_utf8(css).unwrap();
        assert!(css.starts_with(":root {"), "{css}");
        // palette::ROUTE_TIME is RGB (0, 90, 220); SINKAGE (66, 110, 201); the page's ink the
        // report's #222, not the #1d2430 the page once wrote.
        assert!(css.contains("--route-time: #005adc;"), "{css}");
        assert!(css.contains("--sinkage: #426ec9;"), "{css}");
        assert!(css.contains("--page-ink: #222222;"), "{css}");
        for read in [
            "palette(c)",
            "palette(`route-${r}`)",
            "\"sand\"",
            "\"closed-form\"",
            "\"tripod-a\"",
            "palette(\"figure-ink\")",
            "palette(`p-fail-${k}`)",
        ] {
            assert!(SCRIPT.contains(read), "app.js does not read {read}");
        }
        // The safe-slope limit in the risk figure's colour for it, the model's blue.
        assert!(SCRIPT.contains("[safe, \"safe-slope\", SIM_COLOURS.model,"), "{SCRIPT}");
    }
}
