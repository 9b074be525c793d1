//! `sandslope report --out DIR`: the paper reproduced and confronted in one self-contained
//! HTML page (`DIR/index.html`, figures inline as SVG) and `DIR/report.json`. On the defaults it
//! reproduces the paper from the shipped data; `--robot`, `--terrain`, `--observed`, `--forces`,
//! `--t1` and `--tracks` (motion-capture recordings per slope, analysed as `sandslope track`
//! does) make it a report on the user's own campaign.

use std::path::PathBuf;

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;

use sandslope::gait::{GaitOptions, Upslope};
use sandslope::AnchoringObservation;
use sandslope_io::mocap::MocapFormat;

use sandslope::paper::{self, compare_with_paper};
use sandslope::risk::{risk_curve, safe_slope_limit};
use sandslope::{
    calibrate_jointly, predict, Axis, AxisScale, FreeParameter, JointCalibration, JointSetup, Parameter,
    PhasePanel, Robot, ShearShape, Slope, SpeedObservation, Terrain, UncertainTerrain,
};
use sandslope_io::presets::DEFAULT_TERRAIN;
use sandslope_io::{load_anchoring_times, load_speeds, load_terrain, terrain_from_toml, Source};

/// The paper's force tests as its text reports them (docs/calibration.md).
const PAPER_FORCE_TESTS: &str = include_str!("../../../../data/example-force-tests.toml");

use plotters::chart::SeriesLabelPosition;

use crate::args::{RobotArgs, TerrainArgs};
use crate::figures::calibrate::{speed_pulls, CalibrationFigure};
use crate::figures::phase::PhaseFigure;
use crate::figures::risk::CurveFigure;
use crate::figures::slope_curves::SlopeCurveFigure;
use crate::figures::to_svg;
use crate::figures::track::{StridePanels, TrackFigure};
use crate::mocap_input::{expand, parse_mocap_format, parse_upslope, track_files, CaptureOptions, Tracked};
use crate::output::write_atomic;
use crate::report::{page, FigureRecord, PageFigure, ReportJson, SpeedRecord, TrackRecord, TracksSection};

/// Arguments of `sandslope report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// Folder to write index.html and report.json into (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Observed speeds (slope_deg,speed_m_s,speed_sd_m_s); default: the paper's five.
    #[arg(long, value_name = "CSV")]
    pub observed: Option<PathBuf>,
    /// Force tests (a terrain file with k_s_sd, as `sandslope fit` writes): drawn in fig4d/h
    /// and used as the k_s shape in the calibration; default: the terrain itself.
    #[arg(long, value_name = "FILE|PRESET")]
    pub forces: Option<String>,
    /// Observed anchoring times (slope_deg,t1_s,t1_sd_s), drawn in fig5b and calibrated on.
    #[arg(long, value_name = "CSV")]
    pub t1: Option<PathBuf>,
    /// Motion-capture recordings at one slope, `DEG=FILE|GLOB` (e.g. `10=runs/10deg-*.csv`);
    /// repeat for more files or slopes. Each slope's files are pooled and analysed as
    /// `sandslope track` does: their anchoring time t1 joins the observed ones (fig5b and the
    /// calibration) and, without --observed, their mean speeds are the observed speeds. Adds
    /// fig3b (speed within a stride) and a motion-capture table.
    #[arg(long, value_name = "DEG=FILE|GLOB", value_parser = parse_tracks)]
    pub tracks: Vec<TracksArg>,
    /// Format of the --tracks files: motive, vicon or plain; detected from each file's first
    /// line when omitted.
    #[arg(long, value_name = "motive|vicon|plain", value_parser = parse_mocap_format, requires = "tracks")]
    pub tracks_format: Option<MocapFormat>,
    /// Rigid body, marker or model output to track in the --tracks files (required when a
    /// file has several).
    #[arg(long, value_name = "NAME", requires = "tracks")]
    pub tracks_body: Option<String>,
    /// Upslope direction in the --tracks files' capture frame: +x, -x, +y, -y, +z, -z or a
    /// vector such as `0.91,0,0.41`; estimated per slope from the direction of travel when
    /// omitted.
    #[arg(
        long,
        value_name = "AXIS|X,Y,Z",
        value_parser = |s: &str| parse_upslope(s, "--tracks-upslope"),
        allow_hyphen_values = true,
        requires = "tracks"
    )]
    pub tracks_upslope: Option<Upslope>,
    /// Risk threshold for the safe-slope limit.
    #[arg(long, default_value_t = 0.05)]
    pub max_risk: f64,
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
    if Slope::from_degrees(slope_deg).is_err() {
        return Err(format!("slope {slope_deg} is outside 0 to 90 degrees; {TRACKS_FORM}"));
    }
    if pattern.trim().is_empty() {
        return Err(format!("no file after `=` in `{s}`; {TRACKS_FORM}"));
    }
    Ok(TracksArg { text: s.to_string(), slope_deg, pattern: pattern.to_string() })
}

