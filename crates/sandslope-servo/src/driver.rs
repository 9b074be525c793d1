//! The gait driver: the commanded alternating tripod sent to XL330s over Protocol 2.0, the
//! servos' state read back every cycle, and the safety logic (docs/drive.md).
//!
//! One cycle: a Sync Write of every servo's goal (Goal Position in extended position mode, or
//! Goal Velocity with a phase correction in velocity mode), then a Sync Read of the block from
//! Present Current (126) to Present Temperature (146). Safety:
//! - before moving: every ID must answer a ping with an XL330 model number; the current and
//!   temperature limits, the operating mode, the velocity-based profile and the servos' own
//!   Bus Watchdog are written while the torque is off;
//! - torque off on every exit: the end of the run, Ctrl-C (the caller's stop flag), a servo
//!   that stops answering or whose packets keep failing their CRC (three cycles in a row), a
//!   cycle slower than the driver's watchdog, a servo that raises its alert (a hardware error:
//!   it shut itself down), and an error writing the log;
//! - the servos' Bus Watchdog stops them by themselves if the driver dies without a word;
//! - `stop_on_risk`: the gait halts when the live risk that the walk fails (slippage or sinkage) passes the threshold; the
//!   torque stays on and the legs hold where they are (the stance tripod planted) for
//!   `hold_s`, then the torque goes off.

use std::sync::atomic::{AtomicBool, Ordering};

use dynamixel2::instructions::SyncWriteData;
use dynamixel2::ReadError;
use sandslope::infer::servo::{
    infer_from_run_up, infer_from_stance, CurrentInference, ModelGrid, RUN_UP_OFFSET_SD_MA,
};
use sandslope::risk::UncertainTerrain;
use sandslope::servo::verdict::{pool, prior_p_fail, PooledEstimate};
use sandslope::servo::{GaitSchedule, ServoModel};
use sandslope::{Robot, Slope};
use serde::Serialize;

use crate::clock::Clock;
pub use crate::config::{DriveSettings, DynamixelBus, Profile, ServoConfig};
pub use crate::error::{hardware_faults, DriveError};
use crate::guard::{Following, GoalCheck};
pub use crate::setup::{setup_writes, velocity_limit_units, SetupDone, SetupWrite};
use crate::stance::StanceBins;
use crate::table::{self as t, read_states, PresentState};

/// One servo's state in one cycle: what the log holds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ServoSample {
    /// Time since the gait started, s (negative while standing up).
    pub time_s: f64,
    /// Leg index.
    pub leg: usize,
    /// Tripod.
    pub tripod: usize,
    /// Dynamixel ID.
    pub id: u8,
    /// Present values.
    #[serde(skip)]
    pub state: PresentState,
    /// Hardware Error Status (read when the status packet's alert bit is set), else 0.
    pub hardware_error: u8,
    /// Goal position sent this cycle, pulses (the velocity profile: the schedule's angle).
    pub goal_position: i32,
    /// Leg angle in the gait's frame, rad.
    pub leg_angle_rad: f64,
    /// Drive torque `K_t I` in the leg's direction of rotation, N m (docs/model.md §19), by
    /// the servos' model ([`ServoModel::torque_from_reading`]).
    pub drive_torque_n_m: f64,
    /// The motor current the reading of address 126 stands for, mA (the servo's own sign).
    #[serde(skip)]
    pub current_ma: f64,
    /// The reading as a share of the model's stall torque, % (the servo's own sign).
    #[serde(skip)]
    pub load_percent: f64,
}

/// One live estimate, after one stance.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LiveEstimate {
    /// Gait time at the end of the stance, s.
    pub time_s: f64,
    /// Tripod.
    pub tripod: usize,
    /// The estimate from this stance alone.
    pub inference: CurrentInference,
    /// The stances so far pooled (the last `window` of them with a moving window), with the
    /// simulator's and the closed form's verdicts and the decision, the larger of the two
    /// (`sandslope::servo::verdict`): what `--stop-on-risk` watches.
    pub pooled: Option<PooledEstimate>,
    /// The risk `--stop-on-risk` compares: the largest of the pooled estimate's two verdicts
    /// and this stance's own simulator verdict (so that sand that weakens mid-run halts the
    /// gait on its first stance, before the pooled estimate follows it).
    pub decision_p_fail: f64,
}

