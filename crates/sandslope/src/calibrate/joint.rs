//! Joint calibration (docs/model.md §14, docs/calibration.md): the unmeasured quantities that
//! make the model agree with several kinds of evidence at once.
//!
//! Evidence: observed step-averaged speeds, observed anchoring times t1 and force-test
//! measurements of the plate shear strength k_s(theta) (a terrain table with `k_s_sd`). Free
//! quantities: any continuous robot key (`hip_height_m`, `level_step_m`, ...), the plate-to-leg
//! scale `c` in `k_s_leg = c k_s_plate` (`plate_scale`), and a model-error floor added in
//! quadrature to every observed speed SD (`error_floor`). Without force tests, k_s(theta)
//! follows a smooth law instead ([`ShearLaw::Linear`] as `k_s0 (1 + (rho - 1) theta / 20 deg)`,
//! so that `rho = k_s(20)/k_s(0)` is itself a parameter, or [`ShearLaw::Coulomb`]).
//!
//! The fit maximises the Gaussian likelihood: it minimises
//! `-2 ln L = sum pull_i^2 + sum_speeds ln(1 + f^2 / sd_i^2)` (+ const), where
//! `pull = (observed - model) / sqrt(sd^2 + f^2)` for speeds, `(observed - model) / sd` for
//! anchoring times and force tests, and f is the error floor; the second sum is what stops a
//! free floor from growing without limit, and it is zero when f = 0. The minimisation is
//! Levenberg-Marquardt on transformed parameters (a logistic map onto each parameter's bounds, in
//! log space for scale parameters), started from several points. Each 68% interval is the
//! profile-likelihood interval `{value : min over the others of -2 ln L <= minimum + 1}`,
//! found by walking out from the best value and bracketing the crossing with Brent's method.
//! `k_s(20)/k_s(0)` is profiled the same way with the ratio held by a stiff penalty term.
//!
//! Where a trial value makes the leg fail to anchor, the speed and t1 are continued at the
//! anchoring limit (`d_s = d_max`), so the objective stays continuous.

use std::fmt;

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{storage::Owned, DMatrix, DVector, Dyn};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::{continued_speed, shear_strength_for_speed, ShearLaw, SpeedObservation};
use crate::model::{anchoring_time, level_step_length, normal_equilibrium_depth, shear_equilibrium_depth};
use crate::paper;
use crate::robot::{Robot, RobotSpec};
use crate::slope::Slope;
use crate::terrain::{Terrain, TerrainPoint, TerrainSpec};

/// One observed anchoring time with its standard deviation (as `sandslope track` measures it)
/// at a slope, for the joint calibration. `infer`'s per-walk mean with its standard error is
/// [`crate::infer::MeanAnchoringTime`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnchoringObservation {
    /// Slope of the trials.
    pub slope: Slope,
    /// Mean anchoring time t1 after touchdown, s.
    pub t1: f64,
    /// Its standard deviation across steps or trials, s (> 0).
    pub t1_sd: f64,
}

/// A continuous robot key that a calibration may free (docs/model.md §2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RobotKey {
    /// `mass_kg`.
    MassKg,
    /// `leg_radius_m`.
    LegRadiusM,
    /// `leg_width_m`.
    LegWidthM,
    /// `hip_height_m`.
    HipHeightM,
    /// `leg_speed_rad_s`.
    LegSpeedRadS,
    /// `response_time_s`.
    ResponseTimeS,
    /// `leg_contact_area_m2`.
    LegContactAreaM2,
    /// `level_step_m`.
    LevelStepM,
}

impl RobotKey {
    /// Every key, in file order.
    pub const ALL: [RobotKey; 8] = [
        RobotKey::MassKg,
        RobotKey::LegRadiusM,
        RobotKey::LegWidthM,
        RobotKey::HipHeightM,
        RobotKey::LegSpeedRadS,
        RobotKey::ResponseTimeS,
        RobotKey::LegContactAreaM2,
        RobotKey::LevelStepM,
    ];

    /// The file key.
    pub fn name(self) -> &'static str {
        match self {
            RobotKey::MassKg => "mass_kg",
            RobotKey::LegRadiusM => "leg_radius_m",
            RobotKey::LegWidthM => "leg_width_m",
            RobotKey::HipHeightM => "hip_height_m",
            RobotKey::LegSpeedRadS => "leg_speed_rad_s",
            RobotKey::ResponseTimeS => "response_time_s",
            RobotKey::LegContactAreaM2 => "leg_contact_area_m2",
            RobotKey::LevelStepM => "level_step_m",
        }
    }

    fn unit(self) -> &'static str {
        match self {
            RobotKey::MassKg => "kg",
            RobotKey::LegSpeedRadS => "rad/s",
            RobotKey::ResponseTimeS => "s",
            RobotKey::LegContactAreaM2 => "m^2",
            _ => "m",
        }
    }

    /// Default search bounds around a robot.
    fn default_bounds(self, spec: &RobotSpec) -> (f64, f64) {
        let r = spec.leg_radius_m;
        match self {
            RobotKey::MassKg => (0.01, 100.0),
            RobotKey::LegRadiusM => (0.005, 0.5),
            RobotKey::LegWidthM => (0.001, 0.2),
            RobotKey::HipHeightM => (0.0, 2.0 * r),
            RobotKey::LegSpeedRadS => (0.1, 100.0),
            RobotKey::ResponseTimeS => (0.01, 2.0),
            RobotKey::LegContactAreaM2 => (1e-6, 1e-2),
            RobotKey::LevelStepM => (1e-3, 2.0 * r),
        }
    }

    /// Scale parameters are searched in log space.
    fn is_scale(self) -> bool {
        !matches!(self, RobotKey::HipHeightM)
    }

    fn get(self, robot: &Robot, k_n_level: f64) -> f64 {
        match self {
            RobotKey::MassKg => robot.mass(),
            RobotKey::LegRadiusM => robot.leg_radius(),
            RobotKey::LegWidthM => robot.leg_width(),
            RobotKey::HipHeightM => robot.hip_height(),
            RobotKey::LegSpeedRadS => robot.leg_speed(),
            RobotKey::ResponseTimeS => robot.response_time(),
            RobotKey::LegContactAreaM2 => robot.contact_area(),
            RobotKey::LevelStepM => {
                level_step_length(robot, normal_equilibrium_depth(robot, Slope::LEVEL, k_n_level))
            }
        }
    }

    fn set(self, spec: &mut RobotSpec, v: f64) {
        match self {
            RobotKey::MassKg => spec.mass_kg = v,
            RobotKey::LegRadiusM => spec.leg_radius_m = v,
            RobotKey::LegWidthM => spec.leg_width_m = v,
            RobotKey::HipHeightM => spec.hip_height_m = v,
            RobotKey::LegSpeedRadS => spec.leg_speed_rad_s = v,
            RobotKey::ResponseTimeS => spec.response_time_s = v,
            RobotKey::LegContactAreaM2 => spec.leg_contact_area_m2 = Some(v),
            RobotKey::LevelStepM => spec.level_step_m = Some(v),
        }
    }
}

