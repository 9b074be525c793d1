//! `sandslope fit`: k_n and k_s per slope from load-cell recordings (MODEL.md section 10),
//! written as a terrain file that every other command accepts.

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::{anyhow, bail, Result};
use clap::Args;
use serde::Serialize;

use sandslope::measure::{
    clean, fit_penetration, fit_shear, per_slope, AirCorrection, Curve, Dropped, Kind, Origin,
    PenetrationFit, ShearFit, SlopeEstimate, SlopeStat, WindowChoice,
};
use sandslope::{Terrain, TerrainSpec};

use crate::args::check_positive;
use crate::figures::measurements as figures;
use crate::output::{csv_string, num, print_json, sci, table, write_atomic, Format, FormatArgs};
use sandslope_io::measurements::{load_manifest, read_recording, Manifest, Trial};

/// Arguments of `sandslope fit`.
#[derive(Debug, Args)]
pub struct FitArgs {
    /// Manifest (TOML) listing the trials; trial files are relative to it (docs/measurements.md).
    #[arg(value_name = "MANIFEST")]
    pub manifest: PathBuf,
    /// Write the fitted terrain (MODEL.md section 7 format, with k_n_sd/k_s_sd) to this TOML file.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Write the force-measurement figures (PNG) into this folder (created if missing).
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Fit k_n over this depth window, metres, instead of finding it (e.g. 0.005:0.03).
    #[arg(long, value_name = "MIN:MAX")]
    pub depth_window: Option<String>,
    /// Shear plateau starts at this displacement, metres, instead of being found (e.g. 0.02).
    #[arg(long, allow_negative_numbers = true, value_name = "M")]
    pub plateau_from: Option<f64>,
    /// Subtract the in-air run's force curve against position instead of its mean.
    #[arg(long)]
    pub air_curve: bool,
    /// Load-cell counts per newton, for recordings with a force_counts column.
    #[arg(long, allow_negative_numbers = true, value_name = "COUNTS")]
    pub counts_per_newton: Option<f64>,
    #[command(flatten)]
    pub format: FormatArgs,
}

/// Parses `MIN:MAX` (metres, 0 <= MIN < MAX).
fn parse_window(s: &str) -> Result<(f64, f64)> {
    let bad =
        || anyhow!("--depth-window `{s}` must be MIN:MAX in metres with 0 <= MIN < MAX, e.g. 0.005:0.03");
    let (a, b) = s.split_once(':').ok_or_else(bad)?;
    let a: f64 = a.trim().parse().map_err(|_| bad())?;
    let b: f64 = b.trim().parse().map_err(|_| bad())?;
    if !(a.is_finite() && b.is_finite() && a >= 0.0 && a < b) {
        return Err(bad());
    }
    Ok((a, b))
}

/// One trial read and cleaned.
pub struct CleanTrial {
    /// The manifest entry.
    pub trial: Trial,
    /// Data rows in the file.
    pub rows: usize,
    /// The clean curve (offset not yet removed).
    pub curve: Curve,
    /// What cleaning dropped.
    pub dropped: Dropped,
}

/// The fit of a measuring trial.
#[derive(Debug, Clone, Copy)]
pub enum TrialFit {
    /// Penetration: k_n.
    Penetration(PenetrationFit),
    /// Shear: k_s.
    Shear(ShearFit),
    /// In-air run: used as calibration.
    Air,
}

/// A fitted trial, with the offset-corrected curve for plotting.
pub struct FittedTrial {
    /// The cleaned trial.
    pub clean: CleanTrial,
    /// The in-air correction applied.
    pub air: AirCorrection,
    /// The offset-corrected curve.
    pub corrected: Curve,
    /// The fit.
    pub fit: TrialFit,
}

/// Per-trial JSON record.
#[derive(Debug, Serialize)]
struct TrialRecord {
    file: String,
    kind: &'static str,
    slope_deg: f64,
    air: bool,
    rows: usize,
    used: usize,
    dropped: Dropped,
    /// "mean", "curve" or "none" (no in-air run at this slope and kind).
    air_correction: &'static str,
    /// Mean in-air force subtracted (mean mode) or the mean of this air run, N.
    air_offset_n: Option<f64>,
    k_n: Option<f64>,
    k_n_se: Option<f64>,
    r_squared: Option<f64>,
    depth_window_m: Option<(f64, f64)>,
    k_s: Option<f64>,
    k_s_se: Option<f64>,
    plateau_force_n: Option<f64>,
    plateau_sd_n: Option<f64>,
    plateau_m: Option<(f64, f64)>,
    window: Option<WindowChoice>,
}

