//! The two-band float32 GeoTIFF of [`super::write_two_band_geotiff`] written band of rows by
//! band of rows (issue 56), for rasters larger than memory: the `tiff` crate's encoder writes
//! strips only (it has no tile writer), so the file is a striped GeoTIFF of [`STRIP_ROWS`]
//! rows a strip, Deflate-compressed, pixel-interleaved, each strip written as soon as its rows
//! arrive; only a strip's rows and the strip offsets are held. A raster whose samples exceed
//! 3 GiB is written as BigTIFF (classic TIFF's offsets stop at 4 GiB). GDAL reads both. The
//! file goes through [`crate::files::write_output`]: nothing is put in place unless every
//! row was written.

use std::io::{BufWriter, Seek, Write};
use std::path::Path;

use anyhow::{anyhow, bail, Result};
use tiff::encoder::{colortype::Gray32Float, compression::DeflateLevel, Compression, TiffEncoder, TiffKind};
use tiff::tags::ExtraSamples;

use super::geotiff::write_geo_tags;
use super::grid::GeoRef;

/// Rows a strip holds (GDAL reads a window through the strips it crosses).
pub const STRIP_ROWS: usize = 16;

/// Samples above this many bytes are written as BigTIFF.
const BIG_TIFF_BYTES: u64 = 3 << 30;

/// Writes a `cols` x `rows` two-band float32 GeoTIFF at `path`, georeferenced by `geo`, whose
/// rows `fill` gives in order from the north: `fill` is handed a function taking the next rows
/// of band 1 and band 2 (row-major, any whole number of rows, the same for both), and every
/// row must have been given when it returns. Band 1 and 2 and the tags are those of
/// [`super::write_two_band_geotiff`]; the samples are the same.
pub fn write_two_band_geotiff_by_rows(
    path: &Path,
    cols: usize,
    rows: usize,
    geo: &GeoRef,
    fill: impl FnOnce(&mut dyn FnMut(&[f32], &[f32]) -> Result<()>) -> Result<()>,
) -> Result<()> {
    let name = path.display().to_string();
    let big = cols as u64 * rows as u64 * 8 > BIG_TIFF_BYTES;
    crate::files::write_output(path, |file| {
        let err = |e: tiff::TiffError| anyhow!("{name}: {e}");
        let out = BufWriter::new(file);
        let level = Compression::Deflate(DeflateLevel::default());
        if big {
            encode(TiffEncoder::new_big(out).map_err(err)?.with_compression(level), &name, cols, rows, geo, fill)
        } else {
            encode(TiffEncoder::new(out).map_err(err)?.with_compression(level), &name, cols, rows, geo, fill)
        }
    })
}

/// The image written by `enc`, strip by strip as `fill` gives rows.
fn encode<W: Write + Seek, K: TiffKind>(
    mut enc: TiffEncoder<W, K>,
    name: &str,
    cols: usize,
    rows: usize,
    geo: &GeoRef,
    fill: impl FnOnce(&mut dyn FnMut(&[f32], &[f32]) -> Result<()>) -> Result<()>,
) -> Result<()> {
    let err = |e: tiff::TiffError| anyhow!("{name}: {e}");
    let (w, h) = (u32::try_from(cols)?, u32::try_from(rows)?);
    let mut img = enc.new_image::<Gray32Float>(w, h).map_err(err)?;
    img.extra_samples(&[ExtraSamples::Unspecified]).map_err(err)?;
    img.rows_per_strip(STRIP_ROWS as u32).map_err(err)?;
    write_geo_tags(img.encoder(), geo).map_err(err)?;
    let mut strip: Vec<f32> = Vec::with_capacity(2 * cols * STRIP_ROWS.min(rows));
    let mut given = 0usize;
    let mut push = |a: &[f32], b: &[f32]| -> Result<()> {
        if a.len() != b.len() || cols == 0 || a.len() % cols != 0 {
            bail!("{name}: {} and {} samples are not whole rows of {cols} for both bands", a.len(), b.len());
        }
        given += a.len() / cols;
        if given > rows {
            bail!("{name}: {given} rows given for a raster of {rows}");
        }
        for (ra, rb) in a.chunks_exact(cols).zip(b.chunks_exact(cols)) {
            strip.extend(ra.iter().zip(rb).flat_map(|(&x, &y)| [x, y]));
            if strip.len() as u64 == img.next_strip_sample_count() {
                img.write_strip(&strip).map_err(err)?;
                strip.clear();
            }
        }
        Ok(())
    };
    fill(&mut push)?;
    if given != rows {
        bail!("{name}: {given} of {rows} rows were written");
    }
    img.finish().map_err(err)
}

#[cfg(test)]
mod strips_tests;
