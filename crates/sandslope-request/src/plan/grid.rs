//! [`GridRequest`] and [`GridPlanRequest`]: a risk raster and routes over heights a front end
//! already holds (Python's `risk_raster` and `plan`, whose DEM is a NumPy array), where
//! [`PlanRequest`](super::PlanRequest) reads its DEM from a file. The fields are Python's
//! keywords and messages name them so; the settings, the descent rule and the objectives are
//! checked by the same functions as the file-based request's.

use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::LazyLock;

use anyhow::anyhow;
use serde::{Deserialize, Serialize};

use sandslope::plan::{Cell, ElevationGrid, PitchTableCache, PlanResult, PlanSettings, Planner, Route};
use sandslope::risk::UncertainTerrain;
use sandslope::{Robot, Terrain};

use crate::error::{RequestError, Result, Words};
use crate::grammar::uncertain_terrain_in;

use super::settings::{parse_descent, parse_objectives, settings_in};

/// The DEM's geometry and the planner's settings: what a risk raster needs (Python's
/// `risk_raster`), and the part of a [`GridPlanRequest`] that is not its route.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GridRequest {
    /// East-west ground size of a cell, m (`cell_x`).
    pub cell_x: f64,
    /// North-south ground size of a cell, m (`cell_y`).
    pub cell_y: f64,
    /// The east-west ground size of each row's cells, m, where they differ (a geographic
    /// DEM's; `row_widths_m`).
    pub row_widths_m: Option<Vec<f64>>,
    /// A height that marks a missing cell, besides NaN (`nodata`).
    pub nodata: Option<f64>,
    /// Coefficient of variation of k_n instead of the terrains' (`cv_n`).
    pub cv_n: Option<f64>,
    /// Coefficient of variation of k_s instead of the terrains' (`cv_s`).
    pub cv_s: Option<f64>,
    /// Cross-slope (roll) limit, degrees (`max_roll_deg`).
    pub max_roll_deg: f64,
    /// How descending edges are evaluated: `symmetric` or `level` (`descent`).
    pub descent: String,
    /// Let the time objective use metastable edges (`allow_metastable`).
    pub allow_metastable: bool,
    /// Risk objective: weight of travel time, per second (`time_weight`).
    pub time_weight: f64,
}

/// Routes over heights in memory (Python's `plan`): the grid's request, the endpoints as cells
/// and the objectives.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GridPlanRequest {
    /// The DEM's geometry and the planner's settings.
    #[serde(flatten)]
    pub grid: GridRequest,
    /// Start cell, `(row, col)` from the north-west corner (`start`).
    pub start: (i64, i64),
    /// Goal cell, `(row, col)` (`goal`).
    pub goal: (i64, i64),
    /// What to minimise: `time`, `risk` or `distance`, each item one word or a comma list of
    /// them (`objectives`).
    pub objectives: Vec<String>,
    /// Map coordinates of the DEM's north-west corner, m (`origin`): the routes' `x_m`, `y_m`;
    /// default `(0, rows * cell_y)`, the south-west corner at the origin.
    pub origin: Option<(f64, f64)>,
}

/// A terrain class raster as a front end holds it: one value per DEM cell (row-major; NaN: no
/// class) with its shape.
pub struct ClassRaster<'a> {
    /// The class of each cell.
    pub values: &'a [f64],
    /// `(rows, cols)` of the class raster.
    pub shape: (usize, usize),
}

/// What a grid request is answered on: the heights (row-major, row 0 north), the robot, the
/// terrain and, for routes, the optional class raster.
pub struct GridSource<'a> {
    /// The heights, m, `rows * cols` of them.
    pub heights: &'a [f64],
    /// Rows of the DEM.
    pub rows: usize,
    /// Columns of the DEM.
    pub cols: usize,
    /// The robot.
    pub robot: &'a Robot,
    /// The terrain everywhere without classes.
    pub terrain: &'a Terrain,
    /// The class raster (`classes`), given with `class_terrains` or not at all.
    pub classes: Option<ClassRaster<'a>>,
    /// Each class's terrain, `(class, terrain)` pairs (`class_terrains`).
    pub class_terrains: Option<Vec<(i64, &'a Terrain)>>,
}

/// The pitch tables of this process, shared by every risk raster: the tiles of a Dask raster
/// on one worker tabulate the model once, not once per tile (the table was 60% of a 1024 x
/// 1024 tile's time); results are bit for bit those of a fresh table.
static PITCH_TABLES: LazyLock<PitchTableCache> = LazyLock::new(PitchTableCache::new);

