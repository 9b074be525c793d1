//! `calibrate`'s request: fit the unmeasured quantities (k_s(theta), and any robot key, a
//! plate-to-leg scale or a model-error floor) so that the model agrees with observed speeds,
//! anchoring times and force tests together (docs/calibration.md), by one library call
//! ([`sandslope::calibrate_jointly`], or [`sandslope::invert_each_speed`] for the per-slope
//! law). The front end loads the robot and the source terrain (with its overrides) and writes
//! the answer's terrain and robot files; every flag's check, default and the fit live here.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use serde::{Deserialize, Serialize};

use sandslope::calibrate::{PerSlopeCalibration, SpeedModel, SpeedObservation};
use sandslope::{
    calibrate_jointly, calibrate_jointly_cancellable, calibrate_jointly_with, invert_each_speed,
    FreeParameter, JointCalibration, JointSetup, Parameter, Robot, ShearLaw, ShearShape, Terrain,
    TerrainPoint, TerrainSpec,
};
use sandslope_io::{load_anchoring_times, load_speeds, load_terrain};

use crate::error::{check_positive_in, check_range_in, RequestError, Result, Words};
use crate::field::{Field, Fields, Kind, Table};
use crate::params::Params;
use crate::scenario::TERRAIN;

/// The words of `--law`, in [`CalibrateLaw::ALL`]'s order.
const LAW_WORDS: [&str; 3] = ["linear", "coulomb", "per-slope"];
/// The words of `--model`, in [`CalibrateModel::ALL`]'s order.
const MODEL_WORDS: [&str; 2] = ["closed-form", "simulate"];

/// `--observed`: the observed speeds.
pub const OBSERVED: Field = Field::text("observed", "CSV")
    .keyword("observed")
    .help("Observed speeds: CSV with columns slope_deg,speed_m_s,speed_sd_m_s");
/// `--forces`: the force tests giving k_s's shape.
pub const FORCES: Field = Field::text("forces", "FILE|PRESET").keyword("forces").help(
    "Force tests: a terrain file (as `sandslope fit` writes) whose k_s(theta) and k_s_sd give the \
     shape of k_s; its k_n is used too. Without it, k_s follows --law",
);
/// `--t1`: the observed anchoring times.
pub const T1: Field = Field::text("t1", "CSV")
    .keyword("t1")
    .help("Observed anchoring times: CSV with columns slope_deg,t1_s,t1_sd_s");
/// `--free`: the quantities fitted besides k_s.
pub const FREE: Field = Field::text("free", "LIST").keyword("free").help(
    "Quantities to fit besides k_s, comma-separated: any robot key (hip_height_m, level_step_m, \
     response_time_s, leg_contact_area_m2, ...), plate_scale (k_s_leg = c * k_s_plate, needs \
     --forces) and error_floor; each optionally with bounds, KEY=MIN:MAX",
);
/// `--error-floor`: a fixed model-error floor.
pub const ERROR_FLOOR: Field = Field::number("error-floor", "M/S")
    .keyword("error_floor")
    .unit("m/s")
    .range("0 to 1")
    .help("A fixed model-error floor added in quadrature to every observed speed SD, m/s");
/// `--law`: the form of k_s(theta) without force tests.
pub const LAW: Field = Field::new("law", Kind::Choice(&LAW_WORDS), "linear|coulomb|per-slope")
    .keyword("law")
    .default("linear")
    .help(
        "Form of k_s(theta) to fit when there are no --forces: linear (k_s0 * (1 + (rho - 1) * \
         theta_deg / 20)), coulomb (k_s0 * (cos theta - sin theta / tan phi)) or per-slope (one \
         k_s per observed slope, by root finding; speeds only)",
    );
/// `--model`: the model whose speeds are fitted.
pub const MODEL: Field = Field::new("model", Kind::Choice(&MODEL_WORDS), "closed-form|simulate")
    .keyword("model")
    .default("closed-form")
    .help(
        "The model whose speeds and anchoring times are fitted (docs/calibration.md): closed-form \
         (docs/model.md §3-§5) or simulate (the stride simulator, docs/model.md §15-§18: one \
         walk per observed slope and trial point, in parallel; minutes of CPU, the closed \
         form's fit printed beside it)",
    );
