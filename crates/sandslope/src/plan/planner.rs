//! The 16-connected grid graph the planner searches ([`super::search`]; routes:
//! [`super::route`]; risk maps: [`super::risk_map`]).
//!
//! Nothing per edge is stored: a cell keeps its Horn gradient (2 x f32, NaN when impassable)
//! and its class (u8); an edge's cost is computed when it is relaxed, from the two cells'
//! gradients, the heading and the per-class cost table (cost per horizontal metre against
//! `tan(pitch)`).

use rayon::prelude::*;

use super::grid::{Cell, ElevationGrid};
use super::table::{PitchTable, PitchTableCache, TAN_STEP};
use super::{Descent, Objective, PlanError, PlanSettings};
use crate::regime::Regime;
use crate::risk::UncertainTerrain;
use crate::robot::Robot;

/// Number of headings: 8 neighbours and 8 knight moves.
pub const HEADINGS: usize = 16;

/// The 16 moves as `(d_col, d_row)`, clockwise from north (row 0 is north).
pub fn heading_offsets() -> [(isize, isize); HEADINGS] {
    [
        (0, -1),
        (1, -2),
        (1, -1),
        (2, -1),
        (1, 0),
        (2, 1),
        (1, 1),
        (1, 2),
        (0, 1),
        (-1, 2),
        (-1, 1),
        (-2, 1),
        (-1, 0),
        (-2, -1),
        (-1, -1),
        (-1, -2),
    ]
}

/// Class index meaning "no terrain here" (impassable).
pub const NO_CLASS: u8 = u8::MAX;

#[derive(Debug, Clone, Copy)]
pub(super) struct Move {
    pub(super) dc: isize,
    pub(super) dr: isize,
    /// Flat offsets of the two cells a knight move passes through (0 if not a knight move).
    pub(super) via: [isize; 2],
    /// The same two cells as `(d_col, d_row)` (for a corridor, whose rows start at different
    /// map columns).
    pub(super) via_at: [(isize, isize); 2],
}

/// A move's horizontal geometry from a cell of a given row: unit heading (east, north), f32
/// for the hot loop, and horizontal length, m.
#[derive(Debug, Clone, Copy)]
pub(super) struct MoveGeom {
    pub(super) ux: f32,
    pub(super) uy: f32,
    pub(super) len: f64,
}

/// The grid graph with the model tabulated on it; build once, plan many routes.
#[derive(Debug, Clone)]
pub struct Planner {
    pub(super) grid: ElevationGrid,
    pub(super) grad: Vec<[f32; 2]>,
    pub(super) class: Vec<u8>,
    pub(super) tables: Vec<PitchTable>,
    /// Cost per horizontal metre, `[objective][class][entry]` (infinite: impassable).
    costs: [Vec<Vec<f32>>; 3],
    /// Smallest entry of `costs[objective]`, scaled down a hair for f32 rounding.
    pub(super) min_cost: [f64; 3],
    pub(super) moves: [Move; HEADINGS],
    /// Each move's geometry on a grid whose rows are equally wide (row 0's otherwise), held
    /// inline: the uniform grid's search reads it as it read the moves before rows had widths.
    pub(super) geom0: [MoveGeom; HEADINGS],
    /// Each move's geometry from a cell of row `r`, `row_geoms[r]`, when the rows' widths
    /// differ; empty otherwise.
    pub(super) row_geoms: Vec<[MoveGeom; HEADINGS]>,
    pub(super) settings: PlanSettings,
    pub(super) tan_max_roll: f32,
    pub(super) cell_width: f64,
    /// Where the cells lie on the map.
    pub(super) layout: Layout,
}

/// Where a planner's cells lie on the map: the whole map (`col0` empty: cell indices are the
/// map's), or a corridor of it ([`super::corridor`]) whose local row `r` is the map's row
/// `row0 + r` from the map's column `col0[r]`, `width` cells wide (the grid's columns).
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) struct Layout {
    pub(super) row0: usize,
    pub(super) col0: Vec<isize>,
    pub(super) width: usize,
    pub(super) map_cols: usize,
    pub(super) map_rows: usize,
}

impl Layout {
    /// The whole of a `cols` x `rows` map.
    pub(super) fn whole(cols: usize, rows: usize) -> Layout {
        Layout { row0: 0, col0: Vec::new(), width: cols, map_cols: cols, map_rows: rows }
    }
    /// Whether the planner holds the whole map.
    pub(super) fn is_whole(&self) -> bool {
        self.col0.is_empty()
    }
    /// Number of cells held.
    pub(super) fn cells(&self) -> usize {
        if self.is_whole() {
            self.map_cols * self.map_rows
        } else {
            self.col0.len() * self.width
        }
    }
}

