//! `sandslope.report(...)`: the report's one library value (`sandslope::report::report`) as a
//! dict with exactly the keys and values of `report.json`. Files are read by `sandslope-io`,
//! motion capture as `sandslope.track` reads it.

use std::path::PathBuf;

use pyo3::prelude::*;

use sandslope::gait::{GaitOptions, Upslope};
use sandslope::report::{report as build_report, Evidence, TrackReading, TrackedSlope};
use sandslope::Slope;
use sandslope_io::force_tests::report_force_tests;
use sandslope_io::mocap::MocapFormat;
use sandslope_io::presets::{is_default, PresetKind};
use sandslope_io::{load_anchoring_times, load_speeds};

use crate::measure::read_and_track;
use crate::types::{PyRobot, PyTerrain};
use crate::{anyhow_error, value_error};

/// The report as `sandslope report --out DIR`'s `report.json` text (the Python layer parses it,
/// so the dict equals the file's, lists and nulls alike). `robot_source` and
/// `terrain_source` name the robot and terrain as the inputs table shows them; without
/// `forces`, the built-in terrain is reported with the paper's force tests. `tracks`: one
/// `(slope_deg, paths)` per slope; `simulator_fit`: also the simulator's joint fit (an estimated hour of CPU or more with the converged simulator, docs/calibration.md).
/// `html`: a folder to write the page into, `index.html` and `report.json`, byte for byte what
/// `sandslope report --out` writes (the render crate's `report::write_dir`).
#[pyfunction]
#[pyo3(signature = (robot, terrain, robot_source, terrain_source, observed=None, forces=None, t1=None, tracks=None, tracks_format=None, tracks_body=None, tracks_upslope=None, max_risk=0.05, simulator_fit=false, html=None))]
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
    if let Some(dir) = html.as_ref().filter(|d| d.exists() && !d.is_dir()) {
        return Err(value_error(format!("html = {}: exists and is not a folder", dir.display())));
    }
    if !(max_risk > 0.0 && max_risk < 1.0) {
        return Err(value_error(format!(
            "max_risk = {max_risk} must be a probability strictly between 0 and 1"
        )));
    }
    let format: Option<MocapFormat> = tracks_format.map(str::parse).transpose().map_err(value_error)?;
    let mut options = GaitOptions::new(robot.inner.stride_period()).map_err(value_error)?;
    if let Some(u) = tracks_upslope {
        options =
            options.with_upslope(Upslope::new(u).map_err(|e| value_error(e.renamed("tracks_upslope")))?);
    }
    let mut tracks = tracks.unwrap_or_default();
    tracks.sort_by(|a, b| a.0.total_cmp(&b.0));
    let robot = robot.inner.clone();
    let terrain = terrain.inner.clone();
    let value = py
        .detach(|| -> anyhow::Result<_> {
            let mut tracked = Vec::new();
            for (slope_deg, paths) in &tracks {
                let slope = Slope::from_degrees(*slope_deg).map_err(|e| e.renamed("tracks slope"))?;
                if paths.is_empty() {
                    anyhow::bail!("tracks at {slope_deg} deg: no recording given");
                }
                let (captures, result) =
                    read_and_track(paths, format, tracks_body.as_deref(), None, &options, Some(slope))?;
                let files = captures.iter().map(|c| c.path.display().to_string()).collect();
                tracked.push(TrackedSlope { slope_deg: *slope_deg, files, result });
            }
            let evidence = Evidence {
                forces: report_force_tests(forces.as_deref(), &terrain_source)?,
                observed: observed
                    .map(|p| load_speeds(&p).map(|s| (p.display().to_string(), s)))
                    .transpose()?,
                anchoring: t1
                    .map(|p| load_anchoring_times(&p).map(|a| (p.display().to_string(), a)))
                    .transpose()?,
                tracks: tracked,
                track_reading: TrackReading {
                    format: format.map(|f| f.name().to_string()),
                    body: tracks_body.clone(),
                    upslope: tracks_upslope.map(|u| Upslope::new(u).map_or(u, |u| u.vector())),
                },
                max_risk,
                simulator_fit,
                builtin_robot: is_default(&robot_source, PresetKind::Robot),
                builtin_terrain: is_default(&terrain_source, PresetKind::Terrain),
                robot,
                robot_source,
                terrain,
                terrain_source,
            };
            let value = build_report(&evidence)?;
            if let Some(dir) = &html {
                sandslope_render::report::write_dir(dir, &value)?;
            }
            Ok(value)
        })
        .map_err(anyhow_error)?;
    serde_json::to_string(&value).map_err(value_error)
}
