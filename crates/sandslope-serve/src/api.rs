//! The JSON API: `GET /api/<command>?<flag>=<value>&...` answered with exactly what
//! `sandslope <command> <flags> --json` prints.
//!
//! A request's parameters are read into the command's typed request (`sandslope-request`:
//! `slope=20` is the field `slope` of `PredictRequest`), the one the command line builds from
//! its flags, so fields, defaults, checks and messages are the command line's, and the field at
//! fault comes from the request layer's error. The answer is the request's `answer`, the value
//! the command prints with `--json`, serialised as `print_json` does: pretty JSON and a newline.
//!
//! What a request may not do: name a file (robots and terrains are built-in presets or the
//! ones the server was started with; `plan` plans on the served DEM), ask for an output file
//! (`--plot`, `--csv`, ...), or ask for more work than the limits below.

use crate::reply::{ApiError, Reply};
use crate::served::Served;
use sandslope_io::presets::{self, PresetKind};
use sandslope_request::plan::{CLASSES, CLASS_TERRAIN};
use sandslope_request::risk::AnswerLimits;
use sandslope_request::scenario::{ROBOT, TERRAIN};
use sandslope_request::simulate::{self, Walks};
use sandslope_request::sweep;
use sandslope_request::{
    PhaseRequest, PlanRequest, PredictRequest, RiskRequest, SimulateRequest, SweepRequest,
};

/// Most slopes one `/api/sweep` request evaluates.
pub const MAX_SWEEP_SLOPES: usize = 10_000;
/// Most grid cells one `/api/phase` request computes, over all its panels (the command line
/// allows 2^28; 2^20 is 6 panels of the default 400 x 400 and takes about a second).
pub const MAX_PHASE_CELLS: u128 = 1 << 20;
/// What one `/api/risk` request may ask for: at most 1000 slopes of a p_fail curve (a
/// quadrature each, a few ms), 100 slopes of a payload envelope (a search over masses each)
/// and 2^20 `--map` cells (the command line allows 65536 slopes and 2^24 cells).
pub const RISK_LIMITS: AnswerLimits =
    AnswerLimits { curve_slopes: 1000, envelope_slopes: 100, map_cells: 1 << 20 };

/// Longest walk one `/api/simulate` request simulates, s (the command line has no limit but
/// the library's 2e7 integration steps).
pub const MAX_SIM_DURATION_S: f64 = 60.0;
/// Most slopes of one `/api/simulate?slopes=...` request (the command line allows 1000).
pub const MAX_SIM_SLOPES: usize = 100;
/// Highest trajectory sample rate one request may ask for, Hz (the command line allows 1e5).
pub const MAX_SIM_RATE_HZ: f64 = 1000.0;
/// Most integration steps of one request, over all its slopes, settling included (2e6 at the
/// default 1 ms step is 100 slopes of 10 s or 33 of 60 s: about 2 s of one core, release build).
pub const MAX_SIM_STEPS: f64 = 2e6;

/// The commands the API answers, in the order docs/serve.md lists them.
pub const COMMANDS: [&str; 6] = ["predict", "sweep", "phase", "risk", "simulate", "plan"];

/// Flags that write files or choose an output format: the API always answers JSON and
/// writes nothing.
const OUTPUT_FLAGS: [&str; 11] = [
    "json",
    "csv",
    "plot",
    "npy",
    "observed",
    "geojson",
    "risk-map",
    "out",
    CLASSES.flag,
    CLASS_TERRAIN.flag,
    "animate",
];

/// A request's parameters as the request layer reads them: output flags and names that are
/// not built-in presets refused (a request writes no file and reads none), the served robot
/// and terrain added where the request names none.
pub fn request_params(
    params: &[(String, String)],
    served: &Served,
) -> Result<Vec<(String, String)>, ApiError> {
    for (key, value) in params {
        if OUTPUT_FLAGS.contains(&key.as_str()) {
            return Err(ApiError::bad(
                Some(key.clone()),
                format!(
                    "{key}: the API answers JSON and writes no file; this flag is for the command line only"
                ),
            ));
        }
        if let Some(kind) = preset_kind(key) {
            check_preset(key, value, kind)?;
        }
    }
    let mut params = params.to_vec();
    for (key, served_value) in [(ROBOT.flag, &served.robot), (TERRAIN.flag, &served.terrain)] {
        if !params.iter().any(|(k, _)| k == key) {
            params.push((key.to_string(), served_value.clone()));
        }
    }
    Ok(params)
}

