//! `simulate`: the dynamic stride simulator (`sandslope simulate --json`, docs/model.md
//! §15-§18): the trajectory as NumPy columns (the Python layer makes a DataFrame of them) and
//! the summary as a dict with the same keys as `--json`.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use pythonize::pythonize;

use sandslope::simulate::SimSettings;
use sandslope::Scenario;
use sandslope_request::error::Words;
use sandslope_request::field::{Field, Kind};
use sandslope_request::scenario::{K_N, K_S};
use sandslope_request::simulate::{SettingsRequest, SimAnswer, Walks, DURATION, NO_SERVO_LIMIT, SETTINGS};
use sandslope_request::{Params, RequestError};

use crate::arrays::put;
use crate::types::{PyRobot, PyTerrain};
use crate::value_error;

/// Runs one walk; returns `(columns, summary)`: `columns` maps each trajectory column
/// (`time_s`, `x_m`, `z_m`, `pitch_rad`, `vx_m_s`, `vz_m_s`, then per leg j `leg{j}_angle_rad`,
/// `leg{j}_depth_m`, `leg{j}_force_x_n`, `leg{j}_force_z_n`, `leg{j}_torque_n_m`) to a 1-D
/// array; `summary` is `sandslope simulate --json`, its `scaling_spread` the slope walked under
/// all three contact scalings (`--scaling-spread`; `None` with `scaling_spread=False`).
#[pyfunction]
#[pyo3(signature = (robot, terrain, slope_deg, duration_s, scaling_spread=true, **keywords))]
pub fn simulate<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    terrain: &PyTerrain,
    slope_deg: f64,
    duration_s: f64,
    scaling_spread: bool,
    keywords: Option<&Bound<'py, PyDict>>,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyAny>)> {
    let (scenario, settings) = setup(robot, terrain, duration_s, keywords)?;
    let slope = sandslope::SignedSlope::from_degrees(slope_deg).map_err(value_error)?;
    let walks = Walks { scaling_spread, ..Walks::at(scenario, slope, settings, None) };
    let (mut spreads, mut sims) = py
        .detach(|| walks.simulate_with_spreads().map(|(sims, spreads)| (spreads, sims)))
        .map_err(request_error)?;
    let sim = sims.pop().ok_or_else(|| value_error("the walk gave no result"))?;
    let spread = spreads.pop().flatten();
    let tr = sim.trajectory;
    let d = PyDict::new(py);
    put(&d, "time_s", tr.time_s)?;
    put(&d, "x_m", tr.x_m)?;
    put(&d, "z_m", tr.z_m)?;
    put(&d, "pitch_rad", tr.pitch_rad)?;
    put(&d, "vx_m_s", tr.vx_m_s)?;
    put(&d, "vz_m_s", tr.vz_m_s)?;
    let legs = tr.leg_depth_m.len();
    let columns = tr
        .leg_angle_rad
        .into_iter()
        .zip(tr.leg_depth_m)
        .zip(tr.leg_force_x_n)
        .zip(tr.leg_force_z_n)
        .zip(tr.leg_torque_n_m);
    for (j, ((((angle, depth), fx), fz), torque)) in columns.enumerate().take(legs) {
        put(&d, &format!("leg{j}_angle_rad"), angle)?;
        put(&d, &format!("leg{j}_depth_m"), depth)?;
        put(&d, &format!("leg{j}_force_x_n"), fx)?;
        put(&d, &format!("leg{j}_force_z_n"), fz)?;
        put(&d, &format!("leg{j}_torque_n_m"), torque)?;
    }
    let answer = SimAnswer { summary: sim.summary, scaling_spread: spread };
    let summary = pythonize(py, &answer).map_err(value_error)?;
    Ok((d, summary))
}

/// A refused request as Python's `ValueError`, its message in Python's words.
fn request_error(e: RequestError) -> PyErr {
    value_error(e.message())
}

/// The keywords every walk takes (`simulate`, `simulate_ensemble` and `check_convergence`
/// share them): `k_n` and `k_s`, and the settings' fields ([`SETTINGS`]) by their Python
/// keyword, as `sandslope simulate`'s flags and `/api/simulate`'s fields are read, each absent
/// or `None` keyword taking the table's default. `servo_limit=False` is the flag
/// `--no-servo-limit`.
pub fn walk_keywords() -> Vec<&'static Field> {
    [&K_N, &K_S].into_iter().chain(SETTINGS.fields.iter().filter(|f| f.flag != DURATION.flag)).collect()
}

