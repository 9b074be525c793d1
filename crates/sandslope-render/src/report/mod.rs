//! The report page: one self-contained HTML file (figures inline as SVG, styles inline, no
//! scripts, no network) rendered from the library's [`Report`]; `report.json` beside it is the
//! same value serialised. This module renders; it computes no physics.

mod figures;
mod sections;

pub use figures::page_figures;

use std::path::Path;

use sandslope::report::{Report, TrackGap, TrackRecord};
use sandslope_files::{create_output_dir, write_atomic};

use crate::figures::palette;

/// One figure of the page, by the paper's figure number.
pub struct PageFigure {
    /// The paper's id (`fig3a`, ...), or a name for figures the paper does not have.
    pub id: String,
    /// Title.
    pub title: String,
    /// What it shows and how to read it.
    pub caption: String,
    /// The figure as an SVG document.
    pub svg: String,
    /// Panels with their own paper ids and titles (`fig6a`...), when one figure holds several.
    pub parts: Vec<(String, String)>,
}

/// The page's "Motion capture" section: one row per tracked slope, and what was (not) used.
struct TracksSection<'a> {
    /// One row per slope, lowest first; no section when empty.
    records: &'a [TrackRecord],
    /// Sentences on how the tracks entered the report (skipped t1s, speeds not used, ...).
    notes: &'a [String],
}

/// Escapes text for HTML.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// Drops the XML prolog of an SVG document so it can sit inside HTML.
fn inline_svg(svg: &str) -> &str {
    match svg.find("<svg") {
        Some(i) => &svg[i..],
        None => svg,
    }
}

/// The page's style sheet, its colours from [`palette`] (`#222` is [`palette::PAGE_INK`]).
fn style() -> String {
    use palette::css;
    format!(
        "body{{font-family:'DejaVu Sans',Verdana,sans-serif;max-width:1100px;margin:2em auto;\
padding:0 1em;color:{ink};line-height:1.45}}h1{{font-size:1.7em}}h2{{margin-top:2em;border-bottom:1px solid {rule}}}\
table{{border-collapse:collapse;margin:1em 0;font-size:0.92em}}td,th{{border:1px solid {rule};padding:4px 8px;\
text-align:left}}th{{background:{th}}}tr.no td{{background:{no}}}tr.yes td.v{{color:{yes}}}\
figure{{margin:1.5em 0;display:inline-block;vertical-align:top;max-width:100%}}\
figure svg{{max-width:100%;height:auto;border:1px solid {fig}}}figcaption{{font-size:0.9em;color:{cap};max-width:900px}}\
figure{{display:block}}figure svg{{width:100%}}\
div.scroll{{overflow-x:auto;max-width:100%}}div.scroll table{{margin:0.5em 0}}\
.warn{{background:{warn};border-left:4px solid {bar};padding:0.5em 1em}}code{{background:{code};padding:0 3px}}\
table.sim{{table-layout:fixed;width:100%;min-width:1000px;font-size:0.85em}}table.sim td,table.sim th{{overflow-wrap:anywhere}}\
table.sim th:first-child{{width:7%}}table.sim th:last-child{{width:26%}}td.part summary{{color:{part}}}td.agree summary{{color:{yes}}}\
details summary{{cursor:pointer}}details[open]{{font-size:0.92em}}",
        ink = css(palette::PAGE_INK),
        rule = css(palette::PAGE_RULE),
        th = css(palette::PAGE_HEADER_BG),
        no = css(palette::PAGE_DISAGREE_BG),
        yes = css(palette::PAGE_AGREE_INK),
        fig = css(palette::PAGE_FIGURE_BORDER),
        cap = css(palette::PAGE_CAPTION),
        warn = css(palette::PAGE_WARN_BG),
        bar = css(palette::PAGE_WARN_BAR),
        code = css(palette::PAGE_CODE_BG),
        part = css(palette::PAGE_PART_INK),
    )
}

