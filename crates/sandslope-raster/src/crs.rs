//! What a raster's coordinates mean (issue 24): the GeoTIFF GeoKeys read into a [`Crs`], and the
//! ground size of a cell in metres, so that a DEM in degrees (most public DEMs of Earth) or in
//! feet is never read as metres. A geographic CRS is taken on the ellipsoid its GeoKeys name
//! (WGS84 when unnamed), including other bodies' (Mars 3 396 190 m, Moon 1 737 400 m).
//!
//! GeoKey numbers and EPSG codes are from the GeoTIFF specification (OGC 19-008r4, section 7)
//! and the EPSG registry.

use anyhow::{bail, Result};

/// GTModelTypeGeoKey: 1 projected, 2 geographic, 3 geocentric.
const GT_MODEL_TYPE: u16 = 1024;
/// GeographicTypeGeoKey (an EPSG geographic CRS code).
const GEOGRAPHIC_TYPE: u16 = 2048;
/// GeogCitationGeoKey (ASCII).
const GEOG_CITATION: u16 = 2049;
/// GeogAngularUnitsGeoKey.
const GEOG_ANGULAR_UNITS: u16 = 2054;
/// GeogEllipsoidGeoKey (an EPSG ellipsoid code).
const GEOG_ELLIPSOID: u16 = 2056;
/// GeogSemiMajorAxisGeoKey (double, metres).
const GEOG_SEMI_MAJOR: u16 = 2057;
/// GeogSemiMinorAxisGeoKey (double, metres).
const GEOG_SEMI_MINOR: u16 = 2058;
/// GeogInvFlatteningGeoKey (double).
const GEOG_INV_FLATTENING: u16 = 2059;
/// ProjLinearUnitsGeoKey.
const PROJ_LINEAR_UNITS: u16 = 3076;
/// ProjectedCSTypeGeoKey: the EPSG code of a projected CRS.
const PROJECTED_CS_TYPE: u16 = 3072;
/// VerticalUnitsGeoKey.
const VERTICAL_UNITS: u16 = 4099;
/// ProjCoordTransGeoKey, and its CT_Equirectangular.
const PROJ_COORD_TRANS: u16 = 3075;
const CT_EQUIRECTANGULAR: u16 = 17;
/// ProjStdParallel1GeoKey, ProjNatOriginLatGeoKey, ProjFalseNorthingGeoKey, ProjCenterLatGeoKey.
const PROJ_STD_PARALLEL1: u16 = 3078;
const PROJ_NAT_ORIGIN_LAT: u16 = 3081;
const PROJ_FALSE_NORTHING: u16 = 3083;
const PROJ_CENTER_LAT: u16 = 3089;

/// WGS84: a = 6 378 137 m, 1/f = 298.257223563.
pub const WGS84: Ellipsoid =
    Ellipsoid { name: "WGS84", semi_major_m: 6_378_137.0, inverse_flattening: 298.257_223_563 };

/// An ellipsoid of revolution (a sphere when `inverse_flattening` is 0).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Ellipsoid {
    /// Its name, or the body's ("Mars", "Moon") for a sphere of that radius.
    pub name: &'static str,
    /// Semi-major axis, m.
    pub semi_major_m: f64,
    /// Inverse flattening (0 for a sphere).
    pub inverse_flattening: f64,
}

impl Ellipsoid {
    fn e2(&self) -> f64 {
        if self.inverse_flattening == 0.0 {
            0.0
        } else {
            let f = 1.0 / self.inverse_flattening;
            f * (2.0 - f)
        }
    }

    /// Metres per radian along a meridian (M) and along a parallel (N cos phi) at latitude
    /// `lat_deg`: M = a (1 - e^2) / (1 - e^2 sin^2 phi)^(3/2), N = a / (1 - e^2 sin^2 phi)^(1/2).
    pub fn metres_per_radian(&self, lat_deg: f64) -> (f64, f64) {
        let (s, c) = lat_deg.to_radians().sin_cos();
        let e2 = self.e2();
        let w = 1.0 - e2 * s * s;
        let m = self.semi_major_m * (1.0 - e2) / w.powf(1.5);
        let n = self.semi_major_m / w.sqrt();
        (m, n * c)
    }
}

