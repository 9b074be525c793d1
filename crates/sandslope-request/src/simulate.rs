//! [`SimulateRequest`]: the dynamic stride simulator (docs/model.md §15-§18) at one slope or
//! over several in parallel, beside the closed form's answer for the same inputs.

use serde::{Deserialize, Serialize};

use sandslope::simulate::{
    simulate, simulate_slopes, BodyPitch, RftScaling, SimSettings, SimSummary, SimulateError, Simulation,
};
use sandslope::{ParamError, Scenario};

use crate::error::{check_range, RequestError, Result};
use crate::grammar::{parse_slope_list, SlopeSign};
use crate::params::Params;
use crate::scenario::ScenarioRequest;

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
    /// Time step, s (field `dt`; default T / 2000, docs/model.md §17).
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
    /// Trajectory sample rate, Hz (field `rate`, default 120).
    pub rate_hz: f64,
}

/// Parses the field `slopes`: the one slope-list grammar, signed, at most [`MAX_SLOPES`].
pub fn parse_slopes(text: &str) -> Result<Vec<f64>> {
    parse_slope_list("slopes", text, SlopeSign::Signed, MAX_SLOPES)
}

/// A library error with its keys renamed to the request's fields.
fn flagged(e: ParamError) -> RequestError {
    let field = match e.key.as_str() {
        "duration_s" => "duration",
        "dt_s" => "dt",
        "slope_deg" => "slope",
        "creep_m_s" => "creep",
        "sample_rate_hz" => "rate",
        "step" | "from" => "slopes",
        _ => return RequestError::from_error(None, anyhow::anyhow!("{e}")),
    };
    let flag = format!("--{field}");
    RequestError::invalid(field, e.renamed(flag))
}

fn sim_err(e: SimulateError) -> RequestError {
    match e {
        SimulateError::Param(p) => flagged(p),
    }
}

impl SimulateRequest {
    /// Reads the fields of a simulate request; refuses any other key.
    pub fn from_params(params: &[(String, String)]) -> Result<SimulateRequest> {
        let mut p = Params::new("simulate", params);
        let slope = p.number("slope")?;
        let slopes = match (slope, p.text("slopes")?) {
            (Some(_), Some(_)) => {
                return Err(RequestError::invalid("slopes", "--slopes cannot be used with --slope: give one"))
            }
            (Some(deg), None) => SimSlopes::One(deg),
            (None, Some(text)) => SimSlopes::Many(parse_slopes(text)?),
            (None, None) => return Err(RequestError::invalid("slope", "--slope or --slopes is required")),
        };
        let duration_s = p.number_or("duration", 10.0)?;
        let dt_s = p.number("dt")?;
        let creep_m_s = p.number("creep")?;
        let servo_limit = !p.flag("no-servo-limit")?;
        let body_pitch = match p.text("body-pitch")? {
            None => BodyPitch::default(),
            Some("free") => BodyPitch::Free,
            Some("locked") => BodyPitch::Locked,
            Some(other) => {
                return Err(RequestError::invalid(
                    "body-pitch",
                    format!("--body-pitch = `{other}` must be free or locked"),
                ))
            }
        };
        let rft_scaling = match p.text("rft-scaling")? {
            None => RftScaling::default(),
            Some("motion") => RftScaling::Motion,
            Some("components") => RftScaling::Components,
            Some("li2013") => RftScaling::Li2013,
            Some(other) => {
                return Err(RequestError::invalid(
                    "rft-scaling",
                    format!("--rft-scaling = `{other}` must be motion, components or li2013"),
                ))
            }
        };
        let rate_hz = p.number_or("rate", 120.0)?;
        let scenario = ScenarioRequest::from_params(&mut p)?;
        p.finish()?;
        Ok(SimulateRequest {
            slopes,
            scenario,
            duration_s,
            dt_s,
            creep_m_s,
            servo_limit,
            body_pitch,
            rft_scaling,
            rate_hz,
        })
    }

