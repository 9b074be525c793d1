//! The commanded alternating-tripod gait (docs/model.md §19): each leg's angle and angular
//! velocity over time, from the robot file's timing.

use std::f64::consts::PI;

use serde::Serialize;

use crate::robot::Robot;

/// Why a schedule cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ScheduleError {
    /// The number of legs is not `2 n` (two tripods of the robot file's `stance_legs`).
    #[error("{legs} servos were given for a robot with stance_legs = {n}: the alternating tripod needs 2 * stance_legs = {} legs", 2 * n)]
    LegCount {
        /// Legs (servos) given.
        legs: usize,
        /// The robot's legs per tripod.
        n: u32,
    },
}

/// One leg's command at one instant: the angle and angular velocity in the gait's frame
/// (docs/model.md §15: 0 is the C's circle centre straight ahead of the axle; positive turns
/// the leg forward, driving the robot upslope).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LegCommand {
    /// Commanded leg angle, rad (unwrapped: it grows by 2 pi each stride).
    pub angle_rad: f64,
    /// Commanded angular velocity, rad/s.
    pub velocity_rad_s: f64,
}

/// The alternating tripod as the robot file times it (docs/model.md §19).
///
/// Legs are numbered in the order of the robot file's servos; leg `j` belongs to tripod
/// `j mod 2`. For a hexapod listed left-front, left-middle, left-rear, right-front,
/// right-middle, right-rear this puts left-front, left-rear and right-middle in tripod 0, the
/// paper's grouping ("front and rear leg from one side, plus the middle leg from the other").
///
/// Leg `j` of tripod `k` is commanded to `psi_j(t) = phi0 + k pi + omega (t - dt/2)` once the
/// gait has run up to speed, with `phi0` the touchdown angle of §4 and `omega` the leg speed.
/// The run-up lasts the response time `dt` of §4 with constant acceleration `omega / dt`
/// (`psi_j = phi0 + k pi + omega t^2 / (2 dt)` for `t < dt`), so tripod 0 touches down at
/// `dt/2 + m T` and tripod 1 at `dt/2 + T/2 + m T`: the paper's touchdown offsets 0 and `T/2`
/// after the run-up.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GaitSchedule {
    /// Leg speed omega, rad/s.
    pub leg_speed_rad_s: f64,
    /// Stride period `T = 2 pi / omega`, s.
    pub period_s: f64,
    /// Touchdown angle phi0, rad (docs/model.md §4).
    pub touchdown_angle_rad: f64,
    /// Run-up time (the robot file's `response_time_s`), s.
    pub run_up_s: f64,
    /// Each leg's tripod (0 or 1).
    pub tripods: Vec<usize>,
}

impl GaitSchedule {
    /// The schedule of `robot` for `legs` servos, which must be `2 * stance_legs`.
    pub fn new(robot: &Robot, legs: usize) -> Result<GaitSchedule, ScheduleError> {
        let n = robot.stance_legs();
        if legs != 2 * n as usize {
            return Err(ScheduleError::LegCount { legs, n });
        }
        Ok(GaitSchedule {
            leg_speed_rad_s: robot.leg_speed(),
            period_s: robot.stride_period(),
            touchdown_angle_rad: robot.touchdown_angle(),
            run_up_s: robot.response_time(),
            tripods: (0..legs).map(|j| j % 2).collect(),
        })
    }

    /// Number of legs.
    pub fn legs(&self) -> usize {
        self.tripods.len()
    }

    /// Leg `leg`'s angle before the gait starts (`t <= 0`): `phi0 + k pi`, rad.
    pub fn start_angle(&self, leg: usize) -> f64 {
        self.touchdown_angle_rad + self.tripods[leg] as f64 * PI
    }

    /// Leg `leg`'s command at gait time `t` s (`t < 0`: standing at the start angle).
    pub fn command(&self, leg: usize, t: f64) -> LegCommand {
        let w = self.leg_speed_rad_s;
        let r = self.run_up_s;
        let start = self.start_angle(leg);
        if t <= 0.0 {
            LegCommand { angle_rad: start, velocity_rad_s: 0.0 }
        } else if t < r {
            LegCommand { angle_rad: start + 0.5 * w * t * t / r, velocity_rad_s: w * t / r }
        } else {
            LegCommand { angle_rad: start + w * (t - 0.5 * r), velocity_rad_s: w }
        }
    }

    /// The gait time at which a leg has turned `travel_rad` from its start angle (the inverse
    /// of [`GaitSchedule::command`]'s angle: `sqrt(2 dt travel / omega)` within the run-up,
    /// `dt/2 + travel / omega` after it); 0 for no travel.
    pub fn time_to_travel(&self, travel_rad: f64) -> f64 {
        let (w, r) = (self.leg_speed_rad_s, self.run_up_s);
        if travel_rad <= 0.0 {
            0.0
        } else if travel_rad < 0.5 * w * r {
            (2.0 * r * travel_rad / w).sqrt()
        } else {
            0.5 * r + travel_rad / w
        }
    }

