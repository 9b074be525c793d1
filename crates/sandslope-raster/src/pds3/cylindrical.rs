//! `MAP_PROJECTION_TYPE = "SIMPLE CYLINDRICAL"`, the projection of every MOLA MEGDR (issue
//! 56): longitude and latitude on a grid of `MAP_RESOLUTION` pixels a degree, the standard
//! parallel at the equator (an equirectangular map whose x is `R lambda` and y `R phi`). Read as
//! a geographic raster in degrees on the body's sphere, so that `--start/--goal` and the
//! GeoJSON are longitude,latitude and each row has its own east-west ground width
//! `R cos(phi) (pi / 180) / MAP_RESOLUTION`, as for a geographic GeoTIFF.
//!
//! The projection offsets follow the MEGDR's own definition (its DSMAP.CAT, and the PDS3
//! Standards Reference's for this projection), where lines and samples count from 1 at the
//! north-west pixel's centre: `longitude = CENTER_LONGITUDE + (sample -
//! SAMPLE_PROJECTION_OFFSET) / MAP_RESOLUTION` and `latitude = CENTER_LATITUDE +
//! (LINE_PROJECTION_OFFSET - line) / MAP_RESOLUTION`. That convention differs by one pixel
//! from the 0-based one of HiRISE and ISIS exports (`projection.rs`); where the label states
//! its extent (`WESTERNMOST_LONGITUDE`, `MAXIMUM_LATITUDE`) the convention that reproduces it
//! is taken, and a label that matches neither is refused naming the keys.

use anyhow::{anyhow, bail, Result};

use super::label::Label;
use crate::crs::{Crs, Ellipsoid, GroundCells};
use crate::grid::GeoRef;

/// Degrees of difference between the label's stated extent and the computed one that still
/// count as agreement: a hundredth of a pixel at 128 pixels a degree.
const EXTENT_TOLERANCE_PIXELS: f64 = 0.01;

