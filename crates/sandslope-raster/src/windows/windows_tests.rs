//! Windows of every layout read equal the whole read's heights, bit for bit.

use std::path::{Path, PathBuf};

use super::*;

fn fixture(dir: &str, name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../sandslope-io/tests/fixtures").join(dir).join(name)
}

#[test]
fn every_window_of_every_layout_is_the_whole_read_s_heights() {
    let files = [
        ("gdal", "f32-deflate-pred3-tiled.tif", Some(true)),
        ("gdal", "i16-lzw-pred2-strips.tif", Some(true)),
        ("gdal", "zstd-pred3-tiled.tif", Some(true)),
        ("gdal", "zstd-pred2-i16-strips.tif", Some(true)),
        ("gdal", "bigtiff-deflate-tiled.tif", Some(true)),
        ("gdal", "cog-overviews.tif", Some(true)),
        ("gdal", "f64-point.tif", Some(true)),
        ("gdal", "geo-wgs84.tif", Some(true)),
        // Tiled LZW with partial edge tiles, which `read_image` cannot decode: chunk by chunk it can.
        ("gdal", "bigtiff-lzw-pred3-tiled.tif", Some(true)),
        ("gdal", "aaigrid.asc", Some(false)),
        ("pds3", "dtm-attached.img", None),
        ("pds3", "dtm-detached.lbl", None),
        ("pds3", "moon-bytes.img", None),
    ];
    for (dir, name, tiff_chunks) in files {
        let path = fixture(dir, name);
        let (whole, heights) = crate::read_heights_within(&path, &|_, _| Ok(())).unwrap();
        let (raster, w) =
            open_height_windows(&path, &|_, _, _| Ok(())).unwrap_or_else(|e| panic!("{name}: {e:#}"));
        assert_eq!(
            (raster.cols, raster.rows, &raster.geo, &raster.row_widths_m),
            (whole.cols, whole.rows, &whole.geo, &whole.row_widths_m),
            "{name}"
        );
        match tiff_chunks {
            Some(true) => assert!(matches!(w.kind, Kind::Tiff(_)), "{name} is read chunk by chunk"),
            Some(false) => assert!(w.is_in_memory(), "{name} is read whole"),
            None => assert!(matches!(w.kind, Kind::Pds3(_)), "{name} is read line by line"),
        }
        let (c, r) = (whole.cols, whole.rows);
        for (rows, cols) in [
            (0..r, 0..c),
            (0..1, 0..1),
            (r - 1..r, c - 1..c),
            (1..r / 2, c / 3..c),
            (r / 3..r, 0..c / 2 + 1),
            (3..3, 0..c),
            (5..r - 2, 7..c - 3),
        ] {
            let got = w.read(rows.clone(), cols.clone()).unwrap();
            assert_eq!(got.len(), rows.len() * cols.len());
            for (k, g) in got.iter().enumerate() {
                let (i, j) = (rows.start + k / cols.len(), cols.start + k % cols.len());
                let want = heights[i * c + j];
                assert!(
                    g.to_bits() == want.to_bits() || (g.is_nan() && want.is_nan()),
                    "{name} ({i}, {j}): {g} vs {want}"
                );
            }
        }
        assert!(w.read(0..r + 1, 0..c).is_err());
    }
}

/// A tile whose bytes would lie past the end of the file (a truncated download) is refused
/// when the file is opened, naming the file, the tile and its offset: nothing is planned on
/// a map with a hole in it.
#[test]
fn a_tile_past_the_end_of_the_file_is_refused_naming_it_and_its_offset() {
    let src = std::fs::read(fixture("gdal", "f32-deflate-pred3-tiled.tif")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let (raster, w) =
        open_height_windows(&fixture("gdal", "f32-deflate-pred3-tiled.tif"), &|_, _, _| Ok(())).unwrap();
    let Kind::Tiff(t) = &w.kind else { panic!("tiled") };
    let chunks = t.across * raster.rows.div_ceil(t.ch);
    // The last tile's data is the last thing GDAL writes before any overview: cut the file
    // just after the directory and the first tiles, so the later tiles lie past its end.
    let mut dec = open_full_resolution(&fixture("gdal", "f32-deflate-pred3-tiled.tif")).unwrap();
    let offsets: Vec<u64> = dec.find_tag_unsigned_vec(Tag::TileOffsets).unwrap().unwrap();
    let cut = (offsets[..chunks].iter().max().unwrap() + 1) as usize;
    let path = dir.path().join("cut.tif");
    std::fs::write(&path, &src[..cut.min(src.len())]).unwrap();
    let e = open_height_windows(&path, &|_, _, _| Ok(())).err().map(|e| format!("{e:#}")).unwrap_or_default();
    assert!(e.contains("cut.tif") && e.contains("past the end of the") && e.contains("at byte"), "{e}");
}
