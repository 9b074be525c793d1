//! The Dynamixel XL330-M288-T of the paper's robot (docs/model.md §19): its control table's
//! units and the datasheet's electro-mechanical numbers.
//!
//! Source: ROBOTIS e-Manual, XL330-M288-T (specifications and control table): 4096 pulses per
//! revolution, 0.229 rev/min per velocity unit, 1 mA per current unit, 0.1 V per voltage unit,
//! stall torque 0.52 N m at 5.0 V and 1.47 A (0.42 N m at 3.7 V, 1.11 A; 0.60 N m at 6.0 V,
//! 1.74 A), no-load speed 103 rev/min at 5.0 V, current limit at most 1750 mA, temperature limit
//! 70 degC by default (operating range -5 to 70 degC), input voltage 3.7 to 6.0 V.

use std::f64::consts::PI;

/// Model number the XL330-M288 reports at address 0.
pub const MODEL_NUMBER: u16 = 1200;
/// Encoder pulses per output-shaft revolution.
pub const PULSES_PER_REV: f64 = 4096.0;
/// One position pulse, rad.
pub const RAD_PER_PULSE: f64 = 2.0 * PI / PULSES_PER_REV;
/// One velocity unit (0.229 rev/min), rad/s.
pub const RAD_S_PER_VELOCITY_UNIT: f64 = 0.229 * 2.0 * PI / 60.0;
/// One profile-acceleration unit (214.577 rev/min^2), rad/s^2.
pub const RAD_S2_PER_ACCELERATION_UNIT: f64 = 214.577 * 2.0 * PI / 3600.0;
/// One current unit, A.
pub const AMP_PER_CURRENT_UNIT: f64 = 0.001;
/// One voltage unit, V.
pub const VOLT_PER_VOLTAGE_UNIT: f64 = 0.1;
/// One Bus Watchdog unit, s.
pub const WATCHDOG_UNIT_S: f64 = 0.020;
/// Stall torque at 5.0 V, N m (datasheet).
pub const STALL_TORQUE_N_M: f64 = 0.52;
/// Stall current at 5.0 V, A (datasheet).
pub const STALL_CURRENT_A: f64 = 1.47;
/// Torque constant `K_t = 0.52 N m / 1.47 A = 0.354 N m/A` at the recommended 5.0 V
/// (docs/model.md §19, a choice: the stall point through the origin; the datasheet's 3.7 V and
/// 6.0 V points give 0.378 and 0.345 N m/A).
pub const TORQUE_CONSTANT_N_M_PER_A: f64 = STALL_TORQUE_N_M / STALL_CURRENT_A;
/// No-load speed at 5.0 V, rad/s (103 rev/min).
pub const NO_LOAD_SPEED_RAD_S: f64 = 103.0 * 2.0 * PI / 60.0;
/// Largest current limit the control table accepts, mA.
pub const MAX_CURRENT_LIMIT_MA: u16 = 1750;
/// Highest temperature limit the servo is rated for, degC.
pub const MAX_TEMPERATURE_C: u8 = 70;
/// Input voltage range, V.
pub const VOLTAGE_RANGE_V: (f64, f64) = (3.7, 6.0);
/// Goal Position's range in Extended Position Control Mode (Operating Mode 4), pulses: -1,048,575
/// to 1,048,575, 256 turns either way (e-Manual, Goal Position (116)). A goal outside it is
/// refused with a Data Range Error (by a Sync Write, silently: no status packet).
pub const EXTENDED_GOAL_LIMIT_PULSES: i32 = 1_048_575;
/// Goal Position's range in Position Control Mode (Operating Mode 3), pulses: 0 to 4095.
pub const POSITION_GOAL_RANGE_PULSES: (i32, i32) = (0, 4095);
/// Largest Velocity Limit (44) the control table accepts, 0.229 rev/min units; Goal Velocity
/// (104) must lie within plus or minus the Velocity Limit written.
pub const MAX_VELOCITY_LIMIT: u32 = 2047;
/// Largest Profile Velocity (112) and Profile Acceleration (108), in their units.
pub const MAX_PROFILE: u32 = 32767;
/// Largest Return Delay Time (9), 2 us units.
pub const MAX_RETURN_DELAY: u8 = 254;
/// One Return Delay Time unit, s.
pub const RETURN_DELAY_UNIT_S: f64 = 2e-6;
/// Largest Bus Watchdog (98) a host writes, 20 ms units (100 is what the servo sets when it fired).
pub const MAX_BUS_WATCHDOG: u8 = 127;
/// Largest Temperature Limit (31) the control table accepts, degC (the rated range ends at 70).
pub const MAX_TEMPERATURE_LIMIT_REGISTER: u8 = 100;

/// Shaft torque from a Present Current reading, N m (`tau = K_t I`, §19).
pub fn torque_from_current(current_ma: f64) -> f64 {
    TORQUE_CONSTANT_N_M_PER_A * current_ma * AMP_PER_CURRENT_UNIT
}

/// The Present Current, mA, at shaft torque `tau` N m (the inverse of [`torque_from_current`]).
pub fn current_from_torque(torque_n_m: f64) -> f64 {
    torque_n_m / TORQUE_CONSTANT_N_M_PER_A / AMP_PER_CURRENT_UNIT
}

/// A shaft angle, rad, as position pulses (rounded).
pub fn pulses_from_rad(angle_rad: f64) -> i64 {
    (angle_rad / RAD_PER_PULSE).round() as i64
}

/// An angular speed, rad/s, in velocity units (rounded).
pub fn velocity_units_from_rad_s(speed: f64) -> i64 {
    (speed / RAD_S_PER_VELOCITY_UNIT).round() as i64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_paper_leg_speed_in_control_table_units() {
        // omega = 2 pi rad/s is 60 rev/min; 60 / 0.229 = 262.01 units.
        assert_eq!(velocity_units_from_rad_s(2.0 * PI), 262);
        // Half a turn is 2048 pulses.
        assert_eq!(pulses_from_rad(PI), 2048);
        // K_t by hand: 0.52 / 1.47 = 0.35374 N m/A.
        assert!((TORQUE_CONSTANT_N_M_PER_A - 0.353_741).abs() < 1e-6);
        // 1 A at that constant is 0.354 N m; 1470 mA is the stall torque.
        assert!((torque_from_current(1470.0) - 0.52).abs() < 1e-12);
        assert!((current_from_torque(0.52) - 1470.0).abs() < 1e-9);
        // The no-load speed, 103 rev/min = 10.79 rad/s, is above the paper's 2 pi rad/s.
        assert!((NO_LOAD_SPEED_RAD_S - 10.786).abs() < 1e-3);
    }
}
