//! A run's setup, before anything moves (docs/drive.md, "What it sends"): every ID pinged (its
//! model and any hardware error latched before the run checked), then the control table
//! written with the torque off, the EEPROM registers only where they differ, and the
//! revolution counter cleared so that every goal of the run fits the extended position mode's
//! range.

use dynamixel2::ReadError;
use sandslope::servo::model as x;
use sandslope::servo::{GaitSchedule, ServoModel};

use crate::config::{DriveSettings, DynamixelBus, Profile};
use crate::error::DriveError;
use crate::models::ControlTable;
use crate::table::{self as t, mode};

/// One control-table write of a servo's setup, before it stands.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SetupWrite {
    /// The register's name, as `drive --dry-run` prints it.
    pub name: &'static str,
    /// The register's address.
    pub addr: u16,
    /// The value written, little-endian in `width` bytes.
    pub value: u32,
    /// The register's width, bytes (1, 2 or 4).
    pub width: usize,
    /// What a failed write names.
    pub what: &'static str,
    /// What to do about it.
    pub fix: &'static str,
    /// Whether the register is in the EEPROM area (below 64): read first and written only when
    /// it differs (the EEPROM wears, and each write takes the servo's time).
    pub eeprom: bool,
}

/// The Velocity Limit the setup writes: twice the leg speed, in 0.229 rev/min units (1 to the
/// model's largest, 2047 on the XL330s, 1023 on the XL430 and XM430). Goal Velocity is kept
/// within it.
pub fn velocity_limit_units(schedule: &GaitSchedule, model: &ServoModel) -> u32 {
    (2.0 * schedule.leg_speed_rad_s / x::RAD_S_PER_VELOCITY_UNIT)
        .round()
        .clamp(1.0, f64::from(model.max_velocity_limit)) as u32
}

/// Every servo's setup, in the order written (docs/drive.md): torque off, the bus watchdog
/// cleared, Status Return Level 2 (every instruction answered, so every write's error byte is
/// seen), Return Delay Time 0, the operating mode for the profile, a velocity-based profile,
/// the current and temperature limits, the velocity limit (2 omega), the profile's
/// acceleration (position: 0, the schedule's own run-up limits it; velocity: omega over the
/// run-up) and velocity (1.5 omega), and the bus watchdog; what `drive` writes and `drive
/// --dry-run` prints, for the servos' model `ct` (Current Limit in its units, and not written
/// where the model has no current control).
pub fn setup_writes(schedule: &GaitSchedule, settings: &DriveSettings, ct: &ControlTable) -> Vec<SetupWrite> {
    let model = ct.model;
    let omega = schedule.leg_speed_rad_s;
    let op = match settings.profile {
        Profile::Position => mode::EXTENDED_POSITION,
        Profile::Velocity => mode::VELOCITY,
    };
    let max_profile = f64::from(x::MAX_PROFILE);
    let accel = match settings.profile {
        Profile::Position => 0,
        Profile::Velocity => ((omega / schedule.run_up_s) / x::RAD_S2_PER_ACCELERATION_UNIT)
            .round()
            .clamp(1.0, max_profile) as u32,
    };
    let prof_v = (1.5 * omega / x::RAD_S_PER_VELOCITY_UNIT).round().clamp(1.0, max_profile) as u32;
    let vel_limit = velocity_limit_units(schedule, model);
    let watchdog = (settings.bus_watchdog_s / x::WATCHDOG_UNIT_S)
        .round()
        .clamp(1.0, f64::from(x::MAX_BUS_WATCHDOG)) as u32;
    let w = |name, addr: u16, value, width, what, fix| SetupWrite {
        name,
        addr,
        value,
        width,
        what,
        fix,
        eeprom: addr < t::TORQUE_ENABLE,
    };
    let check_model = "check the model and its firmware (Dynamixel Wizard)";
    let mut writes = vec![
        w("Torque Enable", t::TORQUE_ENABLE, 0, 1, "Torque Enable = 0", "power-cycle the servo"),
        w("Bus Watchdog", t::BUS_WATCHDOG, 0, 1, "Bus Watchdog = 0", "reboot the servo (Dynamixel Wizard)"),
        w(
            "Status Return Level",
            t::STATUS_RETURN_LEVEL,
            2,
            1,
            "Status Return Level = 2",
            "set Status Return Level (68) to 2 in Dynamixel Wizard",
        ),
        w("Return Delay Time (2 us)", t::RETURN_DELAY_TIME, 0, 1, "Return Delay Time = 0", check_model),
        w("Operating Mode", t::OPERATING_MODE, u32::from(op), 1, "Operating Mode", check_model),
        w(
            "Drive Mode (velocity-based profile)",
            t::DRIVE_MODE,
            0,
            1,
            "Drive Mode = 0 (velocity-based profile)",
            check_model,
        ),
        w(
            "Temperature Limit (degC)",
            t::TEMPERATURE_LIMIT,
            u32::from(settings.temperature_limit_c),
            1,
            "Temperature Limit",
            "use a lower --temperature-limit",
        ),
        w("Velocity Limit", t::VELOCITY_LIMIT, vel_limit, 4, "Velocity Limit", "lower leg_speed_rad_s"),
        w(
            "Profile Acceleration",
            t::PROFILE_ACCELERATION,
            accel,
            4,
            "Profile Acceleration",
            "raise response_time_s",
        ),
        w("Profile Velocity", t::PROFILE_VELOCITY, prof_v, 4, "Profile Velocity", "lower leg_speed_rad_s"),
        w(
            "Bus Watchdog (20 ms)",
            t::BUS_WATCHDOG,
            watchdog,
            1,
            "Bus Watchdog",
            "reboot the servo (Dynamixel Wizard)",
        ),
    ];
    if let Some(units) = model.current_limit_units(f64::from(settings.current_limit_ma)) {
        let at = writes.iter().position(|w| w.addr == t::TEMPERATURE_LIMIT).unwrap_or(writes.len());
        let name = match model.reading {
            sandslope::servo::TorqueReading::Current { ma_per_unit } if ma_per_unit != 1.0 => {
                "Current Limit (the model's current unit)"
            }
            _ => "Current Limit (mA)",
        };
        writes
            .insert(at, w(name, t::CURRENT_LIMIT, units, 2, "Current Limit", "use a lower --current-limit"));
    }
    writes
}