/// A quantity a calibration may free.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Parameter {
    /// A robot key.
    Robot(RobotKey),
    /// The plate-to-leg scale `c` in `k_s_leg = c k_s_plate` (needs force tests).
    PlateScale,
    /// The model-error floor added in quadrature to every observed speed SD, m/s.
    ErrorFloor,
}

impl Parameter {
    /// Parses a name as written on the command line: a robot key, `plate_scale` or
    /// `error_floor`.
    pub fn parse(name: &str) -> Option<Parameter> {
        match name {
            "plate_scale" => Some(Parameter::PlateScale),
            "error_floor" => Some(Parameter::ErrorFloor),
            _ => RobotKey::ALL.into_iter().find(|k| k.name() == name).map(Parameter::Robot),
        }
    }

    /// Every name [`Parameter::parse`] accepts, comma-separated (for error messages).
    pub fn names() -> String {
        let mut v: Vec<&str> = RobotKey::ALL.iter().map(|k| k.name()).collect();
        v.extend(["plate_scale", "error_floor"]);
        v.join(", ")
    }

    /// The name as written on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Parameter::Robot(k) => k.name(),
            Parameter::PlateScale => "plate_scale",
            Parameter::ErrorFloor => "error_floor",
        }
    }
}

/// A freed quantity with optional search bounds `(min, max)` (defaults per quantity otherwise).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FreeParameter {
    /// Which quantity.
    pub parameter: Parameter,
    /// Search bounds, or the default ones.
    pub bounds: Option<(f64, f64)>,
}

/// Where k_s(theta) comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum ShearShape {
    /// Force tests: the plate k_s at each measured slope is a fitted value held to the
    /// measurement by its SD (`k_s_sd`; without SDs the measured values are used exactly), and
    /// the leg's k_s is `plate_scale` times it, interpolated as a terrain table (docs/model.md §7).
    ForceTests(Terrain),
    /// A smooth law of two parameters ([`ShearLaw::Linear`] or [`ShearLaw::Coulomb`]).
    Law(ShearLaw),
}

/// Everything a joint calibration needs.
#[derive(Debug, Clone)]
pub struct JointSetup {
    /// The robot; its freed keys are starting values.
    pub robot: Robot,
    /// Where k_n(theta) comes from (the force tests themselves, or an assumed terrain).
    pub normal: Terrain,
    /// Where k_s(theta) comes from.
    pub shear: ShearShape,
    /// Observed speeds.
    pub speeds: Vec<SpeedObservation>,
    /// Observed anchoring times.
    pub anchoring: Vec<AnchoringObservation>,
    /// The freed quantities.
    pub free: Vec<FreeParameter>,
    /// The error floor when it is not freed, m/s (>= 0).
    pub error_floor: f64,
}

/// Why a joint calibration could not be done.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum JointError {
    /// No speeds and no anchoring times.
    #[error("nothing to calibrate against: give observed speeds or anchoring times")]
    NoObservations,
    /// More free parameters than observations.
    #[error("{parameters} free parameters but only {observations} observations: free fewer")]
    TooFewObservations {
        /// Observations (speeds, anchoring times and force tests with SDs).
        observations: usize,
        /// Free parameters.
        parameters: usize,
    },
    /// An observation that cannot be used.
    #[error("{what} at {slope_deg} deg: {reason}")]
    BadObservation {
        /// `speed` or `anchoring time`.
        what: &'static str,
        /// Slope, degrees.
        slope_deg: f64,
        /// What is wrong.
        reason: String,
    },
    /// Two observations of one kind at one slope.
    #[error("two {what} observations at {slope_deg} deg: pool them into one mean and SD first")]
    DuplicateSlope {
        /// `speed` or `anchoring time`.
        what: &'static str,
        /// Slope, degrees.
        slope_deg: f64,
    },
    /// Bounds that are not an interval, or that exclude the starting value.
    #[error("bounds of {name}: {reason}")]
    BadBounds {
        /// The parameter.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// A parameter freed twice.
    #[error("{name} is freed twice")]
    DuplicateParameter {
        /// The parameter.
        name: String,
    },
    /// `plate_scale` without force tests.
    #[error("plate_scale needs force tests (a terrain with k_s per slope) to scale")]
    PlateScaleWithoutForces,
    /// A law that is not smooth.
    #[error(
        "the joint calibration fits a smooth law (linear or coulomb) or force tests, not per-slope values"
    )]
    UnsupportedLaw,
    /// A negative or non-finite fixed error floor.
    #[error("error floor = {0} must be a finite number >= 0 m/s")]
    BadErrorFloor(f64),
}

/// A value with its 68% profile-likelihood interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Interval {
    /// Best value.
    pub value: f64,
    /// Lower end of the 68% interval (the search bound when `lower_open`).
    pub lower: f64,
    /// Upper end of the 68% interval (the search bound when `upper_open`).
    pub upper: f64,
    /// The likelihood stays within 1 of its minimum down to the lower search bound.
    pub lower_open: bool,
    /// The likelihood stays within 1 of its minimum up to the upper search bound.
    pub upper_open: bool,
}

/// One fitted quantity.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FittedParameter {
    /// Name (`hip_height_m`, `plate_scale`, `error_floor`, `k_s_plate(20 deg)`, `k_s0`, ...).
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Best value and 68% interval.
    #[serde(flatten)]
    pub estimate: Interval,
    /// Search bounds `[min, max]`.
    pub bounds: [f64; 2],
    /// The best value sits at a search bound (within 0.1% of the range).
    pub at_bound: bool,
}

