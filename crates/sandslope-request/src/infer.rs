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
use crate::field::{Field, Fields, Kind, Table};
use crate::grammar::{parse_slope_list, SlopeSign};
use crate::params::Params;
pub use crate::risk::{CV_N, CV_S};

/// `--observed`: the observed speeds.
pub const OBSERVED: Field = Field::text("observed", "FILE").help(
    "Observed speeds: CSV `slope_deg,speed_m_s,speed_sd_m_s[,n]` (as `track --speeds-out` writes; \
     with n, the mean's standard error is sd/sqrt(n)); or --steps, or --servo-log",
);
/// `--steps`: per-step outputs of `track --csv`, one per slope.
pub const STEPS: Field = Field::new("steps", Kind::List, "DEG=FILE").conflicts(&["observed"]).help(
    "Per-step output of `track --csv` at one slope, DEG=FILE (repeat for several slopes): speed \
     and anchoring time t1 of every step",
);
/// `--servo-log`: a drive's servo log.
pub const SERVO_LOG: Field = Field::text("servo-log", "FILE").conflicts(&["observed", "steps", "law"]).help(
    "A servo log of `sandslope drive --log` (docs/drive.md): k_s at its slope from the \
     stance-phase currents, with the leg's shear load and the risk of slippage (docs/model.md \
     §19)",
);
/// `--topic`: the bag's joint-state topic.
pub const TOPIC: Field = Field::text("topic", "TOPIC").help(
    "A ROS 2 bag's sensor_msgs/JointState topic for --servo-log (docs/bags.md); the bag's only \
     one when omitted",
);
/// `--joints`: the bag's joint names in leg order.
pub const JOINTS: Field = Field::new("joints", Kind::List, "NAME,...").help(
    "The bag's joint names in leg order (leg 0 first), comma-separated; the message's own order \
     when omitted (with --servo-log)",
);
/// `--effort-unit`: what the bag's efforts hold.
pub const EFFORT_UNIT: Field = Field::text("effort-unit", "n_m|a|ma").default("n_m").help(
    "What the bag's JointState effort holds: n_m (torque, the message's unit), a or ma (current, \
     turned into torque with the XL330's K_t, docs/model.md §19; with --servo-log)",
);
/// `--slope`: the servo log's slope.
pub const SLOPE: Field = Field::number("slope", "DEG")
    .keyword("slope_deg")
    .key("slope_deg")
    .unit("deg")
    .range("-90 to 90")
    .help("The slope of the --servo-log run, degrees (default: the log's `slope_deg` header)");
/// `--grid-points`: the servo-log inference's k_s grid (the library's
/// [`sandslope::infer::servo::SERVO_LOG_GRID_POINTS`] by default, a test checks).
pub const GRID_POINTS: Field = Field::new("grid-points", Kind::Whole, "N")
    .keyword("grid_points")
    .default("41")
    .range("3 to 1000")
    .help("k_s values the stride simulator walks for --servo-log (log-spaced over --k-s-prior)");
/// `--k-s-prior`: the prior's range of k_s (the library's
/// [`sandslope::infer::servo::SERVO_LOG_K_S_PRIOR`] by default, a test checks).
pub const K_S_PRIOR: Field = Field::text("k-s-prior", "MIN:MAX")
    .keyword("k_s_prior")
    .unit("N/m^3")
    .default("1e4:1e9")
    .range("0 < MIN < MAX")
    .help("Log-uniform prior range of k_s, N/m^3");
/// `--law`: the shear law tying the slopes together.
pub const LAW: Field = Field::new("law", Kind::Choice(&["linear", "coulomb"]), "LAW").help(
    "Tie the slopes together with a shear law and predict at --predict slopes: `linear`, \
     k_s(theta) = k_s0 + b theta_deg; `coulomb`, k_s(theta) = k_s0 (cos theta - sin theta / tan phi)",
);
/// `--predict`: the slopes the law predicts at.
pub const PREDICT: Field = Field::text("predict", "DEG|LIST|MIN:MAX:N")
    .unit("deg")
    .default("0:30:31")
    .range("0 to 90 each, at most 10,000")
    .help("Slopes to predict k_s and p_fail at with --law: DEG, a comma list or MIN:MAX:N");

