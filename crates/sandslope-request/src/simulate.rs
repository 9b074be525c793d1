//! [`SimulateRequest`]: the dynamic stride simulator (docs/model.md §15-§18) at one slope or
//! over several in parallel, beside the closed form's answer for the same inputs.

use serde::{Deserialize, Serialize};

use sandslope::simulate::convergence::{CREEP_REFINEMENT, STEP_REFINEMENT};
use sandslope::simulate::{
    check_convergence, check_convergence_slopes, integration_step_for, simulate, simulate_ensemble,
    simulate_slopes, BodyPitch, ConvergenceCheck, Ensemble, Mechanisms, RftScaling, SimSettings,
    SimulateError, Simulation, CREEP_RANGE_M_S, SCALINGS,
};
use sandslope::{ParamError, Scenario, SignedSlope};

use crate::error::{check_range, RequestError, Result, Words};
use crate::field::{Field, Fields, Kind, Table};
use crate::grammar::{parse_slope_list, SlopeSign};
use crate::params::Params;
use crate::scenario::ScenarioRequest;
pub use crate::simulate_spread::{ScalingWalk, SimAnswer, SpreadAnswer};

/// `--slope`: one walk's slope.
pub const SLOPE: Field = Field::number("slope", "DEG")
    .keyword("slope_deg")
    .key("slope_deg")
    .unit("deg")
    .range("strictly between -90 and 90")
    .help("Slope, degrees (negative: walking downhill)");
/// `--slopes`: walks in parallel.
pub const SLOPES: Field = Field::text("slopes", "MIN:MAX:N").unit("deg").conflicts(&["slope"]).help(
    "Slopes, degrees, simulated in parallel (instead of --slope): DEG,DEG,... or MIN:MAX:N \
     (N evenly spaced, ends included), as risk --slope takes them.",
);
/// `--duration`: simulated time after settling.
pub const DURATION: Field = Field::number("duration", "S")
    .keyword("duration_s")
    .key("duration_s")
    .unit("s")
    .default("10")
    .range("at least 1.5 T")
    .help(
        "Simulated time after settling, s (at least 1.5 T: one stride to settle into the gait, \
         then steps to measure).",
    );
/// `--dt`: the time step.
pub const DT: Field =
    Field::number("dt", "S").keyword("dt_s").key("dt_s").unit("s").range("at most T / 100").help(
        "Time step, s (default: T / 2000 with the body's pitch locked, 0.5 ms for the paper's \
         robot; T / 16000 with it free, 62.5 us; at most T / 100; docs/model.md §17).",
    );
/// `--creep`: the contact law's creep speed.
pub const CREEP: Field = Field::number("creep", "M/S")
    .keyword("creep_m_s")
    .key("creep_m_s")
    .unit("m/s")
    .range("1e-9 to 1e-3")
    .help(
        "Creep speed of the contact law's smoothing at rest, m/s (default 1e-7; 1e-9 to 1e-3; \
         docs/model.md §17): a numerical setting, which moves no converged answer.",
    );
/// `--no-servo-limit` (Python: `servo_limit=False`).
pub const NO_SERVO_LIMIT: Field = Field::switch("no-servo-limit").keyword("servo_limit").help(
    "Drive the legs as ideal position servos even where the robot file gives a servo torque \
     limit (by default the limit applies, docs/model.md §15).",
);
/// `--body-pitch`.
pub const BODY_PITCH: Field = Field::new("body-pitch", Kind::Choice(&["free", "locked"]), "MODE")
    .keyword("body_pitch")
    .default("locked")
    .help(
        "Whether the body may pitch: `locked` (the default) holds it parallel to the slope, the \
         closed form's assumption and the setting whose answers converge; `free` lets it pitch, \
         rear and tumble, chaotic on slopes: one walk is one draw of a spread (docs/simulate.md).",
    );
/// `--rft-scaling`.
pub const RFT_SCALING: Field =
    Field::new("rft-scaling", Kind::Choice(&["motion", "components", "li2013"]), "MODE")
        .keyword("rft_scaling")
        .default("motion")
        .help(
            "How resistive force theory is scaled to the terrain's k_n and k_s: `motion` (one \
             scale that follows the direction of motion), `components` (normal stress by k_n, \
             shear stress by k_s) or `li2013` (Li, Zhang and Goldman 2013: one factor from k_n, \
             k_s unused), docs/model.md §16.",
        );
/// `--leg-friction` (docs/model.md §20.1).
pub const LEG_FRICTION: Field =
    Field::number("leg-friction", "MU").keyword("leg_friction").key("leg_friction").range("0 to 10").help(
        "Leg-sand friction coefficient (0 to 10): the stress along a leg element's surface at \
         most MU times the stress normal to it (docs/model.md §20.1; default: none, resistive \
         force theory's stresses as they are).",
    );
