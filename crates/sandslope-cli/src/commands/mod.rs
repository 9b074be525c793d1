//! One module per subcommand; each parses its arguments, calls the library and writes.

pub mod common;
pub mod phase;
pub mod predict;
pub mod presets;
pub mod risk;
