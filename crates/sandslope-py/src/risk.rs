//! Failure risk on uncertain terrain (docs/model.md §9), mirroring `sandslope risk`: regime
//! probabilities per slope, the p_fail map over median (k_n, k_s), the safe-slope limit, the
//! heaviest safe mass at a slope and the payload envelope over several.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use pythonize::pythonize;

use sandslope::risk::uncertainty::CvSource;
use sandslope::risk::{risk_curve, RegimeProbabilities, RiskPoint, UncertainTerrain, RISK_MAP_CELL_KEYS};
use sandslope::{ParamError, SignedSlope, Slope};

use crate::arrays::{axis, put, values};
use crate::types::{PyRobot, PyTerrain};
use crate::value_error;

/// The terrain read as uncertain by the library's one rule (docs/model.md §9): a given CV,
/// else the table's SD over its value, else the default CV.
pub fn uncertain(terrain: &PyTerrain, cv_n: Option<f64>, cv_s: Option<f64>) -> PyResult<UncertainTerrain> {
    UncertainTerrain::new(terrain.inner.clone(), cv_n, cv_s).map_err(value_error)
}

fn source(s: CvSource) -> &'static str {
    match s {
        CvSource::Given => "given",
        CvSource::Table => "table",
        CvSource::Default => "default",
    }
}

/// Slopes per chunk of [`risk`], between which Ctrl-C is checked (about 0.1 s of work each on
/// this 2-core machine).
const RISK_SLOPES_PER_CHUNK: usize = 128;

/// Slopes per chunk of [`payload_envelope`] (each slope a search over masses).
const ENVELOPE_SLOPES_PER_CHUNK: usize = 8;

/// `compute` over `degrees` in chunks of `per_chunk` slopes, the GIL released for each and
/// Ctrl-C checked between them (at least one call, on no slopes when `degrees` is empty). A
/// library error names the element (`slope_deg[i]`) when there are several slopes.
fn in_chunks<T: Send>(
    py: Python<'_>,
    degrees: &[f64],
    per_chunk: usize,
    compute: impl Fn(&[f64]) -> Result<T, ParamError> + Sync,
) -> PyResult<Vec<T>> {
    sandslope::limits::count("len(slope_deg)", degrees.len(), sandslope::limits::MAX_RISK_SLOPES)
        .map_err(value_error)?;
    let chunks: Vec<&[f64]> =
        if degrees.is_empty() { vec![degrees] } else { degrees.chunks(per_chunk).collect() };
    let mut out = Vec::with_capacity(chunks.len());
    for (c, chunk) in chunks.into_iter().enumerate() {
        let part = py.detach(|| compute(chunk)).map_err(|e| {
            // The library names the key; point at the element when there are several.
            let at = c * per_chunk
                + chunk.iter().position(|&d| Slope::from_signed_degrees(d).is_err()).unwrap_or(0);
            value_error(if degrees.len() > 1 && e.key == "slope_deg" {
                e.renamed(format!("slope_deg[{at}]"))
            } else {
                e
            })
        })?;
        out.push(part);
        py.check_signals()?;
    }
    Ok(out)
}

/// Regime probabilities at each slope: the keys of `sandslope risk --json` as columns
/// (`p_regime` a dict of columns), with the coefficients of variation used and where they came
/// from (`given`, `table`, `default`); no other keys.
#[pyfunction]
#[pyo3(signature = (robot, slope_deg, terrain, cv_n=None, cv_s=None))]
pub fn risk<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    slope_deg: PyReadonlyArray1<'py, f64>,
    terrain: &PyTerrain,
    cv_n: Option<f64>,
    cv_s: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let terrain = uncertain(terrain, cv_n, cv_s)?;
    let degrees = values(&slope_deg);
    let robot = &robot.inner;
    // In chunks, the GIL released for each and Ctrl-C checked between them: 65,536 slopes (the
    // cap) took 74 s in one call that only a kill could stop (issue 21); a chunk is a fraction
    // of a second.
    let parts = in_chunks(py, &degrees, RISK_SLOPES_PER_CHUNK, |chunk| risk_curve(robot, &terrain, chunk))?;
    let pts: Vec<RiskPoint> = parts.into_iter().flat_map(|c| c.points).collect();
    let pts = &pts;
    let d = PyDict::new(py);
    put(&d, "slope_deg", degrees.clone())?;
    put(&d, "cv_n", pts.iter().map(|p| p.uncertainty.cv_n).collect())?;
    put(&d, "cv_s", pts.iter().map(|p| p.uncertainty.cv_s).collect())?;
    d.set_item("cv_n_source", pts.iter().map(|p| source(p.uncertainty.cv_n_source)).collect::<Vec<_>>())?;
    d.set_item("cv_s_source", pts.iter().map(|p| source(p.uncertainty.cv_s_source)).collect::<Vec<_>>())?;
    put(&d, "p_fail", pts.iter().map(|p| p.p_fail).collect())?;
    put(&d, "p_not_success", pts.iter().map(|p| p.p_not_success).collect())?;
    let p_regime = PyDict::new(py);
    let of = |q: &RegimeProbabilities| [q.success, q.metastable, q.slippage, q.sinkage];
    for (i, name) in ["success", "metastable", "slippage", "sinkage"].into_iter().enumerate() {
        put(&p_regime, name, pts.iter().map(|p| of(&p.probabilities)[i]).collect())?;
    }
    d.set_item("p_regime", p_regime)?;
    Ok(d)
}

