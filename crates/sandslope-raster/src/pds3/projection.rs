//! The IMAGE_MAP_PROJECTION of a PDS3 DTM: equirectangular (HiRISE, CTX), polar stereographic
//! or sinusoidal (HRSC) on the body's sphere, as projected-metre georeferencing, ground cell
//! sizes, and GeoKeys.

use anyhow::{anyhow, bail, Result};

use super::label::Label;
use crate::crs::{Crs, GroundCells};
use crate::grid::GeoRef;

/// Where the DTM lies on its projection (projected metres) and on which sphere.
#[derive(Debug, Clone, Copy)]
struct Extent<'a> {
    name: &'a str,
    body: &'a str,
    radius_m: f64,
    /// MAP_SCALE, metres per pixel.
    cell: f64,
    /// CENTER_LATITUDE, degrees.
    clat: f64,
    /// LINE_PROJECTION_OFFSET.
    lpo: f64,
    west: f64,
    east: f64,
    north: f64,
    south: f64,
}

/// The map's georeferencing (projected metres, north up) and the ground cell sizes in metres
/// of a DTM of `rows` x `cols`; notes what was assumed.
pub(super) fn georef(
    label: &Label,
    rows: u64,
    cols: u64,
    notes: &mut Vec<String>,
) -> Result<(GeoRef, GroundCells, Crs)> {
    let name = &label.name;
    let map = |key: &str| format!("IMAGE_MAP_PROJECTION.{key}");
    if !label
        .entries
        .iter()
        .any(|(p, _, _)| p.starts_with("IMAGE_MAP_PROJECTION.") || p.contains(".IMAGE_MAP_PROJECTION."))
    {
        bail!(
            "{name}: the label has no IMAGE_MAP_PROJECTION object (MAP_SCALE, the projection): the planner needs \
             the cell size in metres"
        );
    }
    let (ptype, pline) = label
        .word(&map("MAP_PROJECTION_TYPE"))
        .ok_or_else(|| anyhow!("{name}: the label has no IMAGE_MAP_PROJECTION.MAP_PROJECTION_TYPE"))?;
    let projection = ptype.replace([' ', '_'], "");
    if !matches!(
        projection.as_str(),
        "EQUIRECTANGULAR" | "POLARSTEREOGRAPHIC" | "SIMPLECYLINDRICAL" | "SINUSOIDAL"
    ) {
        bail!(
            "{name}: line {pline}: MAP_PROJECTION_TYPE = {ptype} is not supported (EQUIRECTANGULAR or \
             POLARSTEREOGRAPHIC, the projections of HiRISE and CTX DTMs, SINUSOIDAL, HRSC's, or SIMPLE \
             CYLINDRICAL, MOLA's); reproject it (gdalwarp) to one of those or to a GeoTIFF"
        );
    }
    if let Some((rot, _)) = label.number(&map("MAP_PROJECTION_ROTATION"))? {
        if rot != 0.0 {
            bail!("{name}: MAP_PROJECTION_ROTATION = {rot}: rotated maps are not supported (north-up only)");
        }
    }
    let (radius, runit) = label.need_number(&map("A_AXIS_RADIUS"), "the body's radius")?;
    let radius_m = match runit.as_deref() {
        None | Some("KM" | "KILOMETERS" | "KILOMETER") => radius * 1000.0,
        Some("M" | "METERS" | "METER" | "METRES" | "METRE") => radius,
        Some(u) => bail!("{name}: A_AXIS_RADIUS = {radius} <{u}>: the unit must be KM or M"),
    };
    if !(1e3..=1e8).contains(&radius_m) {
        bail!("{name}: A_AXIS_RADIUS = {radius} ({radius_m} m) must be from 1 to 100000 km");
    }
    if projection == "SIMPLECYLINDRICAL" {
        let body = body_name(label, radius_m);
        return super::cylindrical::simple_cylindrical(label, rows, cols, radius_m, &body, notes);
    }
    let (map_scale, sunit) = label.need_number(&map("MAP_SCALE"), "the cell size")?;
    let cell = match sunit.as_deref().map(|u| u.replace(' ', "")).as_deref() {
        Some("METERS/PIXEL" | "METERS/PIX" | "M/PIXEL" | "M/PIX" | "METERS" | "M" | "METRES/PIXEL") => {
            map_scale
        }
        Some("KM/PIXEL" | "KM/PIX" | "KM" | "KILOMETERS/PIXEL") => map_scale * 1000.0,
        None => {
            notes.push(format!(
                "{name}: MAP_SCALE = {map_scale} has no unit: taken as the PDS3 standard's KM/PIXEL ({} m cells)",
                map_scale * 1000.0
            ));
            map_scale * 1000.0
        }
        Some(u) => bail!("{name}: MAP_SCALE = {map_scale} <{u}>: the unit must be METERS/PIXEL or KM/PIXEL"),
    };
    if !(cell.is_finite() && cell > 0.0) {
        bail!("{name}: MAP_SCALE = {map_scale} must be a number greater than 0");
    }
    let (lpo, _) = label.need_number(&map("LINE_PROJECTION_OFFSET"), "where the map's origin is")?;
    let (spo, _) = label.need_number(&map("SAMPLE_PROJECTION_OFFSET"), "where the map's origin is")?;
    let (clat, _) = label.need_number(&map("CENTER_LATITUDE"), "the projection's latitude")?;
    let west = -(spo + 0.5) * cell;
    let north = (lpo + 0.5) * cell;
    let south = north - rows as f64 * cell;
    let body = body_name(label, radius_m);
    let east = west + cols as f64 * cell;
    let extent = Extent { name, body: &body, radius_m, cell, clat, lpo, west, east, north, south };
    let clon = label.number(&map("CENTER_LONGITUDE"))?.map_or(0.0, |v| v.0);
    let cells = match projection.as_str() {
        "EQUIRECTANGULAR" => equirectangular_cells(&extent, rows, notes)?,
        "SINUSOIDAL" => GroundCells::uniform(sinusoidal_cells(&extent, clon, notes)?),
        _ => GroundCells::uniform(polar_cells(&extent, notes)?),
    };
    let (keys, doubles, ascii) = geokeys(&projection, radius_m, clat, clon, &body);
    let crs = Crs::Projected { metres_per_unit: 1.0, unit: "metre" };
    Ok((GeoRef::north_up((west, north, cell, cell), keys, doubles, ascii), cells, crs))
}

