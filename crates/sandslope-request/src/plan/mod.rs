//! [`PlanRequest`]: heading-aware routes and risk maps over an elevation model (docs/model.md
//! §8, docs/planning.md): the DEM, start and goal, objectives, robot, terrain (one, or a class
//! raster with a terrain per class) and the search's settings, checked once, and the routes
//! planned at full resolution or in corridors.

use std::path::PathBuf;

use anyhow::{anyhow, bail, Context};
use serde::{Deserialize, Serialize};

use sandslope::plan::{
    plan, plan_corridor_from, Cell, CorridorPlan, CorridorSettings, Descent, ElevationGrid, Objective,
    PlanResult, PlanSettings, Planner,
};
use sandslope::risk::{DefaultsUsed, UncertainTerrain};
use sandslope::Robot;
use sandslope_io::height_windows::{open_height_windows, HeightWindows};
use sandslope_raster::{read_heights_within, read_raster, Raster};

use crate::error::{RequestError, Result, Words};
use crate::field::{Field, Fields, Table};
use crate::grammar;
use crate::params::Params;
use crate::scenario::{RobotRequest, TERRAIN};

mod answer;
mod grid;
mod memory;
mod risk_raster;
mod settings;

pub use answer::{answer, corridor_answer, records, CorridorJson, PlanJson, RouteRecord};
pub use grid::{ClassRaster, GridPlanRequest, GridRequest, GridSource, RouteCells};
use memory::choose_search;
pub use risk_raster::risk_band_rows;
pub use settings::{
    parse_descent, parse_objective, parse_objectives, settings_in, ALLOW_METASTABLE, CLASSES, CLASS_TERRAIN,
    COARSE_FACTOR, CORRIDOR_WIDTH, CV_N, CV_S, DEM, DESCENT, FIELDS, GOAL, GOAL_PX, MAX_MEMORY, MAX_ROLL,
    OBJECTIVE, SEARCH, START, START_PX, TIME_WEIGHT,
};

/// `search = auto` searches maps of up to this many cells at full resolution (4096 x 4096)
/// and larger ones in a corridor.
pub const AUTO_FULL_MAX_CELLS: u64 = 1 << 24;

/// How to search for the routes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PlanSearch {
    /// Full resolution for maps of up to 4096 x 4096 cells, corridor above.
    #[default]
    Auto,
    /// The exact optimum over every cell of the map.
    Full,
    /// Coarse-to-fine: the exact optimum inside a corridor around a route planned on a
    /// coarsened map.
    Corridor,
}

/// How the routes are searched for, as decided from the DEM's size.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Search {
    Full,
    /// With the bytes each corridor may take.
    Corridor(Option<u64>),
}

/// The inputs of `plan` (and `/api/plan`, whose DEM is the server's).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanRequest {
    /// Elevation model: GeoTIFF, ESRI ASCII grid or PDS3 DTM (field `dem`).
    pub dem: PathBuf,
    /// Start in map coordinates, `X,Y` as written (field `start`).
    pub start: Option<String>,
    /// Goal in map coordinates, `X,Y` as written (field `goal`).
    pub goal: Option<String>,
    /// Start as a cell, `COL,ROW` from the north-west corner as written (field `start-px`).
    pub start_px: Option<String>,
    /// Goal as a cell, `COL,ROW` as written (field `goal-px`).
    pub goal_px: Option<String>,
    /// What to minimise; the distance route is always added (field `objective`, a comma list
    /// of time, risk, distance; default time).
    pub objectives: Vec<Objective>,
    /// The robot.
    pub robot: RobotRequest,
    /// A terrain file or preset, used everywhere without `classes` (field `terrain`).
    pub terrain: String,
    /// An integer raster aligned with the DEM giving each cell's terrain class (field
    /// `classes`), and each class's terrain, `CLASS=TERRAIN,...` as written (field
    /// `class-terrain`).
    pub classes: Option<(PathBuf, String)>,
    /// Let the time objective use metastable edges (field `allow-metastable`).
    pub allow_metastable: bool,
    /// Risk objective: weight of travel time, per second (field `time-weight`).
    pub time_weight: f64,
    /// Cross-slope (roll) limit, degrees (field `max-roll`, default 20).
    pub max_roll: f64,
    /// How descending edges are evaluated (field `descent`: symmetric or level).
    pub descent: Descent,
    /// Coefficient of variation of k_n instead of the terrain's (field `cv-n`).
    pub cv_n: Option<f64>,
    /// Coefficient of variation of k_s instead of the terrain's (field `cv-s`).
    pub cv_s: Option<f64>,
    /// Refuse a DEM whose planning would need more than this many GiB (field `max-memory`;
    /// default the memory available).
    pub max_memory: Option<f64>,
    /// How to search (field `search`).
    pub search: PlanSearch,
    /// Corridor search: fine cells per coarse cell along each axis, 2 to 64 (field
    /// `coarse-factor`, default 8).
    pub coarse_factor: usize,
    /// Corridor search: the corridor's half-width in coarse cells, 1 to 256 (field
    /// `corridor-width`, default 8).
    pub corridor_width: usize,
}

