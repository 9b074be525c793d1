//! `infer`'s request: what the robot's own gait says about the sand (docs/inference.md). From
//! observed speeds (and anchoring times), the posterior of k_s at each observed slope
//! ([`sandslope::infer::posteriors`]); with a shear law, the law's joint posterior and the
//! predicted failure risk at slopes not walked ([`sandslope::infer::law_posterior`]). And
//! `infer --servo-log`, k_s from a drive's currents ([`ServoLogRequest`]): the log read, its
//! slope taken from the request or the log's header, its prior and grid checked, for the
//! command line and Python's `infer_servo_log` of a log's path.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use sandslope::infer::servo::{
    infer_servo_log, CurrentInference, CurrentInferenceError, CurrentInferenceSettings, LegTrace,
};
use sandslope::infer::{
    law_posterior, posteriors, GaitObservation, InferLaw, LawPosterior, LogUniformPrior, RiskPrediction,
    SlopePosterior,
};
use sandslope::risk::UncertainTerrain;
use sandslope::{Robot, SignedSlope, Slope, Terrain};
use sandslope_io::observations::{load_speed_observations, load_step_observation};

use crate::error::{RequestError, Result, Words};

/// Where the gait observations come from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GaitEvidence {
    /// A CSV of observed speeds, `slope_deg,speed_m_s,speed_sd_m_s[,n]` (field `observed`).
    Observed(PathBuf),
    /// Per-step outputs of `track --csv`, one per slope, each `DEG=FILE` (field `steps`).
    Steps(Vec<String>),
}

/// The inputs of `infer` from gait observations, besides the robot and terrain (the front end
/// loads those, with its overrides and the terrain's uncertainty).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InferRequest {
    /// The observations.
    pub evidence: GaitEvidence,
    /// Log-uniform prior range of k_s, `(MIN, MAX)`, N/m^3 (field `k-s-prior`).
    pub k_s_prior: (f64, f64),
    /// The shear law tying the slopes together, if any (field `law`).
    pub law: Option<InferLaw>,
    /// Slopes to predict k_s and p_fail at with a law, degrees (field `predict`).
    pub predict: Vec<f64>,
}

/// The answer, as `infer --json` prints it.
#[derive(Debug, Clone, Serialize)]
pub struct InferAnswer {
    /// The prior used.
    pub prior: LogUniformPrior,
    /// The posterior of k_s at each observed slope.
    pub points: Vec<SlopePosterior>,
    /// The law's joint posterior, with a law.
    pub law: Option<LawPosterior>,
    /// The law's predictions (empty without a law).
    pub prediction: Vec<RiskPrediction>,
    /// Notes on defaults used (the terrain's uncertainty, with a law).
    pub notes: Vec<String>,
}

/// Parses the prior's command-line form `MIN:MAX`, N/m^3.
pub fn parse_prior(text: &str) -> Result<(f64, f64)> {
    let field = "k-s-prior";
    let parts: Vec<&str> = text.split(':').map(str::trim).collect();
    let [lo, hi] = parts.as_slice() else {
        return Err(RequestError::invalid(
            field,
            format!("--k-s-prior = {text} must be MIN:MAX in N/m^3 (e.g. 1e4:1e9)"),
        ));
    };
    let num = |s: &str| {
        s.parse::<f64>().map_err(|_| {
            RequestError::invalid(field, format!("--k-s-prior: `{s}` is not a number (in {text})"))
        })
    };
    Ok((num(lo)?, num(hi)?))
}

/// The log-uniform prior on `(MIN, MAX)`, checked (`0 < MIN < MAX`, finite); also what
/// `infer --servo-log` takes.
pub fn prior(range: (f64, f64)) -> Result<LogUniformPrior> {
    prior_in(Words::Flag, range)
}

/// [`prior`], naming the field in `words` (Python's `k_s_prior = (MIN, MAX)`).
pub fn prior_in(words: Words, (lo, hi): (f64, f64)) -> Result<LogUniformPrior> {
    LogUniformPrior::new(lo, hi).map_err(|e| {
        let message = match words {
            Words::Flag => format!("--k-s-prior: {e}"),
            Words::Keyword => format!("k_s_prior = ({lo:?}, {hi:?}): {e}"),
        };
        RequestError::invalid("k-s-prior", message)
    })
}

/// The most points of the servo-log inference's k_s grid (`infer --servo-log --grid-points`,
/// Python's `infer_servo_log(grid_points=...)`); at least 3.
pub const MAX_SERVO_GRID_POINTS: usize = 1000;

/// The servo-log inference's number of grid points, checked (3 to
/// [`MAX_SERVO_GRID_POINTS`]), the message naming the field in `words`.
pub fn servo_grid_points(words: Words, n: usize) -> Result<usize> {
    if (3..=MAX_SERVO_GRID_POINTS).contains(&n) {
        Ok(n)
    } else {
        Err(RequestError::invalid(
            "grid-points",
            format!("{} = {n} must be within 3 to {MAX_SERVO_GRID_POINTS}", words.name("grid-points")),
        ))
    }
}

