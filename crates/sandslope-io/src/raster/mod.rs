//! Raster files for `sandslope plan`: GeoTIFF (read with the `tiff` crate: float32/float64
//! and integer samples, strips or tiles, any compression the crate decodes, the GeoTIFF
//! ModelPixelScale/ModelTiepoint/ModelTransformation and GDAL_NODATA tags) and ESRI ASCII
//! grids (`.asc`); and a two-band float32 GeoTIFF writer georeferenced like the input.

use std::fs::File;
use std::io::{BufReader, BufWriter};
use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};
use tiff::decoder::{Decoder, DecodingResult, Limits};

use crate::crs::Crs;

mod ascii;
mod chunks;

use ascii::read_asc;
use tiff::encoder::{colortype::Gray32Float, compression::DeflateLevel, Compression, TiffEncoder};
use tiff::tags::{ExtraSamples, Tag};

/// The most cells a raster may have: 2^29 (about 23,000 x 23,000; 4 GiB as f64). The size a
/// file claims is checked against it before anything is allocated, so a small file that claims
/// a huge image is refused at once instead of exhausting memory.
pub const MAX_RASTER_CELLS: usize = 1 << 29;

/// The largest GeoTIFF tag value (GeoKeys, strip offsets, ...) read, in bytes. A tag whose
/// count claims more is refused before its value is allocated.
pub const MAX_TIFF_TAG_BYTES: usize = 16 << 20;

/// Refuses a `cols` x `rows` raster with more than [`MAX_RASTER_CELLS`] cells, naming the file.
pub(crate) fn check_raster_size(name: &dyn std::fmt::Display, cols: u64, rows: u64) -> Result<()> {
    let cells = cols.saturating_mul(rows);
    if cells > MAX_RASTER_CELLS as u64 {
        bail!(
            "{name}: {cols} x {rows} = {cells} cells is more than the {MAX_RASTER_CELLS}-cell limit \
             (2^29); crop or resample the raster (for example with gdal_translate -srcwin or -tr)"
        );
    }
    Ok(())
}

/// Largest expansion of a compressed GeoTIFF's bytes into samples that is believed: LZW's
/// 12-bit codes expand to at most 4096 bytes each (about 2730:1), Deflate to about 1032:1.
const MAX_EXPANSION: u64 = 4096;

/// Decoded images up to this size are allocated whatever the file's size.
const ALWAYS_BELIEVED_BYTES: u64 = 64 << 20;

/// Refuses an image whose decoded samples (`cols` x `rows` x `bits` / 8 bytes) could not come
/// from a file of `file_bytes` bytes under any TIFF compression, before the decoder allocates
/// them: a 700-byte file claiming a 4 GiB image made the allocation abort the process.
fn check_claimed_bytes(
    name: &dyn std::fmt::Display,
    cols: u64,
    rows: u64,
    bits: u64,
    file_bytes: u64,
) -> Result<()> {
    let claimed = cols.saturating_mul(rows).saturating_mul(bits.max(8) / 8);
    if claimed > ALWAYS_BELIEVED_BYTES && claimed / MAX_EXPANSION > file_bytes {
        bail!(
            "{name}: claims {cols} x {rows} samples of {bits} bits ({claimed} bytes), more than a \
             {file_bytes}-byte file can hold under any TIFF compression; the file is truncated or corrupt"
        );
    }
    Ok(())
}

