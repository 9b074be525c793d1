//! The answers of `sandslope risk` as plain serialisable values: the solving modes' (what
//! `risk --solve slope|mass --json` and `risk --map --json` print and what Python's
//! `safe_slope`, `safe_mass` and `risk_map` return, each with the uncertainty it used,
//! docs/model.md §9), and [`RiskAnswer`], the one value every `risk --json` mode prints.

use serde::ser::{SerializeSeq, SerializeStruct};
use serde::{Deserialize, Serialize, Serializer};

use super::curve::RiskPoint;
use super::limits::{max_safe_mass, safe_slope_limit, success_slope_limit, PayloadEnvelope, SafeLimit};
use super::map::RiskMap;
use super::uncertainty::{DefaultsUsed, UncertainTerrain, UsedUncertainty};
use crate::error::ParamError;
use crate::robot::Robot;
use crate::slope::{SignedSlope, Slope};
use crate::strength_grid::StrengthGrid;
use crate::Axis;

/// What `sandslope risk --json` prints (and `serve`'s `/api/risk` returns), one variant per
/// mode, serialised as its value alone: one slope's [`RiskPoint`], several slopes' points,
/// the safe-slope limit (`--solve slope`), the heaviest safe mass at one slope or the payload
/// envelope over several (`--solve mass`), or the `--map` cells with their summary.
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
    /// A map with its summary.
    Map(Box<RiskMapAnswer>),
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

/// The two slope limits with what they assumed (`risk --solve slope`): up to where the robot
/// does not fail (`safe_slope_deg`, p_fail = P(sinkage or slippage) below `max_risk`) and up to
/// where it climbs (`success_slope_deg`, P(not success) below `max_risk`: not metastable
/// either). Between the two the model says the robot neither sinks nor slips back for good but
/// makes less than the minimum step: it gets stuck (metastable, docs/model.md §5). "How steep can
/// we go?" is answered by the success limit; the safe-slope limit says where the robot starts to
/// fail outright.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SafeSlope {
    /// The risk threshold of both limits.
    pub max_risk: f64,
    /// The safe-slope (no-failure) limit, degrees: p_fail < `max_risk` from level up to it; the
    /// angle of repose when `limit.kind` is `"repose"`; `None` when the search found no
    /// crossing (see `limit`).
    pub safe_slope_deg: Option<f64>,
    /// What the p_fail search found: `kind` `"limit"` (the risk threshold crossed),
    /// `"repose"` (p_fail stays below it up to the angle of repose, where the sand flows),
    /// `"none_safe"` or `"beyond_range"`.
    pub limit: SafeLimit,
    /// The success limit, degrees: P(not success) < `max_risk` from level up to it (the robot
    /// climbs: it does not sink, slip or get stuck metastable); `None` when the search found
    /// no crossing (see `success_limit`).
    pub success_slope_deg: Option<f64>,
    /// What the P(not success) search found ([`success_slope_limit`]; its `p_fail` field is
    /// P(not success) where the search stopped).
    pub success_limit: SafeLimit,
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
    let success_limit = success_slope_limit(robot, terrain, max_risk)?;
    // Where the search evaluated `limit.p_fail`: it scans up from level ground.
    let at = match limit {
        SafeLimit::NoneSafe { .. } => 0.0,
        SafeLimit::Limit { value, .. } => value,
        // The search stopped just below the repose.
        SafeLimit::Repose { repose_deg, .. } => repose_deg - 2.0 * super::limits::SLOPE_TOLERANCE_DEG,
        SafeLimit::BeyondRange { up_to, .. } => up_to,
    };
    let at = Slope::from_signed_degrees(at).map_err(|e| e.renamed("safe_slope_deg"))?;
    Ok(SafeSlope {
        max_risk,
        safe_slope_deg: limit.value(),
        limit,
        success_slope_deg: success_limit.value(),
        success_limit,
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

/// The heaviest total mass of `robot` with `p_fail < max_risk` at `slope` on `terrain`
/// ([`max_safe_mass`]), with the uncertainty it used.
pub fn safe_mass(
    robot: &Robot,
    signed: SignedSlope,
    terrain: &UncertainTerrain,
    max_risk: f64,
) -> Result<SafeMass, ParamError> {
    let (slope_deg, slope) = (signed.degrees(), signed.felt());
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

/// A [`RiskMap`]'s grid and a summary of its cells (the first keys of [`RiskMapAnswer`]).
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
    /// The summary of `map`, computed for `robot` at `slope` on `terrain`.
    pub fn of(
        map: &RiskMap,
        robot: &Robot,
        signed: SignedSlope,
        terrain: &UncertainTerrain,
        max_risk: f64,
    ) -> RiskMapSummary {
        let (slope_deg, slope) = (signed.degrees(), signed.felt());
        let sample = terrain.sample(slope);
        let ground = sample.ground;
        RiskMapSummary {
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
        }
    }
}

/// A risk map and its summary: what `risk --map --json` prints and Python's `risk_map`
/// returns (there the cells and axis values as NumPy arrays, under the same keys).
///
/// Serialised as the [`RiskMapSummary`]'s keys followed by `beyond_repose`, the axis values
/// `k_n` and `k_s`, and the cells `p_fail` and `p_not_success` as nested lists indexed
/// `[k_n][k_s]` (Python's shape `(len(k_n), len(k_s))`; [`RiskMap`] holds them row-major,
/// one row per k_s).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RiskMapAnswer {
    /// The grid and the summary of its cells.
    #[serde(flatten)]
    pub summary: RiskMapSummary,
    /// The cells.
    #[serde(flatten, serialize_with = "serialize_cells")]
    pub map: RiskMap,
}

/// The keys [`RiskMapAnswer`] adds to its summary, in order: the ones Python gives as arrays
/// (all but `beyond_repose`).
pub const RISK_MAP_CELL_KEYS: [&str; 5] = ["beyond_repose", "k_n", "k_s", "p_fail", "p_not_success"];

/// A row-major `rows x columns` block serialised by columns: `[i][j]` is `values[j * columns + i]`.
struct ByColumns<'a> {
    values: &'a [f64],
    columns: usize,
}

