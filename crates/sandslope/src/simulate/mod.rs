//! A dynamic stride simulator on granular slopes (docs/model.md §15-§18): the closed form's
//! test bench.
//!
//! A planar rigid body (x along the slope, z normal to it, pitch) walks on C-legs in the
//! alternating tripod, driven by position servos with an optional torque limit; the sand
//! pushes on every leg element by resistive force theory scaled to the same terrain file as
//! the closed form ([`rft`]), so the two differ only by the closed form's assumptions. The
//! integrator is a fixed-step, linearly implicit Euler step ([`dynamics`]). [`simulate`] runs
//! one walk and measures it exactly as `track` measures a recording (docs/model.md §11):
//! speed, per-step anchoring time, slip and step, and the regime read from the motion, beside
//! the closed form's answer for the same inputs. [`simulate_slopes`] runs several slopes in
//! parallel.

pub mod body;
pub mod convergence;
pub mod dynamics;
pub mod ensemble;
mod linear;
pub mod mechanisms;
pub mod phase1;
pub mod rft;
pub mod spread;

use rayon::prelude::*;
use serde::Serialize;

pub use crate::leg::LegShape;
pub use body::BodyPitch;
pub use convergence::{check_convergence, check_convergence_slopes, check_walked, ConvergenceCheck};
use dynamics::Walker;
pub use ensemble::{simulate_ensemble, Ensemble};
pub use mechanisms::Mechanisms;
pub use phase1::PhaseOne;
pub use rft::RftScaling;
pub use spread::{scaling_spread, ScalingSpread, SCALINGS};

use crate::error::ParamError;
use crate::gait::{SmoothTrack, StepMeasure, REST_SPEED_FRACTION};
use crate::regime::{classify, Cause, Regime};
use crate::scenario::{Scenario, SlopeEvaluation};
use crate::slope::{SignedSlope, Slope};

/// Default creep speed of the set-valued resistive-force law's smoothing, m/s (docs/model.md
/// §17): an element loaded below its resistive-force limit creeps at most this fast. A tenth of
/// it moves no converged answer (a test on the built-in robot and terrain).
pub const DEFAULT_CREEP_M_S: f64 = 1e-7;
/// Smallest and largest creep speed a walk takes, m/s.
pub const CREEP_RANGE_M_S: (f64, f64) = (1e-9, 1e-3);
/// Default output sample rate, Hz (the paper's motion capture).
pub const DEFAULT_SAMPLE_RATE_HZ: f64 = 120.0;
/// Pitch beyond which the body has pitched over (tumbled), rad: 90 degrees, the body standing
/// on its end (docs/model.md §18).
pub const PITCH_OVER_RAD: f64 = std::f64::consts::FRAC_PI_2;
/// Default settling time before the gait starts, s (gravity ramps in over it).
pub const DEFAULT_SETTLE_S: f64 = 0.5;
/// Longest walk, s.
pub const MAX_DURATION_S: f64 = 3600.0;
/// Most integration steps one walk may take.
pub const MAX_STEPS: f64 = 2e7;
/// Steps (one tripod stance each) left out of the means while the gait settles in.
pub const WARMUP_STEPS: usize = 2;
/// Longest run-up of the legs, s ([`SimSettings::with_ramp_up`]).
pub const MAX_RAMP_UP_S: f64 = 10.0;

/// How to run a walk. Build with [`SimSettings::new`] and the `with_` methods.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SimSettings {
    /// Simulated time after settling, s.
    pub duration_s: f64,
    /// Integration step, s; `None`: chosen from the stiffness and the gait (docs/model.md §17).
    pub dt_s: Option<f64>,
    /// Trajectory sample rate, Hz.
    pub sample_rate_hz: f64,
    /// Creep speed of the smoothed set-valued contact law, m/s (docs/model.md §17).
    pub creep_m_s: f64,
    /// Whether the robot file's servo torque limit applies (default: yes, where it gives one).
    pub servo_limit: bool,
    /// Settling time before the gait starts (gravity ramps in), s.
    pub settle_s: f64,
    /// Hold every leg at this angle (rad, tripod B half a turn on) instead of walking.
    pub locked_leg_angle: Option<f64>,
    /// Whether the body may pitch (default: free).
    pub body_pitch: BodyPitch,
    /// How resistive force theory is scaled to the terrain (default: by the direction of motion).
    pub rft_scaling: RftScaling,
    /// The candidate mechanisms of docs/model.md §20, all off by default.
    pub mechanisms: Mechanisms,
    /// The legs' run-up, s: the constant-speed gait reaches omega at constant acceleration
    /// over this time, as `sandslope drive` commands a robot (docs/model.md §19:
    /// `omega t^2 / (2 r)`, then `omega (t - r / 2)`, every touchdown `r / 2` later). Default
    /// 0: full speed from t = 0 (§15); the servo sensor's walks take the robot's response time.
    /// Serialised only when set, so that every answer without it reads as before.
    #[serde(skip_serializing_if = "no_ramp_up")]
    pub ramp_up_s: f64,
}

