//! `sandslope drive`: the robot in the loop (docs/drive.md). The alternating tripod of the
//! robot file's timing sent to Dynamixel servos (XL330-M288s, or another model of
//! `sandslope::servo::ServoModel`) over Protocol 2.0 (`sandslope-servo`), every
//! servo's state logged at the bus's rate, and, with `--live` or `--stop-on-risk`, the sand's
//! k_s and the risk that the walk fails (slippage or sinkage) read from the stance currents after every stance
//! (`sandslope::infer::servo`). `--emulate` drives a bus of virtual servos on a
//! pseudo-terminal through the same code; `--dry-run` prints the commands without a bus.

use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::Ordering;

use anyhow::{anyhow, bail, Result};
use clap::Args;

use sandslope::servo::{GaitSchedule, ServoModel};
use sandslope_io::robot_terrain::load_servos;
use sandslope_io::servo_log::DEFAULT_BAUD_RATE;
use sandslope_request::drive::{DriveFields, DriveRun, EMULATE_FAULT, EMULATE_OFFSET, EMULATE_WEAKEN};
use sandslope_request::field::Field;
use sandslope_request::scenario::{ROBOT, TERRAIN};
use sandslope_servo::clock::ClockKind;
use sandslope_servo::driver::{DriveReport, LiveEstimate};
use sandslope_servo::emulator::EmulatorFaults;
use sandslope_servo::log::{drive_logged, live_record, LogTarget};
use sandslope_servo::session::{
    default_servos, emulator_summary, BusChoice, DriveConfig, EmulateOptions, Session, STAND_S,
};
use sandslope_servo::table as t;
use sandslope_servo::{DriveSettings, Profile, ServoConfig};

#[path = "drive_bench.rs"]
mod bench;

use crate::args::{FieldArgs, RobotArgs, TerrainArgs};
use crate::error::{KeepLog, EXIT_HALTED};
use crate::output::{check_parent_exists, print_json};

/// Arguments of `sandslope drive`.
#[derive(Debug, Args)]
pub struct DriveArgs {
    /// Serial port of the Protocol 2.0 adapter (U2D2 or any): /dev/ttyUSB0, /dev/ttyACM0, COM3.
    #[arg(long, value_name = "PATH", required_unless_present_any = ["emulate", "dry_run"])]
    pub port: Option<PathBuf>,
    /// Drive a bus of emulated servos (the robot file's [servos] model, else XL330-M288s; a pseudo-terminal; currents from the stride simulator on
    /// --terrain at --slope) instead of a port.
    #[arg(long, conflicts_with = "port")]
    pub emulate: bool,
    /// Print the commands (setup writes, then every cycle's goals as CSV) without opening a bus.
    #[arg(long, conflicts_with_all = ["port", "emulate"])]
    pub dry_run: bool,
    /// With every leg set by hand at leg angle 0 (the torque off), read each servo's Present
    /// Position and write them into the robot file's [servos] zero_offsets; nothing moves
    /// (docs/drive.md, "On the bench").
    #[arg(long, conflicts_with_all = ["dry_run", "pty"])]
    pub zero: bool,
    /// With --emulate: serve the emulated servos alone on a pseudo-terminal, its path the first
    /// line on stdout, for Dynamixel Wizard or the ROBOTIS SDK, for S seconds (left out or 0:
    /// until Ctrl-C); no gait is driven.
    #[arg(long, value_name = "S", num_args = 0..=1, default_missing_value = "0", requires = "emulate")]
    pub pty: Option<f64>,
    #[command(flatten)]
    pub robot: RobotArgs,
    /// Terrain: k_n at the slope for the live estimate, and the emulated sand.
    #[command(flatten)]
    pub terrain: TerrainArgs,
    #[command(flatten)]
    pub run: DriveRunArgs,
    /// Print the live estimate of k_s and the risk after every stance (implied by --stop-on-risk).
    #[arg(long)]
    pub live: bool,
    /// Print the run's report as JSON.
    #[arg(long)]
    pub json: bool,
    /// Stream the channels of `--log run.mcap` live to Foxglove over its WebSocket protocol
    /// on ADDR (default 127.0.0.1:8765, loopback only; docs/bags.md, "Watch live").
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = sandslope_io::foxglove::DEFAULT_ADDR)]
    pub foxglove: Option<String>,
}

