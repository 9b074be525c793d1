//! The report's "where the model and the paper disagree" items, each with the rule that
//! decided it: the comparison rows that fail their rule, observed speeds that rise with slope,
//! the calibration's model-error floor and plate scale, and its warnings.

use crate::calibrate::SpeedObservation;
use crate::calibrate::{JointCalibration, Parameter};
use crate::paper::PaperComparison;

/// The disagreements, generated from the comparison rows, the calibration and the observed
/// speeds.
pub(crate) fn disagreements(
    rows: &[PaperComparison],
    calibration: Option<&JointCalibration>,
    speeds: &[SpeedObservation],
) -> Vec<String> {
    let mut out: Vec<String> = rows
        .iter()
        .filter(|r| !r.agrees)
        .map(|r| {
            format!(
                "{}: the paper reports {}, the model gives {} (rule: {}; {}).",
                r.quantity, r.paper, r.model, r.rule, r.source
            )
        })
        .collect();
    out.extend(rising_speeds(speeds));
    if let Some(c) = calibration {
        out.extend(calibration_items(c, speeds));
    }
    out
}

/// One item per pair of neighbouring slopes where the observed speed rises.
fn rising_speeds(speeds: &[SpeedObservation]) -> Vec<String> {
    let mut sorted: Vec<&SpeedObservation> = speeds.iter().collect();
    sorted.sort_by(|a, b| a.slope.radians().total_cmp(&b.slope.radians()));
    sorted
        .windows(2)
        .filter(|w| w[1].speed > w[0].speed)
        .map(|w| {
            format!(
                "The observed speed rises from {} to {} deg ({:.2} to {:.2} cm/s); a k_s that falls with slope makes the model's speed fall, so no calibration of this model can follow it.",
                w[0].slope.degrees(),
                w[1].slope.degrees(),
                w[0].speed * 100.0,
                w[1].speed * 100.0
            )
        })
        .collect()
}

/// The calibration's floor, its plate scale against the plate force, and its warnings.
fn calibration_items(c: &JointCalibration, speeds: &[SpeedObservation]) -> Vec<String> {
    let mut out = Vec::new();
    if c.error_floor_m_s > 0.0 {
        let floor = c.parameter(Parameter::ErrorFloor);
        out.push(format!(
            "Fitting the speeds takes a model-error floor of {:.2} cm/s added to the quoted SDs (68%: {:.2} to {:.2}); the quoted SDs alone (as small as {:.2} cm/s) are not reachable by the model.",
            c.error_floor_m_s * 100.0,
            floor.map_or(0.0, |p| p.estimate.lower * 100.0),
            floor.map_or(0.0, |p| p.estimate.upper * 100.0),
            speeds.iter().map(|o| o.speed_sd).fold(f64::INFINITY, f64::min) * 100.0
        ));
    }
    let scale = c.plate_scale();
    if let (Some(level), true) = (c.shear.first(), scale > 3.0) {
        out.push(format!(
            "The leg k_s the model needs at {} deg ({:.2e} N/m³) would give {:.0} N on the paper's 3 cm × 2 cm shear plate (F = k_s W d²), {scale:.0} times what the force tests give: the model's k_s is an effective leg parameter, not the plate's.",
            level.slope_deg, level.k_s, level.plate_force_n
        ));
    }
    for w in &c.warnings {
        out.push(format!("Calibration: {w}."));
    }
    out
}