/// `--duty-cycle` (docs/model.md §20.2).
pub const DUTY_CYCLE: Field = Field::number("duty-cycle", "D")
    .keyword("duty_cycle")
    .key("duty_cycle")
    .default("0.5")
    .range("0.1 to 0.9")
    .help(
        "Share of the stride period over which a leg turns the half turn from its touchdown, \
         0.1 to 0.9 (docs/model.md §20.2; 0.5: one speed all round, the paper's gait).",
    );
/// `--disturbed-sand` (docs/model.md §20.3).
pub const DISTURBED_SAND: Field = Field::number("disturbed-sand", "F")
    .keyword("disturbed_sand")
    .key("disturbed_sand")
    .default("1")
    .range("greater than 0, at most 1")
    .help(
        "Resistance of sand a leg passed through in an earlier stance, as a share of the \
         undisturbed sand's, greater than 0 and at most 1 (docs/model.md §20.3, the trench; \
         1: as strong as before).",
    );
/// `--one-sided-belly` (docs/model.md §20.5): the default, kept as a flag for scripts that name it.
pub const ONE_SIDED_BELLY: Field =
    Field::switch("one-sided-belly").keyword("one_sided_belly").conflicts(&["two-faced-belly"]).help(
        "The belly as the body's underside, sand below it only: it pushes and never pulls the \
         body down, its drag capped by its push (docs/model.md §20.5). The default; the flag is \
         kept so scripts that name it still run.",
    );
/// `--two-faced-belly` (docs/model.md §20.5).
pub const TWO_FACED_BELLY: Field = Field::switch("two-faced-belly").keyword("two_faced_belly").help(
    "The belly as a plate in sand on both faces, as resistive force theory's plates are: the \
     sand may pull it down, and the body rests at touchdown with no backward slip \
     (docs/simulate.md, \"The default belly\").",
);
/// `--actuator` (docs/model.md §20.6).
pub const ACTUATOR: Field = Field::new("actuator", Kind::Choice(&["ideal", "servo"]), "ideal|servo")
    .keyword("actuator")
    .default("ideal")
    .help(
        "What turns the legs: `ideal` (position sources that follow the gait whatever the sand \
         resists, the default) or `servo` (the XL330-M288's motor, its torque-speed line and \
         current limit, the leg rates solved with the body's; docs/model.md §20.6).",
    );
/// `--ensemble` (Python: `walks`).
pub const ENSEMBLE: Field = Field::number("ensemble", "N")
    .keyword("walks")
    .key("ensemble")
    .range("a whole number from 2 to 1000")
    .conflicts(&["slopes"])
    .help(
        "Walk the one slope N times (2 to 1000), the robot's mass perturbed by 1e-9 relative \
         between walks, and give the spread: mean speed, its SD and standard error, mean t1, the \
         regimes' counts, how many pitched over. For the free body, whose walk on a slope is \
         chaotic, the spread is the answer (docs/simulate.md, \"Pitch free\").",
    );
/// `--check-convergence` (Python: `sandslope.check_convergence`).
pub const CHECK_CONVERGENCE: Field = Field::switch("check-convergence").help(
    "Walk the slope (or each of --slopes) again at a quarter of the time step and at a tenth \
     of the creep speed, and say whether the answer is converged: speed, and the spread of the \
     steps' speeds, within 3% (or 0.3 cm/s), t1 within 1 ms and the same regime \
     (docs/simulate.md, \"Checking convergence\"). The default step is shown converged for the \
     built-in robot and terrain only; check your own. With --ensemble N each setting is N \
     walks, their means compared (a single free-pitch walk on a slope is chaotic and cannot \
     converge).",
);
/// `--scaling-spread` (Python: `scaling_spread=True/False`): the contact scaling as model
/// uncertainty (docs/model.md §20, item 7; docs/simulate.md, "The scaling as model uncertainty").
pub const SCALING_SPREAD: Field = Field::new("scaling-spread", Kind::Choice(&["on", "off"]), "on|off")
    .keyword("scaling_spread")
    .conflicts(&["ensemble", "check-convergence"])
    .help(
        "Walk each slope under all three contact scalings (motion, li2013, components; \
         docs/model.md §16), none of which the sand is measured to follow, and give beside the \
         answer the range of their speeds and whether their regimes agree (docs/simulate.md, \
         \"The scaling as model uncertainty\"): a steep slope's verdict hangs on it. Three walks \
         instead of one (the other two in parallel). Default: on with --slope, off with \
         --slopes.",
    );
/// `--rate` (Python: `sample_rate_hz`).
pub const RATE: Field = Field::number("rate", "HZ")
    .keyword("sample_rate_hz")
    .key("sample_rate_hz")
    .unit("Hz")
    .default("120")
    .range("greater than 0")
    .help("Trajectory sample rate for --out, --plot and --animate, Hz");

