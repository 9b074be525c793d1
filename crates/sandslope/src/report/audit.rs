//! What a referee would check beside the comparison table: the fit without the error floor
//! (the goodness-of-fit test), the k_s each observed speed needs on its own (the per-slope
//! inversion), which term of docs/model.md §5 carries the lost step (the step budget), and
//! whether a regime claim at a slope beyond the measured points rests on an extrapolated k_s.

use serde::Serialize;
use statrs::distribution::{ChiSquared, ContinuousCDF};

use crate::calibrate::shear_strength_for_speed;
use crate::calibrate::SpeedObservation;
use crate::calibrate::{
    calibrate_jointly, AnchoringObservation, FreeParameter, JointSetup, Parameter, ShearShape,
};
use crate::constants::G;
use crate::critical::{critical_shear_strength, StepTarget};
use crate::model::predict;
use crate::regime::Regime;
use crate::robot::Robot;
use crate::slope::Slope;
use crate::terrain::Terrain;

/// Frame rate of the paper's motion capture, frames per second (Sec. II-B: 120 FPS).
pub const PAPER_FRAME_RATE_HZ: f64 = 120.0;

/// The joint fit with the error floor fixed at 0: ordinary weighted least squares, whose
/// chi^2 is the goodness-of-fit test (with the floor free, chi^2/dof near 1 to 2 is close to
/// built in: the floor grows until it is).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct NoFloorFit {
    /// `sum pull^2` with the quoted SDs only.
    pub chi_squared: f64,
    /// Observations minus fitted quantities.
    pub dof: i64,
    /// `chi^2 / dof` (`None` when dof <= 0).
    pub chi_squared_per_dof: Option<f64>,
    /// `P(chi^2_dof >= chi_squared)`: the probability of a fit this poor if the model and the
    /// quoted SDs were right (`None` when dof <= 0).
    pub p_value: Option<f64>,
    /// The fitted plate_scale without the floor (force-test calibrations only).
    pub plate_scale: Option<f64>,
}

/// The same joint calibration as the report's, with the floor fixed at 0.
pub(crate) fn no_floor_fit(
    robot: &Robot,
    shape: &Terrain,
    speeds: &[SpeedObservation],
    anchoring: &[AnchoringObservation],
) -> Option<NoFloorFit> {
    let setup = JointSetup {
        robot: robot.clone(),
        normal: shape.clone(),
        shear: ShearShape::ForceTests(shape.clone()),
        speeds: speeds.to_vec(),
        anchoring: anchoring.to_vec(),
        free: vec![FreeParameter { parameter: Parameter::PlateScale, bounds: None }],
        error_floor: 0.0,
    };
    let c = calibrate_jointly(&setup).ok()?;
    let p_value =
        (c.dof > 0).then(|| ChiSquared::new(c.dof as f64).ok().map(|d| d.sf(c.chi_squared))).flatten();
    Some(NoFloorFit {
        chi_squared: c.chi_squared,
        dof: c.dof,
        chi_squared_per_dof: c.chi_squared_per_dof,
        p_value,
        plate_scale: c.parameter(Parameter::PlateScale).map(|p| p.estimate.value),
    })
}

/// The k_s one observed speed needs on its own (docs/model.md §13 solved for `s = v T/2`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpeedInversion {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Observed speed, m/s.
    pub observed_m_s: f64,
    /// The k_s at which the model's speed equals it, N/m^3 (`calibrate --law per-slope`);
    /// `None` when no k_s reaches it (at or above the ceiling `s*/(T/2)`, or below the speed at
    /// the anchoring threshold).
    pub k_s_needed: Option<f64>,
    /// The model's k_s there (the report's terrain), N/m^3.
    pub k_s_model: f64,
}

/// Inverts each observed speed alone, lowest slope first.
pub(crate) fn invert_speeds(
    robot: &Robot,
    terrain: &Terrain,
    speeds: &[SpeedObservation],
) -> Vec<SpeedInversion> {
    let mut sorted = speeds.to_vec();
    sorted.sort_by(|a, b| a.slope.degrees().total_cmp(&b.slope.degrees()));
    sorted
        .iter()
        .map(|o| {
            let ground = terrain.at(o.slope);
            SpeedInversion {
                slope_deg: o.slope.degrees(),
                observed_m_s: o.speed,
                k_s_needed: shear_strength_for_speed(robot, o.slope, ground.k_n, o.speed).ok(),
                k_s_model: ground.k_s,
            }
        })
        .collect()
}

