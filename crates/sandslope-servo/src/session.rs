//! One run of the robot as every front end starts it: the typed [`DriveConfig`] that `sandslope
//! drive`'s flags and `sandslope serve --drive`'s are translated into, opened into a
//! [`Session`] (the live monitor's grid simulated, the bus opened or the emulator started,
//! before anything moves), driven once, and closed (the emulator's own tables read back).

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use sandslope::infer::servo::{model_grid, CurrentInferenceSettings, ModelGrid};
use sandslope::infer::LogUniformPrior;
use sandslope::risk::{safe_slope_limit, SafeLimit, UncertainTerrain};
use sandslope::servo::{GaitSchedule, ServoModel};
use sandslope::{Robot, Scenario, SignedSlope, Terrain};

use crate::clock::{Clock, ClockKind};
use crate::driver::{
    drive_on_clock, DriveError, DriveReport, DynamixelBus, LiveEstimate, Monitor, ServoSample,
};
use crate::emulator::{Emulator, EmulatorConfig, EmulatorFaults, EmulatorReport};
use crate::{DriveSettings, ServoConfig};

/// The live monitor's log-uniform prior on k_s, N/m^3: from sand weak enough to sink the
/// robot to the stiffest the grid's simulated walks stay reportable on.
pub const LIVE_K_S_PRIOR: (f64, f64) = (1e4, 3e7);

/// Seconds the legs take to stand to their start angles before the gait. No flag sets it; the
/// defaults of the flags of a run are the request layer's drive table
/// (`sandslope_request::drive::FIELDS`, shown by `sandslope_request::drive::RunDefaults`).
pub const STAND_S: f64 = 1.0;

/// Where the servos are.
#[derive(Debug, Clone)]
pub enum BusChoice {
    /// A Protocol 2.0 adapter's serial port at a baud rate.
    Port {
        /// `/dev/ttyUSB0`, `COM3`, ...
        path: PathBuf,
        /// Baud rate.
        baud: u32,
    },
    /// A bus of virtual servos (the robot file's model, else XL330-M288s) on a pseudo-terminal.
    Emulate(EmulateOptions),
}

/// The emulator's sand and faults (`--emulate-*`).
#[derive(Debug, Clone, Default)]
pub struct EmulateOptions {
    /// The sand's k_s, N/m^3; `None`: the terrain's at the slope.
    pub k_s: Option<f64>,
    /// Present Current noise, mA (standard deviation).
    pub noise_ma: f64,
    /// Seed of the noise.
    pub seed: u64,
    /// Present Current offsets, mA (`--emulate-offset`; [`EmulatorConfig::current_offset_ma`]).
    pub current_offset_ma: Vec<f64>,
    /// Mid-run weakening and bus faults.
    pub faults: EmulatorFaults,
    /// The clock the emulated servos and the driver's loop keep (`--emulate-clock`).
    pub clock: ClockKind,
}

/// Everything one run needs, checked by the front end that built it.
#[derive(Debug, Clone)]
pub struct DriveConfig {
    /// The robot (its gait timing; its mass and legs for the live estimate).
    pub robot: Robot,
    /// The terrain: k_n at the slope for the live estimate, and the emulated sand's default.
    pub terrain: Terrain,
    /// The slope climbed, degrees.
    pub slope_deg: f64,
    /// The driver's settings (servos in leg order, profile, duration, limits, halt on risk).
    pub settings: DriveSettings,
    /// The bus.
    pub bus: BusChoice,
    /// Estimate k_s and the risk after every stance (implied by `settings.stop_on_risk`).
    pub monitor: bool,
    /// Pool the live estimate over the last this many stances (`--live-window`); `None`: all.
    pub window: Option<usize>,
    /// Drive beyond the calibrated safe slope (`--force`); without it such a run is refused
    /// before anything moves.
    pub force: bool,
}

/// Why a run could not start (nothing was sent to a servo).
#[derive(Debug, thiserror::Error)]
pub enum SessionError {
    /// The robot's gait or the terrain at the slope is unusable.
    #[error("{0}")]
    Setting(String),
    /// The live monitor's simulated grid failed.
    #[error("live estimate: {0}")]
    Grid(String),
    /// The emulator did not start.
    #[error("--emulate: {0}")]
    Emulator(String),
    /// The port could not be opened.
    #[error("cannot open the serial port {path}: {reason}. Fix: plug in the U2D2 (or other Protocol 2.0 adapter) and check the path (ls /dev/ttyUSB* /dev/ttyACM*), that you may use it (the dialout group), or try --emulate")]
    Port {
        /// The port.
        path: PathBuf,
        /// The system's error.
        reason: String,
    },
    /// The port opened but could not be configured.
    #[error("cannot configure the serial port: {0}")]
    Bus(String),
}