/// Per-slope JSON record (the keys of the issue, plus `interpolated`).
#[derive(Debug, Serialize)]
struct PointRecord {
    slope_deg: f64,
    k_n: f64,
    k_n_sd: Option<f64>,
    k_s: f64,
    k_s_sd: Option<f64>,
    trials_penetration: usize,
    trials_shear: usize,
    /// What was not measured at this slope and how it was filled, e.g.
    /// "k_s interpolated between 10 and 20 deg".
    interpolated: Vec<String>,
}

#[derive(Debug, Serialize)]
struct FitReport {
    points: Vec<PointRecord>,
    trials: Vec<TrialRecord>,
}

/// How a filled-in value was obtained, in words; `None` when measured.
fn origin_note(what: &str, s: &SlopeStat) -> Option<String> {
    match s.origin {
        Origin::Measured => None,
        Origin::Interpolated { below, above } => {
            Some(format!("{what} interpolated between {below} and {above} deg"))
        }
        Origin::Nearest { from } => Some(format!("{what} held from {from} deg (nearest measured)")),
    }
}

fn point_record(p: &SlopeEstimate) -> PointRecord {
    PointRecord {
        slope_deg: p.slope_deg,
        k_n: p.k_n.mean,
        k_n_sd: p.k_n.sd,
        k_s: p.k_s.mean,
        k_s_sd: p.k_s.sd,
        trials_penetration: p.k_n.trials,
        trials_shear: p.k_s.trials,
        interpolated: [origin_note("k_n", &p.k_n), origin_note("k_s", &p.k_s)]
            .into_iter()
            .flatten()
            .collect(),
    }
}

fn trial_record(t: &FittedTrial) -> TrialRecord {
    let c = &t.clean;
    let (air_correction, air_offset_n) = match (&t.fit, &t.air) {
        (TrialFit::Air, _) => ("none", Some(c.curve.mean_force())),
        (_, AirCorrection::None) => ("none", None),
        (_, AirCorrection::Mean(m)) => ("mean", Some(*m)),
        (_, AirCorrection::Curve(a)) => ("curve", Some(a.mean_force())),
    };
    let mut r = TrialRecord {
        file: c.trial.file.display().to_string(),
        kind: c.trial.kind.name(),
        slope_deg: c.trial.slope_deg,
        air: c.trial.air,
        rows: c.rows,
        used: c.curve.len(),
        dropped: c.dropped,
        air_correction,
        air_offset_n,
        k_n: None,
        k_n_se: None,
        r_squared: None,
        depth_window_m: None,
        k_s: None,
        k_s_se: None,
        plateau_force_n: None,
        plateau_sd_n: None,
        plateau_m: None,
        window: None,
    };
    match t.fit {
        TrialFit::Penetration(f) => {
            r.k_n = Some(f.k_n);
            r.k_n_se = Some(f.k_n_se);
            r.r_squared = Some(f.line.r_squared);
            r.depth_window_m = Some(f.window);
            r.window = Some(f.choice);
        }
        TrialFit::Shear(f) => {
            r.k_s = Some(f.k_s);
            r.k_s_se = Some(f.k_s_se);
            r.plateau_force_n = Some(f.plateau_force);
            r.plateau_sd_n = Some(f.plateau_sd);
            r.plateau_m = Some(f.plateau);
            r.window = Some(f.choice);
        }
        TrialFit::Air => {}
    }
    r
}

/// "3 blank, 2 NaN, ..." or "none".
fn dropped_text(d: &Dropped) -> String {
    let parts: Vec<String> = [
        (d.blank, "blank"),
        (d.non_finite, "NaN/inf"),
        (d.duplicate, "repeated"),
        (d.saturated, "saturated"),
        (d.reordered, "reordered (kept)"),
    ]
    .iter()
    .filter(|(n, _)| *n > 0)
    .map(|(n, what)| format!("{n} {what}"))
    .collect();
    if parts.is_empty() {
        "none".into()
    } else {
        parts.join(", ")
    }
}

