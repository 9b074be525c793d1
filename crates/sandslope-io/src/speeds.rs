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
    const COLUMNS: [&str; 3] = ["slope_deg", "speed_m_s", "speed_sd_m_s"];
    let headers = reader.headers().map_err(|e| anyhow!("{}: line 1: {e}", path.display()))?.clone();
    let names: Vec<&str> = headers.iter().collect();
    if names != COLUMNS {
        bail!(
            "{}: line 1: the header is `{}`; expected columns slope_deg,speed_m_s,speed_sd_m_s",
            path.display(),
            names.join(",")
        );
    }
    let mut out = Vec::new();
    for record in reader.records() {
        let record = record
            .map_err(|e| anyhow!("{}: {e} (expected columns {})", path.display(), COLUMNS.join(",")))?;
        let line = record.position().map_or(0, |p| p.line());
        if record.len() != COLUMNS.len() {
            bail!(
                "{}: line {line}: {} cells; expected 3 ({})",
                path.display(),
                record.len(),
                COLUMNS.join(",")
            );
        }
        // Cells by column name, so an error names the column, not a field index.
        let cell = |i: usize| -> Result<f64> {
            let text = &record[i];
            text.parse::<f64>().map_err(|_| {
                anyhow!("{}: line {line}: column {}: `{text}` is not a number", path.display(), COLUMNS[i])
            })
        };
        let row = SpeedRow { slope_deg: cell(0)?, speed_m_s: cell(1)?, speed_sd_m_s: cell(2)? };
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

#[cfg(test)]
mod tests {
    use super::*;

    fn load(text: &str) -> Result<Vec<SpeedObservation>> {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("s.csv");
        std::fs::write(&p, text).unwrap();
        load_speeds(&p)
    }

    #[test]
    fn errors_name_the_column_and_the_line_despite_comments() {
        let e = load("slope_deg,speed_m_s,speed_sd_m_s\n# measured 2025\n0,0.15,0.01\n10,abc,0.01\n")
            .unwrap_err();
        let msg = e.to_string();
        assert!(msg.ends_with("line 4: column speed_m_s: `abc` is not a number"), "{msg}");
        let e = load("slope,speed,sd\n0,0.1,0.01\n").unwrap_err().to_string();
        assert!(
            e.contains("line 1") && e.contains("expected columns slope_deg,speed_m_s,speed_sd_m_s"),
            "{e}"
        );
        let ok = load("slope_deg,speed_m_s,speed_sd_m_s\n0, 0.15 ,0.01\n").unwrap();
        assert_eq!((ok[0].speed, ok[0].speed_sd), (0.15, 0.01));
    }
}
