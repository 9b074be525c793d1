//! Which model gives the speeds and anchoring times a calibration fits: the closed form
//! (docs/model.md §3-§5, the default) or the stride simulator (docs/model.md §15-§18,
//! `calibrate --model simulate`).
//!
//! With the simulator, each trial point of the fit walks the robot once at every observed
//! slope (in parallel, rayon) with the leg's k_s of that point and the normal source's k_n,
//! and reads the walk's mean step speed and mean anchoring time (docs/model.md §18). A walk
//! whose speed never turned from falling to rising in any measured step has no t1; it is
//! continued at the end of the stance, `T/2` (the leg anchored at the last moment or not at
//! all), as the closed form is continued at its anchoring limit. Walks are remembered by their
//! exact inputs, so the free quantities that do not enter a walk (the error floor) cost no
//! walks when the optimiser varies them.

use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

use rayon::prelude::*;
use serde::Serialize;

use super::{CalibrationError, Parameter, RobotKey};
use crate::error::ParamError;
use crate::robot::Robot;
use crate::scenario::Scenario;
use crate::simulate::{simulate, SimSettings, SimSummary};
use crate::terrain::Terrain;

/// The fit's walk length, s: one stride of warm-up and three strides measured (six steps).
pub const FIT_DURATION_S: f64 = 4.0;

/// The fit's time steps per stride period T (docs/calibration.md): T / 500, four times the
/// simulator's default step. With the one-sided belly (the default since 2026-12-07) a walk at
/// T / 500 is within 0.3 cm/s of the default step's from leg k_s 1e4 to 1e6 at 0 to 24
/// degrees, the range the paper's evidence is fitted in, at a quarter of the cost; the walks
/// of a fit whose settings name a step keep it.
pub const FIT_STEPS_PER_STRIDE: f64 = 500.0;

/// The model a calibration fits with.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SpeedModel {
    /// The closed form (docs/model.md §3-§5).
    ClosedForm,
    /// The stride simulator with these settings (docs/model.md §15-§18).
    Simulator {
        /// How each walk runs.
        settings: SimSettings,
    },
}

impl SpeedModel {
    /// The simulator with the fit's setting: [`FIT_DURATION_S`] walks at the fit's step
    /// ([`FIT_STEPS_PER_STRIDE`] a stride, set per walk from the robot's stride period, so
    /// `dt_s` is left unset here) and the default creep speed and element count.
    pub fn simulator_for_fit() -> SpeedModel {
        let settings = SimSettings::new(FIT_DURATION_S).expect("the fit's constant setting is valid");
        SpeedModel::Simulator { settings }
    }

    /// The name as `calibrate --model` takes it.
    pub fn name(&self) -> &'static str {
        match self {
            SpeedModel::ClosedForm => "closed-form",
            SpeedModel::Simulator { .. } => "simulate",
        }
    }
}

/// What one walk gives the fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Walked {
    /// Mean step speed over the measured steps, m/s.
    pub speed: f64,
    /// Mean anchoring time, continued at T/2 when no measured step anchored, s.
    pub t1: f64,
}

/// The smallest leg k_s handed to the simulator, N/m^3 (docs/calibration.md).
pub(crate) const MIN_SIMULATED_K_S: f64 = 1.0;

/// One walk of `robot` at `slope_deg` on the constant ground `(k_n, k_s)` (no angle of repose)
/// with `settings`: the walk a trial point of the fit takes its model values from, and the
/// report walks again on the fitted ground (`report::simulator_fit_misses`). Settings without
/// a step walk at the fit's, `T / FIT_STEPS_PER_STRIDE` of this robot's stride period.
pub(crate) fn walk_on_ground(
    robot: &Robot,
    slope_deg: f64,
    k_n: f64,
    k_s: f64,
    settings: &SimSettings,
) -> Result<SimSummary, ParamError> {
    let settings = &match settings.dt_s {
        Some(_) => *settings,
        None => settings.with_dt(robot.stride_period() / FIT_STEPS_PER_STRIDE)?,
    };
    let scenario = Scenario::new(robot.clone(), Terrain::constant(k_n, k_s)?, None, None)?;
    let slope = crate::slope::SignedSlope::from_degrees(slope_deg)?;
    simulate(&scenario, slope, settings).map(|s| s.summary).map_err(|e| match e {
        crate::simulate::SimulateError::Param(p) => p,
    })
}

