//! The Dynamixel X series' control table (ROBOTIS e-Manual, XL330-M288-T, XL330-M077-T,
//! XL430-W250-T, XM430-W350-T): the addresses the driver and the emulator use, and their
//! sizes, the same in every supported model. What differs between models (which registers a
//! model has, its modes, ranges and factory values) is [`crate::models`].

/// Model Number (2 bytes, read-only; `ServoModel::model_number`).
pub const MODEL_NUMBER: u16 = 0;
/// Firmware Version (1).
pub const FIRMWARE_VERSION: u16 = 6;
/// ID (1).
pub const ID: u16 = 7;
/// Baud Rate (1): 0 9600, 1 57600, 2 115200, 3 1M, 4 2M, 5 3M, 6 4M.
pub const BAUD_RATE: u16 = 8;
/// Return Delay Time (1), 2 us units.
pub const RETURN_DELAY_TIME: u16 = 9;
/// Drive Mode (1): bit 0 reverse, bit 2 time-based profile (0: velocity-based).
pub const DRIVE_MODE: u16 = 10;
/// Operating Mode (1): 0 current, 1 velocity, 3 position, 4 extended position, 5
/// current-based position, 16 PWM.
pub const OPERATING_MODE: u16 = 11;
/// Homing Offset (4), pulses.
pub const HOMING_OFFSET: u16 = 20;
/// Temperature Limit (1), degC (0 to 100; 70 by default).
pub const TEMPERATURE_LIMIT: u16 = 31;
/// Max Voltage Limit (2), 0.1 V.
pub const MAX_VOLTAGE_LIMIT: u16 = 32;
/// Min Voltage Limit (2), 0.1 V.
pub const MIN_VOLTAGE_LIMIT: u16 = 34;
/// Current Limit (2), the model's current unit (absent on the XL430-W250).
pub const CURRENT_LIMIT: u16 = 38;
/// Velocity Limit (4), 0.229 rev/min (0 to the model's `max_velocity_limit`).
pub const VELOCITY_LIMIT: u16 = 44;
/// Shutdown (1): which hardware errors turn the torque off.
pub const SHUTDOWN: u16 = 63;
/// Torque Enable (1); the EEPROM area (below 64) can be written only while it is 0.
pub const TORQUE_ENABLE: u16 = 64;
/// Status Return Level (1).
pub const STATUS_RETURN_LEVEL: u16 = 68;
/// Hardware Error Status (1): bit 0 input voltage, 2 overheating, 3 motor encoder, 4
/// electrical shock, 5 overload.
pub const HARDWARE_ERROR_STATUS: u16 = 70;
/// Bus Watchdog (1), 20 ms units (0 off; the servo sets 100 when it has fired).
pub const BUS_WATCHDOG: u16 = 98;
/// Goal Current (2, signed), the model's current unit (within plus or minus the Current Limit).
pub const GOAL_CURRENT: u16 = 102;
/// Goal Velocity (4), 0.229 rev/min.
pub const GOAL_VELOCITY: u16 = 104;
/// Profile Acceleration (4), 214.577 rev/min^2 (velocity-based profile).
pub const PROFILE_ACCELERATION: u16 = 108;
/// Profile Velocity (4), 0.229 rev/min (velocity-based profile).
pub const PROFILE_VELOCITY: u16 = 112;
/// Goal Position (4), pulses.
pub const GOAL_POSITION: u16 = 116;
/// Moving (1).
pub const MOVING: u16 = 122;
/// Present Current (2, signed), the model's current unit (Present Load, 0.1 %, on the
/// XL430-W250: `ServoModel::reading`).
pub const PRESENT_CURRENT: u16 = 126;
/// Present Velocity (4, signed), 0.229 rev/min.
pub const PRESENT_VELOCITY: u16 = 128;
/// Present Position (4, signed), pulses.
pub const PRESENT_POSITION: u16 = 132;
/// Present Input Voltage (2), 0.1 V.
pub const PRESENT_INPUT_VOLTAGE: u16 = 144;
/// Present Temperature (1), degC.
pub const PRESENT_TEMPERATURE: u16 = 146;
/// Size of the table the emulator keeps (addresses 0 to 227).
pub const TABLE_SIZE: usize = 228;

/// The block the driver reads every cycle: Present Current (126) to Present Temperature (146).
pub const STATE_BLOCK: (u16, u16) = (PRESENT_CURRENT, PRESENT_TEMPERATURE + 1 - PRESENT_CURRENT);