/// How a run ended without error.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "outcome", rename_all = "snake_case")]
pub enum DriveOutcome {
    /// The gait ran its duration.
    Completed {
        /// Gait time, s.
        time_s: f64,
    },
    /// Ctrl-C (or the caller's stop flag).
    Interrupted {
        /// Gait time, s.
        time_s: f64,
    },
    /// `stop_on_risk` halted the gait.
    Halted {
        /// Gait time of the halt, s.
        time_s: f64,
        /// The risk that passed the threshold (the probability that the walk fails).
        p_fail: f64,
    },
}

/// What the driver leaves behind: the torque state it confirmed on the way out.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct TorqueOff {
    /// IDs whose Torque Enable read back 0.
    pub confirmed: Vec<u8>,
    /// IDs that did not answer the read-back.
    pub unconfirmed: Vec<u8>,
}

/// The whole run's answer. As JSON (`drive --json`, Python's `drive`), how it ended is flat:
/// `outcome` (`completed`, `interrupted`, `halted` or `failed`), `time_s`, `p_fail` for a
/// halt and `error` for a failure, beside the other fields (`crate::report`).
#[derive(Debug)]
pub struct DriveReport {
    /// How it ended.
    pub outcome: Result<DriveOutcome, String>,
    /// Cycles run.
    pub cycles: usize,
    /// Mean cycle rate, Hz.
    pub rate_hz: f64,
    /// The cycles' spread: the standard deviation of the time between cycle starts, ms.
    pub cycle_jitter_ms: f64,
    /// The longest time between cycle starts, ms.
    pub max_cycle_ms: f64,
    /// What the setup wrote (EEPROM writes made and kept) and whether the revolution counters
    /// were cleared.
    pub setup: SetupDone,
    /// Live estimates, one per stance (with a monitor).
    pub live: Vec<LiveEstimate>,
    /// The closed form's p_fail at the terrain's own uncertain k_s, the decision before the
    /// first stance is estimated (with a monitor).
    pub prior_p_fail: Option<f64>,
    /// The legs' mean speed over the run's last stride period as their positions give it,
    /// rad/s ([`crate::speed::LegSpeedMeter`]; the gait commands the robot's leg speed);
    /// `None` when no leg ran a quarter second.
    pub leg_speed_rad_s: Option<f64>,
    /// The torque on the way out.
    pub torque_off: TorqueOff,
    /// Gait time 0 on the run's clock, s (the legs stood up, `stand_s` after the walk's first
    /// cycle), to put another clock on the log's (the emulator's weakening); `None` when the
    /// run ended before it began.
    pub gait_zero: Option<f64>,
}

impl DriveReport {
    /// The report of a run that never started (the log could not be opened: nothing moved).
    pub fn not_started(message: String) -> DriveReport {
        DriveReport {
            outcome: Err(message),
            cycles: 0,
            rate_hz: 0.0,
            cycle_jitter_ms: 0.0,
            max_cycle_ms: 0.0,
            setup: SetupDone::default(),
            live: vec![],
            prior_p_fail: None,
            leg_speed_rad_s: None,
            torque_off: TorqueOff::default(),
            gait_zero: None,
        }
    }
}

/// The live monitor: the robot, the simulator's grid at the slope, and one sample's torque
/// noise, N m.
#[derive(Debug, Clone)]
pub struct Monitor<'a> {
    /// The robot.
    pub robot: &'a Robot,
    /// The grid of simulated stance profiles.
    pub grid: &'a ModelGrid,
    /// SD of one torque sample, N m.
    pub noise_sd_n_m: f64,
    /// The terrain with its uncertainty (the closed form's verdict and the prior's).
    pub terrain: &'a UncertainTerrain,
    /// The slope as the closed form takes it.
    pub slope: Slope,
    /// Pool the last this many stances (a moving window that follows changing sand); `None`:
    /// every stance so far.
    pub window: Option<usize>,
}

/// Phase correction of the velocity profile: speed added per radian of lag, 1/s.
pub const PHASE_GAIN_PER_S: f64 = 4.0;

