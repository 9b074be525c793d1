//! Gait observations for `sandslope infer`: a speeds table (`slope_deg,speed_m_s,speed_sd_m_s`
//! with an optional `n` column, as `track --speeds-out` writes and `calibrate` reads) or
//! `track`'s per-step CSV (`track --csv`: one row per step with `speed_m_s` and `t1_s`), read
//! into the library's [`GaitObservation`]s.

use std::collections::HashMap;
use std::path::Path;

use anyhow::{anyhow, bail, Result};

use sandslope::infer::{GaitObservation, MeanAnchoringTime};
use sandslope::Slope;

use crate::speeds::{read_speed_table, SpeedColumns};
use sandslope_files::read_text;

fn reader(text: &str) -> csv::Reader<&[u8]> {
    csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .flexible(false)
        .from_reader(text.as_bytes())
}

/// Reads a speeds table: `slope_deg,speed_m_s,speed_sd_m_s` and optionally `n` (steps or trials
/// averaged), the format `calibrate` reads, through the same reader
/// ([`crate::speeds::read_speed_table`]). With `n` the standard error of the mean is
/// `speed_sd_m_s / sqrt(n)`; without it `speed_sd_m_s` is taken as that standard error.
pub fn load_speed_observations(path: &Path) -> Result<Vec<GaitObservation>> {
    read_speed_table(path, SpeedColumns::WithCount)?
        .into_iter()
        .map(|r| {
            let se = r.n.map_or(r.speed_sd_m_s, |n| r.speed_sd_m_s / (n as f64).sqrt());
            GaitObservation::new(r.slope, r.speed_m_s, se, None)
                .map_err(|e| anyhow!("{}: line {}: {e}", path.display(), r.line))
        })
        .collect()
}

/// Mean, standard deviation and count of `values`.
fn mean_sd(values: &[f64]) -> (f64, f64, usize) {
    let n = values.len();
    let mean = values.iter().sum::<f64>() / n as f64;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n as f64 - 1.0).max(1.0);
    (mean, var.sqrt(), n)
}

