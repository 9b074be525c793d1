//! What sandslope shows, for every front end: the figures ([`figures`], PNG or SVG with an
//! embedded font, the simulator's GIF), the one palette they and the pages draw in
//! ([`figures::palette`]), the HTML report page ([`report`]) and the CSV layouts the commands
//! write ([`tables`], [`rows`]).
//!
//! It draws and lays out result values of the `sandslope` library; it computes no physics,
//! parses no flags and prints nothing. Files are written through `sandslope_io::files`, the
//! one output writer (random temporary name, renamed into place).

pub mod figures;
pub mod report;
pub mod rows;
pub mod tables;

/// Turns a plotting backend error (not `Send + Sync` in general) into an `anyhow::Error`,
/// the one message every figure gives.
pub fn plot_err<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow::anyhow!("drawing failed: {e}")
}