/// The fields of a walk's settings, named once, between `simulate`'s own fields before them
/// and after them (so [`FIELDS`] keeps its order in `--help` and [`SETTINGS`] is the same rows).
macro_rules! with_walk_settings {
    ([$($before:ident),*], [$($after:ident),*]) => {
        &[
            $($before,)*
            DURATION,
            DT,
            CREEP,
            NO_SERVO_LIMIT,
            BODY_PITCH,
            RFT_SCALING,
            LEG_FRICTION,
            DUTY_CYCLE,
            DISTURBED_SAND,
            ONE_SIDED_BELLY,
            TWO_FACED_BELLY,
            ACTUATOR,
            $($after,)*
            RATE,
        ]
    };
}

/// `simulate`'s own fields (the robot's and terrain's are [`crate::scenario::FIELDS`]).
pub const FIELDS: Table = Table {
    command: "simulate",
    fields: with_walk_settings!([SLOPE, SLOPES], [ENSEMBLE, CHECK_CONVERGENCE, SCALING_SPREAD]),
};

/// A walk's settings' fields (what [`SettingsRequest::read`] reads): every front end's, Python's
/// three simulate functions' keywords among them.
pub const SETTINGS: Table = Table { command: "simulate", fields: with_walk_settings!([], []) };

impl Fields for SimulateRequest {
    const TABLE: Table = FIELDS;
}

/// Most slopes one request simulates (the library's limit on the command line).
pub const MAX_SLOPES: usize = 1000;

/// The slopes of a simulate request.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SimSlopes {
    /// One walk (field `slope`), answered by one summary.
    One(f64),
    /// Walks in parallel (field `slopes`: `DEG,DEG,...` or `MIN:MAX:N`), answered by a list.
    Many(Vec<f64>),
}

/// The inputs of `simulate` (and `/api/simulate`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SimulateRequest {
    /// The slopes, degrees (negative: downhill).
    pub slopes: SimSlopes,
    /// Robot, terrain and overrides.
    pub scenario: ScenarioRequest,
    /// Simulated time after settling, s (field `duration`, default 10).
    pub duration_s: f64,
    /// Time step, s (field `dt`; default T / 2000 pitch locked, T / 16000 free; docs/model.md §17).
    pub dt_s: Option<f64>,
    /// Creep speed of the contact law's smoothing at rest, m/s (field `creep`; default 1e-7).
    pub creep_m_s: Option<f64>,
    /// Whether the robot file's servo torque limit applies (field `no-servo-limit`, a flag,
    /// turns it off; default on).
    pub servo_limit: bool,
    /// Whether the body may pitch (field `body-pitch`: free or locked; default the library's).
    pub body_pitch: BodyPitch,
    /// How resistive force theory is scaled to k_n and k_s (field `rft-scaling`: motion or
    /// components or li2013; default the library's).
    pub rft_scaling: RftScaling,
    /// The candidate mechanisms of docs/model.md §20 (fields `leg-friction`, `duty-cycle`,
    /// `disturbed-sand`; all off by default).
    pub mechanisms: Mechanisms,
    /// Trajectory sample rate, Hz (field `rate`, default 120).
    pub rate_hz: f64,
    /// Walk the one slope this many times, the mass perturbed by 1e-9 relative between walks,
    /// and answer the spread (field `ensemble`; docs/simulate.md, "Pitch free").
    pub ensemble: Option<usize>,
    /// Walk each slope again at a quarter of the step and at a tenth of the creep speed and
    /// answer whether the walk is converged (field `check-convergence`, a flag;
    /// docs/simulate.md, "Checking convergence").
    #[serde(default)]
    pub check_convergence: bool,
    /// Walk each slope under all three contact scalings and answer their spread beside the
    /// walk (field `scaling-spread`: on or off; default on for one slope, off for `slopes`).
    #[serde(default)]
    pub scaling_spread: Option<bool>,
}

/// Parses the field `slopes`: the one slope-list grammar, signed, at most [`MAX_SLOPES`].
pub fn parse_slopes(text: &str) -> Result<Vec<f64>> {
    parse_slope_list(SLOPES.flag, text, SlopeSign::Signed, MAX_SLOPES)
}

/// A library error with its key renamed to the request's field (by [`FIELDS`]; a slope
/// range's `step` and `from` are the field `slopes`).
fn flagged(e: ParamError) -> RequestError {
    let field = match e.key.as_str() {
        "step" | "from" => Some(&SLOPES),
        key => FIELDS.by_key(key),
    };
    match field {
        Some(f) => RequestError::invalid(f.flag, e.renamed(f.long())),
        None => RequestError::from_error(None, anyhow::anyhow!("{e}")),
    }
}

