//! Calibration: the shear strength k_s(theta) that makes the model's speeds match observed ones
//! (this module), and the joint calibration against speeds, anchoring times and force tests with
//! freed robot quantities ([`joint`]).
//!
//! Three laws (the normal resistance k_n is given, because the speed hardly depends on it):
//! - [`ShearLaw::Linear`]: `k_s(theta) = k_s0 + b theta_deg`, linear in degrees, the same form
//!   as the terrain table's interpolation, so the fitted table reproduces the law exactly;
//! - [`ShearLaw::Coulomb`]: `k_s(theta) = k_s0 (cos theta - sin theta / tan phi)`, the
//!   Mohr-Coulomb strength left on an infinite slope with friction angle phi (zero at phi);
//! - [`ShearLaw::PerSlope`]: one k_s per observed slope, by inverting the speed with a root
//!   finder (no smoothing).
//!
//! The smooth laws minimise `sum ((v_model - v_obs) / sd)^2` by Levenberg-Marquardt, started
//! from the per-slope inversion (or, where it fails, from a level-sand guess). Where a law
//! would make the leg fail to anchor, the speed is continued at the anchoring limit
//! (`d_s = d_max`) so the objective stays continuous.

pub mod joint;

use std::fmt;

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{storage::Owned, DVector, Dyn, OMatrix, Vector2, U2};

use crate::measure::line_fit;
use crate::model::{
    anchoring_threshold_k_s, anchoring_time, level_step_length, net_step, normal_equilibrium_depth,
    shear_equilibrium_depth, step_speed,
};
use crate::robot::Robot;
use crate::slope::Slope;

/// One observed step-averaged speed with its standard deviation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedObservation {
    /// Slope of the trials.
    pub slope: Slope,
    /// Mean step-averaged upslope speed, m/s.
    pub speed: f64,
    /// Standard deviation of the speed across steps or trials, m/s (> 0).
    pub speed_sd: f64,
}

/// The functional form of k_s(theta) to fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShearLaw {
    /// `k_s0 + b theta_deg`.
    Linear,
    /// `k_s0 (cos theta - sin theta / tan phi)`.
    Coulomb,
    /// One value per observed slope.
    PerSlope,
}

/// Fitted parameters of a law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LawParams {
    /// `k_s(theta) = k_s0 + per_degree * theta_deg`.
    Linear {
        /// Level-sand shear strength, N/m^3.
        k_s0: f64,
        /// Change per degree of slope, N/m^3/deg.
        per_degree: f64,
    },
    /// `k_s(theta) = k_s0 (cos theta - sin theta / tan phi)`.
    Coulomb {
        /// Level-sand shear strength, N/m^3.
        k_s0: f64,
        /// Friction angle phi, degrees.
        friction_angle_deg: f64,
    },
    /// No parameters: a table.
    PerSlope,
}

impl LawParams {
    /// k_s at `slope` under this law (floored at 0); `None` for a per-slope table.
    pub fn k_s(&self, slope: Slope) -> Option<f64> {
        match *self {
            LawParams::Linear { k_s0, per_degree } => Some((k_s0 + per_degree * slope.degrees()).max(0.0)),
            LawParams::Coulomb { k_s0, friction_angle_deg } => {
                let phi = friction_angle_deg.to_radians();
                Some((k_s0 * (slope.cos() - slope.sin() / phi.tan())).max(0.0))
            }
            LawParams::PerSlope => None,
        }
    }
}

/// The model against one observation after calibration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedResidual {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Normal resistance used, N/m^3.
    pub k_n: f64,
    /// Calibrated shear strength, N/m^3.
    pub k_s: f64,
    /// Observed speed, m/s.
    pub observed: f64,
    /// Observed SD, m/s.
    pub observed_sd: f64,
    /// Model speed at the calibrated k_s, m/s.
    pub model: f64,
}

impl SpeedResidual {
    /// `observed - model`, m/s.
    pub fn residual(&self) -> f64 {
        self.observed - self.model
    }
}