impl Fields for PlanRequest {
    const TABLE: Table = FIELDS;
}

impl PlanRequest {
    /// Reads the fields of a plan request ([`FIELDS`], the robot's and the terrain's), each by
    /// its row: the one raw-to-typed step of the command line and the server; refuses any
    /// other key.
    pub fn from_params(params: &[(String, String)]) -> Result<PlanRequest> {
        Self::read(params, None)
    }

    /// The command line's request: its own fields from `params` (the flags given, by
    /// [`FIELDS`]), the robot and the terrain already read from the flags it shares with
    /// other commands.
    pub fn with_sources(params: &[(String, String)], sources: (RobotRequest, String)) -> Result<PlanRequest> {
        Self::read(params, Some(sources))
    }

    fn read(params: &[(String, String)], sources: Option<(RobotRequest, String)>) -> Result<PlanRequest> {
        let mut p = Params::new(FIELDS.command, params);
        let dem = DEM.text_in(&mut p)?.ok_or_else(|| {
            RequestError::invalid(DEM.flag, format!("{} is required: {}", DEM.long(), DEM.help))
        })?;
        let mut text = |f: &Field| f.text_in(&mut p).map(|t| t.map(str::to_string));
        let (start, goal, start_px, goal_px) =
            (text(&START)?, text(&GOAL)?, text(&START_PX)?, text(&GOAL_PX)?);
        for (map_field, px_field, map, px) in
            [(&START, &START_PX, &start, &start_px), (&GOAL, &GOAL_PX, &goal, &goal_px)]
        {
            match (map, px) {
                (None, None) => {
                    return Err(RequestError::invalid(
                        map_field.flag,
                        format!(
                            "give {} {} or {} {}",
                            map_field.long(),
                            map_field.value_name,
                            px_field.long(),
                            px_field.value_name
                        ),
                    ))
                }
                (Some(_), Some(_)) => {
                    return Err(RequestError::invalid(
                        px_field.flag,
                        format!("{} cannot be used with {}: give one", px_field.long(), map_field.long()),
                    ))
                }
                _ => {}
            }
        }
        let objectives = parse_objectives(Words::Flag, &[OBJECTIVE.text_in(&mut p)?.unwrap_or_default()])?;
        let (robot, terrain) = match sources {
            Some(sources) => sources,
            None => {
                (RobotRequest::from_params(&mut p)?, TERRAIN.text_in(&mut p)?.unwrap_or_default().to_string())
            }
        };
        let classes = match (CLASSES.text_in(&mut p)?, CLASS_TERRAIN.text_in(&mut p)?) {
            (None, None) => None,
            (Some(path), Some(spec)) => Some((PathBuf::from(path), spec.to_string())),
            (given, _) => {
                let (field, other) =
                    if given.is_some() { (&CLASSES, &CLASS_TERRAIN) } else { (&CLASS_TERRAIN, &CLASSES) };
                return Err(RequestError::invalid(
                    field.flag,
                    format!("{} needs {} too: give both or neither", field.long(), other.long()),
                ));
            }
        };
        let allow_metastable = ALLOW_METASTABLE.switch_in(&mut p)?;
        let time_weight = TIME_WEIGHT.required_number_in(&mut p)?;
        let max_roll = MAX_ROLL.required_number_in(&mut p)?;
        let descent = parse_descent(Words::Flag, DESCENT.text_in(&mut p)?.unwrap_or_default())?;
        let (cv_n, cv_s) = (CV_N.number_in(&mut p)?, CV_S.number_in(&mut p)?);
        let max_memory = MAX_MEMORY.number_in(&mut p)?;
        let search = match SEARCH.choice_in(&mut p)? {
            Some("full") => PlanSearch::Full,
            Some("corridor") => PlanSearch::Corridor,
            _ => PlanSearch::Auto,
        };
        let whole = |f: &Field, p: &mut Params<'_>| -> Result<usize> {
            Ok(f.whole_in(p)?.unwrap_or_default() as usize)
        };
        let coarse_factor = whole(&COARSE_FACTOR, &mut p)?;
        let corridor_width = whole(&CORRIDOR_WIDTH, &mut p)?;
        p.finish()?;
        Ok(PlanRequest {
            dem: PathBuf::from(dem),
            start,
            goal,
            start_px,
            goal_px,
            objectives,
            robot,
            terrain,
            classes,
            allow_metastable,
            time_weight,
            max_roll,
            descent,
            cv_n,
            cv_s,
            max_memory,
            search,
            coarse_factor,
            corridor_width,
        })
    }

    /// The settings the fields give, checked.
    pub fn settings(&self) -> Result<PlanSettings> {
        let (roll, weight) = (self.max_roll, self.time_weight);
        settings_in(Words::Flag, roll, self.descent, self.allow_metastable, weight, self.cv_n, self.cv_s)
    }

    /// Checks the corridor search's fields (2 to 64 cells a coarse cell, 1 to 256 coarse
    /// cells of half-width).
    pub fn check_corridor(&self) -> Result<()> {
        if !(2..=64).contains(&self.coarse_factor) {
            return Err(RequestError::invalid(
                COARSE_FACTOR.flag,
                format!("{} = {} must be between 2 and 64", COARSE_FACTOR.long(), self.coarse_factor),
            ));
        }
        if !(1..=256).contains(&self.corridor_width) {
            return Err(RequestError::invalid(
                CORRIDOR_WIDTH.flag,
                format!(
                    "{} = {} must be between 1 and 256 coarse cells",
                    CORRIDOR_WIDTH.long(),
                    self.corridor_width
                ),
            ));
        }
        Ok(())
    }

    /// Reads and checks everything but the endpoints: what a per-cell map without routes
    /// needs. `note` is told each note for the user (the DEM's, the default CVs').
    pub fn inputs(&self, note: &dyn Fn(&str)) -> Result<Inputs> {
        let robot = self.robot.load()?;
        let settings = self.settings()?;
        let dem = read_raster(&self.dem).map_err(|e| RequestError::from_error(Some(DEM.flag), e))?;
        let (classes, terrains) =
            self.classes_of(&dem, note).map_err(|e| RequestError::from_error(None, e))?;
        Ok(Inputs { dem, robot, classes, terrains, settings, dem_path: self.dem.clone() })
    }

    /// Reads the inputs, places start and goal and plans every objective at full resolution,
    /// with the risk raster when `risk_map`; a search the DEM's size sends to a corridor is
    /// refused.
    pub fn plan(
        &self,
        risk_map: bool,
        note: &dyn Fn(&str),
        progress: &(dyn Fn(Objective, u64, u64) + Sync),
    ) -> Result<Planned> {
        match self.compute(risk_map, true, note, progress)? {
            Computed::Full(planned) => Ok(*planned),
            Computed::Corridor(_) => Err(RequestError::invalid(
                SEARCH.flag,
                "search = corridor: only the full-resolution search is available here",
            )),
        }
    }

    /// The answer (what `plan --json` prints) of the full-resolution search.
    pub fn answer(&self) -> Result<PlanJson> {
        Ok(answer::answer(&self.plan(false, &|_| {}, &|_, _, _| {})?))
    }

    /// Plans by the search [`PlanRequest::search`] chooses for the DEM's size (`full_only`:
    /// always the full one, which a risk raster, a figure and terrain classes need), telling
    /// `progress` `(objective, cells settled, cells in all)` as each search goes and `note`
    /// each note for the user.
    ///
    /// Plans by the search [`PlanRequest::search`] chooses for the DEM's size (`full_only`:
    /// always the full one, which a risk raster, a figure and terrain classes need). The size
    /// is checked against the memory limit from the file's header, before its samples are
    /// read (a 16384 x 16384 DEM is refused in a moment instead of after reading 3 GiB).
    pub fn compute(
        &self,
        risk_map: bool,
        full_only: bool,
        note: &dyn Fn(&str),
        progress: &(dyn Fn(Objective, u64, u64) + Sync),
    ) -> Result<Computed> {
        let robot = self.robot.load()?;
        let settings = self.settings()?;
        let full_only = full_only || risk_map || self.classes.is_some();
        let dem_err = |e| RequestError::from_error(Some(DEM.flag), e);
        // The readers check what they allocate against the same limit.
        sandslope_raster::set_memory_limit(
            self.max_memory.filter(|gib| *gib > 0.0).map(|gib| (gib * (1u64 << 30) as f64) as u64),
        );
        // The header only (an ASCII grid is read whole): the search is chosen, and the DEM's
        // size checked against the memory limit, before any sample is read.
        let chosen = std::cell::Cell::new(Search::Full);
        let (head, windows) = open_height_windows(&self.dem, &|cols, rows, whole| {
            chosen.set(choose_search(self, cols, rows, &self.objectives, full_only, whole)?);
            Ok(())
        })
        .map_err(dem_err)?;
        let chosen = chosen.get();
        let anyhow_err = |e: anyhow::Error| RequestError::from_error(None, e);
        let request = |start, goal| sandslope::plan::PlanRequest {
            start,
            goal,
            objectives: self.objectives.clone(),
            risk_map,
        };
        let progress = |obj: Objective, n: u64, total: u64| {
            progress(obj, n, total);
            std::ops::ControlFlow::Continue(())
        };
        let in_dem = |e: &dyn std::fmt::Display| {
            RequestError::from_error(None, anyhow!("{}: {e}", self.dem.display()))
        };
        let Search::Corridor(max_bytes) = chosen else {
            let (dem, heights) = match windows.into_heights() {
                Some(heights) => (head, heights),
                None => read_heights_within(&self.dem, &|_, _| Ok(())).map_err(dem_err)?,
            };
            let valid = |c: Cell| heights[c.row * dem.cols + c.col].is_finite();
            let start = endpoint(&dem, &valid, (&START, &START_PX), &self.start, &self.start_px)?;
            let goal = endpoint(&dem, &valid, (&GOAL, &GOAL_PX), &self.goal, &self.goal_px)?;
            let (mut classes, terrains) = self.classes_of(&dem, note).map_err(anyhow_err)?;
            // A map wrapping in longitude is planned with its columns rolled across the seam.
            let (dem, heights, start, goal) = match across_seam(&dem, start, goal) {
                None => (dem, heights, start, goal),
                Some((shift, start, goal)) => {
                    let mut heights = heights;
                    heights.chunks_mut(dem.cols).for_each(|r| r.rotate_left(shift));
                    if let Some(c) = classes.as_mut() {
                        c.chunks_mut(dem.cols).for_each(|r| r.rotate_left(shift));
                    }
                    (dem.rolled_columns(shift), heights, start, goal)
                }
            };
            for n in &dem.notes {
                note(n);
            }
            // The planner works in metres: the cell's ground size, not its size in map units
            // (degrees for a geographic DEM, feet for some projected ones). Heights are f32,
            // nodata NaN.
            let grid = ElevationGrid::new(dem.cols, dem.rows, dem.cell_m.0, dem.cell_m.1, heights, None);
            let grid = self.with_rows_of(&dem, grid).map_err(anyhow_err)?;
            let result = plan(grid, classes, &terrains, &robot, settings, &request(start, goal), &progress)
                .map_err(|e| in_dem(&e))?;
            return Ok(Computed::Full(Box::new(Planned { dem, result })));
        };
        let dem = head;
        // Only the endpoints' cells are read here; the corridor search reads its windows.
        let valid =
            |c: Cell| windows.read(c.row..c.row + 1, c.col..c.col + 1).is_ok_and(|h| h[0].is_finite());
        let start = endpoint(&dem, &valid, (&START, &START_PX), &self.start, &self.start_px)?;
        let goal = endpoint(&dem, &valid, (&GOAL, &GOAL_PX), &self.goal, &self.goal_px)?;
        // A map wrapping in longitude is planned with its columns rolled across the seam.
        let (dem, windows, start, goal) = match across_seam(&dem, start, goal) {
            None => (dem, windows, start, goal),
            Some((shift, start, goal)) => {
                (dem.rolled_columns(shift), windows.rolled_columns(shift), start, goal)
            }
        };
        for n in &dem.notes {
            note(n);
        }
        let (classes, terrains) = self.classes_of(&dem, note).map_err(anyhow_err)?;
        let (None, [terrain]) = (&classes, terrains.as_slice()) else {
            return Err(RequestError::invalid(
                CLASSES.flag,
                format!("{} needs the full-resolution search ({} full)", CLASSES.long(), SEARCH.long()),
            ));
        };
        let corridor = CorridorSettings::new(self.coarse_factor, self.corridor_width, max_bytes)
            .map_err(|e| RequestError::from_error(None, anyhow!("{e}")))?;
        let plan = plan_corridor_from(
            &windows,
            terrain,
            &robot,
            settings,
            &request(start, goal),
            &corridor,
            &progress,
        )
        .map_err(|e| in_dem(&e))?;
        Ok(Computed::Corridor(Box::new(CorridorPlanned { dem, heights: windows, plan, settings: corridor })))
    }

    /// `grid` with the east-west ground size of each of `dem`'s rows where they differ (a
    /// geographic or equirectangular DEM: the cells narrow towards the pole).
    fn with_rows_of(
        &self,
        dem: &Raster,
        grid: std::result::Result<ElevationGrid, sandslope::plan::PlanError>,
    ) -> anyhow::Result<ElevationGrid> {
        let grid = match &dem.row_widths_m {
            Some(w) => grid.and_then(|g| g.with_row_widths(w.clone())),
            None => grid,
        };
        grid.map_err(|e| anyhow!("{}: {e}", self.dem.display()))
    }

    /// The terrain classes with the note on default CVs (docs/model.md §9) told once.
    fn classes_of(
        &self,
        dem: &Raster,
        note: &dyn Fn(&str),
    ) -> anyhow::Result<(Option<Vec<u8>>, Vec<UncertainTerrain>)> {
        let (classes, terrains) = self.load_classes(dem)?;
        let defaults = terrains.iter().fold(DefaultsUsed::default(), |a, t| a.or(t.defaults_used()));
        if let Some(n) = defaults.note() {
            note(&n);
        }
        Ok((classes, terrains))
    }

    /// Loads the terrain classes: one terrain everywhere, or a class raster with its terrains.
    fn load_classes(&self, dem: &Raster) -> anyhow::Result<(Option<Vec<u8>>, Vec<UncertainTerrain>)> {
        let uncertain = |t| {
            grammar::uncertain_terrain(t, self.cv_n, self.cv_s)
                .map(|(u, _note)| u)
                .map_err(RequestError::into_anyhow)
        };
        let load = |t: &str| sandslope_io::load_terrain(t);
        let Some((path, spec)) = &self.classes else {
            return Ok((None, vec![uncertain(load(&self.terrain)?)?]));
        };
        let flag = CLASS_TERRAIN.long();
        let mut values = Vec::new();
        let mut terrains = Vec::new();
        for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let (k, t) = item
                .split_once('=')
                .ok_or_else(|| anyhow!("{flag}: `{item}` must be CLASS=TERRAIN, e.g. 1=dune.toml"))?;
            let k: i64 = k.trim().parse().map_err(|_| anyhow!("{flag}: class `{k}` must be an integer"))?;
            if values.contains(&k) {
                bail!("{flag}: class {k} is given twice");
            }
            let terrain = load(t.trim()).with_context(|| format!("{flag}: class {k}"))?;
            values.push(k);
            terrains.push(uncertain(terrain)?);
        }
        if terrains.is_empty() || terrains.len() > 254 {
            bail!("{flag}: give between 1 and 254 CLASS=TERRAIN pairs");
        }
        let classes = read_raster(path)?;
        if classes.cols != dem.cols || classes.rows != dem.rows || !classes.geo.aligned(&dem.geo) {
            bail!(
                "{}: the class raster ({} x {}) must be aligned with the DEM ({} x {}): same size, origin and cell size",
                path.display(),
                classes.cols,
                classes.rows,
                dem.cols,
                dem.rows
            );
        }
        let idx = sandslope::plan::class_indices(&classes.values, |i| classes.is_nodata(i), &values)
            .map_err(|e| {
                anyhow!(
                    "{}: class {} ({} cells) has no terrain; add it to {flag} (given: {})",
                    path.display(),
                    e.value,
                    e.cells,
                    e.given
                )
            })?;
        Ok((Some(idx), terrains))
    }
}

