//! One module per subcommand; each parses its arguments, calls the library and writes.

pub mod common;
pub mod plan;
pub mod predict;
pub mod presets;
