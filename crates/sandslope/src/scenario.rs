//! One robot on one terrain, evaluated at one slope or over a range of slopes: what the
//! `predict` and `sweep` commands compute.
//!
//! [`Scenario::evaluate`] runs the model (docs/model.md §3-§6) and adds what a user needs
//! beside it: the regime's cause, the critical shear strengths and the k_s margin
//! (docs/model.md §13), whether the terrain was extrapolated (§7), and the speed the robot
//! makes, which is not always the stance model's `v = s / (T/2)`: where the legs sink or the
//! slope is at or above the angle of repose, the stance model's assumptions fail and the
//! regime rules its speed out (see [`SlopeEvaluation::speed`]).

use serde::{Serialize, Serializer};

use crate::critical::{critical_shear_strength, NoShearSuffices, StepTarget};
use crate::error::{positive, ParamError};
use crate::model::{predict, Prediction};
use crate::regime::{Cause, Regime};
use crate::robot::Robot;
use crate::slope::{SignedSlope, Slope};
use crate::terrain::{Ground, Terrain};

/// A robot on a terrain, with optional fixed resistances overriding the terrain's at every
/// slope. Build it with [`Scenario::new`].
#[derive(Debug, Clone)]
pub struct Scenario {
    robot: Robot,
    terrain: Terrain,
    k_n: Option<f64>,
    k_s: Option<f64>,
}

impl Scenario {
    /// A scenario: `k_n` and `k_s`, if given, replace the terrain's values at every slope
    /// (finite, > 0; errors name the keys `k_n` and `k_s`).
    pub fn new(
        robot: Robot,
        terrain: Terrain,
        k_n: Option<f64>,
        k_s: Option<f64>,
    ) -> Result<Scenario, ParamError> {
        let k_n = k_n.map(|v| positive("k_n", v)).transpose()?;
        let k_s = k_s.map(|v| positive("k_s", v)).transpose()?;
        Ok(Scenario { robot, terrain, k_n, k_s })
    }

    /// The same scenario with another robot (terrain and overrides kept).
    pub fn with_robot(&self, robot: Robot) -> Scenario {
        Scenario { robot, ..self.clone() }
    }

    /// The robot.
    pub fn robot(&self) -> &Robot {
        &self.robot
    }

    /// The terrain table.
    pub fn terrain(&self) -> &Terrain {
        &self.terrain
    }

    /// The ground at `slope` (overrides applied) and whether any value used was extrapolated
    /// beyond the terrain's last point (docs/model.md §7).
    pub fn ground_at(&self, slope: Slope) -> (Ground, bool) {
        let mut ground = self.terrain.at(slope);
        ground.k_n = self.k_n.unwrap_or(ground.k_n);
        ground.k_s = self.k_s.unwrap_or(ground.k_s);
        let extrapolated = self.terrain.extrapolates(slope) && (self.k_n.is_none() || self.k_s.is_none());
        (ground, extrapolated)
    }

    /// The model at a signed slope (descending is evaluated as climbing |slope|, docs/model.md
    /// §8); the slope was validated where it was given ([`SignedSlope::from_degrees`]).
    pub fn evaluate(&self, signed: SignedSlope) -> SlopeEvaluation {
        let slope = signed.felt();
        let (ground, extrapolated) = self.ground_at(slope);
        let prediction = predict(&self.robot, slope, &ground);
        let critical = |target| {
            critical_shear_strength(&self.robot, slope, ground.k_n, ground.beyond_repose(slope), target)
        };
        let (progress, robust) = (critical(StepTarget::Progress), critical(StepTarget::Robust));
        SlopeEvaluation {
            slope_deg: signed.degrees(),
            k_s_margin: progress.as_ref().ok().map(|k| ground.k_s / k),
            prediction,
            critical_progress: progress,
            critical_robust: robust,
            extrapolated,
        }
    }

    /// The model at each of `slopes`, in order (see [`Scenario::evaluate`]).
    pub fn sweep(&self, slopes: &[SignedSlope]) -> Vec<SlopeEvaluation> {
        slopes.iter().map(|&s| self.evaluate(s)).collect()
    }
}

/// The slopes `from, from + step, ..., <= to`, degrees, with a tolerance so that `to` is not
/// lost to rounding (`0:1:0.1` gives 11 slopes). Fails (keys `step`, `from`) unless `step > 0`,
/// both ends are finite and `from <= to`, or when it would give more than `max` slopes.
pub fn slope_range(from: f64, to: f64, step: f64, max: usize) -> Result<Vec<f64>, ParamError> {
    positive("step", step)?;
    if !(from.is_finite() && to.is_finite()) || from > to {
        return Err(ParamError::new(
            "from",
            from,
            format!("a finite number not above the end of the range, {to}"),
        ));
    }
    let n = ((to - from) / step + 1e-9).floor();
    if n >= max as f64 {
        return Err(ParamError::new(
            "step",
            step,
            format!("large enough to give at most {max} slopes ({n} asked)"),
        ));
    }
    Ok((0..=n as usize).map(|i| from + i as f64 * step).collect())
}

