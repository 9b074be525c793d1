//! Anchoring-time tables: `slope_deg,t1_s,t1_sd_s` (one row per slope, as `sandslope track`
//! measures t1), read into the library's [`AnchoringObservation`]s for `calibrate --t1`.

use std::path::Path;

use anyhow::{anyhow, bail, Result};

use sandslope::{AnchoringObservation, Slope};

use sandslope_files::read_text;

/// One row of an anchoring-time file.
#[derive(Debug, Clone, Copy, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct AnchoringRow {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Mean anchoring time after touchdown, s.
    pub t1_s: f64,
    /// Its standard deviation, s.
    pub t1_sd_s: f64,
}

/// Reads an anchoring-time CSV (`#` comments allowed), validating every row.
pub fn load_anchoring_times(path: &Path) -> Result<Vec<AnchoringObservation>> {
    let text = read_text(path)?;
    let mut reader =
        csv::ReaderBuilder::new().trim(csv::Trim::All).comment(Some(b'#')).from_reader(text.as_bytes());
    let mut out = Vec::new();
    for (i, row) in reader.deserialize::<AnchoringRow>().enumerate() {
        let line = i + 2;
        let row = row.map_err(|e| {
            anyhow!("{}: line {line}: {e} (expected columns slope_deg,t1_s,t1_sd_s)", path.display())
        })?;
        let slope = Slope::from_degrees(row.slope_deg)
            .map_err(|e| anyhow!("{}: line {line}: {e}", path.display()))?;
        if !(row.t1_s.is_finite() && row.t1_s >= 0.0) {
            bail!("{}: line {line}: t1_s = {} must be a finite number >= 0", path.display(), row.t1_s);
        }
        if !(row.t1_sd_s.is_finite() && row.t1_sd_s > 0.0) {
            bail!("{}: line {line}: t1_sd_s = {} must be greater than 0", path.display(), row.t1_sd_s);
        }
        out.push(AnchoringObservation { slope, t1: row.t1_s, t1_sd: row.t1_sd_s });
    }
    if out.is_empty() {
        bail!(
            "{}: no data rows (expected a header slope_deg,t1_s,t1_sd_s and one row per slope)",
            path.display()
        );
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_rows_and_names_the_line_of_a_bad_sd() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t1.csv");
        std::fs::write(&p, "# from track\nslope_deg,t1_s,t1_sd_s\n0,0.011,0.003\n20, 0.05 ,0.01\n").unwrap();
        let v = load_anchoring_times(&p).unwrap();
        assert_eq!(v.len(), 2);
        assert_eq!((v[1].slope.degrees(), v[1].t1, v[1].t1_sd), (20.0, 0.05, 0.01));
        std::fs::write(&p, "slope_deg,t1_s,t1_sd_s\n0,0.011,0.003\n10,0.02,0\n").unwrap();
        let e = load_anchoring_times(&p).unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("t1_sd_s = 0"), "{e}");
    }
}