/// What the setup did, for the report.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct SetupDone {
    /// EEPROM writes made (per servo and register); the others already held their values.
    pub eeprom_written: usize,
    /// EEPROM writes left out because the register already held the value.
    pub eeprom_kept: usize,
    /// Whether every servo's revolution counter was cleared (the CLEAR instruction); `false`
    /// where a servo's firmware does not know it (the run's goals are then checked from where
    /// the legs stand).
    pub counter_cleared: bool,
    /// The servos' model, as read at the ping (`XL330-M288`).
    pub servo: &'static str,
    /// Its figures (`None` before the ping).
    #[serde(skip)]
    pub model: Option<&'static ServoModel>,
}

/// Pings every servo (its model, and a hardware error latched before the run: refused, exit 2,
/// nothing moved), then writes its setup ([`setup_writes`]) with the torque off and clears its
/// revolution counter.
pub fn setup(
    bus: &mut DynamixelBus,
    schedule: &GaitSchedule,
    settings: &DriveSettings,
) -> Result<SetupDone, DriveError> {
    let model = ping_all(bus, &settings.servos, settings.servo)?;
    check_limits(settings, model)?;
    let writes = setup_writes(schedule, settings, ControlTable::of(model));
    let mut done = SetupDone { servo: model.name, model: Some(model), ..SetupDone::default() };
    for (leg, s) in settings.servos.iter().enumerate() {
        let id = s.id;
        // Each write up to three times: a busy USB adapter (or machine) can miss one reply.
        for write in &writes {
            if write.eeprom && holds(bus, id, write) == Some(true) {
                done.eeprom_kept += 1;
                continue;
            }
            let data = &write.value.to_le_bytes()[..write.width];
            let mut last = None;
            for _ in 0..3 {
                match bus.write(id, write.addr, data) {
                    Ok(_) => {
                        last = None;
                        break;
                    }
                    // The servo answered with an error number (Data Range, Access, ...): no
                    // use repeating it.
                    Err(dynamixel2::TransferError::ReadError(ReadError::MotorError(e))) => {
                        last = Some(format!("{} ({})", status_error_name(e.error_number()), e));
                        break;
                    }
                    Err(e) => last = Some(e.to_string()),
                }
            }
            if let Some(reason) = last {
                return Err(DriveError::Setup { id, leg, what: write.what, reason, fix: write.fix });
            }
            if write.eeprom {
                done.eeprom_written += 1;
            }
        }
    }
    // The revolution counter back within one turn (CLEAR, 0x10: the servo must be still, its
    // torque is off), so that the run's goals start from within -2048 to 6143 pulses
    // (crate::plan). A servo that does not know the instruction keeps its count; the stand-up
    // checks the goals from where it is.
    done.counter_cleared = settings.profile == Profile::Position
        && settings.servos.iter().all(|s| bus.clear_revolution_counter(s.id).is_ok());
    Ok(done)
}

/// Whether the servo already holds `write`'s value; `None` when it could not be read.
fn holds(bus: &mut DynamixelBus, id: u8, write: &SetupWrite) -> Option<bool> {
    let got = match write.width {
        1 => bus.read_u8(id, write.addr).ok().map(|r| u32::from(r.data)),
        2 => bus.read_u16(id, write.addr).ok().map(|r| u32::from(r.data)),
        _ => bus.read_u32(id, write.addr).ok().map(|r| r.data),
    }?;
    Some(got == write.value)
}

