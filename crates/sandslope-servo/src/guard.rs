//! The run's guards against a servo that no longer does what it is told (docs/drive.md,
//! "Safety"): a goal it refused, and a shaft that stopped following its goal.
//!
//! A Sync Write has no status packet, so a goal a servo refuses (a Data Range Error: a goal
//! outside its range, or any goal once its Bus Watchdog fired) is refused in silence; the
//! driver reads the goal register back every [`GOAL_CHECK_S`] and stops the run when a servo
//! holds another goal than the one sent. And a shaft more than [`FOLLOWING_LIMIT_RAD`] from
//! its command for longer than [`FOLLOWING_TIME_S`] (a leg stuck, a servo stopped by its own
//! watchdog or fault) ends the run as a fault, not as a completed walk.

use sandslope::servo::model::velocity_units_from_rad_s;

use crate::config::{DynamixelBus, ServoConfig};
use crate::error::DriveError;
use crate::table as t;

/// How often the goal register is read back, s of gait time (and at the first cycle).
pub const GOAL_CHECK_S: f64 = 1.0;

/// The largest following error allowed for long, rad: a quarter turn (the emulated position
/// loop lags its goal by omega / 40 s^-1 = 0.16 rad at the paper's leg speed; a torque-limited
/// stance lags more, but a quarter turn is a stride's phase gone).
pub const FOLLOWING_LIMIT_RAD: f64 = std::f64::consts::FRAC_PI_2;

/// How long a following error beyond [`FOLLOWING_LIMIT_RAD`] is borne, s (the stand-up takes up
/// to half a turn at 1.5 omega, 0.33 s at the paper's leg speed; the servos' own Bus Watchdog
/// is 0.5 s by default).
pub const FOLLOWING_TIME_S: f64 = 0.5;

/// The readback of the goals sent.
#[derive(Debug, Default)]
pub(crate) struct GoalCheck {
    last: Option<f64>,
}

impl GoalCheck {
    /// Whether a readback is due at gait time `time`.
    pub fn due(&mut self, time: f64) -> bool {
        let due = self.last.is_none_or(|l| time - l >= GOAL_CHECK_S);
        if due {
            self.last = Some(time);
        }
        due
    }

    /// Reads `address` (Goal Position or Goal Velocity, 4 bytes) back from every servo and
    /// compares it with what was sent; a servo that did not answer is left to the state read's
    /// count of failures.
    pub fn check(
        bus: &mut DynamixelBus,
        servos: &[ServoConfig],
        address: u16,
        sent: &[i32],
        time: f64,
    ) -> Result<(), DriveError> {
        let ids: Vec<u8> = servos.iter().map(|s| s.id).collect();
        let mut held: Vec<Option<i32>> = vec![None; ids.len()];
        let mut k = 0usize;
        bus.sync_read_cb(&ids, address, 4, |r| {
            if let (Ok(resp), Some(slot)) = (r, held.get_mut(k)) {
                if resp.motor_id == ids[k] && resp.data.len() == 4 {
                    *slot =
                        Some(i32::from_le_bytes([resp.data[0], resp.data[1], resp.data[2], resp.data[3]]));
                }
            }
            k += 1;
        })
        .map_err(|e| DriveError::Bus { time_s: time, reason: e.to_string() })?;
        for (j, h) in held.iter().enumerate() {
            let Some(holds) = *h else { continue };
            if holds != sent[j] {
                let id = ids[j];
                let fired = matches!(bus.read_u8(id, t::BUS_WATCHDOG), Ok(r) if r.data == t::WATCHDOG_FIRED);
                return Err(DriveError::Rejected {
                    id,
                    leg: j,
                    time_s: time,
                    register: if address == t::GOAL_POSITION {
                        "Goal Position (116)"
                    } else {
                        "Goal Velocity (104)"
                    },
                    sent: sent[j],
                    holds,
                    cause: if fired {
                        "its Bus Watchdog fired (the bus was silent for longer than --bus-watchdog), and it refuses every goal until the watchdog is cleared"
                    } else {
                        "it answered the goal with a Data Range Error (a goal outside its range), which a Sync Write does not report"
                    },
                });
            }
        }
        Ok(())
    }
}

/// Each servo's time since its following error passed the limit.
#[derive(Debug)]
pub(crate) struct Following {
    since: Vec<Option<f64>>,
}

impl Following {
    /// For `n` servos.
    pub fn new(n: usize) -> Following {
        Following { since: vec![None; n] }
    }

    /// Servo `j`'s shaft is `error_rad` from its command at gait time `time`: an error beyond
    /// [`FOLLOWING_LIMIT_RAD`] for longer than [`FOLLOWING_TIME_S`] is a fault.
    pub fn check(&mut self, j: usize, id: u8, time: f64, error_rad: f64) -> Result<(), DriveError> {
        if error_rad.abs() <= FOLLOWING_LIMIT_RAD {
            self.since[j] = None;
            return Ok(());
        }
        let since = *self.since[j].get_or_insert(time);
        if time - since > FOLLOWING_TIME_S {
            return Err(DriveError::Following { id, leg: j, time_s: time, error_rad, since_s: since });
        }
        Ok(())
    }
}

/// A Goal Velocity in velocity units, within plus or minus the Velocity Limit written (a goal
/// above it is refused with a Data Range Error).
pub fn velocity_goal(speed_rad_s: f64, limit_units: u32) -> i32 {
    let l = i64::from(limit_units);
    velocity_units_from_rad_s(speed_rad_s).clamp(-l, l) as i32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quarter turn and more for more than half a second is a fault; less, or shorter, is not.
    #[test]
    fn a_following_error_must_last_to_be_a_fault() {
        let mut f = Following::new(2);
        assert!(f.check(0, 1, 1.0, 1.6).is_ok(), "1.6 rad passes pi/2 = 1.571: the clock starts");
        assert!(f.check(0, 1, 1.5, -2.0).is_ok(), "0.5 s is not more than 0.5 s");
        assert!(f.check(1, 2, 1.5, 1.5).is_ok(), "1.5 rad is within a quarter turn");
        match f.check(0, 1, 1.52, 3.0) {
            Err(DriveError::Following { id: 1, leg: 0, since_s, .. }) => assert_eq!(since_s, 1.0),
            other => panic!("{other:?}"),
        }
        // Back within the limit: the clock restarts.
        assert!(f.check(1, 2, 1.6, 0.1).is_ok());
        assert!(f.check(1, 2, 1.7, 2.0).is_ok());
        assert!(f.check(1, 2, 2.1, 2.0).is_ok());
    }

    /// Goal Velocity within the Velocity Limit: 2 omega = 524 units at the paper's 2 pi rad/s
    /// (60 rev/min / 0.229 = 262.0 units a leg speed).
    #[test]
    fn velocity_goals_stay_within_the_limit() {
        assert_eq!(velocity_goal(2.0 * std::f64::consts::PI, 524), 262);
        assert_eq!(velocity_goal(100.0, 524), 524);
        assert_eq!(velocity_goal(-100.0, 524), -524);
    }
}