/// Runs the gait on `bus`: setup, stand up, walk for the settings' duration (or until `stop`
/// is set, a halt on risk, or an error), then torque off. `on_sample` receives every servo's
/// state every cycle (the log); an error from it stops the run. Returns the report; its
/// `outcome` is the error's message on failure, and the error itself is returned beside it.
/// The loop keeps the wall's clock ([`drive_on_clock`] takes another).
pub fn drive(
    bus: &mut DynamixelBus,
    schedule: &GaitSchedule,
    settings: &DriveSettings,
    monitor: Option<Monitor<'_>>,
    stop: &AtomicBool,
    on_sample: &mut dyn FnMut(&ServoSample) -> std::io::Result<()>,
    on_live: &mut dyn FnMut(&LiveEstimate),
) -> (DriveReport, Option<DriveError>) {
    drive_on_clock(bus, schedule, settings, monitor, stop, on_sample, on_live, &Clock::real())
}

/// [`drive`] on `clock`: the emulator's ([`crate::Emulator::clock`]), whose virtual kind the
/// loop moves on instead of sleeping between cycles ([`crate::clock`]).
#[allow(clippy::too_many_arguments)]
pub fn drive_on_clock(
    bus: &mut DynamixelBus,
    schedule: &GaitSchedule,
    settings: &DriveSettings,
    monitor: Option<Monitor<'_>>,
    stop: &AtomicBool,
    on_sample: &mut dyn FnMut(&ServoSample) -> std::io::Result<()>,
    on_live: &mut dyn FnMut(&LiveEstimate),
    clock: &Clock,
) -> (DriveReport, Option<DriveError>) {
    let mut report = DriveReport::not_started(String::new());
    let mut meter =
        crate::speed::LegSpeedMeter::with_window(settings.servos.len(), schedule.period_s, schedule.run_up_s);
    let result = {
        let mut observed = |s: &ServoSample| {
            meter.observe(s.leg, s.time_s, s.leg_angle_rad);
            on_sample(s)
        };
        crate::setup::setup(bus, schedule, settings).and_then(|done| {
            report.setup = done;
            run(bus, schedule, settings, monitor, stop, clock, &mut observed, on_live, &mut report)
        })
    };
    report.leg_speed_rad_s = meter.mean();
    report.torque_off = torque_off(bus, &settings.servos);
    match result {
        Ok(o) => {
            report.outcome = Ok(o);
            (report, None)
        }
        Err(e) => {
            report.outcome = Err(e.to_string());
            (report, Some(e))
        }
    }
}

/// The start pose found when standing up: each leg's start goal (the nearest turn of its start
/// angle) and the shift of the schedule's angles to it.
struct Stand {
    start_goal: Vec<i32>,
    shift: Vec<f64>,
}

/// The stride loop's state between cycles.
struct Walk<'m> {
    /// The servos' model, read at the ping.
    model: &'static ServoModel,
    ids: Vec<u8>,
    stand: Stand,
    /// Per servo: failed reads in a row and whether they were CRC failures.
    failures: Vec<(usize, bool)>,
    last_pos: Vec<Option<i32>>,
    monitor: Option<(Monitor<'m>, StanceBins)>,
    /// `(time, p_fail)` of a halt on risk, and the goals held since.
    halted: Option<(f64, f64)>,
    halt_goal: Vec<i32>,
    /// The goal registers' readback and the following error.
    goal_check: GoalCheck,
    following: Following,
    /// Each stance's posterior over the grid and its median, for the pooled estimate.
    stances: Vec<Vec<f64>>,
    medians: Vec<f64>,
}

/// The spread of the times between cycle starts.
#[derive(Debug, Default)]
struct Jitter {
    n: usize,
    sum: f64,
    sum_sq: f64,
    max: f64,
}

impl Jitter {
    fn add(&mut self, dt: f64) {
        self.n += 1;
        self.sum += dt;
        self.sum_sq += dt * dt;
        self.max = self.max.max(dt);
    }
    /// Standard deviation and maximum, ms.
    fn ms(&self) -> (f64, f64) {
        if self.n < 2 {
            return (0.0, 1e3 * self.max);
        }
        let n = self.n as f64;
        let var = (self.sum_sq - self.sum * self.sum / n) / (n - 1.0);
        (1e3 * var.max(0.0).sqrt(), 1e3 * self.max)
    }
}

