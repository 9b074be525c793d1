//! Tiled LZW GeoTIFFs whose edge tiles are partial, decoded tile by tile.
//!
//! The `tiff` crate (0.11.3, the newest) fails on them with "no lzw end code found"
//! (image-rs/image-tiff#395, open): it decodes an edge tile into a buffer of the tile's data
//! size, while the LZW stream holds the whole padded tile, as TIFF 6.0 requires and GDAL writes.
//! Most DEMs written with `gdal_translate -co TILED=YES -co COMPRESS=LZW` have such tiles (their
//! width is rarely a multiple of the tile size), so this reads them: each tile's bytes are
//! decompressed whole by `weezl` (the crate's own LZW decoder), the predictor undone (none,
//! horizontal differencing, or the floating-point predictor), and the tile's data part copied
//! into the image. Used only when the crate's own decoding of such a file fails.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom};

use anyhow::{anyhow, bail, Result};

/// What the tiles hold: the image and tile sizes, the samples and their layout.
pub struct TileLayout {
    /// Image width and height, pixels.
    pub width: usize,
    /// Image height, pixels.
    pub height: usize,
    /// Tile width and height, pixels.
    pub tile_width: usize,
    /// Tile height, pixels.
    pub tile_height: usize,
    /// Bits per sample (8, 16, 32 or 64).
    pub bits: u16,
    /// SampleFormat: 1 unsigned integer, 2 signed integer, 3 IEEE float.
    pub format: u16,
    /// Predictor: 1 none, 2 horizontal differencing, 3 floating point.
    pub predictor: u16,
    /// Whether the file is little-endian (`II`).
    pub little_endian: bool,
    /// Each tile's byte offset and byte count, row of tiles by row of tiles.
    pub tiles: Vec<(u64, u64)>,
}

/// Decodes every tile of `layout` from `file` into row-major values.
pub fn decode(name: &dyn std::fmt::Display, file: &mut File, layout: &TileLayout) -> Result<Vec<f64>> {
    let l = layout;
    let bytes_per = usize::from(l.bits / 8);
    if !matches!((l.bits, l.format), (8 | 16 | 32, 1 | 2) | (32 | 64, 3)) {
        bail!("{name}: {}-bit samples of SampleFormat {} are not supported in tiled LZW", l.bits, l.format);
    }
    if !matches!(l.predictor, 1..=3) {
        bail!("{name}: Predictor = {} is not a TIFF predictor (1, 2 or 3)", l.predictor);
    }
    // Decided before allocating a tile: at most 2^24 pixels (GDAL writes 256 x 256 or 512 x 512).
    if l.tile_width == 0 || l.tile_height == 0 || l.tile_width.saturating_mul(l.tile_height) > 1 << 24 {
        bail!(
            "{name}: tiles of {} x {} pixels (TileWidth x TileLength must be 1 to 2^24 pixels)",
            l.tile_width,
            l.tile_height
        );
    }
    let across = l.width.div_ceil(l.tile_width);
    let down = l.height.div_ceil(l.tile_height);
    if l.tiles.len() != across * down {
        bail!("{name}: {} tile offsets for {across} x {down} tiles", l.tiles.len());
    }
    let file_len = file.metadata()?.len();
    let tile_bytes = l.tile_width * l.tile_height * bytes_per;
    let mut values = vec![f64::NAN; l.width * l.height];
    let mut compressed = Vec::new();
    let mut raw = vec![0u8; tile_bytes];
    for (t, &(offset, count)) in l.tiles.iter().enumerate() {
        if offset.saturating_add(count) > file_len || count > (tile_bytes as u64) * 8 + 1024 {
            bail!("{name}: tile {t} claims {count} bytes at byte {offset}, past the end of the {file_len}-byte file");
        }
        compressed.resize(count as usize, 0);
        file.seek(SeekFrom::Start(offset))?;
        file.read_exact(&mut compressed)?;
        let mut lzw = weezl::decode::Decoder::with_tiff_size_switch(weezl::BitOrder::Msb, 8);
        // Until the tile is full or the stream ends (its end code may be missing).
        let (mut read, mut written) = (0, 0);
        while written < tile_bytes {
            let r = lzw.decode_bytes(&compressed[read..], &mut raw[written..]);
            read += r.consumed_in;
            written += r.consumed_out;
            match r.status {
                Err(e) => bail!("{name}: tile {t}: invalid LZW data: {e}"),
                Ok(weezl::LzwStatus::Done) => break,
                Ok(weezl::LzwStatus::NoProgress) if r.consumed_in == 0 && r.consumed_out == 0 => break,
                Ok(_) => {}
            }
        }
        if written != tile_bytes {
            bail!("{name}: tile {t} decodes to {written} bytes, not the {tile_bytes} of a whole tile");
        }
        undo_predictor(&mut raw, l, bytes_per);
        let (tx, ty) = (t % across * l.tile_width, t / across * l.tile_height);
        for row in 0..l.tile_height.min(l.height - ty) {
            for col in 0..l.tile_width.min(l.width - tx) {
                let at = (row * l.tile_width + col) * bytes_per;
                values[(ty + row) * l.width + tx + col] = sample(&raw[at..at + bytes_per], l);
            }
        }
    }
    Ok(values)
}

