//! Each supported servo model's control table where it differs from the X series' shared one
//! ([`crate::table`]: the addresses and widths every model has): which registers it has, the
//! operating modes it accepts and its factory values, the emulator's starting table. The
//! physics figures (torque, speed, units of address 126) are the library's
//! [`sandslope::servo::ServoModel`]; [`ControlTable::model`] links the two.
//!
//! Source of every value: the model's ROBOTIS e-Manual page (`ServoModel::source`), "Control
//! Table of EEPROM Area" (the initial values) and "Operating Mode (11)".

use sandslope::servo::ServoModel;

/// One model's control table: what differs between the supported models.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlTable {
    /// The model's physics figures and ranges.
    pub model: &'static ServoModel,
    /// The Operating Mode (11) values the model accepts.
    pub operating_modes: &'static [u8],
    /// Whether the model has Current Limit (38) and Goal Current (102) (current control).
    pub current_control: bool,
    /// Factory Temperature Limit (31), degC.
    pub temperature_limit: u8,
    /// Factory Max and Min Voltage Limit (32, 34), 0.1 V.
    pub voltage_limits: (u16, u16),
    /// Factory Current Limit (38), its units (0 where the model has none).
    pub current_limit: u16,
    /// Factory Velocity Limit (44), 0.229 rev/min.
    pub velocity_limit: u32,
    /// Factory Shutdown (63).
    pub shutdown: u8,
}

/// Modes of the models with current control: current, velocity, position, extended
/// position, current-based position, PWM.
const SIX_MODES: &[u8] = &[0, 1, 3, 4, 5, 16];

/// The XL330-M288-T.
pub const XL330_M288: ControlTable = ControlTable {
    model: &ServoModel::XL330_M288,
    operating_modes: SIX_MODES,
    current_control: true,
    temperature_limit: 70,
    voltage_limits: (70, 35),
    current_limit: 1750,
    velocity_limit: 445,
    shutdown: 53,
};

/// The XL330-M077-T.
pub const XL330_M077: ControlTable = ControlTable {
    model: &ServoModel::XL330_M077,
    operating_modes: SIX_MODES,
    current_control: true,
    temperature_limit: 70,
    voltage_limits: (70, 35),
    current_limit: 1750,
    velocity_limit: 1620,
    shutdown: 53,
};

/// The XL430-W250-T: velocity, position, extended position and PWM only; no current control.
pub const XL430_W250: ControlTable = ControlTable {
    model: &ServoModel::XL430_W250,
    operating_modes: &[1, 3, 4, 16],
    current_control: false,
    temperature_limit: 72,
    voltage_limits: (140, 60),
    current_limit: 0,
    velocity_limit: 265,
    shutdown: 52,
};

/// The XM430-W350-T.
pub const XM430_W350: ControlTable = ControlTable {
    model: &ServoModel::XM430_W350,
    operating_modes: SIX_MODES,
    current_control: true,
    temperature_limit: 80,
    voltage_limits: (160, 95),
    current_limit: 1193,
    velocity_limit: 350,
    shutdown: 52,
};

/// Every supported model's table, in `ServoModel::ALL`'s order.
pub const ALL: [&ControlTable; 4] = [&XL330_M288, &XL330_M077, &XL430_W250, &XM430_W350];

impl ControlTable {
    /// The table of `model` (every model of `ServoModel::ALL` has one; a test checks it).
    pub fn of(model: &ServoModel) -> &'static ControlTable {
        ALL.iter().copied().find(|t| t.model.model_number == model.model_number).unwrap_or(&XL330_M288)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_model_has_its_table() {
        for m in ServoModel::ALL {
            assert_eq!(ControlTable::of(m).model, m, "{}", m.name);
        }
        // Current control and the model's current limit agree.
        for t in ALL {
            assert_eq!(t.current_control, t.model.max_current_limit.is_some(), "{}", t.model.name);
            assert!(t.velocity_limit <= t.model.max_velocity_limit);
        }
    }
}