/// The whole page.
pub fn page(report: &Report, figures: &[PageFigure]) -> String {
    let own = report.own_observations;
    let mut h = String::with_capacity(1 << 20);
    h.push_str("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">");
    h.push_str("<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">");
    h.push_str(if own {
        "<title>sandslope report: your observations beside the model</title>"
    } else {
        "<title>sandslope report: the paper reproduced and confronted</title>"
    });
    h.push_str(&format!("<style>{}</style></head><body>\n", style()));
    h.push_str(&sections::header(report));
    h.push_str(&sections::plain_answer(report));
    h.push_str(&sections::warnings(report));
    h.push_str(&sections::fit_diagnosis(report));
    h.push_str(&sections::inputs(report));
    h.push_str(&sections::disagreements(report));
    h.push_str(&sections::comparison(report));
    if let Some(c) = &report.calibration {
        h.push_str(&sections::calibration(c, report.model_is_calibration));
    }
    h.push_str(&sections::step_budget(report));
    h.push_str(&sections::simulator(report));
    h.push_str(&sections::simulator_fit(report));
    let notes = track_notes(report);
    let tracks = TracksSection { records: &report.tracks, notes: &notes };
    if !tracks.records.is_empty() {
        h.push_str(&tracks_section(&tracks));
    }

    // Every table in a box of the page's width that scrolls sideways: at 600 px the wide
    // tables (the comparison, the simulator's) ran off the right edge of the page.
    let mut h = h.replace("<table", "<div class=\"scroll\"><table").replace("</table>", "</table></div>");
    h.push_str("<h2 id=\"figures\">Figures</h2>\n");
    for f in figures {
        let anchors: String =
            f.parts.iter().map(|(id, _)| format!("<span id=\"{}\"></span>", escape(id))).collect();
        h.push_str(&format!(
            "<figure id=\"{}\">{anchors}{}<figcaption><b>{} · {}</b>. {}</figcaption></figure>\n",
            escape(&f.id),
            inline_svg(&f.svg),
            escape(&f.id),
            escape(&f.title),
            escape(&f.caption)
        ));
    }
    h.push_str("<p><small>Made by <code>sandslope report</code>. Self-contained: no scripts, no network.</small></p>");
    h.push_str("</body></html>\n");
    h
}

/// Refuses a report folder that exists and is not a folder, naming it as the front end does
/// (`--out`, `html =`): checked before the report is built, which takes seconds.
pub fn check_dir(name: &str, dir: &Path) -> anyhow::Result<()> {
    if dir.exists() && !dir.is_dir() {
        anyhow::bail!("{name} {}: exists and is not a folder", dir.display());
    }
    Ok(())
}

/// Writes `report` into the folder `dir`, made with its missing parents: `index.html`, the
/// [`page`] with every figure of [`page_figures`], and `report.json`, the value as pretty JSON.
/// What `sandslope report --out DIR` and Python's `sandslope.report(html=DIR)` write. Page and
/// JSON are rendered before any folder or file is made, and each file is written through the
/// one output writer (a temporary file renamed into place).
pub fn write_dir(dir: &Path, report: &Report) -> anyhow::Result<()> {
    let figures = page_figures(report)?;
    let html = page(report, &figures);
    let json = serde_json::to_string_pretty(report)?;
    create_output_dir(dir)?;
    write_atomic(&dir.join("report.json"), json.as_bytes())?;
    write_atomic(&dir.join("index.html"), html.as_bytes())
}

/// `mean ± SD` scaled for display, `mean` alone without an SD, `-` without a mean.
pub(crate) fn plus_minus(mean: Option<f64>, sd: Option<f64>, scale: f64, decimals: usize) -> String {
    match (mean, sd) {
        (Some(m), Some(sd)) => format!("{:.decimals$} ± {:.decimals$}", m * scale, sd * scale),
        (Some(m), None) => format!("{:.decimals$}", m * scale),
        _ => "-".into(),
    }
}

/// The notes under the motion-capture table: each tracked slope whose anchoring time or speed
/// could not be used, and where the observed speeds come from when `--observed` is given too.
fn track_notes(report: &Report) -> Vec<String> {
    let mut out: Vec<String> = report
        .unused_tracks
        .iter()
        .map(|u| {
            let (what, why, figure) = match u.gap {
                TrackGap::NoAnchoredStep => {
                    ("anchoring time", format!("no anchored step among {} steps", u.steps), "fig5b")
                }
                TrackGap::NoAnchoringSd => (
                    "anchoring time",
                    "its SD needs at least two anchored steps with different t1".to_string(),
                    "fig5b",
                ),
                TrackGap::NoSpeedSd => (
                    "observed speed",
                    format!("its SD needs at least two steps with different speeds; found {} steps", u.steps),
                    "fig3a",
                ),
            };
            format!(
                "The tracks at {}° ({}) give no {what} ({why}): not drawn in {figure} nor used in the calibration.",
                u.slope_deg,
                u.files.join(", ")
            )
        })
        .collect();
    if report.track_speeds_shown_only {
        out.push(
            "The observed speeds are --observed's: the tracks' speeds are shown in this table only.".into(),
        );
    }
    out
}

/// The "Motion capture" section: the tracks' table and notes.
fn tracks_section(tracks: &TracksSection<'_>) -> String {
    let mut h = String::from("<h2 id=\"tracks\">Motion capture</h2>\n");
    h.push_str(
        "<p>Each slope's recordings (<code>--tracks</code>) pooled and analysed as <code>sandslope track</code> \
         does (docs/model.md §11): means and SDs across steps; t1 and slip over anchored steps.</p>\n",
    );
    h.push_str(
        "<table><tr><th>slope (°)</th><th>files</th><th>steps</th><th>unanchored</th>\
         <th>speed ± SD (cm/s)</th><th>t1 ± SD (ms)</th><th>slip ± SD (mm)</th></tr>",
    );
    for r in tracks.records {
        h.push_str(&format!(
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            r.slope_deg,
            r.files.iter().map(|f| escape(f)).collect::<Vec<_>>().join("<br>"),
            r.summary.steps,
            r.summary.unanchored_steps,
            plus_minus(Some(r.summary.speed_m_s), r.summary.speed_sd_m_s, 100.0, 2),
            plus_minus(r.summary.t1_s, r.summary.t1_sd_s, 1e3, 1),
            plus_minus(r.summary.slip_m, r.summary.slip_sd_m, 1e3, 2),
        ));
    }
    h.push_str("</table>\n");
    for n in tracks.notes {
        h.push_str(&format!("<p class=\"warn\">{}</p>", escape(n)));
    }
    h
}
