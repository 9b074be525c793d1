//! # sandslope
//!
//! Whether, how fast and why a C-legged robot climbs a sand slope: the shear-anchoring model of
//! Liao and Qian, "Failure Mechanisms and Risk Estimation for Legged Robot Locomotion on
//! Granular Slopes" (arXiv:2603.06928), implemented exactly as the repository's `docs/model.md`
//! specifies, with the analysis around it.
//!
//! Slope weakens the sand's shear strength `k_s`, so each leg must dig deeper (to the
//! shear-equilibrium depth `d_s`) before it anchors; the robot slips back until then
//! (anchoring time `t1`), and its step and speed fall. Too weak in shear and the robot slips
//! back (`Regime::Slippage`); too weak in normal support `k_n` and its legs sink
//! (`Regime::Sinkage`).
//!
//! This crate is physics and analysis: no file formats, no plotting, no CLI; its one word to
//! the operating system is a huge-page hint for large output buffers ([`memory`]). Types are
//! validated once when built ([`Robot::new`], [`Terrain::new`], [`Slope::from_degrees`]) and
//! trusted after.
//!
//! ```
//! use sandslope::{predict, Ground, Regime, Robot, RobotSpec, Slope};
//! let robot = Robot::new(RobotSpec {
//!     mass_kg: 0.35, leg_radius_m: 0.04, leg_width_m: 0.01, hip_height_m: 0.03,
//!     leg_speed_rad_s: std::f64::consts::TAU, stance_legs: 3, response_time_s: 0.2,
//!     leg_contact_area_m2: None, level_step_m: None, min_step_m: None, body_length_m: None,
//!     body_width_m: None, pitch_inertia_kg_m2: None, servo_torque_limit_n_m: None, leg_elements: None,
//! }).unwrap();
//! let p = predict(&robot, Slope::from_degrees(20.0).unwrap(), &Ground::new(7e5, 1e6).unwrap());
//! assert_eq!(p.regime, Regime::Metastable);
//! assert!(p.speed.unwrap() > 0.0);
//! ```

#![warn(missing_docs)]

pub mod axis;
pub mod calibrate;
pub mod constants;
pub mod contour;
pub mod critical;
pub mod design;
pub mod error;
pub mod gait;
pub mod infer;
pub mod leg;
pub mod limits;
pub mod measure;
pub mod memory;
pub mod model;
pub mod paper;
pub mod phase;
pub mod plan;
pub mod regime;
pub mod report;
pub mod risk;
pub mod robot;
pub mod robot_key;
pub mod scenario;
pub mod servo;
pub mod simulate;
pub mod slope;
pub mod strength_grid;
pub mod terrain;

pub use axis::{Axis, AxisScale};
pub use calibrate::{
    calibrate_jointly, calibrate_jointly_cancellable, calibrate_jointly_with, invert_each_speed,
    AnchoringObservation, CalibrationError, CalibrationWarning, FittedParameter, FreeParameter,
    JointCalibration, JointSetup, Parameter, Quantity, RobotKey, ShearLaw, ShearShape, SpeedModel,
    SpeedObservation,
};
pub use constants::G;
pub use contour::ContourSegment;
pub use critical::{critical_shear_strength, NoShearSuffices, StepTarget};
pub use error::ParamError;
pub use gait::{analyse, GaitAnalysis, GaitError, GaitOptions, Recording, Upslope};
pub use leg::LegShape;
pub use measure::{MeasureError, SlopeEstimate};
pub use model::{predict, Prediction};
pub use phase::{
    write_phase, write_phase_rows, PanelGround, PanelSummary, PhaseMap, PhasePanel, RegimeCounts, TerrainGrid,
};
pub use plan::{ElevationGrid, Objective, PlanSettings, Planner};
pub use regime::{Cause, Regime};
pub use risk::{
    regime_probabilities, RegimeProbabilities, RiskCurve, RiskMap, SafeLimit, UncertainTerrain, Uncertainty,
};
pub use robot::{LevelStep, Robot, RobotSpec};
pub use scenario::{Scenario, SlopeEvaluation};
pub use simulate::{simulate, simulate_slopes, SimSettings, SimSummary, Simulation};
pub use slope::{SignedSlope, Slope};
pub use strength_grid::StrengthGrid;
pub use terrain::{Ground, Terrain, TerrainPoint, TerrainSpec};