/// A library error with its key as Python's keyword (by [`FIELDS`]: the ensemble's size is
/// `walks` there).
fn keyworded(e: ParamError) -> RequestError {
    let field = FIELDS.by_key(&e.key).map_or_else(|| e.key.clone(), |f| f.keyword.to_string());
    RequestError::invalid(field.clone(), e.renamed(field))
}

pub(crate) fn sim_err(e: SimulateError, words: Words) -> RequestError {
    match (e, words) {
        (SimulateError::Param(p), Words::Flag) => flagged(p),
        (SimulateError::Param(p), Words::Keyword) => keyworded(p),
    }
}

impl SimulateRequest {
    /// Reads the fields of a simulate request, each by its row of [`FIELDS`]; refuses any
    /// other key.
    pub fn from_params(params: &[(String, String)]) -> Result<SimulateRequest> {
        Self::read(params, None)
    }

    /// The command line's request: its own fields from `params` (the flags given, by
    /// [`FIELDS`]), the scenario already read from the flags it shares with other commands.
    pub fn with_scenario(params: &[(String, String)], scenario: ScenarioRequest) -> Result<SimulateRequest> {
        Self::read(params, Some(scenario))
    }

    fn read(params: &[(String, String)], scenario: Option<ScenarioRequest>) -> Result<SimulateRequest> {
        let mut p = Params::new(FIELDS.command, params);
        let slope = SLOPE.number_in(&mut p)?;
        let slopes = match (slope, SLOPES.text_in(&mut p)?) {
            (Some(_), Some(_)) => {
                return Err(RequestError::invalid(
                    SLOPES.flag,
                    format!("{} cannot be used with {}: give one", SLOPES.long(), SLOPE.long()),
                ))
            }
            (Some(deg), None) => SimSlopes::One(deg),
            (None, Some(text)) => SimSlopes::Many(parse_slopes(text)?),
            (None, None) => {
                return Err(RequestError::invalid(
                    SLOPE.flag,
                    format!("{} or {} is required", SLOPE.long(), SLOPES.long()),
                ))
            }
        };
        let settings = SettingsRequest::read(&mut p, Words::Flag)?;
        let ensemble = ENSEMBLE.number_in(&mut p)?.map(|n| ensemble_size(n, &slopes)).transpose()?;
        let check_convergence = CHECK_CONVERGENCE.switch_in(&mut p)?;
        let scaling_spread = SCALING_SPREAD.choice_in(&mut p)?.map(|on| on == "on");
        if scaling_spread == Some(true) && (ensemble.is_some() || check_convergence) {
            return Err(RequestError::invalid(
                SCALING_SPREAD.flag,
                format!(
                    "{} on walks each slope once under each scaling: not with {} or {}",
                    SCALING_SPREAD.long(),
                    ENSEMBLE.long(),
                    CHECK_CONVERGENCE.long()
                ),
            ));
        }
        let scenario = match scenario {
            Some(s) => s,
            None => ScenarioRequest::from_params(&mut p)?,
        };
        p.finish()?;
        let SettingsRequest {
            duration_s,
            dt_s,
            creep_m_s,
            servo_limit,
            body_pitch,
            rft_scaling,
            mechanisms,
            rate_hz,
        } = settings;
        Ok(SimulateRequest {
            slopes,
            scenario,
            duration_s,
            dt_s,
            creep_m_s,
            servo_limit,
            body_pitch,
            rft_scaling,
            mechanisms,
            rate_hz,
            ensemble,
            check_convergence,
            scaling_spread,
        })
    }

    /// The settings the fields ask for, checked.
    pub fn settings(&self) -> Result<SimSettings> {
        self.settings_request().settings(Words::Flag)
    }

    /// The settings' fields alone.
    pub fn settings_request(&self) -> SettingsRequest {
        SettingsRequest {
            duration_s: self.duration_s,
            dt_s: self.dt_s,
            creep_m_s: self.creep_m_s,
            servo_limit: self.servo_limit,
            body_pitch: self.body_pitch,
            rft_scaling: self.rft_scaling,
            mechanisms: self.mechanisms,
            rate_hz: self.rate_hz,
        }
    }

    /// Reads the robot and terrain and checks every field: the walks to run.
    pub fn walks(&self) -> Result<Walks> {
        let settings = self.settings()?;
        let scenario = self.scenario.walk_scenario()?;
        let signed = |deg: f64, field: &'static str| {
            SignedSlope::from_degrees(deg)
                .map_err(|e| RequestError::invalid(field, e.renamed(format!("--{field}"))))
        };
        let (slopes, many) = match &self.slopes {
            SimSlopes::Many(slopes) => {
                (slopes.iter().map(|&d| signed(d, SLOPES.flag)).collect::<Result<Vec<_>>>()?, true)
            }
            SimSlopes::One(slope) => (vec![signed(check_slope(*slope)?, SLOPE.flag)?], false),
        };
        Ok(Walks {
            scenario,
            slopes,
            many,
            settings,
            ensemble: self.ensemble,
            check_convergence: self.check_convergence,
            scaling_spread: self.scaling_spread.unwrap_or(!many)
                && self.ensemble.is_none()
                && !self.check_convergence,
            words: Words::Flag,
        })
    }

    /// The answer (what `simulate --json` prints).
    pub fn answer(&self) -> Result<Answer> {
        self.walks()?.respond()
    }
}

