//! A bus of virtual Dynamixel servos (XL330-M288s by default, any model of
//! [`crate::models`]) on a pseudo-terminal (docs/drive.md, "The emulator").
//!
//! Each virtual servo keeps its model's control table ([`crate::models`]), answers Protocol 2.0 byte for byte
//! ([`crate::packet`]), moves its shaft as its operating mode and goal say (velocity-based
//! profile: velocity and acceleration limits from Profile Velocity and Profile Acceleration,
//! or the Velocity Limit) and reports as Present Current the torque its leg needs in the sand,
//! `I = tau / K_t` (docs/model.md §19), plus Gaussian sensor noise. The torque comes from a
//! walk of the stride simulator (`sandslope::simulate`) on the given terrain and slope, looked
//! up by the leg's angle: a leg at angle psi feels what the simulated leg of the same tripod
//! felt at that angle of its stride, stride after stride (the simulated strides played in
//! turn). The driver talks to it through the same `dynamixel2::Bus` over a `serial2` port as
//! to a real bus; only the opening differs (a pty pair instead of a device path).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

use sandslope::infer::servo::{sensor_walk_settings, simulated_legs, LegTrace};
use sandslope::servo::model as x;
use sandslope::servo::GaitSchedule;
use sandslope::simulate::simulate;
use sandslope::{Robot, Scenario, Terrain};
use serial2::SerialPort;

use crate::clock::{Clock, ClockKind, REPLY_TIMEOUT_S};
use crate::driver::ServoConfig;
use crate::models::ControlTable;
use crate::packet::{self, error, inst, Instruction, Parsed, Parser};
use crate::table::{self as t, mode};

/// Faults the emulator can be told to show, for tests and demonstrations.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EmulatorFaults {
    /// `(id, s)`: servo `id` stops answering (and obeying) `s` seconds after the start.
    pub silent: Option<(u8, f64)>,
    /// `(id, s)`: servo `id`'s status packets fail their CRC from `s` seconds on.
    pub corrupt: Option<(u8, f64)>,
    /// `(s, length)`: the bus hangs for `length` seconds from `s` (nothing is answered).
    pub freeze: Option<(f64, f64)>,
    /// `(s, k_s)`: the sand weakens to shear strength `k_s` N/m^3 `s` seconds after the start.
    pub weaken: Option<(f64, f64)>,
    /// `(id, s)`: servo `id` refuses every goal from `s` seconds on with a Data Range Error, as
    /// a servo refuses a goal outside its range (a Sync Write's refusal is silent).
    pub reject: Option<(u8, f64)>,
    /// `(id, bits)`: servo `id` starts with a hardware error latched (Hardware Error Status
    /// `bits`, its alert bit set in every status packet), as one left overloaded by an earlier run.
    pub latched: Option<(u8, u8)>,
}

/// What the emulator emulates.
#[derive(Debug, Clone)]
pub struct EmulatorConfig {
    /// The servos as mounted (IDs, directions, zero offsets), in leg order.
    pub servos: Vec<ServoConfig>,
    /// The robot.
    pub robot: Robot,
    /// The terrain.
    pub terrain: Terrain,
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Present Current noise, mA (standard deviation).
    pub current_noise_ma: f64,
    /// Seed of the noise.
    pub seed: u64,
    /// Present Current offset, mA: a current sensor's zero bias, added to every reading (the
    /// torque-free swing then reads it too). Empty: none; one value: every servo; else one per
    /// servo in leg order.
    pub current_offset_ma: Vec<f64>,
    /// Strides the stride simulator walks (played in turn, the first left out).
    pub simulated_strides: usize,
    /// Faults to show.
    pub faults: EmulatorFaults,
    /// Model number reported (1200, the XL330-M288): a supported model's number makes the
    /// servos that model (its control table and figures); another number (a test of the
    /// driver's refusal) reports it over an XL330-M288's table.
    pub model_number: u16,
    /// Firmware version reported.
    pub firmware: u8,
    /// Whole turns every shaft starts away from its zero offset (a revolution count kept from
    /// earlier runs in extended position mode; 0: within the first turn).
    pub initial_turns: i32,
    /// Whether the servos know the Clear instruction (firmware 42 and later do); `false`
    /// emulates older firmware, which answers it with an Instruction Error.
    pub clear_supported: bool,
    /// The clock the servos keep (`--emulate-clock`; [`crate::clock`]).
    pub clock: ClockKind,
}

