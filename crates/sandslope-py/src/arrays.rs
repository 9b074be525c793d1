//! NumPy in and out: outputs are built as Rust vectors and handed to NumPy without a copy;
//! grid axes given as arrays are matched to the library's [`Axis`] (evenly spaced values or
//! logarithms), so phase and risk maps run on exactly the library's grids.

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use sandslope::{Axis, AxisScale};

use crate::value_error;

/// Moves `v` into a 1-D NumPy array (the array owns the Rust buffer: no copy).
pub fn array<'py, T: numpy::Element>(py: Python<'py>, v: Vec<T>) -> Bound<'py, PyArray1<T>> {
    PyArray1::from_vec(py, v)
}

pub use sandslope::memory::uninit;

/// Puts `v` into `d` under `key` as a NumPy array.
pub fn put<T: numpy::Element>(d: &Bound<'_, PyDict>, key: &str, v: Vec<T>) -> PyResult<()> {
    d.set_item(key, array(d.py(), v))
}

/// The values of a 1-D array, copied (axes and small inputs only).
pub fn values(a: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    a.as_array().iter().copied().collect()
}

/// The library axis whose values are `v`: evenly spaced values (`np.linspace`) or evenly
/// spaced logarithms (`np.geomspace`, `np.logspace`), to a relative 1e-9. `key` names the
/// argument in errors.
pub fn axis(key: &str, v: &[f64]) -> PyResult<Axis> {
    if v.len() < 2 {
        return Err(value_error(format!("{key} has {} values; at least 2 are needed", v.len())));
    }
    let (min, max) = (v[0], v[v.len() - 1]);
    let matches = |a: &Axis| {
        v.iter().enumerate().all(|(i, &x)| {
            let y = a.value(i);
            (x - y).abs() <= 1e-9 * x.abs().max(y.abs()).max(f64::MIN_POSITIVE)
        })
    };
    let linear = Axis::new(key, min, max, v.len(), AxisScale::Linear).map_err(value_error)?;
    if matches(&linear) {
        return Ok(linear);
    }
    if min > 0.0 {
        let log = Axis::new(key, min, max, v.len(), AxisScale::Log).map_err(value_error)?;
        if matches(&log) {
            return Ok(log);
        }
    }
    Err(value_error(format!(
        "{key} must be ascending and evenly spaced (np.linspace) or evenly spaced in logarithm \
         (np.geomspace), from {min} to {max}"
    )))
}

/// `"linear"` or `"log"`.
pub fn scale_name(a: &Axis) -> &'static str {
    match a.scale() {
        AxisScale::Linear => "linear",
        AxisScale::Log => "log",
    }
}