/// What a raster's map coordinates are.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Crs {
    /// Projected (or not stated): map units of `metres_per_unit` metres.
    Projected {
        /// Metres per map unit (1 for metres, 0.3048 for feet).
        metres_per_unit: f64,
        /// The unit's name.
        unit: &'static str,
    },
    /// Geographic: longitude and latitude in degrees on `ellipsoid`.
    Geographic {
        /// The ellipsoid (or body sphere).
        ellipsoid: Ellipsoid,
    },
}

impl Crs {
    /// Whether map coordinates are longitude and latitude.
    pub fn is_geographic(&self) -> bool {
        matches!(self, Crs::Geographic { .. })
    }
}

/// A linear unit by its EPSG code: (metres per unit, name).
fn linear_unit(code: u16) -> Option<(f64, &'static str)> {
    Some(match code {
        9001 => (1.0, "metre"),
        9002 => (0.3048, "foot"),
        9003 => (1200.0 / 3937.0, "US survey foot"),
        9036 => (1000.0, "kilometre"),
        9030 => (1852.0, "nautical mile"),
        _ => return None,
    })
}

/// An ellipsoid by its EPSG code.
fn ellipsoid(code: u16) -> Option<Ellipsoid> {
    Some(match code {
        7030 => WGS84,
        7019 => Ellipsoid { name: "GRS80", semi_major_m: 6_378_137.0, inverse_flattening: 298.257_222_101 },
        7043 => Ellipsoid { name: "WGS72", semi_major_m: 6_378_135.0, inverse_flattening: 298.26 },
        7008 => {
            Ellipsoid { name: "Clarke 1866", semi_major_m: 6_378_206.4, inverse_flattening: 294.978_698_2 }
        }
        7022 => {
            Ellipsoid { name: "International 1924", semi_major_m: 6_378_388.0, inverse_flattening: 297.0 }
        }
        7004 => {
            Ellipsoid { name: "Bessel 1841", semi_major_m: 6_377_397.155, inverse_flattening: 299.152_812_8 }
        }
        _ => return None,
    })
}

/// The ellipsoid of a geographic CRS by its EPSG code.
fn geographic(code: u16) -> Option<Ellipsoid> {
    match code {
        4326 | 4030 => Some(WGS84),
        4269 | 4258 | 4019 | 4283 | 4617 | 4152 => ellipsoid(7019),
        4322 => ellipsoid(7043),
        4267 => ellipsoid(7008),
        4230 | 4022 => ellipsoid(7022),
        4314 | 4004 => ellipsoid(7004),
        _ => None,
    }
}

/// A sphere or ellipsoid given by its axes, named after the body it matches.
fn by_axes(a: f64, inv_f: f64) -> Ellipsoid {
    let near = |r: f64| (a - r).abs() < 1000.0;
    let name = if near(3_396_190.0) || near(3_389_500.0) {
        "Mars"
    } else if near(1_737_400.0) {
        "Moon"
    } else if near(6_378_137.0) && (inv_f - 298.257).abs() < 0.01 {
        "WGS84"
    } else {
        "the ellipsoid the file gives"
    };
    Ellipsoid { name, semi_major_m: a, inverse_flattening: inv_f }
}

/// The GeoKeys of a GeoTIFF: `(key, value)` where the value is a short, doubles or text.
struct Keys<'a> {
    dir: &'a [u16],
    doubles: &'a [f64],
    ascii: &'a str,
}

impl Keys<'_> {
    fn entries(&self) -> impl Iterator<Item = &[u16]> {
        self.dir.get(4..).unwrap_or(&[]).chunks_exact(4)
    }
    fn short(&self, key: u16) -> Option<u16> {
        self.entries().find(|e| e[0] == key && e[1] == 0).map(|e| e[3])
    }
    fn double(&self, key: u16) -> Option<f64> {
        self.entries()
            .find(|e| e[0] == key && e[1] == 34736)
            .and_then(|e| self.doubles.get(usize::from(e[3])).copied())
    }
    fn text(&self, key: u16) -> Option<&str> {
        self.entries().find(|e| e[0] == key && e[1] == 34737).and_then(|e| {
            let (start, len) = (usize::from(e[3]), usize::from(e[2]));
            self.ascii.get(start..start + len)
        })
    }
}

