//! HRSC and CTX DTMs as their archives label them: an HRSC level-4 DTM (`*_DA4.IMG`: the PDS3
//! label attached before a VICAR header and the image, MSB 16-bit heights in metres, -32768
//! missing, SINUSOIDAL about the strip's own meridian, MAP_SCALE in METERS/PIXEL) and a CTX DTM
//! exported by ISIS (`isis2pds`: attached label, PC_REAL, EQUIRECTANGULAR with units written
//! as ISIS writes them, `<DEG>`, `<PIX/DEG>`). Expected values worked by hand from the labels.

use std::path::{Path, PathBuf};

use crate::read_raster;

/// An attached-label DTM `name` written to `dir`: `label(n)` (its statements, with `n` the
/// records of `record` bytes it takes, which its pointers count), then `header_records`
/// records of a VICAR header, then the samples' bytes `data`.
fn attached(
    dir: &Path,
    name: &str,
    label: impl Fn(usize) -> String,
    record: usize,
    header_records: usize,
    data: &[u8],
) -> PathBuf {
    let mut n = 1;
    while label(n).len() > n * record {
        n += 1;
    }
    let mut bytes = label(n).into_bytes();
    bytes.resize(n * record, b' ');
    let vicar = format!("LBLSIZE={}  FORMAT='HALF'  TYPE='IMAGE'", header_records * record);
    let mut header = vicar.into_bytes();
    header.resize(header_records * record, b' ');
    bytes.extend(header);
    bytes.extend_from_slice(data);
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// The label of an HRSC DA4 DTM taking `n` records, with `spo` its SAMPLE_PROJECTION_OFFSET:
/// 30 lines of 40 samples (80-byte records), label in records 1 to n, VICAR header in record
/// n + 1, image from record n + 2.
fn hrsc_label(n: usize, spo: &str) -> String {
    [
        "PDS_VERSION_ID = PDS3",
        "RECORD_TYPE = FIXED_LENGTH",
        "RECORD_BYTES = 80",
        &format!("FILE_RECORDS = {}", n + 31),
        &format!("LABEL_RECORDS = {n}"),
        &format!("^IMAGE_HEADER = {}", n + 1),
        &format!("^IMAGE = {}", n + 2),
        "DATA_SET_ID = \"MEX-M-HRSC-5-REFDR-DTM-V1.0\"",
        "PRODUCT_ID = \"H0000_0000_DA4.IMG\"",
        "INSTRUMENT_ID = HRSC",
        "TARGET_NAME = MARS",
        "PROCESSING_LEVEL_ID = 5",
        "OBJECT = IMAGE_HEADER",
        "  BYTES = 80",
        "  TYPE = VICAR2",
        "  INTERCHANGE_FORMAT = ASCII",
        "END_OBJECT = IMAGE_HEADER",
        "OBJECT = IMAGE",
        "  INTERCHANGE_FORMAT = BINARY",
        "  LINES = 30",
        "  LINE_SAMPLES = 40",
        "  SAMPLE_TYPE = MSB_INTEGER",
        "  SAMPLE_BITS = 16",
        "  BANDS = 1",
        "  BAND_STORAGE_TYPE = BAND_SEQUENTIAL",
        "  CORE_NULL = -32768",
        "  MISSING_CONSTANT = -32768",
        "  SCALING_FACTOR = 1.0",
        "  OFFSET = 0.0",
        "  UNIT = METER",
        "END_OBJECT = IMAGE",
        "OBJECT = IMAGE_MAP_PROJECTION",
        "  ^DATA_SET_MAP_PROJECTION = \"DSMAP.CAT\"",
        "  MAP_PROJECTION_TYPE = SINUSOIDAL",
        "  A_AXIS_RADIUS = 3396.0 <KM>",
        "  B_AXIS_RADIUS = 3396.0 <KM>",
        "  C_AXIS_RADIUS = 3396.0 <KM>",
        "  FIRST_STANDARD_PARALLEL = \"N/A\"",
        "  SECOND_STANDARD_PARALLEL = \"N/A\"",
        "  POSITIVE_LONGITUDE_DIRECTION = EAST",
        "  CENTER_LATITUDE = 0.0 <DEG>",
        "  CENTER_LONGITUDE = 76.0 <DEG>",
        "  MAP_PROJECTION_ROTATION = 0.0",
        "  MAP_RESOLUTION = 1185.42 <PIXEL/DEG>",
        "  MAP_SCALE = 50.0 <METERS/PIXEL>",
        "  LINE_PROJECTION_OFFSET = 23708.5 <PIXEL>",
        &format!("  SAMPLE_PROJECTION_OFFSET = {spo} <PIXEL>"),
        "  COORDINATE_SYSTEM_NAME = PLANETOCENTRIC",
        "END_OBJECT = IMAGE_MAP_PROJECTION",
        "END",
    ]
    .join("\r\n")
}

/// By hand: MAP_SCALE 50 m, the 0-based offsets (as GDAL's PDS driver takes them) put the
/// west edge at -(19.5 + 0.5) 50 = -1000 m and the north edge at (23708.5 + 0.5) 50 =
/// 1 185 450 m (latitude 1 185 450 / 3 396 000 rad = 20.0004 degrees); cells are 50 x 50 m.
/// At the corners the meridians lean by atan(1000 / 3 396 000 tan(20.0004 deg)) = 0.0061
/// degrees. Heights: row r, column c holds 10 (r - c) m, one cell -32768 (missing).
#[test]
fn an_hrsc_dtm_reads_in_sinusoidal_metres() {
    let dir = tempfile::tempdir().unwrap();
    let data: Vec<u8> = (0..30 * 40)
        .flat_map(|i| {
            let (c, r) = (i % 40, i / 40);
            let v = if (c, r) == (7, 3) { -32768 } else { 10 * (r as i16 - c as i16) };
            v.to_be_bytes()
        })
        .collect();
    let path = attached(dir.path(), "H0000_0000_DA4.IMG", |n| hrsc_label(n, "19.5"), 80, 1, &data);
    let m = read_raster(&path).unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!((m.cols, m.rows), (40, 30));
    assert_eq!((m.geo.west, m.geo.north, m.geo.cell_x, m.geo.cell_y), (-1000.0, 1_185_450.0, 50.0, 50.0));
    assert_eq!((m.cell_m, m.row_widths_m.is_none()), ((50.0, 50.0), true));
    assert_eq!((m.values[0], m.values[2 * 40 + 5], m.values[29 * 40 + 39]), (0.0, -30.0, -100.0));
    assert!(m.is_nodata(3 * 40 + 7));
    let notes = m.notes.join("\n");
    assert!(
        notes.contains("sinusoidal map on Mars") && notes.contains("lean by up to 0.006 degrees"),
        "{notes}"
    );
    // A GeoTIFF written over it carries CT_Sinusoidal (24) about longitude 76.
    let keys = m.geo.geokeys.as_ref().unwrap();
    assert!(keys[4..].chunks(4).any(|k| k == [3075, 0, 1, 24]), "{keys:?}");
    // Far from its central meridian (600 to 602 km east at 20 degrees: at the east edge the
    // meridians lean by atan(602 / 3396 tan(20.0004 deg)) = 3.69 degrees) the sheared cells
    // are refused.
    let path = attached(dir.path(), "FAR_DA4.IMG", |n| hrsc_label(n, "-12000.5"), 80, 1, &data);
    let e = format!("{:#}", read_raster(&path).unwrap_err());
    assert!(
        e.contains("FAR_DA4.IMG")
            && e.contains("CENTER_LONGITUDE = 76")
            && e.contains("lean by 3.69 degrees"),
        "{e}"
    );
}

/// A CTX DTM exported by ISIS's isis2pds: the label attached (records of 80 bytes), PC_REAL
/// heights, ISIS's NULL as MISSING_CONSTANT, EQUIRECTANGULAR with ISIS's units. By hand:
/// MAP_SCALE 20 m true at CENTER_LATITUDE 0 (the ISIS default), the north edge at (-11500.5 +
/// 0.5) 20 = -230 000 m, latitude -230 000 / 3 396 190 rad = -3.8804 degrees; row 0's centre
/// 10 m further south, -3.88055 degrees: its cells are 20 cos(3.88055 deg) = 19.9541 m east-west.
#[test]
fn a_ctx_dtm_from_isis_reads_as_equirectangular_rows() {
    let dir = tempfile::tempdir().unwrap();
    let label = |n: usize| {
        [
            "PDS_VERSION_ID = PDS3",
            "RECORD_TYPE = FIXED_LENGTH",
            "RECORD_BYTES = 80",
            &format!("FILE_RECORDS = {}", n + 21),
            &format!("LABEL_RECORDS = {n}"),
            &format!("^IMAGE = {}", n + 2),
            "PRODUCT_ID = \"DTEEC_CTX\"",
            "TARGET_NAME = MARS",
            "INSTRUMENT_ID = CTX",
            "OBJECT = IMAGE",
            "  LINES = 20",
            "  LINE_SAMPLES = 20",
            "  BANDS = 1",
            "  OFFSET = 0.0",
            "  SCALING_FACTOR = 1.0",
            "  SAMPLE_BITS = 32",
            "  SAMPLE_BIT_MASK = 2#11111111111111111111111111111111#",
            "  SAMPLE_TYPE = PC_REAL",
            "  MISSING_CONSTANT = 16#FF7FFFFB#",
            "  CORE_NULL = 16#FF7FFFFB#",
            "  UNIT = METER",
            "END_OBJECT = IMAGE",
            "OBJECT = IMAGE_MAP_PROJECTION",
            "  ^DATA_SET_MAP_PROJECTION = \"DSMAP.CAT\"",
            "  MAP_PROJECTION_TYPE = EQUIRECTANGULAR",
            "  PROJECTION_LATITUDE_TYPE = PLANETOCENTRIC",
            "  A_AXIS_RADIUS = 3396.19 <KM>",
            "  B_AXIS_RADIUS = 3396.19 <KM>",
            "  C_AXIS_RADIUS = 3396.19 <KM>",
            "  COORDINATE_SYSTEM_NAME = PLANETOCENTRIC",
            "  POSITIVE_LONGITUDE_DIRECTION = EAST",
            "  KEYWORD_LATITUDE_TYPE = PLANETOCENTRIC",
            "  CENTER_LATITUDE = 0.0 <DEG>",
            "  CENTER_LONGITUDE = 180.0 <DEG>",
            "  LINE_FIRST_PIXEL = 1",
            "  LINE_LAST_PIXEL = 20",
            "  SAMPLE_FIRST_PIXEL = 1",
            "  SAMPLE_LAST_PIXEL = 20",
            "  MAP_PROJECTION_ROTATION = 0.0 <DEG>",
            "  MAP_RESOLUTION = 2963.8 <PIX/DEG>",
            "  MAP_SCALE = 20.0 <METERS/PIXEL>",
            "  LINE_PROJECTION_OFFSET = -11500.5 <PIXEL>",
            "  SAMPLE_PROJECTION_OFFSET = 299.5 <PIXEL>",
            "END_OBJECT = IMAGE_MAP_PROJECTION",
            "END",
        ]
        .join("\r\n")
    };
    let data: Vec<u8> = (0..400)
        .flat_map(
            |i| if i == 21 { 0xFF7F_FFFBu32.to_le_bytes() } else { (-2500.0f32 + i as f32).to_le_bytes() },
        )
        .collect();
    let path = attached(dir.path(), "CTX_DTM.IMG", label, 80, 1, &data);
    let m = read_raster(&path).unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!((m.geo.west, m.geo.north), (-6000.0, -230_000.0));
    let w = m.row_widths_m.as_ref().unwrap();
    let want = 20.0 * (230_010.0f64 / 3_396_190.0).cos();
    assert!((w[0] - want).abs() < 1e-9 && (want - 19.9541).abs() < 1e-4, "{} vs {want}", w[0]);
    assert_eq!((m.values[0], m.values[399]), (-2500.0, -2101.0));
    assert!(m.is_nodata(21));
    // An ISIS cube is refused naming what is read and how to export it.
    std::fs::write(dir.path().join("ctx.cub"), b"Object = IsisCube\n").unwrap();
    let e = format!("{:#}", read_raster(&dir.path().join("ctx.cub")).unwrap_err());
    assert!(e.contains("ISIS cube") && e.contains("isis2std") && e.contains("GeoTIFF (.tif"), "{e}");
}

/// A GeoTIFF in the equirectangular projection (as GDAL and ISIS export CTX DTMs, and as
/// `plan --risk-map` writes over a PDS3 equirectangular DTM) has the rows of the PDS3 DTM it
/// came from: the GeoKeys (CT_Equirectangular, standard parallel 15, Mars' sphere) of the
/// HiRISE-layout fixture give each row the width its label gives, 20 cos(lat) / cos(15 deg):
/// 19.4558 m at row 0 (latitude 20.0084, worked in docs/planning.md).
#[test]
fn an_equirectangular_geotiff_has_the_rows_of_its_pds3_twin() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../sandslope-io/tests/fixtures/pds3/dtm-attached.img");
    let r = read_raster(&path).unwrap();
    let g = &r.geo;
    let mut notes = Vec::new();
    let cells = crate::crs::equirectangular_rows(
        &"twin.tif",
        g.geokeys.as_deref(),
        g.geodoubles.as_deref(),
        1.0,
        (g.cell_x, g.cell_y),
        g.north,
        r.rows,
        &mut notes,
    )
    .unwrap()
    .unwrap();
    let (want, got) = (r.row_widths_m.as_ref().unwrap(), cells.row_widths_m.as_ref().unwrap());
    assert_eq!(want.len(), got.len());
    for (a, b) in want.iter().zip(got) {
        assert!((a - b).abs() <= 1e-12 * a, "{a} vs {b}");
    }
    assert!((got[0] - 19.4558).abs() < 1e-4 && cells.cell_m.1 == 20.0, "{} {:?}", got[0], cells.cell_m);
    assert!(notes[0].contains("standard parallel 15 degrees"), "{notes:?}");
}
