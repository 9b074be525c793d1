//! `sandslope plan`: heading-aware routes and risk maps over an elevation model.

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::{anyhow, bail, Context, Result};
use clap::{Args, ValueEnum};
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;

use sandslope::plan::{
    plan, plan_corridor, Cell, CorridorPlan, CorridorSettings, Descent, ElevationGrid, NoRoute, Objective,
    PlanRequest, PlanResult, PlanSettings, Planner, Route,
};
use sandslope::risk::{DefaultsUsed, UncertainTerrain};
use sandslope::{Regime, Robot};

use crate::args::{check_flag, RobotArgs, TerrainArgs, UncertaintyArgs};
use crate::figures::plan::PlanFigure;
use crate::output::print_json;
use sandslope_io::load_terrain;
use sandslope_io::raster::{read_heights_within, read_raster, write_two_band_geotiff, Raster};
use sandslope_io::routes as writers;

mod memory;
mod table;

use memory::choose_search;
use table::print_routes;

/// Maps at least this large get a progress bar (on a terminal).
const PROGRESS_MIN_CELLS: usize = 1 << 20;

/// `--objective` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, ValueEnum)]
pub enum ObjectiveArg {
    /// Fastest route through cells whose regime is success.
    Time,
    /// Maximum survival probability (plus --time-weight times the time).
    Risk,
    /// Shortest 3-D length, physics ignored (the naive baseline).
    Distance,
}

impl From<ObjectiveArg> for Objective {
    fn from(o: ObjectiveArg) -> Objective {
        match o {
            ObjectiveArg::Time => Objective::Time,
            ObjectiveArg::Risk => Objective::Risk,
            ObjectiveArg::Distance => Objective::Distance,
        }
    }
}

/// `--search` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SearchArg {
    /// Full resolution for maps of up to 4096 x 4096 cells, corridor above.
    Auto,
    /// The exact optimum over every cell of the map.
    Full,
    /// Coarse-to-fine: the exact optimum inside a corridor around a route planned on a
    /// coarsened map (not the full optimum: docs/planning.md measures the gap).
    Corridor,
}

/// `--search auto` searches maps of up to this many cells at full resolution (4096 x 4096) and
/// larger ones in a corridor.
pub const AUTO_FULL_MAX_CELLS: u64 = 1 << 24;

/// How the routes are searched for, as decided from the DEM's size.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Search {
    Full,
    /// With the bytes each corridor may take.
    Corridor(Option<u64>),
}

/// `--descent` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DescentArg {
    /// Descending evaluated as climbing |pitch| (docs/model.md §8 default).
    Symmetric,
    /// Descending evaluated as level ground (optimistic).
    Level,
}