fn no_ramp_up(ramp_up_s: &f64) -> bool {
    *ramp_up_s == 0.0
}

impl SimSettings {
    /// A walk of `duration_s` seconds with the defaults; fails (key `duration_s`) unless
    /// `0 < duration_s <= 3600`.
    pub fn new(duration_s: f64) -> Result<SimSettings, ParamError> {
        if !(duration_s.is_finite() && duration_s > 0.0 && duration_s <= MAX_DURATION_S) {
            return Err(ParamError::new(
                "duration_s",
                duration_s,
                format!("a number of seconds greater than 0 and at most {MAX_DURATION_S}"),
            ));
        }
        Ok(SimSettings {
            duration_s,
            dt_s: None,
            sample_rate_hz: DEFAULT_SAMPLE_RATE_HZ,
            creep_m_s: DEFAULT_CREEP_M_S,
            servo_limit: true,
            settle_s: DEFAULT_SETTLE_S,
            locked_leg_angle: None,
            body_pitch: BodyPitch::default(),
            rft_scaling: RftScaling::Motion,
            mechanisms: Mechanisms::default(),
            ramp_up_s: 0.0,
        })
    }

    /// The legs' run-up, s (0 to [`MAX_RAMP_UP_S`]; [`SimSettings::ramp_up_s`]).
    pub fn with_ramp_up(self, ramp_up_s: f64) -> Result<SimSettings, ParamError> {
        if !(ramp_up_s.is_finite() && (0.0..=MAX_RAMP_UP_S).contains(&ramp_up_s)) {
            return Err(ParamError::new("ramp_up_s", ramp_up_s, format!("between 0 and {MAX_RAMP_UP_S} s")));
        }
        Ok(SimSettings { ramp_up_s, ..self })
    }

    /// Switches on the mechanisms of docs/model.md §20 (checked: errors name the switch).
    pub fn with_mechanisms(self, mechanisms: Mechanisms) -> Result<SimSettings, ParamError> {
        Ok(SimSettings { mechanisms: mechanisms.checked()?, ..self })
    }

    /// A fixed integration step, s (checked against the stiffness by [`simulate`]).
    pub fn with_dt(self, dt_s: f64) -> Result<SimSettings, ParamError> {
        Ok(SimSettings { dt_s: Some(crate::error::positive("dt_s", dt_s)?), ..self })
    }

    /// The trajectory sample rate, Hz (1 to 100000).
    pub fn with_sample_rate(self, hz: f64) -> Result<SimSettings, ParamError> {
        if !(hz.is_finite() && (1.0..=1e5).contains(&hz)) {
            return Err(ParamError::new("sample_rate_hz", hz, "between 1 and 100000 Hz"));
        }
        Ok(SimSettings { sample_rate_hz: hz, ..self })
    }

    /// The creep speed of the contact law's smoothing, m/s (1e-9 to 1e-3; docs/model.md §17).
    pub fn with_creep(self, creep_m_s: f64) -> Result<SimSettings, ParamError> {
        let (lo, hi) = CREEP_RANGE_M_S;
        if !(creep_m_s.is_finite() && (lo..=hi).contains(&creep_m_s)) {
            return Err(ParamError::new("creep_m_s", creep_m_s, format!("between {lo:e} and {hi:e} m/s")));
        }
        Ok(SimSettings { creep_m_s, ..self })
    }

    /// Applies the robot file's servo torque limit (`true`, the default) or drives the legs
    /// as ideal position servos whatever the file says (`false`).
    pub fn with_servo_limit(self, servo_limit: bool) -> SimSettings {
        SimSettings { servo_limit, ..self }
    }

    /// The settling time, s (0 to 60).
    pub fn with_settle(self, settle_s: f64) -> Result<SimSettings, ParamError> {
        if !(settle_s.is_finite() && (0.0..=60.0).contains(&settle_s)) {
            return Err(ParamError::new("settle_s", settle_s, "between 0 and 60 s"));
        }
        Ok(SimSettings { settle_s, ..self })
    }

