//! Failure risk on uncertain terrain (docs/model.md §9), mirroring `sandslope risk`: regime
//! probabilities per slope, the p_fail map over median (k_n, k_s), the safe-slope limit and
//! the heaviest safe mass.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use pythonize::pythonize;
use rayon::prelude::*;

use sandslope::risk::{failure_risk, failure_risk_map, max_safe_mass, safe_slope_limit, UncertainTerrain};
use sandslope::{RegimeProbabilities, Slope};

use crate::arrays::{axis, put, values};
use crate::types::{PyRobot, PyTerrain};
use crate::value_error;

/// The terrain read as uncertain, with the CLI's hint when standard deviations are missing
/// (naming the Python arguments instead of the flags).
pub fn uncertain(terrain: &PyTerrain, cv_n: Option<f64>, cv_s: Option<f64>) -> PyResult<UncertainTerrain> {
    UncertainTerrain::new(terrain.inner.clone(), cv_n, cv_s).map_err(|e| {
        if e.key.starts_with("points") {
            let what = e.key.rsplit('.').next().unwrap_or("k_n_sd / k_s_sd").to_string();
            let arg = if what.starts_with("k_n") { "cv_n" } else { "cv_s" };
            value_error(format!(
                "terrain `{}` has no {what} (standard deviation across trials) at {}: give {arg} \
                 (a coefficient of variation, sd / value, e.g. {arg}=0.2), or add {what} to every point",
                terrain.inner.name().unwrap_or("(unnamed)"),
                e.key.split('.').next().unwrap_or("a point"),
            ))
        } else {
            value_error(e)
        }
    })
}

fn put_probabilities(d: &Bound<'_, PyDict>, p: &[RegimeProbabilities]) -> PyResult<()> {
    put(d, "p_fail", p.iter().map(RegimeProbabilities::p_fail).collect())?;
    put(d, "p_not_success", p.iter().map(RegimeProbabilities::p_not_success).collect())?;
    put(d, "p_success", p.iter().map(|p| p.success).collect())?;
    put(d, "p_metastable", p.iter().map(|p| p.metastable).collect())?;
    put(d, "p_slippage", p.iter().map(|p| p.slippage).collect())?;
    put(d, "p_sinkage", p.iter().map(|p| p.sinkage).collect())
}

/// Regime probabilities at each slope (the columns of `sandslope risk --csv`).
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
    let n = degrees.len();
    let slopes: Vec<Slope> = degrees
        .iter()
        .enumerate()
        .map(|(i, &d)| {
            Slope::from_signed_degrees(d).map_err(|e| {
                value_error(e.renamed(if n > 1 { format!("slope_deg[{i}]") } else { "slope_deg".into() }))
            })
        })
        .collect::<PyResult<_>>()?;
    let robot = &robot.inner;
    let out: Vec<(RegimeProbabilities, f64, f64)> = py.detach(|| {
        slopes
            .par_iter()
            .map(|&s| {
                let (_, u) = terrain.at(s);
                (failure_risk(robot, s, &terrain), u.cv_n(), u.cv_s())
            })
            .collect()
    });
    let d = PyDict::new(py);
    put(&d, "slope_deg", degrees)?;
    put(&d, "cv_n", out.iter().map(|o| o.1).collect())?;
    put(&d, "cv_s", out.iter().map(|o| o.2).collect())?;
    let p: Vec<RegimeProbabilities> = out.into_iter().map(|o| o.0).collect();
    put_probabilities(&d, &p)?;
    Ok(d)
}

/// Regime probabilities over a grid of median (k_n, k_s) at one slope, with the terrain's
/// uncertainty and repose at that slope (`sandslope risk --map`); row-major, one row per k_s.
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
    let slope = Slope::from_signed_degrees(slope_deg).map_err(value_error)?;
    let kn = axis("k_n_axis", &values(&k_n_axis))?;
    let ks = axis("k_s_axis", &values(&k_s_axis))?;
    let (ground, u) = terrain.at(slope);
    let robot = &robot.inner;
    let p = py.detach(|| failure_risk_map(robot, slope, ground.repose, &kn, &ks, u, &|| {}));
    let d = PyDict::new(py);
    put_probabilities(&d, &p)?;
    put(&d, "k_n", kn.values())?;
    put(&d, "k_s", ks.values())?;
    d.set_item("terrain_k_n", ground.k_n)?;
    d.set_item("terrain_k_s", ground.k_s)?;
    d.set_item("cv_n", u.cv_n())?;
    d.set_item("cv_s", u.cv_s())?;
    Ok(d)
}

/// The safe-slope limit (`sandslope risk --solve slope --json`).
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
    let limit = py.detach(|| safe_slope_limit(robot, &terrain, max_risk)).map_err(value_error)?;
    let d = PyDict::new(py);
    d.set_item("max_risk", max_risk)?;
    d.set_item("safe_slope_deg", limit.value())?;
    d.set_item("limit", pythonize(py, &limit).map_err(value_error)?)?;
    Ok(d)
}

/// The heaviest safe total mass at one slope (`sandslope risk --solve mass --json`).
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
    let slope = Slope::from_signed_degrees(slope_deg).map_err(value_error)?;
    let robot = &robot.inner;
    let limit = py.detach(|| max_safe_mass(robot, slope, &terrain, max_risk)).map_err(value_error)?;
    let own = robot.mass();
    let d = PyDict::new(py);
    d.set_item("slope_deg", slope_deg)?;
    d.set_item("max_risk", max_risk)?;
    d.set_item("robot_mass_kg", own)?;
    d.set_item("max_mass_kg", limit.value())?;
    d.set_item("max_payload_kg", limit.value().map(|m| m - own))?;
    d.set_item("limit", pythonize(py, &limit).map_err(value_error)?)?;
    Ok(d)
}
