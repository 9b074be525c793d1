//! The servo log (docs/drive.md, "The log") and the robot file's `[servos]` table.
//!
//! The log is CSV, one row per servo per bus cycle, after `#` comment lines that record the
//! run (slope, robot, leg speed, servo IDs): `pandas.read_csv(path, comment="#")` reads it.
//! Columns, in order:
//!
//! | column | unit | meaning |
//! |---|---|---|
//! | `time_s` | s | time since the gait started (negative while standing up) |
//! | `id` | | Dynamixel ID |
//! | `leg` | | leg index (the order of `[servos] ids`) |
//! | `tripod` | | 0 or 1 |
//! | `present_position` | pulse | Present Position (132), 4096 per turn |
//! | `present_velocity` | 0.229 rev/min | Present Velocity (128) |
//! | `present_current_ma` | mA | Present Current (126) |
//! | `load_percent` | % | the current as a share of the 1.47 A stall current (the XL330 has no load register) |
//! | `input_voltage_v` | V | Present Input Voltage (144) |
//! | `temperature_c` | degC | Present Temperature (146) |
//! | `hardware_error` | | Hardware Error Status (70) when the status packet's alert bit was set, else 0 |
//! | `goal_position` | pulse | the goal sent that cycle |
//! | `leg_angle_rad` | rad | leg angle in the gait's frame (docs/model.md §15) |
//! | `drive_torque_n_m` | N m | `K_t I` in the leg's direction of rotation (docs/model.md §19) |

use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};
use serde::{Deserialize, Serialize};

use sandslope_files::Source;

/// One row of the servo log.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ServoLogRow {
    /// Time since the gait started, s.
    pub time_s: f64,
    /// Dynamixel ID.
    pub id: u8,
    /// Leg index.
    pub leg: usize,
    /// Tripod (0 or 1).
    pub tripod: usize,
    /// Present Position, pulses.
    pub present_position: i32,
    /// Present Velocity, 0.229 rev/min.
    pub present_velocity: i32,
    /// Present Current, mA.
    pub present_current_ma: i32,
    /// Current as a share of the stall current, %.
    pub load_percent: f64,
    /// Present Input Voltage, V.
    pub input_voltage_v: f64,
    /// Present Temperature, degC.
    pub temperature_c: i32,
    /// Hardware Error Status.
    pub hardware_error: u8,
    /// Goal position sent, pulses.
    pub goal_position: i32,
    /// Leg angle in the gait's frame, rad.
    pub leg_angle_rad: f64,
    /// Drive torque, N m.
    pub drive_torque_n_m: f64,
}

/// Writes the log row by row into an open file (flushed every `flush_every` rows and at the
/// end), after its comment header.
#[derive(Debug)]
pub struct ServoLogWriter<W: Write> {
    writer: csv::Writer<W>,
    rows: usize,
}

impl<W: Write> ServoLogWriter<W> {
    /// Starts a log on `out` with `meta` as `# key = value` lines.
    pub fn new(mut out: W, meta: &[(&str, String)]) -> Result<ServoLogWriter<W>> {
        writeln!(
            out,
            "# sandslope servo log (docs/drive.md); read with pandas.read_csv(path, comment=\"#\")"
        )?;
        for (k, v) in meta {
            writeln!(out, "# {k} = {v}")?;
        }
        Ok(ServoLogWriter { writer: csv::WriterBuilder::new().flexible(true).from_writer(out), rows: 0 })
    }

    /// Appends a row (flushing every 60 rows, ten cycles of six servos).
    pub fn write(&mut self, row: &ServoLogRow) -> std::io::Result<()> {
        self.writer.serialize(row).map_err(std::io::Error::other)?;
        self.rows += 1;
        if self.rows % 60 == 0 {
            self.writer.flush()?;
        }
        Ok(())
    }

    /// Writes `# key = value` between the rows (a live estimate as it came; `pandas.read_csv`
    /// with `comment="#"` and [`read_servo_log`] skip it). Commas in `value` become semicolons.
    pub fn note(&mut self, key: &str, value: &str) -> std::io::Result<()> {
        let line = format!("# {key} = {}", value.replace([',', '"', '\n', '\r'], ";"));
        self.writer.write_record([line.as_str()]).map_err(std::io::Error::other)
    }

    /// Flushes the rows written so far to the file (the flight recorder does after every row).
    pub fn flush(&mut self) -> std::io::Result<()> {
        self.writer.flush()
    }

    /// Rows written.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Flushes everything.
    pub fn finish(mut self) -> std::io::Result<()> {
        self.writer.flush()
    }
}