/// The kind of an observation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ObservationKind {
    /// A step-averaged speed, m/s.
    Speed,
    /// An anchoring time, s.
    AnchoringTime,
    /// A force-test plate shear strength, N/m^3.
    PlateShearStrength,
}

/// The model against one observation at the best fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Pull {
    /// What was observed.
    pub kind: ObservationKind,
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Observed value.
    pub observed: f64,
    /// Observed SD as given.
    pub sd: f64,
    /// SD used in the fit (with the error floor for speeds).
    pub sd_total: f64,
    /// Model value at the best fit.
    pub model: f64,
    /// `(observed - model) / sd_total`.
    pub pull: f64,
}

/// The calibrated shear strength at one slope.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ShearAtSlope {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Normal resistance used, N/m^3.
    pub k_n: f64,
    /// Shear strength on the robot's legs, N/m^3.
    pub k_s: f64,
    /// The plate shear strength fitted to the force tests (force-test calibrations only), N/m^3.
    pub k_s_plate: Option<f64>,
    /// The force this leg k_s would give on the paper's shear plate (3 cm wide, 2 cm deep,
    /// `F = k_s W_p d_p^2`), N: compare with what the sand gives in a force test.
    pub plate_force_n: f64,
    /// The model's speed ceiling here, `s*/(T/2)` (instant anchoring), m/s.
    pub speed_ceiling_m_s: f64,
}

/// Something a user should know about a calibration.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum CalibrationWarning {
    /// An observed speed is within one SD of the model's ceiling `s*/(T/2)`: the k_s there is
    /// barely constrained (any large value fits), so ratios that divide by it are weak.
    SpeedNearCeiling {
        /// Slope, degrees.
        slope_deg: f64,
        /// Observed speed, m/s.
        observed_m_s: f64,
        /// Its SD (with the error floor), m/s.
        sd_m_s: f64,
        /// The model's ceiling, m/s.
        ceiling_m_s: f64,
    },
    /// A fitted value sits at its search bound.
    ParameterAtBound {
        /// The parameter.
        name: String,
        /// Its value.
        value: f64,
        /// The bound it sits at.
        bound: f64,
    },
    /// `chi^2/dof > 3`: the model does not fit the evidence within its stated SDs.
    PoorFit {
        /// chi^2 / dof.
        chi_squared_per_dof: f64,
    },
}

impl fmt::Display for CalibrationWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CalibrationWarning::SpeedNearCeiling { slope_deg, observed_m_s, sd_m_s, ceiling_m_s }
                if observed_m_s > ceiling_m_s =>
            {
                write!(
                    f,
                    "the speed at {slope_deg} deg ({:.2} ± {:.2} cm/s) is above the model's ceiling s*/(T/2) = {:.2} cm/s: \
                     no k_s reaches it, and the k_s there is pushed to its largest values",
                    observed_m_s * 100.0,
                    sd_m_s * 100.0,
                    ceiling_m_s * 100.0
                )
            }
            CalibrationWarning::SpeedNearCeiling { slope_deg, observed_m_s, sd_m_s, ceiling_m_s } => write!(
                f,
                "the speed at {slope_deg} deg ({:.2} ± {:.2} cm/s) is within one SD of the model's ceiling \
                 s*/(T/2) = {:.2} cm/s: k_s there is barely constrained, and so is any ratio to it",
                observed_m_s * 100.0,
                sd_m_s * 100.0,
                ceiling_m_s * 100.0
            ),
            CalibrationWarning::ParameterAtBound { name, value, bound } => {
                write!(f, "{name} = {value:.4e} sits at its search bound {bound:.4e}: widen the bound or fix it")
            }
            CalibrationWarning::PoorFit { chi_squared_per_dof } => write!(
                f,
                "chi^2/dof = {chi_squared_per_dof:.2} > 3: the model does not fit this evidence within its stated SDs \
                 (freeing error_floor shows how much model error that takes)"),
        }
    }
}

/// The result of a joint calibration: plain values, ready to serialise.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JointCalibration {
    /// Every fitted quantity with its 68% profile-likelihood interval.
    pub parameters: Vec<FittedParameter>,
    /// `sum pull^2` over all observations.
    pub chi_squared: f64,
    /// Observations minus fitted quantities.
    pub dof: i64,
    /// `chi^2 / dof` (`None` when dof <= 0).
    pub chi_squared_per_dof: Option<f64>,
    /// The error floor used, m/s (fitted or fixed).
    pub error_floor_m_s: f64,
    /// One entry per observation: speeds, then anchoring times, then force tests, by slope.
    pub pulls: Vec<Pull>,
    /// `k_s(20 deg) / k_s(0)` with its 68% interval (the paper's force tests: about 0.40).
    pub shear_ratio_20: Interval,
    /// The calibrated k_s at each slope of the written terrain.
    pub shear: Vec<ShearAtSlope>,
    /// The robot with the fitted keys.
    pub robot: RobotSpec,
    /// The calibrated terrain (the angle of repose carried over from the source terrain).
    pub terrain: TerrainSpec,
    /// What to be careful about.
    pub warnings: Vec<CalibrationWarning>,
}

// ---------------------------------------------------------------------------------------------
// The problem in numbers.

#[derive(Debug, Clone, Copy, PartialEq)]
enum Slot {
    Robot(RobotKey),
    PlateScale,
    ErrorFloor,
    Knot(usize),
    LawLevel,
    LawRatio,
    LawFriction,
}

#[derive(Debug, Clone)]
struct Def {
    slot: Slot,
    name: String,
    unit: &'static str,
    lo: f64,
    hi: f64,
    log: bool,
    start: f64,
}

impl Def {
    fn g(&self, p: f64) -> f64 {
        if self.log {
            p.ln()
        } else {
            p
        }
    }
    fn g_inv(&self, q: f64) -> f64 {
        if self.log {
            q.exp()
        } else {
            q
        }
    }
    /// Physical value from the unbounded coordinate.
    fn value_at(&self, u: f64) -> f64 {
        let t = 1.0 / (1.0 + (-u).exp());
        let (a, b) = (self.g(self.lo), self.g(self.hi));
        self.g_inv(a + t * (b - a)).clamp(self.lo, self.hi)
    }
    /// Unbounded coordinate of a physical value (clamped just inside the bounds).
    fn coordinate_of(&self, p: f64) -> f64 {
        let (a, b) = (self.g(self.lo), self.g(self.hi));
        let t = ((self.g(p) - a) / (b - a)).clamp(1e-9, 1.0 - 1e-9);
        (t / (1.0 - t)).ln()
    }
}

