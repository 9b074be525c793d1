//! The report's "where the model and the evidence disagree" findings that the library makes by
//! walking the model: the user's observations more than 2 SDs from the calibrated model, as
//! values. Every item's words, these and those found from the report's values alone (failing
//! comparisons, the per-slope inversion, the calibration's floor and plate scale), and the
//! calibration's warnings are the front ends' (the request layer's `report_text`).

use crate::calibrate::{AnchoringObservation, ObservationKind, SpeedObservation};
use crate::model::predict;
use crate::regime::Cause;
use crate::robot::Robot;
use crate::terrain::Terrain;

/// How far, in the observation's quoted SD, the calibrated model must miss a user's
/// observation for the report to list it.
pub const OBSERVATION_MISS_SD: f64 = 2.0;

/// One of the user's observations more than [`OBSERVATION_MISS_SD`] quoted SDs from the
/// calibrated model's value, or one the model has no value for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObservationMiss {
    /// A speed (m/s) or an anchoring time (s).
    pub kind: ObservationKind,
    /// Slope, degrees.
    pub slope_deg: f64,
    /// The observed value.
    pub observed: f64,
    /// Its quoted SD.
    pub sd: f64,
    /// The calibrated model's value (`None`: no speed, or no anchoring).
    pub model: Option<f64>,
    /// Why the model has no speed there: the cause of its regime (speeds only).
    pub cause: Cause,
}

impl ObservationMiss {
    /// `(observed - model) / sd`, where the model has a value.
    pub fn pull(&self) -> Option<f64> {
        self.model.map(|m| (self.observed - m) / self.sd)
    }
}

/// The user's observations against the model (the calibration on them): every speed, then
/// every anchoring time, more than [`OBSERVATION_MISS_SD`] quoted SDs from the model's value.
pub(crate) fn observation_misses(
    robot: &Robot,
    terrain: &Terrain,
    speeds: &[SpeedObservation],
    anchoring: &[AnchoringObservation],
) -> Vec<ObservationMiss> {
    let speeds = speeds.iter().map(|o| {
        let p = predict(robot, o.slope, &terrain.at(o.slope));
        ObservationMiss {
            kind: ObservationKind::Speed,
            slope_deg: o.slope.degrees(),
            observed: o.speed,
            sd: o.speed_sd,
            model: p.speed,
            cause: p.cause,
        }
    });
    let anchoring = anchoring.iter().map(|o| {
        let p = predict(robot, o.slope, &terrain.at(o.slope));
        ObservationMiss {
            kind: ObservationKind::AnchoringTime,
            slope_deg: o.slope.degrees(),
            observed: o.t1,
            sd: o.t1_sd,
            model: p.anchoring_time,
            cause: p.cause,
        }
    });
    speeds.chain(anchoring).filter(|m| m.pull().is_none_or(|z| z.abs() > OBSERVATION_MISS_SD)).collect()
}
