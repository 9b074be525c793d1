//! A GeoTIFF's image decoded on every core: each band of chunk rows (a row of tiles, or a
//! strip) is read by its own decoder into its rows of the image.
//!
//! The `tiff` crate decodes an image chunk by chunk on one thread. A DEM is hundreds of
//! deflate, LZW or ZSTD chunks that decode independently: on the 4096 x 4096 deflate dune
//! field of bench/plan, decoding took 0.24 s of the 0.52 s of CPU before `plan`'s searches.
//! Each chunk goes through the crate's own `read_chunk` (decompression, predictor, byte
//! order) and only its data rows are copied, so the image is the one `read_image` gives, byte
//! for byte; anything unusual (sub-byte samples, a chunk of an unexpected size, an error of
//! any kind) makes [`read_image_in_parallel`] give up, and the caller decodes serially as
//! before, with the crate's errors and fallbacks.

use std::io::{Read, Seek};

use rayon::prelude::*;
use tiff::decoder::{ChunkType, Decoder, DecodingResult};

/// Images smaller than this many cells decode serially: their decoding takes milliseconds.
pub(super) const MIN_PARALLEL_CELLS: u64 = 1 << 20;

/// The image of `dec` (at its full-resolution directory, `bits` bits a sample, a decoding
/// buffer of at most `max_bytes`) decoded in parallel, each band of chunk rows by a decoder
/// that `open` makes for the same image; `None` when the image has fewer than `min_cells`
/// cells ([`MIN_PARALLEL_CELLS`] to gain anything), has
/// sub-byte samples or a single band of chunks, or anything fails (the caller then decodes
/// serially).
pub(super) fn read_image_in_parallel<R, S>(
    dec: &mut Decoder<R>,
    bits: u64,
    max_bytes: usize,
    min_cells: u64,
    open: impl Fn() -> Option<Decoder<S>> + Sync + Send,
) -> Option<DecodingResult>
where
    R: Read + Seek,
    S: Read + Seek,
{
    if !matches!(bits, 8 | 16 | 32 | 64) || rayon::current_num_threads() < 2 {
        return None;
    }
    let sample = (bits / 8) as usize;
    let (w, h) = dec.dimensions().ok()?;
    let (w, h) = (w as usize, h as usize);
    if (w as u64) * (h as u64) < min_cells || w.checked_mul(h)?.checked_mul(sample)? > max_bytes {
        return None;
    }
    let tiled = dec.get_chunk_type() == ChunkType::Tile;
    // Chunk width and height: a tile's, or a strip's (the image's width by its rows).
    let (cw, ch) = match dec.get_chunk_type() {
        ChunkType::Tile => {
            let width = dec.find_tag_unsigned::<u32>(tiff::tags::Tag::TileWidth).ok()??;
            let length = dec.find_tag_unsigned::<u32>(tiff::tags::Tag::TileLength).ok()??;
            (width as usize, length as usize)
        }
        ChunkType::Strip => {
            let rows = dec.find_tag_unsigned::<u32>(tiff::tags::Tag::RowsPerStrip).ok().flatten();
            (w, rows.map_or(h, |r| (r as usize).min(h)))
        }
    };
    if cw == 0 || ch == 0 || ch >= h {
        return None;
    }
    let across = if tiled { w.div_ceil(cw) } else { 1 };
    // The first chunk says which kind of samples the image holds.
    let mut image = empty_like(&dec.read_chunk(0).ok()?, w * h)?;
    let bytes_ok = {
        let mut out = image.as_buffer(0);
        let bytes = out.as_bytes_mut();
        bytes.len() == w * h * sample
            && decode_bands(bytes, Geometry { w, cw, ch, across, tiled, sample }, open).is_ok()
    };
    bytes_ok.then_some(image)
}

/// The image's and its chunks' sizes: width `w`, chunk `cw` x `ch`, `across` chunks a band,
/// whether they are tiles, and bytes a sample.
#[derive(Clone, Copy)]
struct Geometry {
    w: usize,
    cw: usize,
    ch: usize,
    across: usize,
    tiled: bool,
    sample: usize,
}