/// `--k-n`: the normal resistance at every slope.
pub const K_N: Field = Field::number("k-n", "N/M^3")
    .keyword("k_n")
    .unit("N/m^3")
    .range("greater than 0")
    .help("Normal resistance k_n, N/m^3, at every slope (default: the --forces' or --terrain's k_n)");
/// `--name`: the name written into the terrain.
pub const NAME: Field = Field::text("name", "NAME")
    .keyword("name")
    .help("Name written into the terrain file (default: `calibrated-<law>` or calibrated-forces)");
/// `--repose`: the angle of repose written into the terrain.
pub const REPOSE: Field = Field::number("repose", "DEG").keyword("repose").unit("deg").range("0 to 90").help(
    "Angle of repose written into the terrain file, degrees (default: carried over from the \
     --forces or --terrain file)",
);

/// `calibrate`'s own fields (the robot's and the source terrain's are [`crate::scenario`]'s).
pub const FIELDS: Table = Table {
    command: "calibrate",
    fields: &[OBSERVED, FORCES, T1, FREE, ERROR_FLOOR, LAW, MODEL, K_N, NAME, REPOSE],
};

impl Fields for CalibrateRequest {
    const TABLE: Table = FIELDS;
}

/// The form of k_s(theta) fitted when there are no force tests (field `law`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CalibrateLaw {
    /// k_s(theta) = k_s0 * (1 + (rho - 1) * theta_deg / 20), rho = k_s(20)/k_s(0).
    Linear,
    /// k_s(theta) = k_s0 * (cos theta - sin theta / tan phi), Mohr-Coulomb on an infinite slope.
    Coulomb,
    /// One k_s per observed slope, by root finding (speeds only).
    PerSlope,
}

impl CalibrateLaw {
    /// Every law, in the command line's order.
    pub const ALL: [CalibrateLaw; 3] = [CalibrateLaw::Linear, CalibrateLaw::Coulomb, CalibrateLaw::PerSlope];

    /// The law's name as the command line writes it.
    pub fn name(self) -> &'static str {
        LAW_WORDS[self as usize]
    }

    /// The law named `word`, if any.
    pub fn named(word: &str) -> Option<CalibrateLaw> {
        Self::ALL.into_iter().find(|l| l.name() == word)
    }
}

/// The model whose speeds and anchoring times are fitted (field `model`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CalibrateModel {
    /// The closed form (docs/model.md §3-§5).
    ClosedForm,
    /// The stride simulator (docs/model.md §15-§18), [`SpeedModel::simulator_for_fit`]; the
    /// closed form's fit of the same evidence is answered beside it.
    Simulate,
}

impl CalibrateModel {
    /// Every model, in the command line's order.
    pub const ALL: [CalibrateModel; 2] = [CalibrateModel::ClosedForm, CalibrateModel::Simulate];

    /// The model's name as the command line writes it.
    pub fn name(self) -> &'static str {
        MODEL_WORDS[self as usize]
    }

    /// The model named `word`, if any.
    pub fn named(word: &str) -> Option<CalibrateModel> {
        Self::ALL.into_iter().find(|m| m.name() == word)
    }
}

/// The inputs of `calibrate`, besides the robot and the source terrain (the front end loads
/// those with its overrides).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CalibrateRequest {
    /// Observed speeds: CSV `slope_deg,speed_m_s,speed_sd_m_s` (field `observed`).
    pub observed: Option<PathBuf>,
    /// Force tests: a terrain file or preset whose k_s(theta) gives k_s's shape (field `forces`).
    pub forces: Option<String>,
    /// Observed anchoring times: CSV `slope_deg,t1_s,t1_sd_s` (field `t1`).
    pub t1: Option<PathBuf>,
    /// Quantities to fit besides k_s, each `KEY` or `KEY=MIN:MAX` (field `free`).
    pub free: Vec<String>,
    /// A fixed model-error floor, m/s, `0..=1` (field `error-floor`).
    pub error_floor: Option<f64>,
    /// The law of k_s(theta) without force tests (field `law`).
    pub law: CalibrateLaw,
    /// The model fitted (field `model`).
    pub model: CalibrateModel,
    /// Normal resistance at every slope, N/m^3 (field `k-n`; default: the force tests' or the
    /// source terrain's).
    pub k_n: Option<f64>,
    /// Name written into the terrain (field `name`; default `calibrated-<law>` or
    /// `calibrated-forces`).
    pub name: Option<String>,
    /// Angle of repose written into the terrain, degrees, `0..=90` (field `repose`; default:
    /// carried over from the force tests or the source terrain).
    pub repose: Option<f64>,
}