/// The flags of a run that `drive` and `serve --drive` share: the gait, the limits, the halt on
/// risk and the emulator's sand and faults. Each command adds its own bus flags (`drive --port`,
/// `serve --drive-port`) and `--emulate`, which the `--emulate-*` flags require.
#[derive(Debug, Clone, Args)]
pub struct DriveRunArgs {
    /// Write every servo's state every cycle to this CSV (docs/drive.md, "The log"), kept on
    /// every exit.
    #[arg(long, value_name = "FILE")]
    pub log: Option<PathBuf>,
    /// The run's fields, `--slope` to `--emulate-offset` ([`sandslope_request::drive::FIELDS`]).
    #[command(flatten)]
    pub fields: FieldArgs<DriveFields>,
}

impl DriveRunArgs {
    /// Whether any of the run's flags was given.
    pub fn given(&self) -> bool {
        self.log.is_some() || !self.fields.pairs.is_empty()
    }

    /// The run's fields read by the request layer's one raw-to-typed step (defaults from its
    /// table, every number checked); the `--emulate-*` flags only when `emulate`.
    pub fn fields(&self, emulate: bool) -> Result<DriveFields> {
        Ok(DriveFields::from_params(&self.fields.pairs, emulate)?)
    }
}

/// Where a run's servos are, as the front end's flags say.
#[derive(Debug, Clone)]
pub enum BusFlag {
    /// `--port` (`serve --drive-port`).
    Port(PathBuf),
    /// `--emulate`.
    Emulate,
    /// `--dry-run`: no bus.
    None,
}

/// `--emulate-offset`: one value, or one per servo (`legs`), each within -500 to 500 mA.
fn parse_offsets(text: &str, legs: usize) -> Result<Vec<f64>> {
    let v: Vec<f64> = text.split(',').map(|x| number(&EMULATE_OFFSET, x, text)).collect::<Result<_>>()?;
    if v.len() != 1 && v.len() != legs {
        bail!(
            "--emulate-offset `{text}`: give one value (every servo) or {legs} (one per servo), not {}",
            v.len()
        );
    }
    if let Some(x) = v.iter().find(|x| !(-500.0..=500.0).contains(*x)) {
        bail!("--emulate-offset `{text}`: {x} mA is outside -500 to 500 mA");
    }
    Ok(v)
}

/// One number of a list or pair given to `field`, an error naming its flag.
fn number(field: &Field, text: &str, whole: &str) -> Result<f64> {
    text.trim().parse::<f64>().map_err(|_| anyhow!("{}: `{text}` is not a number (in {whole})", field.long()))
}

/// A fault's time, s: a finite number at least 0.
fn fault_time(text: &str, whole: &str) -> Result<f64> {
    let t = number(&EMULATE_FAULT, text, whole)?;
    if !(t.is_finite() && t >= 0.0) {
        bail!("--emulate-fault `{whole}`: the time `{text}` must be a finite number of seconds, at least 0");
    }
    Ok(t)
}

fn parse_faults(args: &DriveFields, servos: &[ServoConfig]) -> Result<EmulatorFaults> {
    let mut f = EmulatorFaults::default();
    if let Some(w) = &args.emulate_weaken {
        let (s, k) =
            w.split_once(':').ok_or_else(|| anyhow!("--emulate-weaken `{w}` must be S:K_S, e.g. 3:2e5"))?;
        let (s, k) = (number(&EMULATE_WEAKEN, s, w)?, number(&EMULATE_WEAKEN, k, w)?);
        if !(s >= 0.0 && k > 0.0 && k.is_finite() && s.is_finite()) {
            bail!("--emulate-weaken `{w}`: S must be at least 0 and K_S a finite number above 0");
        }
        f.weaken = Some((s, k));
    }
    if let Some(text) = &args.emulate_fault {
        let parts: Vec<&str> = text.split(':').collect();
        let on_bus: Vec<String> = servos.iter().map(|s| s.id.to_string()).collect();
        let id = |s: &str| -> Result<u8> {
            let id = s.trim().parse::<u8>().ok().filter(|&i| i <= 252).ok_or_else(|| {
                anyhow!("--emulate-fault: `{s}` is not a servo ID from 0 to 252 (in {text})")
            })?;
            if !servos.iter().any(|c| c.id == id) {
                bail!(
                    "--emulate-fault `{text}`: servo ID {id} is not on the bus (the robot's servos are IDs {})",
                    on_bus.join(", ")
                );
            }
            Ok(id)
        };
        let t = |s: &str| fault_time(s, text);
        match parts.as_slice() {
            ["silent", i, s] => f.silent = Some((id(i)?, t(s)?)),
            ["corrupt", i, s] => f.corrupt = Some((id(i)?, t(s)?)),
            ["reject", i, s] => f.reject = Some((id(i)?, t(s)?)),
            ["latched", i] => f.latched = Some((id(i)?, 1 << 5)),
            ["freeze", s, len] => {
                let len = t(len)?;
                if len <= 0.0 {
                    bail!("--emulate-fault `{text}`: LEN must be above 0 s");
                }
                f.freeze = Some((t(s)?, len))
            }
            _ => bail!(
                "--emulate-fault `{text}` must be silent:ID:S, corrupt:ID:S, reject:ID:S, latched:ID or freeze:S:LEN"
            ),
        }
    }
    Ok(f)
}

