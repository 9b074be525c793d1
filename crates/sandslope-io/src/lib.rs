//! # sandslope-io
//!
//! Readers and writers of every file format sandslope uses, shared by the `sandslope` binary,
//! the Python package and the report: robot and terrain TOML files and the built-in presets
//! ([`robot_terrain`], [`presets`]), a report's force tests ([`force_tests`]), speed tables ([`speeds`]), anchoring-time tables ([`anchoring`]), load-cell manifests and
//! recordings ([`measurements`]), motion-capture exports ([`mocap`]), elevation rasters and the
//! risk-map GeoTIFF ([`raster`]; PDS3 DTMs in [`pds3`]), route GeoJSON and CSV ([`routes`]), NumPy `.npy` arrays of
//! phase and risk maps ([`npy`]), fast CSV of large grids ([`grid_csv`]), simulated walks as
//! motion capture ([`trajectory`]), and atomic file
//! writing ([`files`]).
//!
//! This is the edge where files become the library's validated types: every error names the
//! file (or preset), the line, column or key, and the valid range. Nothing here computes
//! physics; that is the `sandslope` library's job.

#![warn(missing_docs)]

pub mod anchoring;
pub mod bag;
pub mod crs;
pub mod files;
pub mod force_tests;
pub mod foxglove;
pub mod grid_csv;
mod lzw_tiles;
pub mod mcap_out;
pub mod measurements;
pub mod mocap;
pub mod nav2_map;
pub mod npy;
pub mod observations;
pub mod pds3;
pub mod presets;
pub mod raster;
pub mod robot_terrain;
pub mod routes;
pub mod servo_log;
pub mod servo_zero;
pub mod speeds;
pub mod trajectory;

pub use anchoring::{load_anchoring_times, AnchoringRow};
pub use files::{csv_string, read_text, write_atomic, write_output, OutputFile, Source, WriteError};
pub use robot_terrain::{load_robot, load_terrain, robot_from_toml, terrain_from_toml};
pub use speeds::{load_speeds, parse_speeds, SpeedRow};