/// The georeferencing in degrees, the ground cells in metres and the geographic CRS of a
/// SIMPLE CYLINDRICAL map of `rows` x `cols` on a sphere of `radius_m` metres.
pub(super) fn simple_cylindrical(
    label: &Label,
    rows: u64,
    cols: u64,
    radius_m: f64,
    body: &str,
    notes: &mut Vec<String>,
) -> Result<(GeoRef, GroundCells, Crs)> {
    let name = &label.name;
    let map = |key: &str| format!("IMAGE_MAP_PROJECTION.{key}");
    if let Some((dir, line)) = label.word(&map("POSITIVE_LONGITUDE_DIRECTION")) {
        if dir != "EAST" {
            bail!(
                "{name}: line {line}: POSITIVE_LONGITUDE_DIRECTION = {dir} is not supported (EAST, as every MOLA \
                 MEGDR is labelled); convert it to east-positive longitudes first"
            );
        }
    }
    let metres_per_degree = radius_m * std::f64::consts::PI / 180.0;
    // Pixels a degree: MAP_RESOLUTION, exact in the label; else from MAP_SCALE, which MEGDR
    // labels round (0.463 KM/PIXEL at 128 pixels a degree is 463.06 m: 5.6 pixels across the globe).
    let scale_m = map_scale_m(label)?;
    let res = match label.number(&map("MAP_RESOLUTION"))? {
        Some((r, _)) if r.is_finite() && r > 0.0 && r <= 1e6 => {
            if let Some(s) = scale_m {
                let from_res = metres_per_degree / r;
                if (s / from_res - 1.0).abs() > 0.005 {
                    notes.push(format!(
                        "{name}: MAP_SCALE = {s} m a pixel differs from MAP_RESOLUTION = {r} pixels a degree on the \
                         sphere of A_AXIS_RADIUS ({from_res:.3} m) by more than 0.5%; MAP_RESOLUTION is used"
                    ));
                }
            }
            r
        }
        Some((r, _)) => {
            bail!("{name}: MAP_RESOLUTION = {r} must be a number of pixels a degree greater than 0")
        }
        None => {
            let s = scale_m.ok_or_else(|| {
                anyhow!("{name}: the label has neither IMAGE_MAP_PROJECTION.MAP_RESOLUTION nor MAP_SCALE")
            })?;
            metres_per_degree / s
        }
    };
    let cell = 1.0 / res;
    let (west, north) = north_west_corner(label, cell, notes)?;
    let south = north - rows as f64 * cell;
    let tol = 1e-9 * (1.0 + cell);
    if north > 90.0 + tol || south < -90.0 - tol {
        bail!(
            "{name}: LINES = {rows} at MAP_RESOLUTION = {res} pixels a degree from latitude {north} reach latitude \
             {south}: beyond a pole"
        );
    }
    if cols as f64 * cell > 360.0 + tol {
        bail!("{name}: LINE_SAMPLES = {cols} at MAP_RESOLUTION = {res} pixels a degree span more than 360 degrees");
    }
    // Ground cells: north-south R dphi everywhere; east-west each row's R cos(phi) dlambda.
    let ns = metres_per_degree * cell;
    let row_lat = |r: u64| north - (r as f64 + 0.5) * cell;
    let widths: Vec<f64> = (0..rows).map(|r| ns * row_lat(r).to_radians().cos()).collect();
    let mid = 0.5 * (north + south);
    let gx = ns * mid.to_radians().cos();
    let last = rows.saturating_sub(1);
    let east = west + cols as f64 * cell;
    notes.push(format!(
        "{name}: PDS3 simple cylindrical map on {body} (sphere of radius {radius_m} m), {res} pixels a degree \
         (cells of {cell} degrees), longitudes {west} to {east} east and latitudes {south} to {north}: cells are \
         {ns:.4} m north-south and, east-west, each row's own width R cos(latitude) x {cell} degrees, from {:.4} m \
         (row 0, latitude {:.4}) to {:.4} m (row {last}, latitude {:.4}); --start/--goal are longitude,latitude \
         (either -180..180 or 0..360)",
        widths.first().copied().unwrap_or(gx),
        row_lat(0),
        widths.last().copied().unwrap_or(gx),
        row_lat(last),
    ));
    if north > 89.0 || south < -89.0 {
        notes.push(format!(
            "{name}: rows within a degree of a pole are planned as rows of rectangles {:.4} m wide at the last row, \
             with the meridians' convergence ignored; plan there on a polar stereographic product",
            ns * (90.0 - 0.5 * cell).to_radians().cos()
        ));
    }
    let static_body = match body {
        "Mars" => "Mars",
        "Moon" | "the Moon" => "the Moon",
        _ => "the body",
    };
    let ellipsoid = Ellipsoid { name: static_body, semi_major_m: radius_m, inverse_flattening: 0.0 };
    let (keys, doubles, ascii) = geographic_geokeys(radius_m, static_body);
    let geo = GeoRef::north_up((west, north, cell, cell), keys, doubles, ascii);
    Ok((geo, GroundCells { cell_m: (gx, ns), row_widths_m: Some(widths) }, Crs::Geographic { ellipsoid }))
}

