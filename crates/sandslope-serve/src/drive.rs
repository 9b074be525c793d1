//! `serve --drive`: the robot driven while the explorer shows the run (docs/drive.md, "Watching
//! a run in the explorer").
//!
//! The run is the one `sandslope drive` makes: the server is handed the same typed
//! [`DriveConfig`] the CLI's flags are translated into, opens it into a
//! [`Session`] before it listens (the monitor's grid, the bus), and drives it once on a thread
//! of its own, so the server's pools and timeouts are those of every other run. What the page
//! reads:
//! - `GET /api/drive/status`: a [`DriveStatus`], whose `live` is the last per-stance record
//!   exactly as `drive --json`'s `live` list holds it;
//! - `POST /api/drive/stop`: the operator's stop, the path the CLI's Ctrl-C takes (the gait
//!   stops, the torque is turned off and read back).
//!
//! When the process is asked to end (the CLI's signal handler sets [`DriveThread`]'s `stop`
//! while `driving` is set), or the server fails, the gait is stopped and the torque turned off
//! before the process ends.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;

use serde::Serialize;

use sandslope_io::foxglove::DriveStream;
use sandslope_servo::driver::{DriveReport, LiveEstimate, ServoSample, TorqueOff};
use sandslope_servo::log::{drive_logged, live_record, log_row, LogTarget};
use sandslope_servo::session::{emulator_summary, DriveConfig, Session};
use sandslope_servo::speed::LegSpeedMeter;
use sandslope_servo::DriveOutcome;

use crate::reply::{json, ApiError};

/// What a served run is doing, as `/api/drive/status` answers it.
#[derive(Debug, Clone, Default, Serialize)]
pub struct DriveStatus {
    /// `off` (the server drives no robot), `standing` (torque on, legs to the start pose), `driving`, then how it ended:
    /// `completed`, `interrupted` (the stop button or the process ending), `halted`
    /// (`--stop-on-risk`) or `failed` (a bus fault: `error` says which servo and the fix).
    pub state: &'static str,
    /// Gait time of the last cycle, s (negative while standing up).
    pub time_s: f64,
    /// Bus cycles run.
    pub cycles: usize,
    /// The gait's duration, s.
    pub duration_s: f64,
    /// The slope climbed, degrees.
    pub slope_deg: f64,
    /// Whether the bus is the emulator's.
    pub emulated: bool,
    /// Commanded leg speed omega, rad/s (the robot file's).
    pub commanded_leg_speed_rad_s: f64,
    /// Measured leg speed, rad/s: the mean over the legs of each one's turn over the last
    /// stride period, from Present Position.
    pub leg_speed_rad_s: f64,
    /// `--stop-on-risk`'s threshold on P(fail), if set.
    pub stop_on_risk: Option<f64>,
    /// Whether `--stop-on-risk` halted the gait (torque held, legs planted, then torque off).
    pub halted: bool,
    /// The last live estimate (one per stance), the record `drive --json` lists under `live`.
    pub live: Option<LiveEstimate>,
    /// Live estimates so far.
    pub estimates: usize,
    /// The run's error (which servo, and the fix), once it failed.
    pub error: Option<String>,
    /// The torque read back on the way out, once the run ended.
    pub torque_off: Option<TorqueOff>,
    /// The emulator's own tables on the way out (`emulator: torque off on every servo`).
    pub emulator: Option<String>,
}

/// The served run: its status, and the flag the stop button sets.
#[derive(Debug, Default)]
pub struct LiveDrive {
    status: Mutex<DriveStatus>,
    stop: AtomicBool,
}

impl LiveDrive {
    fn update(&self, f: impl FnOnce(&mut DriveStatus)) {
        f(&mut self.status.lock().unwrap_or_else(PoisonError::into_inner));
    }

    /// A copy of the status now.
    pub fn status(&self) -> DriveStatus {
        self.status.lock().unwrap_or_else(PoisonError::into_inner).clone()
    }
}