/// One force-test knot: slope, measured plate k_s and its SD (if any).
#[derive(Debug, Clone, Copy)]
struct Knot {
    slope_deg: f64,
    k_s: f64,
    sd: Option<f64>,
}

struct Problem<'a> {
    setup: &'a JointSetup,
    defs: Vec<Def>,
    knots: Vec<Knot>,
    /// For each knot, the index of its def (None: fixed at the measurement).
    knot_def: Vec<Option<usize>>,
    law: Option<ShearLaw>,
    plate_scale: f64,
    n_obs: usize,
}

/// A trial point, resolved.
struct Trial {
    robot: Option<Robot>,
    floor: f64,
    knots: Vec<(f64, f64)>,
    scale: f64,
    law: [f64; 2],
}

/// Linear interpolation in degrees with the terrain table's rule (docs/model.md §7).
fn interpolate(points: &[(f64, f64)], deg: f64) -> f64 {
    let n = points.len();
    if n == 1 || deg <= points[0].0 {
        return points[0].1;
    }
    let i = if deg > points[n - 1].0 { n - 1 } else { points.partition_point(|p| p.0 < deg).max(1) };
    let (a, b) = (points[i - 1], points[i]);
    (a.1 + (deg - a.0) / (b.0 - a.0) * (b.1 - a.1)).max(0.0)
}

fn law_k_s(law: ShearLaw, params: [f64; 2], deg: f64) -> f64 {
    match law {
        ShearLaw::Coulomb => {
            let t = deg.to_radians();
            (params[0] * (t.cos() - t.sin() / params[1].to_radians().tan())).max(0.0)
        }
        _ => (params[0] * (1.0 + (params[1] - 1.0) * deg / 20.0)).max(0.0),
    }
}

impl Problem<'_> {
    fn trial(&self, x: &[f64]) -> Trial {
        let mut spec = self.setup.robot.spec().clone();
        let mut t = Trial {
            robot: None,
            floor: self.setup.error_floor,
            knots: self.knots.iter().map(|k| (k.slope_deg, k.k_s)).collect(),
            scale: self.plate_scale,
            law: [0.0, 1.0],
        };
        for (d, &v) in self.defs.iter().zip(x) {
            match d.slot {
                Slot::Robot(k) => k.set(&mut spec, v),
                Slot::PlateScale => t.scale = v,
                Slot::ErrorFloor => t.floor = v,
                Slot::Knot(i) => t.knots[i].1 = v,
                Slot::LawLevel => t.law[0] = v,
                Slot::LawRatio | Slot::LawFriction => t.law[1] = v,
            }
        }
        t.robot = Robot::new(spec).ok();
        t
    }

    fn k_s(&self, t: &Trial, deg: f64) -> f64 {
        match self.law {
            Some(law) => law_k_s(law, t.law, deg),
            None => t.scale * interpolate(&t.knots, deg),
        }
    }

    fn k_n(&self, slope: Slope) -> f64 {
        self.setup.normal.at(slope).k_n
    }

    fn level_step(&self, robot: &Robot, slope: Slope) -> f64 {
        level_step_length(robot, normal_equilibrium_depth(robot, slope, self.k_n(slope)))
    }

    fn model_speed(&self, t: &Trial, robot: &Robot, slope: Slope) -> f64 {
        continued_speed(robot, slope, self.level_step(robot, slope), self.k_s(t, slope.degrees()))
    }

    fn model_t1(&self, t: &Trial, robot: &Robot, slope: Slope) -> f64 {
        let k_s = self.k_s(t, slope.degrees());
        let d_s = if k_s > 0.0 { shear_equilibrium_depth(robot, slope, k_s) } else { f64::INFINITY };
        anchoring_time(robot, d_s.min(robot.max_depth())).unwrap_or(robot.stance_duration())
    }

    /// Pulls of every observation (speeds, anchoring times, force tests) at `x`.
    fn pulls(&self, x: &[f64]) -> Option<(Vec<Pull>, f64)> {
        let t = self.trial(x);
        let robot = t.robot.as_ref()?;
        let mut out = Vec::with_capacity(self.n_obs);
        for o in &self.setup.speeds {
            let sd_total = o.speed_sd.hypot(t.floor);
            let model = self.model_speed(&t, robot, o.slope);
            out.push(Pull {
                kind: ObservationKind::Speed,
                slope_deg: o.slope.degrees(),
                observed: o.speed,
                sd: o.speed_sd,
                sd_total,
                model,
                pull: (o.speed - model) / sd_total,
            });
        }
        for o in &self.setup.anchoring {
            let model = self.model_t1(&t, robot, o.slope);
            out.push(Pull {
                kind: ObservationKind::AnchoringTime,
                slope_deg: o.slope.degrees(),
                observed: o.t1,
                sd: o.t1_sd,
                sd_total: o.t1_sd,
                model,
                pull: (o.t1 - model) / o.t1_sd,
            });
        }
        for (k, fitted) in self.knots.iter().zip(&t.knots) {
            if let Some(sd) = k.sd.filter(|&s| s > 0.0) {
                out.push(Pull {
                    kind: ObservationKind::PlateShearStrength,
                    slope_deg: k.slope_deg,
                    observed: k.k_s,
                    sd,
                    sd_total: sd,
                    model: fitted.1,
                    pull: (k.k_s - fitted.1) / sd,
                });
            }
        }
        let log_det: f64 =
            self.setup.speeds.iter().map(|o| (1.0 + (t.floor / o.speed_sd).powi(2)).ln()).sum();
        Some((out, log_det))
    }

    /// Residual vector whose sum of squares is `-2 ln L` (+ const).
    fn residuals(&self, x: &[f64]) -> Vec<f64> {
        match self.pulls(x) {
            Some((pulls, log_det)) => {
                let mut r: Vec<f64> = pulls.iter().map(|p| p.pull).collect();
                r.push(log_det.max(0.0).sqrt());
                r
            }
            // An invalid robot (say h > 2R with both free): a large, flat penalty.
            None => vec![1e3; self.n_obs + 1],
        }
    }

    fn objective(&self, x: &[f64]) -> f64 {
        self.residuals(x).iter().map(|r| r * r).sum()
    }

    /// k_s(20)/k_s(0) at `x`.
    fn ratio(&self, x: &[f64]) -> f64 {
        let t = self.trial(x);
        let level = self.k_s(&t, 0.0);
        if level > 0.0 {
            self.k_s(&t, 20.0) / level
        } else {
            f64::NAN
        }
    }
}

