//! One panel of a phase diagram: the map of one robot at one slope with the terrain's own
//! `(k_n, k_s)` there and the sinkage and anchoring thresholds drawn with it, and the panel
//! without its cells, as `sandslope phase --json` prints it.

use serde::Serialize;

use super::{PhaseMap, RegimeCounts};
use crate::axis::Axis;
use crate::regime::Regime;
use crate::robot::Robot;
use crate::slope::SignedSlope;
use crate::strength_grid::StrengthGrid;
use crate::terrain::{Ground, Terrain};

/// One panel of a phase diagram: the map of one robot mass at one slope, with the terrain's
/// own (k_n, k_s) at that slope and the thresholds drawn and reported with it.
#[derive(Debug, Clone, Serialize)]
pub struct PhasePanel {
    /// Slope, degrees, as requested (a negative slope is evaluated as its magnitude).
    pub slope_deg: f64,
    /// Total robot mass, kg.
    pub mass_kg: f64,
    /// The regime of every grid cell.
    pub map: PhaseMap,
    /// The terrain's k_n at this slope, N/m^3.
    pub terrain_k_n: f64,
    /// The terrain's k_s at this slope, N/m^3.
    pub terrain_k_s: f64,
    /// The regime of the robot on the terrain's own (k_n, k_s).
    pub terrain_regime: Regime,
    /// Below this k_n the legs sink (docs/model.md §3), N/m^3.
    pub sinkage_threshold_k_n: f64,
    /// Below this k_s the legs never anchor (docs/model.md §4), N/m^3.
    pub anchoring_threshold_k_s: f64,
}

/// A terrain and the strength grid its phase diagrams are drawn over: `k_n` the columns and
/// `k_s` the rows, N/m^3; the terrain's own point at each slope is marked on them and its angle
/// of repose bounds them.
#[derive(Debug, Clone, Copy)]
pub struct TerrainGrid<'a> {
    /// The terrain.
    pub terrain: &'a Terrain,
    /// The normal resistances k_n: the grid's columns.
    pub k_n: &'a Axis,
    /// The shear strengths k_s: the grid's rows.
    pub k_s: &'a Axis,
}

impl PhasePanel {
    /// The panel of `robot` at `signed` (a descent evaluated as the climb of its size) on
    /// `on`'s terrain over its grid. `row_done` as in [`PhaseMap::compute`].
    pub fn compute(
        robot: &Robot,
        signed: SignedSlope,
        on: TerrainGrid<'_>,
        row_done: &(dyn Fn() + Sync),
    ) -> PhasePanel {
        let (slope_deg, slope) = (signed.degrees(), signed.felt());
        let terrain = on.terrain;
        let map =
            PhaseMap::compute(&StrengthGrid::new(robot, slope, terrain.repose(), on.k_n, on.k_s), row_done);
        let g: Ground = terrain.at(slope);
        PhasePanel {
            slope_deg,
            mass_kg: robot.mass(),
            map,
            terrain_k_n: g.k_n,
            terrain_k_s: g.k_s,
            terrain_regime: crate::model::predict(robot, slope, &g).regime,
            sinkage_threshold_k_n: crate::model::sinkage_threshold_k_n(robot, slope),
            anchoring_threshold_k_s: crate::model::anchoring_threshold_k_s(robot, slope),
        }
    }
}

/// The terrain's ground on a phase panel: its `(k_n, k_s)` at the panel's slope and the
/// robot's regime there.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PanelGround {
    /// The terrain's k_n at the panel's slope, N/m^3.
    pub k_n: f64,
    /// The terrain's k_s at the panel's slope, N/m^3.
    pub k_s: f64,
    /// The robot's regime on that ground.
    pub regime: Regime,
}

/// A phase panel without its cells: what `sandslope phase --json` prints per panel (and the
/// explorer's `/api/phase` returns).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PanelSummary {
    /// Slope, degrees, as requested.
    pub slope_deg: f64,
    /// Total robot mass, kg.
    pub mass_kg: f64,
    /// The grid's k_n axis.
    pub k_n_axis: Axis,
    /// The grid's k_s axis.
    pub k_s_axis: Axis,
    /// Cells per regime.
    pub counts: RegimeCounts,
    /// The terrain's own point and its regime.
    pub terrain: PanelGround,
    /// Below this k_n the legs sink (docs/model.md §3), N/m^3.
    pub sinkage_threshold_k_n: f64,
    /// Below this k_s the legs never anchor (docs/model.md §4), N/m^3.
    pub anchoring_threshold_k_s: f64,
    /// Whether the slope is at or beyond the terrain's angle of repose (every cell slips).
    pub beyond_repose: bool,
}

impl PhasePanel {
    /// The panel without its cells ([`PanelSummary`]).
    pub fn summary(&self) -> PanelSummary {
        PanelSummary {
            slope_deg: self.slope_deg,
            mass_kg: self.mass_kg,
            k_n_axis: *self.map.k_n_axis(),
            k_s_axis: *self.map.k_s_axis(),
            counts: self.map.counts(),
            terrain: PanelGround {
                k_n: self.terrain_k_n,
                k_s: self.terrain_k_s,
                regime: self.terrain_regime,
            },
            sinkage_threshold_k_n: self.sinkage_threshold_k_n,
            anchoring_threshold_k_s: self.anchoring_threshold_k_s,
            beyond_repose: self.map.beyond_repose(),
        }
    }
}