/// Arguments of `sandslope plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// Elevation model: GeoTIFF (.tif), ESRI ASCII grid (.asc) or PDS3 DTM (.img, .lbl).
    #[arg(long, value_name = "FILE")]
    pub dem: PathBuf,
    /// Start in map coordinates.
    #[arg(long, value_name = "X,Y", allow_hyphen_values = true, required_unless_present = "start_px")]
    pub start: Option<String>,
    /// Goal in map coordinates.
    #[arg(long, value_name = "X,Y", allow_hyphen_values = true, required_unless_present = "goal_px")]
    pub goal: Option<String>,
    /// Start as a cell of the DEM (column, row from the north-west corner).
    #[arg(long, value_name = "COL,ROW", conflicts_with = "start", allow_hyphen_values = true)]
    pub start_px: Option<String>,
    /// Goal as a cell of the DEM (column, row from the north-west corner).
    #[arg(long, value_name = "COL,ROW", conflicts_with = "goal", allow_hyphen_values = true)]
    pub goal_px: Option<String>,
    /// What to minimise (comma-separated for several); the distance route is always added.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "time")]
    pub objective: Vec<ObjectiveArg>,
    #[command(flatten)]
    pub robot: RobotArgs,
    #[command(flatten)]
    pub terrain: TerrainArgs,
    /// Integer raster aligned with the DEM giving each cell's terrain class.
    #[arg(long, value_name = "FILE", requires = "class_terrain")]
    pub classes: Option<PathBuf>,
    /// Terrain of each class, e.g. `1=dune.toml,2=crust.toml` (files or presets).
    #[arg(long, value_name = "CLASS=TERRAIN,...", requires = "classes")]
    pub class_terrain: Option<String>,
    /// Let the time objective use metastable edges (0 < step < s_min).
    #[arg(long)]
    pub allow_metastable: bool,
    /// Risk objective: weight of travel time, per second (1e-4: 100 s weigh like a 1 % risk;
    /// 0: survival only, ties broken by length).
    #[arg(long, allow_negative_numbers = true, value_name = "PER_S", default_value_t = sandslope::plan::DEFAULT_TIME_WEIGHT)]
    pub time_weight: f64,
    /// Cross-slope (roll) limit, degrees: steeper cross slopes are impassable.
    #[arg(long, allow_negative_numbers = true, value_name = "DEG", default_value_t = 20.0)]
    pub max_roll: f64,
    /// How descending edges are evaluated.
    #[arg(long, value_enum, default_value = "symmetric")]
    pub descent: DescentArg,
    #[command(flatten)]
    pub uncertainty: UncertaintyArgs,
    /// Refuse a DEM whose planning would need more than this many GiB (default: the memory
    /// available when plan starts, MemAvailable in /proc/meminfo).
    #[arg(long, allow_negative_numbers = true, value_name = "GIB")]
    pub max_memory: Option<f64>,
    /// How to search: `full`, the exact optimum over the whole map (48 bytes a cell); `corridor`,
    /// coarse-to-fine for maps too large or slow for that: the routes planned on the map
    /// averaged over --coarse-factor cells, then the exact optimum at full resolution inside a
    /// corridor of --corridor-width coarse cells on each side of the coarse route (an upper
    /// bound on the full optimum; docs/planning.md measures the gap; one terrain, no --plot or
    /// --risk-map); `auto`, full for maps of up to 4096 x 4096 cells, corridor above.
    #[arg(long, value_enum, default_value = "auto")]
    pub search: SearchArg,
    /// Corridor search: fine cells per coarse cell along each axis (2 to 64).
    #[arg(long, value_name = "N", default_value_t = 8)]
    pub coarse_factor: usize,
    /// Corridor search: the corridor's half-width around the coarse route, in coarse cells (1 to 256).
    #[arg(long, value_name = "CELLS", default_value_t = 8)]
    pub corridor_width: usize,
    #[command(flatten)]
    pub out: Box<OutputArgs>,
}