    /// Lets the body pitch, or holds its pitch at zero as the closed form assumes.
    pub fn with_body_pitch(self, body_pitch: BodyPitch) -> SimSettings {
        SimSettings { body_pitch, ..self }
    }

    /// Another scaling of resistive force theory to the terrain (docs/model.md §16).
    pub fn with_rft_scaling(self, rft_scaling: RftScaling) -> SimSettings {
        SimSettings { rft_scaling, ..self }
    }

    /// Legs held at `angle` rad (tripod B at `angle + pi`) instead of walking.
    pub fn with_locked_legs(self, angle: f64) -> SimSettings {
        SimSettings { locked_leg_angle: Some(angle), ..self }
    }
}

/// Why a walk ended in its regime: one of the closed form's causes (docs/model.md §6) read
/// from the motion, or one the closed form cannot have (a stalled servo, a pitch-over).
/// Serialised as its snake_case name, the closed form's causes by [`Cause::name`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotionCause {
    /// A cause of docs/model.md §6, read from the motion: a leg deeper than `2R - h` is
    /// [`Cause::NormalSinkage`], no step anchored (the speed never turned from falling to
    /// rising) and no progress is [`Cause::NoAnchoring`], and the step causes come from the
    /// measured steps' mean.
    Model(Cause),
    /// A servo stalled (its torque limit bound) and the walk did not succeed.
    ServoStall,
    /// The body pitched past 90 degrees: the robot tumbled (docs/model.md §18). The closed
    /// form has no pitch, so it has no such failure.
    PitchOver,
    /// The mean speed is within the speed's resolution ([`convergence::SPEED_TOLERANCE_M_S`])
    /// of zero, the regimes' border `s = 0`: the robot stalls, counted in slippage (§6 puts
    /// `s = 0` there) whichever side of zero the walk's number fell (docs/model.md §18).
    NoNetProgress,
}

impl MotionCause {
    /// The snake_case name used in JSON.
    pub fn name(self) -> &'static str {
        match self {
            MotionCause::Model(cause) => cause.name(),
            MotionCause::ServoStall => "servo_stall",
            MotionCause::PitchOver => "pitch_over",
            MotionCause::NoNetProgress => "no_net_progress",
        }
    }
}

impl Serialize for MotionCause {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// One step: one tripod's stance of T/2 from its touchdown, measured as docs/model.md §11
/// (the gait's one step type, [`StepMeasure`], as `track` measures a recording) with what the
/// simulation knows besides.
///
/// Serialised flat, its fields in the order `simulate --json` and `--csv` have always listed
/// them: `index`, `tripod`, `touchdown_s`, `warmup`, then the rest of the step's (`t1_s`,
/// `slip_m`, `step_m`, `speed_m_s`) and this type's own (`serde(flatten)` would move
/// `touchdown_s`, and the CSV writer cannot write a flattened struct).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimStep {
    /// Step number from 0.
    pub index: usize,
    /// Tripod in stance (0 or 1).
    pub tripod: usize,
    /// Whether the step is left out of the means (the first stride).
    pub warmup: bool,
    /// The step as `track` measures it: touchdown (s after the gait started), anchoring time,
    /// backward slip, net step and step speed.
    pub step: StepMeasure,
    /// Deepest any leg went below the surface, m.
    pub max_depth_m: f64,
    /// Largest sand force on one leg, N.
    pub peak_leg_force_n: f64,
    /// Largest servo torque on one leg, N m.
    pub peak_servo_torque_n_m: f64,
    /// Time servos spent stalled, summed over legs, s.
    pub stall_s: f64,
    /// Largest lag of a leg behind its commanded angle, rad (0 for ideal servos; with the
    /// servo actuator, docs/model.md §20.6, the motor's shortfall).
    pub peak_lag_rad: f64,
    /// Phase 1 (touchdown to t1): the lowest speed and what held the body (issue 59).
    pub phase1: PhaseOne,
}

