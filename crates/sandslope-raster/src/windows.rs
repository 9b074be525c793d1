//! A raster's heights read window by window (issue 56), for maps larger than memory: a
//! GeoTIFF's tiles or strips decoded only where a window touches them (through the `tiff`
//! crate's `read_chunk`, on every core, a bounded cache of decoded chunks), a PDS3 DTM's lines
//! read only over the window's samples. Every height is the one [`super::read_heights_within`]
//! gives for that cell, bit for bit. An ESRI ASCII grid has no random access: it is read
//! whole, once, and its windows cut from it (so is a tiled LZW GeoTIFF with partial edge
//! tiles, which the crate cannot decode chunk by chunk: `lzw_tiles.rs`).

use std::collections::{HashMap, VecDeque};
use std::fs::File;
use std::io::BufReader;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use anyhow::{anyhow, bail, Context, Result};
use rayon::prelude::*;
use tiff::decoder::{ChunkType, Decoder};
use tiff::tags::Tag;

use super::geotiff::{open_full_resolution, samples_as};
use super::grid::Raster;
use super::Format;

/// Decoded chunks kept for later windows, at most this many bytes (with at least two bands of
/// chunks: a pass over the map reads each band once, a corridor's windows overlap).
const CACHE_BYTES: usize = 128 << 20;

/// A raster opened for reading windows of its heights (metres as `f32`, NaN where there is no
/// height); sandslope-io's `height_windows` makes it the corridor search's `HeightSource`.
pub struct RasterWindows {
    name: String,
    cols: usize,
    rows: usize,
    cell_m: (f64, f64),
    row_widths: Option<Vec<f64>>,
    kind: Kind,
    /// Columns rolled across the seam of a map that wraps in longitude (super::seam): column
    /// `j` of the windows is the file's column `(j + roll) % cols`.
    roll: usize,
}

enum Kind {
    Tiff(Box<TiffChunks>),
    Pds3(Box<crate::pds3::Pds3Dtm>),
    Memory(Vec<f32>),
}

/// Decoded chunks' heights by chunk index, and the indices in the order they came (the first
/// is evicted first).
type ChunkCache = (HashMap<u32, Chunk>, VecDeque<u32>);

/// A chunk's heights, shared by the windows that read it.
type Chunk = Arc<Vec<f32>>;

/// A GeoTIFF's chunks: where they are, how to decode them, and the cache.
struct TiffChunks {
    path: PathBuf,
    /// The chunk's width and height (a strip is the image's width), and chunks a band.
    cw: usize,
    ch: usize,
    across: usize,
    /// Samples to heights: the raster's nodata and vertical factor.
    raster: Raster,
    vertical: f64,
    decoders: Mutex<Vec<Decoder<BufReader<File>>>>,
    cache: Mutex<ChunkCache>,
    cache_chunks: usize,
}

/// What a caller checks a raster opened for window reads against, from its header and before
/// any sample is read: `fits(cols, rows, whole)`, `whole` when the heights will be read whole
/// (an ASCII grid). Its error refuses the raster.
pub type WindowsCheck<'a> = &'a dyn Fn(usize, usize, bool) -> Result<()>;