/// Checks every entry of a TIFF's first image directory (classic or BigTIFF) before the decoder
/// reads one: a value larger than [`MAX_TIFF_TAG_BYTES`], or one that would lie past the end of
/// the file, is refused naming the tag. The decoder's own limit does not cover ASCII tags, so a
/// 450-byte file whose GeoAsciiParams or GDAL_NODATA tag claimed 4 GiB made it allocate that
/// and abort (found by scripts/fuzz.sh).
fn check_tiff_directory(name: &dyn std::fmt::Display, file: &mut File) -> Result<()> {
    use std::io::{Read, Seek, SeekFrom};
    let file_len = file.metadata().with_context(|| format!("cannot read {name}"))?.len();
    let mut head = [0u8; 16];
    let got = file.read(&mut head).with_context(|| format!("cannot read {name}"))?;
    if got < 8 {
        bail!("{name}: not a TIFF ({got} bytes)");
    }
    let little = match &head[..2] {
        b"II" => true,
        b"MM" => false,
        _ => return Ok(()), // not a TIFF: the decoder says so
    };
    let (u16_at, u32_at, u64_at) =
        (|b: &[u8]| u16_at(b, little), |b: &[u8]| u32_at(b, little), |b: &[u8]| u64_at(b, little));
    let big = match u16_at(&head[2..4]) {
        42 => false,
        43 if got >= 16 => true,
        _ => return Ok(()),
    };
    let mut ifd = if big { u64_at(&head[8..16]) } else { u32_at(&head[4..8]) };
    let (count_len, entry_len, inline) = if big { (8u64, 20u64, 8u64) } else { (2, 12, 4) };
    // Every directory (a COG's overviews and masks follow the full image), at most 64.
    for index in 0..MAX_IFDS {
        if index > 0 && ifd == 0 {
            break;
        }
        let which = if index == 0 {
            "the first image directory".to_string()
        } else {
            format!("image directory {index}")
        };
        if ifd.saturating_add(count_len) > file_len {
            bail!("{name}: {which} (at byte {ifd}) lies past the end of the {file_len}-byte file");
        }
        file.seek(SeekFrom::Start(ifd))?;
        let mut n = [0u8; 8];
        file.read_exact(&mut n[..count_len as usize])?;
        let entries = if big { u64_at(&n) } else { u64::from(u16_at(&n)) };
        let table = entries.saturating_mul(entry_len);
        if table > 1 << 20 || ifd + count_len + table > file_len {
            bail!("{name}: {which} claims {entries} entries, more than the {file_len}-byte file holds");
        }
        let mut buf = vec![0u8; table as usize];
        file.read_exact(&mut buf)?;
        check_entries(name, &buf, entry_len, inline, file_len, big, little)?;
        // The next directory's offset follows the entries (absent when the file ends there).
        let mut next = [0u8; 8];
        let want = if big { 8 } else { 4 };
        ifd = match file.read_exact(&mut next[..want]) {
            Ok(()) => {
                if big {
                    u64_at(&next)
                } else {
                    u32_at(&next[..4])
                }
            }
            Err(_) => 0,
        };
    }
    file.seek(SeekFrom::Start(0))?;
    Ok(())
}

/// Image directories checked by [`check_tiff_directory`] (a COG has one per overview and mask).
const MAX_IFDS: usize = 64;

/// A TIFF's 16-bit field at the start of `b`, in the file's byte order.
fn u16_at(b: &[u8], little: bool) -> u16 {
    let a = [b[0], b[1]];
    if little {
        u16::from_le_bytes(a)
    } else {
        u16::from_be_bytes(a)
    }
}

/// A TIFF's 32-bit field at the start of `b`, in the file's byte order, widened.
fn u32_at(b: &[u8], little: bool) -> u64 {
    let a = [b[0], b[1], b[2], b[3]];
    u64::from(if little { u32::from_le_bytes(a) } else { u32::from_be_bytes(a) })
}

/// A BigTIFF's 64-bit field at the start of `b`, in the file's byte order.
fn u64_at(b: &[u8], little: bool) -> u64 {
    let a = [b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]];
    if little {
        u64::from_le_bytes(a)
    } else {
        u64::from_be_bytes(a)
    }
}

/// Checks one directory's entries (see [`check_tiff_directory`]).
fn check_entries(
    name: &dyn std::fmt::Display,
    buf: &[u8],
    entry_len: u64,
    inline: u64,
    file_len: u64,
    big: bool,
    little: bool,
) -> Result<()> {
    let (u16_at, u32_at, u64_at) =
        (|b: &[u8]| u16_at(b, little), |b: &[u8]| u32_at(b, little), |b: &[u8]| u64_at(b, little));
    for e in buf.chunks_exact(entry_len as usize) {
        let tag = u16_at(&e[0..2]);
        let size_of = match u16_at(&e[2..4]) {
            1 | 2 | 6 | 7 => 1u64,
            3 | 8 => 2,
            4 | 9 | 11 | 13 => 4,
            5 | 10 | 12 | 16 | 17 | 18 => 8,
            _ => continue, // an unknown type: the decoder skips or refuses it
        };
        let count = if big { u64_at(&e[4..12]) } else { u32_at(&e[4..8]) };
        let bytes = count.saturating_mul(size_of);
        let offset = if big { u64_at(&e[12..20]) } else { u32_at(&e[8..12]) };
        let label = Tag::from_u16(tag).map_or_else(|| format!("{tag}"), |t| format!("{t:?} ({tag})"));
        if bytes > MAX_TIFF_TAG_BYTES as u64 {
            bail!("{name}: tag {label} claims {bytes} bytes, more than the {MAX_TIFF_TAG_BYTES}-byte limit of a tag value");
        }
        if bytes > inline && offset.saturating_add(bytes) > file_len {
            bail!("{name}: tag {label} claims {bytes} bytes at byte {offset}, past the end of the {file_len}-byte file");
        }
    }
    Ok(())
}

