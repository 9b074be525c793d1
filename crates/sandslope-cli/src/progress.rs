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
    terminal_spinner(what)
}

/// Progress that is never silent unless asked to be: a bar or spinner on a terminal (as
/// [`progress_bar`] and [`spinner`]), and when stderr is not a terminal (a log file, CI, a
/// pipe) plain lines on stderr instead: the task when it starts, every tenth of its steps and
/// the time it took when it ends. `simulate` uses it: a walk with its GIF takes tens of seconds,
/// which a log showed as nothing at all. Silent when `quiet` (`--json`, `--csv`).
pub enum Progress {
    /// The terminal's bar or spinner (or a hidden one when quiet).
    Bar(ProgressBar),
    /// Lines on stderr.
    Lines {
        /// What is being done.
        what: String,
        /// Steps in all (0: unknown, a spinner's task).
        len: u64,
        /// Steps done.
        done: u64,
        /// When it started.
        start: std::time::Instant,
    },
}

impl Progress {
    /// Progress of `len` steps (`len` 0: a task of unknown length, shown as a spinner).
    pub fn new(len: u64, quiet: bool, what: &str) -> Progress {
        if quiet || shown(false) {
            return Progress::Bar(if len == 0 {
                spinner(quiet, what)
            } else {
                progress_bar(len, quiet, what)
            });
        }
        if std::io::stderr().is_terminal() {
            // A terminal on stderr while stdout is piped: the bar, on stderr.
            return Progress::Bar(if len == 0 { terminal_spinner(what) } else { terminal_bar(len, what) });
        }
        eprintln!("{what}{}", if len == 0 { " ..." } else { "" });
        Progress::Lines { what: what.to_string(), len, done: 0, start: std::time::Instant::now() }
    }

    /// One step done.
    pub fn inc(&mut self) {
        match self {
            Progress::Bar(bar) => bar.inc(1),
            Progress::Lines { what, len, done, .. } => {
                *done += 1;
                let tenth = |d: u64| d * 10 / (*len).max(1);
                if *len > 0 && tenth(*done) > tenth(*done - 1) && *done < *len {
                    eprintln!("{what}: {done}/{len}");
                }
            }
        }
    }

    /// The task is over: the bar cleared, or a last line with the time taken.
    pub fn finish(self) {
        match self {
            Progress::Bar(bar) => bar.finish_and_clear(),
            Progress::Lines { what, len, start, .. } => {
                let steps = if len > 0 { format!(" {len}/{len},") } else { String::new() };
                eprintln!("{what}:{steps} done in {:.1} s", start.elapsed().as_secs_f64());
            }
        }
    }
}

/// [`progress_bar`] on stderr whatever stdout is.
fn terminal_bar(len: u64, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    if let Ok(style) = ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} ({eta})") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(what.to_string());
    bar
}

/// [`spinner`] on stderr whatever stdout is.
fn terminal_spinner(what: &str) -> ProgressBar {
    let bar = ProgressBar::new_spinner();
    if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} ({elapsed})") {
        bar.set_style(style);
    }
    bar.set_message(what.to_string());
    bar.enable_steady_tick(std::time::Duration::from_millis(100));
    bar
}