    /// The settings the fields ask for, checked.
    pub fn settings(&self) -> Result<SimSettings> {
        let mut s = SimSettings::new(self.duration_s).map_err(flagged)?;
        if let Some(dt) = self.dt_s {
            s = s.with_dt(dt).map_err(flagged)?;
        }
        if let Some(c) = self.creep_m_s {
            s = s.with_creep(c).map_err(flagged)?;
        }
        s = s.with_servo_limit(self.servo_limit);
        s = s.with_body_pitch(self.body_pitch).with_rft_scaling(self.rft_scaling);
        s.with_sample_rate(self.rate_hz).map_err(flagged)
    }

    /// Reads the robot and terrain and checks every field: the walks to run.
    pub fn walks(&self) -> Result<Walks> {
        let settings = self.settings()?;
        let scenario = self.scenario.scenario()?;
        let (slopes, many) = match &self.slopes {
            SimSlopes::Many(slopes) => (slopes.clone(), true),
            SimSlopes::One(slope) => (vec![check_slope(*slope)?], false),
        };
        Ok(Walks { scenario, slopes, many, settings })
    }

    /// The answer (what `simulate --json` prints).
    pub fn answer(&self) -> Result<Answer> {
        let walks = self.walks()?;
        let sims = walks.simulate()?;
        Ok(walks.answer(sims))
    }
}

/// One walk's slope: strictly between -90 and 90 degrees.
pub fn check_slope(slope: f64) -> Result<f64> {
    check_range("slope", slope, -89.999_999, 89.999_999).map_err(|_| {
        RequestError::invalid(
            "slope",
            format!("--slope = {slope} must be strictly between -90 and 90 degrees"),
        )
    })
}

/// What `simulate --json` prints: one walk's summary, or one per slope.
#[derive(Debug, Serialize)]
#[serde(untagged)]
pub enum Answer {
    /// One slope.
    One(Box<SimSummary>),
    /// Several slopes.
    Many(Vec<SimSummary>),
}

/// The walks of a simulate request, checked: what a server weighs against its limits before
/// running them.
#[derive(Debug)]
pub struct Walks {
    /// The robot on its terrain.
    pub scenario: Scenario,
    /// The slopes, degrees.
    pub slopes: Vec<f64>,
    /// Whether they came from `slopes` (the answer is then a list, even of one).
    pub many: bool,
    /// The checked settings.
    pub settings: SimSettings,
}

impl Walks {
    /// Integration steps of all the walks, settling included (what they cost to run).
    pub fn integration_steps(&self) -> Result<f64> {
        let mut steps = 0.0;
        for &deg in &self.slopes {
            let slope = sandslope::Slope::from_signed_degrees(deg)
                .map_err(|e| RequestError::invalid("slope", e.renamed("--slope")))?;
            let dt = sandslope::simulate::integration_step(&self.scenario, slope, self.settings.dt_s)
                .map_err(flagged)?;
            steps += (self.settings.duration_s + self.settings.settle_s) / dt;
        }
        Ok(steps)
    }

    /// Runs the walks (several in parallel).
    pub fn simulate(&self) -> Result<Vec<Simulation>> {
        if self.many {
            simulate_slopes(&self.scenario, &self.slopes, &self.settings).map_err(sim_err)
        } else {
            Ok(vec![simulate(&self.scenario, self.slopes[0], &self.settings).map_err(sim_err)?])
        }
    }

    /// The value `simulate --json` prints for these walks' results.
    pub fn answer(&self, sims: Vec<Simulation>) -> Answer {
        let mut summaries: Vec<SimSummary> = sims.into_iter().map(|s| s.summary).collect();
        match (self.many, summaries.pop()) {
            (false, Some(one)) if summaries.is_empty() => Answer::One(Box::new(one)),
            (_, last) => {
                summaries.extend(last);
                Answer::Many(summaries)
            }
        }
    }
}
