//! The report's answer in words: the plain answer's paragraph, the first warning on a robot
//! other than the paper's, and the comparison table's summary sentence.

use crate::format::Outcome;
use sandslope::paper::{Basis, PaperComparison};
use sandslope::report::{Evidence, PlainAnswer, Summary};
use sandslope::risk::SafeLimit;

/// The plain answer in one paragraph: how steep the robot climbs steadily and how fast, the
/// first slope where it does not and the first where it fails (the model at the terrain's
/// medians, docs/model.md §5-§6), then the two risk limits (§9).
pub(super) fn plain_answer(a: &PlainAnswer) -> String {
    let cm = |v: Option<f64>| v.map_or("-".into(), |v| format!("{:.1} cm/s", 100.0 * v));
    let mut text = format!("On {} the {} kg robot ", a.terrain, a.mass_kg);
    match a.climbs_up_to_deg {
        Some(deg) => text.push_str(&format!(
            "climbs steadily up to {deg:.2}° ({} on level ground, {} there)",
            cm(a.level_speed_m_s),
            cm(a.speed_at_limit_m_s)
        )),
        None => text.push_str("does not climb steadily even on level ground"),
    }
    if let Some((deg, regime)) = a.first_not_success.filter(|(_, r)| !r.is_failure()) {
        text.push_str(&format!(
            "; from {deg:.2}° it {} (the paper's \"{}\": it still moves up, {} there, but each step is shorter than \
             the robust step, so the next foothold lands in sand the last one disturbed and it can stall in its own trench)",
            regime.outcome(),
            regime.name(),
            cm(a.speed_at_first_not_success_m_s)
        ));
    }
    if let Some((deg, regime)) = a.first_failure {
        let why = if a.repose_deg.is_some_and(|r| deg >= r) { " (the angle of repose)" } else { "" };
        text.push_str(&format!("; from {deg:.2}°{why} it {} ({})", regime.outcome(), regime.name()));
    }
    text.push_str(" (the model at the terrain's medians, docs/model.md §5-§6).");
    let words = |l: &SafeLimit| match *l {
        SafeLimit::Limit { value, .. } => format!("up to {value:.1}°"),
        SafeLimit::Repose { repose_deg, .. } => format!("up to the angle of repose, {repose_deg}°"),
        SafeLimit::NoneSafe { .. } => "on no slope".into(),
        SafeLimit::BeyondRange { up_to, .. } => format!("at every slope up to {up_to}°"),
    };
    text.push_str(&format!(
        " With the terrain's uncertainty, it climbs steadily (P(not climbing steadily) < {r}) {} and is safe (P(sinks or slides back) < {r}) {} (§9).",
        words(&a.success_limit),
        words(&a.safe_limit),
        r = a.max_risk
    ));
    if a.untested {
        text.push_str(
            " This is the model's prediction for your robot, untested: the paper's speeds are of its 0.35 kg robot, and you gave no observations of yours.",
        );
    }
    if a.unreliable {
        text.push_str(
            " These numbers rest on a calibration that does not fit its observations: read why, and what data would fix it, before using them.",
        );
    }
    text
}

/// The first warning of a report on a robot other than the paper's without observations of its
/// own ([`PlainAnswer::untested`]): nothing about the paper's 0.35 kg robot is fitted or
/// compared.
pub(super) fn another_robot(evidence: &Evidence) -> String {
    let r = &evidence.robot;
    let (mass, ..) = sandslope::paper::ROBOT;
    format!(
        "your robot ({}, {} kg, R = {} cm) is not the paper's ({mass} kg, R = 4 cm) and you gave no observations \
         of it (--observed, --t1, --tracks): the paper's speeds, anchoring trend, step period and heavy-robot claim \
         are of the paper's robot, so this report neither fits nor compares them; it is the model's prediction \
         for your robot on {}, untested. Give its measured speeds with --observed to test and calibrate it",
        evidence.robot_source,
        r.mass(),
        r.leg_radius() * 100.0,
        evidence.terrain_source
    )
}

