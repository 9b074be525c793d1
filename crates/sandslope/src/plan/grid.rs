//! A digital elevation model on a regular grid and its surface gradient (Horn's method).
//!
//! Row 0 is the northern edge, columns run east; map `x` grows east and `y` grows north, so
//! a step of one row is `-cell_y` in `y`. No file formats here: readers build the grid.
//!
//! A grid in geographic coordinates (degrees) has cells of one north-south size but an
//! east-west size that shrinks with latitude, `N(phi) cos(phi) dlambda`: such a grid carries
//! one width per row ([`ElevationGrid::with_row_widths`]), and everything that measures east-west
//! (Horn gradients, move lengths and headings, the heuristic) uses the row's.

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
    /// East-west size of each row's cells, m; empty when every row is `cell_x` wide.
    row_cell_x: Vec<f64>,
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
        Ok(ElevationGrid { cols, rows, cell_x, cell_y, z, valid, row_cell_x: Vec::new() })
    }

    /// The grid with the east-west cell size of each row given (`widths[r]`, m, row 0 at the
    /// north), as in a geographic DEM whose cells narrow towards the pole; `cell_x` stays the
    /// grid's reference width (the mid-latitude's, from the readers), which sets only the
    /// cell length of the risk objective (docs/model.md §9). Fails unless there is one finite,
    /// positive width per row. Equal widths leave the grid uniform, as cheap as one built by
    /// [`ElevationGrid::new`] with that width.
    pub fn with_row_widths(mut self, widths: Vec<f64>) -> Result<ElevationGrid, PlanError> {
        if widths.len() != self.rows {
            return Err(PlanError::Grid(format!(
                "{} row widths for a grid of {} rows",
                widths.len(),
                self.rows
            )));
        }
        if let Some((r, w)) = widths.iter().enumerate().find(|(_, w)| !(w.is_finite() && **w > 0.0)) {
            return Err(PlanError::Grid(format!(
                "cell size x of row {r} = {w} must be a finite number greater than 0"
            )));
        }
        if widths.iter().all(|&w| w == widths[0]) {
            self.cell_x = widths[0];
            self.row_cell_x = Vec::new();
        } else {
            self.row_cell_x = widths;
        }
        Ok(self)
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
    /// Cell width (east-west), m: every row's on a uniform grid; on a grid with per-row widths
    /// ([`ElevationGrid::with_row_widths`]) the reference width it was built with.
    pub fn cell_x(&self) -> f64 {
        self.cell_x
    }
    /// The east-west size of row `row`'s cells, m (the last row's beyond the grid).
    #[inline(always)]
    pub fn cell_x_at(&self, row: usize) -> f64 {
        if self.row_cell_x.is_empty() {
            self.cell_x
        } else {
            self.row_cell_x[row.min(self.rows - 1)]
        }
    }
    /// The east-west size of each row's cells, if the rows differ (`None`: every row is
    /// [`ElevationGrid::cell_x`] wide).
    pub fn row_widths(&self) -> Option<&[f64]> {
        (!self.row_cell_x.is_empty()).then_some(&self.row_cell_x[..])
    }
    /// The smallest east-west cell size of any row, m.
    pub fn min_cell_x(&self) -> f64 {
        self.row_cell_x
            .iter()
            .copied()
            .fold(if self.row_cell_x.is_empty() { self.cell_x } else { f64::INFINITY }, f64::min)
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
    /// `dz/dy = ((a + 2b + c) - (g + 2h + i)) / (8 cell_y)`, where `cell_x` is the centre
    /// row's width on a grid with per-row widths (docs/model.md §8).
    pub fn horn_gradient(&self) -> Vec<[f32; 2]> {
        let (cols, rows) = (self.cols, self.rows);
        let mut out = vec![[f32::NAN; 2]; cols * rows];
        use rayon::prelude::*;
        out.par_chunks_mut(cols).enumerate().for_each(|(r, chunk)| {
            if r != 0 && r + 1 != rows {
                self.horn_row(r, chunk);
            }
        });
        out
    }

    /// [`ElevationGrid::horn_at`] for every interior cell of the interior row `r`, into `out`
    /// (the row's gradients; its first and last stay as they are): the same arithmetic in the
    /// same order, with the row's scale and the three rows' slices taken once (the per-cell
    /// form took 0.28 s of CPU of a 4096 x 4096 plan, the third of everything before its
    /// searches).
    fn horn_row(&self, r: usize, out: &mut [[f32; 2]]) {
        let cols = self.cols;
        let (sx, sy) = (1.0 / (8.0 * self.cell_x_at(r)), 1.0 / (8.0 * self.cell_y));
        let row = |k: usize| (&self.z[k * cols..(k + 1) * cols], &self.valid[k * cols..(k + 1) * cols]);
        let ((zn, vn), (zm, vm), (zs, vs)) = (row(r - 1), row(r), row(r + 1));
        let windows = zn.windows(3).zip(zm.windows(3)).zip(zs.windows(3));
        let valid = vn.windows(3).zip(vm.windows(3)).zip(vs.windows(3));
        for ((((n, m), s), ((a, b), c)), out) in windows.zip(valid).zip(&mut out[1..cols - 1]) {
            if !(a.iter().chain(b).chain(c).all(|&v| v)) {
                *out = [f32::NAN; 2];
                continue;
            }
            let h = |z: &[f32], i: usize| f64::from(z[i]);
            let dzdx = ((h(n, 2) + 2.0 * h(m, 2) + h(s, 2)) - (h(n, 0) + 2.0 * h(m, 0) + h(s, 0))) * sx;
            let dzdy = ((h(n, 0) + 2.0 * h(n, 1) + h(n, 2)) - (h(s, 0) + 2.0 * h(s, 1) + h(s, 2))) * sy;
            *out = [dzdx as f32, dzdy as f32];
        }
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
        let (sx, sy) = (1.0 / (8.0 * self.cell_x_at(r)), 1.0 / (8.0 * self.cell_y));
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
    /// when fewer than half of its cells have one; cells `factor` times as large (a block row
    /// `factor` times its rows' mean width when the rows differ). Fails as
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
        let grid = ElevationGrid::new(cc, cr, self.cell_x * f as f64, self.cell_y * f as f64, z, None)?;
        if self.row_cell_x.is_empty() {
            return Ok(grid);
        }
        let widths = self
            .row_cell_x
            .chunks(f)
            .map(|rows| f as f64 * rows.iter().sum::<f64>() / rows.len() as f64)
            .collect();
        grid.with_row_widths(widths)
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
    fn the_whole_grid_s_gradients_are_the_per_cell_ones_bit_for_bit() {
        // The corridor search takes gradients cell by cell (`horn_at`), the full search the
        // whole grid's row by row: on a bumpy grid with nodata and rows of different widths
        // the two must be the same numbers, or the two searches would see different maps.
        let (cols, rows) = (23, 17);
        let z: Vec<f32> = (0..cols * rows)
            .map(|i| {
                let (c, r) = ((i % cols) as f32, (i / cols) as f32);
                (0.37 * c).sin() * 3.0 + (0.21 * r * c).cos() + 0.013 * r * r
            })
            .collect();
        let mask: Vec<bool> = (0..cols * rows).map(|i| i % 29 == 7 || i == 5 * cols + 11).collect();
        let widths = (0..rows).map(|r| 0.7 + 0.01 * r as f64).collect();
        let g = ElevationGrid::new(cols, rows, 0.8, 0.9, z, Some(&mask))
            .unwrap()
            .with_row_widths(widths)
            .unwrap();
        let grad = g.horn_gradient();
        let (mut nan, mut finite) = (0, 0);
        for r in 0..rows {
            for c in 0..cols {
                let (a, b) = (grad[r * cols + c], g.horn_at(c, r));
                assert_eq!(a.map(f32::to_bits), b.map(f32::to_bits), "cell ({c}, {r}): {a:?} vs {b:?}");
                if a[0].is_nan() {
                    nan += 1;
                } else {
                    finite += 1;
                }
            }
        }
        // Both kinds of cell were compared.
        assert!(nan > 2 * (cols + rows) && finite > cols * rows / 3, "{nan} {finite}");
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

    /// A plane tilted 0.1 east and -0.05 north on a geographic grid, 0.25-degree cells from
    /// 60 to 30 degrees north on a sphere of 6371 km: each row's Horn gradient recovers the
    /// tilt when the row's own width is used, where one mid-latitude width misreads it by the
    /// ratio of the widths (cos 59.875 / cos 45 = 0.71 at the northern row).
    #[test]
    fn horn_recovers_an_east_tilt_on_every_row_of_a_geographic_grid() {
        let (cols, rows, r_m) = (5, 120, 6_371_000.0_f64);
        let d = 0.25_f64.to_radians();
        let lat = |r: usize| (60.0 - (r as f64 + 0.5) * 0.25_f64).to_radians();
        let widths: Vec<f64> = (0..rows).map(|r| r_m * lat(r).cos() * d).collect();
        let cell_y = r_m * d;
        // Heights from ground metres: x east along the row from the middle column (the
        // meridian of the cells tested), y north of the southern row.
        let z: Vec<f32> = (0..rows * cols)
            .map(|i| {
                let (c, r) = (i % cols, i / cols);
                (0.1 * (c as f64 - 2.0) * widths[r] - 0.05 * (rows - 1 - r) as f64 * cell_y) as f32
            })
            .collect();
        let mid = r_m * 45.0_f64.to_radians().cos() * d;
        let uniform = ElevationGrid::new(cols, rows, mid, cell_y, z, None).unwrap();
        let g = uniform.clone().with_row_widths(widths.clone()).unwrap();
        for r in 1..rows - 1 {
            let [gx, gy] = g.horn_at(2, r);
            // The window's outer rows are a little wider or narrower than its centre: the
            // east tilt is read within their second difference, (d lat)^2 / 4 = 5e-6.
            assert!((f64::from(gx) / 0.1 - 1.0).abs() < 2e-5, "row {r}: {gx}");
            assert!((f64::from(gy) / -0.05 - 1.0).abs() < 1e-4, "row {r}: {gy}");
        }
        let [gx0, _] = uniform.horn_at(2, 1);
        let want = 0.1 * widths[1] / mid;
        assert!((f64::from(gx0) / want - 1.0).abs() < 1e-4 && want < 0.072, "{gx0} vs {want}");
    }

    #[test]
    fn row_widths_are_checked_and_equal_ones_leave_the_grid_uniform() {
        let g = ElevationGrid::new(3, 4, 2.0, 1.0, vec![0.0; 12], None).unwrap();
        assert!(g.clone().with_row_widths(vec![1.0; 3]).is_err());
        assert!(g.clone().with_row_widths(vec![1.0, 0.0, 1.0, 1.0]).is_err());
        assert!(g.clone().with_row_widths(vec![1.0, f64::NAN, 1.0, 1.0]).is_err());
        let same = g.clone().with_row_widths(vec![1.5; 4]).unwrap();
        assert_eq!(same, ElevationGrid::new(3, 4, 1.5, 1.0, vec![0.0; 12], None).unwrap());
        assert_eq!(same.row_widths(), None);
        let rows = g.with_row_widths(vec![4.0, 3.0, 2.0, 1.0]).unwrap();
        assert_eq!((rows.cell_x(), rows.cell_x_at(1), rows.min_cell_x()), (2.0, 3.0, 1.0));
    }

    #[test]
    fn rejects_bad_grids() {
        assert!(ElevationGrid::new(2, 5, 1.0, 1.0, vec![0.0; 10], None).is_err());
        assert!(ElevationGrid::new(3, 3, 0.0, 1.0, vec![0.0; 9], None).is_err());
        assert!(ElevationGrid::new(3, 3, 1.0, 1.0, vec![0.0; 8], None).is_err());
    }
}
