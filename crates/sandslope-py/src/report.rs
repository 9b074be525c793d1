//! `sandslope.report(...)`: the report's one library value (`sandslope::report::report`) as a
//! dict with exactly the keys and values of `report.json`. The evidence is read by the request
//! layer's `ReportRequest`, as `sandslope report` reads it (motion capture as `track` does).

use std::path::PathBuf;

use pyo3::prelude::*;

use sandslope_io::mocap::MocapFormat;
use sandslope_request::error::Words;
use sandslope_request::report::{ReportRequest, TracksAt};

use crate::types::{PyRobot, PyTerrain};
use crate::{anyhow_error, value_error};

/// The report as `sandslope report --out DIR`'s `report.json` text (the Python layer parses it,
/// so the dict equals the file's, lists and nulls alike). `robot_source` and
/// `terrain_source` name the robot and terrain as the inputs table shows them; without
/// `forces`, the built-in terrain is reported with the paper's force tests. `tracks`: one
/// `(slope_deg, paths)` per slope; `simulator_fit`: also the simulator's joint fit (about 8 minutes of CPU on the paper's evidence, docs/calibration.md).
/// `html`: a folder to write the page into, `index.html` and `report.json`, byte for byte what
/// `sandslope report --out` writes (the render crate's `report::write_dir`).
#[pyfunction]
#[pyo3(signature = (robot, terrain, robot_source, terrain_source, observed=None, forces=None, t1=None, tracks=None, tracks_format=None, tracks_body=None, tracks_upslope=None, max_risk=sandslope::risk::DEFAULT_MAX_RISK, simulator_fit=false, html=None))]
#[allow(clippy::too_many_arguments)]
pub fn report(
    py: Python<'_>,
    robot: &PyRobot,
    terrain: &PyTerrain,
    robot_source: String,
    terrain_source: String,
    observed: Option<PathBuf>,
    forces: Option<String>,
    t1: Option<PathBuf>,
    tracks: Option<Vec<(f64, Vec<PathBuf>)>>,
    tracks_format: Option<&str>,
    tracks_body: Option<String>,
    tracks_upslope: Option<[f64; 3]>,
    max_risk: f64,
    simulator_fit: bool,
    html: Option<PathBuf>,
) -> PyResult<String> {
    if let Some(dir) = &html {
        sandslope_render::report::check_dir("html =", dir).map_err(value_error)?;
    }
    let format: Option<MocapFormat> = tracks_format.map(str::parse).transpose().map_err(value_error)?;
    // The request `sandslope report` makes: its checks, its evidence and its answer.
    let request = ReportRequest {
        robot_source,
        terrain_source,
        observed,
        forces,
        t1,
        tracks: tracks
            .unwrap_or_default()
            .into_iter()
            .map(|(slope_deg, files)| TracksAt { slope_deg, files })
            .collect(),
        tracks_format: format,
        tracks_body,
        tracks_upslope,
        max_risk,
        simulator_fit,
    };
    request.check(Words::Keyword).map_err(|e| value_error(e.message()))?;
    let robot = robot.closed_form()?.clone();
    let terrain = terrain.inner.clone();
    let value = py
        .detach(|| -> anyhow::Result<_> {
            let value = request.answer(robot, terrain, Words::Keyword)?;
            if let Some(dir) = &html {
                sandslope_render::report::write_dir(dir, &value)?;
            }
            Ok(value)
        })
        .map_err(anyhow_error)?;
    serde_json::to_string(&value).map_err(value_error)
}
