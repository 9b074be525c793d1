//! Speed tables: `slope_deg,speed_m_s,speed_sd_m_s` (as `data/paper-speeds.csv` and
//! `sandslope track --speeds-out`), read into the library's [`SpeedObservation`]s.

use std::path::Path;

use anyhow::{anyhow, bail, Result};

use sandslope::{Slope, SpeedObservation};

use sandslope_files::{read_text, record_line};

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

/// The three columns every speeds table has, in the order `track --speeds-out` writes them.
const COLUMNS: [&str; 3] = ["slope_deg", "speed_m_s", "speed_sd_m_s"];

/// Which columns a reader of a speeds table accepts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpeedColumns {
    /// Exactly `slope_deg,speed_m_s,speed_sd_m_s`, in that order (`calibrate`, `sweep`,
    /// `report`, and `track --speeds-out`, which appends rows in that order to the file).
    Plain,
    /// Those by name in any order and optionally `n`, the steps or trials averaged (`infer
    /// --observed`).
    WithCount,
}

impl SpeedColumns {
    fn expected(self) -> &'static str {
        match self {
            SpeedColumns::Plain => "slope_deg,speed_m_s,speed_sd_m_s",
            SpeedColumns::WithCount => "slope_deg,speed_m_s,speed_sd_m_s[,n]",
        }
    }
}

/// One validated row of a speeds table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedTableRow {
    /// Line of the file (1 is the header), for messages about the row.
    pub line: u64,
    /// `slope_deg`, checked.
    pub slope: Slope,
    /// `speed_m_s`, finite.
    pub speed_m_s: f64,
    /// `speed_sd_m_s`, finite and greater than 0.
    pub speed_sd_m_s: f64,
    /// `n` (at least 1), when the table has that column.
    pub n: Option<usize>,
}

/// Largest speed magnitude a speeds table may hold, m/s: 10 m/s (36 km/h) is far beyond any
/// legged robot on sand, so a larger value is a typo or a unit error, and refusing it keeps
/// values such as -1e308 from every fit and figure downstream (issue 21).
pub const MAX_SPEED_M_S: f64 = 10.0;

/// Smallest speed SD a speeds table may hold, m/s (1 um/s): a smaller SD would weigh one row
/// more than 10^12 times a 1 mm/s one and overflow chi^2 (an SD of 1e-320 made it inf).
pub const MIN_SPEED_SD_M_S: f64 = 1e-6;

/// Reads a speeds table, `slope_deg,speed_m_s,speed_sd_m_s` (with [`SpeedColumns::WithCount`]
/// by name in any order, and optionally `n`): the one reader of that format
/// ([`load_speeds`] and `observations::load_speed_observations` build on it). Blank lines
/// and `#` comments are skipped; errors name the file, its line and the column, and the valid
/// range (|speed| <= [`MAX_SPEED_M_S`], SD in [[`MIN_SPEED_SD_M_S`], [`MAX_SPEED_M_S`]]).
pub fn read_speed_table(path: &Path, columns: SpeedColumns) -> Result<Vec<SpeedTableRow>> {
    parse_speed_table(&read_text(path)?, path, columns)
}