/// The robot on its terrain and the settings `sandslope simulate` checks, in Python's words.
fn setup(
    robot: &PyRobot,
    terrain: &PyTerrain,
    duration_s: f64,
    keywords: Option<&Bound<'_, PyDict>>,
) -> PyResult<(Scenario, SimSettings)> {
    let mut pairs = vec![(DURATION.flag.to_string(), format!("{duration_s}"))];
    let (mut k_n, mut k_s) = (None, None);
    let accepted = walk_keywords();
    for (key, value) in keywords.into_iter().flat_map(|d| d.iter()) {
        let key: String = key.extract()?;
        let Some(field) = accepted.iter().find(|f| f.keyword == key) else {
            let names: Vec<&str> = accepted.iter().map(|f| f.keyword).collect();
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "unexpected keyword argument '{key}': a walk takes {}",
                names.join(", ")
            )));
        };
        if value.is_none() {
            continue;
        }
        let number =
            || value.extract::<f64>().map_err(|_| value_error(format!("{key} = {value} is not a number")));
        if field.flag == K_N.flag {
            k_n = Some(number()?);
            continue;
        }
        if field.flag == K_S.flag {
            k_s = Some(number()?);
            continue;
        }
        let text = match field.kind {
            Kind::Switch => {
                let on: bool =
                    value.extract().map_err(|_| value_error(format!("{key} = {value} is not a bool")))?;
                // `servo_limit` is the switch `no-servo-limit` the other way round.
                if on == (field.flag == NO_SERVO_LIMIT.flag) {
                    continue;
                }
                "true".to_string()
            }
            Kind::Number | Kind::Whole => format!("{}", number()?),
            Kind::Text | Kind::Choice(_) | Kind::List => {
                value.extract::<String>().map_err(|_| value_error(format!("{key} = {value} is not a str")))?
            }
        };
        pairs.push((field.flag.to_string(), text));
    }
    let scenario =
        Scenario::new(robot.inner.clone(), terrain.inner.clone(), k_n, k_s).map_err(value_error)?;
    let mut p = Params::new("simulate", &pairs);
    let settings = SettingsRequest::read(&mut p, Words::Keyword)
        .and_then(|s| s.settings(Words::Keyword))
        .map_err(request_error)?;
    p.finish().map_err(request_error)?;
    Ok((scenario, settings))
}

/// Walks the robot `walks` times (2 to 1000) at one slope, the mass perturbed by 1e-9 relative
/// between walks (`sandslope simulate --ensemble N --json`, docs/simulate.md "Pitch free"):
/// the spread's dict, with every walk's summary under `summaries`.
#[pyfunction]
#[pyo3(signature = (robot, terrain, slope_deg, duration_s, walks, **keywords))]
pub fn simulate_ensemble<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    terrain: &PyTerrain,
    slope_deg: f64,
    duration_s: f64,
    walks: usize,
    keywords: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let (scenario, settings) = setup(robot, terrain, duration_s, keywords)?;
    let slope = sandslope::SignedSlope::from_degrees(slope_deg).map_err(value_error)?;
    let request = Walks::at(scenario, slope, settings, Some(walks));
    let e = py.detach(|| request.simulate_ensemble(walks)).map_err(request_error)?;
    pythonize(py, &e).map_err(value_error)
}

/// Whether a walk is converged (`sandslope simulate --check-convergence --json`,
/// docs/simulate.md "Checking convergence"): the walk as asked, again at a quarter of its step
/// and at a tenth of its creep speed, held to issue 38's tolerances; with `walks`, each setting
/// is an ensemble of that many walks and their means are compared. `slope_deg` is one slope
/// (answered by one dict) or a sequence of slopes (`--slopes`: a list of dicts, the slopes
/// in parallel; not with `walks`).
#[pyfunction]
#[pyo3(signature = (robot, terrain, slope_deg, duration_s, walks=None, **keywords))]
pub fn check_convergence<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    terrain: &PyTerrain,
    slope_deg: &Bound<'py, PyAny>,
    duration_s: f64,
    walks: Option<usize>,
    keywords: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let (scenario, settings) = setup(robot, terrain, duration_s, keywords)?;
    let signed = |deg: f64| sandslope::SignedSlope::from_degrees(deg).map_err(value_error);
    let request = match slope_deg.extract::<f64>() {
        Ok(deg) => Walks::at(scenario, signed(deg)?, settings, walks),
        Err(_) => {
            let degs: Vec<f64> = slope_deg
                .extract()
                .map_err(|_| value_error("slope_deg must be a number of degrees or a sequence of them"))?;
            if walks.is_some() {
                return Err(value_error("walks: an ensemble walks one slope; give slope_deg as a number"));
            }
            if degs.is_empty() || degs.len() > sandslope_request::simulate::MAX_SLOPES {
                return Err(value_error(format!(
                    "slope_deg holds {} slopes: give 1 to {}",
                    degs.len(),
                    sandslope_request::simulate::MAX_SLOPES
                )));
            }
            let slopes = degs.into_iter().map(signed).collect::<PyResult<Vec<_>>>()?;
            Walks::at_slopes(scenario, slopes, settings)
        }
    }
    .checking_convergence();
    let many = request.many;
    let mut checks = py.detach(|| request.check_convergence()).map_err(request_error)?;
    if many {
        return pythonize(py, &checks).map_err(value_error);
    }
    let c = checks.pop().ok_or_else(|| value_error("the check gave no result"))?;
    pythonize(py, &c).map_err(value_error)
}

/// The keywords every walk takes, with their defaults as the table gives them (`None`: not
/// set unless given): what the Python layer's `WalkSettings` and the stubs are checked
/// against.
#[pyfunction]
pub fn walk_keyword_defaults() -> Vec<(&'static str, Option<&'static str>)> {
    walk_keywords().into_iter().map(|f| (f.keyword, f.default)).collect()
}
