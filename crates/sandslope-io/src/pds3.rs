//! PDS3 `.IMG` elevation models as HiRISE publishes its DTMs (issue 24): an ODL label
//! attached at the start of the `.IMG` or detached beside it (`.LBL`), one band of
//! `SAMPLE_TYPE`/`SAMPLE_BITS` samples (MSB/LSB integers, signed or unsigned, 8 to 32 bits;
//! IEEE or PC reals, 32 or 64 bits) with `OFFSET`/`SCALING_FACTOR`, `MISSING_CONSTANT` and the
//! ISIS special pixels as nodata, and the `IMAGE_MAP_PROJECTION` (equirectangular or polar
//! stereographic on the body's sphere `A_AXIS_RADIUS`, `MAP_SCALE` metres per pixel).
//!
//! Written from the PDS3 Standards Reference (chapter 5 pointers, chapter 12 ODL, appendix C
//! data types); the projection offsets are read as the standard defines them (and as GDAL's
//! PDS driver and ISIS read them): the centre of the pixel in 0-based column `c` and line `l`
//! is at `x = (c - SAMPLE_PROJECTION_OFFSET) MAP_SCALE`, `y = (LINE_PROJECTION_OFFSET - l)
//! MAP_SCALE`. Every size a label claims is checked against the file before anything is
//! allocated, and every error names the file, the key and its value.

use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context, Result};

use crate::crs::Crs;
use crate::raster::{check_raster_size, GeoRef, Raster};

/// The largest PDS3 label read, in bytes (a HiRISE DTM's is about 10 KB).
pub const MAX_LABEL_BYTES: u64 = 1 << 20;

/// Lists nested deeper than this are refused (a label is not a program).
const MAX_NESTING: usize = 16;

/// Whether the file at `path` begins with a PDS3 label (`PDS_VERSION_ID`, or the SFDU line
/// `CCSD3ZF0000100000001NJPL3IF0PDS200000001 = SFDU_LABEL` older products put before it).
pub fn starts_with_label(path: &Path) -> bool {
    let mut head = [0u8; 32];
    File::open(path).and_then(|mut f| f.read(&mut head)).is_ok_and(|n| {
        let text = String::from_utf8_lossy(&head[..n]).trim_start().to_ascii_uppercase();
        text.starts_with("PDS_VERSION_ID") || text.starts_with("CCSD3ZF")
    })
}

/// One value of a label statement: its text (quotes removed) and its `<unit>`, if any.
#[derive(Debug, Clone)]
struct Item {
    text: String,
    unit: Option<String>,
    quoted: bool,
}

/// A statement's value: one item, or a list `(a, b)` / set `{a, b}` (nested lists flattened).
#[derive(Debug, Clone)]
enum Value {
    One(Item),
    List(Vec<Item>),
}

impl Value {
    /// The value as written, for messages.
    fn shown(&self) -> String {
        let item = |i: &Item| {
            let t = if i.quoted { format!("\"{}\"", i.text) } else { i.text.clone() };
            match &i.unit {
                Some(u) => format!("{t} <{u}>"),
                None => t,
            }
        };
        match self {
            Value::One(i) => item(i),
            Value::List(v) => format!("({})", v.iter().map(item).collect::<Vec<_>>().join(", ")),
        }
    }
}

/// A parsed label: `(path, value, line)` with the path the enclosing OBJECT/GROUP names and
/// the keyword joined by dots (`IMAGE.LINES`, `IMAGE_MAP_PROJECTION.MAP_SCALE`).
struct Label {
    name: String,
    entries: Vec<(String, Value, usize)>,
}

impl Label {
    /// The first statement whose path is `key` or ends with `.key`.
    fn get(&self, key: &str) -> Option<(&Value, usize)> {
        let dotted = format!(".{key}");
        self.entries.iter().find(|(p, _, _)| p == key || p.ends_with(&dotted)).map(|(_, v, l)| (v, *l))
    }

    /// A numeric value and its unit (upper case), or None when the key is absent.
    fn number(&self, key: &str) -> Result<Option<(f64, Option<String>)>> {
        let Some((value, line)) = self.get(key) else { return Ok(None) };
        let Value::One(item) = value else {
            bail!("{}: line {line}: {key} = {} must be one number", self.name, value.shown());
        };
        let x = parse_number(&item.text).ok_or_else(|| {
            anyhow!("{}: line {line}: {key} = {} is not a number", self.name, value.shown())
        })?;
        Ok(Some((x, item.unit.as_ref().map(|u| u.to_ascii_uppercase()))))
    }

    /// A required numeric value and its unit.
    fn need_number(&self, key: &str, why: &str) -> Result<(f64, Option<String>)> {
        self.number(key)?.ok_or_else(|| anyhow!("{}: the label has no {key} ({why})", self.name))
    }

    /// A whole number in `min..=max`, or `default` when absent.
    fn count(&self, key: &str, min: u64, max: u64, default: Option<u64>) -> Result<u64> {
        match self.number(key)? {
            Some((x, _)) if x.fract() == 0.0 && x >= min as f64 && x <= max as f64 => Ok(x as u64),
            Some((x, _)) => {
                let line = self.get(key).map_or(0, |(_, l)| l);
                bail!("{}: line {line}: {key} = {x} must be a whole number from {min} to {max}", self.name)
            }
            None => default.ok_or_else(|| anyhow!("{}: the label has no {key}", self.name)),
        }
    }

    /// A keyword value (upper case, quotes removed), or None.
    fn word(&self, key: &str) -> Option<(String, usize)> {
        match self.get(key)? {
            (Value::One(i), line) => Some((i.text.trim().to_ascii_uppercase(), line)),
            (Value::List(_), _) => None,
        }
    }
}

/// A PDS3 number: decimal, or based integer `radix#digits#` (`16#FF7FFFFB#`).
fn parse_number(text: &str) -> Option<f64> {
    parse_based(text).map(|v| v as f64).or_else(|| text.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
}

/// A based integer `radix#digits#` as its bits.
fn parse_based(text: &str) -> Option<u64> {
    let t = text.trim();
    let (radix, rest) = t.split_once('#')?;
    let digits = rest.strip_suffix('#')?;
    let radix: u32 = radix.parse().ok().filter(|r| (2..=16).contains(r))?;
    u64::from_str_radix(digits, radix).ok()
}

/// The ODL tokenizer's position in the label text.
struct Cursor<'a> {
    b: &'a [u8],
    pos: usize,
    line: usize,
}

