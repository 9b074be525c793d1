//! # sandslope-raster
//!
//! Raster files for `sandslope plan`: the format of a file decided by its extension or first
//! bytes, and each read by its own module (GeoTIFF in [`geotiff`], ESRI ASCII grids in
//! `ascii`, PDS3 DTMs in [`crate::pds3`]) into one [`Raster`] ([`grid`]), their coordinate
//! reference systems ([`crs`]); a raster's heights read window by window
//! ([`open_height_windows`]); and a two-band float32 GeoTIFF writer georeferenced like the
//! input. Nothing here needs the `sandslope` library, so a first build compiles this crate
//! beside it; the corridor search's `HeightSource` over these windows is sandslope-io's
//! `height_windows`.

#![warn(missing_docs)]

use std::path::Path;

use anyhow::{bail, Result};

use crate::crs::Crs;

mod ascii;
mod chunks;
pub mod crs;
pub mod geotiff;
pub mod grid;
mod lzw_tiles;
pub mod pds3;
mod seam;
mod tiles;
mod windows;

use ascii::read_asc;
pub use geotiff::{geotiff_nodata, write_two_band_geotiff, MAX_TIFF_TAG_BYTES};
use geotiff::{read_geotiff, samples_as};
pub use grid::{
    available_memory, memory_limit, set_memory_limit, GeoRef, Raster, SizeCheck, DEFAULT_MEMORY_LIMIT,
};
pub use seam::{rolled_column, seam_roll, wraps_in_longitude};
pub use tiles::{write_two_band_geotiff_by_rows, TILE};
pub use windows::{open_height_windows, RasterWindows, WindowsCheck};

/// Reads a GeoTIFF (`.tif`, `.tiff`), an ESRI ASCII grid (`.asc`) or a PDS3 DTM (`.img` with
/// its label attached or a `.lbl` beside it, or the `.lbl`; any file beginning with a PDS3
/// label), by extension or, for other names, by its first bytes.
pub fn read_raster(path: &Path) -> Result<Raster> {
    read_raster_within(path, &|_, _| Ok(()))
}

/// [`read_raster`], with `fits(cols, rows)` called once the header gives the size and before
/// anything of that size is allocated or decoded: its error refuses the raster.
pub fn read_raster_within(path: &Path, fits: SizeCheck) -> Result<Raster> {
    let (mut raster, vertical) = match Format::of(path)? {
        Format::GeoTiff => {
            let (mut raster, vertical, image) = read_geotiff(path, fits, 8)?;
            let n = raster.cols * raster.rows;
            raster.values =
                samples_as(&path.display(), image, n, |v| v, |v| v.into_iter().map(f64::from).collect())?;
            (raster, vertical)
        }
        Format::Asc => read_asc(path, fits)?,
        // PDS3 rasters carry their own cell size in metres (pds3.rs).
        Format::Pds3 => return crate::pds3::read_pds3_within(path, fits),
    };
    if vertical != 1.0 {
        for v in raster.values.iter_mut().filter(|v| v.is_finite()) {
            *v *= vertical;
        }
    }
    finish(path, raster, vertical)
}

/// A raster's heights in metres as `f32` (the planner's precision), nodata cells as NaN, with
/// the raster's georeference (its `values` left empty): [`read_raster_within`] without the
/// `f64` copy of the samples, so a float32 GeoTIFF is held once, 4 bytes a cell (its decoded
/// buffer is converted in place). Each height is the `f64` value [`read_raster_within`] gives
/// rounded to `f32`, and NaN exactly where [`Raster::is_nodata`] holds; an ASCII grid or a PDS3
/// DTM is read as `f64` first and converted.
pub fn read_heights_within(path: &Path, fits: SizeCheck) -> Result<(Raster, Vec<f32>)> {
    let to_f32 = |raster: &Raster, v: f64| if raster.is_nodata_value(v) { f32::NAN } else { v as f32 };
    if Format::of(path)? != Format::GeoTiff {
        let mut raster = read_raster_within(path, fits)?;
        let values = std::mem::take(&mut raster.values);
        let heights = values.iter().map(|&v| to_f32(&raster, v)).collect();
        return Ok((raster, heights));
    }
    let (raster, vertical, image) = read_geotiff(path, fits, 4)?;
    let raster = finish(path, raster, vertical)?;
    let height = |v: f64| to_f32(&raster, if v.is_finite() { v * vertical } else { v });
    let n = raster.cols * raster.rows;
    let heights = samples_as(&path.display(), image, n, height, |v| {
        v.into_iter().map(|x| height(f64::from(x))).collect()
    })?;
    Ok((raster, heights))
}