/// Pitch and roll of an edge, as tangents.
#[derive(Debug, Clone, Copy)]
pub(super) struct EdgeGeom {
    pub(super) tan_pitch: f32,
    pub(super) tan_roll: f32,
}

impl Planner {
    /// Builds the graph: Horn gradients, per-class pitch tables and cost tables.
    ///
    /// `classes`, if given, holds one class index per cell into `terrains` ([`NO_CLASS`]:
    /// impassable); without it every cell is class 0. Fails if `terrains` is empty or longer
    /// than 255, or `classes` has the wrong size or an index without terrain.
    pub fn new(
        grid: ElevationGrid,
        classes: Option<Vec<u8>>,
        terrains: &[UncertainTerrain],
        robot: &Robot,
        settings: PlanSettings,
    ) -> Result<Planner, PlanError> {
        Planner::build(grid, None, classes, terrains, robot, settings, None)
    }

    /// [`Planner::new`] with its pitch tables taken from (and kept in) `cache`: the same
    /// planner, built faster when the cache already holds the robot on these terrains (the
    /// tiles of a large map, repeated calls).
    pub fn with_cache(
        grid: ElevationGrid,
        classes: Option<Vec<u8>>,
        terrains: &[UncertainTerrain],
        robot: &Robot,
        settings: PlanSettings,
        cache: &PitchTableCache,
    ) -> Result<Planner, PlanError> {
        Planner::build(grid, None, classes, terrains, robot, settings, Some(cache))
    }

    /// The planner on `grid` (a corridor when `placed` gives its layout and gradients, else the
    /// whole map with its own Horn gradients).
    pub(super) fn build(
        grid: ElevationGrid,
        placed: Option<(Layout, Vec<[f32; 2]>)>,
        classes: Option<Vec<u8>>,
        terrains: &[UncertainTerrain],
        robot: &Robot,
        settings: PlanSettings,
        cache: Option<&PitchTableCache>,
    ) -> Result<Planner, PlanError> {
        if terrains.is_empty() || terrains.len() >= usize::from(NO_CLASS) {
            return Err(PlanError::Classes(format!(
                "{} terrains given; between 1 and 254 are supported",
                terrains.len()
            )));
        }
        let classed = classes.is_some();
        let class = match classes {
            None => vec![0; grid.len()],
            Some(c) if c.len() != grid.len() => {
                return Err(PlanError::Classes(format!(
                    "{} class cells for {} elevation cells",
                    c.len(),
                    grid.len()
                )))
            }
            Some(c) => {
                if let Some(bad) = c.iter().find(|&&k| k != NO_CLASS && usize::from(k) >= terrains.len()) {
                    return Err(PlanError::Classes(format!("class index {bad} has no terrain")));
                }
                c
            }
        };
        let (layout, mut grad) =
            placed.unwrap_or_else(|| (Layout::whole(grid.cols(), grid.rows()), grid.horn_gradient()));
        // Without classes every cell is class 0, and no cell is impassable by its class.
        if classed {
            grad.par_iter_mut().zip(class.par_iter()).for_each(|(g, &k)| {
                if k == NO_CLASS {
                    *g = [f32::NAN; 2];
                }
            });
        }
        // No edge is steeper than the steepest cell gradient (an edge averages two of them).
        // The squares of f32 components are exact in f64 and cannot overflow, so the largest
        // squared norm has its square root taken once (`hypot` per cell was 12 % of the CPU
        // before a 4096 x 4096 plan's searches).
        let max_tan = grad
            .par_iter()
            .filter(|g| !g[0].is_nan())
            .map(|g| f64::from(g[0]) * f64::from(g[0]) + f64::from(g[1]) * f64::from(g[1]))
            .reduce(|| 0.0, f64::max)
            .sqrt();
        let tables: Vec<PitchTable> = terrains
            .iter()
            .map(|t| match cache {
                Some(cache) => cache.table(robot, t, max_tan),
                None => PitchTable::new(robot, t, max_tan),
            })
            .collect();
        let cell_width = (grid.cell_x() * grid.cell_y()).sqrt();
        let costs = Objective::ALL
            .map(|obj| tables.iter().map(|t| cost_table(t, obj, &settings, cell_width)).collect::<Vec<_>>());
        let min_cost = std::array::from_fn(|o| {
            let m = costs[o].iter().flatten().fold(f32::INFINITY, |a, &b| a.min(b));
            if m.is_finite() {
                f64::from(m) * (1.0 - 1e-5)
            } else {
                0.0
            }
        });
        let cols = grid.cols() as isize;
        let geom_rows = if grid.row_widths().is_some() { grid.rows() } else { 1 };
        let geoms_of = |r: usize| {
            heading_offsets().map(|(dc, dr)| {
                let (ex, ny) = move_vector(&grid, r, dc, dr);
                let len = ex.hypot(ny);
                MoveGeom { ux: (ex / len) as f32, uy: (ny / len) as f32, len }
            })
        };
        let geom0 = geoms_of(0);
        let row_geoms = if geom_rows > 1 { (0..geom_rows).map(geoms_of).collect() } else { Vec::new() };
        let moves = heading_offsets().map(|(dc, dr)| {
            // A knight move's segment crosses two cells between its ends (a corner-to-corner
            // diagonal crosses none): both must be passable too.
            let via_at = if dc.abs() + dr.abs() == 3 {
                if dc.abs() == 2 {
                    [(dc.signum(), 0), (dc.signum(), dr)]
                } else {
                    [(0, dr.signum()), (dc, dr.signum())]
                }
            } else {
                [(0, 0); 2]
            };
            let via = via_at.map(|(c, r)| r * cols + c);
            Move { dc, dr, via, via_at }
        });
        let tan_max_roll = settings.max_roll().radians().tan() as f32;
        Ok(Planner {
            grid,
            grad,
            class,
            tables,
            costs,
            min_cost,
            moves,
            geom0,
            row_geoms,
            settings,
            tan_max_roll,
            cell_width,
            layout,
        })
    }