/// Ground cell sizes of an equirectangular map (y = R lat): MAP_SCALE north-south; east-west
/// MAP_SCALE is true at CENTER_LATITUDE, so each row's cells are `MAP_SCALE cos(lat) /
/// cos(CENTER_LATITUDE)` wide at the row's central latitude (the reference cell at the DTM's
/// mid-latitude).
fn equirectangular_cells(e: &Extent, rows: u64, notes: &mut Vec<String>) -> Result<GroundCells> {
    let Extent { name, body, radius_m, cell, clat, lpo, north, south, .. } = *e;
    if clat.abs() >= 89.0 {
        bail!("{name}: CENTER_LATITUDE = {clat}: an equirectangular DTM's must lie within 89 degrees of the equator");
    }
    // y = R lat: the rows' latitudes; east-west, MAP_SCALE is true at CENTER_LATITUDE.
    let lat = |y: f64| (y / radius_m).to_degrees();
    let (lat_n, lat_s) = (lat(north), lat(south));
    if lat_n.abs() >= 89.0 || lat_s.abs() >= 89.0 {
        bail!(
            "{name}: LINE_PROJECTION_OFFSET = {lpo} puts the rows at latitudes {lat_s:.3} to {lat_n:.3} degrees: \
             an equirectangular DTM must lie within 89 degrees of the equator"
        );
    }
    let mid = 0.5 * (lat_n + lat_s);
    let east = |phi: f64| cell * phi.to_radians().cos() / clat.to_radians().cos();
    let gx = east(mid);
    let row_lat = |r: u64| lat(north - (r as f64 + 0.5) * cell);
    let widths: Vec<f64> = (0..rows).map(|r| east(row_lat(r))).collect();
    let last = rows.saturating_sub(1);
    notes.push(format!(
        "{name}: PDS3 equirectangular map on {body} (sphere of radius {radius_m} m): MAP_SCALE {cell} m is true \
         east-west at CENTER_LATITUDE {clat} degrees; cells are {cell} m north-south and, east-west, each row's \
         own width MAP_SCALE cos(latitude) / cos(CENTER_LATITUDE), from {:.4} m (row 0, latitude {:.4}) to \
         {:.4} m (row {last}, latitude {:.4})",
        widths.first().copied().unwrap_or(gx),
        row_lat(0),
        widths.last().copied().unwrap_or(gx),
        row_lat(last),
    ));
    Ok(GroundCells { cell_m: (gx, cell), row_widths_m: Some(widths) })
}