/// Where the step is lost at one slope (docs/model.md §5): `s = s* - shorter_propulsion -
/// inherited_speed - slip`, all in m.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StepBudget {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Level-sand step s*, m.
    pub level_step_m: f64,
    /// Anchoring time t1, s (`None`: the leg never anchors, and the budget is undefined).
    pub t1_s: Option<f64>,
    /// t1 in frames of the paper's 120 fps motion capture.
    pub t1_frames: Option<f64>,
    /// Backward slip before anchoring `s1 = 1/2 g sin(theta) t1^2`, m.
    pub slip_m: Option<f64>,
    /// The inherited-speed term of `s2`, `g sin(theta) t1 (T/2 - t1)`, m.
    pub inherited_speed_m: Option<f64>,
    /// The shorter propulsion time, `s* (1 - ((T/2 - t1)/(T/2))^2)`, m.
    pub shorter_propulsion_m: Option<f64>,
    /// Net step `s`, m.
    pub step_m: Option<f64>,
}

/// The step budget of `robot` on `terrain` at `slopes`.
pub(crate) fn step_budget(robot: &Robot, terrain: &Terrain, slopes: &[Slope]) -> Vec<StepBudget> {
    let half = robot.stance_duration();
    slopes
        .iter()
        .map(|&s| {
            let p = predict(robot, s, &terrain.at(s));
            let gs = G * s.sin();
            let t1 = p.anchoring_time;
            StepBudget {
                slope_deg: s.degrees(),
                level_step_m: p.level_step,
                t1_s: t1,
                t1_frames: t1.map(|t| t * PAPER_FRAME_RATE_HZ),
                slip_m: p.slip,
                inherited_speed_m: t1.map(|t| gs * t * (half - t)),
                shorter_propulsion_m: t1.map(|t| p.level_step * (1.0 - ((half - t) / half).powi(2))),
                step_m: p.step,
            }
        })
        .collect()
}

/// A regime claim at a slope beyond the measured points: the k_s the model uses there is
/// extrapolated, and the claim would hold within `[k_s_from, k_s_to)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Extrapolation {
    /// Slope of the claim, degrees.
    pub slope_deg: f64,
    /// The highest slope with a measured (or tabulated) k_s, degrees.
    pub last_measured_deg: f64,
    /// The extrapolated k_s the model uses there, N/m^3.
    pub k_s_used: f64,
    /// The regime claimed.
    pub claim: Regime,
    /// The regime the model gives at `k_s_used`.
    pub model: Regime,
    /// The smallest k_s at which the claim holds, N/m^3 (`None`: no k_s gives it).
    pub k_s_from: Option<f64>,
    /// The k_s above which the claim stops holding (`None`: it holds for every larger k_s).
    pub k_s_to: Option<f64>,
    /// The report robot's speed at `k_s_from` at this slope, m/s.
    pub speed_at_k_s_from_m_s: Option<f64>,
}

/// Attributes a regime claim `(mass, slope, regime)` to the extrapolation when `slope` lies
/// beyond the last of `measured_deg` (`None` otherwise).
pub(crate) fn extrapolation(
    robot: &Robot,
    terrain: &Terrain,
    measured_deg: &[f64],
    claim: (f64, f64, Regime),
) -> Option<Extrapolation> {
    let (mass, deg, regime) = claim;
    let last = measured_deg.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if deg <= last || last.is_nan() {
        return None;
    }
    let slope = Slope::from_degrees(deg).ok()?;
    let heavy = robot.with_mass(mass).ok()?;
    let ground = terrain.at(slope);
    let beyond = ground.beyond_repose(slope);
    let progress = critical_shear_strength(&heavy, slope, ground.k_n, beyond, StepTarget::Progress).ok();
    let robust = critical_shear_strength(&heavy, slope, ground.k_n, beyond, StepTarget::Robust).ok();
    let (from, to) = match regime {
        Regime::Metastable => (progress, robust),
        Regime::Success => (robust, None),
        Regime::Slippage => (None, progress),
        Regime::Sinkage => (None, None),
    };
    let speed_at = |k: f64| {
        let g = crate::terrain::Ground::new(ground.k_n, k).ok()?;
        predict(robot, slope, &g).speed
    };
    Some(Extrapolation {
        slope_deg: deg,
        last_measured_deg: last,
        k_s_used: ground.k_s,
        claim: regime,
        model: predict(&heavy, slope, &ground).regime,
        k_s_from: from,
        k_s_to: to,
        speed_at_k_s_from_m_s: from.and_then(speed_at),
    })
}