/// [`read_speed_table`] on text already in memory; `path` names it in messages.
pub fn parse_speed_table(text: &str, path: &Path, columns: SpeedColumns) -> Result<Vec<SpeedTableRow>> {
    let mut reader =
        csv::ReaderBuilder::new().trim(csv::Trim::All).comment(Some(b'#')).from_reader(text.as_bytes());
    let expected = columns.expected();
    let headers = reader.headers().map_err(|e| anyhow!("{}: line 1: {e}", path.display()))?.clone();
    let names: Vec<&str> = headers.iter().collect();
    let col = |name: &str| names.iter().position(|h| *h == name);
    let (Some(c_slope), Some(c_speed), Some(c_sd)) = (col(COLUMNS[0]), col(COLUMNS[1]), col(COLUMNS[2]))
    else {
        bail!("{}: line 1: the header is `{}`; expected columns {expected}", path.display(), names.join(","));
    };
    let allowed: &[&str] = match columns {
        SpeedColumns::Plain => &COLUMNS,
        SpeedColumns::WithCount => &["slope_deg", "speed_m_s", "speed_sd_m_s", "n"],
    };
    if let Some(extra) = names.iter().find(|h| !allowed.contains(h)) {
        bail!("{}: line 1: unknown column `{extra}` (expected columns {expected})", path.display());
    }
    if columns == SpeedColumns::Plain && names != COLUMNS {
        // `track --speeds-out` appends rows in this order: another order would be corrupted.
        bail!("{}: line 1: the header is `{}`; expected columns {expected}", path.display(), names.join(","));
    }
    let c_n = col("n");
    let mut out = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| anyhow!("{}: {e} (expected columns {expected})", path.display()))?;
        let line = record.position().map_or(0, |p| record_line(text, p));
        // Cells by column name, so an error names the column, not a field index.
        let cell = |c: usize| -> Result<f64> {
            let text = &record[c];
            text.parse::<f64>().map_err(|_| {
                anyhow!("{}: line {line}: column {}: `{text}` is not a number", path.display(), names[c])
            })
        };
        let row =
            SpeedRow { slope_deg: cell(c_slope)?, speed_m_s: cell(c_speed)?, speed_sd_m_s: cell(c_sd)? };
        let slope = Slope::from_degrees(row.slope_deg)
            .map_err(|e| anyhow!("{}: line {line}: {e}", path.display()))?;
        if !(row.speed_m_s.is_finite() && row.speed_m_s.abs() <= MAX_SPEED_M_S) {
            bail!(
                "{}: line {line}: column speed_m_s: {} is not a robot's speed on sand: expected a number \
                 from -{MAX_SPEED_M_S} to {MAX_SPEED_M_S} m/s",
                path.display(),
                &record[c_speed]
            );
        }
        if !(row.speed_sd_m_s.is_finite() && (MIN_SPEED_SD_M_S..=MAX_SPEED_M_S).contains(&row.speed_sd_m_s)) {
            bail!(
                "{}: line {line}: column speed_sd_m_s: {} is outside the valid range {MIN_SPEED_SD_M_S:e} \
                 to {MAX_SPEED_M_S} m/s (a standard deviation, greater than 0)",
                path.display(),
                &record[c_sd]
            );
        }
        let n = match c_n {
            None => None,
            Some(c) => Some(record[c].parse::<usize>().ok().filter(|&n| n >= 1).ok_or_else(|| {
                anyhow!(
                    "{}: line {line}: n `{}` must be a whole number of at least 1",
                    path.display(),
                    &record[c]
                )
            })?),
        };
        if let Some(first) = out.iter().find(|r: &&SpeedTableRow| r.slope == slope) {
            bail!(
                "{}: lines {} and {line} both give slope_deg = {}: pool them into one mean and SD \
                 (one row per slope)",
                path.display(),
                first.line,
                row.slope_deg
            );
        }
        out.push(SpeedTableRow { line, slope, speed_m_s: row.speed_m_s, speed_sd_m_s: row.speed_sd_m_s, n });
    }
    if out.is_empty() {
        bail!("{}: no data rows (expected a header {expected} and one row per slope)", path.display());
    }
    Ok(out)
}

/// Reads a speeds CSV (`slope_deg,speed_m_s,speed_sd_m_s`) into observations, validating
/// every row.
pub fn load_speeds(path: &Path) -> Result<Vec<SpeedObservation>> {
    Ok(observations(read_speed_table(path, SpeedColumns::Plain)?))
}

/// [`load_speeds`] on text already in memory (a file about to be written); `path` names it.
pub fn parse_speeds(text: &str, path: &Path) -> Result<Vec<SpeedObservation>> {
    Ok(observations(parse_speed_table(text, path, SpeedColumns::Plain)?))
}

fn observations(rows: Vec<SpeedTableRow>) -> Vec<SpeedObservation> {
    rows.into_iter()
        .map(|r| SpeedObservation { slope: r.slope, speed: r.speed_m_s, speed_sd: r.speed_sd_m_s })
        .collect()
}

#[cfg(test)]
mod tests {
    /// The paper's speeds are written twice, as the file users pass (`data/paper-speeds.csv`)
    /// and as the library's constant the report compares with (`sandslope::paper::SPEEDS`):
    /// they must be the same numbers, bit for bit.
    #[test]
    fn the_paper_speeds_file_is_the_librarys_constant() {
        let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/paper-speeds.csv");
        let got: Vec<(f64, f64, f64)> = load_speeds(&file)
            .unwrap()
            .into_iter()
            .map(|o| (o.slope.degrees(), o.speed, o.speed_sd))
            .collect();
        assert_eq!(got, sandslope::paper::SPEEDS.to_vec());
    }

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

