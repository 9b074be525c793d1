//! Why a joint calibration is unreliable, and what data would fix it: the report's plain
//! diagnosis of a poor fit (docs/calibration.md, "When the fit is unreliable").
//!
//! Two findings, both computed from the observations and the model's form, not from the fit's
//! own verdict:
//! - **A speed and an anchoring time that contradict each other.** Given t1, the model's step
//!   at a slope does not depend on k_s at all (docs/model.md §5:
//!   `s = s* ((T/2 - t1)/(T/2))^2 - 1/2 g sin(theta) t1 (T - t1)`, with s* from k_n, §3). Where
//!   the observed step (speed times T/2) and this step at the observed t1 differ by more than
//!   [`CONTRADICTION_SD`] combined SDs, no k_s can meet both: the fit must fail there.
//! - **The observations farthest from the fitted model**, in their quoted SDs (without the
//!   model-error floor, which would hide them).
//!
//! The findings are values; the paragraph and the remedies are worded by the front end (the
//! request layer's `report_text`).

use serde::Serialize;

use super::tracks::TrackedSlope;
use crate::calibrate::{
    AnchoringObservation, CalibrationWarning, JointCalibration, ObservationKind, SpeedObservation,
};
use crate::model::{backward_slip, net_step, predict};
use crate::robot::Robot;
use crate::terrain::Terrain;

/// A step and an anchoring time further apart than this, in combined SDs, contradict each
/// other (a 3 SD rule: a chance coincidence is below 0.3%).
pub const CONTRADICTION_SD: f64 = 3.0;

/// How many of the worst-fitting observations the diagnosis names.
const WORST: usize = 3;

/// At one slope: the observed step against the model's step at the observed anchoring time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StepAtObservedT1 {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// The observed anchoring time and its SD, s.
    pub t1_s: f64,
    /// Its SD, s.
    pub t1_sd_s: f64,
    /// The observed step, speed times T/2, m.
    pub observed_step_m: f64,
    /// Its SD, m.
    pub observed_step_sd_m: f64,
    /// The model's step at the observed t1 (any k_s), m (docs/model.md §5).
    pub model_step_m: f64,
    /// Its SD from the t1 SD alone, m.
    pub model_step_sd_m: f64,
    /// `|observed - model|` in combined SDs.
    pub sigmas: f64,
    /// The slip the recordings show before anchoring, m (motion-capture tracks only).
    pub recorded_slip_m: Option<f64>,
    /// The model's free slide over the observed t1, `1/2 g sin(theta) t1^2`, m (§5).
    pub free_slide_m: f64,
}

/// One observation far from the fitted model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Miss {
    /// What was observed.
    pub kind: ObservationKind,
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Observed value (m/s, s or N/m^3 by kind).
    pub observed: f64,
    /// Its quoted SD.
    pub sd: f64,
    /// The fitted model's value.
    pub model: f64,
    /// `|observed - model| / sd`.
    pub sigmas: f64,
}

/// Why the calibration is unreliable and what data would fix it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitDiagnosis {
    /// Slopes whose observed speed and anchoring time contradict each other in the model.
    pub contradictions: Vec<StepAtObservedT1>,
    /// The observations farthest from the fitted model (at most three, beyond 3 quoted SDs).
    pub worst: Vec<Miss>,
    /// What data would fix it, one sentence each: worded by the front end from these values
    /// and the fit without the floor (empty as [`super::report`] returns it).
    pub remedies: Vec<String>,
    /// The diagnosis in one paragraph: worded by the front end likewise (empty as
    /// [`super::report`] returns it).
    pub text: String,
    /// The fitted robot's stance duration T/2, s, over which the paragraph turns each observed
    /// step back into a speed (a value of the paragraph, not of the JSON).
    #[serde(skip)]
    pub stance_duration_s: f64,
}

/// The evidence the diagnosis reads.
pub(crate) struct DiagnosisInput<'a> {
    pub fit: &'a JointCalibration,
    pub speeds: &'a [SpeedObservation],
    pub anchoring: &'a [AnchoringObservation],
    pub tracks: &'a [TrackedSlope],
}

/// The diagnosis of a calibration the fit itself flags (a poor fit or a quantity at its
/// bound); `None` for a fit without such a warning.
pub(crate) fn diagnose(input: &DiagnosisInput<'_>) -> Option<FitDiagnosis> {
    let fit = input.fit;
    let flagged = fit.warnings.iter().any(|w| {
        matches!(w, CalibrationWarning::PoorFit { .. } | CalibrationWarning::ParameterAtBound { .. })
    });
    if !flagged {
        return None;
    }
    let robot = Robot::new(fit.robot.clone()).ok()?;
    let terrain = Terrain::new(fit.terrain.clone()).ok()?;
    let contradictions: Vec<StepAtObservedT1> = input
        .speeds
        .iter()
        .filter_map(|o| {
            let a = input.anchoring.iter().find(|a| a.slope == o.slope)?;
            let slip = input
                .tracks
                .iter()
                .find(|t| t.slope_deg == o.slope.degrees())
                .and_then(|t| t.result.summary.slip_m);
            step_at_observed_t1(&robot, &terrain, o, a, slip)
        })
        .filter(|c| c.sigmas > CONTRADICTION_SD)
        .collect();
    let worst = worst(fit);
    Some(FitDiagnosis {
        contradictions,
        worst,
        remedies: Vec::new(),
        text: String::new(),
        stance_duration_s: robot.stance_duration(),
    })
}

