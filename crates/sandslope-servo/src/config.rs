//! What one run is configured with: the servos as mounted, how the gait is commanded, the
//! run's settings, and the bus they are driven over. The driver, its range plan, its setup
//! writes and its guards all read these; none of them is read back from the driver.

use dynamixel2::Bus;
use sandslope::servo::{model::RAD_PER_PULSE, ServoModel};
use serde::Serialize;

/// One servo as mounted on the robot (the robot file's `[servos]` table).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct ServoConfig {
    /// Dynamixel ID, 0 to 252.
    pub id: u8,
    /// +1 if a positive shaft turn drives the leg forward, -1 if mounted mirrored.
    pub direction: i8,
    /// Shaft position, pulses, at which the leg is at gait angle 0 (the C's circle centre
    /// straight ahead of the axle).
    pub zero_offset_pulses: i32,
}

impl ServoConfig {
    /// Goal position, pulses, for leg angle `angle` rad.
    pub fn pulses(&self, angle: f64) -> i32 {
        let p = self.zero_offset_pulses as f64 + f64::from(self.direction) * angle / RAD_PER_PULSE;
        p.round().clamp(i32::MIN as f64, i32::MAX as f64) as i32
    }

    /// Leg angle, rad, at shaft position `pulses`.
    pub fn angle(&self, pulses: i32) -> f64 {
        f64::from(self.direction) * f64::from(pulses - self.zero_offset_pulses) * RAD_PER_PULSE
    }
}

/// How the gait is commanded (the servo's velocity-based profile either way).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Profile {
    /// Extended position mode: the schedule's angle every cycle, Profile Velocity 1.5 omega
    /// (a lagging leg catches up at most that fast, as in the simulator).
    Position,
    /// Velocity mode: the schedule's speed plus `4/s` times the phase error every cycle.
    Velocity,
}

/// Settings of one run.
#[derive(Debug, Clone, Serialize)]
pub struct DriveSettings {
    /// Servos in leg order.
    pub servos: Vec<ServoConfig>,
    /// Position or velocity commands.
    pub profile: Profile,
    /// Gait time, s (after standing up).
    pub duration_s: f64,
    /// Cycles per second the driver aims at.
    pub rate_hz: f64,
    /// The servos' model as the robot file names it (`[servos] model`); `None`: the model the
    /// servos report at their ping, whichever supported one it is. Every servo must be the same.
    pub servo: Option<&'static ServoModel>,
    /// Current Limit written to every servo, mA (at most the model's; not written to a model
    /// without current control, the XL430-W250).
    pub current_limit_ma: u16,
    /// Temperature Limit written to every servo, degC (at most the model's rated maximum).
    pub temperature_limit_c: u8,
    /// Longest cycle the driver accepts before it stops everything, s.
    pub watchdog_s: f64,
    /// The servos' own Bus Watchdog, s (20 ms units, 1 to 127).
    pub bus_watchdog_s: f64,
    /// Halt when the live risk that the walk fails (slippage or sinkage) passes this probability.
    pub stop_on_risk: Option<f64>,
    /// After a halt, how long the legs are held before the torque goes off, s.
    pub hold_s: f64,
    /// Time allowed to stand up to the start pose, s.
    pub stand_s: f64,
}

/// The bus type the driver runs on.
pub type DynamixelBus = Bus<Vec<u8>, Vec<u8>>;
