//! Each observed speed inverted alone: the k_s at which the model gives it, by Brent's root
//! finder on `ln k_s` (`calibrate --law per-slope`, and the calibration's starting values).

use serde::Serialize;

use super::evidence::check_speeds;
use super::{CalibrationError, SpeedObservation};
use crate::model::{
    anchoring_threshold_k_s, continued_speed, level_step_length, normal_equilibrium_depth, step_speed,
};
use crate::robot::Robot;
use crate::slope::Slope;
use crate::terrain::Terrain;

/// Level step at this slope and k_n, or the sinkage error.
fn level_step_at(robot: &Robot, slope: Slope, k_n: f64) -> Result<f64, CalibrationError> {
    let d_n = normal_equilibrium_depth(robot, slope, k_n);
    if d_n >= robot.max_depth() {
        return Err(CalibrationError::Sinkage { slope_deg: slope.degrees() });
    }
    Ok(level_step_length(robot, slope, d_n))
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
        // A NaN or infinite end also stops the search (`hi > lo + 200` never holds for them).
        if (hi - lo).is_nan() || hi - lo > 200.0 {
            return Err(unreachable);
        }
    }
    let mut conv = roots::SimpleConvergency { eps: 1e-13, max_iter: 200 };
    roots::find_root_brent(lo, hi, f, &mut conv).map(f64::exp).map_err(|_| unreachable)
}

/// One observed speed and the k_s that reproduces it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct InvertedSpeed {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Normal resistance used, N/m^3.
    pub k_n: f64,
    /// The shear strength at which the model gives the observed speed, N/m^3.
    pub k_s: f64,
    /// Observed speed, m/s.
    pub observed: f64,
    /// Observed SD, m/s.
    pub observed_sd: f64,
    /// Model speed at that k_s, m/s (the observed one, to the root finder's tolerance).
    pub model: f64,
}

impl InvertedSpeed {
    /// `observed - model`, m/s.
    pub fn residual(&self) -> f64 {
        self.observed - self.model
    }
}

/// Every observed speed inverted alone (no smoothing, no joint fit), in slope order.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PerSlopeCalibration {
    /// One entry per observed speed, by slope.
    pub points: Vec<InvertedSpeed>,
}

impl PerSlopeCalibration {
    /// Root-mean-square of `observed - model`, m/s.
    pub fn rmse(&self) -> f64 {
        let n = self.points.len() as f64;
        (self.points.iter().map(|r| r.residual().powi(2)).sum::<f64>() / n).sqrt()
    }

    /// `sum ((observed - model) / sd)^2`.
    pub fn chi_squared(&self) -> f64 {
        self.points.iter().map(|r| (r.residual() / r.observed_sd).powi(2)).sum()
    }
}

/// Inverts each of `speeds` alone on `normal`'s k_n (the angle of repose is not applied: an
/// observed speed shows the robot moved).
pub fn invert_each_speed(
    robot: &Robot,
    normal: &Terrain,
    speeds: &[SpeedObservation],
) -> Result<PerSlopeCalibration, CalibrationError> {
    check_speeds(speeds)?;
    if speeds.is_empty() {
        return Err(CalibrationError::NoObservations);
    }
    let mut sorted = speeds.to_vec();
    sorted.sort_by(|a, b| a.slope.radians().total_cmp(&b.slope.radians()));
    let points = sorted
        .iter()
        .map(|o| {
            let k_n = normal.at(o.slope).k_n;
            let k_s = shear_strength_for_speed(robot, o.slope, k_n, o.speed)?;
            let s_star = level_step_at(robot, o.slope, k_n)?;
            Ok(InvertedSpeed {
                slope_deg: o.slope.degrees(),
                k_n,
                k_s,
                observed: o.speed,
                observed_sd: o.speed_sd,
                model: continued_speed(robot, o.slope, s_star, k_s),
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(PerSlopeCalibration { points })
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
    fn each_speed_is_inverted_in_slope_order_and_bad_input_is_refused() {
        let r = paper_robot();
        let normal = Terrain::constant(7e5, 1.0).unwrap();
        // Speeds the model makes at k_s 8e5 (20 deg) and 2e6 (level), given out of order.
        let v = |d: f64, k_s: f64| predict(&r, slope(d), &Ground::new(7e5, k_s).unwrap()).speed.unwrap();
        let obs = [
            SpeedObservation { slope: slope(20.0), speed: v(20.0, 8e5), speed_sd: 0.01 },
            SpeedObservation { slope: slope(0.0), speed: v(0.0, 2e6), speed_sd: 0.01 },
        ];
        let cal = invert_each_speed(&r, &normal, &obs).unwrap();
        let k: Vec<f64> = cal.points.iter().map(|p| p.k_s).collect();
        assert!((k[0] / 2e6 - 1.0).abs() < 1e-8 && (k[1] / 8e5 - 1.0).abs() < 1e-8, "{k:?}");
        assert!(cal.rmse() < 1e-10 && cal.chi_squared() < 1e-12);
        let bad_sd = [SpeedObservation { slope: slope(0.0), speed: 0.15, speed_sd: 0.0 }];
        assert!(matches!(
            invert_each_speed(&r, &normal, &bad_sd),
            Err(CalibrationError::BadObservation { .. })
        ));
        let dup = [obs[0], obs[0]];
        assert!(matches!(invert_each_speed(&r, &normal, &dup), Err(CalibrationError::DuplicateSlope { .. })));
        assert_eq!(invert_each_speed(&r, &normal, &[]), Err(CalibrationError::NoObservations));
    }
}