/// The request's values, checked.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckedCalibrate {
    /// The quantities to fit besides k_s.
    pub free: Vec<FreeParameter>,
    /// The fixed k_n, if any.
    pub k_n: Option<f64>,
    /// The fixed error floor, if any.
    pub error_floor: Option<f64>,
}

impl CheckedCalibrate {
    /// Whether a robot key is fitted (so that a fitted robot differs from the one given).
    pub fn fits_robot(&self) -> bool {
        self.free.iter().any(|f| matches!(f.parameter, Parameter::Robot(_)))
    }
}

/// Where the angle of repose written into the terrain came from.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReposeRecord {
    /// The angle, degrees, or none.
    pub deg: Option<f64>,
    /// Where it came from, in the command line's words.
    pub source: String,
}

/// The answer of a joint fit, as `calibrate --json` prints it (the terrain, robot and speeds
/// are for the front end's files and figure).
#[derive(Debug, Clone, Serialize)]
pub struct JointAnswer {
    /// `"joint"`.
    pub mode: &'static str,
    /// The fit, with the terrain's name and angle of repose set.
    #[serde(flatten)]
    pub calibration: JointCalibration,
    /// Where the angle of repose came from.
    pub repose: ReposeRecord,
    /// With the simulator: the closed form's fit of the same evidence, for comparison.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub closed_form_fit: Option<JointCalibration>,
    /// The calibrated terrain, validated.
    #[serde(skip)]
    pub terrain: Terrain,
    /// The robot with its fitted keys, validated.
    #[serde(skip)]
    pub robot: Robot,
    /// The observed speeds fitted.
    #[serde(skip)]
    pub speeds: Vec<SpeedObservation>,
}

/// One observed speed inverted alone.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResidualRecord {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Normal resistance used, N/m^3.
    pub k_n: f64,
    /// The k_s that reproduces the speed, N/m^3.
    pub k_s: f64,
    /// Observed speed, m/s.
    pub observed_m_s: f64,
    /// Observed SD, m/s.
    pub observed_sd_m_s: f64,
    /// Model speed at that k_s, m/s.
    pub model_m_s: f64,
    /// `observed - model`, m/s.
    pub residual_m_s: f64,
}

/// The answer of `--law per-slope`, as `calibrate --json` prints it.
#[derive(Debug, Clone, Serialize)]
pub struct PerSlopeAnswer {
    /// `"per-slope"`.
    pub mode: &'static str,
    /// `"per-slope"`.
    pub law: &'static str,
    /// One row per observed speed, by slope.
    pub residuals: Vec<ResidualRecord>,
    /// Root-mean-square residual, m/s.
    pub rmse_m_s: f64,
    /// `sum ((observed - model) / sd)^2`.
    pub chi_squared: f64,
    /// The calibrated terrain (validated).
    pub terrain: TerrainSpec,
    /// Where the angle of repose came from.
    pub repose: ReposeRecord,
}

/// What `calibrate` answers.
#[derive(Debug, Clone)]
pub enum CalibrateAnswer {
    /// A joint fit (linear or Coulomb law, or force tests).
    Joint(Box<JointAnswer>),
    /// Each speed inverted alone.
    PerSlope(PerSlopeAnswer),
}

