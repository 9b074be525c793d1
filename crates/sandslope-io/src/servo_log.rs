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

use crate::files::Source;

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
        Ok(ServoLogWriter { writer: csv::Writer::from_writer(out), rows: 0 })
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

    /// Rows written.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Flushes everything.
    pub fn finish(mut self) -> std::io::Result<()> {
        self.writer.flush()
    }
}

/// A servo log read back: its header's `key = value` pairs and its rows.
#[derive(Debug, Clone, PartialEq)]
pub struct ServoLog {
    /// `# key = value` lines of the header.
    pub meta: BTreeMap<String, String>,
    /// The rows.
    pub rows: Vec<ServoLogRow>,
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
}

/// Most rows a log may hold (an hour at 100 Hz on 12 servos).
pub const MAX_ROWS: usize = 5_000_000;

/// Reads a servo log; errors name the file, the line and the column.
pub fn read_servo_log(path: &Path) -> Result<ServoLog> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read servo log {}", path.display()))?;
    let mut meta = BTreeMap::new();
    let mut header_lines = 0usize;
    for line in text.lines() {
        let Some(rest) = line.strip_prefix('#') else { break };
        header_lines += 1;
        if let Some((k, v)) = rest.split_once('=') {
            meta.insert(k.trim().to_string(), v.trim().to_string());
        }
    }
    let body: String = text.lines().skip(header_lines).collect::<Vec<_>>().join("\n");
    let mut reader = csv::ReaderBuilder::new().from_reader(body.as_bytes());
    let headers =
        reader.headers().with_context(|| format!("{}: no column header line", path.display()))?.clone();
    for want in ["time_s", "id", "leg", "leg_angle_rad", "drive_torque_n_m"] {
        if !headers.iter().any(|h| h == want) {
            bail!("{}: the column `{want}` is missing (a servo log as `sandslope drive --log` writes it has {})", path.display(), COLUMNS.join(","));
        }
    }
    let mut rows = Vec::new();
    for (i, rec) in reader.deserialize::<ServoLogRow>().enumerate() {
        let line = header_lines + 2 + i;
        let row =
            rec.map_err(|e| anyhow!("{}: line {line}: {}", path.display(), e.to_string().trim_end()))?;
        if !(row.time_s.is_finite() && row.leg_angle_rad.is_finite() && row.drive_torque_n_m.is_finite()) {
            bail!(
                "{}: line {line}: time_s, leg_angle_rad and drive_torque_n_m must be finite numbers",
                path.display()
            );
        }
        rows.push(row);
        if rows.len() > MAX_ROWS {
            bail!("{}: more than {MAX_ROWS} rows; split the log", path.display());
        }
    }
    if rows.is_empty() {
        bail!("{}: the log has no rows", path.display());
    }
    Ok(ServoLog { meta, rows })
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
}

/// The servos of a robot file and their bus's baud rate.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Servos {
    /// Servos in leg order.
    pub mounts: Vec<ServoMount>,
    /// Baud rate, one the XL330 supports.
    pub baud_rate: u32,
}

/// Baud rates the XL330 supports (Baud Rate (8) values 0 to 6).
pub const BAUD_RATES: [u32; 7] = [9_600, 57_600, 115_200, 1_000_000, 2_000_000, 3_000_000, 4_000_000];
/// The XL330's factory baud rate.
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
        bail!("{source}: [servos] baud_rate = {baud_rate} must be one the XL330 supports: {BAUD_RATES:?}");
    }
    Ok(Servos { mounts, baud_rate })
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
}