/// A plan request's parameters: those of [`request_params`] and the served DEM, the only one
/// a request may plan on (naming another is refused; without one, a 404).
pub fn plan_params(params: &[(String, String)], served: &Served) -> Result<Vec<(String, String)>, ApiError> {
    let dem_key = sandslope_request::plan::DEM.flag;
    if params.iter().any(|(k, _)| k == dem_key) {
        return Err(ApiError::bad(
            Some(dem_key.into()),
            format!("{dem_key}: a request cannot name a file; the server plans on the DEM it was started with (serve --{dem_key})"),
        ));
    }
    let Some(dem) = &served.dem else {
        return Err(ApiError {
            status: 404,
            field: None,
            error: format!("/api/plan needs an elevation model: start the server with --{dem_key} FILE"),
        });
    };
    let mut params = request_params(params, served)?;
    params.push((dem_key.to_string(), dem.display().to_string()));
    Ok(params)
}

/// Refuses a robot or terrain that is not a built-in preset: a request cannot name a file.
fn check_preset(key: &str, value: &str, kind: PresetKind) -> Result<(), ApiError> {
    if presets::find(value, kind).is_none() {
        return Err(ApiError::bad(
            Some(key.into()),
            format!(
                "{key} = `{value}` is not a built-in preset ({}); a request cannot name a file",
                presets::names(kind)
            ),
        ));
    }
    Ok(())
}

/// Answers `/api/<command>` with these parameters (in request order): the JSON body, written
/// as it is sent.
pub fn answer(command: &str, params: &[(String, String)], served: &Served) -> Result<Reply, ApiError> {
    match command {
        "predict" => {
            let request = PredictRequest::from_params(&request_params(params, served)?)?;
            Ok(Reply::pretty(request.answer()?))
        }
        "sweep" => {
            let request = SweepRequest::from_params(&request_params(params, served)?)?;
            let n = request.slopes()?.len();
            if n > MAX_SWEEP_SLOPES {
                return Err(ApiError::bad(
                    Some(sweep::STEP.flag.to_string()),
                    format!(
                        "{}/{}/{} give {n} slopes; the server evaluates at most {MAX_SWEEP_SLOPES}",
                        sweep::FROM.long(),
                        sweep::TO.long(),
                        sweep::STEP.long()
                    ),
                ));
            }
            Ok(Reply::pretty(request.answer()?))
        }
        "phase" => {
            let request = PhaseRequest::from_params(&request_params(params, served)?)?;
            Ok(Reply::pretty(request.answer(MAX_PHASE_CELLS)?))
        }
        "risk" => {
            let request = RiskRequest::from_params(&request_params(params, served)?)?;
            Ok(Reply::pretty(request.answer(RISK_LIMITS)?))
        }
        "simulate" => {
            let walks = simulate_walks(params, served)?;
            Ok(Reply::pretty(walks.respond()?))
        }
        "plan" => {
            let request = PlanRequest::from_params(&plan_params(params, served)?)?;
            Ok(Reply::pretty(request.answer()?))
        }
        _ => Err(ApiError {
            status: 404,
            field: None,
            error: format!("no endpoint /api/{command}; the API answers {}", COMMANDS.join(", ")),
        }),
    }
}

/// The walks a `simulate` request asks for, checked by the command's own flags and then
/// against the server's limits ([`MAX_SIM_DURATION_S`], [`MAX_SIM_SLOPES`],
/// [`MAX_SIM_RATE_HZ`], [`MAX_SIM_STEPS`]), each refusal naming its flag and limit.
pub fn simulate_walks(params: &[(String, String)], served: &Served) -> Result<Walks, ApiError> {
    let request = SimulateRequest::from_params(&request_params(params, served)?)?;
    let walks = request.walks()?;
    let duration = walks.settings.duration_s;
    if duration > MAX_SIM_DURATION_S {
        return Err(ApiError::bad(
            Some(simulate::DURATION.flag.to_string()),
            format!(
                "{} = {duration} s: the server simulates at most {MAX_SIM_DURATION_S} s per walk",
                simulate::DURATION.long()
            ),
        ));
    }
    if walks.slopes.len() > MAX_SIM_SLOPES {
        return Err(ApiError::bad(
            Some(simulate::SLOPES.flag.to_string()),
            format!(
                "{} gives {} slopes: the server simulates at most {MAX_SIM_SLOPES} per request",
                simulate::SLOPES.long(),
                walks.slopes.len()
            ),
        ));
    }
    if request.rate_hz > MAX_SIM_RATE_HZ {
        return Err(ApiError::bad(
            Some(simulate::RATE.flag.to_string()),
            format!(
                "{} = {} Hz: the server samples at most {MAX_SIM_RATE_HZ} Hz",
                simulate::RATE.long(),
                request.rate_hz
            ),
        ));
    }
    let steps = walks.integration_steps()?;
    if steps > MAX_SIM_STEPS {
        use simulate::{CHECK_CONVERGENCE, DT, DURATION, ENSEMBLE};
        let field = match (request.dt_s, request.ensemble, request.check_convergence) {
            (Some(_), _, _) => DT,
            (None, Some(_), _) => ENSEMBLE,
            (None, None, true) => CHECK_CONVERGENCE,
            (None, None, false) => DURATION,
        };
        return Err(ApiError::bad(
            Some(field.flag.to_string()),
            format!(
                "{}, {}, the slopes, {} and {} ask for {steps:.3e} integration steps: the server takes at \
                 most {MAX_SIM_STEPS:e} per request",
                DURATION.long(),
                DT.long(),
                ENSEMBLE.long(),
                CHECK_CONVERGENCE.long()
            ),
        ));
    }
    Ok(walks)
}

