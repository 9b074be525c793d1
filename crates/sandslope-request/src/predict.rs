//! [`PredictRequest`]: every model quantity for one robot, terrain and slope.

use serde::{Deserialize, Serialize};

use sandslope::{ParamError, Robot, Scenario, SignedSlope, SlopeEvaluation, Terrain};

use crate::error::{RequestError, Result};
use crate::field::{Field, Fields, Table};
use crate::params::Params;
use crate::scenario::{ScenarioRequest, K_N, K_S, ROBOT_QUANTITIES, TERRAIN};

/// `--slope`: the one slope of a prediction (Python's `slope_deg`, the library's key).
pub const SLOPE: Field = Field::number("slope", "DEG")
    .keyword("slope_deg")
    .key("slope_deg")
    .unit("deg")
    .range("-90 to 90 (docs/model.md §8)")
    .required()
    .help(
        "Slope along the direction of travel, degrees (negative: descending, evaluated as \
         |slope|, docs/model.md §8)",
    );

/// `predict`'s own field (the robot's and terrain's are [`crate::scenario::FIELDS`]).
pub const FIELDS: Table = Table { command: "predict", fields: &[SLOPE] };

impl Fields for PredictRequest {
    const TABLE: Table = FIELDS;
}

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
        Self::read(params, None)
    }

    /// The command line's request: its own fields from `params` (the flags given, by
    /// [`FIELDS`]), the scenario already read from the flags it shares with other commands.
    pub fn with_scenario(params: &[(String, String)], scenario: ScenarioRequest) -> Result<PredictRequest> {
        Self::read(params, Some(scenario))
    }

    fn read(params: &[(String, String)], scenario: Option<ScenarioRequest>) -> Result<PredictRequest> {
        let mut p = Params::new(FIELDS.command, params);
        let slope = SLOPE.required_number_in(&mut p)?;
        let scenario = match scenario {
            Some(s) => s,
            None => ScenarioRequest::from_params(&mut p)?,
        };
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
    let slope = SignedSlope::from_degrees(slope)
        .map_err(|e| RequestError::invalid(SLOPE.flag, e.renamed(SLOPE.long())))?;
    Ok(scenario.evaluate(slope))
}

/// One point of an array `predict` (Python's `sandslope.predict` answers one per element): a
/// robot and terrain already read, with the point's own mass and fixed resistances.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointRequest {
    /// Slope along the direction of travel, degrees (negative: descending, docs/model.md §8).
    pub slope: f64,
    /// Normal resistance k_n, N/m^3, instead of the terrain's.
    pub k_n: Option<f64>,
    /// Shear strength k_s, N/m^3, instead of the terrain's.
    pub k_s: Option<f64>,
    /// Total mass, kg, instead of the robot's.
    pub mass: Option<f64>,
}

/// The request field of a library key (`k_n` -> `k-n`, `slope_deg` -> `slope`, `mass_kg` ->
/// `mass`): a lookup in the tables, `None` for a key no field sets.
fn field_of_key(key: &str) -> Option<&'static str> {
    [SLOPE, K_N, K_S].iter().chain(ROBOT_QUANTITIES.fields).find(|f| f.key == key).map(|f| f.flag)
}

impl PointRequest {
    /// The answer at this point, `predict --json`'s evaluation: the scenario with the point's
    /// overrides (checked by [`Scenario::new`] and [`Robot::with_mass`]) evaluated at its
    /// slope. A refused value's message names it by `name` applied to the library's key
    /// (`slope_deg`, `k_n`, `k_s`, `mass_kg`), as the front end calls it (Python: `k_n[3]`);
    /// the error's field is the request's (`slope`, `k-n`, `k-s`, `mass`).
    pub fn answer(
        &self,
        robot: &Robot,
        terrain: &Terrain,
        name: impl Fn(&str) -> String,
    ) -> Result<SlopeEvaluation> {
        let refuse = |e: ParamError| match field_of_key(&e.key) {
            Some(field) => {
                let key = name(&e.key);
                RequestError::invalid(field, e.renamed(key))
            }
            None => RequestError::from_error(None, anyhow::anyhow!("{e}")),
        };
        let robot = match self.mass {
            Some(m) => robot.with_mass(m).map_err(|e| refuse(e.renamed("mass_kg")))?,
            None => robot.clone(),
        };
        let scenario = Scenario::new(robot, terrain.clone(), self.k_n, self.k_s).map_err(refuse)?;
        let slope = SignedSlope::from_degrees(self.slope).map_err(refuse)?;
        Ok(scenario.evaluate(slope))
    }
}

/// The terrain an array `predict` looks resistances up in: the one given, or, with both k_n
/// and k_s given at every point, any valid one-point table (it only lends its absent angle of
/// repose). Without either, an error in Python's words naming the field `terrain`.
pub fn point_terrain(terrain: Option<&Terrain>, k_n_given: bool, k_s_given: bool) -> Result<Terrain> {
    match terrain {
        Some(t) => Ok(t.clone()),
        None if k_n_given && k_s_given => Terrain::constant(1.0, 1.0)
            .map_err(|e| RequestError::from_error(Some(TERRAIN.flag), anyhow::anyhow!("{e}"))),
        None => Err(RequestError::invalid(
            TERRAIN.flag,
            "give both k_n and k_s, or a terrain (k_n and k_s then override it)",
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn robot() -> Robot {
        Robot::new(sandslope::RobotSpec::paper_hexapod()).unwrap()
    }

    /// A point's overrides replace the terrain's resistances and the robot's mass: the same
    /// evaluation as a scenario built with them by hand; a refused value is named as the
    /// front end names it, under the request's field.
    #[test]
    fn a_point_overrides_and_names_its_refusals() {
        let terrain = Terrain::constant(3e6, 1e6).unwrap();
        let point = PointRequest { slope: 10.0, k_n: None, k_s: Some(5e5), mass: Some(1.0) };
        let got = point.answer(&robot(), &terrain, str::to_string).unwrap();
        let by_hand = Scenario::new(robot().with_mass(1.0).unwrap(), terrain.clone(), None, Some(5e5))
            .unwrap()
            .evaluate(SignedSlope::from_degrees(10.0).unwrap());
        assert_eq!(got.prediction.k_s, 5e5);
        assert_eq!(got.prediction.k_n, 3e6);
        assert_eq!(got, by_hand);
        let name = |k: &str| format!("{k}[2]");
        for (point, field, start) in [
            (PointRequest { k_n: Some(-1.0), ..point }, "k-n", "k_n[2] = -1 must be"),
            (PointRequest { k_s: Some(0.0), ..point }, "k-s", "k_s[2] = 0 must be"),
            (PointRequest { mass: Some(-2.0), ..point }, "mass", "mass_kg[2] = -2 must be"),
            (PointRequest { slope: 95.0, ..point }, "slope", "slope_deg[2] = 95 must be"),
        ] {
            let e = point.answer(&robot(), &terrain, name).unwrap_err();
            assert_eq!(e.field(), Some(field), "{}", e.message());
            assert!(e.message().starts_with(start), "{}", e.message());
        }
    }

    #[test]
    fn a_point_terrain_needs_a_table_or_both_resistances() {
        let t = Terrain::constant(3e6, 1e6).unwrap();
        assert_eq!(point_terrain(Some(&t), false, false).unwrap(), t);
        assert!(point_terrain(None, true, true).is_ok());
        let e = point_terrain(None, true, false).unwrap_err();
        assert_eq!(e.field(), Some("terrain"));
        assert_eq!(e.message(), "give both k_n and k_s, or a terrain (k_n and k_s then override it)");
    }
}
