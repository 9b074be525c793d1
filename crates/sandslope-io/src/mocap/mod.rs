//! Motion-capture file readers (as `sandslope track` uses them): OptiTrack Motive CSV (format 1.23 and
//! 1.25), Vicon Nexus CSV and a plain CSV, detected from the first line or forced with
//! `--format`. Each reader returns one body's positions in metres (NaN where occluded), the
//! frame rate and the time of the first frame; every error names the file and the line.

mod motive;
mod plain;
mod vicon;

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context, Result};
use csv::StringRecord;

/// A file format `sandslope track` reads (serialised as its [`name`](MocapFormat::name)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MocapFormat {
    /// OptiTrack Motive CSV export (format version 1.23 or 1.25).
    Motive,
    /// Vicon Nexus CSV (Trajectories or Model Outputs section).
    Vicon,
    /// Plain CSV: `time_s` and `x_m,y_m,z_m` (or `x_mm,y_mm,z_mm`).
    Plain,
}

impl std::str::FromStr for MocapFormat {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        MocapFormat::ALL
            .into_iter()
            .find(|f| f.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| format!("`{s}` is not a motion-capture format (motive, vicon or plain)"))
    }
}

impl MocapFormat {
    /// Every format, in the order they are documented.
    pub const ALL: [MocapFormat; 3] = [MocapFormat::Motive, MocapFormat::Vicon, MocapFormat::Plain];

    /// The vertical (up) axis of the format's capture frame, `[x, y, z]`: Motive's default
    /// axis convention is Y up; Vicon Nexus is Z up; the plain format is Z up (as `simulate
    /// --out` writes it). `track` orients upslope by it (rising with a positive `--slope`).
    pub fn vertical_axis(self) -> [f64; 3] {
        match self {
            MocapFormat::Motive => [0.0, 1.0, 0.0],
            MocapFormat::Vicon | MocapFormat::Plain => [0.0, 0.0, 1.0],
        }
    }

    /// Display name.
    pub fn name(self) -> &'static str {
        match self {
            MocapFormat::Motive => "motive",
            MocapFormat::Vicon => "vicon",
            MocapFormat::Plain => "plain",
        }
    }
}

/// One body's trajectory from one file.
#[derive(Debug, Clone)]
pub struct Capture {
    /// The file read.
    pub path: PathBuf,
    /// Its format.
    pub format: MocapFormat,
    /// The body (rigid body, marker or model output) whose positions these are.
    pub body: String,
    /// Frames per second.
    pub frame_rate_hz: f64,
    /// Time of the first frame, s.
    pub start_time_s: f64,
    /// Positions per frame, m; NaN where the body was occluded.
    pub positions: Vec<[f64; 3]>,
}

impl Capture {
    /// The library's view of this capture for [`sandslope::gait::track()`], with the touchdown
    /// times given for it (from a gait controller's log), if any.
    pub fn recording<'a>(&'a self, touchdowns_s: Option<&'a [f64]>) -> sandslope::gait::Recording<'a> {
        sandslope::gait::Recording {
            positions: &self.positions,
            frame_rate_hz: self.frame_rate_hz,
            start_time_s: self.start_time_s,
            touchdowns_s,
        }
    }
}

/// The records of a CSV file with their line numbers.
pub(crate) struct Rows {
    pub path: PathBuf,
    pub rows: Vec<(u64, StringRecord)>,
}

impl Rows {
    fn read(path: &Path) -> Result<Rows> {
        // The OS error kept as the cause (not only its text): Python raises FileNotFoundError on it.
        let file = std::fs::File::open(path).with_context(|| format!("cannot read {}", path.display()))?;
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .trim(csv::Trim::All)
            .from_reader(std::io::BufReader::new(file));
        let mut rows = Vec::new();
        let mut record = StringRecord::new();
        loop {
            let line = reader.position().line();
            match reader.read_record(&mut record) {
                Ok(true) => {
                    let line = record.position().map_or(line, |p| p.line());
                    rows.push((line, record.clone()));
                }
                Ok(false) => break,
                Err(e) => bail!("{}: line {}: {e}", path.display(), line),
            }
        }
        Ok(Rows { path: path.to_path_buf(), rows })
    }

    /// `file: line N: message`.
    pub fn err(&self, line: u64, msg: impl std::fmt::Display) -> anyhow::Error {
        anyhow!("{}: line {line}: {msg}", self.path.display())
    }

