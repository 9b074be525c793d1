//! A* on the planner's flat arrays ([`super::planner`] holds the graph; routes:
//! [`super::route`]; risk maps: [`super::risk_map`]).
//!
//! The search is a label-correcting A*: per cell a 16-byte [`Node`] (the `f64` distance
//! beside the gradient, read together for every neighbour), a `u8` predecessor heading, and
//! unordered buckets over the key ([`super::queue`]); the neighbourhood of the next cell to
//! expand is prefetched while the current one is expanded. The heuristic is the straight-line
//! horizontal distance to the goal times the smallest cost per horizontal metre in any table,
//! which never overestimates (every edge costs at least that much per horizontal metre) and is
//! consistent.
//!
//! Why hand-written: on a 1024 x 1024 dune field (`cargo bench -p sandslope --bench plan`)
//! this search plans the time route in 222 ms, against 1.58 s for the `pathfinding` crate's
//! A* over the same graph ([`Planner::edges`]) with the same heuristic: 7.1x.
//!
//! On the 4096 x 4096 benchmark (`bench/plan/run.py`) the time search settles 12.6 M cells;
//! with a binary heap per bucket it took 10.4-10.8 s, unordered buckets brought it to
//! 6.6-6.9 s, the packed node to 5.8-6.4 s and the prefetch to 4.9-5.6 s (single runs on the
//! 2-core VM).

use std::ops::ControlFlow;

use rayon::prelude::*;

use super::grid::Cell;
use super::planner::{Planner, HEADINGS};
use super::queue::BucketQueue;
use super::route::Route;
use super::{NoRoute, Objective, PlanError};