/// An opened run: the bus ready, the monitor's grid simulated.
pub struct Session {
    config: DriveConfig,
    /// The commanded gait.
    pub schedule: GaitSchedule,
    /// The terrain's k_n at the slope, N/m^3.
    pub k_n: f64,
    grid: Option<ModelGrid>,
    uncertain: UncertainTerrain,
    slope: sandslope::Slope,
    bus: DynamixelBus,
    emulator: Option<Emulator>,
    /// The last drive's gait time 0 ([`DriveReport::gait_zero`]).
    gait_zero: Option<f64>,
}

impl std::fmt::Debug for Session {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Session").field("k_n", &self.k_n).field("emulated", &self.emulator.is_some()).finish()
    }
}

impl Session {
    /// Prepares the run: the schedule, the terrain at the slope, the monitor's grid of
    /// simulated stances (seconds of CPU), then the emulator or the port. Nothing moves yet.
    pub fn open(config: DriveConfig) -> Result<Session, SessionError> {
        let legs = config.settings.servos.len();
        let schedule =
            GaitSchedule::new(&config.robot, legs).map_err(|e| SessionError::Setting(e.to_string()))?;
        let signed = SignedSlope::from_degrees(config.slope_deg)
            .map_err(|e| SessionError::Setting(e.renamed("--slope").to_string()))?;
        let (ground, _) = Scenario::new(config.robot.clone(), config.terrain.clone(), None, None)
            .map_err(|e| SessionError::Setting(e.to_string()))?
            .ground_at(signed.felt());
        let k_n = ground.k_n;
        let uncertain = UncertainTerrain::new(config.terrain.clone(), None, None)
            .map_err(|e| SessionError::Setting(e.to_string()))?;
        if !config.force {
            check_safe_slope(&config, &uncertain, signed.felt())?;
        }
        let grid = if config.monitor || config.settings.stop_on_risk.is_some() {
            // The prior reaches down to 1e4 N/m^3, below the library's default 3e4: sand that
            // weak fails by sinkage at moderate slopes, and a monitor whose grid cannot hold it
            // reads it as the weakest point it has, at the regimes' border (docs/drive.md).
            let prior = LogUniformPrior::new(LIVE_K_S_PRIOR.0, LIVE_K_S_PRIOR.1).expect("a valid range");
            let inference = CurrentInferenceSettings {
                simulated_strides: 6,
                prior,
                // The live stance is read after its leg's last swing median, as a log's after
                // its swings (docs/drive.md): the grid's walks are taken the same way.
                swing_offset: true,
                ..Default::default()
            };
            Some(
                model_grid(&config.robot, k_n, signed, &inference)
                    .map_err(|e| SessionError::Grid(e.to_string()))?,
            )
        } else {
            None
        };
        let (port, emulator) = match &config.bus {
            BusChoice::Emulate(o) => {
                let cfg = emulator_config(&config, o)?;
                let (emu, port) = Emulator::start(&cfg).map_err(|e| SessionError::Emulator(e.to_string()))?;
                (port, Some(emu))
            }
            BusChoice::Port { path, baud } => {
                let port = serial2::SerialPort::open(path, *baud)
                    .map_err(|e| SessionError::Port { path: path.clone(), reason: e.to_string() })?;
                (port, None)
            }
        };
        let bus = dynamixel2::Bus::new(port).map_err(|e| SessionError::Bus(format!("{e:?}")))?;
        let slope = signed.felt();
        Ok(Session { config, schedule, k_n, grid, uncertain, slope, bus, emulator, gait_zero: None })
    }

    /// The configuration the session was opened with.
    pub fn config(&self) -> &DriveConfig {
        &self.config
    }