/// For a map that wraps in longitude (sandslope_raster::wraps_in_longitude), the column
/// roll that moves its edges opposite the endpoints, and the endpoints in the rolled map.
fn across_seam(dem: &Raster, start: Cell, goal: Cell) -> Option<(usize, Cell, Cell)> {
    use sandslope_raster::{rolled_column, seam_roll, wraps_in_longitude};
    if !wraps_in_longitude(dem) {
        return None;
    }
    let shift = seam_roll(dem.cols, start.col, goal.col);
    let roll = |c: Cell| Cell { col: rolled_column(c.col, dem.cols, shift), row: c.row };
    Some((shift, roll(start), roll(goal)))
}

fn parse_pair(flag: &str, s: &str) -> anyhow::Result<(f64, f64)> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    match parts.as_slice() {
        [a, b] => match (a.parse::<f64>(), b.parse::<f64>()) {
            (Ok(a), Ok(b)) if a.is_finite() && b.is_finite() => Ok((a, b)),
            _ => bail!("{flag} = `{s}` must be two numbers separated by a comma"),
        },
        _ => bail!("{flag} = `{s}` must be two numbers separated by a comma"),
    }
}

/// The cell of an endpoint given in map coordinates (`map`) or as a cell (`px`), inside the
/// map and not on nodata; errors name the field.
fn endpoint(
    raster: &Raster,
    valid: &dyn Fn(Cell) -> bool,
    fields: (&Field, &Field),
    map: &Option<String>,
    px: &Option<String>,
) -> Result<Cell> {
    let field = if px.is_some() { fields.1 } else { fields.0 };
    endpoint_cell(raster, valid, fields, map, px).map_err(|e| RequestError::from_error(Some(field.flag), e))
}