    /// The elevation grid.
    pub fn grid(&self) -> &ElevationGrid {
        &self.grid
    }
    /// The settings.
    pub fn settings(&self) -> &PlanSettings {
        &self.settings
    }
    /// The pitch table of each class.
    pub fn tables(&self) -> &[PitchTable] {
        &self.tables
    }
    /// The Horn gradient `(dz/dx, dz/dy)` of a cell, if it is passable.
    pub fn gradient(&self, cell: Cell) -> Option<[f64; 2]> {
        let g = self.grad[self.index_of(cell)?];
        (!g[0].is_nan()).then(|| [f64::from(g[0]), f64::from(g[1])])
    }
    /// Number of passable cells (those with a gradient and a class).
    pub fn passable_cells(&self) -> usize {
        self.grad.par_iter().filter(|g| !g[0].is_nan()).count()
    }

    /// Checks that `cell` can start or end a route: inside the grid, with a height, a Horn
    /// gradient and a terrain class. `which` names it in the error (`start` or `goal`).
    pub fn check_endpoint(&self, cell: Cell, which: &'static str) -> Result<usize, PlanError> {
        let (cols, rows) = (self.layout.map_cols, self.layout.map_rows);
        let i = self.index_of(cell).ok_or(PlanError::Outside { which, cell, cols, rows })?;
        let on_border = cell.col == 0 || cell.row == 0 || cell.col + 1 == cols || cell.row + 1 == rows;
        let reason = if !self.grid.is_valid(i) {
            "nodata"
        } else if self.class[i] == NO_CLASS {
            "without a terrain class"
        } else if self.grad[i][0].is_nan() && on_border {
            "on the map border, which is impassable (no slope can be computed there)"
        } else if self.grad[i][0].is_nan() {
            "next to nodata (no slope can be computed there)"
        } else {
            return Ok(i);
        };
        Err(PlanError::NoData { which, cell, reason })
    }

    /// The map cell of the planner's cell `i`.
    pub(super) fn cell_at(&self, i: usize) -> Cell {
        let c = self.grid.cell(i);
        match self.layout.col0.get(c.row) {
            None => c,
            Some(&c0) => Cell { col: (c0 + c.col as isize) as usize, row: self.layout.row0 + c.row },
        }
    }

    /// The planner's index of map cell `cell`, if it holds it.
    pub(super) fn index_of(&self, cell: Cell) -> Option<usize> {
        if self.layout.is_whole() {
            return self.grid.index(cell);
        }
        let r = cell.row.checked_sub(self.layout.row0)?;
        let c = usize::try_from(cell.col as isize - *self.layout.col0.get(r)?).ok()?;
        self.grid.index(Cell { col: c, row: r })
    }

