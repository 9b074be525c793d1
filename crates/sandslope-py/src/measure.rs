//! Measurements into model inputs, mirroring `sandslope fit` (load-cell campaigns, docs/model.md
//! §10) and `sandslope track` (motion capture, docs/model.md §11): files read by
//! `sandslope-io`, analysed by one library call each, returned as plain dicts (the Python layer
//! turns their tables into DataFrames when pandas is installed).

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use pythonize::pythonize;

use sandslope::robot_key::RobotKey;
use sandslope::Robot;
use sandslope_io::mocap::MocapFormat;
use sandslope_request::error::Words;
use sandslope_request::fit::{FitAnswer, FitRequest};
use sandslope_request::track::{Touchdowns, TrackRequest};

use crate::types::{PyRobot, PyTerrain};
use crate::{anyhow_error, value_error};

/// A load-cell campaign (`sandslope fit MANIFEST --json`): `{"trials": [...], "points":
/// [...], "terrain": Terrain}`.
#[pyfunction]
#[pyo3(signature = (manifest, depth_window=None, plateau_from=None, air="auto", counts_per_newton=None, skip_malformed=false))]
pub fn fit<'py>(
    py: Python<'py>,
    manifest: PathBuf,
    depth_window: Option<(f64, f64)>,
    plateau_from: Option<f64>,
    air: &str,
    counts_per_newton: Option<f64>,
    skip_malformed: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let air = FitRequest::air_mode(air).map_err(|e| value_error(e.message()))?;
    // The request `sandslope fit` makes: one check and one answer for both front ends.
    let request = FitRequest { manifest, depth_window, plateau_from, air, counts_per_newton, skip_malformed };
    request.check(Words::Keyword).map_err(|e| value_error(e.message()))?;
    let FitAnswer { campaign, terrain, .. } =
        py.detach(|| request.answer(Words::Keyword)).map_err(|e| anyhow_error(e.into()))?;
    let d = PyDict::new(py);
    d.set_item("trials", pythonize(py, &campaign.trials).map_err(value_error)?)?;
    d.set_item("points", pythonize(py, &campaign.points).map_err(value_error)?)?;
    d.set_item("terrain", Bound::new(py, PyTerrain { inner: terrain })?)?;
    Ok(d)
}

/// Motion-capture recordings at one slope (`sandslope track FILES --json`).
/// A touchdowns file (one time in seconds per line, `#` comments), as `track --touchdowns`
/// reads it.
#[pyfunction]
pub fn read_touchdowns(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Vec<f64>> {
    py.detach(|| sandslope_io::mocap::load_touchdowns(&path)).map_err(crate::anyhow_error)
}

#[pyfunction]
#[pyo3(signature = (paths, robot, slope_deg=None, format=None, body=None, upslope=None, max_gap=sandslope::gait::DEFAULT_MAX_GAP, cutoff_hz=sandslope::gait::DEFAULT_CUTOFF_HZ, leg_speed_rad_s=None, touchdowns=None, topic=None, frame=None))]
#[allow(clippy::too_many_arguments)]
pub fn track<'py>(
    py: Python<'py>,
    paths: Vec<PathBuf>,
    robot: &PyRobot,
    slope_deg: Option<f64>,
    format: Option<&str>,
    body: Option<String>,
    upslope: Option<[f64; 3]>,
    max_gap: usize,
    cutoff_hz: f64,
    leg_speed_rad_s: Option<f64>,
    touchdowns: Option<Vec<Vec<f64>>>,
    topic: Option<String>,
    frame: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    if paths.is_empty() {
        return Err(value_error("paths is empty: give at least one recording"));
    }
    let format: Option<MocapFormat> = format.map(str::parse).transpose().map_err(value_error)?;
    // The stride period of the robot (with `leg_speed_rad_s` in place of its leg speed, by the
    // robot key table and validated again as a whole, as the command line's `--leg-speed`):
    // the library's T = 2 pi / omega, not restated here.
    let robot = match leg_speed_rad_s {
        Some(w) => {
            let mut spec = robot.inner.spec().clone();
            RobotKey::LegSpeedRadS.set(&mut spec, w);
            Robot::new(spec).map_err(value_error)?
        }
        None => robot.inner.clone(),
    };
    let period = robot.stride_period();
    // The request `sandslope track` makes: one check and one path from files to the library.
    let request = TrackRequest {
        files: paths,
        format,
        body,
        upslope,
        max_gap,
        cutoff_hz,
        touchdowns: touchdowns.map_or(Touchdowns::Estimated, Touchdowns::Times),
        slope_deg,
        stride_period_s: period,
        topic,
        frame,
    };
    request.options(Words::Keyword).map_err(|e| value_error(e.message()))?;
    let tracked =
        py.detach(|| request.answer(Words::Keyword, &mut || ())).map_err(|e| value_error(e.message()))?;
    // The answer `track --json` prints, assembled once in the request layer.
    let answer = tracked.answer().map_err(value_error)?;
    let d = pythonize(py, &answer).map_err(value_error)?.cast_into::<PyDict>()?;
    Ok(d)
}
