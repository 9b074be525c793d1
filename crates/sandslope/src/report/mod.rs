//! The report: the paper reproduced and confronted, as one value (what `sandslope report`
//! renders to `index.html` and `report.json`, and Python's `sandslope.report` returns).
//!
//! [`report`] takes the evidence (robot, terrain, observed speeds, force tests, anchoring
//! times, motion-capture tracks) and returns a [`Report`]: the inputs, the paper's numbers
//! beside the model's (docs/model.md §12), the joint calibration (§14, docs/calibration.md),
//! the disagreements with the rules that found them, and the data of every figure. It reads
//! no file and draws nothing.

mod disagreements;
mod tracks;

use serde::Serialize;

use crate::calibrate::SpeedObservation;
use crate::calibrate::{
    calibrate_jointly, AnchoringObservation, FreeParameter, JointCalibration, JointSetup, Parameter,
    ShearShape,
};
use crate::error::ParamError;
use crate::gait::track::TrackResult;
use crate::model::{predict, Prediction};
use crate::paper::{self, compare_with_paper, PaperComparison};
use crate::phase::{Axis, AxisScale, PhasePanel};
use crate::risk::{risk_curve, safe_slope_limit, RiskCurve, SafeLimit, UncertainTerrain};
use crate::robot::Robot;
use crate::slope::Slope;
use crate::terrain::{Terrain, TerrainPoint};

use tracks::TrackUse;
pub use tracks::{TrackRecord, TrackedSlope};

/// Where the force tests come from.
#[derive(Debug, Clone, PartialEq)]
pub enum ForceTests {
    /// None: the terrain's own table is drawn, and is the k_s shape calibrated.
    None,
    /// The paper's force tests as its text reports them (`data/example-force-tests.toml`,
    /// from which the built-in terrain was calibrated; its levels and SDs are assumptions).
    Paper(Terrain),
    /// A user's force tests (a terrain file with `k_s_sd`, as `sandslope fit` writes).
    Given {
        /// The table.
        table: Terrain,
        /// Where it came from, as the user named it.
        source: String,
    },
}

impl ForceTests {
    fn table(&self) -> Option<&Terrain> {
        match self {
            ForceTests::None => None,
            ForceTests::Paper(t) | ForceTests::Given { table: t, .. } => Some(t),
        }
    }
}

/// How the motion-capture files were read, for the inputs table.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TrackReading {
    /// The format's name; `None`: detected per file.
    pub format: Option<String>,
    /// The body tracked; `None`: chosen per file.
    pub body: Option<String>,
    /// The upslope unit vector; `None`: estimated per slope from the travel.
    pub upslope: Option<[f64; 3]>,
}

/// Everything the report is made from. Sources are named as the user gave them.
#[derive(Debug, Clone)]
pub struct Evidence {
    /// The robot.
    pub robot: Robot,
    /// Its preset name or file.
    pub robot_source: String,
    /// The terrain the model runs on.
    pub terrain: Terrain,
    /// Its preset name or file.
    pub terrain_source: String,
    /// Observed speeds and their file; `None`: the tracks' speeds, else the paper's five.
    pub observed: Option<(String, Vec<SpeedObservation>)>,
    /// The force tests.
    pub forces: ForceTests,
    /// Observed anchoring times and their file (`--t1`).
    pub anchoring: Option<(String, Vec<AnchoringObservation>)>,
    /// Motion-capture tracks, one pooled analysis per slope, lowest slope first.
    pub tracks: Vec<TrackedSlope>,
    /// How the tracks were read.
    pub track_reading: TrackReading,
    /// Risk threshold of the safe-slope limit, in (0, 1).
    pub max_risk: f64,
}

/// `report.json`'s figure entry: the paper's figure number (or a name for figures the paper
/// does not have) and title.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FigureRecord {
    /// Id.
    pub id: String,
    /// Title.
    pub title: String,
}

/// One observed speed beside the model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpeedRecord {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Observed mean, m/s.
    pub observed_m_s: f64,
    /// Observed SD, m/s.
    pub observed_sd_m_s: f64,
    /// The model's speed on the terrain (`null` where the regime rules it out), m/s.
    pub model_m_s: Option<f64>,
}

