//! The answers of `sandslope risk` as plain serialisable values: the solving modes' (what
//! `risk --solve slope|mass --json` and `risk --map --json` print and what Python's
//! `safe_slope` and `safe_mass` return, each with the uncertainty it used, docs/model.md §9),
//! and [`RiskAnswer`], the one value every `risk --json` mode prints.

use serde::{Deserialize, Serialize};

use super::curve::RiskPoint;
use super::limits::{max_safe_mass, safe_slope_limit, PayloadEnvelope, SafeLimit};
use super::map::RiskMap;
use super::uncertainty::{DefaultsUsed, UncertainTerrain, UsedUncertainty};
use crate::error::ParamError;
use crate::robot::Robot;
use crate::slope::Slope;
use crate::Axis;

/// What `sandslope risk --json` prints (and `serve`'s `/api/risk` returns), one variant per
/// mode, serialised as its value alone: one slope's [`RiskPoint`], several slopes' points,
/// the safe-slope limit (`--solve slope`), the heaviest safe mass at one slope or the payload
/// envelope over several (`--solve mass`), or the `--map` summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum RiskAnswer {
    /// One slope.
    Point(Box<RiskPoint>),
    /// Several slopes.
    Curve(Vec<RiskPoint>),
    /// The safe-slope limit.
    Slope(Box<SafeSlope>),
    /// The heaviest safe mass at one slope.
    Mass(Box<SafeMass>),
    /// The heaviest safe mass at several slopes.
    Envelope(Box<PayloadEnvelope>),
    /// A map's summary.
    Map(Box<RiskMapSummary>),
}

impl RiskAnswer {
    /// The answer for a risk curve's points: one point alone, several (or none) as a list.
    pub fn of_points(points: Vec<RiskPoint>) -> RiskAnswer {
        match <[RiskPoint; 1]>::try_from(points) {
            Ok([one]) => RiskAnswer::Point(Box::new(one)),
            Err(points) => RiskAnswer::Curve(points),
        }
    }
}

/// The safe-slope limit with what it assumed (`risk --solve slope`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SafeSlope {
    /// The failure-risk threshold.
    pub max_risk: f64,
    /// The steepest safe slope, degrees, or `None` when the search found no crossing (see
    /// `limit`).
    pub safe_slope_deg: Option<f64>,
    /// What the search found.
    pub limit: SafeLimit,
    /// The uncertainty at the slope where `limit.p_fail` was evaluated (the safe slope, level
    /// ground when none is safe, the end of the search when all are).
    #[serde(flatten)]
    pub uncertainty: UsedUncertainty,
    /// Whether a default CV was used at some slope of the table (the search covers them all).
    pub defaults_used: DefaultsUsed,
}

/// The steepest slope with `p_fail < max_risk` for `robot` on `terrain`
/// ([`safe_slope_limit`]), with the uncertainty it used.
pub fn safe_slope(robot: &Robot, terrain: &UncertainTerrain, max_risk: f64) -> Result<SafeSlope, ParamError> {
    let limit = safe_slope_limit(robot, terrain, max_risk)?;
    // Where the search evaluated `limit.p_fail`: it scans up from level ground.
    let at = match limit {
        SafeLimit::NoneSafe { .. } => 0.0,
        SafeLimit::Limit { value, .. } => value,
        SafeLimit::BeyondRange { up_to, .. } => up_to,
    };
    let at = Slope::from_signed_degrees(at).map_err(|e| e.renamed("safe_slope_deg"))?;
    Ok(SafeSlope {
        max_risk,
        safe_slope_deg: limit.value(),
        limit,
        uncertainty: terrain.sample(at).used(),
        defaults_used: terrain.defaults_used(),
    })
}

/// The heaviest safe total mass at one slope, and the payload it leaves (`risk --solve mass`
/// at one slope).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SafeMass {
    /// Slope, degrees, as requested (a negative slope is evaluated as its magnitude).
    pub slope_deg: f64,
    /// The failure-risk threshold.
    pub max_risk: f64,
    /// The robot's own mass, kg.
    pub robot_mass_kg: f64,
    /// The heaviest safe total mass, kg, or `None` when the search found no crossing (see
    /// `limit`).
    pub max_mass_kg: Option<f64>,
    /// `max_mass_kg` minus the robot's own mass, kg.
    pub max_payload_kg: Option<f64>,
    /// What the search found.
    pub limit: SafeLimit,
    /// The uncertainty at `slope_deg`.
    #[serde(flatten)]
    pub uncertainty: UsedUncertainty,
}

/// The heaviest total mass of `robot` with `p_fail < max_risk` at `slope_deg` (degrees, in
/// (-90, 90)) on `terrain` ([`max_safe_mass`]), with the uncertainty it used.
pub fn safe_mass(
    robot: &Robot,
    slope_deg: f64,
    terrain: &UncertainTerrain,
    max_risk: f64,
) -> Result<SafeMass, ParamError> {
    let slope = Slope::from_signed_degrees(slope_deg).map_err(|e| e.renamed("slope_deg"))?;
    let limit = max_safe_mass(robot, slope, terrain, max_risk)?;
    let own = robot.mass();
    Ok(SafeMass {
        slope_deg,
        max_risk,
        robot_mass_kg: own,
        max_mass_kg: limit.value(),
        max_payload_kg: limit.payload_over(own),
        limit,
        uncertainty: terrain.sample(slope).used(),
    })
}

/// A [`RiskMap`]'s grid and a summary of its cells (`risk --map --json`; the cells themselves
/// are the map's arrays).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RiskMapSummary {
    /// Slope, degrees, as requested.
    pub slope_deg: f64,
    /// The uncertainty at `slope_deg`, applied around every cell's medians.
    #[serde(flatten)]
    pub uncertainty: UsedUncertainty,
    /// The failure-risk threshold.
    pub max_risk: f64,
    /// The median-k_n axis.
    pub k_n_axis: Axis,
    /// The median-k_s axis.
    pub k_s_axis: Axis,
    /// Number of cells.
    pub cells: usize,
    /// Cells with `p_fail < max_risk`.
    pub cells_below_max_risk: usize,
    /// The terrain's own median k_n at the slope, N/m^3.
    pub terrain_k_n: f64,
    /// The terrain's own median k_s at the slope, N/m^3.
    pub terrain_k_s: f64,
    /// p_fail at the terrain's own medians.
    pub terrain_p_fail: f64,
    /// Whether a default CV was used at this slope.
    pub defaults_used: DefaultsUsed,
}

impl RiskMapSummary {
    /// The summary of `map`, computed for `robot` at `slope_deg` on `terrain`.
    pub fn of(
        map: &RiskMap,
        robot: &Robot,
        slope_deg: f64,
        terrain: &UncertainTerrain,
        max_risk: f64,
    ) -> Result<RiskMapSummary, ParamError> {
        let slope = Slope::from_signed_degrees(slope_deg).map_err(|e| e.renamed("slope_deg"))?;
        let sample = terrain.sample(slope);
        let ground = sample.ground;
        Ok(RiskMapSummary {
            slope_deg,
            uncertainty: sample.used(),
            max_risk,
            k_n_axis: map.k_n_axis,
            k_s_axis: map.k_s_axis,
            cells: map.p_fail.len(),
            cells_below_max_risk: map.p_fail.iter().filter(|&&p| p < max_risk).count(),
            terrain_k_n: ground.k_n,
            terrain_k_s: ground.k_s,
            terrain_p_fail: super::failure_probability::p_fail(robot, slope, &ground, sample.uncertainty),
            defaults_used: terrain.defaults_used_at(slope),
        })
    }
}
