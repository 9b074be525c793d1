//! `simulate`: the dynamic stride simulator (`sandslope simulate --json`, docs/model.md
//! §15-§18): the trajectory as NumPy columns (the Python layer makes a DataFrame of them) and
//! the summary as a dict with the same keys as `--json`.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use pythonize::pythonize;

use sandslope::simulate::{BodyPitch, Mechanisms, RftScaling, SimSettings};
use sandslope::Scenario;
use sandslope_request::error::Words;
use sandslope_request::simulate::{parse_body_pitch, parse_rft_scaling, SettingsRequest, Walks};
use sandslope_request::RequestError;

use crate::arrays::put;
use crate::types::{PyRobot, PyTerrain};
use crate::value_error;

/// Runs one walk; returns `(columns, summary)`: `columns` maps each trajectory column
/// (`time_s`, `x_m`, `z_m`, `pitch_rad`, `vx_m_s`, `vz_m_s`, then per leg j `leg{j}_angle_rad`,
/// `leg{j}_depth_m`, `leg{j}_force_x_n`, `leg{j}_force_z_n`, `leg{j}_torque_n_m`) to a 1-D
/// array; `summary` is `sandslope simulate --json`.
#[pyfunction]
#[pyo3(signature = (robot, terrain, slope_deg, duration_s, k_n=None, k_s=None, dt_s=None, creep_m_s=None, sample_rate_hz=sandslope::simulate::DEFAULT_SAMPLE_RATE_HZ, body_pitch="locked", rft_scaling="motion", servo_limit=true, leg_friction=None, duty_cycle=sandslope::simulate::mechanisms::CONSTANT_SPEED_DUTY, disturbed_sand=sandslope::simulate::mechanisms::UNDISTURBED_SAND))]
#[allow(clippy::too_many_arguments)]
pub fn simulate<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    terrain: &PyTerrain,
    slope_deg: f64,
    duration_s: f64,
    k_n: Option<f64>,
    k_s: Option<f64>,
    dt_s: Option<f64>,
    creep_m_s: Option<f64>,
    sample_rate_hz: f64,
    body_pitch: &str,
    rft_scaling: &str,
    servo_limit: bool,
    leg_friction: Option<f64>,
    duty_cycle: f64,
    disturbed_sand: f64,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyAny>)> {
    let (scenario, settings) = WalkKeywords {
        k_n,
        k_s,
        duration_s,
        dt_s,
        creep_m_s,
        rate_hz: sample_rate_hz,
        body_pitch,
        rft_scaling,
        servo_limit,
        mechanisms: Mechanisms { leg_friction, duty_cycle, disturbed_sand, ..Default::default() },
    }
    .setup(robot, terrain)?;
    let slope = sandslope::SignedSlope::from_degrees(slope_deg).map_err(value_error)?;
    let walks = Walks::at(scenario, slope, settings, None);
    let mut sims = py.detach(|| walks.simulate()).map_err(request_error)?;
    let sim = sims.pop().ok_or_else(|| value_error("the walk gave no result"))?;
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
    let summary = pythonize(py, &sim.summary).map_err(value_error)?;
    Ok((d, summary))
}

/// A refused request as Python's `ValueError`, its message in Python's words.
fn request_error(e: RequestError) -> PyErr {
    value_error(e.message())
}

/// The body-pitch and scaling keywords, parsed with the CLI's names, errors in Python's words.
fn modes(body_pitch: &str, rft_scaling: &str) -> PyResult<(BodyPitch, RftScaling)> {
    Ok((
        parse_body_pitch(body_pitch, Words::Keyword).map_err(request_error)?,
        parse_rft_scaling(rft_scaling, Words::Keyword).map_err(request_error)?,
    ))
}

/// The keywords every walk takes, as Python passes them.
struct WalkKeywords<'a> {
    k_n: Option<f64>,
    k_s: Option<f64>,
    duration_s: f64,
    dt_s: Option<f64>,
    creep_m_s: Option<f64>,
    rate_hz: f64,
    body_pitch: &'a str,
    rft_scaling: &'a str,
    servo_limit: bool,
    mechanisms: Mechanisms,
}