/// The phase-diagram panels, in the paper's order: `(id, mass kg, slope deg)`.
pub const PHASE_PANELS: [(&str, f64, f64); 4] =
    [("fig6a", 0.35, 0.0), ("fig6b", 0.35, 24.0), ("fig6c", 1.0, 0.0), ("fig6d", 1.0, 24.0)];

/// The data the figures are drawn from (not part of `report.json`).
#[derive(Debug, Clone)]
pub struct Plots {
    /// The model on the terrain at every slope of the grid, 0 to 30 degrees every 0.25.
    pub model: Vec<Prediction>,
    /// The observed speeds.
    pub speeds: Vec<SpeedObservation>,
    /// The observed anchoring times (`--t1` and the tracks').
    pub anchoring: Vec<AnchoringObservation>,
    /// Tracked slopes with at least one complete step, lowest first: `(slope deg, analysis)`.
    pub strides: Vec<(f64, TrackResult)>,
    /// The table drawn beside the terrain in fig4d/h: the force tests, else the terrain's.
    pub table: Vec<TerrainPoint>,
    /// Whether `table` is force tests.
    pub table_is_forces: bool,
    /// The fitted plate_scale the plate k_s is drawn times (1 without force tests).
    pub plate_scale: f64,
    /// The terrain's angle of repose, degrees.
    pub repose_deg: Option<f64>,
    /// The terrain's name.
    pub terrain_name: String,
    /// The robot's stance duration T/2, s.
    pub stance_duration_s: f64,
    /// The robot's minimum robust step s_min, m.
    pub min_step_m: f64,
    /// The robot's mass, kg.
    pub mass_kg: f64,
    /// The phase panels of [`PHASE_PANELS`].
    pub phase: Vec<PhasePanel>,
    /// p_fail against slope, 0 to 30 degrees every 0.5.
    pub risk: RiskCurve,
    /// The safe-slope limit at `max_risk`.
    pub safe_limit: SafeLimit,
    /// The risk threshold.
    pub max_risk: f64,
    /// The calibrated model's speed, 0 to 24.5 degrees (empty without a calibration).
    pub calibrated_speed: Vec<(f64, Option<f64>)>,
}

/// The whole report. Serialises to `report.json`; [`Report::plots`], the page's notes and
/// the terminal warnings are not part of it.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// The figures, in page order (panels of one figure each listed).
    pub figures: Vec<FigureRecord>,
    /// Observed against model speeds.
    pub speeds: Vec<SpeedRecord>,
    /// The motion-capture tracks per slope (empty without).
    pub tracks: Vec<TrackRecord>,
    /// The joint calibration of the terrain's (or force tests') k_s shape on the evidence
    /// (`null` if it failed).
    pub calibration: Option<JointCalibration>,
    /// Every number the paper reports beside the model's.
    pub paper_vs_model: Vec<PaperComparison>,
    /// The generated "where the model and the paper disagree" items.
    pub disagreements: Vec<String>,
    /// What the report was made from: `[what, value]`.
    pub inputs: Vec<(String, String)>,
    /// Sentences on how the tracks entered the report (skipped t1s, speeds not used, ...).
    #[serde(skip)]
    pub track_notes: Vec<String>,
    /// Warnings for the user's terminal.
    #[serde(skip)]
    pub warnings: Vec<String>,
    /// The figures' data.
    #[serde(skip)]
    pub plots: Plots,
}

/// Slopes of the model curves: 0 to 30 deg every 0.25 deg.
fn slope_grid() -> Vec<Slope> {
    (0..=120).map(|i| at(i as f64 * 0.25)).collect()
}

fn at(d: f64) -> Slope {
    Slope::from_degrees(d).expect("grid slopes are valid")
}