/// The decoder's limits: the image at most [`MAX_RASTER_CELLS`] 8-byte samples, any tag
/// value at most [`MAX_TIFF_TAG_BYTES`].
fn tiff_limits() -> Limits {
    let mut limits = Limits::default();
    limits.decoding_buffer_size = MAX_RASTER_CELLS * 8;
    limits.ifd_value_size = MAX_TIFF_TAG_BYTES;
    limits
}

/// GeoKey GTRasterTypeGeoKey and its value RasterPixelIsPoint.
const GT_RASTER_TYPE: u16 = 1025;
const PIXEL_IS_POINT: u16 = 2;

/// Where a raster sits on the map: the north-west corner of its north-west cell and the cell
/// size (x east, y north). Plus the raw GeoTIFF georeferencing tags, copied to outputs.
#[derive(Debug, Clone, PartialEq)]
pub struct GeoRef {
    /// Map x of the western edge of column 0.
    pub west: f64,
    /// Map y of the northern edge of row 0.
    pub north: f64,
    /// Cell width, map units.
    pub cell_x: f64,
    /// Cell height, map units.
    pub cell_y: f64,
    /// GeoKeyDirectory, GeoDoubleParams, GeoAsciiParams of the source, if any.
    pub geokeys: Option<Vec<u16>>,
    geodoubles: Option<Vec<f64>>,
    geoascii: Option<String>,
}

impl GeoRef {
    /// A north-up raster's georeferencing with the GeoTIFF keys that describe its CRS (a PDS3
    /// map's, for instance), copied to the GeoTIFFs written over it.
    pub(crate) fn north_up(
        (west, north, cell_x, cell_y): (f64, f64, f64, f64),
        geokeys: Vec<u16>,
        geodoubles: Vec<f64>,
        geoascii: String,
    ) -> GeoRef {
        GeoRef {
            west,
            north,
            cell_x,
            cell_y,
            geokeys: Some(geokeys),
            geodoubles: Some(geodoubles),
            geoascii: Some(geoascii),
        }
    }
    /// Map coordinates of the centre of (col, row).
    pub fn centre(&self, col: usize, row: usize) -> (f64, f64) {
        (self.west + (col as f64 + 0.5) * self.cell_x, self.north - (row as f64 + 0.5) * self.cell_y)
    }
    /// The (col, row) containing map point (x, y), as signed numbers (may be outside).
    pub fn cell_of(&self, x: f64, y: f64) -> (f64, f64) {
        (((x - self.west) / self.cell_x).floor(), ((self.north - y) / self.cell_y).floor())
    }
    /// Whether two rasters share cell size and origin (within a thousandth of a cell).
    pub fn aligned(&self, other: &GeoRef) -> bool {
        let tol = 1e-3 * self.cell_x.min(self.cell_y);
        (self.west - other.west).abs() < tol
            && (self.north - other.north).abs() < tol
            && (self.cell_x - other.cell_x).abs() < tol
            && (self.cell_y - other.cell_y).abs() < tol
    }
}

/// A single-band raster: values row-major from the north-west corner.
#[derive(Debug, Clone)]
pub struct Raster {
    /// Columns.
    pub cols: usize,
    /// Rows.
    pub rows: usize,
    /// Values (nodata cells hold the nodata value or NaN).
    pub values: Vec<f64>,
    /// The nodata value, if declared.
    pub nodata: Option<f64>,
    /// Georeferencing, in the file's own map units (degrees for a geographic CRS).
    pub geo: GeoRef,
    /// What the map coordinates are (crs.rs).
    pub crs: Crs,
    /// Ground size of a cell, metres (east, north): the cell size the planner uses (on a
    /// geographic raster the east-west size at the mid-latitude, the reference cell).
    pub cell_m: (f64, f64),
    /// East-west ground size of each row's cells, metres (row 0 at the north), where the rows
    /// differ (a geographic CRS): what the planner uses east-west instead of `cell_m.0`.
    pub row_widths_m: Option<Vec<f64>>,
    /// What was assumed or converted in reading (units, ellipsoid, the mid-latitude), for the
    /// front end to print as notes.
    pub notes: Vec<String>,
}

impl Raster {
    /// Whether cell `i` is nodata (the declared value, or not finite).
    pub fn is_nodata(&self, i: usize) -> bool {
        self.is_nodata_value(self.values[i])
    }

    /// Whether `v` is a nodata value here (the declared value, or not finite).
    pub fn is_nodata_value(&self, v: f64) -> bool {
        !v.is_finite() || self.nodata.is_some_and(|nd| v == nd || (nd.is_nan() && v.is_nan()))
    }
}

/// Reads a GeoTIFF (`.tif`, `.tiff`), an ESRI ASCII grid (`.asc`) or a PDS3 DTM (`.img` with
/// its label attached or a `.lbl` beside it, or the `.lbl`; any file beginning with a PDS3
/// label), by extension or, for other names, by its first bytes.
pub fn read_raster(path: &Path) -> Result<Raster> {
    read_raster_within(path, &|_, _| Ok(()))
}