impl Serialize for SimStep {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let m = &self.step;
        let mut st = s.serialize_struct("SimStep", 20)?;
        st.serialize_field("index", &self.index)?;
        st.serialize_field("tripod", &self.tripod)?;
        st.serialize_field("touchdown_s", &m.touchdown_s)?;
        st.serialize_field("warmup", &self.warmup)?;
        // StepMeasure's own names (a test checks they match its serialisation).
        st.serialize_field("t1_s", &m.anchoring_time_s)?;
        st.serialize_field("slip_m", &m.slip_m)?;
        st.serialize_field("step_m", &m.step_m)?;
        st.serialize_field("speed_m_s", &m.speed_m_s)?;
        st.serialize_field("max_depth_m", &self.max_depth_m)?;
        st.serialize_field("peak_leg_force_n", &self.peak_leg_force_n)?;
        st.serialize_field("peak_servo_torque_n_m", &self.peak_servo_torque_n_m)?;
        st.serialize_field("stall_s", &self.stall_s)?;
        st.serialize_field("peak_lag_rad", &self.peak_lag_rad)?;
        let p = &self.phase1;
        st.serialize_field("phase1_min_speed_m_s", &p.min_speed_m_s)?;
        st.serialize_field("phase1_belly_x_n", &p.belly_n[0])?;
        st.serialize_field("phase1_belly_z_n", &p.belly_n[1])?;
        st.serialize_field("phase1_old_tripod_x_n", &p.old_tripod_n[0])?;
        st.serialize_field("phase1_old_tripod_z_n", &p.old_tripod_n[1])?;
        st.serialize_field("phase1_new_tripod_x_n", &p.new_tripod_n[0])?;
        st.serialize_field("phase1_new_tripod_z_n", &p.new_tripod_n[1])?;
        st.end()
    }
}

/// The body and legs over time, sampled at the settings' rate (one column per quantity).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Trajectory {
    /// Time since the gait started, s.
    pub time_s: Vec<f64>,
    /// Centre of mass along the slope (upslope positive), m.
    pub x_m: Vec<f64>,
    /// Axle line height above the undisturbed surface, normal to it, m.
    pub z_m: Vec<f64>,
    /// Pitch, rad (nose up positive).
    pub pitch_rad: Vec<f64>,
    /// Velocity along the slope, m/s.
    pub vx_m_s: Vec<f64>,
    /// Velocity normal to the slope, m/s.
    pub vz_m_s: Vec<f64>,
    /// Each leg's angle, rad (0: the C's circle centre straight ahead of the axle).
    pub leg_angle_rad: Vec<Vec<f64>>,
    /// Each leg's depth below the surface (deepest point, 0 when out), m.
    pub leg_depth_m: Vec<Vec<f64>>,
    /// Each leg's sand force, along the slope, N.
    pub leg_force_x_n: Vec<Vec<f64>>,
    /// Each leg's sand force, normal to the slope, N.
    pub leg_force_z_n: Vec<Vec<f64>>,
    /// Each leg's servo torque, N m.
    pub leg_torque_n_m: Vec<Vec<f64>>,
}

/// The hip positions and tripods of the legs, for drawing.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Geometry {
    /// Hip x in the body frame, m, one per leg.
    pub hip_x_m: Vec<f64>,
    /// Tripod of each leg (0 or 1).
    pub tripod: Vec<usize>,
    /// Leg outline in its own frame (angle 0), m: the element nodes.
    pub leg_nodes_m: Vec<[f64; 2]>,
    /// Body length, m.
    pub body_length_m: f64,
    /// Hip height h (axle to belly), m.
    pub hip_height_m: f64,
}

/// What a walk did, as `simulate --json` prints it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SimSummary {
    /// Slope, degrees (negative: descending).
    pub slope_deg: f64,
    /// Normal penetration resistance used, N/m^3.
    pub k_n: f64,
    /// Shear strength used, N/m^3.
    pub k_s: f64,
    /// Simulated time after settling, s.
    pub duration_s: f64,
    /// Integration step used, s.
    pub dt_s: f64,
    /// Elements per leg.
    pub leg_elements: u32,
    /// Leg shape ([`crate::leg::Leg::name`]: `c_leg`, `spoke`, `foot`, or a caller's own).
    pub shape: String,
    /// Creep speed of the contact law's smoothing, m/s.
    pub creep_m_s: f64,
    /// The servo torque limit applied, N m (`None`: ideal position servos).
    pub servo_torque_limit_n_m: Option<f64>,
    /// Time steps whose implicit velocity solve stopped before converging (0 in a sound walk).
    pub unconverged_steps: usize,
    /// Whether the body could pitch (`locked`: held parallel to the slope).
    pub body_pitch: BodyPitch,
    /// How resistive force theory was scaled to the terrain.
    pub rft_scaling: RftScaling,
    /// The mechanisms of docs/model.md §20 the walk had switched on.
    pub mechanisms: Mechanisms,
    /// Mean step speed over the measured steps, m/s.
    pub speed_m_s: f64,
    /// Mean anchoring time over the measured steps that anchored, s.
    pub t1_s: Option<f64>,
    /// Mean backward slip over the measured steps that anchored, m.
    pub slip_m: Option<f64>,
    /// Phase 1 (touchdown to t1, docs/model.md §11) averaged over the measured steps that
    /// anchored: the lowest speed and the sand's forces on the belly and the two tripods.
    /// Its t1 and slip are `t1_s` and `slip_m`; the closed form's are in `closed_form`.
    pub phase1: Option<PhaseOne>,
    /// Mean net step over the measured steps, m.
    pub step_m: f64,
    /// Standard deviation of the step speed across measured steps, m/s.
    pub speed_sd_m_s: f64,
    /// Measured steps (after the first stride).
    pub steps_measured: usize,
    /// Measured steps without anchoring.
    pub unanchored_steps: usize,
    /// Deepest any leg went in a measured step, m.
    pub max_depth_m: f64,
    /// The leg reach `2R - h`, m: deeper means the body sank.
    pub d_max_m: f64,
    /// Largest |pitch| over the walk, degrees.
    pub max_pitch_deg: f64,
    /// When the body first pitched past 90 degrees (it tumbled), s after the gait started;
    /// `None` if it never did. Steps from then on still count in the means, which then
    /// describe a tumbling body, not a walk.
    pub pitch_over_s: Option<f64>,
    /// Regime read from the motion (docs/model.md §18).
    pub regime: Regime,
    /// Why.
    pub cause: MotionCause,
    /// Legs whose servo stalled in a measured step (indices).
    pub stalled_legs: Vec<usize>,
    /// Every step, warm-up included.
    pub steps: Vec<SimStep>,
    /// What `predict --json` gives for the same robot, terrain and slope.
    pub closed_form: SlopeEvaluation,
}