/// The result of a calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct Calibration {
    /// The law fitted.
    pub law: ShearLaw,
    /// Its parameters.
    pub params: LawParams,
    /// Standard errors of the two parameters of a smooth law, from the Jacobian at the optimum
    /// (`(J^T J)^-1` with residuals weighted by the observed SDs); `None` for per-slope.
    pub param_se: Option<[f64; 2]>,
    /// One entry per observation, in slope order.
    pub residuals: Vec<SpeedResidual>,
}

impl Calibration {
    /// Root-mean-square of `observed - model`, m/s.
    pub fn rmse(&self) -> f64 {
        let n = self.residuals.len() as f64;
        (self.residuals.iter().map(|r| r.residual().powi(2)).sum::<f64>() / n).sqrt()
    }

    /// `sum ((observed - model) / sd)^2`.
    pub fn chi_squared(&self) -> f64 {
        self.residuals.iter().map(|r| (r.residual() / r.observed_sd).powi(2)).sum()
    }
}

/// Why a calibration could not be done.
#[derive(Debug, Clone, PartialEq)]
pub enum CalibrationError {
    /// Not enough observations for the law's parameters.
    TooFewObservations {
        /// Observations needed.
        needed: usize,
        /// Observations given.
        given: usize,
    },
    /// An observation has a non-positive or non-finite SD or speed.
    BadObservation {
        /// Slope of the observation, degrees.
        slope_deg: f64,
        /// What is wrong.
        reason: String,
    },
    /// Two observations at one slope.
    DuplicateSlope {
        /// The slope, degrees.
        slope_deg: f64,
    },
    /// Per-slope inversion: no k_s gives the observed speed.
    Unreachable {
        /// Slope, degrees.
        slope_deg: f64,
        /// Observed speed, m/s.
        observed: f64,
        /// The model's speed range `[lowest, highest)` over all k_s that anchor, m/s.
        range: (f64, f64),
    },
    /// The legs sink at this slope and k_n: k_s has no effect on the speed.
    Sinkage {
        /// Slope, degrees.
        slope_deg: f64,
    },
}

impl fmt::Display for CalibrationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CalibrationError::TooFewObservations { needed, given } => {
                write!(f, "this law needs at least {needed} observed slopes, got {given}")
            }
            CalibrationError::BadObservation { slope_deg, reason } => write!(f, "observation at {slope_deg} deg: {reason}"),
            CalibrationError::DuplicateSlope { slope_deg } => {
                write!(f, "two observations at {slope_deg} deg: pool them into one mean and SD first")
            }
            CalibrationError::Unreachable { slope_deg, observed, range } => write!(
                f,
                "at {slope_deg} deg the observed speed {observed:.4} m/s is outside what the model can reach for any k_s \
                 ({:.4} m/s when the leg anchors at the last moment, up to {:.4} m/s with instant anchoring); \
                 check the robot's hip height, level step or k_n",
                range.0, range.1
            ),
            CalibrationError::Sinkage { slope_deg } => {
                write!(f, "at {slope_deg} deg the legs sink (d_n >= 2R - h) with this k_n: the speed does not depend on k_s")
            }
        }
    }
}

impl std::error::Error for CalibrationError {}

/// Level step at this slope and k_n, or the sinkage error.
fn level_step_at(robot: &Robot, slope: Slope, k_n: f64) -> Result<f64, CalibrationError> {
    let d_n = normal_equilibrium_depth(robot, slope, k_n);
    if d_n >= robot.max_depth() {
        return Err(CalibrationError::Sinkage { slope_deg: slope.degrees() });
    }
    Ok(level_step_length(robot, d_n))
}

/// Model speed at k_s, continued at the anchoring limit when the leg would not anchor.
pub(crate) fn continued_speed(robot: &Robot, slope: Slope, s_star: f64, k_s: f64) -> f64 {
    let d_s = if k_s > 0.0 { shear_equilibrium_depth(robot, slope, k_s) } else { f64::INFINITY };
    let t1 = anchoring_time(robot, d_s.min(robot.max_depth())).expect("clamped depth anchors");
    step_speed(robot, net_step(robot, slope, s_star, t1))
}

