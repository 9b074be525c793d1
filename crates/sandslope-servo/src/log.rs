//! The run's log as every front end writes it (docs/drive.md, "The log"): `sandslope drive
//! --log` and `sandslope serve --drive --log` write the same header and rows, as a flight
//! recorder (`sandslope_io::servo_log::FlightLog`): under the log's own name from the first
//! cycle, created `O_EXCL` (a symbolic link there is refused), every row flushed as it comes
//! and the file synced every second, kept on every exit.

use std::path::Path;
use std::sync::atomic::AtomicBool;

use sandslope::servo::model::VOLT_PER_VOLTAGE_UNIT;
use sandslope_io::servo_log::{FlightLog, ServoLogRow};

use crate::driver::{DriveError, DriveOutcome, DriveReport, LiveEstimate, ServoSample};
use crate::session::Session;

/// A sample as the log's row.
pub fn log_row(s: &ServoSample) -> ServoLogRow {
    ServoLogRow {
        time_s: s.time_s,
        id: s.id,
        leg: s.leg,
        tripod: s.tripod,
        present_position: s.state.position,
        present_velocity: s.state.velocity,
        present_current_ma: s.current_ma.round() as i32,
        load_percent: s.load_percent,
        input_voltage_v: f64::from(s.state.voltage) / (1.0 / VOLT_PER_VOLTAGE_UNIT).round(),
        temperature_c: i32::from(s.state.temperature_c),
        hardware_error: s.hardware_error,
        goal_position: s.goal_position,
        leg_angle_rad: s.leg_angle_rad,
        drive_torque_n_m: s.drive_torque_n_m,
    }
}

/// A live estimate as `/sandslope/live` carries it (`drive --log run.mcap`, `drive
/// --foxglove`, `serve --drive --foxglove`; docs/bags.md).
pub fn live_record(l: &LiveEstimate) -> sandslope_io::mcap_out::LiveRecord {
    let i = &l.inference;
    sandslope_io::mcap_out::LiveRecord {
        time_s: l.time_s,
        values: [
            l.tripod as f64,
            i.k_s,
            i.k_s_lo,
            i.k_s_hi,
            i.speed_m_s,
            i.speed_lo_m_s,
            i.speed_hi_m_s,
            i.p_fail,
            i.p_slippage,
            i.p_sinkage,
        ],
    }
}

/// The log's `# key = value` header: the run's robot and terrain (as named on the command
/// line), slope, k_n, timing, servos, profile and whether the bus was emulated.
pub fn log_meta(session: &Session, robot: &str, terrain: &str) -> Vec<(&'static str, String)> {
    let schedule = &session.schedule;
    let config = session.config();
    let servos = &config.settings.servos;
    let join = |v: Vec<String>| v.join(" ");
    vec![
        ("robot", robot.to_string()),
        ("terrain", terrain.to_string()),
        ("slope_deg", format!("{}", config.slope_deg)),
        ("k_n", format!("{}", session.k_n)),
        ("leg_speed_rad_s", format!("{}", schedule.leg_speed_rad_s)),
        ("period_s", format!("{}", schedule.period_s)),
        ("run_up_s", format!("{}", schedule.run_up_s)),
        ("ids", join(servos.iter().map(|s| s.id.to_string()).collect())),
        ("directions", join(servos.iter().map(|s| s.direction.to_string()).collect())),
        ("zero_offsets", join(servos.iter().map(|s| s.zero_offset_pulses.to_string()).collect())),
        ("profile", format!("{:?}", config.settings.profile).to_lowercase()),
        ("emulated", session.emulated().to_string()),
        ("rate_hz", format!("{}", config.settings.rate_hz)),
        (
            "bus_max_rate_hz",
            session
                .bus_budget()
                .map_or("not limited (emulated)".to_string(), |b| format!("{:.1}", b.max_rate_hz)),
        ),
    ]
}

/// Where a run's log goes, and the names its header records.
#[derive(Debug, Clone, Copy)]
pub struct LogTarget<'a> {
    /// The log's path.
    pub path: &'a Path,
    /// The robot as named on the command line (a preset or a file).
    pub robot: &'a str,
    /// The terrain as named on the command line.
    pub terrain: &'a str,
}

