//! The explorer page: one HTML file, its script and its style sheet, embedded in the binary
//! (docs/serve.md). The script draws every chart itself on SVG and canvas, so nothing is
//! fetched from anywhere but this server.

use crate::served::Served;

const INDEX: &str = include_str!("page/index.html");
const SCRIPT: &str = include_str!("page/app.js");
const STYLE: &str = include_str!("page/style.css");

/// The page's file at `path`, with its content type, or `None` (404).
pub fn asset(path: &str, _served: &Served) -> Option<(Vec<u8>, &'static str)> {
    match path {
        "/" | "/index.html" => Some((INDEX.as_bytes().to_vec(), "text/html; charset=utf-8")),
        "/app.js" => Some((SCRIPT.as_bytes().to_vec(), "text/javascript; charset=utf-8")),
        "/style.css" => Some((STYLE.as_bytes().to_vec(), "text/css; charset=utf-8")),
        _ => None,
    }
}