/// Width of each of the flight recorder's status lines, bytes with the line end: rewritten in
/// place when the run ends.
const STATUS_LINE: usize = 100;

/// The status lines' keys, in order: `status` (`incomplete` until the run ends, then how it
/// ended), the achieved cycle rate and the cycles' jitter.
pub const STATUS_KEYS: [&str; 4] = ["status", "achieved_rate_hz", "cycle_jitter_ms", "max_cycle_ms"];

/// The value a log's `status` line holds while its run is under way (or after it was killed).
pub const INCOMPLETE: &str =
    "incomplete (the run had not ended when this was written: killed, or power lost)";

/// The servo log as a flight recorder (docs/drive.md, "The log"): written under its own name
/// from the first cycle, every row flushed to the file as it comes and the file synced to the
/// disk every second, so that a process killed without a word (SIGKILL, the OOM killer) or a
/// machine that loses power leaves every cycle up to the last second readable. Its first lines
/// are fixed-width status lines, `# status = incomplete ...` until [`FlightLog::finish`]
/// rewrites them in place with how the run ended, its achieved rate and jitter.
#[derive(Debug)]
pub struct FlightLog {
    file: std::fs::File,
    writer: ServoLogWriter<std::io::BufWriter<std::fs::File>>,
    last_sync: std::time::Instant,
}

fn status_line(key: &str, value: &str) -> Vec<u8> {
    let mut line = format!("# {key} = {value}");
    line.truncate(STATUS_LINE - 1);
    let mut bytes = format!("{line:<width$}\n", width = STATUS_LINE - 1).into_bytes();
    bytes.truncate(STATUS_LINE);
    bytes
}

impl FlightLog {
    /// Creates the log at `path` with `meta` as its header. A file already there is replaced
    /// (removed, then a new one created `O_EXCL`, so nothing planted in between is opened); a
    /// symbolic link, a folder or a device at `path` is refused.
    pub fn create(path: &Path, meta: &[(&str, String)]) -> Result<FlightLog> {
        match std::fs::symlink_metadata(path) {
            Ok(m) if m.file_type().is_symlink() => bail!(
                "--log {}: a symbolic link; give the log's own path (a link could point at a file that is not a log)",
                path.display()
            ),
            Ok(m) if !m.is_file() => {
                bail!("--log {}: not a regular file (a folder or a device); give a file's path", path.display())
            }
            Ok(_) => std::fs::remove_file(path)
                .with_context(|| format!("cannot replace the servo log {}", path.display()))?,
            Err(_) => {}
        }
        let file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(path)
            .map_err(|source| sandslope_files::WriteError { path: path.to_path_buf(), source })?;
        let mut out = std::io::BufWriter::new(file.try_clone()?);
        for key in STATUS_KEYS {
            out.write_all(&status_line(key, if key == "status" { INCOMPLETE } else { "" }))?;
        }
        let mut writer = ServoLogWriter::new(out, meta)?;
        writer.flush()?;
        Ok(FlightLog { file, writer, last_sync: std::time::Instant::now() })
    }

    /// Appends a row, flushed to the file at once and synced to the disk once a second.
    pub fn write(&mut self, row: &ServoLogRow) -> std::io::Result<()> {
        self.writer.write(row)?;
        self.writer.flush()?;
        if self.last_sync.elapsed().as_secs_f64() >= 1.0 {
            self.file.sync_data()?;
            self.last_sync = std::time::Instant::now();
        }
        Ok(())
    }

    /// Rows written.
    pub fn rows(&self) -> usize {
        self.writer.rows()
    }

    /// Writes a `# key = value` note between the rows, flushed at once ([`ServoLogWriter::note`]).
    pub fn note(&mut self, key: &str, value: &str) -> std::io::Result<()> {
        self.writer.note(key, value)?;
        self.writer.flush()
    }

    /// Ends the log: the rows flushed, the status lines rewritten with `status` (the values of
    /// [`STATUS_KEYS`] in order), and the file synced.
    pub fn finish(self, status: &[String; 4]) -> std::io::Result<()> {
        let FlightLog { file, writer, .. } = self;
        writer.finish()?;
        let mut head = Vec::with_capacity(4 * STATUS_LINE);
        for (key, value) in STATUS_KEYS.iter().zip(status) {
            head.extend(status_line(key, value));
        }
        std::os::unix::fs::FileExt::write_all_at(&file, &head, 0)?;
        file.sync_all()
    }
}