/// Builds the report from the evidence. Errors: `max_risk` outside (0, 1), a track slope
/// outside [0, 90), or a robot the phase panels' masses make invalid.
pub fn report(evidence: &Evidence) -> Result<Report, ParamError> {
    let robot = &evidence.robot;
    let terrain = &evidence.terrain;
    let track_use = TrackUse::new(&evidence.tracks, evidence.observed.is_some())?;
    let mut anchoring: Vec<AnchoringObservation> =
        evidence.anchoring.as_ref().map(|(_, a)| a.clone()).unwrap_or_default();
    anchoring.extend(track_use.anchoring.iter().copied());
    let speeds: Vec<SpeedObservation> = match &evidence.observed {
        Some((_, s)) => s.clone(),
        None if !evidence.tracks.is_empty() => track_use.speeds.clone(),
        None => paper::SPEEDS
            .iter()
            .map(|&(d, v, sd)| SpeedObservation { slope: at(d), speed: v, speed_sd: sd })
            .collect(),
    };
    let calibration = calibrate(evidence, &speeds, &anchoring);
    let plots = plots(evidence, speeds.clone(), anchoring, calibration.as_ref())?;
    let paper_vs_model = compare_with_paper(robot, terrain);
    let disagreements = disagreements::disagreements(&paper_vs_model, calibration.as_ref(), &speeds);
    let speeds = speeds
        .iter()
        .map(|o| SpeedRecord {
            slope_deg: o.slope.degrees(),
            observed_m_s: o.speed,
            observed_sd_m_s: o.speed_sd,
            model_m_s: predict(robot, o.slope, &terrain.at(o.slope)).speed,
        })
        .collect();
    Ok(Report {
        figures: figure_records(&plots, calibration.is_some()),
        speeds,
        tracks: evidence.tracks.iter().map(TrackRecord::from).collect(),
        calibration,
        paper_vs_model,
        disagreements,
        inputs: inputs(evidence, !track_use.anchoring.is_empty()),
        track_notes: track_use.notes,
        warnings: track_use.warnings,
        plots,
    })
}

/// The joint calibration of the force tests' (or the terrain's) k_s shape on the evidence,
/// `plate_scale` and the model-error floor free (docs/calibration.md); `None` if it fails.
fn calibrate(
    evidence: &Evidence,
    speeds: &[SpeedObservation],
    anchoring: &[AnchoringObservation],
) -> Option<JointCalibration> {
    let shape = evidence.forces.table().unwrap_or(&evidence.terrain).clone();
    let setup = JointSetup {
        robot: evidence.robot.clone(),
        normal: shape.clone(),
        shear: ShearShape::ForceTests(shape),
        speeds: speeds.to_vec(),
        anchoring: anchoring.to_vec(),
        free: [Parameter::PlateScale, Parameter::ErrorFloor]
            .into_iter()
            .map(|parameter| FreeParameter { parameter, bounds: None })
            .collect(),
        error_floor: 0.0,
    };
    calibrate_jointly(&setup).ok()
}

/// The figures' data.
fn plots(
    evidence: &Evidence,
    speeds: Vec<SpeedObservation>,
    anchoring: Vec<AnchoringObservation>,
    calibration: Option<&JointCalibration>,
) -> Result<Plots, ParamError> {
    let robot = &evidence.robot;
    let terrain = &evidence.terrain;
    let grid = slope_grid();
    let forces = evidence.forces.table();
    // Plate values are drawn on the leg's scale: times the fitted plate_scale.
    let plate_scale = match (forces, calibration) {
        (Some(_), Some(c)) => c.plate_scale(),
        _ => 1.0,
    };
    let k_n_axis = Axis::new("k_n", 1e4, 1e8, 120, AxisScale::Log)?;
    let k_s_axis = Axis::new("k_s", 1e4, 1e9, 120, AxisScale::Log)?;
    let mut phase = Vec::new();
    for (_, mass, slope_deg) in PHASE_PANELS {
        let r = robot.with_mass(mass)?;
        phase.push(PhasePanel::compute(&r, slope_deg, terrain, &k_n_axis, &k_s_axis, &|| {})?);
    }
    let uncertain = UncertainTerrain::new(terrain.clone(), None, None)?;
    let risk_slopes: Vec<f64> = (0..=60).map(|i| i as f64 * 0.5).collect();
    let calibrated_speed = match calibration {
        Some(c) => {
            let fitted_robot = Robot::new(c.robot.clone())?;
            let fitted_terrain = Terrain::new(c.terrain.clone())?;
            grid.iter()
                .filter(|s| s.degrees() <= 24.5)
                .map(|&s| (s.degrees(), predict(&fitted_robot, s, &fitted_terrain.at(s)).speed))
                .collect()
        }
        None => Vec::new(),
    };
    Ok(Plots {
        model: grid.iter().map(|&s| predict(robot, s, &terrain.at(s))).collect(),
        speeds,
        anchoring,
        strides: evidence
            .tracks
            .iter()
            .filter(|t| t.result.steps > 0)
            .map(|t| (t.slope_deg, t.result.clone()))
            .collect(),
        table: forces.unwrap_or(terrain).points().to_vec(),
        table_is_forces: forces.is_some(),
        plate_scale,
        repose_deg: terrain.spec().repose_deg,
        terrain_name: terrain.name().unwrap_or("terrain").to_string(),
        stance_duration_s: robot.stance_duration(),
        min_step_m: robot.min_step(),
        mass_kg: robot.mass(),
        phase,
        risk: risk_curve(robot, &uncertain, &risk_slopes)?,
        safe_limit: safe_slope_limit(robot, &uncertain, evidence.max_risk)?,
        max_risk: evidence.max_risk,
        calibrated_speed,
    })
}