/// Reads, cleans and fits every trial of a manifest.
pub fn fit_manifest(manifest: &Manifest, args: &FitArgs) -> Result<Vec<FittedTrial>> {
    let window = args.depth_window.as_deref().map(parse_window).transpose()?;
    if let Some(x) = args.plateau_from {
        if !(x.is_finite() && x >= 0.0) {
            bail!("--plateau-from = {x} must be a displacement in metres of at least 0");
        }
    }
    let cpn = args.counts_per_newton.map(|c| check_positive("--counts-per-newton", c)).transpose()?;
    let mut cleaned = Vec::with_capacity(manifest.trials.len());
    for trial in &manifest.trials {
        let ctx =
            || format!("{}: [[trial]] #{} ({})", manifest.path.display(), trial.index, trial.file.display());
        if !trial.path.is_file() {
            bail!("{}: trial file {} does not exist", ctx(), trial.path.display());
        }
        let rec = read_recording(&trial.path, trial.kind, cpn)?;
        let (curve, dropped) = clean(&rec.raw).map_err(|e| anyhow!("{}: {e}", trial.path.display()))?;
        if curve.is_empty() {
            bail!(
                "{}: all {} data rows were dropped ({}); nothing to fit",
                trial.path.display(),
                rec.rows,
                dropped_text(&dropped)
            );
        }
        cleaned.push(CleanTrial { trial: trial.clone(), rows: rec.rows, curve, dropped });
    }
    // In-air runs by (kind, slope).
    let key = |t: &Trial| (t.kind, t.slope_deg.to_bits());
    let mut air_runs: BTreeMap<(Kind, u64), Vec<&Curve>> = BTreeMap::new();
    for c in cleaned.iter().filter(|c| c.trial.air) {
        air_runs.entry(key(&c.trial)).or_default().push(&c.curve);
    }
    let corrections: BTreeMap<(Kind, u64), AirCorrection> = air_runs
        .iter()
        .map(|(k, runs)| {
            let corr =
                if args.air_curve { AirCorrection::curve_of(runs) } else { AirCorrection::mean_of(runs) };
            (*k, corr)
        })
        .collect();
    let mut warned = std::collections::BTreeSet::new();
    let mut out = Vec::with_capacity(cleaned.len());
    for c in cleaned {
        let where_ =
            || format!("{} ({} trial at {} deg)", c.trial.path.display(), c.trial.kind, c.trial.slope_deg);
        if c.trial.air {
            let corrected = c.curve.clone();
            out.push(FittedTrial { clean: c, air: AirCorrection::None, corrected, fit: TrialFit::Air });
            continue;
        }
        let air = corrections.get(&key(&c.trial)).cloned().unwrap_or(AirCorrection::None);
        if air == AirCorrection::None && warned.insert(key(&c.trial)) {
            let effect = match c.trial.kind {
                Kind::Penetration => "the fitted intercept absorbs a constant offset, k_n is unaffected",
                Kind::Shear => "the plateau force includes any load-cell offset, k_s may be biased",
            };
            eprintln!(
                "warning: no in-air {} run at {} deg: force not offset-corrected ({effect})",
                c.trial.kind, c.trial.slope_deg
            );
        }
        let corrected = c.curve.minus_air(&air);
        let fit = match c.trial.kind {
            Kind::Penetration => TrialFit::Penetration(
                fit_penetration(&corrected, manifest.disk_area_m2, window)
                    .map_err(|e| anyhow!("{}: {e}", where_()))?,
            ),
            Kind::Shear => TrialFit::Shear(
                fit_shear(&corrected, manifest.plate, args.plateau_from)
                    .map_err(|e| anyhow!("{}: {e}", where_()))?,
            ),
        };
        out.push(FittedTrial { clean: c, air, corrected, fit });
    }
    Ok(out)
}