/// One slope's recordings, read and analysed pooled.
struct SlopeTracks {
    slope_deg: f64,
    tracked: Tracked,
}

/// Reads and analyses the `--tracks` recordings, one pooled analysis per slope, lowest slope
/// first; `period` is the robot's stride period.
fn load_tracks(args: &ReportArgs, period: f64) -> Result<Vec<SlopeTracks>> {
    let mut slopes: Vec<f64> = args.tracks.iter().map(|t| t.slope_deg).collect();
    slopes.sort_by(f64::total_cmp);
    slopes.dedup();
    let mut options = GaitOptions::new(period).map_err(|e| anyhow!("the robot's stride period: {e}"))?;
    if let Some(u) = args.tracks_upslope {
        options = options.with_upslope(u);
    }
    let read =
        CaptureOptions { format: args.tracks_format, body: args.tracks_body.as_deref(), cutoff_flag: None };
    let mut out = Vec::new();
    for slope_deg in slopes {
        let mut files: Vec<PathBuf> = Vec::new();
        for t in args.tracks.iter().filter(|t| t.slope_deg == slope_deg) {
            let found = expand(std::slice::from_ref(&t.pattern))
                .with_context(|| format!("--tracks `{}`: no recording to read ({TRACKS_FORM})", t.text))?;
            // A file named twice (a path and a glob that matches it) is read once.
            for f in found {
                if !files.contains(&f) {
                    files.push(f);
                }
            }
        }
        let tracked = track_files(&files, read, &[], &options, Some(at(slope_deg)))?;
        out.push(SlopeTracks { slope_deg, tracked });
    }
    Ok(out)
}

/// Slopes of the model curves: 0 to 30 deg every 0.25 deg.
fn slope_grid() -> Vec<f64> {
    (0..=120).map(|i| i as f64 * 0.25).collect()
}

fn at(d: f64) -> Slope {
    Slope::from_degrees(d).expect("grid slopes are valid")
}

fn add(figures: &mut Vec<PageFigure>, id: &str, title: &str, caption: String, svg: String) {
    figures.push(PageFigure { id: id.into(), title: title.into(), caption, svg, parts: vec![] });
}

