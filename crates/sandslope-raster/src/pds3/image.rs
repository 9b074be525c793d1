//! The IMAGE object of a PDS3 DTM: its layout (lines, samples, sample type, scaling,
//! MISSING_CONSTANT) and its samples decoded to heights in metres.

use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};

use super::label::{parse_based, parse_number, Label, Value};
use crate::grid::check_raster_size;

/// How samples are stored.
#[derive(Debug, Clone, Copy)]
enum Sample {
    Int { signed: bool, big: bool },
    Real { big: bool },
}

/// A SAMPLE_TYPE by its PDS3 name (appendix C of the Standards Reference).
fn sample_kind(t: &str) -> Option<Sample> {
    Some(match t.replace(' ', "_").as_str() {
        "MSB_INTEGER" | "INTEGER" | "SUN_INTEGER" | "MAC_INTEGER" => Sample::Int { signed: true, big: true },
        "LSB_INTEGER" | "PC_INTEGER" | "VAX_INTEGER" => Sample::Int { signed: true, big: false },
        "MSB_UNSIGNED_INTEGER" | "UNSIGNED_INTEGER" | "SUN_UNSIGNED_INTEGER" | "MAC_UNSIGNED_INTEGER" => {
            Sample::Int { signed: false, big: true }
        }
        "LSB_UNSIGNED_INTEGER" | "PC_UNSIGNED_INTEGER" | "VAX_UNSIGNED_INTEGER" => {
            Sample::Int { signed: false, big: false }
        }
        "IEEE_REAL" | "REAL" | "FLOAT" | "SUN_REAL" | "MAC_REAL" => Sample::Real { big: true },
        "PC_REAL" => Sample::Real { big: false },
        _ => return None,
    })
}

/// The IMAGE object's layout, as the label gives it.
#[derive(Debug, Clone, Copy)]
pub(super) struct Layout {
    /// LINES.
    pub(super) rows: u64,
    /// LINE_SAMPLES.
    pub(super) cols: u64,
    kind: Sample,
    bits: u64,
    /// Bytes per sample.
    bytes: usize,
    /// LINE_PREFIX_BYTES and LINE_SUFFIX_BYTES.
    prefix: u64,
    suffix: u64,
    /// Heights are `add + scale * stored` metres (OFFSET, SCALING_FACTOR and UNIT).
    add: f64,
    scale: f64,
    /// MISSING_CONSTANT as the stored sample's bits (reals) or value (integers).
    missing: Option<(u64, f64)>,
}