/// The model's step at an observed t1 against the observed step (`None` where t1 is not
/// within the stance, where the model has no step).
fn step_at_observed_t1(
    robot: &Robot,
    terrain: &Terrain,
    speed: &SpeedObservation,
    anchoring: &AnchoringObservation,
    recorded_slip_m: Option<f64>,
) -> Option<StepAtObservedT1> {
    let half = robot.stance_duration();
    let (t1, t1_sd) = (anchoring.t1, anchoring.t1_sd);
    if !(0.0..half).contains(&t1) {
        return None;
    }
    let slope = speed.slope;
    let level_step = predict(robot, slope, &terrain.at(slope)).level_step;
    let step = |t: f64| net_step(robot, slope, level_step, t.clamp(0.0, half));
    let model = step(t1);
    // The step's SD from t1's, by the derivative (central difference, 0.1 ms).
    let h = 1e-4;
    let slope_of_step = (step(t1 + h) - step(t1 - h)) / (2.0 * h);
    let model_sd = (slope_of_step * t1_sd).abs();
    let (observed, observed_sd) = (speed.speed * half, speed.speed_sd * half);
    let combined = (observed_sd.powi(2) + model_sd.powi(2)).sqrt();
    Some(StepAtObservedT1 {
        slope_deg: slope.degrees(),
        t1_s: t1,
        t1_sd_s: t1_sd,
        observed_step_m: observed,
        observed_step_sd_m: observed_sd,
        model_step_m: model,
        model_step_sd_m: model_sd,
        sigmas: (observed - model).abs() / combined,
        recorded_slip_m,
        free_slide_m: backward_slip(slope, t1),
    })
}

/// The fitted model's worst misses in the observations' quoted SDs (not the floor's).
fn worst(fit: &JointCalibration) -> Vec<Miss> {
    let mut misses: Vec<Miss> = fit
        .pulls
        .iter()
        .map(|p| Miss {
            kind: p.kind,
            slope_deg: p.slope_deg,
            observed: p.observed,
            sd: p.sd,
            model: p.model,
            sigmas: (p.observed - p.model).abs() / p.sd,
        })
        .filter(|m| m.sigmas > 3.0)
        .collect();
    misses.sort_by(|a, b| b.sigmas.total_cmp(&a.sigmas));
    misses.truncate(WORST);
    misses
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::tests::paper_robot;
    use crate::slope::Slope;

    fn builtin_robot() -> Robot {
        paper_robot()
    }

    /// The built-in terrain's level point (k_n 7e5, k_s 2e6), the same at every slope.
    fn builtin_terrain() -> Terrain {
        Terrain::constant(7e5, 2e6).unwrap()
    }

    fn at(d: f64) -> Slope {
        Slope::from_degrees(d).unwrap()
    }

    /// The k_s-free step at an observed t1, worked by hand from docs/model.md §5 with the
    /// built-in robot (T/2 = 0.5 s) at 20 deg and t1 = 0.1 s:
    /// `s = s* (0.4/0.5)^2 - 1/2 g sin 20 (0.1)(0.9)`.
    #[test]
    fn the_step_at_an_observed_t1_is_section_5_at_that_t1() {
        let robot = builtin_robot();
        let terrain = builtin_terrain();
        let s = at(20.0);
        let level = predict(&robot, s, &terrain.at(s)).level_step;
        let half = robot.stance_duration();
        assert!((half - 0.5).abs() < 1e-12, "the built-in robot's T/2 is 0.5 s");
        let by_hand = level * 0.64 - 0.5 * 9.81 * 20f64.to_radians().sin() * 0.1 * 0.9;
        let speed = SpeedObservation { slope: s, speed: 0.05, speed_sd: 0.005 };
        let anchoring = AnchoringObservation { slope: s, t1: 0.1, t1_sd: 0.01 };
        let c = step_at_observed_t1(&robot, &terrain, &speed, &anchoring, Some(0.01)).unwrap();
        assert!((c.model_step_m - by_hand).abs() < 1e-9, "{} vs {by_hand}", c.model_step_m);
        // ds/dt1 = -2 s* (T/2 - t1)/(T/2)^2 - 1/2 g sin(theta) (T - 2 t1)
        let derivative = -2.0 * level * 0.4 / 0.25 - 0.5 * 9.81 * 20f64.to_radians().sin() * 0.8;
        assert!((c.model_step_sd_m - derivative.abs() * 0.01).abs() < 1e-6);
        assert!((c.observed_step_m - 0.025).abs() < 1e-12);
        assert!((c.free_slide_m - 0.5 * 9.81 * 20f64.to_radians().sin() * 0.01).abs() < 1e-12);
        // A step of 2.5 cm against about -7 cm: far beyond 3 combined SDs.
        assert!(c.sigmas > CONTRADICTION_SD, "{}", c.sigmas);
    }

    /// A speed and t1 taken from the model itself never contradict each other.
    #[test]
    fn the_models_own_speed_and_t1_do_not_contradict() {
        let robot = builtin_robot();
        let terrain = builtin_terrain();
        for d in [5.0, 10.0, 15.0, 20.0] {
            let s = at(d);
            let p = predict(&robot, s, &terrain.at(s));
            let speed = SpeedObservation { slope: s, speed: p.speed.unwrap(), speed_sd: 0.001 };
            let anchoring = AnchoringObservation { slope: s, t1: p.anchoring_time.unwrap(), t1_sd: 0.001 };
            let c = step_at_observed_t1(&robot, &terrain, &speed, &anchoring, None).unwrap();
            assert!(c.sigmas < 1e-6, "{d} deg: {}", c.sigmas);
        }
    }
}