/// Runs `sandslope report`.
pub fn run(args: ReportArgs) -> Result<()> {
    if !(args.max_risk > 0.0 && args.max_risk < 1.0) {
        bail!("--max-risk = {} must be a probability strictly between 0 and 1", args.max_risk);
    }
    if args.out.exists() && !args.out.is_dir() {
        bail!("--out {}: exists and is not a folder", args.out.display());
    }
    let robot = args.robot.load()?;
    let terrain = args.terrain.load()?;
    // The force tests: given, or on the built-in terrain the paper's as its text reports them
    // (data/example-force-tests.toml, from which the built-in terrain was calibrated).
    let paper_forces = args.forces.is_none() && args.terrain.terrain == DEFAULT_TERRAIN;
    let forces = match &args.forces {
        Some(f) => Some(load_terrain(f)?),
        None if paper_forces => {
            Some(terrain_from_toml(PAPER_FORCE_TESTS, &Source::Preset("example-force-tests"))?)
        }
        None => None,
    };
    let mut anchoring = args.t1.as_deref().map(load_anchoring_times).transpose()?.unwrap_or_default();
    let tracks = load_tracks(&args, robot.stride_period())?;
    let track_use = TrackUse::new(&tracks, args.observed.is_some());
    anchoring.extend(track_use.anchoring.iter().copied());
    let speeds: Vec<SpeedObservation> = match &args.observed {
        Some(p) => load_speeds(p)?,
        None if !tracks.is_empty() => track_use.speeds.clone(),
        None => paper::SPEEDS
            .iter()
            .map(|&(d, v, sd)| SpeedObservation { slope: at(d), speed: v, speed_sd: sd })
            .collect(),
    };
    let mut inputs = vec![
        ("robot".to_string(), args.robot.robot.clone()),
        ("terrain".to_string(), args.terrain.terrain.clone()),
        (
            "observed speeds".to_string(),
            match (&args.observed, tracks.is_empty()) {
                (Some(p), _) => p.display().to_string(),
                (None, false) => "the motion-capture tracks' (mean ± SD per slope, --tracks)".into(),
                (None, true) => "the paper's (docs/model.md §12)".into(),
            },
        ),
        (
            "force tests".to_string(),
            match (&args.forces, paper_forces) {
                (Some(f), _) => f.clone(),
                (None, true) => {
                    "the paper's, as its text reports them (data/example-force-tests.toml)".into()
                }
                (None, false) => "the terrain's own table".into(),
            },
        ),
    ];
    let t1_sources: Vec<String> = args
        .t1
        .iter()
        .map(|p| p.display().to_string())
        .chain((!track_use.anchoring.is_empty()).then(|| "the motion-capture tracks (--tracks)".to_string()))
        .collect();
    if !t1_sources.is_empty() {
        inputs.push(("anchoring times".into(), t1_sources.join(" and ")));
    }
    for t in &tracks {
        inputs.push((format!("motion capture at {}°", t.slope_deg), t.tracked.names.join(", ")));
    }
    if !tracks.is_empty() {
        inputs.push((
            "motion-capture reading".into(),
            format!(
                "format {}; body {}; upslope {}; stride period T = {} s (the robot's)",
                args.tracks_format.map_or("detected per file", |f| f.name()),
                args.tracks_body.as_deref().unwrap_or("chosen per file (no --tracks-body)"),
                args.tracks_upslope.map_or("estimated per slope from the travel".to_string(), |u| {
                    let v = u.vector();
                    format!("[{:.3}, {:.3}, {:.3}]", v[0], v[1], v[2])
                }),
                robot.stride_period()
            ),
        ));
    }

    // The joint calibration of the terrain's (or the force tests') k_s shape on the evidence.
    let shape = forces.clone().unwrap_or_else(|| terrain.clone());
    let setup = JointSetup {
        robot: robot.clone(),
        normal: shape.clone(),
        shear: ShearShape::ForceTests(shape.clone()),
        speeds: speeds.clone(),
        anchoring: anchoring.clone(),
        free: [Parameter::PlateScale, Parameter::ErrorFloor]
            .into_iter()
            .map(|parameter| FreeParameter { parameter, bounds: None })
            .collect(),
        error_floor: 0.0,
    };
    let calibration = calibrate_jointly(&setup).ok();

    let grid = slope_grid();
    let predictions: Vec<_> = grid.iter().map(|&d| predict(&robot, at(d), &terrain.at(at(d)))).collect();
    let repose = terrain.spec().repose_deg;
    let mut figures = Vec::new();

    // fig3a: speed against slope.
    let fig = SlopeCurveFigure {
        title: "Step-averaged upslope speed".into(),
        y_label: "speed v (cm/s)".into(),
        // No speed where the regime rules one out (docs/model.md §6).
        model: grid
            .iter()
            .zip(&predictions)
            .map(|(&d, p)| (d, p.speed.filter(|_| !p.regime.is_failure()).map(|v| v * 100.0)))
            .collect(),
        model_label: "model on the terrain".into(),
        observed: speeds.iter().map(|o| (o.slope.degrees(), o.speed * 100.0, o.speed_sd * 100.0)).collect(),
        observed_label: "observed (mean ± SD)".into(),
        reference: None,
        repose,
        from_zero: true,
        legend: SeriesLabelPosition::LowerLeft,
    };
    add(&mut figures, "fig3a", "Speed against slope", "The model's step-averaged speed v = s/(T/2) on the terrain (dashed) and the observed speeds. Where the line stops, the regime rules a speed out (slippage or sinkage, docs/model.md §6).".into(), to_svg(&fig)?);

    // fig3b: speed within a stride, one panel per tracked slope with a complete step.
    let strided: Vec<&SlopeTracks> = tracks.iter().filter(|t| t.tracked.result.steps > 0).collect();
    if !strided.is_empty() {
        let slopes: Vec<String> = strided.iter().map(|t| format!("{}°", t.slope_deg)).collect();
        let fig =
            StridePanels(strided.iter().map(|t| TrackFigure::new(&t.tracked.result, None, &[])).collect());
        add(
            &mut figures,
            "fig3b",
            "Speed within a stride",
            format!(
                "The motion-capture tracks' upslope speed against time since touchdown, averaged over strides (mean ± SD band), with the mean anchoring time t1 (docs/model.md §11); one panel per tracked slope, lowest first: {}.",
                slopes.join(", ")
            ),
            to_svg(&fig)?,
        );
    }

    // fig4d, fig4h: k_n and k_s against slope with error bars.
    let table = forces.as_ref().unwrap_or(&terrain);
    // Plate values are drawn on the leg's scale: times the fitted plate_scale.
    let plate_scale = match (&forces, &calibration) {
        (Some(_), Some(c)) => {
            c.parameters.iter().find(|p| p.name == "plate_scale").map_or(1.0, |p| p.estimate.value)
        }
        _ => 1.0,
    };
    let label =
        if forces.is_some() { "force tests (mean ± SD)" } else { "terrain table (± SD where given)" };
    for (id, title, unit_scale, pick) in [
        ("fig4d", "Normal penetration resistance k_n", 1e-5, 0usize),
        ("fig4h", "Shear strength k_s", 1e-5, 1usize),
    ] {
        let value =
            |p: &sandslope::TerrainPoint| if pick == 0 { (p.k_n, p.k_n_sd) } else { (p.k_s, p.k_s_sd) };
        let fig = SlopeCurveFigure {
            title: title.into(),
            y_label: format!("{} (10⁵ N/m³)", if pick == 0 { "k_n" } else { "k_s" }),
            model: grid
                .iter()
                .map(|&d| {
                    let g = terrain.at(at(d));
                    (d, Some(if pick == 0 { g.k_n } else { g.k_s } * unit_scale))
                })
                .collect(),
            model_label: "terrain used by the model (interpolated)".into(),
            observed: table
                .points()
                .iter()
                .map(|p| {
                    let (v, sd) = value(p);
                    let c = if pick == 1 { plate_scale } else { 1.0 };
                    (p.slope_deg, c * v * unit_scale, c * sd.unwrap_or(0.0) * unit_scale)
                })
                .collect(),
            observed_label: if pick == 1 && plate_scale != 1.0 {
                format!("{label} × plate_scale {plate_scale:.1}")
            } else {
                label.into()
            },
            reference: None,
            repose,
            from_zero: true,
            legend: if pick == 0 { SeriesLabelPosition::LowerRight } else { SeriesLabelPosition::LowerLeft },
        };
        let caption = if pick == 0 {
            "The paper: k_n \"remains nearly constant\" with slope (Fig. 4d).".to_string()
        } else {
            "The paper: k_s at 20° is about 40% of level (Fig. 4h). With force tests given, the model's leg k_s is plate_scale times the plate's (docs/calibration.md).".to_string()
        };
        add(&mut figures, id, title, caption, to_svg(&fig)?);
    }

    // fig5b: anchoring time; fig5c: net step.
    let fig = SlopeCurveFigure {
        title: "Anchoring time t1".into(),
        y_label: "t1 (ms)".into(),
        model: grid.iter().zip(&predictions).map(|(&d, p)| (d, p.anchoring_time.map(|t| t * 1e3))).collect(),
        model_label: "model".into(),
        observed: anchoring.iter().map(|o| (o.slope.degrees(), o.t1 * 1e3, o.t1_sd * 1e3)).collect(),
        observed_label: "observed (mean ± SD)".into(),
        reference: None,
        repose,
        from_zero: true,
        legend: SeriesLabelPosition::UpperLeft,
    };
    add(&mut figures, "fig5b", "Anchoring time against slope", "The time after touchdown at which the leg reaches the shear-equilibrium depth d_s (docs/model.md §4). The paper plots measured t1 but prints no values; give --t1 (a CSV of means and SDs) or --tracks (motion-capture recordings) to overlay yours.".into(), to_svg(&fig)?);
    let fig = SlopeCurveFigure {
        title: "Net step length".into(),
        y_label: "net step s (mm)".into(),
        model: grid.iter().zip(&predictions).map(|(&d, p)| (d, p.step.map(|s| s * 1e3))).collect(),
        model_label: "model".into(),
        observed: speeds
            .iter()
            .map(|o| {
                let half = robot.stance_duration() * 1e3;
                (o.slope.degrees(), o.speed * half, o.speed_sd * half)
            })
            .collect(),
        observed_label: "observed speed × T/2".into(),
        reference: Some((robot.min_step() * 1e3, "s_min = R: success above, metastable below".into())),
        repose,
        from_zero: true,
        legend: SeriesLabelPosition::LowerLeft,
    };
    add(
        &mut figures,
        "fig5c",
        "Net step against slope",
        "s = s2 - s1 (docs/model.md §5); the observed points are the observed speeds times T/2.".into(),
        to_svg(&fig)?,
    );

    // fig6a-d: the four phase diagrams, in the paper's order (a, b: 0.35 kg on level sand and
    // at 24 deg; c, d: 1 kg), drawn as one 2 x 2 figure so the panel letters match the paper's.
    let k_n_axis = Axis::new("k_n", 1e4, 1e8, 120, AxisScale::Log).map_err(|e| anyhow!("{e}"))?;
    let k_s_axis = Axis::new("k_s", 1e4, 1e9, 120, AxisScale::Log).map_err(|e| anyhow!("{e}"))?;
    let mut panels = Vec::new();
    let mut parts = Vec::new();
    let mut regimes = Vec::new();
    for (id, mass, slope_deg) in
        [("fig6a", 0.35, 0.0), ("fig6b", 0.35, 24.0), ("fig6c", 1.0, 0.0), ("fig6d", 1.0, 24.0)]
    {
        let r = robot.with_mass(mass).map_err(|e| anyhow!("{e}"))?;
        let panel = PhasePanel::compute(&r, slope_deg, &terrain, &k_n_axis, &k_s_axis, &|| {})
            .map_err(|e| anyhow!("{e}"))?;
        regimes.push(format!("({}) {}", &id[4..], panel.terrain_regime));
        parts.push((id.to_string(), format!("Phase diagram, {mass} kg at {slope_deg} deg")));
        panels.push(panel);
    }
    let fig = PhaseFigure::new(&panels, 2, terrain.name().unwrap_or("terrain").to_string());
    figures.push(PageFigure {
        id: "fig6".into(),
        title: "Phase diagrams: 0.35 kg and 1 kg, on level sand and at 24°".into(),
        caption: format!(
            "Regime over (k_n, k_s): blue sinkage, red slippage, yellow metastable, green success; the black line is s = R; the star is the terrain at that slope: {}. The paper (Fig. 6d) calls the 1 kg robot at 24° metastable.",
            regimes.join(", ")
        ),
        svg: to_svg(&fig)?,
        parts,
    });

    // p_fail against slope with the safe-slope limit.
    let uncertain = UncertainTerrain::new(terrain.clone(), None, None).map_err(|e| anyhow!("{e}"))?;
    let risk_slopes: Vec<f64> = (0..=60).map(|i| i as f64 * 0.5).collect();
    let curve = risk_curve(&robot, &uncertain, &risk_slopes).map_err(|e| anyhow!("{e}"))?;
    let limit = safe_slope_limit(&robot, &uncertain, args.max_risk).map_err(|e| anyhow!("{e}"))?;
    let fig = CurveFigure {
        curve: curve.points.iter().map(|p| (p.slope_deg, p.probabilities)).collect(),
        points: vec![],
        hi: 30.0,
        max_risk: args.max_risk,
        limit,
        title: format!("Failure risk of the {} kg robot", robot.mass()),
    };
    let note = curve.defaults_used.note().map(|n| format!(" {n}.")).unwrap_or_default();
    add(&mut figures,
        "risk",
        "Failure probability against slope",
        format!(
            "p_fail = P(sinkage or slippage) with log-normal k_n, k_s (docs/model.md §9), and the safe-slope limit at p_fail < {}.{note}",
            args.max_risk
        ),
        to_svg(&fig)?,
    );

    // The calibration pulls.
    if let Some(c) = &calibration {
        let points = speed_pulls(&c.pulls);
        let fitted = Robot::new(c.robot.clone()).map_err(|e| anyhow!("{e}"))?;
        let fitted_terrain = Terrain::new(c.terrain.clone()).map_err(|e| anyhow!("{e}"))?;
        let curve: Vec<(f64, Option<f64>)> = grid
            .iter()
            .filter(|&&d| d <= 24.5)
            .map(|&d| {
                let g = fitted_terrain.at(at(d));
                (d, predict(&fitted, at(d), &g).speed)
            })
            .collect();
        let subtitle = format!(
            "χ²/dof = {}, floor {:.2} cm/s",
            c.chi_squared_per_dof.map_or("-".into(), |r| format!("{r:.2}")),
            c.error_floor_m_s * 100.0
        );
        add(&mut figures, "calibration", "Joint calibration: observed against fitted speeds, and pulls", "The terrain's k_s shape scaled by a fitted plate_scale, with a fitted model-error floor (docs/calibration.md). Pulls beyond ±2 are red.".into(), to_svg(&CalibrationFigure { points: &points, curve: &curve, subtitle: &subtitle })?);
    }

    let paper_rows = compare_with_paper(&robot, &terrain);
    let disagreements = disagreements(&paper_rows, calibration.as_ref(), &speeds);
    let speed_records: Vec<SpeedRecord> = speeds
        .iter()
        .map(|o| SpeedRecord {
            slope_deg: o.slope.degrees(),
            observed_m_s: o.speed,
            observed_sd_m_s: o.speed_sd,
            model_m_s: predict(&robot, o.slope, &terrain.at(o.slope)).speed,
        })
        .collect();
    let track_records: Vec<TrackRecord> = tracks.iter().map(track_record).collect();
    let html = page(
        &inputs,
        &figures,
        &paper_rows,
        calibration.as_ref(),
        &disagreements,
        &TracksSection { records: &track_records, notes: &track_use.notes },
    );
    let json = ReportJson {
        figures: figures
            .iter()
            .flat_map(|f| {
                if f.parts.is_empty() {
                    vec![FigureRecord { id: &f.id, title: &f.title }]
                } else {
                    f.parts.iter().map(|(id, title)| FigureRecord { id, title }).collect()
                }
            })
            .collect(),
        speeds: &speed_records,
        tracks: &track_records,
        calibration: calibration.as_ref(),
        paper_vs_model: &paper_rows,
        disagreements: &disagreements,
        inputs: &inputs,
    };
    let json = serde_json::to_string_pretty(&json)?;
    std::fs::create_dir_all(&args.out)
        .map_err(|source| sandslope_io::WriteError { path: args.out.clone(), source })?;
    write_atomic(&args.out.join("report.json"), json.as_bytes())?;
    write_atomic(&args.out.join("index.html"), html.as_bytes())?;
    let failing = paper_rows.iter().filter(|r| !r.agrees).count();
    println!(
        "{} figures; the model agrees with {} of the paper's {} numbers; {} disagreement(s) listed",
        figures.len(),
        paper_rows.len() - failing,
        paper_rows.len(),
        disagreements.len()
    );
    eprintln!(
        "wrote {} and {}",
        args.out.join("index.html").display(),
        args.out.join("report.json").display()
    );
    Ok(())
}