/// A library error, its key the keyword.
fn library(e: impl std::fmt::Display) -> RequestError {
    RequestError::from_error(None, anyhow!("{e}"))
}

impl GridRequest {
    /// The planner's settings, checked as the file-based request checks them.
    pub fn settings(&self) -> Result<PlanSettings> {
        let descent = parse_descent(Words::Keyword, &self.descent)?;
        settings_in(
            Words::Keyword,
            self.max_roll_deg,
            descent,
            self.allow_metastable,
            self.time_weight,
            self.cv_n,
            self.cv_s,
        )
    }

    /// The elevation grid of `source`'s heights (NaN or `nodata`: missing; float32, as the
    /// command line reads a DEM), with its rows' widths where given.
    pub fn grid(&self, source: &GridSource<'_>) -> Result<ElevationGrid> {
        let (rows, cols) = (source.rows, source.cols);
        ElevationGrid::from_heights(cols, rows, self.cell_x, self.cell_y, source.heights, self.nodata)
            .and_then(|g| match &self.row_widths_m {
                Some(w) => g.with_row_widths(w.clone()),
                None => Ok(g),
            })
            .map_err(|e| {
                RequestError::invalid(
                    "row-widths-m",
                    format!("{e} (row_widths_m: one width per row of the dem, in metres)"),
                )
            })
    }

    /// The terrain `terrain` read as uncertain by the one rule of docs/model.md §9.
    fn uncertain(&self, terrain: &Terrain) -> Result<UncertainTerrain> {
        Ok(uncertain_terrain_in(Words::Keyword, terrain.clone(), self.cv_n, self.cv_s)?.0)
    }

    /// Per cell, the lowest p_fail over the 16 headings and the azimuth of the steepest usable
    /// climb (degrees from north), as `sandslope plan --risk-map` writes them: `2 * rows *
    /// cols` values, band after band. The pitch tables are this process's
    /// ([`PitchTableCache`]).
    pub fn risk_raster(&self, source: &GridSource<'_>) -> Result<Vec<f32>> {
        let settings = self.settings()?;
        let terrain = self.uncertain(source.terrain)?;
        let grid = self.grid(source)?;
        let planner = Planner::with_cache(grid, None, &[terrain], source.robot, settings, &PITCH_TABLES)
            .map_err(library)?;
        let (mut p_fail, climb) = planner.risk_map();
        drop(planner);
        p_fail.extend_from_slice(&climb);
        Ok(p_fail)
    }

    /// Each cell's index into the terrains and the terrains with their uncertainty: `source`'s
    /// one terrain, or its classes by the rule of `sandslope plan --classes --class-terrain`.
    fn terrains(&self, source: &GridSource<'_>) -> Result<(Option<Vec<u8>>, Vec<UncertainTerrain>)> {
        let (classes, pairs) = match (&source.classes, &source.class_terrains) {
            (None, None) => return Ok((None, vec![self.uncertain(source.terrain)?])),
            (Some(classes), Some(pairs)) => (classes, pairs),
            _ => {
                return Err(RequestError::invalid(
                    super::CLASSES.flag,
                    "classes and class_terrains go together: give both or neither",
                ))
            }
        };
        let (rows, cols) = (source.rows, source.cols);
        if classes.shape != (rows, cols) {
            let (r, c) = classes.shape;
            return Err(RequestError::invalid(
                super::CLASSES.flag,
                format!("classes has shape ({r}, {c}); it must be the DEM's ({rows}, {cols})"),
            ));
        }
        if pairs.is_empty() || pairs.len() >= usize::from(sandslope::plan::NO_CLASS) {
            return Err(RequestError::invalid(
                "class-terrains",
                "class_terrains: give between 1 and 254 {class: terrain} pairs",
            ));
        }
        let keys: Vec<i64> = pairs.iter().map(|(k, _)| *k).collect();
        let terrains = pairs.iter().map(|(_, t)| self.uncertain(t)).collect::<Result<Vec<_>>>()?;
        let values = classes.values;
        let indices =
            sandslope::plan::class_indices(values, |i| !values[i].is_finite(), &keys).map_err(|e| {
                RequestError::invalid(super::CLASSES.flag, format!("classes: {e}; add it to class_terrains"))
            })?;
        Ok((Some(indices), terrains))
    }
}

/// An endpoint `(row, col)` inside a `rows` x `cols` map, or an error naming it.
fn cell(which: &str, (r, c): (i64, i64), rows: usize, cols: usize) -> Result<Cell> {
    if r < 0 || c < 0 || r as usize >= rows || c as usize >= cols {
        return Err(RequestError::invalid(
            which,
            format!(
                "{which} = ({r}, {c}) is outside the map: rows 0 to {}, columns 0 to {}",
                rows.saturating_sub(1),
                cols.saturating_sub(1)
            ),
        ));
    }
    Ok(Cell { col: c as usize, row: r as usize })
}

