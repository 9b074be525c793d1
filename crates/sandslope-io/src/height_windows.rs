//! A raster opened for window reads (sandslope-raster's [`RasterWindows`]) as the corridor
//! search's [`HeightSource`]: the one piece of reading a map by windows that needs the
//! library, kept here so that sandslope-raster compiles beside it.

use std::ops::{Deref, Range};
use std::path::Path;

use anyhow::Result;
use sandslope::plan::HeightSource;
use sandslope_raster::{Raster, RasterWindows, WindowsCheck};

/// A raster's heights read window by window (metres as `f32`, NaN where there is no height):
/// the corridor search's [`HeightSource`]; every [`RasterWindows`] method through `Deref`.
pub struct HeightWindows(pub RasterWindows);

impl Deref for HeightWindows {
    type Target = RasterWindows;
    fn deref(&self) -> &RasterWindows {
        &self.0
    }
}

impl HeightWindows {
    /// [`RasterWindows::into_heights`]: the whole map's heights when it is held in memory.
    pub fn into_heights(self) -> Option<Vec<f32>> {
        self.0.into_heights()
    }
    /// [`RasterWindows::rolled_columns`]: the windows with their columns rolled by `shift`.
    pub fn rolled_columns(self, shift: usize) -> HeightWindows {
        HeightWindows(self.0.rolled_columns(shift))
    }
}

/// [`sandslope_raster::open_height_windows`], the windows as a [`HeightSource`].
pub fn open_height_windows(path: &Path, fits: WindowsCheck) -> Result<(Raster, HeightWindows)> {
    let (raster, windows) = sandslope_raster::open_height_windows(path, fits)?;
    Ok((raster, HeightWindows(windows)))
}

impl HeightSource for HeightWindows {
    fn cols(&self) -> usize {
        self.0.cols()
    }
    fn rows(&self) -> usize {
        self.0.rows()
    }
    fn cell_x(&self) -> f64 {
        self.0.cell_m().0
    }
    fn cell_y(&self) -> f64 {
        self.0.cell_m().1
    }
    fn row_widths(&self) -> Option<&[f64]> {
        self.0.row_widths()
    }
    fn window(&self, rows: Range<usize>, cols: Range<usize>) -> Result<Vec<f32>, String> {
        self.0.read(rows, cols).map_err(|e| format!("{e:#}"))
    }
    fn band_rows(&self) -> usize {
        self.0.band_rows()
    }
}