/// Undoes the predictor in place, row by row of the tile.
fn undo_predictor(raw: &mut [u8], l: &TileLayout, bytes_per: usize) {
    let row_bytes = l.tile_width * bytes_per;
    for row in raw.chunks_exact_mut(row_bytes) {
        match l.predictor {
            2 => {
                // Horizontal differencing: each sample is the difference to the one before,
                // in the sample's own width and byte order, wrapping.
                for i in 1..l.tile_width {
                    let (prev, cur) = row.split_at_mut(i * bytes_per);
                    let p = &prev[(i - 1) * bytes_per..];
                    let c = &mut cur[..bytes_per];
                    let read = |b: &[u8]| -> u64 {
                        let mut v = 0u64;
                        for k in 0..bytes_per {
                            let byte = if l.little_endian { b[bytes_per - 1 - k] } else { b[k] };
                            v = (v << 8) | u64::from(byte);
                        }
                        v
                    };
                    let sum = read(p).wrapping_add(read(c));
                    for (k, byte) in c.iter_mut().enumerate() {
                        let shift = 8 * if l.little_endian { k } else { bytes_per - 1 - k };
                        *byte = (sum >> shift) as u8;
                    }
                }
            }
            3 => {
                // Floating point: bytes differenced across the whole row, then the row holds
                // the most significant byte of every sample, then the next, ... (TIFF
                // Technical Note 3); rebuilt into big-endian samples.
                for i in 1..row.len() {
                    row[i] = row[i].wrapping_add(row[i - 1]);
                }
                let planes = row.to_vec();
                for s in 0..l.tile_width {
                    for k in 0..bytes_per {
                        row[s * bytes_per + k] = planes[k * l.tile_width + s];
                    }
                }
            }
            _ => {}
        }
    }
}

/// One sample as f64. After the floating-point predictor the bytes are big-endian.
fn sample(b: &[u8], l: &TileLayout) -> f64 {
    let big = l.predictor == 3 || !l.little_endian;
    let mut v = [0u8; 8];
    let n = b.len();
    // As big-endian bytes of `n` bytes.
    for k in 0..n {
        v[8 - n + k] = if big { b[k] } else { b[n - 1 - k] };
    }
    let u = u64::from_be_bytes(v);
    match (l.format, l.bits) {
        (3, 32) => f64::from(f32::from_bits(u as u32)),
        (3, _) => f64::from_bits(u),
        (2, 8) => f64::from(u as u8 as i8),
        (2, 16) => f64::from(u as u16 as i16),
        (2, _) => f64::from(u as u32 as i32),
        (_, 8) => f64::from(u as u8),
        (_, 16) => f64::from(u as u16),
        _ => f64::from(u as u32),
    }
}

/// The error the `tiff` crate gives on such a file.
pub fn is_partial_tile_lzw_error(message: &str) -> bool {
    message.contains("no lzw end code found")
}

/// Builds the layout from the decoder's tags.
pub fn layout<R: Read + Seek>(
    name: &dyn std::fmt::Display,
    dec: &mut tiff::decoder::Decoder<R>,
    little_endian: bool,
) -> Result<TileLayout> {
    use tiff::tags::Tag;
    let (w, h) = dec.dimensions().map_err(|e| anyhow!("{name}: {e}"))?;
    let mut short = |tag: Tag, default: u16| -> Result<u16> {
        Ok(dec
            .find_tag_unsigned::<u16>(tag)
            .map_err(|e| anyhow!("{name}: tag {tag:?}: {e}"))?
            .unwrap_or(default))
    };
    let bits = short(Tag::BitsPerSample, 8)?;
    let format = short(Tag::SampleFormat, 1)?;
    let predictor = short(Tag::Predictor, 1)?;
    let tile_width = dec.find_tag_unsigned::<u32>(Tag::TileWidth).ok().flatten().unwrap_or(0) as usize;
    let tile_height = dec.find_tag_unsigned::<u32>(Tag::TileLength).ok().flatten().unwrap_or(0) as usize;
    let vec = |dec: &mut tiff::decoder::Decoder<R>, tag: Tag| -> Result<Vec<u64>> {
        dec.find_tag(tag)
            .map_err(|e| anyhow!("{name}: tag {tag:?}: {e}"))?
            .ok_or_else(|| anyhow!("{name}: no {tag:?} tag"))?
            .into_u64_vec()
            .map_err(|e| anyhow!("{name}: tag {tag:?}: {e}"))
    };
    let offsets = vec(dec, Tag::TileOffsets)?;
    let counts = vec(dec, Tag::TileByteCounts)?;
    if offsets.len() != counts.len() {
        bail!("{name}: {} tile offsets and {} tile byte counts", offsets.len(), counts.len());
    }
    Ok(TileLayout {
        width: w as usize,
        height: h as usize,
        tile_width,
        tile_height,
        bits,
        format,
        predictor,
        little_endian,
        tiles: offsets.into_iter().zip(counts).collect(),
    })
}