/// A servo log read back: its header's `key = value` pairs and its rows, in time order.
#[derive(Debug, Clone, PartialEq)]
pub struct ServoLog {
    /// `# key = value` lines of the header.
    pub meta: BTreeMap<String, String>,
    /// The rows, sorted by time (stably: a log's own order within a cycle is kept).
    pub rows: Vec<ServoLogRow>,
    /// The file's line of each row.
    pub lines: Vec<usize>,
    /// What the reader repaired or left out (a cut last row, rows with missing values,
    /// repeated rows, rows out of order, gaps in time), one sentence each.
    pub notes: Vec<String>,
}

impl ServoLog {
    /// A header value parsed as a number, naming the file and key when it is not one.
    pub fn meta_f64(&self, key: &str, path: &Path) -> Result<Option<f64>> {
        match self.meta.get(key) {
            None => Ok(None),
            Some(v) => v
                .parse::<f64>()
                .map(Some)
                .map_err(|_| anyhow!("{}: header line `# {key} = {v}`: not a number", path.display())),
        }
    }

    /// The rows as the current inference's leg traces (`legs` of them: leg angle and drive
    /// torque per leg); a row whose leg the robot does not have is an error naming its line.
    pub fn leg_traces(&self, legs: usize, path: &Path) -> Result<Vec<sandslope::infer::servo::LegTrace>> {
        let mut traces = vec![sandslope::infer::servo::LegTrace::default(); legs];
        for (r, line) in self.rows.iter().zip(&self.lines) {
            let t = traces.get_mut(r.leg).ok_or_else(|| {
                anyhow!(
                    "{}: line {line} (servo ID {}): leg {}, but the robot has {legs} legs (0 to {}; 2 * stance_legs)",
                    path.display(),
                    r.id,
                    r.leg,
                    legs.saturating_sub(1)
                )
            })?;
            t.angle_rad.push(r.leg_angle_rad);
            t.torque_n_m.push(r.drive_torque_n_m);
        }
        Ok(traces)
    }
}

/// Most rows a log may hold (an hour at 100 Hz on 12 servos).
pub const MAX_ROWS: usize = 5_000_000;

/// A gap in time longer than this many bus cycles is reported in [`ServoLog::notes`].
const GAP_CYCLES: f64 = 3.0;

/// One field of a row: `None` when empty or NaN (a value the logger did not get, as pandas
/// writes it), an error naming the line, servo and column when it is not a number.
fn field(rec: &csv::StringRecord, col: usize, name: &str, at: &dyn Fn() -> String) -> Result<Option<f64>> {
    let text = rec.get(col).unwrap_or("").trim();
    if text.is_empty() || text.eq_ignore_ascii_case("nan") {
        return Ok(None);
    }
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(Some(v)),
        _ => bail!("{}: `{name}` = `{text}` is not a finite number", at()),
    }
}

/// An integer column read as a number (pandas writes integer columns holding a NaN as floats:
/// `3.0`), checked to be whole and within `lo..=hi`.
fn whole(v: f64, name: &str, lo: i64, hi: i64, at: &dyn Fn() -> String) -> Result<i64> {
    if v.fract() != 0.0 || v < lo as f64 || v > hi as f64 {
        bail!("{}: `{name}` = {v} must be a whole number within {lo} to {hi}", at());
    }
    Ok(v as i64)
}

/// Line numbers for a note: the first few and how many more.
fn some_lines(lines: &[usize]) -> String {
    let shown: Vec<String> = lines.iter().take(5).map(|l| l.to_string()).collect();
    match lines.len() {
        n if n > 5 => format!("lines {} and {} more", shown.join(", "), n - 5),
        1 => format!("line {}", shown[0]),
        _ => format!("lines {}", shown.join(", ")),
    }
}

