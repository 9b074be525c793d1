//! Why a calibration could not be done.

/// Why a calibration could not be done.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CalibrationError {
    /// No speeds and no anchoring times.
    #[error("nothing to calibrate against: give observed speeds or anchoring times")]
    NoObservations,
    /// The caller's cancel flag was raised during the fit ([`super::calibrate_jointly_cancellable`]).
    #[error("interrupted")]
    Interrupted,
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
    /// A robot key no calibration can free (a whole number, or one no observation depends on).
    #[error("{name} cannot be freed; the parameters that can: {fittable}")]
    NotFittable {
        /// The key.
        name: String,
        /// The parameters that can be freed, comma-separated.
        fittable: String,
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
    /// A negative or non-finite fixed error floor.
    #[error("error floor = {0} must be a finite number >= 0 m/s")]
    BadErrorFloor(f64),
    /// The per-slope inversion: no k_s gives the observed speed.
    #[error(
        "at {slope_deg} deg the observed speed {observed:.4} m/s is outside what the model can reach for any k_s \
         ({:.4} m/s when the leg anchors at the last moment, up to {:.4} m/s with instant anchoring); \
         check the robot's hip height, level step or k_n",
        range.0,
        range.1
    )]
    Unreachable {
        /// Slope, degrees.
        slope_deg: f64,
        /// Observed speed, m/s.
        observed: f64,
        /// The model's speed range `[lowest, highest)` over all k_s that anchor, m/s.
        range: (f64, f64),
    },
    /// The per-slope inversion: the legs sink at this slope and k_n, so k_s has no effect on
    /// the speed.
    #[error(
        "at {slope_deg} deg the legs sink (d_n >= 2R - h) with this k_n: the speed does not depend on k_s"
    )]
    Sinkage {
        /// Slope, degrees.
        slope_deg: f64,
    },
    /// A freed quantity the simulator does not read (`calibrate --model simulate`).
    #[error(
        "--free {name}: the simulator does not use {name} (it computes the contact and the body's \
         acceleration itself, docs/model.md §15), so the fit could not constrain it; free it with \
         --model closed-form only"
    )]
    NotASimulatorInput {
        /// The robot key.
        name: String,
    },
    /// The simulator refused a walk at the starting point (`calibrate --model simulate`).
    #[error("the simulator cannot walk this robot and ground: {reason}")]
    Simulator {
        /// The simulator's message.
        reason: String,
    },
}
