//! Coarse-to-fine planning for maps too large for the full-resolution search (issue 24).
//!
//! The map is averaged into coarse cells of `factor x factor` fine cells
//! ([`ElevationGrid::coarsened`]) and each objective is planned on the coarse grid; the fine
//! search then runs at full resolution, exactly, but only inside a corridor: the fine cells
//! within `half_width` coarse cells (Chebyshev distance) of the coarse route and of the start's
//! and goal's coarse cells. A corridor is held as rows of one common width, row `r` starting at
//! its own map column (the planner's `Layout`), so a diagonal corridor costs its own cells, not
//! its bounding box.
//!
//! What this gives up: the fine route is the optimum among routes inside the corridor, not over
//! the whole map. Every corridor route is a route of the full graph, with the same edges, costs
//! and statistics (the gradients are the full map's, edges leaving the corridor are dropped),
//! so its cost is an upper bound on the full optimum; the gap is measured against the full
//! search where that fits (docs/planning.md). A passage narrower than a coarse cell can be
//! missed by the coarse route (it then goes around it, or finds no route).

use std::ops::ControlFlow;

use rayon::prelude::*;
use serde::Serialize;

use super::grid::{Cell, ElevationGrid};
use super::planner::{Layout, Planner};
use super::result::{extrapolation_of, Extrapolation, PlanRequest};
use super::route::Route;
use super::source::{coarsened_from, HeightSource};
use super::table::PitchTableCache;
use super::{NoRoute, Objective, PlanError, PlanSettings, PLANNER_BYTES_PER_CELL, SEARCH_BYTES_PER_CELL};
use crate::risk::UncertainTerrain;
use crate::robot::Robot;

/// How the corridor search is set up; validated by [`CorridorSettings::new`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct CorridorSettings {
    factor: usize,
    half_width: usize,
    #[serde(skip)]
    max_bytes: Option<u64>,
}

impl CorridorSettings {
    /// `factor` fine cells per coarse cell along each axis (2 to 64), a corridor of
    /// `half_width` coarse cells (1 to 256) on each side of the coarse route, and, if given, the
    /// most bytes one corridor's planner and search may take (checked before they are built).
    pub fn new(
        factor: usize,
        half_width: usize,
        max_bytes: Option<u64>,
    ) -> Result<CorridorSettings, PlanError> {
        if !(2..=64).contains(&factor) {
            return Err(PlanError::Grid(format!("coarse factor = {factor} must be between 2 and 64")));
        }
        if !(1..=256).contains(&half_width) {
            return Err(PlanError::Grid(format!(
                "corridor half-width = {half_width} coarse cells must be between 1 and 256"
            )));
        }
        Ok(CorridorSettings { factor, half_width, max_bytes })
    }
    /// Fine cells per coarse cell along each axis.
    pub fn factor(&self) -> usize {
        self.factor
    }
    /// Corridor half-width, coarse cells.
    pub fn half_width(&self) -> usize {
        self.half_width
    }
}

/// Bytes per fine cell of the map that the corridor search holds besides its corridors: the
/// grid (an `f32` height and a validity flag).
pub const CORRIDOR_MAP_BYTES_PER_CELL: u64 = 4 + 1;

/// Bytes per corridor cell: a planner's cell and one search's.
pub const CORRIDOR_BYTES_PER_CELL: u64 = PLANNER_BYTES_PER_CELL + SEARCH_BYTES_PER_CELL;

/// What the corridor search did for one objective.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CorridorStats {
    /// The objective.
    pub objective: Objective,
    /// Cost of the coarse route (the objective's units), if there was one.
    pub coarse_cost: Option<f64>,
    /// The corridor's half-width in the end, coarse cells: the one asked for, or wider when
    /// that corridor held no route.
    pub half_width: usize,
    /// Fine cells in the corridor.
    pub corridor_cells: usize,
    /// Whether the corridor was the whole map (the route is then the full optimum, and no
    /// route means none exists).
    pub whole: bool,
    /// The route's cost (the objective's units), if one was found.
    pub cost: Option<f64>,
    /// A lower bound on the cost of any route between the endpoints over the whole map: the
    /// straight line between them, east-west at the map's narrowest row width, times the
    /// cheapest cost per metre of the pitch tables (the A* heuristic at the start). The full
    /// optimum lies between it and `cost`.
    pub lower_bound: f64,
    /// `cost / lower_bound - 1`: the most the route can cost above the full optimum, as a
    /// fraction (a bound, often loose where routes must switch back; `null` without a route
    /// or a zero bound). 0 when the corridor was the whole map.
    pub gap_at_most: Option<f64>,
}

