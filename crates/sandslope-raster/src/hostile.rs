//! Files that lie about their size: each is refused by the size it claims, before the
//! claimed amount is allocated (without the limits each of these aborts the process).
use super::*;

/// A little-endian classic TIFF of one IFD whose entries are (tag, type, count, value).
fn tiff_with(entries: &[(u16, u16, u32, u32)]) -> Vec<u8> {
    let mut b = b"II*\0".to_vec();
    b.extend_from_slice(&8u32.to_le_bytes());
    b.extend_from_slice(&(entries.len() as u16).to_le_bytes());
    for &(tag, ty, count, value) in entries {
        b.extend_from_slice(&tag.to_le_bytes());
        b.extend_from_slice(&ty.to_le_bytes());
        b.extend_from_slice(&count.to_le_bytes());
        b.extend_from_slice(&value.to_le_bytes());
    }
    b.extend_from_slice(&0u32.to_le_bytes());
    b.resize(1024, 0);
    b
}

fn read_bytes(name: &str, bytes: &[u8]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    let started = std::time::Instant::now();
    let err = read_raster(&path).expect_err("a lying file must be refused");
    // Refused from the header: no time is spent (or memory allocated) on the claimed size.
    assert!(started.elapsed().as_secs() < 5);
    format!("{err:#}")
}

const SHORT: u16 = 3;
const LONG: u16 = 4;
const DOUBLE: u16 = 12;

#[test]
fn a_1kb_tiff_claiming_3_6e9_cells_is_refused_by_its_dimensions() {
    let bytes = tiff_with(&[
        (256, LONG, 1, 60_000), // ImageWidth
        (257, LONG, 1, 60_000), // ImageLength
        (258, SHORT, 1, 32),    // BitsPerSample
        (259, SHORT, 1, 1),     // Compression: none
        (262, SHORT, 1, 1),     // Photometric
        (273, LONG, 1, 200),    // StripOffsets
        (278, LONG, 1, 60_000), // RowsPerStrip
        (279, LONG, 1, 800),    // StripByteCounts
        (339, SHORT, 1, 3),     // SampleFormat: float
    ]);
    let err = read_bytes("claims.tif", &bytes);
    assert!(err.contains("claims.tif") && err.contains("3600000000 cells") && err.contains("limit"), "{err}");
}

/// The entries of an uncompressed 10 x 10 float32 image, and `extra`.
fn small_float_image_with(extra: (u16, u16, u32, u32)) -> Vec<(u16, u16, u32, u32)> {
    vec![
        (256, LONG, 1, 10),
        (257, LONG, 1, 10),
        (258, SHORT, 1, 32),
        (259, SHORT, 1, 1),
        (262, SHORT, 1, 1),
        (273, LONG, 1, 200),
        (278, LONG, 1, 10),
        (279, LONG, 1, 400),
        (339, SHORT, 1, 3),
        extra,
    ]
}

/// An ASCII tag (GDAL_NODATA) claiming 4 GiB in a 1 KB file: the decoder's limit does not
/// cover ASCII values, so the directory is checked first (found by scripts/fuzz.sh).
#[test]
fn an_ascii_tag_claiming_gigabytes_is_refused_before_the_decoder_reads_it() {
    let bytes = tiff_with(&small_float_image_with((42113, 2, 0xFFFF_0000, 300))); // GDAL_NODATA, ASCII
    let err = read_bytes("nodata.tif", &bytes);
    assert!(err.contains("nodata.tif: tag GdalNodata (42113) claims 4294901760 bytes"), "{err}");
    let bytes = tiff_with(&[(256, LONG, 1, 10), (34737, 2, 5000, 300)]);
    let err = read_bytes("past.tif", &bytes);
    assert!(err.contains("past.tif: tag GeoAsciiParamsTag (34737) claims 5000 bytes at byte 300, past the end of the 1024-byte file"), "{err}");
}

