//! The servo as an actuator (issue 59 item 1, docs/model.md §20.6): each leg's rate is what
//! its motor can give against the sand's torque, solved with the body's rates in one step.
//!
//! The model **(choices)**: a position-mode servo whose position loop asks for the commanded
//! rate plus a correction of its lag, `r_d = omega_cmd + K (psi_cmd - psi)` (K = 20/s, the
//! catch-up rate of §15's torque-limited servo), at least 0 and at most the no-load speed; a DC
//! motor whose torque at rate r is at most `tau_stall (1 - r / omega_0)` (the torque-speed line
//! through the stall torque and the no-load speed) and at most `K_t I_limit`; a massless leg,
//! so the motor's torque is the sand's. The leg turns at the largest rate up to `r_d` its
//! motor can hold against the sand's torque at that rate: `r = min(r_d, omega_0 (1 -
//! tau_sand(r) / tau_max))`, with `tau_max = min(tau_stall, K_t I_limit)`, clamped at 0 (a
//! stall; the leg is not back-driven). Since the sand's torque depends on the leg's rate
//! through the direction of its elements' motion, the rates and the body's velocity are one
//! implicit system: it is solved by damped fixed-point iteration on the rates, each iterate a
//! full body solve (§17), to a rate change below [`RATE_TOL`].

use super::Walker;

/// The paper's servo, the XL330-M288-T at 5 V (docs/model.md §19): its figures, with their
/// source, are `crate::servo::ServoModel::XL330_M288`'s.
const PAPER_SERVO: &crate::servo::ServoModel = &crate::servo::ServoModel::XL330_M288;
/// The position loop's lag correction, 1/s.
pub(crate) const LAG_GAIN_PER_S: f64 = 20.0;
/// The rates' fixed point has converged when no rate changes by more than this, rad/s.
pub(crate) const RATE_TOL: f64 = 1e-6;
/// Most fixed-point iterations in one step.
pub(crate) const MAX_ITERATIONS: usize = 60;

/// A servo's motor: the largest torque and the no-load speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Motor {
    pub tau_max: f64,
    pub omega_0: f64,
}

impl Motor {
    /// The XL330-M288 at 5 V (the paper's servo).
    pub(crate) fn xl330() -> Motor {
        Motor::of(PAPER_SERVO)
    }

    /// A servo model's motor at its nominal supply: the stall torque, capped by `K_t` times
    /// the largest Current Limit where the model has one (for the XL330-M288, 1.75 A times
    /// 0.354 N m/A = 0.62 N m, above the stall torque, so the torque-speed line binds first).
    pub(crate) fn of(model: &crate::servo::ServoModel) -> Motor {
        let by_current =
            model.max_current_limit_ma().map_or(f64::INFINITY, |ma| model.torque_from_current_ma(ma));
        Motor { tau_max: model.stall_torque_n_m.min(by_current), omega_0: model.no_load_speed_rad_s() }
    }

    /// The rate the motor holds against `torque` (N m, positive resisting), asked for `demand`.
    pub(crate) fn rate(&self, demand: f64, torque: f64) -> f64 {
        let curve = self.omega_0 * (1.0 - torque.max(0.0) / self.tau_max);
        demand.min(curve).max(0.0)
    }
}

impl Walker {
    /// The demanded rate of leg `j` this step (the position loop), rad/s.
    pub(crate) fn demanded_rate(&self, j: usize, motor: &Motor) -> f64 {
        let nominal = self.nominal_rate(j, self.time);
        let cmd = self.command(j, self.time);
        (nominal + LAG_GAIN_PER_S * (cmd - self.psi[j])).clamp(0.0, motor.omega_0)
    }

    /// Solves the step with every leg's rate the motor's (module docs): from the rates the
    /// caller solved with, iterate `r <- min(r_d, curve(tau_sand(r)))`, damped, re-solving the
    /// body each time. Returns whether the last body solve converged and the rates settled
    /// (a step that did not is counted with the unconverged ones).
    pub(crate) fn actuate(
        &mut self,
        motor: Motor,
        demand: &[f64],
        v_free: [f64; 3],
        m: [f64; 3],
        v0: [f64; 3],
    ) -> bool {
        let mut converged = true;
        let mut settled = false;
        for it in 0..MAX_ITERATIONS {
            self.leg_outputs();
            let mut change: f64 = 0.0;
            // Damped after a few iterations: the map is decreasing in r (more rate, more torque,
            // less rate allowed), so undamped it can swing.
            let relax = if it < 4 { 1.0 } else { 0.5 };
            for ((rate, out), &asked) in self.rates.iter_mut().zip(&self.legs_out).zip(demand) {
                let target = motor.rate(asked, out.torque);
                let next = *rate + relax * (target - *rate);
                change = change.max((next - *rate).abs());
                *rate = next;
            }
            if change < RATE_TOL {
                settled = true;
                break;
            }
            self.v = v0;
            converged = self.solve(v_free, m);
        }
        for ((stalled, &rate), &asked) in self.stalled.iter_mut().zip(&self.rates).zip(demand) {
            *stalled = rate <= 0.0 && asked > 0.0;
        }
        converged && settled
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The XL330-M288's line by hand: 0.52 N m stall, 103 rev/min = 10.786 rad/s no load; at the
    /// gait's 2 pi rad/s it holds 0.52 (1 - 6.283 / 10.786) = 0.217 N m (docs/model.md §20.4's
    /// 0.218); against 0.345 N m (the level stance's peak) it turns at most 10.786 (1 - 0.345 /
    /// 0.52) = 3.630 rad/s; against more than the stall torque it stalls.
    #[test]
    fn the_motor_line_by_hand() {
        let m = Motor::xl330();
        assert_eq!(m.tau_max, 0.52);
        let two_pi = std::f64::consts::TAU;
        assert!((m.rate(20.0, 0.217) - two_pi).abs() < 0.01, "{}", m.rate(20.0, 0.217));
        assert!((m.rate(two_pi, 0.345) - 3.630).abs() < 1e-3, "{}", m.rate(two_pi, 0.345));
        assert_eq!(m.rate(two_pi, 0.0), two_pi);
        assert_eq!(m.rate(two_pi, 0.6), 0.0);
        assert!((PAPER_SERVO.torque_from_current_ma(1750.0) - 0.619).abs() < 1e-3);
    }
}