/// The simulator as the fit's model: its settings and the walks already run.
pub(crate) struct SimulatedModel<'a> {
    settings: SimSettings,
    walks: Mutex<HashMap<String, Result<Walked, String>>>,
    /// Raised by the caller to stop: every walk not yet run then fails at once.
    cancel: Option<&'a AtomicBool>,
}

impl<'a> SimulatedModel<'a> {
    pub fn new(settings: SimSettings, cancel: Option<&'a AtomicBool>) -> SimulatedModel<'a> {
        SimulatedModel { settings, walks: Mutex::new(HashMap::new()), cancel }
    }

    /// Whether the caller asked the fit to stop.
    pub fn cancelled(&self) -> bool {
        self.cancel.as_ref().is_some_and(|c| c.load(Ordering::Relaxed))
    }

    /// One walk of `robot` at `slope_deg` on ground `(k_n, k_s)`, remembered by its exact
    /// inputs (the robot's keys as written, which round-trip, and the bits of the rest).
    fn walk(&self, robot: &Robot, slope_deg: f64, k_n: f64, k_s: f64) -> Result<Walked, String> {
        let key =
            format!("{:?}|{:x}|{:x}|{:x}", robot.spec(), slope_deg.to_bits(), k_n.to_bits(), k_s.to_bits());
        if let Some(w) = self.walks.lock().ok().and_then(|m| m.get(&key).cloned()) {
            return w;
        }
        if self.cancelled() {
            return Err("interrupted".into());
        }
        let walked = walk_on_ground(robot, slope_deg, k_n, k_s, &self.settings)
            .map_err(|e| e.to_string())
            .map(|summary| Walked {
                speed: summary.speed_m_s,
                t1: summary.t1_s.unwrap_or(robot.stance_duration()),
            });
        if let Ok(mut m) = self.walks.lock() {
            m.insert(key, walked.clone());
        }
        walked
    }

    /// Walks at every `(slope_deg, k_n, k_s)`, in parallel.
    pub fn walks(&self, robot: &Robot, grounds: &[(f64, f64, f64)]) -> Result<Vec<Walked>, String> {
        grounds.par_iter().map(|&(deg, k_n, k_s)| self.walk(robot, deg, k_n, k_s)).collect()
    }

    /// Walks run so far (distinct inputs).
    pub fn walks_run(&self) -> usize {
        self.walks.lock().map_or(0, |m| m.len())
    }
}

/// The simulator does not read this freed quantity: the fit would be flat in it.
pub(crate) fn check_free_for_simulator(parameter: Parameter) -> Result<(), CalibrationError> {
    match parameter {
        Parameter::Robot(
            k @ (RobotKey::LevelStepM | RobotKey::ResponseTimeS | RobotKey::LegContactAreaM2),
        ) => Err(CalibrationError::NotASimulatorInput { name: k.name().into() }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::{calibrate_jointly_with, FreeParameter, JointSetup, ShearShape, SpeedObservation};
    use crate::model::tests::paper_robot;
    use crate::robot::RobotSpec;
    use crate::slope::Slope;
    use crate::terrain::{TerrainPoint, TerrainSpec};
    use crate::CalibrationError;

    /// Two force tests used exactly (no SDs): k_s = 1e5 at 0 deg and 4e4 at 20 deg.
    fn forces() -> Terrain {
        let p = |slope_deg, k_s| TerrainPoint { slope_deg, k_n: 7e5, k_s, k_n_sd: None, k_s_sd: None };
        Terrain::new(TerrainSpec { name: None, repose_deg: None, points: vec![p(0.0, 1e5), p(20.0, 4e4)] })
            .unwrap()
    }

    fn setup(free: Vec<FreeParameter>) -> JointSetup {
        let speed = |deg: f64, speed, speed_sd| SpeedObservation {
            slope: Slope::from_degrees(deg).unwrap(),
            speed,
            speed_sd,
        };
        JointSetup {
            robot: paper_robot(),
            normal: forces(),
            shear: ShearShape::ForceTests(forces()),
            speeds: vec![speed(0.0, 0.157, 0.0097), speed(10.0, 0.110, 0.0014)],
            anchoring: vec![],
            free,
            error_floor: 0.01,
        }
    }

    fn short_walks() -> SpeedModel {
        SpeedModel::Simulator { settings: SimSettings::new(1.5).unwrap().with_dt(2e-3).unwrap() }
    }

    /// With nothing free the fit is the simulator evaluated once: each speed's model value is
    /// the walk at that slope with the leg k_s of the force tests interpolated by hand (1e5 at
    /// 0 deg; halfway from 1e5 to 4e4, 7e4, at 10 deg), the pull is (observed - model) /
    /// sqrt(sd^2 + f^2), and chi^2 their sum of squares; two walks were run.
    #[test]
    fn the_simulator_replaces_the_closed_form_speed_by_the_walk() {
        let SpeedModel::Simulator { settings } = short_walks() else { unreachable!() };
        let cal = calibrate_jointly_with(&setup(vec![]), short_walks()).unwrap();
        let mut chi2 = 0.0;
        for (pull, (deg, k_s, observed, sd)) in
            cal.pulls.iter().zip([(0.0, 1e5, 0.157, 0.0097), (10.0, 7e4, 0.110, 0.0014)])
        {
            let scenario =
                Scenario::new(paper_robot(), Terrain::constant(7e5, k_s).unwrap(), None, None).unwrap();
            let walk = simulate(&scenario, crate::slope::SignedSlope::from_degrees(deg).unwrap(), &settings)
                .unwrap()
                .summary
                .speed_m_s;
            assert_eq!(pull.model, walk, "{deg} deg");
            let expected = (observed - walk) / (sd * sd + 0.01f64 * 0.01).sqrt();
            assert!((pull.pull - expected).abs() < 1e-12, "{deg} deg: {} vs {expected}", pull.pull);
            chi2 += expected * expected;
        }
        assert!((cal.chi_squared - chi2).abs() < 1e-9);
        assert_eq!(cal.walks, 2);
        assert_eq!(cal.model, short_walks());
        // No closed-form ceiling warning: the simulator has no s*/(T/2) ceiling.
        use crate::calibrate::CalibrationWarning as W;
        assert!(!cal.warnings.iter().any(|w| matches!(w, W::SpeedNearCeiling { .. })), "{:?}", cal.warnings);
    }

    /// A cancel flag raised before the fit stops it before any walk: the answer is
    /// `Interrupted`, not a fit of the penalties the refused walks leave (Python raises it on
    /// Ctrl-C, `calibrate_jointly_cancellable`).
    #[test]
    fn a_raised_cancel_flag_interrupts_the_simulators_fit() {
        use crate::calibrate::calibrate_jointly_cancellable;
        let free = vec![FreeParameter { parameter: Parameter::PlateScale, bounds: None }];
        let cancel = AtomicBool::new(true);
        let e = calibrate_jointly_cancellable(&setup(free), short_walks(), &cancel).unwrap_err();
        assert_eq!(e, CalibrationError::Interrupted);
        assert_eq!(e.to_string(), "interrupted");
    }

    /// Robot keys the simulator does not read are refused by name before any walk; a robot
    /// the simulator refuses (65 stance legs) is refused with the simulator's reason.
    #[test]
    fn keys_the_simulator_ignores_and_robots_it_refuses_are_errors() {
        for key in [RobotKey::ResponseTimeS, RobotKey::LevelStepM, RobotKey::LegContactAreaM2] {
            let free = vec![FreeParameter { parameter: Parameter::Robot(key), bounds: None }];
            let e = calibrate_jointly_with(&setup(free), short_walks()).unwrap_err();
            assert_eq!(e, CalibrationError::NotASimulatorInput { name: key.name().into() });
            assert!(e.to_string().contains(key.name()));
        }
        let spec = RobotSpec { stance_legs: 65, ..paper_robot().spec().clone() };
        let s = JointSetup { robot: Robot::new(spec).unwrap(), ..setup(vec![]) };
        match calibrate_jointly_with(&s, short_walks()) {
            Err(CalibrationError::Simulator { reason }) => {
                assert!(reason.contains("stance_legs"), "{reason}")
            }
            other => panic!("{other:?}"),
        }
    }
}