/// Answers `/api/drive/<name>`: `status` (GET) and `stop` (POST). Without a served run the
/// status is `{"state": "off", ...}` (the page asks at every load and hides its Drive tab) and
/// a stop is a 404.
/// The body is pretty JSON, as `--json` prints.
pub fn answer(name: &str, post: bool, drive: Option<&LiveDrive>) -> Result<Vec<u8>, ApiError> {
    let Some(drive) = drive else {
        if name == "status" {
            return json(&DriveStatus { state: "off", ..Default::default() });
        }
        return Err(ApiError {
            status: 404,
            field: None,
            error: "no robot is driven: start the server with --drive (and --drive-port PATH or --emulate)"
                .into(),
        });
    };
    match (name, post) {
        ("status", _) => json(&drive.status()),
        ("stop", true) => {
            drive.stop.store(true, Ordering::SeqCst);
            json(&serde_json::json!({ "stopping": true }))
        }
        ("stop", false) => Err(ApiError {
            status: 405,
            field: None,
            error: "/api/drive/stop stops the robot: send it as a POST".into(),
        }),
        _ => Err(ApiError {
            status: 404,
            field: None,
            error: format!("no page /api/drive/{name}: /api/drive/status and /api/drive/stop"),
        }),
    }
}

/// The thread that drives a served run.
pub struct DriveThread {
    /// What the page reads.
    pub live: Arc<LiveDrive>,
    handle: Option<JoinHandle<()>>,
    /// Set by the process's signal handler (the CLI's Ctrl-C flag).
    stop: &'static AtomicBool,
}

/// Flags shared with the process's signal handler: the handler sets `stop` (and `signal`)
/// instead of ending the process while `driving` is set, and the drive thread ends the process
/// once the torque is off and the log is in place, with 128 + the signal (130 for SIGINT, 143
/// for SIGTERM, 129 for SIGHUP), as the CLI's every interrupted run exits.
#[derive(Debug, Clone, Copy)]
pub struct SignalFlags {
    /// Set by a signal while driving.
    pub stop: &'static AtomicBool,
    /// Set while the servos may have torque on.
    pub driving: &'static AtomicBool,
    /// The signal's number (0 until one arrives).
    pub signal: &'static AtomicI32,
}

/// The served run's log (`serve --drive --log`) and the names its header records.
#[derive(Debug, Clone)]
pub struct LogFile {
    /// The log's path.
    pub path: PathBuf,
    /// The robot as named on the command line.
    pub robot: String,
    /// The terrain as named on the command line.
    pub terrain: String,
}

impl DriveThread {
    /// Starts driving an opened session on a thread of its own.
    /// `foxglove`, when given, streams the run (its header already sent) to Foxglove.
    pub fn start(
        session: Session,
        flags: SignalFlags,
        log: Option<LogFile>,
        foxglove: Option<DriveStream>,
    ) -> std::io::Result<DriveThread> {
        let config: &DriveConfig = session.config();
        let live = Arc::new(LiveDrive {
            status: Mutex::new(DriveStatus {
                state: "standing",
                duration_s: config.settings.duration_s,
                slope_deg: config.slope_deg,
                emulated: session.emulated(),
                commanded_leg_speed_rad_s: session.schedule.leg_speed_rad_s,
                stop_on_risk: config.settings.stop_on_risk,
                time_s: -config.settings.stand_s,
                ..Default::default()
            }),
            stop: AtomicBool::new(false),
        });
        flags.driving.store(true, Ordering::SeqCst);
        let shared = Arc::clone(&live);
        let handle = std::thread::Builder::new()
            .name("drive".into())
            .spawn(move || run(session, &shared, flags, log, foxglove))
            .inspect_err(|_| flags.driving.store(false, Ordering::SeqCst))?;
        Ok(DriveThread { live, handle: Some(handle), stop: flags.stop })
    }