/// The raster formats read, by extension or, for other names, by the first bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Format {
    GeoTiff,
    Asc,
    Pds3,
}

impl Format {
    fn of(path: &Path) -> Result<Format> {
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        Ok(match ext.as_deref() {
            Some("tif" | "tiff") => Format::GeoTiff,
            Some("asc") => Format::Asc,
            Some("img" | "lbl") => Format::Pds3,
            _ if crate::pds3::starts_with_label(path) => Format::Pds3,
            // ISIS3 cubes (CTX DTMs made with ISIS are often shared as .cub): not read.
            Some("cub") => bail!(
                "{}: an ISIS cube (.cub) is not read; export it to a GeoTIFF (ISIS isis2std format=tiff, or \
                 gdal_translate -of GTiff) or to a PDS3 .IMG (ISIS isis2pds), which are: GeoTIFF (.tif, .tiff), \
                 ESRI ASCII grid (.asc), PDS3 DTM (.img, .lbl)",
                path.display()
            ),
            _ => bail!(
                "{}: unknown raster format; use a GeoTIFF (.tif, .tiff), an ESRI ASCII grid (.asc) or a PDS3 DTM \
                 (.img, .lbl)",
                path.display()
            ),
        })
    }
}

/// A GeoTIFF or ASCII grid read so far, its heights (if any) already in metres: the nodata
/// value converted by `vertical` too, the ground cell size and the notes on the CRS.
fn finish(path: &Path, mut raster: Raster, vertical: f64) -> Result<Raster> {
    if vertical != 1.0 {
        raster.nodata = raster.nodata.map(|nd| nd * vertical);
    }
    let g = &raster.geo;
    let south = g.north - raster.rows as f64 * g.cell_y;
    let cells = crate::crs::ground_cell_size(
        &path.display(),
        &raster.crs,
        g.cell_x,
        g.cell_y,
        g.north,
        south,
        raster.rows,
        &mut raster.notes,
    )?;
    (raster.cell_m, raster.row_widths_m) = (cells.cell_m, cells.row_widths_m);
    // An equirectangular map in metres (a CTX DTM from ISIS or GDAL): each row its own width.
    if let Crs::Projected { metres_per_unit, .. } = raster.crs {
        let rows = crate::crs::equirectangular_rows(
            &path.display(),
            g.geokeys.as_deref(),
            g.geodoubles.as_deref(),
            metres_per_unit,
            (g.cell_x, g.cell_y),
            g.north,
            raster.rows,
            &mut raster.notes,
        )?;
        if let Some(cells) = rows {
            (raster.cell_m, raster.row_widths_m) = (cells.cell_m, cells.row_widths_m);
        }
    }
    if !raster.crs.is_geographic()
        && g.cell_x < 0.01
        && g.west.abs() <= 180.0
        && g.north.abs() <= 90.0
        && south >= -90.0
    {
        raster.notes.push(format!(
            "{}: cells of {} map units inside the longitude/latitude range look like degrees, but the file \
             declares no geographic CRS; they are read as {}s",
            path.display(),
            g.cell_x,
            match &raster.crs {
                Crs::Projected { unit, .. } => unit,
                Crs::Geographic { .. } => "degree",
            }
        ));
    }
    Ok(raster)
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod hostile;