/// What [`plan_corridor`] computed.
#[derive(Debug, Clone, Serialize)]
pub struct CorridorPlan {
    /// The route of each objective, or why none exists, in [`Objective`] order.
    pub routes: Vec<(Objective, Result<Route, NoRoute>)>,
    /// Per objective, the coarse route's cost and the corridor's size.
    pub corridors: Vec<CorridorStats>,
    /// The coarse grid's size (columns, rows).
    pub coarse_size: (usize, usize),
    /// Set when a route climbs above a terrain's last measured point.
    pub extrapolation: Option<Extrapolation>,
}

/// Plans `request` on `grid` coarse-to-fine ([module docs](self)): one terrain everywhere, no
/// risk raster. `progress(objective, settled, corridor passable cells)` as in
/// [`super::plan`], for the fine searches.
///
/// Errors as [`super::plan`], and when a corridor would need more than the settings' byte
/// limit. Where the corridor holds no route (or the coarse grid has none: the corridor is then
/// the start's and goal's surroundings), it is widened, twice as wide each time, until it holds
/// one or is the whole map, as far as the byte limit allows; [`CorridorStats`] says how wide it
/// ended and whether it was the whole map (only then is a missing route known not to exist).
pub fn plan_corridor(
    grid: &ElevationGrid,
    terrain: &UncertainTerrain,
    robot: &Robot,
    settings: PlanSettings,
    request: &PlanRequest,
    corridor: &CorridorSettings,
    progress: &(dyn Fn(Objective, u64, u64) -> ControlFlow<()> + Sync),
) -> Result<CorridorPlan, PlanError> {
    plan_corridor_from(grid, terrain, robot, settings, request, corridor, progress)
}

/// [`plan_corridor`] on a map read window by window ([`HeightSource`], issue 56): the coarse
/// grid from one pass over bands of rows ([`coarsened_from`]), each corridor from the windows
/// its rows cover; the whole map is never held. On the same heights it plans exactly what
/// [`plan_corridor`] plans on a grid holding them (the same coarse grid, heights and Horn
/// gradients, bit for bit).
pub fn plan_corridor_from(
    source: &dyn HeightSource,
    terrain: &UncertainTerrain,
    robot: &Robot,
    settings: PlanSettings,
    request: &PlanRequest,
    corridor: &CorridorSettings,
    progress: &(dyn Fn(Objective, u64, u64) -> ControlFlow<()> + Sync),
) -> Result<CorridorPlan, PlanError> {
    let (cols, rows) = (source.cols(), source.rows());
    for (which, cell) in [("start", request.start), ("goal", request.goal)] {
        if cell.col >= cols || cell.row >= rows {
            return Err(PlanError::Outside { which, cell, cols, rows });
        }
    }
    let terrains = std::slice::from_ref(terrain);
    let cache = PitchTableCache::new();
    let coarse = Planner::with_cache(
        coarsened_from(source, corridor.factor)?,
        None,
        terrains,
        robot,
        settings,
        &cache,
    )?;
    let mut objectives = request.objectives.clone();
    objectives.push(Objective::Distance);
    objectives.sort();
    objectives.dedup();
    let coarse_cells = coarse.passable_cells() as u64;
    let planned = objectives
        .par_iter()
        .map(|&obj| {
            let route = coarse_route(&coarse, obj, request, corridor, &|n| progress(obj, n, coarse_cells))?;
            let coarse_cost = route.as_ref().map(|r| coarse.cost_of_route(obj, &r.cells));
            let cells = route.map_or_else(Vec::new, |r| r.cells);
            // Widened (twice as wide each time) while the corridor holds no route and not yet
            // the whole map, as far as the byte limit allows.
            let mut wider = *corridor;
            let mut found = None;
            loop {
                let (layout, spans) = match corridor_layout((cols, rows), &cells, request, &wider) {
                    Ok(corridor) => corridor,
                    Err(e) => match found {
                        Some(found) => break Ok(found),
                        None => break Err(e),
                    },
                };
                let corridor_cells = spans.iter().map(|s| s.1 - s.0).sum();
                let whole = corridor_cells == cols * rows;
                let p = Planner::corridor_from(source, layout, &spans, terrains, robot, settings, &cache)?;
                let passable = p.passable_cells() as u64;
                let r = p.route(obj, request.start, request.goal, &|n| progress(obj, n, passable))?;
                // Only the final position of the bar; a stop asked now changes nothing.
                let _ = progress(obj, passable, passable);
                let cost = r.as_ref().ok().map(|route| p.cost_of_route(obj, &route.cells));
                let lower_bound = straight_line_bound(&p, obj, request, source);
                let gap_at_most = match cost {
                    Some(_) if whole => Some(0.0),
                    Some(c) if lower_bound > 0.0 => Some((c / lower_bound - 1.0).max(0.0)),
                    _ => None,
                };
                let stats = CorridorStats {
                    objective: obj,
                    coarse_cost,
                    half_width: wider.half_width,
                    corridor_cells,
                    whole,
                    cost,
                    lower_bound,
                    gap_at_most,
                };
                // A start no edge leaves (or a goal none enters) is so on the whole map: every
                // cell within two of it (its moves' reach) is in the corridor, which holds at
                // least one coarse cell of at least two cells around it. Widening cannot help.
                let ends = matches!(r, Err(NoRoute::StartImpassable | NoRoute::GoalImpassable));
                let done = r.is_ok() || whole || ends;
                if done {
                    break Ok(((obj, r), stats));
                }
                found = Some(((obj, r), stats));
                wider.half_width *= 2;
            }
        })
        .collect::<Result<Vec<_>, PlanError>>()?;
    let (routes, corridors): (Vec<_>, Vec<_>) = planned.into_iter().unzip();
    let extrapolation = extrapolation_of(&routes, coarse.tables());
    Ok(CorridorPlan {
        routes,
        corridors,
        coarse_size: (coarse.grid().cols(), coarse.grid().rows()),
        extrapolation,
    })
}