/// A walk's settings as a request gives them: what `simulate`'s flags, the server's fields and
/// Python's keywords set, checked once into the library's [`SimSettings`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SettingsRequest {
    /// Simulated time after settling, s (field `duration`).
    pub duration_s: f64,
    /// Time step, s (field `dt`; default T / 2000 pitch locked, T / 16000 free).
    pub dt_s: Option<f64>,
    /// Creep speed of the contact law's smoothing at rest, m/s (field `creep`).
    pub creep_m_s: Option<f64>,
    /// Whether the robot file's servo torque limit applies.
    pub servo_limit: bool,
    /// Whether the body may pitch.
    pub body_pitch: BodyPitch,
    /// How resistive force theory is scaled to k_n and k_s.
    pub rft_scaling: RftScaling,
    /// The candidate mechanisms of docs/model.md §20.
    pub mechanisms: Mechanisms,
    /// Trajectory sample rate, Hz (field `rate`).
    pub rate_hz: f64,
}

impl SettingsRequest {
    /// Reads the settings' fields ([`SETTINGS`]) from `p`, each given or its default; a choice
    /// not among its words is refused naming the field in `words`.
    pub fn read(p: &mut Params<'_>, words: Words) -> Result<SettingsRequest> {
        let number = |f: &Field, p: &mut Params<'_>| f.required_number_in(p);
        let duration_s = number(&DURATION, p)?;
        let dt_s = DT.number_in(p)?;
        let creep_m_s = CREEP.number_in(p)?;
        let servo_limit = !NO_SERVO_LIMIT.switch_in(p)?;
        let body_pitch = parse_body_pitch(BODY_PITCH.text_in(p)?.unwrap_or_default(), words)?;
        let rft_scaling = parse_rft_scaling(RFT_SCALING.text_in(p)?.unwrap_or_default(), words)?;
        let (one_sided, two_faced) = (ONE_SIDED_BELLY.switch_in(p)?, TWO_FACED_BELLY.switch_in(p)?);
        if one_sided && two_faced {
            return Err(RequestError::invalid(
                TWO_FACED_BELLY.flag,
                format!(
                    "{} and {} name two bellies: give one (the one-sided belly is the default)",
                    words.name(ONE_SIDED_BELLY.flag),
                    words.name(TWO_FACED_BELLY.flag)
                ),
            ));
        }
        let mechanisms = Mechanisms {
            leg_friction: LEG_FRICTION.number_in(p)?,
            duty_cycle: number(&DUTY_CYCLE, p)?,
            disturbed_sand: number(&DISTURBED_SAND, p)?,
            one_sided_belly: !two_faced,
            servo_actuator: choose(
                ACTUATOR.flag,
                ACTUATOR.text_in(p)?.unwrap_or_default(),
                &[("ideal", false), ("servo", true)],
                words,
            )?,
        };
        let rate_hz = number(&RATE, p)?;
        Ok(SettingsRequest {
            duration_s,
            dt_s,
            creep_m_s,
            servo_limit,
            body_pitch,
            rft_scaling,
            mechanisms,
            rate_hz,
        })
    }

    /// The settings, checked; errors name the field in `words` (Python's keywords are the
    /// library's own keys: `duration_s`, `dt_s`, `creep_m_s`, `sample_rate_hz`).
    pub fn settings(&self, words: Words) -> Result<SimSettings> {
        let err = |e: ParamError| match words {
            Words::Flag => flagged(e),
            Words::Keyword => RequestError::invalid(e.key.clone(), e),
        };
        let mut s = SimSettings::new(self.duration_s).map_err(err)?;
        if let Some(dt) = self.dt_s {
            s = s.with_dt(dt).map_err(err)?;
        }
        if let Some(c) = self.creep_m_s {
            s = s.with_creep(c).map_err(err)?;
        }
        s = s.with_servo_limit(self.servo_limit);
        s = s.with_body_pitch(self.body_pitch).with_rft_scaling(self.rft_scaling);
        s = s.with_mechanisms(self.mechanisms).map_err(err)?;
        s.with_sample_rate(self.rate_hz).map_err(err)
    }
}

