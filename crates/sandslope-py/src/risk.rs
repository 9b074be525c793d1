//! Failure risk on uncertain terrain (docs/model.md §9), mirroring `sandslope risk`: regime
//! probabilities per slope, the p_fail map over median (k_n, k_s), the safe-slope limit, the
//! heaviest safe mass at a slope and the payload envelope over several. Each builds the request
//! layer's [`RiskQuestion`] from its keywords and converts its answer: the checks, the chunks
//! between which Ctrl-C is seen and the answer are the request layer's.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use pythonize::pythonize;

use sandslope::risk::uncertainty::CvSource;
use sandslope::risk::{RegimeProbabilities, RiskAnswer, RiskPoint, RISK_MAP_CELL_KEYS};
use sandslope_request::error::Words;
use sandslope_request::grammar::{axis_of_values, AxisRange};
use sandslope_request::risk::{AnswerLimits, RiskMapGrid, RiskQuestion, Solve};

use crate::arrays::{put, values};
use crate::interrupt::interruptibly;
use crate::types::{PyRobot, PyTerrain};
use crate::value_error;

fn source(s: CvSource) -> &'static str {
    match s {
        CvSource::Given => "given",
        CvSource::Table => "table",
        CvSource::Default => "default",
    }
}

/// The answer to `question` for `robot` on `terrain`, in Python's words, the GIL released and
/// Ctrl-C seen while it computes ([`interruptibly`]: the request layer stops between chunks).
fn answer(
    py: Python<'_>,
    question: RiskQuestion,
    robot: &PyRobot,
    terrain: &PyTerrain,
) -> PyResult<RiskAnswer> {
    let (robot, terrain) = (robot.closed_form()?, terrain.inner.clone());
    interruptibly(py, |stop| {
        question.answer_on(robot, terrain, AnswerLimits::LIBRARY, Words::Keyword, Some(stop))
    })?
    .map_err(|e| value_error(e.message()))
}

/// The question of every solver: the slopes, CVs and risk threshold given, no map.
fn question(
    slopes: Vec<f64>,
    cv_n: Option<f64>,
    cv_s: Option<f64>,
    max_risk: f64,
    solve: Option<Solve>,
) -> RiskQuestion {
    RiskQuestion { slopes, cv_n, cv_s, max_risk, solve, map: None }
}

/// A dict of what `--json` prints for `value`.
fn dict<'py>(py: Python<'py>, value: &impl serde::Serialize) -> PyResult<Bound<'py, PyDict>> {
    Ok(pythonize(py, value).map_err(value_error)?.cast_into::<PyDict>()?)
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
    let degrees = values(&slope_deg);
    let q = question(degrees.clone(), cv_n, cv_s, sandslope::risk::DEFAULT_MAX_RISK, None);
    let pts: Vec<RiskPoint> = match answer(py, q, robot, terrain)? {
        RiskAnswer::Point(p) => vec![*p],
        RiskAnswer::Curve(points) => points,
        _ => unreachable!("a question without solve or map is answered by a curve"),
    };
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
    // An axis given is matched to the library's; one not given is the library's default, as
    // `risk --map` without --k-n/--k-s.
    let given = |key: &str, a: &Option<PyReadonlyArray1<'py, f64>>| {
        a.as_ref()
            .map(|a| axis_of_values(key, &values(a)).map(|axis| AxisRange::of(&axis)))
            .transpose()
            .map_err(|e| value_error(e.message()))
    };
    let grid = RiskMapGrid { k_n: given("k_n_axis", &k_n_axis)?, k_s: given("k_s_axis", &k_s_axis)? };
    let q = RiskQuestion { map: Some(grid), ..question(vec![slope_deg], cv_n, cv_s, max_risk, None) };
    let RiskAnswer::Map(answer) = answer(py, q, robot, terrain)? else {
        unreachable!("a question with a map is answered by a map")
    };
    // The summary as `--json` serialises it, then the keys the answer adds, as arrays.
    let d = dict(py, &answer.summary)?;
    let map = answer.map;
    let (kn, ks) = (map.k_n_axis.values(), map.k_s_axis.values());
    let [repose, k_n, k_s, p_fail, p_not_success] = RISK_MAP_CELL_KEYS;
    d.set_item(repose, map.beyond_repose)?;
    put(&d, k_n, kn)?;
    put(&d, k_s, ks)?;
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
    let q = question(Vec::new(), cv_n, cv_s, max_risk, Some(Solve::Slope));
    match answer(py, q, robot, terrain)? {
        RiskAnswer::Slope(limit) => dict(py, &limit),
        _ => unreachable!("solve slope is answered by the safe-slope limit"),
    }
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
    let q = question(vec![slope_deg], cv_n, cv_s, max_risk, Some(Solve::Mass));
    match answer(py, q, robot, terrain)? {
        RiskAnswer::Mass(mass) => dict(py, &mass),
        _ => unreachable!("solve mass at one slope is answered by the heaviest safe mass"),
    }
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
    let q = question(values(&slope_deg), cv_n, cv_s, max_risk, Some(Solve::Envelope));
    match answer(py, q, robot, terrain)? {
        RiskAnswer::Envelope(envelope) => dict(py, &envelope),
        _ => unreachable!("solve envelope is answered by the payload envelope"),
    }
}