/// What a caller checks a raster's size against before its samples are read: `fits(cols,
/// rows)` fails to refuse the raster (for instance because what the caller would build on it
/// cannot fit in memory).
pub type SizeCheck<'a> = &'a dyn Fn(usize, usize) -> Result<()>;

/// [`read_raster`], with `fits(cols, rows)` called once the header gives the size and before
/// anything of that size is allocated or decoded: its error refuses the raster.
pub fn read_raster_within(path: &Path, fits: SizeCheck) -> Result<Raster> {
    let (mut raster, vertical) = match Format::of(path)? {
        Format::GeoTiff => {
            let (mut raster, vertical, image) = read_geotiff(path, fits)?;
            let n = raster.cols * raster.rows;
            raster.values =
                samples_as(&path.display(), image, n, |v| v, |v| v.into_iter().map(f64::from).collect())?;
            (raster, vertical)
        }
        Format::Asc => read_asc(path, fits)?,
        // PDS3 rasters carry their own cell size in metres (pds3.rs).
        Format::Pds3 => return crate::pds3::read_pds3_within(path, fits),
    };
    if vertical != 1.0 {
        for v in raster.values.iter_mut().filter(|v| v.is_finite()) {
            *v *= vertical;
        }
    }
    finish(path, raster, vertical)
}

/// A raster's heights in metres as `f32` (the planner's precision), nodata cells as NaN, with
/// the raster's georeference (its `values` left empty): [`read_raster_within`] without the
/// `f64` copy of the samples, so a float32 GeoTIFF is held once, 4 bytes a cell (its decoded
/// buffer is converted in place). Each height is the `f64` value [`read_raster_within`] gives
/// rounded to `f32`, and NaN exactly where [`Raster::is_nodata`] holds; an ASCII grid or a PDS3
/// DTM is read as `f64` first and converted.
pub fn read_heights_within(path: &Path, fits: SizeCheck) -> Result<(Raster, Vec<f32>)> {
    let to_f32 = |raster: &Raster, v: f64| if raster.is_nodata_value(v) { f32::NAN } else { v as f32 };
    if Format::of(path)? != Format::GeoTiff {
        let mut raster = read_raster_within(path, fits)?;
        let values = std::mem::take(&mut raster.values);
        let heights = values.iter().map(|&v| to_f32(&raster, v)).collect();
        return Ok((raster, heights));
    }
    let (raster, vertical, image) = read_geotiff(path, fits)?;
    let raster = finish(path, raster, vertical)?;
    let height = |v: f64| to_f32(&raster, if v.is_finite() { v * vertical } else { v });
    let n = raster.cols * raster.rows;
    let heights = samples_as(&path.display(), image, n, height, |v| {
        v.into_iter().map(|x| height(f64::from(x))).collect()
    })?;
    Ok((raster, heights))
}

/// The raster formats read, by extension or, for other names, by the first bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Format {
    GeoTiff,
    Asc,
    Pds3,
}

impl Format {
    fn of(path: &Path) -> Result<Format> {
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        Ok(match ext.as_deref() {
            Some("tif" | "tiff") => Format::GeoTiff,
            Some("asc") => Format::Asc,
            Some("img" | "lbl") => Format::Pds3,
            _ if crate::pds3::starts_with_label(path) => Format::Pds3,
            _ => bail!(
                "{}: unknown raster format; use a GeoTIFF (.tif, .tiff), an ESRI ASCII grid (.asc) or a PDS3 DTM \
                 (.img, .lbl)",
                path.display()
            ),
        })
    }
}

/// A GeoTIFF or ASCII grid read so far, its heights (if any) already in metres: the nodata
/// value converted by `vertical` too, the ground cell size and the notes on the CRS.
fn finish(path: &Path, mut raster: Raster, vertical: f64) -> Result<Raster> {
    if vertical != 1.0 {
        raster.nodata = raster.nodata.map(|nd| nd * vertical);
    }
    let g = &raster.geo;
    let south = g.north - raster.rows as f64 * g.cell_y;
    let cells = crate::crs::ground_cell_size(
        &path.display(),
        &raster.crs,
        g.cell_x,
        g.cell_y,
        g.north,
        south,
        raster.rows,
        &mut raster.notes,
    )?;
    (raster.cell_m, raster.row_widths_m) = (cells.cell_m, cells.row_widths_m);
    if !raster.crs.is_geographic()
        && g.cell_x < 0.01
        && g.west.abs() <= 180.0
        && g.north.abs() <= 90.0
        && south >= -90.0
    {
        raster.notes.push(format!(
            "{}: cells of {} map units inside the longitude/latitude range look like degrees, but the file \
             declares no geographic CRS; they are read as {}s",
            path.display(),
            g.cell_x,
            match &raster.crs {
                Crs::Projected { unit, .. } => unit,
                Crs::Geographic { .. } => "degree",
            }
        ));
    }
    Ok(raster)
}

