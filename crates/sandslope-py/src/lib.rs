//! `sandslope._sandslope`: the compiled core of the `sandslope` Python package.
//!
//! A thin layer over the `sandslope` library, the `sandslope-io` readers and the
//! `sandslope-request` requests: it converts Python values into a request's fields (which the
//! request checks into the library's types and answers), releases the GIL while the library
//! computes (in parallel, with rayon), and hands the results back as NumPy arrays that own
//! the Rust buffers (no copy). It computes nothing itself. The pure-Python package
//! (`python/sandslope/`) adds NumPy broadcasting, reshaping, docstrings and the Dask layer.
//!
//! Errors are `ValueError`s carrying the message the CLI would print for the same input:
//! the key (here the Python argument name), the value and the valid range (docs/model.md); a
//! missing input file is a `FileNotFoundError`.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

mod arrays;
mod calibrate;
mod fields;
mod interrupt;
mod measure;
mod model;
mod plan;
mod report;
mod risk;
mod servo;
mod simulate;
mod types;

/// A `ValueError` from anything displayable, with its whole cause chain on one line
/// (`file: key = value must be ...`).
pub(crate) fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// A `ValueError` from an `anyhow` error, causes joined by `: ` as the CLI prints them; a
/// file that is not there is a `FileNotFoundError` (errno 2, the message, the path when the
/// reader named it), as Python's own `open` raises.
pub(crate) fn anyhow_error(e: anyhow::Error) -> PyErr {
    let not_found = e
        .chain()
        .filter_map(|c| c.downcast_ref::<std::io::Error>())
        .any(|io| io.kind() == std::io::ErrorKind::NotFound);
    if not_found {
        return pyo3::exceptions::PyFileNotFoundError::new_err((ENOENT, format!("{e:#}")));
    }
    PyValueError::new_err(format!("{e:#}"))
}

/// `ENOENT`, the errno of a missing file on every platform Python runs on.
const ENOENT: i32 = 2;

/// The compiled module.
#[pymodule]
fn _sandslope(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<types::PyRobot>()?;
    m.add_class::<types::PyTerrain>()?;
    m.add_function(wrap_pyfunction!(types::preset_names, m)?)?;
    m.add_function(wrap_pyfunction!(model::predict, m)?)?;
    m.add_function(wrap_pyfunction!(model::phase, m)?)?;
    m.add_function(wrap_pyfunction!(risk::risk, m)?)?;
    m.add_function(wrap_pyfunction!(risk::risk_map, m)?)?;
    m.add_function(wrap_pyfunction!(risk::safe_slope, m)?)?;
    m.add_function(wrap_pyfunction!(risk::safe_mass, m)?)?;
    m.add_function(wrap_pyfunction!(risk::payload_envelope, m)?)?;
    m.add_function(wrap_pyfunction!(plan::risk_raster, m)?)?;
    m.add_function(wrap_pyfunction!(plan::plan, m)?)?;
    m.add_function(wrap_pyfunction!(plan::read_raster, m)?)?;
    m.add_function(wrap_pyfunction!(plan::geotiff_nodata, m)?)?;
    m.add_function(wrap_pyfunction!(plan::pds3_info, m)?)?;
    m.add_function(wrap_pyfunction!(plan::pds3_window, m)?)?;
    m.add_function(wrap_pyfunction!(measure::read_touchdowns, m)?)?;
    m.add_function(wrap_pyfunction!(measure::fit, m)?)?;
    m.add_function(wrap_pyfunction!(measure::track, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate::calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(simulate::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(simulate::simulate_ensemble, m)?)?;
    m.add_function(wrap_pyfunction!(simulate::check_convergence, m)?)?;
    m.add_function(wrap_pyfunction!(simulate::walk_keyword_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(fields::request_keywords, m)?)?;
    m.add_function(wrap_pyfunction!(report::report, m)?)?;
    m.add_function(wrap_pyfunction!(servo::read_servo_log, m)?)?;
    m.add_function(wrap_pyfunction!(servo::infer_servo_log, m)?)?;
    m.add_function(wrap_pyfunction!(servo::infer_servo_log_file, m)?)?;
    m.add_function(wrap_pyfunction!(servo::drive_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(servo::drive, m)?)?;
    m.add_function(wrap_pyfunction!(servo::bag_topics, m)?)?;
    m.add_function(wrap_pyfunction!(servo::read_bag_poses, m)?)?;
    m.add_function(wrap_pyfunction!(servo::read_bag_joints, m)?)?;
    m.add_function(wrap_pyfunction!(servo::read_bag_load_cell, m)?)?;
    m.add("DEFAULT_MAX_RISK", sandslope::risk::DEFAULT_MAX_RISK)?;
    m.add("DEFAULT_MAX_ROLL_DEG", sandslope::plan::DEFAULT_MAX_ROLL_DEG)?;
    m.add("REGIMES", sandslope::Regime::ALL.map(sandslope::Regime::name))?;
    m.add("OUTCOMES", sandslope::Regime::ALL.map(sandslope_request::format::Outcome::outcome))?;
    m.add("CAUSES", sandslope::Cause::ALL.map(sandslope::Cause::name))?;
    Ok(())
}