/// How the tracks enter the report: their anchoring times, their speeds (used as the
/// observed speeds unless --observed is given) and the page's notes on what was left out.
struct TrackUse {
    anchoring: Vec<AnchoringObservation>,
    speeds: Vec<SpeedObservation>,
    notes: Vec<String>,
}

impl TrackUse {
    /// Splits the tracks into observations, warning on stderr (and noting for the page) about
    /// every slope whose t1 or speed cannot be used: without an SD > 0 an observation has no
    /// weight in the calibration.
    fn new(tracks: &[SlopeTracks], observed_given: bool) -> TrackUse {
        let mut out = TrackUse { anchoring: Vec::new(), speeds: Vec::new(), notes: Vec::new() };
        for t in tracks {
            let r = &t.tracked.result;
            let files = t.tracked.names.join(", ");
            let slope = at(t.slope_deg);
            match (r.t1_s, r.t1_sd_s) {
                (Some(t1), Some(sd)) if sd > 0.0 => {
                    out.anchoring.push(AnchoringObservation { slope, t1, t1_sd: sd })
                }
                _ => {
                    let why = if r.t1_s.is_none() {
                        format!("no anchored step among {} steps", r.steps)
                    } else {
                        "its SD needs at least two anchored steps with different t1".to_string()
                    };
                    let note = format!(
                        "The tracks at {}° ({files}) give no anchoring time ({why}): not drawn in fig5b nor used in the calibration.",
                        t.slope_deg
                    );
                    eprintln!(
                        "warning: --tracks at {}° ({files}): no anchoring time ({why}); not used",
                        t.slope_deg
                    );
                    out.notes.push(note);
                }
            }
            if observed_given {
                continue;
            }
            match r.speed_sd_m_s {
                Some(sd) if sd > 0.0 => {
                    out.speeds.push(SpeedObservation { slope, speed: r.speed_m_s, speed_sd: sd })
                }
                _ => {
                    let why = format!(
                        "its SD needs at least two steps with different speeds; found {} steps",
                        r.steps
                    );
                    eprintln!(
                        "warning: --tracks at {}° ({files}): no observed speed ({why}); not used",
                        t.slope_deg
                    );
                    out.notes.push(format!(
                        "The tracks at {}° ({files}) give no observed speed ({why}): not drawn in fig3a nor used in the calibration.",
                        t.slope_deg
                    ));
                }
            }
        }
        if observed_given && !tracks.is_empty() {
            out.notes.push(
                "The observed speeds are --observed's: the tracks' speeds are shown in this table only."
                    .into(),
            );
        }
        out
    }
}