/// A GeoTIFF (its `values` left empty), the factor converting its heights to metres, and its
/// decoded samples.
fn read_geotiff(path: &Path, fits: SizeCheck) -> Result<(Raster, f64, DecodingResult)> {
    let name = path.display();
    let mut dec = open_full_resolution(path)?;
    let (w, h) = dec.dimensions().map_err(|e| anyhow!("{name}: {e}"))?;
    check_raster_size(&name, u64::from(w), u64::from(h))?;
    fits(w as usize, h as usize)?;
    let bits: u64 = dec.find_tag_unsigned(Tag::BitsPerSample).ok().flatten().unwrap_or(64);
    let file_bytes = std::fs::metadata(path).with_context(|| format!("cannot read {name}"))?.len();
    check_claimed_bytes(&name, u64::from(w), u64::from(h), bits, file_bytes)?;
    let samples: u16 = dec.find_tag_unsigned(Tag::SamplesPerPixel).ok().flatten().unwrap_or(1);
    if samples != 1 {
        bail!("{name}: has {samples} bands (SamplesPerPixel = {samples}); an elevation or class raster must have exactly 1");
    }
    let tags = GeoTags::read(&name, &mut dec)?;
    let (west, north, cell_x, cell_y) = tags.origin_and_cell(&name)?;
    let image = decode_samples(&name, path, &mut dec, bits)?;
    let (cols, rows) = (w as usize, h as usize);
    let mut notes = Vec::new();
    let GeoTags { geokeys, geodoubles, geoascii, nodata, .. } = tags;
    let (crs, vertical) = crate::crs::from_geokeys(
        &name,
        geokeys.as_deref(),
        geodoubles.as_deref(),
        geoascii.as_deref(),
        &mut notes,
    )?;
    let geo = GeoRef { west, north, cell_x, cell_y, geokeys, geodoubles, geoascii };
    let raster = Raster {
        cols,
        rows,
        values: Vec::new(),
        nodata,
        geo,
        crs,
        cell_m: (cell_x, cell_y),
        row_widths_m: None,
        notes,
    };
    Ok((raster, vertical, image))
}

/// The GDAL_NODATA value of a GeoTIFF, from its tags alone (the samples are not decoded), as
/// [`read_raster`] honours it: for readers that take a GeoTIFF's samples window by window (the
/// Python package's Dask raster) and must mark the same cells as nodata.
pub fn geotiff_nodata(path: &Path) -> Result<Option<f64>> {
    let name = path.display();
    let mut dec = open_full_resolution(path)?;
    Ok(GeoTags::read(&name, &mut dec)?.nodata)
}

/// A GeoTIFF's decoder at its full-resolution image, every directory's tags checked first.
fn open_full_resolution(path: &Path) -> Result<Decoder<BufReader<File>>> {
    let name = path.display();
    let mut file = File::open(path).with_context(|| format!("cannot read {name}"))?;
    check_tiff_directory(&name, &mut file)?;
    let mut dec = Decoder::new(BufReader::new(file))
        .map_err(|e| anyhow!("{name}: not a readable TIFF: {e}"))?
        .with_limits(tiff_limits());
    skip_to_full_resolution(&name, &mut dec)?;
    Ok(dec)
}

/// Moves `dec` to the full-resolution image.
fn skip_to_full_resolution<R: std::io::Read + std::io::Seek>(
    name: &dyn std::fmt::Display,
    dec: &mut Decoder<R>,
) -> Result<()> {
    // The full-resolution image: should a file begin with an overview or a mask (NewSubfileType
    // bit 0, reduced resolution, or bit 2, transparency mask), skip to the first that is neither.
    // (GDAL's COG and COPY_SRC_OVERVIEWS put the full image first and overviews after it.)
    loop {
        let kind: u32 = dec.find_tag_unsigned(Tag::NewSubfileType).ok().flatten().unwrap_or(0);
        if kind & 0b101 == 0 {
            break;
        }
        if !dec.more_images() {
            bail!("{name}: every image directory is an overview or a mask (NewSubfileType = {kind}): no full-resolution image");
        }
        dec.next_image().map_err(|e| anyhow!("{name}: the image directory after an overview: {e}"))?;
    }
    Ok(())
}

