//! Dynamixel Protocol 2.0 for sandslope (docs/drive.md): the robot in the loop.
//!
//! - [`table`]: the X series' control table addresses and the register values the driver writes;
//! - [`models`]: each supported model's control table where it differs (registers, modes,
//!   factory values), beside the library's `sandslope::servo::ServoModel` figures;
//! - [`packet`]: the device side of Protocol 2.0 (instruction parsing, status encoding with
//!   byte stuffing and the CRC of `dynamixel2::checksum`), what the emulator speaks;
//! - [`driver`]: the alternating tripod of [`sandslope::servo::GaitSchedule`] sent to the
//!   servos over a `dynamixel2::Bus` (sync write of goals, sync read of the present state), with
//!   its safety logic: torque off on every exit, Ctrl-C, a lost servo and a watchdog;
//! - [`error`]: why a run failed, naming the servo and the fix, and its exit code;
//! - [`session`]: one run as every front end starts it, from the typed [`session::DriveConfig`]
//!   that `drive`'s and `serve --drive`'s flags are translated into;
//! - [`clock`]: the run's clock, the wall's or the emulator's virtual one;
//! - [`log`]: the run's log as every front end writes it (header, rows, the output path);
//! - [`emulator`]: a bus of virtual servos of any supported model on a pseudo-terminal, whose shafts move as commanded
//!   and whose currents come from the stride simulator (`sandslope::simulate`).
//!
//! The bus is the one place this crate touches hardware; the physics (the schedule, the
//! servo's torque constant, the inference from currents) is the library's.

pub mod clock;
pub mod config;
pub mod driver;
pub mod emulator;
pub mod error;
pub mod guard;
pub mod log;
pub mod models;
pub mod packet;
pub mod plan;
mod report;
pub mod session;
pub mod setup;
pub mod speed;
mod stance;
pub mod table;
pub mod zero;

pub use driver::{drive, DriveError, DriveOutcome, DriveSettings, Profile, ServoConfig, ServoSample};
pub use emulator::{Emulator, EmulatorConfig, EmulatorFaults, EmulatorReport};