impl EmulatorConfig {
    /// Six XL330-M288s (IDs 1-6, directions +1, zero offsets 0) under the robot on the terrain.
    pub fn new(robot: Robot, terrain: Terrain, slope_deg: f64, servos: Vec<ServoConfig>) -> EmulatorConfig {
        EmulatorConfig {
            servos,
            robot,
            terrain,
            slope_deg,
            current_noise_ma: 10.0,
            seed: 1,
            current_offset_ma: vec![],
            simulated_strides: 8,
            faults: EmulatorFaults::default(),
            model_number: sandslope::servo::ServoModel::XL330_M288.model_number,
            firmware: 46,
            initial_turns: 0,
            clear_supported: true,
            clock: ClockKind::Real,
        }
    }
}

/// Why the emulator could not start.
#[derive(Debug, thiserror::Error)]
pub enum EmulatorError {
    /// The pseudo-terminal pair could not be opened.
    #[error("cannot open a pseudo-terminal pair for the emulator: {0}")]
    Pty(std::io::Error),
    /// The stride simulator refused the walk.
    #[error("the emulator's stride simulator cannot walk this robot on this terrain: {0}")]
    Simulator(String),
}

/// What the emulator saw, returned when it stops: the state of each servo's torque as its own
/// control table holds it (not as the driver believes).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EmulatorReport {
    /// `(id, torque enabled)` per servo at the end.
    pub torque_enabled: Vec<(u8, bool)>,
    /// Instruction packets received with a valid CRC.
    pub packets: usize,
    /// Packets received with a bad CRC.
    pub bad_crc: usize,
    /// Each servo's Bus Watchdog at the end (100: it fired).
    pub watchdog: Vec<(u8, u8)>,
    /// `(t, k_s)`: the sand weakened to `k_s` N/m^3 at gait time `t` s (the log's `time_s`),
    /// when `--emulate-weaken` set a weakening that the run reached and the gait started.
    pub weakened: Option<(f64, f64)>,
}

/// A walk of the stride simulator, as the legs' drive torque against their angle.
#[derive(Debug, Clone)]
struct Walk {
    legs: Vec<LegTrace>,
}

impl Walk {
    fn new(robot: &Robot, terrain: Terrain, slope_deg: f64, strides: usize) -> Result<Walk, EmulatorError> {
        let schedule = GaitSchedule::new(robot, 2 * robot.stance_legs() as usize)
            .map_err(|e| EmulatorError::Simulator(e.to_string()))?;
        let rate_hz = 500.0;
        // The driver's run-up (docs/model.md §19) walked too, and the strides after it whole.
        let settings = sensor_walk_settings(
            strides.max(3) as f64 * schedule.period_s + schedule.run_up_s,
            rate_hz,
            schedule.run_up_s,
        )
        .map_err(|e| EmulatorError::Simulator(e.to_string()))?;
        let scenario = Scenario::new(robot.clone(), terrain, None, None)
            .map_err(|e| EmulatorError::Simulator(e.to_string()))?;
        let slope = sandslope::SignedSlope::from_degrees(slope_deg)
            .map_err(|e| EmulatorError::Simulator(e.to_string()))?;
        let sim =
            simulate(&scenario, slope, &settings).map_err(|e| EmulatorError::Simulator(e.to_string()))?;
        Ok(Walk { legs: simulated_legs(&schedule, &sim) })
    }

    /// Drive torque of leg `leg` at gait angle `angle` (N m): the simulated leg's at the same
    /// angle, strides beyond the simulated ones wrapped back onto strides 1 and later.
    fn torque(&self, leg: usize, angle: f64) -> f64 {
        let trace = &self.legs[leg];
        let n = trace.angle_rad.len();
        if n < 2 {
            return 0.0;
        }
        let a0 = trace.angle_rad[0];
        let span = trace.angle_rad[n - 1] - a0;
        let turn = 2.0 * std::f64::consts::PI;
        let mut rel = angle - a0;
        if rel > span {
            // Play strides 1.. again: wrap by whole turns into [turn, span].
            let usable = ((span - turn) / turn).floor().max(1.0) * turn;
            rel = turn + (rel - turn).rem_euclid(usable);
        }
        // The sample nearest the angle: the simulated angle does not grow at omega from a0
        // (the legs run up over the response time, as the driver commands them), so it is
        // looked up, not computed from the time.
        let target = a0 + rel.max(0.0);
        let i = trace.angle_rad.partition_point(|&a| a < target).min(n - 1);
        let i =
            if i > 0 && target - trace.angle_rad[i - 1] < trace.angle_rad[i] - target { i - 1 } else { i };
        trace.torque_n_m[i]
    }
}

/// The emulated position loop's gain, 1/s: a shaft 0.1 rad behind its goal turns at 4 rad/s
/// (a time constant of 25 ms, the order of an X-series servo's step response at its default
/// gains).
pub const POSITION_GAIN_PER_S: f64 = 40.0;