/// One slope's row of the motion-capture table and of report.json's `tracks`.
fn track_record(t: &SlopeTracks) -> TrackRecord {
    let r = &t.tracked.result;
    TrackRecord {
        slope_deg: t.slope_deg,
        files: t.tracked.names.clone(),
        steps: r.steps,
        unanchored_steps: r.unanchored_steps,
        speed_m_s: r.speed_m_s,
        speed_sd_m_s: r.speed_sd_m_s,
        t1_s: r.t1_s,
        t1_sd_s: r.t1_sd_s,
        slip_m: r.slip_m,
        slip_sd_m: r.slip_sd_m,
    }
}

/// The "where the model and the paper disagree" items, generated from the comparison and the
/// calibration.
fn disagreements(
    rows: &[sandslope::paper::PaperComparison],
    calibration: Option<&JointCalibration>,
    speeds: &[SpeedObservation],
) -> Vec<String> {
    let mut out: Vec<String> = rows
        .iter()
        .filter(|r| !r.agrees)
        .map(|r| {
            format!(
                "{}: the paper reports {}, the model gives {} (rule: {}; {}).",
                r.quantity, r.paper, r.model, r.rule, r.source
            )
        })
        .collect();
    let mut sorted: Vec<&SpeedObservation> = speeds.iter().collect();
    sorted.sort_by(|a, b| a.slope.radians().total_cmp(&b.slope.radians()));
    for w in sorted.windows(2) {
        if w[1].speed > w[0].speed {
            out.push(format!(
                "The observed speed rises from {} to {} deg ({:.2} to {:.2} cm/s); a k_s that falls with slope makes the model's speed fall, so no calibration of this model can follow it.",
                w[0].slope.degrees(),
                w[1].slope.degrees(),
                w[0].speed * 100.0,
                w[1].speed * 100.0
            ));
        }
    }
    if let Some(c) = calibration {
        if c.error_floor_m_s > 0.0 {
            out.push(format!(
                "Fitting the speeds takes a model-error floor of {:.2} cm/s added to the quoted SDs (68%: {:.2} to {:.2}); the quoted SDs alone (as small as {:.2} cm/s) are not reachable by the model.",
                c.error_floor_m_s * 100.0,
                c.parameters.iter().find(|p| p.name == "error_floor").map_or(0.0, |p| p.estimate.lower * 100.0),
                c.parameters.iter().find(|p| p.name == "error_floor").map_or(0.0, |p| p.estimate.upper * 100.0),
                speeds.iter().map(|o| o.speed_sd).fold(f64::INFINITY, f64::min) * 100.0
            ));
        }
        let scale = c.parameters.iter().find(|p| p.name == "plate_scale").map_or(1.0, |p| p.estimate.value);
        if let (Some(level), true) = (c.shear.first(), scale > 3.0) {
            out.push(format!(
                "The leg k_s the model needs at {} deg ({:.2e} N/m³) would give {:.0} N on the paper's 3 cm × 2 cm shear plate (F = k_s W d²), {scale:.0} times what the force tests give: the model's k_s is an effective leg parameter, not the plate's.",
                level.slope_deg, level.k_s, level.plate_force_n
            ));
        }
        for w in &c.warnings {
            out.push(format!("Calibration: {w}."));
        }
    }
    out
}