    /// `infer` finds columns by name and reads `n`; the others keep the fixed order `track`
    /// appends in; every error names its line, whatever comments come before it.
    #[test]
    fn columns_by_name_and_n_only_where_asked() {
        let e = load("speed_sd_m_s,slope_deg,speed_m_s\n0.01,10,0.12\n").unwrap_err().to_string();
        assert!(e.contains("line 1: the header is `speed_sd_m_s,slope_deg,speed_m_s`; expected"), "{e}");
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("any-order.csv");
        std::fs::write(&p, "speed_sd_m_s,n,slope_deg,speed_m_s\n0.01,4,10,0.12\n").unwrap();
        let r = read_speed_table(&p, SpeedColumns::WithCount).unwrap()[0];
        assert_eq!((r.slope.degrees(), r.speed_m_s, r.speed_sd_m_s, r.n), (10.0, 0.12, 0.01, Some(4)));
        let e = load("slope_deg,speed_m_s,speed_sd_m_s,n\n10,0.12,0.01,4\n").unwrap_err().to_string();
        assert!(
            e.contains("line 1: unknown column `n` (expected columns slope_deg,speed_m_s,speed_sd_m_s)"),
            "{e}"
        );
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("s.csv");
        std::fs::write(&p, "slope_deg,speed_m_s,speed_sd_m_s,n\n# a\n\n# b\n10,0.12,0.01,4\n15,0.1,0.01\n")
            .unwrap();
        let e = read_speed_table(&p, SpeedColumns::WithCount).unwrap_err().to_string();
        assert!(
            e.contains("line: 6") && e.contains("expected columns slope_deg,speed_m_s,speed_sd_m_s[,n]"),
            "{e}"
        );
        std::fs::write(&p, "slope_deg,speed_m_s,speed_sd_m_s,n\n# a\n10,0.12,0.01,4\n# b\n15,0.1,0.01,x\n")
            .unwrap();
        let e = read_speed_table(&p, SpeedColumns::WithCount).unwrap_err().to_string();
        assert!(e.ends_with("line 5: n `x` must be a whole number of at least 1"), "{e}");
        std::fs::write(&p, "slope_deg,speed_m_s,speed_sd_m_s,n\n# a\n10,0.12,0.01,4\n").unwrap();
        let rows = read_speed_table(&p, SpeedColumns::WithCount).unwrap();
        assert_eq!((rows[0].line, rows[0].n), (3, Some(4)));
    }

    /// Values no robot on sand has (the fuzz's -1e308 speed, SDs of 1e-320 and 1e308) are
    /// refused at the edge with the file, line, column and valid range; the bounds themselves pass.
    #[test]
    fn implausible_speeds_and_sds_are_refused_with_the_range() {
        let row = |v: &str, sd: &str| load(&format!("slope_deg,speed_m_s,speed_sd_m_s\n0,{v},{sd}\n"));
        let e = row("-1e308", "0.01").unwrap_err().to_string();
        assert!(e.contains("line 2: column speed_m_s: -1e308") && e.contains("from -10 to 10 m/s"), "{e}");
        for sd in ["1e-320", "1e308", "0", "-0.01", "inf"] {
            let e = row("0.1", sd).unwrap_err().to_string();
            assert!(
                e.contains("line 2: column speed_sd_m_s") && e.contains("valid range 1e-6 to 10 m/s"),
                "{sd}: {e}"
            );
        }
        assert_eq!(row("-10", "1e-6").unwrap()[0].speed, -10.0);
        assert_eq!(row("10", "10").unwrap()[0].speed_sd, 10.0);
    }

    /// Two rows at one slope are refused by the reader, naming both lines (calibrate and infer
    /// refused them later without naming the file).
    #[test]
    fn two_rows_at_one_slope_name_both_lines() {
        let e = load("slope_deg,speed_m_s,speed_sd_m_s\n10,0.1,0.01\n# again\n10,0.12,0.01\n")
            .unwrap_err()
            .to_string();
        assert!(e.ends_with("s.csv: lines 2 and 4 both give slope_deg = 10: pool them into one mean and SD (one row per slope)"), "{e}");
    }

    /// The text form reads what the file form reads, naming the path it was given.
    #[test]
    fn parse_speeds_names_the_path() {
        let p = Path::new("out/speeds.csv");
        let ok = parse_speeds("slope_deg,speed_m_s,speed_sd_m_s\n20,0.05,0.004\n", p).unwrap();
        assert_eq!((ok[0].slope.degrees(), ok[0].speed), (20.0, 0.05));
        let e = parse_speeds("slope_deg,speed_m_s,speed_sd_m_s\n20,x,0.004\n", p).unwrap_err().to_string();
        assert!(e.starts_with("out/speeds.csv: line 2"), "{e}");
    }
}
