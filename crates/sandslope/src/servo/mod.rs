//! The robot's servos: the commanded alternating-tripod gait as a plain value
//! ([`GaitSchedule`], docs/model.md §19) and the Dynamixel XL330-M288's electro-mechanics
//! ([`xl330`]: units of its control table, torque constant and limits from its datasheet).
//!
//! Physics only: the bus, the Protocol 2.0 packets and the emulator live in the
//! `sandslope-servo` crate; the servo log's file format in `sandslope-io`. What the currents
//! say about the sand is [`crate::infer::servo`].

mod schedule;
pub mod verdict;
pub mod xl330;

pub use schedule::{GaitSchedule, LegCommand, ScheduleError};
