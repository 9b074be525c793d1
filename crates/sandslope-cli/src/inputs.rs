//! Reading robots, terrains and speed tables from files or presets, into validated types.
//!
//! This is the edge where user input becomes library types: every error names the file (or
//! preset), the key or line, and the valid range.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context, Result};
use serde::de::DeserializeOwned;

use sandslope::{Robot, RobotSpec, Slope, SpeedObservation, Terrain, TerrainSpec};

use crate::presets::{self, PresetKind};

/// Where a robot or terrain came from, for messages.
#[derive(Debug, Clone)]
pub enum Source {
    /// A built-in preset.
    Preset(&'static str),
    /// A file.
    File(PathBuf),
}

impl std::fmt::Display for Source {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Source::Preset(n) => write!(f, "preset `{n}`"),
            Source::File(p) => write!(f, "{}", p.display()),
        }
    }
}

/// Reads a whole file, naming it in the error.
pub fn read_text(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))
}

/// Parses TOML into `T`, naming the source; unknown keys are rejected by `T`'s definition.
pub fn parse_toml<T: DeserializeOwned>(text: &str, source: &Source) -> Result<T> {
    toml::from_str(text).map_err(|e| anyhow!("{source}: {}", e.to_string().trim_end()))
}

/// Resolves `arg` to a preset of `kind` or a file: an existing path, or anything ending in
/// `.toml`, is a file; otherwise it must be a preset name.
fn resolve(arg: &str, kind: PresetKind) -> Result<(Source, String)> {
    let path = Path::new(arg);
    if path.exists() || arg.ends_with(".toml") {
        return Ok((Source::File(path.to_path_buf()), read_text(path)?));
    }
    match presets::find(arg, kind) {
        Some(p) => Ok((Source::Preset(p.name), p.toml.to_string())),
        None => {
            let what = if kind == PresetKind::Robot { "robot" } else { "terrain" };
            bail!(
                "`{arg}` is neither a {what} file nor a built-in {what} (built-in: {})",
                presets::names(kind)
            )
        }
    }
}

/// Loads a robot from a file or preset name.
pub fn load_robot(arg: &str) -> Result<Robot> {
    let (source, text) = resolve(arg, PresetKind::Robot)?;
    robot_from_toml(&text, &source)
}

/// Parses and validates a robot.
pub fn robot_from_toml(text: &str, source: &Source) -> Result<Robot> {
    let spec: RobotSpec = parse_toml(text, source)?;
    Robot::new(spec).map_err(|e| anyhow!("{source}: {e}"))
}

/// Loads a terrain from a file or preset name.
pub fn load_terrain(arg: &str) -> Result<Terrain> {
    let (source, text) = resolve(arg, PresetKind::Terrain)?;
    terrain_from_toml(&text, &source)
}

/// Parses and validates a terrain.
pub fn terrain_from_toml(text: &str, source: &Source) -> Result<Terrain> {
    let spec: TerrainSpec = parse_toml(text, source)?;
    Terrain::new(spec).map_err(|e| anyhow!("{source}: {e}"))
}

/// One row of a speeds file (`slope_deg,speed_m_s,speed_sd_m_s`, as `data/paper-speeds.csv`).
#[derive(Debug, Clone, Copy, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct SpeedRow {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Mean step-averaged speed, m/s.
    pub speed_m_s: f64,
    /// Its standard deviation, m/s.
    pub speed_sd_m_s: f64,
}

/// Reads a speeds CSV into observations, validating every row.
pub fn load_speeds(path: &Path) -> Result<Vec<SpeedObservation>> {
    let text = read_text(path)?;
    let mut reader =
        csv::ReaderBuilder::new().trim(csv::Trim::All).comment(Some(b'#')).from_reader(text.as_bytes());
    let mut out = Vec::new();
    for (i, row) in reader.deserialize::<SpeedRow>().enumerate() {
        // Line numbers: the header is line 1.
        let line = i + 2;
        let row = row.map_err(|e| {
            anyhow!(
                "{}: line {line}: {e} (expected columns slope_deg,speed_m_s,speed_sd_m_s)",
                path.display()
            )
        })?;
        let slope = Slope::from_degrees(row.slope_deg)
            .map_err(|e| anyhow!("{}: line {line}: {e}", path.display()))?;
        if !row.speed_m_s.is_finite() {
            bail!("{}: line {line}: speed_m_s = {} must be a finite number", path.display(), row.speed_m_s);
        }
        if !(row.speed_sd_m_s.is_finite() && row.speed_sd_m_s > 0.0) {
            bail!(
                "{}: line {line}: speed_sd_m_s = {} must be greater than 0",
                path.display(),
                row.speed_sd_m_s
            );
        }
        out.push(SpeedObservation { slope, speed: row.speed_m_s, speed_sd: row.speed_sd_m_s });
    }
    if out.is_empty() {
        bail!(
            "{}: no data rows (expected a header slope_deg,speed_m_s,speed_sd_m_s and one row per slope)",
            path.display()
        );
    }
    Ok(out)
}

/// Checks a command-line number: finite and within `lo..=hi`, naming the flag (`hi` infinite:
/// no upper bound).
pub fn check_flag(flag: &str, value: f64, lo: f64, hi: f64) -> Result<f64> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(value)
    } else if hi == f64::INFINITY {
        bail!("{flag} = {value} must be a finite number of at least {lo}")
    } else {
        bail!("{flag} = {value} must be between {lo} and {hi}")
    }
}

/// Checks a command-line number is finite and strictly positive, naming the flag.
pub fn check_positive(flag: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        bail!("{flag} = {value} must be a finite number greater than 0")
    }
}