/// The least-squares problem handed to Levenberg-Marquardt: the free coordinates `u` of the
/// defs not held fixed, plus an optional penalty holding a derived quantity at a target.
struct Fit<'a, 'b> {
    problem: &'a Problem<'b>,
    /// Physical values of every def; the free ones are overwritten from `u`.
    base: Vec<f64>,
    free: Vec<usize>,
    u: DVector<f64>,
    penalty: Option<(f64, f64)>, // (target ln ratio, tolerance)
}

impl Fit<'_, '_> {
    fn x_at(&self, u: &DVector<f64>) -> Vec<f64> {
        let mut x = self.base.clone();
        for (k, &i) in self.free.iter().enumerate() {
            x[i] = self.problem.defs[i].value_at(u[k]);
        }
        x
    }

    fn residuals_at(&self, u: &DVector<f64>) -> DVector<f64> {
        let x = self.x_at(u);
        let mut r = self.problem.residuals(&x);
        if let Some((target, tol)) = self.penalty {
            let g = self.problem.ratio(&x).ln();
            r.push(if g.is_finite() { (g - target) / tol } else { 1e3 });
        }
        while r.len() < self.free.len() {
            r.push(0.0);
        }
        DVector::from_vec(r)
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Fit<'_, '_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, u: &DVector<f64>) {
        self.u.copy_from(u);
    }
    fn params(&self) -> DVector<f64> {
        self.u.clone()
    }
    fn residuals(&self) -> Option<DVector<f64>> {
        Some(self.residuals_at(&self.u))
    }
    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let base = self.residuals_at(&self.u);
        let mut j = DMatrix::zeros(base.len(), self.free.len());
        for c in 0..self.free.len() {
            let h = 1e-6 * self.u[c].abs().max(1.0);
            let (mut up, mut down) = (self.u.clone(), self.u.clone());
            up[c] += h;
            down[c] -= h;
            let col = (self.residuals_at(&up) - self.residuals_at(&down)) / (2.0 * h);
            j.set_column(c, &col);
        }
        Some(j)
    }
}

/// Minimises over the defs not in `fixed` (physical values), from `start`; returns the
/// physical point and its objective (without the penalty).
fn minimise(
    problem: &Problem,
    start: &[f64],
    fixed: &[usize],
    penalty: Option<(f64, f64)>,
) -> (Vec<f64>, f64) {
    let free: Vec<usize> = (0..problem.defs.len()).filter(|i| !fixed.contains(i)).collect();
    if free.is_empty() {
        return (start.to_vec(), problem.objective(start));
    }
    let u = DVector::from_iterator(free.len(), free.iter().map(|&i| problem.defs[i].coordinate_of(start[i])));
    let fit = Fit { problem, base: start.to_vec(), free, u, penalty };
    let (fit, _) = LevenbergMarquardt::new().with_patience(100).with_xtol(1e-12).minimize(fit);
    let x = fit.x_at(&fit.u);
    let s = problem.objective(&x);
    // Keep the start when the optimiser wandered off to something worse.
    let s0 = problem.objective(start);
    if penalty.is_none() && s0 < s {
        (start.to_vec(), s0)
    } else {
        (x, s)
    }
}

// ---------------------------------------------------------------------------------------------
// Setting up.

fn check_observations(setup: &JointSetup) -> Result<(), JointError> {
    let mut speeds: Vec<f64> = Vec::new();
    for o in &setup.speeds {
        let slope_deg = o.slope.degrees();
        let bad = |reason: String| JointError::BadObservation { what: "speed", slope_deg, reason };
        if !o.speed.is_finite() {
            return Err(bad(format!("speed_m_s = {} must be a finite number", o.speed)));
        }
        if !(o.speed_sd.is_finite() && o.speed_sd > 0.0) {
            return Err(bad(format!("speed_sd_m_s = {} must be greater than 0", o.speed_sd)));
        }
        if speeds.contains(&slope_deg) {
            return Err(JointError::DuplicateSlope { what: "speed", slope_deg });
        }
        speeds.push(slope_deg);
    }
    let mut t1s: Vec<f64> = Vec::new();
    for o in &setup.anchoring {
        let slope_deg = o.slope.degrees();
        let bad = |reason: String| JointError::BadObservation { what: "anchoring time", slope_deg, reason };
        if !(o.t1.is_finite() && o.t1 >= 0.0) {
            return Err(bad(format!("t1_s = {} must be a finite number >= 0", o.t1)));
        }
        if !(o.t1_sd.is_finite() && o.t1_sd > 0.0) {
            return Err(bad(format!("t1_sd_s = {} must be greater than 0", o.t1_sd)));
        }
        if t1s.contains(&slope_deg) {
            return Err(JointError::DuplicateSlope { what: "anchoring time", slope_deg });
        }
        t1s.push(slope_deg);
    }
    if setup.speeds.is_empty() && setup.anchoring.is_empty() {
        return Err(JointError::NoObservations);
    }
    if !(setup.error_floor.is_finite() && setup.error_floor >= 0.0) {
        return Err(JointError::BadErrorFloor(setup.error_floor));
    }
    Ok(())
}

/// The k_s each observed speed alone implies (where the model can reach it).
fn inverted_k_s(setup: &JointSetup) -> Vec<(f64, f64)> {
    setup
        .speeds
        .iter()
        .filter_map(|o| {
            let k_n = setup.normal.at(o.slope).k_n;
            shear_strength_for_speed(&setup.robot, o.slope, k_n, o.speed).ok().map(|k| (o.slope.degrees(), k))
        })
        .collect()
}