fn endpoint_cell(
    raster: &Raster,
    valid: &dyn Fn(Cell) -> bool,
    (map_field, px_field): (&Field, &Field),
    map: &Option<String>,
    px: &Option<String>,
) -> anyhow::Result<Cell> {
    let (map_flag, px_flag) = (map_field.long(), px_field.long());
    let (cols, rows) = (raster.cols, raster.rows);
    let g = &raster.geo;
    let (east, south) = (g.west + cols as f64 * g.cell_x, g.north - rows as f64 * g.cell_y);
    let (x, y) = if raster.crs.is_geographic() { ("longitude", "latitude") } else { ("x", "y") };
    let round_coord = sandslope_io::routes::round_coordinate;
    let extent = format!(
        "{x} {} to {} and {y} {} to {}, columns 0 to {} and rows 0 to {}",
        round_coord(g.west),
        round_coord(east),
        round_coord(south),
        round_coord(g.north),
        cols - 1,
        rows - 1
    );
    let (c, r, what, on_edge) = if let Some(s) = px {
        let (c, r) = parse_pair(&px_flag, s)?;
        if c.fract() != 0.0 || r.fract() != 0.0 {
            bail!("{px_flag} = `{s}` must be whole column and row numbers");
        }
        (c, r, format!("{px_flag} {s}"), false)
    } else if let Some(s) = map {
        let (x, y) = parse_pair(&map_flag, s)?;
        // A longitude is the same place 360 degrees on: -10 on a map of 0 to 360 east (a MOLA
        // MEGDR's) is 350.
        let x = if raster.crs.is_geographic() && !(g.west..=east).contains(&x) {
            [x + 360.0, x - 360.0].into_iter().find(|v| (g.west..=east).contains(v)).unwrap_or(x)
        } else {
            x
        };
        let (c, r) = g.cell_of(x, y);
        // On the map's outline (e.g. its corner 0,0): inside the closed extent, but not in any cell.
        let on_edge = (g.west..=east).contains(&x) && (south..=g.north).contains(&y);
        (c, r, format!("{map_flag} {s}"), on_edge)
    } else {
        bail!("give {map_flag} {} or {px_flag} {}", map_field.value_name, px_field.value_name);
    };
    let outside = c < 0.0 || r < 0.0 || c >= cols as f64 || r >= rows as f64;
    if outside && on_edge {
        bail!(
            "{what} lies on the edge of the map ({extent}); the border is impassable, no slope can be computed \
             there: pick a point at least one cell ({} m) inside",
            round_coord(g.cell_x.max(g.cell_y))
        );
    }
    if outside {
        bail!("{what} is outside the map: {extent}");
    }
    let cell = Cell { col: c as usize, row: r as usize };
    if !valid(cell) {
        bail!("{what} lies on a nodata cell (column {}, row {}) of the DEM", cell.col, cell.row);
    }
    Ok(cell)
}