/// The model's answer at one slope, with what a user needs beside it.
///
/// Serialises (JSON, CSV) as one flat record, `null` where a quantity is undefined:
/// `slope_deg, k_n, k_s, regime, cause, d_n_m, level_step_m, d_s_m, t1_s, slip_m,
/// propulsion_m, step_m, speed_m_s, model_speed_m_s, k_s_margin, critical_k_s_progress,
/// critical_k_s_robust, extrapolated`.
#[derive(Debug, Clone, PartialEq)]
pub struct SlopeEvaluation {
    /// The slope as given (negative: descending, evaluated as |slope|).
    pub slope_deg: f64,
    /// Every model quantity, including the regime and its cause.
    pub prediction: Prediction,
    /// `k_s / critical k_s for s > 0` (docs/model.md §13); `None` when no k_s is enough.
    pub k_s_margin: Option<f64>,
    /// Smallest k_s giving progress (`s > 0`), or why none does.
    pub critical_progress: Result<f64, NoShearSuffices>,
    /// Smallest k_s giving robust progress (`s >= s_min`), or why none does.
    pub critical_robust: Result<f64, NoShearSuffices>,
    /// Whether a terrain value used was extrapolated beyond the table's last point.
    pub extrapolated: bool,
}

impl SlopeEvaluation {
    /// The regime (docs/model.md §6).
    pub fn regime(&self) -> Regime {
        self.prediction.regime
    }

    /// Why the stance ended in its regime.
    pub fn cause(&self) -> Cause {
        self.prediction.cause
    }

    /// The speed the robot makes, m/s: the stance model's `v = s / (T/2)`, except where the
    /// regime rules it out (legs sinking, or the slope at or above the angle of repose, where
    /// the surface itself yields: [`Cause::rules_out_speed`]), which gives `None`. A negative
    /// speed (net backward step, regime slippage) is kept: the robot loses ground.
    pub fn speed(&self) -> Option<f64> {
        self.prediction.speed.filter(|_| !self.cause().rules_out_speed())
    }

    /// Whether the stance model has a speed here that the regime rules out (so a display
    /// showing [`SlopeEvaluation::model_speed`] must say why).
    pub fn speed_ruled_out(&self) -> bool {
        self.prediction.speed.is_some() && self.speed().is_none()
    }

    /// The stance model's speed `v = s / (T/2)`, m/s, whatever the regime.
    pub fn model_speed(&self) -> Option<f64> {
        self.prediction.speed
    }
}

/// The flat form of a [`SlopeEvaluation`] (see its documentation for the keys).
#[derive(Serialize)]
struct SlopeRecord {
    slope_deg: f64,
    k_n: f64,
    k_s: f64,
    regime: Regime,
    cause: Cause,
    d_n_m: Option<f64>,
    level_step_m: f64,
    d_s_m: Option<f64>,
    t1_s: Option<f64>,
    slip_m: Option<f64>,
    propulsion_m: Option<f64>,
    step_m: Option<f64>,
    speed_m_s: Option<f64>,
    model_speed_m_s: Option<f64>,
    k_s_margin: Option<f64>,
    critical_k_s_progress: Option<f64>,
    critical_k_s_robust: Option<f64>,
    extrapolated: bool,
}

impl Serialize for SlopeEvaluation {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let p = &self.prediction;
        SlopeRecord {
            slope_deg: self.slope_deg,
            k_n: p.k_n,
            k_s: p.k_s,
            regime: p.regime,
            cause: p.cause,
            d_n_m: p.normal_depth,
            level_step_m: p.level_step,
            d_s_m: p.shear_depth,
            t1_s: p.anchoring_time,
            slip_m: p.slip,
            propulsion_m: p.propulsion,
            step_m: p.step,
            speed_m_s: self.speed(),
            model_speed_m_s: p.speed,
            k_s_margin: self.k_s_margin,
            critical_k_s_progress: self.critical_progress.ok(),
            critical_k_s_robust: self.critical_robust.ok(),
            extrapolated: self.extrapolated,
        }
        .serialize(serializer)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::tests::paper_robot;
    use crate::terrain::{TerrainPoint, TerrainSpec};

    fn deg(d: f64) -> SignedSlope {
        SignedSlope::from_degrees(d).unwrap()
    }