/// The k_s (N/m^3) at which the model's speed equals `speed`, by Brent's method on `ln k_s`.
///
/// Fails with [`CalibrationError::Unreachable`] when the speed is at or above the instant
/// anchoring limit `s* / (T/2)` or below the speed at the anchoring threshold.
pub fn shear_strength_for_speed(
    robot: &Robot,
    slope: Slope,
    k_n: f64,
    speed: f64,
) -> Result<f64, CalibrationError> {
    let s_star = level_step_at(robot, slope, k_n)?;
    let k_anchor = anchoring_threshold_k_s(robot, slope);
    let v_low = continued_speed(robot, slope, s_star, k_anchor);
    let v_high = step_speed(robot, s_star);
    let unreachable =
        CalibrationError::Unreachable { slope_deg: slope.degrees(), observed: speed, range: (v_low, v_high) };
    if !(speed >= v_low && speed < v_high) {
        return Err(unreachable);
    }
    let f = |ln_k: f64| continued_speed(robot, slope, s_star, ln_k.exp()) - speed;
    let lo = k_anchor.ln();
    let mut hi = lo + 1.0;
    while f(hi) < 0.0 {
        hi += 2.0;
        if hi > lo + 200.0 {
            return Err(unreachable);
        }
    }
    let mut conv = roots::SimpleConvergency { eps: 1e-13, max_iter: 200 };
    roots::find_root_brent(lo, hi, f, &mut conv).map(f64::exp).map_err(|_| unreachable)
}

/// Fits `law` so that the model's speeds match `observations`.
///
/// `k_n_at` gives the normal resistance at each slope (the speed depends on it through the
/// level step). The angle of repose is not applied: an observed speed shows the robot moved.
pub fn calibrate(
    robot: &Robot,
    k_n_at: &dyn Fn(Slope) -> f64,
    observations: &[SpeedObservation],
    law: ShearLaw,
) -> Result<Calibration, CalibrationError> {
    let mut obs = observations.to_vec();
    obs.sort_by(|a, b| a.slope.radians().total_cmp(&b.slope.radians()));
    for o in &obs {
        let slope_deg = o.slope.degrees();
        if !(o.speed.is_finite()) {
            return Err(CalibrationError::BadObservation {
                slope_deg,
                reason: format!("speed_m_s = {} must be a finite number", o.speed),
            });
        }
        if !(o.speed_sd.is_finite() && o.speed_sd > 0.0) {
            return Err(CalibrationError::BadObservation {
                slope_deg,
                reason: format!("speed_sd_m_s = {} must be greater than 0", o.speed_sd),
            });
        }
    }
    for w in obs.windows(2) {
        if w[0].slope == w[1].slope {
            return Err(CalibrationError::DuplicateSlope { slope_deg: w[0].slope.degrees() });
        }
    }
    let needed = if law == ShearLaw::PerSlope { 1 } else { 2 };
    if obs.len() < needed {
        return Err(CalibrationError::TooFewObservations { needed, given: obs.len() });
    }
    let stars =
        obs.iter().map(|o| level_step_at(robot, o.slope, k_n_at(o.slope))).collect::<Result<Vec<_>, _>>()?;

    if law == ShearLaw::PerSlope {
        let residuals = obs
            .iter()
            .map(|o| {
                let k_n = k_n_at(o.slope);
                let k_s = shear_strength_for_speed(robot, o.slope, k_n, o.speed)?;
                Ok(residual(robot, o, k_n, k_s))
            })
            .collect::<Result<Vec<_>, _>>()?;
        return Ok(Calibration { law, params: LawParams::PerSlope, param_se: None, residuals });
    }

    // Start from the per-slope inversion where it exists.
    let inverted: Vec<(f64, f64)> = obs
        .iter()
        .filter_map(|o| {
            shear_strength_for_speed(robot, o.slope, k_n_at(o.slope), o.speed)
                .ok()
                .map(|k| (o.slope.degrees(), k))
        })
        .collect();
    let level_guess = inverted.first().map_or(1e6, |&(_, k)| k);
    let scale = level_guess.max(1.0);
    let theta_max = obs.last().map_or(1.0, |o| o.slope.degrees()).max(1.0);
    let start = match law {
        ShearLaw::Linear => {
            let (x, y): (Vec<f64>, Vec<f64>) = inverted.iter().copied().unzip();
            let (k0, b) = line_fit(&x, &y).map_or((level_guess, 0.0), |f| (f.intercept, f.slope));
            Vector2::new(k0 / scale, b * theta_max / scale)
        }
        _ => Vector2::new(level_guess / scale, (theta_max + 10.0).min(89.0) / 90.0),
    };
    let problem = SpeedFit { robot, obs: &obs, stars: &stars, law, scale, theta_max, params: start };
    let (fitted, _report) = LevenbergMarquardt::new().with_patience(200).minimize(problem);
    let params = fitted.law_params(&fitted.params);
    let param_se = fitted.standard_errors();
    let residuals =
        obs.iter().map(|o| residual(robot, o, k_n_at(o.slope), params.k_s(o.slope).unwrap_or(0.0))).collect();
    Ok(Calibration { law, params, param_se, residuals })
}

