//! The measurement manifest (TOML) and trial recordings (CSV) of `sandslope fit`.
//!
//! A manifest names the disk and plate geometry and lists trials; each trial CSV has a header
//! with a position column (`depth_m|mm|cm` for penetration, `displacement_m|mm|cm` for shear),
//! a force column (`force_n`, or `force_counts` with a counts-per-newton factor) and an
//! optional `time_s`. Values are converted to SI here; blank cells become `None` and `NaN`
//! stays NaN so the library can count what it drops. Every error names the file, the line and
//! column or key, and what is valid.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context, Result};
use serde::Deserialize;

use sandslope::measure::{disk_area, Kind, RawRecording, ShearPlate, TrialInput};
use sandslope::Slope;

use sandslope_files::{parse_toml, read_text, Source};

/// `[penetration]`: the disk, by radius or area.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PenetrationTable {
    /// Disk radius, m.
    pub disk_radius_m: Option<f64>,
    /// Disk area, m^2 (instead of the radius).
    pub area_m2: Option<f64>,
}

/// `[shear]`: the plate.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShearTable {
    /// Plate width W_p, m.
    pub plate_width_m: f64,
    /// Insertion depth d_p, m.
    pub plate_depth_m: f64,
}

/// `kind = "penetration" | "shear"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum KindName {
    /// Penetration test.
    Penetration,
    /// Shear test.
    Shear,
}

impl From<KindName> for Kind {
    fn from(k: KindName) -> Kind {
        match k {
            KindName::Penetration => Kind::Penetration,
            KindName::Shear => Kind::Shear,
        }
    }
}

/// One `[[trial]]` as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrialEntry {
    /// Penetration or shear.
    pub kind: KindName,
    /// Slope of the bed, degrees.
    pub slope_deg: f64,
    /// CSV file, relative to the manifest.
    pub file: PathBuf,
    /// An in-air calibration run.
    #[serde(default)]
    pub air: bool,
    /// A bag trial's `geometry_msgs/WrenchStamped` topic (docs/bags.md); the bag's only one
    /// when absent.
    pub force_topic: Option<String>,
    /// A bag trial's intruder pose topic; the bag's only pose topic when absent.
    pub position_topic: Option<String>,
    /// A bag trial's child frame on a TF or odometry topic.
    pub frame: Option<String>,
    /// A bag trial's force component in the load cell's frame (`z`, `-z`, `x`, ...): required
    /// for a bag.
    pub force_axis: Option<String>,
    /// A bag trial's axis of the depth or displacement in the pose topic's frame; the direction
    /// of travel when absent.
    pub position_axis: Option<String>,
}

/// How a trial's bag is read (docs/bags.md): the manifest's keys, axes parsed.
#[derive(Debug, Clone, PartialEq)]
pub struct BagKeys {
    /// `force_topic`.
    pub force_topic: Option<String>,
    /// `position_topic`.
    pub position_topic: Option<String>,
    /// `frame`.
    pub frame: Option<String>,
    /// `force_axis`, a unit vector.
    pub force_axis: [f64; 3],
    /// `position_axis`, a unit vector.
    pub position_axis: Option<[f64; 3]>,
}

/// The manifest file as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ManifestFile {
    /// Name for the terrain file written.
    pub name: Option<String>,
    /// Angle of repose to write in the terrain file, degrees.
    pub repose_deg: Option<f64>,
    /// Disk geometry.
    pub penetration: Option<PenetrationTable>,
    /// Plate geometry.
    pub shear: Option<ShearTable>,
    /// Trials.
    #[serde(default, rename = "trial")]
    pub trials: Vec<TrialEntry>,
}

/// A validated trial: kind, slope, resolved path.
#[derive(Debug, Clone)]
pub struct Trial {
    /// 1-based position in the manifest.
    pub index: usize,
    /// Penetration or shear.
    pub kind: Kind,
    /// Slope, degrees (validated in [0, 90)).
    pub slope_deg: f64,
    /// The path as written in the manifest.
    pub file: PathBuf,
    /// The path resolved against the manifest's folder.
    pub path: PathBuf,
    /// In-air calibration run.
    pub air: bool,
    /// How to read it when the file is a ROS 2 bag (`None` for a CSV).
    pub bag: Option<BagKeys>,
}