/// One virtual servo.
#[derive(Debug, Clone)]
struct VirtualServo {
    table: [u8; t::TABLE_SIZE],
    /// Shaft position, pulses (multi-turn).
    position: f64,
    /// Shaft velocity, rad/s.
    velocity: f64,
    last_update: f64,
    last_seen: f64,
    current_ema: f64,
    /// The current sensor's zero bias, mA.
    offset_ma: f64,
    config: ServoConfig,
    leg: usize,
    /// Refuses every goal (the `reject` fault).
    refuse_goals: bool,
    /// Knows the Clear instruction.
    clear_supported: bool,
    /// Its model's control table.
    ct: &'static ControlTable,
}

impl VirtualServo {
    fn new(config: ServoConfig, leg: usize, model: u16, firmware: u8) -> VirtualServo {
        let ct = sandslope::servo::ServoModel::from_model_number(model)
            .map_or(&crate::models::XL330_M288, ControlTable::of);
        let mut table = [0u8; t::TABLE_SIZE];
        let mut s = VirtualServo {
            table: [0; t::TABLE_SIZE],
            position: f64::from(config.zero_offset_pulses),
            velocity: 0.0,
            last_update: 0.0,
            last_seen: 0.0,
            current_ema: 0.0,
            offset_ma: 0.0,
            config,
            leg,
            refuse_goals: false,
            clear_supported: true,
            ct,
        };
        table[0..2].copy_from_slice(&model.to_le_bytes());
        table[t::FIRMWARE_VERSION as usize] = firmware;
        table[t::ID as usize] = config.id;
        table[t::BAUD_RATE as usize] = 3;
        table[t::RETURN_DELAY_TIME as usize] = 250;
        table[t::OPERATING_MODE as usize] = mode::POSITION;
        table[t::TEMPERATURE_LIMIT as usize] = ct.temperature_limit;
        table[t::MAX_VOLTAGE_LIMIT as usize..][..2].copy_from_slice(&ct.voltage_limits.0.to_le_bytes());
        table[t::MIN_VOLTAGE_LIMIT as usize..][..2].copy_from_slice(&ct.voltage_limits.1.to_le_bytes());
        table[t::CURRENT_LIMIT as usize..][..2].copy_from_slice(&ct.current_limit.to_le_bytes());
        table[t::VELOCITY_LIMIT as usize..][..4].copy_from_slice(&ct.velocity_limit.to_le_bytes());
        table[t::SHUTDOWN as usize] = ct.shutdown;
        table[t::STATUS_RETURN_LEVEL as usize] = 2;
        s.table = table;
        s
    }

    fn u8_at(&self, a: u16) -> u8 {
        self.table[a as usize]
    }
    fn u16_at(&self, a: u16) -> u16 {
        u16::from_le_bytes([self.table[a as usize], self.table[a as usize + 1]])
    }
    fn i32_at(&self, a: u16) -> i32 {
        let a = a as usize;
        i32::from_le_bytes([self.table[a], self.table[a + 1], self.table[a + 2], self.table[a + 3]])
    }
    fn put(&mut self, a: u16, bytes: &[u8]) {
        self.table[a as usize..][..bytes.len()].copy_from_slice(bytes);
    }
    fn torque_on(&self) -> bool {
        self.u8_at(t::TORQUE_ENABLE) == 1
    }

    /// Leg angle in the gait's frame, rad.
    fn leg_angle(&self) -> f64 {
        f64::from(self.config.direction)
            * (self.position - f64::from(self.config.zero_offset_pulses))
            * x::RAD_PER_PULSE
    }