/// Decodes every band of chunk rows into its rows of `bytes` (the image, row-major), the bands
/// in parallel, each worker with a decoder from `open`; `Err` on the first failure.
fn decode_bands<S: Read + Seek>(
    bytes: &mut [u8],
    g: Geometry,
    open: impl Fn() -> Option<Decoder<S>> + Sync + Send,
) -> Result<(), ()> {
    let Geometry { w, cw, ch, across, tiled, sample } = g;
    bytes.par_chunks_mut(ch * w * sample).enumerate().try_for_each_init(open, |dec, (band, rows)| {
        let dec = dec.as_mut().ok_or(())?;
        let dh = rows.len() / (w * sample);
        for a in 0..across {
            let index = u32::try_from(band * across + a).map_err(|_| ())?;
            let dw = if tiled { cw.min(w - a * cw) } else { w };
            let mut chunk = dec.read_chunk(index).map_err(|_| ())?;
            let chunk = chunk.as_buffer(0);
            let data = chunk.as_bytes();
            if data.len() != dw * dh * sample {
                return Err(());
            }
            let (row_bytes, x0) = (dw * sample, a * cw * sample);
            for (r, src) in data.chunks_exact(row_bytes).enumerate() {
                let start = r * w * sample + x0;
                rows[start..start + row_bytes].copy_from_slice(src);
            }
        }
        Ok(())
    })
}

/// A zeroed image of `n` samples of the same kind as `chunk`'s (`None` for 16-bit floats and
/// other kinds sandslope does not read: the serial decoder names them).
fn empty_like(chunk: &DecodingResult, n: usize) -> Option<DecodingResult> {
    Some(match chunk {
        DecodingResult::U8(_) => DecodingResult::U8(vec![0; n]),
        DecodingResult::I8(_) => DecodingResult::I8(vec![0; n]),
        DecodingResult::U16(_) => DecodingResult::U16(vec![0; n]),
        DecodingResult::I16(_) => DecodingResult::I16(vec![0; n]),
        DecodingResult::U32(_) => DecodingResult::U32(vec![0; n]),
        DecodingResult::I32(_) => DecodingResult::I32(vec![0; n]),
        DecodingResult::F32(_) => DecodingResult::F32(vec![0.0; n]),
        DecodingResult::F64(_) => DecodingResult::F64(vec![0.0; n]),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn every_gdal_layout_decodes_in_parallel_to_the_crate_s_serial_image() {
        // Every GeoTIFF fixture GDAL wrote (tiles and strips; deflate, LZW, ZSTD; predictors
        // 2 and 3; big-endian; BigTIFF; a COG with overviews), decoded in parallel with no
        // size threshold, against the crate's own `read_image`: the same samples, byte for
        // byte, or a refusal (then `plan` decodes serially as before).
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../sandslope-io/tests/fixtures/gdal");
        let mut parallel = Vec::new();
        let mut names: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
        names.sort();
        for path in names.iter().filter(|p| p.extension().is_some_and(|e| e == "tif")) {
            let Ok(mut dec) = crate::geotiff::open_full_resolution(path) else { continue };
            let bits: u64 =
                dec.find_tag_unsigned(tiff::tags::Tag::BitsPerSample).ok().flatten().unwrap_or(64);
            let open = || crate::geotiff::open_full_resolution(path).ok();
            let Some(mut image) = read_image_in_parallel(&mut dec, bits, usize::MAX, 0, open) else {
                continue;
            };
            let mut serial = crate::geotiff::open_full_resolution(path).unwrap().read_image().unwrap();
            assert_eq!(image.as_buffer(0).as_bytes(), serial.as_buffer(0).as_bytes(), "{}", path.display());
            parallel.push(path.file_name().unwrap().to_string_lossy().into_owned());
        }
        for name in [
            "f32-deflate-pred3-tiled.tif",
            "i16-lzw-pred2-strips.tif",
            "zstd-pred3-tiled.tif",
            "zstd-pred2-i16-strips.tif",
            "bigtiff-deflate-tiled.tif",
            "cog-overviews.tif",
        ] {
            assert!(parallel.iter().any(|p| p == name), "{name} was not decoded in parallel: {parallel:?}");
        }
    }
}