/// The comparison table summed up in a sentence: the independent agreements counted, or the
/// one independent number named.
pub(super) fn summary(counts: &Summary, rows: &[PaperComparison]) -> String {
    let construction = format!(
        "{} more agree by construction (inputs, tuned values, consequences of the model's form), out of {} compared",
        counts.by_construction_agree, counts.total
    );
    let mut independent = rows.iter().filter(|r| r.basis == Basis::Independent);
    match (counts.independent, independent.next()) {
        (0, _) | (_, None) => {
            format!("none of the paper's numbers tests the model independently here; {construction}")
        }
        // One number: name it, rather than "0 of the paper's 1 independent numbers".
        (1, Some(row)) => format!(
            "one of the paper's numbers tests the model independently, the {}: paper {}, model {}, so the model {} it; {construction}",
            row.quantity,
            row.paper,
            row.model,
            if row.agrees { "agrees with" } else { "disagrees with" }
        ),
        (n, Some(_)) => format!(
            "the model agrees with {} of the paper's {n} independent numbers; {construction}",
            counts.independent_agree
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plain answer worded from its values alone: a robot that climbs steadily to 18.5°
    /// at 15.7 cm/s on level ground and 6.2 there, turns metastable at 18.75° (the paper's
    /// name beside the field engineer's words) and slides back from the repose, 25°; both risk
    /// limits; untested and unreliable each add their sentence.
    #[test]
    fn the_plain_answer_is_worded_from_its_values() {
        use sandslope::regime::Regime;
        let mut a = PlainAnswer {
            mass_kg: 0.35,
            terrain: "sand".into(),
            climbs_up_to_deg: Some(18.5),
            level_speed_m_s: Some(0.157),
            speed_at_limit_m_s: Some(0.062),
            first_not_success: Some((18.75, Regime::Metastable)),
            first_failure: Some((25.0, Regime::Slippage)),
            success_limit: SafeLimit::Limit { value: 17.04, p_fail: 0.04 },
            safe_limit: SafeLimit::Repose { repose_deg: 25.0, p_fail: 0.01 },
            max_risk: 0.05,
            speed_at_first_not_success_m_s: Some(0.05),
            repose_deg: Some(25.0),
            untested: false,
            unreliable: false,
            text: String::new(),
        };
        let text = plain_answer(&a);
        assert!(
            text.starts_with(
                "On sand the 0.35 kg robot climbs steadily up to 18.50° (15.7 cm/s on level ground, 6.2 cm/s there); \
                 from 18.75° it climbs slowly and may stall (the paper's \"metastable\": it still moves up, 5.0 cm/s there"
            ),
            "{text}"
        );
        assert!(
            text.contains("; from 25.00° (the angle of repose) it slides back (slippage) (the model"),
            "{text}"
        );
        assert!(
            text.ends_with(
                "(P(not climbing steadily) < 0.05) up to 17.0° and is safe (P(sinks or slides back) < 0.05) up to \
                 the angle of repose, 25° (§9)."
            ),
            "{text}"
        );
        (a.untested, a.unreliable, a.climbs_up_to_deg) = (true, true, None);
        let text = plain_answer(&a);
        assert!(text.starts_with("On sand the 0.35 kg robot does not climb steadily even on level ground;"));
        assert!(
            text.contains("prediction for your robot, untested")
                && text.contains("does not fit its observations")
        );
    }

    /// The summary: no independent row, one (named), or several (counted).
    #[test]
    fn the_summary_names_one_independent_number_and_counts_more() {
        let row = |id: &str, basis: Basis, agrees: bool| PaperComparison {
            id: id.into(),
            quantity: format!("{id} quantity"),
            source: String::new(),
            paper: "1".into(),
            model: "2".into(),
            paper_value: None,
            model_value: None,
            agrees,
            rule: String::new(),
            basis,
            basis_note: String::new(),
            reading: sandslope::paper::Reading::StepPeriod { half_s: 0.5 },
        };
        let count = |rows: &[PaperComparison]| {
            let independent: Vec<&PaperComparison> =
                rows.iter().filter(|r| r.basis == Basis::Independent).collect();
            Summary {
                independent: independent.len(),
                independent_agree: independent.iter().filter(|r| r.agrees).count(),
                by_construction_agree: rows
                    .iter()
                    .filter(|r| r.basis != Basis::Independent && r.agrees)
                    .count(),
                total: rows.len(),
                text: String::new(),
            }
        };
        let mut rows = vec![row("a", Basis::Input, true)];
        assert_eq!(
            summary(&count(&rows), &rows),
            "none of the paper's numbers tests the model independently here; 1 more agree by construction \
             (inputs, tuned values, consequences of the model's form), out of 1 compared"
        );
        rows.push(row("b", Basis::Independent, false));
        assert!(summary(&count(&rows), &rows)
            .starts_with("one of the paper's numbers tests the model independently, the b quantity: paper 1, model 2, so the model disagrees with it; 1 more"));
        rows.push(row("c", Basis::Independent, true));
        assert!(summary(&count(&rows), &rows).starts_with(
            "the model agrees with 1 of the paper's 2 independent numbers; 1 more agree by construction"
        ));
    }
}
