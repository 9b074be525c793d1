//! Why a run of the driver failed ([`DriveError`]), each with the servo, the time and the fix,
//! and the exit code a front end gives it.

/// Why a run failed. [`DriveError::exit_code`] is 2 for what was wrong before anything moved
/// (the setup: port, IDs, models, a latched hardware error, goals out of range) and 3 for a bus that failed during the run.
#[derive(Debug, thiserror::Error)]
pub enum DriveError {
    /// A servo did not answer a ping.
    #[error("servo ID {id} (leg {leg}) did not answer a ping at {baud} baud; IDs that answered: {answered}. Fix: check its cable and power, or set its ID in the robot file's [servos] ids (Dynamixel Wizard shows the IDs on the bus)")]
    Missing {
        /// ID.
        id: u8,
        /// Leg.
        leg: usize,
        /// Baud rate.
        baud: u32,
        /// IDs that did answer, listed.
        answered: String,
    },
    /// A servo answered with a model number the driver does not support, another model than
    /// the robot file's `[servos] model`, or another model than the servos before it.
    #[error("servo ID {id} (leg {leg}) reports model number {model}: {why}. Fix: {fix}")]
    WrongModel {
        /// ID.
        id: u8,
        /// Leg.
        leg: usize,
        /// Model number reported.
        model: u16,
        /// Why it is refused.
        why: String,
        /// What to do.
        fix: String,
    },
    /// A setting beyond what the servos' model accepts (`--current-limit`,
    /// `--temperature-limit`).
    #[error("{what} = {value} is beyond what the {servo} accepts: {range}. Fix: {fix}")]
    ModelLimit {
        /// The setting, as the front end names it.
        what: &'static str,
        /// Its value.
        value: f64,
        /// The model.
        servo: &'static str,
        /// The model's range, in words.
        range: String,
        /// What to do.
        fix: &'static str,
    },
    /// A setup write failed.
    #[error("servo ID {id} (leg {leg}) refused {what}: {reason}. Fix: {fix}")]
    Setup {
        /// ID.
        id: u8,
        /// Leg.
        leg: usize,
        /// What was written.
        what: &'static str,
        /// The error.
        reason: String,
        /// What to do.
        fix: &'static str,
    },
    /// A servo stopped answering during the run.
    #[error("servo ID {id} (leg {leg}) stopped answering at t = {time_s:.3} s ({cycles} cycles in a row without a status packet: {reason}). Fix: check its cable, connector and power; the torque was turned off on every servo that answers")]
    Lost {
        /// ID.
        id: u8,
        /// Leg.
        leg: usize,
        /// Gait time, s.
        time_s: f64,
        /// Failed cycles.
        cycles: usize,
        /// The last error.
        reason: String,
    },
    /// A servo's status packets kept failing their CRC.
    #[error("servo ID {id} (leg {leg}) sent corrupt packets at t = {time_s:.3} s ({cycles} cycles in a row failed their CRC). Fix: check the bus wiring and connectors, that only one adapter drives the bus, and that every servo uses the same baud rate; the torque was turned off")]
    Corrupt {
        /// ID.
        id: u8,
        /// Leg.
        leg: usize,
        /// Gait time, s.
        time_s: f64,
        /// Failed cycles.
        cycles: usize,
    },
    /// A servo raised its alert: a fault of its own (overheating, overload, electrical shock,
    /// input voltage) made it shut its torque off, as its Shutdown register (63) says.
    #[error("servo ID {id} (leg {leg}) reported {} at t = {time_s:.3} s (Hardware Error Status {bits:#04x}) and shut its own torque off. Fix: {}; then clear the error by rebooting the servo (power it off and on, or the Reboot instruction); the torque was turned off on the others", hardware_faults(*.bits), hardware_fix(*.bits))]
    Hardware {
        /// ID.
        id: u8,
        /// Leg.
        leg: usize,
        /// Gait time, s.
        time_s: f64,
        /// Hardware Error Status (70); 0xFF when it could not be read.
        bits: u8,
    },
    /// A servo's Hardware Error Status was set before the run (its alert bit at ping).
    #[error("servo ID {id} (leg {leg}) has a hardware error latched from before the run: {} (Hardware Error Status {bits:#04x}); nothing was moved. Fix: {}; then clear it by rebooting the servo (power it off and on, or Dynamixel Wizard's Reboot)", hardware_faults(*.bits), hardware_fix(*.bits))]
    Latched {
        /// ID.
        id: u8,
        /// Leg.
        leg: usize,
        /// Hardware Error Status (70); 0xFF when it could not be read.
        bits: u8,
    },
    /// The run's goals would leave the extended position mode's range from where a leg stands.
    #[error("--duration {duration_s} s would carry servo ID {id} (leg {leg}) past Goal Position's range in extended position mode (-1,048,575 to 1,048,575 pulses, 256 turns) from {start} pulses, where it stands: the longest run that fits is {longest_s:.1} s; nothing was moved. Fix: --duration {:.0} or less, --profile velocity (no position goal), or power-cycle the servo (its revolution count restarts within one turn)", longest_s.floor())]
    Range {
        /// ID.
        id: u8,
        /// Leg.
        leg: usize,
        /// The start goal, pulses.
        start: i32,
        /// Requested duration, s.
        duration_s: f64,
        /// Longest that fits, s.
        longest_s: f64,
    },
    /// A servo holds another goal than the one sent (a Sync Write's goal refused in silence).
    #[error("servo ID {id} (leg {leg}) did not take its goal at t = {time_s:.3} s: {register} = {sent} was sent, it holds {holds}; {cause}. The run was stopped and the torque turned off")]
    Rejected {
        /// ID.
        id: u8,
        /// Leg.
        leg: usize,
        /// Gait time, s.
        time_s: f64,
        /// The register, named with its address.
        register: &'static str,
        /// The goal sent.
        sent: i32,
        /// What the servo holds.
        holds: i32,
        /// Why, as far as the driver can tell.
        cause: &'static str,
    },
    /// A servo answered a read with an error number in its status packet.
    #[error("servo ID {id} (leg {leg}) answered the read of {register} with a {error} at t = {time_s:.3} s. The run was stopped and the torque turned off. Fix: check the servo's model and firmware (Dynamixel Wizard)")]
    Status {
        /// ID.
        id: u8,
        /// Leg.
        leg: usize,
        /// Gait time, s.
        time_s: f64,
        /// The register(s) read.
        register: &'static str,
        /// The error's name and number.
        error: String,
    },
    /// A servo's shaft stopped following its command.
    #[error("servo ID {id} (leg {leg}) stopped following its goal: at t = {time_s:.3} s its shaft was {error_rad:.2} rad ({:.2} turns) from the command, beyond a quarter turn since t = {since_s:.3} s (more than 0.5 s). Fix: free the leg (stuck in the sand or against the frame), check its power and that its torque is on; the torque was turned off", error_rad / std::f64::consts::TAU)]
    Following {
        /// ID.
        id: u8,
        /// Leg.
        leg: usize,
        /// Gait time, s.
        time_s: f64,
        /// The error, rad (command minus shaft).
        error_rad: f64,
        /// When it passed the limit, s.
        since_s: f64,
    },
    /// A cycle took longer than the watchdog allows.
    #[error("the driver's watchdog fired at t = {time_s:.3} s: one cycle took {cycle_s:.3} s, more than --watchdog {limit_s} s. Fix: lower --rate, raise the baud rate, or find what stalls the bus; the torque was turned off")]
    Watchdog {
        /// Gait time, s.
        time_s: f64,
        /// The cycle's length, s.
        cycle_s: f64,
        /// The limit, s.
        limit_s: f64,
    },
    /// The bus itself failed (the port went away).
    #[error("the bus failed at t = {time_s:.3} s: {reason}. Fix: check the USB adapter's connection; the torque was turned off on every servo that answers")]
    Bus {
        /// Gait time, s.
        time_s: f64,
        /// The error.
        reason: String,
    },
    /// The log could not be written.
    #[error("the servo log could not be written at t = {time_s:.3} s: {reason}; the torque was turned off and the rows written before it are kept. Fix: free space on that disk (or raise the file-size limit, `ulimit -f`), or log to another one")]
    Log {
        /// Gait time, s.
        time_s: f64,
        /// The error.
        reason: String,
    },
}

