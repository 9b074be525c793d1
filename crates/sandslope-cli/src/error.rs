//! The CLI's error handling: every failure is a user-facing message and an exit code.
//!
//! Commands return `anyhow::Result`; context added on the way up names the file, key and
//! valid range. `main` prints the chain on one line per cause and exits with [`exit_code`]:
//!
//! | code | meaning |
//! |---|---|
//! | 0 | success, or stdout was closed by its reader (`sandslope sweep --json \| head`) |
//! | 2 | bad input: a flag, value, key or file the tool cannot accept (a file that does not exist, a malformed or implausible one); clap's usage errors |
//! | 3 | the system failed: an output (file, folder, stdout or stderr) could not be written (disk full, no permission), or an input that exists could not be read (no permission, I/O error) |
//! | 4 | `report --strict`: the report was written, but it carries warnings |
//! | 5 | `drive --stop-on-risk`: the gait was halted on risk (legs held, then torque off; log kept) |
//! | 130, 143, 129 | interrupted by SIGINT (Ctrl-C), SIGTERM or SIGHUP (128 + the signal); temporary files removed, no output left |
//!
//! Whatever the code, a run that does not succeed leaves no output behind
//! (`sandslope_files::discard_outputs`); the exceptions are code 4, whose outputs are
//! written and whose failure is the verdict on them, and `drive`, whose log is kept on every
//! exit (it is the record of what the robot did; [`KeepLog`]).

use std::io::ErrorKind;

/// Exit code of a successful run, and of a run whose stdout was closed by its reader.
pub const EXIT_OK: i32 = 0;
/// Exit code for bad input: flags, files, keys or values the tool cannot accept.
pub const EXIT_USAGE: i32 = 2;
/// Exit code when the system failed: an output could not be written, or an existing input
/// could not be read.
pub const EXIT_OUTPUT: i32 = 3;
/// Exit code of `report --strict` when the report was written but carries warnings.
pub const EXIT_WARNINGS: i32 = 4;
/// Exit code after SIGINT (128 + 2), as shells report it.
pub const EXIT_SIGINT: i32 = 130;
/// Exit code of `drive --stop-on-risk` when the risk halted the gait.
pub const EXIT_HALTED: i32 = 5;

/// Set while `drive` runs: Ctrl-C then asks it to stop ([`STOP`]) instead of ending the process,
/// so that the torque is turned off and the log kept.
pub static DRIVING: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);
/// Set by Ctrl-C while [`DRIVING`].
pub static STOP: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);
/// The signal that set [`STOP`] (2 SIGINT, 15 SIGTERM, 1 SIGHUP): a stopped run exits with
/// 128 plus it, as every other interrupted run of the tool does.
pub static STOP_SIGNAL: std::sync::atomic::AtomicI32 = std::sync::atomic::AtomicI32::new(0);

/// The exit code and the name of the signal that stopped a driven run ([`STOP_SIGNAL`]).
pub fn stop_signal() -> (i32, &'static str) {
    match STOP_SIGNAL.load(std::sync::atomic::Ordering::SeqCst) {
        15 => (143, "SIGTERM"),
        1 => (129, "SIGHUP"),
        _ => (EXIT_SIGINT, "Ctrl-C"),
    }
}

/// `drive` ended other than by completing its run (a failed bus, Ctrl-C, a halt on risk): its
/// outputs (the log) are kept and the process exits with `code`.
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct KeepLog {
    /// Exit code.
    pub code: i32,
    /// What happened.
    pub message: String,
}

/// `report --strict`: the outputs were written, but the report carries this many warnings.
#[derive(Debug, thiserror::Error)]
#[error(
    "--strict: the report carries {0} warning(s) (above); its numbers are not to be trusted as they stand"
)]
pub struct Strict(pub usize);

/// Whether `e` is a verdict on outputs that are nonetheless kept ([`Strict`]).
pub fn keeps_outputs(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.is::<Strict>() || c.is::<KeepLog>())
}
/// The I/O error kinds that mean the input is wrong rather than the system failing.
fn is_input_kind(kind: ErrorKind) -> bool {
    matches!(
        kind,
        ErrorKind::NotFound
            | ErrorKind::IsADirectory
            | ErrorKind::NotADirectory
            | ErrorKind::InvalidInput
            | ErrorKind::InvalidData
            | ErrorKind::UnexpectedEof
            | ErrorKind::InvalidFilename
    )
}

