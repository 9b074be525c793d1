//! The run's log as every front end writes it (docs/drive.md, "The log"): `sandslope drive
//! --log` and `sandslope serve --drive --log` write the same header and rows, through the
//! project's one output path (`sandslope_io::files::write_output`: a temporary file with a
//! random name beside the destination, created `O_EXCL`, so no planted file or symbolic link
//! is opened, then renamed into place), flushed every ten cycles and kept on every exit.

use std::path::Path;
use std::sync::atomic::AtomicBool;

use sandslope::servo::xl330;
use sandslope_io::servo_log::{ServoLogRow, ServoLogWriter};

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
        present_current_ma: i32::from(s.state.current_ma),
        load_percent: 100.0 * f64::from(s.state.current_ma) / (xl330::STALL_CURRENT_A * 1000.0),
        input_voltage_v: f64::from(s.state.voltage) / (1.0 / xl330::VOLT_PER_VOLTAGE_UNIT).round(),
        temperature_c: i32::from(s.state.temperature_c),
        hardware_error: s.hardware_error,
        goal_position: s.goal_position,
        leg_angle_rad: s.leg_angle_rad,
        drive_torque_n_m: s.drive_torque_n_m,
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
/// `log`, written to it. The log is finished (flushed, synced) whatever ended the run, and
/// put in place as every output is (staged until the binary commits its outputs, if it
/// staged them). A log that fails once the run has begun (a full disk, the file-size limit) is
/// the run's failure, [`DriveError::Log`], beside its report, and what was written before the
/// failure is kept (the last row may be cut short; the log's reader leaves it out and says
/// so); the error is a log that could not be started (nothing moved).
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
    let mut outcome = None;
    let mut lost = None;
    let written = sandslope_io::files::write_output(target.path, |file| {
        let mut log = ServoLogWriter::new(std::io::BufWriter::new(&mut *file), &meta)?;
        let mut write = |s: &ServoSample| {
            on_sample(s);
            log.write(&log_row(s))
                .map_err(|e| std::io::Error::new(e.kind(), format!("{}: {e}", target.path.display())))
        };
        outcome = Some(session.drive(stop, &mut write, on_live));
        // The log is the record of what happened: flushed and kept on every exit, also past a
        // write that failed (a full disk, `ulimit -f`): the rows before it are what the robot
        // did, and the reader drops a last row cut short (sandslope_io::servo_log).
        let finished = log.finish();
        let first = file.take_failure();
        lost = first.or(finished.err());
        Ok(())
    });
    let Some((report, failure)) = outcome else {
        // The log could not be started: nothing moved.
        return Err(written.err().unwrap_or_else(|| anyhow::anyhow!("the run did not start")));
    };
    let time_s = match &report.outcome {
        Ok(DriveOutcome::Completed { time_s })
        | Ok(DriveOutcome::Interrupted { time_s })
        | Ok(DriveOutcome::Halted { time_s, .. }) => *time_s,
        Err(_) => 0.0,
    };
    let log_failure = match (written, lost) {
        (Err(e), _) => Some(format!("{e:#}")),
        (Ok(()), Some(e)) => Some(format!("{}: {e}", target.path.display())),
        (Ok(()), None) => None,
    };
    let log_failure = log_failure.map(|reason| DriveError::Log { time_s, reason });
    Ok((report, failure.or(log_failure)))
}