/// The robot and source terrain the front end loaded, and the source's name as the user gave
/// it (for the repose record's words).
#[derive(Debug, Clone, Copy)]
pub struct CalibrateSource<'a> {
    /// The robot, with its overrides.
    pub robot: &'a Robot,
    /// The source of k_n (without force tests or a fixed k_n) and of the angle of repose.
    pub terrain: &'a Terrain,
    /// The source terrain's file or preset name.
    pub terrain_name: &'a str,
}

/// Parses `free` items: `KEY` or `KEY=MIN:MAX`; errors name the field in `words`.
fn parse_free(items: &[String], words: Words) -> Result<Vec<FreeParameter>> {
    let bad = |m: String| RequestError::invalid(FREE.flag, m);
    let free = words.name(FREE.flag);
    let mut out = Vec::new();
    for item in items.iter().map(|s| s.trim()).filter(|s| !s.is_empty()) {
        let (key, bounds) = match item.split_once('=') {
            Some((k, b)) => {
                let (lo, hi) = b.split_once(':').ok_or_else(|| {
                    bad(format!(
                        "{free} {item}: bounds must be written MIN:MAX (e.g. hip_height_m=0.01:0.07)"
                    ))
                })?;
                let num = |s: &str| {
                    s.trim().parse::<f64>().map_err(|_| bad(format!("{free} {item}: `{s}` is not a number")))
                };
                (k.trim(), Some((num(lo)?, num(hi)?)))
            }
            None => (item, None),
        };
        let parameter = Parameter::parse(key).ok_or_else(|| {
            bad(format!("{free}: unknown quantity `{key}` (valid: {})", Parameter::names()))
        })?;
        out.push(FreeParameter { parameter, bounds });
    }
    Ok(out)
}

impl CalibrateRequest {
    /// The request of the flags given, `params` ([`FIELDS`]): the one raw-to-typed step of the
    /// command line. `--free`'s comma list is split into its items; refuses any other key.
    pub fn from_fields(params: &[(String, String)]) -> Result<CalibrateRequest> {
        let mut p = Params::new(FIELDS.command, params);
        let path = |text: Option<&str>| text.map(PathBuf::from);
        let observed = path(OBSERVED.text_in(&mut p)?);
        let forces = FORCES.text_in(&mut p)?.map(str::to_string);
        let t1 = path(T1.text_in(&mut p)?);
        let free =
            FREE.text_in(&mut p)?.map_or_else(Vec::new, |t| t.split(',').map(str::to_string).collect());
        let error_floor = ERROR_FLOOR.number_in(&mut p)?;
        // The choices' words are checked by `choice_in`, and their defaults are among them.
        let unnamed = |f: &Field| RequestError::invalid(f.flag, format!("{} names nothing", f.long()));
        let law = LAW.choice_in(&mut p)?.and_then(CalibrateLaw::named).ok_or_else(|| unnamed(&LAW))?;
        let model =
            MODEL.choice_in(&mut p)?.and_then(CalibrateModel::named).ok_or_else(|| unnamed(&MODEL))?;
        let k_n = K_N.number_in(&mut p)?;
        let name = NAME.text_in(&mut p)?.map(str::to_string);
        let repose = REPOSE.number_in(&mut p)?;
        p.finish()?;
        Ok(CalibrateRequest { observed, forces, t1, free, error_floor, law, model, k_n, name, repose })
    }

    /// Every value checked before any file is read; errors name the field as its flag.
    pub fn check(&self) -> Result<CheckedCalibrate> {
        self.check_in(Words::Flag)
    }

