//! GeoTIFF: reading (with the `tiff` crate: float32/float64 and integer samples, strips or
//! tiles, any compression the crate decodes, the GeoTIFF ModelPixelScale/ModelTiepoint/
//! ModelTransformation and GDAL_NODATA tags), every size a file claims checked before it is
//! allocated, and the two-band float32 writer georeferenced like the input.

use std::fs::File;
use std::io::{BufReader, BufWriter};
use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};
use tiff::decoder::{Decoder, DecodingResult, Limits};
use tiff::encoder::{colortype::Gray32Float, compression::DeflateLevel, Compression, TiffEncoder};
use tiff::tags::{ExtraSamples, Tag};

use super::chunks;
use super::grid::{check_raster_size, memory_limit, GeoRef, Raster, SizeCheck};

/// The largest GeoTIFF tag value (GeoKeys, strip offsets, ...) read, in bytes. A tag whose
/// count claims more is refused before its value is allocated.
pub const MAX_TIFF_TAG_BYTES: usize = 16 << 20;

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

/// The decoder's limits: the image at most the memory limit ([`memory_limit`]), any tag value
/// at most [`MAX_TIFF_TAG_BYTES`].
fn tiff_limits() -> Limits {
    let mut limits = Limits::default();
    limits.decoding_buffer_size = usize::try_from(memory_limit().0).unwrap_or(usize::MAX);
    limits.ifd_value_size = MAX_TIFF_TAG_BYTES;
    limits
}

/// GeoKey GTRasterTypeGeoKey and its value RasterPixelIsPoint.
const GT_RASTER_TYPE: u16 = 1025;
const PIXEL_IS_POINT: u16 = 2;

/// A GeoTIFF (its `values` left empty), the factor converting its heights to metres, and its
/// decoded samples; `out_bytes` a cell are what the caller converts the samples to (8 for
/// `f64` values, 4 for `f32` heights, converted in place from float32 samples), checked with
/// the samples against the memory limit.
pub(super) fn read_geotiff(
    path: &Path,
    fits: SizeCheck,
    out_bytes: u64,
) -> Result<(Raster, f64, DecodingResult)> {
    let name = path.display();
    let mut dec = open_full_resolution(path)?;
    let (w, h) = dec.dimensions().map_err(|e| anyhow!("{name}: {e}"))?;
    let bits: u64 = dec.find_tag_unsigned(Tag::BitsPerSample).ok().flatten().unwrap_or(64);
    let in_place = out_bytes == 4 && bits == 32;
    fits(w as usize, h as usize)?;
    check_raster_size(
        &name,
        u64::from(w),
        u64::from(h),
        bits.max(8) / 8 + if in_place { 0 } else { out_bytes },
    )?;
    let (raster, vertical) = header(path, &mut dec)?;
    let image = decode_samples(&name, path, &mut dec, bits)?;
    Ok((raster, vertical, image))
}

/// A GeoTIFF's raster (its `values` left empty) and the factor converting its heights to
/// metres, from its directory alone: no sample is read.
pub(super) fn read_geotiff_header(path: &Path) -> Result<(Raster, f64)> {
    header(path, &mut open_full_resolution(path)?)
}

/// The raster and vertical factor of the image `dec` is at (see [`read_geotiff_header`]).
fn header(path: &Path, dec: &mut Decoder<BufReader<File>>) -> Result<(Raster, f64)> {
    let name = path.display();
    let (w, h) = dec.dimensions().map_err(|e| anyhow!("{name}: {e}"))?;
    let bits: u64 = dec.find_tag_unsigned(Tag::BitsPerSample).ok().flatten().unwrap_or(64);
    let file_bytes = std::fs::metadata(path).with_context(|| format!("cannot read {name}"))?.len();
    check_claimed_bytes(&name, u64::from(w), u64::from(h), bits, file_bytes)?;
    let samples: u16 = dec.find_tag_unsigned(Tag::SamplesPerPixel).ok().flatten().unwrap_or(1);
    if samples != 1 {
        bail!("{name}: has {samples} bands (SamplesPerPixel = {samples}); an elevation or class raster must have exactly 1");
    }
    let tags = GeoTags::read(&name, dec)?;
    let (west, north, cell_x, cell_y) = tags.origin_and_cell(&name)?;
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
    Ok((raster, vertical))
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
pub(super) fn open_full_resolution(path: &Path) -> Result<Decoder<BufReader<File>>> {
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
pub(super) fn samples_as<T>(
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
    sandslope_files::write_output(path, |file| {
        let err = |e: tiff::TiffError| anyhow!("{name}: {e}");
        let mut enc = TiffEncoder::new(BufWriter::new(file))
            .map_err(err)?
            .with_compression(Compression::Deflate(DeflateLevel::default()));
        let (w, h) = (u32::try_from(cols)?, u32::try_from(rows)?);
        let mut img = enc.new_image::<Gray32Float>(w, h).map_err(err)?;
        img.extra_samples(&[ExtraSamples::Unspecified]).map_err(err)?;
        write_geo_tags(img.encoder(), geo).map_err(err)?;
        let data: Vec<f32> = band1.iter().zip(band2).flat_map(|(&a, &b)| [a, b]).collect();
        img.write_data(&data).map_err(err)?;
        Ok(())
    })
}

/// The georeference tags of a raster written like `geo`'s input (pixel scale, tie point,
/// GeoKeys with PixelIsArea, their parameters) and GDAL's nodata, NaN.
pub(super) fn write_geo_tags<W: std::io::Write + std::io::Seek, K: tiff::encoder::TiffKind>(
    d: &mut tiff::encoder::DirectoryEncoder<'_, W, K>,
    geo: &GeoRef,
) -> tiff::TiffResult<()> {
    d.write_tag(Tag::ModelPixelScaleTag, &[geo.cell_x, geo.cell_y, 0.0][..])?;
    d.write_tag(Tag::ModelTiepointTag, &[0.0, 0.0, 0.0, geo.west, geo.north, 0.0][..])?;
    // Our tie point is the corner of the corner cell: declare PixelIsArea, keep the rest.
    let keys = with_pixel_is_area(geo.geokeys.as_deref());
    d.write_tag(Tag::GeoKeyDirectoryTag, &keys[..])?;
    if let Some(dbl) = &geo.geodoubles {
        d.write_tag(Tag::GeoDoubleParamsTag, &dbl[..])?;
    }
    if let Some(a) = &geo.geoascii {
        d.write_tag(Tag::GeoAsciiParamsTag, a.as_str())?;
    }
    d.write_tag(Tag::GdalNodata, "nan")
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