/// The north-west corner (longitude, latitude) of a SIMPLE CYLINDRICAL map of `cell` degrees:
/// by the 1-based convention, or the 0-based one where only that reproduces the label's stated
/// extent (with a note); refused when neither does.
fn north_west_corner(label: &Label, cell: f64, notes: &mut Vec<String>) -> Result<(f64, f64)> {
    let name = &label.name;
    let map = |key: &str| format!("IMAGE_MAP_PROJECTION.{key}");
    let (lpo, _) = label.need_number(&map("LINE_PROJECTION_OFFSET"), "where the map's origin is")?;
    let (spo, _) = label.need_number(&map("SAMPLE_PROJECTION_OFFSET"), "where the map's origin is")?;
    let (clat, _) = label.need_number(&map("CENTER_LATITUDE"), "the latitude of the map's origin")?;
    let (clon, _) = label.need_number(&map("CENTER_LONGITUDE"), "the longitude of the map's origin")?;
    // The west and north edges by the standard's 1-based convention (the edge of sample 1
    // is at sample 0.5) and by the 0-based one (HiRISE, ISIS, GDAL's default).
    let one_based = (clon + (0.5 - spo) * cell, clat + (lpo - 0.5) * cell);
    let zero_based = (clon + (-0.5 - spo) * cell, clat + (lpo + 0.5) * cell);
    let stated_west = label.number(&map("WESTERNMOST_LONGITUDE"))?.map(|v| v.0);
    let stated_north = label.number(&map("MAXIMUM_LATITUDE"))?.map(|v| v.0);
    let agrees = |(west, north): (f64, f64)| {
        let tol = EXTENT_TOLERANCE_PIXELS * cell;
        let lon_ok = |w: f64| {
            let d = (west - w).rem_euclid(360.0);
            d.min(360.0 - d) <= tol
        };
        stated_west.is_none_or(lon_ok) && stated_north.is_none_or(|n| (north - n).abs() <= tol)
    };
    if agrees(one_based) {
        Ok(one_based)
    } else if agrees(zero_based) {
        notes.push(format!(
            "{name}: the projection offsets are read from the north-west pixel's centre counted from 0 (as \
             HiRISE and ISIS write them), which is what reproduces the label's WESTERNMOST_LONGITUDE and \
             MAXIMUM_LATITUDE"
        ));
        Ok(zero_based)
    } else {
        bail!(
            "{name}: SAMPLE_PROJECTION_OFFSET = {spo} and LINE_PROJECTION_OFFSET = {lpo} put the north-west corner at \
             longitude {:.6}, latitude {:.6} (samples and lines from 1, the PDS3 standard's convention) or {:.6}, \
             {:.6} (from 0), but the label states WESTERNMOST_LONGITUDE = {} and MAXIMUM_LATITUDE = {}",
            one_based.0,
            one_based.1,
            zero_based.0,
            zero_based.1,
            stated_west.map_or_else(|| "(none)".into(), |v| v.to_string()),
            stated_north.map_or_else(|| "(none)".into(), |v| v.to_string()),
        );
    }
}

/// MAP_SCALE in metres a pixel, if the label gives it (KM/PIXEL when it has no unit).
fn map_scale_m(label: &Label) -> Result<Option<f64>> {
    let Some((s, unit)) = label.number("IMAGE_MAP_PROJECTION.MAP_SCALE")? else { return Ok(None) };
    let m = match unit.as_deref().map(|u| u.replace(' ', "")).as_deref() {
        Some("METERS/PIXEL" | "METERS/PIX" | "M/PIXEL" | "M/PIX" | "METERS" | "M") => s,
        _ => s * 1000.0,
    };
    Ok((m.is_finite() && m > 0.0).then_some(m))
}

/// GeoTIFF keys (OGC 19-008r4) of longitude and latitude in degrees on the body's sphere
/// (user-defined: GDAL reads `+proj=longlat +R=radius`), for GeoTIFFs written over the map.
fn geographic_geokeys(radius_m: f64, body: &str) -> (Vec<u16>, Vec<f64>, String) {
    const USER: u16 = 32767;
    const DOUBLES: u16 = 34736;
    const ASCII: u16 = 34737;
    let citation = format!("GCS {body} sphere|");
    let entries: [[u16; 4]; 9] = [
        [1024, 0, 1, 2], // GTModelTypeGeoKey: geographic
        [1025, 0, 1, 1], // GTRasterTypeGeoKey: PixelIsArea
        [2048, 0, 1, USER],
        [2049, ASCII, citation.len() as u16, 0],
        [2050, 0, 1, USER],
        [2054, 0, 1, 9102], // degree
        [2056, 0, 1, USER],
        [2057, DOUBLES, 1, 0],
        [2058, DOUBLES, 1, 1],
    ];
    let mut dir = vec![1, 1, 0, entries.len() as u16];
    dir.extend(entries.into_iter().flatten());
    (dir, vec![radius_m, radius_m], citation)
}
