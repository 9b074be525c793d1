//! `predict` over arrays (the quantities of `sandslope predict --json`) and `phase` maps.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

use sandslope::{critical_shear_strength, predict as model, Ground, PhaseMap, Robot, Slope, StepTarget};

use crate::arrays::{axis, put, scale_name, values};
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
    margin: f64,
    extrapolated: bool,
}

/// The reason codes, index of `cause` in the result (see `sandslope.CAUSES`).
pub const CAUSES: [sandslope::Cause; 6] = [
    sandslope::Cause::NormalSinkage,
    sandslope::Cause::AtOrAboveRepose,
    sandslope::Cause::NoAnchoring,
    sandslope::Cause::NetBackwardStep,
    sandslope::Cause::ShortStep,
    sandslope::Cause::RobustStep,
];

/// Every model quantity at each element of the (already broadcast, equally long) inputs.
/// Either `terrain` (looked up at each slope, `k_n`/`k_s` overriding it where given) or both
/// `k_n` and `k_s`.
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
    if terrain.is_none() && (k_n.is_none() || k_s.is_none()) {
        return Err(value_error("give both k_n and k_s, or a terrain (k_n and k_s then override it)"));
    }
    let slope = slope_deg.as_slice()?;
    let n = slope.len();
    let k_n = k_n.as_ref().map(|a| a.as_slice()).transpose()?;
    let k_s = k_s.as_ref().map(|a| a.as_slice()).transpose()?;
    let mass = mass_kg.as_ref().map(|a| a.as_slice()).transpose()?;
    for (key, a) in [("k_n", k_n), ("k_s", k_s), ("mass_kg", mass)] {
        if a.is_some_and(|a| a.len() != n) {
            return Err(value_error(format!(
                "{key} has {} values for {n} slopes",
                a.map_or(0, <[f64]>::len)
            )));
        }
    }
    let robot = &robot.inner;
    let terrain = terrain.map(|t| &t.inner);
    let eval = |i: usize| -> Result<Row, String> {
        let s = Slope::from_signed_degrees(slope[i])
            .map_err(|e| e.renamed(element("slope_deg", i, n)).to_string())?;
        let own;
        let robot: &Robot = match mass {
            Some(m) => {
                own = robot.with_mass(m[i]).map_err(|e| e.renamed(element("mass_kg", i, n)).to_string())?;
                &own
            }
            None => robot,
        };
        let sample = terrain.map(|t| t.sample(s));
        let kn = k_n.map(|a| a[i]).or(sample.map(|t| t.ground.k_n)).unwrap_or(f64::NAN);
        let ks = k_s.map(|a| a[i]).or(sample.map(|t| t.ground.k_s)).unwrap_or(f64::NAN);
        let ground = Ground::new(kn, ks)
            .map_err(|e| {
                let key = e.key.clone();
                e.renamed(element(&key, i, n)).to_string()
            })?
            .with_repose(terrain.and_then(|t| t.repose()));
        let p = model(robot, s, &ground);
        let margin =
            critical_shear_strength(robot, s, ground.k_n, ground.beyond_repose(s), StepTarget::Progress)
                .map_or(f64::NAN, |k| ground.k_s / k);
        let nan = |x: Option<f64>| x.unwrap_or(f64::NAN);
        Ok(Row {
            k_n: p.k_n,
            k_s: p.k_s,
            regime: p.regime as i8,
            cause: CAUSES.iter().position(|&c| c == p.cause).unwrap_or(0) as i8,
            d_n: nan(p.normal_depth),
            level_step: p.level_step,
            d_s: nan(p.shear_depth),
            t1: nan(p.anchoring_time),
            slip: nan(p.slip),
            propulsion: nan(p.propulsion),
            step: nan(p.step),
            speed: nan(p.speed),
            margin,
            extrapolated: sample.is_some_and(|t| t.extrapolated) && (k_n.is_none() || k_s.is_none()),
        })
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
    column!("d_n_m", d_n);
    column!("level_step_m", level_step);
    column!("d_s_m", d_s);
    column!("t1_s", t1);
    column!("slip_m", slip);
    column!("propulsion_m", propulsion);
    column!("step_m", step);
    column!("speed_m_s", speed);
    column!("k_s_margin", margin);
    column!("cause", cause);
    column!("extrapolated", extrapolated);
    Ok(d)
}

/// The phase map at one slope: regime codes (int8) and net step (m, NaN where the leg never
/// anchors) of every cell, row-major with one row per k_s value (`(len(k_s), len(k_n))`).
#[pyfunction]
#[pyo3(signature = (robot, slope_deg, k_n_axis, k_s_axis, repose_deg=None))]
pub fn phase<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    slope_deg: f64,
    k_n_axis: PyReadonlyArray1<'py, f64>,
    k_s_axis: PyReadonlyArray1<'py, f64>,
    repose_deg: Option<f64>,
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
    let cells = nx
        .checked_mul(ny)
        .filter(|&c| c <= isize::MAX as usize / 16)
        .ok_or_else(|| value_error(format!("a {nx} x {ny} map is too large")))?;
    let (regime, step, counts) = py.detach(|| {
        let map = PhaseMap::compute(robot, slope, repose, &kn, &ks, &|| {});
        // Output buffers written row by row, in parallel, straight from the map's per-axis
        // parts: one pass, no intermediate copies.
        let mut regime = vec![0i8; cells];
        let mut step = vec![0f64; cells];
        regime.par_chunks_mut(nx).zip(step.par_chunks_mut(nx)).enumerate().for_each(|(j, (reg, st))| {
            for i in 0..nx {
                reg[i] = map.regime(i, j) as i8;
                st[i] = map.step(i, j).unwrap_or(f64::NAN);
            }
        });
        (regime, step, map.counts())
    });
    let d = PyDict::new(py);
    put(&d, "regime", regime)?;
    put(&d, "step_m", step)?;
    put(&d, "k_n", kn.values())?;
    put(&d, "k_s", ks.values())?;
    d.set_item("k_n_scale", scale_name(&kn))?;
    d.set_item("k_s_scale", scale_name(&ks))?;
    let c = PyDict::new(py);
    for g in sandslope::Regime::ALL {
        c.set_item(g.name(), counts.get(g))?;
    }
    d.set_item("counts", c)?;
    Ok(d)
}