/// A validated manifest.
#[derive(Debug, Clone)]
pub struct Manifest {
    /// Where it was read from.
    pub path: PathBuf,
    /// Terrain name.
    pub name: Option<String>,
    /// Angle of repose, degrees.
    pub repose_deg: Option<f64>,
    /// Disk area, m^2.
    pub disk_area_m2: f64,
    /// Shear plate.
    pub plate: ShearPlate,
    /// Trials in manifest order.
    pub trials: Vec<Trial>,
}

/// Reads and validates a manifest: geometry present and positive, slopes in range, at least
/// one measuring (non-air) trial of each kind.
pub fn load_manifest(path: &Path) -> Result<Manifest> {
    let text = read_text(path)?;
    let source = Source::File(path.to_path_buf());
    let file: ManifestFile = parse_toml(&text, &source)?;
    let here = path.display();
    let dir = path.parent().unwrap_or(Path::new("."));
    if file.trials.is_empty() {
        bail!("{here}: no [[trial]] entries (each needs kind, slope_deg, file and optionally air)");
    }
    let mut trials = Vec::with_capacity(file.trials.len());
    for (i, t) in file.trials.iter().enumerate() {
        let index = i + 1;
        Slope::from_degrees(t.slope_deg)
            .map_err(|e| anyhow!("{here}: [[trial]] #{index} ({}): {e}", t.file.display()))?;
        let path = dir.join(&t.file);
        let bag = bag_keys(t, &path)
            .map_err(|e| anyhow!("{here}: [[trial]] #{index} ({}): {e}", t.file.display()))?;
        trials.push(Trial {
            index,
            kind: t.kind.into(),
            slope_deg: t.slope_deg,
            file: t.file.clone(),
            path,
            air: t.air,
            bag,
        });
    }
    for kind in [Kind::Penetration, Kind::Shear] {
        if !trials.iter().any(|t| t.kind == kind && !t.air) {
            let other = trials.iter().filter(|t| t.kind != kind && !t.air).count();
            bail!(
                "{here}: no {kind} trial (with air = false) at any slope, but {other} {} trial(s): a terrain needs \
                 both k_n (penetration) and k_s (shear) measured at one slope at least",
                if kind == Kind::Penetration { Kind::Shear } else { Kind::Penetration }
            );
        }
    }
    let pen = file.penetration.as_ref().ok_or_else(|| {
        anyhow!("{here}: missing [penetration] table (disk_radius_m, e.g. 0.01, or area_m2)")
    })?;
    let disk_area_m2 = match (pen.disk_radius_m, pen.area_m2) {
        (Some(r), None) => disk_area(r).map_err(|e| anyhow!("{here}: [penetration] {e}"))?,
        (None, Some(a)) if a.is_finite() && a > 0.0 => a,
        (None, Some(a)) => {
            bail!("{here}: [penetration] area_m2 = {a} must be a finite number greater than 0")
        }
        (Some(_), Some(_)) => bail!("{here}: [penetration] give either disk_radius_m or area_m2, not both"),
        (None, None) => bail!("{here}: [penetration] needs disk_radius_m (e.g. 0.01) or area_m2"),
    };
    let sh = file
        .shear
        .as_ref()
        .ok_or_else(|| anyhow!("{here}: missing [shear] table (plate_width_m, plate_depth_m)"))?;
    let plate =
        ShearPlate::new(sh.plate_width_m, sh.plate_depth_m).map_err(|e| anyhow!("{here}: [shear] {e}"))?;
    Ok(Manifest {
        path: path.to_path_buf(),
        name: file.name,
        repose_deg: file.repose_deg,
        disk_area_m2,
        plate,
        trials,
    })
}