/// A walk: its summary and its trajectory.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Simulation {
    /// The measured walk.
    pub summary: SimSummary,
    /// Body and legs over time.
    pub trajectory: Trajectory,
    /// The robot's legs, for drawing.
    pub geometry: Geometry,
}

/// Why a walk could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimulateError {
    /// A parameter is out of range.
    #[error(transparent)]
    Param(#[from] ParamError),
}

/// The default time step as a fraction of the stride period T (docs/model.md §17), pitch
/// locked.
pub const DEFAULT_STEPS_PER_STRIDE: f64 = 2000.0;
/// The default time step of a walk with the body free to pitch, as a fraction of T
/// (docs/model.md §17): an eighth of the locked walk's. At T / 2000 the free body's landing on
/// its belly at the end of each step comes milliseconds early, and at 15 degrees its speed
/// moves by 4% at a quarter of the step; at T / 8000 a third of its level steps still coast
/// into touchdown on the belly, which at a quarter of that step they do not, so its level t1
/// (2.0 against 0.0 ms) had not converged (docs/simulate.md, "The free body's step").
pub const DEFAULT_STEPS_PER_STRIDE_FREE: f64 = 16000.0;
/// The coarsest time step a walk takes, as a fraction of T.
pub const MIN_STEPS_PER_STRIDE: f64 = 100.0;

/// The time step for `scenario`: the given one, checked, or the default `T / 2000`
/// (docs/model.md §17). The contact sets no stability limit (the step is passive for any
/// length); the limit `T / 100` is one of accuracy, a leg turning 3.6 degrees per step.
pub fn integration_step(scenario: &Scenario, slope: Slope, given: Option<f64>) -> Result<f64, ParamError> {
    step_for(scenario, slope, given, BodyPitch::Locked)
}

/// The time step of a walk with `settings`: its own, checked, or the default for its body
/// pitch (`T / 2000` locked, `T / 16000` free; docs/model.md §17).
pub fn integration_step_for(
    scenario: &Scenario,
    slope: Slope,
    settings: &SimSettings,
) -> Result<f64, ParamError> {
    step_for(scenario, slope, settings.dt_s, settings.body_pitch)
}

fn step_for(
    scenario: &Scenario,
    _slope: Slope,
    given: Option<f64>,
    pitch: BodyPitch,
) -> Result<f64, ParamError> {
    let period = scenario.robot().stride_period();
    let limit = period / MIN_STEPS_PER_STRIDE;
    match given {
        None if pitch == BodyPitch::Free => Ok(period / DEFAULT_STEPS_PER_STRIDE_FREE),
        None => Ok(period / DEFAULT_STEPS_PER_STRIDE),
        Some(dt) if dt.is_finite() && dt > 0.0 && dt <= limit => Ok(dt),
        Some(dt) => Err(ParamError::new(
            "dt_s",
            dt,
            format!("greater than 0 and at most T / {MIN_STEPS_PER_STRIDE} = {limit:.3e} s for this robot's stride"),
        )),
    }
}