/// Output files of `sandslope plan`.
#[derive(Debug, Args)]
pub struct OutputArgs {
    /// Write the routes as GeoJSON LineStrings in map coordinates.
    #[arg(long, value_name = "FILE")]
    pub geojson: Option<PathBuf>,
    /// Write one row per route vertex (x, y, z, heading, pitch, roll, regime, speed, p_fail).
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Draw hillshade, risk layer and routes (PNG or SVG).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Write a 2-band GeoTIFF: best-heading p_fail, steepest safe climb azimuth (deg from north).
    #[arg(long, value_name = "FILE")]
    pub risk_map: Option<PathBuf>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// One route as printed by `--json`. The keys are in alphabetical order, the order `plan --json`
/// has always printed (it went through a `serde_json::Value`).
#[derive(Debug, Serialize)]
pub struct RouteRecord {
    pub edges_over_roll_limit: Option<usize>,
    pub found: bool,
    pub length_m: Option<f64>,
    pub max_pitch_deg: Option<f64>,
    pub max_roll_deg: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub message: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<NoRoute>,
    pub regimes: Option<BTreeMap<&'static str, usize>>,
    pub survival: Option<f64>,
    pub time_s: Option<f64>,
}

impl RouteRecord {
    fn from(r: &Result<Route, NoRoute>) -> RouteRecord {
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

fn parse_pair(flag: &str, s: &str) -> Result<(f64, f64)> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    match parts.as_slice() {
        [a, b] => match (a.parse::<f64>(), b.parse::<f64>()) {
            (Ok(a), Ok(b)) if a.is_finite() && b.is_finite() => Ok((a, b)),
            _ => bail!("{flag} = `{s}` must be two numbers separated by a comma"),
        },
        _ => bail!("{flag} = `{s}` must be two numbers separated by a comma"),
    }
}

fn endpoint(
    raster: &Raster,
    grid: &ElevationGrid,
    which: &str,
    map: &Option<String>,
    px: &Option<String>,
) -> Result<Cell> {
    let (cols, rows) = (raster.cols, raster.rows);
    let g = &raster.geo;
    let (east, south) = (g.west + cols as f64 * g.cell_x, g.north - rows as f64 * g.cell_y);
    let (x, y) = if raster.crs.is_geographic() { ("longitude", "latitude") } else { ("x", "y") };
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
        let (c, r) = parse_pair(&format!("--{which}-px"), s)?;
        if c.fract() != 0.0 || r.fract() != 0.0 {
            bail!("--{which}-px = `{s}` must be whole column and row numbers");
        }
        (c, r, format!("--{which}-px {s}"), false)
    } else if let Some(s) = map {
        let (x, y) = parse_pair(&format!("--{which}"), s)?;
        let (c, r) = g.cell_of(x, y);
        // On the map's outline (e.g. its corner 0,0): inside the closed extent, but not in any cell.
        let on_edge = (g.west..=east).contains(&x) && (south..=g.north).contains(&y);
        (c, r, format!("--{which} {s}"), on_edge)
    } else {
        bail!("give --{which} X,Y or --{which}-px COL,ROW");
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
    if !grid.is_valid(cell.row * cols + cell.col) {
        bail!("{what} lies on a nodata cell (column {}, row {}) of the DEM", cell.col, cell.row);
    }
    Ok(cell)
}

/// A map coordinate for people: float noise from cell arithmetic removed (at most 9
/// significant decimals), so `51.449999999999996` prints as `51.45`.
fn round_coord(v: f64) -> f64 {
    sandslope_io::routes::round_coordinate(v)
}

/// Loads the terrain classes: one terrain everywhere, or a class raster with its terrains.
fn load_classes(args: &PlanArgs, dem: &Raster) -> Result<(Option<Vec<u8>>, Vec<UncertainTerrain>)> {
    // The one uncertainty rule of docs/model.md §9, per class; the note is printed once below.
    let uncertain = |t| args.uncertainty.apply(t).map(|(u, _note)| u);
    let (Some(path), Some(spec)) = (&args.classes, &args.class_terrain) else {
        return Ok((None, vec![uncertain(args.terrain.load()?)?]));
    };
    let mut values = Vec::new();
    let mut terrains = Vec::new();
    for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let (k, t) = item
            .split_once('=')
            .ok_or_else(|| anyhow!("--class-terrain: `{item}` must be CLASS=TERRAIN, e.g. 1=dune.toml"))?;
        let k: i64 =
            k.trim().parse().map_err(|_| anyhow!("--class-terrain: class `{k}` must be an integer"))?;
        if values.contains(&k) {
            bail!("--class-terrain: class {k} is given twice");
        }
        let terrain = load_terrain(t.trim()).with_context(|| format!("--class-terrain: class {k}"))?;
        values.push(k);
        terrains.push(uncertain(terrain)?);
    }
    if terrains.is_empty() || terrains.len() > 254 {
        bail!("--class-terrain: give between 1 and 254 CLASS=TERRAIN pairs");
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
    let idx =
        sandslope::plan::class_indices(&classes.values, |i| classes.is_nodata(i), &values).map_err(|e| {
            anyhow!(
                "{}: class {} ({} cells) has no terrain; add it to --class-terrain (given: {})",
                path.display(),
                e.value,
                e.cells,
                e.given
            )
        })?;
    Ok((Some(idx), terrains))
}

/// What `plan` reads and checks before any search: the DEM, the robot, the terrain classes and
/// the settings (the planner's inputs), shared by the routes and by risk maps without routes.
pub struct Inputs {
    /// The elevation model as read.
    pub dem: Raster,
    /// The robot.
    pub robot: Robot,
    /// Per-cell terrain class indices, when `--classes` is given.
    pub classes: Option<Vec<u8>>,
    /// The terrain of each class, with its uncertainty (docs/model.md §9).
    pub terrains: Vec<UncertainTerrain>,
    /// Roll limit, descent rule, metastable edges and time weight.
    pub settings: PlanSettings,
}

impl Inputs {
    /// Reads and checks everything `args` names except the endpoints (output folders are the
    /// caller's), printing the note on default CVs unless `quiet`.
    pub fn read(args: &PlanArgs, quiet: bool) -> Result<Inputs> {
        let robot = args.robot.load()?;
        let settings = settings(args)?;
        let dem = read_raster(&args.dem)?;
        let (classes, terrains) = classes_of(args, &dem, quiet)?;
        Ok(Inputs { dem, robot, classes, terrains, settings })
    }