    /// Moves the shaft to time `now` and refreshes the present values.
    fn advance(&mut self, now: f64, walk: &Walk, noise: &mut Noise, noise_ma: f64) {
        let dt = (now - self.last_update).max(0.0);
        self.last_update = now;
        let wd = self.u8_at(t::BUS_WATCHDOG);
        if self.torque_on()
            && (1..=127).contains(&wd)
            && now - self.last_seen > f64::from(wd) * x::WATCHDOG_UNIT_S
        {
            // The watchdog fired: the servo stops where it is and marks it (e-Manual, Bus Watchdog).
            self.table[t::BUS_WATCHDOG as usize] = t::WATCHDOG_FIRED;
            let here = self.position.round() as i32;
            self.put(t::GOAL_POSITION, &here.to_le_bytes());
            self.put(t::GOAL_VELOCITY, &0i32.to_le_bytes());
        }
        let vel_limit = f64::from(self.i32_at(t::VELOCITY_LIMIT)) * x::RAD_S_PER_VELOCITY_UNIT;
        let acc = f64::from(self.i32_at(t::PROFILE_ACCELERATION)) * x::RAD_S2_PER_ACCELERATION_UNIT;
        let prof_v = f64::from(self.i32_at(t::PROFILE_VELOCITY)) * x::RAD_S_PER_VELOCITY_UNIT;
        let fired = self.u8_at(t::BUS_WATCHDOG) == t::WATCHDOG_FIRED;
        let target_v = if !self.torque_on() {
            0.0
        } else if self.u8_at(t::OPERATING_MODE) == mode::VELOCITY {
            if fired {
                0.0
            } else {
                (f64::from(self.i32_at(t::GOAL_VELOCITY)) * x::RAD_S_PER_VELOCITY_UNIT)
                    .clamp(-vel_limit, vel_limit)
            }
        } else {
            // Position control: a proportional pull on the error (POSITION_GAIN_PER_S), capped
            // by the profile velocity, and by the speed from which the profile acceleration
            // can still stop at the goal (a trapezoidal profile: no overshoot).
            let vmax = if prof_v > 0.0 { prof_v.min(vel_limit) } else { vel_limit };
            let to_go = (f64::from(self.i32_at(t::GOAL_POSITION)) - self.position) * x::RAD_PER_PULSE;
            let brake = if acc > 0.0 { (2.0 * acc * to_go.abs()).sqrt() } else { f64::INFINITY };
            (POSITION_GAIN_PER_S * to_go).clamp(-vmax.min(brake), vmax.min(brake))
        };
        if self.torque_on() && acc > 0.0 {
            let dv = (target_v - self.velocity).clamp(-acc * dt, acc * dt);
            self.velocity += dv;
        } else {
            self.velocity = target_v;
        }
        if !self.torque_on() {
            self.velocity = 0.0;
        }
        self.position += self.velocity * dt / x::RAD_PER_PULSE;
        // The leg's drive torque in the sand, as the servo's current (its own sign).
        let tau = if self.torque_on() { walk.torque(self.leg, self.leg_angle()) } else { 0.0 };
        let dir = f64::from(self.config.direction);
        // The sensor's noise and bias are in mA (as a torque by K_t on a load-reporting model);
        // the reading is in the model's units of address 126, within its Current Limit (or
        // the load's +/-100 %).
        let model = self.ct.model;
        let tau_read = dir * tau + model.torque_from_current_ma(noise.gauss() * noise_ma + self.offset_ma);
        let limit = if self.ct.current_control { f64::from(self.u16_at(t::CURRENT_LIMIT)) } else { 1000.0 };
        let reading = model.reading_from_torque(tau_read).clamp(-limit, limit);
        let current = model.current_ma_from_reading(reading);
        let stall_ma = 1000.0 * model.stall_current_a;
        self.current_ema += (current * current - self.current_ema) * (dt / 30.0).min(1.0);
        let temp = 28.0 + 25.0 * self.current_ema / (stall_ma * stall_ma);
        let voltage = (10.0 * model.nominal_voltage_v).round() - (current.abs() / 500.0).round()
            + noise.gauss().round().clamp(-1.0, 1.0);
        self.put(t::PRESENT_CURRENT, &(reading.round() as i16).to_le_bytes());
        let v_units = (self.velocity / x::RAD_S_PER_VELOCITY_UNIT).round() as i32;
        self.put(t::PRESENT_VELOCITY, &v_units.to_le_bytes());
        self.put(t::PRESENT_POSITION, &(self.position.round() as i32).to_le_bytes());
        self.put(t::PRESENT_INPUT_VOLTAGE, &(voltage.max(0.0) as u16).to_le_bytes());
        self.table[t::PRESENT_TEMPERATURE as usize] = temp.round().clamp(0.0, 255.0) as u8;
        self.table[t::MOVING as usize] = u8::from(self.velocity.abs() > 0.01);
        if temp.round() > f64::from(self.u8_at(t::TEMPERATURE_LIMIT)) {
            self.table[t::HARDWARE_ERROR_STATUS as usize] |= 1 << 2;
            self.table[t::TORQUE_ENABLE as usize] = 0;
        }
    }

    fn error_byte(&self, e: u8) -> u8 {
        if self.u8_at(t::HARDWARE_ERROR_STATUS) != 0 {
            e | error::ALERT
        } else {
            e
        }
    }