    /// The planner's index of the map cell `(d_col, d_row)` away from its cell `u`, if it
    /// holds it.
    pub(super) fn offset_of(&self, u: usize, (dc, dr): (isize, isize)) -> Option<usize> {
        let c = self.cell_at(u);
        self.index_of(Cell { col: c.col.checked_add_signed(dc)?, row: c.row.checked_add_signed(dr)? })
    }

    /// The geometry of every move from a cell of the planner's row `r`.
    #[inline(always)]
    pub(super) fn geoms_at(&self, r: usize) -> &[MoveGeom; HEADINGS] {
        if self.row_geoms.is_empty() {
            &self.geom0
        } else {
            &self.row_geoms[r.min(self.row_geoms.len() - 1)]
        }
    }

    /// The geometry of move `k` from the planner's cell `u`.
    #[inline(always)]
    pub(super) fn move_geom(&self, u: usize, k: usize) -> &MoveGeom {
        &self.geoms_at(u / self.grid.cols())[k]
    }

    /// The 16 headings at a cell of row `r` in that row's own metric (`dc` columns of the
    /// row's width east, `dr` rows of `cell_y` south), with their azimuths, degrees clockwise
    /// from north: what the risk map scans (on a uniform grid, the moves' own geometry).
    pub(super) fn headings_in_row(&self, r: usize) -> [(MoveGeom, f64); HEADINGS] {
        let w = self.grid.cell_x_at(r);
        self.moves.map(|m| {
            let (ex, ny) = (m.dc as f64 * w, -(m.dr as f64) * self.grid.cell_y());
            let len = ex.hypot(ny);
            let g = MoveGeom { ux: (ex / len) as f32, uy: (ny / len) as f32, len };
            (g, ex.atan2(ny).to_degrees().rem_euclid(360.0))
        })
    }

    /// The azimuth of move `k` from the planner's cell `u`, degrees clockwise from north.
    pub(super) fn azimuth_deg(&self, u: usize, k: usize) -> f64 {
        let m = &self.moves[k];
        let (ex, ny) = move_vector(&self.grid, u / self.grid.cols(), m.dc, m.dr);
        ex.atan2(ny).to_degrees().rem_euclid(360.0)
    }

    #[inline(always)]
    pub(super) fn geom(&self, u: usize, v: usize, k: usize) -> EdgeGeom {
        Self::geom_of(self.grad[u], self.grad[v], self.move_geom(u, k))
    }