    /// What the bus can carry ([`crate::plan::bus_budget`]): the serial port's baud rate, the
    /// servos, Return Delay Time 0 (the setup writes it) and the adapter's latency timer (as
    /// Linux shows it; 16 ms, the FTDI driver's default, where it does not say); `None` for the
    /// emulator, whose pseudo-terminal moves bytes at once.
    pub fn bus_budget(&self) -> Option<crate::plan::BusBudget> {
        bus_budget_of(&self.config)
    }

    /// The servos' model as the run knows it before the ping: the robot file's, else the
    /// paper's XL330-M288.
    pub fn servo_model(&self) -> &'static ServoModel {
        self.config.settings.servo.unwrap_or(&ServoModel::XL330_M288)
    }

    /// Whether the bus is the emulator's.
    pub fn emulated(&self) -> bool {
        self.emulator.is_some()
    }

    /// Runs the gait once (see [`drive`]): until its duration, `stop`, a halt on risk or an
    /// error, then torque off. `on_sample` gets every servo's state every cycle, `on_live`
    /// every stance's estimate.
    pub fn drive(
        &mut self,
        stop: &AtomicBool,
        on_sample: &mut dyn FnMut(&ServoSample) -> std::io::Result<()>,
        on_live: &mut dyn FnMut(&LiveEstimate),
    ) -> (DriveReport, Option<DriveError>) {
        let noise_ma = match &self.config.bus {
            BusChoice::Emulate(o) => o.noise_ma.max(1.0),
            BusChoice::Port { .. } => 10.0,
        };
        let noise_sd_n_m = self.servo_model().torque_from_current_ma(noise_ma);
        let monitor = self.grid.as_ref().map(|g| Monitor {
            robot: &self.config.robot,
            grid: g,
            noise_sd_n_m,
            terrain: &self.uncertain,
            slope: self.slope,
            window: self.config.window,
        });
        // The emulator's clock (virtual with `--emulate-clock virtual`), else the wall's.
        let clock = self.emulator.as_ref().map_or_else(Clock::real, Emulator::clock);
        let (bus, settings) = (&mut self.bus, &self.config.settings);
        let (report, failure) =
            drive_on_clock(bus, &self.schedule, settings, monitor, stop, on_sample, on_live, &clock);
        self.gait_zero = report.gait_zero;
        (report, failure)
    }

    /// Closes the bus; with the emulator, stops it and returns what its servos' tables hold.
    pub fn close(self) -> Option<EmulatorReport> {
        drop(self.bus);
        let zero = self.gait_zero;
        self.emulator.map(|e| e.stop(zero))
    }
}

/// The emulator a run on `--emulate` starts (and `drive --emulate-pty` serves alone): the
/// run's servos, robot and slope, the sand `o.k_s` or the terrain's at the slope, the
/// options' noise, offsets and faults, and the robot file's servo model.
pub fn emulator_config(config: &DriveConfig, o: &EmulateOptions) -> Result<EmulatorConfig, SessionError> {
    let signed = SignedSlope::from_degrees(config.slope_deg)
        .map_err(|e| SessionError::Setting(e.renamed("--slope").to_string()))?;
    let (ground, _) = Scenario::new(config.robot.clone(), config.terrain.clone(), None, None)
        .map_err(|e| SessionError::Setting(e.to_string()))?
        .ground_at(signed.felt());
    let (k_n, ground_k_s) = (ground.k_n, ground.k_s);
    if o.k_s.is_none() && ground_k_s.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Err(SessionError::Setting(format!(
                "--slope {}: the terrain's sand has no shear strength at this slope (k_s = {}: at or beyond its angle of repose), so the emulator has no sand to walk on; give the emulated sand's k_s with --emulate-k-s, or a shallower --slope",
                config.slope_deg, ground_k_s
            )));
    }
    let k_s = o.k_s.unwrap_or(ground_k_s);
    let sand = Terrain::constant(k_n, k_s)
        .map_err(|e| SessionError::Setting(e.renamed("--emulate-k-s").to_string()))?;
    let mut cfg =
        EmulatorConfig::new(config.robot.clone(), sand, config.slope_deg, config.settings.servos.clone());
    cfg.current_noise_ma = o.noise_ma;
    cfg.seed = o.seed;
    cfg.current_offset_ma = o.current_offset_ma.clone();
    cfg.faults = o.faults;
    cfg.clock = o.clock;
    cfg.model_number = config.settings.servo.map_or(cfg.model_number, |m| m.model_number);
    Ok(cfg)
}