fn build(setup: &JointSetup) -> Result<Problem<'_>, JointError> {
    check_observations(setup)?;
    let spec = setup.robot.spec();
    let k_n_level = setup.normal.at(Slope::LEVEL).k_n;
    let mut defs = Vec::new();
    let mut seen = Vec::new();
    let mut plate_scale_free = None;
    for f in &setup.free {
        if seen.contains(&f.parameter) {
            return Err(JointError::DuplicateParameter { name: f.parameter.name().into() });
        }
        seen.push(f.parameter);
        let name = f.parameter.name().to_string();
        let (slot, unit, default, log, start) = match f.parameter {
            Parameter::Robot(k) => (
                Slot::Robot(k),
                k.unit(),
                k.default_bounds(spec),
                k.is_scale(),
                k.get(&setup.robot, k_n_level),
            ),
            Parameter::PlateScale => {
                if !matches!(setup.shear, ShearShape::ForceTests(_)) {
                    return Err(JointError::PlateScaleWithoutForces);
                }
                (Slot::PlateScale, "", (1e-3, 1e4), true, 1.0)
            }
            Parameter::ErrorFloor => {
                // Start inside: at the median observed SD (a logistic map has no slope at its bound).
                let mut sds: Vec<f64> = setup.speeds.iter().map(|o| o.speed_sd).collect();
                sds.sort_by(f64::total_cmp);
                let median = sds.get(sds.len() / 2).copied().unwrap_or(0.0);
                (Slot::ErrorFloor, "m/s", (0.0, 0.1), false, setup.error_floor.max(median))
            }
        };
        let (lo, hi) = f.bounds.unwrap_or(default);
        let bad = |reason: String| JointError::BadBounds { name: name.clone(), reason };
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(bad(format!("{lo}:{hi} must be finite with min < max")));
        }
        if log && lo <= 0.0 {
            return Err(bad(format!("min = {lo} must be greater than 0 for a scale parameter")));
        }
        if slot == Slot::PlateScale {
            plate_scale_free = Some(defs.len());
        }
        defs.push(Def { slot, name, unit, lo, hi, log, start: start.clamp(lo, hi) });
    }
    let inverted = inverted_k_s(setup);
    let (mut knots, mut knot_def, mut law) = (Vec::new(), Vec::new(), None);
    match &setup.shear {
        ShearShape::ForceTests(terrain) => {
            for p in terrain.points() {
                knots.push(Knot { slope_deg: p.slope_deg, k_s: p.k_s, sd: p.k_s_sd.filter(|&s| s > 0.0) });
            }
            for (i, k) in knots.iter().enumerate() {
                if let Some(sd) = k.sd {
                    knot_def.push(Some(defs.len()));
                    let lo = (k.k_s - 10.0 * sd).max(k.k_s * 1e-3);
                    defs.push(Def {
                        slot: Slot::Knot(i),
                        name: format!("k_s_plate({} deg)", k.slope_deg),
                        unit: "N/m^3",
                        lo,
                        hi: k.k_s + 10.0 * sd,
                        log: true,
                        start: k.k_s,
                    });
                } else {
                    knot_def.push(None);
                }
            }
            // Start the plate scale where the speeds' own k_s lie (geometric mean of the ratios).
            if let Some(i) = plate_scale_free {
                let pts: Vec<(f64, f64)> = knots.iter().map(|k| (k.slope_deg, k.k_s)).collect();
                let ln: Vec<f64> = inverted.iter().map(|&(d, k)| (k / interpolate(&pts, d)).ln()).collect();
                if !ln.is_empty() {
                    let c = (ln.iter().sum::<f64>() / ln.len() as f64).exp();
                    defs[i].start = c.clamp(defs[i].lo, defs[i].hi);
                }
            }
        }
        ShearShape::Law(ShearLaw::PerSlope) => return Err(JointError::UnsupportedLaw),
        ShearShape::Law(l) => {
            law = Some(*l);
            let level = inverted.first().map_or(1e6, |&(_, k)| k).clamp(1e3, 1e11);
            defs.push(Def {
                slot: Slot::LawLevel,
                name: "k_s0".into(),
                unit: "N/m^3",
                lo: 1.0,
                hi: 1e12,
                log: true,
                start: level,
            });
            let theta_max = setup.speeds.iter().map(|o| o.slope.degrees()).fold(0.0, f64::max);
            if *l == ShearLaw::Coulomb {
                defs.push(Def {
                    slot: Slot::LawFriction,
                    name: "friction_angle_deg".into(),
                    unit: "deg",
                    lo: theta_max + 1e-3,
                    hi: 89.999,
                    log: false,
                    start: (theta_max + 20.0).min(89.0),
                });
            } else {
                defs.push(Def {
                    slot: Slot::LawRatio,
                    name: "k_s(20 deg)/k_s(0)".into(),
                    unit: "",
                    lo: 0.0,
                    hi: 5.0,
                    log: false,
                    start: 0.8,
                });
            }
        }
    }
    let n_force = knots.iter().filter(|k| k.sd.is_some()).count();
    let n_obs = setup.speeds.len() + setup.anchoring.len() + n_force;
    if defs.len() > n_obs {
        return Err(JointError::TooFewObservations { observations: n_obs, parameters: defs.len() });
    }
    Ok(Problem { setup, defs, knots, knot_def, law, plate_scale: 1.0, n_obs })
}

// ---------------------------------------------------------------------------------------------
// Profiles.

/// The value of a profiled quantity at a point, in its natural coordinate.
#[derive(Clone, Copy)]
enum Target {
    Def(usize),
    LnRatio,
}

/// Profile `-2 ln L` with the target held at `q` (natural coordinate), warm-started at `from`.
fn profile_at(problem: &Problem, target: Target, q: f64, from: &[f64]) -> (Vec<f64>, f64) {
    match target {
        Target::Def(j) => {
            let mut x = from.to_vec();
            x[j] = problem.defs[j].g_inv(q).clamp(problem.defs[j].lo, problem.defs[j].hi);
            minimise(problem, &x, &[j], None)
        }
        Target::LnRatio => minimise(problem, from, &[], Some((q, 1e-5))),
    }
}

