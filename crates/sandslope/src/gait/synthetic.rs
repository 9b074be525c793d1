//! A known speed profile for one step, repeated every `T/2`: for tests and benchmarks that need
//! a trajectory whose t1, slip, step and speed are known exactly. Test support, not the
//! library's API: compiled for this crate's tests and with the `test-support` feature (which
//! this crate's benches and the CLI's tests enable as a dev-dependency).
//!
//! The phases follow the paper's description of a stride (Results, Fig. 3b): touchdown at
//! rest (`v = 0`), backward slip to a speed minimum `-V_s` at the anchoring time `t1`,
//! propulsion up to the peak `V_p` at lift-off `t3`, then the speed falls back to zero at the
//! next touchdown:
//!
//! - `0 <= tau <= t1`: `v = -V_s sin(pi tau / (2 t1))`
//! - `t1 <= tau <= t3`: `v = -V_s + (V_p + V_s) (1 - cos(pi (tau - t1) / (t3 - t1))) / 2`
//! - `t3 <= tau <= T/2`: `v = V_p cos(pi (tau - t3) / (2 (T/2 - t3)))`
//!
//! The speed is continuous, its minimum is at `t1` with zero slope (so the acceleration
//! turns from negative to positive exactly there), and every integral is closed-form:
//! slip `2 V_s t1 / pi`, step `-2 V_s t1/pi + (V_p - V_s)(t3 - t1)/2 + 2 V_p (T/2 - t3)/pi`.

use std::f64::consts::PI;

use crate::error::ParamError;

/// One step's speed profile (see the module docs); times in s, speeds in m/s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepProfile {
    step_s: f64,
    t1: f64,
    t3: f64,
    slip_speed: f64,
    peak_speed: f64,
}

impl StepProfile {
    /// A profile with step duration `T/2 = step_s`, anchoring time `t1`, lift-off `t3`,
    /// slip speed `V_s` (the speed minimum is `-V_s`) and peak speed `V_p`.
    ///
    /// Requires `0 <= t1 < t3 < step_s`, `V_s >= 0` (and `V_s = 0` when `t1 = 0`), `V_p > 0`.
    pub fn new(step_s: f64, t1: f64, t3: f64, slip_speed: f64, peak_speed: f64) -> Result<Self, ParamError> {
        let check = |ok: bool, key: &str, v: f64, what: &str| {
            if ok {
                Ok(())
            } else {
                Err(ParamError::new(key, v, what))
            }
        };
        check(step_s.is_finite() && step_s > 0.0, "step_s", step_s, "greater than 0")?;
        check(t1 >= 0.0 && t1 < step_s, "t1", t1, "in [0, step_s)")?;
        check(t3 > t1 && t3 < step_s, "t3", t3, "in (t1, step_s)")?;
        check(
            slip_speed >= 0.0 && (t1 > 0.0 || slip_speed == 0.0),
            "slip_speed",
            slip_speed,
            "at least 0, and 0 when t1 = 0",
        )?;
        check(peak_speed.is_finite() && peak_speed > 0.0, "peak_speed", peak_speed, "greater than 0")?;
        Ok(StepProfile { step_s, t1, t3, slip_speed, peak_speed })
    }

    /// Step duration T/2, s.
    pub fn step_duration(&self) -> f64 {
        self.step_s
    }

    /// Anchoring time t1 after touchdown, s.
    pub fn anchoring_time(&self) -> f64 {
        self.t1
    }

    /// Backward slip from touchdown to t1, `2 V_s t1 / pi`, m.
    pub fn slip(&self) -> f64 {
        2.0 * self.slip_speed * self.t1 / PI
    }

    /// Net step over T/2, m.
    pub fn step(&self) -> f64 {
        self.displacement_within(self.step_s)
    }

    /// Step-averaged speed, m/s.
    pub fn mean_speed(&self) -> f64 {
        self.step() / self.step_s
    }

    /// Speed at time `t` since a touchdown (the profile repeats every T/2), m/s.
    pub fn speed(&self, t: f64) -> f64 {
        let tau = t.rem_euclid(self.step_s);
        let (vs, vp) = (self.slip_speed, self.peak_speed);
        if tau < self.t1 {
            -vs * (PI * tau / (2.0 * self.t1)).sin()
        } else if tau < self.t3 {
            let u = (tau - self.t1) / (self.t3 - self.t1);
            -vs + 0.5 * (vp + vs) * (1.0 - (PI * u).cos())
        } else {
            vp * (0.5 * PI * (tau - self.t3) / (self.step_s - self.t3)).cos()
        }
    }

    /// Position at time `t` (`t >= 0`), with position 0 at the touchdown at `t = 0`, m.
    pub fn position(&self, t: f64) -> f64 {
        let k = (t / self.step_s).floor();
        k * self.step() + self.displacement_within(t - k * self.step_s)
    }

    /// Displacement from touchdown to `tau` in `[0, T/2]`.
    fn displacement_within(&self, tau: f64) -> f64 {
        let (vs, vp, t1, t3) = (self.slip_speed, self.peak_speed, self.t1, self.t3);
        let slip_part = |tau: f64| {
            if t1 > 0.0 {
                -vs * (2.0 * t1 / PI) * (1.0 - (PI * tau / (2.0 * t1)).cos())
            } else {
                0.0
            }
        };
        let d = t3 - t1;
        let push_part = |u: f64| -vs * u + 0.5 * (vp + vs) * (u - d / PI * (PI * u / d).sin());
        let l = self.step_s - t3;
        let lift_part = |w: f64| vp * (2.0 * l / PI) * (0.5 * PI * w / l).sin();
        if tau <= t1 {
            slip_part(tau)
        } else if tau <= t3 {
            slip_part(t1) + push_part(tau - t1)
        } else {
            slip_part(t1) + push_part(d) + lift_part(tau.min(self.step_s) - t3)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_forms_match_numerical_integration() {
        let p = StepProfile::new(0.5, 0.08, 0.4, 0.15, 0.3).unwrap();
        let n = 200_000;
        let h = p.step_duration() / n as f64;
        let integral = |a: f64, b: f64| {
            let m = ((b - a) / h).round() as usize;
            (0..m).map(|i| p.speed(a + (i as f64 + 0.5) * h) * h).sum::<f64>()
        };
        assert!((integral(0.0, 0.08) + p.slip()).abs() < 1e-9);
        assert!((integral(0.0, 0.5) - p.step()).abs() < 1e-9);
        assert!((p.position(1.3) - (2.0 * p.step() + integral(0.0, 0.3))).abs() < 1e-8);
        // Continuity at the joins and the minimum at t1.
        assert!((p.speed(0.08 - 1e-9) - p.speed(0.08 + 1e-9)).abs() < 1e-6);
        assert!((p.speed(0.4 - 1e-9) - p.speed(0.4 + 1e-9)).abs() < 1e-6);
        assert!((p.speed(0.5 - 1e-9)).abs() < 1e-6);
        assert!((p.speed(0.08) + 0.15).abs() < 1e-12);
        // By hand: step = -2*0.15*0.08/pi + (0.3-0.15)*0.32/2 + 2*0.3*0.1/pi
        //               = -0.0076394 + 0.024 + 0.0190986 = 0.0354592
        assert!((p.step() - 0.035_459_2).abs() < 1e-7);
        assert!(StepProfile::new(0.5, 0.0, 0.3, 0.1, 0.2).is_err());
        assert!(StepProfile::new(0.5, 0.2, 0.1, 0.1, 0.2).is_err());
    }
}
