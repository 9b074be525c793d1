//! Dynamixel servo models as values (docs/model.md §19): one [`ServoModel`] per supported
//! model, each with its datasheet figures (stall torque and current, no-load speed, supply)
//! and the ranges of its control table that differ between models, every figure with its
//! source. The driver picks the model from the number a servo reports at its ping
//! ([`ServoModel::from_model_number`]); the robot file may name it (`[servos] model`,
//! [`ServoModel::by_name`]); the simulator's actuator reads the same figures.
//!
//! What every supported model shares (the Dynamixel X series' Protocol 2.0 control table,
//! e-Manual "Control Table" of each model below) is a constant of this module: 4096 pulses per
//! turn, 0.229 rev/min per velocity unit, 214.577 rev/min^2 per acceleration unit, 0.1 V per
//! voltage unit, 20 ms per Bus Watchdog unit, 2 us per Return Delay Time unit, Goal Position
//! within +/-1,048,575 pulses in extended position mode (256 turns).
//!
//! Adding a model is one value here (and its entry in [`ServoModel::ALL`]) plus its control
//! table in `sandslope-servo` (`models.rs`: which registers it has, its factory values).

use std::f64::consts::PI;

use serde::Serialize;

/// Encoder pulses per output-shaft revolution (every X-series model: 12-bit encoder).
pub const PULSES_PER_REV: f64 = 4096.0;
/// One position pulse, rad.
pub const RAD_PER_PULSE: f64 = 2.0 * PI / PULSES_PER_REV;
/// One velocity unit (0.229 rev/min), rad/s.
pub const RAD_S_PER_VELOCITY_UNIT: f64 = 0.229 * 2.0 * PI / 60.0;
/// One profile-acceleration unit (214.577 rev/min^2), rad/s^2.
pub const RAD_S2_PER_ACCELERATION_UNIT: f64 = 214.577 * 2.0 * PI / 3600.0;
/// One voltage unit, V.
pub const VOLT_PER_VOLTAGE_UNIT: f64 = 0.1;
/// One Bus Watchdog unit, s.
pub const WATCHDOG_UNIT_S: f64 = 0.020;
/// Goal Position's range in Extended Position Control Mode (Operating Mode 4), pulses: -1,048,575
/// to 1,048,575, 256 turns either way (e-Manual, Goal Position (116)). A goal outside it is
/// refused with a Data Range Error (by a Sync Write, silently: no status packet).
pub const EXTENDED_GOAL_LIMIT_PULSES: i32 = 1_048_575;
/// Goal Position's range in Position Control Mode (Operating Mode 3), pulses: 0 to 4095.
pub const POSITION_GOAL_RANGE_PULSES: (i32, i32) = (0, 4095);
/// Largest Profile Velocity (112) and Profile Acceleration (108), in their units.
pub const MAX_PROFILE: u32 = 32767;
/// Largest Return Delay Time (9), 2 us units.
pub const MAX_RETURN_DELAY: u8 = 254;
/// One Return Delay Time unit, s.
pub const RETURN_DELAY_UNIT_S: f64 = 2e-6;
/// Largest Bus Watchdog (98) a host writes, 20 ms units (100 is what the servo sets when it fired).
pub const MAX_BUS_WATCHDOG: u8 = 127;
/// Largest Temperature Limit (31) the control table accepts, degC (the rated range is lower).
pub const MAX_TEMPERATURE_LIMIT_REGISTER: u8 = 100;

/// What address 126 reports, and so how a reading becomes a shaft torque.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TorqueReading {
    /// Present Current (126), signed, in units of `ma_per_unit` mA; the torque is `K_t I`.
    Current {
        /// mA per unit.
        ma_per_unit: f64,
    },
    /// Present Load (126), signed, in units of `percent_per_unit` % of the stall torque (the
    /// model measures no current; the torque is the load's share of the stall torque, a choice:
    /// the e-Manual gives the load as a share of the maximum output).
    Load {
        /// Percent of the stall torque per unit.
        percent_per_unit: f64,
    },
}