/// Opens the raster at `path` for window reads: its georeference and notes (its `values`
/// empty) and the windows. Reads the header (a GeoTIFF's directory, a PDS3 label, whose every
/// chunk or line is checked to lie inside the file), then calls `fits`, and reads no sample;
/// an ASCII grid is read whole after `fits`.
pub fn open_height_windows(path: &Path, fits: WindowsCheck) -> Result<(Raster, RasterWindows)> {
    let name = path.display().to_string();
    let whole = |fits: WindowsCheck| -> Result<(Raster, Kind)> {
        let (raster, heights) = super::read_heights_within(path, &|c, r| fits(c, r, true))?;
        Ok((raster, Kind::Memory(heights)))
    };
    let (raster, kind) = match Format::of(path)? {
        Format::GeoTiff => {
            let (raster, _, chunks) = open_tiff(path)?;
            match chunks {
                Some(c) => {
                    fits(raster.cols, raster.rows, false)?;
                    (raster, Kind::Tiff(Box::new(c)))
                }
                None => whole(fits)?,
            }
        }
        Format::Pds3 => {
            let (raster, dtm) = crate::pds3::open_windows(path)?;
            fits(raster.cols, raster.rows, false)?;
            (raster, Kind::Pds3(Box::new(dtm)))
        }
        Format::Asc => whole(fits)?,
    };
    // As the planner's grid takes them: rows all of one width are a uniform grid of that width.
    let (mut cell_m, mut row_widths) = (raster.cell_m, raster.row_widths_m.clone());
    if let Some(w) = row_widths.as_ref().filter(|w| w.iter().all(|&x| x == w[0])) {
        cell_m.0 = w[0];
        row_widths = None;
    }
    let windows =
        RasterWindows { name, cols: raster.cols, rows: raster.rows, cell_m, row_widths, kind, roll: 0 };
    Ok((raster, windows))
}

impl RasterWindows {
    /// Whether the heights are held whole in memory (an ASCII grid, or a GeoTIFF the `tiff`
    /// crate cannot decode chunk by chunk): then [`RasterWindows::into_heights`] gives them.
    pub fn is_in_memory(&self) -> bool {
        matches!(self.kind, Kind::Memory(_))
    }

    /// The heights held in memory ([`RasterWindows::is_in_memory`]), row-major (rolled as
    /// the windows are).
    pub fn into_heights(self) -> Option<Vec<f32>> {
        match self.kind {
            Kind::Memory(mut h) => {
                if self.roll != 0 {
                    h.chunks_mut(self.cols).for_each(|row| row.rotate_left(self.roll));
                }
                Some(h)
            }
            _ => None,
        }
    }

    /// The windows of the map with its columns rolled by `shift` across the seam of a map that
    /// wraps in longitude (as [`Raster::rolled_columns`] rolls its georeference): column `j`
    /// is the file's column `(j + shift) % cols`.
    pub fn rolled_columns(mut self, shift: usize) -> RasterWindows {
        self.roll = (self.roll + shift) % self.cols;
        self
    }

    /// The heights of rows `rows` and columns `cols`, row-major, NaN where there is none.
    pub fn read(&self, rows: Range<usize>, cols: Range<usize>) -> Result<Vec<f32>> {
        if rows.start > rows.end || rows.end > self.rows || cols.start > cols.end || cols.end > self.cols {
            bail!(
                "{}: rows {rows:?} and columns {cols:?} are not a window of the {} x {} raster",
                self.name,
                self.cols,
                self.rows
            );
        }
        if self.roll != 0 {
            // The file's columns of the window: one run, or two where it crosses the seam.
            let (a, n) = ((cols.start + self.roll) % self.cols, cols.len());
            if a + n <= self.cols {
                return self.read_file(rows, a..a + n);
            }
            let (east, west) =
                (self.read_file(rows.clone(), a..self.cols)?, self.read_file(rows, 0..a + n - self.cols)?);
            let (e, w) = (self.cols - a, a + n - self.cols);
            return Ok(east
                .chunks(e)
                .zip(west.chunks(w))
                .flat_map(|(e, w)| e.iter().chain(w).copied())
                .collect());
        }
        self.read_file(rows, cols)
    }

    /// [`RasterWindows::read`] in the file's own columns.
    fn read_file(&self, rows: Range<usize>, cols: Range<usize>) -> Result<Vec<f32>> {
        match &self.kind {
            Kind::Memory(h) => Ok(rows
                .flat_map(|r| h[r * self.cols + cols.start..r * self.cols + cols.end].iter().copied())
                .collect()),
            Kind::Pds3(dtm) => Ok(dtm
                .read_window(rows, cols)?
                .into_iter()
                .map(|v| if v.is_finite() { v as f32 } else { f32::NAN })
                .collect()),
            Kind::Tiff(t) => t.read(&self.name, self.cols, self.rows, rows, cols),
        }
    }
}