/// One end of the 68% interval: walk from the best value in direction `dir` until the profile
/// rises by 1, then bracket the crossing with Brent's method. Returns `(end, open)`.
/// Where a walk starts, where it must stop, its first step and its direction (+1 or -1).
#[derive(Clone, Copy)]
struct Walk {
    q_best: f64,
    limit: f64,
    step0: f64,
    dir: f64,
}

fn interval_end(problem: &Problem, target: Target, best: &[f64], s_min: f64, walk: Walk) -> (f64, bool) {
    let Walk { q_best, limit, step0, dir } = walk;
    let mut q_in = q_best;
    let mut x_in = best.to_vec();
    let mut step = step0;
    for _ in 0..40 {
        let mut q = q_in + dir * step;
        let at_limit = (q - limit) * dir >= 0.0;
        if at_limit {
            q = limit;
        }
        let (x, s) = profile_at(problem, target, q, &x_in);
        if s - s_min >= 1.0 {
            let f = |q: f64| profile_at(problem, target, q, &x_in).1 - s_min - 1.0;
            let mut conv = roots::SimpleConvergency { eps: 1e-4 * (q - q_in).abs().max(1e-12), max_iter: 40 };
            return match roots::find_root_brent(q_in, q, f, &mut conv) {
                Ok(r) => (r, false),
                Err(_) => (0.5 * (q_in + q), false),
            };
        }
        if at_limit {
            return (limit, true);
        }
        q_in = q;
        x_in = x;
        step *= 2.0;
    }
    (q_in, true)
}

/// Initial step for the walk: the conditional standard error from the curvature of `-2 ln L`
/// in the target alone (never larger than the profile's), bounded to a sane fraction.
fn initial_step(problem: &Problem, target: Target, best: &[f64], s_min: f64, q_best: f64, span: f64) -> f64 {
    let h = 1e-3 * span.max(1e-12);
    let s_at = |q: f64| match target {
        Target::Def(j) => {
            let mut x = best.to_vec();
            x[j] = problem.defs[j].g_inv(q).clamp(problem.defs[j].lo, problem.defs[j].hi);
            problem.objective(&x)
        }
        Target::LnRatio => s_min,
    };
    let curv = (s_at(q_best + h) - 2.0 * s_min + s_at(q_best - h)) / (h * h);
    let se = if curv > 0.0 { (2.0 / curv).sqrt() } else { 0.1 * span };
    se.clamp(1e-6 * span.max(1e-9), 0.25 * span.max(1e-9))
}

fn interval_for(problem: &Problem, target: Target, best: &[f64], s_min: f64) -> Interval {
    let (q_best, lo, hi) = match target {
        Target::Def(j) => {
            let d = &problem.defs[j];
            (d.g(best[j]), d.g(d.lo), d.g(d.hi))
        }
        Target::LnRatio => {
            let r = problem.ratio(best).ln();
            (r, r - 5.0, r + 3.0)
        }
    };
    let step = match target {
        Target::Def(_) => initial_step(problem, target, best, s_min, q_best, hi - lo),
        Target::LnRatio => 0.05,
    };
    let (q_lo, lower_open) =
        interval_end(problem, target, best, s_min, Walk { q_best, limit: lo, step0: step, dir: -1.0 });
    let (q_hi, upper_open) =
        interval_end(problem, target, best, s_min, Walk { q_best, limit: hi, step0: step, dir: 1.0 });
    let back = |q: f64| match target {
        Target::Def(j) => problem.defs[j].g_inv(q),
        Target::LnRatio => q.exp(),
    };
    Interval { value: back(q_best), lower: back(q_lo), upper: back(q_hi), lower_open, upper_open }
}

// ---------------------------------------------------------------------------------------------
// The calibration.

/// Fits the free quantities of `setup` to all its evidence at once; see the module docs.
pub fn calibrate_jointly(setup: &JointSetup) -> Result<JointCalibration, JointError> {
    let problem = build(setup)?;
    let n = problem.defs.len();
    let start: Vec<f64> = problem.defs.iter().map(|d| d.start).collect();
    // Several starts: the given one, and the scale-like quantities a decade either way.
    let mut starts = vec![start.clone()];
    for factor in [0.1, 10.0, 30.0] {
        let mut s = start.clone();
        for (d, v) in problem.defs.iter().zip(s.iter_mut()) {
            if matches!(d.slot, Slot::PlateScale | Slot::LawLevel | Slot::ErrorFloor) {
                *v = (*v * factor).clamp(d.lo, d.hi);
            }
        }
        if s != start {
            starts.push(s);
        }
    }
    let (mut best, mut s_min) = (start.clone(), f64::INFINITY);
    for s in &starts {
        let (x, v) = minimise(&problem, s, &[], None);
        if v < s_min {
            (best, s_min) = (x, v);
        }
    }
    // Polish once more from the best point.
    let (x, v) = minimise(&problem, &best, &[], None);
    if v < s_min {
        (best, s_min) = (x, v);
    }

    // Profile intervals, one parameter per task.
    let intervals: Vec<Interval> =
        (0..n).into_par_iter().map(|j| interval_for(&problem, Target::Def(j), &best, s_min)).collect();
    // A profile that found a lower minimum means the global fit was not global: take it.
    let parameters: Vec<FittedParameter> = problem
        .defs
        .iter()
        .zip(&intervals)
        .zip(&best)
        .map(|((d, iv), &v)| {
            let tol = 1e-3 * (d.g(d.hi) - d.g(d.lo));
            let at_bound = (d.g(v) - d.g(d.lo)).abs() < tol || (d.g(d.hi) - d.g(v)).abs() < tol;
            FittedParameter {
                name: d.name.clone(),
                unit: d.unit.into(),
                estimate: Interval { value: v, ..*iv },
                bounds: [d.lo, d.hi],
                at_bound,
            }
        })
        .collect();

    let shear_ratio_20 = ratio_interval(&problem, &best, s_min, &parameters);
    let (pulls, _) = problem.pulls(&best).unwrap_or_default();
    let chi_squared: f64 = pulls.iter().map(|p| p.pull * p.pull).sum();
    let dof = problem.n_obs as i64 - n as i64;
    let chi_squared_per_dof = (dof > 0).then(|| chi_squared / dof as f64);
    let trial = problem.trial(&best);
    let robot = trial.robot.clone().unwrap_or_else(|| setup.robot.clone());

    let shear = shear_table(&problem, &trial, &robot);
    let terrain = terrain_spec(&problem, &shear);
    let mut warnings = Vec::new();
    for p in pulls.iter().filter(|p| p.kind == ObservationKind::Speed) {
        let ceiling = shear.iter().find(|s| s.slope_deg == p.slope_deg).map(|s| s.speed_ceiling_m_s);
        let ceiling = ceiling.unwrap_or_else(|| {
            let slope = Slope::from_degrees(p.slope_deg).unwrap_or(Slope::LEVEL);
            problem.level_step(&robot, slope) / robot.stance_duration()
        });
        if ceiling - p.observed < p.sd_total {
            warnings.push(CalibrationWarning::SpeedNearCeiling {
                slope_deg: p.slope_deg,
                observed_m_s: p.observed,
                sd_m_s: p.sd_total,
                ceiling_m_s: ceiling,
            });
        }
    }
    for p in parameters.iter().filter(|p| p.at_bound) {
        let v = p.estimate.value;
        let bound =
            if (v - p.bounds[0]).abs() <= (p.bounds[1] - v).abs() { p.bounds[0] } else { p.bounds[1] };
        warnings.push(CalibrationWarning::ParameterAtBound { name: p.name.clone(), value: v, bound });
    }
    if let Some(r) = chi_squared_per_dof.filter(|&r| r > 3.0) {
        warnings.push(CalibrationWarning::PoorFit { chi_squared_per_dof: r });
    }
    Ok(JointCalibration {
        parameters,
        chi_squared,
        dof,
        chi_squared_per_dof,
        error_floor_m_s: trial.floor,
        pulls,
        shear_ratio_20,
        shear,
        robot: robot.spec().clone(),
        terrain,
        warnings,
    })
}

