//! A planned route and its steps: what the model says about each edge of the chain of cells a
//! search returns (pitch, roll, regime, speed, p_fail) and the route's totals (length, time,
//! survival, docs/model.md §8-§9).

use super::grid::Cell;
use super::planner::Planner;
use super::Objective;
use crate::regime::Regime;

/// One edge of a route, with what the model says about it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct RouteStep {
    /// Cell left.
    pub from: Cell,
    /// Cell reached.
    pub to: Cell,
    /// Heading, degrees clockwise from north.
    pub heading_deg: f64,
    /// Signed pitch along the heading, degrees (positive: climbing).
    pub pitch_deg: f64,
    /// Cross slope, degrees.
    pub roll_deg: f64,
    /// Length along the surface, `horizontal / cos(pitch)`, m.
    pub length_m: f64,
    /// Horizontal length in cell widths: the number of independent cells the edge crosses.
    pub cells_crossed: f64,
    /// Whether the roll exceeds the cross-slope limit (impassable: counts as failure).
    pub over_roll_limit: bool,
    /// The model's regime at this pitch (the worse of the two cells' classes).
    pub regime: Regime,
    /// Speed along the surface, m/s, where defined.
    pub speed: Option<f64>,
    /// P(sinkage or slippage) per cell crossed at this pitch (1 over the roll limit).
    pub p_fail: f64,
}

/// A planned route and its statistics.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Route {
    /// The objective it minimises.
    pub objective: Objective,
    /// Cells from start to goal.
    pub cells: Vec<Cell>,
    /// One step per edge (`cells.len() - 1`).
    pub steps: Vec<RouteStep>,
    /// Length along the surface, m.
    pub length_m: f64,
    /// Travel time, s; `None` when some step fails (sinkage or slippage: no progress), has no
    /// positive speed or exceeds the roll limit.
    pub time_s: Option<f64>,
    /// Survival probability, `prod (1 - p_fail)^(cells crossed)` (docs/model.md §9).
    pub survival: f64,
    /// Largest `|pitch|`, degrees.
    pub max_pitch_deg: f64,
    /// Largest roll, degrees.
    pub max_roll_deg: f64,
    /// Number of steps in each regime, in [`Regime::ALL`] order (sinkage first).
    pub regimes: [usize; 4],
    /// Number of steps over the roll limit.
    pub over_roll_limit: usize,
}

impl Planner {
    /// Evaluates the edge `u -> v` along move `k` (which must be a valid move).
    pub(super) fn step(&self, u: usize, v: usize, k: usize) -> RouteStep {
        let e = self.geom(u, v, k);
        let m = self.move_geom(u, k);
        let over = e.tan_roll > self.tan_max_roll;
        let tan_p = f64::from(e.tan_pitch);
        let (cu, cv) = (usize::from(self.class[u]), usize::from(self.class[v]));
        let (regime, speed, p_fail) = match self.entries(e) {
            None => (Regime::Slippage, None, 1.0),
            Some((i, _)) => {
                let (a, b) = (&self.tables[cu], &self.tables[cv]);
                let regime = a.regime(i).min(b.regime(i));
                let speed = match (a.speed(i), b.speed(i)) {
                    (Some(x), Some(y)) if x > 0.0 && y > 0.0 => Some(2.0 / (1.0 / x + 1.0 / y)),
                    (Some(x), Some(y)) => Some(x.min(y)),
                    _ => None,
                };
                let p = 1.0 - ((1.0 - a.p_fail(i)) * (1.0 - b.p_fail(i))).sqrt();
                (regime, speed, if over { 1.0 } else { p })
            }
        };
        RouteStep {
            from: self.cell_at(u),
            to: self.cell_at(v),
            heading_deg: self.azimuth_deg(u, k),
            pitch_deg: tan_p.atan().to_degrees(),
            roll_deg: f64::from(e.tan_roll).atan().to_degrees(),
            length_m: m.len * (1.0 + tan_p * tan_p).sqrt(),
            cells_crossed: m.len / self.cell_width,
            over_roll_limit: over,
            regime,
            speed,
            p_fail,
        }
    }

    /// The move index from `u` to `v`, if they are one move apart.
    pub(super) fn move_between(&self, u: usize, v: usize) -> Option<usize> {
        let (a, b) = (self.cell_at(u), self.cell_at(v));
        let (dc, dr) = (b.col as isize - a.col as isize, b.row as isize - a.row as isize);
        self.moves.iter().position(|m| m.dc == dc && m.dr == dr)
    }

    /// Statistics of a chain of cells (consecutive cells must be one move apart).
    pub(super) fn route_from_cells(&self, objective: Objective, cells: Vec<usize>) -> Route {
        let steps: Vec<RouteStep> = cells
            .windows(2)
            .filter_map(|w| self.move_between(w[0], w[1]).map(|k| self.step(w[0], w[1], k)))
            .collect();
        let mut regimes = [0; 4];
        for s in &steps {
            regimes[Regime::ALL.iter().position(|&r| r == s.regime).unwrap_or(0)] += 1;
        }
        let time_s = steps.iter().try_fold(0.0, |acc, s| match s.speed {
            Some(v) if v > 0.0 && !s.over_roll_limit && !s.regime.is_failure() => Some(acc + s.length_m / v),
            _ => None,
        });
        let log_survival: f64 = steps.iter().map(|s| s.cells_crossed * (-s.p_fail).ln_1p()).sum();
        Route {
            objective,
            cells: cells.iter().map(|&i| self.cell_at(i)).collect(),
            length_m: steps.iter().map(|s| s.length_m).sum(),
            time_s,
            survival: log_survival.exp(),
            max_pitch_deg: steps.iter().map(|s| s.pitch_deg.abs()).fold(0.0, f64::max),
            max_roll_deg: steps.iter().map(|s| s.roll_deg).fold(0.0, f64::max),
            regimes,
            over_roll_limit: steps.iter().filter(|s| s.over_roll_limit).count(),
            steps,
        }
    }
}
