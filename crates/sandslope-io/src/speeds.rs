//! Speed tables: `slope_deg,speed_m_s,speed_sd_m_s` (as `data/paper-speeds.csv` and
//! `sandslope track --speeds-out`), read into the library's [`SpeedObservation`]s.

use std::path::Path;

use anyhow::{anyhow, bail, Result};

use sandslope::{Slope, SpeedObservation};

use crate::files::read_text;

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
