//! The two-band float32 GeoTIFF of [`super::write_two_band_geotiff`] written band of rows by
//! band of rows (issue 56), for rasters larger than memory: a tiled GeoTIFF of
//! [`TILE`] x [`TILE`] tiles, pixel-interleaved, each tile Deflate-compressed (zlib, TIFF
//! compression 8) as soon as its rows have arrived, so only one row of tiles and the tile
//! offsets are held. The `tiff` crate's encoder writes strips only, and its `write_strip`
//! leaves strips uncompressed under a Deflate tag (tiff 0.11.3): the tiles are compressed
//! here and written through its directory encoder with the baseline and tile tags. A raster
//! whose samples exceed 3 GiB is written as BigTIFF (classic TIFF's offsets stop at 4 GiB).
//! GDAL reads both; edge tiles are padded with NaN (nodata). The file goes through
//! [`sandslope_files::write_output`]: nothing is put in place unless every row was written.

use std::io::{BufWriter, Seek, Write};
use std::path::Path;

use anyhow::{anyhow, bail, Result};
use tiff::encoder::{TiffEncoder, TiffKind};
use tiff::tags::Tag;

use super::geotiff::write_geo_tags;
use super::grid::GeoRef;

/// The side of a tile, cells (GDAL's and COG's usual 256).
pub const TILE: usize = 256;

/// Samples above this many bytes are written as BigTIFF.
const BIG_TIFF_BYTES: u64 = 3 << 30;

/// Writes a `cols` x `rows` two-band float32 tiled GeoTIFF at `path`, georeferenced by `geo`,
/// whose rows `fill` gives in order from the north: `fill` is handed a function taking the
/// next rows of band 1 and band 2 (row-major, any whole number of rows, the same for both),
/// and every row must have been given when it returns. Band 1 and 2, the georeference and
/// nodata tags are those of [`super::write_two_band_geotiff`], and so are the samples.
pub fn write_two_band_geotiff_by_rows(
    path: &Path,
    cols: usize,
    rows: usize,
    geo: &GeoRef,
    fill: impl FnOnce(&mut dyn FnMut(&[f32], &[f32]) -> Result<()>) -> Result<()>,
) -> Result<()> {
    let name = path.display().to_string();
    if cols == 0 || rows == 0 {
        bail!("{name}: a {cols} x {rows} raster has no cells to write");
    }
    let big = cols as u64 * rows as u64 * 8 > BIG_TIFF_BYTES;
    sandslope_files::write_output(path, |file| {
        let err = |e: tiff::TiffError| anyhow!("{name}: {e}");
        let out = BufWriter::new(file);
        if big {
            encode(TiffEncoder::new_big(out).map_err(err)?, true, &name, cols, rows, geo, fill)
        } else {
            encode(TiffEncoder::new(out).map_err(err)?, false, &name, cols, rows, geo, fill)
        }
    })
}