    /// A position cell: empty means occluded (NaN); anything else must be a number.
    pub fn position_cell(&self, line: u64, record: &StringRecord, col: usize, what: &str) -> Result<f64> {
        match record.get(col).unwrap_or("") {
            "" => Ok(f64::NAN),
            s => {
                s.parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| {
                    self.err(line, format!("column {} ({what}): `{s}` is not a number", col + 1))
                })
            }
        }
    }
}

/// Picks the body named `wanted` among `available` (name, payload); the only one when
/// `wanted` is `None`. `matches` says whether a requested name designates an available one.
pub(crate) fn pick_body<T>(
    rows: &Rows,
    line: u64,
    available: Vec<(String, T)>,
    wanted: Option<&str>,
    matches: impl Fn(&str, &str) -> bool,
) -> Result<(String, T)> {
    let names = available.iter().map(|(n, _)| format!("`{n}`")).collect::<Vec<_>>().join(", ");
    match wanted {
        Some(w) => {
            let mut hits: Vec<(String, T)> = available.into_iter().filter(|(n, _)| matches(n, w)).collect();
            match hits.len() {
                1 => Ok(hits.remove(0)),
                0 => Err(rows.err(line, format!("no body named `{w}` (bodies with positions: {names})"))),
                _ => {
                    Err(rows.err(line, format!("`{w}` matches several bodies ({names}); give the full name")))
                }
            }
        }
        None => {
            let mut available = available;
            if available.len() == 1 {
                Ok(available.remove(0))
            } else {
                Err(rows
                    .err(line, format!("several bodies have positions ({names}); choose one with --body")))
            }
        }
    }
}

/// Multiplier from a length unit name to metres.
pub(crate) fn unit_scale(unit: &str) -> Option<f64> {
    match unit.to_ascii_lowercase().as_str() {
        "m" | "meters" | "metres" | "meter" | "metre" => Some(1.0),
        "cm" | "centimeters" | "centimetres" => Some(1e-2),
        "mm" | "millimeters" | "millimetres" => Some(1e-3),
        _ => None,
    }
}

/// Detects the format from the first record.
fn detect(rows: &Rows) -> Result<MocapFormat> {
    let Some((line, first)) = rows.rows.first() else {
        bail!("{}: the file is empty", rows.path.display());
    };
    let cell0 = first.get(0).unwrap_or("");
    if cell0.eq_ignore_ascii_case("Format Version") {
        Ok(MocapFormat::Motive)
    } else if vicon::SECTIONS.iter().any(|s| cell0.eq_ignore_ascii_case(s)) {
        Ok(MocapFormat::Vicon)
    } else if first.iter().any(|c| c == "time_s") {
        Ok(MocapFormat::Plain)
    } else {
        Err(rows.err(
            *line,
            "unrecognised format: expected an OptiTrack Motive CSV export (first cell `Format Version`), a Vicon \
             Nexus CSV (first cell `Trajectories`, `Model Outputs` or `Devices`) or a plain CSV with a `time_s` \
             column; or force one with --format",
        ))
    }
}

/// Reads one body's trajectory from `path`, detecting the format unless `format` is given.
pub fn read(path: &Path, format: Option<MocapFormat>, body: Option<&str>) -> Result<Capture> {
    let rows = Rows::read(path)?;
    let format = match format {
        Some(f) => f,
        None => detect(&rows)?,
    };
    let (body, frame_rate_hz, start_time_s, positions) = match format {
        MocapFormat::Motive => motive::parse(&rows, body)?,
        MocapFormat::Vicon => vicon::parse(&rows, body)?,
        MocapFormat::Plain => plain::parse(&rows)?,
    };
    Ok(Capture { path: path.to_path_buf(), format, body, frame_rate_hz, start_time_s, positions })
}
/// Reads a touchdowns file: one time in seconds per line; blank lines and `#` comments skipped.
pub fn load_touchdowns(path: &Path) -> Result<Vec<f64>> {
    let text = sandslope_files::read_text(path)?;
    let mut times = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let t = line.parse::<f64>().ok().filter(|t| t.is_finite()).ok_or_else(|| {
            anyhow!("{}: line {}: `{line}` is not a time in seconds", path.display(), i + 1)
        })?;
        times.push(t);
    }
    if times.is_empty() {
        bail!("{}: no touchdown times (expected one time in seconds per line)", path.display());
    }
    times.sort_by(f64::total_cmp);
    Ok(times)
}
