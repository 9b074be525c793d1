//! Everything `sandslope plan` computes, in one call: the planner built on the grid, the
//! route of each objective (the distance route always among them, as the naive baseline),
//! and, if asked, the risk raster (docs/model.md §8, §9).

use std::ops::ControlFlow;

use rayon::prelude::*;
use serde::ser::{SerializeMap, SerializeSeq};
use serde::{Serialize, Serializer};

use super::grid::{Cell, ElevationGrid};
use super::planner::Planner;
use super::route::Route;
use super::{NoRoute, Objective, PlanError, PlanSettings};
use crate::risk::UncertainTerrain;
use crate::robot::Robot;

/// What to plan on a grid.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanRequest {
    /// Start cell.
    pub start: Cell,
    /// Goal cell.
    pub goal: Cell,
    /// Objectives to route for; [`Objective::Distance`] is always added.
    pub objectives: Vec<Objective>,
    /// Whether to compute the risk raster ([`Planner::risk_map`]).
    pub risk_map: bool,
}

/// The risk raster: per cell, row-major from the north-west corner, NaN where impassable.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RiskRaster {
    /// The lowest P(failure) over the 16 headings.
    pub p_fail: Vec<f32>,
    /// Azimuth of the steepest climbing heading the time objective may use, degrees
    /// clockwise from north.
    pub climb_azimuth_deg: Vec<f32>,
}

/// Terrain values used beyond a table's last measured point (docs/model.md §7).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Extrapolation {
    /// The steepest pitch a route reaches, degrees.
    pub max_pitch_deg: f64,
    /// The slope of the table's last measured point, degrees.
    pub last_point_deg: f64,
}

/// What `plan` computed.
#[derive(Debug, Clone, Serialize)]
pub struct PlanResult {
    /// Start cell.
    pub start: Cell,
    /// Goal cell.
    pub goal: Cell,
    /// The route of each objective, or why none exists, in [`Objective`] order. Serialised as
    /// a list of objects, `{"objective": "time", "route": {...}}` or `{"objective": "time",
    /// "no_route": {"reason": "goal_unreachable"}}`, not as tuples and `Ok`/`Err` variants (the
    /// front ends' answers add the reason in words, `sandslope_format::Explain`).
    #[serde(serialize_with = "routes_as_objects")]
    pub routes: Vec<(Objective, Result<Route, NoRoute>)>,
    /// The risk raster, if asked for.
    pub risk: Option<RiskRaster>,
    /// Set when a route climbs above a terrain's last measured point.
    pub extrapolation: Option<Extrapolation>,
    /// The planner (grid, gradients, pitch tables), for figures and further routes.
    #[serde(skip)]
    pub planner: Planner,
}

/// Serialises [`PlanResult::routes`] as a list of `{"objective", "route" | "no_route"}`
/// objects.
fn routes_as_objects<S: Serializer>(
    routes: &[(Objective, Result<Route, NoRoute>)],
    serializer: S,
) -> Result<S::Ok, S::Error> {
    /// Why an objective has no route.
    #[derive(Serialize)]
    struct Missing {
        reason: NoRoute,
    }
    /// One objective's outcome.
    struct Outcome<'a>(Objective, &'a Result<Route, NoRoute>);
    impl Serialize for Outcome<'_> {
        fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
            let mut m = serializer.serialize_map(Some(2))?;
            m.serialize_entry("objective", &self.0)?;
            match self.1 {
                Ok(route) => m.serialize_entry("route", route)?,
                Err(e) => m.serialize_entry("no_route", &Missing { reason: *e })?,
            }
            m.end()
        }
    }
    let mut seq = serializer.serialize_seq(Some(routes.len()))?;
    for (objective, outcome) in routes {
        seq.serialize_element(&Outcome(*objective, outcome))?;
    }
    seq.end()
}

impl PlanResult {
    /// The route of `objective`, if it was planned.
    pub fn route(&self, objective: Objective) -> Option<&Result<Route, NoRoute>> {
        self.routes.iter().find(|(o, _)| *o == objective).map(|(_, r)| r)
    }
}