    /// Writes `data` at `addr` as a Write instruction does; the status error number.
    fn write(&mut self, addr: u16, data: &[u8]) -> u8 {
        let end = usize::from(addr) + data.len();
        if end > t::TABLE_SIZE || data.is_empty() {
            return error::DATA_LENGTH;
        }
        if addr < t::TORQUE_ENABLE && self.torque_on() {
            return error::ACCESS;
        }
        if (addr..addr + data.len() as u16).any(|a| a < 64 && matches!(a, 0..=6)) {
            return error::ACCESS;
        }
        // A register the model does not have (the XL430-W250's Current Limit and Goal Current).
        let touches = |reg: u16, width: u16| addr < reg + width && end > usize::from(reg);
        if !self.ct.current_control && (touches(t::CURRENT_LIMIT, 2) || touches(t::GOAL_CURRENT, 2)) {
            return error::ACCESS;
        }
        if (self.u8_at(t::BUS_WATCHDOG) == t::WATCHDOG_FIRED || self.refuse_goals)
            && (addr == t::GOAL_POSITION || addr == t::GOAL_VELOCITY)
        {
            return error::DATA_RANGE;
        }
        // The e-Manual's ranges: a value outside its register's range is refused whole, with a
        // Data Range Error, and nothing of the write is kept.
        let before = self.table;
        self.put(addr, data);
        if t::out_of_range(&self.table, addr, end, self.ct).is_some() {
            self.table = before;
            return error::DATA_RANGE;
        }
        if addr == t::TORQUE_ENABLE && data[0] == 1 {
            // Torque on holds the present position (as a real servo's goal follows it).
            let here = self.position.round() as i32;
            self.put(t::GOAL_POSITION, &here.to_le_bytes());
        }
        0
    }

    /// The Clear instruction: the revolution counter back within one turn (0 to 4095), only
    /// while the shaft is still (else Result Fail).
    fn clear(&mut self) -> u8 {
        if self.velocity.abs() > 0.01 {
            return error::RESULT_FAIL;
        }
        self.position = self.position.rem_euclid(x::PULSES_PER_REV);
        self.put(t::PRESENT_POSITION, &(self.position.round() as i32).to_le_bytes());
        0
    }

    fn read(&self, addr: u16, len: u16) -> Result<Vec<u8>, u8> {
        let end = usize::from(addr) + usize::from(len);
        if end > t::TABLE_SIZE {
            return Err(error::DATA_LENGTH);
        }
        Ok(self.table[usize::from(addr)..end].to_vec())
    }
}

/// Gaussian noise from a seeded generator (splitmix64 and Box-Muller).
#[derive(Debug, Clone)]
struct Noise(u64);

impl Noise {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn gauss(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }
}

/// The virtual bus: servos, walks and faults; answers instruction packets.
#[derive(Debug, Clone)]
pub struct VirtualBus {
    servos: Vec<VirtualServo>,
    walk: Walk,
    weak_walk: Option<Walk>,
    faults: EmulatorFaults,
    noise: Noise,
    noise_ma: f64,
    parser_packets: usize,
    bad_crc: usize,
    /// Replies a silent servo owed since [`VirtualBus::take_missed`] (each a reply timeout).
    missed: usize,
}

impl VirtualBus {
    /// The bus of `config` (runs the stride simulator once, twice with a weakening).
    pub fn new(config: &EmulatorConfig) -> Result<VirtualBus, EmulatorError> {
        let walk =
            Walk::new(&config.robot, config.terrain.clone(), config.slope_deg, config.simulated_strides)?;
        let weak_walk = match config.faults.weaken {
            Some((_, k_s)) => {
                let k_n = config
                    .terrain
                    .at(sandslope::Slope::from_signed_degrees(config.slope_deg.abs())
                        .map_err(|e| EmulatorError::Simulator(e.to_string()))?)
                    .k_n;
                let weak =
                    Terrain::constant(k_n, k_s).map_err(|e| EmulatorError::Simulator(e.to_string()))?;
                Some(Walk::new(&config.robot, weak, config.slope_deg, config.simulated_strides)?)
            }
            None => None,
        };
        let servos = config
            .servos
            .iter()
            .enumerate()
            .map(|(leg, c)| {
                let mut s = VirtualServo::new(*c, leg, config.model_number, config.firmware);
                let o = &config.current_offset_ma;
                s.offset_ma = if o.len() == 1 { o[0] } else { o.get(leg).copied().unwrap_or(0.0) };
                s.position += f64::from(config.initial_turns) * x::PULSES_PER_REV;
                s.clear_supported = config.clear_supported;
                if let Some((id, bits)) = config.faults.latched {
                    if id == c.id {
                        s.table[t::HARDWARE_ERROR_STATUS as usize] = bits;
                    }
                }
                s
            })
            .collect();
        Ok(VirtualBus {
            servos,
            walk,
            weak_walk,
            faults: config.faults,
            noise: Noise(config.seed),
            noise_ma: config.current_noise_ma,
            parser_packets: 0,
            bad_crc: 0,
            missed: 0,
        })
    }

