//! The report: the paper reproduced and confronted, as one value (what `sandslope report`
//! renders to `index.html` and `report.json`, and Python's `sandslope.report` returns).
//!
//! [`report`] takes the evidence (robot, terrain, observed speeds, force tests, anchoring
//! times, motion-capture tracks) and returns a [`Report`]: the inputs, the paper's numbers
//! beside the model's (docs/model.md §12), the joint calibration (§14, docs/calibration.md),
//! the disagreements with the rules that found them, and the data of every figure. It reads
//! no file and draws nothing.

mod audit;
mod diagnosis;
mod disagreements;
mod provenance;
mod scope;
mod simulator;
mod tracks;

use serde::Serialize;

use crate::axis::{Axis, AxisScale};
use crate::calibrate::SpeedObservation;
use crate::calibrate::{
    calibrate_jointly, calibrate_jointly_with, AnchoringObservation, FreeParameter, JointCalibration,
    JointSetup, Parameter, ShearShape, SpeedModel,
};
use crate::error::ParamError;
use crate::gait::track::TrackResult;
use crate::model::{predict, Prediction};
use crate::paper::{self, compare_with_paper, ComparisonContext, PaperComparison};
use crate::phase::{PhasePanel, TerrainGrid};
use crate::risk::{
    risk_curve, safe_slope_limit, success_slope_limit, RiskCurve, SafeLimit, UncertainTerrain,
};
use crate::robot::Robot;
use crate::slope::{SignedSlope, Slope};
use crate::terrain::{Terrain, TerrainPoint};

pub use audit::{Extrapolation, NoFloorFit, SpeedInversion, StepBudget, PAPER_FRAME_RATE_HZ};
pub use diagnosis::{FitDiagnosis, Miss, StepAtObservedT1, CONTRADICTION_SD};
pub use disagreements::{ObservationMiss, OBSERVATION_MISS_SD};
pub use provenance::{Input, Provenance, ProvenanceKind};
use scope::{another_robot_without_observations, summary, terrain_rows_only};
pub use scope::{SimulatorLeftOut, Summary};
pub use simulator::{
    simulator_fit_misses, Parting, SimulatorMiss, SimulatorRecord, SimulatorWalks, AGREE_WITHIN, MISS_SD,
    REACH_K_S, REPORT_FREE_STEPS_PER_STRIDE, REPORT_WALK_S,
};
use tracks::TrackUse;
pub use tracks::{TrackGap, TrackRecord, TrackedSlope, UnusedTrack};

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
    /// The robot is the built-in paper-hexapod (the paper's robot, h tuned to its level speed).
    pub builtin_robot: bool,
    /// The terrain is the built-in glass-beads-300um (the joint calibration on the paper's
    /// speeds and force-test ratio).
    pub builtin_terrain: bool,
    /// Also fit the evidence with the stride simulator in place of the closed form
    /// (`report --simulator-fit`, [`Report::simulator_fit`]): about 8 minutes of CPU on the paper's
    /// evidence, where the rest of the report takes under a second, so it is asked for.
    pub simulator_fit: bool,
}

impl Evidence {
    /// Whether the observations are the user's (speeds, anchoring times or tracks) rather
    /// than the paper's.
    pub fn has_own_observations(&self) -> bool {
        self.observed.is_some() || self.anchoring.is_some() || !self.tracks.is_empty()
    }
}

/// `report.json`'s figure entry: the paper's figure number (or a name for figures the paper
/// does not have) and title.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FigureRecord {
    /// Id.
    pub id: String,
    /// Title: the front end's, by id (empty as [`report`] returns it).
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
    /// The slope of the terrain's last point when it has several, degrees: beyond it the
    /// model's k_n and k_s are extrapolated (docs/model.md §1).
    pub last_point_deg: Option<f64>,
    /// The terrain's own name (`None`: unnamed, as a calibration's terrain; the front end
    /// names it then).
    pub terrain_name: Option<String>,
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
    /// The safe-slope limit at `max_risk` (p_fail: no sinkage or slippage).
    pub safe_limit: SafeLimit,
    /// The success limit at `max_risk` (P(not success): the robot climbs, not metastable).
    pub success_limit: SafeLimit,
    /// The risk threshold.
    pub max_risk: f64,
    /// The calibrated model's speed, 0 to 24.5 degrees (empty without a calibration).
    pub calibrated_speed: Vec<(f64, Option<f64>)>,
    /// The step budget over the slope grid, up to the angle of repose.
    pub step_budget: Vec<StepBudget>,
    /// The simulator's walks of the simulator section, in slope order.
    pub simulated: Vec<crate::simulate::SimSummary>,
    /// The same walks with the body's pitch locked (docs/model.md §15).
    pub simulated_pitch_locked: Vec<crate::simulate::SimSummary>,
}

