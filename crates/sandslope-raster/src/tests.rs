//! Rasters written by GDAL itself (`tests/fixtures/gdal/make.py`, rasterio 1.4.4 / GDAL
//! 3.10.3), each holding a known formula of (col, row).
use std::fs::File;
use std::io::BufWriter;

use tiff::encoder::TiffEncoder;
use tiff::tags::Tag;

use super::*;

fn fixture(name: &str) -> Raster {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../sandslope-io/tests/fixtures/gdal").join(name);
    read_raster(&path).unwrap_or_else(|e| panic!("{name}: {e:#}"))
}

/// The planner's `f32` heights are the `f64` values rounded, NaN exactly where the raster
/// says nodata (the declared value, or not finite), with the same size, georeference and
/// cell size: for float32 (converted in place), int16, float64, LZW tiles read by
/// lzw_tiles.rs, an ASCII grid and a PDS3 DTM with special pixels.
#[test]
fn f32_heights_are_the_f64_values_rounded_with_nodata_as_nan() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../sandslope-io/tests/fixtures");
    let mut nodata_seen = 0;
    for name in [
        "gdal/f32-deflate-pred3-tiled.tif",
        "gdal/i16-lzw-pred2-strips.tif",
        "gdal/f64-point.tif",
        "gdal/geo-wgs84-lzw-pred2-i16-be.tif",
        "gdal/aaigrid.asc",
        "pds3/dtm-attached.img",
    ] {
        let path = dir.join(name);
        let raster = read_raster(&path).unwrap();
        let (meta, heights) = read_heights_within(&path, &|_, _| Ok(())).unwrap();
        assert!(meta.values.is_empty(), "{name}");
        assert_eq!(
            (meta.cols, meta.rows, meta.cell_m, meta.nodata),
            (raster.cols, raster.rows, raster.cell_m, raster.nodata)
        );
        assert_eq!((meta.geo.west, meta.geo.north), (raster.geo.west, raster.geo.north), "{name}");
        assert_eq!(heights.len(), raster.values.len(), "{name}");
        for (i, (&h, &v)) in heights.iter().zip(&raster.values).enumerate() {
            if raster.is_nodata(i) {
                assert!(h.is_nan(), "{name} cell {i}: {h} for nodata {v}");
                nodata_seen += 1;
            } else {
                assert_eq!(h.to_bits(), (v as f32).to_bits(), "{name} cell {i}");
            }
        }
    }
    assert!(nodata_seen > 0);
}

/// Tiled LZW with partial edge tiles, which the `tiff` crate fails on: read tile by tile,
/// the float32 file (floating-point predictor) equal to its Deflate twin bit for bit, the
/// big-endian int16 decimetres (horizontal predictor) equal to round(10 z).
#[test]
fn tiled_lzw_with_partial_edge_tiles_reads_like_its_deflate_twin() {
    let deflate = fixture("geo-wgs84.tif");
    let pred3 = fixture("geo-wgs84-lzw-pred3.tif");
    let be16 = fixture("geo-wgs84-lzw-pred2-i16-be.tif");
    assert_eq!((pred3.cols, pred3.rows, be16.cols, be16.rows), (60, 48, 60, 48));
    for i in 0..deflate.values.len() {
        let z = deflate.values[i];
        assert_eq!(pred3.values[i].to_bits(), z.to_bits(), "cell {i}");
        let want = if z == -32768.0 { -32768.0 } else { (z * 10.0).round() };
        assert_eq!(be16.values[i], want, "cell {i}");
    }
    assert!(deflate.values.iter().filter(|v| **v > 11.0).count() > 0, "the hill is there");
}

/// Coordinates as GDAL writes them (make_crs.py): EPSG:4326 in degrees, a user-defined Mars
/// sphere, a projected CRS in metres. Ground cell sizes by hand: on the Mars sphere one
/// thousandth of a degree is 3 396 190 * pi / 180 / 1000 = 59.2747 m north and that times
/// cos(4.524 deg) = 0.996885 east (the mid-latitude of rows -4.5 to -4.548).
#[test]
fn geographic_and_planetary_rasters_get_ground_cell_sizes_in_metres() {
    let mars = fixture("mars-sphere.tif");
    assert!(
        matches!(&mars.crs, Crs::Geographic { ellipsoid } if ellipsoid.name == "Mars" && ellipsoid.semi_major_m == 3_396_190.0),
        "{:?}",
        mars.crs
    );
    assert!((mars.cell_m.1 - 59.2747).abs() < 1e-3, "{:?}", mars.cell_m);
    assert!((mars.cell_m.0 - 59.2747 * 0.996_885).abs() < 2e-3, "{:?}", mars.cell_m);
    assert!(mars.notes.iter().any(|n| n.contains("on Mars (a = 3396190 m)")), "{:?}", mars.notes);
    let earth = fixture("geo-wgs84.tif");
    assert!(matches!(&earth.crs, Crs::Geographic { ellipsoid } if ellipsoid.name == "WGS84"));
    // One arc-second: about 30.8 m north and 23.7 m east at 40 N (cos 40 = 0.766).
    assert!(
        (earth.cell_m.1 - 30.84).abs() < 0.01 && (earth.cell_m.0 - 23.72).abs() < 0.01,
        "{:?}",
        earth.cell_m
    );
    let utm = fixture("proj-same-cells.tif");
    assert_eq!(utm.crs, Crs::Projected { metres_per_unit: 1.0, unit: "metre" });
    assert_eq!(utm.cell_m, (utm.geo.cell_x, utm.geo.cell_y));
    assert!(utm.notes.is_empty(), "{:?}", utm.notes);
}