/// The IMAGE object's layout from the label; notes a unit converted.
pub(super) fn layout(label: &Label, notes: &mut Vec<String>) -> Result<Layout> {
    let name = &label.name;
    let rows = label.count("IMAGE.LINES", 1, 1 << 31, None)?;
    let cols = label.count("IMAGE.LINE_SAMPLES", 1, 1 << 31, None)?;
    let bands = label.count("IMAGE.BANDS", 1, 1 << 16, Some(1))?;
    if bands != 1 {
        bail!("{name}: IMAGE.BANDS = {bands}; an elevation model must have exactly 1 band");
    }
    let (type_name, type_line) = label
        .word("IMAGE.SAMPLE_TYPE")
        .ok_or_else(|| anyhow!("{name}: the label has no IMAGE.SAMPLE_TYPE"))?;
    let kind = sample_kind(&type_name).ok_or_else(|| {
        anyhow!(
            "{name}: line {type_line}: SAMPLE_TYPE = {type_name} is not supported (MSB_INTEGER, LSB_INTEGER, \
             MSB_UNSIGNED_INTEGER, LSB_UNSIGNED_INTEGER, IEEE_REAL or PC_REAL)"
        )
    })?;
    let bits = label.count("IMAGE.SAMPLE_BITS", 1, 64, None)?;
    let bits_ok = match kind {
        Sample::Int { .. } => matches!(bits, 8 | 16 | 32),
        Sample::Real { .. } => matches!(bits, 32 | 64),
    };
    if !bits_ok {
        bail!(
            "{name}: SAMPLE_BITS = {bits} with SAMPLE_TYPE = {type_name}: integers have 8, 16 or 32 bits, reals 32 or 64"
        );
    }
    let bytes = (bits / 8) as usize;
    let prefix = label.count("IMAGE.LINE_PREFIX_BYTES", 0, 1 << 30, Some(0))?;
    let suffix = label.count("IMAGE.LINE_SUFFIX_BYTES", 0, 1 << 30, Some(0))?;
    let add = label.number("IMAGE.OFFSET")?.map_or(0.0, |v| v.0);
    let scale = label.number("IMAGE.SCALING_FACTOR")?.map_or(1.0, |v| v.0);
    if scale == 0.0 {
        bail!("{name}: IMAGE.SCALING_FACTOR = 0 would make every height {add}");
    }
    let unit = label.word("IMAGE.UNIT");
    let vertical = match unit.as_ref().map(|(u, _)| u.as_str()) {
        None | Some("METER" | "METERS" | "M" | "METRE" | "METRES") => 1.0,
        Some("KILOMETER" | "KILOMETERS" | "KM" | "KILOMETRE" | "KILOMETRES") => {
            notes.push(format!("{name}: heights in kilometres (IMAGE.UNIT) converted to metres"));
            1000.0
        }
        Some(u) => bail!("{name}: IMAGE.UNIT = {u}: heights must be in metres or kilometres"),
    };
    let (add, scale) = (add * vertical, scale * vertical);
    // MISSING_CONSTANT as the stored sample's bits (reals) or value (integers).
    let missing: Option<(u64, f64)> = match label.get("IMAGE.MISSING_CONSTANT") {
        None => None,
        Some((Value::One(item), line)) => {
            let based = parse_based(&item.text);
            let x = parse_number(&item.text).ok_or_else(|| {
                anyhow!("{name}: line {line}: MISSING_CONSTANT = {} is not a number", item.text)
            })?;
            Some(match (kind, bytes, based) {
                (Sample::Real { .. }, 4, Some(b)) => (b, f64::from(f32::from_bits(b as u32))),
                (Sample::Real { .. }, 4, None) => ((x as f32).to_bits().into(), f64::from(x as f32)),
                (Sample::Real { .. }, _, Some(b)) => (b, f64::from_bits(b)),
                (Sample::Real { .. }, _, None) => (x.to_bits(), x),
                (Sample::Int { .. }, _, _) => (0, x),
            })
        }
        Some((v, line)) => bail!("{name}: line {line}: MISSING_CONSTANT = {} must be one number", v.shown()),
    };
    Ok(Layout { rows, cols, kind, bits, bytes, prefix, suffix, add, scale, missing })
}

/// Rows `rows` and columns `cols` of an image (half-open ranges of 0-based lines and samples).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct Window {
    pub(super) rows: std::ops::Range<u64>,
    pub(super) cols: std::ops::Range<u64>,
}

/// The samples of `data_path` from byte `offset`: heights in metres, NaN where missing or
/// special. The file is checked to hold them before anything is allocated; a note says how
/// many cells have no height.
pub(super) fn read_samples(
    layout: &Layout,
    name: &str,
    data_path: &Path,
    offset: u64,
    notes: &mut Vec<String>,
) -> Result<Vec<f64>> {
    let whole = Window { rows: 0..layout.rows, cols: 0..layout.cols };
    let (values, missing_n, special) = read_window(layout, name, data_path, offset, &whole)?;
    if missing_n + special > 0 {
        notes.push(format!(
            "{name}: {} cells without a height (MISSING_CONSTANT: {missing_n}, other ISIS special pixels: {special}) are nodata",
            missing_n + special
        ));
    }
    Ok(values)
}