    fn advance_all(&mut self, now: f64) {
        // In steps of at most 2 ms, as the real-time thread ticks (a virtual cycle comes at once).
        let last = self.servos.iter().map(|s| s.last_update).fold(now, f64::min);
        let steps = ((now - last) / 0.002).ceil().clamp(1.0, 1e6) as usize;
        for i in 1..=steps {
            let t = if i == steps { now } else { last + (now - last) * i as f64 / steps as f64 };
            let walk = match (&self.weak_walk, self.faults.weaken) {
                (Some(w), Some((at, _))) if t >= at => w,
                _ => &self.walk,
            };
            // A silent servo still runs (its data line is what failed): its watchdog stops it.
            for s in &mut self.servos {
                s.advance(t, walk, &mut self.noise, self.noise_ma);
            }
        }
    }

    /// The replies silent servos owed since the last call (each a reply timeout the driver waited).
    pub fn take_missed(&mut self) -> usize {
        std::mem::take(&mut self.missed)
    }

    fn silent(&self, id: u8, now: f64) -> bool {
        matches!(self.faults.silent, Some((sid, at)) if sid == id && now >= at)
    }

    /// Whether the bus is frozen at `now`.
    pub fn frozen(&self, now: f64) -> bool {
        matches!(self.faults.freeze, Some((at, len)) if now >= at && now < at + len)
    }

    /// The bytes the servos send back for one parsed packet received at `now` s.
    pub fn respond(&mut self, parsed: Parsed, now: f64) -> Vec<u8> {
        self.advance_all(now);
        let ins = match parsed {
            Parsed::BadCrc { .. } => {
                self.bad_crc += 1;
                return vec![];
            }
            Parsed::Instruction(i) => i,
        };
        self.parser_packets += 1;
        let mut out = Vec::new();
        let ids: Vec<u8> = self.servos.iter().map(|s| s.config.id).collect();
        for (k, id) in ids.iter().enumerate() {
            if self.silent(*id, now) {
                self.missed += usize::from(crate::clock::expects_reply(&ins, *id));
                continue;
            }
            self.servos[k].refuse_goals =
                matches!(self.faults.reject, Some((rid, at)) if rid == *id && now >= at);
            let reply = self.handle_one(k, &ins, now);
            if let Some(mut bytes) = reply {
                if matches!(self.faults.corrupt, Some((cid, at)) if cid == *id && now >= at) {
                    let n = bytes.len();
                    bytes[n - 1] ^= 0x5A;
                }
                out.push((packet::order_of(&ins, *id), bytes));
            }
        }
        out.sort_by_key(|(o, _)| *o);
        out.into_iter().flat_map(|(_, b)| b).collect()
    }