/// The step of a C-leg that rolls on rigid ground, m (docs/simulate.md, "On level sand the
/// legs roll"): per stance of half a turn the leg rolls on its arc from touchdown until its tip
/// points straight down (the C's circle centre moves `R (pi/2 - phi0)`, the hip `R cos(phi0)`
/// more, from behind the centre to above it), then pivots on its tip until the belly lands
/// (the hip moves `2R sqrt(1 - (h / 2R)^2)`), with `phi0 = asin((h - R)/R)`. The limit the
/// simulated step tends to on stiff level sand; the closed form's s* is the step of a leg that
/// slides along its own fixed circle instead.
pub fn rigid_rolling_step(robot: &crate::robot::Robot) -> f64 {
    let (r, h) = (robot.leg_radius(), robot.hip_height());
    let phi0 = robot.touchdown_angle();
    let rolling = r * (std::f64::consts::FRAC_PI_2 - phi0) + r * phi0.cos();
    let pivot = 2.0 * r * (1.0 - (h / (2.0 * r)).powi(2)).max(0.0).sqrt();
    rolling + pivot
}

/// Most legs per tripod the simulator takes (a 128-legged robot).
pub const MAX_STANCE_LEGS: u32 = 64;

/// Simulates `scenario`'s robot walking on its terrain at `signed` (negative walks downhill;
/// the terrain is read at |slope| as docs/model.md §8) for `settings.duration_s` seconds, and
/// measures the walk (docs/model.md §15-§18), its legs the robot's ([`crate::Robot::leg`], of
/// the robot file's `leg_shape`).
pub fn simulate(
    scenario: &Scenario,
    signed: SignedSlope,
    settings: &SimSettings,
) -> Result<Simulation, SimulateError> {
    simulate_with_leg(scenario, signed, settings, &scenario.robot().leg())
}

/// [`simulate`] with every leg of shape `leg` (its outline, docs/model.md §15) in place of
/// the robot's: a new leg shape is one type implementing [`crate::leg::Leg`], which the
/// closed form and the simulator then both take.
pub fn simulate_with_leg(
    scenario: &Scenario,
    signed: SignedSlope,
    settings: &SimSettings,
    leg: &dyn crate::leg::Leg,
) -> Result<Simulation, SimulateError> {
    let slope = signed.felt();
    let slope_deg = signed.degrees();
    let closed_form = scenario.evaluate(signed);
    let robot = scenario.robot();
    // Decided before the legs are made: 2 n legs of `leg_elements` elements each (a robot file
    // with stance_legs = 1e9 asked for 8 GB and aborted; found by scripts/fuzz.sh).
    if robot.stance_legs() > MAX_STANCE_LEGS {
        return Err(ParamError::new(
            "stance_legs",
            f64::from(robot.stance_legs()),
            format!("at most {MAX_STANCE_LEGS} for the simulator (it simulates 2 n legs)"),
        )
        .into());
    }
    let (ground, _) = scenario.ground_at(slope);
    let dt = integration_step_for(scenario, slope, settings)?;
    settings.mechanisms.checked()?;
    if settings.ramp_up_s != 0.0 && settings.mechanisms.duty_cycle != mechanisms::CONSTANT_SPEED_DUTY {
        return Err(ParamError::new(
            "ramp_up_s",
            settings.ramp_up_s,
            "0 with a duty cycle other than 0.5 (the run-up is the constant-speed gait's)",
        )
        .into());
    }
    let half = robot.stance_duration();
    if settings.locked_leg_angle.is_none() && settings.duration_s < 3.0 * half {
        return Err(ParamError::new(
            "duration_s",
            settings.duration_s,
            format!(
                "at least 1.5 T = {} s (one stride to settle into the gait, then one step to measure)",
                3.0 * half
            ),
        )
        .into());
    }
    let n_steps = (settings.duration_s / dt).round();
    if n_steps + settings.settle_s / dt > MAX_STEPS {
        return Err(ParamError::new(
            "duration_s",
            settings.duration_s,
            format!("at most {MAX_STEPS:e} integration steps of {dt:.3e} s (settling included)"),
        )
        .into());
    }
    let n_steps = n_steps as usize;
    let theta = slope_deg.to_radians();
    let mut walker = Walker::with_leg(robot, &ground, theta, settings, dt, leg);
    walker.settle(settings.settle_s);
    let run = walker.run(n_steps, half, settings.sample_rate_hz);

    // Measure each step exactly as `track` does (docs/model.md §11) on the full-rate track.
    let track = SmoothTrack {
        start_time_s: 0.0,
        frame_rate_hz: 1.0 / dt,
        position: run.x,
        speed: run.vx,
        speed_noise_m_s: SPEED_RISE_M_S / 3.0,
        // 1 um/s, or the creep speed if more (docs/model.md §18): a resting body creeps.
        rest_speed_m_s: (REST_SPEED_FRACTION * (SPEED_RISE_M_S / 3.0))
            .max(REST_CREEP_FRACTION * settings.creep_m_s),
    };
    let duration = n_steps as f64 * dt;
    // The steps start at the touchdowns, `r / 2` late after a run-up of `r`.
    let delay = 0.5 * settings.ramp_up_s;
    let n_meas = ((duration - delay + 1e-9) / half).floor() as usize;
    let mut steps = Vec::with_capacity(n_meas);
    for k in 0..n_meas {
        let t0 = delay + k as f64 * half;
        if !track.covers(t0, half) {
            break;
        }
        let acc = run.per_step.get(k).copied().unwrap_or_default();
        let (step, phase1) = phase1::measure(&track, &run.groups, t0, half, k % 2, slope_deg == 0.0);
        steps.push(SimStep {
            index: k,
            tripod: k % 2,
            warmup: k < WARMUP_STEPS,
            step,
            max_depth_m: acc.max_depth,
            peak_leg_force_n: acc.peak_force,
            peak_servo_torque_n_m: acc.peak_torque,
            stall_s: acc.stall_s,
            peak_lag_rad: acc.peak_lag,
            phase1,
        });
    }
    let pitch = Pitch { max_abs_rad: run.max_abs_pitch, over_s: run.pitch_over_s };
    let summary = summarise(
        scenario,
        slope,
        &ground,
        settings,
        leg,
        dt,
        steps,
        closed_form,
        &run.stalled_by_step,
        pitch,
        run.unconverged_steps,
    );
    Ok(Simulation { summary, trajectory: run.trajectory, geometry: run.geometry })
}

