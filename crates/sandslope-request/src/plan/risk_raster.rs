//! `plan --risk-map` over a DEM larger than memory (issue 56): the per-cell risk raster
//! computed band of rows by band of rows from the heights read window by window
//! ([`sandslope::plan::risk_map_from`], the in-memory raster bit for bit) and written tile row
//! by tile row ([`write_two_band_geotiff_by_rows`]), so only a band is held.

use std::path::Path;

use anyhow::anyhow;

use sandslope::plan::{risk_map_from, HeightSource, RISK_BAND_CELLS};
use sandslope_io::height_windows::HeightWindows;
use sandslope_raster::{write_two_band_geotiff_by_rows, Raster, TILE};

use super::PlanRequest;
use crate::error::{RequestError, Result};

/// Rows a band of the streamed risk raster takes for a map `cols` wide: about
/// [`RISK_BAND_CELLS`] cells, whole rows of tiles, at least one row of tiles.
pub fn risk_band_rows(cols: usize) -> usize {
    (RISK_BAND_CELLS / cols.max(1) / TILE).max(1) * TILE
}

impl PlanRequest {
    /// Writes the risk raster of the DEM whose header is `dem` and whose heights `heights`
    /// reads, to the GeoTIFF `path` (a tiled two-band float32 file, the bands of
    /// `--risk-map`), band of rows by band of rows, telling `progress` `(rows done, rows)`
    /// after each; one terrain everywhere (terrain classes need the in-memory planner). A
    /// window that cannot be read stops it with the reader's error, and no file is left.
    pub fn write_streamed_risk_map(
        &self,
        dem: &Raster,
        heights: &HeightWindows,
        path: &Path,
        progress: &dyn Fn(u64, u64),
    ) -> Result<()> {
        let robot = self.robot.load()?;
        let settings = self.settings()?;
        let (classes, terrains) = self.load_classes(dem).map_err(|e| RequestError::from_error(None, e))?;
        let (None, [terrain]) = (&classes, terrains.as_slice()) else {
            return Err(RequestError::invalid(
                super::CLASSES.flag,
                format!(
                    "a risk map with {} needs the full-resolution search ({} full)",
                    super::CLASSES.long(),
                    super::SEARCH.long()
                ),
            ));
        };
        let (cols, rows) = (heights.cols(), heights.rows());
        let band = risk_band_rows(cols);
        // A window's read error names the file and offset; the planner's are said of the DEM.
        let in_dem = |e: &anyhow::Error| match e.downcast_ref::<sandslope::plan::PlanError>() {
            Some(sandslope::plan::PlanError::Grid(read)) => anyhow!("{read}"),
            _ => anyhow!("{}: {e:#}", self.dem.display()),
        };
        write_two_band_geotiff_by_rows(path, cols, rows, &dem.geo, |push| {
            risk_map_from(heights, terrain, &robot, settings, band, |done, p, a| {
                push(p, a)?;
                progress(done.end as u64, rows as u64);
                Ok::<(), anyhow::Error>(())
            })
            .map_err(|e| in_dem(&e))
        })
        .map_err(|e| RequestError::from_error(None, e))
    }
}