/// A GeoTIFF's georeferencing tags and GDAL_NODATA, as stored.
struct GeoTags {
    scale: Option<Vec<f64>>,
    tie: Option<Vec<f64>>,
    transform: Option<Vec<f64>>,
    geodoubles: Option<Vec<f64>>,
    geokeys: Option<Vec<u16>>,
    geoascii: Option<String>,
    nodata: Option<f64>,
}

impl GeoTags {
    fn read<R: std::io::Read + std::io::Seek>(
        name: &dyn std::fmt::Display,
        dec: &mut Decoder<R>,
    ) -> Result<GeoTags> {
        let tag_f64 = |dec: &mut Decoder<_>, tag: Tag| -> Result<Option<Vec<f64>>> {
            match dec.find_tag(tag).map_err(|e| anyhow!("{name}: tag {tag:?}: {e}"))? {
                Some(v) => Ok(Some(v.into_f64_vec().map_err(|e| anyhow!("{name}: tag {tag:?}: {e}"))?)),
                None => Ok(None),
            }
        };
        let scale = tag_f64(dec, Tag::ModelPixelScaleTag)?;
        let tie = tag_f64(dec, Tag::ModelTiepointTag)?;
        let transform = tag_f64(dec, Tag::ModelTransformationTag)?;
        let geodoubles = tag_f64(dec, Tag::GeoDoubleParamsTag)?;
        let geokeys = match dec.find_tag(Tag::GeoKeyDirectoryTag).ok().flatten() {
            Some(v) => Some(v.into_u16_vec().map_err(|e| anyhow!("{name}: GeoKeyDirectory: {e}"))?),
            None => None,
        };
        let geoascii = dec.find_tag(Tag::GeoAsciiParamsTag).ok().flatten().and_then(|v| v.into_string().ok());
        let nodata = match dec.find_tag(Tag::GdalNodata).ok().flatten() {
            Some(v) => {
                let s = v.into_string().map_err(|e| anyhow!("{name}: GDAL_NODATA tag: {e}"))?;
                let s = s.trim_matches(|c: char| c == '\0' || c.is_whitespace());
                Some(s.parse::<f64>().map_err(|_| anyhow!("{name}: GDAL_NODATA tag `{s}` is not a number"))?)
            }
            None => None,
        };
        Ok(GeoTags { scale, tie, transform, geodoubles, geokeys, geoascii, nodata })
    }

    /// The raster's west and north edges and cell size (x, y), in the CRS's units, from the
    /// pixel scale and tie point or the transformation matrix (north up only), corrected for
    /// PixelIsPoint.
    fn origin_and_cell(&self, name: &dyn std::fmt::Display) -> Result<(f64, f64, f64, f64)> {
        let (scale, tie, transform) = (self.scale.as_deref(), self.tie.as_deref(), self.transform.as_deref());
        let from_transform =
            !(scale.as_ref().is_some_and(|s| s.len() >= 2) && tie.as_ref().is_some_and(|t| t.len() >= 6));
        let (mut west, mut north, cell_x, cell_y) = match (scale, tie, transform) {
            (_, Some(t), None) if t.len() > 6 => bail!(
                "{name}: ModelTiepointTag (33922) holds {} tie points: a raster georeferenced by ground control \
                 points is not a regular grid; warp it to one first (gdalwarp -t_srs ...)",
                t.len() / 6
            ),
            (Some(s), Some(t), _) if s.len() >= 2 && t.len() >= 6 => {
                (t[3] - t[0] * s[0], t[4] + t[1] * s[1], s[0], s[1])
            }
            (_, _, Some(m)) if m.len() >= 16 => {
                if m[1] != 0.0 || m[4] != 0.0 {
                    bail!(
                        "{name}: ModelTransformationTag (34264) has rotation or shear terms {} (row 1, column 2) and {} \
                         (row 2, column 1): only north-up rasters are supported; make it north-up first (gdalwarp)",
                        m[1],
                        m[4]
                    );
                }
                (m[3], m[7], m[0], -m[5])
            }
            _ => bail!(
                "{name}: no georeferencing (needs the GeoTIFF ModelPixelScale and ModelTiepoint tags, or \
                 ModelTransformation); the planner needs the cell size in metres"
            ),
        };
        if !(cell_x.is_finite() && cell_x > 0.0 && cell_y.is_finite() && cell_y > 0.0) {
            let tag = if from_transform {
                "ModelTransformationTag (34264): m[0], -m[5]"
            } else {
                "ModelPixelScaleTag (33550)"
            };
            bail!("{name}: pixel scale ({cell_x}, {cell_y}) from {tag} must be positive (north-up rasters only)");
        }
        if pixel_is_point(self.geokeys.as_deref()) {
            west -= 0.5 * cell_x;
            north += 0.5 * cell_y;
        }
        Ok((west, north, cell_x, cell_y))
    }
}