    /// Every leg's command at gait time `t`.
    pub fn commands(&self, t: f64) -> Vec<LegCommand> {
        (0..self.legs()).map(|j| self.command(j, t)).collect()
    }

    /// Gait time of tripod `tripod`'s `m`-th touchdown (`m >= 0`), s.
    pub fn touchdown_time(&self, tripod: usize, m: usize) -> f64 {
        0.5 * self.run_up_s + (tripod as f64 * 0.5 + m as f64) * self.period_s
    }

    /// Where in its stride a leg at angle `angle_rad` is: `(stride, time since touchdown)`,
    /// both from the angle alone (`psi - phi0 = omega tau + 2 pi stride`: every leg touches
    /// down at `phi0`, tripod 1 half a turn after tripod 0). A leg is in stance while the time
    /// since touchdown is below `T/2`. (`leg` is kept for legs with their own touchdown angle.)
    pub fn stride_position(&self, _leg: usize, angle_rad: f64) -> (i64, f64) {
        let turned = angle_rad - self.touchdown_angle_rad;
        let stride = (turned / (2.0 * PI)).floor();
        let within = turned - stride * 2.0 * PI;
        (stride as i64, within / self.leg_speed_rad_s)
    }

    /// Whether a leg at `angle_rad` is in stance (its C below the axle's sweep into the sand).
    pub fn in_stance(&self, leg: usize, angle_rad: f64) -> bool {
        self.stride_position(leg, angle_rad).1 < 0.5 * self.period_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::robot::RobotSpec;

    fn paper() -> GaitSchedule {
        GaitSchedule::new(&Robot::new(RobotSpec::paper_hexapod()).unwrap(), 6).unwrap()
    }

    #[test]
    fn time_to_travel_inverts_the_command() {
        let s = paper();
        // 256 turns at 1 turn/s after the 0.2 s run-up: 0.1 + 256 = 256.1 s.
        assert!((s.time_to_travel(256.0 * 2.0 * PI) - 256.1).abs() < 1e-9);
        // Within the run-up: 0.05 pi at t = 0.1 s (a quarter of the run-up's 0.2 pi).
        assert!((s.time_to_travel(0.05 * PI) - 0.1).abs() < 1e-12);
        assert_eq!(s.time_to_travel(0.0), 0.0);
    }

    #[test]
    fn paper_timing_by_hand() {
        let s = paper();
        // omega = 2 pi: T = 1 s; dt = 0.2 s run-up.
        assert!((s.period_s - 1.0).abs() < 1e-12);
        assert_eq!(s.tripods, vec![0, 1, 0, 1, 0, 1]);
        // phi0 = asin((0.03 - 0.04) / 0.04) = asin(-0.25) = -0.25268 rad.
        assert!((s.touchdown_angle_rad + 0.252_680_255).abs() < 1e-8);
        // Run-up: at t = dt the leg has turned omega dt / 2 = 0.2 pi and runs at omega.
        let c = s.command(0, 0.2);
        assert!((c.angle_rad - s.start_angle(0) - 0.2 * PI).abs() < 1e-12);
        assert!((c.velocity_rad_s - 2.0 * PI).abs() < 1e-12);
        // Half-way through the run-up: half the speed, a quarter of the angle.
        let c = s.command(3, 0.1);
        assert!((c.velocity_rad_s - PI).abs() < 1e-12);
        assert!((c.angle_rad - s.start_angle(3) - 0.05 * PI).abs() < 1e-12);
        // Tripod 1 is half a turn ahead at every instant after the start.
        for t in [0.0, 0.05, 0.3, 1.7] {
            let d = s.command(1, t).angle_rad - s.command(0, t).angle_rad;
            assert!((d - PI).abs() < 1e-12);
        }
        // Touchdowns: tripod 0 at 0.1 s, 1.1 s; tripod 1 at 0.6 s.
        assert!((s.touchdown_time(0, 1) - 1.1).abs() < 1e-12);
        assert!((s.touchdown_time(1, 0) - 0.6).abs() < 1e-12);
        // At its touchdown time a leg is at the start of a stance: tripod 1 starts half a turn
        // past phi0, so its m-th touchdown (m from 0) begins its turn m + 1.
        let t = s.touchdown_time(1, 2) + 1e-9;
        let (stride, since) = s.stride_position(1, s.command(1, t).angle_rad);
        assert_eq!(stride, 3);
        assert!(since < 1e-6);
        assert!(s.in_stance(1, s.command(1, t + 0.49).angle_rad));
        assert!(!s.in_stance(1, s.command(1, t + 0.51).angle_rad));
    }

    #[test]
    fn leg_count_must_be_two_tripods() {
        let robot = Robot::new(RobotSpec::paper_hexapod()).unwrap();
        let e = GaitSchedule::new(&robot, 4).unwrap_err();
        assert!(e.to_string().contains("2 * stance_legs = 6"), "{e}");
    }
}
