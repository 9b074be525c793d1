//! A digital elevation model on a regular grid and its surface gradient (Horn's method).
//!
//! Row 0 is the northern edge, columns run east; map `x` grows east and `y` grows north, so
//! a step of one row is `-cell_y` in `y`. No file formats here: readers build the grid.

use super::PlanError;

/// Heights on a regular grid with a nodata mask. Build it with [`ElevationGrid::new`].
#[derive(Debug, Clone, PartialEq)]
pub struct ElevationGrid {
    cols: usize,
    rows: usize,
    cell_x: f64,
    cell_y: f64,
    z: Vec<f32>,
    valid: Vec<bool>,
}

/// A cell of a grid, by column (east) and row (south).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub struct Cell {
    /// Column, 0 at the western edge.
    pub col: usize,
    /// Row, 0 at the northern edge.
    pub row: usize,
}

impl ElevationGrid {
    /// A grid of `cols x rows` cells of `cell_x` by `cell_y` metres holding heights `z` (m,
    /// row-major from the north-west corner). A cell is nodata where `nodata[i]` is true or its
    /// height is not finite. Fails on a size mismatch, fewer than 3 x 3 cells, or a cell size
    /// that is not finite and positive.
    pub fn new(
        cols: usize,
        rows: usize,
        cell_x: f64,
        cell_y: f64,
        z: Vec<f32>,
        nodata: Option<&[bool]>,
    ) -> Result<ElevationGrid, PlanError> {
        for (key, v) in [("cell size x", cell_x), ("cell size y", cell_y)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(PlanError::Grid(format!("{key} = {v} must be a finite number greater than 0")));
            }
        }
        if cols < 3 || rows < 3 {
            return Err(PlanError::Grid(format!(
                "the grid is {cols} x {rows} cells; at least 3 x 3 are needed"
            )));
        }
        let n = cols.checked_mul(rows).filter(|&n| n < u32::MAX as usize).ok_or_else(|| {
            PlanError::Grid(format!("{cols} x {rows} cells is more than the planner's 4 294 967 295"))
        })?;
        if z.len() != n || nodata.is_some_and(|m| m.len() != n) {
            return Err(PlanError::Grid(format!(
                "{} heights and {} nodata flags for a {cols} x {rows} grid ({n} cells)",
                z.len(),
                nodata.map_or(n, <[bool]>::len)
            )));
        }
        let valid = match nodata {
            Some(m) => z.iter().zip(m).map(|(h, &nd)| h.is_finite() && !nd).collect(),
            None => z.iter().map(|h| h.is_finite()).collect(),
        };
        Ok(ElevationGrid { cols, rows, cell_x, cell_y, z, valid })
    }

    /// A grid from heights as a raster holds them (`f64`, row-major from the north-west
    /// corner): a cell is nodata where its value equals the raster's declared `nodata` value
    /// (NaN matches NaN) or is not finite. Heights are stored as `f32` (a millimetre on a
    /// 10 km mountain). Fails as [`ElevationGrid::new`].
    pub fn from_heights(
        cols: usize,
        rows: usize,
        cell_x: f64,
        cell_y: f64,
        heights: &[f64],
        nodata: Option<f64>,
    ) -> Result<ElevationGrid, PlanError> {
        let is_nodata =
            |v: f64| !v.is_finite() || nodata.is_some_and(|nd| v == nd || (nd.is_nan() && v.is_nan()));
        let mask: Vec<bool> = heights.iter().map(|&v| is_nodata(v)).collect();
        let z: Vec<f32> = heights.iter().map(|&v| v as f32).collect();
        ElevationGrid::new(cols, rows, cell_x, cell_y, z, Some(&mask))
    }

    /// Whether `cell` lies on the outermost ring of cells, where no Horn gradient exists.
    pub fn on_border(&self, cell: Cell) -> bool {
        cell.col == 0 || cell.row == 0 || cell.col + 1 == self.cols || cell.row + 1 == self.rows
    }

    /// Number of columns (west to east).
    pub fn cols(&self) -> usize {
        self.cols
    }
    /// Number of rows (north to south).
    pub fn rows(&self) -> usize {
        self.rows
    }
    /// Cell width (east-west), m.
    pub fn cell_x(&self) -> f64 {
        self.cell_x
    }
    /// Cell height (north-south), m.
    pub fn cell_y(&self) -> f64 {
        self.cell_y
    }
    /// Number of cells.
    pub fn len(&self) -> usize {
        self.z.len()
    }
    /// Whether the grid has no cells (never true for a validated grid).
    pub fn is_empty(&self) -> bool {
        self.z.is_empty()
    }
    /// The flat index of `cell` (row-major), if it is inside the grid.
    pub fn index(&self, cell: Cell) -> Option<usize> {
        (cell.col < self.cols && cell.row < self.rows).then(|| cell.row * self.cols + cell.col)
    }
    /// The cell at flat index `i`.
    pub fn cell(&self, i: usize) -> Cell {
        Cell { col: i % self.cols, row: i / self.cols }
    }
    /// The height of `cell`, m, or `None` for nodata or outside the grid.
    pub fn height(&self, cell: Cell) -> Option<f64> {
        self.index(cell).filter(|&i| self.valid[i]).map(|i| f64::from(self.z[i]))
    }
    /// Whether the cell at flat index `i` holds a height.
    pub fn is_valid(&self, i: usize) -> bool {
        self.valid[i]
    }
    /// Heights, row-major (meaningless where [`ElevationGrid::is_valid`] is false).
    pub fn heights(&self) -> &[f32] {
        &self.z
    }

    /// The surface gradient `(dz/dx, dz/dy)` (x east, y north) of every cell by Horn's
    /// third-order finite difference over the 3 x 3 window; `None` (stored as NaN) where the
    /// cell is on the map border or any cell of its window is nodata.
    ///
    /// With the window `a b c / d e f / g h i` (north row first):
    /// `dz/dx = ((c + 2f + i) - (a + 2d + g)) / (8 cell_x)` and
    /// `dz/dy = ((a + 2b + c) - (g + 2h + i)) / (8 cell_y)`.
    pub fn horn_gradient(&self) -> Vec<[f32; 2]> {
        let (cols, rows) = (self.cols, self.rows);
        let mut out = vec![[f32::NAN; 2]; cols * rows];
        let row_fn = |r: usize, out_row: &mut [[f32; 2]]| {
            if r == 0 || r + 1 == rows {
                return;
            }
            for (c, out) in out_row.iter_mut().enumerate().take(cols - 1).skip(1) {
                *out = self.horn_at(c, r);
            }
        };
        use rayon::prelude::*;
        out.par_chunks_mut(cols).enumerate().for_each(|(r, chunk)| row_fn(r, chunk));
        out
    }

    /// The Horn gradient of the cell at column `c`, row `r` ([`ElevationGrid::horn_gradient`]),
    /// NaN on the border or next to nodata.
    #[inline(always)]
    pub fn horn_at(&self, c: usize, r: usize) -> [f32; 2] {
        let cols = self.cols;
        if c == 0 || r == 0 || c + 1 >= cols || r + 1 >= self.rows {
            return [f32::NAN; 2];
        }
        let (z, v) = (&self.z, &self.valid);
        let (sx, sy) = (1.0 / (8.0 * self.cell_x), 1.0 / (8.0 * self.cell_y));
        let (n, m, s) = ((r - 1) * cols + c, r * cols + c, (r + 1) * cols + c);
        let ok = [n - 1, n, n + 1, m - 1, m, m + 1, s - 1, s, s + 1].iter().all(|&i| v[i]);
        if !ok {
            return [f32::NAN; 2];
        }
        let h = |i: usize| f64::from(z[i]);
        let dzdx = ((h(n + 1) + 2.0 * h(m + 1) + h(s + 1)) - (h(n - 1) + 2.0 * h(m - 1) + h(s - 1))) * sx;
        let dzdy = ((h(n - 1) + 2.0 * h(n) + h(n + 1)) - (h(s - 1) + 2.0 * h(s) + h(s + 1))) * sy;
        [dzdx as f32, dzdy as f32]
    }

    /// The grid averaged into blocks of `factor` x `factor` cells (the last row and column of
    /// blocks may be smaller): a block's height is the mean of its cells with heights, nodata
    /// when fewer than half of its cells have one; cells `factor` times as large. Fails as
    /// [`ElevationGrid::new`] when that leaves fewer than 3 x 3 blocks.
    pub fn coarsened(&self, factor: usize) -> Result<ElevationGrid, PlanError> {
        use rayon::prelude::*;
        let f = factor.max(1);
        let (cc, cr) = (self.cols.div_ceil(f), self.rows.div_ceil(f));
        let mut z = vec![f32::NAN; cc * cr];
        z.par_chunks_mut(cc).enumerate().for_each(|(br, out)| {
            let rows = br * f..((br + 1) * f).min(self.rows);
            for (bc, out) in out.iter_mut().enumerate() {
                let cols = bc * f..((bc + 1) * f).min(self.cols);
                let (mut sum, mut n) = (0.0_f64, 0usize);
                for r in rows.clone() {
                    for i in r * self.cols + cols.start..r * self.cols + cols.end {
                        if self.valid[i] {
                            sum += f64::from(self.z[i]);
                            n += 1;
                        }
                    }
                }
                if 2 * n >= rows.len() * cols.len() && n > 0 {
                    *out = (sum / n as f64) as f32;
                }
            }
        });
        ElevationGrid::new(cc, cr, self.cell_x * f as f64, self.cell_y * f as f64, z, None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(cols: usize, rows: usize, dx: f64, dy: f64, a: f64, b: f64) -> ElevationGrid {
        // z = a x + b y with x east of the west edge and y north of the south edge.
        let mut z = Vec::new();
        for r in 0..rows {
            for c in 0..cols {
                let (x, y) = (c as f64 * dx, (rows - 1 - r) as f64 * dy);
                z.push((a * x + b * y) as f32);
            }
        }
        ElevationGrid::new(cols, rows, dx, dy, z, None).unwrap()
    }

    #[test]
    fn horn_recovers_a_plane_exactly_and_masks_the_border() {
        let g = plane(6, 5, 2.0, 3.0, 0.25, -0.5);
        let grad = g.horn_gradient();
        for r in 0..5 {
            for c in 0..6 {
                let [gx, gy] = grad[r * 6 + c];
                if r == 0 || r == 4 || c == 0 || c == 5 {
                    assert!(gx.is_nan() && gy.is_nan());
                } else {
                    assert!((gx - 0.25).abs() < 1e-5 && (gy + 0.5).abs() < 1e-5, "{gx} {gy}");
                }
            }
        }
    }

    #[test]
    fn nodata_poisons_its_window() {
        let mut mask = vec![false; 36];
        mask[2 * 6 + 2] = true;
        let g = ElevationGrid::new(6, 6, 1.0, 1.0, vec![1.0; 36], Some(&mask)).unwrap();
        let grad = g.horn_gradient();
        // Every interior cell within one of (2, 2) has no gradient; (4, 4) has one.
        for (c, r) in [(1, 1), (2, 2), (3, 3), (1, 3)] {
            assert!(grad[r * 6 + c][0].is_nan(), "{c} {r}");
        }
        assert_eq!(grad[4 * 6 + 4], [0.0, 0.0]);
    }

    #[test]
    fn from_heights_masks_the_declared_nodata_value_and_non_finite_heights() {
        let mut h = vec![2.0; 16];
        h[5] = -9999.0;
        h[6] = f64::NAN;
        let g = ElevationGrid::from_heights(4, 4, 1.0, 1.0, &h, Some(-9999.0)).unwrap();
        let valid: Vec<bool> = (0..16).map(|i| g.is_valid(i)).collect();
        assert_eq!(valid.iter().filter(|v| !**v).count(), 2);
        assert!(!valid[5] && !valid[6] && valid[7]);
        // Without a declared value, -9999 is a height.
        assert!(ElevationGrid::from_heights(4, 4, 1.0, 1.0, &h, None).unwrap().is_valid(5));
        assert!(g.on_border(Cell { col: 0, row: 2 }) && g.on_border(Cell { col: 2, row: 3 }));
        assert!(!g.on_border(Cell { col: 1, row: 2 }));
    }

    #[test]
    fn rejects_bad_grids() {
        assert!(ElevationGrid::new(2, 5, 1.0, 1.0, vec![0.0; 10], None).is_err());
        assert!(ElevationGrid::new(3, 3, 0.0, 1.0, vec![0.0; 9], None).is_err());
        assert!(ElevationGrid::new(3, 3, 1.0, 1.0, vec![0.0; 8], None).is_err());
    }
}