/// Reads a servo log; errors name the file, the line, the servo and the column.
///
/// A real bus's log is messy, and the reader says what it did about each mess in
/// [`ServoLog::notes`]: a last row cut short (the file does not end with a line end: a logger
/// killed mid-write) is left out; a row with an empty or NaN measurement is left out (a value
/// the logger did not get); a row repeated exactly is read once; rows out of time order are
/// sorted; gaps in time (bus timeouts) are reported. It refuses, naming the lines: a row whose
/// time, ID or leg is missing, a field that is not a number, a row with the wrong number of
/// fields, one servo with two different rows at one time, one ID on two legs.
pub fn read_servo_log(path: &Path) -> Result<ServoLog> {
    let text = read_log_text(path)?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let mut meta = BTreeMap::new();
    let mut header_lines = 0usize;
    for line in text.lines() {
        let Some(rest) = line.strip_prefix('#') else { break };
        header_lines += 1;
        if let Some((k, v)) = rest.split_once('=') {
            meta.insert(k.trim().to_string(), v.trim().to_string());
        }
    }
    let mut notes = vec![];
    if meta.get("status").is_some_and(|v| v.starts_with("incomplete")) {
        notes.push(
            "the log is marked incomplete: its run did not end (the process was killed or the machine lost power); its rows are what was written up to then"
                .to_string(),
        );
    }
    let mut body_lines: Vec<&str> = text.lines().skip(header_lines).collect();
    if !text.is_empty() && !text.ends_with('\n') && body_lines.len() > 1 {
        let line = header_lines + body_lines.len();
        body_lines.pop();
        notes.push(format!(
            "line {line}: the log ends mid-row (no line end after it: the logger stopped while writing); the row is left out"
        ));
    }
    let body = body_lines.join("\n");
    let mut reader =
        csv::ReaderBuilder::new().flexible(true).comment(Some(b'#')).from_reader(body.as_bytes());
    let headers =
        reader.headers().with_context(|| format!("{}: no column header line", path.display()))?.clone();
    let mut col = [0usize; 14];
    for (c, want) in col.iter_mut().zip(COLUMNS) {
        *c = headers.iter().position(|h| h.trim() == want).ok_or_else(|| {
            anyhow!(
                "{}: the column `{want}` is missing (a servo log as `sandslope drive --log` writes it has {})",
                path.display(),
                COLUMNS.join(",")
            )
        })?;
    }
    let (mut rows, mut lines, mut missing) = (Vec::new(), Vec::new(), Vec::new());
    for (i, rec) in reader.records().enumerate() {
        // The file's line: the body's (notes between rows are skipped) after the header's.
        let line = match &rec {
            Ok(r) => r.position().map_or(header_lines + 2 + i, |p| header_lines + p.line() as usize),
            Err(_) => header_lines + 2 + i,
        };
        let rec =
            rec.map_err(|e| anyhow!("{}: line {line}: {}", path.display(), e.to_string().trim_end()))?;
        let plain = |line: usize| format!("{}: line {line}", path.display());
        let id = field(&rec, col[1], "id", &|| plain(line))?
            .ok_or_else(|| anyhow!("{}: `id` is empty; every row needs its servo's ID", plain(line)))?;
        let id = whole(id, "id", 0, 252, &|| plain(line))? as u8;
        let at = || format!("{}: line {line} (servo ID {id})", path.display());
        if rec.len() != headers.len() {
            bail!(
                "{}: {} fields, the header has {}; a row cut or joined (fix or delete the line)",
                at(),
                rec.len(),
                headers.len()
            );
        }
        let mut v = [0.0f64; 14];
        let mut complete = true;
        for (k, (&c, name)) in col.iter().zip(COLUMNS).enumerate() {
            match field(&rec, c, name, &at)? {
                Some(x) => v[k] = x,
                None if k <= 2 => bail!("{}: `{name}` is empty; every row needs its time, ID and leg", at()),
                None => complete = false,
            }
        }
        if !complete {
            missing.push(line);
            continue;
        }
        plausible(&v, &at)?;
        let int = |k: usize, lo: i64, hi: i64| whole(v[k], COLUMNS[k], lo, hi, &at);
        rows.push(ServoLogRow {
            time_s: v[0],
            id,
            leg: int(2, 0, 251)? as usize,
            tripod: int(3, 0, 1)? as usize,
            present_position: int(4, i32::MIN.into(), i32::MAX.into())? as i32,
            present_velocity: int(5, i32::MIN.into(), i32::MAX.into())? as i32,
            present_current_ma: int(6, i32::MIN.into(), i32::MAX.into())? as i32,
            load_percent: v[7],
            input_voltage_v: v[8],
            temperature_c: int(9, i32::MIN.into(), i32::MAX.into())? as i32,
            hardware_error: int(10, 0, 255)? as u8,
            goal_position: int(11, i32::MIN.into(), i32::MAX.into())? as i32,
            leg_angle_rad: v[12],
            drive_torque_n_m: v[13],
        });
        lines.push(line);
        if rows.len() > MAX_ROWS {
            bail!("{}: more than {MAX_ROWS} rows; split the log", path.display());
        }
    }
    if !missing.is_empty() {
        notes.push(format!(
            "{} row(s) with an empty or NaN value left out ({}): a value the logger did not get",
            missing.len(),
            some_lines(&missing)
        ));
    }
    let (rows, lines) = tidy(path, rows, lines, &mut notes)?;
    if rows.is_empty() {
        bail!("{}: the log has no complete rows", path.display());
    }
    Ok(ServoLog { meta, rows, lines, notes })
}

