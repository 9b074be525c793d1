//! Progress bars for long runs: shown on a terminal, hidden when output is piped or quiet.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressStyle};

/// Whether progress is shown: stdout and stderr are terminals and `quiet` is false.
fn shown(quiet: bool) -> bool {
    !quiet && std::io::stdout().is_terminal() && std::io::stderr().is_terminal()
}

/// A progress bar of `len` steps on stderr, shown only when stdout and stderr are terminals
/// and `quiet` is false (hidden in `--json` mode and when piped).
pub fn progress_bar(len: u64, quiet: bool, what: &str) -> ProgressBar {
    if !shown(quiet) {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    if let Ok(style) = ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} ({eta})") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(what.to_string());
    bar
}

/// A spinner on stderr with `what` and the time elapsed, for work of unknown length (a
/// simulation), ticking on its own; shown as [`progress_bar`] is.
pub fn spinner(quiet: bool, what: &str) -> ProgressBar {
    if !shown(quiet) {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new_spinner();
    if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} ({elapsed})") {
        bar.set_style(style);
    }
    bar.set_message(what.to_string());
    bar.enable_steady_tick(std::time::Duration::from_millis(100));
    bar
}