/// The servos: the robot file's `[servos]` table, or IDs 1 to 2n with the left side (the first
/// n) turning positive and the right side mirrored.
/// Also the `[servos] model` named there, if any.
pub(crate) fn servos(
    robot_spec: &str,
    baud: Option<u32>,
    legs: usize,
) -> Result<(Vec<ServoConfig>, u32, Option<&'static ServoModel>)> {
    let table = load_servos(robot_spec)?;
    let model = table.as_ref().and_then(|s| s.model);
    let (list, file_baud) = match table {
        Some(s) => (
            s.mounts
                .iter()
                .map(|m| ServoConfig {
                    id: m.id,
                    direction: m.direction,
                    zero_offset_pulses: m.zero_offset_pulses,
                })
                .collect::<Vec<_>>(),
            s.baud_rate,
        ),
        None => (default_servos(legs), DEFAULT_BAUD_RATE),
    };
    if list.len() != legs {
        bail!(
            "{robot_spec}: [servos] ids lists {} servos; the alternating tripod of this robot (stance_legs = {}) needs {legs}",
            list.len(),
            legs / 2
        );
    }
    Ok((list, baud.unwrap_or(file_baud), model))
}

/// The typed run that `drive`'s flags (and `serve --drive`'s, the same [`DriveRunArgs`]) make,
/// `fields` read and checked by the request layer ([`DriveRunArgs::fields`]); the servos from the
/// robot file `robot_spec`.
pub fn config(
    fields: &DriveFields,
    robot: sandslope::Robot,
    robot_spec: &str,
    terrain: sandslope::Terrain,
    bus: BusFlag,
    monitor: bool,
) -> Result<DriveConfig> {
    let emulate = matches!(bus, BusFlag::Emulate);
    let (run, args) = (&fields.run, fields);
    let legs = 2 * robot.stance_legs() as usize;
    let current_offset_ma = match &args.emulate_offset {
        Some(text) if emulate => parse_offsets(text, legs)?,
        _ => vec![],
    };
    GaitSchedule::new(&robot, legs).map_err(|e| anyhow!("{robot_spec}: {e}"))?;
    let (servos, baud, model) = servos(robot_spec, args.baud, legs)?;
    let faults = if emulate { parse_faults(args, &servos)? } else { EmulatorFaults::default() };
    if let Some(b) = args.baud {
        if !sandslope_io::servo_log::BAUD_RATES.contains(&b) {
            bail!("--baud = {b} must be one the servos support: {:?}", sandslope_io::servo_log::BAUD_RATES);
        }
    }
    let settings = DriveSettings {
        servos,
        profile: if args.profile == "velocity" { Profile::Velocity } else { Profile::Position },
        duration_s: run.duration_s,
        rate_hz: run.rate_hz,
        current_limit_ma: run.current_limit_ma,
        temperature_limit_c: run.temperature_limit_c,
        watchdog_s: run.watchdog_s,
        bus_watchdog_s: run.bus_watchdog_s,
        stop_on_risk: run.stop_on_risk,
        hold_s: run.hold_s,
        stand_s: STAND_S,
        servo: model,
    };
    // Every goal within the servos' ranges for the whole run, from the worst start a cleared
    // revolution counter allows (the driver checks again from where the legs stand).
    let schedule = GaitSchedule::new(&robot, legs)?;
    if let Err(short) = sandslope_servo::plan::check_goal_range(
        &schedule,
        &settings.servos,
        settings.profile,
        settings.duration_s,
        None,
    ) {
        bail!(
            "--duration = {} s is longer than the position profile's goals can reach: in extended position mode a servo's Goal Position must stay within -1,048,575 to 1,048,575 pulses (256 turns), which at {:.3} rad/s ({:.3} turns/s) lasts {:.1} s from the start pose. Fix: --duration {:.0} or less, or --profile velocity (no position goal; Goal Velocity stays within the Velocity Limit)",
            run.duration_s,
            schedule.leg_speed_rad_s,
            schedule.leg_speed_rad_s / std::f64::consts::TAU,
            short.longest_s,
            short.longest_s.floor()
        );
    }
    let bus = match bus {
        BusFlag::Port(path) => BusChoice::Port { path, baud },
        BusFlag::Emulate | BusFlag::None => BusChoice::Emulate(EmulateOptions {
            k_s: run.emulate_k_s,
            noise_ma: run.emulate_noise_ma.unwrap_or_default(),
            seed: args.emulate_seed,
            current_offset_ma,
            faults,
            clock: ClockKind::parse(&args.emulate_clock).unwrap_or_default(),
        }),
    };
    Ok(DriveConfig {
        robot,
        terrain,
        slope_deg: run.slope_deg,
        settings,
        bus,
        monitor,
        window: args.live_window,
        force: args.force,
    })
}