/// The faults a Hardware Error Status (70) names, as the XL330's control table lists its bits:
/// 0 input voltage, 2 overheating, 4 electrical shock, 5 overload.
pub fn hardware_faults(bits: u8) -> String {
    if bits == 0xFF {
        return "an alert whose Hardware Error Status could not be read".to_string();
    }
    let names: Vec<&str> = [
        (0, "an input voltage out of its limits"),
        (2, "overheating (Present Temperature above its Temperature Limit)"),
        (4, "an electrical shock (a motor circuit fault)"),
        (5, "an overload (a load above its torque for too long)"),
    ]
    .iter()
    .filter(|(bit, _)| bits & (1 << bit) != 0)
    .map(|(_, name)| *name)
    .collect();
    if names.is_empty() {
        format!("a hardware error the XL330's table does not name (bits {bits:#04x})")
    } else {
        names.join(" and ")
    }
}

/// What to do about the faults of [`hardware_faults`].
fn hardware_fix(bits: u8) -> &'static str {
    if bits == 0xFF {
        "check its cable and read its Hardware Error Status (70) with the Dynamixel Wizard"
    } else if bits & (1 << 2) != 0 {
        "let it cool, and lower its load (a shallower slope, a lighter robot) or raise --temperature-limit within the datasheet's 70 degC"
    } else if bits & (1 << 5) != 0 {
        "free the leg (stuck in the sand or against the frame) and lower its load"
    } else if bits & 1 != 0 {
        "check the supply (the XL330 runs on 3.7 to 6.0 V, the XL430-W250 on 6.5 to 12.0 V, the XM430-W350 on 10.0 to 14.8 V)"
    } else {
        "check its wiring and motor"
    }
}

impl DriveError {
    /// 2: the setup was wrong before anything moved; 3: the bus or the log failed mid-run.
    pub fn exit_code(&self) -> i32 {
        match self {
            DriveError::Missing { .. }
            | DriveError::WrongModel { .. }
            | DriveError::ModelLimit { .. }
            | DriveError::Setup { .. }
            | DriveError::Latched { .. }
            | DriveError::Range { .. } => 2,
            _ => 3,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::hardware_faults;

    /// The bits as the XL330-M288's control table (Hardware Error Status, 70) lists them.
    #[test]
    fn hardware_faults_name_the_control_tables_bits() {
        assert!(hardware_faults(0x04).starts_with("overheating"));
        let both = hardware_faults(0x24);
        assert!(both.contains("overheating") && both.contains(" and an overload"), "{both}");
        assert!(hardware_faults(0x01).starts_with("an input voltage"));
        assert!(hardware_faults(0x10).starts_with("an electrical shock"));
        assert!(hardware_faults(0x08).contains("does not name (bits 0x08)"));
        assert!(hardware_faults(0xFF).contains("could not be read"));
    }
}