/// make_crs.py's hill, as make_layouts.py wrote it in every layout: 60 x 48 float32 cells of
/// 1 arc-second from (10.0 E, 40.02 N), nodata -32768 at (0, 0); `z(col, row)` in f32.
fn hill(col: usize, row: usize) -> f64 {
    let (c, r) = (col as f64, row as f64);
    f64::from((12.0 * (-(((c - 30.0) / 14.0).powi(2) + ((r - 24.0) / 11.0).powi(2))).exp()) as f32)
}

fn check_hill(name: &str, decimetres: bool) {
    let r = fixture(name);
    assert_eq!((r.cols, r.rows), (60, 48), "{name}");
    assert_eq!((r.geo.west, r.geo.north), (10.0, 40.02), "{name}");
    assert!((r.geo.cell_x - 1.0 / 3600.0).abs() < 1e-15 && r.geo.cell_x == r.geo.cell_y, "{name}");
    assert!(r.is_nodata(0), "{name}: (0, 0) is nodata");
    for i in 1..r.values.len() {
        let z = hill(i % 60, i / 60);
        let want = if decimetres { (10.0 * z).round() } else { z };
        assert!(
            (r.values[i] - want).abs() <= 1e-6 * want.abs().max(1.0),
            "{name} cell {i}: {} vs {want}",
            r.values[i]
        );
    }
}

/// ZSTD (both predictors, tiles with partial edge tiles and strips with a partial last strip)
/// and BigTIFF (Deflate, and LZW with partial edge tiles), written by GDAL 3.10.3
/// (make_layouts.py, which checks GDAL reads back what it wrote).
#[test]
fn zstd_and_bigtiff_written_by_gdal_read_to_the_written_heights() {
    check_hill("zstd-pred3-tiled.tif", false);
    check_hill("zstd-pred2-i16-strips.tif", true);
    check_hill("bigtiff-deflate-tiled.tif", false);
    check_hill("bigtiff-lzw-pred3-tiled.tif", false);
}

/// A cloud-optimised GeoTIFF (GDAL's COG driver) and a GTiff with COPY_SRC_OVERVIEWS carry
/// overviews of 30 x 24 and 15 x 12 cells in the same file: the full-resolution image is read.
#[test]
fn a_cog_reads_its_full_resolution_image_not_an_overview() {
    check_hill("cog-overviews.tif", false);
    check_hill("gtiff-copy-src-overviews.tif", false);
}

/// A geotransform with rotation terms (GDAL writes ModelTransformationTag) and a raster
/// georeferenced by ground control points only (four tie points) are refused, naming the tag.
#[test]
fn rotated_and_gcp_georeferenced_rasters_are_refused_naming_the_tag() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../sandslope-io/tests/fixtures/gdal");
    let err = format!("{:#}", read_raster(&path.join("rotated.tif")).unwrap_err());
    assert!(err.contains("rotated.tif") && err.contains("ModelTransformationTag (34264)"), "{err}");
    // The rotation terms GDAL wrote: 0.2 and 0.1 arc-seconds.
    assert!(err.contains("0.0000555") && err.contains("0.0000277"), "{err}");
    let err = format!("{:#}", read_raster(&path.join("gcps.tif")).unwrap_err());
    assert!(err.contains("gcps.tif") && err.contains("ModelTiepointTag (33922) holds 4 tie points"), "{err}");
}

/// A file whose first directory is a 2 x 2 overview (NewSubfileType 1) and whose second is
/// the 4 x 3 image: the image is read, with its own georeferencing.
#[test]
fn an_overview_written_before_the_full_image_is_skipped() {
    use tiff::encoder::colortype::Gray32Float;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("overview-first.tif");
    {
        let mut enc = TiffEncoder::new(BufWriter::new(File::create(&path).unwrap())).unwrap();
        let mut small = enc.new_image::<Gray32Float>(2, 2).unwrap();
        small.encoder().write_tag(Tag::NewSubfileType, 1u32).unwrap();
        small.write_data(&[9.0f32; 4]).unwrap();
        let mut full = enc.new_image::<Gray32Float>(4, 3).unwrap();
        full.encoder().write_tag(Tag::ModelPixelScaleTag, &[2.0, 2.0, 0.0][..]).unwrap();
        full.encoder().write_tag(Tag::ModelTiepointTag, &[0.0, 0.0, 0.0, 100.0, 200.0, 0.0][..]).unwrap();
        let data: Vec<f32> = (0..12).map(|i| i as f32).collect();
        full.write_data(&data).unwrap();
    }
    let r = read_raster(&path).unwrap();
    assert_eq!((r.cols, r.rows, r.geo.west, r.geo.north, r.geo.cell_x), (4, 3, 100.0, 200.0, 2.0));
    assert_eq!(r.values, (0..12).map(f64::from).collect::<Vec<_>>());
}

