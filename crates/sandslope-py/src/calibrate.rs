//! `sandslope.calibrate(...)`: the joint calibration of `sandslope calibrate` (docs/calibration.md)
//! through the request layer's [`CalibrateRequest`]: its checks, its evidence files and its one
//! library call, answered as the text `calibrate --json` prints (the Python layer parses it, so
//! the dict has exactly its keys and values).

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use pyo3::prelude::*;

use sandslope_request::calibrate::{CalibrateAnswer, CalibrateLaw, CalibrateModel, CalibrateSource};
use sandslope_request::error::Words;
use sandslope_request::CalibrateRequest;

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

/// How often the waiting thread looks for Ctrl-C while the fit runs.
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// Runs `work` on its own thread with the GIL released, looking for a signal (Ctrl-C) every
/// [`SIGNAL_POLL`]: on one it raises the cancel flag `work` was given, waits for `work` to
/// stop (the simulator's fit ends within the walks in flight) and raises the signal's error
/// (`KeyboardInterrupt`). `calibrate(model="simulate")` runs for minutes.
fn interruptible<T: Send>(py: Python<'_>, work: impl FnOnce(Arc<AtomicBool>) -> T + Send) -> PyResult<T> {
    let cancel = Arc::new(AtomicBool::new(false));
    std::thread::scope(|scope| {
        let flag = Arc::clone(&cancel);
        let worker = scope.spawn(move || work(flag));
        while !worker.is_finished() {
            py.detach(|| std::thread::sleep(SIGNAL_POLL));
            if let Err(signal) = py.check_signals() {
                cancel.store(true, Ordering::Relaxed);
                let _ = py.detach(|| worker.join());
                return Err(signal);
            }
        }
        py.detach(|| worker.join()).map_err(|_| value_error("calibrate stopped unexpectedly (a panic)"))
    })
}

/// The fit as `sandslope calibrate --json` prints it (as text). `robot` and `terrain` are the
/// command line's `--robot` and `--terrain` (the source of k_n without `forces` or `k_n`, and
/// of the angle of repose), `terrain_source` the terrain's name as the answer's repose record
/// gives it; every other keyword is the flag of the same name. The GIL is released during the
/// fit, and Ctrl-C stops it ([`interruptible`]).
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
    let source =
        CalibrateSource { robot: &robot.inner, terrain: &terrain.inner, terrain_name: &terrain_source };
    let answer =
        interruptible(py, |cancel| request.answer_cancellable(source, Words::Keyword, Some(cancel)))?
            .map_err(|e| value_error(e.message()))?;
    match answer {
        CalibrateAnswer::Joint(joint) => serde_json::to_string(&joint),
        CalibrateAnswer::PerSlope(per_slope) => serde_json::to_string(&per_slope),
    }
    .map_err(value_error)
}
