//! Why the calibration is unreliable, in words: the paragraph and the remedies of the
//! library's [`FitDiagnosis`] (docs/calibration.md, "When the fit is unreliable"), worded from
//! its contradictions, its worst misses and the fit without the floor.

use sandslope::calibrate::ObservationKind;
use sandslope::report::{FitDiagnosis, Miss, NoFloorFit, StepAtObservedT1};

/// Fills `d`'s paragraph and remedies; `no_floor` is the report's fit without the floor.
pub(super) fn word_diagnosis(d: &mut FitDiagnosis, no_floor: Option<&NoFloorFit>) {
    d.remedies = remedies(&d.contradictions, &d.worst, no_floor);
    d.text = text(&d.contradictions, &d.worst, no_floor, d.stance_duration_s);
}

/// One observation far from the fitted model, in words.
fn describe(m: &Miss) -> String {
    let value = |v: f64| match m.kind {
        ObservationKind::Speed => format!("{:.2} cm/s", v * 100.0),
        ObservationKind::AnchoringTime => format!("{:.1} ms", v * 1e3),
        ObservationKind::PlateShearStrength => format!("{v:.3e} N/m³"),
    };
    let what = match m.kind {
        ObservationKind::Speed => "speed",
        ObservationKind::AnchoringTime => "anchoring time",
        ObservationKind::PlateShearStrength => "plate shear strength",
    };
    format!(
        "the {what} at {}° (observed {} ± {}, the fitted model {}: {:.1} SD)",
        m.slope_deg,
        value(m.observed),
        value(m.sd),
        value(m.model),
        m.sigmas
    )
}

/// The diagnosis in one paragraph: the contradictions by slope, where the recordings do not
/// slide freely before anchoring, and the observations farthest from the fitted model.
fn text(
    contradictions: &[StepAtObservedT1],
    worst: &[Miss],
    no_floor: Option<&NoFloorFit>,
    half: f64,
) -> String {
    let mut t = String::from("The model cannot meet these observations within their SDs");
    if let Some(n) = no_floor {
        t.push_str(&format!(
            " (χ² = {:.1} on {} degrees of freedom without the model-error floor)",
            n.chi_squared, n.dof
        ));
    }
    t.push('.');
    if !contradictions.is_empty() {
        let at: Vec<String> = contradictions
            .iter()
            .map(|c| {
                format!(
                    "at {}° the model's step at your t1 = {:.0} ± {:.0} ms is {:.2} ± {:.2} cm, and you observed {:.2} ± {:.2} cm ({:.2} cm/s over T/2 = {:.2} s)",
                    c.slope_deg,
                    c.t1_s * 1e3,
                    c.t1_sd_s * 1e3,
                    c.model_step_m * 100.0,
                    c.model_step_sd_m * 100.0,
                    c.observed_step_m * 100.0,
                    c.observed_step_sd_m * 100.0,
                    c.observed_step_m / half * 100.0,
                    half
                )
            })
            .collect();
        t.push_str(&format!(
            " Your anchoring times and speeds contradict each other whatever k_s is: {}. In the model (docs/model.md §5) the robot slides at g sin θ until it anchors and carries that slip speed through the rest of the stance, so a long t1 on a slope costs more step than these recordings lost.",
            at.join("; ")
        ));
        for c in contradictions {
            let Some(slip) = c.recorded_slip_m else { continue };
            if !(0.5..=2.0).contains(&(slip / c.free_slide_m)) {
                t.push_str(&format!(
                    " At {}° the recordings slip {:.1} mm in those {:.0} ms where a free slide is {:.1} mm: the robot does not slide freely before it anchors, as the model assumes.",
                    c.slope_deg,
                    slip * 1e3,
                    c.t1_s * 1e3,
                    c.free_slide_m * 1e3
                ));
            }
        }
    }
    if !worst.is_empty() {
        let list: Vec<String> = worst.iter().map(describe).collect();
        t.push_str(&format!(" Farthest from the fitted model: {}.", list.join("; ")));
    }
    t
}