    fn dune(repose_deg: Option<f64>) -> Terrain {
        let pt = |slope_deg, k_s| TerrainPoint { slope_deg, k_n: 7e5, k_s, k_n_sd: None, k_s_sd: None };
        Terrain::new(TerrainSpec { name: None, repose_deg, points: vec![pt(0.0, 2e6), pt(20.0, 1e6)] })
            .unwrap()
    }

    #[test]
    fn overrides_replace_the_terrain_and_hand_worked_values_hold() {
        // 20 deg, k_n = 7e5, k_s = 1e6 (the table's own value at 20 deg): worked by hand in the
        // model's tests, s = 21.7682 mm, v = 4.35363 cm/s, metastable.
        let s = Scenario::new(paper_robot(), dune(None), None, None).unwrap();
        let e = s.evaluate(deg(20.0));
        assert!((e.speed().unwrap() - 0.043_536_3).abs() < 1e-7);
        assert_eq!((e.regime(), e.cause()), (Regime::Metastable, Cause::ShortStep));
        // The margin is k_s over the critical k_s for progress: above 1, since s > 0.
        let k0 = *e.critical_progress.as_ref().unwrap();
        assert!((e.k_s_margin.unwrap() - 1e6 / k0).abs() < 1e-12 && e.k_s_margin.unwrap() > 1.0);
        // Overriding k_s with the critical value itself puts the margin at exactly 1.
        let at_critical = Scenario::new(paper_robot(), dune(None), None, Some(k0)).unwrap();
        assert!((at_critical.evaluate(deg(20.0)).k_s_margin.unwrap() - 1.0).abs() < 1e-12);
        assert_eq!(Scenario::new(paper_robot(), dune(None), Some(-1.0), None).unwrap_err().key, "k_n");
        // Descending is evaluated as climbing.
        let down = s.evaluate(deg(-20.0));
        assert_eq!((down.slope_deg, down.prediction.speed), (-20.0, e.prediction.speed));
        assert_eq!(SignedSlope::from_degrees(95.0).unwrap_err().key, "slope_deg");
    }

    #[test]
    fn at_or_above_repose_the_speed_is_ruled_out_but_a_backward_step_is_not() {
        // Same ground with a repose of 18 deg: at 20 deg the stance model still gives its
        // positive speed, but the surface yields, so the robot makes none.
        let s = Scenario::new(paper_robot(), dune(Some(18.0)), None, None).unwrap();
        let e = s.evaluate(deg(20.0));
        assert_eq!((e.regime(), e.cause()), (Regime::Slippage, Cause::AtOrAboveRepose));
        assert!((e.model_speed().unwrap() - 0.043_536_3).abs() < 1e-7);
        assert_eq!(e.speed(), None);
        assert!(e.speed_ruled_out());
        assert_eq!(e.k_s_margin, None);
        // A weak k_s without repose: the leg anchors late and the net step is negative; that
        // negative speed is the model's answer (the robot loses ground) and is kept.
        let weak = Scenario::new(paper_robot(), dune(None), None, Some(8e4)).unwrap().evaluate(deg(20.0));
        assert_eq!(weak.cause(), Cause::NetBackwardStep);
        assert!(weak.speed().unwrap() < 0.0 && !weak.speed_ruled_out());
    }

    #[test]
    fn causes_along_a_sweep_and_extrapolation_unless_both_values_are_fixed() {
        let s = Scenario::new(paper_robot(), dune(Some(18.0)), None, None).unwrap();
        let rows = s.sweep(&[deg(10.0), deg(20.0), deg(25.0)]);
        let text = format!("{:?}", rows.iter().map(|r| r.cause()).collect::<Vec<_>>());
        assert_eq!(text, "[RobustStep, AtOrAboveRepose, AtOrAboveRepose]");
        // Extrapolated beyond the last point (20 deg) unless both values are overridden.
        assert!(rows[2].extrapolated && !rows[1].extrapolated);
        let fixed = Scenario::new(paper_robot(), dune(None), Some(7e5), Some(1e6)).unwrap();
        assert!(!fixed.evaluate(deg(25.0)).extrapolated);
    }

    #[test]
    fn slope_ranges_include_the_end_and_refuse_bad_steps() {
        assert_eq!(slope_range(0.0, 1.0, 0.1, 1000).unwrap().len(), 11);
        assert_eq!(slope_range(-5.0, 5.0, 5.0, 1000).unwrap(), vec![-5.0, 0.0, 5.0]);
        assert_eq!(slope_range(10.0, 0.0, 1.0, 1000).unwrap_err().key, "from");
        assert_eq!(slope_range(0.0, 10.0, 0.0, 1000).unwrap_err().key, "step");
        assert_eq!(slope_range(0.0, 10.0, 1e-9, 1000).unwrap_err().key, "step");
    }
}
