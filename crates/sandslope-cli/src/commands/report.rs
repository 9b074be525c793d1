//! `sandslope report --out DIR`: the paper reproduced and confronted in one self-contained
//! HTML page (`DIR/index.html`, figures inline as SVG) and `DIR/report.json`. On the defaults it
//! reproduces the paper from the shipped data; `--robot`, `--terrain`, `--observed`, `--forces`,
//! `--t1` and `--tracks` (motion-capture recordings per slope, analysed as `sandslope track`
//! does) make it a report on the user's own campaign.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use sandslope::Slope;

use sandslope::gait::GaitOptions;
use sandslope::report::Evidence;
use sandslope_request::error::Words;
use sandslope_request::report::{answer_evidence, ReportRequest, TracksAt, TRACKS};

use crate::args::{FieldArgs, LevelStepArgs, RobotArgs, TerrainArgs};
use crate::mocap_input::{expand, warn_without_steps};

/// Arguments of `sandslope report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// Folder to write index.html and report.json into (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// `--tracks` ([`TRACKS`]): given once per slope or file, so not among `fields`.
    #[arg(long = TRACKS.flag, value_name = TRACKS.value_name, help = TRACKS.help, value_parser = parse_tracks)]
    pub tracks: Vec<TracksArg>,
    /// `--observed`, `--forces`, `--t1`, `--tracks-format`, `--tracks-body`,
    /// `--tracks-upslope`, `--max-risk` and `--simulator-fit`: the request's own fields
    /// ([`sandslope_request::report::FIELDS`]).
    #[command(flatten)]
    pub fields: FieldArgs<ReportRequest>,
    /// Fail (exit code 4, after writing the page) when the report carries a warning: a
    /// calibration quantity at its search bound, chi^2/dof > 3, or tracks that could not be
    /// used. Without it such a report exits 0 and prints the warnings on stderr.
    #[arg(long)]
    pub strict: bool,
    #[command(flatten)]
    pub level: LevelStepArgs,
    #[command(flatten)]
    pub robot: RobotArgs,
    #[command(flatten)]
    pub terrain: TerrainArgs,
}

/// One `--tracks DEG=FILE|GLOB` value.
#[derive(Debug, Clone)]
pub struct TracksArg {
    /// The value as given.
    pub text: String,
    /// Slope of the recordings, degrees.
    pub slope_deg: f64,
    /// A recording or a glob pattern.
    pub pattern: String,
}

/// The valid form of a `--tracks` value, for error messages.
const TRACKS_FORM: &str = "expected DEG=FILE|GLOB: a slope in degrees (0 to 90, 90 excluded), `=`, \
     then a recording or a glob pattern, e.g. `10=runs/10deg-*.csv`";

/// Parses `--tracks`; whether its files exist is checked when they are read.
fn parse_tracks(s: &str) -> Result<TracksArg, String> {
    let Some((deg, pattern)) = s.split_once('=') else {
        return Err(format!("no `=` in `{s}`; {TRACKS_FORM}"));
    };
    let slope_deg: f64 =
        deg.trim().parse().map_err(|_| format!("`{deg}` is not a slope in degrees; {TRACKS_FORM}"))?;
    // Checked here too, before any pattern is expanded (ReportRequest checks it for every
    // front end, after the files are found): a bad slope is named with the flag's form.
    if Slope::from_degrees(slope_deg).is_err() {
        return Err(format!("slope {slope_deg} is outside 0 to 90 degrees; {TRACKS_FORM}"));
    }
    if pattern.trim().is_empty() {
        return Err(format!("no file after `=` in `{s}`; {TRACKS_FORM}"));
    }
    Ok(TracksArg { text: s.to_string(), slope_deg, pattern: pattern.to_string() })
}

/// The `--tracks` recordings per slope, lowest slope first: each slope's patterns expanded,
/// a file named twice (a path and a glob that matches it) read once.
fn tracks(args: &ReportArgs) -> Result<Vec<TracksAt>> {
    let mut slopes: Vec<f64> = args.tracks.iter().map(|t| t.slope_deg).collect();
    slopes.sort_by(f64::total_cmp);
    slopes.dedup();
    let mut out = Vec::new();
    for slope_deg in slopes {
        let mut files: Vec<PathBuf> = Vec::new();
        for t in args.tracks.iter().filter(|t| t.slope_deg == slope_deg) {
            let found = expand(std::slice::from_ref(&t.pattern))
                .with_context(|| format!("--tracks `{}`: no recording to read ({TRACKS_FORM})", t.text))?;
            for f in found {
                if !files.contains(&f) {
                    files.push(f);
                }
            }
        }
        out.push(TracksAt { slope_deg, files });
    }
    Ok(out)
}

/// Runs `sandslope report`.
pub fn run(args: ReportArgs) -> Result<()> {
    // The flags read first (by the request's one raw-to-typed step), then the folder checked,
    // then the evidence read: nothing is read or written on a bad flag.
    let request = ReportRequest::from_fields(
        args.robot.robot.clone(),
        args.terrain.terrain.clone(),
        tracks(&args)?,
        &args.fields.pairs,
    )?;
    sandslope_render::report::check_dir("--out", &args.out)?;
    let evidence = evidence(&args, request)?;
    // Seconds in a release build (the simulator section walks 14 slopes twice), a minute in a
    // debug one: a spinner with the time on a terminal.
    let spin = crate::progress::spinner(
        false,
        "building the report (the model, the calibration, the simulator's walks)",
    );
    let report = answer_evidence(&evidence);
    spin.finish_and_clear();
    let report = report?;
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    if report.fit_diagnosis.is_some() {
        eprintln!(
            "why the calibration is unreliable, and what data would fix it: {}, section \"Why the calibration is unreliable\" (report.json: fit_diagnosis)",
            args.out.join("index.html").display()
        );
    }
    crate::report::write_dir(&args.out, &report)?;
    println!(
        "{} figures; {}; {} disagreement(s) listed",
        report.figures.len(),
        report.summary.text,
        report.disagreements.len()
    );
    if args.strict && !report.warnings.is_empty() {
        return Err(crate::error::Strict(report.warnings.len()).into());
    }
    Ok(())
}

/// The evidence `request` names, read by the request layer (as Python's `report` reads it),
/// with a warning on stderr for each recording without a complete step.
fn evidence(args: &ReportArgs, request: ReportRequest) -> Result<Evidence> {
    let robot = args.robot.load()?.with_level_step(args.level.level_step);
    let terrain = args.terrain.load()?;
    let period = robot.stride_period();
    let evidence = request.evidence(robot, terrain, Words::Flag)?;
    if let Ok(options) = GaitOptions::new(period) {
        for t in &evidence.tracks {
            warn_without_steps(&t.files, &t.result, &options);
        }
    }
    Ok(evidence)
}