/// A speed minimum counts as the anchoring time only if the speed then rises by more than
/// this, m/s (docs/model.md §18; the simulated speed has no noise, but resistive-force
/// elements entering the sand leave sub-millimetre-per-second ripples).
pub const SPEED_RISE_M_S: f64 = 3e-4;

/// A simulated walk is at rest within this fraction of the creep speed of zero, where that is
/// more than a motion-capture track's rest (docs/model.md §18). Below the creep speed an
/// element feels less than 1/sqrt(2) of the law's stress (the smoothing of §17,
/// `phi(1) = 1/sqrt(2)`): it is in the law's smoothed rest, not moving under the law, and a
/// body held there creeps (on level sand with the creep 1e-4 m/s at up to 0.6 of it before
/// the legs push). At the default creep the 1 um/s of [`REST_SPEED_FRACTION`] is the larger.
pub const REST_CREEP_FRACTION: f64 = 1.0;

/// How far the body pitched over a walk.
#[derive(Debug, Clone, Copy)]
struct Pitch {
    max_abs_rad: f64,
    over_s: Option<f64>,
}

/// The cause read from the motion, by docs/model.md §18's precedence: at or above repose, then
/// a pitch-over, then a stalled servo when the walk did not succeed, then §6's causes.
fn motion_cause(cause: Cause, pitched_over: bool, stalled: bool) -> MotionCause {
    if cause == Cause::AtOrAboveRepose {
        MotionCause::Model(cause)
    } else if pitched_over {
        MotionCause::PitchOver
    } else if stalled && cause.regime() != Regime::Success {
        MotionCause::ServoStall
    } else {
        MotionCause::Model(cause)
    }
}

/// The step's cause with the border `s = 0` as wide as the speed's resolution (docs/model.md
/// §18): a short step whose mean speed is within [`convergence::SPEED_TOLERANCE_M_S`] of zero
/// cannot be told from `s = 0`, which §6 counts as slippage (backward slip cancels
/// propulsion), so it is [`Cause::NetBackwardStep`]; every other cause stands.
pub(crate) fn stall_band(cause: Cause, speed_m_s: f64) -> Cause {
    if cause == Cause::ShortStep && speed_m_s <= convergence::SPEED_TOLERANCE_M_S {
        Cause::NetBackwardStep
    } else {
        cause
    }
}

