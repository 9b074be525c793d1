//! What a calibration may fit: the robot keys and other quantities a user frees
//! ([`Parameter`]), and every quantity a fit reports ([`Quantity`]), each with its name and unit.

use super::ShearLaw;
use crate::model::{level_step_length, normal_equilibrium_depth};
use crate::robot::{Robot, RobotSpec};
use crate::slope::Slope;

pub use crate::robot_key::RobotKey;

/// What calibration adds to the table of robot keys ([`crate::robot_key`]): the search of a
/// freed key ([`RobotKey::FITTABLE`]).
impl RobotKey {
    /// Default search bounds around a robot.
    pub(crate) fn default_bounds(self, spec: &RobotSpec) -> (f64, f64) {
        let r = spec.leg_radius_m;
        match self {
            RobotKey::MassKg => (0.01, 100.0),
            RobotKey::LegRadiusM => (0.005, 0.5),
            RobotKey::LegWidthM => (0.001, 0.2),
            RobotKey::HipHeightM => (0.0, 2.0 * r),
            RobotKey::LegSpeedRadS => (0.1, 100.0),
            RobotKey::ResponseTimeS => (0.01, 2.0),
            RobotKey::LegContactAreaM2 => (1e-6, 1e-2),
            RobotKey::LevelStepM | RobotKey::MinStepM => (1e-3, 2.0 * r),
            // Never searched: `free_unknown` refuses keys outside `RobotKey::FITTABLE`.
            RobotKey::StanceLegs => (1.0, 6.0),
        }
    }

    /// Scale parameters are searched in log space.
    pub(crate) fn is_scale(self) -> bool {
        !matches!(self, RobotKey::HipHeightM)
    }

    /// The key's value for `robot` (the level step at `k_n_level` unless measured).
    pub(crate) fn value_for(self, robot: &Robot, k_n_level: f64) -> f64 {
        match self {
            RobotKey::MassKg => robot.mass(),
            RobotKey::LegRadiusM => robot.leg_radius(),
            RobotKey::LegWidthM => robot.leg_width(),
            RobotKey::HipHeightM => robot.hip_height(),
            RobotKey::LegSpeedRadS => robot.leg_speed(),
            RobotKey::StanceLegs => f64::from(robot.stance_legs()),
            RobotKey::ResponseTimeS => robot.response_time(),
            RobotKey::LegContactAreaM2 => robot.contact_area(),
            RobotKey::MinStepM => robot.min_step(),
            RobotKey::LevelStepM => level_step_length(
                robot,
                Slope::LEVEL,
                normal_equilibrium_depth(robot, Slope::LEVEL, k_n_level),
            ),
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
            _ => RobotKey::FITTABLE.into_iter().find(|k| k.name() == name).map(Parameter::Robot),
        }
    }

    /// Every name [`Parameter::parse`] accepts, comma-separated (for error messages).
    pub fn names() -> String {
        let mut v: Vec<&str> = RobotKey::FITTABLE.iter().map(|k| k.name()).collect();
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

/// A quantity a calibration fits and reports: a freed [`Parameter`], or one that the shape of
/// k_s(theta) brings (a force test's plate strength, a law's two parameters).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Quantity {
    /// A quantity the user freed.
    Free(Parameter),
    /// The plate shear strength at one force-test slope, held to the measurement by its SD.
    PlateShearStrength {
        /// Index of the force test in the terrain table.
        point: usize,
        /// Its slope, degrees.
        slope_deg: f64,
    },
    /// A law's level-sand shear strength k_s0.
    LevelShearStrength,
    /// The linear law's `rho = k_s(20 deg) / k_s(0)`.
    ShearRatio20,
    /// The Coulomb law's friction angle phi, degrees.
    FrictionAngle,
}

impl Quantity {
    /// The two parameters of a smooth law.
    pub fn of_law(law: ShearLaw) -> [Quantity; 2] {
        match law {
            ShearLaw::Linear => [Quantity::LevelShearStrength, Quantity::ShearRatio20],
            ShearLaw::Coulomb => [Quantity::LevelShearStrength, Quantity::FrictionAngle],
        }
    }

    /// The name as reported (`hip_height_m`, `plate_scale`, `k_s_plate(20 deg)`, `k_s0`, ...).
    pub fn name(self) -> String {
        match self {
            Quantity::Free(p) => p.name().into(),
            Quantity::PlateShearStrength { slope_deg, .. } => format!("k_s_plate({slope_deg} deg)"),
            Quantity::LevelShearStrength => "k_s0".into(),
            Quantity::ShearRatio20 => "k_s(20 deg)/k_s(0)".into(),
            Quantity::FrictionAngle => "friction_angle_deg".into(),
        }
    }

    /// The unit of its value (empty for a ratio).
    pub fn unit(self) -> &'static str {
        match self {
            Quantity::Free(Parameter::Robot(k)) => k.unit(),
            Quantity::Free(Parameter::PlateScale) | Quantity::ShearRatio20 => "",
            Quantity::Free(Parameter::ErrorFloor) => "m/s",
            Quantity::PlateShearStrength { .. } | Quantity::LevelShearStrength => "N/m^3",
            Quantity::FrictionAngle => "deg",
        }
    }
}
