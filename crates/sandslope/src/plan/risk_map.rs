//! Per-cell risk over all headings (the `--risk-map` raster) and the head-on climb of a cell
//! (the plan figure's tint), from the planner's gradients and pitch tables.

use std::ops::Range;

use rayon::prelude::*;

use super::grid::Cell;
use super::planner::{EdgeGeom, MoveGeom, Planner, HEADINGS};
use super::source::{window_grid, with_margin, HeightSource};
use super::{PitchTableCache, PlanError, PlanSettings};
use crate::regime::Regime;
use crate::risk::UncertainTerrain;
use crate::Robot;

/// Cells a band of [`risk_map_from`] holds at most, about (2^23: 256 rows of a 32,768-column
/// map; the band's planner takes some 30 bytes a cell, so about 250 MB).
pub const RISK_BAND_CELLS: usize = 1 << 23;

/// [`Planner::risk_map`] of a map read window by window, for maps too large to hold: the rows
/// are taken `band_rows` at a time (at least 1), each band read from `source` with a margin of
/// one row on each side (the whole width, so the map's own west and east borders), its planner
/// built on that window (one terrain everywhere) and its risk map cut to the band's rows.
/// A cell's values depend on its 3 x 3 window and its row's width alone, and the pitch tables
/// of a window are a prefix of the whole map's (the same step), so every band is the whole
/// map's [`Planner::risk_map`] rows bit for bit. `sink` is given each band's rows, its
/// best-heading P(failure) and its steepest-climb azimuth (row-major), in order from the north;
/// its error stops the pass and is returned.
pub fn risk_map_from<E: From<PlanError>>(
    source: &dyn HeightSource,
    terrain: &UncertainTerrain,
    robot: &Robot,
    settings: PlanSettings,
    band_rows: usize,
    mut sink: impl FnMut(Range<usize>, &[f32], &[f32]) -> Result<(), E>,
) -> Result<(), E> {
    let (cols, rows) = (source.cols(), source.rows());
    let band = band_rows.max(1);
    let cache = PitchTableCache::new();
    let terrains = std::slice::from_ref(terrain);
    for r0 in (0..rows).step_by(band) {
        let r1 = (r0 + band).min(rows);
        let wr = with_margin(r0, r1, rows);
        let grid = window_grid(source, wr.clone(), 0..cols)?;
        let planner = Planner::with_cache(grid, None, terrains, robot, settings, &cache)?;
        let (p_fail, azimuth) = planner.risk_map();
        let cut = (r0 - wr.start) * cols..(r1 - wr.start) * cols;
        sink(r0..r1, &p_fail[cut.clone()], &azimuth[cut])?;
    }
    Ok(())
}

impl Planner {
    /// The regime and P(failure) of climbing `cell` head-on, straight up its fall line
    /// (pitch `atan |grad z|`, no roll); `None` where the cell is impassable.
    pub fn fall_line(&self, cell: Cell) -> Option<(Regime, f64)> {
        let i = self.index_of(cell)?;
        let g = self.grad[i];
        if g[0].is_nan() {
            return None;
        }
        let (_, k) = self.entries(EdgeGeom { tan_pitch: g[0].hypot(g[1]), tan_roll: 0.0 })?;
        let t = &self.tables[usize::from(self.class[i])];
        Some((t.regime(k), t.p_fail(k)))
    }

    /// Per cell, P(failure) of climbing it head-on ([`Planner::fall_line`]); NaN where the cell
    /// is impassable. The explorer's `rule=fall-line` raster.
    pub fn fall_line_map(&self) -> Vec<f32> {
        let grid = self.grid();
        (0..grid.len()).map(|i| self.fall_line(grid.cell(i)).map_or(f32::NAN, |(_, p)| p as f32)).collect()
    }

    /// Per cell, the lowest P(failure) over the 16 headings (roll over the limit counts as
    /// failure), and the azimuth (degrees clockwise from north) of the steepest climbing
    /// heading the time objective may use; NaN where the cell is impassable or no heading
    /// qualifies. Uses the cell's own gradient, and the headings in its own row's metric (on
    /// a grid with per-row widths, the 16 moves' directions with the cell's row width east-west:
    /// a cell's values depend on its 3 x 3 window alone, so a raster computed tile by tile with a
    /// one-cell halo is this one, bit for bit).
    pub fn risk_map(&self) -> (Vec<f32>, Vec<f32>) {
        let allowed =
            |r: Regime| r == Regime::Success || (self.settings.allow_metastable() && r == Regime::Metastable);
        let cols = self.grid.cols();
        let rows = if self.grid.row_widths().is_some() { self.grid.rows() } else { 1 };
        let headings: Vec<[(MoveGeom, f64); HEADINGS]> = (0..rows).map(|r| self.headings_in_row(r)).collect();
        self.grad
            .par_iter()
            .zip(self.class.par_iter())
            .enumerate()
            .map(|(i, (g, &c))| {
                if g[0].is_nan() {
                    return (f32::NAN, f32::NAN);
                }
                let table = &self.tables[usize::from(c)];
                let mut best = 1.0_f64;
                let mut climb: Option<(f32, f64)> = None;
                for (m, azimuth) in &headings[(i / cols).min(rows - 1)] {
                    let e = EdgeGeom {
                        tan_pitch: g[0] * m.ux + g[1] * m.uy,
                        tan_roll: (g[0] * m.uy - g[1] * m.ux).abs(),
                    };
                    if e.tan_roll > self.tan_max_roll {
                        continue;
                    }
                    let Some((i, _)) = self.entries(e) else { continue };
                    best = best.min(table.p_fail(i));
                    if e.tan_pitch > 0.0
                        && allowed(table.regime(i))
                        && climb.is_none_or(|(t, _)| e.tan_pitch > t)
                    {
                        climb = Some((e.tan_pitch, *azimuth));
                    }
                }
                (best as f32, climb.map_or(f32::NAN, |(_, a)| a as f32))
            })
            .unzip()
    }
}
