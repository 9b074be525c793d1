//! `sandslope.calibrate(...)`: the joint calibration of `sandslope calibrate` (docs/calibration.md)
//! through the request layer's [`CalibrateRequest`]: its checks, its evidence files and its one
//! library call, answered as the text `calibrate --json` prints (the Python layer parses it, so
//! the dict has exactly its keys and values).

use std::path::PathBuf;

use pyo3::prelude::*;

use sandslope_request::calibrate::{CalibrateAnswer, CalibrateLaw, CalibrateModel, CalibrateSource};
use sandslope_request::error::Words;
use sandslope_request::CalibrateRequest;

use crate::interrupt::interruptibly;
use crate::types::{PyRobot, PyTerrain};
use crate::value_error;

/// The item of `all` whose command-line name is `given`, or an error naming the keyword and
/// the valid names.
fn named<T: Copy>(keyword: &str, given: &str, all: &[T], name: impl Fn(T) -> &'static str) -> PyResult<T> {
    all.iter().copied().find(|&x| name(x) == given).ok_or_else(|| {
        let valid: Vec<String> = all.iter().map(|&x| format!("{:?}", name(x))).collect();
        value_error(format!("{keyword} = {given:?} must be one of {}", valid.join(", ")))
    })
}

/// The fit as `sandslope calibrate --json` prints it (as text). `robot` and `terrain` are the
/// command line's `--robot` and `--terrain` (the source of k_n without `forces` or `k_n`, and
/// of the angle of repose), `terrain_source` the terrain's name as the answer's repose record
/// gives it; every other keyword is the flag of the same name. The GIL is released during the
/// fit, and Ctrl-C stops it ([`interruptibly`]).
#[pyfunction]
#[pyo3(signature = (robot, terrain, terrain_source, observed=None, forces=None, t1=None, free=Vec::new(), error_floor=None, law="linear", model="closed-form", k_n=None, name=None, repose=None))]
#[allow(clippy::too_many_arguments)]
pub fn calibrate(
    py: Python<'_>,
    robot: &PyRobot,
    terrain: &PyTerrain,
    terrain_source: String,
    observed: Option<PathBuf>,
    forces: Option<String>,
    t1: Option<PathBuf>,
    free: Vec<String>,
    error_floor: Option<f64>,
    law: &str,
    model: &str,
    k_n: Option<f64>,
    name: Option<String>,
    repose: Option<f64>,
) -> PyResult<String> {
    let request = CalibrateRequest {
        observed,
        forces,
        t1,
        free,
        error_floor,
        law: named("law", law, &CalibrateLaw::ALL, CalibrateLaw::name)?,
        model: named("model", model, &CalibrateModel::ALL, CalibrateModel::name)?,
        k_n,
        name,
        repose,
    };
    request.check_in(Words::Keyword).map_err(|e| value_error(e.message()))?;
    let source = CalibrateSource {
        robot: robot.closed_form()?,
        terrain: &terrain.inner,
        terrain_name: &terrain_source,
    };
    let answer = interruptibly(py, |stop| request.answer_cancellable(source, Words::Keyword, Some(stop)))?
        .map_err(|e| value_error(e.message()))?;
    match answer {
        CalibrateAnswer::Joint(joint) => serde_json::to_string(&joint),
        CalibrateAnswer::PerSlope(per_slope) => serde_json::to_string(&per_slope),
    }
    .map_err(value_error)
}
