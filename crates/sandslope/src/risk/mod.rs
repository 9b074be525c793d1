//! Probability of each regime when the terrain is uncertain (docs/model.md §9).
//!
//! k_n and k_s at a slope are independent log-normal variables whose medians are the table
//! values; their coefficients of variation follow the one rule of the whole tool
//! ([`UncertainTerrain`]: a user-given CV, else the table's SD over its value, else the
//! defaults 0.1 for k_n and 0.2 for k_s).
//!
//! - [`regime_probabilities`]: the four regime probabilities at one slope and one median
//!   ground, by deterministic quadrature (the reference; [`quadrature`]).
//! - [`failure_risk`], [`risk_curve`]: the same on an uncertain terrain, at one or several
//!   slopes ([`RiskCurve`]).
//! - [`p_fail`]: the failure probability alone, about a hundred times faster than the
//!   reference and within 2e-9 of it ([`failure_probability`]); what the safe-slope limit and
//!   `design` decide with.
//! - [`safe_slope_limit`] (steepest slope below a failure-risk threshold), [`max_safe_mass`]
//!   (heaviest safe robot at a slope) and [`payload_envelope`] (that mass at each slope): one
//!   scan-and-bisect search ([`limits`]); [`success_slope_limit`] (steepest slope below a
//!   risk threshold of not succeeding: not metastable either) is the same search.
//! - [`RiskMap`]: p_fail and p_not_success over a grid of median (k_n, k_s).
//! - [`safe_slope`], [`safe_mass`], [`risk_map`] ([`RiskMapAnswer`]: the cells and their
//!   summary): the solving modes' answers with the uncertainty they used ([`results`]), what
//!   `risk --json` prints and Python returns;
//!   [`RiskAnswer`]: the one value every `risk --json` mode prints.
//!
//! Every result is a plain serialisable value; none draws or writes anything.

pub mod curve;
pub mod failure_probability;
pub mod limits;
pub mod map;
mod panels;
pub mod quadrature;
pub mod results;
pub mod uncertainty;

/// The largest acceptable failure probability when none is given (`--max-risk`, Python's
/// `max_risk`): the safe-slope limit, the heaviest safe mass and a design's risk target are
/// taken at p_fail = 0.05 (docs/model.md §9).
pub const DEFAULT_MAX_RISK: f64 = 0.05;

pub use curve::{risk_curve, RiskCurve, RiskPoint};
pub use failure_probability::p_fail;
pub use limits::{
    failure_risk, max_safe_mass, payload_envelope, safe_slope_limit, success_slope_limit, PayloadEnvelope,
    PayloadPoint, SafeLimit, MASS_SCAN_FACTOR, MAX_MASS_FACTOR, MAX_SCAN_SLOPE_DEG, SLOPE_SCAN_STEP_DEG,
    SLOPE_TOLERANCE_DEG,
};
pub use map::RiskMap;
pub use quadrature::{regime_probabilities, RegimeProbabilities};
pub use results::{
    map_axes, risk_map, safe_mass, safe_slope, RiskAnswer, RiskMapAnswer, RiskMapSummary, SafeMass,
    SafeSlope, MAP_POINTS, RISK_MAP_CELL_KEYS,
};
pub use uncertainty::{
    CvSource, DefaultsUsed, UncertainGround, UncertainTerrain, Uncertainty, UsedUncertainty, DEFAULT_CV_N,
    DEFAULT_CV_S,
};
