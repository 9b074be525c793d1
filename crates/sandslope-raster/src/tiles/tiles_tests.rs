//! The tiled writer against the whole-raster writer: the same samples and georeference
//! whatever bands of rows they come in, and nothing left behind when rows are missing.

use std::fs::File;
use std::path::Path;

use tiff::decoder::{Decoder, DecodingResult};
use tiff::tags::Tag;

use super::*;
use crate::{read_raster, write_two_band_geotiff};

/// The interleaved samples of a written two-band file, decoded by the `tiff` crate.
fn samples(path: &Path) -> Vec<u32> {
    let mut dec = Decoder::new(File::open(path).unwrap()).unwrap();
    match dec.read_image().unwrap() {
        DecodingResult::F32(v) => v.into_iter().map(f32::to_bits).collect(),
        _ => panic!("not float32"),
    }
}

/// The georeference and nodata tags of a written file, as the decoder reads them.
fn geo_tags(path: &Path) -> Vec<String> {
    let mut dec = Decoder::new(File::open(path).unwrap()).unwrap();
    [Tag::ModelPixelScaleTag, Tag::ModelTiepointTag, Tag::GeoKeyDirectoryTag, Tag::GdalNodata]
        .into_iter()
        .map(|t| format!("{:?}", dec.find_tag(t).unwrap().unwrap()))
        .collect()
}

#[test]
fn rows_written_band_by_band_are_the_whole_raster_s_samples() {
    let fixture =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../sandslope-io/tests/fixtures/gdal/geo-wgs84.tif");
    let geo = read_raster(&fixture).unwrap().geo;
    let dir = tempfile::tempdir().unwrap();
    // 300 x 530: two tiles across and three down, the last of each partial.
    let (cols, rows) = (300, 530);
    let a: Vec<f32> =
        (0..cols * rows).map(|i| if i % 17 == 3 { f32::NAN } else { i as f32 * 0.001 }).collect();
    let b: Vec<f32> = (0..cols * rows).map(|i| (i % 360) as f32).collect();
    let whole = dir.path().join("whole.tif");
    write_two_band_geotiff(&whole, cols, rows, &geo, &a, &b).unwrap();
    let want = samples(&whole);
    assert_eq!(want.len(), 2 * cols * rows);
    for band in [1, 7, 256, 300, 530] {
        let path = dir.path().join(format!("by-{band}.tif"));
        write_two_band_geotiff_by_rows(&path, cols, rows, &geo, |push| {
            for r0 in (0..rows).step_by(band) {
                let r1 = (r0 + band).min(rows);
                push(&a[r0 * cols..r1 * cols], &b[r0 * cols..r1 * cols])?;
            }
            Ok(())
        })
        .unwrap();
        assert_eq!(samples(&path), want, "bands of {band} rows");
        assert_eq!(geo_tags(&path), geo_tags(&whole));
        // Tiles of 256 x 256: 2 across, 3 down.
        let mut dec = Decoder::new(File::open(&path).unwrap()).unwrap();
        assert_eq!(dec.get_chunk_type(), tiff::decoder::ChunkType::Tile);
        assert_eq!(dec.chunk_dimensions(), (256, 256));
        assert_eq!(dec.tile_count().unwrap(), 6);
    }
}

#[test]
fn missing_rows_or_a_failing_producer_leave_no_file() {
    let fixture =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../sandslope-io/tests/fixtures/gdal/geo-wgs84.tif");
    let geo = read_raster(&fixture).unwrap().geo;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("risk.tif");
    let row = vec![0.5_f32; 10];
    let err = write_two_band_geotiff_by_rows(&path, 10, 40, &geo, |push| {
        for _ in 0..20 {
            push(&row, &row)?;
        }
        Ok(())
    })
    .unwrap_err();
    assert!(format!("{err:#}").contains("20 of 40 rows were written"), "{err:#}");
    let err = write_two_band_geotiff_by_rows(&path, 10, 40, &geo, |push| {
        push(&row, &row)?;
        anyhow::bail!("tile 7 at byte 123456 is past the end of dem.tif")
    })
    .unwrap_err();
    assert!(format!("{err:#}").contains("byte 123456"), "{err:#}");
    let err = write_two_band_geotiff_by_rows(&path, 10, 40, &geo, |push| push(&row, &row[..5])).unwrap_err();
    assert!(format!("{err:#}").contains("not whole rows"), "{err:#}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "something was left behind");
}