/// The name of a status packet's error number (e-Manual, Protocol 2.0, "Status Packet").
pub fn status_error_name(number: u8) -> &'static str {
    match number {
        1 => "Result Fail",
        2 => "Instruction Error",
        3 => "CRC Error",
        4 => "Data Range Error",
        5 => "Data Length Error",
        6 => "Data Limit Error",
        7 => "Access Error",
        _ => "an unknown error number",
    }
}

/// The run's current and temperature limits against what the servos' `model` accepts.
fn check_limits(settings: &DriveSettings, model: &'static ServoModel) -> Result<(), DriveError> {
    if let Some(max) = model.max_current_limit_ma() {
        if f64::from(settings.current_limit_ma) > max {
            return Err(DriveError::ModelLimit {
                what: "--current-limit",
                value: f64::from(settings.current_limit_ma),
                servo: model.name,
                range: format!("0 to {max:.0} mA (its Current Limit (38))"),
                fix: "a lower --current-limit",
            });
        }
    }
    if settings.temperature_limit_c > model.max_temperature_c {
        return Err(DriveError::ModelLimit {
            what: "--temperature-limit",
            value: f64::from(settings.temperature_limit_c),
            servo: model.name,
            range: format!("0 to {} degC (its rated range)", model.max_temperature_c),
            fix: "a lower --temperature-limit",
        });
    }
    Ok(())
}

/// Pings every ID up to three times: one that does not answer is named with the IDs that do;
/// one of a model the driver does not know, of another model than the robot file names or
/// than the servos before it, or with its alert bit set (a hardware error latched before the
/// run: overheating, overload, ...), is refused before anything is written. The servos' model.
pub(crate) fn ping_all(
    bus: &mut DynamixelBus,
    servos: &[crate::config::ServoConfig],
    named: Option<&'static ServoModel>,
) -> Result<&'static ServoModel, DriveError> {
    let baud = bus.baud_rate();
    let mut missing = None;
    let mut found_model: Option<(&'static ServoModel, u8, usize)> = named.map(|m| (m, 0, usize::MAX));
    for (leg, s) in servos.iter().enumerate() {
        let mut ping = bus.ping(s.id);
        for _ in 0..2 {
            if ping.is_ok() {
                break;
            }
            ping = bus.ping(s.id);
        }
        match ping {
            Ok(r) => {
                let wrong = |why: String, fix: String| DriveError::WrongModel {
                    id: s.id,
                    leg,
                    model: r.data.model,
                    why,
                    fix,
                };
                let model = ServoModel::from_model_number(r.data.model).map_err(|_| {
                    wrong(
                        format!("not a supported servo (supported: {})", ServoModel::supported()),
                        "use a supported model, or check the ID".into(),
                    )
                })?;
                match found_model {
                    Some((m, _, usize::MAX)) if m != model => {
                        return Err(wrong(
                            format!("an {}, but the robot file's [servos] model names the {}", model.name, m.name),
                            format!(
                                "set [servos] model = \"{}\" (or leave it out: the model is read from the servos)",
                                model.name
                            ),
                        ))
                    }
                    Some((m, id, first)) if m != model => {
                        return Err(wrong(
                            format!("an {}, but servo ID {id} (leg {first}) is an {}", model.name, m.name),
                            "use one model on every leg".into(),
                        ))
                    }
                    Some(_) => {}
                    None => found_model = Some((model, s.id, leg)),
                }
                if matches!(found_model, Some((_, _, usize::MAX))) {
                    found_model = Some((model, s.id, leg));
                }
                if r.alert {
                    let bits = bus.read_u8(s.id, t::HARDWARE_ERROR_STATUS).map(|r| r.data).unwrap_or(0xFF);
                    return Err(DriveError::Latched { id: s.id, leg, bits });
                }
            }
            Err(_) => {
                if missing.is_none() {
                    missing = Some((s.id, leg));
                }
            }
        }
    }
    if let Some((id, leg)) = missing {
        // Which IDs are on the bus at all: a broadcast ping.
        let mut found: Vec<u8> = bus
            .scan()
            .map(|v| v.into_iter().filter_map(|r| r.ok().map(|r| r.motor_id)).collect())
            .unwrap_or_default();
        found.sort_unstable();
        found.dedup();
        let answered = if found.is_empty() {
            "none".to_string()
        } else {
            found.iter().map(|i| i.to_string()).collect::<Vec<_>>().join(", ")
        };
        return Err(DriveError::Missing { id, leg, baud, answered });
    }
    Ok(found_model.map_or(&ServoModel::XL330_M288, |(m, _, _)| m))
}