/// P(failure) and P(not success) over a grid of median (k_n, k_s) at one slope, with the
/// terrain's uncertainty and repose at that slope: the value `sandslope risk --map --json`
/// prints (the library's `RiskMapAnswer`, key for key), its axis values and cells as NumPy
/// arrays (cells row-major, one row per k_s); an axis not given is the library's default.
#[pyfunction]
#[pyo3(signature = (robot, slope_deg, k_n_axis, k_s_axis, terrain, max_risk=sandslope::risk::DEFAULT_MAX_RISK, cv_n=None, cv_s=None))]
#[allow(clippy::too_many_arguments)]
pub fn risk_map<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    slope_deg: f64,
    k_n_axis: Option<PyReadonlyArray1<'py, f64>>,
    k_s_axis: Option<PyReadonlyArray1<'py, f64>>,
    terrain: &PyTerrain,
    max_risk: f64,
    cv_n: Option<f64>,
    cv_s: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let terrain = uncertain(terrain, cv_n, cv_s)?;
    let given = |key: &str, a: &Option<PyReadonlyArray1<'py, f64>>| {
        a.as_ref().map(|a| axis(key, &values(a))).transpose()
    };
    // The library's default grid where an axis is not given, as `risk --map` without --k-n/--k-s.
    let slope = SignedSlope::from_degrees(slope_deg).map_err(value_error)?;
    let (kn, ks) = sandslope::risk::map_axes(
        &terrain,
        slope,
        given("k_n_axis", &k_n_axis)?,
        given("k_s_axis", &k_s_axis)?,
    )
    .map_err(value_error)?;
    sandslope::limits::grid_cells(
        "len(k_n_axis) * len(k_s_axis)",
        kn.len(),
        ks.len(),
        1,
        sandslope::limits::MAX_RISK_MAP_CELLS,
    )
    .map_err(value_error)?;
    let robot = &robot.inner;
    let answer = py
        .detach(|| sandslope::risk::risk_map(robot, slope, &terrain, (&kn, &ks), max_risk, &|| {}))
        .map_err(value_error)?;
    // The summary as `--json` serialises it, then the keys the answer adds, as arrays.
    let d = pythonize(py, &answer.summary).map_err(value_error)?.cast_into::<PyDict>()?;
    let map = answer.map;
    let [repose, k_n, k_s, p_fail, p_not_success] = RISK_MAP_CELL_KEYS;
    d.set_item(repose, map.beyond_repose)?;
    put(&d, k_n, kn.values())?;
    put(&d, k_s, ks.values())?;
    put(&d, p_fail, map.p_fail)?;
    put(&d, p_not_success, map.p_not_success)?;
    Ok(d)
}

/// The safe-slope limit with the uncertainty it used: the value `sandslope risk --solve slope
/// --json` prints.
#[pyfunction]
#[pyo3(signature = (robot, terrain, max_risk=sandslope::risk::DEFAULT_MAX_RISK, cv_n=None, cv_s=None))]
pub fn safe_slope<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    terrain: &PyTerrain,
    max_risk: f64,
    cv_n: Option<f64>,
    cv_s: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let terrain = uncertain(terrain, cv_n, cv_s)?;
    let robot = &robot.inner;
    let answer = py.detach(|| sandslope::risk::safe_slope(robot, &terrain, max_risk)).map_err(value_error)?;
    Ok(pythonize(py, &answer).map_err(value_error)?.cast_into::<PyDict>()?)
}

/// The heaviest safe total mass at one slope, the payload it leaves and the uncertainty it used:
/// the value `sandslope risk --solve mass --json` prints.
#[pyfunction]
#[pyo3(signature = (robot, slope_deg, terrain, max_risk=sandslope::risk::DEFAULT_MAX_RISK, cv_n=None, cv_s=None))]
pub fn safe_mass<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    slope_deg: f64,
    terrain: &PyTerrain,
    max_risk: f64,
    cv_n: Option<f64>,
    cv_s: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let terrain = uncertain(terrain, cv_n, cv_s)?;
    let slope = SignedSlope::from_degrees(slope_deg).map_err(value_error)?;
    let robot = &robot.inner;
    let answer =
        py.detach(|| sandslope::risk::safe_mass(robot, slope, &terrain, max_risk)).map_err(value_error)?;
    Ok(pythonize(py, &answer).map_err(value_error)?.cast_into::<PyDict>()?)
}

/// The payload envelope: the heaviest safe total mass and the payload it leaves at each slope,
/// with the uncertainty used there: the value `sandslope risk --slope A,B,... --solve mass
/// --json` prints.
#[pyfunction]
#[pyo3(signature = (robot, slope_deg, terrain, max_risk=sandslope::risk::DEFAULT_MAX_RISK, cv_n=None, cv_s=None))]
pub fn payload_envelope<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    slope_deg: PyReadonlyArray1<'py, f64>,
    terrain: &PyTerrain,
    max_risk: f64,
    cv_n: Option<f64>,
    cv_s: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let terrain = uncertain(terrain, cv_n, cv_s)?;
    let degrees = values(&slope_deg);
    let robot = &robot.inner;
    let parts = in_chunks(py, &degrees, ENVELOPE_SLOPES_PER_CHUNK, |chunk| {
        sandslope::risk::payload_envelope(robot, &terrain, chunk, max_risk)
    })?;
    let mut parts = parts.into_iter();
    let mut envelope = parts.next().expect("in_chunks calls at least once");
    for part in parts {
        envelope.points.extend(part.points);
        envelope.defaults_used = envelope.defaults_used.or(part.defaults_used);
    }
    Ok(pythonize(py, &envelope).map_err(value_error)?.cast_into::<PyDict>()?)
}