impl Cursor<'_> {
    fn peek(&self) -> Option<u8> {
        self.b.get(self.pos).copied()
    }
    fn bump(&mut self) -> Option<u8> {
        let c = self.peek()?;
        self.pos += 1;
        if c == b'\n' {
            self.line += 1;
        }
        Some(c)
    }
    /// Skips white space and `/* comments */`.
    fn skip_space(&mut self) {
        loop {
            match self.peek() {
                Some(c) if c.is_ascii_whitespace() || c == 0 => {
                    self.bump();
                }
                Some(b'/') if self.b.get(self.pos + 1) == Some(&b'*') => {
                    self.pos += 2;
                    while self.pos < self.b.len() && !self.b[self.pos..].starts_with(b"*/") {
                        self.bump();
                    }
                    self.pos = (self.pos + 2).min(self.b.len());
                }
                _ => return,
            }
        }
    }
    /// A bare word: up to white space or punctuation.
    fn word(&mut self) -> String {
        let start = self.pos;
        while let Some(c) = self.peek() {
            if c.is_ascii_whitespace() || b"=,(){}<>\"'".contains(&c) || c == 0 {
                break;
            }
            self.pos += 1;
        }
        String::from_utf8_lossy(&self.b[start..self.pos]).into_owned()
    }
}

/// Parses an ODL label up to its `END` statement.
fn parse_label(name: &str, text: &[u8]) -> Result<Label> {
    let mut c = Cursor { b: text, pos: 0, line: 1 };
    let mut stack: Vec<String> = Vec::new();
    let mut entries = Vec::new();
    loop {
        c.skip_space();
        let line = c.line;
        if c.peek().is_none() {
            bail!(
                "{name}: the PDS3 label has no END statement in its first {} bytes (not a PDS3 label, or truncated)",
                text.len()
            );
        }
        let key = c.word().to_ascii_uppercase();
        if key.is_empty() {
            bail!(
                "{name}: line {line}: expected a keyword, found `{}`",
                char::from(c.peek().unwrap_or(b' '))
            );
        }
        if key == "END" {
            return Ok(Label { name: name.to_owned(), entries });
        }
        c.skip_space();
        if key == "END_OBJECT" || key == "END_GROUP" {
            if c.peek() == Some(b'=') {
                c.bump();
                c.skip_space();
                c.word();
            }
            if stack.pop().is_none() {
                bail!("{name}: line {line}: {key} without an OBJECT or GROUP to end");
            }
            continue;
        }
        if c.bump() != Some(b'=') {
            bail!("{name}: line {line}: keyword `{key}` is not followed by `=`");
        }
        c.skip_space();
        let value = parse_value(name, &mut c, 0)?;
        if key == "OBJECT" || key == "GROUP" {
            let Value::One(item) = &value else {
                bail!("{name}: line {line}: {key} = {} must be a name", value.shown());
            };
            stack.push(item.text.to_ascii_uppercase());
            continue;
        }
        let path = if stack.is_empty() { key } else { format!("{}.{key}", stack.join(".")) };
        entries.push((path, value, line));
    }
}

/// One value: a quoted string, a list or set, or a bare word; then an optional `<unit>`.
fn parse_value(name: &str, c: &mut Cursor, depth: usize) -> Result<Value> {
    if depth > MAX_NESTING {
        bail!("{name}: line {}: lists nested more than {MAX_NESTING} deep", c.line);
    }
    let line = c.line;
    match c.peek() {
        Some(open @ (b'(' | b'{')) => {
            c.bump();
            let close = if open == b'(' { b')' } else { b'}' };
            let mut items: Vec<Item> = Vec::new();
            loop {
                c.skip_space();
                match c.peek() {
                    Some(b',') => {
                        c.bump();
                    }
                    Some(x) if x == close => {
                        c.bump();
                        // A unit after the list (`(450, 550) <NM>`) applies to every item.
                        if let Some(u) = unit(c) {
                            for i in items.iter_mut().filter(|i| i.unit.is_none()) {
                                i.unit = Some(u.clone());
                            }
                        }
                        return Ok(Value::List(items));
                    }
                    None => bail!("{name}: line {line}: a list opened here is never closed"),
                    Some(_) => match parse_value(name, c, depth + 1)? {
                        Value::One(i) => items.push(i),
                        Value::List(v) => items.extend(v),
                    },
                }
            }
        }
        Some(q @ (b'"' | b'\'')) => {
            c.bump();
            let start = c.pos;
            while c.peek().is_some_and(|x| x != q) {
                c.bump();
            }
            if c.peek().is_none() {
                bail!("{name}: line {line}: a quoted value opened here is never closed");
            }
            let text =
                String::from_utf8_lossy(&c.b[start..c.pos]).split_whitespace().collect::<Vec<_>>().join(" ");
            c.bump();
            Ok(Value::One(Item { text, unit: unit(c), quoted: true }))
        }
        _ => {
            let text = c.word();
            if text.is_empty() {
                bail!("{name}: line {line}: a keyword has no value");
            }
            Ok(Value::One(Item { text, unit: unit(c), quoted: false }))
        }
    }
}

/// An optional `<unit>` after a value, on the same line.
fn unit(c: &mut Cursor) -> Option<String> {
    while c.peek().is_some_and(|x| x == b' ' || x == b'\t') {
        c.bump();
    }
    if c.peek() != Some(b'<') {
        return None;
    }
    c.bump();
    let start = c.pos;
    while c.peek().is_some_and(|x| x != b'>' && x != b'\n') {
        c.bump();
    }
    let u = String::from_utf8_lossy(&c.b[start..c.pos]).trim().to_owned();
    if c.peek() == Some(b'>') {
        c.bump();
    }
    Some(u)
}

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