/// The same lie in a second directory (where a COG keeps its overviews) is refused too.
#[test]
fn a_lying_tag_in_a_later_image_directory_is_refused() {
    let entries = small_float_image_with((254, LONG, 1, 0)); // NewSubfileType 0
    let mut bytes = tiff_with(&entries);
    let next = 8 + 2 + 12 * entries.len();
    bytes[next..next + 4].copy_from_slice(&600u32.to_le_bytes());
    let mut ifd1 = 1u16.to_le_bytes().to_vec();
    for v in [42113u16.to_le_bytes().to_vec(), 2u16.to_le_bytes().to_vec()] {
        ifd1.extend(v);
    }
    ifd1.extend(0xFFFF_0000u32.to_le_bytes());
    ifd1.extend(300u32.to_le_bytes());
    ifd1.extend(0u32.to_le_bytes());
    bytes[600..600 + ifd1.len()].copy_from_slice(&ifd1);
    let err = read_bytes("second.tif", &bytes);
    assert!(err.contains("second.tif: tag GdalNodata (42113) claims 4294901760 bytes"), "{err}");
}

/// Within the cell limit (2^28 cells) but 1 GiB of samples from a 1 KB file: no
/// compression expands that far, so it is refused before the decoder allocates (found by
/// scripts/fuzz.sh: a 700-byte file made the decoder ask for 4 GiB and abort).
#[test]
fn a_1kb_tiff_claiming_a_gigabyte_of_samples_is_refused_by_the_file_size() {
    let bytes = tiff_with(&[
        (256, LONG, 1, 16_384),
        (257, LONG, 1, 16_384),
        (258, SHORT, 1, 32),
        (259, SHORT, 1, 5), // LZW
        (262, SHORT, 1, 1),
        (273, LONG, 1, 200),
        (278, LONG, 1, 16_384),
        (279, LONG, 1, 800),
        (339, SHORT, 1, 3),
    ]);
    let err = read_bytes("small.tif", &bytes);
    assert!(
        err.contains("small.tif") && err.contains("1073741824 bytes") && err.contains("1024-byte file"),
        "{err}"
    );
}

#[test]
fn a_tag_whose_count_claims_gigabytes_is_refused() {
    // ModelPixelScale: 2^28 doubles = 2 GiB.
    let bytes = tiff_with(&small_float_image_with((33550, DOUBLE, 0x1000_0000, 300)));
    let err = read_bytes("tag.tif", &bytes);
    assert!(err.contains("tag.tif") && err.contains("ModelPixelScale") && err.contains("limit"), "{err}");
}

#[test]
fn an_ascii_grid_claiming_more_cells_than_its_bytes_is_refused() {
    let text = "ncols 60000\nnrows 60000\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n";
    let err = read_bytes("big.asc", text.as_bytes());
    assert!(err.contains("big.asc") && err.contains("limit"), "{err}");
    let text = "ncols 20000\nnrows 20000\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n";
    let err = read_bytes("lies.asc", text.as_bytes());
    assert!(err.contains("lies.asc") && err.contains("400000000 values") && err.contains("bytes"), "{err}");
}

/// The memory limit set by `--max-memory` refuses a raster whose read needs more, before its
/// samples are read, naming what it needs: GDAL's 40 x 30 float32 deflate fixture read as
/// `f64` values holds 4 + 8 bytes a cell, 1200 x 12 = 14 400 bytes; as `f32` heights
/// (converted in place) 4 bytes a cell, 4800 bytes.
#[test]
fn the_memory_limit_refuses_a_raster_that_needs_more_naming_the_bytes() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../sandslope-io/tests/fixtures/gdal/f32-deflate-pred3-tiled.tif");
    let probe = crate::read_raster(&path).unwrap();
    assert_eq!((probe.cols, probe.rows), (40, 30));
    crate::set_memory_limit(Some(14_399));
    let err = format!("{:#}", crate::read_raster(&path).unwrap_err());
    assert!(
        err.contains("40 x 30 = 1200 cells need 0.000 GiB to read (12 bytes a cell)")
            && err.contains("--max-memory limit"),
        "{err}"
    );
    crate::set_memory_limit(Some(14_400));
    assert!(crate::read_raster(&path).is_ok());
    crate::set_memory_limit(Some(4_799));
    let err = format!("{:#}", crate::read_heights_within(&path, &|_, _| Ok(())).unwrap_err());
    assert!(err.contains("(4 bytes a cell)"), "{err}");
    crate::set_memory_limit(Some(4_800));
    assert!(crate::read_heights_within(&path, &|_, _| Ok(())).is_ok());
    crate::set_memory_limit(None);
}