impl RasterWindows {
    /// Columns (west to east).
    pub fn cols(&self) -> usize {
        self.cols
    }
    /// Rows (north to south).
    pub fn rows(&self) -> usize {
        self.rows
    }
    /// Cell width (east-west) and height (north-south), m; the width is the reference one
    /// when the rows differ ([`RasterWindows::row_widths`]).
    pub fn cell_m(&self) -> (f64, f64) {
        self.cell_m
    }
    /// The east-west size of each row's cells, m, when the rows differ.
    pub fn row_widths(&self) -> Option<&[f64]> {
        self.row_widths.as_deref()
    }
    /// How many rows a pass over the map reads at once: a whole number of the file's strips
    /// or tiles (at least 256 rows), 256 where the file has no chunks.
    pub fn band_rows(&self) -> usize {
        match &self.kind {
            Kind::Tiff(t) => t.ch.max(256usize.div_ceil(t.ch) * t.ch),
            _ => 256,
        }
    }
}

/// A GeoTIFF's raster (georeference, nodata, notes), the factor of its heights to metres, and
/// its chunks (`None` when they cannot be decoded one by one: tiled LZW with partial edge
/// tiles, or samples narrower than a byte). Every chunk's bytes are checked to lie inside the
/// file, naming the first that does not and its offset.
fn open_tiff(path: &Path) -> Result<(Raster, f64, Option<TiffChunks>)> {
    let name = path.display();
    let (raster, vertical) = super::geotiff::read_geotiff_header(path)?;
    let raster = super::finish(path, raster, vertical)?;
    let mut dec = open_full_resolution(path)?;
    let bits: u64 = dec.find_tag_unsigned(Tag::BitsPerSample).ok().flatten().unwrap_or(64);
    let (w, h) = (raster.cols, raster.rows);
    let (cw, ch) = dec.chunk_dimensions();
    let (cw, ch) = (cw as usize, ch.max(1) as usize);
    let tiled = dec.get_chunk_type() == ChunkType::Tile;
    let (offsets_tag, counts_tag, kind) = if tiled {
        (Tag::TileOffsets, Tag::TileByteCounts, "tile")
    } else {
        (Tag::StripOffsets, Tag::StripByteCounts, "strip")
    };
    let offsets: Vec<u64> =
        dec.find_tag_unsigned_vec(offsets_tag).map_err(|e| anyhow!("{name}: {e}"))?.unwrap_or_default();
    let counts: Vec<u64> =
        dec.find_tag_unsigned_vec(counts_tag).map_err(|e| anyhow!("{name}: {e}"))?.unwrap_or_default();
    let file_len = std::fs::metadata(path).with_context(|| format!("cannot read {name}"))?.len();
    let across = if tiled { w.div_ceil(cw.max(1)) } else { 1 };
    let chunks = across * h.div_ceil(ch);
    if offsets.len() < chunks || counts.len() < chunks {
        bail!(
            "{name}: {} {kind} offsets and {} byte counts for an image of {chunks} {kind}s",
            offsets.len(),
            counts.len()
        );
    }
    if let Some(i) = (0..chunks).find(|&i| offsets[i].saturating_add(counts[i]) > file_len) {
        bail!(
            "{name}: {kind} {i} claims {} bytes at byte {}, past the end of the {file_len}-byte file; the file is \
             truncated or corrupt",
            counts[i],
            offsets[i]
        );
    }
    if !matches!(bits, 8 | 16 | 32 | 64) || cw == 0 {
        return Ok((raster, vertical, None));
    }
    // The last chunk is the partial one if any is: the crate's LZW cannot decode some of those.
    let last = u32::try_from(chunks - 1)?;
    match dec.read_chunk(last) {
        Ok(_) => {}
        Err(e) if crate::lzw_tiles::is_partial_tile_lzw_error(&e.to_string()) => {
            return Ok((raster, vertical, None));
        }
        Err(e) => bail!("{name}: cannot decode {kind} {last}: {e}"),
    }
    let chunk_bytes = cw * ch * 4;
    let cache_chunks = (CACHE_BYTES / chunk_bytes.max(1)).max(2 * across);
    let chunks = TiffChunks {
        path: path.to_path_buf(),
        cw,
        ch,
        across,
        raster: raster.clone(),
        vertical,
        decoders: Mutex::new(vec![dec]),
        cache: Mutex::new((HashMap::new(), VecDeque::new())),
        cache_chunks,
    };
    Ok((raster, vertical, Some(chunks)))
}

