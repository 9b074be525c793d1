//! [`PredictRequest`]: every model quantity for one robot, terrain and slope.

use serde::{Deserialize, Serialize};

use sandslope::SlopeEvaluation;

use crate::error::{RequestError, Result};
use crate::params::Params;
use crate::scenario::ScenarioRequest;

/// The inputs of `predict` (and `/api/predict`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PredictRequest {
    /// Slope along the direction of travel, degrees (negative: descending, evaluated as
    /// |slope|, docs/model.md §8; field `slope`).
    pub slope: f64,
    /// Robot, terrain and overrides.
    pub scenario: ScenarioRequest,
}

impl PredictRequest {
    /// Reads `slope` (required) and the scenario's fields; refuses any other key.
    pub fn from_params(params: &[(String, String)]) -> Result<PredictRequest> {
        let mut p = Params::new("predict", params);
        let slope = p.required_number("slope", "the slope along the direction of travel, degrees")?;
        let scenario = ScenarioRequest::from_params(&mut p)?;
        p.finish()?;
        Ok(PredictRequest { slope, scenario })
    }

    /// The answer (what `predict --json` prints): the library's evaluation at `slope`.
    pub fn answer(&self) -> Result<SlopeEvaluation> {
        evaluate(&self.scenario.scenario()?, self.slope)
    }
}

/// The scenario at one slope, an error naming the field `slope`.
pub fn evaluate(scenario: &sandslope::Scenario, slope: f64) -> Result<SlopeEvaluation> {
    scenario.evaluate(slope).map_err(|e| RequestError::invalid("slope", e.renamed("--slope")))
}