/// Refuses a row's value outside its column's plausible range ([`PLAUSIBLE`]), naming the
/// column, the range and its unit.
fn plausible(v: &[f64; 14], at: &dyn Fn() -> String) -> Result<()> {
    if let Some((k, (lo, hi, unit))) = PLAUSIBLE
        .iter()
        .enumerate()
        .find_map(|(k, r)| r.filter(|(lo, hi, _)| !(*lo..=*hi).contains(&v[k])).map(|r| (k, r)))
    {
        bail!(
            "{}: `{}` = {} is outside {lo} to {hi} {unit}, the plausible range of a Dynamixel's reading (is the column in the log's unit?)",
            at(),
            COLUMNS[k],
            if v[k].abs() >= 1e6 { format!("{:e}", v[k]) } else { v[k].to_string() }
        );
    }
    Ok(())
}

/// The plausible range of each column, in the order of [`COLUMNS`] (`None`: any finite value):
/// wide enough for every Dynamixel X servo (the XM430-W350 stalls at 4.1 N m, 2.3 A, and runs
/// on up to 14.8 V), narrow enough to catch a column in the wrong unit (torque in N mm, current
/// in A) or garbage such as 1e300.
const PLAUSIBLE: [Option<(f64, f64, &str)>; 14] = [
    Some((-1e6, 1e6, "s")),
    None,
    None,
    None,
    None,
    None,
    Some((-10_000.0, 10_000.0, "mA")),
    Some((-1000.0, 1000.0, "%")),
    Some((0.0, 30.0, "V")),
    Some((-40.0, 150.0, "degC")),
    None,
    None,
    Some((-1e7, 1e7, "rad")),
    Some((-20.0, 20.0, "N m")),
];

/// Largest servo log read, bytes (a little above [`MAX_ROWS`] rows of about 120 bytes).
pub const MAX_LOG_BYTES: u64 = 1 << 30;

/// Longest line of a servo log, bytes (a row is about 120).
pub const MAX_LINE_BYTES: usize = 64 * 1024;

/// The log's text, its size checked before anything is read and every line's length as it is
/// read (a file of no line ends is refused at its first 64 KiB, not read whole).
fn read_log_text(path: &Path) -> Result<String> {
    use std::io::BufRead;
    let cannot = || format!("cannot read servo log {}", path.display());
    let file = std::fs::File::open(path).with_context(cannot)?;
    let size = file.metadata().with_context(cannot)?.len();
    if size > MAX_LOG_BYTES {
        bail!(
            "{}: {size} bytes, more than the {MAX_LOG_BYTES} a servo log may hold ({MAX_ROWS} rows); split the log",
            path.display()
        );
    }
    let mut reader = std::io::BufReader::new(file);
    let mut bytes = Vec::with_capacity(size as usize);
    let mut line = 0usize;
    loop {
        line += 1;
        let before = bytes.len();
        let n = std::io::Read::take(&mut reader, MAX_LINE_BYTES as u64 + 1)
            .read_until(b'\n', &mut bytes)
            .with_context(cannot)?;
        if n == 0 {
            break;
        }
        if bytes.len() - before > MAX_LINE_BYTES && bytes.last() != Some(&b'\n') {
            bail!(
                "{}: line {line} is longer than {MAX_LINE_BYTES} bytes (a row is about 120): not a servo log, or its line ends are missing",
                path.display()
            );
        }
    }
    String::from_utf8(bytes).map_err(|e| anyhow!("{}: not UTF-8 text ({e})", path.display()))
}