/// A trial's bag keys: `None` for a CSV (which must have none of them), else the keys with
/// their axes parsed (`force_axis` required).
fn bag_keys(t: &TrialEntry, path: &Path) -> Result<Option<BagKeys>> {
    let given: Vec<&str> = [
        ("force_topic", t.force_topic.is_some()),
        ("position_topic", t.position_topic.is_some()),
        ("frame", t.frame.is_some()),
        ("force_axis", t.force_axis.is_some()),
        ("position_axis", t.position_axis.is_some()),
    ]
    .iter()
    .filter(|k| k.1)
    .map(|k| k.0)
    .collect();
    if !sandslope_bag::is_bag(path) {
        if !given.is_empty() {
            bail!(
                "{} are keys of a ROS 2 bag trial (a bag folder, .mcap or .db3 file), but {} is not one",
                given.join(", "),
                path.display()
            );
        }
        return Ok(None);
    }
    let axis = |key: &str, text: &str| {
        sandslope_bag::wrench::parse_axis(text)
            .ok_or_else(|| anyhow!("{key} = \"{text}\" must be one of x, y, z, -x, -y, -z"))
    };
    let force_axis = match &t.force_axis {
        Some(a) => axis("force_axis", a)?,
        None => bail!(
            "a bag trial needs force_axis: the wrench's force component, in the load cell's frame, that the \
             sand's resistance makes grow (e.g. force_axis = \"z\", or \"-z\" for a cell that reads it negative)"
        ),
    };
    Ok(Some(BagKeys {
        force_topic: t.force_topic.clone(),
        position_topic: t.position_topic.clone(),
        frame: t.frame.clone(),
        force_axis,
        position_axis: t.position_axis.as_deref().map(|a| axis("position_axis", a)).transpose()?,
    }))
}

/// Metres per unit for a length-column suffix.
fn unit_scale(unit: &str) -> Option<f64> {
    match unit {
        "m" => Some(1.0),
        "cm" => Some(1e-2),
        "mm" => Some(1e-3),
        _ => None,
    }
}

/// A trial's columns in SI units, with how many data rows the file had.
#[derive(Debug, Clone)]
pub struct Recording {
    /// The columns, for [`sandslope::measure::clean()`].
    pub raw: RawRecording,
    /// Data rows read.
    pub rows: usize,
}

/// How trial CSVs are read.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ReadOptions {
    /// Load-cell counts per newton, for a `force_counts` column.
    pub counts_per_newton: Option<f64>,
    /// Skip (and count) rows with a cell that is not a number, instead of failing.
    pub skip_malformed: bool,
}

/// Reads every trial of a manifest, in its order, as the library's [`TrialInput`]s; a trial
/// file that does not exist is an error naming the manifest, the trial and the file.
pub fn read_trials(manifest: &Manifest, options: ReadOptions) -> Result<Vec<TrialInput>> {
    let mut out = Vec::with_capacity(manifest.trials.len());
    for trial in &manifest.trials {
        if !(trial.path.is_file() || trial.bag.is_some()) {
            bail!(
                "{}: [[trial]] #{} ({}): trial file {} does not exist",
                manifest.path.display(),
                trial.index,
                trial.file.display(),
                trial.path.display()
            );
        }
        let rec = match &trial.bag {
            Some(keys) => read_bag_recording(&trial.path, keys).map_err(|e| {
                anyhow!(
                    "{}: [[trial]] #{} ({}): {e:#}",
                    manifest.path.display(),
                    trial.index,
                    trial.file.display()
                )
            })?,
            None => read_recording_with(&trial.path, trial.kind, options)?,
        };
        out.push(TrialInput {
            file: trial.file.display().to_string(),
            kind: trial.kind,
            slope_deg: trial.slope_deg,
            air: trial.air,
            rows: rec.rows,
            raw: rec.raw,
        });
    }
    Ok(out)
}

/// Reads one trial from a ROS 2 bag (docs/bags.md): one row per wrench message, its time, the
/// intruder's position at its stamp and its force.
pub fn read_bag_recording(path: &Path, keys: &BagKeys) -> Result<Recording> {
    let options = sandslope_bag::wrench::LoadCellOptions {
        force_topic: keys.force_topic.as_deref(),
        position_topic: keys.position_topic.as_deref(),
        frame: keys.frame.as_deref(),
        force_axis: keys.force_axis,
        position_axis: keys.position_axis,
    };
    let s = sandslope_bag::wrench::read_load_cell(path, &options)?;
    let rows = s.time_s.len();
    let raw = RawRecording {
        time: Some(s.time_s.into_iter().map(Some).collect()),
        position: s.position_m,
        force: s.force_n.into_iter().map(Some).collect(),
        malformed: 0,
    };
    Ok(Recording { raw, rows })
}

/// A recording's cell that is not a number (the file, line and column in the message): the
/// error [`read_trials`] and [`read_recording`] return for it, so a front end can offer to skip
/// such rows ([`ReadOptions::skip_malformed`]) by its type rather than by its words.
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct MalformedCell {
    message: String,
}