/// A lower bound on the cost of every route of `objective` from the request's start to its
/// goal over the whole map `source`: its horizontal length at least, times the planner `p`'s
/// cheapest cost per metre (its A* heuristic's factor, which never overestimates). The tables
/// of `p` reach the corridor's steepest gradient; every cost per metre of the model grows with
/// the pitch (slower, longer, riskier), so the cheapest is at the level and the same for the
/// whole map's tables.
///
/// The length: a route's moves sum at least |dc| cells east-west, each at least as wide as the
/// narrowest row the route visits (a move's width is the mean of its two rows'), and |dr| + 2k
/// rows north-south when it strays k rows beyond the endpoints' rows (there and back), so its
/// length is at least `hypot(|dc| w_k, (|dr| + 2k) cell_y)` with `w_k` the narrowest row within
/// k rows of the endpoints' (the sum of the moves' lengths is at least the length of their
/// sum); the bound is the least of these over k. On a uniform grid that is the straight line;
/// on a geographic one it does not take the poles' width for a route that stays far from them.
fn straight_line_bound(
    p: &Planner,
    objective: Objective,
    request: &PlanRequest,
    source: &dyn HeightSource,
) -> f64 {
    let dc = request.start.col.abs_diff(request.goal.col) as f64;
    let (r0, r1) = (request.start.row.min(request.goal.row), request.start.row.max(request.goal.row));
    let cy = source.cell_y();
    let length = match source.row_widths() {
        None => (dc * source.cell_x()).hypot((r1 - r0) as f64 * cy),
        Some(w) => {
            let mut narrowest = w[r0..=r1].iter().copied().fold(f64::INFINITY, f64::min);
            let mut best = (dc * narrowest).hypot((r1 - r0) as f64 * cy);
            for k in 1..w.len() {
                let (above, below) = (r0.checked_sub(k), w.get(r1 + k));
                if above.is_none() && below.is_none() {
                    break;
                }
                narrowest = above.map_or(narrowest, |a| narrowest.min(w[a]));
                narrowest = below.map_or(narrowest, |&b| narrowest.min(b));
                best = best.min((dc * narrowest).hypot((r1 - r0 + 2 * k) as f64 * cy));
            }
            best
        }
    };
    p.min_cost[objective as usize] * length
}

