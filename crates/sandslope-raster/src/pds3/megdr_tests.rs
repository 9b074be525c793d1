//! MOLA MEGDR layouts (issue 56): detached `.LBL` over an `.IMG` of MSB 16-bit integers,
//! `MAP_PROJECTION_TYPE = "SIMPLE CYLINDRICAL"`, written here as the MEGDR labels are (keys,
//! units and the 1-based projection offsets of the MEGDR's DSMAP.CAT), a global map and a
//! tile. Expected values worked by hand from the labels.

use std::path::{Path, PathBuf};

use crate::crs::Crs;
use crate::read_raster;

/// A MEGDR-style label over `lines` x `samples` and its `.IMG` of heights `z(col, row)`
/// (MSB_INTEGER), written to `dir`; `extra` replaces statements (`KEY = value` lines) by key.
fn megdr(
    dir: &Path,
    stem: &str,
    lines: usize,
    samples: usize,
    map: &[(&str, &str)],
    z: impl Fn(usize, usize) -> i16,
) -> PathBuf {
    let img = format!("{stem}.IMG");
    let mut statements: Vec<(String, String)> = [
        ("PDS_VERSION_ID", "PDS3".to_string()),
        ("RECORD_TYPE", "FIXED_LENGTH".into()),
        ("RECORD_BYTES", (2 * samples).to_string()),
        ("FILE_RECORDS", lines.to_string()),
        ("^IMAGE", format!("\"{img}\"")),
        ("DATA_SET_ID", "\"MGS-M-MOLA-5-MEGDR-L3-V1.0\"".into()),
        ("TARGET_NAME", "MARS".into()),
        ("OBJECT", "IMAGE".into()),
        ("NAME", "TOPOGRAPHY".into()),
        ("LINES", lines.to_string()),
        ("LINE_SAMPLES", samples.to_string()),
        ("SAMPLE_TYPE", "MSB_INTEGER".into()),
        ("SAMPLE_BITS", "16".into()),
        ("UNIT", "METER".into()),
        ("SCALING_FACTOR", "1".into()),
        ("OFFSET", "0".into()),
        ("END_OBJECT", "IMAGE".into()),
        ("OBJECT", "IMAGE_MAP_PROJECTION".into()),
        ("^DATA_SET_MAP_PROJECTION", "\"DSMAP.CAT\"".into()),
        ("MAP_PROJECTION_TYPE", "\"SIMPLE CYLINDRICAL\"".into()),
        ("A_AXIS_RADIUS", "3396.0 <KM>".into()),
        ("B_AXIS_RADIUS", "3396.0 <KM>".into()),
        ("C_AXIS_RADIUS", "3396.0 <KM>".into()),
        ("FIRST_STANDARD_PARALLEL", "\"N/A\"".into()),
        ("POSITIVE_LONGITUDE_DIRECTION", "\"EAST\"".into()),
        ("CENTER_LATITUDE", "0.0 <DEGREE>".into()),
        ("CENTER_LONGITUDE", "180.0 <DEGREE>".into()),
        ("MAP_PROJECTION_ROTATION", "0.0".into()),
        ("MAP_RESOLUTION", "4 <PIXEL/DEGREE>".into()),
        ("MAP_SCALE", "14.818 <KM/PIXEL>".into()),
        ("MAXIMUM_LATITUDE", "90.0 <DEGREE>".into()),
        ("MINIMUM_LATITUDE", "-90.0 <DEGREE>".into()),
        ("WESTERNMOST_LONGITUDE", "0.0 <DEGREE>".into()),
        ("EASTERNMOST_LONGITUDE", "360.0 <DEGREE>".into()),
        ("LINE_PROJECTION_OFFSET", "360.5 <PIXEL>".into()),
        ("SAMPLE_PROJECTION_OFFSET", "720.5 <PIXEL>".into()),
        ("END_OBJECT", "IMAGE_MAP_PROJECTION".into()),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect();
    for (k, v) in map {
        match statements.iter_mut().find(|(key, _)| key == k) {
            Some(s) => s.1 = v.to_string(),
            None => panic!("no statement {k}"),
        }
    }
    let mut text: String = statements.iter().map(|(k, v)| format!("{k:<30}= {v}\r\n")).collect();
    text.push_str("END\r\n");
    std::fs::write(dir.join(format!("{stem}.LBL")), text).unwrap();
    let mut bytes = Vec::with_capacity(2 * lines * samples);
    for r in 0..lines {
        for c in 0..samples {
            bytes.extend_from_slice(&z(c, r).to_be_bytes());
        }
    }
    std::fs::write(dir.join(img), bytes).unwrap();
    dir.join(format!("{stem}.LBL"))
}

/// The global 4 pixels-a-degree topography (MEGT90N000CB's layout: 1440 x 720, the origin
/// at longitude 180 between samples 720 and 721, SAMPLE_PROJECTION_OFFSET 720.5, and at the
/// equator between lines 360 and 361). By hand: the west edge is 180 + (0.5 - 720.5) / 4 = 0
/// degrees, the north edge 0 + (360.5 - 0.5) / 4 = 90 degrees, cells 0.25 degrees; on the
/// 3396 km sphere a cell is 2 pi 3 396 000 / 1440 = 14 817.85 m north-south, and row r's is
/// that times cos(90 - (r + 0.5) / 4 degrees) east-west: 32.33 m at row 0 (latitude 89.875, cos 0.0021817),
/// 14 817.81 m at row 359 (latitude 0.125).
#[test]
fn a_global_megdr_reads_as_longitude_latitude_on_the_sphere() {
    let dir = tempfile::tempdir().unwrap();
    let path = megdr(dir.path(), "MEGT90N000CB", 720, 1440, &[], |c, r| (c as i16 - r as i16) * 3 - 8000);
    let m = read_raster(&path).unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!((m.cols, m.rows), (1440, 720));
    assert_eq!((m.geo.west, m.geo.north, m.geo.cell_x, m.geo.cell_y), (0.0, 90.0, 0.25, 0.25));
    assert!(
        matches!(&m.crs, Crs::Geographic { ellipsoid } if ellipsoid.semi_major_m == 3_396_000.0 && ellipsoid.name == "Mars")
    );
    assert!((m.cell_m.1 - 14_817.85).abs() < 0.01 && m.cell_m.0 == m.cell_m.1, "{:?}", m.cell_m);
    let w = m.row_widths_m.as_ref().unwrap();
    assert!(
        (w[0] - 32.33).abs() < 0.01 && (w[359] - 14_817.81).abs() < 0.01 && w[0] == w[719],
        "{} {}",
        w[0],
        w[359]
    );
    // Heights: MSB 16-bit, metres: (col - row) 3 - 8000.
    assert_eq!(m.values[0], -8000.0);
    assert_eq!(m.values[5 * 1440 + 1439], f64::from((1439 - 5) * 3 - 8000));
    assert_eq!(m.values[719 * 1440], f64::from(-719 * 3 - 8000));
    let notes = m.notes.join("\n");
    assert!(notes.contains("simple cylindrical map on Mars"), "{notes}");
    assert!(notes.contains("within a degree of a pole"), "{notes}");
    // A GeoTIFF written over it says longitude and latitude in degrees (GTModelType 2).
    let keys = m.geo.geokeys.as_ref().unwrap();
    assert!(keys[4..].chunks(4).any(|k| k == [1024, 0, 1, 2]), "{keys:?}");
}

/// A tile of the 128 pixels-a-degree set has the same label with its own offsets: here the
/// layout of a tile from the equator to 44 degrees south and 90 to 180 east at 4 pixels a
/// degree (176 x 360): LINE_PROJECTION_OFFSET 0.5 puts the north edge at 0 + (0.5 - 0.5) / 4
/// = 0, SAMPLE_PROJECTION_OFFSET 360.5 the west edge at 180 + (0.5 - 360.5) / 4 = 90.
#[test]
fn a_megdr_tile_is_placed_by_its_offsets() {
    let dir = tempfile::tempdir().unwrap();
    let tile = [
        ("LINE_PROJECTION_OFFSET", "0.5 <PIXEL>"),
        ("SAMPLE_PROJECTION_OFFSET", "360.5 <PIXEL>"),
        ("MAXIMUM_LATITUDE", "0.0 <DEGREE>"),
        ("MINIMUM_LATITUDE", "-44.0 <DEGREE>"),
        ("WESTERNMOST_LONGITUDE", "90.0 <DEGREE>"),
        ("EASTERNMOST_LONGITUDE", "180.0 <DEGREE>"),
    ];
    let path = megdr(dir.path(), "MEGT00N090CB", 176, 360, &tile, |_, _| 100);
    let m = read_raster(&path).unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!((m.geo.west, m.geo.north, m.rows, m.cols), (90.0, 0.0, 176, 360));
    let notes = m.notes.join("\n");
    assert!(!notes.contains("pole"), "{notes}");
    // Offsets written from the north-west pixel's centre counted from 0 (as ISIS writes
    // them: 359.5 for the same tile): only that convention gives the stated west edge,
    // 180 + (-0.5 - 359.5) / 4 = 90, and it is taken with a note.
    let zero = [("SAMPLE_PROJECTION_OFFSET", "359.5"), ("LINE_PROJECTION_OFFSET", "-0.5")];
    let both: Vec<_> = tile.iter().copied().filter(|(k, _)| !k.ends_with("OFFSET")).chain(zero).collect();
    let m = read_raster(&megdr(dir.path(), "ZERO", 176, 360, &both, |_, _| 1)).unwrap();
    assert_eq!((m.geo.west, m.geo.north), (90.0, 0.0));
    assert!(m.notes.iter().any(|n| n.contains("counted from 0")), "{:?}", m.notes);
    // A stated extent that neither convention gives is refused naming the keys.
    let wrong: Vec<_> = tile
        .iter()
        .copied()
        .map(|(k, v)| if k == "WESTERNMOST_LONGITUDE" { (k, "100.0") } else { (k, v) })
        .collect();
    let e =
        format!("{:#}", read_raster(&megdr(dir.path(), "WRONG", 176, 360, &wrong, |_, _| 1)).unwrap_err());
    assert!(e.contains("WRONG.LBL") && e.contains("WESTERNMOST_LONGITUDE = 100"), "{e}");
    let west = [("POSITIVE_LONGITUDE_DIRECTION", "WEST")];
    let e = format!("{:#}", read_raster(&megdr(dir.path(), "WEST", 176, 360, &west, |_, _| 1)).unwrap_err());
    assert!(e.contains("POSITIVE_LONGITUDE_DIRECTION = WEST is not supported"), "{e}");
    // Beyond the pole: 721 lines of 0.25 degrees from 90 north.
    let e = format!(
        "{:#}",
        read_raster(&megdr(dir.path(), "POLE", 721, 8, &[("EASTERNMOST_LONGITUDE", "2")], |_, _| 1))
            .unwrap_err()
    );
    assert!(e.contains("beyond a pole"), "{e}");
}
