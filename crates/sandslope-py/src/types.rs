//! `Robot` and `Terrain`: the library's validated types as Python classes, built from keyword
//! arguments, TOML files (read by `sandslope-io`) or built-in presets; readable `repr`, plain
//! `to_dict()`, equality and pickling (Dask sends them to worker processes).

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use pythonize::{depythonize, pythonize};

use sandslope::robot_key::RobotKey;
use sandslope::{Robot, RobotSpec, Slope, Terrain, TerrainSpec};
use sandslope_files::{read_text, Source};
use sandslope_io::presets::{self, PresetKind};
use sandslope_io::{robot_from_toml, terrain_from_toml};

use crate::{anyhow_error, value_error};

/// A legged robot (docs/model.md §2), validated when built.
#[pyclass(module = "sandslope", name = "Robot", frozen, eq, skip_from_py_object)]
#[derive(Clone, PartialEq)]
pub struct PyRobot {
    pub inner: Robot,
}

impl PyRobot {
    /// The robot for the closed form: a `ValueError` naming `leg_shape` unless its legs are
    /// C-legs, the one shape the closed form is derived for (`simulate` walks every shape).
    pub(crate) fn closed_form(&self) -> PyResult<&Robot> {
        self.inner.leg_shape().closed_form().map_err(value_error)?;
        Ok(&self.inner)
    }
}

/// A number as Python's `repr` writes it (`0.35`, `1e-05`, `700000.0`).
fn py_float(x: f64) -> String {
    if x.is_finite() && x == x.trunc() && x.abs() < 1e16 {
        format!("{x:.1}")
    } else {
        format!("{x}")
    }
}

fn preset_toml(name: &str, kind: PresetKind) -> PyResult<(&'static str, &'static str)> {
    match presets::find(name, kind) {
        Some(p) => Ok((p.name, p.toml)),
        None => {
            let what = if kind == PresetKind::Robot { "robot" } else { "terrain" };
            Err(value_error(format!(
                "`{name}` is not a built-in {what} (built-in: {})",
                presets::names(kind)
            )))
        }
    }
}

/// Calls `sandslope._pickle.<name>(spec)`: the reconstructor pickle records by name.
fn reducer<'py>(py: Python<'py>, name: &str, spec: Bound<'py, PyAny>) -> PyResult<Bound<'py, PyTuple>> {
    let f = py.import("sandslope._pickle")?.getattr(name)?;
    PyTuple::new(py, [f, PyTuple::new(py, [spec])?.into_any()])
}

#[pymethods]
impl PyRobot {
    /// Robot(**keys): the keys of docs/model.md §2 (mass_kg, leg_radius_m, leg_width_m,
    /// hip_height_m, leg_speed_rad_s, stance_legs, response_time_s; optional
    /// leg_contact_area_m2, level_step_m, min_step_m, the simulator's keys and leg_shape).
    #[new]
    #[pyo3(signature = (**keys))]
    fn new(py: Python<'_>, keys: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let empty = PyDict::new(py);
        let keys = keys.unwrap_or(&empty);
        let spec: RobotSpec = depythonize(keys).map_err(|e| value_error(format!("Robot: {e}")))?;
        Robot::new(spec).map(|inner| PyRobot { inner }).map_err(value_error)
    }

    /// The robot of a TOML file (keys of docs/model.md §2; unknown keys rejected).
    #[staticmethod]
    fn from_toml(path: PathBuf) -> PyResult<Self> {
        let text = read_text(&path).map_err(anyhow_error)?;
        robot_from_toml(&text, &Source::File(path)).map(|inner| PyRobot { inner }).map_err(anyhow_error)
    }

    /// A TOML file or a built-in robot's name, as the command line's `--robot FILE|PRESET`
    /// takes it (an existing path, or anything ending in `.toml`, is a file).
    #[staticmethod]
    fn load(file_or_preset: PathBuf) -> PyResult<Self> {
        sandslope_io::load_robot(&file_or_preset.to_string_lossy())
            .map(|inner| PyRobot { inner })
            .map_err(anyhow_error)
    }