#[allow(clippy::too_many_arguments)]
fn run(
    bus: &mut DynamixelBus,
    schedule: &GaitSchedule,
    settings: &DriveSettings,
    monitor: Option<Monitor<'_>>,
    stop: &AtomicBool,
    clock: &Clock,
    on_sample: &mut dyn FnMut(&ServoSample) -> std::io::Result<()>,
    on_live: &mut dyn FnMut(&LiveEstimate),
    report: &mut DriveReport,
) -> Result<DriveOutcome, DriveError> {
    let ids: Vec<u8> = settings.servos.iter().map(|s| s.id).collect();
    let stand = stand_up(bus, schedule, settings, &ids)?;
    let mut walk = Walk {
        model: report.setup.model.unwrap_or(&ServoModel::XL330_M288),
        failures: vec![(0usize, false); ids.len()],
        last_pos: vec![None; ids.len()],
        monitor: monitor.map(|m| {
            let run_up = !m.grid.run_up_mean.is_empty();
            let bins = StanceBins::new(m.grid.bins, settings.servos.len(), m.grid.swing_offset, run_up);
            (m, bins)
        }),
        goal_check: GoalCheck::default(),
        following: Following::new(ids.len()),
        stances: vec![],
        medians: vec![],
        ids,
        stand,
        halted: None,
        halt_goal: vec![],
    };
    let mut jitter = Jitter::default();
    let period = 1.0 / settings.rate_hz;
    let begin = clock.now();
    report.gait_zero = Some(begin + settings.stand_s);
    let (mut last_cycle, mut waits) = (begin, 0);
    loop {
        let now = clock.now();
        let time = now - begin - settings.stand_s;
        let cycle = now - last_cycle;
        last_cycle = now;
        if report.cycles > 0 {
            jitter.add(cycle);
            (report.cycle_jitter_ms, report.max_cycle_ms) = jitter.ms();
        }
        if report.cycles > 0 && cycle > settings.watchdog_s {
            return Err(DriveError::Watchdog { time_s: time, cycle_s: cycle, limit_s: settings.watchdog_s });
        }
        if let Some(outcome) = walk.finished(settings, stop, time) {
            return Ok(outcome);
        }
        // Before the first stance is estimated the prior decides: the closed form on the
        // terrain's own uncertain k_s at the slope.
        if time >= 0.0 && report.prior_p_fail.is_none() {
            if let Some((m, _)) = &walk.monitor {
                let p = prior_p_fail(m.robot, m.terrain, m.slope);
                report.prior_p_fail = Some(p);
                if settings.stop_on_risk.is_some_and(|limit| p > limit) {
                    walk.halted = Some((time, p));
                    walk.halt_goal = walk
                        .last_pos
                        .iter()
                        .zip(&walk.stand.start_goal)
                        .map(|(p, &g)| p.unwrap_or(g))
                        .collect();
                }
            }
        }
        let goals = walk.goals(schedule, settings, time);
        let sent = walk
            .write_goals(bus, schedule, settings, &goals, time)
            .map_err(|e| DriveError::Bus { time_s: time, reason: e.to_string() })?;
        walk.read_cycle(bus, schedule, settings, &goals, time, on_sample, on_live, report)?;
        // The goals read back (a Sync Write's refusal is silent): every second of the gait.
        if time >= 0.0 && walk.goal_check.due(time) {
            let address = match settings.profile {
                Profile::Position => t::GOAL_POSITION,
                Profile::Velocity => t::GOAL_VELOCITY,
            };
            GoalCheck::check(bus, &settings.servos, address, &sent, time)?;
        }
        clock.wait_cycle(period, clock.now() - last_cycle, waits);
        waits += 1;
        report.rate_hz = report.cycles as f64 / (clock.now() - begin).max(1e-9);
    }
}