/// Bus Watchdog value a servo sets after the watchdog fired.
pub const WATCHDOG_FIRED: u8 = 100;

/// The first register written in `addr..end` whose new value lies outside its range in
/// model `ct`'s control table (ROBOTIS e-Manual), by name.
pub(crate) fn out_of_range(
    table: &[u8; TABLE_SIZE],
    addr: u16,
    end: usize,
    ct: &crate::models::ControlTable,
) -> Option<&'static str> {
    use sandslope::servo::model as x;
    let max_current = ct.model.max_current_limit.unwrap_or(0);
    let u8_at = |a: u16| table[a as usize];
    let u16_at = |a: u16| u16::from_le_bytes([table[a as usize], table[a as usize + 1]]);
    let i32_le = |a: u16| {
        let a = a as usize;
        i32::from_le_bytes([table[a], table[a + 1], table[a + 2], table[a + 3]])
    };
    let touched =
        |reg: u16, width: usize| usize::from(addr) < usize::from(reg) + width && end > usize::from(reg);
    let i32_at = |a: u16| i32_le(a);
    let i16_at = |a: u16| i16::from_le_bytes([table[a as usize], table[a as usize + 1]]);
    let mode = u8_at(OPERATING_MODE);
    let checks: [(&'static str, u16, usize, bool); 13] = [
        ("Return Delay Time", RETURN_DELAY_TIME, 1, u8_at(RETURN_DELAY_TIME) <= x::MAX_RETURN_DELAY),
        ("Operating Mode", OPERATING_MODE, 1, ct.operating_modes.contains(&mode)),
        (
            "Temperature Limit",
            TEMPERATURE_LIMIT,
            1,
            u8_at(TEMPERATURE_LIMIT) <= x::MAX_TEMPERATURE_LIMIT_REGISTER,
        ),
        ("Current Limit", CURRENT_LIMIT, 2, u16_at(CURRENT_LIMIT) <= max_current),
        (
            "Velocity Limit",
            VELOCITY_LIMIT,
            4,
            (0..=ct.model.max_velocity_limit as i32).contains(&i32_at(VELOCITY_LIMIT)),
        ),
        ("Torque Enable", TORQUE_ENABLE, 1, u8_at(TORQUE_ENABLE) <= 1),
        ("Status Return Level", STATUS_RETURN_LEVEL, 1, u8_at(STATUS_RETURN_LEVEL) <= 2),
        ("Bus Watchdog", BUS_WATCHDOG, 1, u8_at(BUS_WATCHDOG) <= x::MAX_BUS_WATCHDOG),
        (
            "Goal Current",
            GOAL_CURRENT,
            2,
            i32::from(i16_at(GOAL_CURRENT)).abs() <= i32::from(u16_at(CURRENT_LIMIT)),
        ),
        (
            "Goal Velocity",
            GOAL_VELOCITY,
            4,
            i32_at(GOAL_VELOCITY).unsigned_abs() <= i32_at(VELOCITY_LIMIT).unsigned_abs(),
        ),
        (
            "Profile Acceleration",
            PROFILE_ACCELERATION,
            4,
            (0..=x::MAX_PROFILE as i32).contains(&i32_at(PROFILE_ACCELERATION)),
        ),
        (
            "Profile Velocity",
            PROFILE_VELOCITY,
            4,
            (0..=x::MAX_PROFILE as i32).contains(&i32_at(PROFILE_VELOCITY)),
        ),
        ("Goal Position", GOAL_POSITION, 4, {
            let g = i32_at(GOAL_POSITION);
            let l = x::EXTENDED_GOAL_LIMIT_PULSES;
            let (lo, hi) = x::POSITION_GOAL_RANGE_PULSES;
            match mode {
                mode::EXTENDED_POSITION | 5 => (-l..=l).contains(&g),
                mode::POSITION => (lo..=hi).contains(&g),
                _ => true,
            }
        }),
    ];
    checks.iter().find(|(_, reg, width, ok)| touched(*reg, *width) && !ok).map(|c| c.0)
}

/// Operating modes the driver uses.
pub mod mode {
    /// Velocity control.
    pub const VELOCITY: u8 = 1;
    /// Position control within one turn.
    pub const POSITION: u8 = 3;
    /// Extended (multi-turn) position control.
    pub const EXTENDED_POSITION: u8 = 4;
}