impl WalkKeywords<'_> {
    /// The robot on its terrain and the settings `sandslope simulate` checks, in Python's words.
    fn setup(&self, robot: &PyRobot, terrain: &PyTerrain) -> PyResult<(Scenario, SimSettings)> {
        let scenario = Scenario::new(robot.inner.clone(), terrain.inner.clone(), self.k_n, self.k_s)
            .map_err(value_error)?;
        let (body_pitch, rft_scaling) = modes(self.body_pitch, self.rft_scaling)?;
        let settings = SettingsRequest {
            duration_s: self.duration_s,
            dt_s: self.dt_s,
            creep_m_s: self.creep_m_s,
            servo_limit: self.servo_limit,
            body_pitch,
            rft_scaling,
            mechanisms: self.mechanisms,
            rate_hz: self.rate_hz,
        }
        .settings(Words::Keyword)
        .map_err(request_error)?;
        Ok((scenario, settings))
    }
}

/// Walks the robot `walks` times (2 to 1000) at one slope, the mass perturbed by 1e-9 relative
/// between walks (`sandslope simulate --ensemble N --json`, docs/simulate.md "Pitch free"):
/// the spread's dict, with every walk's summary under `summaries`.
#[pyfunction]
#[pyo3(signature = (robot, terrain, slope_deg, duration_s, walks, k_n=None, k_s=None, dt_s=None, creep_m_s=None, body_pitch="locked", rft_scaling="motion", servo_limit=true, leg_friction=None, duty_cycle=sandslope::simulate::mechanisms::CONSTANT_SPEED_DUTY, disturbed_sand=sandslope::simulate::mechanisms::UNDISTURBED_SAND))]
#[allow(clippy::too_many_arguments)]
pub fn simulate_ensemble<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    terrain: &PyTerrain,
    slope_deg: f64,
    duration_s: f64,
    walks: usize,
    k_n: Option<f64>,
    k_s: Option<f64>,
    dt_s: Option<f64>,
    creep_m_s: Option<f64>,
    body_pitch: &str,
    rft_scaling: &str,
    servo_limit: bool,
    leg_friction: Option<f64>,
    duty_cycle: f64,
    disturbed_sand: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let (scenario, settings) = WalkKeywords {
        k_n,
        k_s,
        duration_s,
        dt_s,
        creep_m_s,
        rate_hz: sandslope::simulate::DEFAULT_SAMPLE_RATE_HZ,
        body_pitch,
        rft_scaling,
        servo_limit,
        mechanisms: Mechanisms { leg_friction, duty_cycle, disturbed_sand, ..Default::default() },
    }
    .setup(robot, terrain)?;
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
#[pyo3(signature = (robot, terrain, slope_deg, duration_s, walks=None, k_n=None, k_s=None, dt_s=None, creep_m_s=None, body_pitch="locked", rft_scaling="motion", servo_limit=true, leg_friction=None, duty_cycle=sandslope::simulate::mechanisms::CONSTANT_SPEED_DUTY, disturbed_sand=sandslope::simulate::mechanisms::UNDISTURBED_SAND))]
#[allow(clippy::too_many_arguments)]
pub fn check_convergence<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    terrain: &PyTerrain,
    slope_deg: &Bound<'py, PyAny>,
    duration_s: f64,
    walks: Option<usize>,
    k_n: Option<f64>,
    k_s: Option<f64>,
    dt_s: Option<f64>,
    creep_m_s: Option<f64>,
    body_pitch: &str,
    rft_scaling: &str,
    servo_limit: bool,
    leg_friction: Option<f64>,
    duty_cycle: f64,
    disturbed_sand: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let (scenario, settings) = WalkKeywords {
        k_n,
        k_s,
        duration_s,
        dt_s,
        creep_m_s,
        rate_hz: sandslope::simulate::DEFAULT_SAMPLE_RATE_HZ,
        body_pitch,
        rft_scaling,
        servo_limit,
        mechanisms: Mechanisms { leg_friction, duty_cycle, disturbed_sand, ..Default::default() },
    }
    .setup(robot, terrain)?;
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