/// The EPSG code of a projected CRS named by its GeoKeys (`ProjectedCSTypeGeoKey`, 3072), if
/// the keys name one (not user-defined, 32767). Geographic rasters have none here: their
/// GeoJSON is RFC 7946's longitude, latitude.
pub fn projected_epsg(dir: &[u16]) -> Option<u16> {
    let keys = Keys { dir, doubles: &[], ascii: "" };
    if keys.short(GT_MODEL_TYPE) == Some(2) {
        return None;
    }
    keys.short(PROJECTED_CS_TYPE).filter(|&c| (1024..32767).contains(&c))
}

/// Reads the CRS from GeoKeys (`dir`, `doubles`, `ascii` as in the file); `notes` gains what was
/// assumed. No keys: projected in metres, with a note. Unsupported (geocentric, an angular unit
/// other than degrees or radians, an unknown linear unit): an error naming the key and value.
pub fn from_geokeys(
    name: &dyn std::fmt::Display,
    dir: Option<&[u16]>,
    doubles: Option<&[f64]>,
    ascii: Option<&str>,
    notes: &mut Vec<String>,
) -> Result<(Crs, f64)> {
    let Some(dir) = dir else {
        notes.push(format!("{name}: no GeoKeys: map units taken as metres"));
        return Ok((Crs::Projected { metres_per_unit: 1.0, unit: "metre" }, 1.0));
    };
    let keys = Keys { dir, doubles: doubles.unwrap_or(&[]), ascii: ascii.unwrap_or("") };
    let vertical = match keys.short(VERTICAL_UNITS) {
        None => 1.0,
        Some(code) => match linear_unit(code) {
            Some((1.0, _)) => 1.0,
            Some((m, unit)) => {
                notes.push(format!("{name}: heights in {unit}s (VerticalUnitsGeoKey {code}), converted to metres"));
                m
            }
            None => bail!("{name}: VerticalUnitsGeoKey = {code} is not a linear unit sandslope knows (metre 9001, foot 9002, US survey foot 9003)"),
        },
    };
    match keys.short(GT_MODEL_TYPE) {
        Some(2) => {}
        Some(3) => bail!("{name}: GTModelTypeGeoKey = 3 (geocentric) is not a map; reproject to a projected or geographic CRS"),
        _ => {
            // Projected (1), or not stated: the linear unit.
            let (m, unit) = match keys.short(PROJ_LINEAR_UNITS) {
                None => (1.0, "metre"),
                Some(code) => linear_unit(code).ok_or_else(|| {
                    anyhow::anyhow!("{name}: ProjLinearUnitsGeoKey = {code} is not a linear unit sandslope knows (metre 9001, foot 9002, US survey foot 9003, kilometre 9036)")
                })?,
            };
            if m != 1.0 {
                notes.push(format!("{name}: map units are {unit}s (ProjLinearUnitsGeoKey): cell sizes converted to metres"));
            }
            return Ok((Crs::Projected { metres_per_unit: m, unit }, vertical));
        }
    }
    match keys.short(GEOG_ANGULAR_UNITS) {
        None | Some(9102) | Some(9122) => {}
        Some(code) => bail!("{name}: GeogAngularUnitsGeoKey = {code}: only degrees (9102) are supported; reproject with gdalwarp"),
    }
    let by_code = keys
        .short(GEOGRAPHIC_TYPE)
        .and_then(geographic)
        .or_else(|| keys.short(GEOG_ELLIPSOID).and_then(ellipsoid));
    let ellipsoid = match (by_code, keys.double(GEOG_SEMI_MAJOR)) {
        (Some(e), _) => e,
        (None, Some(a)) if a.is_finite() && a > 1000.0 => {
            let inv_f = match (keys.double(GEOG_INV_FLATTENING), keys.double(GEOG_SEMI_MINOR)) {
                (Some(f), _) if f.is_finite() && f >= 0.0 => f,
                (_, Some(b)) if b.is_finite() && b > 0.0 && b < a => a / (a - b),
                _ => 0.0,
            };
            by_axes(a, inv_f)
        }
        _ => {
            let citation = keys.text(GEOG_CITATION).unwrap_or("").trim_end_matches('|').to_string();
            notes.push(format!(
                "{name}: a geographic CRS without a known ellipsoid{}: WGS84 assumed",
                if citation.is_empty() { String::new() } else { format!(" (`{citation}`)") }
            ));
            WGS84
        }
    };
    Ok((Crs::Geographic { ellipsoid }, vertical))
}