/// The whole report. Serialises to `report.json`; [`Report::plots`] and the values the front
/// end words its sentences from (serde-skipped) are not part of it. Every sentence field is
/// empty as [`report`] returns it: the front end (the request layer's `report_text`) fills it.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// Whether the observations are the user's (then the model is the joint calibration on
    /// them) rather than the paper's.
    pub own_observations: bool,
    /// Whether the model of every table and figure is the calibration's robot and terrain (the
    /// user's observations, or the built-in terrain, which is that calibration); otherwise the
    /// terrain as given, and the calibration is shown beside it.
    pub model_is_calibration: bool,
    /// The plain answer for the report's robot and terrain, before the evidence: how steep it
    /// climbs and how fast, where it turns metastable and where it fails.
    pub plain_answer: PlainAnswer,
    /// Why the joint calibration is unreliable and what data would fix it, when the fit flags
    /// itself (a poor fit or a quantity at its search bound); `None` otherwise.
    pub fit_diagnosis: Option<FitDiagnosis>,
    /// The figures, in page order (panels of one figure each listed).
    pub figures: Vec<FigureRecord>,
    /// Observed against model speeds.
    pub speeds: Vec<SpeedRecord>,
    /// The motion-capture tracks per slope (empty without).
    pub tracks: Vec<TrackRecord>,
    /// The joint calibration of the terrain's (or force tests') k_s shape on the evidence,
    /// with its fit without the floor (`null` if it failed).
    pub calibration: Option<ReportCalibration>,
    /// Every number the paper reports beside the model's, each with its basis.
    pub paper_vs_model: Vec<PaperComparison>,
    /// How many of the paper's numbers the model agrees with, independent ones apart.
    pub summary: Summary,
    /// The generated "where the model and the evidence disagree" items: the user's observations
    /// the calibrated model misses ([`Self::observation_misses`]), then the failing comparisons,
    /// the per-slope inversion, the calibration's floor and plate scale; worded by the front end
    /// from this report's values (empty as [`report`] returns it).
    pub disagreements: Vec<String>,
    /// The user's observations more than [`OBSERVATION_MISS_SD`] quoted SDs from the calibrated
    /// model, speeds then anchoring times (empty on the paper's evidence).
    #[serde(skip)]
    pub observation_misses: Vec<ObservationMiss>,
    /// The k_s each observed speed needs on its own, lowest slope first.
    pub speed_inversion: Vec<SpeedInversion>,
    /// Regime claims at slopes beyond the measured k_s, and the k_s at which they would hold.
    pub extrapolations: Vec<Extrapolation>,
    /// Where the step is lost, one entry per observed slope (docs/model.md §5).
    pub step_budget: Vec<StepBudget>,
    /// The stride simulator beside the closed form and the observations, slope by slope, with
    /// where and why the two part (docs/simulate.md).
    pub simulator: Vec<SimulatorRecord>,
    /// Each of those pitch-locked walks checked for convergence (`simulate
    /// --check-convergence`, docs/simulate.md "Checking convergence"), in slope order.
    pub simulator_convergence: Vec<crate::simulate::ConvergenceCheck>,
    /// The same joint calibration with the stride simulator in place of the closed form
    /// (`calibrate --model simulate`), beside [`Report::calibration`]; `null` unless asked for
    /// ([`Evidence::simulator_fit`]: its thousands of walks take about 8 minutes of CPU on the paper's evidence) or
    /// when it failed (then a warning says why).
    pub simulator_fit: Option<JointCalibration>,
    /// The observed speeds that fit misses by more than [`MISS_SD`] of their own SD, each with
    /// the walk on the fitted ground, what a scan of the leg's k_s reaches there, and why
    /// (empty without the fit).
    pub simulator_fit_misses: Vec<SimulatorMiss>,
    /// What the report was made from, each with its provenance: worded by the front end from
    /// the evidence (empty as [`report`] returns it).
    pub inputs: Vec<Input>,
    /// Whether the motion-capture tracks give anchoring times (a row of the inputs table).
    #[serde(skip)]
    pub tracks_give_t1: bool,
    /// The tracked slopes whose anchoring time or speed could not be used, in slope order (the
    /// front ends word them: a note on the page, a warning first among [`Self::warnings`]).
    #[serde(skip)]
    pub unused_tracks: Vec<UnusedTrack>,
    /// Whether the observed speeds are `--observed`'s while tracks were given too: the tracks'
    /// speeds are shown in their table only.
    #[serde(skip)]
    pub track_speeds_shown_only: bool,
    /// Why the simulator section is left out (`None`: it is not).
    #[serde(skip)]
    pub simulator_left_out: Option<SimulatorLeftOut>,
    /// The parts of the simulator's joint fit that failed, fit first.
    #[serde(skip)]
    pub simulator_fit_failures: Vec<SimulatorFitFailure>,
    /// What a reader must know before trusting the page: a robot other than the paper's without
    /// observations, tracks that could not be used, the simulator section left out or not
    /// converged, the simulator's fit failed, a fitted quantity at its search bound, a fit far
    /// worse than the quoted SDs allow (chi^2/dof > 3). Printed at the top of the page and on
    /// stderr (`report --strict` fails on any). Worded by the front end from this report's
    /// values (empty as [`report`] returns it).
    pub warnings: Vec<String>,
    /// The figures' data.
    #[serde(skip)]
    pub plots: Plots,
}

