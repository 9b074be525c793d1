//! The CLI's error handling: every failure is a user-facing message and an exit code.
//!
//! Commands return `anyhow::Result`; context added on the way up names the file, key and
//! valid range. `main` prints the chain on one line per cause and exits with
//! [`exit_code`]: 2 for bad input (flags, files, values out of range; clap uses 2 for usage
//! errors too), 3 when an output could not be written (disk full, no permission), 4 when
//! `report --strict` wrote a report that carries warnings, and 0,
//! silently, when the reader of stdout went away (`sandslope sweep --json | head`).

use std::io::ErrorKind;

/// Exit code of a successful run, and of a run whose stdout was closed by its reader.
pub const EXIT_OK: i32 = 0;
/// Exit code for bad input: flags, files, keys or values the tool cannot accept.
pub const EXIT_USAGE: i32 = 2;
/// Exit code when an output file could not be written (the environment, not the input).
pub const EXIT_OUTPUT: i32 = 3;
/// Exit code of `report --strict` when the report was written but carries warnings.
pub const EXIT_WARNINGS: i32 = 4;

/// `report --strict`: the outputs were written, but the report carries this many warnings.
#[derive(Debug, thiserror::Error)]
#[error(
    "--strict: the report carries {0} warning(s) (above); its numbers are not to be trusted as they stand"
)]
pub struct Strict(pub usize);

/// The exit code for a failed run (see the module documentation).
pub fn exit_code(e: &anyhow::Error) -> i32 {
    let broken_pipe = e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>().map(std::io::Error::kind) == Some(ErrorKind::BrokenPipe)
            || c.downcast_ref::<serde_json::Error>().and_then(serde_json::Error::io_error_kind)
                == Some(ErrorKind::BrokenPipe)
            || c.downcast_ref::<csv::Error>().is_some_and(|e| match e.kind() {
                csv::ErrorKind::Io(io) => io.kind() == ErrorKind::BrokenPipe,
                _ => false,
            })
    });
    if broken_pipe {
        EXIT_OK
    } else if e.chain().any(|c| c.is::<sandslope_io::WriteError>()) {
        EXIT_OUTPUT
    } else if e.chain().any(|c| c.is::<Strict>()) {
        EXIT_WARNINGS
    } else {
        EXIT_USAGE
    }
}

/// `println!` panics when stdout is a closed pipe; end such a run quietly instead, as
/// coreutils and ripgrep do, leaving every other panic message as it is.
pub fn exit_quietly_on_broken_pipe() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let message = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if message.contains("failed printing to stdout") && message.contains("Broken pipe") {
            std::process::exit(EXIT_OK);
        }
        default(info);
    }));
}

/// Turns a plotting backend error (not `Send + Sync` in general) into an `anyhow::Error`.
pub fn plot_err<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow::anyhow!("drawing failed: {e}")
}