impl TiffChunks {
    /// The window `rows` x `cols` of a `w` x `h` image, from its chunks (decoded in parallel
    /// where not cached).
    fn read(
        &self,
        name: &str,
        w: usize,
        h: usize,
        rows: Range<usize>,
        cols: Range<usize>,
    ) -> Result<Vec<f32>> {
        let mut out = vec![f32::NAN; rows.len() * cols.len()];
        if out.is_empty() {
            return Ok(out);
        }
        let (band0, band1) = (rows.start / self.ch, (rows.end - 1) / self.ch);
        let (a0, a1) =
            if self.across > 1 { (cols.start / self.cw, (cols.end - 1) / self.cw) } else { (0, 0) };
        let wanted: Vec<(usize, usize)> =
            (band0..=band1).flat_map(|b| (a0..=a1).map(move |a| (b, a))).collect();
        let decoded: Vec<((usize, usize), Chunk)> = wanted
            .into_par_iter()
            .map(|(b, a)| Ok(((b, a), self.chunk(name, w, h, b, a)?)))
            .collect::<Result<_>>()?;
        let width = cols.len();
        for ((b, a), data) in decoded {
            let (x0, y0) = (a * self.cw, b * self.ch);
            let dw = if self.across > 1 { self.cw.min(w - x0) } else { w };
            let (r0, r1) = (rows.start.max(y0), rows.end.min(y0 + self.ch));
            let (c0, c1) = (cols.start.max(x0), cols.end.min(x0 + dw));
            for r in r0..r1 {
                let src = &data[(r - y0) * dw + c0 - x0..(r - y0) * dw + c1 - x0];
                let at = (r - rows.start) * width + c0 - cols.start;
                out[at..at + src.len()].copy_from_slice(src);
            }
        }
        Ok(out)
    }

    /// The heights of chunk (band `b`, column `a`), from the cache or decoded.
    fn chunk(&self, name: &str, w: usize, h: usize, b: usize, a: usize) -> Result<Arc<Vec<f32>>> {
        let index = u32::try_from(b * self.across + a)?;
        if let Some(c) = self.cache.lock().map_err(|_| anyhow!("{name}: a reader failed"))?.0.get(&index) {
            return Ok(c.clone());
        }
        let dec = self.decoders.lock().map_err(|_| anyhow!("{name}: a reader failed"))?.pop();
        let mut dec = match dec {
            Some(d) => d,
            None => open_full_resolution(&self.path)?,
        };
        let result = dec.read_chunk(index).map_err(|e| anyhow!("{name}: cannot decode chunk {index}: {e}"));
        self.decoders.lock().map_err(|_| anyhow!("{name}: a reader failed"))?.push(dec);
        let dw = if self.across > 1 { self.cw.min(w - a * self.cw) } else { w };
        let dh = self.ch.min(h - b * self.ch);
        let (raster, vertical) = (&self.raster, self.vertical);
        let to_f32 = |v: f64| if raster.is_nodata_value(v) { f32::NAN } else { v as f32 };
        let height = |v: f64| to_f32(if v.is_finite() { v * vertical } else { v });
        let heights = samples_as(&name, result?, dw * dh, height, |v| {
            v.into_iter().map(|x| height(f64::from(x))).collect()
        })?;
        let heights = Arc::new(heights);
        let mut cache = self.cache.lock().map_err(|_| anyhow!("{name}: a reader failed"))?;
        if cache.0.insert(index, heights.clone()).is_none() {
            cache.1.push_back(index);
        }
        while cache.1.len() > self.cache_chunks {
            if let Some(old) = cache.1.pop_front() {
                cache.0.remove(&old);
            }
        }
        Ok(heights)
    }
}

#[cfg(test)]
mod windows_tests;