/// The coarse route of `objective` between the coarse cells of the request's start and goal;
/// where such a cell cannot start or end a route (the coarse border, nodata, every edge
/// impassable) the nearest one within the corridor's half-width that can is taken.
fn coarse_route(
    coarse: &Planner,
    objective: Objective,
    request: &PlanRequest,
    corridor: &CorridorSettings,
    progress: &(dyn Fn(u64) -> ControlFlow<()> + Sync),
) -> Result<Option<Route>, PlanError> {
    let candidates = |fine: Cell| {
        let g = coarse.grid();
        let f = corridor.factor;
        let (c, r) = ((fine.col / f).clamp(1, g.cols() - 2), (fine.row / f).clamp(1, g.rows() - 2));
        let w = corridor.half_width as isize;
        let mut ring: Vec<Cell> = (-w..=w)
            .flat_map(|dr| (-w..=w).map(move |dc| (dc, dr)))
            .filter_map(|(dc, dr)| {
                Some(Cell { col: c.checked_add_signed(dc)?, row: r.checked_add_signed(dr)? })
            })
            .filter(|cell| coarse.check_endpoint(*cell, "start").is_ok())
            .collect();
        ring.sort_by_key(|cell| {
            let (dc, dr) = (cell.col.abs_diff(c), cell.row.abs_diff(r));
            (dc.max(dr), dc + dr)
        });
        ring
    };
    let (starts, goals) = (candidates(request.start), candidates(request.goal));
    let index = |cell: &Cell| coarse.index_of(*cell);
    let s = starts.iter().find(|c| index(c).is_some_and(|i| coarse.has_edge_out(objective, i)));
    let t = goals.iter().find(|c| index(c).is_some_and(|i| coarse.has_edge_in(objective, i)));
    let (Some(s), Some(t)) = (s, t) else { return Ok(None) };
    Ok(coarse.route(objective, *s, *t, progress)?.ok())
}

/// Layout rows a corridor planner reads as one window (with a margin of one cell).
const CORRIDOR_BAND_ROWS: usize = 64;

impl Planner {
    /// The planner on the corridor `spans` (map columns `[start, end)` of each of the layout's
    /// rows) of the map `source`: its heights, and the map's own Horn gradients, so that every
    /// edge inside the corridor is the full planner's edge; the layout's cells outside the
    /// spans are nodata. The map is read in windows of [`CORRIDOR_BAND_ROWS`] rows with a
    /// margin of one cell, and each window's Horn gradients are [`ElevationGrid::horn_at`]'s on
    /// it: the whole map's, bit for bit (the margin holds every cell a window's interior needs,
    /// and a window's edge is the map's border wherever it has no margin).
    pub(super) fn corridor_from(
        source: &dyn HeightSource,
        layout: Layout,
        spans: &[(usize, usize)],
        terrains: &[UncertainTerrain],
        robot: &Robot,
        settings: PlanSettings,
        cache: &PitchTableCache,
    ) -> Result<Planner, PlanError> {
        let (width, rows) = (layout.width, layout.col0.len());
        let (map_cols, map_rows) = (source.cols(), source.rows());
        let mut z = vec![f32::NAN; width * rows];
        let mut grad = vec![[f32::NAN; 2]; width * rows];
        let band = CORRIDOR_BAND_ROWS * width;
        z.par_chunks_mut(band).zip(grad.par_chunks_mut(band)).enumerate().try_for_each(
            |(b, (z, grad))| -> Result<(), PlanError> {
                let first = b * CORRIDOR_BAND_ROWS;
                let n = z.len() / width.max(1);
                let band_spans = &spans[first..first + n];
                let (lo, hi) = band_spans
                    .iter()
                    .filter(|s| s.1 > s.0)
                    .fold((usize::MAX, 0), |(lo, hi), s| (lo.min(s.0), hi.max(s.1)));
                if lo >= hi {
                    return Ok(());
                }
                let row_a = layout.row0 + first;
                let wr = super::source::with_margin(row_a, row_a + n, map_rows);
                let wc = super::source::with_margin(lo, hi, map_cols);
                let local = super::source::window_grid(source, wr.clone(), wc.clone())?;
                for (k, &(start, end)) in band_spans.iter().enumerate() {
                    let (row, c0) = (row_a + k, layout.col0[first + k] as usize);
                    let lr = row - wr.start;
                    for c in start..end {
                        let j = k * width + c - c0;
                        let lc = c - wc.start;
                        let li = lr * wc.len() + lc;
                        if local.is_valid(li) {
                            z[j] = local.heights()[li];
                        }
                        grad[j] = local.horn_at(lc, lr);
                    }
                }
                Ok(())
            },
        )?;
        let mut grid = ElevationGrid::new(width, rows, source.cell_x(), source.cell_y(), z, None)?;
        if let Some(w) = source.row_widths() {
            grid = grid.with_row_widths(w[layout.row0..layout.row0 + rows].to_vec())?;
        }
        Planner::build(grid, Some((layout, grad)), None, terrains, robot, settings, Some(cache))
    }

