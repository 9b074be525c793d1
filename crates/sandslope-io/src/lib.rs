//! # sandslope-io
//!
//! Readers and writers of the file formats that carry the library's types, shared by the
//! `sandslope` binary, the Python package and the report: robot and terrain TOML files and the
//! built-in presets ([`robot_terrain`], [`presets`]), a report's force tests ([`force_tests`]),
//! speed tables ([`speeds`]), anchoring-time tables ([`anchoring`]), load-cell manifests and
//! recordings ([`measurements`]), motion-capture exports ([`mocap`]), a bag's topics as a
//! capture or a servo log ([`bag_series`]), servo logs ([`servo_log`]), a raster's windows as
//! the corridor search's height source ([`height_windows`]), route GeoJSON and CSV
//! ([`routes`]), NumPy `.npy` arrays of phase and risk maps ([`npy`]), fast CSV of large grids
//! ([`grid_csv`]), simulated walks as motion capture ([`trajectory`]) and as MCAP
//! ([`mcap_out`]).
//!
//! The formats that need nothing from the library are crates of their own, which a first
//! build compiles beside it (docs/building.md): reading text and writing every output
//! atomically (`sandslope-files`), elevation rasters, PDS3 DTMs and their coordinate systems
//! (`sandslope-raster`), ROS 2 bags (`sandslope-bag`).
//!
//! This is the edge where files become the library's validated types: every error names the
//! file (or preset), the line, column or key, and the valid range. Nothing here computes
//! physics; that is the `sandslope` library's job.

#![warn(missing_docs)]

pub mod anchoring;
pub mod bag_series;
pub mod force_tests;
pub mod foxglove;
pub mod grid_csv;
pub mod height_windows;
pub mod mcap_out;
pub mod measurements;
pub mod mocap;
pub mod nav2_map;
pub mod npy;
pub mod observations;
pub mod presets;
pub mod robot_terrain;
pub mod routes;
pub mod servo_log;
pub mod servo_zero;
pub mod speeds;
pub mod trajectory;

pub use anchoring::{load_anchoring_times, AnchoringRow};
pub use robot_terrain::{load_robot, load_terrain, robot_from_toml, terrain_from_toml};
pub use speeds::{load_speeds, parse_speeds, SpeedRow};