/// The value `text` names among `options`, or an error naming the field in `words` and the
/// names it takes.
fn choose<T: Copy>(field: &str, text: &str, options: &[(&str, T)], words: Words) -> Result<T> {
    if let Some(&(_, v)) = options.iter().find(|(name, _)| *name == text) {
        return Ok(v);
    }
    let names: Vec<&str> = options.iter().map(|(name, _)| *name).collect();
    let message = match words {
        Words::Flag => {
            let (last, rest) = names.split_last().unwrap_or((&"", &[]));
            let list =
                if rest.is_empty() { last.to_string() } else { format!("{} or {last}", rest.join(", ")) };
            format!("--{field} = `{text}` must be {list}")
        }
        Words::Keyword => {
            let quoted: Vec<String> = names.iter().map(|n| format!("{n:?}")).collect();
            format!("{} = {text:?}: expected {}", words.name(field), quoted.join(" or "))
        }
    };
    Err(RequestError::invalid(field, message))
}

/// Parses a body-pitch setting: `free` or `locked`.
pub fn parse_body_pitch(text: &str, words: Words) -> Result<BodyPitch> {
    choose(BODY_PITCH.flag, text, &[("free", BodyPitch::Free), ("locked", BodyPitch::Locked)], words)
}

/// Parses an RFT scaling: `motion`, `components` or `li2013`.
pub fn parse_rft_scaling(text: &str, words: Words) -> Result<RftScaling> {
    let options = [
        ("motion", RftScaling::Motion),
        ("components", RftScaling::Components),
        ("li2013", RftScaling::Li2013),
    ];
    choose(RFT_SCALING.flag, text, &options, words)
}

/// Checks an ensemble's size (a whole number from 2 to 1000) and that it has one slope.
pub fn ensemble_size(n: f64, slopes: &SimSlopes) -> Result<usize> {
    let (lo, hi) = sandslope::simulate::ensemble::ENSEMBLE_RANGE;
    if !(n.fract() == 0.0 && n >= lo as f64 && n <= hi as f64) {
        return Err(RequestError::invalid(
            ENSEMBLE.flag,
            format!("{} = {n} must be a whole number of walks from {lo} to {hi}", ENSEMBLE.long()),
        ));
    }
    if matches!(slopes, SimSlopes::Many(_)) {
        return Err(RequestError::invalid(
            ENSEMBLE.flag,
            format!("{} walks one slope: give {}, not {}", ENSEMBLE.long(), SLOPE.long(), SLOPES.long()),
        ));
    }
    Ok(n as usize)
}

/// One walk's slope: strictly between -90 and 90 degrees.
pub fn check_slope(slope: f64) -> Result<f64> {
    check_range(SLOPE.flag, slope, -89.999_999, 89.999_999).map_err(|_| {
        RequestError::invalid(
            SLOPE.flag,
            format!("{} = {slope} must be strictly between -90 and 90 degrees", SLOPE.long()),
        )
    })
}

/// What `simulate --json` prints: one walk's summary, or one per slope.
#[derive(Debug, Serialize)]
#[serde(untagged)]
pub enum Answer {
    /// One slope.
    One(Box<SimAnswer>),
    /// Several slopes.
    Many(Vec<SimAnswer>),
    /// An ensemble at one slope.
    Ensemble(Box<Ensemble>),
    /// The convergence check at one slope.
    Convergence(Box<ConvergenceCheck>),
    /// The convergence check at each of several slopes.
    Convergences(Vec<ConvergenceCheck>),
}

/// The walks of a simulate request, checked: what a server weighs against its limits before
/// running them.
#[derive(Debug)]
pub struct Walks {
    /// The robot on its terrain.
    pub scenario: Scenario,
    /// The slopes (negative: downhill).
    pub slopes: Vec<SignedSlope>,
    /// Whether they came from `slopes` (the answer is then a list, even of one).
    pub many: bool,
    /// The checked settings.
    pub settings: SimSettings,
    /// Walks in an ensemble at the one slope, if asked.
    pub ensemble: Option<usize>,
    /// Whether the walks (or the one slope's ensemble) are checked for convergence instead.
    pub check_convergence: bool,
    /// Whether each slope is walked under the other two contact scalings as well and their
    /// spread answered ([`Walks::spreads`]).
    pub scaling_spread: bool,
    /// How the library's errors name their field: the command line's flags and the server's
    /// fields, or Python's keywords.
    pub words: Words,
}

impl Walks {
    /// One slope's walk, or an ensemble of `ensemble` walks there, of a robot and terrain a
    /// front end built itself (Python's objects, whose settings [`SettingsRequest`] checked);
    /// the library's errors name Python's keywords (`dt_s`, `walks`).
    pub fn at(
        scenario: Scenario,
        slope: SignedSlope,
        settings: SimSettings,
        ensemble: Option<usize>,
    ) -> Walks {
        Walks {
            scenario,
            slopes: vec![slope],
            many: false,
            settings,
            ensemble,
            check_convergence: false,
            scaling_spread: false,
            words: Words::Keyword,
        }
    }