    /// Servo `k`'s reply to `ins`, if it answers.
    fn handle_one(&mut self, k: usize, ins: &Instruction, now: f64) -> Option<Vec<u8>> {
        let id = self.servos[k].config.id;
        let p = &ins.params;
        let addressed = ins.id == id || ins.id == packet::BROADCAST;
        let u16p = |i: usize| u16::from_le_bytes([p[i], p[i + 1]]);
        match ins.instruction {
            inst::PING if addressed => {
                self.servos[k].last_seen = now;
                let s = &self.servos[k];
                Some(packet::status(
                    id,
                    s.error_byte(0),
                    &[s.table[0], s.table[1], s.table[t::FIRMWARE_VERSION as usize]],
                ))
            }
            inst::READ if ins.id == id => {
                self.servos[k].last_seen = now;
                let s = &self.servos[k];
                if p.len() != 4 {
                    return Some(packet::status(id, s.error_byte(error::DATA_LENGTH), &[]));
                }
                Some(match s.read(u16p(0), u16p(2)) {
                    Ok(data) => packet::status(id, s.error_byte(0), &data),
                    Err(e) => packet::status(id, s.error_byte(e), &[]),
                })
            }
            inst::WRITE if addressed => {
                self.servos[k].last_seen = now;
                if p.len() < 3 {
                    return (ins.id == id).then(|| packet::status(id, error::DATA_LENGTH, &[]));
                }
                let e = self.servos[k].write(u16p(0), &p[2..]);
                (ins.id == id).then(|| packet::status(id, self.servos[k].error_byte(e), &[]))
            }
            inst::REBOOT if addressed => {
                let s = &mut self.servos[k];
                s.last_seen = now;
                s.table[t::TORQUE_ENABLE as usize] = 0;
                s.table[t::HARDWARE_ERROR_STATUS as usize] = 0;
                s.table[t::BUS_WATCHDOG as usize] = 0;
                (ins.id == id).then(|| packet::status(id, 0, &[]))
            }
            inst::CLEAR if addressed => {
                let s = &mut self.servos[k];
                s.last_seen = now;
                let e = if !s.clear_supported {
                    error::INSTRUCTION
                } else if p.as_slice() != packet::CLEAR_MULTI_TURN {
                    error::DATA_RANGE
                } else {
                    s.clear()
                };
                (ins.id == id).then(|| packet::status(id, s.error_byte(e), &[]))
            }
            inst::SYNC_READ if ins.id == packet::BROADCAST && p.len() >= 4 => {
                if !p[4..].contains(&id) {
                    return None;
                }
                self.servos[k].last_seen = now;
                let s = &self.servos[k];
                Some(match s.read(u16p(0), u16p(2)) {
                    Ok(data) => packet::status(id, s.error_byte(0), &data),
                    Err(e) => packet::status(id, s.error_byte(e), &[]),
                })
            }
            inst::SYNC_WRITE if ins.id == packet::BROADCAST && p.len() >= 4 => {
                let (addr, len) = (u16p(0), usize::from(u16p(2)));
                for chunk in p[4..].chunks(len + 1) {
                    if chunk.len() == len + 1 && chunk[0] == id {
                        self.servos[k].last_seen = now;
                        self.servos[k].write(addr, &chunk[1..]);
                    }
                }
                None
            }
            inst::BULK_READ if ins.id == packet::BROADCAST => {
                let entry = p.chunks(5).find(|c| c.len() == 5 && c[0] == id)?;
                self.servos[k].last_seen = now;
                let s = &self.servos[k];
                let (addr, len) =
                    (u16::from_le_bytes([entry[1], entry[2]]), u16::from_le_bytes([entry[3], entry[4]]));
                Some(match s.read(addr, len) {
                    Ok(data) => packet::status(id, s.error_byte(0), &data),
                    Err(e) => packet::status(id, s.error_byte(e), &[]),
                })
            }
            inst::BULK_WRITE if ins.id == packet::BROADCAST => {
                let mut i = 0;
                while i + 5 <= p.len() {
                    let (sid, addr, len) = (p[i], u16p(i + 1), usize::from(u16p(i + 3)));
                    let data = p.get(i + 5..i + 5 + len)?;
                    if sid == id {
                        self.servos[k].last_seen = now;
                        self.servos[k].write(addr, data);
                    }
                    i += 5 + len;
                }
                None
            }
            _ if ins.id == id => Some(packet::status(id, error::INSTRUCTION, &[])),
            _ => None,
        }
    }

    /// The torque state and watchdogs as the servos' tables hold them.
    pub fn report(&self) -> EmulatorReport {
        EmulatorReport {
            torque_enabled: self.servos.iter().map(|s| (s.config.id, s.torque_on())).collect(),
            packets: self.parser_packets,
            bad_crc: self.bad_crc,
            watchdog: self.servos.iter().map(|s| (s.config.id, s.u8_at(t::BUS_WATCHDOG))).collect(),
            weakened: None,
        }
    }

    /// Refreshes every servo to `now` s (the watchdog, the shafts).
    pub fn tick(&mut self, now: f64) {
        self.advance_all(now);
    }
}

/// The path of the pseudo-terminal `port` (the slave side [`Emulator::start`] returns), e.g.
/// `/dev/pts/3`, that another program (Dynamixel Wizard, the ROBOTIS SDK) opens as a serial
/// port; `None` where the system does not say (Linux reads it from `/proc/self/fd`).
pub fn pty_path(port: &SerialPort) -> Option<std::path::PathBuf> {
    use std::os::unix::io::AsRawFd;
    std::fs::read_link(format!("/proc/self/fd/{}", port.as_raw_fd())).ok()
}

/// The pty's nominal baud rate (see [`Emulator::start`]); defined beside the emulated clock,
/// whose reply timeout follows from it.
pub use crate::clock::EMULATED_BAUD;

/// A running emulator: a thread serving the pty's master side.
#[derive(Debug)]
pub struct Emulator {
    stop: Arc<AtomicBool>,
    handle: Option<JoinHandle<EmulatorReport>>,
    /// The emulator's clock: its time 0 is the one its fault and weakening times count from.
    clock: Clock,
    /// When the sand weakens, s after `started`, and to what k_s, N/m^3.
    weaken: Option<(f64, f64)>,
}

