//! Heading-aware route planning and risk maps over an elevation model (docs/model.md §8).
//!
//! On a surface `z(x, y)`, a robot heading along the horizontal unit vector `u` feels the
//! pitch `atan(grad z . u)` and the roll `atan(|grad z x u|)`. Crossing a slope feels gentler
//! than climbing it head-on, so a switchback can succeed where the direct line fails.
//!
//! The map is a 16-connected grid graph: from every cell, its 8 neighbours and the 8 knight
//! moves (headings every ~26.6 degrees). A directed edge's gradient is the mean of the Horn
//! gradients of its two end cells; its pitch and roll follow from the heading. Descending is
//! evaluated at `|pitch|` by default and any roll above a limit (default 20 degrees) is
//! impassable, both configurable (**choices** of docs/model.md §8). The model is evaluated
//! once per class on a pitch table ([`PitchTable`]), never per edge.
//!
//! Objectives ([`Objective`]): fastest route through cells whose regime is success
//! (`Time`), maximum survival probability (`Risk`: minimises `sum -ln(1 - p_fail)` plus a
//! weight times the time, docs/model.md §9), and shortest 3-D length with physics ignored
//! (`Distance`). The search is A* on flat arrays with a straight-line heuristic that never
//! overestimates.

mod classes;
mod corridor;
mod grid;
mod planner;
mod queue;
mod result;
mod risk_map;
mod route;
mod search;
mod source;
mod table;

pub use classes::{class_indices, UnmappedClass};
pub use corridor::{
    plan_corridor, plan_corridor_from, CorridorPlan, CorridorSettings, CorridorStats,
    CORRIDOR_BYTES_PER_CELL, CORRIDOR_MAP_BYTES_PER_CELL,
};
pub use grid::{Cell, ElevationGrid};
pub use planner::{heading_offsets, Planner, HEADINGS, NO_CLASS};
pub use result::{plan, Extrapolation, PlanRequest, PlanResult, RiskRaster};
pub use risk_map::{risk_map_from, RISK_BAND_CELLS};
pub use route::{Route, RouteStep};
pub use source::{coarsened_from, HeightSource};
pub use table::{PitchTable, PitchTableCache, MAX_PITCH_DEG, P_FAIL_STEP_DEG, TAN_STEP};

use serde::{Deserialize, Serialize};

use crate::error::ParamError;
use crate::slope::Slope;

/// Bytes per cell the planner holds besides its route searches: the grid's height (`f32`),
/// nodata mask (`bool`) and terrain class (`u8`), and the Horn gradient (two `f32`).
pub const PLANNER_BYTES_PER_CELL: u64 = 4 + 1 + 1 + 8;

/// Bytes per cell of one route search: the 16-byte node (the `f64` distance beside a copy of
/// the gradient) and the predecessor heading (`u8`).
pub const SEARCH_BYTES_PER_CELL: u64 = 16 + 1;

/// The memory [`plan`] allocates per cell with `searches` route searches running at once (one
/// per objective, as many at once as there are threads): what to check a map against before
/// planning on it.
pub fn bytes_per_cell(searches: u64) -> u64 {
    PLANNER_BYTES_PER_CELL + searches * SEARCH_BYTES_PER_CELL
}

/// What a route minimises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Objective {
    /// Travel time, through edges whose regime is success (metastable if allowed).
    Time,
    /// `sum -ln(1 - p_fail)` over the cells crossed, plus `time_weight` times the time.
    Risk,
    /// 3-D length; the physics is ignored (the naive baseline).
    Distance,
}

impl Objective {
    /// All objectives.
    pub const ALL: [Objective; 3] = [Objective::Time, Objective::Risk, Objective::Distance];

    /// The lowercase name used in files and JSON.
    pub fn name(self) -> &'static str {
        match self {
            Objective::Time => "time",
            Objective::Risk => "risk",
            Objective::Distance => "distance",
        }
    }
}

/// How descending edges (negative pitch) are evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Descent {
    /// As climbing `|pitch|` (docs/model.md §8 default: symmetric, conservative).
    #[default]
    Symmetric,
    /// As level ground (optimistic: gravity helps going down).
    Level,
}

impl Descent {
    /// Every rule, the default first.
    pub const ALL: [Descent; 2] = [Descent::Symmetric, Descent::Level];

    /// The rule's name, as `--descent`, the server and Python write it.
    pub fn name(self) -> &'static str {
        match self {
            Descent::Symmetric => "symmetric",
            Descent::Level => "level",
        }
    }

    /// The rule of that name, if any.
    pub fn parse(name: &str) -> Option<Descent> {
        Descent::ALL.into_iter().find(|d| d.name() == name)
    }
}