    /// Walks at each of `slopes` (answered as a list, even of one) of a robot and terrain a
    /// front end built itself, as [`Walks::at`]; errors name Python's keywords.
    pub fn at_slopes(scenario: Scenario, slopes: Vec<SignedSlope>, settings: SimSettings) -> Walks {
        Walks {
            scenario,
            slopes,
            many: true,
            settings,
            ensemble: None,
            check_convergence: false,
            scaling_spread: false,
            words: Words::Keyword,
        }
    }

    /// The same walks checked for convergence instead ([`Walks::respond`] then answers
    /// [`Answer::Convergence`]).
    pub fn checking_convergence(self) -> Walks {
        Walks { check_convergence: true, ..self }
    }

    /// Integration steps of all the walks, settling included (what they cost to run).
    pub fn integration_steps(&self) -> Result<f64> {
        let mut steps = 0.0;
        for signed in &self.slopes {
            let dt = integration_step_for(&self.scenario, signed.felt(), &self.settings)
                .map_err(|e| sim_err(SimulateError::Param(e), self.words))?;
            steps += (self.settings.duration_s + self.settings.settle_s) / dt;
        }
        // The check walks again at a quarter of the step and, where there is a tenth of the
        // creep to walk at, at the step itself.
        let checks = if self.check_convergence {
            let tenth = self.settings.creep_m_s / CREEP_REFINEMENT >= CREEP_RANGE_M_S.0;
            1.0 + STEP_REFINEMENT + if tenth { 1.0 } else { 0.0 }
        } else {
            1.0
        };
        let scalings = if self.scaling_spread { SCALINGS.len() as f64 } else { 1.0 };
        Ok(steps * checks * scalings * self.ensemble.unwrap_or(1) as f64)
    }

    /// Runs the walks (several in parallel).
    pub fn simulate(&self) -> Result<Vec<Simulation>> {
        if self.many {
            simulate_slopes(&self.scenario, &self.slopes, &self.settings).map_err(|e| sim_err(e, self.words))
        } else {
            let sim = simulate(&self.scenario, self.slopes[0], &self.settings)
                .map_err(|e| sim_err(e, self.words))?;
            Ok(vec![sim])
        }
    }

    /// Runs the walks, or the ensemble, and answers (what `simulate --json` prints).
    pub fn respond(&self) -> Result<Answer> {
        if self.check_convergence {
            return Ok(match (self.many, self.check_convergence()?) {
                (false, mut one) if one.len() == 1 => Answer::Convergence(Box::new(one.remove(0))),
                (_, checks) => Answer::Convergences(checks),
            });
        }
        match self.ensemble {
            Some(n) => Ok(Answer::Ensemble(Box::new(self.simulate_ensemble(n)?))),
            None => {
                let (sims, spreads) = self.simulate_with_spreads()?;
                Ok(self.answer(sims, spreads))
            }
        }
    }

    /// The ensemble of `n` walks at the one slope.
    pub fn simulate_ensemble(&self, n: usize) -> Result<Ensemble> {
        simulate_ensemble(&self.scenario, self.slopes[0], &self.settings, n)
            .map_err(|e| sim_err(e, self.words))
    }

    /// The convergence check of each slope's walk (or of the one slope's ensemble): the walk,
    /// at a quarter of its step and at a tenth of its creep speed, held to issue 38's
    /// tolerances; the slopes in parallel.
    pub fn check_convergence(&self) -> Result<Vec<ConvergenceCheck>> {
        let checks = if self.many {
            check_convergence_slopes(&self.scenario, &self.slopes, &self.settings)
        } else {
            check_convergence(&self.scenario, self.slopes[0], &self.settings, self.ensemble).map(|c| vec![c])
        };
        checks.map_err(|e| sim_err(e, self.words))
    }