/// Runs `sandslope fit`.
pub fn run(args: FitArgs) -> Result<()> {
    // --plot DIR is created when missing; the terrain file's folder must exist.
    if let Some(out) = &args.out {
        crate::output::check_parent_exists(out)?;
    }
    let manifest = load_manifest(&args.manifest)?;
    let trials = fit_manifest(&manifest, &args)?;
    let values = |kind: Kind| -> Vec<(f64, f64)> {
        trials
            .iter()
            .filter_map(|t| match (kind, t.fit) {
                (Kind::Penetration, TrialFit::Penetration(f)) => Some((t.clean.trial.slope_deg, f.k_n)),
                (Kind::Shear, TrialFit::Shear(f)) => Some((t.clean.trial.slope_deg, f.k_s)),
                _ => None,
            })
            .collect()
    };
    let points = per_slope(&values(Kind::Penetration), &values(Kind::Shear))
        .map_err(|e| anyhow!("{}: {e}", manifest.path.display()))?;
    let spec = TerrainSpec {
        name: manifest.name.clone(),
        repose_deg: manifest.repose_deg,
        points: points.iter().map(SlopeEstimate::terrain_point).collect(),
    };
    let terrain = Terrain::new(spec)
        .map_err(|e| anyhow!("{}: fitted terrain is invalid: {e}", manifest.path.display()))?;
    let report = FitReport {
        points: points.iter().map(point_record).collect(),
        trials: trials.iter().map(trial_record).collect(),
    };
    for p in &report.points {
        for note in &p.interpolated {
            eprintln!("note: {} deg: {note} (not measured at this slope)", p.slope_deg);
        }
    }

    // Files first (each atomic), then the printout.
    if let Some(out) = &args.out {
        let header = format!(
            "# Terrain fitted by `sandslope fit` from {} (MODEL.md section 7).\n# k_n_sd/k_s_sd: sample SD across \
             trials; absent with a single trial or where a value was interpolated from SD-less neighbours.\n",
            manifest.path.display()
        );
        let body = toml::to_string(terrain.spec()).map_err(|e| anyhow!("cannot write terrain TOML: {e}"))?;
        write_atomic(out, format!("{header}{body}").as_bytes())?;
    }
    if let Some(dir) = &args.plot {
        std::fs::create_dir_all(dir)
            .map_err(|e| anyhow!("cannot create plot folder {}: {e}", dir.display()))?;
        for path in figures::write_all(dir, &trials, &points)? {
            eprintln!("wrote {}", path.display());
        }
    }

    match args.format.format() {
        Format::Json => print_json(&report),
        Format::Csv => {
            #[derive(Serialize)]
            struct Row<'a> {
                slope_deg: f64,
                k_n: f64,
                k_n_sd: Option<f64>,
                k_s: f64,
                k_s_sd: Option<f64>,
                trials_penetration: usize,
                trials_shear: usize,
                interpolated: &'a str,
            }
            let notes: Vec<String> = report.points.iter().map(|p| p.interpolated.join("; ")).collect();
            let rows: Vec<Row> = report
                .points
                .iter()
                .zip(&notes)
                .map(|(p, n)| Row {
                    slope_deg: p.slope_deg,
                    k_n: p.k_n,
                    k_n_sd: p.k_n_sd,
                    k_s: p.k_s,
                    k_s_sd: p.k_s_sd,
                    trials_penetration: p.trials_penetration,
                    trials_shear: p.trials_shear,
                    interpolated: n,
                })
                .collect();
            print!("{}", csv_string(&rows)?);
            Ok(())
        }
        Format::Table => {
            let mut t = table(&[
                "file",
                "kind",
                "slope deg",
                "k (N/m^3)",
                "SE",
                "R^2",
                "window (mm)",
                "used",
                "dropped",
            ]);
            for tr in &trials {
                let c = &tr.clean;
                let (k, se, r2, w) = match tr.fit {
                    TrialFit::Penetration(f) => {
                        (sci(f.k_n), sci(f.k_n_se), num(Some(f.line.r_squared), 4), f.window)
                    }
                    TrialFit::Shear(f) => (sci(f.k_s), sci(f.k_s_se), "-".into(), f.plateau),
                    TrialFit::Air => (
                        format!("air {:.3} N", c.curve.mean_force()),
                        "-".into(),
                        "-".into(),
                        (f64::NAN, f64::NAN),
                    ),
                };
                let window =
                    if w.0.is_nan() { "-".into() } else { format!("{:.1}-{:.1}", w.0 * 1e3, w.1 * 1e3) };
                t.add_row([
                    c.trial.file.display().to_string(),
                    c.trial.kind.name().into(),
                    format!("{}", c.trial.slope_deg),
                    k,
                    se,
                    r2,
                    window,
                    format!("{}/{}", c.curve.len(), c.rows),
                    dropped_text(&c.dropped),
                ]);
            }
            println!("{t}");
            let mut t =
                table(&["slope deg", "k_n (N/m^3)", "k_n SD", "n", "k_s (N/m^3)", "k_s SD", "n", "note"]);
            for p in &report.points {
                t.add_row([
                    format!("{}", p.slope_deg),
                    sci(p.k_n),
                    p.k_n_sd.map(sci).unwrap_or_else(|| "-".into()),
                    p.trials_penetration.to_string(),
                    sci(p.k_s),
                    p.k_s_sd.map(sci).unwrap_or_else(|| "-".into()),
                    p.trials_shear.to_string(),
                    p.interpolated.join("; "),
                ]);
            }
            println!("{t}");
            if let Some(out) = &args.out {
                println!("terrain written to {}", out.display());
            }
            Ok(())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_window_syntax() {
        assert_eq!(parse_window("0.005:0.03").unwrap(), (0.005, 0.03));
        for bad in ["0.03:0.005", "5", "a:b", "-1:2", "0.01:0.01"] {
            assert!(parse_window(bad).is_err(), "{bad}");
        }
    }
}
