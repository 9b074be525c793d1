//! NumPy in and out: outputs are built as Rust vectors and handed to NumPy without a copy.
//! (Grid axes given as arrays are matched to the library's [`Axis`] by the request layer,
//! `sandslope_request::grammar::axis_of_values`.)

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use sandslope::{Axis, AxisScale};

/// Moves `v` into a 1-D NumPy array (the array owns the Rust buffer: no copy).
pub fn array<'py, T: numpy::Element>(py: Python<'py>, v: Vec<T>) -> Bound<'py, PyArray1<T>> {
    PyArray1::from_vec(py, v)
}

/// Puts `v` into `d` under `key` as a NumPy array.
pub fn put<T: numpy::Element>(d: &Bound<'_, PyDict>, key: &str, v: Vec<T>) -> PyResult<()> {
    d.set_item(key, array(d.py(), v))
}

/// The values of a 1-D array, copied (axes and small inputs only).
pub fn values(a: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    a.as_array().iter().copied().collect()
}

/// `"linear"` or `"log"`.
pub fn scale_name(a: &Axis) -> &'static str {
    match a.scale() {
        AxisScale::Linear => "linear",
        AxisScale::Log => "log",
    }
}
