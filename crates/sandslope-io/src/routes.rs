//! Route writers for `sandslope plan`: GeoJSON LineStrings and a per-vertex CSV, in the map
//! coordinates of the elevation raster the routes were planned on.

use std::path::Path;

use anyhow::Result;
use geojson::{Feature, FeatureCollection, Geometry, GeometryValue};
use serde::Serialize;

use sandslope::plan::{HeightSource, NoRoute, Objective, Route};

use sandslope_files::{csv_string, write_atomic};
use sandslope_raster::GeoRef;

/// A map coordinate without float noise from cell arithmetic: rounded to 15 significant
/// digits and at most 9 decimals (a nanometre in a metric CRS, 0.1 mm in degrees), so
/// `51.449999999999996` becomes `51.45` while every real digit of a survey coordinate stays.
pub fn round_coordinate(v: f64) -> f64 {
    if !v.is_finite() || v == 0.0 {
        return v;
    }
    let int_digits = (v.abs().log10().floor() as i32 + 1).max(1);
    let decimals = (15 - int_digits).clamp(0, 9);
    let scale = 10f64.powi(decimals);
    (v * scale).round() / scale
}

/// A cell centre in map coordinates, rounded by [`round_coordinate`].
fn centre(geo: &GeoRef, col: usize, row: usize) -> (f64, f64) {
    let (x, y) = geo.centre(col, row);
    (round_coordinate(x), round_coordinate(y))
}

/// Routes by objective, as `plan` found them (or why none exists).
pub type Routes = [(Objective, Result<Route, NoRoute>)];

/// Writes every found route as a GeoJSON Feature (LineString of cell centres in map
/// coordinates, with objective, length_m, time_s and survival properties).
pub fn write_geojson(path: &Path, geo: &GeoRef, routes: &Routes) -> Result<()> {
    let features = routes.iter().filter_map(|(obj, r)| {
        let r = r.as_ref().ok()?;
        let coords: Vec<[f64; 2]> = r
            .cells
            .iter()
            .map(|c| {
                let (x, y) = centre(geo, c.col, c.row);
                [x, y]
            })
            .collect();
        let mut f = Feature::from(Geometry::new(GeometryValue::new_line_string(coords)));
        f.set_property("objective", obj.name());
        f.set_property("length_m", r.length_m);
        f.set_property("time_s", r.time_s);
        f.set_property("survival", r.survival);
        f.set_property("max_pitch_deg", r.max_pitch_deg);
        f.set_property("max_roll_deg", r.max_roll_deg);
        Some(f)
    });
    let mut fc = FeatureCollection::new(features);
    // RFC 7946 GeoJSON is longitude, latitude on WGS84; routes on a projected map are in its
    // own coordinates, so the CRS is named beside them the way GDAL and QGIS read it (the
    // 2008 GeoJSON `crs` member), when the GeoKeys give its EPSG code.
    if let Some(code) = geo.geokeys.as_deref().and_then(sandslope_raster::crs::projected_epsg) {
        let mut crs = serde_json::Map::new();
        crs.insert("type".into(), "name".into());
        crs.insert(
            "properties".into(),
            serde_json::json!({ "name": format!("urn:ogc:def:crs:EPSG::{code}") }),
        );
        fc.foreign_members = Some(serde_json::Map::from_iter([("crs".to_string(), crs.into())]));
    }
    write_atomic(path, serde_json::to_string_pretty(&fc)?.as_bytes())
}

/// One route vertex: where it is and the edge that leaves it (empty at the goal).
#[derive(Debug, Serialize)]
struct VertexRow {
    objective: &'static str,
    vertex: usize,
    x: f64,
    y: f64,
    z: f64,
    heading_deg: Option<f64>,
    pitch_deg: Option<f64>,
    roll_deg: Option<f64>,
    regime: Option<&'static str>,
    speed_m_s: Option<f64>,
    p_fail: Option<f64>,
    over_roll_limit: Option<bool>,
}

/// Writes one row per route vertex; the edge columns describe the edge leaving the vertex.
/// The heights come from `grid`: the planner's grid, or a map read window by window.
pub fn write_csv(path: &Path, geo: &GeoRef, grid: &dyn HeightSource, routes: &Routes) -> Result<()> {
    let mut rows = Vec::new();
    for (obj, r) in routes {
        let Ok(r) = r else { continue };
        for (i, c) in r.cells.iter().enumerate() {
            let (x, y) = centre(geo, c.col, c.row);
            let s = r.steps.get(i);
            rows.push(VertexRow {
                objective: obj.name(),
                vertex: i,
                x,
                y,
                z: grid
                    .window(c.row..c.row + 1, c.col..c.col + 1)
                    .ok()
                    .and_then(|v| v.first().copied())
                    .map_or(f64::NAN, f64::from),
                heading_deg: s.map(|s| s.heading_deg),
                pitch_deg: s.map(|s| s.pitch_deg),
                roll_deg: s.map(|s| s.roll_deg),
                regime: s.map(|s| s.regime.name()),
                speed_m_s: s.and_then(|s| s.speed),
                p_fail: s.map(|s| s.p_fail),
                over_roll_limit: s.map(|s| s.over_roll_limit),
            });
        }
    }
    write_atomic(path, csv_string(&rows)?.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::round_coordinate;

    #[test]
    fn coordinates_lose_float_noise_but_keep_real_digits() {
        assert_eq!(round_coordinate(51.449_999_999_999_996), 51.45);
        assert_eq!(round_coordinate(0.1 + 0.2), 0.3);
        assert_eq!(round_coordinate(-3.000_000_000_000_000_4), -3.0);
        // A UTM northing keeps its millimetres, a longitude its 9 decimals.
        assert_eq!(round_coordinate(5_712_345.678), 5_712_345.678);
        assert_eq!(round_coordinate(13.123_456_789), 13.123_456_789);
        assert_eq!(round_coordinate(0.0), 0.0);
        assert!(round_coordinate(f64::NAN).is_nan());
    }
}