/// The interval of `k_s(20)/k_s(0)`: a parameter of the linear law, a monotone function of the
/// friction angle for Coulomb, a penalty-held profile for force tests (exact when the force
/// values are not free).
fn ratio_interval(problem: &Problem, best: &[f64], s_min: f64, params: &[FittedParameter]) -> Interval {
    let value = problem.ratio(best);
    match problem.law {
        Some(ShearLaw::Linear) => params.iter().find(|p| p.name == "k_s(20 deg)/k_s(0)").map(|p| p.estimate),
        Some(ShearLaw::Coulomb) => params.iter().find(|p| p.name == "friction_angle_deg").map(|p| {
            let r = |phi: f64| law_k_s(ShearLaw::Coulomb, [1.0, phi], 20.0);
            Interval { value, lower: r(p.estimate.lower), upper: r(p.estimate.upper), ..p.estimate }
        }),
        _ => {
            let free_knots = problem.knot_def.iter().any(Option::is_some);
            Some(if free_knots {
                interval_for(problem, Target::LnRatio, best, s_min)
            } else {
                Interval { value, lower: value, upper: value, lower_open: false, upper_open: false }
            })
        }
    }
    .unwrap_or(Interval { value, lower: value, upper: value, lower_open: false, upper_open: false })
}

/// The calibrated k_s at the slopes of the written terrain: the observed and force-test slopes
/// (and every whole degree between them for the curved Coulomb law).
fn shear_table(problem: &Problem, trial: &Trial, robot: &Robot) -> Vec<ShearAtSlope> {
    // The observed slopes, and the force-test slopes (so nothing observed is extrapolated).
    let mut slopes: Vec<f64> = problem.setup.speeds.iter().map(|o| o.slope.degrees()).collect();
    slopes.extend(problem.setup.anchoring.iter().map(|o| o.slope.degrees()));
    slopes.extend(problem.knots.iter().map(|k| k.slope_deg));
    slopes.sort_by(f64::total_cmp);
    slopes.dedup();
    if let (Some(ShearLaw::Coulomb), Some(&first), Some(&last)) = (problem.law, slopes.first(), slopes.last())
    {
        let whole: Vec<f64> = (first.ceil() as i64..=last.floor() as i64).map(|d| d as f64).collect();
        slopes.extend(whole);
        slopes.sort_by(f64::total_cmp);
        slopes.dedup();
    }
    slopes
        .into_iter()
        .filter_map(|deg| Slope::from_degrees(deg).ok().map(|s| (deg, s)))
        .map(|(deg, slope)| {
            let k_s = problem.k_s(trial, deg);
            ShearAtSlope {
                slope_deg: deg,
                k_n: problem.k_n(slope),
                k_s,
                k_s_plate: problem.law.is_none().then(|| interpolate(&trial.knots, deg)),
                plate_force_n: k_s * paper::SHEAR_PLATE_WIDTH_M * paper::SHEAR_PLATE_DEPTH_M.powi(2),
                speed_ceiling_m_s: problem.level_step(robot, slope) / robot.stance_duration(),
            }
        })
        .collect()
}

/// The calibrated terrain: k_n (and its SD) from the normal source, k_s from the fit, k_s SD
/// the force tests' SD times the plate scale; the source's angle of repose and name carried over.
fn terrain_spec(problem: &Problem, shear: &[ShearAtSlope]) -> TerrainSpec {
    let normal = &problem.setup.normal;
    let knot_sds: Option<Vec<(f64, f64)>> =
        problem.knots.iter().map(|k| k.sd.map(|sd| (k.slope_deg, sd))).collect();
    let points = shear
        .iter()
        .map(|s| {
            let (k_n_sd, _) = normal.sd_at(Slope::from_degrees(s.slope_deg).unwrap_or(Slope::LEVEL));
            // The force tests' SD (interpolated like the value) times the plate scale.
            let k_s_sd = knot_sds.as_ref().and_then(|sds| {
                s.k_s_plate.filter(|&p| p > 0.0).map(|p| interpolate(sds, s.slope_deg) * s.k_s / p)
            });
            TerrainPoint { slope_deg: s.slope_deg, k_n: s.k_n, k_s: s.k_s, k_n_sd, k_s_sd }
        })
        .collect();
    let repose_deg = match &problem.setup.shear {
        ShearShape::ForceTests(t) => t.spec().repose_deg.or(normal.spec().repose_deg),
        ShearShape::Law(_) => normal.spec().repose_deg,
    };
    TerrainSpec { name: None, repose_deg, points }
}