    /// The elevation grid of the DEM (named after the file in errors).
    pub fn grid(&self, args: &PlanArgs) -> Result<ElevationGrid> {
        grid_of(&self.dem, args)
    }

    /// The planner over the whole DEM (for per-cell maps without routes).
    pub fn planner(&self, args: &PlanArgs) -> Result<Planner> {
        Planner::new(self.grid(args)?, self.classes.clone(), &self.terrains, &self.robot, self.settings)
            .map_err(|e| anyhow!("{}: {e}", args.dem.display()))
    }
}

/// The elevation grid of `dem`, read from `--dem` (named in errors).
fn grid_of(dem: &Raster, args: &PlanArgs) -> Result<ElevationGrid> {
    // The planner works in metres: the cell's ground size, not its size in map units (degrees
    // for a geographic DEM, feet for some projected ones).
    let (cell_x, cell_y) = dem.cell_m;
    let grid = ElevationGrid::from_heights(dem.cols, dem.rows, cell_x, cell_y, &dem.values, dem.nodata);
    with_rows_of(dem, grid, args)
}

/// `grid` with the east-west ground size of each of `dem`'s rows where they differ (a
/// geographic or equirectangular DEM: the cells narrow towards the pole).
fn with_rows_of(
    dem: &Raster,
    grid: Result<ElevationGrid, sandslope::plan::PlanError>,
    args: &PlanArgs,
) -> Result<ElevationGrid> {
    let grid = match &dem.row_widths_m {
        Some(w) => grid.and_then(|g| g.with_row_widths(w.clone())),
        None => grid,
    };
    grid.map_err(|e| anyhow!("{}: {e}", args.dem.display()))
}

/// [`load_classes`], with the note on default CVs printed unless `quiet`.
fn classes_of(
    args: &PlanArgs,
    dem: &Raster,
    quiet: bool,
) -> Result<(Option<Vec<u8>>, Vec<UncertainTerrain>)> {
    let (classes, terrains) = load_classes(args, dem)?;
    let defaults = terrains.iter().fold(DefaultsUsed::default(), |a, t| a.or(t.defaults_used()));
    if let (Some(note), false) = (defaults.note(), quiet) {
        eprintln!("note: {note}");
    }
    Ok((classes, terrains))
}

/// The settings the flags give, checked.
fn settings(args: &PlanArgs) -> Result<PlanSettings> {
    let max_roll = check_flag("--max-roll", args.max_roll, 0.0, 90.0)?;
    if max_roll <= 0.0 || max_roll >= 90.0 {
        bail!("--max-roll = {max_roll} must be strictly between 0 and 90 degrees");
    }
    let time_weight = check_flag("--time-weight", args.time_weight, 0.0, f64::INFINITY)?;
    args.uncertainty.check()?;
    let descent = match args.descent {
        DescentArg::Symmetric => Descent::Symmetric,
        DescentArg::Level => Descent::Level,
    };
    PlanSettings::new(max_roll, descent, args.allow_metastable, time_weight).map_err(|e| anyhow!("{e}"))
}

/// The routes `plan` found and the DEM they were planned on.
pub struct Planned {
    /// The elevation model as read (its georeference places the routes), its `values` released
    /// once the planner's grid holds the heights (`result.planner.grid()`).
    pub dem: Raster,
    /// The library's result.
    pub result: PlanResult,
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
fn records(routes: &[(Objective, Result<Route, NoRoute>)]) -> BTreeMap<&'static str, RouteRecord> {
    routes.iter().map(|(o, r)| (o.name(), RouteRecord::from(r))).collect()
}

/// The routes `plan` found in corridors (`--search corridor`) and what they were planned on.
pub struct CorridorPlanned {
    /// The elevation model's georeference (its heights are in `grid`).
    pub dem: Raster,
    /// The full-resolution grid.
    pub grid: ElevationGrid,
    /// The library's result.
    pub plan: CorridorPlan,
    /// How the corridors were made.
    pub settings: CorridorSettings,
}

/// What `plan` computed, by the search `--search` chose.
pub enum Computed {
    /// The full-resolution search.
    Full(Box<Planned>),
    /// The corridor search.
    Corridor(Box<CorridorPlanned>),
}

/// Reads the inputs of `args`, places start and goal and plans every objective at full
/// resolution, with the risk raster when `risk_map` (progress bars on a terminal for large
/// maps, notes on stderr, unless `quiet`); `--search corridor` is refused.
pub fn compute(args: &PlanArgs, risk_map: bool, quiet: bool) -> Result<Planned> {
    match compute_any(args, risk_map, true, quiet)? {
        Computed::Full(planned) => Ok(*planned),
        Computed::Corridor(_) => {
            bail!("search = corridor: only the full-resolution search is available here")
        }
    }
}

/// [`compute`] by the search `--search` chooses for the DEM's size (`full_only`: always the
/// full one, which the risk raster, the figure and terrain classes need).
pub fn compute_any(args: &PlanArgs, risk_map: bool, full_only: bool, quiet: bool) -> Result<Computed> {
    let robot = args.robot.load()?;
    let settings = settings(args)?;
    let objectives: Vec<Objective> = args.objective.iter().map(|&o| o.into()).collect();
    // The size is checked against the memory limit from the file's header, before its samples
    // are read (a 16384 x 16384 DEM is refused in a moment instead of after reading 3 GiB).
    let chosen = std::cell::Cell::new(Search::Full);
    let full_only = full_only || risk_map || args.classes.is_some();
    let (dem, heights) = read_heights_within(&args.dem, &|cols, rows| {
        chosen.set(choose_search(args, cols, rows, &objectives, full_only)?);
        Ok(())
    })?;
    if !quiet {
        for note in &dem.notes {
            eprintln!("note: {note}");
        }
    }
    // The planner works in metres: the cell's ground size, not its size in map units (degrees
    // for a geographic DEM, feet for some projected ones). Heights are f32, nodata NaN.
    let grid = ElevationGrid::new(dem.cols, dem.rows, dem.cell_m.0, dem.cell_m.1, heights, None);
    let grid = with_rows_of(&dem, grid, args)?;
    let start = endpoint(&dem, &grid, "start", &args.start, &args.start_px)?;
    let goal = endpoint(&dem, &grid, "goal", &args.goal, &args.goal_px)?;
    let (classes, terrains) = classes_of(args, &dem, quiet)?;
    let request = PlanRequest { start, goal, objectives, risk_map };
    let bars = Bars::new(!quiet && grid.len() >= PROGRESS_MIN_CELLS);
    let progress = |obj: Objective, n: u64, total: u64| {
        bars.set(obj, n, total);
        std::ops::ControlFlow::Continue(())
    };
    let computed = match chosen.get() {
        Search::Full => {
            let result = plan(grid, classes, &terrains, &robot, settings, &request, &progress)
                .map_err(|e| anyhow!("{}: {e}", args.dem.display()))?;
            Computed::Full(Box::new(Planned { dem, result }))
        }
        Search::Corridor(max_bytes) => {
            let (None, [terrain]) = (&classes, terrains.as_slice()) else {
                bail!("--classes needs the full-resolution search (--search full)");
            };
            let corridor = CorridorSettings::new(args.coarse_factor, args.corridor_width, max_bytes)
                .map_err(|e| anyhow!("{e}"))?;
            let plan = plan_corridor(&grid, terrain, &robot, settings, &request, &corridor, &progress)
                .map_err(|e| anyhow!("{}: {e}", args.dem.display()))?;
            Computed::Corridor(Box::new(CorridorPlanned { dem, grid, plan, settings: corridor }))
        }
    };
    bars.finish();
    Ok(computed)
}

/// A progress bar per objective on a terminal (hidden ones otherwise).
struct Bars {
    show: bool,
    multi: MultiProgress,
    style: ProgressStyle,
    bars: std::sync::Mutex<Vec<(Objective, ProgressBar)>>,
}

impl Bars {
    /// Bars drawn on stderr when `show` and stderr is a terminal.
    fn new(show: bool) -> Bars {
        let show = show && std::io::IsTerminal::is_terminal(&std::io::stderr());
        let multi = MultiProgress::with_draw_target(if show {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        });
        let style =
            ProgressStyle::with_template("{prefix:>9} {bar:40} {pos}/{len} cells settled ({elapsed})")
                .unwrap_or_else(|_| ProgressStyle::default_bar());
        let bars = Objective::ALL.iter().map(|&o| (o, ProgressBar::hidden())).collect();
        Bars { show, multi, style, bars: std::sync::Mutex::new(bars) }
    }

