//! `predict` over arrays (the quantities of `sandslope predict --json`) and `phase` maps.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

use sandslope::{write_phase_rows, Cause, Regime, Slope, SlopeEvaluation, StrengthGrid};
use sandslope_request::predict::{point_terrain, PointRequest};

use crate::arrays::{axis, put, scale_name, uninit, values};
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
    let robot = &robot.inner;
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

/// Cells `phase` computes between two checks for Ctrl-C (about 10 ms of one core).
const PHASE_CELLS_PER_BLOCK: usize = 1 << 20;

/// The phase map at one slope: regime codes (int8) and net step (m, NaN where the leg never
/// anchors) of every cell, row-major with one row per k_s value (`(len(k_s), len(k_n))`);
/// with `regime_only` the codes alone (no `step_m`).
#[pyfunction]
#[pyo3(signature = (robot, slope_deg, k_n_axis, k_s_axis, repose_deg=None, regime_only=false))]
#[allow(clippy::too_many_arguments)]
pub fn phase<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    slope_deg: f64,
    k_n_axis: PyReadonlyArray1<'py, f64>,
    k_s_axis: PyReadonlyArray1<'py, f64>,
    repose_deg: Option<f64>,
    regime_only: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let slope = Slope::from_signed_degrees(slope_deg).map_err(value_error)?;
    let repose = repose_deg
        .map(|r| {
            Slope::from_degrees(r).ok().filter(|_| r > 0.0).ok_or_else(|| {
                value_error(format!("repose_deg = {r} must be strictly between 0 and 90 degrees"))
            })
        })
        .transpose()?;
    let kn = axis("k_n_axis", &values(&k_n_axis))?;
    let ks = axis("k_s_axis", &values(&k_s_axis))?;
    let robot = &robot.inner;
    let (nx, ny) = (kn.len(), ks.len());
    let cells = sandslope::limits::grid_cells(
        "len(k_n_axis) * len(k_s_axis)",
        nx,
        ny,
        1,
        sandslope::limits::MAX_PHASE_CELLS,
    )
    .map_err(value_error)?;
    // Written row by row, in parallel, straight into the buffers NumPy will own, in one pass
    // (`sandslope::phase::write_phase_rows`: no packed map to unpack afterwards, the row's
    // step terms once for both arrays), no intermediate copies, no zeroing first; in blocks of
    // about 2^20 cells with the GIL released for each and Ctrl-C checked between them (issue
    // 21: the cap, 2^28 cells, took minutes that only a kill could stop).
    let mut regime = uninit::<i8>(cells);
    let mut step = (!regime_only).then(|| uninit::<f64>(cells));
    let block = (PHASE_CELLS_PER_BLOCK / nx).max(1);
    let mut counts = [0usize; 4];
    let mut j0 = 0;
    while j0 < ny {
        let rows = j0..(j0 + block).min(ny);
        let span = rows.start * nx..rows.end * nx;
        let codes = &mut regime.spare_capacity_mut()[span.clone()];
        let steps = step.as_mut().map(|s| &mut s.spare_capacity_mut()[span]);
        let grid = StrengthGrid::new(robot, slope, repose, &kn, &ks);
        let c = py.detach(|| write_phase_rows(&grid, rows.clone(), codes, steps));
        for (n, g) in counts.iter_mut().zip(sandslope::Regime::ALL) {
            *n += c.get(g);
        }
        j0 = rows.end;
        py.check_signals()?;
    }
    // SAFETY: the blocks cover rows 0..ny, and `write_phase_rows` writes every one of its
    // rows' elements of each buffer it is given; `cells` is within their capacities.
    unsafe {
        regime.set_len(cells);
        if let Some(s) = step.as_mut() {
            s.set_len(cells);
        }
    }
    let d = PyDict::new(py);
    put(&d, "regime", regime)?;
    if let Some(step) = step {
        put(&d, "step_m", step)?;
    }
    put(&d, "k_n", kn.values())?;
    put(&d, "k_s", ks.values())?;
    d.set_item("k_n_scale", scale_name(&kn))?;
    d.set_item("k_s_scale", scale_name(&ks))?;
    let c = PyDict::new(py);
    for (g, n) in sandslope::Regime::ALL.into_iter().zip(counts) {
        c.set_item(g.name(), n)?;
    }
    d.set_item("counts", c)?;
    Ok(d)
}