/// The samples of `window` (row-major, `window.cols` wide), with how many were
/// MISSING_CONSTANT and how many other special pixels. The file is checked to hold the whole
/// image, and the window to lie inside it, before anything is allocated; only the window's
/// bytes are read (the Dask raster reads a DTM larger than memory tile by tile this way).
pub(super) fn read_window(
    layout: &Layout,
    name: &str,
    data_path: &Path,
    offset: u64,
    window: &Window,
) -> Result<(Vec<f64>, usize, usize)> {
    let Layout { rows, cols, kind, bits, bytes, prefix, suffix, add, scale, missing } = *layout;
    // Sizes, checked before anything is allocated.
    let line_bytes = prefix + cols * bytes as u64 + suffix;
    let data_name = data_path.display();
    let file_len = std::fs::metadata(data_path).with_context(|| format!("cannot read {data_name}"))?.len();
    let need = offset.saturating_add(rows.saturating_mul(line_bytes));
    if need > file_len {
        bail!(
            "{name}: LINES = {rows} lines of {line_bytes} bytes (LINE_SAMPLES = {cols} samples of SAMPLE_BITS = \
             {bits}{}) from byte {offset} need {need} bytes, but {data_name} has {file_len}: the label claims more \
             than the file holds (or the file is truncated)",
            if prefix + suffix > 0 { format!(", {prefix} prefix and {suffix} suffix bytes") } else { String::new() }
        );
    }
    let Window { rows: ref wr, cols: ref wc } = *window;
    if wr.start > wr.end || wr.end > rows || wc.start > wc.end || wc.end > cols {
        bail!(
            "{name}: rows {}..{} and columns {}..{} are not a window of the {rows} x {cols} image (LINES x LINE_SAMPLES)",
            wr.start,
            wr.end,
            wc.start,
            wc.end
        );
    }

    // The window's heights (`f64`) and one line's bytes, against the memory limit.
    check_raster_size(&name, wc.end - wc.start, wr.end - wr.start, 8)?;
    // The samples.
    let mut file = BufReader::new(File::open(data_path).with_context(|| format!("cannot read {data_name}"))?);
    let width = (wc.end - wc.start) as usize;
    let mut values = Vec::with_capacity(width * (wr.end - wr.start) as usize);
    let mut buf = vec![0u8; width * bytes];
    // MISSING_CONSTANT as the stored sample's bits, so every type compares the same way.
    let missing_bits: Option<u64> = missing.and_then(|(bits, value)| match kind {
        Sample::Real { .. } => Some(bits),
        _ if value.fract() != 0.0 => None,
        Sample::Int { signed: true, .. } => {
            Some((value as i64 as u64) & (u64::MAX >> (64 - 8 * bytes as u32)))
        }
        Sample::Int { signed: false, .. } => (value >= 0.0).then_some(value as u64),
    });
    let (mut special, mut missing_n) = (0usize, 0usize);
    let mut at = None;
    for r in wr.clone() {
        let start = offset + r * line_bytes + prefix + wc.start * bytes as u64;
        // Consecutive whole lines without prefix or suffix need no seek (BufReader keeps its
        // buffer); otherwise seek to the window's part of the line.
        if at != Some(start) {
            file.seek(SeekFrom::Start(start)).with_context(|| format!("cannot read {data_name}"))?;
        }
        file.read_exact(&mut buf).with_context(|| format!("cannot read {data_name}"))?;
        at = Some(start + buf.len() as u64);
        let (m, sp) = decode(kind, bytes, &buf, missing_bits, (add, scale), &mut values);
        missing_n += m;
        special += sp;
    }
    Ok((values, missing_n, special))
}

