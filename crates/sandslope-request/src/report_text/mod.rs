//! The report's words: the sentences a reader sees, worded from the library's values
//! ([`sandslope::report::report`] returns numbers, flags and small enums; this module writes
//! the inputs table, the plain answer and the summary, why the calibration is unreliable, the
//! disagreements, the simulator section's reasons and every warning), and the one number
//! format of the page and `report.json` ([`sci`], [`format_p`]). The request's one answer path
//! ([`crate::report::answer_evidence`]) words every report, so the command line, Python and
//! the page read the same text.

mod answer;
mod diagnosis;
mod findings;
mod inputs;
mod labels;
mod observations;
mod paper;
mod simulator;
mod warnings;

use sandslope::report::{Evidence, Report};

use answer::{plain_answer, summary};
use diagnosis::word_diagnosis;
use findings::{disagreements, goodness_of_fit};
use inputs::inputs;
use labels::{label_terrain_rows, terrain_name, title_figures};
use observations::observation_items;
use paper::word_paper_rows;
use simulator::word_simulator;
use warnings::warnings;

/// Words `report`, built from `evidence`: the comparison with the paper's numbers, its labels (the figures' titles, the terrain's name,
/// the terrain's rows on another robot), its inputs table, its plain answer and summary,
/// its calibration's goodness-of-fit sentence, the diagnosis of an unreliable fit, the
/// disagreements (the user's observations the model misses first), the simulator section's
/// reasons and the warnings.
pub fn word(report: &mut Report, evidence: &Evidence) {
    word_paper_rows(&mut report.paper_vs_model);
    if !sandslope::paper::is_papers_robot(&evidence.robot) {
        label_terrain_rows(&mut report.paper_vs_model);
    }
    title_figures(&mut report.figures);
    report.plain_answer.terrain = terrain_name(report);
    report.inputs = inputs(evidence, report.tracks_give_t1);
    report.summary.text = summary(&report.summary, &report.paper_vs_model);
    report.plain_answer.text = plain_answer(&report.plain_answer);
    if let Some(c) = &mut report.calibration {
        c.goodness_of_fit = goodness_of_fit(c.no_floor);
    }
    let no_floor = report.calibration.as_ref().and_then(|c| c.no_floor);
    if let Some(d) = &mut report.fit_diagnosis {
        word_diagnosis(d, no_floor.as_ref());
    }
    let mut items = observation_items(&report.observation_misses);
    items.extend(disagreements(report, &evidence.forces));
    report.disagreements = items;
    word_simulator(&mut report.simulator, &mut report.simulator_fit_misses);
    report.warnings = warnings(report, evidence);
}

/// A probability as text (crate::format::probability).
pub use crate::format::probability as format_p;

/// The report's number format, shared by every front end (crate::format).
pub use crate::format::powers_of_ten as sci;

#[cfg(test)]
mod tests {
    use sandslope::report::ProvenanceKind;

    /// The report on the built-in terrain for `robot`, through the request's one answer path.
    fn default_report(robot: sandslope::Robot) -> sandslope::report::Report {
        let terrain = sandslope_io::load_terrain("glass-beads-300um").unwrap();
        let request = crate::report::ReportRequest::from_fields(
            "paper-hexapod".into(),
            "glass-beads-300um".into(),
            Vec::new(),
            &[],
        )
        .unwrap();
        request.answer(robot, terrain, crate::error::Words::Flag).unwrap()
    }

    /// The paper's evidence worded: the inputs table (the contact area W R = 1 cm x 4 cm =
    /// 4.0 x 10⁻⁴ m², the paper's five speeds measured), the goodness-of-fit sentence, and the
    /// inversion's disagreement (the k_s the observed speeds need rises from 20° to 24°, where
    /// the paper's 4.98 cm/s becomes 5.6 cm/s).
    #[test]
    fn the_papers_report_is_worded() {
        let robot = sandslope_io::load_robot("paper-hexapod").unwrap();
        let r = default_report(robot);
        let row = |name: &str| r.inputs.iter().find(|i| i.name == name).unwrap();
        assert_eq!(row("robot: leg contact area A_c").value, "4.0 × 10⁻⁴ m² (W R)");
        assert_eq!(row("observed speeds").provenance.kind, ProvenanceKind::Measured);
        assert!(r.figures.iter().all(|f| !f.title.is_empty() && f.title != f.id), "{:?}", r.figures);
        assert!(
            !r.plain_answer.terrain.is_empty()
                && r.plain_answer.text.starts_with(&format!("On {} the", r.plain_answer.terrain))
        );
        let c = r.calibration.as_ref().unwrap();
        assert!(c
            .goodness_of_fit
            .starts_with("The goodness-of-fit test is the fit without the floor: χ² = "));
        assert!(
            r.disagreements.iter().any(|d| d.contains("would have to rise from") && d.contains("20° to 24°")),
            "{:?}",
            r.disagreements
        );
    }

    /// A 0.5 kg robot without observations: the first warning says it is not the paper's
    /// 0.35 kg robot, with its mass, and the plain answer that it is untested.
    #[test]
    fn another_robot_is_warned_first() {
        let robot = sandslope_io::load_robot("paper-hexapod").unwrap().with_mass(0.5).unwrap();
        let r = default_report(robot);
        assert!(
            r.warnings[0].contains("kg, R = 4 cm) is not the paper's (0.35 kg, R = 4 cm)")
                && r.warnings[0].contains("0.5 kg"),
            "{:?}",
            r.warnings
        );
        // Only the terrain's two ratios are compared, labelled as the terrain's.
        assert_eq!(r.paper_vs_model.len(), 2);
        assert!(r
            .paper_vs_model
            .iter()
            .all(|c| c.quantity.ends_with("(the terrain, against the paper's glass beads)")
                && c.basis_note.starts_with("a property of the terrain alone")));
        assert!(
            r.plain_answer.text.contains("prediction for your robot, untested"),
            "{}",
            r.plain_answer.text
        );
    }
}