impl DriveArgs {
    /// Where the servos are: `--emulate`, `--port`, else none (`--dry-run`, `--zero`).
    fn bus(&self) -> BusFlag {
        match (&self.port, self.emulate) {
            (_, true) => BusFlag::Emulate,
            (Some(p), false) => BusFlag::Port(p.clone()),
            (None, false) => BusFlag::None,
        }
    }
}

/// Runs `sandslope drive`.
pub fn run(args: DriveArgs) -> Result<()> {
    let robot = args.robot.load()?;
    let terrain = args.terrain.load()?;
    let bus = args.bus();
    let fields = args.run.fields(matches!(bus, BusFlag::Emulate))?;
    let monitor = args.live || fields.run.stop_on_risk.is_some();
    let config = config(&fields, robot, &args.robot.robot, terrain, bus, monitor)?;
    if args.zero {
        return bench::zero(&config, &args.robot.robot);
    }
    if let Some(seconds) = args.pty {
        if !(seconds.is_finite() && (0.0..=86_400.0).contains(&seconds)) {
            bail!("--pty {seconds} must be between 0 and 86400 s (0: until Ctrl-C)");
        }
        return bench::serve_pty(&config, seconds);
    }
    if args.dry_run {
        let schedule = GaitSchedule::new(&config.robot, config.settings.servos.len())?;
        return dry_run(&schedule, &config.settings);
    }
    if let Some(p) = &args.run.log {
        check_parent_exists(p)?;
        refuse_input_as_log(
            p,
            &[(&args.robot.robot, &ROBOT.long()), (&args.terrain.terrain, &TERRAIN.long())],
        )?;
    }
    check_bus_budget(&config)?;
    // The live monitor's grid of simulated stance profiles and the bus (the emulator's
    // simulated walk), before anything moves.
    let foxglove = args.foxglove.as_deref().map(sandslope_io::foxglove::DriveStream::start).transpose()?;
    let mut session = Session::open(config)?;
    // Ctrl-C from here on stops the gait and turns the torque off rather than ending the process.
    crate::error::DRIVING.store(true, Ordering::SeqCst);
    // The setup above can take seconds; say when the servos are about to move and how to stop them.
    let servos = session.config().settings.servos.clone();
    say(format_args!(
        "driving {} servos for {} s: Ctrl-C stops the gait and turns the torque off",
        servos.len(),
        fields.run.duration_s
    ));
    let quiet = args.json;
    let mut on_live = |l: &LiveEstimate| {
        if !quiet {
            let i = &l.inference;
            say(format_args!(
                "t = {:.2} s, tripod {}: k_s {:.3e} [{:.3e} - {:.3e}] N/m^3, speed {:.1} [{:.1} - {:.1}] cm/s, P(fail) {:.3} (slippage {:.3}, sinkage {:.3})",
                l.time_s,
                l.tripod,
                i.k_s,
                i.k_s_lo,
                i.k_s_hi,
                100.0 * i.speed_m_s,
                100.0 * i.speed_lo_m_s,
                100.0 * i.speed_hi_m_s,
                i.p_fail,
                i.p_slippage,
                i.p_sinkage
            ));
            if let Some(p) = &l.pooled {
                say(format_args!(
                    "  pooled over {} stance(s): k_s {:.3e} [{:.3e} - {:.3e}] N/m^3; P(fail) {:.3} (simulator {:.3}, closed form {:.3})",
                    p.stances, p.k_s, p.k_s_lo, p.k_s_hi, p.p_fail, p.p_fail_simulator, p.p_fail_closed_form
                ));
            }
        }
        foxglove.iter().for_each(|f| f.live(&live_record(l)));
    };
    let stop = &crate::error::STOP;
    // `--log run.mcap`: the rows kept in memory and written as ROS 2 messages (docs/bags.md).
    let mcap =
        args.run.log.as_deref().filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("mcap")));
    let log = args.run.log.as_deref().filter(|_| mcap.is_none()).map(|path| LogTarget {
        path,
        robot: &args.robot.robot,
        terrain: &args.terrain.terrain,
    });
    let (mut rows, meta) =
        (Vec::new(), sandslope_servo::log::log_meta(&session, &args.robot.robot, &args.terrain.terrain));
    foxglove.iter().for_each(|f| f.header(&meta));
    let on_sample = &mut |s: &sandslope_servo::driver::ServoSample| {
        rows.extend(mcap.map(|_| sandslope_servo::log::log_row(s)));
        foxglove.iter().for_each(|f| f.row(sandslope_servo::log::log_row(s)));
    };
    let (report, failure) = drive_logged(&mut session, log, stop, on_sample, &mut on_live)?;
    foxglove.into_iter().for_each(|f| {
        f.finish(&sandslope_io::mcap_out::verdict_text(
            &report.outcome,
            failure.as_ref().map(|e| e as &dyn std::fmt::Display),
        ))
    });
    if let Some(path) = mcap {
        write_mcap_log(path, &rows, &report, &meta, failure.as_ref())?;
    }
    crate::error::DRIVING.store(false, Ordering::SeqCst);
    let budget = session.bus_budget();
    let emulator = session.close().map(|r| emulator_summary(&r));
    if let Some(e) = &emulator {
        say(format_args!("{e}"));
    }
    summarise(&report, quiet);
    // Everything said from here on may meet a closed stdout or stderr (a pipe's reader gone, a
    // hung-up terminal): the torque is off and the log finished, and the exit code is the
    // run's own.
    let printed = if args.json {
        // The report and the emulator's last word, the keys Python's `sandslope.drive` returns.
        let mut value = serde_json::to_value(&report)?;
        value["emulator"] = emulator.clone().into();
        value["bus_max_rate_hz"] = budget.map(|b| b.max_rate_hz).into();
        print_json(&value)
    } else {
        Ok(())
    };
    let verdict = verdict(failure, &report, &fields.run);
    match (verdict, printed) {
        (Err(e), _) => Err(e),
        (Ok(()), printed) => printed,
    }
}