impl InferRequest {
    /// The prior, checked ([`prior`]).
    pub fn prior(&self) -> Result<LogUniformPrior> {
        prior(self.k_s_prior)
    }

    /// The prediction slopes, checked (`0 <= slope < 90`); none without a law.
    pub fn predict_slopes(&self) -> Result<Vec<Slope>> {
        if self.law.is_none() {
            return Ok(Vec::new());
        }
        self.predict
            .iter()
            .map(|&d| {
                Slope::from_degrees(d).map_err(|e| RequestError::invalid("predict", e.renamed("--predict")))
            })
            .collect()
    }

    /// Every value checked before any file is read.
    pub fn check(&self) -> Result<()> {
        self.prior()?;
        self.predict_slopes().map(|_| ())
    }

    /// Reads the observations; errors name the file (and line) or the `steps` item.
    pub fn observations(&self) -> Result<Vec<GaitObservation>> {
        let steps = match &self.evidence {
            GaitEvidence::Observed(path) => {
                return load_speed_observations(path)
                    .map_err(|e| RequestError::from_error(Some("observed"), e));
            }
            GaitEvidence::Steps(steps) => steps,
        };
        let field = "steps";
        steps
            .iter()
            .map(|item| {
                let (deg, file) = item.split_once('=').ok_or_else(|| {
                    RequestError::invalid(
                        field,
                        format!("--steps `{item}` must be DEG=FILE (the slope of that track output)"),
                    )
                })?;
                let deg: f64 = deg.trim().parse().map_err(|_| {
                    RequestError::invalid(
                        field,
                        format!("--steps: slope `{deg}` is not a number (in {item})"),
                    )
                })?;
                let slope = Slope::from_degrees(deg)
                    .map_err(|e| RequestError::invalid(field, e.renamed("--steps slope")))?;
                load_step_observation(std::path::Path::new(file.trim()), slope)
                    .map_err(|e| RequestError::from_error(Some(field), e))
            })
            .collect()
    }

    /// The posteriors for `robot` on `terrain` (its k_n at each slope; with a law, its spread
    /// too), given the observations read by [`InferRequest::observations`]; `note` is the
    /// terrain's uncertainty note, kept with a law.
    pub fn answer(
        &self,
        robot: &Robot,
        terrain: &UncertainTerrain,
        note: Option<String>,
        observations: &[GaitObservation],
    ) -> Result<InferAnswer> {
        let prior = self.prior()?;
        let predict = self.predict_slopes()?;
        let points = posteriors(robot, terrain.terrain(), observations, &prior)
            .map_err(|e| RequestError::from_error(None, anyhow::anyhow!("{e}")))?;
        let law = match self.law {
            None => None,
            Some(law) => Some(
                law_posterior(robot, terrain, observations, &prior, law, &predict)
                    .map_err(|e| RequestError::invalid("law", format!("--law: {e}")))?,
            ),
        };
        let notes = if law.is_some() { note.into_iter().collect() } else { Vec::new() };
        let prediction = law.as_ref().map_or_else(Vec::new, |l| l.prediction.clone());
        Ok(InferAnswer { prior, points, law, prediction, notes })
    }
}

/// `infer --servo-log FILE` (and Python's `infer_servo_log` of a log's path): k_s from the
/// stance currents a `drive` run logged (docs/model.md §19).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ServoLogRequest {
    /// The log, as `drive --log` writes it.
    pub path: PathBuf,
    /// The run's slope, degrees (field `slope`); the log's `# slope_deg` header when `None`.
    pub slope_deg: Option<f64>,
    /// The prior's range of k_s, N/m^3 (field `k-s-prior`).
    pub k_s_prior: (f64, f64),
    /// Points of the simulator's k_s grid (field `grid-points`).
    pub grid_points: usize,
}

/// A servo log read and checked: what the inference runs on.
#[derive(Debug, Clone)]
pub struct ServoLogRun {
    /// The log's path (errors name it).
    pub path: PathBuf,
    /// The run's slope.
    pub slope: SignedSlope,
    /// Each leg's stance trace.
    pub traces: Vec<LegTrace>,
    /// What the reader repaired (the CLI's `note:` lines, Python's `notes`).
    pub notes: Vec<String>,
    /// The prior and grid.
    pub settings: CurrentInferenceSettings,
}

impl ServoLogRequest {
    /// Checks the prior and grid, reads the log for `robot`'s legs and takes the slope (the
    /// request's, else the log's header); errors name the file and the field in `words`.
    pub fn read(&self, robot: &Robot, words: Words) -> Result<ServoLogRun> {
        prior_in(words, self.k_s_prior)?;
        servo_grid_points(words, self.grid_points)?;
        let log = sandslope_io::servo_log::read_servo_log(&self.path)
            .map_err(|e| RequestError::from_error(Some("servo-log"), e))?;
        self.read_log(log, robot, words)
    }