/// The risk the safe slope is searched at when `--stop-on-risk` does not give one.
pub const SAFE_SLOPE_RISK: f64 = 0.5;

/// Refuses a slope beyond the calibrated safe-slope limit (`risk --solve slope`: p_fail below
/// `--stop-on-risk`, else 0.5, from level up to it), naming the limit and `--force`.
fn check_safe_slope(
    config: &DriveConfig,
    terrain: &UncertainTerrain,
    slope: sandslope::Slope,
) -> Result<(), SessionError> {
    let risk = config.settings.stop_on_risk.filter(|p| *p > 0.0 && *p < 1.0).unwrap_or(SAFE_SLOPE_RISK);
    let limit =
        safe_slope_limit(&config.robot, terrain, risk).map_err(|e| SessionError::Setting(e.to_string()))?;
    let deg = slope.degrees();
    let beyond = match limit {
        SafeLimit::NoneSafe { .. } => Some("no slope is (p_fail is above it from level)".to_string()),
        SafeLimit::Limit { value, .. } if deg > value => Some(format!("the limit is {value:.1} deg")),
        SafeLimit::Repose { repose_deg, .. } if deg >= repose_deg => {
            Some(format!("the limit is the sand's angle of repose, {repose_deg:.1} deg"))
        }
        _ => None,
    };
    match beyond {
        Some(why) => Err(SessionError::Setting(format!(
            "--slope {} is beyond the calibrated safe slope for this robot on this terrain (p_fail < {risk} from level up to it; `sandslope risk --solve slope --max-risk {risk}`): {why}. Nothing was moved. Fix: a shallower --slope, or --force to drive anyway (expect the legs to slip or sink; --stop-on-risk halts the gait when the live risk passes it)",
            config.slope_deg
        ))),
        None => Ok(()),
    }
}

/// [`Session::bus_budget`] of a run not yet opened.
pub fn bus_budget_of(config: &DriveConfig) -> Option<crate::plan::BusBudget> {
    match &config.bus {
        BusChoice::Emulate(_) => None,
        BusChoice::Port { path, baud } => {
            let latency = crate::plan::usb_latency_s(path).unwrap_or(DEFAULT_USB_LATENCY_S);
            Some(crate::plan::bus_budget(*baud, config.settings.servos.len(), 0.0, latency))
        }
    }
}

/// The USB-serial latency timer assumed where the system does not show it, s: 16 ms, the Linux
/// FTDI driver's default (the U2D2 is an FTDI FT232H).
pub const DEFAULT_USB_LATENCY_S: f64 = 0.016;

/// The servos of a robot file without a `[servos]` table: IDs 1 to `legs` in leg order, the
/// first half (the left side) turning positive and the second half mirrored, zero offsets 0
/// (docs/drive.md, "Wiring and IDs").
pub fn default_servos(legs: usize) -> Vec<ServoConfig> {
    (0..legs)
        .map(|j| ServoConfig {
            id: u8::try_from(j + 1).unwrap_or(u8::MAX),
            direction: if j < legs / 2 { 1 } else { -1 },
            zero_offset_pulses: 0,
        })
        .collect()
}

/// The emulator's last word, as `drive` prints it: whether any servo's torque is still on,
/// whose Bus Watchdog fired, and the packet counts.
pub fn emulator_summary(r: &EmulatorReport) -> String {
    let on: Vec<String> =
        r.torque_enabled.iter().filter(|(_, on)| *on).map(|(id, _)| id.to_string()).collect();
    let fired: Vec<String> = r
        .watchdog
        .iter()
        .filter(|(_, w)| *w == crate::table::WATCHDOG_FIRED)
        .map(|(id, _)| id.to_string())
        .collect();
    let weakened = match r.weakened {
        Some((t, k_s)) => format!("; the sand weakened to k_s {k_s:.3e} N/m^3 at t = {t:.2} s"),
        None => String::new(),
    };
    format!(
        "emulator: torque {}{} ({} packets, {} with a bad CRC){weakened}",
        if on.is_empty() {
            "off on every servo".to_string()
        } else {
            format!("still ON on servos {}", on.join(", "))
        },
        if fired.is_empty() {
            String::new()
        } else {
            format!("; Bus Watchdog fired on servos {} (stopped)", fired.join(", "))
        },
        r.packets,
        r.bad_crc
    )
}
