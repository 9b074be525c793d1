//! Calibration (docs/model.md §14, docs/calibration.md): the unmeasured quantities that make the
//! model agree with several kinds of evidence at once.
//!
//! Evidence ([`evidence`]): observed step-averaged speeds, observed anchoring times t1 and
//! force-test measurements of the plate shear strength k_s(theta) (a terrain table with
//! `k_s_sd`). Free quantities ([`parameter`]): any continuous robot key (`hip_height_m`,
//! `level_step_m`, ...), the plate-to-leg scale `c` in `k_s_leg = c k_s_plate` (`plate_scale`),
//! and a model-error floor added in quadrature to every observed speed SD (`error_floor`).
//! Without force tests, k_s(theta) follows a smooth law instead ([`shear`]: [`ShearLaw::Linear`]
//! as `k_s0 (1 + (rho - 1) theta / 20 deg)`, so that `rho = k_s(20)/k_s(0)` is itself a
//! parameter, or [`ShearLaw::Coulomb`]).
//!
//! The fit ([`joint`]) maximises the Gaussian likelihood: it minimises
//! `-2 ln L = sum pull_i^2 + sum_speeds ln(1 + f^2 / sd_i^2)` (+ const), where
//! `pull = (observed - model) / sqrt(sd^2 + f^2)` for speeds, `(observed - model) / sd` for
//! anchoring times and force tests, and f is the error floor; the second sum is what stops a
//! free floor from growing without limit, and it is zero when f = 0. The minimisation is
//! Levenberg-Marquardt ([`optimiser`]) on transformed parameters (a logistic map onto each
//! parameter's bounds, in log space for scale parameters, [`problem`]), started from several
//! points. Each 68% interval ([`profile`]) is the profile-likelihood interval
//! `{value : min over the others of -2 ln L <= minimum + 1}`, found by walking out from the best
//! value and bracketing the crossing with Brent's method. `k_s(20)/k_s(0)` is profiled the same
//! way with the ratio held by a stiff penalty term.
//!
//! Where a trial value makes the leg fail to anchor, the speed and t1 are continued at the
//! anchoring limit (`d_s = d_max`, [`crate::model::continued_speed`]), so the objective stays
//! continuous. [`inversion`] inverts each speed alone (`calibrate --law per-slope`, and the
//! fit's starting values).

pub mod error;
pub mod evidence;
pub mod inversion;
pub mod joint;
pub mod model;
mod optimiser;
pub mod parameter;
mod problem;
mod profile;
pub mod result;
pub mod shear;

pub use error::CalibrationError;
pub use evidence::{AnchoringObservation, SpeedObservation};
pub use inversion::{invert_each_speed, shear_strength_for_speed, InvertedSpeed, PerSlopeCalibration};
pub use joint::{
    calibrate_jointly, calibrate_jointly_cancellable, calibrate_jointly_with, speed_curve, JointSetup,
};
pub use model::SpeedModel;
pub use parameter::{FreeParameter, Parameter, Quantity, RobotKey};
pub use result::{
    CalibrationWarning, FittedParameter, Interval, JointCalibration, ObservationKind, Pull, ShearAtSlope,
};
pub use shear::{ShearLaw, ShearShape};