/// Ground cell size of a polar stereographic map centred on a pole, at the DTM's centre.
fn polar_cells(e: &Extent, notes: &mut Vec<String>) -> Result<(f64, f64)> {
    let Extent { name, body, radius_m, cell, clat, west, east: east_edge, north, south, .. } = *e;
    if (clat.abs() - 90.0).abs() > 1e-9 {
        bail!(
            "{name}: CENTER_LATITUDE = {clat}: only polar stereographic maps centred on a pole (CENTER_LATITUDE \
             = 90 or -90) are supported"
        );
    }
    // Scale factor of the polar stereographic on a sphere, true at the pole: k = 2 / (1 +
    // sin|lat|), |lat| = 90 - 2 atan(rho / 2R) degrees.
    let k_at = |x: f64, y: f64| {
        let colat = 2.0 * (x.hypot(y) / (2.0 * radius_m)).atan();
        2.0 / (1.0 + colat.cos())
    };
    let k = k_at(0.5 * (west + east_edge), 0.5 * (north + south));
    let corners = [(west, north), (east_edge, north), (west, south), (east_edge, south)];
    let vary = corners.iter().map(|&(x, y)| (1.0 - k / k_at(x, y)).abs()).fold(0.0, f64::max);
    let g = cell / k;
    notes.push(format!(
        "{name}: PDS3 polar stereographic map about the {} pole of {body} (sphere of radius {radius_m} m): \
         MAP_SCALE {cell} m is true at the pole; cells taken as {g:.4} x {g:.4} m at the DTM's centre (scale \
         factor {k:.6}; the cell size varies by up to {:.3}% across the DTM{})",
        if clat > 0.0 { "north" } else { "south" },
        100.0 * vary,
        if vary > 0.005 { ": more than 0.5%, crop the DTM for exact lengths" } else { "" }
    ));
    Ok((g, g))
}

/// Ground cell size of a sinusoidal map (x = R (lon - CENTER_LONGITUDE) cos(lat), y = R lat, as
/// HRSC DTMs are projected about their strip's own central meridian): MAP_SCALE is true along
/// every parallel, and along the meridians at the central one; away from it a meridian leans by
/// `atan(t)` from the map's north and is `sqrt(1 + t^2)` longer than its map length, `t = (lon -
/// CENTER_LONGITUDE) sin(lat)` (radians). Cells are taken as MAP_SCALE square, with a note of the
/// largest `t` over the DTM's corners; a DTM reaching where `t` exceeds 0.05 (a 2.9-degree lean, 0.12%
/// longer meridians; slopes off by as much) is refused, naming the keys.
fn sinusoidal_cells(e: &Extent, clon: f64, notes: &mut Vec<String>) -> Result<(f64, f64)> {
    let Extent { name, body, radius_m, cell, clat, lpo, west, east, north, south, .. } = *e;
    if clat != 0.0 {
        bail!(
            "{name}: CENTER_LATITUDE = {clat}: a sinusoidal map's origin must be on the equator (CENTER_LATITUDE = \
             0, as in HRSC DTMs)"
        );
    }
    let lat = |y: f64| y / radius_m;
    if lat(north).to_degrees().abs() >= 89.0 || lat(south).to_degrees().abs() >= 89.0 {
        bail!(
            "{name}: LINE_PROJECTION_OFFSET = {lpo} puts the rows at latitudes {:.3} to {:.3} degrees: a sinusoidal \
             DTM must lie within 89 degrees of the equator",
            lat(south).to_degrees(),
            lat(north).to_degrees()
        );
    }
    let lean = |x: f64, y: f64| (x / (radius_m * lat(y).cos()) * lat(y).sin()).abs();
    let t = [(west, north), (east, north), (west, south), (east, south)]
        .iter()
        .map(|&(x, y)| lean(x, y))
        .fold(0.0, f64::max);
    let lon = |x: f64, y: f64| clon + (x / (radius_m * lat(y).cos())).to_degrees();
    if t > 0.05 {
        bail!(
            "{name}: the DTM reaches from longitude {:.4} to {:.4} at latitude {:.4}, about CENTER_LONGITUDE = {clon}: \
             there the sinusoidal projection's meridians lean by {:.2} degrees and its cells are sheared; only \
             sinusoidal DTMs near their central meridian (lean up to 2.9 degrees, as HRSC DTMs about their strip's \
             meridian) are read: reproject it (gdalwarp -t_srs with +proj=eqc) or crop it",
            lon(west, if north.abs() > south.abs() { north } else { south }),
            lon(east, if north.abs() > south.abs() { north } else { south }),
            lat(if north.abs() > south.abs() { north } else { south }).to_degrees(),
            t.atan().to_degrees()
        );
    }
    notes.push(format!(
        "{name}: PDS3 sinusoidal map on {body} (sphere of radius {radius_m} m) about CENTER_LONGITUDE {clon}: \
         MAP_SCALE {cell} m is true along the parallels; cells taken as {cell} x {cell} m (at the DTM's corners \
         the meridians lean by up to {:.3} degrees and are {:.4}% longer than on the map)",
        t.atan().to_degrees(),
        100.0 * ((1.0 + t * t).sqrt() - 1.0)
    ));
    Ok((cell, cell))
}