/// The ground size of a raster's cells, metres.
#[derive(Debug, Clone, PartialEq)]
pub struct GroundCells {
    /// (east, north): everywhere on a projected map; on a geographic or equirectangular one
    /// the east-west size at the raster's mid-latitude (the planner's reference cell).
    pub cell_m: (f64, f64),
    /// East-west size of each row's cells (row 0 at the north) where the rows differ: a
    /// geographic raster's `N(lat) cos(lat) dlambda`, an equirectangular map's. The planner
    /// uses these (`ElevationGrid::with_row_widths`).
    pub row_widths_m: Option<Vec<f64>>,
}

impl GroundCells {
    /// Cells of one size everywhere.
    pub fn uniform(cell_m: (f64, f64)) -> GroundCells {
        GroundCells { cell_m, row_widths_m: None }
    }
}

/// Ground size of the cells of `cell_x` by `cell_y` map units of a raster whose `rows` rows
/// span latitudes `south..north` (geographic) or anything (projected): on a geographic CRS
/// each row's east-west size `N cos(lat) dlambda` at the row's central latitude, and `M dphi`
/// north-south at the mid-latitude; a note says what was assumed. A geographic raster
/// reaching a pole, or with latitudes outside -90..90, is refused.
#[allow(clippy::too_many_arguments)]
pub fn ground_cell_size(
    name: &dyn std::fmt::Display,
    crs: &Crs,
    cell_x: f64,
    cell_y: f64,
    north: f64,
    south: f64,
    rows: usize,
    notes: &mut Vec<String>,
) -> Result<GroundCells> {
    match crs {
        Crs::Projected { metres_per_unit, .. } => {
            Ok(GroundCells::uniform((cell_x * metres_per_unit, cell_y * metres_per_unit)))
        }
        Crs::Geographic { ellipsoid } => {
            if !(north <= 90.0 && south >= -90.0) {
                bail!("{name}: latitudes {south}..{north} are outside -90..90 degrees: not a geographic raster in degrees");
            }
            if north > 89.0 || south < -89.0 {
                bail!("{name}: reaches latitude {} degrees: east-west cell sizes vanish near a pole; reproject to a polar stereographic CRS (gdalwarp -t_srs)", if north > 89.0 { north } else { south });
            }
            let mid = 0.5 * (north + south);
            let (m, p) = ellipsoid.metres_per_radian(mid);
            let (gx, gy) = (p * cell_x.to_radians(), m * cell_y.to_radians());
            // Each row at its central latitude.
            let lat = |r: usize| north - (r as f64 + 0.5) * cell_y;
            let widths: Vec<f64> =
                (0..rows).map(|r| ellipsoid.metres_per_radian(lat(r)).1 * cell_x.to_radians()).collect();
            let last = rows.saturating_sub(1);
            notes.push(format!(
                "{name}: geographic coordinates (degrees) on {} (a = {} m): cells of {cell_x} x {cell_y} degrees \
                 are {gy:.2} m north-south (at the mid-latitude {mid:.4} degrees) and, east-west, each row's own \
                 width, from {:.4} m (row 0, latitude {:.4}) to {:.4} m (row {last}, latitude {:.4})",
                ellipsoid.name,
                ellipsoid.semi_major_m,
                widths.first().copied().unwrap_or(gx),
                lat(0),
                widths.last().copied().unwrap_or(gx),
                lat(last),
            ));
            Ok(GroundCells { cell_m: (gx, gy), row_widths_m: Some(widths) })
        }
    }
}