/// 64-bit integers and three bands are refused naming the tags and their values.
#[test]
fn unsupported_samples_and_bands_are_refused_naming_the_tag() {
    use tiff::encoder::colortype::{Gray64, RGB8};
    let dir = tempfile::tempdir().unwrap();
    let georef =
        |d: &mut tiff::encoder::DirectoryEncoder<'_, BufWriter<File>, tiff::encoder::TiffKindStandard>| {
            d.write_tag(Tag::ModelPixelScaleTag, &[2.0, 2.0, 0.0][..]).unwrap();
            d.write_tag(Tag::ModelTiepointTag, &[0.0, 0.0, 0.0, 100.0, 200.0, 0.0][..]).unwrap();
        };
    let u64_path = dir.path().join("u64.tif");
    {
        let mut enc = TiffEncoder::new(BufWriter::new(File::create(&u64_path).unwrap())).unwrap();
        let mut img = enc.new_image::<Gray64>(2, 2).unwrap();
        georef(img.encoder());
        img.write_data(&[1u64, 2, 3, 4]).unwrap();
    }
    let err = format!("{:#}", read_raster(&u64_path).unwrap_err());
    assert!(
        err.contains(
            "u64.tif: unsupported sample type (BitsPerSample = 64, SampleFormat = 1: 64-bit integers)"
        ),
        "{err}"
    );
    let rgb_path = dir.path().join("rgb.tif");
    {
        let mut enc = TiffEncoder::new(BufWriter::new(File::create(&rgb_path).unwrap())).unwrap();
        let mut img = enc.new_image::<RGB8>(2, 2).unwrap();
        georef(img.encoder());
        img.write_data(&[0u8; 12]).unwrap();
    }
    let err = format!("{:#}", read_raster(&rgb_path).unwrap_err());
    assert!(err.contains("rgb.tif: has 3 bands (SamplesPerPixel = 3)"), "{err}");
}

/// The grid every fixture shares: 40 x 30 cells of 2 m, north-west corner (500000, 4100000).
fn check_grid(r: &Raster) {
    assert_eq!((r.cols, r.rows), (40, 30));
    assert_eq!((r.geo.west, r.geo.north, r.geo.cell_x, r.geo.cell_y), (500000.0, 4100000.0, 2.0, 2.0));
}

fn check_values(r: &Raster, nodata: &[(usize, usize)], z: impl Fn(f64, f64) -> f64) {
    for row in 0..r.rows {
        for col in 0..r.cols {
            let i = row * r.cols + col;
            if nodata.contains(&(col, row)) {
                assert!(r.is_nodata(i), "({col}, {row}) should be nodata");
            } else {
                assert!(!r.is_nodata(i));
                let want = z(col as f64, row as f64);
                assert!((r.values[i] - want).abs() <= 1e-5 * want.abs().max(1.0), "({col}, {row})");
            }
        }
    }
}

#[test]
fn reads_gdal_float32_deflate_with_floating_point_predictor_in_tiles() {
    let r = fixture("f32-deflate-pred3-tiled.tif");
    check_grid(&r);
    assert_eq!(r.nodata, Some(-9999.0));
    check_values(&r, &[(3, 4), (30, 20)], |c, w| 100.0 + 0.25 * c - 0.5 * w);
    // The CRS keys (EPSG:32633 in ProjectedCSTypeGeoKey 3072) are kept for the outputs.
    let keys = r.geo.geokeys.as_deref().unwrap();
    assert!(keys[4..].chunks_exact(4).any(|e| e[0] == 3072 && e[3] == 32633), "{keys:?}");
}

#[test]
fn reads_gdal_int16_lzw_with_horizontal_predictor_in_strips() {
    let r = fixture("i16-lzw-pred2-strips.tif");
    check_grid(&r);
    check_values(&r, &[(0, 0)], |c, w| 50.0 + 3.0 * c - 2.0 * w);
}

#[test]
fn reads_gdal_float64_pixel_is_point_onto_the_same_cells() {
    // Its tie point is the centre of cell (0, 0): half a cell inside the corner.
    let r = fixture("f64-point.tif");
    check_grid(&r);
    check_values(&r, &[], |c, w| 0.125 * c + 0.0625 * w);
}

#[test]
fn reads_gdal_ascii_grid() {
    let r = fixture("aaigrid.asc");
    check_grid(&r);
    check_values(&r, &[(3, 4), (30, 20)], |c, w| 100.0 + 0.25 * c - 0.5 * w);
}