/// GeoTIFF keys (OGC 19-008r4) of the map's projected CRS, user-defined on the body's sphere,
/// so that a GeoTIFF written over a PDS3 DTM (`plan --risk-map`) carries its projection: the
/// GeoKeyDirectory, GeoDoubleParams and GeoAsciiParams. Equirectangular is CT_Equirectangular
/// (17) with the standard parallel CENTER_LATITUDE and latitude of origin 0 (y = R lat); polar
/// stereographic is CT_PolarStereographic (15) with origin at the pole and scale 1 there;
/// sinusoidal is CT_Sinusoidal (24) about CENTER_LONGITUDE.
fn geokeys(
    projection: &str,
    radius_m: f64,
    clat: f64,
    clon: f64,
    body: &str,
) -> (Vec<u16>, Vec<f64>, String) {
    const USER: u16 = 32767;
    const DOUBLES: u16 = 34736;
    const ASCII: u16 = 34737;
    let equi = projection == "EQUIRECTANGULAR";
    let sinusoidal = projection == "SINUSOIDAL";
    let (transform, title) = match projection {
        "EQUIRECTANGULAR" => (17, "Equirectangular"),
        "SINUSOIDAL" => (24, "Sinusoidal"),
        _ => (15, "Polar Stereographic"),
    };
    let citation = format!("{title} {body}|");
    let geog = format!("GCS {body} sphere|");
    let ascii = format!("{citation}{geog}");
    let mut doubles = vec![radius_m, radius_m];
    let mut entries: Vec<[u16; 4]> = vec![
        [1024, 0, 1, 1], // GTModelTypeGeoKey: projected
        [1025, 0, 1, 1], // GTRasterTypeGeoKey: PixelIsArea
        [1026, ASCII, citation.len() as u16, 0],
        [2048, 0, 1, USER], // GeographicTypeGeoKey
        [2049, ASCII, geog.len() as u16, citation.len() as u16],
        [2050, 0, 1, USER],      // GeogGeodeticDatumGeoKey
        [2054, 0, 1, 9102],      // GeogAngularUnitsGeoKey: degree
        [2056, 0, 1, USER],      // GeogEllipsoidGeoKey
        [2057, DOUBLES, 1, 0],   // GeogSemiMajorAxisGeoKey
        [2058, DOUBLES, 1, 1],   // GeogSemiMinorAxisGeoKey
        [3072, 0, 1, USER],      // ProjectedCSTypeGeoKey
        [3074, 0, 1, USER],      // ProjectionGeoKey
        [3075, 0, 1, transform], // ProjCoordTransGeoKey
        [3076, 0, 1, 9001],      // ProjLinearUnitsGeoKey: metre
    ];
    let mut param = |key: u16, v: f64| {
        entries.push([key, DOUBLES, 1, doubles.len() as u16]);
        doubles.push(v);
    };
    param(3082, 0.0); // ProjFalseEastingGeoKey
    param(3083, 0.0); // ProjFalseNorthingGeoKey
    if sinusoidal {
        param(3088, clon); // ProjCenterLongGeoKey
    } else if equi {
        param(3078, clat); // ProjStdParallel1GeoKey
        param(3088, clon); // ProjCenterLongGeoKey
        param(3089, 0.0); // ProjCenterLatGeoKey
    } else {
        param(3081, clat); // ProjNatOriginLatGeoKey: the pole
        param(3092, 1.0); // ProjScaleAtNatOriginGeoKey
        param(3095, clon); // ProjStraightVertPoleLongGeoKey
    }
    entries.sort_by_key(|e| e[0]);
    let mut dir = vec![1, 1, 0, entries.len() as u16];
    dir.extend(entries.into_iter().flatten());
    (dir, doubles, ascii)
}

/// The body: TARGET_NAME as written ("MARS" -> "Mars"), else by its radius.
fn body_name(label: &Label, radius_m: f64) -> String {
    if let Some((t, _)) = label.word("TARGET_NAME") {
        let mut chars = t.chars();
        if let Some(first) = chars.next() {
            return first.to_string() + &chars.as_str().to_ascii_lowercase();
        }
    }
    let near = |r: f64| (radius_m - r).abs() < 1000.0;
    if near(3_396_190.0) {
        "Mars".into()
    } else if near(1_737_400.0) {
        "the Moon".into()
    } else {
        "the body".into()
    }
}