/// The run's exit: its failure, a signal's code, a halt's, or success.
fn verdict(failure: Option<sandslope_servo::DriveError>, report: &DriveReport, run: &DriveRun) -> Result<()> {
    match (failure, &report.outcome) {
        (Some(e), _) => {
            let code = e.exit_code();
            Err(KeepLog { code, message: e.to_string() }.into())
        }
        (None, Ok(sandslope_servo::DriveOutcome::Interrupted { time_s })) => {
            let (code, signal) = crate::error::stop_signal();
            Err(KeepLog {
                code,
                message: format!("interrupted ({signal}) at t = {time_s:.2} s; the torque was turned off"),
            }
            .into())
        }
        (None, Ok(sandslope_servo::DriveOutcome::Halted { time_s, p_fail })) => Err(KeepLog {
            code: EXIT_HALTED,
            message: format!(
                "--stop-on-risk: halted at t = {time_s:.2} s, P(fail) = {p_fail:.3} > {}; the legs were held {} s, then the torque was turned off",
                run.stop_on_risk.unwrap_or(1.0),
                run.hold_s
            ),
        }
        .into()),
        _ => Ok(()),
    }
}

/// One line on stderr that never fails the run: a closed stderr (a pipe's reader gone, a
/// hung-up terminal) must not skip the torque-off nor change the exit code (`eprintln!`
/// would panic).
fn say(text: std::fmt::Arguments<'_>) {
    let _ = writeln!(std::io::stderr(), "{text}");
}

