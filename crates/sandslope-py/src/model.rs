//! `predict` over arrays (the quantities of `sandslope predict --json`) and `phase` maps.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

use sandslope::{Cause, Regime, SlopeEvaluation};
use sandslope_request::phase::PhaseMapRequest;
use sandslope_request::predict::{point_terrain, PointRequest};

use crate::arrays::{put, scale_name, values};
use crate::interrupt::interruptibly;
use crate::types::{PyRobot, PyTerrain};
use crate::value_error;

/// `key = value` of element `i` of a length-`n` array, for messages.
fn element(key: &str, i: usize, n: usize) -> String {
    if n > 1 {
        format!("{key}[{i}]")
    } else {
        key.to_string()
    }
}

/// One evaluation, as the columns of `predict --json` (NaN where JSON has null).
#[derive(Default, Clone, Copy)]
struct Row {
    k_n: f64,
    k_s: f64,
    regime: i8,
    cause: i8,
    d_n: f64,
    level_step: f64,
    d_s: f64,
    t1: f64,
    slip: f64,
    propulsion: f64,
    step: f64,
    speed: f64,
    model_speed: f64,
    margin: f64,
    critical_progress: f64,
    critical_robust: f64,
    extrapolated: bool,
}

/// The reason codes, index of `cause` in the result (see `sandslope.CAUSES`).
pub const CAUSES: [Cause; 6] = Cause::ALL;

impl Row {
    fn from(e: &SlopeEvaluation) -> Row {
        let nan = |x: Option<f64>| x.unwrap_or(f64::NAN);
        let p = &e.prediction;
        Row {
            k_n: p.k_n,
            k_s: p.k_s,
            regime: Regime::ALL.iter().position(|&g| g == p.regime).unwrap_or(0) as i8,
            cause: CAUSES.iter().position(|&c| c == p.cause).unwrap_or(0) as i8,
            d_n: nan(p.normal_depth),
            level_step: p.level_step,
            d_s: nan(p.shear_depth),
            t1: nan(p.anchoring_time),
            slip: nan(p.slip),
            propulsion: nan(p.propulsion),
            step: nan(p.step),
            speed: nan(e.speed()),
            model_speed: nan(e.model_speed()),
            margin: nan(e.k_s_margin),
            critical_progress: e.critical_progress.as_ref().map_or(f64::NAN, |k| *k),
            critical_robust: e.critical_robust.as_ref().map_or(f64::NAN, |k| *k),
            extrapolated: e.extrapolated,
        }
    }
}