    /// [`CalibrateRequest::check`], errors naming the field in the front end's `words`.
    pub fn check_in(&self, words: Words) -> Result<CheckedCalibrate> {
        let law = |l: &str| words.setting(LAW.flag, l);
        if self.model == CalibrateModel::Simulate && self.law == CalibrateLaw::PerSlope {
            return Err(RequestError::invalid(
                LAW.flag,
                format!(
                    "{} inverts the closed form only: with {} use {}, {} or {}",
                    law(CalibrateLaw::PerSlope.name()),
                    words.setting(MODEL.flag, CalibrateModel::Simulate.name()),
                    law(CalibrateLaw::Linear.name()),
                    law(CalibrateLaw::Coulomb.name()),
                    words.name(FORCES.flag)
                ),
            ));
        }
        let free = parse_free(&self.free, words)?;
        let k_n = self.k_n.map(|v| check_positive_in(words, K_N.flag, v)).transpose()?;
        if let Some(r) = self.repose {
            check_range_in(words, REPOSE.flag, r, 0.0, 90.0)?;
        }
        let error_floor =
            self.error_floor.map(|v| check_range_in(words, ERROR_FLOOR.flag, v, 0.0, 1.0)).transpose()?;
        if error_floor.is_some() && free.iter().any(|f| f.parameter == Parameter::ErrorFloor) {
            return Err(RequestError::invalid(
                ERROR_FLOOR.flag,
                format!(
                    "{} fixes the floor and {} fits it: give one of them",
                    words.name(ERROR_FLOOR.flag),
                    words.setting(FREE.flag, "error_floor")
                ),
            ));
        }
        if self.law == CalibrateLaw::PerSlope && self.forces.is_none() {
            if !free.is_empty() || self.t1.is_some() || error_floor.is_some() {
                return Err(RequestError::invalid(
                    LAW.flag,
                    format!(
                        "{} inverts each speed alone: it takes no {}, {} or {}",
                        law(CalibrateLaw::PerSlope.name()),
                        words.name(FREE.flag),
                        words.name(T1.flag),
                        words.name(ERROR_FLOOR.flag)
                    ),
                ));
            }
            if self.observed.is_none() {
                return Err(RequestError::invalid(
                    OBSERVED.flag,
                    format!(
                        "{} needs {} speeds",
                        law(CalibrateLaw::PerSlope.name()),
                        words.name(OBSERVED.flag)
                    ),
                ));
            }
        }
        Ok(CheckedCalibrate { free, k_n, error_floor })
    }

    /// Reads the evidence and fits it. Errors name the file (and line) or the field, in the
    /// front end's `words`.
    pub fn answer(&self, source: CalibrateSource, words: Words) -> Result<CalibrateAnswer> {
        self.answer_cancellable(source, words, None)
    }

    /// [`CalibrateRequest::answer`] whose simulator fit stops when `cancel` is raised (a front
    /// end's Ctrl-C; `sandslope::calibrate_jointly_cancellable`): the error then says
    /// `interrupted`.
    pub fn answer_cancellable(
        &self,
        source: CalibrateSource,
        words: Words,
        cancel: Option<&AtomicBool>,
    ) -> Result<CalibrateAnswer> {
        let checked = self.check_in(words)?;
        let speeds = match &self.observed {
            Some(p) => load_speeds(p).map_err(|e| RequestError::from_error(Some(OBSERVED.flag), e))?,
            None => Vec::new(),
        };
        let anchoring = match &self.t1 {
            Some(p) => load_anchoring_times(p).map_err(|e| RequestError::from_error(Some(T1.flag), e))?,
            None => Vec::new(),
        };
        let forces = match &self.forces {
            Some(f) => Some(load_terrain(f).map_err(|e| RequestError::from_error(Some(FORCES.flag), e))?),
            None => None,
        };
        let repose = self.repose_record(source, forces.as_ref());
        // k_n: the fixed one, else the force tests', else the source terrain's.
        let normal = match (checked.k_n, &forces) {
            (Some(k), _) => Terrain::constant(k, 1.0)
                .map_err(|e| RequestError::invalid(K_N.flag, e.renamed(words.name(K_N.flag))))?,
            (None, Some(f)) => f.clone(),
            (None, None) => source.terrain.clone(),
        };
        let shear = match (&forces, self.law) {
            (Some(f), _) => ShearShape::ForceTests(f.clone()),
            (None, CalibrateLaw::Linear) => ShearShape::Law(ShearLaw::Linear),
            (None, CalibrateLaw::Coulomb) => ShearShape::Law(ShearLaw::Coulomb),
            (None, CalibrateLaw::PerSlope) => {
                return self.per_slope(source.robot, &speeds, &normal, repose).map(CalibrateAnswer::PerSlope);
            }
        };
        let setup = JointSetup {
            robot: source.robot.clone(),
            normal,
            shear,
            speeds,
            anchoring,
            free: checked.free,
            error_floor: checked.error_floor.unwrap_or(0.0),
        };
        let fail = |e: anyhow::Error| RequestError::from_error(None, e);
        let closed_form_fit =
            calibrate_jointly(&setup).map_err(|e| fail(anyhow::anyhow!("calibrate: {e}")))?;
        let (mut calibration, closed_form_fit) = match self.model {
            CalibrateModel::ClosedForm => (closed_form_fit, None),
            CalibrateModel::Simulate => {
                let model = SpeedModel::simulator_for_fit();
                let sim = match cancel {
                    Some(cancel) => calibrate_jointly_cancellable(&setup, model, cancel),
                    None => calibrate_jointly_with(&setup, model),
                }
                .map_err(|e| fail(anyhow::anyhow!("calibrate --model simulate: {e}")))?;
                (sim, Some(closed_form_fit))
            }
        };
        let default_name = if forces.is_some() {
            "calibrated-forces".to_string()
        } else {
            format!("calibrated-{}", self.law.name())
        };
        calibration.terrain.name = Some(self.name.clone().unwrap_or(default_name));
        calibration.terrain.repose_deg = repose.deg;
        let terrain = Terrain::new(calibration.terrain.clone()).map_err(|e| {
            fail(anyhow::anyhow!(
                "the calibrated terrain is not valid ({e}); a fitted k_s reached zero within the observed slopes: try {} or force tests",
                words.setting(LAW.flag, CalibrateLaw::Coulomb.name())
            ))
        })?;
        let robot = Robot::new(calibration.robot.clone())
            .map_err(|e| fail(anyhow::anyhow!("the fitted robot is not valid: {e}")))?;
        Ok(CalibrateAnswer::Joint(Box::new(JointAnswer {
            mode: "joint",
            calibration,
            repose,
            closed_form_fit,
            terrain,
            robot,
            speeds: setup.speeds,
        })))
    }