impl GridPlanRequest {
    /// The routes of every objective by the library's `plan::plan` (what `sandslope plan`
    /// computes), with `stop` looked at as each search goes: once it is raised the search ends
    /// and the answer is [`RequestError::interrupted`].
    pub fn answer(&self, source: &GridSource<'_>, stop: Option<&AtomicBool>) -> Result<PlanResult> {
        let objectives = parse_objectives(Words::Keyword, &self.objectives)?;
        let settings = self.grid.settings()?;
        let grid = self.grid.grid(source)?;
        let (rows, cols) = (grid.rows(), grid.cols());
        let request = sandslope::plan::PlanRequest {
            start: cell("start", self.start, rows, cols)?,
            goal: cell("goal", self.goal, rows, cols)?,
            objectives,
            risk_map: false,
        };
        let (classes, terrains) = self.grid.terrains(source)?;
        let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
        let progress = |_, _, _| if stopped() { ControlFlow::Break(()) } else { ControlFlow::Continue(()) };
        let result =
            sandslope::plan::plan(grid, classes, &terrains, source.robot, settings, &request, &progress);
        if stopped() {
            return Err(RequestError::interrupted());
        }
        result.map_err(library)
    }

    /// The cells of a found route as columns (what Python's `plan` returns beside its
    /// `--json` record): rows, columns, map coordinates of the cells' centres, heights and
    /// each step.
    pub fn route_cells(&self, route: &Route, planner: &Planner) -> RouteCells {
        let g = planner.grid();
        let (x0, y0) = self.origin.unwrap_or((0.0, g.rows() as f64 * g.cell_y()));
        let steps = &route.steps;
        RouteCells {
            rows: route.cells.iter().map(|c| c.row as i64).collect(),
            cols: route.cells.iter().map(|c| c.col as i64).collect(),
            // East of the west edge along the cell's own row: on a geographic DEM each row's
            // cells have their own width (`row_widths_m`), on a uniform grid this is cell_x.
            x_m: route.cells.iter().map(|c| x0 + (c.col as f64 + 0.5) * g.cell_x_at(c.row)).collect(),
            y_m: route.cells.iter().map(|c| y0 - (c.row as f64 + 0.5) * g.cell_y()).collect(),
            z_m: route.cells.iter().map(|&c| g.height(c).unwrap_or(f64::NAN)).collect(),
            heading_deg: steps.iter().map(|s| s.heading_deg).collect(),
            pitch_deg: steps.iter().map(|s| s.pitch_deg).collect(),
            roll_deg: steps.iter().map(|s| s.roll_deg).collect(),
            length_m: steps.iter().map(|s| s.length_m).collect(),
            regime: steps.iter().map(|s| s.regime as i8).collect(),
            speed_m_s: steps.iter().map(|s| s.speed.unwrap_or(f64::NAN)).collect(),
            p_fail: steps.iter().map(|s| s.p_fail).collect(),
            over_roll_limit: steps.iter().map(|s| s.over_roll_limit).collect(),
        }
    }
}

/// A found route's cells and steps as columns ([`GridPlanRequest::route_cells`]); NaN where a
/// height or a speed is absent.
#[derive(Debug, Clone, PartialEq)]
pub struct RouteCells {
    /// Each cell's row.
    pub rows: Vec<i64>,
    /// Each cell's column.
    pub cols: Vec<i64>,
    /// Each cell centre's easting, m.
    pub x_m: Vec<f64>,
    /// Each cell centre's northing, m.
    pub y_m: Vec<f64>,
    /// Each cell's height, m.
    pub z_m: Vec<f64>,
    /// Each step's heading, degrees from north.
    pub heading_deg: Vec<f64>,
    /// Each step's pitch, degrees.
    pub pitch_deg: Vec<f64>,
    /// Each step's roll, degrees.
    pub roll_deg: Vec<f64>,
    /// Each step's 3-D length, m.
    pub length_m: Vec<f64>,
    /// Each step's regime, its index in [`sandslope::Regime::ALL`].
    pub regime: Vec<i8>,
    /// Each step's speed, m/s.
    pub speed_m_s: Vec<f64>,
    /// Each step's failure probability.
    pub p_fail: Vec<f64>,
    /// Whether each step is steeper in roll than the limit.
    pub over_roll_limit: Vec<bool>,
}