#[allow(clippy::too_many_arguments)]
fn summarise(
    scenario: &Scenario,
    slope: Slope,
    ground: &crate::terrain::Ground,
    settings: &SimSettings,
    leg: &dyn crate::leg::Leg,
    dt: f64,
    steps: Vec<SimStep>,
    closed_form: SlopeEvaluation,
    stalled_by_step: &[Vec<usize>],
    pitch: Pitch,
    unconverged_steps: usize,
) -> SimSummary {
    let robot = scenario.robot();
    let measured: Vec<&SimStep> = steps.iter().filter(|s| !s.warmup).collect();
    let n = measured.len().max(1) as f64;
    let speed = measured.iter().map(|s| s.step.speed_m_s).sum::<f64>() / n;
    let speed_sd = if measured.len() > 1 {
        (measured.iter().map(|s| (s.step.speed_m_s - speed).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    } else {
        0.0
    };
    let step = measured.iter().map(|s| s.step.step_m).sum::<f64>() / n;
    let anchored: Vec<&StepMeasure> =
        measured.iter().map(|s| &s.step).filter(|s| s.anchoring_time_s.is_some()).collect();
    let mean_of = |f: &dyn Fn(&StepMeasure) -> f64| {
        (!anchored.is_empty()).then(|| anchored.iter().map(|s| f(s)).sum::<f64>() / anchored.len() as f64)
    };
    let t1 = mean_of(&|s| s.anchoring_time_s.unwrap_or(0.0));
    let slip = mean_of(&|s| s.slip_m.unwrap_or(0.0));
    let phase1 =
        phase1::mean(measured.iter().filter(|s| s.step.anchoring_time_s.is_some()).map(|s| &s.phase1));
    let max_depth = measured.iter().map(|s| s.max_depth_m).fold(0.0, f64::max);
    // Sinkage: in most measured steps a leg went deeper than its reach from the rest height
    // (the walked leg's own reach, docs/model.md §3: a C-leg's 2R - h).
    let d_max = leg.max_depth();
    let sunk_steps = measured.iter().filter(|s| s.max_depth_m > d_max * (1.0 + 1e-3)).count();
    let sunk = 2 * sunk_steps > measured.len();
    let step_for_regime = if anchored.is_empty() && step <= 0.0 { None } else { Some(step) };
    let cause =
        stall_band(classify(sunk, ground.beyond_repose(slope), step_for_regime, robot.min_step()), speed);
    let mut stalled_legs: Vec<usize> =
        measured.iter().filter_map(|s| stalled_by_step.get(s.index)).flatten().copied().collect();
    stalled_legs.sort_unstable();
    stalled_legs.dedup();
    let motion_cause = match motion_cause(cause, pitch.over_s.is_some(), !stalled_legs.is_empty()) {
        MotionCause::Model(Cause::NetBackwardStep) if speed.abs() <= convergence::SPEED_TOLERANCE_M_S => {
            MotionCause::NoNetProgress
        }
        m => m,
    };
    // A body that pitched over failed whatever its steps measure: the closed form's regimes
    // have no tumble, so it is counted with the failures that lose ground (slippage).
    let regime = if motion_cause == MotionCause::PitchOver { Regime::Slippage } else { cause.regime() };
    SimSummary {
        slope_deg: closed_form.slope_deg,
        k_n: ground.k_n,
        k_s: ground.k_s,
        duration_s: settings.duration_s,
        dt_s: dt,
        leg_elements: robot.leg_elements(),
        shape: leg.name().to_string(),
        creep_m_s: settings.creep_m_s,
        servo_torque_limit_n_m: if settings.servo_limit { robot.servo_torque_limit() } else { None },
        unconverged_steps,
        body_pitch: settings.body_pitch,
        rft_scaling: settings.rft_scaling,
        mechanisms: settings.mechanisms,
        speed_m_s: speed,
        t1_s: t1,
        slip_m: slip,
        phase1,
        step_m: step,
        speed_sd_m_s: speed_sd,
        steps_measured: measured.len(),
        unanchored_steps: measured.len() - anchored.len(),
        max_depth_m: max_depth,
        d_max_m: d_max,
        max_pitch_deg: pitch.max_abs_rad.to_degrees(),
        pitch_over_s: pitch.over_s,
        regime,
        cause: motion_cause,
        stalled_legs,
        steps,
        closed_form,
    }
}

/// Simulates every one of `slopes` in parallel (rayon), in order.
pub fn simulate_slopes(
    scenario: &Scenario,
    slopes: &[SignedSlope],
    settings: &SimSettings,
) -> Result<Vec<Simulation>, SimulateError> {
    slopes.par_iter().map(|&s| simulate(scenario, s, settings)).collect()
}

#[cfg(test)]
mod phase1_tests;
#[cfg(test)]
mod slide_tests;
#[cfg(test)]
mod stride_probe;
#[cfg(test)]
mod t1_tests;
#[cfg(test)]
mod tests;
