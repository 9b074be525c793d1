//! What `plan --json` prints (and `/api/plan` returns): each route's statistics or why none
//! exists, and how corridors were planned.

use std::collections::BTreeMap;

use serde::Serialize;

use sandslope::plan::{NoRoute, Objective, Route};
use sandslope::Regime;
use sandslope_format::Explain;

use super::{CorridorPlanned, Planned};

/// One route as printed by `--json`. The keys are in alphabetical order, the order `plan --json`
/// has always printed (it went through a `serde_json::Value`).
#[derive(Debug, Serialize)]
pub struct RouteRecord {
    /// Edges steeper in roll than the limit.
    pub edges_over_roll_limit: Option<usize>,
    /// Whether a route was found.
    pub found: bool,
    /// 3-D length, m.
    pub length_m: Option<f64>,
    /// Steepest pitch, degrees.
    pub max_pitch_deg: Option<f64>,
    /// Steepest roll, degrees.
    pub max_roll_deg: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    /// Why no route exists, in words ([`Explain`]).
    pub message: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    /// Why no route exists.
    pub reason: Option<NoRoute>,
    /// Edges by regime.
    pub regimes: Option<BTreeMap<&'static str, usize>>,
    /// Probability of crossing without failure.
    pub survival: Option<f64>,
    /// Travel time, s.
    pub time_s: Option<f64>,
}

impl RouteRecord {
    /// The record of one route or of why none exists.
    pub fn from(r: &Result<Route, NoRoute>) -> RouteRecord {
        match r {
            Ok(r) => RouteRecord {
                found: true,
                reason: None,
                message: None,
                length_m: Some(r.length_m),
                time_s: r.time_s,
                survival: Some(r.survival),
                max_pitch_deg: Some(r.max_pitch_deg),
                max_roll_deg: Some(r.max_roll_deg),
                edges_over_roll_limit: Some(r.over_roll_limit),
                regimes: Some(Regime::ALL.iter().zip(r.regimes).map(|(g, n)| (g.name(), n)).collect()),
            },
            Err(e) => RouteRecord {
                found: false,
                reason: Some(*e),
                message: Some(e.explain()),
                length_m: None,
                time_s: None,
                survival: None,
                max_pitch_deg: None,
                max_roll_deg: None,
                edges_over_roll_limit: None,
                regimes: None,
            },
        }
    }
}

/// What `plan --json` prints: per objective, the route's statistics or why none exists, and,
/// when the routes were planned in corridors, how.
#[derive(Debug, Serialize)]
pub struct PlanJson {
    /// By objective name.
    pub routes: BTreeMap<&'static str, RouteRecord>,
    /// The corridor search's settings and corridors (absent for the full search).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub search: Option<CorridorJson>,
}

/// How the routes were planned by `--search corridor`, in `plan --json`.
#[derive(Debug, Serialize)]
pub struct CorridorJson {
    /// `corridor`.
    pub mode: &'static str,
    /// Fine cells per coarse cell along each axis.
    pub coarse_factor: usize,
    /// The corridor's half-width, coarse cells.
    pub corridor_width: usize,
    /// The coarse grid's columns and rows.
    pub coarse_size: (usize, usize),
    /// Per objective, the coarse route's cost (seconds for time, metres for distance) and the
    /// corridor's cells.
    pub corridors: BTreeMap<&'static str, sandslope::plan::CorridorStats>,
}

/// The value `plan --json` prints (and `serve`'s `/api/plan` returns).
pub fn answer(planned: &Planned) -> PlanJson {
    PlanJson { routes: records(&planned.result.routes), search: None }
}

/// The `--json` record of each route, by objective name.
pub fn records(routes: &[(Objective, Result<Route, NoRoute>)]) -> BTreeMap<&'static str, RouteRecord> {
    routes.iter().map(|(o, r)| (o.name(), RouteRecord::from(r))).collect()
}

/// The value `plan --json` prints for a corridor search.
pub fn corridor_answer(planned: &CorridorPlanned) -> PlanJson {
    let CorridorPlanned { plan, settings, .. } = planned;
    let search = CorridorJson {
        mode: "corridor",
        coarse_factor: settings.factor(),
        corridor_width: settings.half_width(),
        coarse_size: plan.coarse_size,
        corridors: plan.corridors.iter().map(|c| (c.objective.name(), *c)).collect(),
    };
    PlanJson { routes: records(&plan.routes), search: Some(search) }
}