/// `infer`'s own fields (the robot's and the terrain's are [`crate::scenario`]'s).
pub const FIELDS: Table = Table {
    command: "infer",
    fields: &[
        OBSERVED,
        STEPS,
        SERVO_LOG,
        TOPIC,
        JOINTS,
        EFFORT_UNIT,
        SLOPE,
        GRID_POINTS,
        CV_N,
        CV_S,
        K_S_PRIOR,
        LAW,
        PREDICT,
    ],
};

/// Most slopes `--predict` evaluates.
pub const MAX_PREDICT: usize = 10_000;

/// What `infer`'s fields ask: the posterior from the gait, or k_s from a servo log.
#[derive(Debug, Clone, PartialEq)]
pub enum InferQuestion {
    /// The gait's observations, with the CVs of the terrain's uncertainty given (used with a
    /// law, docs/model.md §9).
    Gait {
        /// The request.
        request: InferRequest,
        /// `--cv-n`.
        cv_n: Option<f64>,
        /// `--cv-s`.
        cv_s: Option<f64>,
    },
    /// A servo log (or a ROS 2 bag's joint states).
    ServoLog(ServoLogQuestion),
}

/// `infer --servo-log`: the log's request and how a bag's joint states are read.
#[derive(Debug, Clone, PartialEq)]
pub struct ServoLogQuestion {
    /// The log, its slope, prior and grid.
    pub request: ServoLogRequest,
    /// The bag's joint-state topic (`--topic`).
    pub topic: Option<String>,
    /// The bag's joint names in leg order (`--joints`), empty for the message's own order.
    pub joints: Vec<String>,
    /// What the bag's efforts hold (`--effort-unit`).
    pub effort: sandslope_io::bag_series::EffortUnit,
}

impl Fields for InferQuestion {
    const TABLE: Table = FIELDS;
}

/// `field`'s text when given (not its default), so that a field given without the one it
/// needs is refused.
fn given<'a>(p: &mut Params<'a>, field: &Field) -> Result<Option<&'a str>> {
    p.text(field.flag)
}

/// Refuses `field`, given, without `needed`.
fn needs(field: &Field, given: bool, needed: &Field, present: bool) -> Result<()> {
    if given && !present {
        return Err(RequestError::invalid(
            field.flag,
            format!("{} goes with {}: give {} too", field.long(), needed.long(), needed.long()),
        ));
    }
    Ok(())
}