/// A part of the simulator's joint fit ([`Report::simulator_fit`]) that failed: the error.
#[derive(Debug, Clone, PartialEq)]
pub enum SimulatorFitFailure {
    /// The fit itself.
    Fit(String),
    /// Walking the observations it misses ([`simulator_fit_misses`]).
    Misses(String),
}

/// The report's plain answer for its robot and terrain (the model every table and figure
/// uses), from the closed form at the terrain's medians every 0.25 degrees from level to 30
/// degrees (docs/model.md §5-§6) and the two risk limits (§9).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlainAnswer {
    /// The robot's mass, kg.
    pub mass_kg: f64,
    /// The terrain's name: worded by the front end from [`Plots::terrain_name`] (empty as
    /// [`report`] returns it).
    pub terrain: String,
    /// The steepest slope of the grid up to which every slope from level is success, degrees
    /// (`None` when level ground is not).
    pub climbs_up_to_deg: Option<f64>,
    /// The speed on level ground, m/s.
    pub level_speed_m_s: Option<f64>,
    /// The speed at `climbs_up_to_deg`, m/s.
    pub speed_at_limit_m_s: Option<f64>,
    /// The first slope of the grid whose regime is not success, degrees, and that regime.
    pub first_not_success: Option<(f64, crate::regime::Regime)>,
    /// The first slope of the grid whose regime is a failure (sinkage or slippage), degrees,
    /// and that regime.
    pub first_failure: Option<(f64, crate::regime::Regime)>,
    /// The success limit with the terrain's uncertainty (P(not success) < `max_risk`).
    pub success_limit: SafeLimit,
    /// The safe-slope limit with the terrain's uncertainty (p_fail < `max_risk`).
    pub safe_limit: SafeLimit,
    /// The risk threshold of both limits.
    pub max_risk: f64,
    /// The speed at `first_not_success`, m/s (a value of the paragraph, not of the JSON).
    #[serde(skip)]
    pub speed_at_first_not_success_m_s: Option<f64>,
    /// The terrain's angle of repose, degrees (a value of the paragraph, not of the JSON).
    #[serde(skip)]
    pub repose_deg: Option<f64>,
    /// Whether the robot is not the paper's and has no observations of its own: the answer is
    /// the model's, untested.
    #[serde(skip)]
    pub untested: bool,
    /// Whether the answer rests on a calibration that flags itself ([`Report::fit_diagnosis`]).
    #[serde(skip)]
    pub unreliable: bool,
    /// The answer in one paragraph: worded by the front end from these values (empty as
    /// [`report`] returns it).
    pub text: String,
}

fn plain_answer(plots: &Plots, unreliable: bool, untested: bool) -> PlainAnswer {
    let grid = &plots.model;
    let deg = |p: &Prediction| p.slope.degrees();
    let success = |p: &&Prediction| p.regime == crate::regime::Regime::Success;
    let first_not = grid.iter().find(|p| !success(p));
    let first_fail = grid.iter().find(|p| p.regime.is_failure());
    let last_success = match grid.iter().position(|p| !success(&p)) {
        Some(0) => None,
        Some(i) => grid.get(i - 1),
        None => grid.last(),
    };
    let level = grid.first().and_then(|p| p.speed);
    PlainAnswer {
        mass_kg: plots.mass_kg,
        terrain: String::new(),
        climbs_up_to_deg: last_success.map(deg),
        level_speed_m_s: level,
        speed_at_limit_m_s: last_success.and_then(|p| p.speed),
        first_not_success: first_not.map(|p| (deg(p), p.regime)),
        first_failure: first_fail.map(|p| (deg(p), p.regime)),
        success_limit: plots.success_limit,
        safe_limit: plots.safe_limit,
        max_risk: plots.max_risk,
        speed_at_first_not_success_m_s: first_not.and_then(|p| p.speed),
        repose_deg: plots.repose_deg,
        untested,
        unreliable,
        text: String::new(),
    }
}