/// What `plan` reads and checks before any search: the DEM, the robot, the terrain classes and
/// the settings (the planner's inputs), shared by the routes and by risk maps without routes.
pub struct Inputs {
    /// The elevation model as read.
    pub dem: Raster,
    /// The robot.
    pub robot: Robot,
    /// Per-cell terrain class indices, when classes are given.
    pub classes: Option<Vec<u8>>,
    /// The terrain of each class, with its uncertainty (docs/model.md §9).
    pub terrains: Vec<UncertainTerrain>,
    /// Roll limit, descent rule, metastable edges and time weight.
    pub settings: PlanSettings,
    dem_path: PathBuf,
}

impl Inputs {
    /// The planner over the whole DEM (for per-cell maps without routes).
    pub fn planner(&self) -> Result<Planner> {
        let in_dem = |e: &dyn std::fmt::Display| {
            RequestError::from_error(None, anyhow!("{}: {e}", self.dem_path.display()))
        };
        let dem = &self.dem;
        let (cell_x, cell_y) = dem.cell_m;
        let grid = ElevationGrid::from_heights(dem.cols, dem.rows, cell_x, cell_y, &dem.values, dem.nodata);
        let grid = match &dem.row_widths_m {
            Some(w) => grid.and_then(|g| g.with_row_widths(w.clone())),
            None => grid,
        }
        .map_err(|e| in_dem(&e))?;
        Planner::new(grid, self.classes.clone(), &self.terrains, &self.robot, self.settings)
            .map_err(|e| in_dem(&e))
    }
}

/// The routes `plan` found at full resolution and the DEM they were planned on.
pub struct Planned {
    /// The elevation model as read (its georeference places the routes), its `values` released
    /// once the planner's grid holds the heights (`result.planner.grid()`).
    pub dem: Raster,
    /// The library's result.
    pub result: PlanResult,
}

/// The routes `plan` found in corridors and what they were planned on.
pub struct CorridorPlanned {
    /// The elevation model's georeference (its heights are in `grid`).
    pub dem: Raster,
    /// The map's heights, read window by window (the corridor search never holds them whole).
    pub heights: HeightWindows,
    /// The library's result.
    pub plan: CorridorPlan,
    /// How the corridors were made.
    pub settings: CorridorSettings,
}

/// What `plan` computed, by the search chosen.
pub enum Computed {
    /// The full-resolution search.
    Full(Box<Planned>),
    /// The corridor search.
    Corridor(Box<CorridorPlanned>),
}