/// The present state decoded from [`STATE_BLOCK`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PresentState {
    /// Present Current, mA.
    pub current_ma: i16,
    /// Present Velocity, 0.229 rev/min.
    pub velocity: i32,
    /// Present Position, pulses.
    pub position: i32,
    /// Present Input Voltage, 0.1 V.
    pub voltage: u16,
    /// Present Temperature, degC.
    pub temperature_c: u8,
}

impl PresentState {
    /// Decodes the bytes read from [`STATE_BLOCK`]; `None` if there are too few.
    pub fn decode(b: &[u8]) -> Option<PresentState> {
        let at = |a: u16| usize::from(a - PRESENT_CURRENT);
        if b.len() < usize::from(STATE_BLOCK.1) {
            return None;
        }
        let u32_at = |a| u32::from_le_bytes([b[at(a)], b[at(a) + 1], b[at(a) + 2], b[at(a) + 3]]);
        Some(PresentState {
            current_ma: i16::from_le_bytes([b[0], b[1]]),
            velocity: u32_at(PRESENT_VELOCITY) as i32,
            position: u32_at(PRESENT_POSITION) as i32,
            voltage: u16::from_le_bytes([b[at(PRESENT_INPUT_VOLTAGE)], b[at(PRESENT_INPUT_VOLTAGE) + 1]]),
            temperature_c: b[at(PRESENT_TEMPERATURE)],
        })
    }
}

/// One servo's read: its state and the status packet's alert bit, or the read error.
pub(crate) type StateRead = Result<(PresentState, bool), dynamixel2::ReadError>;

/// Reads every servo's state block; per servo `Ok((state, alert))` or the read error.
///
/// The replies are matched to their IDs: when a servo does not answer, `dynamixel2` reads the
/// next servo's reply in its place (and refuses it, a wrong packet ID), so every servo after a
/// silent one would lose its row. The IDs whose replies were seen in another's place answered:
/// they are read again on their own Sync Read, and only the silent servo loses its row.
pub(crate) fn read_states(
    bus: &mut dynamixel2::Bus<Vec<u8>, Vec<u8>>,
    ids: &[u8],
) -> Result<Vec<StateRead>, String> {
    let mut out = read_states_once(bus, ids)?;
    let answered: Vec<u8> = out
        .iter()
        .filter_map(|r| match r {
            Err(dynamixel2::ReadError::InvalidMessage(dynamixel2::InvalidMessage::InvalidPacketId(e))) => {
                Some(e.actual)
            }
            _ => None,
        })
        .collect();
    let again: Vec<usize> =
        (0..ids.len()).filter(|&k| out[k].is_err() && answered.contains(&ids[k])).collect();
    if !again.is_empty() && again.len() < ids.len() {
        let retry: Vec<u8> = again.iter().map(|&k| ids[k]).collect();
        for (&k, r) in again.iter().zip(read_states_once(bus, &retry)?) {
            if r.is_ok() {
                out[k] = r;
            }
        }
    }
    Ok(out)
}

/// One Sync Read of the state block, each reply in its ID's slot in the order asked.
fn read_states_once(
    bus: &mut dynamixel2::Bus<Vec<u8>, Vec<u8>>,
    ids: &[u8],
) -> Result<Vec<StateRead>, String> {
    // dynamixel2 calls back once per ID, in the order asked: the k-th call is ids[k]'s.
    let mut out: Vec<Option<StateRead>> = (0..ids.len()).map(|_| None).collect();
    let mut k = 0usize;
    bus.sync_read_cb(ids, STATE_BLOCK.0, STATE_BLOCK.1, |r| {
        let slot = k;
        k += 1;
        let value = match r {
            Ok(resp) => PresentState::decode(resp.data).map(|s| (s, resp.alert)).ok_or_else(|| {
                dynamixel2::ReadError::Io(std::io::Error::new(
                    std::io::ErrorKind::InvalidData,
                    "short state block",
                ))
            }),
            Err(e) => Err(e),
        };
        if let Some(o) = out.get_mut(slot) {
            *o = Some(value);
        }
    })
    .map_err(|e| e.to_string())?;
    Ok(out
        .into_iter()
        .map(|o| o.unwrap_or_else(|| Err(dynamixel2::ReadError::Io(std::io::ErrorKind::TimedOut.into()))))
        .collect())
}
