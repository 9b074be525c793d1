//! The robot's servos: the commanded alternating-tripod gait as a plain value
//! ([`GaitSchedule`], docs/model.md §19) and the Dynamixel servo models as values
//! ([`ServoModel`]: the units of their control table, torque constant and limits from their
//! datasheets, with the source of each).
//!
//! Physics only: the bus, the Protocol 2.0 packets and the emulator live in the
//! `sandslope-servo` crate; the servo log's file format in `sandslope-io`. What the currents
//! say about the sand is [`crate::infer::servo`].

pub mod model;
mod schedule;
pub mod verdict;

pub use model::{ServoModel, TorqueReading, UnsupportedServo};
pub use schedule::{GaitSchedule, LegCommand, ScheduleError};
