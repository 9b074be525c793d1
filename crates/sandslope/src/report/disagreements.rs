//! The report's "where the model and the evidence disagree" items that the library finds by
//! walking the model: the user's observations more than 2 SDs from the calibrated model. The
//! items worded from the report's values alone (failing comparisons, the per-slope inversion,
//! the calibration's floor and plate scale) and the calibration's warnings are the front ends'
//! (the request layer's `report_text`).

use crate::calibrate::{AnchoringObservation, SpeedObservation};
use crate::model::predict;
use crate::robot::Robot;
use crate::terrain::Terrain;

/// The user's observations against the model (the calibration on them): every speed or
/// anchoring time more than 2 quoted SDs from the model's value.
pub(crate) fn observation_items(
    robot: &Robot,
    terrain: &Terrain,
    speeds: &[SpeedObservation],
    anchoring: &[AnchoringObservation],
) -> Vec<String> {
    let mut out = Vec::new();
    for o in speeds {
        let p = predict(robot, o.slope, &terrain.at(o.slope));
        let pull = p.speed.map(|v| (o.speed - v) / o.speed_sd);
        if pull.is_none_or(|z| z.abs() > 2.0) {
            out.push(format!(
                "Your speed at {}°: observed {:.2} ± {:.2} cm/s (SD as measured), the calibrated model gives {} (rule: within 2 SD).",
                o.slope.degrees(),
                o.speed * 100.0,
                o.speed_sd * 100.0,
                match (p.speed, pull) {
                    (Some(v), Some(z)) => format!("{:.2} cm/s, {:.1} SD away", v * 100.0, z.abs()),
                    _ => format!("no speed ({})", p.cause.explain()),
                }
            ));
        }
    }
    for o in anchoring {
        let p = predict(robot, o.slope, &terrain.at(o.slope));
        let pull = p.anchoring_time.map(|t| (o.t1 - t) / o.t1_sd);
        if pull.is_none_or(|z| z.abs() > 2.0) {
            out.push(format!(
                "Your anchoring time at {}°: observed t1 = {:.0} ± {:.0} ms, the calibrated model gives {} (rule: within 2 SD).",
                o.slope.degrees(),
                o.t1 * 1e3,
                o.t1_sd * 1e3,
                match (p.anchoring_time, pull) {
                    (Some(t), Some(z)) => format!(
                        "{:.0} ms (the observed is {:.1} times the model's, {:.1} SD away)",
                        t * 1e3,
                        o.t1 / t,
                        z.abs()
                    ),
                    _ => "no anchoring".to_string(),
                }
            ));
        }
    }
    out
}