/// Refuses a log path that is one of the run's inputs (`--log r.toml --robot r.toml` would
/// replace the robot file with the log).
fn refuse_input_as_log(log: &std::path::Path, inputs: &[(&str, &str)]) -> Result<()> {
    let resolved = |p: &std::path::Path| -> Option<PathBuf> {
        p.canonicalize().ok().or_else(|| {
            let parent =
                p.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(std::path::Path::new("."));
            Some(parent.canonicalize().ok()?.join(p.file_name()?))
        })
    };
    let Some(out) = resolved(log) else { return Ok(()) };
    for (input, flag) in inputs {
        let path = std::path::Path::new(input);
        if path.is_file() && path.canonicalize().ok().as_ref() == Some(&out) {
            bail!(
                "--log {}: that is the run's {flag} file; the log would replace it. Give the log another path",
                log.display()
            );
        }
    }
    Ok(())
}

/// What the bus can carry at its baud rate against `--rate` (docs/drive.md, "The loop rate"):
/// a warning with the fix before anything moves when it cannot keep up, refused when one
/// cycle would take longer than `--watchdog`.
fn check_bus_budget(config: &DriveConfig) -> Result<()> {
    let Some(b) = sandslope_servo::session::bus_budget_of(config) else { return Ok(()) };
    let rate = config.settings.rate_hz;
    let fix = format!(
        "Fix: a faster baud rate (--baud 1000000, set in each servo's Baud Rate (8) with Dynamixel Wizard and in the robot file's [servos] baud_rate), the adapter's USB latency timer at 1 ms (Linux: echo 1 | sudo tee /sys/bus/usb-serial/devices/ttyUSB0/latency_timer; it is {:.0} ms), or a lower --rate; drive sets Return Delay Time to 0",
        1e3 * b.latency_s
    );
    if b.cycle_s > config.settings.watchdog_s {
        bail!(
            "at {} baud one cycle of {} servos takes {:.0} ms ({} bytes and the adapter's latency), more than --watchdog {} s: the run would stop at its first cycle. {fix}",
            b.baud,
            b.servos,
            1e3 * b.cycle_s,
            b.bytes,
            config.settings.watchdog_s
        );
    }
    if b.max_rate_hz < rate {
        say(format_args!(
            "warning: --rate {rate} Hz asks for {:.1} ms cycles, but at {} baud one cycle of {} servos takes {:.1} ms ({} bytes, and {:.0} ms of USB latency): the loop will run at about {:.1} Hz at most. {fix}",
            1e3 / rate,
            b.baud,
            b.servos,
            1e3 * b.cycle_s,
            b.bytes,
            1e3 * b.latency_s,
            b.max_rate_hz
        ));
    }
    Ok(())
}

fn summarise(r: &DriveReport, quiet: bool) {
    if quiet {
        return;
    }
    let off = &r.torque_off;
    say(format_args!(
        "{} cycles at {:.1} Hz (jitter {:.1} ms, longest cycle {:.0} ms); torque off confirmed on servos {}{}",
        r.cycles,
        r.rate_hz,
        r.cycle_jitter_ms,
        r.max_cycle_ms,
        if off.confirmed.is_empty() {
            "none".into()
        } else {
            off.confirmed.iter().map(|i| i.to_string()).collect::<Vec<_>>().join(", ")
        },
        if off.unconfirmed.is_empty() {
            String::new()
        } else {
            format!(
                " (NOT confirmed on {}: they did not answer; their Bus Watchdog stops them)",
                off.unconfirmed.iter().map(|i| i.to_string()).collect::<Vec<_>>().join(", ")
            )
        }
    ));
    if let Some(p) = r.live.last().and_then(|l| l.pooled.as_ref()) {
        let _ = writeln!(
            std::io::stdout(),
            "pooled estimate over {} stance(s): k_s {:.3e} [{:.3e} - {:.3e}] N/m^3, P(fail) {:.3} (simulator {:.3}, closed form {:.3})",
            p.stances,
            p.k_s,
            p.k_s_lo,
            p.k_s_hi,
            p.p_fail,
            p.p_fail_simulator,
            p.p_fail_closed_form
        );
    }
    if let Some(last) = r.live.last() {
        let i = &last.inference;
        let _ = writeln!(
            std::io::stdout(),
            "last stance's estimate: k_s {:.3e} [{:.3e} - {:.3e}] N/m^3, P(fail) {:.3} (slippage {:.3}, sinkage {:.3}) at {} deg",
            i.k_s,
            i.k_s_lo,
            i.k_s_hi,
            i.p_fail,
            i.p_slippage,
            i.p_sinkage,
            i.slope_deg
        );
    }
}