fn residual(robot: &Robot, o: &SpeedObservation, k_n: f64, k_s: f64) -> SpeedResidual {
    let s_star = level_step_at(robot, o.slope, k_n).unwrap_or(0.0);
    SpeedResidual {
        slope_deg: o.slope.degrees(),
        k_n,
        k_s,
        observed: o.speed,
        observed_sd: o.speed_sd,
        model: continued_speed(robot, o.slope, s_star, k_s),
    }
}

/// The weighted least-squares problem in scaled parameters:
/// linear `p = (k_s0 / scale, b theta_max / scale)`, Coulomb `p = (k_s0 / scale, phi / 90 deg)`.
struct SpeedFit<'a> {
    robot: &'a Robot,
    obs: &'a [SpeedObservation],
    stars: &'a [f64],
    law: ShearLaw,
    scale: f64,
    theta_max: f64,
    params: Vector2<f64>,
}

impl SpeedFit<'_> {
    fn law_params(&self, p: &Vector2<f64>) -> LawParams {
        match self.law {
            ShearLaw::Linear => {
                LawParams::Linear { k_s0: p[0] * self.scale, per_degree: p[1] * self.scale / self.theta_max }
            }
            _ => LawParams::Coulomb {
                k_s0: p[0] * self.scale,
                friction_angle_deg: (p[1] * 90.0).clamp(self.theta_max + 1e-6, 89.999),
            },
        }
    }

    fn residuals_at(&self, p: &Vector2<f64>) -> DVector<f64> {
        let law = self.law_params(p);
        DVector::from_iterator(
            self.obs.len(),
            self.obs.iter().zip(self.stars).map(|(o, &s_star)| {
                let k_s = law.k_s(o.slope).unwrap_or(0.0);
                (continued_speed(self.robot, o.slope, s_star, k_s) - o.speed) / o.speed_sd
            }),
        )
    }

    fn jacobian_at(&self, p: &Vector2<f64>) -> OMatrix<f64, Dyn, U2> {
        let mut j = OMatrix::<f64, Dyn, U2>::zeros(self.obs.len());
        for c in 0..2 {
            let h = 1e-6 * p[c].abs().max(1e-3);
            let (mut up, mut down) = (*p, *p);
            up[c] += h;
            down[c] -= h;
            let col = (self.residuals_at(&up) - self.residuals_at(&down)) / (2.0 * h);
            j.set_column(c, &col);
        }
        j
    }

    /// Standard errors of the unscaled parameters, `sqrt(diag((J^T J)^-1))`.
    fn standard_errors(&self) -> Option<[f64; 2]> {
        let j = self.jacobian_at(&self.params);
        let cov = (j.transpose() * &j).try_inverse()?;
        let (s0, s1) = (cov[(0, 0)].sqrt(), cov[(1, 1)].sqrt());
        let se = match self.law {
            ShearLaw::Linear => [s0 * self.scale, s1 * self.scale / self.theta_max],
            _ => [s0 * self.scale, s1 * 90.0],
        };
        se.iter().all(|x| x.is_finite()).then_some(se)
    }
}