/// One Dynamixel servo model: the figures the physics and the driver need, with their source.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ServoModel {
    /// The model's name (`XL330-M288`), as the robot file's `[servos] model` names it.
    pub name: &'static str,
    /// The number it reports at Model Number (0) and in its ping.
    pub model_number: u16,
    /// Where the figures come from (the ROBOTIS e-Manual page: specifications and control table).
    pub source: &'static str,
    /// The recommended supply, V, at which the figures below hold.
    pub nominal_voltage_v: f64,
    /// The supply's range, V.
    pub voltage_range_v: (f64, f64),
    /// Stall torque at the nominal supply, N m.
    pub stall_torque_n_m: f64,
    /// Stall current at the nominal supply, A.
    pub stall_current_a: f64,
    /// No-load speed at the nominal supply, rev/min.
    pub no_load_speed_rev_min: f64,
    /// What address 126 reports.
    pub reading: TorqueReading,
    /// Largest Current Limit (38), in its units; `None`: the model has no current control.
    pub max_current_limit: Option<u16>,
    /// Largest Velocity Limit (44), 0.229 rev/min units; Goal Velocity must lie within plus or
    /// minus the Velocity Limit written.
    pub max_velocity_limit: u32,
    /// Highest operating temperature, degC (the rated range's top).
    pub max_temperature_c: u8,
}

impl ServoModel {
    /// The XL330-M288-T of the paper's robot: 0.52 N m at 5.0 V and 1.47 A (0.42 N m at 3.7 V,
    /// 1.11 A; 0.60 N m at 6.0 V, 1.74 A), 103 rev/min, Present Current in 1 mA, Current Limit
    /// 0 to 1750, Velocity Limit 0 to 2047, -5 to 70 degC, 3.7 to 6.0 V.
    pub const XL330_M288: ServoModel = ServoModel {
        name: "XL330-M288",
        model_number: 1200,
        source: "https://emanual.robotis.com/docs/en/dxl/x/xl330-m288/",
        nominal_voltage_v: 5.0,
        voltage_range_v: (3.7, 6.0),
        stall_torque_n_m: 0.52,
        stall_current_a: 1.47,
        no_load_speed_rev_min: 103.0,
        reading: TorqueReading::Current { ma_per_unit: 1.0 },
        max_current_limit: Some(1750),
        max_velocity_limit: 2047,
        max_temperature_c: 70,
    };

    /// The XL330-M077-T (the XL330 with 77.5:1 gearing): 0.215 N m at 5.0 V and 1.47 A,
    /// 383 rev/min, otherwise the XL330-M288's table (Current Limit 0 to 1750 in 1 mA,
    /// Velocity Limit 0 to 2047).
    pub const XL330_M077: ServoModel = ServoModel {
        name: "XL330-M077",
        model_number: 1190,
        source: "https://emanual.robotis.com/docs/en/dxl/x/xl330-m077/",
        nominal_voltage_v: 5.0,
        voltage_range_v: (3.7, 6.0),
        stall_torque_n_m: 0.215,
        stall_current_a: 1.47,
        no_load_speed_rev_min: 383.0,
        reading: TorqueReading::Current { ma_per_unit: 1.0 },
        max_current_limit: Some(1750),
        max_velocity_limit: 2047,
        max_temperature_c: 70,
    };

    /// The XL430-W250-T: 1.4 N m at 11.1 V and 1.3 A (1.0 N m at 9.0 V; 1.5 N m at 12.0 V,
    /// 1.4 A), 57 rev/min, 6.5 to 12.0 V, -5 to 72 degC; no current control (no Current Limit
    /// (38), no Goal Current (102)); address 126 is Present Load, -1000 to 1000 in 0.1 %;
    /// Velocity Limit 0 to 1023.
    pub const XL430_W250: ServoModel = ServoModel {
        name: "XL430-W250",
        model_number: 1060,
        source: "https://emanual.robotis.com/docs/en/dxl/x/xl430-w250/",
        nominal_voltage_v: 11.1,
        voltage_range_v: (6.5, 12.0),
        stall_torque_n_m: 1.4,
        stall_current_a: 1.3,
        no_load_speed_rev_min: 57.0,
        reading: TorqueReading::Load { percent_per_unit: 0.1 },
        max_current_limit: None,
        max_velocity_limit: 1023,
        max_temperature_c: 72,
    };

    /// The XM430-W350-T: 4.1 N m at 12.0 V and 2.3 A (3.8 N m at 11.1 V, 2.1 A; 4.8 N m at
    /// 14.8 V, 2.7 A), 46 rev/min, 10.0 to 14.8 V, -5 to 80 degC; Present Current and Current
    /// Limit in about 2.69 mA units, Current Limit 0 to 1193; Velocity Limit 0 to 1023.
    pub const XM430_W350: ServoModel = ServoModel {
        name: "XM430-W350",
        model_number: 1020,
        source: "https://emanual.robotis.com/docs/en/dxl/x/xm430-w350/",
        nominal_voltage_v: 12.0,
        voltage_range_v: (10.0, 14.8),
        stall_torque_n_m: 4.1,
        stall_current_a: 2.3,
        no_load_speed_rev_min: 46.0,
        reading: TorqueReading::Current { ma_per_unit: 2.69 },
        max_current_limit: Some(1193),
        max_velocity_limit: 1023,
        max_temperature_c: 80,
    };

