//! [`SweepRequest`]: the model over a range of slopes.

use serde::{Deserialize, Serialize};

use sandslope::scenario::slope_range;
use sandslope::{Scenario, SignedSlope, SlopeEvaluation};

use crate::error::{RequestError, Result};
use crate::field::{Field, Fields, Table};
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

/// `--slope`: the slopes in the one slope grammar.
pub const SLOPE: Field =
    Field::text("slope", "DEG|LIST|MIN:MAX:N").unit("deg").conflicts(&["from", "to", "step"]).help(
        "Slope(s), degrees, in the one slope grammar of every command (as `risk --slope` and \
         `phase --slope`): one value, a comma list (0,10,20) or MIN:MAX:N, N slopes evenly spaced \
         with both ends included (0:30:31 is every degree). Without it, --from/--to/--step.",
    );
/// `--from`: the first slope of the shorthand range.
pub const FROM: Field = Field::number("from", "DEG")
    .key("from")
    .unit("deg")
    .default("0")
    .range("not above --to")
    .help("First slope, degrees (the older shorthand for --slope FROM:TO:N)");
/// `--to`: the last slope of the shorthand range.
pub const TO: Field = Field::number("to", "DEG")
    .unit("deg")
    .default("30")
    .help("Last slope, degrees, included when the steps land on it (shorthand, see --slope)");
/// `--step`: the increment of the shorthand range.
pub const STEP: Field = Field::number("step", "DEG")
    .key("step")
    .unit("deg")
    .default("1")
    .range("greater than 0")
    .help("Slope increment, degrees (shorthand, see --slope)");

/// `sweep`'s own fields (the robot's and terrain's are [`crate::scenario::FIELDS`]).
pub const FIELDS: Table = Table { command: "sweep", fields: &[SLOPE, FROM, TO, STEP] };

impl Fields for SweepRequest {
    const TABLE: Table = FIELDS;
}

impl SweepRequest {
    /// Most slopes a sweep evaluates (a guard against `step = 1e-9`).
    pub const MAX_SLOPES: usize = 100_000;

    /// Reads `slope` (or `from`, `to`, `step`) and the scenario's fields, each by its row of
    /// [`FIELDS`]; refuses any other key.
    pub fn from_params(params: &[(String, String)]) -> Result<SweepRequest> {
        Self::read(params, None)
    }

    /// The command line's request: its own fields from `params` (the flags given, by
    /// [`FIELDS`]), the scenario already read from the flags it shares with other commands.
    pub fn with_scenario(params: &[(String, String)], scenario: ScenarioRequest) -> Result<SweepRequest> {
        Self::read(params, Some(scenario))
    }

    fn read(params: &[(String, String)], scenario: Option<ScenarioRequest>) -> Result<SweepRequest> {
        let mut p = Params::new(FIELDS.command, params);
        let slope = SLOPE.text_in(&mut p)?.map(str::to_string);
        let from = FROM.required_number_in(&mut p)?;
        let to = TO.required_number_in(&mut p)?;
        let step = STEP.required_number_in(&mut p)?;
        let scenario = match scenario {
            Some(s) => s,
            None => ScenarioRequest::from_params(&mut p)?,
        };
        p.finish()?;
        Ok(SweepRequest { slope, from, to, step, scenario })
    }

    /// The slopes of `slope`, else of the range, at most [`SweepRequest::MAX_SLOPES`]; errors
    /// name `slope`, `from`, `to` or `step`.
    pub fn slopes(&self) -> Result<Vec<f64>> {
        if let Some(text) = &self.slope {
            return parse_slope_list(SLOPE.flag, text, SlopeSign::Signed, Self::MAX_SLOPES);
        }
        slope_range(self.from, self.to, self.step, Self::MAX_SLOPES).map_err(|e| {
            let field = FIELDS.by_key(&e.key).unwrap_or(&FROM);
            RequestError::invalid(field.flag, e.renamed(field.long()))
        })
    }

    /// The answer (what `sweep --json` prints): the library's evaluation at every slope.
    pub fn answer(&self) -> Result<Vec<SlopeEvaluation>> {
        self.answer_in(&self.scenario.scenario()?)
    }

    /// The answer on a scenario already read from this request's (the command line keeps it
    /// to draw the figure).
    pub fn answer_in(&self, scenario: &Scenario) -> Result<Vec<SlopeEvaluation>> {
        let slopes = self.slopes()?;
        evaluate(scenario, &slopes)
    }
}

/// The scenario at every slope, an error naming `from` (the range's own fields).
pub fn evaluate(scenario: &Scenario, slopes: &[f64]) -> Result<Vec<SlopeEvaluation>> {
    let slopes = slopes
        .iter()
        .map(|&d| SignedSlope::from_degrees(d))
        .collect::<std::result::Result<Vec<_>, _>>()
        .map_err(|e| RequestError::invalid(FROM.flag, e.renamed(format!("{}/{}", FROM.long(), TO.long()))))?;
    Ok(scenario.sweep(&slopes))
}
