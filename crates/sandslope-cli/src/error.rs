//! The CLI's error handling: every failure is a user-facing message and exit code 2.
//!
//! Commands return `anyhow::Result`; context added on the way up names the file, key and
//! valid range. `main` prints the chain on one line per cause and exits with [`EXIT_USAGE`].

/// Exit code for bad input, bad files and every other failure (clap uses the same for usage).
pub const EXIT_USAGE: i32 = 2;

/// Turns a plotting backend error (not `Send + Sync` in general) into an `anyhow::Error`.
pub fn plot_err<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow::anyhow!("drawing failed: {e}")
}