impl InferQuestion {
    /// Reads the fields given, `params`, each by its row of [`FIELDS`] (the one raw-to-typed
    /// step): which question, its settings checked before any file is read; refuses any
    /// other key.
    pub fn from_fields(params: &[(String, String)]) -> Result<InferQuestion> {
        let mut p = Params::new(FIELDS.command, params);
        let observed = OBSERVED.text_in(&mut p)?;
        let steps = STEPS.text_in(&mut p)?;
        let servo_log = SERVO_LOG.text_in(&mut p)?;
        let topic = given(&mut p, &TOPIC)?;
        let joints = given(&mut p, &JOINTS)?;
        let effort = given(&mut p, &EFFORT_UNIT)?;
        let slope = SLOPE.number_in(&mut p)?;
        let grid_points = given(&mut p, &GRID_POINTS)?;
        let (cv_n, cv_s) = (CV_N.number_in(&mut p)?, CV_S.number_in(&mut p)?);
        let k_s_prior = parse_prior(K_S_PRIOR.text_in(&mut p)?.unwrap_or_default())?;
        let law =
            LAW.choice_in(&mut p)?.map(|l| if l == "coulomb" { InferLaw::Coulomb } else { InferLaw::Linear });
        let predict_given = given(&mut p, &PREDICT)?;
        p.finish()?;
        let conflict = |field: &Field, other: &Field| {
            Err(RequestError::invalid(
                field.flag,
                format!("{} cannot be used with {}", field.long(), other.long()),
            ))
        };
        match (observed, steps, servo_log, law) {
            (Some(_), Some(_), _, _) => return conflict(&STEPS, &OBSERVED),
            (Some(_), _, Some(_), _) => return conflict(&SERVO_LOG, &OBSERVED),
            (_, Some(_), Some(_), _) => return conflict(&SERVO_LOG, &STEPS),
            (_, _, Some(_), Some(_)) => return conflict(&SERVO_LOG, &LAW),
            _ => {}
        }
        let servo = servo_log.is_some();
        for (field, is_given) in [
            (&TOPIC, topic.is_some()),
            (&JOINTS, joints.is_some()),
            (&EFFORT_UNIT, effort.is_some()),
            (&SLOPE, slope.is_some()),
            (&GRID_POINTS, grid_points.is_some()),
        ] {
            needs(field, is_given, &SERVO_LOG, servo)?;
        }
        needs(&PREDICT, predict_given.is_some(), &LAW, law.is_some())?;
        if let Some(path) = servo_log {
            let effort_text = effort.or(EFFORT_UNIT.default).unwrap_or_default();
            let effort = effort_text.parse().map_err(|why| {
                RequestError::invalid(
                    EFFORT_UNIT.flag,
                    format!("{} = {effort_text}: {why}", EFFORT_UNIT.long()),
                )
            })?;
            let points_text = grid_points.or(GRID_POINTS.default).unwrap_or_default();
            let grid_points = points_text.trim().parse::<usize>().map_err(|_| {
                RequestError::invalid(
                    GRID_POINTS.flag,
                    format!("{} = `{points_text}` is not a whole number of at least 0", GRID_POINTS.long()),
                )
            })?;
            let request =
                ServoLogRequest { path: PathBuf::from(path), slope_deg: slope, k_s_prior, grid_points };
            prior(k_s_prior)?;
            servo_grid_points(Words::Flag, grid_points)?;
            let joints =
                joints.map_or_else(Vec::new, |j| j.split(',').map(|n| n.trim().to_string()).collect());
            let topic = topic.map(str::to_string);
            return Ok(InferQuestion::ServoLog(ServoLogQuestion { request, topic, joints, effort }));
        }
        let evidence = match (observed, steps) {
            (Some(path), _) => GaitEvidence::Observed(PathBuf::from(path)),
            (None, Some(steps)) => GaitEvidence::Steps(steps.split(',').map(str::to_string).collect()),
            (None, None) => {
                return Err(RequestError::invalid(
                    OBSERVED.flag,
                    format!(
                        "give the observations: {} FILE, {} DEG=FILE or {} FILE",
                        OBSERVED.long(),
                        STEPS.long(),
                        SERVO_LOG.long()
                    ),
                ))
            }
        };
        let request = InferRequest { evidence, k_s_prior, law, predict: Vec::new() };
        request.prior()?;
        let predict = match law {
            Some(_) => parse_slope_list(
                PREDICT.flag,
                predict_given.or(PREDICT.default).unwrap_or_default(),
                SlopeSign::Uphill,
                MAX_PREDICT,
            )?,
            None => Vec::new(),
        };
        let request = InferRequest { predict, ..request };
        request.check()?;
        Ok(InferQuestion::Gait { request, cv_n, cv_s })
    }
}

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
    let field = K_S_PRIOR.flag;
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
        RequestError::invalid(K_S_PRIOR.flag, message)
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
            GRID_POINTS.flag,
            format!("{} = {n} must be within 3 to {MAX_SERVO_GRID_POINTS}", words.name(GRID_POINTS.flag)),
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
                Slope::from_degrees(d)
                    .map_err(|e| RequestError::invalid(PREDICT.flag, e.renamed(PREDICT.long())))
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
                    .map_err(|e| RequestError::from_error(Some(OBSERVED.flag), e));
            }
            GaitEvidence::Steps(steps) => steps,
        };
        let field = STEPS.flag;
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
                    .map_err(|e| RequestError::invalid(LAW.flag, format!("{}: {e}", LAW.long())))?,
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
            .map_err(|e| RequestError::from_error(Some(SERVO_LOG.flag), e))?;
        self.read_log(log, robot, words)
    }

    /// As [`read`](Self::read), for a log already read (a ROS 2 bag's joint states,
    /// `sandslope_io::bag_series::read_joint_states`); `path` names it in errors.
    pub fn read_log(
        &self,
        log: sandslope_io::servo_log::ServoLog,
        robot: &Robot,
        words: Words,
    ) -> Result<ServoLogRun> {
        let prior = prior_in(words, self.k_s_prior)?;
        let grid_points = servo_grid_points(words, self.grid_points)?;
        let path = self.path.as_path();
        let file_error = |e: anyhow::Error| RequestError::from_error(Some(SERVO_LOG.flag), e);
        let slope_name = match words {
            Words::Flag => SLOPE.long(),
            Words::Keyword => SLOPE.keyword.to_string(),
        };
        let (slope_deg, from_header) =
            match (self.slope_deg, log.meta_f64("slope_deg", path).map_err(file_error)?) {
                (Some(s), _) => (s, false),
                (None, Some(s)) => (s, true),
                (None, None) => {
                    let give = match words {
                        Words::Flag => format!("give the run's slope with {slope_name}"),
                        Words::Keyword => format!("give {slope_name}"),
                    };
                    return Err(RequestError::invalid(
                        SLOPE.flag,
                        format!("{}: the log has no `# slope_deg = ...` header line; {give}", path.display()),
                    ));
                }
            };
        // A bad slope read from the header is the header's, not a flag the user did not give.
        let slope = SignedSlope::from_degrees(slope_deg).map_err(|e| {
            if from_header {
                let e = e.renamed(format!("{}: header line `# slope_deg`", path.display()));
                RequestError::invalid(SLOPE.flag, format!("{e}; give the run's slope with {slope_name}"))
            } else {
                RequestError::invalid(SLOPE.flag, e.renamed(slope_name.as_str()))
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

    fn pairs(list: &[(&str, &str)]) -> Vec<(String, String)> {
        list.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()
    }

    /// The table's defaults of the servo log's prior and grid are the library's, which
    /// Python's `infer_servo_log` takes for `None`.
    #[test]
    fn defaults_are_the_librarys() {
        use sandslope::infer::servo::{SERVO_LOG_GRID_POINTS, SERVO_LOG_K_S_PRIOR};
        assert_eq!(GRID_POINTS.default.map(|d| d.parse::<usize>().unwrap()), Some(SERVO_LOG_GRID_POINTS));
        assert_eq!(K_S_PRIOR.default.map(|d| parse_prior(d).unwrap()), Some(SERVO_LOG_K_S_PRIOR));
    }

    /// The fields pick the question: the gait's (the prior 1e4 to 1e9, predictions from 0 to
    /// 30 degrees by one with a law) or the servo log's (41 grid points, efforts in N m); a
    /// field given without the one it goes with, or against one it excludes, is named.
    #[test]
    fn fields_pick_the_question_and_are_checked_together() {
        let q = InferQuestion::from_fields(&pairs(&[("observed", "s.csv"), ("law", "linear")])).unwrap();
        let InferQuestion::Gait { request, cv_n: None, cv_s: None } = q else { panic!("{q:?}") };
        assert_eq!(request.evidence, GaitEvidence::Observed("s.csv".into()));
        assert_eq!((request.k_s_prior, request.law), ((1e4, 1e9), Some(InferLaw::Linear)));
        assert_eq!(request.predict, (0..=30).map(f64::from).collect::<Vec<_>>());
        let q = InferQuestion::from_fields(&pairs(&[("steps", "10=a.csv,20=b.csv")])).unwrap();
        let InferQuestion::Gait { request, .. } = q else { panic!("{q:?}") };
        assert_eq!(request.evidence, GaitEvidence::Steps(vec!["10=a.csv".into(), "20=b.csv".into()]));
        assert!(request.predict.is_empty());
        let q = InferQuestion::from_fields(&pairs(&[("servo-log", "run.csv"), ("joints", "a, b")])).unwrap();
        let InferQuestion::ServoLog(s) = q else { panic!("{q:?}") };
        assert_eq!((s.request.grid_points, s.request.slope_deg, s.joints.len()), (41, None, 2));
        assert_eq!(s.effort, sandslope_io::bag_series::EffortUnit::NewtonMetre);
        let err = |list: &[(&str, &str)]| InferQuestion::from_fields(&pairs(list)).unwrap_err().message();
        assert_eq!(
            err(&[("observed", "s.csv"), ("topic", "/j")]),
            "--topic goes with --servo-log: give --servo-log too"
        );
        assert_eq!(
            err(&[("observed", "s.csv"), ("predict", "10")]),
            "--predict goes with --law: give --law too"
        );
        assert_eq!(
            err(&[("servo-log", "r.csv"), ("law", "linear")]),
            "--servo-log cannot be used with --law"
        );
        assert!(err(&[]).starts_with("give the observations: --observed FILE"));
        assert!(err(&[("servo-log", "r.csv"), ("grid-points", "2")]).starts_with("--grid-points = 2"));
        assert!(err(&[("servo-log", "r.csv"), ("effort-unit", "volts")]).starts_with("--effort-unit = volts"));
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