/// Where the image's bytes are: the file and the byte offset of its first line.
fn image_location(label: &Label, label_path: &Path, attached: bool) -> Result<(PathBuf, u64)> {
    let name = &label.name;
    let record_bytes = || -> Result<u64> {
        label
            .count("RECORD_BYTES", 1, 1 << 32, None)
            .context("a ^IMAGE pointer in records needs RECORD_BYTES")
    };
    // A pointer `n` (records, 1-based) or `n <BYTES>` (bytes, 1-based).
    let offset_of = |item: &Item, shown: &str| -> Result<u64> {
        let n =
            item.text.trim().parse::<u64>().ok().filter(|&n| n >= 1).ok_or_else(|| {
                anyhow!("{name}: ^IMAGE = {shown}: the pointer must be a whole number from 1")
            })?;
        match item.unit.as_deref().map(str::to_ascii_uppercase).as_deref() {
            Some("BYTES" | "BYTE") => Ok(n - 1),
            None => Ok((n - 1).saturating_mul(record_bytes()?)),
            Some(u) => bail!("{name}: ^IMAGE = {shown}: unknown pointer unit <{u}> (records, or <BYTES>)"),
        }
    };
    let dir = label_path.parent().unwrap_or(Path::new("."));
    let Some((value, _)) = label.get("^IMAGE") else {
        if !attached {
            bail!("{name}: the label has no ^IMAGE pointer to the image's file");
        }
        // No pointer: the image follows the label records.
        let records = label.count("LABEL_RECORDS", 1, 1 << 32, None).context("no ^IMAGE pointer")?;
        return Ok((label_path.to_path_buf(), records.saturating_mul(record_bytes()?)));
    };
    let shown = value.shown();
    match value {
        Value::One(item) if item.quoted => Ok((data_file(name, dir, &item.text, &shown)?, 0)),
        Value::One(item) => Ok((label_path.to_path_buf(), offset_of(item, &shown)?)),
        Value::List(items) => match items.as_slice() {
            [file, at] if file.quoted => {
                Ok((data_file(name, dir, &file.text, &shown)?, offset_of(at, &shown)?))
            }
            [file] if file.quoted => Ok((data_file(name, dir, &file.text, &shown)?, 0)),
            _ => bail!("{name}: ^IMAGE = {shown}: expected n, n <BYTES>, \"FILE\" or (\"FILE\", n)"),
        },
    }
}

/// The file a detached pointer names, beside the label (its name's case as given, lower or
/// upper: labels name `FILE.IMG` for a `file.img` often enough).
fn data_file(name: &str, dir: &Path, file: &str, shown: &str) -> Result<PathBuf> {
    if file.contains('/') || file.contains('\\') {
        bail!("{name}: ^IMAGE = {shown}: the file must lie beside the label (no folders)");
    }
    let ext = Path::new(file).extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if matches!(ext.as_str(), "tif" | "tiff") {
        bail!("{name}: ^IMAGE = {shown} is a GeoTIFF: give sandslope the .tif itself");
    }
    if matches!(ext.as_str(), "jp2" | "jpg" | "png") {
        bail!("{name}: ^IMAGE = {shown}: a .{ext} image is not an elevation model sandslope reads");
    }
    for candidate in [file.to_owned(), file.to_ascii_lowercase(), file.to_ascii_uppercase()] {
        let p = dir.join(&candidate);
        if p.is_file() {
            return Ok(p);
        }
    }
    bail!("{name}: ^IMAGE = {shown}: no such file beside the label in {}", dir.display())
}

/// The label's file and text: the file itself when it begins with `PDS_VERSION_ID` (an
/// attached label, or a detached `.lbl`), else the `.lbl` beside it.
fn find_label(path: &Path) -> Result<(PathBuf, Vec<u8>, bool)> {
    let name = path.display();
    let label_path = if starts_with_label(path) {
        path.to_path_buf()
    } else if !path.is_file() {
        bail!("cannot read {name}: no such file");
    } else {
        let mut head = [0u8; 15];
        if File::open(path).and_then(|mut f| f.read_exact(&mut head)).is_ok() && &head == b"EHFA_HEADER_TAG" {
            bail!(
                "{name}: an ERDAS IMAGINE .img, not a PDS3 DTM; convert it to a GeoTIFF first (gdal_translate -of GTiff)"
            );
        }
        let found = ["lbl", "LBL"].iter().map(|e| path.with_extension(e)).find(|p| p.is_file() && p != path);
        found.ok_or_else(|| {
            anyhow!(
                "{name}: not a PDS3 file: it does not begin with a label (PDS_VERSION_ID) and there is no {} beside it",
                path.with_extension("lbl").file_name().map_or_else(String::new, |f| f.to_string_lossy().into_owned())
            )
        })?
    };
    let mut text = Vec::new();
    File::open(&label_path)
        .with_context(|| format!("cannot read {}", label_path.display()))?
        .take(MAX_LABEL_BYTES)
        .read_to_end(&mut text)
        .with_context(|| format!("cannot read {}", label_path.display()))?;
    let attached = label_path == path && !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("lbl"));
    Ok((label_path, text, attached))
}

