//! The robot in the loop from Python (docs/drive.md): a servo log read into NumPy columns,
//! `infer --servo-log` on a log's arrays, and a run of `drive --emulate` (the emulator on a
//! pseudo-terminal, driven through the same `dynamixel2` bus code as a robot) returning its log
//! as columns and its report as `drive --json` prints it.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use pythonize::pythonize;

use sandslope::infer::servo::{infer_servo_log as infer, CurrentInferenceSettings, LegTrace};
use sandslope_io::servo_log::ServoLogRow;
use sandslope_request::drive::{emulate_clock_keyword, DriveRun, RunDefaults};
use sandslope_request::error::Words;
use sandslope_request::infer::{prior_in, servo_grid_points, ServoLogRequest};
use sandslope_servo::clock::ClockKind;
use sandslope_servo::driver::ServoSample;
use sandslope_servo::session::{
    default_servos, emulator_summary, BusChoice, DriveConfig, EmulateOptions, Session, STAND_S,
};
use sandslope_servo::{DriveSettings, EmulatorFaults, Profile};

use crate::arrays::{put, values};
use crate::types::{PyRobot, PyTerrain};
use crate::{anyhow_error, value_error};

/// A servo log's rows as its columns, 1-D arrays by column name (docs/drive.md, "The log").
fn log_columns<'py>(py: Python<'py>, r: &[ServoLogRow]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    put(&d, "time_s", r.iter().map(|r| r.time_s).collect())?;
    put(&d, "id", r.iter().map(|r| i64::from(r.id)).collect())?;
    put(&d, "leg", r.iter().map(|r| r.leg as i64).collect())?;
    put(&d, "tripod", r.iter().map(|r| r.tripod as i64).collect())?;
    put(&d, "present_position", r.iter().map(|r| i64::from(r.present_position)).collect())?;
    put(&d, "present_velocity", r.iter().map(|r| i64::from(r.present_velocity)).collect())?;
    put(&d, "present_current_ma", r.iter().map(|r| i64::from(r.present_current_ma)).collect())?;
    put(&d, "load_percent", r.iter().map(|r| r.load_percent).collect())?;
    put(&d, "input_voltage_v", r.iter().map(|r| r.input_voltage_v).collect())?;
    put(&d, "temperature_c", r.iter().map(|r| i64::from(r.temperature_c)).collect())?;
    put(&d, "hardware_error", r.iter().map(|r| i64::from(r.hardware_error)).collect())?;
    put(&d, "goal_position", r.iter().map(|r| i64::from(r.goal_position)).collect())?;
    put(&d, "leg_angle_rad", r.iter().map(|r| r.leg_angle_rad).collect())?;
    put(&d, "drive_torque_n_m", r.iter().map(|r| r.drive_torque_n_m).collect())?;
    Ok(d)
}

/// Reads a `drive --log` CSV: `(columns, meta, notes)`, `columns` the log's columns as 1-D
/// arrays (docs/drive.md, "The log"), `meta` its `# key = value` header lines, `notes` what the
/// reader repaired (the CLI's `note:` lines and `infer --servo-log --json`'s `notes`).
#[pyfunction]
#[allow(clippy::type_complexity)]
pub fn read_servo_log<'py>(
    py: Python<'py>,
    path: std::path::PathBuf,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyDict>, Vec<String>)> {
    let log = py.detach(|| sandslope_io::servo_log::read_servo_log(&path)).map_err(anyhow_error)?;
    let d = log_columns(py, &log.rows)?;
    let meta = PyDict::new(py);
    for (k, v) in &log.meta {
        meta.set_item(k, v)?;
    }
    Ok((d, meta, log.notes))
}

