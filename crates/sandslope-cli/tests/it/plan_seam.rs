//! Routes across the seam of a global map (longitudes wrapping at 0/360): checked against
//! lengths worked out by hand on level ground, and against the same heights planned as a map
//! that does not wrap (a 200-degree crop whose columns run on across longitude 360), which the
//! planner searches without any seam logic.

use std::path::Path;

use assert_cmd::Command;
use serde_json::Value;

/// Mars' sphere in the MEGDR labels, m.
const R: f64 = 3_396_000.0;

/// Writes a MEGDR-layout DTM `name`.LBL/.IMG at 2 pixels a degree, `samples` columns from
/// longitude `west` (whole degrees), all 360 rows from 90 N, heights `z(col, row)` of the
/// global map's columns (col counted from longitude 0), MSB 16-bit with `scale` metres a unit.
fn write_megdr(
    dir: &Path,
    name: &str,
    west: f64,
    samples: usize,
    scale: f64,
    z: impl Fn(usize, usize) -> f64,
) {
    let lines = 360usize;
    // Sample 1's centre is at west + 0.25: longitude = 180 + (sample - offset) / 2.
    let offset = 1.0 - 2.0 * (west + 0.25 - 180.0);
    let label = format!(
        "PDS_VERSION_ID = PDS3\r\nRECORD_TYPE = FIXED_LENGTH\r\nRECORD_BYTES = {}\r\nFILE_RECORDS = {lines}\r\n\
         ^IMAGE = \"{name}.IMG\"\r\nTARGET_NAME = MARS\r\nOBJECT = IMAGE\r\n  LINES = {lines}\r\n\
         LINE_SAMPLES = {samples}\r\n  SAMPLE_TYPE = MSB_INTEGER\r\n  SAMPLE_BITS = 16\r\n  UNIT = METER\r\n\
         SCALING_FACTOR = {scale}\r\n  OFFSET = 0\r\nEND_OBJECT = IMAGE\r\nOBJECT = IMAGE_MAP_PROJECTION\r\n\
         MAP_PROJECTION_TYPE = \"SIMPLE CYLINDRICAL\"\r\n  A_AXIS_RADIUS = 3396.0 <KM>\r\n\
         POSITIVE_LONGITUDE_DIRECTION = \"EAST\"\r\n  CENTER_LATITUDE = 0.0 <DEGREE>\r\n\
         CENTER_LONGITUDE = 180.0 <DEGREE>\r\n  MAP_RESOLUTION = 2 <PIXEL/DEGREE>\r\n\
         MAXIMUM_LATITUDE = 90.0 <DEGREE>\r\n  WESTERNMOST_LONGITUDE = {west} <DEGREE>\r\n\
         LINE_PROJECTION_OFFSET = 180.5 <PIXEL>\r\n  SAMPLE_PROJECTION_OFFSET = {offset} <PIXEL>\r\n\
         END_OBJECT = IMAGE_MAP_PROJECTION\r\nEND\r\n",
        2 * samples
    );
    std::fs::write(dir.join(format!("{name}.LBL")), label).unwrap();
    let first = (2.0 * west) as usize;
    let img: Vec<u8> = (0..lines * samples)
        .flat_map(|i| {
            let (c, r) = ((first + i % samples) % 720, i / samples);
            ((z(c, r) / scale).round() as i16).to_be_bytes()
        })
        .collect();
    std::fs::write(dir.join(format!("{name}.IMG")), img).unwrap();
}

/// `plan --json` on `dem` with `args`; the JSON and the GeoJSON's first LineString per objective.
fn plan(dem: &Path, args: &[&str]) -> (Value, Value, String) {
    let geojson = dem.with_extension("geojson");
    let out = Command::cargo_bin("sandslope")
        .unwrap()
        .arg("plan")
        .arg("--dem")
        .arg(dem)
        .args(["--json", "--geojson"])
        .arg(&geojson)
        .args(args)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{stderr}");
    let g = serde_json::from_str(&std::fs::read_to_string(&geojson).unwrap()).unwrap();
    (serde_json::from_slice(&out.stdout).unwrap(), g, stderr)
}