/// Reads a PDS3 DTM (`path` the `.IMG` with its label attached or a `.LBL` beside it, or the
/// `.LBL`): heights in metres (NaN where missing or special), the map georeferencing in
/// projected metres, and the ground cell size in metres.
pub fn read_pds3(path: &Path) -> Result<Raster> {
    let (label_path, text, attached) = find_label(path)?;
    let label = parse_label(&label_path.display().to_string(), &text)?;
    let name = label.name.clone();
    let (data_path, offset) = image_location(&label, &label_path, attached)?;

    // The image object.
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
    let mut notes = Vec::new();
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

    // Sizes, checked before anything is allocated.
    check_raster_size(&name, cols, rows)?;
    let line_bytes = prefix + cols * bytes as u64 + suffix;
    let data_name = data_path.display();
    let file_len = std::fs::metadata(&data_path).with_context(|| format!("cannot read {data_name}"))?.len();
    let need = offset.saturating_add(rows.saturating_mul(line_bytes));
    if need > file_len {
        bail!(
            "{name}: LINES = {rows} lines of {line_bytes} bytes (LINE_SAMPLES = {cols} samples of SAMPLE_BITS = \
             {bits}{}) from byte {offset} need {need} bytes, but {data_name} has {file_len}: the label claims more \
             than the file holds (or the file is truncated)",
            if prefix + suffix > 0 { format!(", {prefix} prefix and {suffix} suffix bytes") } else { String::new() }
        );
    }

    // The samples.
    let mut file =
        BufReader::new(File::open(&data_path).with_context(|| format!("cannot read {data_name}"))?);
    file.seek(SeekFrom::Start(offset)).with_context(|| format!("cannot read {data_name}"))?;
    let (cols_n, rows_n) = (cols as usize, rows as usize);
    let mut values = Vec::with_capacity(cols_n * rows_n);
    let mut buf = vec![0u8; line_bytes as usize];
    // MISSING_CONSTANT as the stored sample's bits, so every type compares the same way.
    let missing_bits: Option<u64> = missing.and_then(|(bits, value)| match kind {
        Sample::Real { .. } => Some(bits),
        _ if value.fract() != 0.0 => None,
        Sample::Int { signed: true, .. } => {
            Some((value as i64 as u64) & (u64::MAX >> (64 - 8 * bytes as u32)))
        }
        Sample::Int { signed: false, .. } => (value >= 0.0).then_some(value as u64),
    });
    let big = match kind {
        Sample::Int { big, .. } | Sample::Real { big } => big,
    };
    let (mut special, mut missing_n) = (0usize, 0usize);
    for _ in 0..rows_n {
        file.read_exact(&mut buf).with_context(|| format!("cannot read {data_name}"))?;
        let line = &buf[prefix as usize..prefix as usize + cols_n * bytes];
        let out = &mut values;
        // The ISIS special pixels (NULL, LRS, LIS, HIS, HRS) mark cells without a height in
        // HiRISE DTMs: the five most negative finite 32-bit reals (0xFF7FFFFB to 0xFF7FFFFF),
        // their 64-bit twins (0xFFEFFFFFFFFFFFFB to ...FF), and -32768 to -32764 of 16-bit
        // signed integers.
        let (m, sp) = match (kind, bytes) {
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
        };
        missing_n += m;
        special += sp;
    }
    if missing_n + special > 0 {
        notes.push(format!(
            "{name}: {} cells without a height (MISSING_CONSTANT: {missing_n}, other ISIS special pixels: {special}) are nodata",
            missing_n + special
        ));
    }

    // The map.
    let map = |key: &str| format!("IMAGE_MAP_PROJECTION.{key}");
    if !label
        .entries
        .iter()
        .any(|(p, _, _)| p.starts_with("IMAGE_MAP_PROJECTION.") || p.contains(".IMAGE_MAP_PROJECTION."))
    {
        bail!(
            "{name}: the label has no IMAGE_MAP_PROJECTION object (MAP_SCALE, the projection): the planner needs \
             the cell size in metres"
        );
    }
    let (ptype, pline) = label
        .word(&map("MAP_PROJECTION_TYPE"))
        .ok_or_else(|| anyhow!("{name}: the label has no IMAGE_MAP_PROJECTION.MAP_PROJECTION_TYPE"))?;
    let projection = ptype.replace([' ', '_'], "");
    if !matches!(projection.as_str(), "EQUIRECTANGULAR" | "POLARSTEREOGRAPHIC") {
        bail!(
            "{name}: line {pline}: MAP_PROJECTION_TYPE = {ptype} is not supported (EQUIRECTANGULAR or \
             POLARSTEREOGRAPHIC, the projections of HiRISE DTMs); reproject it (gdalwarp) to one of those or to a GeoTIFF"
        );
    }
    if let Some((rot, _)) = label.number(&map("MAP_PROJECTION_ROTATION"))? {
        if rot != 0.0 {
            bail!("{name}: MAP_PROJECTION_ROTATION = {rot}: rotated maps are not supported (north-up only)");
        }
    }
    let (radius, runit) = label.need_number(&map("A_AXIS_RADIUS"), "the body's radius")?;
    let radius_m = match runit.as_deref() {
        None | Some("KM" | "KILOMETERS" | "KILOMETER") => radius * 1000.0,
        Some("M" | "METERS" | "METER" | "METRES" | "METRE") => radius,
        Some(u) => bail!("{name}: A_AXIS_RADIUS = {radius} <{u}>: the unit must be KM or M"),
    };
    if !(1e3..=1e8).contains(&radius_m) {
        bail!("{name}: A_AXIS_RADIUS = {radius} ({radius_m} m) must be from 1 to 100000 km");
    }
    let (map_scale, sunit) = label.need_number(&map("MAP_SCALE"), "the cell size")?;
    let cell = match sunit.as_deref().map(|u| u.replace(' ', "")).as_deref() {
        Some("METERS/PIXEL" | "METERS/PIX" | "M/PIXEL" | "M/PIX" | "METERS" | "M" | "METRES/PIXEL") => {
            map_scale
        }
        Some("KM/PIXEL" | "KM/PIX" | "KM" | "KILOMETERS/PIXEL") => map_scale * 1000.0,
        None => {
            notes.push(format!(
                "{name}: MAP_SCALE = {map_scale} has no unit: taken as the PDS3 standard's KM/PIXEL ({} m cells)",
                map_scale * 1000.0
            ));
            map_scale * 1000.0
        }
        Some(u) => bail!("{name}: MAP_SCALE = {map_scale} <{u}>: the unit must be METERS/PIXEL or KM/PIXEL"),
    };
    if !(cell.is_finite() && cell > 0.0) {
        bail!("{name}: MAP_SCALE = {map_scale} must be a number greater than 0");
    }
    let (lpo, _) = label.need_number(&map("LINE_PROJECTION_OFFSET"), "where the map's origin is")?;
    let (spo, _) = label.need_number(&map("SAMPLE_PROJECTION_OFFSET"), "where the map's origin is")?;
    let (clat, _) = label.need_number(&map("CENTER_LATITUDE"), "the projection's latitude")?;
    let west = -(spo + 0.5) * cell;
    let north = (lpo + 0.5) * cell;
    let south = north - rows as f64 * cell;
    let body = body_name(&label, radius_m);
    let cell_m = if projection == "EQUIRECTANGULAR" {
        if clat.abs() >= 89.0 {
            bail!("{name}: CENTER_LATITUDE = {clat}: an equirectangular DTM's must lie within 89 degrees of the equator");
        }
        // y = R lat: the rows' latitudes; east-west, MAP_SCALE is true at CENTER_LATITUDE.
        let lat = |y: f64| (y / radius_m).to_degrees();
        let (lat_n, lat_s) = (lat(north), lat(south));
        if lat_n.abs() >= 89.0 || lat_s.abs() >= 89.0 {
            bail!(
                "{name}: LINE_PROJECTION_OFFSET = {lpo} puts the rows at latitudes {lat_s:.3} to {lat_n:.3} degrees: \
                 an equirectangular DTM must lie within 89 degrees of the equator"
            );
        }
        let mid = 0.5 * (lat_n + lat_s);
        let east = |phi: f64| cell * phi.to_radians().cos() / clat.to_radians().cos();
        let gx = east(mid);
        let vary = (1.0 - east(lat_n) / gx).abs().max((1.0 - east(lat_s) / gx).abs());
        notes.push(format!(
            "{name}: PDS3 equirectangular map on {body} (sphere of radius {radius_m} m): MAP_SCALE {cell} m is true \
             east-west at CENTER_LATITUDE {clat} degrees; cells taken as {gx:.4} x {cell} m at the mid-latitude \
             {mid:.4} degrees (the east-west size varies by up to {:.3}% across the rows{})",
            100.0 * vary,
            if vary > 0.005 { ": more than 0.5%, crop the DTM for exact lengths" } else { "" }
        ));
        (gx, cell)
    } else {
        if (clat.abs() - 90.0).abs() > 1e-9 {
            bail!(
                "{name}: CENTER_LATITUDE = {clat}: only polar stereographic maps centred on a pole (CENTER_LATITUDE \
                 = 90 or -90) are supported"
            );
        }
        // Scale factor of the polar stereographic on a sphere, true at the pole: k = 2 / (1 +
        // sin|lat|), |lat| = 90 - 2 atan(rho / 2R) degrees.
        let k_at = |x: f64, y: f64| {
            let colat = 2.0 * (x.hypot(y) / (2.0 * radius_m)).atan();
            2.0 / (1.0 + colat.cos())
        };
        let east_edge = west + cols as f64 * cell;
        let k = k_at(0.5 * (west + east_edge), 0.5 * (north + south));
        let corners = [(west, north), (east_edge, north), (west, south), (east_edge, south)];
        let vary = corners.iter().map(|&(x, y)| (1.0 - k / k_at(x, y)).abs()).fold(0.0, f64::max);
        let g = cell / k;
        notes.push(format!(
            "{name}: PDS3 polar stereographic map about the {} pole of {body} (sphere of radius {radius_m} m): \
             MAP_SCALE {cell} m is true at the pole; cells taken as {g:.4} x {g:.4} m at the DTM's centre (scale \
             factor {k:.6}; the cell size varies by up to {:.3}% across the DTM{})",
            if clat > 0.0 { "north" } else { "south" },
            100.0 * vary,
            if vary > 0.005 { ": more than 0.5%, crop the DTM for exact lengths" } else { "" }
        ));
        (g, g)
    };
    let clon = label.number(&map("CENTER_LONGITUDE"))?.map_or(0.0, |v| v.0);
    let (keys, doubles, ascii) = geokeys(&projection, radius_m, clat, clon, &body);
    let geo = GeoRef::north_up((west, north, cell, cell), keys, doubles, ascii);
    Ok(Raster {
        cols: cols_n,
        rows: rows_n,
        values,
        nodata: None,
        geo,
        crs: Crs::Projected { metres_per_unit: 1.0, unit: "metre" },
        cell_m,
        notes,
    })
}