    /// The corridor planner from a map held whole, cell by cell: the reference the windowed
    /// [`Planner::corridor_from`] is tested against.
    #[cfg(test)]
    pub(super) fn corridor(
        map: &ElevationGrid,
        layout: Layout,
        spans: &[(usize, usize)],
        terrains: &[UncertainTerrain],
        robot: &Robot,
        settings: PlanSettings,
        cache: &PitchTableCache,
    ) -> Result<Planner, PlanError> {
        let (width, rows) = (layout.width, layout.col0.len());
        let mut z = vec![f32::NAN; width * rows];
        let mut grad = vec![[f32::NAN; 2]; width * rows];
        z.par_chunks_mut(width).zip(grad.par_chunks_mut(width)).enumerate().for_each(|(r, (z, grad))| {
            let row = layout.row0 + r;
            let c0 = layout.col0[r] as usize;
            let (start, end) = spans[r];
            for (j, (z, grad)) in
                z.iter_mut().zip(grad.iter_mut()).enumerate().skip(start - c0).take(end - start)
            {
                let i = row * map.cols() + c0 + j;
                if map.is_valid(i) {
                    *z = map.heights()[i];
                }
                *grad = map.horn_at(c0 + j, row);
            }
        });
        let mut grid = ElevationGrid::new(width, rows, map.cell_x(), map.cell_y(), z, None)?;
        if let Some(w) = map.row_widths() {
            grid = grid.with_row_widths(w[layout.row0..layout.row0 + rows].to_vec())?;
        }
        Planner::build(grid, Some((layout, grad)), None, terrains, robot, settings, Some(cache))
    }

    /// [`Planner::cost_of_route`], for the tests of the windowed search.
    #[cfg(test)]
    pub(super) fn cost_of_route_for_tests(&self, objective: Objective, cells: &[Cell]) -> f64 {
        self.cost_of_route(objective, cells)
    }

    /// The cost of the chain of cells `cells` for `objective` (infinite if an edge is missing).
    fn cost_of_route(&self, objective: Objective, cells: &[Cell]) -> f64 {
        cells
            .windows(2)
            .map(|w| {
                let (Some(u), Some(v)) = (self.index_of(w[0]), self.index_of(w[1])) else {
                    return f64::INFINITY;
                };
                self.move_between(u, v)
                    .and_then(|k| self.edge_cost(objective, u, v, k))
                    .unwrap_or(f64::INFINITY)
            })
            .sum()
    }
}

/// The corridor around a coarse route: the fine cells within `half_width` coarse cells of a
/// route cell or of the start's or goal's coarse cell, as each row's span of map columns
/// (`[start, end)`), and the layout that holds them: rows as wide as the widest span, each
/// starting at its span (or further west, to stay inside the map).
fn corridor_layout(
    (map_cols, map_rows): (usize, usize),
    route: &[Cell],
    request: &PlanRequest,
    corridor: &CorridorSettings,
) -> Result<(Layout, Vec<(usize, usize)>), PlanError> {
    let (f, w) = (corridor.factor, corridor.half_width);
    let (cc, cr) = (map_cols.div_ceil(f), map_rows.div_ceil(f));
    // Per coarse row, the smallest and largest coarse column within the corridor.
    let mut span = vec![(usize::MAX, 0usize); cr];
    let ends = [request.start, request.goal].map(|c| Cell { col: c.col / f, row: c.row / f });
    for c in route.iter().chain(&ends) {
        let (c0, c1) = (c.col.saturating_sub(w), (c.col + w).min(cc - 1));
        for s in &mut span[c.row.saturating_sub(w)..=(c.row + w).min(cr - 1)] {
            *s = (s.0.min(c0), s.1.max(c1));
        }
    }
    // The fine columns of each coarse row's span (none where the corridor misses the row).
    let fine: Vec<(usize, usize)> = span
        .iter()
        .map(|&(c0, c1)| if c0 == usize::MAX { (0, 0) } else { (c0 * f, ((c1 + 1) * f).min(map_cols)) })
        .collect();
    let first = fine.iter().position(|s| s.1 > s.0).unwrap_or(0);
    let last = fine.iter().rposition(|s| s.1 > s.0).unwrap_or(0);
    let (row0, row1) = (first * f, ((last + 1) * f).min(map_rows));
    let width = fine[first..=last].iter().map(|s| s.1 - s.0).max().unwrap_or(0);
    let spans: Vec<(usize, usize)> = (row0..row1).map(|r| fine[r / f]).collect();
    let col0 = spans.iter().map(|s| s.0.min(map_cols - width) as isize).collect();
    let layout = Layout { row0, col0, width, map_cols, map_rows };
    let bytes = layout.cells() as u64 * CORRIDOR_BYTES_PER_CELL;
    if let Some(limit) = corridor.max_bytes.filter(|&l| bytes > l) {
        return Err(PlanError::Grid(format!(
            "the corridor around the coarse route is {} rows of {} cells, which need {:.3} GiB \
             ({CORRIDOR_BYTES_PER_CELL} bytes a cell), more than the {:.3} GiB left for it; narrow the corridor \
             or coarsen less",
            row1 - row0,
            width,
            bytes as f64 / (1u64 << 30) as f64,
            limit as f64 / (1u64 << 30) as f64
        )));
    }
    Ok((layout, spans))
}