/// The longitude,latitude vertices of the route of `objective` in a GeoJSON file.
fn line(g: &Value, objective: &str) -> Vec<(f64, f64)> {
    let f =
        g["features"].as_array().unwrap().iter().find(|f| f["properties"]["objective"] == objective).unwrap();
    f["geometry"]["coordinates"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
        .collect()
}

/// Level ground: from 355.25 E to 4.75 E along the row centred at 10.25 N the distance route
/// crosses the seam, 19 steps of half a degree east: 9.5 degrees of the parallel, R cos(10.25)
/// 9.5 pi / 180 = 555,168 m (a route the other way round would be 701 steps, 20.5 Mm). In the
/// corridor search too.
#[test]
fn on_level_ground_the_route_across_the_seam_is_the_short_way() {
    let dir = tempfile::tempdir().unwrap();
    write_megdr(dir.path(), "LEVEL", 0.0, 720, 1.0, |_, _| 0.0);
    let dem = dir.path().join("LEVEL.LBL");
    let want = R * 10.25_f64.to_radians().cos() * 9.5_f64.to_radians();
    for search in ["full", "corridor"] {
        let (json, g, notes) = plan(
            &dem,
            &["--start", "355.3,10.3", "--goal", "4.8,10.3", "--objective", "distance", "--search", search],
        );
        assert!(notes.contains("routes wrap across its edges"), "{notes}");
        let got = json["routes"]["distance"]["length_m"].as_f64().unwrap();
        assert!((got / want - 1.0).abs() < 1e-9, "{search}: {got} m, want {want} m");
        // The GeoJSON runs on across the seam: 355.25 to 364.75 (the map rolled by 359 columns,
        // so that its edges lie at 179.5 E, spans 179.5 to 539.5).
        let l = line(&g, "distance");
        assert_eq!(l.len(), 20, "{search}: {l:?}");
        assert_eq!((l[0], *l.last().unwrap()), ((355.25, 10.25), (364.75, 10.25)), "{search}");
    }
}

/// Ridges of 20 km every 5 degrees (slopes up to about 23 degrees at 29.6 km a cell: the time
/// route must wind) on a global map, planned from 350.25 E, 10.25 N to 20.25 E, 25.25 N across
/// the seam; the same heights as a map of 400 columns from 270 E to 470 E (which does not
/// wrap: the planner sees no seam, the route's columns are plain neighbours) give the same
/// routes: lengths, times, survival and vertices (360 degrees apart in longitude), by the full
/// search and by a corridor wide enough to hold the whole map.
#[test]
fn a_route_across_the_seam_equals_the_route_on_a_map_without_it() {
    let dir = tempfile::tempdir().unwrap();
    let z = |c: usize, r: usize| {
        let (x, y) = (c as f64 * std::f64::consts::TAU, r as f64 * std::f64::consts::TAU);
        20_000.0 * (x / 10.0).sin() * (0.6 + 0.4 * (y / 36.0).cos()) + 3_000.0 * ((x + 3.0 * y) / 24.0).sin()
    };
    write_megdr(dir.path(), "GLOBAL", 0.0, 720, 2.0, z);
    write_megdr(dir.path(), "CROP", 270.0, 400, 2.0, z);
    let args = ["--start", "350.3,10.3", "--goal", "20.3,25.3", "--objective", "time,risk"];
    let (crop, crop_g, crop_notes) = plan(&dir.path().join("CROP.LBL"), &args);
    assert!(!crop_notes.contains("wrap"), "{crop_notes}");
    for extra in [&["--search", "full"][..], &["--search", "corridor", "--corridor-width", "128"]] {
        let (global, global_g, _) = plan(&dir.path().join("GLOBAL.LBL"), &[&args[..], extra].concat());
        for obj in ["time", "risk", "distance"] {
            let (a, b) = (&global["routes"][obj], &crop["routes"][obj]);
            assert_eq!(a["found"], true, "{extra:?} {obj}: {a}");
            for key in ["length_m", "time_s", "survival", "max_pitch_deg"] {
                let (x, y) = (a[key].as_f64().unwrap(), b[key].as_f64().unwrap());
                assert!((x - y).abs() <= 1e-9 * y.abs(), "{extra:?} {obj} {key}: {x} vs {y}");
            }
            let (la, lb) = (line(&global_g, obj), line(&crop_g, obj));
            assert_eq!(la.len(), lb.len(), "{extra:?} {obj}");
            for (p, q) in la.iter().zip(&lb) {
                assert_eq!(((p.0 - q.0).rem_euclid(360.0), p.1), (0.0, q.1), "{extra:?} {obj}");
            }
        }
        // The route does cross the seam: it starts west of longitude 360 and ends east of it.
        let l = line(&crop_g, "time");
        assert!(l[0].0 < 360.0 && l.last().unwrap().0 > 360.0, "{l:?}");
    }
}