/// The report's joint calibration: the fit itself (flattened: the keys of `calibrate --json`)
/// and the same fit with the error floor fixed at 0.
#[derive(Debug, Clone, Serialize)]
pub struct ReportCalibration {
    /// The fit with the floor free.
    #[serde(flatten)]
    pub fit: JointCalibration,
    /// The fit without the floor: its chi^2 is the goodness-of-fit test.
    pub no_floor: Option<NoFloorFit>,
    /// Which chi^2 tests the model, in words: worded by the front end from [`Self::no_floor`]
    /// (empty as [`report`] returns it).
    pub goodness_of_fit: String,
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
///
/// One model drives every table and figure: with the user's own observations, the robot and
/// terrain of the joint calibration on them; on the paper's evidence, the robot and terrain as
/// given (the built-in terrain is that calibration).
pub fn report(evidence: &Evidence) -> Result<Report, ParamError> {
    let track_use = TrackUse::new(&evidence.tracks, evidence.observed.is_some())?;
    let mut anchoring: Vec<AnchoringObservation> =
        evidence.anchoring.as_ref().map(|(_, a)| a.clone()).unwrap_or_default();
    anchoring.extend(track_use.anchoring.iter().copied());
    let papers_robot = paper::is_papers_robot(&evidence.robot);
    let other_robot = another_robot_without_observations(evidence);
    let speeds = observed_speeds(evidence, &track_use.speeds, papers_robot);
    let calibration = calibrate(evidence, &speeds, &anchoring);
    let (simulator_fit, simulator_fit_misses, simulator_fit_failures) =
        simulator_fit_section(evidence, &speeds, &anchoring);
    let (robot, terrain) = model(evidence, calibration.as_ref())?;
    let mut plots = plots(evidence, &robot, &terrain, speeds.clone(), anchoring, calibration.as_ref())?;
    // The simulator takes fewer robots than the closed form (at most 64 stance legs, ...) and
    // walks no implausible terrain: either loses this section, with a warning, not the report.
    let at_bound = calibration.as_ref().and_then(|c| scope::terrain_at_bound(&c.fit, evidence));
    let section = scope::simulator_walks(&robot, &terrain, &speeds, at_bound);
    let (simulator, simulator_convergence, simulator_left_out) = match section {
        Ok(walks) => {
            plots.simulated = walks.free;
            plots.simulated_pitch_locked = walks.pitch_locked;
            (walks.records, walks.convergence, None)
        }
        Err(why) => (Vec::new(), Vec::new(), Some(why)),
    };
    let own = evidence.has_own_observations();
    let context = ComparisonContext {
        fitted_to_paper_speeds: !own && evidence.builtin_terrain,
        tuned_to_level_speed: evidence.builtin_robot,
        shear_ratio_input: matches!(evidence.forces, ForceTests::Paper(_)),
        normal_ratio_input: evidence.builtin_terrain || matches!(evidence.forces, ForceTests::Paper(_)),
    };
    let mut paper_vs_model = compare_with_paper(&robot, &terrain, context);
    if !papers_robot {
        paper_vs_model = terrain_rows_only(paper_vs_model);
    }
    let speed_inversion = audit::invert_speeds(&robot, &terrain, &speeds);
    let measured: Vec<f64> = plots.table.iter().map(|p| p.slope_deg).collect();
    let extrapolations: Vec<Extrapolation> =
        audit::extrapolation(&robot, &terrain, &measured, paper::HEAVY_ROBOT_CLAIM).into_iter().collect();
    let mut slopes: Vec<Slope> = speeds.iter().map(|o| o.slope).collect();
    slopes.sort_by(|a, b| a.degrees().total_cmp(&b.degrees()));
    slopes.dedup();
    let step_budget = audit::step_budget(&robot, &terrain, &slopes);
    let speed_records = speeds
        .iter()
        .map(|o| SpeedRecord {
            slope_deg: o.slope.degrees(),
            observed_m_s: o.speed,
            observed_sd_m_s: o.speed_sd,
            model_m_s: predict(&robot, o.slope, &terrain.at(o.slope)).speed,
        })
        .collect();
    let untested = other_robot;
    let observation_misses = if own {
        disagreements::observation_misses(&robot, &terrain, &speeds, &plots.anchoring)
    } else {
        Vec::new()
    };
    let fit_diagnosis = calibration.as_ref().and_then(|c| {
        diagnosis::diagnose(&diagnosis::DiagnosisInput {
            fit: &c.fit,
            speeds: &speeds,
            anchoring: &plots.anchoring,
            tracks: &evidence.tracks,
        })
    });
    Ok(Report {
        plain_answer: plain_answer(&plots, fit_diagnosis.is_some(), untested),
        fit_diagnosis,
        own_observations: own,
        model_is_calibration: own || evidence.builtin_terrain,
        figures: figure_records(&plots, calibration.is_some()),
        speeds: speed_records,
        tracks: evidence.tracks.iter().map(TrackRecord::from).collect(),
        summary: summary(&paper_vs_model),
        calibration,
        paper_vs_model,
        disagreements: Vec::new(),
        observation_misses,
        speed_inversion,
        extrapolations,
        step_budget,
        simulator,
        simulator_convergence,
        simulator_fit,
        simulator_fit_misses,
        inputs: Vec::new(),
        tracks_give_t1: !track_use.anchoring.is_empty(),
        unused_tracks: track_use.unused,
        track_speeds_shown_only: evidence.observed.is_some() && !evidence.tracks.is_empty(),
        simulator_left_out,
        simulator_fit_failures,
        warnings: Vec::new(),
        plots,
    })
}

/// The speeds the report fits and compares: the user's (`--observed`, else the tracks'), else
/// the paper's five, which are of its 0.35 kg robot and so none on another robot.
fn observed_speeds(
    evidence: &Evidence,
    tracks: &[SpeedObservation],
    papers_robot: bool,
) -> Vec<SpeedObservation> {
    match &evidence.observed {
        Some((_, s)) => s.clone(),
        None if !evidence.tracks.is_empty() => tracks.to_vec(),
        None if !papers_robot => Vec::new(),
        None => paper::SPEEDS
            .iter()
            .map(|&(d, v, sd)| SpeedObservation { slope: at(d), speed: v, speed_sd: sd })
            .collect(),
    }
}

/// The simulator's joint fit when the evidence asks for it: the fit, its misses walked with
/// the simulator, and each part that failed (the report keeps the rest).
fn simulator_fit_section(
    evidence: &Evidence,
    speeds: &[SpeedObservation],
    anchoring: &[AnchoringObservation],
) -> (Option<JointCalibration>, Vec<SimulatorMiss>, Vec<SimulatorFitFailure>) {
    let (simulator_fit, simulator_fit_failure) = if evidence.simulator_fit {
        match calibrate_jointly_with(
            &joint_setup(evidence, speeds, anchoring),
            SpeedModel::simulator_for_fit(),
        ) {
            Ok(fit) => (Some(fit), None),
            Err(e) => (None, Some(SimulatorFitFailure::Fit(e.to_string()))),
        }
    } else {
        (None, None)
    };
    let (simulator_fit_misses, misses_failure) = match &simulator_fit {
        None => (Vec::new(), None),
        Some(fit) => match simulator_fit_misses(fit, speeds) {
            Ok(m) => (m, None),
            Err(e) => (Vec::new(), Some(SimulatorFitFailure::Misses(e.to_string()))),
        },
    };
    (simulator_fit, simulator_fit_misses, simulator_fit_failure.into_iter().chain(misses_failure).collect())
}

/// The robot and terrain every table and figure uses (see [`report`]).
fn model(
    evidence: &Evidence,
    calibration: Option<&ReportCalibration>,
) -> Result<(Robot, Terrain), ParamError> {
    match calibration {
        Some(c) if evidence.has_own_observations() => {
            Ok((Robot::new(c.fit.robot.clone())?, Terrain::new(c.fit.terrain.clone())?))
        }
        _ => Ok((evidence.robot.clone(), evidence.terrain.clone())),
    }
}

/// The report's joint calibration problem: the force tests' (or the terrain's) k_s shape on
/// the evidence, `plate_scale` and the model-error floor free (docs/calibration.md).
fn joint_setup(
    evidence: &Evidence,
    speeds: &[SpeedObservation],
    anchoring: &[AnchoringObservation],
) -> JointSetup {
    let shape = evidence.forces.table().unwrap_or(&evidence.terrain).clone();
    JointSetup {
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
    }
}

/// The joint calibration of [`joint_setup`] by the closed form; `None` if it fails.
fn calibrate(
    evidence: &Evidence,
    speeds: &[SpeedObservation],
    anchoring: &[AnchoringObservation],
) -> Option<ReportCalibration> {
    let setup = joint_setup(evidence, speeds, anchoring);
    let no_floor = audit::no_floor_fit(&evidence.robot, &setup.normal, speeds, anchoring);
    let fit = calibrate_jointly(&setup).ok()?;
    Some(ReportCalibration { fit, no_floor, goodness_of_fit: String::new() })
}

/// The figures' data.
fn plots(
    evidence: &Evidence,
    robot: &Robot,
    terrain: &Terrain,
    speeds: Vec<SpeedObservation>,
    anchoring: Vec<AnchoringObservation>,
    calibration: Option<&ReportCalibration>,
) -> Result<Plots, ParamError> {
    let grid = slope_grid();
    let forces = evidence.forces.table();
    // Plate values are drawn on the leg's scale: times the fitted plate_scale.
    let plate_scale = match (forces, calibration) {
        (Some(_), Some(c)) => c.fit.plate_scale(),
        _ => 1.0,
    };
    let k_n_axis = Axis::new("k_n", 1e4, 1e8, 120, AxisScale::Log)?;
    let k_s_axis = Axis::new("k_s", 1e4, 1e9, 120, AxisScale::Log)?;
    let mut phase = Vec::new();
    for (_, mass, slope_deg) in PHASE_PANELS {
        let r = robot.with_mass(mass)?;
        let on = TerrainGrid { terrain, k_n: &k_n_axis, k_s: &k_s_axis };
        phase.push(PhasePanel::compute(&r, SignedSlope::from_degrees(slope_deg)?, on, &|| {}));
    }
    let uncertain = UncertainTerrain::new(terrain.clone(), None, None)?;
    let risk_slopes =
        (0..=60).map(|i| SignedSlope::from_degrees(i as f64 * 0.5)).collect::<Result<Vec<_>, _>>()?;
    let calibrated_speed = match calibration {
        Some(c) => {
            let fitted_robot = Robot::new(c.fit.robot.clone())?;
            let fitted_terrain = Terrain::new(c.fit.terrain.clone())?;
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
            .filter(|t| t.result.summary.steps > 0)
            .map(|t| (t.slope_deg, t.result.clone()))
            .collect(),
        table: forces.unwrap_or(terrain).points().to_vec(),
        table_is_forces: forces.is_some(),
        plate_scale,
        repose_deg: terrain.spec().repose_deg,
        last_point_deg: (terrain.points().len() > 1)
            .then(|| terrain.points().last().map_or(0.0, |p| p.slope_deg)),
        terrain_name: terrain.name().map(str::to_string),
        stance_duration_s: robot.stance_duration(),
        min_step_m: robot.min_step(),
        mass_kg: robot.mass(),
        phase,
        risk: risk_curve(robot, &uncertain, &risk_slopes),
        safe_limit: safe_slope_limit(robot, &uncertain, evidence.max_risk)?,
        success_limit: success_slope_limit(robot, &uncertain, evidence.max_risk)?,
        max_risk: evidence.max_risk,
        calibrated_speed,
        step_budget: audit::step_budget(
            robot,
            terrain,
            &grid.iter().copied().filter(|s| !terrain.at(*s).beyond_repose(*s)).collect::<Vec<_>>(),
        ),
        simulated: Vec::new(),
        simulated_pitch_locked: Vec::new(),
    })
}

/// The figures in page order, the phase diagram's panels listed one by one (their titles are
/// the front end's).
fn figure_records(plots: &Plots, calibrated: bool) -> Vec<FigureRecord> {
    let mut out = vec!["fig3a"];
    if !plots.strides.is_empty() {
        out.push("fig3b");
    }
    out.extend(["fig4d", "fig4h", "fig5b", "fig5c"]);
    out.extend(PHASE_PANELS.iter().map(|(id, ..)| *id));
    out.extend(["risk", "step_budget"]);
    if !plots.simulated.is_empty() {
        out.push("simulator");
    }
    if calibrated {
        out.push("calibration");
    }
    out.into_iter().map(|id| FigureRecord { id: id.into(), title: String::new() }).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::tests::paper_robot;
    use crate::paper::Basis;
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
            builtin_robot: false,
            builtin_terrain: false,
            simulator_fit: false,
        }
    }

    /// The report on [`evidence`], made once for the three tests that read it (a report walks
    /// the simulator's section, seconds of CPU each time).
    fn evidence_report() -> &'static Report {
        static REPORT: std::sync::OnceLock<Report> = std::sync::OnceLock::new();
        REPORT.get_or_init(|| report(&evidence()).unwrap())
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
        result.summary.speed_sd_m_s = speed_sd;
        result.summary.t1_sd_s = t1_sd;
        TrackedSlope { slope_deg, files: vec![format!("{slope_deg}.csv")], result }
    }

    #[test]
    fn default_evidence_compares_the_papers_five_speeds_with_the_model() {
        let r = evidence_report();
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
        // The test terrain's points are at 0 and 20 deg: fig4d/h draw beyond 20 dashed.
        assert_eq!(r.plots.last_point_deg, Some(20.0));
        assert_eq!(r.calibration.is_some(), ids.contains(&"calibration"));
        // The observed speed rises from 20 to 24 deg (4.98 to 5.6 cm/s): the k_s it needs rises
        // (the request layer words it, and tests the words).
        let needed: Vec<Option<f64>> = r.speed_inversion.iter().map(|i| i.k_s_needed).collect();
        assert!(matches!(needed[3..], [Some(a), Some(b)] if b > a), "{needed:?}");
        // A terrain file of the user's: its speed comparisons are independent tests.
        let mut speed_rows = r.paper_vs_model.iter().filter(|c| c.id.starts_with("speed_"));
        assert!(speed_rows.clone().count() == 5 && speed_rows.all(|c| c.basis == Basis::Independent));
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
        // Its one step gives no speed SD; its t1 SD is 0. The front ends word both.
        let gaps: Vec<(f64, TrackGap)> = r.unused_tracks.iter().map(|u| (u.slope_deg, u.gap)).collect();
        assert_eq!(gaps, [(20.0, TrackGap::NoAnchoringSd), (20.0, TrackGap::NoSpeedSd)]);
        assert!(!r.track_speeds_shown_only);
        assert_eq!(r.figures[1].id, "fig3b");
        assert_eq!(r.plots.strides.len(), 2);
    }

    /// The plain answer, checked against `predict` slope by slope: success up to the stated
    /// slope and not just above it, the speeds there, and the regime that follows.
    #[test]
    fn the_plain_answer_is_predicts_regimes_read_off_the_slope_grid() {
        let r = evidence_report();
        let a = &r.plain_answer;
        let t = terrain();
        let at = |d: f64| {
            predict(&paper_robot(), Slope::from_degrees(d).unwrap(), &t.at(Slope::from_degrees(d).unwrap()))
        };
        let top = a.climbs_up_to_deg.unwrap();
        assert!((0..=(top / 0.25).round() as usize)
            .all(|i| at(i as f64 * 0.25).regime == crate::regime::Regime::Success));
        let (next, regime) = a.first_not_success.unwrap();
        assert_eq!(next, top + 0.25);
        assert_eq!(at(next).regime, regime);
        assert_eq!(a.level_speed_m_s, at(0.0).speed);
        assert_eq!(a.speed_at_limit_m_s, at(top).speed);
        assert_eq!(a.speed_at_first_not_success_m_s, at(next).speed);
        // Repose 25 deg: at and beyond it the regime is slippage.
        assert!(a.first_failure.unwrap().0 <= 25.0);
    }

    /// Observations like the example tracks' (a long t1 at 20 deg with a positive speed)
    /// contradict the model whatever k_s is: the page says so with the model's step at that
    /// t1, worked by hand from docs/model.md §5, and the answer says it rests on a bad fit.
    #[test]
    fn a_speed_and_t1_the_model_cannot_both_meet_are_diagnosed_by_slope() {
        let mut e = evidence();
        let obs = |d: f64, v: f64| SpeedObservation { slope: at(d), speed: v, speed_sd: 0.0005 };
        e.observed = Some(("speeds.csv".into(), vec![obs(0.0, 0.157), obs(10.0, 0.11), obs(20.0, 0.0498)]));
        e.anchoring =
            Some(("t1.csv".into(), vec![AnchoringObservation { slope: at(20.0), t1: 0.114, t1_sd: 0.01 }]));
        let r = report(&e).unwrap();
        let d = r.fit_diagnosis.as_ref().expect("the fit flags itself");
        assert_eq!(d.contradictions.len(), 1, "{:?}", d.contradictions);
        let c = &d.contradictions[0];
        assert_eq!(c.slope_deg, 20.0);
        // s* from the calibrated terrain's k_n (the test terrain's 7e5 is not refitted).
        let fitted = Terrain::new(r.calibration.as_ref().unwrap().fit.terrain.clone()).unwrap();
        let level = predict(&paper_robot(), at(20.0), &fitted.at(at(20.0))).level_step;
        let by_hand =
            level * (0.386f64 / 0.5).powi(2) - 0.5 * 9.81 * 20f64.to_radians().sin() * 0.114 * 0.886;
        assert!((c.model_step_m - by_hand).abs() < 1e-9, "{} vs {by_hand}", c.model_step_m);
        assert!((c.observed_step_m - 0.0249).abs() < 1e-12);
        // The front end words the paragraph and the remedies (request/report_text/diagnosis.rs).
        assert!(d.text.is_empty() && d.remedies.is_empty());
        assert!((d.stance_duration_s - 0.5).abs() < 1e-12);
        assert!(r.plain_answer.unreliable);
        assert_eq!(r.plots.terrain_name, None);
    }

    /// The paper's own evidence on its terrain: nothing to diagnose when the fit does not flag
    /// itself, and the answer carries no such sentence.
    #[test]
    fn a_fit_without_warnings_has_no_diagnosis() {
        let r = evidence_report();
        let flagged = r.calibration.as_ref().is_some_and(|c| {
            c.fit.warnings.iter().any(|w| {
                matches!(
                    w,
                    crate::calibrate::CalibrationWarning::PoorFit { .. }
                        | crate::calibrate::CalibrationWarning::ParameterAtBound { .. }
                )
            })
        });
        assert_eq!(r.fit_diagnosis.is_some(), flagged);
        assert_eq!(r.plain_answer.unreliable, flagged);
    }

    /// A 0.5 kg robot without observations (a heavier one's report walks the same, in twice the
    /// CPU: 1.2 kg sinks deep on the steep slopes): nothing about the paper's 0.35 kg robot is fitted
    /// or compared, a warning says so first, and only the terrain's ratios stand. On the test
    /// terrain by hand: k_s(20)/k_s(0) = 8e5 / 2e6 = 0.40, within 0.10 of the paper's 0.40;
    /// k_n(20)/k_n(0) = 7e5 / 7e5 = 1, within 0.15 of 1: two independent numbers, both agree.
    /// With observed speeds of its own, those are compared with the model instead.
    #[test]
    fn another_robot_is_not_compared_with_the_papers_speeds() {
        let mut e = evidence();
        e.robot = paper_robot().with_mass(0.5).unwrap();
        e.robot_source = "mine.toml".into();
        assert!(paper::is_papers_robot(&paper_robot()) && !paper::is_papers_robot(&e.robot));
        let r = report(&e).unwrap();
        // The front end words its warning first (request/report_text/warnings.rs).
        assert!(r.plain_answer.untested);
        assert!(r.speeds.is_empty() && r.calibration.is_none());
        assert!(r.plain_answer.untested);
        let ids: Vec<&str> = r.paper_vs_model.iter().map(|c| c.id.as_str()).collect();
        assert_eq!(ids, paper::TERRAIN_ROWS);
        assert!(r
            .paper_vs_model
            .iter()
            .all(|c| c.agrees && !matches!(c.reading, paper::Reading::Speed { .. })));
        // The front end labels them as the terrain's (request/report_text/labels.rs).
        assert!((r.paper_vs_model[0].model_value.unwrap() - 0.4).abs() < 1e-12);
        assert_eq!((r.summary.independent, r.summary.independent_agree), (2, 2));

        let obs = |d: f64, v: f64| SpeedObservation { slope: at(d), speed: v, speed_sd: 0.01 };
        e.observed = Some(("mine.csv".into(), vec![obs(0.0, 0.12), obs(10.0, 0.08), obs(20.0, 0.04)]));
        let r = report(&e).unwrap();
        assert!(!r.plain_answer.untested);
        let observed: Vec<f64> = r.speeds.iter().map(|s| s.observed_m_s).collect();
        assert_eq!(observed, [0.12, 0.08, 0.04]);
        assert!(r.speeds.iter().all(|s| s.model_m_s.is_some()));
        assert_eq!(r.paper_vs_model.len(), 2);
    }

    /// One outlier speed (5 m/s at 10 degrees, 30 times the model's ceiling of about 16 cm/s)
    /// runs the fit's plate_scale to its bound: the simulator section, whose walks on that
    /// stiff terrain took 115 s of CPU, is left out with a warning that says why.
    #[test]
    fn an_outlier_speed_does_not_walk_an_implausible_terrain() {
        let mut e = evidence();
        let obs = |d: f64, v: f64, sd: f64| SpeedObservation { slope: at(d), speed: v, speed_sd: sd };
        e.observed = Some((
            "outlier.csv".into(),
            vec![
                obs(0.0, 0.157, 0.0097),
                obs(10.0, 5.0, 0.0014),
                obs(15.0, 0.105, 0.0023),
                obs(20.0, 0.0498, 0.0032),
            ],
        ));
        let start = std::time::Instant::now();
        let r = report(&e).unwrap();
        let fit = &r.calibration.as_ref().unwrap().fit;
        assert!(
            scope::terrain_at_bound(fit, &e).is_some_and(|(name, _)| name == "plate_scale"),
            "{:?}",
            fit.warnings
        );
        assert!(r.simulator.is_empty() && r.plots.simulated.is_empty());
        assert!(
            matches!(&r.simulator_left_out, Some(SimulatorLeftOut::AtBound { name, .. }) if name == "plate_scale"),
            "{:?}",
            r.simulator_left_out
        );
        assert!(start.elapsed().as_secs() < 60, "{:?}", start.elapsed());
    }

    #[test]
    fn a_risk_threshold_outside_0_1_is_an_error() {
        let mut e = evidence();
        e.max_risk = 1.5;
        assert!(report(&e).is_err());
    }
}