    /// A built-in robot by name (see `sandslope.presets()`), e.g. `"paper-hexapod"`.
    #[staticmethod]
    fn preset(name: &str) -> PyResult<Self> {
        let (name, toml) = preset_toml(name, PresetKind::Robot)?;
        robot_from_toml(toml, &Source::Preset(name)).map(|inner| PyRobot { inner }).map_err(anyhow_error)
    }

    /// The same robot with another total mass, kg.
    fn with_mass(&self, mass_kg: f64) -> PyResult<Self> {
        self.inner
            .with_mass(mass_kg)
            .map(|inner| PyRobot { inner })
            .map_err(|e| value_error(e.renamed("mass_kg")))
    }

    /// The keys of docs/model.md §2 as a dict (optional keys only when given).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        pythonize(py, self.inner.spec()).map_err(value_error)
    }

    /// Total mass m, kg.
    #[getter]
    fn mass_kg(&self) -> f64 {
        self.inner.mass()
    }

    /// Leg reach below the surface, `2R - h`, m.
    #[getter]
    fn max_depth_m(&self) -> f64 {
        self.inner.max_depth()
    }

    /// Minimum step for robust progress s_min, m.
    #[getter]
    fn min_step_m(&self) -> f64 {
        self.inner.min_step()
    }

    fn __repr__(&self) -> String {
        // The robot keys, from their one table (docs/model.md §2), optional ones where set.
        let s = self.inner.spec();
        let parts: Vec<String> = RobotKey::ALL
            .into_iter()
            .filter_map(|k| {
                let v = k.get(s)?;
                Some(match k {
                    RobotKey::StanceLegs => format!("{}={}", k.name(), s.stance_legs),
                    _ => format!("{}={}", k.name(), py_float(v)),
                })
            })
            .collect();
        format!("Robot({})", parts.join(", "))
    }

    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        reducer(py, "robot", self.to_dict(py)?)
    }
}

/// A terrain table (docs/model.md §7), validated when built.
#[pyclass(module = "sandslope", name = "Terrain", frozen, eq, skip_from_py_object)]
#[derive(Clone, PartialEq)]
pub struct PyTerrain {
    pub inner: Terrain,
}

#[pymethods]
impl PyTerrain {
    /// Terrain(points=[{slope_deg, k_n, k_s, k_n_sd?, k_s_sd?}, ...], repose_deg=None, name=None).
    #[new]
    #[pyo3(signature = (points, repose_deg=None, name=None))]
    fn new(
        py: Python<'_>,
        points: &Bound<'_, PyAny>,
        repose_deg: Option<f64>,
        name: Option<String>,
    ) -> PyResult<Self> {
        let d = PyDict::new(py);
        d.set_item("points", points)?;
        d.set_item("repose_deg", repose_deg)?;
        d.set_item("name", name)?;
        let spec: TerrainSpec = depythonize(&d).map_err(|e| value_error(format!("Terrain: {e}")))?;
        Terrain::new(spec).map(|inner| PyTerrain { inner }).map_err(value_error)
    }

    /// The terrain of a TOML file (keys of docs/model.md §7; unknown keys rejected).
    #[staticmethod]
    fn from_toml(path: PathBuf) -> PyResult<Self> {
        let text = read_text(&path).map_err(anyhow_error)?;
        terrain_from_toml(&text, &Source::File(path)).map(|inner| PyTerrain { inner }).map_err(anyhow_error)
    }

    /// A TOML file or a built-in terrain's name, as the command line's `--terrain
    /// FILE|PRESET` takes it (an existing path, or anything ending in `.toml`, is a file).
    #[staticmethod]
    fn load(file_or_preset: PathBuf) -> PyResult<Self> {
        sandslope_io::load_terrain(&file_or_preset.to_string_lossy())
            .map(|inner| PyTerrain { inner })
            .map_err(anyhow_error)
    }