    /// Pitch and roll of the move of geometry `m` between cells of gradients `a` and `b`.
    #[inline(always)]
    pub(super) fn geom_of(a: [f32; 2], b: [f32; 2], m: &MoveGeom) -> EdgeGeom {
        let (gx, gy) = (0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]));
        EdgeGeom { tan_pitch: gx * m.ux + gy * m.uy, tan_roll: (gx * m.uy - gy * m.ux).abs() }
    }

    /// The neighbour of `u` along move `k` if it exists and is passable (and, for a knight
    /// move, so are the two cells it passes through).
    pub(super) fn neighbour(&self, u: usize, k: usize) -> Option<usize> {
        let m = &self.moves[k];
        let v = self.offset_of(u, (m.dc, m.dr)).filter(|&v| !self.grad[v][0].is_nan())?;
        let open = |d| self.offset_of(u, d).is_some_and(|w| !self.grad[w][0].is_nan());
        (m.via[0] == 0 || m.via_at.iter().all(|&d| open(d))).then_some(v)
    }

    /// Table entry used by the model for this edge (descent rule applied), and the entry of
    /// `|tan(pitch)|` used for the 3-D length; `None` beyond the steepest tabulated pitch.
    #[inline(always)]
    pub(super) fn entries(&self, e: EdgeGeom) -> Option<(usize, usize)> {
        // Rounded up by integer arithmetic: `f32::ceil` is a libm call without SSE4.1 (2 % of
        // a 4096 x 4096 plan in perf). NaN and negative values give 0, as `ceil` did.
        let x = e.tan_pitch.abs() * (1.0 / TAN_STEP as f32);
        let floor = x as usize;
        // Saturating: an infinite pitch (elevations of 1e38 in a corrupt DEM) casts to
        // usize::MAX, and is then beyond the table like any pitch too steep (found by fuzzing).
        let geometric = if (floor as f32) < x { floor.saturating_add(1) } else { floor };
        if geometric >= self.tables[0].len() {
            return None;
        }
        let model =
            if e.tan_pitch < 0.0 && self.settings.descent() == Descent::Level { 0 } else { geometric };
        Some((model, geometric))
    }

    /// Cost of edge `u -> v` along move `k` for `objective`; `None` if impassable.
    #[inline(always)]
    pub(super) fn edge_cost(&self, objective: Objective, u: usize, v: usize, k: usize) -> Option<f64> {
        self.cost_of(objective, self.geom(u, v, k), u, v, self.move_geom(u, k).len)
    }

    /// Cost of edge `u -> v` of horizontal length `len` whose pitch and roll are `e`.
    #[inline(always)]
    pub(super) fn cost_of(
        &self,
        objective: Objective,
        e: EdgeGeom,
        u: usize,
        v: usize,
        len: f64,
    ) -> Option<f64> {
        let physics = objective != Objective::Distance;
        if physics && e.tan_roll > self.tan_max_roll {
            return None;
        }
        let (model, geometric) = self.entries(e)?;
        let i = if physics { model } else { geometric };
        let t = &self.costs[objective as usize];
        // One class (the usual case) needs no look-up of the cells' classes.
        let per_m = if t.len() == 1 {
            t[0][i]
        } else {
            let (cu, cv) = (usize::from(self.class[u]), usize::from(self.class[v]));
            if cu == cv {
                t[cu][i]
            } else {
                0.5 * (t[cu][i] + t[cv][i])
            }
        };
        per_m.is_finite().then(|| len * f64::from(per_m))
    }

    /// The edges out of `cell` for `objective`: each passable neighbour with the edge's cost
    /// (seconds for `Time`, `-ln(survival)` plus weighted time for `Risk`, metres for
    /// `Distance`). This is the graph [`Planner::route`] searches, for use with other graph
    /// algorithms; empty where `cell` is outside the map or impassable.
    pub fn edges(&self, objective: Objective, cell: Cell) -> impl Iterator<Item = (Cell, f64)> + '_ {
        let u = self.index_of(cell).filter(|&u| !self.grad[u][0].is_nan());
        (0..HEADINGS).filter_map(move |k| {
            let u = u?;
            let v = self.neighbour(u, k)?;
            Some((self.cell_at(v), self.edge_cost(objective, u, v, k)?))
        })
    }
}

/// The horizontal vector (metres east, metres north) of the move `(dc, dr)` from a cell of row
/// `r`: `dr` rows of `cell_y` south, `dc` columns of the mean of the two end rows' widths east
/// (a row's width on a uniform grid; within 4e-6 of the haversine on 0.25-degree rows of a
/// geographic DEM, docs/model.md §8).
fn move_vector(grid: &ElevationGrid, r: usize, dc: isize, dr: isize) -> (f64, f64) {
    let width = match grid.row_widths() {
        None => grid.cell_x(),
        Some(_) => {
            let end = r.saturating_add_signed(dr);
            0.5 * (grid.cell_x_at(r) + grid.cell_x_at(end))
        }
    };
    (dc as f64 * width, -(dr as f64) * grid.cell_y())
}

/// Cost per horizontal metre at each table entry for `objective` (infinite: impassable).
fn cost_table(t: &PitchTable, objective: Objective, settings: &PlanSettings, cell_width: f64) -> Vec<f32> {
    (0..t.len())
        .map(|i| {
            let tan = PitchTable::tan_of(i);
            let sec = (1.0 + tan * tan).sqrt();
            let per_m_time = t.speed(i).filter(|&v| v > 0.0).map(|v| sec / v);
            let cost = match objective {
                Objective::Distance => Some(sec),
                Objective::Time => {
                    let r = t.regime(i);
                    let ok = r == Regime::Success || (settings.allow_metastable() && r == Regime::Metastable);
                    per_m_time.filter(|_| ok)
                }
                Objective::Risk => {
                    let p = t.p_fail(i);
                    let risk = (p < 1.0).then(|| -(-p).ln_1p() / cell_width);
                    let w = settings.time_weight();
                    match (risk, w > 0.0) {
                        (Some(r), true) => per_m_time.map(|tm| r + w * tm),
                        // Zero-risk edges would cost nothing, and any zero-risk detour would
                        // do: break such ties by length.
                        (r, false) => r.map(|r| r + super::RISK_TIE_BREAK_PER_M * sec),
                        (None, true) => None,
                    }
                }
            };
            cost.map_or(f32::INFINITY, |c| c as f32)
        })
        .collect()
}
