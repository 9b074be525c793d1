//! Physical constants shared by the model, the robot's validation and the simulator
//! (docs/model.md §1), kept apart so that no module imports another only for a number.

/// Gravitational acceleration, m/s^2 (docs/model.md §1 fixes 9.81, not 9.80665).
pub const G: f64 = 9.81;