/// `--dry-run`: the setup writes, then every cycle's goals as CSV on stdout.
fn dry_run(schedule: &GaitSchedule, s: &DriveSettings) -> Result<()> {
    let ids: Vec<String> = s.servos.iter().map(|c| c.id.to_string()).collect();
    println!("# dry run: no bus opened; the commands `sandslope drive` sends (docs/drive.md)");
    let model = s.servo.unwrap_or(&ServoModel::XL330_M288);
    println!(
        "# ping IDs {} (model {} expected: the {}{})",
        ids.join(", "),
        model.model_number,
        model.name,
        if s.servo.is_some() {
            ", the robot file's [servos] model"
        } else {
            "; a run takes the model the servos report"
        }
    );
    // The driver's own setup list: what `drive` writes is what the dry run prints.
    let table = sandslope_servo::models::ControlTable::of(model);
    for w in sandslope_servo::driver::setup_writes(schedule, s, table) {
        println!("# write {} ({}) = {} on IDs {}", w.name, w.addr, w.value, ids.join(", "));
    }
    if s.profile == Profile::Position {
        println!("# clear the revolution counter (Clear instruction) on IDs {}", ids.join(", "));
    }
    println!("# write Torque Enable ({}) = 1 on IDs {}", t::TORQUE_ENABLE, ids.join(", "));
    let limit = sandslope_servo::driver::velocity_limit_units(schedule, model);
    let goal = match s.profile {
        Profile::Position => "goal_position",
        Profile::Velocity => "goal_velocity",
    };
    println!("time_s,id,leg,tripod,leg_angle_rad,{goal}");
    let n = (s.duration_s * s.rate_hz).floor() as usize;
    if n > 10_000_000 {
        bail!("--dry-run: {n} cycles is more than 10,000,000 lines; shorten --duration or lower --rate");
    }
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    for k in 0..=n {
        let time = k as f64 / s.rate_hz;
        for (j, c) in s.servos.iter().enumerate() {
            let cmd = schedule.command(j, time);
            let value = match s.profile {
                Profile::Position => i64::from(c.pulses(cmd.angle_rad)),
                Profile::Velocity => i64::from(sandslope_servo::guard::velocity_goal(
                    f64::from(c.direction) * cmd.velocity_rad_s,
                    limit,
                )),
            };
            std::io::Write::write_fmt(
                &mut out,
                format_args!("{time:.4},{},{j},{},{:.6},{value}\n", c.id, schedule.tripods[j], cmd.angle_rad),
            )?;
        }
    }
    std::io::Write::flush(&mut out)?;
    println!("# write Torque Enable (64) = 0 on IDs {} (every exit)", ids.join(", "));
    Ok(())
}

/// `--log run.mcap`: the run's rows, live estimates and outcome as ROS 2 messages
/// (`sandslope_io::mcap_out::drive_mcap`, docs/bags.md).
fn write_mcap_log(
    path: &std::path::Path,
    rows: &[sandslope_io::servo_log::ServoLogRow],
    report: &DriveReport,
    meta: &[(&str, String)],
    failure: Option<&sandslope_servo::DriveError>,
) -> Result<()> {
    use sandslope_io::mcap_out::{drive_mcap, LiveRecord};
    let live: Vec<LiveRecord> = report.live.iter().map(live_record).collect();
    let verdict =
        sandslope_io::mcap_out::verdict_text(&report.outcome, failure.map(|e| e as &dyn std::fmt::Display));
    sandslope_files::write_atomic(path, &drive_mcap(rows, &live, meta, &verdict)?)
}