    /// The value `simulate --json` prints for these walks' results and their spreads
    /// ([`Walks::spreads`]).
    pub fn answer(&self, sims: Vec<Simulation>, spreads: Vec<Option<SpreadAnswer>>) -> Answer {
        let mut summaries: Vec<SimAnswer> = sims
            .into_iter()
            .zip(spreads)
            .map(|(s, scaling_spread)| SimAnswer { summary: s.summary, scaling_spread })
            .collect();
        match (self.many, summaries.pop()) {
            (false, Some(one)) if summaries.is_empty() => Answer::One(Box::new(one)),
            (_, last) => {
                summaries.extend(last);
                Answer::Many(summaries)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(pairs: &[(&str, &str)]) -> Vec<(String, String)> {
        pairs.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()
    }

    /// `ensemble`: one slope, 2 to 1000 walks, and it multiplies what the walks cost (the
    /// server weighs that against its step limit; one walk without its scaling spread, which an
    /// ensemble does not walk).
    #[test]
    fn an_ensemble_walks_one_slope_and_costs_n_walks() {
        let one = SimulateRequest::from_params(&params(&[
            ("slope", "10"),
            ("duration", "2"),
            ("scaling-spread", "off"),
        ]))
        .unwrap();
        let three =
            SimulateRequest::from_params(&params(&[("slope", "10"), ("duration", "2"), ("ensemble", "3")]))
                .unwrap();
        assert_eq!(three.ensemble, Some(3));
        let (a, b) = (
            one.walks().unwrap().integration_steps().unwrap(),
            three.walks().unwrap().integration_steps().unwrap(),
        );
        assert!((b / a - 3.0).abs() < 1e-12, "{a} {b}");
        for (pairs, needle) in [
            (vec![("slopes", "0,10"), ("ensemble", "3")], "give --slope, not --slopes"),
            (
                vec![("slope", "10"), ("ensemble", "1")],
                "--ensemble = 1 must be a whole number of walks from 2 to 1000",
            ),
            (vec![("slope", "10"), ("ensemble", "2.5")], "--ensemble = 2.5"),
            (vec![("slope", "10"), ("ensemble", "1001")], "--ensemble = 1001"),
        ] {
            let e = SimulateRequest::from_params(&params(&pairs)).unwrap_err();
            assert!(e.message().contains(needle), "{pairs:?}: {}", e.message());
        }
    }

    /// The two setting names each front end spells its own way, from one list.
    #[test]
    fn settings_names_are_checked_once_in_each_front_ends_words() {
        assert_eq!(parse_body_pitch("free", Words::Keyword).unwrap(), BodyPitch::Free);
        assert_eq!(parse_rft_scaling("li2013", Words::Flag).unwrap(), RftScaling::Li2013);
        let e = parse_body_pitch("sideways", Words::Flag).unwrap_err();
        assert_eq!(e.field(), Some("body-pitch"));
        assert_eq!(e.message(), "--body-pitch = `sideways` must be free or locked");
        let e = parse_rft_scaling("shear", Words::Flag).unwrap_err();
        assert_eq!(e.message(), "--rft-scaling = `shear` must be motion, components or li2013");
        let e = parse_rft_scaling("shear", Words::Keyword).unwrap_err();
        assert_eq!(e.message(), r#"rft_scaling = "shear": expected "motion" or "components" or "li2013""#);
    }

    /// The table's defaults are the library's: what a request without the field walks with is
    /// what `SimSettings::new` and `Mechanisms::default` give.
    #[test]
    fn the_tables_defaults_are_the_librarys() {
        let none = params(&[]);
        let read = SettingsRequest::read(&mut Params::new("simulate", &none), Words::Flag).unwrap();
        let library = SimSettings::new(10.0).unwrap();
        assert_eq!(read.duration_s, 10.0);
        assert_eq!(read.rate_hz, library.sample_rate_hz);
        assert_eq!(read.rate_hz, sandslope::simulate::DEFAULT_SAMPLE_RATE_HZ);
        assert_eq!(read.mechanisms, Mechanisms::default());
        assert_eq!((read.body_pitch, read.rft_scaling), (BodyPitch::default(), RftScaling::default()));
        assert!(read.servo_limit);
        assert_eq!(read.settings(Words::Flag).unwrap(), library);
        // Every library key the settings' checks name is a field's, the fallback gone.
        for key in ["duration_s", "dt_s", "creep_m_s", "sample_rate_hz", "leg_friction", "duty_cycle"] {
            assert!(FIELDS.by_key(key).is_some(), "{key}");
        }
        let e = flagged(ParamError::new("sample_rate_hz", -1.0, "greater than 0"));
        assert_eq!(e.field(), Some("rate"));
        assert!(e.message().starts_with("--rate = -1"), "{}", e.message());
        assert_eq!(keyworded(ParamError::new("ensemble", 1.0, "2 to 1000")).field(), Some("walks"));
    }

    /// Python's keywords are the library's keys; the command line's are its flags.
    #[test]
    fn settings_errors_name_the_field_as_each_front_end_does() {
        let bad = SettingsRequest {
            duration_s: -1.0,
            dt_s: None,
            creep_m_s: None,
            servo_limit: true,
            body_pitch: BodyPitch::Locked,
            rft_scaling: RftScaling::Motion,
            mechanisms: Mechanisms::default(),
            rate_hz: 120.0,
        };
        let e = bad.settings(Words::Keyword).unwrap_err();
        assert_eq!(e.field(), Some("duration_s"));
        assert!(e.message().starts_with("duration_s = -1 must be"), "{}", e.message());
        let e = bad.settings(Words::Flag).unwrap_err();
        assert_eq!(e.field(), Some("duration"));
        assert!(e.message().starts_with("--duration = -1 must be"), "{}", e.message());
    }
}