/// The image's samples, of a type [`samples_as`] converts (float32, float64 or 8/16/32-bit
/// integers; others are refused naming BitsPerSample and SampleFormat).
fn decode_samples<R: std::io::Read + std::io::Seek>(
    name: &dyn std::fmt::Display,
    path: &Path,
    dec: &mut Decoder<R>,
    bits: u64,
) -> Result<DecodingResult> {
    let sample_format: u16 = dec.find_tag_unsigned(Tag::SampleFormat).ok().flatten().unwrap_or(1);
    let limit = tiff_limits().decoding_buffer_size;
    let parallel = chunks::read_image_in_parallel(dec, bits, limit, chunks::MIN_PARALLEL_CELLS, || {
        open_full_resolution(path).ok()
    });
    let image = match parallel.map_or_else(|| dec.read_image(), Ok) {
        Ok(image) => image,
        // Tiled LZW with partial edge tiles, which the `tiff` crate cannot decode (lzw_tiles.rs).
        Err(e) if crate::lzw_tiles::is_partial_tile_lzw_error(&e.to_string()) => {
            let mut file = File::open(path).with_context(|| format!("cannot read {name}"))?;
            let mut order = [0u8; 2];
            std::io::Read::read_exact(&mut file, &mut order)?;
            let layout = crate::lzw_tiles::layout(name, dec, &order == b"II")?;
            DecodingResult::F64(crate::lzw_tiles::decode(name, &mut file, &layout)?)
        }
        Err(e) => bail!("{name}: cannot decode the image: {e}"),
    };
    match image {
        DecodingResult::F32(_)
        | DecodingResult::F64(_)
        | DecodingResult::I16(_)
        | DecodingResult::U16(_)
        | DecodingResult::I32(_)
        | DecodingResult::U32(_)
        | DecodingResult::I8(_)
        | DecodingResult::U8(_) => Ok(image),
        other => bail!(
            "{name}: unsupported sample type (BitsPerSample = {bits}, SampleFormat = {}: {}); use float32, float64 or \
             8/16/32-bit integers",
            sample_format,
            match other {
                DecodingResult::U64(_) | DecodingResult::I64(_) => "64-bit integers",
                DecodingResult::F16(_) => "16-bit floats",
                _ => "another type",
            }
        ),
    }
}

/// The `n` samples of `image` ([`decode_samples`]) converted by `f` from their value as `f64`,
/// float32 samples by `from_f32` (which may convert them in place).
fn samples_as<T>(
    name: &dyn std::fmt::Display,
    image: DecodingResult,
    n: usize,
    f: impl Fn(f64) -> T,
    from_f32: impl FnOnce(Vec<f32>) -> Vec<T>,
) -> Result<Vec<T>> {
    let values: Vec<T> = match image {
        DecodingResult::F32(v) => from_f32(v),
        DecodingResult::F64(v) => v.into_iter().map(f).collect(),
        DecodingResult::I16(v) => v.into_iter().map(|x| f(f64::from(x))).collect(),
        DecodingResult::U16(v) => v.into_iter().map(|x| f(f64::from(x))).collect(),
        DecodingResult::I32(v) => v.into_iter().map(|x| f(f64::from(x))).collect(),
        DecodingResult::U32(v) => v.into_iter().map(|x| f(f64::from(x))).collect(),
        DecodingResult::I8(v) => v.into_iter().map(|x| f(f64::from(x))).collect(),
        DecodingResult::U8(v) => v.into_iter().map(|x| f(f64::from(x))).collect(),
        _ => bail!("{name}: unsupported sample type"),
    };
    if values.len() != n {
        bail!("{name}: decoded {} samples for an image of {n} cells", values.len());
    }
    Ok(values)
}

fn pixel_is_point(keys: Option<&[u16]>) -> bool {
    // Header (4 shorts) then entries (key, location, count, value); location 0 = inline value.
    keys.is_some_and(|k| {
        k.get(4..)
            .unwrap_or(&[])
            .chunks_exact(4)
            .any(|e| e[0] == GT_RASTER_TYPE && e[1] == 0 && e[3] == PIXEL_IS_POINT)
    })
}