/// Sorts the rows by time, reads a repeated row once, refuses two different rows of one servo
/// at one time or one ID on two legs, and reports gaps in time.
fn tidy(
    path: &Path,
    rows: Vec<ServoLogRow>,
    lines: Vec<usize>,
    notes: &mut Vec<String>,
) -> Result<(Vec<ServoLogRow>, Vec<usize>)> {
    let mut order: Vec<usize> = (0..rows.len()).collect();
    if rows.windows(2).any(|w| w[1].time_s < w[0].time_s) {
        let first = rows.windows(2).position(|w| w[1].time_s < w[0].time_s).unwrap_or(0) + 1;
        notes.push(format!("rows out of time order (first at line {}); read in time order", lines[first]));
    }
    order.sort_by(|&a, &b| rows[a].time_s.total_cmp(&rows[b].time_s));
    let mut leg_of: BTreeMap<u8, (usize, usize)> = BTreeMap::new();
    let mut seen: BTreeMap<(u8, u64), usize> = BTreeMap::new();
    let (mut out, mut out_lines, mut repeated) = (Vec::with_capacity(rows.len()), vec![], vec![]);
    for i in order {
        let r = rows[i];
        let &mut (leg, first) = leg_of.entry(r.id).or_insert((r.leg, lines[i]));
        if leg != r.leg {
            bail!(
                "{}: line {} (servo ID {}): leg {}, but line {first} has it on leg {leg}; one servo drives one leg",
                path.display(),
                lines[i],
                r.id,
                r.leg
            );
        }
        match seen.get(&(r.id, r.time_s.to_bits())) {
            Some(&j) if rows[j] == r => repeated.push(lines[i]),
            Some(&j) => bail!(
                "{}: lines {} and {} (servo ID {}): two different rows at time_s = {}; keep the one the bus read",
                path.display(),
                lines[j],
                lines[i],
                r.id,
                r.time_s
            ),
            None => {
                seen.insert((r.id, r.time_s.to_bits()), i);
                out.push(r);
                out_lines.push(lines[i]);
            }
        }
    }
    if !repeated.is_empty() {
        notes.push(format!("{} repeated row(s) read once ({})", repeated.len(), some_lines(&repeated)));
    }
    note_gaps(&out, notes);
    Ok((out, out_lines))
}

/// Reports gaps in time longer than [`GAP_CYCLES`] bus cycles (the median step between the
/// log's distinct times).
fn note_gaps(rows: &[ServoLogRow], notes: &mut Vec<String>) {
    let mut times: Vec<f64> = rows.iter().map(|r| r.time_s).collect();
    times.dedup();
    let mut steps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.len() < 3 {
        return;
    }
    steps.sort_by(f64::total_cmp);
    let cycle = steps[steps.len() / 2];
    let gaps: Vec<(f64, f64)> =
        times.windows(2).filter(|w| w[1] - w[0] > GAP_CYCLES * cycle).map(|w| (w[0], w[1] - w[0])).collect();
    if let Some(&(at, len)) = gaps.iter().max_by(|a, b| a.1.total_cmp(&b.1)) {
        notes.push(format!(
            "{} gap(s) in time longer than {GAP_CYCLES} bus cycles (the longest {len:.3} s, after t = {at:.3} s): bus timeouts; a stride left with an empty stance bin is left out of the estimate",
            gaps.len()
        ));
    }
}

/// The log's columns in order.
pub const COLUMNS: [&str; 14] = [
    "time_s",
    "id",
    "leg",
    "tripod",
    "present_position",
    "present_velocity",
    "present_current_ma",
    "load_percent",
    "input_voltage_v",
    "temperature_c",
    "hardware_error",
    "goal_position",
    "leg_angle_rad",
    "drive_torque_n_m",
];

/// One servo as the robot file mounts it (the `[servos]` table).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ServoMount {
    /// Dynamixel ID, 0 to 252.
    pub id: u8,
    /// +1 or -1: the shaft's sense that drives the leg forward.
    pub direction: i8,
    /// Shaft position at leg angle 0, pulses.
    pub zero_offset_pulses: i32,
}

/// The robot file's optional `[servos]` table.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct ServosTable {
    ids: Vec<i64>,
    #[serde(default)]
    directions: Option<Vec<i64>>,
    #[serde(default)]
    zero_offsets: Option<Vec<i64>>,
    #[serde(default)]
    baud_rate: Option<u32>,
    #[serde(default)]
    model: Option<String>,
}

/// The servos of a robot file and their bus's baud rate.
#[derive(Debug, Clone, PartialEq)]
pub struct Servos {
    /// Servos in leg order.
    pub mounts: Vec<ServoMount>,
    /// Baud rate, one the servos support.
    pub baud_rate: u32,
    /// The servos' model (`model = "XL430-W250"`); `None`: read from the servos at their ping.
    pub model: Option<&'static sandslope::servo::ServoModel>,
}

/// Baud rates every supported servo has (Baud Rate (8) values 0 to 6).
pub const BAUD_RATES: [u32; 7] = [9_600, 57_600, 115_200, 1_000_000, 2_000_000, 3_000_000, 4_000_000];
/// The servos' factory baud rate.
pub const DEFAULT_BAUD_RATE: u32 = 57_600;

