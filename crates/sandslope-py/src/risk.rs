//! Failure risk on uncertain terrain (docs/model.md §9), mirroring `sandslope risk`: regime
//! probabilities per slope, the p_fail map over median (k_n, k_s), the safe-slope limit and
//! the heaviest safe mass.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use pythonize::pythonize;

use sandslope::risk::uncertainty::CvSource;
use sandslope::risk::RegimeProbabilities;
use sandslope::risk::{risk_curve, RiskMap, UncertainTerrain};
use sandslope::Slope;

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

/// Regime probabilities at each slope: the keys of `sandslope risk --json` as columns
/// (`p_regime` a dict of columns) and the columns of `risk --csv` (`p_<regime>`), with the
/// coefficients of variation used and where they came from (`given`, `table`, `default`).
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
    sandslope::limits::count("len(slope_deg)", degrees.len(), sandslope::limits::MAX_RISK_SLOPES)
        .map_err(value_error)?;
    let robot = &robot.inner;
    // In chunks, the GIL released for each and Ctrl-C checked between them: 65,536 slopes (the
    // cap) took 74 s in one call that only a kill could stop (issue 21); a chunk is a fraction
    // of a second.
    let chunks: Vec<&[f64]> =
        if degrees.is_empty() { vec![&degrees[..]] } else { degrees.chunks(RISK_SLOPES_PER_CHUNK).collect() };
    let mut pts = Vec::with_capacity(degrees.len());
    for (c, chunk) in chunks.into_iter().enumerate() {
        let curve = py.detach(|| risk_curve(robot, &terrain, chunk)).map_err(|e| {
            // The library names the key; point at the element when there are several.
            let at = c * RISK_SLOPES_PER_CHUNK
                + chunk.iter().position(|&d| Slope::from_signed_degrees(d).is_err()).unwrap_or(0);
            value_error(if degrees.len() > 1 { e.renamed(format!("slope_deg[{at}]")) } else { e })
        })?;
        pts.extend(curve.points);
        py.check_signals()?;
    }
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
        let column: Vec<f64> = pts.iter().map(|p| of(&p.probabilities)[i]).collect();
        put(&p_regime, name, column.clone())?;
        put(&d, &format!("p_{name}"), column)?;
    }
    d.set_item("p_regime", p_regime)?;
    Ok(d)
}

/// P(failure) and P(not success) over a grid of median (k_n, k_s) at one slope, with the
/// terrain's uncertainty and repose at that slope (`sandslope risk --map`); row-major, one
/// row per k_s.
#[pyfunction]
#[pyo3(signature = (robot, slope_deg, k_n_axis, k_s_axis, terrain, cv_n=None, cv_s=None))]
#[allow(clippy::too_many_arguments)]
pub fn risk_map<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    slope_deg: f64,
    k_n_axis: PyReadonlyArray1<'py, f64>,
    k_s_axis: PyReadonlyArray1<'py, f64>,
    terrain: &PyTerrain,
    cv_n: Option<f64>,
    cv_s: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let terrain = uncertain(terrain, cv_n, cv_s)?;
    let slope = Slope::from_signed_degrees(slope_deg).map_err(|e| value_error(e.renamed("slope_deg")))?;
    let kn = axis("k_n_axis", &values(&k_n_axis))?;
    let ks = axis("k_s_axis", &values(&k_s_axis))?;
    sandslope::limits::grid_cells(
        "len(k_n_axis) * len(k_s_axis)",
        kn.len(),
        ks.len(),
        1,
        sandslope::limits::MAX_RISK_MAP_CELLS,
    )
    .map_err(value_error)?;
    let g = terrain.sample(slope);
    let robot = &robot.inner;
    let map = py.detach(|| RiskMap::compute(robot, slope, g.ground.repose, &kn, &ks, g.uncertainty, &|| {}));
    let d = PyDict::new(py);
    put(&d, "p_fail", map.p_fail)?;
    put(&d, "p_not_success", map.p_not_success)?;
    put(&d, "k_n", kn.values())?;
    put(&d, "k_s", ks.values())?;
    d.set_item("terrain_k_n", g.ground.k_n)?;
    d.set_item("terrain_k_s", g.ground.k_s)?;
    d.set_item("cv_n", g.uncertainty.cv_n())?;
    d.set_item("cv_s", g.uncertainty.cv_s())?;
    d.set_item("cv_n_source", source(g.cv_n_source))?;
    d.set_item("cv_s_source", source(g.cv_s_source))?;
    d.set_item("beyond_repose", map.beyond_repose)?;
    Ok(d)
}

/// The safe-slope limit with the uncertainty it used: the value `sandslope risk --solve slope
/// --json` prints.
#[pyfunction]
#[pyo3(signature = (robot, terrain, max_risk=0.05, cv_n=None, cv_s=None))]
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
#[pyo3(signature = (robot, slope_deg, terrain, max_risk=0.05, cv_n=None, cv_s=None))]
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
    let robot = &robot.inner;
    let answer = py
        .detach(|| sandslope::risk::safe_mass(robot, slope_deg, &terrain, max_risk))
        .map_err(value_error)?;
    Ok(pythonize(py, &answer).map_err(value_error)?.cast_into::<PyDict>()?)
}