/// Plans `request` on `grid` for `robot`: builds the [`Planner`] (classes and terrains as
/// [`Planner::new`]), checks start and goal, searches every objective in parallel, and
/// computes the risk raster if asked. `progress(objective, settled, passable)` is called as
/// each search settles cells (every 65 536), with the number of passable cells as its scale;
/// returning `ControlFlow::Break(())` stops every search with [`PlanError::Stopped`].
///
/// Errors when the grid, classes, start or goal are unusable; an objective without a route is
/// `Err(NoRoute)` in [`PlanResult::routes`], not an error.
pub fn plan(
    grid: ElevationGrid,
    classes: Option<Vec<u8>>,
    terrains: &[UncertainTerrain],
    robot: &Robot,
    settings: PlanSettings,
    request: &PlanRequest,
    progress: &(dyn Fn(Objective, u64, u64) -> ControlFlow<()> + Sync),
) -> Result<PlanResult, PlanError> {
    let planner = Planner::new(grid, classes, terrains, robot, settings)?;
    planner.check_endpoint(request.start, "start")?;
    planner.check_endpoint(request.goal, "goal")?;
    let mut objectives = request.objectives.clone();
    objectives.push(Objective::Distance);
    objectives.sort();
    objectives.dedup();
    let passable = planner.passable_cells() as u64;
    let routes = objectives
        .par_iter()
        .map(|&obj| {
            let r = planner.route(obj, request.start, request.goal, &|n| progress(obj, n, passable))?;
            // Only the final position of the bar; a stop asked now changes nothing.
            let _ = progress(obj, passable, passable);
            Ok((obj, r))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let risk = request.risk_map.then(|| {
        let (p_fail, climb_azimuth_deg) = planner.risk_map();
        RiskRaster { p_fail, climb_azimuth_deg }
    });
    let extrapolation = extrapolation_of(&routes, planner.tables());
    Ok(PlanResult { start: request.start, goal: request.goal, routes, risk, extrapolation, planner })
}

/// Whether a route climbs above the last measured point of a terrain's table, and how far.
pub(super) fn extrapolation_of(
    routes: &[(Objective, Result<Route, NoRoute>)],
    tables: &[super::PitchTable],
) -> Option<Extrapolation> {
    let max_pitch_deg = routes
        .iter()
        .filter_map(|(_, r)| r.as_ref().ok())
        .map(|r| r.max_pitch_deg)
        .fold(f64::NEG_INFINITY, f64::max);
    tables
        .iter()
        .filter_map(|t| t.extrapolated_from_deg())
        .filter(|&last| max_pitch_deg > last)
        .map(|last_point_deg| Extrapolation { max_pitch_deg, last_point_deg })
        .next()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::tests::paper_robot;
    use crate::risk::Uncertainty;
    use crate::terrain::{Terrain, TerrainPoint, TerrainSpec};

    fn tilted(n: usize, grade: f64) -> ElevationGrid {
        // z = grade * x: every cell has the same slope atan(grade), rising to the east.
        let h: Vec<f64> = (0..n * n).map(|i| grade * (i % n) as f64).collect();
        ElevationGrid::from_heights(n, n, 1.0, 1.0, &h, None).unwrap()
    }

    /// A progress callback that never stops the searches.
    fn go_on(_: Objective, _: u64, _: u64) -> ControlFlow<()> {
        ControlFlow::Continue(())
    }

    /// What to plan from `start` to `goal` (columns and rows) for one objective.
    fn request(
        start: (usize, usize),
        goal: (usize, usize),
        objective: Objective,
        risk_map: bool,
    ) -> PlanRequest {
        let cell = |(col, row)| Cell { col, row };
        PlanRequest { start: cell(start), goal: cell(goal), objectives: vec![objective], risk_map }
    }

    /// [`plan`] for the paper's robot on `grid`, one class of `terrain` with CVs 0.1 and 0.2,
    /// default settings.
    fn plan_on(
        grid: ElevationGrid,
        terrain: &Terrain,
        request: &PlanRequest,
        progress: &(dyn Fn(Objective, u64, u64) -> ControlFlow<()> + Sync),
    ) -> Result<PlanResult, PlanError> {
        let class =
            vec![UncertainTerrain::with_uncertainty(terrain.clone(), Uncertainty::new(0.1, 0.2).unwrap())];
        plan(grid, None, &class, &paper_robot(), PlanSettings::default(), request, progress)
    }

    #[test]
    fn plans_every_objective_with_distance_added_and_reports_progress() {
        let seen = std::sync::Mutex::new(Vec::new());
        let sand = Terrain::constant(7e5, 2e6).unwrap();
        let r = plan_on(
            tilted(20, 0.1),
            &sand,
            &request((2, 10), (17, 10), Objective::Time, true),
            &|o, n, total| {
                seen.lock().unwrap().push((o, n, total));
                ControlFlow::Continue(())
            },
        )
        .unwrap();
        let objectives: Vec<Objective> = r.routes.iter().map(|(o, _)| *o).collect();
        assert_eq!(objectives, vec![Objective::Time, Objective::Distance]);
        // A uniform 5.7 degree grade straight east: the straight line, 15 cells of
        // sqrt(1 + 0.1^2) m each.
        let d = r.route(Objective::Distance).unwrap().as_ref().unwrap();
        assert!((d.length_m - 15.0 * 1.01_f64.sqrt()).abs() < 1e-4, "{}", d.length_m);
        // Interior cells: 18 x 18 passable; each search reports its end at that scale.
        let seen = seen.into_inner().unwrap();
        assert!(
            seen.contains(&(Objective::Time, 324, 324)) && seen.contains(&(Objective::Distance, 324, 324))
        );
        let risk = r.risk.unwrap();
        assert_eq!(risk.p_fail.len(), 400);
        assert!(risk.p_fail[0].is_nan() && risk.p_fail[21].is_finite());
        assert_eq!(r.extrapolation, None);
    }

    /// A progress callback that asks to stop ends every search at its first report. A 400 x 400
    /// level map cut by a column of missing heights (col 300) leaves the goal unreachable, so
    /// the search would settle the whole west side (about 398 x 298 cells) before giving up;
    /// told to stop at its first report (65 536 settled cells), it reports nothing more.
    #[test]
    fn a_progress_callback_can_stop_the_searches() {
        const NODATA: f64 = -9999.0;
        let n = 400;
        let h: Vec<f64> = (0..n * n).map(|i| if i % n == 300 { NODATA } else { 0.0 }).collect();
        let grid = ElevationGrid::from_heights(n, n, 1.0, 1.0, &h, Some(NODATA)).unwrap();
        let seen = std::sync::Mutex::new(Vec::new());
        let sand = Terrain::constant(7e5, 2e6).unwrap();
        let r = plan_on(
            grid,
            &sand,
            &request((1, 1), (350, 200), Objective::Distance, false),
            &|_, settled, _| {
                seen.lock().unwrap().push(settled);
                ControlFlow::Break(())
            },
        );
        assert!(matches!(r, Err(PlanError::Stopped)), "{:?}", r.err());
        assert_eq!(seen.into_inner().unwrap(), vec![65_536]);
    }

    /// The routes serialise as objects named by objective, a found route under `route` and a
    /// missing one under `no_route` with its reason, never as tuples or `Ok`/`Err`.
    #[test]
    fn routes_serialise_as_objects_by_objective() {
        // A 45 degree grade to the east: the distance route goes straight up it, the time
        // objective (success edges only) finds none.
        let sand = Terrain::constant(7e5, 2e6).unwrap();
        let r = plan_on(tilted(20, 1.0), &sand, &request((2, 10), (17, 10), Objective::Time, false), &go_on)
            .unwrap();
        let no_route = *r.route(Objective::Time).unwrap().as_ref().unwrap_err();
        let v = serde_json::to_value(&r).unwrap();
        let routes = v["routes"].as_array().unwrap();
        assert_eq!(routes.len(), 2);
        let time = routes[0].as_object().unwrap();
        assert_eq!(time.keys().collect::<Vec<_>>(), ["no_route", "objective"]);
        assert_eq!(time["objective"], "time");
        assert_eq!(time["no_route"]["reason"], serde_json::to_value(no_route).unwrap());
        assert_eq!(time["no_route"].as_object().unwrap().len(), 1, "{time:?}");
        let distance = routes[1].as_object().unwrap();
        assert_eq!(distance.keys().collect::<Vec<_>>(), ["objective", "route"]);
        assert_eq!(distance["objective"], "distance");
        // 15 cells of sqrt(1 + 1^2) m.
        let length = distance["route"]["length_m"].as_f64().unwrap();
        assert!((length - 15.0 * 2f64.sqrt()).abs() < 1e-4, "{length}");
        assert_eq!(distance["route"]["cells"].as_array().unwrap().len(), 16);
    }

    #[test]
    fn border_starts_are_refused_as_border_and_extrapolation_is_reported() {
        let pt = |slope_deg, k_s| TerrainPoint { slope_deg, k_n: 7e5, k_s, k_n_sd: None, k_s_sd: None };
        let terrain = Terrain::new(TerrainSpec {
            name: None,
            repose_deg: None,
            points: vec![pt(0.0, 2e6), pt(5.0, 1.9e6)],
        })
        .unwrap();
        let run = |start| {
            plan_on(tilted(20, 0.2), &terrain, &request(start, (17, 10), Objective::Time, false), &go_on)
        };
        let e = run((0, 10)).unwrap_err().to_string();
        assert!(e.contains("map border") && e.contains("impassable"), "{e}");
        // An 11.3 degree grade climbs above the last point at 5 degrees.
        let r = run((2, 10)).unwrap();
        let x = r.extrapolation.unwrap();
        assert_eq!(x.last_point_deg, 5.0);
        assert!((x.max_pitch_deg - 0.2_f64.atan().to_degrees()).abs() < 0.01, "{x:?}");
    }
}