/// Hints the processor to load `v[i]` into cache (nothing if `i` is out of bounds or the
/// target has no prefetch instruction).
#[inline(always)]
fn prefetch<T>(v: &[T], i: usize) {
    #[cfg(target_arch = "x86_64")]
    if let Some(x) = v.get(i) {
        // SAFETY: `_mm_prefetch` only hints the cache and never faults; SSE is part of the
        // x86_64 baseline, and the pointer comes from a live reference anyway.
        unsafe {
            std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>((x as *const T).cast())
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (v, i);
}

/// A cell's search state beside its gradient (16 bytes: four per cache line).
#[derive(Debug, Clone, Copy)]
#[repr(C, align(16))]
struct Node {
    dist: f64,
    grad: [f32; 2],
}

impl Planner {
    /// The route minimising `objective` from `start` to `goal`, by A*. `progress` is called
    /// with the number of cells settled so far, every 65 536 cells; returning
    /// `ControlFlow::Break(())` stops the search with [`PlanError::Stopped`] (how a front end
    /// honours Ctrl-C).
    ///
    /// Errors when start or goal is outside the map or unusable (see
    /// [`Planner::check_endpoint`]); `Ok(Err(NoRoute))` when they are valid but not joined.
    pub fn route(
        &self,
        objective: Objective,
        start: Cell,
        goal: Cell,
        progress: &(dyn Fn(u64) -> ControlFlow<()> + Sync),
    ) -> Result<Result<Route, NoRoute>, PlanError> {
        let s = self.check_endpoint(start, "start")?;
        let t = self.check_endpoint(goal, "goal")?;
        if s == t {
            return Ok(Ok(self.route_from_cells(objective, vec![s])));
        }
        if let Some(blocked) = self.blocked_end(objective, s, t) {
            return Ok(Err(blocked));
        }
        let cells = self.search(objective, s, t, progress).ok_or(PlanError::Stopped)?;
        Ok(cells.map(|cells| self.route_from_cells(objective, cells)))
    }

    /// Why no route can exist before searching: no passable edge leaves the start, or none
    /// enters the goal, for this objective.
    fn blocked_end(&self, objective: Objective, s: usize, t: usize) -> Option<NoRoute> {
        if !self.has_edge_out(objective, s) {
            return Some(NoRoute::StartImpassable);
        }
        (!self.has_edge_in(objective, t)).then_some(NoRoute::GoalImpassable)
    }

    /// Whether a passable edge leaves the cell `s` for this objective.
    pub(super) fn has_edge_out(&self, objective: Objective, s: usize) -> bool {
        (0..HEADINGS)
            .any(|k| self.neighbour(s, k).is_some_and(|v| self.edge_cost(objective, s, v, k).is_some()))
    }

    /// Whether a passable edge enters the cell `t` for this objective: from a neighbour `w`
    /// along the reverse move.
    pub(super) fn has_edge_in(&self, objective: Objective, t: usize) -> bool {
        (0..HEADINGS).any(|k| {
            let back = (k + HEADINGS / 2) % HEADINGS;
            self.neighbour(t, k).is_some_and(|w| self.edge_cost(objective, w, t, back).is_some())
        })
    }

    /// The cells of the cheapest path from `s` to `t`, by label-correcting A* ([`Search`]):
    /// take the next cell to expand, start loading the one after it, relax its edges; then
    /// walk the predecessors back from the goal. `None` when `progress` asked to stop.
    fn search(
        &self,
        objective: Objective,
        s: usize,
        t: usize,
        progress: &(dyn Fn(u64) -> ControlFlow<()> + Sync),
    ) -> Option<Result<Vec<usize>, NoRoute>> {
        let mut search = Search::new(self, objective, s, t);
        let stopped = match (self.layout.is_whole(), self.row_geoms.is_empty()) {
            (true, true) => search.run::<false, false>(progress),
            (false, true) => search.run::<true, false>(progress),
            (true, false) => search.run::<false, true>(progress),
            (false, false) => search.run::<true, true>(progress),
        };
        if stopped {
            return None;
        }
        Some(search.path())
    }
}

/// The state of one A* search: per cell a [`Node`] (distance beside gradient) and the heading
/// it was reached by, and the open set in buckets over the key `distance + heuristic`.
///
/// The heuristic is the straight-line horizontal distance to the goal times the smallest cost
/// per horizontal metre of the objective, which never overestimates. The search is label
/// correcting: the lowest bucket is drained in any order and a cell is expanded again whenever
/// its distance improves; once the floor of the open set reaches the goal's distance no path
/// can improve on it, so the result is the exact optimum.
struct Search<'p> {
    planner: &'p Planner,
    objective: Objective,
    /// The start's flat index.
    s: usize,
    /// The goal's flat index and its column and row.
    t: usize,
    tc: f64,
    tr: f64,
    /// Cost per horizontal metre of the heuristic.
    h_scale: f64,
    /// East-west metres per column of the heuristic: the narrowest row's cell width, so that
    /// no move is shorter than the heuristic takes it to be.
    h_cell_x: f64,
    node: Vec<Node>,
    /// Move index by which each cell was reached (`u8::MAX`: not reached).
    pred: Vec<u8>,
    open: BucketQueue,
    /// Flat-index offset of each move.
    offsets: [isize; HEADINGS],
    /// Cells expanded so far.
    settled: u64,
}

impl<'p> Search<'p> {
    /// Every distance infinite but the start's (0), the start alone in the open set.
    fn new(planner: &'p Planner, objective: Objective, s: usize, t: usize) -> Search<'p> {
        let cols = planner.grid.cols();
        let h_scale = planner.min_cost[objective as usize];
        // Each cell's distance beside its gradient: the two are read together for every
        // neighbour, so one cache line serves both.
        let mut node: Vec<Node> =
            planner.grad.par_iter().map(|&grad| Node { dist: f64::INFINITY, grad }).collect();
        let pred = vec![u8::MAX; planner.grid.len()];
        let mut search = Search {
            planner,
            objective,
            s,
            t,
            tc: planner.cell_at(t).col as f64,
            tr: planner.cell_at(t).row as f64,
            h_scale,
            h_cell_x: planner.grid.min_cell_x(),
            node: Vec::new(),
            pred,
            // Replaced below, once the start's key is known.
            open: BucketQueue::new(0.0, 1.0),
            offsets: planner.moves.map(|m| m.dr * cols as isize + m.dc),
            settled: 0,
        };
        let h_s = search.heuristic(planner.cell_at(s).col as f64, planner.cell_at(s).row as f64);
        // Buckets an eighth of the cheapest edge's cost wide (cell width times the smallest
        // cost per metre): an edge whose reduced cost `c(u, v) - h(u) + h(v)` exceeds the width
        // cannot make a cell of the same bucket re-expand.
        let width = (0.125 * h_scale * planner.cell_width).max(f64::MIN_POSITIVE);
        search.open = BucketQueue::new(h_s, width);
        node[s].dist = 0.0;
        search.node = node;
        search.open.push(h_s, (s as u32, 0.0));
        search
    }

    /// Lower bound of the cost from the cell at column `c`, row `r` to the goal.
    #[inline(always)]
    fn heuristic(&self, c: f64, r: f64) -> f64 {
        let (ex, ey) = ((c - self.tc) * self.h_cell_x, (r - self.tr) * self.planner.grid.cell_y());
        self.h_scale * (ex * ex + ey * ey).sqrt()
    }

    /// Expands cells until the goal's distance is final (or the open set is empty), calling
    /// `progress` every 65 536 cells and at the end; `CORRIDOR` when the planner holds a
    /// corridor, `ROWS` when its rows differ in width (a uniform grid's search reads one inline
    /// geometry per move, as cheap as before rows had widths). Whether `progress` asked to stop.
    fn run<const CORRIDOR: bool, const ROWS: bool>(
        &mut self,
        progress: &(dyn Fn(u64) -> ControlFlow<()> + Sync),
    ) -> bool {
        while let Some((u, du, gu)) = self.next_cell() {
            self.prefetch_next();
            self.settled += 1;
            if self.settled & 0xFFFF == 0 && progress(self.settled).is_break() {
                return true;
            }
            self.relax_edges::<CORRIDOR, ROWS>(u, du, gu);
        }
        progress(self.settled).is_break()
    }

    /// The next cell to expand with its distance and gradient, skipping stale entries (the
    /// cell improved after the entry was pushed) and the goal; `None` once the open set is
    /// empty or its floor reaches the goal's distance.
    #[inline(always)]
    fn next_cell(&mut self) -> Option<(usize, f64, [f32; 2])> {
        while let Some((u, g)) = self.open.pop() {
            let u = u as usize;
            let Node { dist: du, grad: gu } = self.node[u];
            if (du as f32) < g || u == self.t {
                continue;
            }
            if self.open.floor() >= self.node[self.t].dist {
                return None;
            }
            return Some((u, du, gu));
        }
        None
    }

    /// Starts loading the neighbourhood of the entry below the one being expanded, which is
    /// probably the next to expand.
    #[inline(always)]
    fn prefetch_next(&self) {
        if let Some((w, _)) = self.open.peek() {
            let (w, cols) = (w as usize, self.planner.grid.cols());
            for d in [0, cols, 2 * cols] {
                prefetch(&self.node, w.wrapping_add(d).wrapping_sub(2));
                prefetch(&self.node, w.wrapping_add(d).wrapping_add(2));
                prefetch(&self.node, w.wrapping_sub(d).wrapping_sub(2));
                prefetch(&self.node, w.wrapping_sub(d).wrapping_add(2));
            }
        }
    }

    /// Relaxes every edge out of `u` (distance `du`, gradient `gu`): a neighbour reached
    /// more cheaply gets the new distance, `u` as predecessor and an entry in the open set,
    /// unless its key cannot beat the goal's distance.
    #[inline(always)]
    fn relax_edges<const CORRIDOR: bool, const ROWS: bool>(&mut self, u: usize, du: f64, gu: [f32; 2]) {
        let p = self.planner;
        let (cols, rows) = (p.grid.cols(), p.grid.rows());
        // One division per settled cell; neighbours by flat offsets (a profile showed the
        // per-neighbour `%` and `/` cost about a third of the search).
        let (c, r) = (u % cols, u / cols);
        // In a corridor, rows start at different map columns: the shift of the local column
        // into each of the rows r - 2 ..= r + 2, and u's map cell for the heuristic.
        let col0 = &p.layout.col0;
        let shift: [isize; 5] = if CORRIDOR {
            std::array::from_fn(|i| col0.get((r + i).wrapping_sub(2)).map_or(0, |&s| col0[r] - s))
        } else {
            [0; 5]
        };
        let (mc, mr) = if CORRIDOR { (c as isize + col0[r], (p.layout.row0 + r) as isize) } else { (0, 0) };
        // Each move's geometry from u's row (`ROWS`: the rows' widths differ), or the one
        // geometry of every row.
        let geoms = if ROWS { &p.row_geoms[r] } else { &p.geom0 };
        for (k, m) in p.moves.iter().enumerate() {
            let s = shift[(m.dr + 2) as usize];
            let (nc, nr) = (c.wrapping_add_signed(m.dc + s), r.wrapping_add_signed(m.dr));
            if nc >= cols || nr >= rows {
                continue;
            }
            let v = u.wrapping_add_signed(self.offsets[k] + s);
            // Edges cost more than nothing: a cell already this close cannot improve.
            let Node { dist: dv, grad: gv } = self.node[v];
            if dv <= du || gv[0].is_nan() {
                continue;
            }
            if m.via[0] != 0 {
                let blocked = if CORRIDOR {
                    m.via_at.iter().any(|&(dc, dr)| {
                        let s = shift[(dr + 2) as usize];
                        c.wrapping_add_signed(dc + s) >= cols
                            || self.node[u.wrapping_add_signed(dr * cols as isize + dc + s)].grad[0].is_nan()
                    })
                } else {
                    m.via.iter().any(|&o| self.node[u.wrapping_add_signed(o)].grad[0].is_nan())
                };
                if blocked {
                    continue;
                }
            }
            let g = &geoms[k];
            let Some(cost) = p.cost_of(self.objective, Planner::geom_of(gu, gv, g), u, v, g.len) else {
                continue;
            };
            let nd = du + cost;
            if nd < dv {
                let key = nd
                    + if CORRIDOR {
                        self.heuristic((mc + m.dc) as f64, (mr + m.dr) as f64)
                    } else {
                        self.heuristic(nc as f64, nr as f64)
                    };
                // A path through v at this distance cannot beat the goal's.
                if key >= self.node[self.t].dist {
                    continue;
                }
                self.node[v].dist = nd;
                self.pred[v] = k as u8;
                self.open.push(key, (v as u32, nd as f32));
            }
        }
    }

    /// The cells from start to goal, by walking the predecessors back from the goal;
    /// [`NoRoute::GoalUnreachable`] if the search never reached it.
    fn path(self) -> Result<Vec<usize>, NoRoute> {
        let t = self.t;
        if !self.node[t].dist.is_finite() {
            return Err(NoRoute::GoalUnreachable);
        }
        let mut cells = vec![t];
        let mut v = t;
        while v != self.s {
            let m = &self.planner.moves[usize::from(self.pred[v])];
            v = self.planner.offset_of(v, (-m.dc, -m.dr)).ok_or(NoRoute::GoalUnreachable)?;
            cells.push(v);
        }
        cells.reverse();
        Ok(cells)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::tests::paper_robot;
    use crate::plan::{heading_offsets, Descent, ElevationGrid, PitchTableCache, PlanSettings};
    use crate::risk::UncertainTerrain;
    use crate::risk::Uncertainty;
    use crate::terrain::Terrain;

    fn class() -> Vec<UncertainTerrain> {
        let terrain = Terrain::constant(7e5, 2e6).unwrap();
        vec![UncertainTerrain::with_uncertainty(terrain, Uncertainty::new(0.1, 0.2).unwrap())]
    }

    /// A bumpy surface from a few sines (deterministic), 1 m cells, slopes up to ~17 degrees.
    fn bumpy(n: usize) -> ElevationGrid {
        let z = (0..n * n)
            .map(|i| {
                let (x, y) = ((i % n) as f64, (i / n) as f64);
                (1.5 * (x / 4.0).sin() * (y / 5.0).cos() + 0.7 * ((x + 2.0 * y) / 3.0).sin()) as f32
            })
            .collect();
        ElevationGrid::new(n, n, 1.0, 1.0, z, None).unwrap()
    }

    /// Plain Dijkstra over the same edges, with a sorted set instead of a heap and no
    /// heuristic: the reference for A*.
    fn reference_cost(p: &Planner, obj: Objective, s: usize, t: usize) -> Option<f64> {
        let d = dijkstra(p, obj, s, false, Some(t))[t];
        d.is_finite().then_some(d)
    }

    /// Plain Dijkstra from `from` over the graph's edges (`reverse`: over the reversed edges,
    /// so each cell gets its cost *to* `from`), stopping once `stop` is settled.
    fn dijkstra(p: &Planner, obj: Objective, from: usize, reverse: bool, stop: Option<usize>) -> Vec<f64> {
        let mut dist = vec![f64::INFINITY; p.grid.len()];
        let mut open = std::collections::BTreeSet::new();
        dist[from] = 0.0;
        open.insert((0u64, from));
        while let Some((_, u)) = open.pop_first() {
            if Some(u) == stop {
                break;
            }
            for k in 0..HEADINGS {
                let Some(v) = p.neighbour(u, k) else { continue };
                let back = (k + HEADINGS / 2) % HEADINGS;
                let cost = if reverse { p.edge_cost(obj, v, u, back) } else { p.edge_cost(obj, u, v, k) };
                if let Some(c) = cost {
                    if dist[u] + c < dist[v] {
                        open.remove(&(dist[v].to_bits(), v));
                        dist[v] = dist[u] + c;
                        open.insert((dist[v].to_bits(), v));
                    }
                }
            }
        }
        dist
    }

    fn route_cost(p: &Planner, r: &Route) -> f64 {
        let g = &p.grid;
        r.cells
            .windows(2)
            .map(|w| {
                let (u, v) = (g.index(w[0]).unwrap(), g.index(w[1]).unwrap());
                p.edge_cost(r.objective, u, v, p.move_between(u, v).unwrap()).unwrap()
            })
            .sum()
    }

    #[test]
    fn a_star_finds_the_same_optimum_as_plain_dijkstra() {
        let p = Planner::new(bumpy(40), None, &class(), &paper_robot(), PlanSettings::default()).unwrap();
        let (s, t) = (Cell { col: 2, row: 37 }, Cell { col: 36, row: 3 });
        for obj in Objective::ALL {
            let r = p.route(obj, s, t, &|_| ControlFlow::Continue(())).unwrap().unwrap();
            let want = reference_cost(&p, obj, p.grid.index(s).unwrap(), p.grid.index(t).unwrap()).unwrap();
            let got = route_cost(&p, &r);
            assert!((got - want).abs() <= 1e-9 * want, "{obj:?}: {got} vs {want}");
            assert_eq!(r.cells.first(), Some(&s));
            assert_eq!(r.cells.last(), Some(&t));
        }
    }

    #[test]
    fn label_correcting_search_is_exact_on_many_maps_settings_and_pairs() {
        // Bumpy maps from gentle to steep (steep ones leave the time objective few edges),
        // with a nodata block, two terrain classes, both descent rules and metastable on or
        // off; 30 pseudo-random pairs each, every objective, checked against plain Dijkstra,
        // including whether a route exists at all.
        let n = 36;
        let soft = Terrain::constant(3e5, 1.2e6).unwrap();
        let classes = vec![
            class()[0].clone(),
            UncertainTerrain::with_uncertainty(soft, Uncertainty::new(0.1, 0.2).unwrap()),
        ];
        let class_of: Vec<u8> = (0..n * n).map(|i| u8::from((i % n) * 3 / n == 1)).collect();
        let mut mask = vec![false; n * n];
        for r in 14..20 {
            for c in 20..24 {
                mask[r * n + c] = true;
            }
        }
        let mut state = 7u64;
        let mut next = |m: usize| {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 33) as usize) % m
        };
        let mut checked = [0usize; 2];
        for (amp, descent, meta) in
            [(0.5, Descent::Symmetric, false), (1.2, Descent::Level, true), (2.5, Descent::Symmetric, true)]
        {
            let z: Vec<f32> = bumpy(n).heights().iter().map(|&h| h * amp).collect();
            let grid = ElevationGrid::new(n, n, 1.0, 1.0, z, Some(&mask)).unwrap();
            let settings = PlanSettings::new(20.0, descent, meta, 1e-3).unwrap();
            let p = Planner::new(grid, Some(class_of.clone()), &classes, &paper_robot(), settings).unwrap();
            for _ in 0..30 {
                let s = Cell { col: 1 + next(n - 2), row: 1 + next(n - 2) };
                let t = Cell { col: 1 + next(n - 2), row: 1 + next(n - 2) };
                let (Ok(si), Ok(ti)) = (p.check_endpoint(s, "start"), p.check_endpoint(t, "goal")) else {
                    continue;
                };
                for obj in Objective::ALL {
                    let want = if si == ti { Some(0.0) } else { reference_cost(&p, obj, si, ti) };
                    match (p.route(obj, s, t, &|_| ControlFlow::Continue(())).unwrap(), want) {
                        (Ok(r), Some(w)) => {
                            let got = route_cost(&p, &r);
                            assert!((got - w).abs() <= 1e-9 * w, "{obj:?} {s:?}->{t:?}: {got} vs {w}");
                            checked[0] += 1;
                        }
                        (Err(_), None) => checked[1] += 1,
                        (r, w) => {
                            panic!("{obj:?} {s:?}->{t:?}: {:?} vs {w:?}", r.map(|r| route_cost(&p, &r)))
                        }
                    }
                }
            }
        }
        // Both outcomes occur, so the comparison is not vacuous.
        assert!(checked[0] > 150 && checked[1] > 10, "{checked:?}");
    }

    /// Rows of very different widths (1.3 m in the north to 0.5 m in the south, far more than
    /// any geographic DEM's): the heuristic never exceeds the true cost to the goal from any
    /// cell, for every objective, and A* finds plain Dijkstra's optimum.
    #[test]
    fn on_rows_of_different_widths_the_heuristic_is_admissible_and_a_star_exact() {
        let n = 32;
        let widths = (0..n).map(|r| 1.3 - 0.8 * r as f64 / (n - 1) as f64).collect();
        let grid = bumpy(n).with_row_widths(widths).unwrap();
        let p = Planner::new(grid, None, &class(), &paper_robot(), PlanSettings::default()).unwrap();
        for (s, t) in [
            (Cell { col: 2, row: 29 }, Cell { col: 29, row: 2 }),
            (Cell { col: 28, row: 3 }, Cell { col: 4, row: 27 }),
        ] {
            let (si, ti) = (p.grid.index(s).unwrap(), p.grid.index(t).unwrap());
            for obj in Objective::ALL {
                let to_goal = dijkstra(&p, obj, ti, true, None);
                let search = Search::new(&p, obj, ti, ti);
                let mut reached = 0;
                for (u, &d) in to_goal.iter().enumerate().filter(|(_, d)| d.is_finite()) {
                    let c = p.grid.cell(u);
                    let h = search.heuristic(c.col as f64, c.row as f64);
                    assert!(h <= d, "{obj:?} {c:?}: heuristic {h} > cost {d}");
                    reached += 1;
                }
                assert!(reached > n * n / 2, "{obj:?}: {reached}");
                let r = p.route(obj, s, t, &|_| ControlFlow::Continue(())).unwrap().unwrap();
                let got = route_cost(&p, &r);
                assert!((got - to_goal[si]).abs() <= 1e-9 * got, "{obj:?}: {got} vs {}", to_goal[si]);
            }
        }
    }

    /// The haversine distance, m, between two points (degrees) on a sphere of radius `r_m`.
    fn haversine(r_m: f64, (lon1, lat1): (f64, f64), (lon2, lat2): (f64, f64)) -> f64 {
        let (p1, p2) = (lat1.to_radians(), lat2.to_radians());
        let a = ((p2 - p1) / 2.0).sin().powi(2)
            + p1.cos() * p2.cos() * ((lon2 - lon1).to_radians() / 2.0).sin().powi(2);
        2.0 * r_m * a.sqrt().asin()
    }

    /// Level ground in 0.25-degree cells from 60 to 30 degrees north on a sphere of 6371 km:
    /// with each row's width (R cos(lat) dlambda) the distance routes east-west along a row,
    /// north-south and corner to corner are as long as the haversine lengths of their
    /// longitude,latitude polylines (within 1e-5); with one mid-latitude width (45 degrees)
    /// the east-west route at 54.875 degrees is 23% too long and the diagonal one wrong too.
    #[test]
    fn routes_on_geographic_rows_are_as_long_as_the_haversine() {
        let (cols, rows, r_m, deg) = (41, 120, 6_371_000.0_f64, 0.25_f64);
        let lat = |r: usize| 60.0 - (r as f64 + 0.5) * deg;
        let widths: Vec<f64> =
            (0..rows).map(|r| r_m * lat(r).to_radians().cos() * deg.to_radians()).collect();
        let (mid, cell_y) = (r_m * 45.0_f64.to_radians().cos() * deg.to_radians(), r_m * deg.to_radians());
        let uniform = ElevationGrid::new(cols, rows, mid, cell_y, vec![0.0; cols * rows], None).unwrap();
        let per_row = uniform.clone().with_row_widths(widths).unwrap();
        let error = |grid: &ElevationGrid, s: Cell, t: Cell| {
            let p =
                Planner::new(grid.clone(), None, &class(), &paper_robot(), PlanSettings::default()).unwrap();
            let r = p.route(Objective::Distance, s, t, &|_| ControlFlow::Continue(())).unwrap().unwrap();
            let at = |c: &Cell| ((c.col as f64 + 0.5) * deg, lat(c.row));
            let want: f64 = r.cells.windows(2).map(|w| haversine(r_m, at(&w[0]), at(&w[1]))).sum();
            r.length_m / want - 1.0
        };
        // Each route, and how far off the mid-latitude width leaves it at least (east-west at
        // 54.875 degrees: cos 54.875 / cos 45 - 1 = -19% of the true length, so the route is
        // 23% too long; at 32.375 degrees 16% too short).
        let routes = [
            (Cell { col: 2, row: 20 }, Cell { col: 38, row: 20 }, 0.22),
            (Cell { col: 38, row: 110 }, Cell { col: 2, row: 110 }, 0.15),
            (Cell { col: 20, row: 2 }, Cell { col: 20, row: 117 }, 0.0),
            (Cell { col: 2, row: 2 }, Cell { col: 38, row: 117 }, 0.005),
            (Cell { col: 38, row: 110 }, Cell { col: 1, row: 3 }, 0.0),
        ];
        // Every move from every row: the mean of the end rows' widths east, within 4e-6 (3.92e-6) of
        // the haversine between the two cells' centres (the worst: knight moves (2, 1)).
        let p =
            Planner::new(per_row.clone(), None, &class(), &paper_robot(), PlanSettings::default()).unwrap();
        let mut worst = 0.0_f64;
        for r in 0..rows {
            for (k, &(dc, dr)) in heading_offsets().iter().enumerate() {
                let Some(end) = r.checked_add_signed(dr).filter(|&e| e < rows) else { continue };
                let len = p.move_geom(r * cols + 20, k).len;
                let want = haversine(r_m, (20.5 * deg, lat(r)), ((20.5 + dc as f64) * deg, lat(end)));
                worst = worst.max((len / want - 1.0).abs());
            }
        }
        assert!(worst < 4e-6 && worst > 1e-6, "{worst}");
        for (s, t, off) in routes {
            let (e, e_mid) = (error(&per_row, s, t), error(&uniform, s, t));
            eprintln!("{s:?} -> {t:?}: per-row {e:+.2e}, mid-latitude {e_mid:+.4}");
            assert!(e.abs() < 1e-5, "{s:?} -> {t:?}: {e}");
            assert!(e_mid.abs() >= off, "{s:?} -> {t:?}: {e_mid}");
        }
    }

    #[test]
    fn edges_are_the_graph_the_route_is_costed_on() {
        let p = Planner::new(bumpy(40), None, &class(), &paper_robot(), PlanSettings::default()).unwrap();
        let r = p.route(Objective::Time, Cell { col: 2, row: 37 }, Cell { col: 36, row: 3 }, &|_| {
            ControlFlow::Continue(())
        });
        let r = r.unwrap().unwrap();
        // Summing the route's edges as `edges` reports them gives the route's time.
        let total: f64 =
            r.cells.windows(2).map(|w| p.edges(Objective::Time, w[0]).find(|e| e.0 == w[1]).unwrap().1).sum();
        assert!((total - r.time_s.unwrap()).abs() < 1e-3 * total, "{total} vs {:?}", r.time_s);
        // At most 16 edges; none out of the border or out of the map.
        assert!(p.edges(Objective::Distance, Cell { col: 20, row: 20 }).count() <= HEADINGS);
        assert_eq!(p.edges(Objective::Distance, Cell { col: 0, row: 5 }).count(), 0);
        assert_eq!(p.edges(Objective::Distance, Cell { col: 99, row: 5 }).count(), 0);
    }

    #[test]
    fn routes_go_around_nodata_and_knight_moves_need_the_cells_they_cross() {
        // Level ground with a 5 x 9 nodata block between start and goal.
        let n = 21;
        let mut mask = vec![false; n * n];
        for r in 6..15 {
            for c in 8..13 {
                mask[r * n + c] = true;
            }
        }
        let g = ElevationGrid::new(n, n, 1.0, 1.0, vec![0.0; n * n], Some(&mask)).unwrap();
        let mut p = Planner::new(g, None, &class(), &paper_robot(), PlanSettings::default()).unwrap();
        let r = p.route(Objective::Distance, Cell { col: 3, row: 10 }, Cell { col: 17, row: 10 }, &|_| {
            ControlFlow::Continue(())
        });
        let r = r.unwrap().unwrap();
        for c in &r.cells {
            // Neither nodata nor within one cell of it (no Horn gradient there).
            assert!(!(5..16).contains(&c.row) || !(7..14).contains(&c.col), "{c:?}");
        }
        // Detour is longer than the straight 14 m.
        assert!(r.length_m > 14.0 + 1.0);
        assert!(p.check_endpoint(Cell { col: 10, row: 10 }, "start").is_err());
        assert!(matches!(
            p.check_endpoint(Cell { col: 21, row: 3 }, "goal"),
            Err(PlanError::Outside { which: "goal", .. })
        ));
        // The knight move (2, 1) from (3, 3) crosses (4, 3) and (4, 4): blocking either blocks it.
        let u = 3 * n + 3;
        let k = heading_offsets().iter().position(|&m| m == (2, 1)).unwrap();
        assert_eq!(p.neighbour(u, k), Some(4 * n + 5));
        p.grad[4 * n + 4] = [f32::NAN; 2];
        assert_eq!(p.neighbour(u, k), None);
    }

    #[test]
    fn pure_risk_breaks_ties_between_zero_risk_routes_by_length() {
        // Level ground without uncertainty: every edge has p_fail exactly 0, so with no weight on
        // time every route is equally safe; the tie-break must pick the straight one.
        let n = 30;
        let g = ElevationGrid::new(n, n, 0.5, 0.5, vec![3.0; n * n], None).unwrap();
        let certain =
            UncertainTerrain::with_uncertainty(Terrain::constant(7e5, 2e6).unwrap(), Uncertainty::NONE);
        let settings = PlanSettings::new(20.0, Descent::Symmetric, false, 0.0).unwrap();
        let p = Planner::new(g, None, &[certain], &paper_robot(), settings).unwrap();
        assert_eq!(p.tables()[0].p_fail(0), 0.0);
        let r = p
            .route(Objective::Risk, Cell { col: 3, row: 3 }, Cell { col: 25, row: 14 }, &|_| {
                ControlFlow::Continue(())
            })
            .unwrap()
            .unwrap();
        assert_eq!(r.survival, 1.0);
        let straight = 0.5 * (22.0_f64).hypot(11.0);
        assert!((r.length_m - straight).abs() < 1e-9, "{} vs {straight}", r.length_m);
    }

    #[test]
    fn level_ground_route_is_the_straight_line() {
        let n = 30;
        let g = ElevationGrid::new(n, n, 0.5, 0.5, vec![3.0; n * n], None).unwrap();
        let p = Planner::new(g, None, &class(), &paper_robot(), PlanSettings::default()).unwrap();
        // (3, 3) to (25, 14): 22 columns, 11 rows = 11 knight moves (2, 1), exactly straight.
        let r = p
            .route(Objective::Time, Cell { col: 3, row: 3 }, Cell { col: 25, row: 14 }, &|_| {
                ControlFlow::Continue(())
            })
            .unwrap()
            .unwrap();
        let straight = 0.5 * (22.0_f64).hypot(11.0);
        assert!((r.length_m - straight).abs() < 1e-9, "{} vs {straight}", r.length_m);
        assert_eq!(r.steps.len(), 11);
        assert_eq!(r.regimes, [0, 0, 0, 11]);
        // Level-sand speed, by the model test's hand calculation: 0.151334 m/s.
        assert!((r.time_s.unwrap() - straight / 0.151_334).abs() < 1e-3 * r.time_s.unwrap());
    }

    /// A wall of 3e38 m (a corrupt DEM's float noise, not declared nodata) gives its
    /// neighbours an infinite pitch: impassable like any pitch beyond the table, never an
    /// overflow (found by fuzzing `plan`).
    #[test]
    fn an_infinitely_steep_wall_is_impassable_not_an_overflow() {
        let n = 12;
        let z: Vec<f32> = (0..n * n).map(|i| if i % n == 6 && i / n < 11 { 3e38 } else { 0.0 }).collect();
        let g = ElevationGrid::new(n, n, 1.0, 1.0, z, None).unwrap();
        let p = Planner::new(g, None, &class(), &paper_robot(), PlanSettings::default()).unwrap();
        let r = p
            .route(Objective::Time, Cell { col: 2, row: 2 }, Cell { col: 10, row: 2 }, &|_| {
                ControlFlow::Continue(())
            })
            .unwrap()
            .unwrap();
        // The cells beside the wall (columns 5 and 7) have a gradient of 1.5e38: impassable
        // (an overflow panicked here, and in a release build wrapped round to level ground).
        assert!(r.cells.iter().all(|c| !((c.col == 5 || c.col == 7) && c.row < 11)), "{:?}", r.cells);
    }

    /// On rows of different widths a cell's risk depends on its 3 x 3 window alone: a band of
    /// rows planned as a grid of its own (with its rows' widths) gives the whole map's values
    /// on its interior rows, bit for bit (what the Dask raster's tiles rely on).
    #[test]
    fn a_risk_map_on_rows_of_different_widths_is_the_same_tile_by_tile() {
        let n = 30;
        let widths: Vec<f64> = (0..n).map(|r| 1.3 - 0.8 * r as f64 / (n - 1) as f64).collect();
        let whole = bumpy(n).with_row_widths(widths.clone()).unwrap();
        let band = ElevationGrid::new(n, 12, 1.0, 1.0, whole.heights()[9 * n..21 * n].to_vec(), None)
            .unwrap()
            .with_row_widths(widths[9..21].to_vec())
            .unwrap();
        let map = |g: ElevationGrid| {
            Planner::new(g, None, &class(), &paper_robot(), PlanSettings::default()).unwrap().risk_map()
        };
        let ((p, c), (bp, bc)) = (map(whole), map(band));
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&p[10 * n..20 * n]), bits(&bp[n..11 * n]));
        assert_eq!(bits(&c[10 * n..20 * n]), bits(&bc[n..11 * n]));
        assert!(p[10 * n..20 * n].iter().filter(|v| !v.is_nan()).count() > 250);
    }

    /// A planner built from cached tables draws the same risk map, bit for bit, as one built
    /// fresh, whether the cache held a longer table (a steeper map first) or none.
    #[test]
    fn cached_tables_give_the_same_risk_map() {
        let cache = PitchTableCache::new();
        let bits = |(p, c): (Vec<f32>, Vec<f32>)| p.iter().chain(&c).map(|x| x.to_bits()).collect::<Vec<_>>();
        let steep = |n: usize| {
            let z = bumpy(n).heights().iter().map(|h| 2.0 * h).collect();
            ElevationGrid::new(n, n, 1.0, 1.0, z, None).unwrap()
        };
        for grid in [steep(24), bumpy(30), bumpy(12)] {
            let fresh =
                Planner::new(grid.clone(), None, &class(), &paper_robot(), PlanSettings::default()).unwrap();
            let cached =
                Planner::with_cache(grid, None, &class(), &paper_robot(), PlanSettings::default(), &cache)
                    .unwrap();
            assert_eq!(bits(cached.risk_map()), bits(fresh.risk_map()));
        }
        assert_eq!(cache.len(), 1);
    }
}