/// The I/O error kind somewhere in `e`'s chain of causes (the outermost one), if any.
fn io_kind(e: &anyhow::Error) -> Option<ErrorKind> {
    e.chain().find_map(|c| {
        c.downcast_ref::<std::io::Error>()
            .map(std::io::Error::kind)
            .or_else(|| c.downcast_ref::<serde_json::Error>().and_then(serde_json::Error::io_error_kind))
            .or_else(|| {
                c.downcast_ref::<csv::Error>().and_then(|e| match e.kind() {
                    csv::ErrorKind::Io(io) => Some(io.kind()),
                    _ => None,
                })
            })
    })
}

/// The exit code for a failed run (see the module documentation).
pub fn exit_code(e: &anyhow::Error) -> i32 {
    if let Some(k) = e.chain().find_map(|c| c.downcast_ref::<KeepLog>()) {
        return k.code;
    }
    match io_kind(e) {
        Some(ErrorKind::BrokenPipe) => EXIT_OK,
        _ if e.chain().any(|c| c.is::<sandslope_files::WriteError>()) => EXIT_OUTPUT,
        _ if keeps_outputs(e) => EXIT_WARNINGS,
        Some(kind) if !is_input_kind(kind) => EXIT_OUTPUT,
        _ => EXIT_USAGE,
    }
}

/// `println!` and `eprintln!` panic when their stream fails. End such a run as a careful Unix
/// tool does instead of with a panic (exit 101): quietly with 0 when stdout is a pipe whose
/// reader went away (`sandslope sweep --json | head`), and otherwise (a full disk, a closed
/// terminal) with one line on stderr, if it can still be written, and exit code 3. Temporary
/// outputs are removed first. Every other panic keeps its message.
pub fn exit_cleanly_on_stream_errors() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let message = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        let stream = if message.contains("failed printing to stdout") {
            Some("standard output")
        } else if message.contains("failed printing to stderr") {
            None
        } else {
            default(info);
            return;
        };
        sandslope_files::discard_outputs();
        if message.contains("Broken pipe") {
            std::process::exit(EXIT_OK);
        }
        if let Some(stream) = stream {
            let reason = message.rsplit_once(": ").map_or(message, |(_, r)| r);
            let _ = std::io::Write::write_all(
                &mut std::io::stderr(),
                format!("error: cannot write to {stream}: {reason}\n").as_bytes(),
            );
        }
        std::process::exit(EXIT_OUTPUT);
    }));
}

/// A write past the process's file-size limit (`ulimit -f`, a quota some clusters and robot
/// images set) fails with "File too large" like a full disk, instead of SIGXFSZ ending the
/// process where it stands: that left a `.partial` file behind and, in `drive`, the servos'
/// torque on with only their Bus Watchdog to stop them. With the signal ignored, the failed
/// write takes the run's ordinary error path (exit 3, outputs removed; `drive` turns the
/// torque off and keeps what of its log could be written).
pub fn fail_writes_past_the_file_size_limit() {
    // A handler (a flag nobody reads) rather than SIG_IGN: the write fails with EFBIG all
    // the same, and a program this one starts gets the default back. Failing to install it
    // only loses this.
    let seen = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let _ = signal_hook::flag::register(signal_hook::consts::SIGXFSZ, seen);
}

/// On SIGINT, SIGTERM or SIGHUP: remove this run's temporary files and exit with 128 plus the
/// signal's number (130, 143, 129), as shells report a process the signal ended, so a killed
/// run leaves nothing. The outputs of a run whose final renames have begun are all put in
/// place first ([`sandslope_files::discard_outputs`] waits for them): never a mixed set.
pub fn clean_up_on_signals() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    // Failing to install the handler only loses the clean-up.
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
        return;
    };
    let _ = std::thread::Builder::new().name("signals".into()).spawn(move || {
        for signal in signals.forever() {
            if DRIVING.load(std::sync::atomic::Ordering::SeqCst) {
                // `drive` stops the gait, turns the torque off, keeps its log and exits with
                // 128 + the signal.
                STOP_SIGNAL.store(signal, std::sync::atomic::Ordering::SeqCst);
                STOP.store(true, std::sync::atomic::Ordering::SeqCst);
                continue;
            }
            sandslope_files::discard_outputs();
            std::process::exit(128 + signal);
        }
    });
}
