//! The explorer page: one HTML file, its scripts (`app.js`: helpers, Explore and Risk;
//! `routes.js`: Routes, Simulate and the wiring; `drive.js`: Drive) and its style sheet,
//! embedded in the binary (docs/serve.md). The scripts draw every chart themselves on SVG and
//! canvas, so nothing is fetched from anywhere but this server. The style sheet opens with the palette's colours
//! as CSS custom properties (`sandslope_render::figures::palette::css_custom_properties`),
//! which the script reads, so the page draws in the figures' colours and restates none.

use crate::served::Served;

const INDEX: &str = include_str!("page/index.html");
const SCRIPT: &str = include_str!("page/app.js");
const ROUTES_SCRIPT: &str = include_str!("page/routes.js");
const DRIVE_SCRIPT: &str = include_str!("page/drive.js");
const STYLE: &str = include_str!("page/style.css");

/// The page's file at `path`, with its content type, or `None` (404).
pub fn asset(path: &str, _served: &Served) -> Option<(Vec<u8>, &'static str)> {
    match path {
        "/" | "/index.html" => Some((INDEX.as_bytes().to_vec(), "text/html; charset=utf-8")),
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