/// Reads `track`'s per-step CSV (`track --csv`: columns including `speed_m_s` and `t1_s`; an
/// empty `t1_s` is an unanchored step) recorded at `slope`, into one observation: the mean speed
/// over steps with standard error `sd / sqrt(n)`, and the mean anchoring time over anchored
/// steps with its own standard error. At least two steps with different speeds are needed.
pub fn load_step_observation(path: &Path, slope: Slope) -> Result<GaitObservation> {
    let text = read_text(path)?;
    let mut r = reader(&text);
    let headers = r.headers().map_err(|e| anyhow!("{}: {e}", path.display()))?.clone();
    let cols: HashMap<&str, usize> = headers.iter().enumerate().map(|(i, h)| (h, i)).collect();
    let Some(&c_speed) = cols.get("speed_m_s") else {
        bail!(
            "{}: line 1: no speed_m_s column (expected track's per-step CSV: file,touchdown_s,t1_s,slip_m,step_m,speed_m_s)",
            path.display()
        );
    };
    let c_t1 = cols.get("t1_s").copied();
    let (mut speeds, mut t1s) = (Vec::new(), Vec::new());
    for (i, row) in r.records().enumerate() {
        let line = i + 2;
        let row = row.map_err(|e| anyhow!("{}: line {line}: {e}", path.display()))?;
        let v: f64 =
            row.get(c_speed).and_then(|s| s.parse().ok()).filter(|v: &f64| v.is_finite()).ok_or_else(
                || {
                    anyhow!(
                        "{}: line {line}: speed_m_s `{}` is not a number",
                        path.display(),
                        row.get(c_speed).unwrap_or("")
                    )
                },
            )?;
        speeds.push(v);
        if let Some(c) = c_t1 {
            match row.get(c).unwrap_or("") {
                "" | "-" => {}
                s => t1s.push(s.parse::<f64>().ok().filter(|t| t.is_finite() && *t >= 0.0).ok_or_else(|| {
                    anyhow!("{}: line {line}: t1_s `{s}` must be a number of at least 0 (or empty: unanchored)", path.display())
                })?),
            }
        }
    }
    let (speed, sd, n) = mean_sd(&speeds);
    if n < 2 || sd <= 0.0 {
        bail!(
            "{}: the speed's standard error needs at least two steps with different speeds (found {n} steps)",
            path.display()
        );
    }
    let anchoring = if t1s.len() >= 2 {
        let (t1, t1_sd, m) = mean_sd(&t1s);
        (t1_sd > 0.0).then(|| MeanAnchoringTime { t1_s: t1, t1_se_s: t1_sd / (m as f64).sqrt() })
    } else {
        None
    };
    GaitObservation::new(slope, speed, sd / (n as f64).sqrt(), anchoring)
        .map_err(|e| anyhow!("{}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(text: &str) -> tempfile::NamedTempFile {
        use std::io::Write;
        let mut f = tempfile::NamedTempFile::new().unwrap();
        f.write_all(text.as_bytes()).unwrap();
        f
    }

    #[test]
    fn speeds_with_and_without_n() {
        let f = file("slope_deg,speed_m_s,speed_sd_m_s,n\n10,0.11,0.02,4\n15,0.105,0.01,1\n");
        let o = load_speed_observations(f.path()).unwrap();
        assert_eq!(o.len(), 2);
        assert!((o[0].speed_se() - 0.01).abs() < 1e-15);
        assert!((o[1].speed_se() - 0.01).abs() < 1e-15);
        let f = file("slope_deg,speed_m_s,speed_sd_m_s\n10,0.11,0.02\n");
        assert!((load_speed_observations(f.path()).unwrap()[0].speed_se() - 0.02).abs() < 1e-15);
        for (bad, says) in [
            (
                "slope_deg,speed_m_s,speed_sd_m_s\n10,0.11,0\n",
                "line 2: column speed_sd_m_s: 0 is outside the valid range",
            ),
            ("slope_deg,speed_m_s,speed_sd_m_s\n10,0.11,-0.01\n", "greater than 0"),
            ("slope_deg,speed_m_s,speed_sd_m_s,n\n10,0.11,0.01,0\n", "n `0`"),
            (
                "slope_deg,speed,speed_sd_m_s\n10,0.11,0.01\n",
                "line 1: the header is `slope_deg,speed,speed_sd_m_s`",
            ),
            ("slope_deg,speed_m_s,speed_sd_m_s,k\n10,0.11,0.01,1\n", "unknown column `k`"),
            ("slope_deg,speed_m_s,speed_sd_m_s\n95,0.11,0.01\n", "line 2: slope_deg"),
            ("slope_deg,speed_m_s,speed_sd_m_s\n", "no data rows"),
        ] {
            let e = load_speed_observations(file(bad).path()).unwrap_err().to_string();
            assert!(e.contains(says), "{bad}: {e}");
        }
    }

    /// Three steps 0.10, 0.12, 0.11 m/s (mean 0.11, sd 0.01, se 0.01/sqrt 3); t1 of two
    /// anchored steps 0.03 and 0.05 (mean 0.04, sd 0.01414, se 0.01); the third unanchored.
    #[test]
    fn steps_by_hand() {
        let f = file(
            "file,touchdown_s,t1_s,slip_m,step_m,speed_m_s\na.csv,0.0,0.03,0.001,0.05,0.10\n\
             a.csv,0.5,,,0.06,0.12\na.csv,1.0,0.05,0.002,0.055,0.11\n",
        );
        let o = load_step_observation(f.path(), Slope::from_degrees(10.0).unwrap()).unwrap();
        assert!((o.speed() - 0.11).abs() < 1e-12);
        assert!((o.speed_se() - 0.01 / 3f64.sqrt()).abs() < 1e-12);
        let a = o.anchoring().unwrap();
        assert!((a.t1_s - 0.04).abs() < 1e-12 && (a.t1_se_s - 0.01).abs() < 1e-12);
        let one = file("file,touchdown_s,t1_s,slip_m,step_m,speed_m_s\na.csv,0.0,0.03,0.001,0.05,0.10\n");
        assert!(load_step_observation(one.path(), Slope::LEVEL)
            .unwrap_err()
            .to_string()
            .contains("two steps"));
    }
}
