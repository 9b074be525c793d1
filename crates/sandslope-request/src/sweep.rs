//! [`SweepRequest`]: the model over a range of slopes.

use serde::{Deserialize, Serialize};

use sandslope::scenario::slope_range;
use sandslope::{Scenario, SignedSlope, SlopeEvaluation};

use crate::error::{RequestError, Result};
use crate::grammar::{parse_slope_list, SlopeSign};
use crate::params::Params;
use crate::scenario::ScenarioRequest;

/// The inputs of `sweep` (and `/api/sweep`): the slopes of `slope` in the one slope grammar of
/// every command (`DEG`, `DEG,DEG,...`, `MIN:MAX:N`, [`crate::grammar::parse_slope_list`]),
/// else `from, from + step, ..., <= to` (the older flags, kept as a shorthand).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepRequest {
    /// The slopes, degrees, as `risk --slope` and `phase --slope` take them (field `slope`):
    /// when given, `from`, `to` and `step` are not used.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slope: Option<String>,
    /// First slope, degrees (field `from`, default 0).
    pub from: f64,
    /// Last slope, degrees, included when the steps land on it (field `to`, default 30).
    pub to: f64,
    /// Slope increment, degrees (field `step`, default 1).
    pub step: f64,
    /// Robot, terrain and overrides.
    pub scenario: ScenarioRequest,
}

impl SweepRequest {
    /// Most slopes a sweep evaluates (a guard against `step = 1e-9`).
    pub const MAX_SLOPES: usize = 100_000;

    /// Reads `slope` (or `from`, `to`, `step`) and the scenario's fields; refuses any other key.
    pub fn from_params(params: &[(String, String)]) -> Result<SweepRequest> {
        let mut p = Params::new("sweep", params);
        let slope = p.text("slope")?.map(str::to_string);
        let from = p.number_or("from", 0.0)?;
        let to = p.number_or("to", 30.0)?;
        let step = p.number_or("step", 1.0)?;
        let scenario = ScenarioRequest::from_params(&mut p)?;
        p.finish()?;
        Ok(SweepRequest { slope, from, to, step, scenario })
    }

    /// The slopes of `slope`, else of the range, at most [`SweepRequest::MAX_SLOPES`]; errors
    /// name `slope`, `from`, `to` or `step`.
    pub fn slopes(&self) -> Result<Vec<f64>> {
        if let Some(text) = &self.slope {
            return parse_slope_list("slope", text, SlopeSign::Signed, Self::MAX_SLOPES);
        }
        slope_range(self.from, self.to, self.step, Self::MAX_SLOPES).map_err(|e| {
            let field = e.key.clone();
            let flag = format!("--{field}");
            RequestError::invalid(field, e.renamed(flag))
        })
    }

    /// The answer (what `sweep --json` prints): the library's evaluation at every slope.
    pub fn answer(&self) -> Result<Vec<SlopeEvaluation>> {
        let slopes = self.slopes()?;
        evaluate(&self.scenario.scenario()?, &slopes)
    }
}

/// The scenario at every slope, an error naming `from` (the range's own fields).
pub fn evaluate(scenario: &Scenario, slopes: &[f64]) -> Result<Vec<SlopeEvaluation>> {
    let slopes = slopes
        .iter()
        .map(|&d| SignedSlope::from_degrees(d))
        .collect::<std::result::Result<Vec<_>, _>>()
        .map_err(|e| RequestError::invalid("from", e.renamed("--from/--to")))?;
    Ok(scenario.sweep(&slopes))
}