    /// As [`read`](Self::read), for a log already read (a ROS 2 bag's joint states,
    /// `sandslope_io::bag::series::read_joint_states`); `path` names it in errors.
    pub fn read_log(
        &self,
        log: sandslope_io::servo_log::ServoLog,
        robot: &Robot,
        words: Words,
    ) -> Result<ServoLogRun> {
        let prior = prior_in(words, self.k_s_prior)?;
        let grid_points = servo_grid_points(words, self.grid_points)?;
        let path = self.path.as_path();
        let file_error = |e: anyhow::Error| RequestError::from_error(Some("servo-log"), e);
        let slope_name = match words {
            Words::Flag => "--slope",
            Words::Keyword => "slope_deg",
        };
        let (slope_deg, from_header) =
            match (self.slope_deg, log.meta_f64("slope_deg", path).map_err(file_error)?) {
                (Some(s), _) => (s, false),
                (None, Some(s)) => (s, true),
                (None, None) => {
                    let give = match words {
                        Words::Flag => "give the run's slope with --slope",
                        Words::Keyword => "give slope_deg",
                    };
                    return Err(RequestError::invalid(
                        "slope",
                        format!("{}: the log has no `# slope_deg = ...` header line; {give}", path.display()),
                    ));
                }
            };
        // A bad slope read from the header is the header's, not a flag the user did not give.
        let slope = SignedSlope::from_degrees(slope_deg).map_err(|e| {
            if from_header {
                let e = e.renamed(format!("{}: header line `# slope_deg`", path.display()));
                RequestError::invalid("slope", format!("{e}; give the run's slope with {slope_name}"))
            } else {
                RequestError::invalid("slope", e.renamed(slope_name))
            }
        })?;
        let traces = log.leg_traces(2 * robot.stance_legs() as usize, path).map_err(file_error)?;
        let settings = CurrentInferenceSettings { prior, grid_points, ..Default::default() };
        Ok(ServoLogRun { path: path.to_path_buf(), slope, traces, notes: log.notes, settings })
    }
}

impl ServoLogRun {
    /// The posterior of k_s (seconds of CPU: the stride simulator walks the grid); an error
    /// about the log names it.
    pub fn answer(&self, robot: &Robot, terrain: &Terrain) -> Result<CurrentInference> {
        infer_servo_log(robot, terrain, self.slope, &self.traces, &self.settings).map_err(|e| {
            let message = match e {
                CurrentInferenceError::TooFewStrides { .. } | CurrentInferenceError::Setting(_) => {
                    format!("{}: {e}", self.path.display())
                }
                e => e.to_string(),
            };
            RequestError::from_error(None, anyhow::anyhow!("{message}"))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request() -> InferRequest {
        InferRequest {
            evidence: GaitEvidence::Steps(Vec::new()),
            k_s_prior: (1e4, 1e9),
            law: None,
            predict: vec![0.0, 15.0, 30.0],
        }
    }

    #[test]
    fn checks_name_the_field() {
        assert_eq!(parse_prior(" 1e4 : 1e9 ").unwrap(), (1e4, 1e9));
        let e = parse_prior("1e4").unwrap_err();
        assert_eq!(e.field(), Some("k-s-prior"));
        assert_eq!(e.message(), "--k-s-prior = 1e4 must be MIN:MAX in N/m^3 (e.g. 1e4:1e9)");
        assert_eq!(
            parse_prior("1e4:x").unwrap_err().message(),
            "--k-s-prior: `x` is not a number (in 1e4:x)"
        );
        let e = InferRequest { k_s_prior: (1e9, 1e4), ..request() }.check().unwrap_err();
        assert_eq!(e.field(), Some("k-s-prior"));
        // Prediction slopes are checked only with a law.
        let bad = InferRequest { predict: vec![95.0], ..request() };
        assert!(bad.check().is_ok());
        let e = InferRequest { law: Some(InferLaw::Linear), ..bad }.check().unwrap_err();
        assert_eq!(e.field(), Some("predict"));
        assert!(e.message().starts_with("--predict = 95"), "{}", e.message());
    }

    #[test]
    fn steps_items_name_what_is_wrong() {
        let steps = |s: &str| InferRequest { evidence: GaitEvidence::Steps(vec![s.into()]), ..request() };
        let e = steps("10deg.csv").observations().unwrap_err();
        assert_eq!(e.message(), "--steps `10deg.csv` must be DEG=FILE (the slope of that track output)");
        let e = steps("ten=a.csv").observations().unwrap_err();
        assert_eq!(e.message(), "--steps: slope `ten` is not a number (in ten=a.csv)");
        let e = steps("10=no-such-steps.csv").observations().unwrap_err();
        assert_eq!(e.field(), Some("steps"));
        assert!(e.message().contains("no-such-steps.csv"), "{}", e.message());
    }
}