impl Emulator {
    /// Starts the emulator; returns it and the serial port the driver opens the bus on.
    pub fn start(config: &EmulatorConfig) -> Result<(Emulator, SerialPort), EmulatorError> {
        let mut bus = VirtualBus::new(config)?;
        let (mut master, mut slave) = SerialPort::pair().map_err(EmulatorError::Pty)?;
        for port in [&mut master, &mut slave] {
            if let Ok(mut s) = port.get_configuration() {
                // A pty moves bytes at once whatever its nominal rate, but dynamixel2 sets its
                // reply timeouts from that rate (the transfer time plus 34 ms): 9600 baud gives
                // 67 ms for a 32-byte reply, room for a loaded machine's scheduling.
                if s.set_baud_rate(EMULATED_BAUD).is_ok() {
                    port.set_configuration(&s).ok();
                }
            }
        }
        master.set_read_timeout(Duration::from_millis(2)).map_err(EmulatorError::Pty)?;
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let clock = config.clock.start(config.seed);
        let start = clock.clone();
        let handle = std::thread::Builder::new()
            .name("xl330-emulator".into())
            .spawn(move || {
                let mut parser = Parser::default();
                let mut buf = [0u8; 1024];
                while !flag.load(Ordering::Relaxed) {
                    let now = start.now();
                    if bus.frozen(now) {
                        // The virtual clock moves through the freeze as the real one would.
                        start.sleep(0.002);
                        continue;
                    }
                    match master.read(&mut buf) {
                        Ok(n) if n > 0 => parser.push(&buf[..n]),
                        _ => {}
                    }
                    while let Some(p) = parser.next_packet() {
                        let reply = bus.respond(p, start.now());
                        if !reply.is_empty() {
                            master.write_all(&reply).ok();
                        }
                        start.advance_by(bus.take_missed() as f64 * REPLY_TIMEOUT_S);
                    }
                    bus.tick(start.now());
                }
                bus.report()
            })
            .map_err(EmulatorError::Pty)?;
        Ok((Emulator { stop, handle: Some(handle), clock, weaken: config.faults.weaken }, slave))
    }

    /// The emulator's clock, which the driver's loop keeps too ([`crate::clock`]).
    pub fn clock(&self) -> Clock {
        self.clock.clone()
    }

    /// Stops the emulator and returns what its servos' tables hold. `gait_zero`, the driver's
    /// gait time 0 on the emulator's [`Emulator::clock`], puts the weakening on the log's clock
    /// ([`EmulatorReport::weakened`]).
    pub fn stop(mut self, gait_zero: Option<f64>) -> EmulatorReport {
        self.stop.store(true, Ordering::Relaxed);
        let mut report = self.handle.take().and_then(|h| h.join().ok()).unwrap_or_default();
        report.weakened = match (self.weaken, gait_zero) {
            (Some((at, k_s)), Some(zero)) if self.clock.now() >= at => Some((at - zero.max(0.0), k_s)),
            _ => None,
        };
        report
    }
}

impl Drop for Emulator {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(h) = self.handle.take() {
            h.join().ok();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The playback follows the legs' angle through the run-up (docs/model.md §19), not the
    /// time at full speed. A trace sampled every 0.05 s of the paper's run-up (omega = 2 pi
    /// rad/s over dt = 0.2 s), each sample's torque its time: by hand, angle omega t^2 / (2 dt)
    /// = 0.0125 pi at t = 0.05 s, 0.05 pi at 0.1 s, 0.2 pi at 0.2 s, 0.4 pi at 0.3 s. Read at
    /// full speed from the start (the old playback) 0.05 pi would be t = 0.025 s, not 0.1 s.
    #[test]
    fn the_playback_follows_the_run_up_by_hand() {
        let pi = std::f64::consts::PI;
        let times = [0.0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3];
        let angle = |t: f64| if t < 0.2 { pi * t * t / 0.2 } else { 2.0 * pi * (t - 0.1) };
        let trace =
            LegTrace { angle_rad: times.iter().map(|&t| angle(t)).collect(), torque_n_m: times.to_vec() };
        let walk = Walk { legs: vec![trace] };
        for (a, t) in [(0.0125 * pi, 0.05), (0.05 * pi, 0.1), (0.2 * pi, 0.2), (0.4 * pi, 0.3), (0.0, 0.0)] {
            assert_eq!(walk.torque(0, a), t, "angle {a}");
        }
        // Between samples, the nearest: 0.06 pi lies between 0.05 pi (0.1 s) and 0.1125 pi (0.15 s).
        assert_eq!(walk.torque(0, 0.06 * pi), 0.1);
    }
}