    /// `n` of `total` cells settled by the search of `obj`.
    fn set(&self, obj: Objective, n: u64, total: u64) {
        let mut bars = self.bars.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, bar)) = bars.iter_mut().find(|(o, _)| *o == obj) {
            if bar.is_hidden() && self.show {
                *bar = self
                    .multi
                    .add(ProgressBar::new(total).with_style(self.style.clone()).with_prefix(obj.name()));
            }
            bar.set_length(total);
            bar.set_position(n);
        }
    }

    fn finish(self) {
        for (_, bar) in self.bars.into_inner().unwrap_or_else(|e| e.into_inner()) {
            bar.finish();
        }
    }
}

/// Runs `sandslope plan`.
pub fn run(args: PlanArgs) -> Result<()> {
    // The flags are checked, in this order, before the output folders and any other file.
    args.robot.load()?;
    settings(&args)?;
    for p in [&args.out.plot].into_iter().flatten() {
        crate::figures::format_of(p)?;
    }
    // Every output folder is checked before any work, so a bad path cannot leave some of
    // the outputs written and others not.
    for p in [&args.out.geojson, &args.out.csv, &args.out.plot, &args.out.risk_map].into_iter().flatten() {
        crate::output::check_parent_exists(p)?;
    }
    if args.search == SearchArg::Corridor {
        for (flag, given) in [
            ("--plot", args.out.plot.is_some()),
            ("--risk-map", args.out.risk_map.is_some()),
            ("--classes", args.classes.is_some()),
        ] {
            if given {
                bail!("{flag} needs the full-resolution search: drop --search corridor (or crop the DEM)");
            }
        }
    }
    if !(2..=64).contains(&args.coarse_factor) {
        bail!("--coarse-factor = {} must be between 2 and 64", args.coarse_factor);
    }
    if !(1..=256).contains(&args.corridor_width) {
        bail!("--corridor-width = {} must be between 1 and 256 coarse cells", args.corridor_width);
    }
    let full_only = args.out.plot.is_some();
    match compute_any(&args, args.out.risk_map.is_some() || args.out.plot.is_some(), full_only, false)? {
        Computed::Full(planned) => run_full(&args, &planned),
        Computed::Corridor(planned) => run_corridor(&args, &planned),
    }
}

