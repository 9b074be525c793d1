//! `sandslope plan` end to end, on synthetic DEMs whose geometry is known exactly.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use assert_cmd::Command;
use serde_json::Value;
use tiff::encoder::{colortype, compression::DeflateLevel, Compression, TiffEncoder};
use tiff::tags::Tag;

use sandslope::{predict, Ground, Regime, Robot, RobotSpec, Slope};

const ROBOT: &str = "mass_kg = 0.35\nleg_radius_m = 0.04\nleg_width_m = 0.01\nhip_height_m = 0.03\n\
                     leg_speed_rad_s = 6.283185307179586\nstance_legs = 3\nresponse_time_s = 0.2\n";
const TERRAIN: &str = "repose_deg = 25.0\n[[points]]\nslope_deg = 0.0\nk_n = 7.0e5\nk_s = 2.0e6\n";
const WEAK: &str = "[[points]]\nslope_deg = 0.0\nk_n = 7.0e5\nk_s = 1.0e3\n";
const CELL: f64 = 0.5;

struct Setup {
    dir: tempfile::TempDir,
}

impl Setup {
    fn new() -> Setup {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("robot.toml"), ROBOT).unwrap();
        std::fs::write(dir.path().join("terrain.toml"), TERRAIN).unwrap();
        std::fs::write(dir.path().join("weak.toml"), WEAK).unwrap();
        Setup { dir }
    }
    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }
    fn cmd(&self, dem: &str) -> Command {
        let mut c = Command::cargo_bin("sandslope").unwrap();
        c.arg("plan")
            .arg("--dem")
            .arg(self.path(dem))
            .arg("--robot")
            .arg(self.path("robot.toml"))
            .arg("--terrain")
            .arg(self.path("terrain.toml"));
        c
    }
}

/// Writes an ESRI ASCII grid with lower-left corner (0, 0); `z(x, y)` at cell centres.
fn write_asc(path: &Path, cols: usize, rows: usize, z: impl Fn(f64, f64) -> f64) {
    let mut s = format!(
        "ncols {cols}\nnrows {rows}\nxllcorner 0\nyllcorner 0\ncellsize {CELL}\nNODATA_value -9999\n"
    );
    for r in 0..rows {
        let y = (rows - r) as f64 * CELL - 0.5 * CELL;
        let line: Vec<String> = (0..cols).map(|c| format!("{:.6}", z((c as f64 + 0.5) * CELL, y))).collect();
        s += &line.join(" ");
        s.push('\n');
    }
    std::fs::write(path, s).unwrap();
}

/// Writes a deflate-compressed single-band GeoTIFF with lower-left corner (0, 0).
fn write_geotiff<C: colortype::ColorType>(
    path: &Path,
    cols: usize,
    rows: usize,
    data: &[C::Inner],
    nodata: &str,
) where
    [C::Inner]: tiff::encoder::TiffValue,
{
    let mut enc = TiffEncoder::new(BufWriter::new(File::create(path).unwrap()))
        .unwrap()
        .with_compression(Compression::Deflate(DeflateLevel::default()));
    let mut img = enc.new_image::<C>(cols as u32, rows as u32).unwrap();
    img.encoder().write_tag(Tag::ModelPixelScaleTag, &[CELL, CELL, 0.0][..]).unwrap();
    img.encoder()
        .write_tag(Tag::ModelTiepointTag, &[0.0, 0.0, 0.0, 0.0, rows as f64 * CELL, 0.0][..])
        .unwrap();
    img.encoder().write_tag(Tag::GdalNodata, nodata).unwrap();
    img.write_data(data).unwrap();
}

fn robot() -> Robot {
    let spec: RobotSpec = toml::from_str(ROBOT).unwrap();
    Robot::new(spec).unwrap()
}

/// The smallest pitch (to 0.01 degree) at which the test robot on the test terrain fails
/// (sinkage or slippage), found by scanning the model.
fn failure_pitch_deg() -> f64 {
    let ground = Ground::new(7e5, 2e6).unwrap().with_repose(Some(Slope::from_degrees(25.0).unwrap()));
    (0..9000)
        .map(|i| i as f64 * 0.01)
        .find(|&d| predict(&robot(), Slope::from_degrees(d).unwrap(), &ground).regime.is_failure())
        .unwrap()
}

#[derive(Debug)]
struct Vertex {
    objective: String,
    x: f64,
    y: f64,
    heading: Option<f64>,
    roll: Option<f64>,
    regime: String,
}

fn read_csv(path: &Path) -> Vec<Vertex> {
    let mut r = csv::Reader::from_path(path).unwrap();
    let h = r.headers().unwrap().clone();
    let col = |name: &str| h.iter().position(|c| c == name).unwrap();
    let (o, x, y, hd, rl, rg) =
        (col("objective"), col("x"), col("y"), col("heading_deg"), col("roll_deg"), col("regime"));
    r.records()
        .map(|rec| {
            let rec = rec.unwrap();
            let f = |i: usize| rec[i].parse::<f64>().ok();
            Vertex {
                objective: rec[o].to_string(),
                x: f(x).unwrap(),
                y: f(y).unwrap(),
                heading: f(hd),
                roll: f(rl),
                regime: rec[rg].to_string(),
            }
        })
        .collect()
}

fn route<'a>(v: &'a [Vertex], objective: &str) -> Vec<&'a Vertex> {
    v.iter().filter(|p| p.objective == objective).collect()
}

fn json_of(out: &[u8]) -> Value {
    serde_json::from_slice(out).unwrap()
}

