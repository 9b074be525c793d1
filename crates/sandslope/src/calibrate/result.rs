//! What a calibration returns: plain values, ready to serialise (`calibrate --json`).

use std::fmt;

use serde::Serialize;

use super::{Parameter, Quantity, SpeedModel};
use crate::robot::RobotSpec;
use crate::terrain::TerrainSpec;

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
    /// Which quantity (not serialised: `name` says it).
    #[serde(skip)]
    pub quantity: Quantity,
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
        /// The parameter's name.
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
    /// The model the speeds and anchoring times came from.
    pub model: SpeedModel,
    /// Simulated walks the fit ran (0 for the closed form).
    pub walks: usize,
}

impl JointCalibration {
    /// The fitted value of `quantity`, if the fit had it.
    pub fn fitted(&self, quantity: Quantity) -> Option<&FittedParameter> {
        self.parameters.iter().find(|p| p.quantity == quantity)
    }

    /// The fitted value of a freed `parameter` (`None` when it was not freed).
    pub fn parameter(&self, parameter: Parameter) -> Option<&FittedParameter> {
        self.fitted(Quantity::Free(parameter))
    }

    /// The plate-to-leg scale `c` in `k_s_leg = c k_s_plate`: fitted, or 1 when not freed.
    pub fn plate_scale(&self) -> f64 {
        self.parameter(Parameter::PlateScale).map_or(1.0, |p| p.estimate.value)
    }
}
