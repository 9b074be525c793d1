//! The report's labels: its figures' titles (by id), the terrain's name where the terrain has
//! none, and the comparison rows that stand for any robot marked as the terrain's.

use sandslope::paper::PaperComparison;
use sandslope::report::{FigureRecord, Report, PHASE_PANELS};

/// Fills every figure's title from its id.
pub(super) fn title_figures(figures: &mut [FigureRecord]) {
    for f in figures {
        f.title = figure_title(&f.id);
    }
}

/// A figure's title: the paper's for the paper's figures, the page's own else.
fn figure_title(id: &str) -> String {
    if let Some((_, mass, slope)) = PHASE_PANELS.iter().find(|(panel, ..)| *panel == id) {
        return format!("Phase diagram, {mass} kg at {slope} deg");
    }
    match id {
        "fig3a" => "Speed against slope",
        "fig3b" => "Speed within a stride",
        "fig4d" => "Normal penetration resistance k_n",
        "fig4h" => "Shear strength k_s",
        "fig5b" => "Anchoring time against slope",
        "fig5c" => "Net step against slope",
        "risk" => "Failure probability against slope",
        "step_budget" => "Where the step goes against slope",
        "simulator" => "Stride simulator against the closed form",
        "calibration" => "Joint calibration: observed against fitted speeds, and pulls",
        other => other,
    }
    .to_string()
}

/// The model's terrain as the page names it: its own name, else what it is.
pub(super) fn terrain_name(report: &Report) -> String {
    match &report.plots.terrain_name {
        Some(name) => name.clone(),
        None if report.own_observations => "the terrain calibrated on your observations".into(),
        None => "this terrain".into(),
    }
}

/// The rows compared on a robot other than the paper's (the terrain's alone,
/// [`sandslope::paper::TERRAIN_ROWS`]), each labelled as the terrain's against the paper's glass
/// beads.
pub(super) fn label_terrain_rows(rows: &mut [PaperComparison]) {
    for r in rows {
        r.quantity = format!("{} (the terrain, against the paper's glass beads)", r.quantity);
        r.basis_note =
            format!("a property of the terrain alone, so it stands for any robot; {}", r.basis_note);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every figure the library lists has a title of its own, not its id; the phase panels
    /// name their mass and slope.
    #[test]
    fn every_figure_has_a_title() {
        for id in [
            "fig3a",
            "fig3b",
            "fig4d",
            "fig4h",
            "fig5b",
            "fig5c",
            "risk",
            "step_budget",
            "simulator",
            "calibration",
        ] {
            assert_ne!(figure_title(id), id);
        }
        assert_eq!(figure_title("fig6d"), "Phase diagram, 1 kg at 24 deg");
    }
}