/// The image written by `enc` (`big`: BigTIFF offsets), row of tiles by row of tiles as
/// `fill` gives rows.
fn encode<W: Write + Seek, K: TiffKind>(
    mut enc: TiffEncoder<W, K>,
    big: bool,
    name: &str,
    cols: usize,
    rows: usize,
    geo: &GeoRef,
    fill: impl FnOnce(&mut dyn FnMut(&[f32], &[f32]) -> Result<()>) -> Result<()>,
) -> Result<()> {
    let err = |e: tiff::TiffError| anyhow!("{name}: {e}");
    let (w, h) = (u32::try_from(cols)?, u32::try_from(rows)?);
    let across = cols.div_ceil(TILE);
    let mut dir = enc.image_directory().map_err(err)?;
    // A row of tiles' rows, interleaved (band 1, band 2 per cell).
    let mut band: Vec<f32> = Vec::with_capacity(2 * cols * TILE.min(rows));
    let (mut offsets, mut counts) = (Vec::<u64>::new(), Vec::<u64>::new());
    let mut given = 0usize;
    let mut tile = vec![0_u8; TILE * TILE * 8];
    let mut flush =
        |band: &mut Vec<f32>, dir: &mut tiff::encoder::DirectoryEncoder<'_, W, K>| -> Result<()> {
            let n = band.len() / (2 * cols);
            for a in 0..across {
                let (c0, c1) = (a * TILE, ((a + 1) * TILE).min(cols));
                tile.fill(0);
                for (k, px) in tile.chunks_exact_mut(8).enumerate() {
                    let (r, c) = (k / TILE, c0 + k % TILE);
                    let (x, y) = if r < n && c < c1 {
                        (band[2 * (r * cols + c)], band[2 * (r * cols + c) + 1])
                    } else {
                        (f32::NAN, f32::NAN)
                    };
                    px[..4].copy_from_slice(&x.to_ne_bytes());
                    px[4..].copy_from_slice(&y.to_ne_bytes());
                }
                let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
                z.write_all(&tile)?;
                let bytes = z.finish()?;
                offsets.push(dir.write_data(&bytes[..]).map_err(err)?);
                counts.push(bytes.len() as u64);
            }
            band.clear();
            Ok(())
        };
    let mut push = |a: &[f32], b: &[f32]| -> Result<()> {
        if a.len() != b.len() || a.len() % cols != 0 {
            bail!("{name}: {} and {} samples are not whole rows of {cols} for both bands", a.len(), b.len());
        }
        if given + a.len() / cols > rows {
            bail!("{name}: {} rows given for a raster of {rows}", given + a.len() / cols);
        }
        for (ra, rb) in a.chunks_exact(cols).zip(b.chunks_exact(cols)) {
            band.extend(ra.iter().zip(rb).flat_map(|(&x, &y)| [x, y]));
            given += 1;
            if given % TILE == 0 || given == rows {
                flush(&mut band, &mut dir)?;
            }
        }
        Ok(())
    };
    fill(&mut push)?;
    if given != rows {
        bail!("{name}: {given} of {rows} rows were written");
    }
    dir.write_tag(Tag::ImageWidth, w).map_err(err)?;
    dir.write_tag(Tag::ImageLength, h).map_err(err)?;
    dir.write_tag(Tag::BitsPerSample, &[32_u16, 32][..]).map_err(err)?;
    // Adobe Deflate (zlib).
    dir.write_tag(Tag::Compression, 8_u16).map_err(err)?;
    // BlackIsZero: one grey sample and an extra one.
    dir.write_tag(Tag::PhotometricInterpretation, 1_u16).map_err(err)?;
    dir.write_tag(Tag::SamplesPerPixel, 2_u16).map_err(err)?;
    dir.write_tag(Tag::PlanarConfiguration, 1_u16).map_err(err)?;
    dir.write_tag(Tag::TileWidth, TILE as u32).map_err(err)?;
    dir.write_tag(Tag::TileLength, TILE as u32).map_err(err)?;
    if big {
        dir.write_tag(Tag::TileOffsets, &offsets[..]).map_err(err)?;
        dir.write_tag(Tag::TileByteCounts, &counts[..]).map_err(err)?;
    } else {
        let small = |v: &[u64]| v.iter().map(|&x| u32::try_from(x)).collect::<Result<Vec<u32>, _>>();
        dir.write_tag(Tag::TileOffsets, &small(&offsets)?[..]).map_err(err)?;
        dir.write_tag(Tag::TileByteCounts, &small(&counts)?[..]).map_err(err)?;
    }
    // Unspecified extra sample; IEEE floating point.
    dir.write_tag(Tag::ExtraSamples, &[0_u16][..]).map_err(err)?;
    dir.write_tag(Tag::SampleFormat, &[3_u16, 3][..]).map_err(err)?;
    write_geo_tags(&mut dir, geo).map_err(err)?;
    dir.finish().map_err(err)
}

#[cfg(test)]
mod tiles_tests;