/// Decodes one line of samples of `kind` (`bytes` each) onto `out`; returns how many were
/// MISSING_CONSTANT and how many other special pixels.
fn decode(
    kind: Sample,
    bytes: usize,
    line: &[u8],
    missing_bits: Option<u64>,
    (add, scale): (f64, f64),
    out: &mut Vec<f64>,
) -> (usize, usize) {
    let big = match kind {
        Sample::Int { big, .. } | Sample::Real { big } => big,
    };
    // The ISIS special pixels (NULL, LRS, LIS, HIS, HRS) mark cells without a height in
    // HiRISE DTMs: the five most negative finite 32-bit reals (0xFF7FFFFB to 0xFF7FFFFF),
    // their 64-bit twins (0xFFEFFFFFFFFFFFFB to ...FF), and -32768 to -32764 of 16-bit
    // signed integers.
    match (kind, bytes) {
        (Sample::Real { .. }, 4) => decode_line::<4>(
            line,
            big,
            |u| f64::from(f32::from_bits(u as u32)),
            |u| (0xFF7F_FFFB..=0xFF7F_FFFF).contains(&u),
            missing_bits,
            (add, scale),
            out,
        ),
        (Sample::Real { .. }, _) => decode_line::<8>(
            line,
            big,
            f64::from_bits,
            |u| (0xFFEF_FFFF_FFFF_FFFB..=0xFFEF_FFFF_FFFF_FFFF).contains(&u),
            missing_bits,
            (add, scale),
            out,
        ),
        (Sample::Int { signed: true, .. }, 1) => decode_line::<1>(
            line,
            big,
            |u| f64::from(u as u8 as i8),
            |_| false,
            missing_bits,
            (add, scale),
            out,
        ),
        (Sample::Int { signed: true, .. }, 2) => decode_line::<2>(
            line,
            big,
            |u| f64::from(u as u16 as i16),
            |u| (u as u16 as i16) <= -32764,
            missing_bits,
            (add, scale),
            out,
        ),
        (Sample::Int { signed: true, .. }, _) => decode_line::<4>(
            line,
            big,
            |u| f64::from(u as u32 as i32),
            |_| false,
            missing_bits,
            (add, scale),
            out,
        ),
        (Sample::Int { signed: false, .. }, 1) => {
            decode_line::<1>(line, big, |u| u as f64, |_| false, missing_bits, (add, scale), out)
        }
        (Sample::Int { signed: false, .. }, 2) => {
            decode_line::<2>(line, big, |u| u as f64, |_| false, missing_bits, (add, scale), out)
        }
        (Sample::Int { signed: false, .. }, _) => {
            decode_line::<4>(line, big, |u| u as f64, |_| false, missing_bits, (add, scale), out)
        }
    }
}

/// Decodes one line of `N`-byte samples onto `out`: `add + scale value(bits)`, or NaN where the
/// stored bits are MISSING_CONSTANT's or an ISIS special pixel's (`special`). Returns how many
/// were missing and how many special. (Generic over the sample size so each type's loop is
/// compiled on its own: one match per sample made `plan` on a 4096^2 PC_REAL DTM 0.35 s slower
/// than on the same heights as an uncompressed GeoTIFF; now it is as fast.)
fn decode_line<const N: usize>(
    line: &[u8],
    big: bool,
    value: impl Fn(u64) -> f64,
    special: impl Fn(u64) -> bool,
    missing: Option<u64>,
    (add, scale): (f64, f64),
    out: &mut Vec<f64>,
) -> (usize, usize) {
    let (mut m, mut sp) = (0, 0);
    for s in line.chunks_exact(N) {
        let mut b = [0u8; 8];
        let u = if big {
            b[8 - N..].copy_from_slice(s);
            u64::from_be_bytes(b)
        } else {
            b[..N].copy_from_slice(s);
            u64::from_le_bytes(b)
        };
        if missing == Some(u) {
            m += 1;
            out.push(f64::NAN);
        } else if special(u) {
            sp += 1;
            out.push(f64::NAN);
        } else {
            out.push(add + scale * value(u));
        }
    }
    (m, sp)
}