/// GeoTIFF keys (OGC 19-008r4) of the map's projected CRS, user-defined on the body's sphere,
/// so that a GeoTIFF written over a PDS3 DTM (`plan --risk-map`) carries its projection: the
/// GeoKeyDirectory, GeoDoubleParams and GeoAsciiParams. Equirectangular is CT_Equirectangular
/// (17) with the standard parallel CENTER_LATITUDE and latitude of origin 0 (y = R lat); polar
/// stereographic is CT_PolarStereographic (15) with origin at the pole and scale 1 there.
fn geokeys(
    projection: &str,
    radius_m: f64,
    clat: f64,
    clon: f64,
    body: &str,
) -> (Vec<u16>, Vec<f64>, String) {
    const USER: u16 = 32767;
    const DOUBLES: u16 = 34736;
    const ASCII: u16 = 34737;
    let equi = projection == "EQUIRECTANGULAR";
    let citation = format!("{} {body}|", if equi { "Equirectangular" } else { "Polar Stereographic" });
    let geog = format!("GCS {body} sphere|");
    let ascii = format!("{citation}{geog}");
    let mut doubles = vec![radius_m, radius_m];
    let mut entries: Vec<[u16; 4]> = vec![
        [1024, 0, 1, 1], // GTModelTypeGeoKey: projected
        [1025, 0, 1, 1], // GTRasterTypeGeoKey: PixelIsArea
        [1026, ASCII, citation.len() as u16, 0],
        [2048, 0, 1, USER], // GeographicTypeGeoKey
        [2049, ASCII, geog.len() as u16, citation.len() as u16],
        [2050, 0, 1, USER],                       // GeogGeodeticDatumGeoKey
        [2054, 0, 1, 9102],                       // GeogAngularUnitsGeoKey: degree
        [2056, 0, 1, USER],                       // GeogEllipsoidGeoKey
        [2057, DOUBLES, 1, 0],                    // GeogSemiMajorAxisGeoKey
        [2058, DOUBLES, 1, 1],                    // GeogSemiMinorAxisGeoKey
        [3072, 0, 1, USER],                       // ProjectedCSTypeGeoKey
        [3074, 0, 1, USER],                       // ProjectionGeoKey
        [3075, 0, 1, if equi { 17 } else { 15 }], // ProjCoordTransGeoKey
        [3076, 0, 1, 9001],                       // ProjLinearUnitsGeoKey: metre
    ];
    let mut param = |key: u16, v: f64| {
        entries.push([key, DOUBLES, 1, doubles.len() as u16]);
        doubles.push(v);
    };
    param(3082, 0.0); // ProjFalseEastingGeoKey
    param(3083, 0.0); // ProjFalseNorthingGeoKey
    if equi {
        param(3078, clat); // ProjStdParallel1GeoKey
        param(3088, clon); // ProjCenterLongGeoKey
        param(3089, 0.0); // ProjCenterLatGeoKey
    } else {
        param(3081, clat); // ProjNatOriginLatGeoKey: the pole
        param(3092, 1.0); // ProjScaleAtNatOriginGeoKey
        param(3095, clon); // ProjStraightVertPoleLongGeoKey
    }
    entries.sort_by_key(|e| e[0]);
    let mut dir = vec![1, 1, 0, entries.len() as u16];
    dir.extend(entries.into_iter().flatten());
    (dir, doubles, ascii)
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

/// The body: TARGET_NAME as written ("MARS" -> "Mars"), else by its radius.
fn body_name(label: &Label, radius_m: f64) -> String {
    if let Some((t, _)) = label.word("TARGET_NAME") {
        let mut chars = t.chars();
        if let Some(first) = chars.next() {
            return first.to_string() + &chars.as_str().to_ascii_lowercase();
        }
    }
    let near = |r: f64| (radius_m - r).abs() < 1000.0;
    if near(3_396_190.0) {
        "Mars".into()
    } else if near(1_737_400.0) {
        "the Moon".into()
    } else {
        "the body".into()
    }
}

#[cfg(test)]
mod tests {
    //! The DTMs of `tests/fixtures/pds3/make_pds3.py`, written byte by byte from the PDS3
    //! standard and read back by GDAL 3.10.3's PDS driver with the transforms and heights
    //! below. Expected values come from the script's formulas, worked here by hand.
    use super::*;

    fn fixture_path(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/pds3").join(name)
    }

    fn fixture(name: &str) -> Raster {
        crate::raster::read_raster(&fixture_path(name)).unwrap_or_else(|e| panic!("{name}: {e:#}"))
    }

    /// The script's hill: `height exp(-(((c - cx) / sx)^2 + ((r - cy) / sy)^2))`.
    fn hill(c: f64, r: f64, height: f64, cx: f64, cy: f64, sx: f64, sy: f64) -> f64 {
        height * (-(((c - cx) / sx).powi(2) + ((r - cy) / sy).powi(2))).exp()
    }

    /// HiRISE layout: attached label, record pointer, PC_REAL, ISIS NULL as MISSING_CONSTANT and
    /// the four other special pixels. Corner: SAMPLE_PROJECTION_OFFSET 4399.5 and
    /// LINE_PROJECTION_OFFSET 59299.5 at 20 m give x = -(4399.5 + 0.5) 20 = -88 000 m and
    /// y = (59299.5 + 0.5) 20 = 1 186 000 m (GDAL: the same). Ground cell: rows at y = R lat,
    /// latitudes 59 252 x 20 / 3 396 190 rad = 19.99234 deg to 59 300 x 20 / R = 20.00854 deg,
    /// mid 20.00044 deg; east-west 20 cos(20.00044) / cos(15) = 20 x 0.939687 / 0.965926 =
    /// 19.4568 m; north-south 20 m.
    #[test]
    fn a_hirise_layout_dtm_reads_with_heights_nodata_and_ground_cells() {
        let r = fixture("dtm-attached.img");
        assert_eq!((r.cols, r.rows), (60, 48));
        assert_eq!(
            (r.geo.west, r.geo.north, r.geo.cell_x, r.geo.cell_y),
            (-88_000.0, 1_186_000.0, 20.0, 20.0)
        );
        let special = [(0, 0), (59, 0), (0, 47), (59, 47), (10, 20)];
        for row in 0..48 {
            for col in 0..60 {
                let i = row * 60 + col;
                if special.contains(&(col, row)) {
                    assert!(r.is_nodata(i), "({col}, {row}) is a special pixel");
                } else {
                    let want = f64::from(
                        (-2500.0 + hill(col as f64, row as f64, 12.0, 30.0, 24.0, 14.0, 11.0)) as f32,
                    );
                    assert_eq!(r.values[i], want, "({col}, {row})");
                }
            }
        }
        assert!((r.cell_m.0 - 19.4568).abs() < 1e-3 && r.cell_m.1 == 20.0, "{:?}", r.cell_m);
        assert_eq!(r.crs, Crs::Projected { metres_per_unit: 1.0, unit: "metre" });
        let notes = r.notes.join("\n");
        assert!(notes.contains("equirectangular map on Mars (sphere of radius 3396190 m)"), "{notes}");
        assert!(
            notes.contains("5 cells without a height (MISSING_CONSTANT: 1, other ISIS special pixels: 4)"),
            "{notes}"
        );
    }

    /// Detached label, MSB_INTEGER with OFFSET and SCALING_FACTOR, polar stereographic about the
    /// south pole; the .lbl and the .img name the same DTM. Corner x = -(99.5 + 0.5) 5 = -500 m,
    /// y = (59 999.5 + 0.5) 5 = 300 000 m. Ground cell at the centre (x, y) = (-400, 299 925) m:
    /// the sphere's polar stereographic scale factor is k = 1 + rho^2 / (4 R^2) = 1 +
    /// 8.99550e10 / 4.61363e13 = 1.0019498, so 5 / k = 4.99027 m.
    #[test]
    fn a_detached_label_integer_polar_stereographic_dtm_reads_by_either_file() {
        for name in ["dtm-detached.lbl", "dtm-detached.img"] {
            let r = fixture(name);
            assert_eq!((r.cols, r.rows), (40, 30), "{name}");
            assert_eq!((r.geo.west, r.geo.north, r.geo.cell_x), (-500.0, 300_000.0, 5.0), "{name}");
            for row in 0..30 {
                for col in 0..40 {
                    let i = row * 40 + col;
                    if (col, row) == (0, 0) || (col, row) == (39, 29) {
                        assert!(r.is_nodata(i), "{name} ({col}, {row})");
                    } else {
                        let dn = ((hill(col as f64, row as f64, 30.0, 20.0, 15.0, 9.0, 7.0) + 500.0) * 4.0)
                            .round();
                        assert_eq!(r.values[i], -4000.0 + 0.25 * dn, "{name} ({col}, {row})");
                    }
                }
            }
            let rho2 = 400.0f64.powi(2) + 299_925.0f64.powi(2);
            let k = 1.0 + rho2 / (4.0 * 3_396_190.0f64.powi(2));
            assert!((r.cell_m.0 - 5.0 / k).abs() < 1e-9 && r.cell_m.0 == r.cell_m.1, "{:?}", r.cell_m);
            assert!((r.cell_m.0 - 4.99027).abs() < 1e-5);
            assert!(r.notes.iter().any(|n| n.contains("south pole of Mars")), "{:?}", r.notes);
        }
    }

    /// Byte pointer, IEEE_REAL 64-bit, and MAP_SCALE and A_AXIS_RADIUS without units (the
    /// standard's km): 0.01 km = 10 m cells; corner x = -(-199.5 + 0.5) 10 = 1990 m,
    /// y = (100.5 + 0.5) 10 = 1010 m. At latitude 0.03 deg on the Moon the cells are square.
    #[test]
    fn ieee_doubles_by_byte_pointer_with_the_standards_km_units() {
        let r = fixture("moon-bytes.img");
        assert_eq!((r.cols, r.rows), (20, 16));
        assert_eq!((r.geo.west, r.geo.north, r.geo.cell_x), (1990.0, 1010.0, 10.0));
        for (i, v) in r.values.iter().enumerate() {
            let (c, w) = ((i % 20) as f64, (i / 20) as f64);
            assert_eq!(*v, 1000.0 + 0.5 * c - 0.25 * w + 1.0 / 3.0, "cell {i}");
        }
        // Mid-latitude (1010 + 850) / 2 / 1 737 400 rad: 10 cos(that) = 10 (1 - 1.43e-7) m.
        assert!((r.cell_m.0 - 9.999_998_57).abs() < 1e-8 && r.cell_m.1 == 10.0, "{:?}", r.cell_m);
        let notes = r.notes.join("\n");
        assert!(
            notes.contains("MAP_SCALE = 0.01 has no unit")
                && notes.contains("on Moon (sphere of radius 1737400 m)"),
            "{notes}"
        );
    }

    /// Line prefix and suffix bytes are skipped; LSB_INTEGER 16-bit with MISSING_CONSTANT 7 and
    /// the ISIS LRS -32767, and 8-bit unsigned samples, decode to the values written.
    #[test]
    fn line_prefixes_and_suffixes_are_skipped_and_integers_decode() {
        let label = |t: &str, bits: u32| {
            format!(
                "PDS_VERSION_ID = PDS3\r\nRECORD_TYPE = UNDEFINED\r\n^IMAGE = 1025 <BYTES>\r\nOBJECT = IMAGE\r\n\
                 LINES = 2\r\nLINE_SAMPLES = 3\r\nSAMPLE_TYPE = {t}\r\nSAMPLE_BITS = {bits}\r\n\
                 LINE_PREFIX_BYTES = 4\r\nLINE_SUFFIX_BYTES = 2\r\nMISSING_CONSTANT = 7\r\nEND_OBJECT = IMAGE\r\n\
                 OBJECT = IMAGE_MAP_PROJECTION\r\nMAP_PROJECTION_TYPE = EQUIRECTANGULAR\r\nA_AXIS_RADIUS = 3396.19\r\n\
                 CENTER_LATITUDE = 0\r\nMAP_SCALE = 2 <METERS/PIXEL>\r\nLINE_PROJECTION_OFFSET = 0.5\r\n\
                 SAMPLE_PROJECTION_OFFSET = -0.5\r\nEND_OBJECT = IMAGE_MAP_PROJECTION\r\nEND\r\n"
            )
        };
        let dir = tempfile::tempdir().unwrap();
        let write = |name: &str, label: String, lines: [&[u8]; 2]| {
            let mut bytes = label.into_bytes();
            assert!(bytes.len() <= 1024, "the label fits before byte 1025");
            bytes.resize(1024, b' ');
            for l in lines {
                bytes.extend_from_slice(&[0xEE; 4]);
                bytes.extend_from_slice(l);
                bytes.extend_from_slice(&[0xDD; 2]);
            }
            let path = dir.path().join(name);
            std::fs::write(&path, bytes).unwrap();
            crate::raster::read_raster(&path).unwrap()
        };
        // -2, 300, 7 (missing) / -32767 (LRS), 0, 1000 as little-endian 16-bit.
        let r = write(
            "i16.img",
            label("LSB_INTEGER", 16),
            [&[0xFE, 0xFF, 0x2C, 0x01, 0x07, 0x00], &[0x01, 0x80, 0x00, 0x00, 0xE8, 0x03]],
        );
        let v: Vec<String> = r.values.iter().map(|v| format!("{v}")).collect();
        assert_eq!(v, ["-2", "300", "NaN", "NaN", "0", "1000"]);
        // Corner x = -(-0.5 + 0.5) 2 = 0, y = (0.5 + 0.5) 2 = 2.
        assert_eq!((r.geo.west, r.geo.north), (0.0, 2.0));
        // Behind an SFDU line, under a name that is not .img: found by its first bytes.
        let sfdu = format!(
            "CCSD3ZF0000100000001NJPL3IF0PDS200000001 = SFDU_LABEL\r\n{}",
            label("MSB_UNSIGNED_INTEGER", 8)
        );
        let r = write("u8.dat", sfdu, [&[0, 255, 7], &[1, 2, 3]]);
        let v: Vec<String> = r.values.iter().map(|v| format!("{v}")).collect();
        assert_eq!(v, ["0", "255", "NaN", "1", "2", "3"]);
    }

    /// A copy of the attached fixture with `from` replaced by `to` in its label, read.
    fn edited(from: &str, to: &str) -> String {
        let mut bytes = std::fs::read(fixture_path("dtm-attached.img")).unwrap();
        let at = bytes.windows(from.len()).position(|w| w == from.as_bytes()).expect(from);
        bytes.splice(at..at + from.len(), to.bytes());
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("edited.img");
        std::fs::write(&path, &bytes).unwrap();
        let started = std::time::Instant::now();
        let err = crate::raster::read_raster(&path).expect_err("must be refused");
        assert!(started.elapsed().as_secs() < 5);
        let err = format!("{err:#}");
        assert!(err.contains("edited.img"), "{err}");
        err
    }

    #[test]
    fn a_label_lying_about_its_size_is_refused_naming_the_key_before_allocating() {
        let err = edited("LINES = 48\r", "LINES = 4800\r");
        // By hand: 7 label records of 240 bytes, then 4800 x 240: 1680 + 1 152 000 bytes.
        assert!(
            err.contains("LINES = 4800 lines of 240 bytes")
                && err.contains("from byte 1680 need 1153680 bytes"),
            "{err}"
        );
        let err = edited("LINES = 48\r", "LINES = 2000000000\r");
        assert!(err.contains("cells is more than the"), "{err}");
        let err = edited("LINE_SAMPLES = 60", "LINE_SAMPLES = 60.5");
        assert!(err.contains("IMAGE.LINE_SAMPLES = 60.5 must be a whole number"), "{err}");
    }

    #[test]
    fn unsupported_layouts_are_refused_naming_the_key_and_value() {
        let err = edited("SAMPLE_TYPE = PC_REAL", "SAMPLE_TYPE = VAX_REAL");
        assert!(err.contains("SAMPLE_TYPE = VAX_REAL is not supported"), "{err}");
        let err = edited("SAMPLE_BITS = 32", "SAMPLE_BITS = 16");
        assert!(err.contains("SAMPLE_BITS = 16 with SAMPLE_TYPE = PC_REAL"), "{err}");
        let err = edited("MAP_PROJECTION_ROTATION = 0.0", "MAP_PROJECTION_ROTATION = 9.0");
        assert!(err.contains("MAP_PROJECTION_ROTATION = 9"), "{err}");
        let err = edited("\"EQUIRECTANGULAR\"", "\"SINUSOIDAL\"     ");
        assert!(err.contains("MAP_PROJECTION_TYPE = SINUSOIDAL is not supported"), "{err}");
        let err = edited("MAP_SCALE = 20.0", "MAP_SKALE = 20.0");
        assert!(err.contains("no IMAGE_MAP_PROJECTION.MAP_SCALE"), "{err}");
        let err = edited("BANDS = 1", "BANDS = 3");
        assert!(err.contains("IMAGE.BANDS = 3"), "{err}");
        // Without END the label runs into the samples.
        let err = edited("\r\nEND\r\n", "\r\nXND\r\n");
        assert!(err.contains("line 49: keyword `XND` is not followed by `=`"), "{err}");
        let err = edited("^IMAGE = 8", "^IMAGE = 0");
        assert!(err.contains("^IMAGE = 0"), "{err}");
        // Another format's .img: ERDAS IMAGINE begins with its own header tag.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("erdas.img");
        std::fs::write(&path, b"EHFA_HEADER_TAG\0\0\0\0").unwrap();
        let err = format!("{:#}", crate::raster::read_raster(&path).unwrap_err());
        assert!(err.contains("erdas.img: an ERDAS IMAGINE .img, not a PDS3 DTM"), "{err}");
    }

    #[test]
    fn odl_values_parse_as_the_standard_writes_them() {
        let text =
            b"PDS_VERSION_ID = PDS3\r\n/* a comment */ A = 16#FF7FFFFB#\nB = (\"x.img\",\n 3 <BYTES>)\n\
            W = (450, 550) <NM>\nOBJECT = IMAGE\n C = \"two\n lines\" D = -1.5E+02 <M>\nEND_OBJECT\nEND\n";
        let l = parse_label("t.lbl", text).unwrap();
        assert_eq!(parse_based("16#FF7FFFFB#"), Some(0xFF7F_FFFB));
        assert_eq!(parse_based("2#101#"), Some(5));
        assert!(
            matches!(l.get("B"), Some((Value::List(v), 3)) if v.len() == 2 && v[1].unit.as_deref() == Some("BYTES"))
        );
        assert_eq!(l.word("IMAGE.C").unwrap().0, "TWO LINES");
        assert!(matches!(l.get("W"), Some((Value::List(v), 5)) if v[1].unit.as_deref() == Some("NM")));
        assert_eq!(l.number("IMAGE.D").unwrap(), Some((-150.0, Some("M".into()))));
        assert!(parse_label("t.lbl", b"A = (((((((((((((((((((((1)))))))))))))))))))))\nEND").is_err());
    }
}

#[cfg(test)]
mod mutated {
    //! Mutated labels and truncated files are refused or read, never a panic or an abort.
    use super::*;

    #[test]
    fn mutated_and_truncated_pds3_files_never_panic() {
        let dir = tempfile::tempdir().unwrap();
        let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/pds3");
        std::fs::copy(fixtures.join("dtm-detached.img"), dir.path().join("dtm-detached.img")).unwrap();
        let mut seed = 0x2545_F491_4F6C_DD1Du64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let tokens: [&[u8]; 8] = [b"=", b"(", b"\"", b"<", b"#", b"-", b"9999999999", b"END"];
        for (file, label_len) in
            [("dtm-attached.img", 1680usize), ("dtm-detached.lbl", 682), ("moon-bytes.img", 2048)]
        {
            let original = std::fs::read(fixtures.join(file)).unwrap();
            let path = dir.path().join(file);
            for _ in 0..300 {
                let mut bytes = original.clone();
                match next() % 3 {
                    0 => bytes.truncate((next() % original.len() as u64) as usize),
                    1 => {
                        for _ in 0..1 + next() % 4 {
                            let at = (next() % label_len as u64) as usize;
                            bytes[at] = next() as u8;
                        }
                    }
                    _ => {
                        let at = (next() % label_len as u64) as usize;
                        let t = tokens[(next() % tokens.len() as u64) as usize];
                        bytes.splice(at..at, t.iter().copied());
                    }
                }
                std::fs::write(&path, &bytes).unwrap();
                if let Ok(r) = crate::raster::read_raster(&path) {
                    assert_eq!(r.values.len(), r.cols * r.rows);
                }
            }
        }
    }
}