/// Writes and prints what the full-resolution search found.
fn run_full(args: &PlanArgs, planned: &Planned) -> Result<()> {
    let Planned { dem, result } = planned;
    if let Some(p) = &args.out.geojson {
        writers::write_geojson(p, &dem.geo, &result.routes)?;
    }
    if let Some(p) = &args.out.csv {
        writers::write_csv(p, &dem.geo, result.planner.grid(), &result.routes)?;
    }
    if let (Some(p), Some(risk)) = (&args.out.risk_map, &result.risk) {
        write_two_band_geotiff(p, dem.cols, dem.rows, &dem.geo, &risk.p_fail, &risk.climb_azimuth_deg)?;
    }
    if let (Some(p), Some(risk)) = (&args.out.plot, &result.risk) {
        crate::figures::save(p, &PlanFigure::new(result, &dem.geo, &risk.p_fail))?;
    }
    warn_extrapolation(result.extrapolation);
    if args.out.json {
        return print_json(&answer(planned));
    }
    print_routes(&result.routes, args.allow_metastable);
    Ok(())
}

/// Writes and prints what the corridor search found, saying how it was found.
fn run_corridor(args: &PlanArgs, planned: &CorridorPlanned) -> Result<()> {
    let CorridorPlanned { dem, grid, plan, settings } = planned;
    if let Some(p) = &args.out.geojson {
        writers::write_geojson(p, &dem.geo, &plan.routes)?;
    }
    if let Some(p) = &args.out.csv {
        writers::write_csv(p, &dem.geo, grid, &plan.routes)?;
    }
    warn_extrapolation(plan.extrapolation);
    let search = CorridorJson {
        mode: "corridor",
        coarse_factor: settings.factor(),
        corridor_width: settings.half_width(),
        coarse_size: plan.coarse_size,
        corridors: plan.corridors.iter().map(|c| (c.objective.name(), *c)).collect(),
    };
    if args.out.json {
        return print_json(&PlanJson { routes: records(&plan.routes), search: Some(search) });
    }
    print_routes(&plan.routes, args.allow_metastable);
    let cells: Vec<String> = plan
        .corridors
        .iter()
        .map(|c| {
            let extent =
                if c.whole { "the whole map".to_string() } else { format!("{} coarse cells", c.half_width) };
            format!("{} within {extent}, {} cells", c.objective.name(), c.corridor_cells)
        })
        .collect();
    println!(
        "note: planned coarse-to-fine (--search corridor): routes on the map averaged over {f} x {f} cells \
         ({} x {}), then the exact optimum at full resolution in a corridor around each ({}); the \
         full-resolution optimum may be cheaper (docs/planning.md measures by how much; --search full finds it)",
        plan.coarse_size.0,
        plan.coarse_size.1,
        cells.join("; "),
        f = settings.factor()
    );
    if plan.routes.iter().zip(&plan.corridors).any(|((_, r), c)| r.is_err() && !c.whole) {
        println!(
            "note: a route not found in its corridor may still exist on the whole map (the corridor could not be \
             widened to it within the memory limit): --search full decides"
        );
    }
    Ok(())
}

/// The warning for routes above a terrain's last measured point.
fn warn_extrapolation(extrapolation: Option<sandslope::plan::Extrapolation>) {
    if let Some(x) = extrapolation {
        eprintln!(
            "warning: routes reach {:.1} deg, above the terrain's last measured point ({} deg); k_n and k_s are \
             extrapolated linearly and floored at zero (docs/model.md §7)",
            x.max_pitch_deg, x.last_point_deg
        );
    }
}