/// Every model quantity at each element of the (already broadcast, equally long) inputs, each
/// the request layer's [`PointRequest`] (the library's scenario, what `sandslope predict`
/// evaluates). Either `terrain` (looked up
/// at each slope, `k_n`/`k_s` overriding it where given) or both `k_n` and `k_s`.
#[pyfunction]
#[pyo3(signature = (robot, slope_deg, k_n=None, k_s=None, terrain=None, mass_kg=None))]
#[allow(clippy::too_many_arguments)]
pub fn predict<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    slope_deg: PyReadonlyArray1<'py, f64>,
    k_n: Option<PyReadonlyArray1<'py, f64>>,
    k_s: Option<PyReadonlyArray1<'py, f64>>,
    terrain: Option<&PyTerrain>,
    mass_kg: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let slope = slope_deg.as_slice()?;
    let n = slope.len();
    let k_n = k_n.as_ref().map(|a| a.as_slice()).transpose()?;
    let k_s = k_s.as_ref().map(|a| a.as_slice()).transpose()?;
    let mass = mass_kg.as_ref().map(|a| a.as_slice()).transpose()?;
    for (key, a) in [("k_n", k_n), ("k_s", k_s), ("mass_kg", mass)] {
        if let Some(a) = a.filter(|a| a.len() != n) {
            return Err(value_error(format!("{key} has {} values for {n} slopes", a.len())));
        }
    }
    // The request layer's point: its overrides checked and named as this keyword's element.
    let terrain = point_terrain(terrain.map(|t| &t.inner), k_n.is_some(), k_s.is_some())
        .map_err(|e| value_error(e.message()))?;
    let robot = robot.closed_form()?;
    let eval = |i: usize| -> Result<Row, String> {
        let point = PointRequest {
            slope: slope[i],
            k_n: k_n.map(|a| a[i]),
            k_s: k_s.map(|a| a[i]),
            mass: mass.map(|a| a[i]),
        };
        point
            .answer(robot, &terrain, |key| element(key, i, n))
            .map(|e| Row::from(&e))
            .map_err(|e| e.message())
    };
    let rows: Vec<Row> =
        py.detach(|| (0..n).into_par_iter().map(eval).collect::<Result<_, _>>()).map_err(value_error)?;
    let d = PyDict::new(py);
    put(&d, "slope_deg", slope.to_vec())?;
    macro_rules! column {
        ($key:literal, $field:ident) => {
            put(&d, $key, rows.iter().map(|r| r.$field).collect::<Vec<_>>())?;
        };
    }
    column!("k_n", k_n);
    column!("k_s", k_s);
    column!("regime", regime);
    column!("cause", cause);
    column!("d_n_m", d_n);
    column!("level_step_m", level_step);
    column!("d_s_m", d_s);
    column!("t1_s", t1);
    column!("slip_m", slip);
    column!("propulsion_m", propulsion);
    column!("step_m", step);
    column!("speed_m_s", speed);
    column!("model_speed_m_s", model_speed);
    column!("k_s_margin", margin);
    column!("critical_k_s_progress", critical_progress);
    column!("critical_k_s_robust", critical_robust);
    column!("extrapolated", extrapolated);
    Ok(d)
}

/// The phase map at one slope: regime codes (int8) and net step (m, NaN where the leg never
/// anchors) of every cell, row-major with one row per k_s value (`(len(k_s), len(k_n))`);
/// with `regime_only` the codes alone (no `step_m`); `terrain` lends its angle of repose where
/// `repose_deg` is not given. The request layer's [`PhaseMapRequest`]
/// checks the keywords, refuses a map over the cap before allocating it and writes the cells
/// straight into the buffers NumPy then owns, in blocks between which Ctrl-C is seen (issue
/// 21: the cap, 2^28 cells, took minutes that only a kill could stop).
#[pyfunction]
#[pyo3(signature = (robot, slope_deg, k_n_axis, k_s_axis, terrain=None, repose_deg=None, regime_only=false))]
#[allow(clippy::too_many_arguments)]
pub fn phase<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    slope_deg: f64,
    k_n_axis: PyReadonlyArray1<'py, f64>,
    k_s_axis: PyReadonlyArray1<'py, f64>,
    terrain: Option<&PyTerrain>,
    repose_deg: Option<f64>,
    regime_only: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let request = PhaseMapRequest {
        slope_deg,
        k_n_axis: values(&k_n_axis),
        k_s_axis: values(&k_s_axis),
        repose_deg,
        regime_only,
    };
    let (robot, terrain) = (robot.closed_form()?, terrain.map(|t| &t.inner));
    let answer = interruptibly(py, |stop| request.answer(robot, terrain, Some(stop)))?
        .map_err(|e| value_error(e.message()))?;
    let d = PyDict::new(py);
    put(&d, "regime", answer.regime)?;
    if let Some(step) = answer.step_m {
        put(&d, "step_m", step)?;
    }
    let (kn, ks) = (&answer.k_n_axis, &answer.k_s_axis);
    put(&d, "k_n", kn.values())?;
    put(&d, "k_s", ks.values())?;
    d.set_item("k_n_scale", scale_name(kn))?;
    d.set_item("k_s_scale", scale_name(ks))?;
    let c = PyDict::new(py);
    for g in sandslope::Regime::ALL {
        c.set_item(g.name(), answer.counts.get(g))?;
    }
    d.set_item("counts", c)?;
    Ok(d)
}
