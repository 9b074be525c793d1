//! The bench's zeroing chore (docs/drive.md, "Zero offsets"): with every leg set by hand at
//! leg angle 0 (the C's circle centre straight ahead of the axle, docs/model.md §15) and the
//! torque off, each servo's Present Position (132) is its zero offset. Nothing is written to a
//! servo: every ID is pinged (its model checked as a run's setup checks it) and read.

use sandslope::servo::ServoModel;

use crate::config::{DynamixelBus, ServoConfig};
use crate::error::DriveError;
use crate::table as t;

/// The widest zero offset a robot file takes, pulses (Homing Offset (20)'s range, the same in
/// every supported model).
pub const ZERO_OFFSET_LIMIT_PULSES: i32 = 1_044_479;

/// Each servo's Present Position, pulses, in leg order, after a ping of every ID (a missing
/// servo, an unsupported model or another model than `named` refused as a run refuses it);
/// and the servos' model.
pub fn read_zero_offsets(
    bus: &mut DynamixelBus,
    servos: &[ServoConfig],
    named: Option<&'static ServoModel>,
) -> Result<(Vec<i32>, &'static ServoModel), DriveError> {
    let model = crate::setup::ping_all(bus, servos, named)?;
    let mut out = Vec::with_capacity(servos.len());
    for (leg, s) in servos.iter().enumerate() {
        let mut read = bus.read_u32(s.id, t::PRESENT_POSITION);
        for _ in 0..2 {
            if read.is_ok() {
                break;
            }
            read = bus.read_u32(s.id, t::PRESENT_POSITION);
        }
        let position = read
            .map_err(|e| DriveError::Setup {
                id: s.id,
                leg,
                what: "a read of Present Position (132)",
                reason: e.to_string(),
                fix: "check its cable and power",
            })?
            .data as i32;
        if position.abs() > ZERO_OFFSET_LIMIT_PULSES {
            return Err(DriveError::Setup {
                id: s.id,
                leg,
                what: "a zero offset within -1,044,479 to 1,044,479 pulses",
                reason: format!(
                    "its Present Position is {position} pulses (a revolution count kept from earlier runs)"
                ),
                fix: "power-cycle the servo (its position comes back within one turn) and set the leg again",
            });
        }
        out.push(position);
    }
    Ok((out, model))
}

/// [`read_zero_offsets`] on the run's bus: its port at its baud rate, or the emulator (whose
/// shafts sit at the robot file's zero offsets). The outer error: the bus did not open.
pub fn zero_offsets_of(
    config: &crate::session::DriveConfig,
) -> Result<Result<(Vec<i32>, &'static ServoModel), DriveError>, crate::session::SessionError> {
    use crate::session::{emulator_config, BusChoice, SessionError};
    let (port, emulator) = match &config.bus {
        BusChoice::Port { path, baud } => {
            let port = serial2::SerialPort::open(path, *baud)
                .map_err(|e| SessionError::Port { path: path.clone(), reason: e.to_string() })?;
            (port, None)
        }
        BusChoice::Emulate(o) => {
            let (emu, port) = crate::Emulator::start(&emulator_config(config, o)?)
                .map_err(|e| SessionError::Emulator(e.to_string()))?;
            (port, Some(emu))
        }
    };
    let mut bus = dynamixel2::Bus::new(port).map_err(|e| SessionError::Bus(format!("{e:?}")))?;
    let read = read_zero_offsets(&mut bus, &config.settings.servos, config.settings.servo);
    drop(bus);
    drop(emulator);
    Ok(read)
}