/// With a time weight of zero, the risk objective breaks ties between equally safe routes by
/// their 3-D length, at this cost per metre (in units of `-ln(survival)`): a kilometre adds
/// 1e-6, a survival change of 0.0001 %. Without it, edges where `p_fail` is 0 would cost
/// nothing and any zero-risk detour, however long, would be optimal.
pub const RISK_TIE_BREAK_PER_M: f64 = 1e-9;

/// Planner settings, validated by [`PlanSettings::new`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanSettings {
    max_roll: Slope,
    descent: Descent,
    allow_metastable: bool,
    time_weight: f64,
}

impl Default for PlanSettings {
    /// Roll limit 20 degrees, symmetric descent, success only, time weight 1e-4 per second.
    fn default() -> Self {
        PlanSettings {
            max_roll: Slope::from_degrees(DEFAULT_MAX_ROLL_DEG).unwrap_or(Slope::LEVEL),
            descent: Descent::Symmetric,
            allow_metastable: false,
            time_weight: DEFAULT_TIME_WEIGHT,
        }
    }
}

/// Default weight of travel time in the risk objective, per second: 100 s of travel weigh
/// as much as a 1 % failure risk (`-ln(0.99) = 0.01`). A **choice** that breaks ties
/// between equally safe routes in favour of the faster one.
pub const DEFAULT_TIME_WEIGHT: f64 = 1e-4;

/// The cross-slope (roll) limit when none is given, degrees (`--max-roll`, Python's
/// `max_roll_deg`): steeper cross slopes are impassable (docs/model.md §8).
pub const DEFAULT_MAX_ROLL_DEG: f64 = 20.0;

impl PlanSettings {
    /// Settings: cross-slope limit `max_roll_deg` in `(0, 90)`, the descent rule, whether
    /// metastable edges may be used by the time objective, and the risk objective's weight
    /// on time (per second, >= 0).
    pub fn new(
        max_roll_deg: f64,
        descent: Descent,
        allow_metastable: bool,
        time_weight: f64,
    ) -> Result<PlanSettings, ParamError> {
        let max_roll =
            Slope::from_degrees(max_roll_deg).ok().filter(|_| max_roll_deg > 0.0).ok_or_else(|| {
                ParamError::new("max_roll_deg", max_roll_deg, "strictly between 0 and 90 degrees")
            })?;
        let time_weight = crate::error::non_negative("time_weight", time_weight)?;
        Ok(PlanSettings { max_roll, descent, allow_metastable, time_weight })
    }
    /// Cross-slope limit.
    pub fn max_roll(&self) -> Slope {
        self.max_roll
    }
    /// Descent rule.
    pub fn descent(&self) -> Descent {
        self.descent
    }
    /// Whether the time objective may use metastable edges.
    pub fn allow_metastable(&self) -> bool {
        self.allow_metastable
    }
    /// Weight of time in the risk objective, per second.
    pub fn time_weight(&self) -> f64 {
        self.time_weight
    }
}

/// Why planning could not start or a route does not exist.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// The grid is malformed.
    #[error("elevation grid: {0}")]
    Grid(String),
    /// The class raster does not match the grid or names a class without terrain.
    #[error("classes: {0}")]
    Classes(String),
    /// Start or goal lies outside the grid.
    #[error("{which} cell (col {}, row {}) is outside the {cols} x {rows} map", .cell.col, .cell.row)]
    Outside {
        /// `start` or `goal`.
        which: &'static str,
        /// The cell asked for.
        cell: Cell,
        /// Grid columns.
        cols: usize,
        /// Grid rows.
        rows: usize,
    },
    /// Start or goal has no usable gradient: nodata, next to nodata, on the border, or a
    /// cell without terrain class.
    #[error(
        "{which} cell (col {}, row {}) is {reason}; pick a cell with height data all around it",
        .cell.col, .cell.row
    )]
    NoData {
        /// `start` or `goal`.
        which: &'static str,
        /// The cell asked for.
        cell: Cell,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// The caller's progress callback asked the search to stop (Ctrl-C in a front end).
    #[error("stopped before the search finished")]
    Stopped,
}

/// Why an objective found no route (reported as `found: false`, not as an error); the front
/// ends word it (`sandslope_format::Explain`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NoRoute {
    /// Every edge out of the start is impassable for this objective.
    StartImpassable,
    /// Every edge into the goal is impassable for this objective.
    GoalImpassable,
    /// The search ran out of reachable cells before the goal.
    GoalUnreachable,
}

#[cfg(test)]
mod descent_tests {
    use super::Descent;

    /// The names the front ends parse are the ones serde writes, and each parses back.
    #[test]
    fn descent_names_are_serde_names_and_parse_back() {
        for d in Descent::ALL {
            assert_eq!(serde_json::to_string(&d).unwrap(), format!("\"{}\"", d.name()));
            assert_eq!(Descent::parse(d.name()), Some(d));
        }
        assert_eq!(Descent::ALL[0], Descent::default());
        assert_eq!(Descent::parse("Level"), None);
    }
}