/// Parameters whose value must be a built-in preset of this kind.
fn preset_kind(key: &str) -> Option<PresetKind> {
    match key {
        k if k == ROBOT.flag => Some(PresetKind::Robot),
        k if k == TERRAIN.flag => Some(PresetKind::Terrain),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn served() -> Served {
        Served {
            robot: "paper-hexapod".into(),
            terrain: "glass-beads-300um".into(),
            dem: None,
            dem_info: None,
        }
    }

    fn ask(command: &str, params: &[(&str, &str)]) -> Result<serde_json::Value, ApiError> {
        let params: Vec<(String, String)> =
            params.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
        answer(command, &params, &served()).map(|r| serde_json::from_slice(&r.into_bytes().unwrap()).unwrap())
    }

    #[test]
    fn bad_requests_are_400s_naming_the_field() {
        let field = |r: Result<serde_json::Value, ApiError>| {
            let e = r.unwrap_err();
            assert_eq!(e.status, 400, "{e:?}");
            e.field.unwrap_or_default()
        };
        assert_eq!(field(ask("predict", &[("slope", "abc")])), "slope");
        assert_eq!(field(ask("predict", &[("slope", "NaN")])), "slope");
        assert_eq!(field(ask("predict", &[("slope", "1e308")])), "slope");
        assert_eq!(field(ask("predict", &[])), "slope");
        assert_eq!(field(ask("predict", &[("slope", "10"), ("mass", "-1")])), "mass");
        assert_eq!(field(ask("predict", &[("slope", "10"), ("mass", "1e400")])), "mass");
        assert_eq!(field(ask("predict", &[("slope", "10"), ("bogus", "1")])), "bogus");
        assert_eq!(field(ask("predict", &[("slope", "10"), ("robot", "/etc/passwd")])), "robot");
        assert_eq!(field(ask("predict", &[("slope", "10"), ("terrain", "../x.toml")])), "terrain");
        assert_eq!(field(ask("predict", &[("slope", "10"), ("json", "")])), "json");
        assert_eq!(field(ask("predict", &[("slope", "10"), ("slope", "11")])), "slope");
        assert_eq!(field(ask("sweep", &[("step", "1e-6")])), "step");
        assert_eq!(field(ask("sweep", &[("plot", "/tmp/x.png")])), "plot");
        assert_eq!(ask("nothing", &[]).unwrap_err().status, 404);
    }

    #[test]
    fn a_good_request_is_the_library_value() {
        // On level ground the paper's robot on the built-in terrain succeeds at about the
        // paper's measured 0.157 m/s (the terrain is calibrated on it; within 5 %), and with
        // omega = 2 pi rad/s the stance lasts T/2 = 0.5 s, so v = step / 0.5 s (docs/model.md §5).
        let v = ask("predict", &[("slope", "0")]).unwrap();
        assert_eq!(v["regime"], "success");
        let speed = v["speed_m_s"].as_f64().unwrap();
        assert!((speed - 0.157).abs() < 0.157 * 0.05, "{v}");
        assert!((speed - v["step_m"].as_f64().unwrap() / 0.5).abs() < 1e-12, "{v}");
        let v = ask("sweep", &[("from", "0"), ("to", "10"), ("step", "5")]).unwrap();
        assert_eq!(v.as_array().unwrap().len(), 3);
    }
}