/// Splits a robot file's text into the robot's keys and its `[servos]` table: the table's lines
/// are blanked in the first (so line numbers in messages stay those of the file) and returned
/// alone in the second.
pub fn split_servos_table(text: &str) -> (String, Option<String>) {
    let mut robot = String::with_capacity(text.len());
    let mut servos = String::new();
    let mut inside = false;
    let mut found = false;
    for line in text.lines() {
        let t = line.trim_start();
        if t.starts_with('[') {
            inside = t.starts_with("[servos]");
            found |= inside;
        }
        if inside {
            servos.push_str(line);
            robot.push('\n');
        } else {
            robot.push_str(line);
            robot.push('\n');
        }
        if inside {
            servos.push('\n');
        }
    }
    (robot, found.then_some(servos))
}

/// Parses and checks a `[servos]` table (the text [`split_servos_table`] returns).
pub fn parse_servos(table: &str, source: &Source) -> Result<Servos> {
    #[derive(Deserialize)]
    struct Wrapper {
        servos: ServosTable,
    }
    let w: Wrapper =
        toml::from_str(table).map_err(|e| anyhow!("{source}: [servos]: {}", e.to_string().trim_end()))?;
    let t = w.servos;
    let n = t.ids.len();
    if n == 0 {
        bail!("{source}: [servos] ids must list one Dynamixel ID per leg (0 to 252)");
    }
    let mut mounts = Vec::with_capacity(n);
    for (i, &id) in t.ids.iter().enumerate() {
        if !(0..=252).contains(&id) {
            bail!("{source}: [servos] ids[{i}] = {id} must be a Dynamixel ID from 0 to 252");
        }
        if t.ids[..i].contains(&id) {
            bail!("{source}: [servos] ids[{i}] = {id} appears twice; every servo needs its own ID");
        }
        let direction = match &t.directions {
            None => 1,
            Some(d) if d.len() != n => {
                bail!(
                    "{source}: [servos] directions has {} entries, ids has {n}; give one per servo",
                    d.len()
                )
            }
            Some(d) if d[i] == 1 || d[i] == -1 => d[i] as i8,
            Some(d) => bail!("{source}: [servos] directions[{i}] = {} must be 1 or -1", d[i]),
        };
        let zero = match &t.zero_offsets {
            None => 0,
            Some(z) if z.len() != n => {
                bail!(
                    "{source}: [servos] zero_offsets has {} entries, ids has {n}; give one per servo",
                    z.len()
                )
            }
            Some(z) if (-1_044_479..=1_044_479).contains(&z[i]) => z[i] as i32,
            Some(z) => bail!(
                "{source}: [servos] zero_offsets[{i}] = {} must be within -1044479 to 1044479 pulses",
                z[i]
            ),
        };
        mounts.push(ServoMount { id: id as u8, direction, zero_offset_pulses: zero });
    }
    let baud_rate = t.baud_rate.unwrap_or(DEFAULT_BAUD_RATE);
    if !BAUD_RATES.contains(&baud_rate) {
        bail!("{source}: [servos] baud_rate = {baud_rate} must be one the servos support: {BAUD_RATES:?}");
    }
    let model = match &t.model {
        Some(name) => Some(
            sandslope::servo::ServoModel::by_name(name)
                .map_err(|e| anyhow!("{source}: [servos] model = {e}"))?,
        ),
        None => None,
    };
    Ok(Servos { mounts, baud_rate, model })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn servos_table_is_split_off_and_checked() {
        let text = "mass_kg = 0.35\n[servos]\nids = [1, 2, 3, 4, 5, 6]\ndirections = [1, 1, 1, -1, -1, -1]\n";
        let (robot, servos) = split_servos_table(text);
        assert_eq!(robot, "mass_kg = 0.35\n\n\n\n");
        let s = parse_servos(&servos.unwrap(), &Source::Preset("t")).unwrap();
        assert_eq!(s.mounts[3], ServoMount { id: 4, direction: -1, zero_offset_pulses: 0 });
        assert_eq!(s.baud_rate, 57_600);
        let bad = parse_servos("[servos]\nids = [1, 1]\n", &Source::Preset("t")).unwrap_err().to_string();
        assert!(bad.contains("ids[1] = 1 appears twice"), "{bad}");
        let bad = parse_servos("[servos]\nids = [1, 300]\n", &Source::Preset("t")).unwrap_err().to_string();
        assert!(bad.contains("0 to 252"), "{bad}");
        let bad = parse_servos("[servos]\nids = [1]\ndirections = [2]\n", &Source::Preset("t"))
            .unwrap_err()
            .to_string();
        assert!(bad.contains("must be 1 or -1"), "{bad}");
    }

    #[test]
    fn log_round_trip_with_header() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("log.csv");
        let row = ServoLogRow {
            time_s: 0.25,
            id: 3,
            leg: 2,
            tripod: 0,
            present_position: -4100,
            present_velocity: 262,
            present_current_ma: 120,
            load_percent: 8.16,
            input_voltage_v: 5.0,
            temperature_c: 31,
            hardware_error: 0,
            goal_position: -4096,
            leg_angle_rad: 1.5,
            drive_torque_n_m: 0.042,
        };
        let mut w = ServoLogWriter::new(std::fs::File::create(&path).unwrap(), &[("slope_deg", "20".into())])
            .unwrap();
        w.write(&row).unwrap();
        w.finish().unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text.lines().nth(2).unwrap(), COLUMNS.join(","));
        let log = read_servo_log(&path).unwrap();
        assert_eq!(log.rows, vec![row]);
        assert_eq!(log.meta_f64("slope_deg", &path).unwrap(), Some(20.0));
        std::fs::write(&path, format!("{}\n1,x,0,0,0,0,0,0,0,0,0,0,0,0\n", COLUMNS.join(","))).unwrap();
        let e = read_servo_log(&path).unwrap_err().to_string();
        assert!(e.contains("line 2"), "{e}");
    }

    fn row(t: f64) -> ServoLogRow {
        ServoLogRow {
            time_s: t,
            id: 1,
            leg: 0,
            tripod: 0,
            present_position: 0,
            present_velocity: 0,
            present_current_ma: 100,
            load_percent: 6.8,
            input_voltage_v: 5.0,
            temperature_c: 30,
            hardware_error: 0,
            goal_position: 0,
            leg_angle_rad: 0.1,
            drive_torque_n_m: 0.035,
        }
    }

    /// The flight recorder: rows on disk as they come, `incomplete` until finished, then the
    /// status lines rewritten in place (the rows untouched); a symbolic link refused.
    #[test]
    fn the_flight_log_is_readable_before_it_is_finished() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("run.csv");
        let mut log = FlightLog::create(&path, &[("slope_deg", "10".into())]).unwrap();
        log.write(&row(0.0)).unwrap();
        log.write(&row(0.02)).unwrap();
        // Read while the run is under way (as after a SIGKILL): both rows, and a note.
        let read = read_servo_log(&path).unwrap();
        assert_eq!(read.rows.len(), 2);
        assert!(read.meta["status"].starts_with("incomplete"));
        assert!(read.notes.iter().any(|n| n.contains("marked incomplete")), "{:?}", read.notes);
        let before = std::fs::read(&path).unwrap().len();
        log.finish(&["completed".into(), "49.90".into(), "0.40".into(), "22.0".into()]).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text.len(), before, "the status lines are rewritten in place");
        let read = read_servo_log(&path).unwrap();
        assert_eq!(read.meta["status"], "completed");
        assert_eq!(read.meta["achieved_rate_hz"], "49.90");
        assert!(read.notes.is_empty(), "{:?}", read.notes);
        let link = dir.path().join("link.csv");
        std::os::unix::fs::symlink(&path, &link).unwrap();
        let e = FlightLog::create(&link, &[]).unwrap_err().to_string();
        assert!(e.contains("a symbolic link"), "{e}");
    }

    /// A UTF-8 BOM (a spreadsheet's export) does not hide `time_s`; a line of 64 KiB and more is
    /// refused at once, naming it; values far outside a servo's range name the column and unit.
    #[test]
    fn the_reader_takes_a_bom_and_refuses_long_lines_and_implausible_values() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("log.csv");
        let good = "0,1,0,0,0,0,100,6.8,5,30,0,0,0.1,0.035\n";
        std::fs::write(&path, format!("\u{feff}{}\n{good}", COLUMNS.join(","))).unwrap();
        assert_eq!(read_servo_log(&path).unwrap().rows, vec![row(0.0)]);
        std::fs::write(&path, "x".repeat(200_000)).unwrap();
        let e = read_servo_log(&path).unwrap_err().to_string();
        assert!(e.contains("line 1 is longer than 65536 bytes"), "{e}");
        let huge = good.replace("0.035", "1e300");
        std::fs::write(&path, format!("{}\n{huge}", COLUMNS.join(","))).unwrap();
        let e = read_servo_log(&path).unwrap_err().to_string();
        assert!(
            e.contains("line 2") && e.contains("`drive_torque_n_m` = 1e300 is outside -20 to 20 N m"),
            "{e}"
        );
    }
}