/// The ground cells of a projected map in the equirectangular projection on a sphere
/// (`ProjCoordTransGeoKey` CT_Equirectangular, as ISIS and GDAL write planetary DTMs, CTX ones
/// among them: x = R (lon - lon0) cos(lat_ts), y = R (lat - lat0) + false northing): north-south
/// the map's cell everywhere; east-west the map's cell is true only at the standard parallel
/// `lat_ts`, so each row's cells are `cell_x cos(lat) / cos(lat_ts)` wide at the row's central
/// latitude, as for a PDS3 equirectangular DTM (the reference cell at the mid-latitude). `None`
/// for any other projection, or without the sphere's radius (GeogSemiMajorAxisGeoKey, or an
/// ellipsoid by code: its semi-major axis is taken, with a note). Refused within a degree of a
/// pole.
#[allow(clippy::too_many_arguments)]
pub fn equirectangular_rows(
    name: &dyn std::fmt::Display,
    dir: Option<&[u16]>,
    doubles: Option<&[f64]>,
    metres_per_unit: f64,
    (cell_x, cell_y): (f64, f64),
    north: f64,
    rows: usize,
    notes: &mut Vec<String>,
) -> Result<Option<GroundCells>> {
    let Some(dir) = dir else { return Ok(None) };
    let keys = Keys { dir, doubles: doubles.unwrap_or(&[]), ascii: "" };
    if keys.short(PROJ_COORD_TRANS) != Some(CT_EQUIRECTANGULAR) {
        return Ok(None);
    }
    let (radius, flattened) = match keys.double(GEOG_SEMI_MAJOR).filter(|a| a.is_finite() && *a > 1000.0) {
        Some(a) => (a, keys.double(GEOG_INV_FLATTENING).is_some_and(|f| f > 0.0)),
        None => match keys
            .short(GEOGRAPHIC_TYPE)
            .and_then(geographic)
            .or_else(|| keys.short(GEOG_ELLIPSOID).and_then(ellipsoid))
        {
            Some(e) => (e.semi_major_m, e.inverse_flattening > 0.0),
            None => return Ok(None),
        },
    };
    let lat_ts = keys.double(PROJ_STD_PARALLEL1).unwrap_or(0.0);
    let lat0 = keys.double(PROJ_CENTER_LAT).or_else(|| keys.double(PROJ_NAT_ORIGIN_LAT)).unwrap_or(0.0);
    let false_northing = keys.double(PROJ_FALSE_NORTHING).unwrap_or(0.0);
    let (cx, cy) = (cell_x * metres_per_unit, cell_y * metres_per_unit);
    let lat = |y: f64| lat0 + ((y * metres_per_unit - false_northing) / radius).to_degrees();
    let (lat_n, lat_s) = (lat(north), lat(north - rows as f64 * cell_y));
    if lat_ts.abs() >= 89.0 || lat_n.abs() >= 89.0 || lat_s.abs() >= 89.0 {
        bail!(
            "{name}: an equirectangular map (ProjCoordTransGeoKey 17) with its standard parallel at {lat_ts} degrees \
             and rows from latitude {lat_n:.4} to {lat_s:.4}: it must lie within 89 degrees of the equator; \
             reproject to a polar stereographic CRS (gdalwarp -t_srs)"
        );
    }
    let east = |phi: f64| cx * phi.to_radians().cos() / lat_ts.to_radians().cos();
    let row_lat = |r: usize| lat(north - (r as f64 + 0.5) * cell_y);
    let widths: Vec<f64> = (0..rows).map(|r| east(row_lat(r))).collect();
    let last = rows.saturating_sub(1);
    notes.push(format!(
        "{name}: equirectangular map (ProjCoordTransGeoKey 17) on a sphere of radius {radius} m{}: the map's \
         {cx} m are true east-west at the standard parallel {lat_ts} degrees; cells are {cy} m north-south and, \
         east-west, each row's own width {cx} cos(latitude) / cos({lat_ts}), from {:.4} m (row 0, latitude \
         {:.4}) to {:.4} m (row {last}, latitude {:.4})",
        if flattened { " (the ellipsoid's semi-major axis)" } else { "" },
        widths[0],
        row_lat(0),
        widths[last],
        row_lat(last),
    ));
    Ok(Some(GroundCells { cell_m: (east(0.5 * (lat_n + lat_s)), cy), row_widths_m: Some(widths) }))
}