/// Stands up: reads where the legs are (up to three tries per servo, as during the run), takes
/// the start pose nearest to it, and turns the torque on.
fn stand_up(
    bus: &mut DynamixelBus,
    schedule: &GaitSchedule,
    settings: &DriveSettings,
    ids: &[u8],
) -> Result<Stand, DriveError> {
    let stand_s = settings.stand_s;
    let mut states = read_states(bus, ids).map_err(|reason| DriveError::Bus { time_s: -stand_s, reason })?;
    for _ in 0..2 {
        if states.iter().all(Result::is_ok) {
            break;
        }
        let again = read_states(bus, ids).map_err(|reason| DriveError::Bus { time_s: -stand_s, reason })?;
        for (s, a) in states.iter_mut().zip(again) {
            if s.is_err() {
                *s = a;
            }
        }
    }
    let mut start_goal = vec![0i32; ids.len()];
    for (j, s) in settings.servos.iter().enumerate() {
        let here = match &states[j] {
            Ok((st, _)) => s.angle(st.position),
            Err(e) => {
                return Err(DriveError::Lost {
                    id: s.id,
                    leg: j,
                    time_s: -stand_s,
                    cycles: 1,
                    reason: e.to_string(),
                })
            }
        };
        let start = schedule.start_angle(j);
        // The nearest turn of the start angle: at most half a turn of travel.
        let turns = ((here - start) / (2.0 * std::f64::consts::PI)).round();
        start_goal[j] = s.pulses(start + turns * 2.0 * std::f64::consts::PI);
    }
    // Every goal of the run within the extended position mode's range, from where the legs
    // stand (the setup cleared the revolution counters; a servo that kept its count is
    // checked here): refused before the torque goes on.
    if let Err(short) = crate::plan::check_goal_range(
        schedule,
        &settings.servos,
        settings.profile,
        settings.duration_s,
        Some(&start_goal),
    ) {
        let s = settings.servos[short.leg];
        return Err(DriveError::Range {
            id: s.id,
            leg: short.leg,
            start: start_goal[short.leg],
            duration_s: settings.duration_s,
            longest_s: short.longest_s,
        });
    }
    // Every angle from here on is relative to the start pose found: shift the schedule by it.
    let shift: Vec<f64> = settings
        .servos
        .iter()
        .enumerate()
        .map(|(j, s)| s.angle(start_goal[j]) - schedule.start_angle(j))
        .collect();
    let torque_on: Vec<SyncWriteData<[u8; 1]>> =
        ids.iter().map(|&id| SyncWriteData { motor_id: id, data: [1] }).collect();
    bus.sync_write(t::TORQUE_ENABLE, 1, &torque_on)
        .map_err(|e| DriveError::Bus { time_s: -stand_s, reason: e.to_string() })?;
    Ok(Stand { start_goal, shift })
}