/// Drives `session` once ([`Session::drive`]), every sample handed to `on_sample` and, with a
/// `log`, written to it as a flight recorder ([`FlightLog`]: under its own name from the first
/// cycle, each row flushed at once and synced every second, `# status = incomplete` until the
/// run ends, so that a killed process leaves its rows readable up to the last second). The log
/// is finished whatever ended the run: its status lines say how, with the achieved rate and
/// jitter. A log that fails once the run has begun (a full disk, the file-size limit) is the
/// run's failure, [`DriveError::Log`], beside its report, and what was written before the
/// failure is kept (the last row may be cut short; the log's reader leaves it out and says
/// so); the error is a log that could not be started (nothing moved). A run that ended before
/// any servo was read (a missing servo, a refused setup) leaves no log.
pub fn drive_logged(
    session: &mut Session,
    log: Option<LogTarget<'_>>,
    stop: &AtomicBool,
    on_sample: &mut dyn FnMut(&ServoSample),
    on_live: &mut dyn FnMut(&LiveEstimate),
) -> anyhow::Result<(DriveReport, Option<DriveError>)> {
    let Some(target) = log else {
        return Ok(session.drive(
            stop,
            &mut |s| {
                on_sample(s);
                Ok(())
            },
            on_live,
        ));
    };
    let meta = log_meta(session, target.robot, target.terrain);
    let log = std::cell::RefCell::new(FlightLog::create(target.path, &meta)?);
    let mut first_failure: Option<std::io::Error> = None;
    let (report, failure) = session.drive(
        stop,
        &mut |s: &ServoSample| {
            on_sample(s);
            log.borrow_mut().write(&log_row(s)).map_err(|e| {
                let e = std::io::Error::new(e.kind(), format!("{}: {e}", target.path.display()));
                first_failure.get_or_insert_with(|| std::io::Error::new(e.kind(), e.to_string()));
                e
            })
        },
        &mut |l: &LiveEstimate| {
            on_live(l);
            // Both verdicts in the log, as they came (a failed note is the next row's failure).
            log.borrow_mut().note("live", &live_note(l)).ok();
        },
    );
    let log = log.into_inner();
    let time_s = match &report.outcome {
        Ok(DriveOutcome::Completed { time_s })
        | Ok(DriveOutcome::Interrupted { time_s })
        | Ok(DriveOutcome::Halted { time_s, .. }) => *time_s,
        Err(_) => 0.0,
    };
    if log.rows() == 0 {
        // Nothing was read, nothing moved: no record to keep.
        drop(log);
        std::fs::remove_file(target.path).ok();
        return Ok((report, failure));
    }
    let status = match (&report.outcome, &failure) {
        (Ok(DriveOutcome::Completed { .. }), None) => "completed".to_string(),
        (Ok(DriveOutcome::Interrupted { .. }), None) => "interrupted".to_string(),
        (Ok(DriveOutcome::Halted { .. }), None) => "halted".to_string(),
        (_, Some(e)) => format!("failed ({})", short_reason(e)),
        (Err(e), None) => format!("failed ({e})"),
    };
    let finished = log.finish(&[
        status,
        format!("{:.2}", report.rate_hz),
        format!("{:.2}", report.cycle_jitter_ms),
        format!("{:.1}", report.max_cycle_ms),
    ]);
    let log_failure = match (first_failure, finished) {
        (Some(e), _) => Some(e.to_string()),
        (None, Err(e)) => Some(format!("{}: {e}", target.path.display())),
        (None, Ok(())) => None,
    };
    let log_failure = log_failure.map(|reason| DriveError::Log { time_s, reason });
    Ok((report, failure.or(log_failure)))
}

/// A live estimate as the log's note: the stance's own estimate, the pooled one and both
/// verdicts with the decision.
pub fn live_note(l: &LiveEstimate) -> String {
    let i = &l.inference;
    let mut text = format!(
        "t {:.3} s; tripod {}; stance k_s {:.4e} [{:.4e} {:.4e}]; stance p_fail {:.4}",
        l.time_s, l.tripod, i.k_s, i.k_s_lo, i.k_s_hi, i.p_fail
    );
    if let Some(p) = &l.pooled {
        text += &format!(
            "; pooled over {} k_s {:.4e} [{:.4e} {:.4e}]; p_fail simulator {:.4}; p_fail closed form {:.4}; decision {:.4}",
            p.stances, p.k_s, p.k_s_lo, p.k_s_hi, p.p_fail_simulator, p.p_fail_closed_form, p.p_fail
        );
    }
    text
}

/// The failure's first clause, for the log's one status line.
fn short_reason(e: &DriveError) -> String {
    let text = e.to_string();
    text.split(". Fix").next().unwrap_or(&text).chars().take(70).collect()
}
