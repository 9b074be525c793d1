//! Elevation models read window by window (issue 56): what the corridor search needs of a map
//! too large to hold. The coarse grid is built from bands of rows streamed once
//! ([`coarsened_from`]), and each corridor planner reads only the windows its rows cover
//! (`Planner::corridor_from`), with the Horn gradients computed by the same
//! [`ElevationGrid::horn_at`] on a window one cell larger on every side, so they are the whole
//! map's bit for bit.

use std::ops::Range;

use rayon::prelude::*;

use super::grid::ElevationGrid;
use super::PlanError;

/// A map whose heights are read window by window: its size, its ground cells, and the heights
/// of any window (metres as `f32`, NaN where there is no height), as a file reader gives them
/// without holding the whole map. An [`ElevationGrid`] is one, held in memory.
pub trait HeightSource: Sync {
    /// Columns (west to east).
    fn cols(&self) -> usize;
    /// Rows (north to south).
    fn rows(&self) -> usize;
    /// Cell width (east-west), m: the reference width when the rows differ.
    fn cell_x(&self) -> f64;
    /// Cell height (north-south), m.
    fn cell_y(&self) -> f64;
    /// The east-west size of each row's cells, m, when the rows differ.
    fn row_widths(&self) -> Option<&[f64]>;
    /// The heights of rows `rows` and columns `cols` (inside the map), row-major, NaN where
    /// there is no height; an error says why the window could not be read.
    fn window(&self, rows: Range<usize>, cols: Range<usize>) -> Result<Vec<f32>, String>;
    /// How many rows a pass over the map reads at once (a multiple of the file's strips or
    /// tiles is cheapest).
    fn band_rows(&self) -> usize {
        256
    }
}

impl HeightSource for ElevationGrid {
    fn cols(&self) -> usize {
        ElevationGrid::cols(self)
    }
    fn rows(&self) -> usize {
        ElevationGrid::rows(self)
    }
    fn cell_x(&self) -> f64 {
        ElevationGrid::cell_x(self)
    }
    fn cell_y(&self) -> f64 {
        ElevationGrid::cell_y(self)
    }
    fn row_widths(&self) -> Option<&[f64]> {
        ElevationGrid::row_widths(self)
    }
    fn window(&self, rows: Range<usize>, cols: Range<usize>) -> Result<Vec<f32>, String> {
        let n = ElevationGrid::cols(self);
        Ok(rows
            .flat_map(|r| cols.clone().map(move |c| r * n + c))
            .map(|i| if self.is_valid(i) { self.heights()[i] } else { f32::NAN })
            .collect())
    }
}

/// The source's map averaged into blocks of `factor` x `factor` cells, as
/// [`ElevationGrid::coarsened`] averages a grid (the same sums in the same order, so the same
/// numbers), reading bands of whole rows one at a time: only a band and the coarse grid are
/// held.
pub fn coarsened_from(source: &dyn HeightSource, factor: usize) -> Result<ElevationGrid, PlanError> {
    let f = factor.max(1);
    let (cols, rows) = (source.cols(), source.rows());
    let (cc, cr) = (cols.div_ceil(f), rows.div_ceil(f));
    // Whole block rows a band, about the source's preferred band.
    let blocks_a_band = source.band_rows().div_ceil(f).max(1);
    let mut z = vec![f32::NAN; cc * cr];
    for (band, out) in z.chunks_mut(cc * blocks_a_band).enumerate() {
        let r0 = band * blocks_a_band * f;
        let r1 = (r0 + blocks_a_band * f).min(rows);
        let heights = source.window(r0..r1, 0..cols).map_err(PlanError::Grid)?;
        out.par_chunks_mut(cc).enumerate().for_each(|(k, out)| {
            let block_rows = (k * f)..((k + 1) * f).min(r1 - r0);
            for (bc, out) in out.iter_mut().enumerate() {
                let bcols = bc * f..((bc + 1) * f).min(cols);
                let (mut sum, mut n) = (0.0_f64, 0usize);
                for r in block_rows.clone() {
                    for &h in &heights[r * cols + bcols.start..r * cols + bcols.end] {
                        if h.is_finite() {
                            sum += f64::from(h);
                            n += 1;
                        }
                    }
                }
                if 2 * n >= block_rows.len() * bcols.len() && n > 0 {
                    *out = (sum / n as f64) as f32;
                }
            }
        });
    }
    let grid = ElevationGrid::new(cc, cr, source.cell_x() * f as f64, source.cell_y() * f as f64, z, None)?;
    let Some(widths) = source.row_widths() else { return Ok(grid) };
    let widths =
        widths.chunks(f).map(|rows| f as f64 * rows.iter().sum::<f64>() / rows.len() as f64).collect();
    grid.with_row_widths(widths)
}

/// A window of the source as a grid of its own, with its rows' widths, for Horn gradients:
/// rows `rows` and columns `cols` (each at least 3 long).
pub(super) fn window_grid(
    source: &dyn HeightSource,
    rows: Range<usize>,
    cols: Range<usize>,
) -> Result<ElevationGrid, PlanError> {
    let z = source.window(rows.clone(), cols.clone()).map_err(PlanError::Grid)?;
    let grid = ElevationGrid::new(cols.len(), rows.len(), source.cell_x(), source.cell_y(), z, None)?;
    match source.row_widths() {
        Some(w) => grid.with_row_widths(w[rows].to_vec()),
        None => Ok(grid),
    }
}

/// The range `lo..hi` widened by one on each side within `0..n`, and to at least 3 long.
pub(super) fn with_margin(lo: usize, hi: usize, n: usize) -> Range<usize> {
    let (mut a, mut b) = (lo.saturating_sub(1), (hi + 1).min(n));
    while b - a < 3 && (a > 0 || b < n) {
        if b < n {
            b += 1;
        } else {
            a -= 1;
        }
    }
    a..b
}

#[cfg(test)]
mod source_tests;
