//! The explorer page: one HTML file, its script and its style sheet, embedded in the binary
//! (docs/serve.md). The script draws every chart itself on SVG and canvas, so nothing is
//! fetched from anywhere but this server. The style sheet opens with the palette's colours
//! as CSS custom properties (`sandslope_render::figures::palette::css_custom_properties`),
//! which the script reads, so the page draws in the figures' colours and restates none.

use crate::served::Served;

const INDEX: &str = include_str!("page/index.html");
const SCRIPT: &str = include_str!("page/app.js");
const DRIVE_SCRIPT: &str = include_str!("page/drive.js");
const STYLE: &str = include_str!("page/style.css");

/// The page's file at `path`, with its content type, or `None` (404).
pub fn asset(path: &str, _served: &Served) -> Option<(Vec<u8>, &'static str)> {
    match path {
        "/" | "/index.html" => Some((INDEX.as_bytes().to_vec(), "text/html; charset=utf-8")),
        "/app.js" => Some((SCRIPT.as_bytes().to_vec(), "text/javascript; charset=utf-8")),
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

    /// The page draws in the figures' palette: the style sheet carries it (the fastest route
    /// in the plan figure's blue, not the green the page once wrote), and the script names no
    /// regime, route or simulation colour of its own.
    #[test]
    fn the_page_takes_its_colours_from_the_palette() {
        let served = Served::load("paper-hexapod".into(), "glass-beads-300um".into(), None).unwrap();
        let (css, _) = asset("/style.css", &served).unwrap();
        let css = String::from_utf8(css).unwrap();
        assert!(css.starts_with(":root {"), "{css}");
        // palette::ROUTE_TIME is RGB (0, 90, 220); SINKAGE (66, 110, 201).
        assert!(css.contains("--route-time: #005adc;"), "{css}");
        assert!(css.contains("--sinkage: #426ec9;"), "{css}");
        let own =
            ["#0b6e2f", "#7b2cbf", "#426ec9", "#d63830", "#f7d643", "#a8e296", "rgb(230,205,150)", "#d00"];
        for literal in own {
            assert!(!SCRIPT.contains(literal), "app.js still writes {literal}");
        }
        for read in ["palette(c)", "palette(`route-${r}`)", "\"sand\"", "\"closed-form\"", "\"tripod-a\""] {
            assert!(SCRIPT.contains(read), "app.js does not read {read}");
        }
    }
}
