//! One module per subcommand; each parses its arguments, calls the library and writes.

pub mod calibrate;
pub mod design;
pub mod drive;
pub mod fit;
pub mod infer;
pub mod phase;
pub mod plan;
pub mod predict;
pub mod presets;
pub mod report;
pub mod risk;
pub mod simulate;
pub mod sweep;
pub mod track;