#[test]
fn steep_plane_distance_route_goes_straight_and_fails_while_time_route_zig_zags_below_failure_pitch() {
    let s = Setup::new();
    // A plane rising north at 25.5 degrees: head-on is at or beyond the 25-degree repose.
    let tan = 25.5_f64.to_radians().tan();
    let z = |_x: f64, y: f64| tan * y;
    write_asc(&s.path("steep.asc"), 31, 61, z);
    let out = s
        .cmd("steep.asc")
        .args(["--start-px", "15,58", "--goal-px", "15,2", "--json", "--csv"])
        .arg(s.path("route.csv"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let j = json_of(&out.stdout);
    let fail_deg = failure_pitch_deg();
    assert!(fail_deg < 25.5 && fail_deg > 20.0, "{fail_deg}");

    // Distance: straight up the fall line (one column), every edge failing.
    let dist = &j["routes"]["distance"];
    assert_eq!(dist["found"], true);
    assert!(dist["survival"].as_f64().unwrap() < 1e-6);
    assert!(dist["time_s"].is_null());
    let v = read_csv(&s.path("route.csv"));
    let d = route(&v, "distance");
    assert_eq!(d.len(), 57, "56 unit steps north");
    assert!(d.iter().all(|p| (p.x - d[0].x).abs() < 1e-9));
    assert!(d.iter().filter_map(|p| p.heading).all(|h| h == 0.0));
    assert!(d.iter().filter(|p| p.heading.is_some()).all(|p| p.regime == "slippage"));

    // Time: found, zig-zags (goes both east and west), every edge's pitch from the DEM below
    // the failure pitch and its roll within the 20-degree default limit.
    let time = &j["routes"]["time"];
    assert_eq!(time["found"], true);
    assert_eq!(time["regimes"]["slippage"], 0);
    assert_eq!(time["regimes"]["sinkage"], 0);
    let t = route(&v, "time");
    let (mut east, mut west) = (false, false);
    for w in t.windows(2) {
        let (dx, dy) = (w[1].x - w[0].x, w[1].y - w[0].y);
        east |= dx > 0.0;
        west |= dx < 0.0;
        let pitch = ((z(w[1].x, w[1].y) - z(w[0].x, w[0].y)) / dx.hypot(dy)).atan().to_degrees();
        assert!(pitch.abs() < fail_deg, "edge {w:?}: pitch {pitch} >= {fail_deg}");
        assert!(w[0].roll.unwrap() <= 20.0 + 1e-6);
        assert!(w[0].regime == "success");
    }
    assert!(east && west, "the time route should switch back");
    let length = time["length_m"].as_f64().unwrap();
    let straight = dist["length_m"].as_f64().unwrap();
    assert!(length > straight * 1.1, "switchbacks are longer: {length} vs {straight}");
}

#[test]
fn gentle_plane_time_route_is_as_long_as_the_straight_line() {
    let s = Setup::new();
    let tan = 5.0_f64.to_radians().tan();
    let z = |x: f64, y: f64| tan * (0.6 * x + 0.8 * y);
    write_asc(&s.path("gentle.asc"), 60, 50, z);
    // Map coordinates: start and goal at cell centres.
    let (a, b): ((f64, f64), (f64, f64)) = ((3.25, 2.75), (27.25, 22.25));
    let out = s
        .cmd("gentle.asc")
        .args(["--start", &format!("{},{}", a.0, a.1), "--goal", &format!("{},{}", b.0, b.1), "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let j = json_of(&out.stdout);
    let len = j["routes"]["time"]["length_m"].as_f64().unwrap();
    let dz = z(b.0, b.1) - z(a.0, a.1);
    let straight = (b.0 - a.0).hypot(b.1 - a.1).hypot(dz);
    // A 16-connected grid path is never shorter, and within a few percent (the worst heading
    // error between moves is half of 26.6 degrees: 1/cos(13.3 deg) - 1 = 2.8 %).
    assert!(len >= straight * (1.0 - 1e-6), "{len} < {straight}");
    assert!(len <= straight * 1.028, "{len} vs {straight}");
    assert_eq!(j["routes"]["time"]["regimes"]["success"].as_u64().unwrap() as usize, {
        // every edge succeeds on a 5-degree plane
        j["routes"]["time"]["regimes"]
            .as_object()
            .unwrap()
            .values()
            .map(|v| v.as_u64().unwrap() as usize)
            .sum::<usize>()
    });
}

#[test]
fn geotiff_nodata_hole_is_avoided_and_risk_map_is_georeferenced() {
    let s = Setup::new();
    let (cols, rows) = (40, 30);
    // Level ground with a nodata block across the straight line from start to goal.
    let hole = |c: usize, r: usize| (15..25).contains(&c) && (5..25).contains(&r);
    let data: Vec<f32> =
        (0..rows * cols).map(|i| if hole(i % cols, i / cols) { -9999.0 } else { 1.0 }).collect();
    write_geotiff::<colortype::Gray32Float>(&s.path("hole.tif"), cols, rows, &data, "-9999");
    let out = s
        .cmd("hole.tif")
        .args(["--start-px", "5,15", "--goal-px", "35,15", "--json", "--csv"])
        .arg(s.path("r.csv"))
        .arg("--risk-map")
        .arg(s.path("risk.tif"))
        .arg("--geojson")
        .arg(s.path("r.geojson"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    for v in read_csv(&s.path("r.csv")) {
        let (c, r) = ((v.x / CELL).floor() as usize, rows - 1 - (v.y / CELL).floor() as usize);
        // Neither in the hole nor next to it (no slope can be computed there).
        assert!(!(14..26).contains(&c) || !(4..26).contains(&r), "{v:?} at ({c}, {r})");
    }
    let gj: Value = serde_json::from_str(&std::fs::read_to_string(s.path("r.geojson")).unwrap()).unwrap();
    assert_eq!(gj["features"][0]["geometry"]["type"], "LineString");
    assert!(gj["features"][0]["properties"]["length_m"].as_f64().unwrap() > 15.0);

    // The risk map: 2 float bands, same pixel scale and tie point as the input.
    let mut dec = tiff::decoder::Decoder::new(File::open(s.path("risk.tif")).unwrap()).unwrap();
    assert_eq!(dec.dimensions().unwrap(), (cols as u32, rows as u32));
    assert_eq!(dec.get_tag_unsigned::<u16>(Tag::SamplesPerPixel).unwrap(), 2);
    assert_eq!(dec.get_tag(Tag::ModelPixelScaleTag).unwrap().into_f64_vec().unwrap()[..2], [CELL, CELL]);
    assert_eq!(
        dec.get_tag(Tag::ModelTiepointTag).unwrap().into_f64_vec().unwrap()[3..5],
        [0.0, rows as f64 * CELL]
    );
    let tiff::decoder::DecodingResult::F32(px) = dec.read_image().unwrap() else { panic!("not float32") };
    let (p_fail, climb): (Vec<f32>, Vec<f32>) = px.chunks(2).map(|c| (c[0], c[1])).unzip();
    // Level ground: best-heading p_fail 0 wherever there is a slope; the hole is NaN.
    assert_eq!(p_fail[10 * cols + 5], 0.0);
    assert!(p_fail[15 * cols + 20].is_nan());
    // No heading climbs on level ground.
    assert!(climb[10 * cols + 5].is_nan());
}

#[test]
fn classes_raster_keeps_the_time_route_off_weak_sand() {
    let s = Setup::new();
    let (cols, rows) = (40, 30);
    write_asc(&s.path("flat.asc"), cols, rows, |_, _| 2.0);
    // int16 classes: 1 everywhere, 2 (weak sand: no anchoring) in a band between start and goal.
    let weak = |c: usize, r: usize| (18..22).contains(&c) && r < 26;
    let classes: Vec<i16> = (0..rows * cols).map(|i| if weak(i % cols, i / cols) { 2 } else { 1 }).collect();
    // A GeoTIFF aligned with the .asc grid (same corner and cell size).
    write_geotiff::<colortype::GrayI16>(&s.path("classes.tif"), cols, rows, &classes, "-1");
    let out = s
        .cmd("flat.asc")
        .args(["--start-px", "5,10", "--goal-px", "35,10", "--json", "--csv"])
        .arg(s.path("c.csv"))
        .arg("--classes")
        .arg(s.path("classes.tif"))
        .arg("--class-terrain")
        .arg(format!("1={},2={}", s.path("terrain.toml").display(), s.path("weak.toml").display()))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let j = json_of(&out.stdout);
    assert_eq!(j["routes"]["time"]["regimes"]["slippage"], 0);
    assert!(j["routes"]["distance"]["regimes"]["slippage"].as_u64().unwrap() > 0);
    for v in route(&read_csv(&s.path("c.csv")), "time") {
        let (c, r) = ((v.x / CELL).floor() as usize, rows - 1 - (v.y / CELL).floor() as usize);
        assert!(!weak(c, r), "{v:?}");
    }
    // A class without terrain is an error naming it.
    let out = s
        .cmd("flat.asc")
        .args(["--start-px", "5,10", "--goal-px", "35,10", "--classes"])
        .arg(s.path("classes.tif"))
        .arg("--class-terrain")
        .arg(format!("1={}", s.path("terrain.toml").display()))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("class 2"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn start_or_goal_in_nodata_or_outside_is_a_clear_error_without_output() {
    let s = Setup::new();
    let mut text =
        String::from("ncols 10\nnrows 10\nxllcorner 100\nyllcorner 200\ncellsize 1\nNODATA_value -9999\n");
    for r in 0..10 {
        let row: Vec<&str> = (0..10).map(|c| if (r, c) == (4, 4) { "-9999" } else { "0" }).collect();
        text += &row.join(" ");
        text.push('\n');
    }
    std::fs::write(s.path("small.asc"), text).unwrap();
    let cases: [(&[&str], &str); 8] = [
        (&["--start", "104.5,205.5", "--goal", "107.5,202.5"], "nodata"),
        (&["--start", "99,205", "--goal", "107.5,202.5"], "outside the map"),
        (&["--start-px", "2,2", "--goal-px", "10,3"], "outside the map"),
        (&["--start-px", "0,5", "--goal-px", "7,7"], "map border, which is impassable"),
        (&["--start-px", "-1,5", "--goal-px", "7,7"], "outside the map"),
        // The map's corner and a point on its southern edge lie on the impassable border.
        (&["--start", "100,200", "--goal", "107.5,202.5"], "on the edge of the map"),
        (&["--start", "104,200", "--goal", "107.5,202.5"], "the border is impassable"),
        // Inside the outermost cells: the same reason, from the planner.
        (&["--start", "100.5,205", "--goal", "107.5,202.5"], "map border, which is impassable"),
    ];
    for (args, want) in cases {
        let out = s.cmd("small.asc").args(args).arg("--geojson").arg(s.path("o.geojson")).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
        assert!(!s.path("o.geojson").exists());
    }
}

#[test]
fn unreachable_goal_is_reported_as_not_found() {
    let s = Setup::new();
    // A 40-degree plane: no heading has pitch below the success limit and roll within 20
    // degrees, so nothing but the distance route exists.
    let tan = 40.0_f64.to_radians().tan();
    write_asc(&s.path("wall.asc"), 20, 20, |_, y| tan * y);
    let out =
        s.cmd("wall.asc").args(["--start-px", "10,17", "--goal-px", "10,3", "--json"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let j = json_of(&out.stdout);
    assert_eq!(j["routes"]["time"]["found"], false);
    assert_eq!(j["routes"]["time"]["reason"], "start_impassable");
    assert_eq!(
        j["routes"]["time"]["message"],
        "start impassable: every heading out of the start cell is too steep or too cross-sloped"
    );
    assert_eq!(j["routes"]["distance"]["found"], true);
    let _ = Regime::Success;
}

#[test]
fn gdal_written_dem_in_utm_coordinates_plans_and_keeps_its_crs() {
    // A float32 GeoTIFF written by GDAL (deflate, floating-point predictor, 16 x 16 tiles;
    // crates/sandslope-io/tests/fixtures/gdal/make.py): z = 100 + 0.25 col - 0.5 row on 2 m cells in UTM 33N,
    // north-west corner (500000, 4100000), nodata at (3, 4) and (30, 20).
    let s = Setup::new();
    let dem = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../sandslope-io/tests/fixtures/gdal/f32-deflate-pred3-tiled.tif");
    // An absolute path: `Setup::cmd` joins it onto the temporary folder, which keeps it.
    let out = s
        .cmd(dem.to_str().unwrap())
        .args(["--start", "500011,4099951", "--goal", "500071,4099991", "--json", "--csv"])
        .arg(s.path("r.csv"))
        .arg("--risk-map")
        .arg(s.path("risk.tif"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(json_of(&out.stdout)["routes"]["time"]["found"], true);
    // Start and goal are the centres of cells (5, 24) and (35, 4), in map coordinates.
    let v = read_csv(&s.path("r.csv"));
    let time = route(&v, "time");
    let (first, last) = (time[0], time[time.len() - 1]);
    assert_eq!((first.x, first.y), (500011.0, 4099951.0));
    assert_eq!((last.x, last.y), (500071.0, 4099991.0));
    // The risk map carries the DEM's projected CRS (ProjectedCSTypeGeoKey 3072 = EPSG:32633).
    let mut dec = tiff::decoder::Decoder::new(File::open(s.path("risk.tif")).unwrap()).unwrap();
    let keys = dec.get_tag(Tag::GeoKeyDirectoryTag).unwrap().into_u16_vec().unwrap();
    assert!(keys[4..].chunks_exact(4).any(|e| e[0] == 3072 && e[3] == 32633), "{keys:?}");
    assert_eq!(
        dec.get_tag(Tag::ModelTiepointTag).unwrap().into_f64_vec().unwrap()[3..5],
        [500000.0, 4100000.0]
    );
}

#[test]
fn negative_numbers_get_the_valid_range_not_a_parse_error() {
    // A negative value used to be taken for an unknown flag ("unexpected argument '-1'").
    let s = Setup::new();
    write_asc(&s.path("flat.asc"), 10, 10, |_, _| 0.0);
    let cases: [(&str, &str, &str); 4] = [
        ("--time-weight", "-1", "--time-weight = -1 must be a finite number of at least 0"),
        ("--max-roll", "-5", "--max-roll = -5 must be between 0 and 90"),
        ("--cv-n", "-0.1", "--cv-n = -0.1 must be a finite number of at least 0"),
        ("--cv-s", "-2", "--cv-s = -2 must be a finite number of at least 0"),
    ];
    for (flag, value, want) in cases {
        let out =
            s.cmd("flat.asc").args(["--start-px", "2,2", "--goal-px", "7,7", flag, value]).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{flag}: {err}");
        assert!(err.contains(want), "{flag}: {err}");
    }
}

#[test]
fn geojson_coordinates_carry_no_float_noise() {
    // Cells of 0.1 m from x = 0.3: centres such as 0.3 + 12.5 * 0.1 are not exact in binary
    // and used to print as 1.5499999999999998.
    let s = Setup::new();
    let mut text = String::from("ncols 30\nnrows 30\nxllcorner 0.3\nyllcorner 51.3\ncellsize 0.1\n");
    for _ in 0..30 {
        text += &vec!["0"; 30].join(" ");
        text.push('\n');
    }
    std::fs::write(s.path("fine.asc"), text).unwrap();
    let out = s
        .cmd("fine.asc")
        .args(["--start-px", "2,3", "--goal-px", "25,21", "--geojson"])
        .arg(s.path("r.geojson"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(s.path("r.geojson")).unwrap();
    let g: Value = serde_json::from_str(&text).unwrap();
    let coords = g["features"][0]["geometry"]["coordinates"].as_array().unwrap();
    // The start, the centre of column 2, row 3: x = 0.3 + 2.5 * 0.1, y = 54.3 - 3.5 * 0.1.
    assert_eq!(coords[0][0].as_f64().unwrap(), 0.55);
    assert_eq!(coords[0][1].as_f64().unwrap(), 53.95);
    for c in coords {
        for v in c.as_array().unwrap() {
            // Every coordinate is a centre: a whole number of 0.05 m steps, printed with at most
            // two decimals.
            let printed = v.to_string();
            let decimals = printed.split('.').nth(1).map_or(0, str::len);
            assert!(decimals <= 2, "{printed} in {text}");
        }
    }
}

/// `plan --json` by distance and time from cell (5, 10) to (55, 40) of the GDAL fixture `dem`
/// (`sandslope-io/tests/fixtures/gdal`), with `extra` flags; asserts that it succeeded.
fn plan_gdal_fixture(dem: &str, extra: &[std::ffi::OsString]) -> std::process::Output {
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("../sandslope-io/tests/fixtures/gdal");
    let out = Command::cargo_bin("sandslope")
        .unwrap()
        .args(["plan", "--start-px", "5,10", "--goal-px", "55,40", "--objective", "distance,time", "--json"])
        .arg("--dem")
        .arg(fixtures.join(dem))
        .args(extra)
        .output()
        .unwrap();
    assert!(out.status.success(), "{dem}: {}", String::from_utf8_lossy(&out.stderr));
    out
}

/// One synthetic hill written by GDAL in EPSG:4326 (1 arc-second cells) and in a projected CRS
/// whose cells are the geographic cells' ground size (crates/sandslope-io/tests/fixtures/gdal/
/// make_crs.py): plan finds the same route on both, its GeoJSON is in lon/lat for the
/// geographic DEM, and its length agrees with the haversine length of that polyline (a sphere
/// of the mean Earth radius, 6 371 008.8 m) within 0.5% (before issue 24 the degrees were read as
/// metres and every cell was far too steep).
#[test]
fn a_geographic_dem_plans_in_metres_like_its_projected_twin() {
    let dir = tempfile::tempdir().unwrap();
    let run = |dem: &str| -> (Value, Value, String) {
        let geojson = dir.path().join(format!("{dem}.geojson"));
        let out = plan_gdal_fixture(dem, &["--geojson".into(), geojson.clone().into()]);
        let g: Value = serde_json::from_str(&std::fs::read_to_string(&geojson).unwrap()).unwrap();
        (json_of(&out.stdout), g, String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let (geo, geo_json, notes) = run("geo-wgs84.tif");
    let (utm, utm_json, _) = run("proj-same-cells.tif");
    assert!(notes.contains("geographic coordinates (degrees) on WGS84"), "{notes}");
    // The twin's cells are all the mid-latitude's size; the geographic DEM's rows each have
    // their own width, which across its 48 arc-seconds of latitude differs from that by at most
    // tan(40 deg) x 24" = 9.8e-5 (make_crs.py): the lengths agree within that.
    for objective in ["distance", "time"] {
        let (a, b) = (&geo["routes"][objective], &utm["routes"][objective]);
        assert_eq!(a["found"], true);
        let (la, lb) = (a["length_m"].as_f64().unwrap(), b["length_m"].as_f64().unwrap());
        assert!((la - lb).abs() < 9.8e-5 * lb, "{objective}: {la} vs {lb}");
    }
    let coords = |g: &Value| -> Vec<(f64, f64)> {
        g["features"][0]["geometry"]["coordinates"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
            .collect()
    };
    let (lonlat, metres) = (coords(&geo_json), coords(&utm_json));
    assert_eq!(lonlat.len(), metres.len(), "the same cells");
    assert!(lonlat.iter().all(|&(lon, lat)| (10.0..10.02).contains(&lon) && (40.0..40.03).contains(&lat)));
    let haversine = |a: (f64, f64), b: (f64, f64)| {
        let (l1, p1, l2, p2) = (a.0.to_radians(), a.1.to_radians(), b.0.to_radians(), b.1.to_radians());
        let h = ((p2 - p1) / 2.0).sin().powi(2) + p1.cos() * p2.cos() * ((l2 - l1) / 2.0).sin().powi(2);
        2.0 * 6_371_008.8 * h.sqrt().asin()
    };
    let along: f64 = lonlat.windows(2).map(|w| haversine(w[0], w[1])).sum();
    let length = geo["routes"]["distance"]["length_m"].as_f64().unwrap();
    assert!((length - along).abs() < 0.005 * along, "{length} m vs haversine {along} m");
    // The projected twin's routes name their CRS, EPSG:32632 as make_crs.py wrote it, in the
    // `crs` member GDAL and QGIS read; RFC 7946 longitude, latitude needs none.
    assert_eq!(utm_json["crs"]["type"], "name");
    assert_eq!(utm_json["crs"]["properties"]["name"], "urn:ogc:def:crs:EPSG::32632");
    assert!(geo_json.get("crs").is_none(), "{}", geo_json["crs"]);
}

/// A geographic DEM spanning 60 to 30 degrees north (41 x 120 cells of 0.25 degrees, level
/// ground) on a sphere of 6 371 000 m named by its GeoKeys (semi-major axis, no flattening):
/// each row's cells are R cos(lat) dlambda wide, so the distance routes along row 20 (latitude
/// 54.875) east-west, down column 20 north-south and corner to corner are as long as the
/// haversine lengths of their GeoJSON polylines within 0.5% (they agree within 1e-5). With one
/// width at the mid-latitude, 45 degrees, the east-west route was 23% too long (the library's
/// `routes_on_geographic_rows_are_as_long_as_the_haversine`).
#[test]
fn a_geographic_dem_from_60_to_30_degrees_north_measures_each_row_on_the_sphere() {
    const R: f64 = 6_371_000.0;
    let (cols, rows, deg) = (41usize, 120usize, 0.25);
    let dir = tempfile::tempdir().unwrap();
    let dem = dir.path().join("geo.tif");
    {
        let mut enc = TiffEncoder::new(BufWriter::new(File::create(&dem).unwrap())).unwrap();
        let mut img = enc.new_image::<colortype::Gray32Float>(cols as u32, rows as u32).unwrap();
        img.encoder().write_tag(Tag::ModelPixelScaleTag, &[deg, deg, 0.0][..]).unwrap();
        img.encoder().write_tag(Tag::ModelTiepointTag, &[0.0, 0.0, 0.0, 0.0, 60.0, 0.0][..]).unwrap();
        // GTModelType geographic, PixelIsArea, user-defined geographic CRS and ellipsoid in
        // degrees, semi-major axis R and inverse flattening 0 (a sphere) from GeoDoubleParams.
        let keys: [u16; 32] = [
            1, 1, 0, 7, 1024, 0, 1, 2, 1025, 0, 1, 1, 2048, 0, 1, 32767, 2054, 0, 1, 9102, 2056, 0, 1, 32767,
            2057, 34736, 1, 0, 2059, 34736, 1, 1,
        ];
        img.encoder().write_tag(Tag::GeoKeyDirectoryTag, &keys[..]).unwrap();
        img.encoder().write_tag(Tag::GeoDoubleParamsTag, &[R, 0.0][..]).unwrap();
        img.write_data(&vec![0.0f32; cols * rows]).unwrap();
    }

    let haversine = |a: (f64, f64), b: (f64, f64)| {
        let (l1, p1, l2, p2) = (a.0.to_radians(), a.1.to_radians(), b.0.to_radians(), b.1.to_radians());
        let h = ((p2 - p1) / 2.0).sin().powi(2) + p1.cos() * p2.cos() * ((l2 - l1) / 2.0).sin().powi(2);
        2.0 * R * h.sqrt().asin()
    };
    for (start, goal) in [("2,20", "38,20"), ("20,2", "20,117"), ("2,2", "38,117")] {
        let geojson = dir.path().join("route.geojson");
        let out = Command::cargo_bin("sandslope")
            .unwrap()
            .args([
                "plan",
                "--objective",
                "distance",
                "--json",
                "--start-px",
                start,
                "--goal-px",
                goal,
                "--dem",
            ])
            .arg(&dem)
            .arg("--geojson")
            .arg(&geojson)
            .output()
            .unwrap();
        let notes = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{notes}");
        // Row 0 at 59.875 degrees: 6 371 000 x cos(59.875 deg) x 0.25 deg = 13 951.8549 m; row
        // 119 at 30.125 degrees: 24 044.0268 m.
        assert!(
            notes.contains(
                "from 13951.8549 m (row 0, latitude 59.8750) to 24044.0268 m (row 119, latitude 30.1250)"
            ),
            "{notes}"
        );
        let g: Value = serde_json::from_str(&std::fs::read_to_string(&geojson).unwrap()).unwrap();
        let lonlat: Vec<(f64, f64)> = g["features"][0]["geometry"]["coordinates"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
            .collect();
        let along: f64 = lonlat.windows(2).map(|w| haversine(w[0], w[1])).sum();
        let length = json_of(&out.stdout)["routes"]["distance"]["length_m"].as_f64().unwrap();
        assert!((length / along - 1.0).abs() < 1e-5, "{start} -> {goal}: {length} m vs haversine {along} m");
    }
}

/// A HiRISE-layout PDS3 DTM (`sandslope-io/tests/fixtures/pds3/make_pds3.py`: equirectangular
/// on Mars, MAP_SCALE 20 m true at latitude 15, rows at latitude 20) plans like its GeoTIFF
/// twin written by GDAL with the ground cells worked out in the script (20 cos 20 / cos 15 =
/// 19.4568 m east, 20 m north): the same route, the same length; and cell (5, 10) of the .IMG
/// is at x = -88 000 + 5.5 x 20, y = 1 186 000 - 10.5 x 20 in the map's own metres.
#[test]
fn a_pds3_dtm_plans_in_ground_metres_like_its_geotiff_twin() {
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("../sandslope-io/tests/fixtures/pds3");
    let run = |dem: &str, start: &[&str]| -> (Value, String) {
        let out = Command::cargo_bin("sandslope")
            .unwrap()
            .args(["plan", "--objective", "distance,time", "--json"])
            .args(start)
            .args(["--goal-px", "55,40", "--dem"])
            .arg(fixtures.join(dem))
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        (json_of(&out.stdout), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let (pds, notes) = run("dtm-attached.img", &["--start", "-87890,1185790"]);
    let (twin, _) = run("pds3-twin.tif", &["--start-px", "5,10"]);
    assert!(notes.contains("PDS3 equirectangular map on Mars"), "{notes}");
    // The twin's cells are all the mid-latitude's width; the DTM's rows each their own, which
    // across its latitudes 19.99 to 20.01 degrees differ from that by at most tan(20 deg) x
    // 0.01 deg = 6.4e-5: the lengths agree within that.
    for objective in ["distance", "time"] {
        let (a, b) = (&pds["routes"][objective], &twin["routes"][objective]);
        assert_eq!(a["found"], true, "{objective}");
        let (la, lb) = (a["length_m"].as_f64().unwrap(), b["length_m"].as_f64().unwrap());
        assert!((la - lb).abs() < 6.4e-5 * lb, "{objective}: {la} vs {lb}");
    }
    // At least 50 cells east and 30 north: more than 50 x 19.4568 m, and not 50 x 20 m's worth
    // of straight diagonal moves mistaken for square 20 m cells.
    let length = pds["routes"]["distance"]["length_m"].as_f64().unwrap();
    assert!(length > 50.0 * 19.4568, "{length}");

    // The risk map carries the DTM's map: its corner and cell, and the projection as GeoKeys
    // (GDAL 3.10.3 reads this file as +proj=eqc +lat_ts=15 +lat_0=0 +lon_0=137 +R=3396190, the
    // CRS its PDS driver gives the .IMG).
    let dir = tempfile::tempdir().unwrap();
    let risk = dir.path().join("risk.tif");
    let out = Command::cargo_bin("sandslope")
        .unwrap()
        .args(["plan", "--start-px", "5,10", "--goal-px", "55,40", "--dem"])
        .arg(fixtures.join("dtm-attached.img"))
        .arg("--risk-map")
        .arg(&risk)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mut dec = tiff::decoder::Decoder::new(File::open(&risk).unwrap()).unwrap();
    let tie = dec.get_tag(Tag::ModelTiepointTag).unwrap().into_f64_vec().unwrap();
    let scale = dec.get_tag(Tag::ModelPixelScaleTag).unwrap().into_f64_vec().unwrap();
    assert_eq!((tie[3], tie[4], scale[0], scale[1]), (-88_000.0, 1_186_000.0, 20.0, 20.0));
    let keys = dec.get_tag(Tag::GeoKeyDirectoryTag).unwrap().into_u16_vec().unwrap();
    let doubles = dec.get_tag(Tag::GeoDoubleParamsTag).unwrap().into_f64_vec().unwrap();
    let key = |k: u16| keys[4..].chunks_exact(4).find(|e| e[0] == k).map(|e| (e[1], e[3])).unwrap();
    assert_eq!(key(3075), (0, 17), "CT_Equirectangular");
    assert_eq!(key(3076), (0, 9001), "metres");
    let double = |k: u16| doubles[usize::from(key(k).1)];
    assert_eq!(
        (double(2057), double(2058), double(3078), double(3088)),
        (3_396_190.0, 3_396_190.0, 15.0, 137.0)
    );
}

/// The same hill written by GDAL as ZSTD, BigTIFF (Deflate; LZW with partial edge tiles), a COG
/// with overviews and a GTiff with COPY_SRC_OVERVIEWS (`make_layouts.py`) plans exactly like
/// the Deflate GeoTIFF: the same route length for each objective.
#[test]
fn every_gdal_layout_of_one_dem_plans_the_same_routes() {
    let run = |dem: &str| -> Value { json_of(&plan_gdal_fixture(dem, &[]).stdout) };
    let reference = run("geo-wgs84.tif");
    for dem in [
        "zstd-pred3-tiled.tif",
        "bigtiff-deflate-tiled.tif",
        "bigtiff-lzw-pred3-tiled.tif",
        "cog-overviews.tif",
        "gtiff-copy-src-overviews.tif",
    ] {
        let got = run(dem);
        for objective in ["distance", "time"] {
            let (a, b) = (&got["routes"][objective], &reference["routes"][objective]);
            assert_eq!(a["found"], true, "{dem} {objective}");
            assert_eq!(a["length_m"], b["length_m"], "{dem} {objective}");
            assert_eq!(a["time_s"], b["time_s"], "{dem} {objective}");
        }
    }
}

/// A DEM whose planning would need more memory than `--max-memory` is refused before the
/// planner allocates, with exit code 2 and a message naming the cells, the bytes a cell and the
/// limit. The example dune is 200 x 200 cells; by hand, the planner holds 4 + 1 + 1 + 8 = 14
/// bytes a cell (f32 height, nodata flag, class, two f32 gradients) and each route search 16 + 1
/// (node, predecessor): with the time and distance searches at once (two threads or more) 48
/// bytes a cell, 1.92 MB, or 31 (1.24 MB) on one thread; both above 0.001 GiB (1.07 MB), both
/// below 0.01 GiB.
#[test]
fn a_dem_too_big_for_the_memory_limit_is_refused_naming_the_limit() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let run = |limit: &str| {
        Command::cargo_bin("sandslope")
            .unwrap()
            .current_dir(&root)
            .args(["plan", "--dem", "examples/planning/dune.asc", "--start", "52,30", "--goal", "30,30"])
            .args(["--max-memory", limit, "--json"])
            .output()
            .unwrap()
    };
    let out = run("0.001");
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("dune.asc") && err.contains("200 x 200 cells"), "{err}");
    assert!(err.contains("48 bytes a cell") || err.contains("31 bytes a cell"), "{err}");
    assert!(err.contains("--max-memory limit of 0.001 GiB"), "{err}");
    assert!(out.stdout.is_empty());
    let out = run("0.01");
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let out = run("0");
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--max-memory = 0 must be"));
}

/// The memory check reads the size from the DEM's header, before its samples: an ESRI ASCII
/// grid whose header says 5000 x 5000 cells but which holds a single row is refused for memory
/// (5000^2 x 31 or 48 bytes, 0.72 or 1.12 GiB, against 0.5 GiB) and not for its missing rows,
/// which reading it would have found first; with room for it, the missing rows are the error.
#[test]
fn the_memory_check_comes_from_the_header_before_the_samples_are_read() {
    let s = Setup::new();
    let row: Vec<&str> = vec!["1.0"; 5000];
    std::fs::write(
        s.path("huge.asc"),
        format!("ncols 5000\nnrows 5000\nxllcorner 0\nyllcorner 0\ncellsize 1\n{}\n", row.join(" ")),
    )
    .unwrap();
    let run = |limit: &str, search: &str| {
        let out = s
            .cmd("huge.asc")
            .args(["--start-px", "10,10", "--goal-px", "20,20", "--max-memory", limit, "--search", search])
            .output()
            .unwrap();
        (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let (code, err) = run("0.5", "full");
    assert_eq!(code, Some(2));
    assert!(err.contains("5000 x 5000 cells") && err.contains("--max-memory limit of 0.500 GiB"), "{err}");
    let (code, err) = run("100", "full");
    assert_eq!(code, Some(2));
    assert!(!err.contains("--max-memory") && err.contains("huge.asc"), "{err}");
    // In a corridor (auto's choice above 4096 x 4096 cells) an ASCII grid is held whole, 4
    // bytes a cell (0.093 GiB), the coarse planner 48 + 4 bytes for each of 625 x 625 coarse
    // cells (0.019 GiB) and the coarse pass two bands of 512 rows of 4-byte heights (0.019
    // GiB): 0.131 GiB, above 0.1 GiB and below 0.5.
    for search in ["corridor", "auto"] {
        let (code, err) = run("0.1", search);
        assert_eq!(code, Some(2));
        assert!(err.contains("in a corridor") && err.contains("--max-memory limit of 0.100 GiB"), "{err}");
        let (code, err) = run("0.5", search);
        assert_eq!(code, Some(2));
        assert!(!err.contains("--max-memory") && err.contains("huge.asc"), "{err}");
    }
}

/// `--search corridor` on the example dune (200 x 200 cells, 8 x 8 blocks): the routes are
/// routes of the same graph, so never faster or shorter than the full search's optima, and the
/// JSON says how they were found; the full search's JSON has no such key. Outputs that need the
/// full planner are refused.
#[test]
fn corridor_search_is_never_better_than_the_full_optimum_and_says_so() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let run = |extra: &[&str]| {
        Command::cargo_bin("sandslope")
            .unwrap()
            .current_dir(&root)
            .args([
                "plan",
                "--dem",
                "examples/planning/dune.asc",
                "--start",
                "52,30",
                "--goal",
                "30,30",
                "--json",
            ])
            .args(extra)
            .output()
            .unwrap()
    };
    let full = json_of(&run(&[]).stdout);
    assert!(full.get("search").is_none(), "{full}");
    for width in ["1", "4"] {
        let out = run(&["--search", "corridor", "--corridor-width", width]);
        assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
        let corridor = json_of(&out.stdout);
        assert_eq!(corridor["search"]["mode"], "corridor");
        assert_eq!(corridor["search"]["coarse_size"], serde_json::json!([25, 25]));
        let (a, b) = (&corridor["routes"], &full["routes"]);
        let t = |v: &Value| v["time"]["time_s"].as_f64().unwrap();
        let d = |v: &Value| v["distance"]["length_m"].as_f64().unwrap();
        assert!(t(a) >= t(b) * (1.0 - 1e-12) && d(a) >= d(b) * (1.0 - 1e-12), "{a} vs {b}");
        let cells = corridor["search"]["corridors"]["time"]["corridor_cells"].as_u64().unwrap();
        assert!(cells > 0 && cells <= 40_000, "{cells}");
    }
    let out = run(&["--search", "corridor", "--plot", "x.png"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--plot needs the full-resolution search"));
    let out = run(&["--search", "corridor", "--coarse-factor", "1"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--coarse-factor = 1 must be between 2 and 64"));
}

/// Issue 56: the corridor search reads its DEM window by window (GeoTIFF tiles and strips,
/// PDS3 lines; an ASCII grid is read whole and cut). With a corridor as wide as the map it is
/// the full search, which holds the whole map: the same routes on every layout; and on one hill
/// written in several layouts, the narrow corridors' routes are the same number for number.
#[test]
fn the_windowed_corridor_search_finds_the_full_optimum_on_every_layout() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let fixtures = root.join("crates/sandslope-io/tests/fixtures");
    let run = |dem: &Path, start: &str, goal: &str, extra: &[&str]| -> Value {
        let out = Command::cargo_bin("sandslope")
            .unwrap()
            .args(["plan", "--objective", "distance,time", "--json", "--start-px", start, "--goal-px", goal])
            .arg("--dem")
            .arg(dem)
            .args(extra)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}: {}", dem.display(), String::from_utf8_lossy(&out.stderr));
        json_of(&out.stdout)
    };
    let whole = ["--search", "corridor", "--coarse-factor", "2", "--corridor-width", "256"];
    for (dem, start, goal) in [
        (fixtures.join("gdal/f32-deflate-pred3-tiled.tif"), "6,8", "36,26"),
        (fixtures.join("gdal/i16-lzw-pred2-strips.tif"), "6,8", "36,26"),
        (fixtures.join("gdal/bigtiff-lzw-pred3-tiled.tif"), "5,10", "55,40"),
        (fixtures.join("pds3/dtm-attached.img"), "5,10", "55,40"),
        (fixtures.join("pds3/dtm-detached.lbl"), "3,3", "36,26"),
        (root.join("examples/planning/dune.asc"), "173,100", "100,100"),
    ] {
        let full = run(&dem, start, goal, &["--search", "full"]);
        let corridor = run(&dem, start, goal, &whole);
        assert_eq!(corridor["search"]["mode"], "corridor", "{}", dem.display());
        for objective in ["distance", "time"] {
            let (a, b) = (&corridor["routes"][objective], &full["routes"][objective]);
            assert_eq!(a["found"], b["found"], "{} {objective}", dem.display());
            if b["found"] == true {
                let (la, lb) = (a["length_m"].as_f64().unwrap(), b["length_m"].as_f64().unwrap());
                assert!((la - lb).abs() <= 1e-9 * lb, "{} {objective}: {la} vs {lb}", dem.display());
            }
        }
    }
    let narrow = ["--search", "corridor", "--coarse-factor", "4", "--corridor-width", "1"];
    let reference = run(&fixtures.join("gdal/geo-wgs84.tif"), "5,10", "55,40", &narrow);
    for dem in [
        "zstd-pred3-tiled.tif",
        "bigtiff-deflate-tiled.tif",
        "bigtiff-lzw-pred3-tiled.tif",
        "cog-overviews.tif",
    ] {
        let got = run(&fixtures.join("gdal").join(dem), "5,10", "55,40", &narrow);
        assert_eq!(got["routes"], reference["routes"], "{dem}");
        assert_eq!(got["search"], reference["search"], "{dem}");
    }
}

/// A MOLA MEGDR as published (issue 56): a detached label over MSB 16-bit heights, "SIMPLE
/// CYLINDRICAL" at 4 pixels a degree, the whole globe (1440 x 720, longitudes 0 to 360 east).
/// `--start -10,5` is longitude 350 (the map's own range; latitude 5 is the edge between two
/// rows, and the cell south of it holds it, centred at 4.875); the distance route's length agrees
/// with the haversine length of its GeoJSON polyline on the label's 3396 km sphere within
/// 0.5% (the heights rise 3 m a cell of 14.8 km: the surface adds 2e-8); and the corridor
/// search, reading the .IMG window by window, finds a route at least as long.
#[test]
fn a_global_mola_megdr_plans_in_longitude_and_latitude() {
    let dir = tempfile::tempdir().unwrap();
    let (lines, samples) = (720usize, 1440usize);
    let label = format!(
        "PDS_VERSION_ID = PDS3\r\nRECORD_TYPE = FIXED_LENGTH\r\nRECORD_BYTES = 2880\r\nFILE_RECORDS = 720\r\n\
         ^IMAGE = \"MEGT90N000CB.IMG\"\r\nTARGET_NAME = MARS\r\nOBJECT = IMAGE\r\n  LINES = {lines}\r\n\
         LINE_SAMPLES = {samples}\r\n  SAMPLE_TYPE = MSB_INTEGER\r\n  SAMPLE_BITS = 16\r\n  UNIT = METER\r\n\
         SCALING_FACTOR = 1\r\n  OFFSET = 0\r\nEND_OBJECT = IMAGE\r\nOBJECT = IMAGE_MAP_PROJECTION\r\n\
         MAP_PROJECTION_TYPE = \"SIMPLE CYLINDRICAL\"\r\n  A_AXIS_RADIUS = 3396.0 <KM>\r\n\
         POSITIVE_LONGITUDE_DIRECTION = \"EAST\"\r\n  CENTER_LATITUDE = 0.0 <DEGREE>\r\n\
         CENTER_LONGITUDE = 180.0 <DEGREE>\r\n  MAP_RESOLUTION = 4 <PIXEL/DEGREE>\r\n\
         MAP_SCALE = 14.818 <KM/PIXEL>\r\n  MAXIMUM_LATITUDE = 90.0 <DEGREE>\r\n\
         WESTERNMOST_LONGITUDE = 0.0 <DEGREE>\r\n  LINE_PROJECTION_OFFSET = 360.5 <PIXEL>\r\n\
         SAMPLE_PROJECTION_OFFSET = 720.5 <PIXEL>\r\nEND_OBJECT = IMAGE_MAP_PROJECTION\r\nEND\r\n"
    );
    std::fs::write(dir.path().join("MEGT90N000CB.LBL"), label).unwrap();
    let img: Vec<u8> = (0..lines * samples)
        .flat_map(|i| (((i % samples) as i16 - (i / samples) as i16) * 3 - 8000).to_be_bytes())
        .collect();
    std::fs::write(dir.path().join("MEGT90N000CB.IMG"), img).unwrap();
    let geojson = dir.path().join("routes.geojson");
    let run = |extra: &[&str]| {
        let out = Command::cargo_bin("sandslope")
            .unwrap()
            .args([
                "plan",
                "--start",
                "-10,5",
                "--goal",
                "345,8",
                "--objective",
                "distance",
                "--json",
                "--dem",
            ])
            .arg(dir.path().join("MEGT90N000CB.LBL"))
            .arg("--geojson")
            .arg(&geojson)
            .args(extra)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        (json_of(&out.stdout), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let (full, notes) = run(&[]);
    assert!(
        notes.contains("simple cylindrical map on Mars") && notes.contains("routes wrap across its edges"),
        "{notes}"
    );
    let length = full["routes"]["distance"]["length_m"].as_f64().unwrap();
    let g: Value = serde_json::from_str(&std::fs::read_to_string(&geojson).unwrap()).unwrap();
    let line: Vec<(f64, f64)> = g["features"][0]["geometry"]["coordinates"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
        .collect();
    // Cell centres: longitude 350.125, latitude 4.875 at the start; 345.125, 7.875 at the goal.
    assert_eq!((line[0], *line.last().unwrap()), ((350.125, 4.875), (345.125, 7.875)));
    let haversine = |a: (f64, f64), b: (f64, f64)| {
        let (p1, p2) = (a.1.to_radians(), b.1.to_radians());
        let (dp, dl) = (p2 - p1, (b.0 - a.0).to_radians());
        let h = (dp / 2.0).sin().powi(2) + p1.cos() * p2.cos() * (dl / 2.0).sin().powi(2);
        2.0 * 3_396_000.0 * h.sqrt().asin()
    };
    let along: f64 = line.windows(2).map(|w| haversine(w[0], w[1])).sum();
    assert!((length / along - 1.0).abs() < 0.005, "{length} m vs haversine {along} m");
    let (corridor, _) = run(&["--search", "corridor"]);
    let l = corridor["routes"]["distance"]["length_m"].as_f64().unwrap();
    assert!(l >= length * (1.0 - 1e-12) && l < length * 1.01, "{l} vs {length}");
}