    /// A built-in terrain by name (see `sandslope.presets()`), e.g. `"glass-beads-300um"`.
    #[staticmethod]
    fn preset(name: &str) -> PyResult<Self> {
        let (name, toml) = preset_toml(name, PresetKind::Terrain)?;
        terrain_from_toml(toml, &Source::Preset(name)).map(|inner| PyTerrain { inner }).map_err(anyhow_error)
    }

    /// One point everywhere: constant k_n and k_s (N/m^3) at every slope.
    #[staticmethod]
    fn constant(k_n: f64, k_s: f64) -> PyResult<Self> {
        Terrain::constant(k_n, k_s).map(|inner| PyTerrain { inner }).map_err(value_error)
    }

    /// `{"name", "repose_deg", "points": [...]}` (points sorted by slope).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        pythonize(py, self.inner.spec()).map_err(value_error)
    }

    /// The terrain's name, or None.
    #[getter]
    fn name(&self) -> Option<&str> {
        self.inner.name()
    }

    /// The angle of repose, degrees, or None.
    #[getter]
    fn repose_deg(&self) -> Option<f64> {
        self.inner.repose().map(Slope::degrees)
    }

    /// The terrain at one slope (interpolation rule of docs/model.md §7): a dict with k_n,
    /// k_s, k_n_sd, k_s_sd (None where the table has none) and `extrapolated`.
    fn at<'py>(&self, py: Python<'py>, slope_deg: f64) -> PyResult<Bound<'py, PyDict>> {
        let slope = Slope::from_signed_degrees(slope_deg).map_err(|e| value_error(e.renamed("slope_deg")))?;
        let ground = self.inner.at(slope);
        let (k_n_sd, k_s_sd) = self.inner.sd_at(slope);
        let d = PyDict::new(py);
        d.set_item("k_n", ground.k_n)?;
        d.set_item("k_s", ground.k_s)?;
        d.set_item("k_n_sd", k_n_sd)?;
        d.set_item("k_s_sd", k_s_sd)?;
        d.set_item("extrapolated", self.inner.extrapolates(slope))?;
        Ok(d)
    }

    /// The warning every front end gives for answers at `slopes_deg` above the last measured
    /// point (docs/model.md §7), or None: the request layer's rule and message.
    fn _extrapolation_warning(&self, slopes_deg: Vec<f64>) -> Option<String> {
        let beyond = sandslope_request::scenario::beyond_last_point(&self.inner, &slopes_deg);
        sandslope_request::scenario::extrapolation_warning(&self.inner, &beyond)
    }

    fn __repr__(&self) -> String {
        let spec = self.inner.spec();
        let points: Vec<String> = spec
            .points
            .iter()
            .map(|p| {
                let mut s = format!(
                    "{{'slope_deg': {}, 'k_n': {}, 'k_s': {}",
                    py_float(p.slope_deg),
                    py_float(p.k_n),
                    py_float(p.k_s)
                );
                for (k, v) in [("k_n_sd", p.k_n_sd), ("k_s_sd", p.k_s_sd)] {
                    if let Some(v) = v {
                        s.push_str(&format!(", '{k}': {}", py_float(v)));
                    }
                }
                s + "}"
            })
            .collect();
        let mut out = format!("Terrain(points=[{}]", points.join(", "));
        if let Some(r) = spec.repose_deg {
            out.push_str(&format!(", repose_deg={}", py_float(r)));
        }
        if let Some(n) = &spec.name {
            out.push_str(&format!(", name={n:?}"));
        }
        out + ")"
    }

    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        reducer(py, "terrain", self.to_dict(py)?)
    }
}

/// The built-in presets: `[(name, "robot" | "terrain", summary)]`.
#[pyfunction]
pub fn preset_names() -> Vec<(&'static str, &'static str, &'static str)> {
    presets::PRESETS
        .iter()
        .map(|p| (p.name, if p.kind == PresetKind::Robot { "robot" } else { "terrain" }, p.summary))
        .collect()
}