/// Writes a two-band float32 GeoTIFF (`band1`, `band2`, row-major, NaN for nodata, declared
/// in GDAL_NODATA) georeferenced by `geo`: the source's GeoKeys are copied, so the CRS is kept.
pub fn write_two_band_geotiff(
    path: &Path,
    cols: usize,
    rows: usize,
    geo: &GeoRef,
    band1: &[f32],
    band2: &[f32],
) -> Result<()> {
    let name = path.display().to_string();
    crate::files::write_via_temp(path, |tmp| {
        let file = File::create(tmp).with_context(|| format!("cannot write {name}"))?;
        let err = |e: tiff::TiffError| anyhow!("{name}: {e}");
        let mut enc = TiffEncoder::new(BufWriter::new(file))
            .map_err(err)?
            .with_compression(Compression::Deflate(DeflateLevel::default()));
        let (w, h) = (u32::try_from(cols)?, u32::try_from(rows)?);
        let mut img = enc.new_image::<Gray32Float>(w, h).map_err(err)?;
        img.extra_samples(&[ExtraSamples::Unspecified]).map_err(err)?;
        let d = img.encoder();
        d.write_tag(Tag::ModelPixelScaleTag, &[geo.cell_x, geo.cell_y, 0.0][..]).map_err(err)?;
        d.write_tag(Tag::ModelTiepointTag, &[0.0, 0.0, 0.0, geo.west, geo.north, 0.0][..]).map_err(err)?;
        // Our tie point is the corner of the corner cell: declare PixelIsArea, keep the rest.
        let keys = with_pixel_is_area(geo.geokeys.as_deref());
        d.write_tag(Tag::GeoKeyDirectoryTag, &keys[..]).map_err(err)?;
        if let Some(dbl) = &geo.geodoubles {
            d.write_tag(Tag::GeoDoubleParamsTag, &dbl[..]).map_err(err)?;
        }
        if let Some(a) = &geo.geoascii {
            d.write_tag(Tag::GeoAsciiParamsTag, a.as_str()).map_err(err)?;
        }
        d.write_tag(Tag::GdalNodata, "nan").map_err(err)?;
        let data: Vec<f32> = band1.iter().zip(band2).flat_map(|(&a, &b)| [a, b]).collect();
        img.write_data(&data).map_err(err)?;
        Ok(())
    })
}

/// A GeoKeyDirectory with GTRasterTypeGeoKey = PixelIsArea (added or replaced).
fn with_pixel_is_area(keys: Option<&[u16]>) -> Vec<u16> {
    let mut entries: Vec<[u16; 4]> = keys
        .and_then(|k| k.get(4..))
        .unwrap_or(&[])
        .chunks_exact(4)
        .filter(|e| e[0] != GT_RASTER_TYPE)
        .map(|e| [e[0], e[1], e[2], e[3]])
        .collect();
    entries.push([GT_RASTER_TYPE, 0, 1, 1]);
    entries.sort_by_key(|e| e[0]);
    let (version, rev, minor) = keys.filter(|k| k.len() >= 4).map_or((1, 1, 0), |k| (k[0], k[1], k[2]));
    let mut out = vec![version, rev, minor, entries.len() as u16];
    out.extend(entries.into_iter().flatten());
    out
}

#[cfg(test)]
mod tests {
    //! Rasters written by GDAL itself (`tests/fixtures/gdal/make.py`, rasterio 1.4.4 / GDAL
    //! 3.10.3), each holding a known formula of (col, row).
    use super::*;

    fn fixture(name: &str) -> Raster {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/gdal").join(name);
        read_raster(&path).unwrap_or_else(|e| panic!("{name}: {e:#}"))
    }

    /// The planner's `f32` heights are the `f64` values rounded, NaN exactly where the raster
    /// says nodata (the declared value, or not finite), with the same size, georeference and
    /// cell size: for float32 (converted in place), int16, float64, LZW tiles read by
    /// lzw_tiles.rs, an ASCII grid and a PDS3 DTM with special pixels.
    #[test]
    fn f32_heights_are_the_f64_values_rounded_with_nodata_as_nan() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
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
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/gdal");
        let err = format!("{:#}", read_raster(&path.join("rotated.tif")).unwrap_err());
        assert!(err.contains("rotated.tif") && err.contains("ModelTransformationTag (34264)"), "{err}");
        // The rotation terms GDAL wrote: 0.2 and 0.1 arc-seconds.
        assert!(err.contains("0.0000555") && err.contains("0.0000277"), "{err}");
        let err = format!("{:#}", read_raster(&path.join("gcps.tif")).unwrap_err());
        assert!(
            err.contains("gcps.tif") && err.contains("ModelTiepointTag (33922) holds 4 tie points"),
            "{err}"
        );
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
        let georef = |d: &mut tiff::encoder::DirectoryEncoder<
            '_,
            BufWriter<File>,
            tiff::encoder::TiffKindStandard,
        >| {
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
}

#[cfg(test)]
mod hostile {
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
        assert!(
            err.contains("claims.tif") && err.contains("3600000000 cells") && err.contains("limit"),
            "{err}"
        );
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
        assert!(
            err.contains("lies.asc") && err.contains("400000000 values") && err.contains("bytes"),
            "{err}"
        );
    }
}