impl Serialize for ByColumns<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let rows = self.values.len().checked_div(self.columns).unwrap_or(0);
        let mut seq = s.serialize_seq(Some(self.columns))?;
        for i in 0..self.columns {
            let column: Vec<f64> = (0..rows).map(|j| self.values[j * self.columns + i]).collect();
            seq.serialize_element(&column)?;
        }
        seq.end()
    }
}

fn serialize_cells<S: Serializer>(map: &RiskMap, s: S) -> Result<S::Ok, S::Error> {
    let columns = map.k_n_axis.len();
    let [repose, k_n, k_s, p_fail, p_not_success] = RISK_MAP_CELL_KEYS;
    let mut st = s.serialize_struct("RiskMapCells", RISK_MAP_CELL_KEYS.len())?;
    st.serialize_field(repose, &map.beyond_repose)?;
    st.serialize_field(k_n, &map.k_n_axis.values())?;
    st.serialize_field(k_s, &map.k_s_axis.values())?;
    st.serialize_field(p_fail, &ByColumns { values: &map.p_fail, columns })?;
    st.serialize_field(p_not_success, &ByColumns { values: &map.p_not_success, columns })?;
    st.end()
}

/// Points per axis of a risk map's default grid.
pub const MAP_POINTS: usize = 200;

/// The axes of a risk map at `slope` on `terrain`: `k_n_axis` and
/// `k_s_axis` where given, else the default grid around the terrain's medians at that slope,
/// [`MAP_POINTS`] log-spaced values of k_n from its median / 100 to x 100 and of k_s from
/// / 1000 to x 100 (what `risk --map` and Python's `risk_map` use without axes).
pub fn map_axes(
    terrain: &UncertainTerrain,
    slope: SignedSlope,
    k_n_axis: Option<Axis>,
    k_s_axis: Option<Axis>,
) -> Result<(Axis, Axis), ParamError> {
    let ground = terrain.sample(slope.felt()).ground;
    let k_n_axis = match k_n_axis {
        Some(a) => a,
        None => Axis::log_around("k_n_axis", &[ground.k_n], 100.0, 100.0, MAP_POINTS)?,
    };
    let k_s_axis = match k_s_axis {
        Some(a) => a,
        None => Axis::log_around("k_s_axis", &[ground.k_s], 1000.0, 100.0, MAP_POINTS)?,
    };
    Ok((k_n_axis, k_s_axis))
}