/// `infer --servo-log --json` on a log's columns: `leg` (0 to 2 * stance_legs - 1), the leg's
/// angle in the gait's frame and its drive torque `K_t I`, one entry per servo per cycle.
#[pyfunction]
#[pyo3(signature = (robot, terrain, slope_deg, leg, leg_angle_rad, drive_torque_n_m, k_s_prior=None, grid_points=None))]
#[allow(clippy::too_many_arguments)]
pub fn infer_servo_log<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    terrain: &PyTerrain,
    slope_deg: f64,
    leg: PyReadonlyArray1<'py, i64>,
    leg_angle_rad: PyReadonlyArray1<'py, f64>,
    drive_torque_n_m: PyReadonlyArray1<'py, f64>,
    k_s_prior: Option<(f64, f64)>,
    grid_points: Option<usize>,
) -> PyResult<Bound<'py, PyAny>> {
    // The CLI's defaults: one constant each in the library.
    let k_s_prior = k_s_prior.unwrap_or(sandslope::infer::servo::SERVO_LOG_K_S_PRIOR);
    let grid_points = grid_points.unwrap_or(sandslope::infer::servo::SERVO_LOG_GRID_POINTS);
    let (leg, angle, torque) = (leg.as_slice()?.to_vec(), values(&leg_angle_rad), values(&drive_torque_n_m));
    if leg.len() != angle.len() || leg.len() != torque.len() {
        return Err(value_error(format!(
            "leg, leg_angle_rad and drive_torque_n_m must have one length; they have {}, {} and {}",
            leg.len(),
            angle.len(),
            torque.len()
        )));
    }
    let grid_points = servo_grid_points(Words::Keyword, grid_points).map_err(|e| value_error(e.message()))?;
    let prior = prior_in(Words::Keyword, k_s_prior).map_err(|e| value_error(e.message()))?;
    let legs = 2 * robot.inner.stance_legs() as usize;
    let mut traces = vec![LegTrace::default(); legs];
    for (i, &j) in leg.iter().enumerate() {
        let t = usize::try_from(j).ok().and_then(|j| traces.get_mut(j)).ok_or_else(|| {
            value_error(format!("leg[{i}] = {j}: the robot has {legs} legs (0 to {})", legs - 1))
        })?;
        t.angle_rad.push(angle[i]);
        t.torque_n_m.push(torque[i]);
    }
    let settings = CurrentInferenceSettings { prior, grid_points, ..Default::default() };
    let slope =
        sandslope::SignedSlope::from_degrees(slope_deg).map_err(|e| value_error(e.renamed("slope_deg")))?;
    let (robot, terrain) = (robot.inner.clone(), terrain.inner.clone());
    let answer = py.detach(|| infer(&robot, &terrain, slope, &traces, &settings)).map_err(value_error)?;
    pythonize(py, &answer).map_err(value_error)
}

/// `infer_servo_log` of a log's path: the request `sandslope infer --servo-log FILE` makes
/// (the log read, the slope from `slope_deg` or the log's header, the prior and grid checked),
/// answered; returns `(answer, notes)`, `notes` what the log's reader repaired.
#[pyfunction]
#[pyo3(signature = (robot, terrain, path, slope_deg=None, k_s_prior=None, grid_points=None))]
pub fn infer_servo_log_file<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    terrain: &PyTerrain,
    path: std::path::PathBuf,
    slope_deg: Option<f64>,
    k_s_prior: Option<(f64, f64)>,
    grid_points: Option<usize>,
) -> PyResult<(Bound<'py, PyAny>, Vec<String>)> {
    let request = ServoLogRequest {
        path,
        slope_deg,
        k_s_prior: k_s_prior.unwrap_or(sandslope::infer::servo::SERVO_LOG_K_S_PRIOR),
        grid_points: grid_points.unwrap_or(sandslope::infer::servo::SERVO_LOG_GRID_POINTS),
    };
    let (robot, terrain) = (robot.inner.clone(), terrain.inner.clone());
    let run = py.detach(|| request.read(&robot, Words::Keyword)).map_err(|e| value_error(e.message()))?;
    let answer = py.detach(|| run.answer(&robot, &terrain)).map_err(|e| value_error(e.message()))?;
    Ok((pythonize(py, &answer).map_err(value_error)?, run.notes))
}

/// `drive`'s defaults, the drive table's ([`RunDefaults`]), with the servo crate's time to
/// stand up.
fn run_defaults() -> PyResult<RunDefaults> {
    RunDefaults::read(STAND_S).map_err(|e| value_error(e.message()))
}

/// `drive`'s defaults ([`RunDefaults`], the drive table's), as a dict: what `sandslope.drive`
/// uses for an argument left out, and `sandslope drive --help` shows.
#[pyfunction]
pub fn drive_defaults(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    pythonize(py, &run_defaults()?).map_err(value_error)
}