    /// Every supported model.
    pub const ALL: [&'static ServoModel; 4] =
        [&ServoModel::XL330_M288, &ServoModel::XL330_M077, &ServoModel::XL430_W250, &ServoModel::XM430_W350];

    /// The model that reports `number` at its ping, or an error naming the supported ones.
    pub fn from_model_number(number: u16) -> Result<&'static ServoModel, UnsupportedServo> {
        ServoModel::ALL
            .iter()
            .copied()
            .find(|m| m.model_number == number)
            .ok_or_else(|| UnsupportedServo(format!("model number {number}")))
    }

    /// The model named `name` (`XL430-W250`; case and a trailing `-T`/`-R` ignored), or an
    /// error naming the supported ones.
    pub fn by_name(name: &str) -> Result<&'static ServoModel, UnsupportedServo> {
        let n = name.trim().to_ascii_uppercase();
        let n = n.strip_suffix("-T").or_else(|| n.strip_suffix("-R")).unwrap_or(&n);
        ServoModel::ALL
            .iter()
            .copied()
            .find(|m| m.name == n)
            .ok_or_else(|| UnsupportedServo(format!("`{}`", name.trim())))
    }

    /// The supported models, listed for a message: `XL330-M288 (1200), ...`.
    pub fn supported() -> String {
        ServoModel::ALL
            .iter()
            .map(|m| format!("{} ({})", m.name, m.model_number))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Torque constant `K_t = tau_stall / I_stall` at the nominal supply, N m/A (docs/model.md
    /// §19, a choice: the stall point through the origin).
    pub fn torque_constant_n_m_per_a(&self) -> f64 {
        self.stall_torque_n_m / self.stall_current_a
    }

    /// No-load speed at the nominal supply, rad/s.
    pub fn no_load_speed_rad_s(&self) -> f64 {
        self.no_load_speed_rev_min * 2.0 * PI / 60.0
    }

    /// Shaft torque, N m, from a reading of address 126 in its units (`tau = K_t I`, or the
    /// load's share of the stall torque).
    pub fn torque_from_reading(&self, raw: f64) -> f64 {
        match self.reading {
            TorqueReading::Current { ma_per_unit } => self.torque_from_current_ma(raw * ma_per_unit),
            TorqueReading::Load { percent_per_unit } => {
                raw * percent_per_unit / 100.0 * self.stall_torque_n_m
            }
        }
    }

    /// The reading of address 126, in its units, at shaft torque `tau` N m (the inverse of
    /// [`ServoModel::torque_from_reading`]).
    pub fn reading_from_torque(&self, torque_n_m: f64) -> f64 {
        match self.reading {
            TorqueReading::Current { ma_per_unit } => self.current_ma_from_torque(torque_n_m) / ma_per_unit,
            TorqueReading::Load { percent_per_unit } => {
                torque_n_m / self.stall_torque_n_m * 100.0 / percent_per_unit
            }
        }
    }

    /// Shaft torque, N m, from a motor current in mA (`tau = K_t I`).
    pub fn torque_from_current_ma(&self, current_ma: f64) -> f64 {
        self.torque_constant_n_m_per_a() * current_ma * 1e-3
    }

    /// The motor current, mA, at shaft torque `tau` N m (the inverse of
    /// [`ServoModel::torque_from_current_ma`]).
    pub fn current_ma_from_torque(&self, torque_n_m: f64) -> f64 {
        torque_n_m / self.torque_constant_n_m_per_a() * 1e3
    }

    /// The motor current, mA, a reading of address 126 stands for (for a load-reporting model,
    /// the current at that torque by `K_t`).
    pub fn current_ma_from_reading(&self, raw: f64) -> f64 {
        match self.reading {
            TorqueReading::Current { ma_per_unit } => raw * ma_per_unit,
            TorqueReading::Load { .. } => self.current_ma_from_torque(self.torque_from_reading(raw)),
        }
    }

    /// A reading of address 126 as a share of the stall torque, %.
    pub fn load_percent_from_reading(&self, raw: f64) -> f64 {
        100.0 * self.torque_from_reading(raw) / self.stall_torque_n_m
    }

    /// The largest Current Limit the model accepts, mA; `None` without current control.
    pub fn max_current_limit_ma(&self) -> Option<f64> {
        match (self.max_current_limit, self.reading) {
            (Some(units), TorqueReading::Current { ma_per_unit }) => Some(f64::from(units) * ma_per_unit),
            _ => None,
        }
    }

    /// A current limit in mA as the Current Limit register's units (rounded), `None` without
    /// current control.
    pub fn current_limit_units(&self, current_ma: f64) -> Option<u32> {
        match (self.max_current_limit, self.reading) {
            (Some(_), TorqueReading::Current { ma_per_unit }) => {
                Some((current_ma / ma_per_unit).round() as u32)
            }
            _ => None,
        }
    }
}

/// A servo model the driver does not know.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0} is not a supported servo; the supported ones are {list}", list = ServoModel::supported())]
pub struct UnsupportedServo(pub String);

/// Shaft position in pulses (rounded) for a shaft angle in rad.
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
    fn the_paper_servo_by_hand() {
        let m = ServoModel::XL330_M288;
        // omega = 2 pi rad/s is 60 rev/min; 60 / 0.229 = 262.01 units.
        assert_eq!(velocity_units_from_rad_s(2.0 * PI), 262);
        // Half a turn is 2048 pulses.
        assert_eq!(pulses_from_rad(PI), 2048);
        // K_t by hand: 0.52 / 1.47 = 0.35374 N m/A.
        assert!((m.torque_constant_n_m_per_a() - 0.353_741).abs() < 1e-6);
        // 1470 mA is the stall torque, and back.
        assert!((m.torque_from_reading(1470.0) - 0.52).abs() < 1e-12);
        assert!((m.reading_from_torque(0.52) - 1470.0).abs() < 1e-9);
        // 103 rev/min = 10.786 rad/s, above the paper's 2 pi rad/s.
        assert!((m.no_load_speed_rad_s() - 10.786).abs() < 1e-3);
        assert_eq!(m.max_current_limit_ma(), Some(1750.0));
    }

    #[test]
    fn the_other_models_by_hand() {
        // XM430-W350: K_t = 4.1 / 2.3 = 1.7826 N m/A; a reading of 1000 units is 2690 mA,
        // 4.795 N m; its largest Current Limit 1193 x 2.69 = 3209.2 mA.
        let xm = ServoModel::XM430_W350;
        assert!((xm.torque_constant_n_m_per_a() - 1.782_609).abs() < 1e-6);
        assert!((xm.torque_from_reading(1000.0) - 2.69 * 1.782_609).abs() < 1e-5);
        assert!((xm.max_current_limit_ma().unwrap() - 3209.17).abs() < 1e-9);
        assert_eq!(xm.current_limit_units(1470.0), Some(546));
        // XL430-W250: Present Load 500 (50.0 %) is half the 1.4 N m stall torque; no current
        // control.
        let xl4 = ServoModel::XL430_W250;
        assert!((xl4.torque_from_reading(500.0) - 0.7).abs() < 1e-12);
        assert!((xl4.reading_from_torque(0.7) - 500.0).abs() < 1e-9);
        assert!((xl4.load_percent_from_reading(-250.0) + 25.0).abs() < 1e-12);
        assert_eq!(xl4.max_current_limit_ma(), None);
        // XL330-M077: 0.215 / 1.47 = 0.14626 N m/A; 383 rev/min = 40.11 rad/s.
        let m077 = ServoModel::XL330_M077;
        assert!((m077.torque_constant_n_m_per_a() - 0.146_259).abs() < 1e-6);
        assert!((m077.no_load_speed_rad_s() - 40.107).abs() < 1e-3);
    }

    #[test]
    fn models_are_found_by_number_and_name_and_others_refused() {
        assert_eq!(ServoModel::from_model_number(1060).unwrap().name, "XL430-W250");
        assert_eq!(ServoModel::by_name("xm430-w350-t").unwrap().model_number, 1020);
        let e = ServoModel::from_model_number(1030).unwrap_err().to_string();
        assert_eq!(
            e,
            "model number 1030 is not a supported servo; the supported ones are XL330-M288 (1200), \
             XL330-M077 (1190), XL430-W250 (1060), XM430-W350 (1020)"
        );
        assert!(ServoModel::by_name("AX-12").unwrap_err().to_string().starts_with("`AX-12` is not"));
        // Every number once.
        for (i, a) in ServoModel::ALL.iter().enumerate() {
            assert!(ServoModel::ALL[i + 1..].iter().all(|b| b.model_number != a.model_number));
        }
    }
}