impl Walk<'_> {
    /// How the run ends at `time`, if it does: the stop flag, the end of a halt's hold, or
    /// the duration reached.
    fn finished(&self, settings: &DriveSettings, stop: &AtomicBool, time: f64) -> Option<DriveOutcome> {
        if stop.load(Ordering::Relaxed) {
            return Some(DriveOutcome::Interrupted { time_s: time });
        }
        match self.halted {
            Some((at, p)) if time - at >= settings.hold_s => {
                Some(DriveOutcome::Halted { time_s: at, p_fail: p })
            }
            None if time >= settings.duration_s => Some(DriveOutcome::Completed { time_s: time }),
            _ => None,
        }
    }

    /// Every servo's goal position at `time`: the start pose while standing, the held pose
    /// after a halt, the schedule's angle otherwise.
    fn goals(&self, schedule: &GaitSchedule, settings: &DriveSettings, time: f64) -> Vec<i32> {
        settings
            .servos
            .iter()
            .enumerate()
            .map(|(j, s)| {
                if self.halted.is_some() {
                    self.halt_goal[j]
                } else if time < 0.0 {
                    self.stand.start_goal[j]
                } else {
                    s.pulses(schedule.command(j, time).angle_rad + self.stand.shift[j])
                }
            })
            .collect()
    }

    /// One Sync Write of the goals: positions, or in velocity mode the schedule's speed plus a
    /// phase correction from the last read position (standing and halted: position error
    /// only), within the Velocity Limit written. Returns the register values sent.
    fn write_goals(
        &self,
        bus: &mut DynamixelBus,
        schedule: &GaitSchedule,
        settings: &DriveSettings,
        goals: &[i32],
        time: f64,
    ) -> Result<Vec<i32>, dynamixel2::WriteError> {
        let limit = velocity_limit_units(schedule, self.model);
        let values: Vec<i32> = match settings.profile {
            Profile::Position => goals.to_vec(),
            Profile::Velocity => self
                .ids
                .iter()
                .enumerate()
                .map(|(j, _)| {
                    let s = settings.servos[j];
                    let cmd_v = if time >= 0.0 && self.halted.is_none() {
                        schedule.command(j, time).velocity_rad_s
                    } else {
                        0.0
                    };
                    let err = self.last_pos[j].map_or(0.0, |p| s.angle(goals[j]) - s.angle(p));
                    let v = f64::from(s.direction) * (cmd_v + PHASE_GAIN_PER_S * err);
                    crate::guard::velocity_goal(v, limit)
                })
                .collect(),
        };
        let data: Vec<SyncWriteData<[u8; 4]>> = self
            .ids
            .iter()
            .zip(&values)
            .map(|(&id, v)| SyncWriteData { motor_id: id, data: v.to_le_bytes() })
            .collect();
        let address = match settings.profile {
            Profile::Position => t::GOAL_POSITION,
            Profile::Velocity => t::GOAL_VELOCITY,
        };
        bus.sync_write(address, 4, &data)?;
        Ok(values)
    }

    /// One Sync Read of every servo's state: each answer logged and fed to the monitor, each
    /// failure counted (three in a row end the run).
    #[allow(clippy::too_many_arguments)]
    fn read_cycle(
        &mut self,
        bus: &mut DynamixelBus,
        schedule: &GaitSchedule,
        settings: &DriveSettings,
        goals: &[i32],
        time: f64,
        on_sample: &mut dyn FnMut(&ServoSample) -> std::io::Result<()>,
        on_live: &mut dyn FnMut(&LiveEstimate),
        report: &mut DriveReport,
    ) -> Result<(), DriveError> {
        let states =
            read_states(bus, &self.ids).map_err(|reason| DriveError::Bus { time_s: time, reason })?;
        report.cycles += 1;
        for (j, st) in states.into_iter().enumerate() {
            let s = settings.servos[j];
            match st {
                Ok((state, alert)) => {
                    self.failures[j] = (0, false);
                    self.last_pos[j] = Some(state.position);
                    let hardware_error = if alert {
                        bus.read_u8(s.id, t::HARDWARE_ERROR_STATUS).map(|r| r.data).unwrap_or(0xFF)
                    } else {
                        0
                    };
                    let angle = s.angle(state.position) - self.stand.shift[j];
                    let raw = f64::from(state.current_ma);
                    let tau = f64::from(s.direction) * self.model.torque_from_reading(raw);
                    let sample = ServoSample {
                        time_s: time,
                        leg: j,
                        tripod: schedule.tripods[j],
                        id: s.id,
                        state,
                        hardware_error,
                        goal_position: goals[j],
                        leg_angle_rad: angle,
                        drive_torque_n_m: tau,
                        current_ma: self.model.current_ma_from_reading(raw),
                        load_percent: self.model.load_percent_from_reading(raw),
                    };
                    on_sample(&sample)
                        .map_err(|e| DriveError::Log { time_s: time, reason: e.to_string() })?;
                    // The servo shut itself down (its Shutdown register): a walk on the other
                    // legs is not the commanded gait, and the robot's team must know.
                    if hardware_error != 0 {
                        return Err(DriveError::Hardware {
                            id: s.id,
                            leg: j,
                            time_s: time,
                            bits: hardware_error,
                        });
                    }
                    if time >= 0.0 {
                        let error = s.angle(goals[j]) - s.angle(state.position);
                        self.following.check(j, s.id, time, error)?;
                    }
                    self.monitor_sample(schedule, settings, goals, j, angle, tau, time, on_live, report);
                }
                // The servo answered with an error number: not a lost packet but a refusal.
                Err(ReadError::MotorError(e)) if e.error_number() != 0 => {
                    return Err(DriveError::Status {
                        id: s.id,
                        leg: j,
                        time_s: time,
                        register: "Present Current (126) to Present Temperature (146)",
                        error: format!(
                            "{} (error number {})",
                            crate::setup::status_error_name(e.error_number()),
                            e.error_number()
                        ),
                    })
                }
                Err(e) => self.count_failure(j, s.id, &e, time)?,
            }
        }
        Ok(())
    }

    /// Feeds one sample to the live monitor; after a complete stance, the estimate (and a halt
    /// when its risk passes `stop_on_risk`).
    #[allow(clippy::too_many_arguments)]
    fn monitor_sample(
        &mut self,
        schedule: &GaitSchedule,
        settings: &DriveSettings,
        goals: &[i32],
        j: usize,
        angle: f64,
        tau: f64,
        time: f64,
        on_live: &mut dyn FnMut(&LiveEstimate),
        report: &mut DriveReport,
    ) {
        let Some((m, bins)) = self.monitor.as_mut() else { return };
        let Some(stance) = bins.add(schedule, j, time, angle, tau) else { return };
        let (k, profile, counts) = (stance.tripod, &stance.profile, &stance.counts);
        // Tripod 0's run-up stance against the grid walks' own run-ups, its raw torques'
        // unknown sensor offsets integrated out (docs/drive.md).
        let inf = if stance.stride == 0 {
            let offset_sd = self.model.torque_from_current_ma(RUN_UP_OFFSET_SD_MA);
            infer_from_run_up(m.robot, m.grid, profile, counts, m.noise_sd_n_m, offset_sd)
        } else {
            infer_from_stance(m.robot, m.grid, k, profile, counts, m.noise_sd_n_m)
        };
        let Some(inf) = inf else { return };
        self.stances.push(inf.posterior.iter().map(|x| x.1).collect());
        let from = m.window.map_or(0, |w| self.stances.len().saturating_sub(w.max(1)));
        let pooled_in: Vec<&[f64]> = self.stances[from..].iter().map(Vec::as_slice).collect();
        self.medians.push(inf.k_s);
        let pooled = pool(m.robot, m.terrain, m.slope, m.grid, &pooled_in, &self.medians[from..]);
        let p = pooled.as_ref().map_or(inf.p_fail, |x| x.p_fail.max(inf.p_fail));
        let live = LiveEstimate { time_s: time, tripod: k, inference: inf, pooled, decision_p_fail: p };
        on_live(&live);
        report.live.push(live);
        if let (Some(limit), None) = (settings.stop_on_risk, self.halted) {
            if p > limit {
                self.halted = Some((time, p));
                // Hold every leg where it was last read: the stance tripod stays planted.
                self.halt_goal = self.last_pos.iter().zip(goals).map(|(p, &g)| p.unwrap_or(g)).collect();
            }
        }
    }

    /// Counts servo `j`'s failed read; the third in a row of one kind ends the run.
    fn count_failure(&mut self, j: usize, id: u8, e: &ReadError, time: f64) -> Result<(), DriveError> {
        // A failed CRC is corruption; silence, or the next servo's packet in this one's place,
        // is a servo that did not answer.
        let corrupt = matches!(e, ReadError::InvalidMessage(dynamixel2::InvalidMessage::InvalidChecksum(_)));
        let n = if self.failures[j].1 == corrupt { self.failures[j].0 + 1 } else { 1 };
        self.failures[j] = (n, corrupt);
        if n < 3 {
            return Ok(());
        }
        Err(if corrupt {
            DriveError::Corrupt { id, leg: j, time_s: time, cycles: n }
        } else {
            DriveError::Lost { id, leg: j, time_s: time, cycles: n, reason: e.to_string() }
        })
    }
}

/// Torque off on every servo (a Sync Write, then each servo written and read back alone), and
/// the Bus Watchdog cleared (0), so that a servo left on the bus after the run takes a later
/// program's goals (a fired watchdog refuses them).
pub fn torque_off(bus: &mut DynamixelBus, servos: &[ServoConfig]) -> TorqueOff {
    let data: Vec<SyncWriteData<[u8; 1]>> =
        servos.iter().map(|s| SyncWriteData { motor_id: s.id, data: [0] }).collect();
    bus.sync_write(t::TORQUE_ENABLE, 1, &data).ok();
    let mut out = TorqueOff::default();
    for s in servos {
        let mut ok = false;
        for _ in 0..3 {
            if bus.write_u8(s.id, t::TORQUE_ENABLE, 0).is_ok()
                && matches!(bus.read_u8(s.id, t::TORQUE_ENABLE), Ok(r) if r.data == 0)
            {
                ok = true;
                break;
            }
        }
        if ok {
            bus.write_u8(s.id, t::BUS_WATCHDOG, 0).ok();
            out.confirmed.push(s.id);
        } else {
            out.unconfirmed.push(s.id);
        }
    }
    out
}