impl LeastSquaresProblem<f64, Dyn, U2> for SpeedFit<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, U2>;
    type ParameterStorage = Owned<f64, U2>;

    fn set_params(&mut self, p: &Vector2<f64>) {
        self.params = *p;
    }
    fn params(&self) -> Vector2<f64> {
        self.params
    }
    fn residuals(&self) -> Option<DVector<f64>> {
        Some(self.residuals_at(&self.params))
    }
    fn jacobian(&self) -> Option<OMatrix<f64, Dyn, U2>> {
        Some(self.jacobian_at(&self.params))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{predict, tests::paper_robot};
    use crate::terrain::Ground;

    fn slope(d: f64) -> Slope {
        Slope::from_degrees(d).unwrap()
    }

    #[test]
    fn inversion_recovers_the_strength_that_made_the_speed() {
        let r = paper_robot();
        for (deg, k_s) in [(0.0, 2e6), (10.0, 1.5e6), (20.0, 8e5)] {
            let v = predict(&r, slope(deg), &Ground::new(7e5, k_s).unwrap()).speed.unwrap();
            let back = shear_strength_for_speed(&r, slope(deg), 7e5, v).unwrap();
            assert!((back / k_s - 1.0).abs() < 1e-8, "{deg}: {back} vs {k_s}");
        }
    }

    #[test]
    fn inversion_refuses_speeds_beyond_instant_anchoring() {
        // Level-sand maximum is s*/(T/2) = 0.0791212/0.5 = 0.158242 m/s at k_n = 7e5.
        let r = paper_robot();
        let e = shear_strength_for_speed(&r, Slope::LEVEL, 7e5, 0.16).unwrap_err();
        match e {
            CalibrationError::Unreachable { range, .. } => assert!((range.1 - 0.158_242).abs() < 1e-5),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn smooth_laws_recover_synthetic_parameters() {
        let r = paper_robot();
        let truth = [
            (ShearLaw::Linear, LawParams::Linear { k_s0: 2.0e6, per_degree: -5.0e4 }),
            (ShearLaw::Coulomb, LawParams::Coulomb { k_s0: 2.0e6, friction_angle_deg: 35.0 }),
        ];
        for (law, params) in truth {
            let obs: Vec<_> = [0.0, 5.0, 10.0, 15.0, 20.0, 24.0]
                .iter()
                .map(|&d| {
                    let k_s = params.k_s(slope(d)).unwrap();
                    let v = predict(&r, slope(d), &Ground::new(7e5, k_s).unwrap()).speed.unwrap();
                    SpeedObservation { slope: slope(d), speed: v, speed_sd: 0.005 }
                })
                .collect();
            let cal = calibrate(&r, &|_| 7e5, &obs, law).unwrap();
            assert!(cal.rmse() < 1e-7, "{law:?}: rmse {}", cal.rmse());
            for d in [0.0, 12.0, 24.0] {
                let (got, want) = (cal.params.k_s(slope(d)).unwrap(), params.k_s(slope(d)).unwrap());
                assert!((got / want - 1.0).abs() < 1e-4, "{law:?} at {d}: {got} vs {want}");
            }
        }
    }

    #[test]
    fn rejects_degenerate_input() {
        let r = paper_robot();
        let one = [SpeedObservation { slope: slope(0.0), speed: 0.15, speed_sd: 0.01 }];
        assert!(matches!(
            calibrate(&r, &|_| 7e5, &one, ShearLaw::Linear),
            Err(CalibrationError::TooFewObservations { .. })
        ));
        let bad_sd = [SpeedObservation { slope: slope(0.0), speed: 0.15, speed_sd: 0.0 }];
        assert!(matches!(
            calibrate(&r, &|_| 7e5, &bad_sd, ShearLaw::PerSlope),
            Err(CalibrationError::BadObservation { .. })
        ));
        let dup = [one[0], one[0]];
        assert!(matches!(
            calibrate(&r, &|_| 7e5, &dup, ShearLaw::Linear),
            Err(CalibrationError::DuplicateSlope { .. })
        ));
    }
}
