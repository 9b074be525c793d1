//! `sandslope fit`: k_n and k_s per slope from load-cell recordings (docs/model.md §10),
//! written as a terrain file that every other command accepts. The analysis is one library
//! call, [`sandslope::measure::fit_campaign`]; this command reads, calls it, writes and draws.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use sandslope_render::rows::FitRow;

use sandslope::measure::campaign::dropped_text;
use sandslope::measure::Campaign;
use sandslope_request::error::Words;
use sandslope_request::fit::{FitAnswer, FitRequest};

use crate::args::FieldArgs;
use crate::figures::measurements as figures;
use crate::output::{csv_string, num, print_json, sci, table, write_atomic, Format, FormatArgs};

/// Arguments of `sandslope fit`.
#[derive(Debug, Args)]
pub struct FitArgs {
    /// Manifest (TOML) listing the trials; trial files (CSV, or ROS 2 bags: docs/bags.md) are
    /// relative to it (docs/measurements.md).
    #[arg(value_name = "MANIFEST")]
    pub manifest: PathBuf,
    /// Write the fitted terrain (docs/model.md §7 format, with k_n_sd/k_s_sd) to this TOML file.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Write the force-measurement figures (PNG) into this folder (created if missing).
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// `--depth-window`, `--plateau-from`, `--air-curve`, `--air-mean`, `--skip-malformed` and
    /// `--counts-per-newton`: the request's own fields ([`sandslope_request::fit::FIELDS`]).
    #[command(flatten)]
    pub fields: FieldArgs<FitRequest>,
    #[command(flatten)]
    pub format: FormatArgs,
}

impl FitArgs {
    /// The request these flags make, read by the request's one raw-to-typed step.
    pub fn request(&self) -> Result<FitRequest> {
        Ok(FitRequest::from_fields(self.manifest.clone(), &self.fields.pairs)?)
    }
}

/// Runs `sandslope fit`.
pub fn run(args: FitArgs) -> Result<()> {
    // Every output checked before anything is computed or written: the terrain file's folder
    // must exist; the plot folder is created (an empty folder is all that is left on failure).
    if let Some(out) = &args.out {
        crate::output::check_parent_exists(out)?;
    }
    let FitAnswer { manifest, campaign, terrain } = args.request()?.answer(Words::Flag)?;
    for p in &campaign.points {
        for note in p.notes() {
            eprintln!("note: {} deg: {note} (not measured at this slope)", p.slope_deg);
        }
    }
    for t in &campaign.trials {
        for w in &t.warnings {
            eprintln!("warning: {}: {w}", t.file);
        }
    }

    // Outputs: the plot folder first (creating it is the step most likely to fail), then the
    // figures are drawn in memory and every file is written atomically.
    if let Some(dir) = &args.plot {
        sandslope_files::create_output_dir(dir)
            .map_err(|e| e.context(format!("cannot create plot folder {}", dir.display())))?;
    }
    if let Some(out) = &args.out {
        let header = format!(
            "Terrain fitted by `sandslope fit` from {} (docs/model.md §7).\nk_n_sd/k_s_sd: sqrt(s^2 + mean \
             se^2), the sample SD across trials combined with each trial's standard error (docs/measurements.md).",
            manifest.path.display()
        );
        write_atomic(out, sandslope_io::robot_terrain::terrain_toml(terrain.spec(), &header)?.as_bytes())?;
    }
    if let Some(dir) = &args.plot {
        figures::write_all(dir, &campaign)?;
    }

    match args.format.format() {
        Format::Json => print_json(&campaign),
        Format::Csv => {
            let rows: Vec<FitRow> = campaign.points.iter().map(FitRow::of).collect();
            print!("{}", csv_string(&rows)?);
            Ok(())
        }
        Format::Table => {
            print_tables(&campaign);
            Ok(())
        }
    }
}

/// The per-trial and per-slope tables.
fn print_tables(campaign: &Campaign) {
    let mut t = table(&[
        "file",
        "kind",
        "slope deg",
        "k (N/m^3)",
        "SE",
        "R^2",
        "window (mm)",
        "air",
        "used",
        "warnings",
    ]);
    // What each trial set aside, listed below the table (as a column it made the table about
    // 194 characters wide).
    let mut set_aside = Vec::new();
    for tr in &campaign.trials {
        let (k, se, r2) = match (&tr.penetration, &tr.shear) {
            (Some(p), _) => (sci(p.k_n), sci(p.k_n_se), num(Some(p.r_squared), 3)),
            (_, Some(s)) => (sci(s.k_s), sci(s.k_s_se), "-".into()),
            _ => (format!("air {:.3} N", tr.air_offset_n.unwrap_or(0.0)), "-".into(), "-".into()),
        };
        let window = tr
            .window_m()
            .map(|w| {
                format!("{:.1}-{:.1} of {:.1}", w.0 * 1e3, w.1 * 1e3, (tr.stroke_m.1 - tr.stroke_m.0) * 1e3)
            })
            .unwrap_or_else(|| "-".into());
        let warnings: Vec<&str> = tr.warnings.iter().map(|w| w.code()).collect();
        t.add_row([
            tr.file.clone(),
            tr.kind.name().into(),
            format!("{}", tr.slope_deg),
            k,
            se,
            r2,
            window,
            if tr.air { "-".into() } else { tr.air_correction.to_string() },
            format!("{}/{}", tr.used, tr.rows),
            if warnings.is_empty() { "-".into() } else { warnings.join(", ") },
        ]);
        let dropped = dropped_text(&tr.dropped);
        if dropped != "none" {
            set_aside.push(format!("  {}: {dropped}", tr.file));
        }
    }
    println!("{t}");
    if !set_aside.is_empty() {
        println!("rows not used (docs/measurements.md):\n{}", set_aside.join("\n"));
    }
    let mut t = table(&["slope deg", "k_n (N/m^3)", "k_n SD", "n", "k_s (N/m^3)", "k_s SD", "n", "note"]);
    for p in &campaign.points {
        t.add_row([
            format!("{}", p.slope_deg),
            sci(p.k_n.mean),
            sci(p.k_n.sd),
            p.k_n.trials.to_string(),
            sci(p.k_s.mean),
            sci(p.k_s.sd),
            p.k_s.trials.to_string(),
            p.notes().join("; "),
        ]);
    }
    println!("{t}");
    println!("SD = sqrt(SD across trials^2 + mean trial SE^2) (docs/measurements.md)");
}