/// What data would fix the fit, one sentence each.
fn remedies(
    contradictions: &[StepAtObservedT1],
    worst: &[Miss],
    no_floor: Option<&NoFloorFit>,
) -> Vec<String> {
    let mut out = Vec::new();
    if !contradictions.is_empty() {
        let slopes: Vec<String> = contradictions.iter().map(|c| format!("{}°", c.slope_deg)).collect();
        let slopes = match slopes.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
            _ => slopes.join(""),
        };
        out.push(format!(
            "At {slopes}: the touchdown times from the gait controller (sandslope track --touchdowns), so that t1 is measured from the true touchdown (estimated touchdowns bias t1 by up to 15 ms, docs/tracking.md). If t1 stands, the model's slip (§5) is what fails there, and more data at that slope cannot fix the fit.",
        ));
    }
    if worst.iter().any(|m| m.kind == ObservationKind::PlateShearStrength) {
        out.push(
            "Force tests at the slopes you walked, with repeats: a plate shear strength far from the fitted k_s(θ) means the force tests and the walks disagree on the sand's shear strength (docs/calibration.md).".into(),
        );
    }
    if worst.iter().any(|m| m.kind == ObservationKind::AnchoringTime) && contradictions.is_empty() {
        out.push(
            "Anchoring times measured from the controller's touchdowns at more slopes: t1 is what the model predicts least well here.".into(),
        );
    }
    if no_floor.and_then(|n| n.chi_squared_per_dof).is_some_and(|r| r > 3.0) {
        out.push(
            "More strides at the same slopes will not help: they shrink the SDs and make the misfit larger. The misfit is between the model's form and these observations, not noise.".into(),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A contradiction at 20° (t1 = 114 ± 10 ms; the model's step there -1.20 ± 0.30 cm, the
    /// observed 2.49 ± 0.03 cm, that is 4.98 cm/s over T/2 = 0.5 s), recordings that slip 1 mm
    /// where a free slide is 21.8 mm (1/2 g sin 20° t1^2 = 0.5 x 9.81 x 0.342 x 0.114^2), and a
    /// speed 4.0 SD off: the paragraph says each, the remedies ask for the controller's
    /// touchdowns and, with χ²/dof = 10 without the floor, say more strides will not help.
    #[test]
    fn a_contradiction_is_worded_with_its_numbers_and_remedies() {
        let free_slide = 0.5 * 9.81 * 20f64.to_radians().sin() * 0.114f64.powi(2);
        let mut d = FitDiagnosis {
            contradictions: vec![StepAtObservedT1 {
                slope_deg: 20.0,
                t1_s: 0.114,
                t1_sd_s: 0.01,
                observed_step_m: 0.0249,
                observed_step_sd_m: 0.0003,
                model_step_m: -0.012,
                model_step_sd_m: 0.003,
                sigmas: 12.1,
                recorded_slip_m: Some(0.001),
                free_slide_m: free_slide,
            }],
            worst: vec![Miss {
                kind: ObservationKind::Speed,
                slope_deg: 10.0,
                observed: 0.11,
                sd: 0.005,
                model: 0.13,
                sigmas: 4.0,
            }],
            remedies: Vec::new(),
            text: String::new(),
            stance_duration_s: 0.5,
        };
        let no_floor = NoFloorFit {
            chi_squared: 30.0,
            dof: 3,
            chi_squared_per_dof: Some(10.0),
            p_value: Some(1e-6),
            plate_scale: None,
        };
        word_diagnosis(&mut d, Some(&no_floor));
        assert!(
            d.text.starts_with(
                "The model cannot meet these observations within their SDs (χ² = 30.0 on 3 degrees of freedom \
                 without the model-error floor). Your anchoring times and speeds contradict each other whatever k_s \
                 is: at 20° the model's step at your t1 = 114 ± 10 ms is -1.20 ± 0.30 cm, and you observed 2.49 ± \
                 0.03 cm (4.98 cm/s over T/2 = 0.50 s). In the model (docs/model.md §5)"
            ),
            "{}",
            d.text
        );
        assert!(
            d.text.contains("the recordings slip 1.0 mm in those 114 ms where a free slide is 21.8 mm"),
            "{}",
            d.text
        );
        assert!(
            d.text.ends_with(
                "Farthest from the fitted model: the speed at 10° (observed 11.00 cm/s ± 0.50 cm/s, the fitted model \
                 13.00 cm/s: 4.0 SD)."
            ),
            "{}",
            d.text
        );
        assert_eq!(d.remedies.len(), 2, "{:?}", d.remedies);
        assert!(d.remedies[0].starts_with(
            "At 20°: the touchdown times from the gait controller (sandslope track --touchdowns)"
        ));
        assert!(d.remedies[1].starts_with("More strides at the same slopes will not help"));
    }
}