/// A run of `drive --emulate` with `drive`'s defaults (position profile, 1470 mA, 65 degC,
/// watchdogs 1 s and 0.5 s, a 1 s stand): `(columns, report)`, `columns` the log's columns
/// (as [`read_servo_log`]), `report` what `drive --json` prints, with the emulator's last word
/// under `emulator`.
#[pyfunction]
#[pyo3(signature = (robot, terrain, slope_deg=None, duration_s=None, k_s=None, noise_ma=None, seed=None, weaken=None, stop_on_risk=None, hold_s=None, rate_hz=None, live=None, force=None, window=None, clock=None))]
#[allow(clippy::too_many_arguments)]
pub fn drive<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    terrain: &PyTerrain,
    slope_deg: Option<f64>,
    duration_s: Option<f64>,
    k_s: Option<f64>,
    noise_ma: Option<f64>,
    seed: Option<u64>,
    weaken: Option<(f64, f64)>,
    stop_on_risk: Option<f64>,
    hold_s: Option<f64>,
    rate_hz: Option<f64>,
    live: Option<bool>,
    force: Option<bool>,
    window: Option<usize>,
    clock: Option<String>,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyAny>)> {
    if window == Some(0) {
        return Err(value_error("window = 0 must be at least 1 stance (None pools every stance)"));
    }
    let clock = emulate_clock_keyword(clock.as_deref()).map_err(|e| value_error(e.message()))?;
    let clock = ClockKind::parse(clock).unwrap_or_default();
    // `drive`'s defaults, the table its flags take theirs from.
    let d = run_defaults()?;
    let slope_deg = slope_deg.unwrap_or(d.slope_deg);
    let duration_s = duration_s.unwrap_or(d.duration_s);
    let noise_ma = noise_ma.unwrap_or(d.emulate_noise_ma);
    let seed = seed.unwrap_or(d.emulate_seed);
    let hold_s = hold_s.unwrap_or(d.hold_s);
    let rate_hz = rate_hz.unwrap_or(d.rate_hz);
    let live = live.unwrap_or(d.live);
    // Every number checked once, by the request layer, in Python's words (the command line's
    // ranges and limits; the watchdogs and limits Python does not expose at their defaults).
    DriveRun {
        slope_deg,
        duration_s,
        rate_hz,
        hold_s,
        watchdog_s: d.watchdog_s,
        bus_watchdog_s: d.bus_watchdog_s,
        current_limit_ma: d.current_limit_ma,
        temperature_limit_c: d.temperature_limit_c,
        stop_on_risk,
        emulate_noise_ma: Some(noise_ma),
        emulate_k_s: k_s,
    }
    .check(Words::Keyword)
    .map_err(|e| value_error(e.message()))?;
    if let Some((s, k)) = weaken {
        if !(s >= 0.0 && s.is_finite() && k > 0.0 && k.is_finite()) {
            return Err(value_error(format!(
                "weaken = ({s}, {k}): (seconds at least 0, k_s above 0) expected"
            )));
        }
    }
    let legs = 2 * robot.inner.stance_legs() as usize;
    let settings = DriveSettings {
        servos: default_servos(legs),
        profile: Profile::Position,
        duration_s,
        rate_hz,
        current_limit_ma: d.current_limit_ma,
        temperature_limit_c: d.temperature_limit_c,
        watchdog_s: d.watchdog_s,
        bus_watchdog_s: d.bus_watchdog_s,
        stop_on_risk,
        hold_s,
        stand_s: d.stand_s,
        servo: None,
    };
    let faults = EmulatorFaults { weaken, ..Default::default() };
    let config = DriveConfig {
        robot: robot.inner.clone(),
        terrain: terrain.inner.clone(),
        slope_deg,
        settings,
        bus: BusChoice::Emulate(EmulateOptions {
            k_s,
            noise_ma,
            seed,
            faults,
            current_offset_ma: vec![],
            clock,
        }),
        monitor: live,
        window,
        force: force.unwrap_or(false),
    };
    let (samples, report, emulator) = py
        .detach(move || -> Result<_, String> {
            let mut session = Session::open(config).map_err(|e| e.to_string())?;
            let mut samples: Vec<ServoSample> = vec![];
            let stop = std::sync::atomic::AtomicBool::new(false);
            let (report, _) = session.drive(
                &stop,
                &mut |s| {
                    samples.push(*s);
                    Ok(())
                },
                &mut |_| {},
            );
            let emulator = session.close().map(|r| emulator_summary(&r));
            Ok((samples, report, emulator))
        })
        .map_err(value_error)?;
    // The rows the run's log holds, from the one row builder `drive --log` writes with.
    let rows: Vec<ServoLogRow> = samples.iter().map(sandslope_servo::log::log_row).collect();
    let d = log_columns(py, &rows)?;
    let report_py = pythonize(py, &report).map_err(value_error)?;
    if let Ok(dict) = report_py.cast::<PyDict>() {
        dict.set_item("emulator", emulator)?;
    }
    Ok((d, report_py))
}