/// The figures in page order, the phase diagram's panels listed one by one.
fn figure_records(plots: &Plots, calibrated: bool) -> Vec<FigureRecord> {
    let mut out = vec![("fig3a", "Speed against slope".to_string())];
    if !plots.strides.is_empty() {
        out.push(("fig3b", "Speed within a stride".into()));
    }
    out.extend([
        ("fig4d", "Normal penetration resistance k_n".into()),
        ("fig4h", "Shear strength k_s".into()),
        ("fig5b", "Anchoring time against slope".into()),
        ("fig5c", "Net step against slope".into()),
    ]);
    for (id, mass, slope) in PHASE_PANELS {
        out.push((id, format!("Phase diagram, {mass} kg at {slope} deg")));
    }
    out.push(("risk", "Failure probability against slope".into()));
    if calibrated {
        out.push(("calibration", "Joint calibration: observed against fitted speeds, and pulls".into()));
    }
    out.into_iter().map(|(id, title)| FigureRecord { id: id.into(), title }).collect()
}

/// The inputs table: what the report was made from.
fn inputs(evidence: &Evidence, tracks_give_t1: bool) -> Vec<(String, String)> {
    let tracks = &evidence.tracks;
    let mut inputs = vec![
        ("robot".to_string(), evidence.robot_source.clone()),
        ("terrain".to_string(), evidence.terrain_source.clone()),
        (
            "observed speeds".to_string(),
            match (&evidence.observed, tracks.is_empty()) {
                (Some((p, _)), _) => p.clone(),
                (None, false) => "the motion-capture tracks' (mean ± SD per slope, --tracks)".into(),
                (None, true) => "the paper's (docs/model.md §12)".into(),
            },
        ),
        (
            "force tests".to_string(),
            match &evidence.forces {
                ForceTests::Given { source, .. } => source.clone(),
                ForceTests::Paper(_) => {
                    "the paper's, as its text reports them (data/example-force-tests.toml)".into()
                }
                ForceTests::None => "the terrain's own table".into(),
            },
        ),
    ];
    let t1_sources: Vec<String> = evidence
        .anchoring
        .iter()
        .map(|(p, _)| p.clone())
        .chain(tracks_give_t1.then(|| "the motion-capture tracks (--tracks)".to_string()))
        .collect();
    if !t1_sources.is_empty() {
        inputs.push(("anchoring times".into(), t1_sources.join(" and ")));
    }
    for t in tracks {
        inputs.push((format!("motion capture at {}°", t.slope_deg), t.files.join(", ")));
    }
    if !tracks.is_empty() {
        let r = &evidence.track_reading;
        inputs.push((
            "motion-capture reading".into(),
            format!(
                "format {}; body {}; upslope {}; stride period T = {} s (the robot's)",
                r.format.as_deref().unwrap_or("detected per file"),
                r.body.as_deref().unwrap_or("chosen per file (no --tracks-body)"),
                r.upslope.map_or("estimated per slope from the travel".to_string(), |v| {
                    format!("[{:.3}, {:.3}, {:.3}]", v[0], v[1], v[2])
                }),
                evidence.robot.stride_period()
            ),
        ));
    }
    inputs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::tests::paper_robot;
    use crate::terrain::TerrainSpec;

    /// k_n constant, k_s falling to 40% at 20 deg, repose 25 deg.
    fn terrain() -> Terrain {
        let point = |slope_deg, k_s| TerrainPoint { slope_deg, k_n: 7e5, k_s, k_n_sd: None, k_s_sd: None };
        Terrain::new(TerrainSpec {
            name: Some("test".into()),
            repose_deg: Some(25.0),
            points: vec![point(0.0, 2e6), point(20.0, 8e5)],
        })
        .unwrap()
    }

    fn evidence() -> Evidence {
        Evidence {
            robot: paper_robot(),
            robot_source: "paper-hexapod".into(),
            terrain: terrain(),
            terrain_source: "test.toml".into(),
            observed: None,
            forces: ForceTests::None,
            anchoring: None,
            tracks: vec![],
            track_reading: TrackReading::default(),
            max_risk: 0.05,
        }
    }

    /// A pooled analysis of a known step profile (t1 = 0.12 s, 1,200 frames at 120 fps), with
    /// its speed SD and t1 SD replaced as given (`None`: fewer than two distinct values).
    fn tracked(slope_deg: f64, speed_sd: Option<f64>, t1_sd: Option<f64>) -> TrackedSlope {
        use crate::gait::synthetic::StepProfile;
        use crate::gait::{track, GaitOptions, Recording};
        let profile = StepProfile::new(0.5, 0.12, 0.40, 0.12, 0.30).unwrap();
        let positions = crate::gait::tests::recording(&profile, [1.0, 0.0, 0.0], 1200, 0.2, 3e-4);
        let rec =
            Recording { positions: &positions, frame_rate_hz: 120.0, start_time_s: 0.0, touchdowns_s: None };
        let slope = Slope::from_degrees(slope_deg).unwrap();
        let mut result = track(&[rec], &GaitOptions::new(1.0).unwrap(), Some(slope)).unwrap();
        result.speed_sd_m_s = speed_sd;
        result.t1_sd_s = t1_sd;
        TrackedSlope { slope_deg, files: vec![format!("{slope_deg}.csv")], result }
    }

    #[test]
    fn default_evidence_compares_the_papers_five_speeds_with_the_model() {
        let r = report(&evidence()).unwrap();
        let slopes: Vec<f64> = r.speeds.iter().map(|s| s.slope_deg).collect();
        assert_eq!(slopes, [0.0, 10.0, 15.0, 20.0, 24.0]);
        // Each model speed is predict's on the terrain at that slope, independently evaluated.
        let t = terrain();
        for s in &r.speeds {
            let slope = Slope::from_degrees(s.slope_deg).unwrap();
            assert_eq!(s.model_m_s, predict(&paper_robot(), slope, &t.at(slope)).speed);
        }
        // No tracks: no fig3b; the phase diagram's four panels and the calibration are listed.
        let ids: Vec<&str> = r.figures.iter().map(|f| f.id.as_str()).collect();
        assert!(!ids.contains(&"fig3b"));
        assert_eq!(ids.iter().filter(|id| id.starts_with("fig6")).count(), 4);
        assert_eq!(r.plots.phase.len(), 4);
        assert_eq!(r.calibration.is_some(), ids.contains(&"calibration"));
        // The observed speed rises from 20 to 24 deg (4.98 to 5.6 cm/s): named.
        assert!(
            r.disagreements.iter().any(|d| d.contains("rises from 20 to 24 deg")),
            "{:?}",
            r.disagreements
        );
        assert_eq!(
            r.inputs[2],
            ("observed speeds".to_string(), "the paper's (docs/model.md §12)".to_string())
        );
    }

    #[test]
    fn tracks_without_sds_are_not_used_and_say_why() {
        let mut e = evidence();
        // 10 deg: usable speed and t1; 20 deg: one step, so neither has an SD.
        e.tracks = vec![tracked(10.0, Some(0.01), Some(0.01)), tracked(20.0, None, Some(0.0))];
        let r = report(&e).unwrap();
        assert_eq!(r.speeds.len(), 1);
        assert_eq!(r.speeds[0].slope_deg, 10.0);
        assert_eq!(r.plots.anchoring.len(), 1);
        assert_eq!(r.warnings.len(), 2, "{:?}", r.warnings);
        assert!(r.track_notes.iter().all(|n| n.contains("20°")));
        assert_eq!(r.figures[1].id, "fig3b");
        assert_eq!(r.plots.strides.len(), 2);
    }

    #[test]
    fn a_risk_threshold_outside_0_1_is_an_error() {
        let mut e = evidence();
        e.max_risk = 1.5;
        assert!(report(&e).is_err());
    }
}