/// Reads one trial CSV. `counts_per_newton` converts a `force_counts` column. A cell that is
/// not a number is an error naming the file, line and column.
pub fn read_recording(path: &Path, kind: Kind, counts_per_newton: Option<f64>) -> Result<Recording> {
    read_recording_with(path, kind, ReadOptions { counts_per_newton, skip_malformed: false })
}

/// Reads one trial CSV with `options`: with `skip_malformed`, a row with a cell that is not a
/// number is skipped and counted in [`RawRecording::malformed`] instead of stopping the read.
pub fn read_recording_with(path: &Path, kind: Kind, options: ReadOptions) -> Result<Recording> {
    let counts_per_newton = options.counts_per_newton;
    let here = path.display();
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {here}"))?;
    let position_name = match kind {
        Kind::Penetration => "depth",
        Kind::Shear => "displacement",
    };
    let expected = format!(
        "{position_name}_m, {position_name}_mm or {position_name}_cm, and force_n (or force_counts with \
         a counts-per-newton factor), optionally time_s"
    );
    if text.trim().is_empty() {
        bail!("{here}: empty file (expected a header line with {expected}, then one row per sample)");
    }
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .flexible(true)
        .from_reader(text.as_bytes());
    let header = reader.headers().with_context(|| format!("{here}: cannot read the header line"))?.clone();
    let header_line = header.position().map(|p| p.line()).unwrap_or(1).max(1);
    let names: Vec<String> = header.iter().map(|h| h.to_ascii_lowercase()).collect();

    let Columns { position: (pos_col, pos_scale), force: (force_col, force_scale), time: time_col } =
        columns(&here, header_line, &names, kind, counts_per_newton, &expected)?;

    let mut raw = RawRecording {
        time: time_col.map(|_| Vec::new()),
        position: Vec::new(),
        force: Vec::new(),
        malformed: 0,
    };
    let mut rows = 0;
    for record in reader.records() {
        let record = record.map_err(|e| anyhow!("{here}: {e}"))?;
        let line = record.position().map_or(0, |p| sandslope_files::record_line(&text, p));
        // A line of only separators (or whitespace) is skipped, not counted.
        if record.iter().all(str::is_empty) {
            continue;
        }
        rows += 1;
        let cell = |col: usize, scale: f64| -> Result<Option<f64>> {
            match record.get(col) {
                None | Some("") => Ok(None),
                Some(s) => s.parse::<f64>().map(|v| Some(v * scale)).map_err(|_| {
                    anyhow::Error::new(MalformedCell {
                        message: format!(
                            "{here}: line {line}, column {} ({}): `{s}` is not a number (blank cells and NaN \
                             are accepted and dropped)",
                            col + 1,
                            names[col]
                        ),
                    })
                }),
            }
        };
        let cells = cell(pos_col, pos_scale).and_then(|p| {
            let f = cell(force_col, force_scale)?;
            let t = time_col.map(|c| cell(c, 1.0)).transpose()?;
            Ok((p, f, t))
        });
        let (p, f, t) = match cells {
            Ok(c) => c,
            Err(_) if options.skip_malformed => {
                raw.malformed += 1;
                continue;
            }
            Err(e) => return Err(e),
        };
        raw.position.push(p);
        raw.force.push(f);
        if let (Some(times), Some(t)) = (raw.time.as_mut(), t) {
            times.push(t);
        }
    }
    if rows == 0 {
        bail!("{here}: a header but no data rows (expected {expected})");
    }
    Ok(Recording { raw, rows })
}

/// A trial's columns: position and force (index, factor to metres or newtons), and time.
struct Columns {
    position: (usize, f64),
    force: (usize, f64),
    time: Option<usize>,
}