    /// The angle of repose: `repose`, else carried over from the force tests or the source
    /// terrain, with where it came from.
    fn repose_record(&self, source: CalibrateSource, forces: Option<&Terrain>) -> ReposeRecord {
        match (self.repose, forces) {
            (Some(r), _) => ReposeRecord { deg: Some(r), source: REPOSE.long() },
            (None, Some(f)) if f.spec().repose_deg.is_some() => ReposeRecord {
                deg: f.spec().repose_deg,
                source: format!(
                    "carried over from {} {}",
                    FORCES.long(),
                    self.forces.as_deref().unwrap_or("")
                ),
            },
            _ => {
                let deg = source.terrain.spec().repose_deg;
                let name = source.terrain_name;
                ReposeRecord {
                    deg,
                    source: match deg {
                        Some(_) => format!("carried over from {} {name}", TERRAIN.long()),
                        None => format!("none: {} {name} has no repose_deg", TERRAIN.long()),
                    },
                }
            }
        }
    }

    /// `--law per-slope`: each observed speed inverted alone.
    fn per_slope(
        &self,
        robot: &Robot,
        speeds: &[SpeedObservation],
        normal: &Terrain,
        repose: ReposeRecord,
    ) -> Result<PerSlopeAnswer> {
        let observed = self.observed.as_deref().unwrap_or_else(|| std::path::Path::new(""));
        let cal: PerSlopeCalibration = invert_each_speed(robot, normal, speeds).map_err(|e| {
            RequestError::from_error(Some(OBSERVED.flag), anyhow::anyhow!("{}: {e}", observed.display()))
        })?;
        let points = cal
            .points
            .iter()
            .map(|r| TerrainPoint {
                slope_deg: r.slope_deg,
                k_n: r.k_n,
                k_s: r.k_s,
                k_n_sd: None,
                k_s_sd: None,
            })
            .collect();
        let terrain = TerrainSpec {
            name: Some(self.name.clone().unwrap_or_else(|| "calibrated-per-slope".into())),
            repose_deg: repose.deg,
            points,
        };
        Terrain::new(terrain.clone()).map_err(|e| {
            RequestError::from_error(None, anyhow::anyhow!("the calibrated terrain is not valid ({e})"))
        })?;
        let residuals = cal
            .points
            .iter()
            .map(|r| ResidualRecord {
                slope_deg: r.slope_deg,
                k_n: r.k_n,
                k_s: r.k_s,
                observed_m_s: r.observed,
                observed_sd_m_s: r.observed_sd,
                model_m_s: r.model,
                residual_m_s: r.residual(),
            })
            .collect();
        Ok(PerSlopeAnswer {
            mode: "per-slope",
            law: "per-slope",
            residuals,
            rmse_m_s: cal.rmse(),
            chi_squared: cal.chi_squared(),
            terrain,
            repose,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sandslope::RobotKey;

    fn request() -> CalibrateRequest {
        CalibrateRequest {
            observed: Some(PathBuf::from("no-such-speeds.csv")),
            forces: None,
            t1: None,
            free: Vec::new(),
            error_floor: None,
            law: CalibrateLaw::Linear,
            model: CalibrateModel::ClosedForm,
            k_n: None,
            name: None,
            repose: None,
        }
    }

    /// `KEY` takes the library's default bounds, `KEY=MIN:MAX` its own; a robot key makes
    /// the fitted robot worth writing.
    #[test]
    fn free_items_parse_into_parameters_and_bounds() {
        let r = CalibrateRequest {
            free: vec![" hip_height_m=0.01:0.07".into(), "error_floor".into(), "".into()],
            ..request()
        };
        let c = r.check().unwrap();
        assert_eq!(c.free.len(), 2);
        assert_eq!(c.free[0].parameter, Parameter::Robot(RobotKey::HipHeightM));
        assert_eq!(c.free[0].bounds, Some((0.01, 0.07)));
        assert_eq!(c.free[1], FreeParameter { parameter: Parameter::ErrorFloor, bounds: None });
        assert!(c.fits_robot());
        assert!(!request().check().unwrap().fits_robot());
    }

    /// Each refusal names its field and the valid range, before any file is read (the
    /// observed file does not exist).
    #[test]
    fn checks_name_the_field_before_any_file_is_read() {
        let cases: [(CalibrateRequest, &str, &str); 8] = [
            (
                CalibrateRequest { free: vec!["nope".into()], ..request() },
                "free",
                "--free: unknown quantity `nope`",
            ),
            (
                CalibrateRequest { free: vec!["hip_height_m=1".into()], ..request() },
                "free",
                "--free hip_height_m=1: bounds must be written MIN:MAX",
            ),
            (
                CalibrateRequest { k_n: Some(0.0), ..request() },
                "k-n",
                "--k-n = 0 must be a finite number greater than 0",
            ),
            (
                CalibrateRequest { repose: Some(90.5), ..request() },
                "repose",
                "--repose = 90.5 must be between 0 and 90",
            ),
            (
                CalibrateRequest { error_floor: Some(-0.1), ..request() },
                "error-floor",
                "--error-floor = -0.1 must be between 0 and 1",
            ),
            (
                CalibrateRequest { error_floor: Some(0.1), free: vec!["error_floor".into()], ..request() },
                "error-floor",
                "--error-floor fixes the floor",
            ),
            (
                CalibrateRequest {
                    law: CalibrateLaw::PerSlope,
                    model: CalibrateModel::Simulate,
                    ..request()
                },
                "law",
                "--law per-slope inverts the closed form only",
            ),
            (
                CalibrateRequest { law: CalibrateLaw::PerSlope, t1: Some("t1.csv".into()), ..request() },
                "law",
                "--law per-slope inverts each speed alone",
            ),
        ];
        for (r, field, start) in cases {
            let e = r.check().unwrap_err();
            assert_eq!(e.field(), Some(field), "{}", e.message());
            assert!(e.message().starts_with(start), "{}", e.message());
        }
        let e = CalibrateRequest { law: CalibrateLaw::PerSlope, observed: None, ..request() }
            .check()
            .unwrap_err();
        assert_eq!(
            (e.field(), e.message().as_str()),
            (Some("observed"), "--law per-slope needs --observed speeds")
        );
        // With force tests, per-slope is not the law used, so it refuses nothing.
        let with_forces =
            CalibrateRequest { law: CalibrateLaw::PerSlope, forces: Some("f.toml".into()), ..request() };
        assert!(with_forces.check().is_ok());
    }

    /// Python's words: the same refusals, each naming the keyword (`k_n`, `law="per-slope"`)
    /// where the command line names the flag.
    #[test]
    fn checks_name_the_keyword_in_python_words() {
        let cases: [(CalibrateRequest, &str); 5] = [
            (CalibrateRequest { k_n: Some(-1.0), ..request() }, "k_n = -1 must be a finite number greater than 0"),
            (CalibrateRequest { repose: Some(91.0), ..request() }, "repose = 91 must be between 0 and 90"),
            (
                CalibrateRequest { error_floor: Some(0.1), free: vec!["error_floor".into()], ..request() },
                "error_floor fixes the floor and free=\"error_floor\" fits it: give one of them",
            ),
            (
                CalibrateRequest { law: CalibrateLaw::PerSlope, model: CalibrateModel::Simulate, ..request() },
                "law=\"per-slope\" inverts the closed form only: with model=\"simulate\" use law=\"linear\", law=\"coulomb\" or forces",
            ),
            (
                CalibrateRequest { free: vec!["hip_height_m=a:1".into()], ..request() },
                "free hip_height_m=a:1: `a` is not a number",
            ),
        ];
        for (r, message) in cases {
            assert_eq!(r.check_in(Words::Keyword).unwrap_err().message(), message);
        }
        // The names a front end matches keywords against are the command line's.
        let laws: Vec<&str> = CalibrateLaw::ALL.iter().map(|l| l.name()).collect();
        let models: Vec<&str> = CalibrateModel::ALL.iter().map(|m| m.name()).collect();
        assert_eq!((laws, models), (vec!["linear", "coulomb", "per-slope"], vec!["closed-form", "simulate"]));
    }

    /// The flags read by the table: none given is the linear law on the closed form; `--free`'s
    /// comma list is split; a word of no law is refused naming the flag and the words.
    #[test]
    fn flags_are_read_by_the_table() {
        let none = CalibrateRequest::from_fields(&[]).unwrap();
        assert_eq!(none, CalibrateRequest { observed: None, ..request() });
        let pairs = |list: &[(&str, &str)]| -> Vec<(String, String)> {
            list.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()
        };
        let given = pairs(&[
            ("observed", "s.csv"),
            ("free", "plate_scale,error_floor"),
            ("law", "coulomb"),
            ("model", "simulate"),
            ("k-n", "2e6"),
            ("repose", "25"),
        ]);
        let r = CalibrateRequest::from_fields(&given).unwrap();
        assert_eq!(r.free, vec!["plate_scale".to_string(), "error_floor".to_string()]);
        assert_eq!(
            (r.law, r.model, r.k_n, r.repose),
            (CalibrateLaw::Coulomb, CalibrateModel::Simulate, Some(2e6), Some(25.0))
        );
        assert_eq!(r.observed, Some(PathBuf::from("s.csv")));
        let e = CalibrateRequest::from_fields(&pairs(&[("law", "cubic")])).unwrap_err();
        assert_eq!(
            (e.field(), e.message().as_str()),
            (Some("law"), "--law = `cubic` must be one of: linear, coulomb, per-slope")
        );
    }

    /// A missing evidence file is reported against its field.
    #[test]
    fn a_missing_evidence_file_names_its_field() {
        let robot = Robot::new(sandslope::RobotSpec::paper_hexapod()).unwrap();
        let terrain = Terrain::constant(1e6, 1e6).unwrap();
        let source = CalibrateSource { robot: &robot, terrain: &terrain, terrain_name: "t" };
        let e = request().answer(source, Words::Flag).unwrap_err();
        assert_eq!(e.field(), Some("observed"));
        assert!(e.message().contains("no-such-speeds.csv"), "{}", e.message());
    }
}