/// The risk map of `robot` at `slope` on `terrain` over
/// `k_n_axis x k_s_axis`, each cell with the terrain's uncertainty and angle of repose at that
/// slope ([`RiskMap::compute`]; `row_done` is called once per finished k_s row), and its
/// summary against `max_risk`.
pub fn risk_map(
    robot: &Robot,
    signed: SignedSlope,
    terrain: &UncertainTerrain,
    (k_n_axis, k_s_axis): (&Axis, &Axis),
    max_risk: f64,
    row_done: &(dyn Fn() + Sync),
) -> Result<RiskMapAnswer, ParamError> {
    super::limits::check_risk(max_risk)?;
    let slope = signed.felt();
    let sample = terrain.sample(slope);
    let grid = StrengthGrid::new(robot, slope, sample.ground.repose, k_n_axis, k_s_axis);
    let map = RiskMap::compute(&grid, sample.uncertainty, row_done);
    let summary = RiskMapSummary::of(&map, robot, signed, terrain, max_risk);
    Ok(RiskMapAnswer { summary, map })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::tests::paper_robot;
    use crate::terrain::Terrain;
    use crate::AxisScale;

    fn deg(d: f64) -> SignedSlope {
        SignedSlope::from_degrees(d).unwrap()
    }

    /// The cells come out indexed `[k_n][k_s]` after the summary's keys: a 3 x 2 map read back
    /// from its JSON cell by cell against the map's own row-major store.
    #[test]
    fn map_answer_lists_cells_by_k_n_after_the_summary() {
        let t = UncertainTerrain::new(Terrain::constant(7e5, 1.5e6).unwrap(), None, None).unwrap();
        let kn = Axis::new("k_n", 1e5, 1e7, 3, AxisScale::Log).unwrap();
        let ks = Axis::new("k_s", 1e5, 1e7, 2, AxisScale::Log).unwrap();
        let a = risk_map(&paper_robot(), deg(20.0), &t, (&kn, &ks), 0.05, &|| {}).unwrap();
        // The summary's text, then the cells' keys in order.
        let text = serde_json::to_string(&a).unwrap();
        let summary = serde_json::to_string(&a.summary).unwrap();
        let rest = text.strip_prefix(summary.strip_suffix('}').unwrap()).unwrap();
        let at: Vec<usize> =
            RISK_MAP_CELL_KEYS.iter().map(|k| rest.find(&format!(",\"{k}\":")).unwrap()).collect();
        assert!(at[0] == 0 && at.windows(2).all(|w| w[0] < w[1]), "{rest}");
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        // (serde_json reads numbers back to within an ulp without its float_roundtrip feature.)
        let close = |x: &serde_json::Value, y: f64| (x.as_f64().unwrap() - y).abs() <= 1e-15 * y.abs();
        for i in 0..3 {
            for j in 0..2 {
                assert!(close(&v["p_fail"][i][j], a.map.p_fail_at(i, j)), "{i} {j}");
                assert!(close(&v["p_not_success"][i][j], a.map.p_not_success_at(i, j)), "{i} {j}");
            }
        }
        // Distinct cells: the layout is tested, not a constant.
        assert!(
            a.map.p_fail_at(0, 1) != a.map.p_fail_at(1, 1) && a.map.p_fail_at(0, 0) != a.map.p_fail_at(0, 1)
        );
        assert_eq!(v["p_fail"].as_array().unwrap().len(), 3);
        assert_eq!(v["k_s"], serde_json::json!([1e5, 1e7]));
        assert_eq!(
            risk_map(&paper_robot(), deg(20.0), &t, (&kn, &ks), 1.0, &|| {}).unwrap_err().key,
            "max_risk"
        );
    }

    /// A given axis is kept; a missing one is 200 log-spaced values around the terrain's median
    /// at the slope (k_n / 100 to x 100, k_s / 1000 to x 100); a descent's is its climb's.
    #[test]
    fn map_axes_default_around_the_medians() {
        let t = UncertainTerrain::new(Terrain::constant(7e5, 1.5e6).unwrap(), None, None).unwrap();
        let kn = Axis::new("k_n", 1e5, 1e7, 3, AxisScale::Log).unwrap();
        let (a, b) = map_axes(&t, deg(20.0), Some(kn), None).unwrap();
        assert_eq!(a, kn);
        assert_eq!((b.min(), b.max(), b.len(), b.scale()), (1.5e3, 1.5e8, 200, AxisScale::Log));
        let (a, _) = map_axes(&t, deg(-20.0), None, None).unwrap();
        assert_eq!((a.min(), a.max()), (7e3, 7e7));
    }
}