/// [`corridor_layout`] for the tests of the windowed search.
#[cfg(test)]
pub(super) fn corridor_layout_for_tests(
    map: (usize, usize),
    route: &[Cell],
    request: &PlanRequest,
    corridor: &CorridorSettings,
) -> (Layout, Vec<(usize, usize)>) {
    corridor_layout(map, route, request, corridor).unwrap()
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::model::tests::paper_robot;
    use crate::risk::Uncertainty;
    use crate::terrain::Terrain;

    pub(in crate::plan) fn terrain() -> UncertainTerrain {
        UncertainTerrain::with_uncertainty(
            Terrain::constant(7e5, 2e6).unwrap(),
            Uncertainty::new(0.1, 0.2).unwrap(),
        )
    }

    /// Dunes from a few sines, 0.5 m cells, slopes up to about 25 degrees: routes must wind.
    pub(in crate::plan) fn dunes(n: usize) -> ElevationGrid {
        let z = (0..n * n)
            .map(|i| {
                let (x, y) = (0.5 * (i % n) as f64, 0.5 * (i / n) as f64);
                (1.2 * (x / 3.0 + 0.5 * (y / 7.0).sin()).sin() + 0.3 * ((x + y) / 2.0).sin()) as f32
            })
            .collect();
        ElevationGrid::new(n, n, 0.5, 0.5, z, None).unwrap()
    }

    fn request(start: Cell, goal: Cell) -> PlanRequest {
        PlanRequest { start, goal, objectives: vec![Objective::Time], risk_map: false }
    }

    /// The time and distance routes from `s` to `t` in corridors of `half_width` blocks of
    /// `factor` cells.
    fn corridor_plan(
        grid: &ElevationGrid,
        s: Cell,
        t: Cell,
        factor: usize,
        half_width: usize,
    ) -> CorridorPlan {
        let settings = CorridorSettings::new(factor, half_width, None).unwrap();
        plan_corridor(
            grid,
            &terrain(),
            &paper_robot(),
            PlanSettings::default(),
            &request(s, t),
            &settings,
            &|_, _, _| ControlFlow::Continue(()),
        )
        .unwrap()
    }

    #[test]
    fn coarsening_averages_blocks_and_drops_mostly_empty_ones() {
        // 5 x 6 cells in blocks of 2: 3 x 3 blocks, the last column of blocks one cell wide.
        let z: Vec<f32> = (0..30).map(|i| i as f32).collect();
        let mut nodata = vec![false; 30];
        // Block (0, 0) holds cells 0, 1, 5, 6: with 0 and 1 missing, half remain: (5 + 6) / 2.
        nodata[0] = true;
        nodata[1] = true;
        // Block (1, 1) holds 12, 13, 17, 18: three missing, nodata.
        for i in [12, 13, 17] {
            nodata[i] = true;
        }
        let g = ElevationGrid::new(5, 6, 1.0, 2.0, z, Some(&nodata)).unwrap();
        // Rows of different widths: a block row is twice its two rows' mean width.
        let rows =
            g.clone().with_row_widths(vec![1.0, 3.0, 2.0, 2.0, 0.5, 1.5]).unwrap().coarsened(2).unwrap();
        assert_eq!(rows.row_widths(), Some(&[4.0, 4.0, 2.0][..]));
        let g = g.coarsened(2).unwrap();
        assert_eq!((g.cols(), g.rows(), g.cell_x(), g.cell_y()), (3, 3, 2.0, 4.0));
        let h = |c, r| g.height(Cell { col: c, row: r });
        assert_eq!(h(0, 0), Some(5.5));
        assert_eq!(h(1, 0), Some((2.0 + 3.0 + 7.0 + 8.0) / 4.0));
        assert_eq!(h(2, 0), Some((4.0 + 9.0) / 2.0));
        assert_eq!(h(1, 1), None);
        assert_eq!(h(0, 1), Some((10.0 + 11.0 + 15.0 + 16.0) / 4.0));
        assert_eq!(h(2, 2), Some((24.0 + 29.0) / 2.0));
    }

    /// With a corridor wider than the map the corridor search is the full search: the same
    /// optimum. With a narrow one its route is a route of the full graph, costed exactly as
    /// the full planner costs it, and never cheaper than the full optimum.
    #[test]
    fn a_corridor_route_is_a_full_route_no_cheaper_than_the_optimum() {
        // Also on rows of different widths (0.6 m in the north to 0.4 m in the south, as a
        // geographic DEM's): the corridor's rows keep the map's widths.
        let widths = (0..72).map(|r| 0.6 - 0.2 * r as f64 / 71.0).collect();
        for grid in [dunes(72), dunes(72).with_row_widths(widths).unwrap()] {
            corridor_routes_are_full_routes(&grid);
        }
    }

    fn corridor_routes_are_full_routes(grid: &ElevationGrid) {
        let grid = grid.clone();
        let full =
            Planner::new(grid.clone(), None, &[terrain()], &paper_robot(), PlanSettings::default()).unwrap();
        let (s, t) = (Cell { col: 3, row: 66 }, Cell { col: 68, row: 5 });
        for (half_width, exact) in [(40, true), (1, false)] {
            let plan = corridor_plan(&grid, s, t, 4, half_width);
            for (obj, r) in &plan.routes {
                let want = full.route(*obj, s, t, &|_| ControlFlow::Continue(())).unwrap().unwrap();
                let r = r.as_ref().unwrap();
                let (got, best) = (full.cost_of_route(*obj, &r.cells), full.cost_of_route(*obj, &want.cells));
                // Every step is a full-graph edge, with the full planner's statistics.
                let cells: Vec<usize> = r.cells.iter().map(|c| full.index_of(*c).unwrap()).collect();
                assert_eq!(*r, full.route_from_cells(*obj, cells));
                assert!(got.is_finite());
                if exact {
                    assert!((got - best).abs() <= 1e-9 * best, "{obj:?}: {got} vs {best}");
                } else {
                    assert!(got >= best * (1.0 - 1e-12), "{obj:?}: {got} below the optimum {best}");
                }
            }
            let stats = &plan.corridors[0];
            assert!(stats.corridor_cells > 0 && stats.corridor_cells <= 72 * 72, "{stats:?}");
            assert!(stats.coarse_cost.is_some());
        }
    }

    /// What the corridor gives up: a passage narrower than a coarse cell. Level ground, 1 m
    /// cells, a wall of nodata across rows 32 to 63 with a 3-cell gap at columns 30 to 32 (its
    /// middle column passable) and a wide gap at columns 64 to 94. Averaged over 8 x 8 cells the
    /// narrow gap's blocks are mostly wall, so the coarse route takes the wide gap, and a
    /// corridor one coarse cell wide misses the narrow one: from (10, 10) to (10, 85) the full
    /// route is about 21 sqrt 2 + 33 + 21 sqrt 2 = 92 m long through the narrow gap, the
    /// corridor's about 2 x hypot(55, 21) + 33 = 151 m through the wide one (column 65 is the
    /// first with a slope beside the wall).
    #[test]
    fn a_passage_narrower_than_a_coarse_cell_can_be_missed() {
        let n = 96;
        let nodata: Vec<bool> = (0..n * n)
            .map(|i| {
                let (c, r) = (i % n, i / n);
                (32..64).contains(&r) && !(30..33).contains(&c) && !(64..95).contains(&c)
            })
            .collect();
        let grid = ElevationGrid::new(n, n, 1.0, 1.0, vec![0.0; n * n], Some(&nodata)).unwrap();
        let (s, t) = (Cell { col: 10, row: 10 }, Cell { col: 10, row: 85 });
        let plan = corridor_plan(&grid, s, t, 8, 1);
        let full = Planner::new(grid, None, &[terrain()], &paper_robot(), PlanSettings::default()).unwrap();
        for (obj, r) in &plan.routes {
            let got = r.as_ref().unwrap().length_m;
            let best = full.route(*obj, s, t, &|_| ControlFlow::Continue(())).unwrap().unwrap().length_m;
            assert!((best - 92.0).abs() < 3.0 && (got - 151.0).abs() < 8.0, "{obj:?}: {best} and {got}");
        }
    }

    /// A plane 40 degrees steep: every heading either climbs at more than 37 degrees (beyond
    /// slippage) or rolls more than 20 (tan 40 sin b <= tan 20 needs sin b <= 0.434, and then
    /// the pitch is atan(tan 40 cos b) >= 37 degrees), so no time edge leaves the start. The
    /// corridor is not widened for that (it holds the start's every move): the answer comes at
    /// the width asked for.
    #[test]
    fn an_impassable_start_is_not_widened_for() {
        let n = 64;
        let tan = 40f64.to_radians().tan() as f32;
        let z = (0..n * n).map(|i| tan * 0.5 * (i % n) as f32).collect();
        let grid = ElevationGrid::new(n, n, 0.5, 0.5, z, None).unwrap();
        let plan = corridor_plan(&grid, Cell { col: 5, row: 5 }, Cell { col: 58, row: 58 }, 4, 1);
        let (obj, r) = &plan.routes[0];
        assert_eq!((*obj, r.as_ref().err()), (Objective::Time, Some(&NoRoute::StartImpassable)));
        let stats = &plan.corridors[0];
        assert_eq!((stats.half_width, stats.whole), (1, false), "{stats:?}");
        assert!(plan.routes[1].1.is_ok(), "the distance route exists");
    }

    #[test]
    fn a_corridor_planner_holds_only_its_cells_and_places_them_on_the_map() {
        let grid = dunes(40);
        let route: Vec<Cell> = (1..9).map(|i| Cell { col: i, row: i }).collect();
        let settings = CorridorSettings::new(4, 1, None).unwrap();
        let req = request(Cell { col: 5, row: 5 }, Cell { col: 34, row: 34 });
        let (layout, spans) = corridor_layout((grid.cols(), grid.rows()), &route, &req, &settings).unwrap();
        // Coarse cells within 1 of a diagonal route cell: in coarse row R those of rows R - 1 to
        // R + 1 reach columns R - 2 to R + 2, 5 coarse columns = 20 fine ones a row, all rows.
        assert_eq!((layout.row0, layout.col0.len(), layout.width), (0, 40, 20));
        let p = Planner::corridor(
            &grid,
            layout,
            &spans,
            &[terrain()],
            &paper_robot(),
            PlanSettings::default(),
            &PitchTableCache::new(),
        )
        .unwrap();
        for (r, span) in spans.iter().enumerate() {
            for c in 0..40 {
                let cell = Cell { col: c, row: r };
                let inside = (span.0..span.1).contains(&c);
                // The corridor: within two coarse cells of the diagonal.
                assert_eq!(inside, (c / 4).abs_diff(r / 4) <= 2, "{cell:?}");
                match p.index_of(cell) {
                    Some(i) if inside => {
                        assert_eq!(p.cell_at(i), cell);
                        assert_eq!(p.grid().heights()[i], grid.heights()[r * 40 + c]);
                        let g = grid.horn_at(c, r);
                        assert_eq!(p.grad[i].map(f32::to_bits), g.map(f32::to_bits));
                    }
                    // Held to make the rows equally wide, but impassable.
                    Some(i) => assert!(!p.grid().is_valid(i) && p.grad[i][0].is_nan(), "{cell:?}"),
                    None => assert!(!inside, "{cell:?}"),
                }
            }
        }
        // Too small a byte limit is refused before anything is built.
        let tight = CorridorSettings::new(4, 1, Some(1000)).unwrap();
        let e = corridor_layout((grid.cols(), grid.rows()), &route, &req, &tight).unwrap_err().to_string();
        assert!(e.contains("40 rows of 20 cells"), "{e}");
    }
}