/// The CRS of an ESRI ASCII grid from the `.prj` (ESRI WKT) beside it: `GEOGCS` without
/// `PROJCS` is geographic on its `SPHEROID`; a `PROJCS` takes its last `UNIT`'s factor. No
/// `.prj`: metres, as before.
pub fn from_prj(prj: &std::path::Path, notes: &mut Vec<String>) -> Result<Crs> {
    let metres = Crs::Projected { metres_per_unit: 1.0, unit: "metre" };
    let Ok(text) = std::fs::read_to_string(prj) else {
        return Ok(metres);
    };
    let name = prj.display();
    if text.len() > 1 << 20 {
        bail!("{name}: {} bytes is not a projection file (at most 1 MiB)", text.len());
    }
    let upper = text.to_ascii_uppercase();
    // The numbers after `KEY["name",` in WKT.
    let numbers_after = |key: &str| -> Option<Vec<f64>> {
        let at = upper.rfind(&format!("{key}["))?;
        let rest = &text[at + key.len() + 1..];
        let end = rest.find(']')?;
        Some(rest[..end].split(',').skip(1).filter_map(|v| v.trim().parse::<f64>().ok()).collect())
    };
    if upper.contains("PROJCS[") {
        let factor = numbers_after("UNIT").and_then(|v| v.first().copied()).unwrap_or(1.0);
        if !(factor.is_finite() && factor > 0.0) {
            bail!("{name}: UNIT factor {factor} must be a positive number of metres");
        }
        if factor != 1.0 {
            notes.push(format!(
                "{name}: map units of {factor} m (the PROJCS UNIT): cell sizes converted to metres"
            ));
        }
        let unit = if (factor - 0.3048).abs() < 1e-9 {
            "foot"
        } else if (factor - 1200.0 / 3937.0).abs() < 1e-9 {
            "US survey foot"
        } else if factor == 1.0 {
            "metre"
        } else {
            "map unit"
        };
        return Ok(Crs::Projected { metres_per_unit: factor, unit });
    }
    if upper.contains("GEOGCS[") {
        let ellipsoid = match numbers_after("SPHEROID").as_deref() {
            Some([a, inv_f, ..]) if a.is_finite() && *a > 1000.0 && inv_f.is_finite() && *inv_f >= 0.0 => {
                by_axes(*a, *inv_f)
            }
            _ => {
                notes.push(format!("{name}: a geographic CRS without a readable SPHEROID: WGS84 assumed"));
                WGS84
            }
        };
        return Ok(Crs::Geographic { ellipsoid });
    }
    notes.push(format!("{name}: neither PROJCS nor GEOGCS: map units taken as metres"));
    Ok(metres)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One arc-second on WGS84 at the equator: 30.87 m along the meridian (M = a (1 - e^2) =
    /// 6 335 439 m) and 30.92 m along the equator (a); at 60 degrees the parallel is N cos 60.
    #[test]
    fn ground_sizes_follow_the_ellipsoid_by_hand() {
        let crs = Crs::Geographic { ellipsoid: WGS84 };
        let arcsec = 1.0 / 3600.0;
        let mut notes = Vec::new();
        let (gx, gy) =
            ground_cell_size(&"dem", &crs, arcsec, arcsec, 0.01, -0.01, 72, &mut notes).unwrap().cell_m;
        let e2 = 0.006_694_379_990_14;
        assert!((gy - 6_378_137.0 * (1.0 - e2) * arcsec.to_radians()).abs() < 1e-6, "{gy}");
        assert!((gx - 6_378_137.0 * arcsec.to_radians()).abs() < 1e-3, "{gx}");
        let (gx60, _) =
            ground_cell_size(&"dem", &crs, arcsec, arcsec, 60.0001, 59.9999, 1, &mut notes).unwrap().cell_m;
        let n60 = 6_378_137.0 / (1.0 - e2 * 0.75_f64).sqrt();
        assert!((gx60 - n60 * 0.5 * arcsec.to_radians()).abs() < 1e-3, "{gx60}");
        // Mars as a sphere: 1 degree is 3 396 190 * pi / 180 = 59 274.7 m both ways at 0 degrees.
        let mars = Crs::Geographic { ellipsoid: by_axes(3_396_190.0, 0.0) };
        let (mx, my) = ground_cell_size(&"dtm", &mars, 1.0, 1.0, 0.5, -0.5, 1, &mut notes).unwrap().cell_m;
        assert!((my - 59_274.7).abs() < 0.1 && (mx - my).abs() < 1.0, "{mx} {my}");
        assert!(notes.iter().any(|n| n.contains("on Mars (a = 3396190 m)")), "{notes:?}");
        assert!(ground_cell_size(&"p", &crs, 0.1, 0.1, 89.5, 80.0, 95, &mut notes)
            .unwrap_err()
            .to_string()
            .contains("pole"));
    }

    /// Half-degree cells on WGS84 from 60.25 to 29.75 degrees north: 61 rows centred on 60,
    /// 59.5, ..., 30 degrees, each its own width N cos(lat) dlambda. By hand at 45 degrees:
    /// N = a / sqrt(1 - e^2 sin^2 45) = 6 388 838.29 m, times cos 45 = 0.707107 and 0.5 degree
    /// (8.72665e-3 rad): 39 423.42 m; at 60 degrees N = a / sqrt(1 - 0.75 e^2), half of it.
    #[test]
    fn a_geographic_rasters_rows_each_get_their_width_on_the_ellipsoid() {
        let crs = Crs::Geographic { ellipsoid: WGS84 };
        let mut notes = Vec::new();
        let cells = ground_cell_size(&"dem", &crs, 0.5, 0.5, 60.25, 29.75, 61, &mut notes).unwrap();
        let w = cells.row_widths_m.unwrap();
        assert_eq!(w.len(), 61);
        assert!((w[30] - 39_423.42).abs() < 0.01, "{}", w[30]);
        let e2 = 0.006_694_379_990_14;
        let n60 = 6_378_137.0 / (1.0 - e2 * 0.75_f64).sqrt();
        assert!((w[0] - n60 * 0.5 * 0.5_f64.to_radians()).abs() < 1e-6, "{}", w[0]);
        let n30 = 6_378_137.0 / (1.0 - e2 * 0.25_f64).sqrt();
        assert!((w[60] - n30 * 0.75_f64.sqrt() * 0.5_f64.to_radians()).abs() < 1e-6, "{}", w[60]);
        // The mid-latitude's width stays the reference cell.
        assert_eq!(cells.cell_m.0, w[30]);
        assert!(
            notes[0].contains(
                "from 27900.0008 m (row 0, latitude 60.0000) to 48243.1401 m (row 60, latitude 30.0000)"
            ),
            "{notes:?}"
        );
        // A projected raster's rows are all alike.
        let utm = Crs::Projected { metres_per_unit: 1.0, unit: "metre" };
        assert_eq!(
            ground_cell_size(&"p", &utm, 2.0, 2.0, 10.0, 0.0, 5, &mut notes).unwrap(),
            GroundCells::uniform((2.0, 2.0))
        );
    }

    /// GeoKeys as GDAL writes them: EPSG:4326 by code; a user-defined Mars sphere by its axis;
    /// a projected CRS in feet; a geocentric one refused.
    #[test]
    fn crs_from_geokeys() {
        let mut notes = Vec::new();
        let wgs = [1, 1, 0, 3, 1024, 0, 1, 2, 1025, 0, 1, 1, 2048, 0, 1, 4326];
        let (crs, v) = from_geokeys(&"a", Some(&wgs), None, None, &mut notes).unwrap();
        assert_eq!((crs, v), (Crs::Geographic { ellipsoid: WGS84 }, 1.0));
        let mars = [1, 1, 0, 3, 1024, 0, 1, 2, 2048, 0, 1, 32767, 2057, 34736, 1, 0];
        let (crs, _) = from_geokeys(&"m", Some(&mars), Some(&[3_396_190.0]), None, &mut notes).unwrap();
        assert!(matches!(crs, Crs::Geographic { ellipsoid } if ellipsoid.name == "Mars"));
        let feet = [1, 1, 0, 2, 1024, 0, 1, 1, 3076, 0, 1, 9002];
        let (crs, _) = from_geokeys(&"f", Some(&feet), None, None, &mut notes).unwrap();
        assert_eq!(crs, Crs::Projected { metres_per_unit: 0.3048, unit: "foot" });
        let geocentric = [1, 1, 0, 1, 1024, 0, 1, 3];
        assert!(from_geokeys(&"g", Some(&geocentric), None, None, &mut notes)
            .unwrap_err()
            .to_string()
            .contains("geocentric"));
    }
}