/// A ROS 2 bag's topics (docs/bags.md): `(name, type, encoding, messages)` each.
#[pyfunction]
pub fn bag_topics(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Vec<(String, String, String, u64)>> {
    let topics = py.detach(|| sandslope_bag::topics(&path)).map_err(anyhow_error)?;
    Ok(topics.into_iter().map(|t| (t.name, t.type_name, t.encoding, t.messages)).collect())
}

/// A bag's pose topic as `track` reads it: `(columns, body)`, the plain motion-capture
/// columns `time_s, x_m, y_m, z_m` (NaN where no position) on the regular grid `track` uses.
#[pyfunction]
#[pyo3(signature = (path, topic=None, frame=None))]
pub fn read_bag_poses<'py>(
    py: Python<'py>,
    path: std::path::PathBuf,
    topic: Option<String>,
    frame: Option<String>,
) -> PyResult<(Bound<'py, PyDict>, String)> {
    let c = py
        .detach(|| sandslope_io::bag_series::read_capture(&path, topic.as_deref(), frame.as_deref()))
        .map_err(anyhow_error)?;
    let d = PyDict::new(py);
    let n = c.positions.len();
    put(&d, "time_s", (0..n).map(|k| c.start_time_s + k as f64 / c.frame_rate_hz).collect())?;
    for (i, name) in ["x_m", "y_m", "z_m"].into_iter().enumerate() {
        put(&d, name, c.positions.iter().map(|p| p[i]).collect())?;
    }
    Ok((d, c.body))
}

/// A bag's load-cell trial as `fit` reads it (docs/bags.md): `(columns, position body)`,
/// `time_s`, the intruder's travel `position_m` (NaN where no position brackets the stamp)
/// and `force_n`; the axes `x`, `-z`, ...
#[pyfunction]
#[pyo3(signature = (path, force_axis, force_topic=None, position_topic=None, frame=None, position_axis=None))]
pub fn read_bag_load_cell<'py>(
    py: Python<'py>,
    path: std::path::PathBuf,
    force_axis: &str,
    force_topic: Option<String>,
    position_topic: Option<String>,
    frame: Option<String>,
    position_axis: Option<String>,
) -> PyResult<(Bound<'py, PyDict>, String)> {
    use sandslope_bag::wrench::{parse_axis, read_load_cell, LoadCellOptions};
    let axis = |key: &str, text: &str| {
        parse_axis(text)
            .ok_or_else(|| value_error(format!("{key} = {text:?} must be one of x, y, z, -x, -y, -z")))
    };
    let options = LoadCellOptions {
        force_topic: force_topic.as_deref(),
        position_topic: position_topic.as_deref(),
        frame: frame.as_deref(),
        force_axis: axis("force_axis", force_axis)?,
        position_axis: position_axis.as_deref().map(|a| axis("position_axis", a)).transpose()?,
    };
    let s = py.detach(|| read_load_cell(&path, &options)).map_err(anyhow_error)?;
    let d = PyDict::new(py);
    put(&d, "time_s", s.time_s)?;
    put(&d, "position_m", s.position_m.into_iter().map(|p| p.unwrap_or(f64::NAN)).collect())?;
    put(&d, "force_n", s.force_n)?;
    Ok((d, s.position_body))
}

/// A bag's `JointState` topic as `infer --servo-log` reads it: `(columns, notes)`, the servo
/// log's columns (docs/drive.md), `effort_unit` `n_m`, `a` or `ma`.
#[pyfunction]
#[pyo3(signature = (path, legs, topic=None, joints=None, effort_unit="n_m"))]
pub fn read_bag_joints<'py>(
    py: Python<'py>,
    path: std::path::PathBuf,
    legs: usize,
    topic: Option<String>,
    joints: Option<Vec<String>>,
    effort_unit: &str,
) -> PyResult<(Bound<'py, PyDict>, Vec<String>)> {
    let effort = effort_unit.parse().map_err(value_error)?;
    let options = sandslope_io::bag_series::JointOptions {
        topic: topic.as_deref(),
        joints: joints.as_deref(),
        legs,
        effort,
    };
    let log =
        py.detach(|| sandslope_io::bag_series::read_joint_states(&path, &options)).map_err(anyhow_error)?;
    Ok((log_columns(py, &log.rows)?, log.notes))
}