/// Finds the columns in the header's lower-cased `names`: exactly one `<name>_<unit>` position
/// column with a known unit, `force_n` or `force_counts` (with `counts_per_newton`), `time_s`.
fn columns(
    here: &dyn std::fmt::Display,
    header_line: u64,
    names: &[String],
    kind: Kind,
    counts_per_newton: Option<f64>,
    expected: &str,
) -> Result<Columns> {
    let position_name = match kind {
        Kind::Penetration => "depth",
        Kind::Shear => "displacement",
    };
    // Position column: exactly one `<name>_<unit>` with a known unit.
    let prefix = format!("{position_name}_");
    let mut position: Option<(usize, f64)> = None;
    for (i, n) in names.iter().enumerate() {
        if let Some(unit) = n.strip_prefix(&prefix) {
            let scale = unit_scale(unit).ok_or_else(|| {
                anyhow!(
                    "{here}: line {header_line}, column {}: unknown unit `{unit}` in `{n}` (valid: {position_name}_m, \
                     {position_name}_mm, {position_name}_cm)",
                    i + 1
                )
            })?;
            if position.is_some() {
                bail!("{here}: line {header_line}, column {}: a second {position_name} column `{n}`", i + 1);
            }
            position = Some((i, scale));
        }
    }
    let found = names.join(", ");
    let (pos_col, pos_scale) = position.ok_or_else(|| {
        anyhow!("{here}: line {header_line}: no {position_name} column for a {kind} trial (expected {expected}; found: {found})")
    })?;
    let force_n = names.iter().position(|n| n == "force_n");
    let force_counts = names.iter().position(|n| n == "force_counts");
    let (force_col, force_scale) = match (force_n, force_counts) {
        (Some(_), Some(_)) => bail!("{here}: line {header_line}: both force_n and force_counts; keep one"),
        (Some(i), None) => (i, 1.0),
        (None, Some(i)) => match counts_per_newton {
            Some(c) => (i, 1.0 / c),
            None => bail!(
                "{here}: line {header_line}, column {}: force_counts needs the load cell's counts per newton, from \
                 your calibration (--counts-per-newton; counts_per_newton= in Python)",
                i + 1
            ),
        },
        (None, None) => {
            let unit_hint = names
                .iter()
                .find(|n| n.starts_with("force_"))
                .map(|n| format!(" (`{n}` is not a known force column)"))
                .unwrap_or_default();
            bail!("{here}: line {header_line}: no force column{unit_hint} (expected {expected}; found: {found})")
        }
    };
    let time_col = names.iter().position(|n| n == "time_s");
    Ok(Columns { position: (pos_col, pos_scale), force: (force_col, force_scale), time: time_col })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    #[test]
    fn units_blanks_nan_and_counts() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(dir.path(), "a.csv", "time_s,depth_mm,force_counts\n0,1,100\n0.1,,200\n0.2,3,NaN\n");
        let r = read_recording(&p, Kind::Penetration, Some(50.0)).unwrap();
        assert_eq!(r.rows, 3);
        assert_eq!(r.raw.position, vec![Some(0.001), None, Some(0.003)]);
        assert_eq!(r.raw.force[0], Some(2.0));
        assert!(r.raw.force[2].unwrap().is_nan());
        let p = write(dir.path(), "b.csv", "displacement_cm,force_n\n2.5,1\n");
        let r = read_recording(&p, Kind::Shear, None).unwrap();
        assert!((r.raw.position[0].unwrap() - 0.025).abs() < 1e-15);
    }

    #[test]
    fn bad_cell_names_line_and_column() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(dir.path(), "a.csv", "depth_m,force_n\n0.001,1\n0.002,abc\n");
        let e = read_recording(&p, Kind::Penetration, None).unwrap_err().to_string();
        assert!(e.contains("line 3, column 2 (force_n)") && e.contains("`abc`"), "{e}");
        let opts = ReadOptions { counts_per_newton: None, skip_malformed: true };
        let r = read_recording_with(&p, Kind::Penetration, opts).unwrap();
        assert_eq!((r.rows, r.raw.malformed, r.raw.position.len()), (2, 1, 1));
    }

    /// A lab's notes between rows (`#` lines) and blank lines do not shift the line an error
    /// names: the bad cell below is on line 6 of the file, right after a note and a blank line
    /// (the csv reader places the record where it began reading, line 4).
    #[test]
    fn bad_cell_line_counts_comments_and_blank_lines() {
        let dir = tempfile::tempdir().unwrap();
        let text =
            "# rig 2, operator notes\ndepth_m,force_n\n0.001,1\n# re-zeroed here\n\n0.002,abc\n0.003,3\n";
        let p = write(dir.path(), "a.csv", text);
        let e = read_recording(&p, Kind::Penetration, None).unwrap_err().to_string();
        assert!(e.contains("line 6, column 2 (force_n)"), "{e}");
    }
}