    /// Stops the gait (as Ctrl-C does) and waits until the torque is off.
    pub fn stop_and_join(mut self) {
        self.stop.store(true, Ordering::SeqCst);
        self.live.stop.store(true, Ordering::SeqCst);
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

/// A line on stderr that a closed stderr does not turn into a panic (the torque-off and the
/// process's exit code come first).
macro_rules! say {
    ($($t:tt)*) => {{
        let _ = std::io::Write::write_fmt(&mut std::io::stderr(), format_args!("{}\n", format_args!($($t)*)));
    }};
}

/// The drive thread: the run, its status kept for the page, torque off, then (after a
/// signal) the end of the process.
fn run(
    mut session: Session,
    live: &LiveDrive,
    flags: SignalFlags,
    log: Option<LogFile>,
    foxglove: Option<DriveStream>,
) {
    // Either flag stops the gait: the stop button's or the signal handler's.
    let stop = AtomicBool::new(false);
    // Each leg's speed from its positions a stride period apart, as the run's report gives it.
    let mut meter = LegSpeedMeter::with_window(
        session.config().settings.servos.len(),
        session.schedule.period_s,
        session.schedule.run_up_s,
    );
    let mut on_sample = |s: &ServoSample| {
        if live.stop.load(Ordering::Relaxed) || flags.stop.load(Ordering::Relaxed) {
            stop.store(true, Ordering::Relaxed);
        }
        if let Some(f) = &foxglove {
            f.row(log_row(s));
        }
        meter.observe(s.leg, s.time_s, s.leg_angle_rad);
        let speed = meter.mean();
        live.update(|st| {
            if s.leg == 0 {
                st.cycles += 1;
            }
            st.time_s = s.time_s;
            if st.state == "standing" && s.time_s >= 0.0 {
                st.state = "driving";
            }
            if let Some(w) = speed {
                st.leg_speed_rad_s = w;
            }
        });
    };
    let mut on_live = |l: &LiveEstimate| {
        if let Some(f) = &foxglove {
            f.live(&live_record(l));
        }
        live.update(|st| {
            st.estimates += 1;
            if let Some(p) = st.stop_on_risk {
                st.halted |= l.decision_p_fail > p;
            }
            st.live = Some(l.clone());
        });
    };
    let target = log.as_ref().map(|l| LogTarget { path: &l.path, robot: &l.robot, terrain: &l.terrain });
    let driven = drive_logged(&mut session, target, &stop, &mut on_sample, &mut on_live);
    // The log in place now: the server serves on, and the outputs a later signal finds staged
    // are discarded (the CLI stages every output until its run succeeds).
    let committed = sandslope_files::commit_outputs();
    let emulator = session.close().map(|r| emulator_summary(&r));
    let (report, mut failure) = match driven {
        Ok((report, failure)) => (report, failure.map(|e| e.to_string())),
        // The log could not be started (nothing moved).
        Err(e) => {
            (DriveReport::not_started(format!("{e:#}")), Some(format!("the log could not be written: {e:#}")))
        }
    };
    if let (Err(e), None) = (committed, &failure) {
        failure = Some(format!("the log could not be put in place: {e:#}"));
    }
    if let Some(f) = foxglove {
        f.finish(&sandslope_io::mcap_out::verdict_text(
            &report.outcome,
            failure.as_ref().map(|e| e as &dyn std::fmt::Display),
        ));
    }
    finish(live, &report, failure.as_deref(), emulator);
    if let Some(l) = &log {
        say!("drive: log {}", l.path.display());
    }
    flags.driving.store(false, Ordering::SeqCst);
    // A signal asked the process to end: the torque is off and the log in place, so it may;
    // also when the stop button had stopped the gait just before (a SIGTERM a few ms after
    // the button was lost when only the button's flag was looked at).
    if flags.stop.load(Ordering::SeqCst) {
        let signal = flags.signal.load(Ordering::SeqCst);
        let code = 128 + if signal > 0 { signal } else { 2 };
        say!("interrupted (signal {signal}): the gait was stopped and the torque turned off");
        std::process::exit(code);
    }
}

/// The run's end in the status, and on stderr as `drive` says it.
fn finish(live: &LiveDrive, report: &DriveReport, failure: Option<&str>, emulator: Option<String>) {
    let off = &report.torque_off;
    let list = |ids: &[u8]| ids.iter().map(u8::to_string).collect::<Vec<_>>().join(", ");
    say!(
        "drive: {} cycles; torque off confirmed on servos {}{}",
        report.cycles,
        if off.confirmed.is_empty() { "none".into() } else { list(&off.confirmed) },
        if off.unconfirmed.is_empty() {
            String::new()
        } else {
            format!(" (NOT confirmed on {}: their Bus Watchdog stops them)", list(&off.unconfirmed))
        }
    );
    if let Some(e) = failure {
        say!("drive: {e}");
    }
    if let Some(e) = &emulator {
        say!("{e}");
    }
    live.update(|st| {
        st.state = match (&report.outcome, failure) {
            (_, Some(_)) | (Err(_), _) => "failed",
            (Ok(DriveOutcome::Completed { .. }), None) => "completed",
            (Ok(DriveOutcome::Interrupted { .. }), None) => "interrupted",
            (Ok(DriveOutcome::Halted { .. }), None) => "halted",
        };
        st.halted = matches!(report.outcome, Ok(DriveOutcome::Halted { .. }));
        st.error = failure.map(ToString::to_string);
        st.torque_off = Some(off.clone());
        st.emulator = emulator;
    });
}
