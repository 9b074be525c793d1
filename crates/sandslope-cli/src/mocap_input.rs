//! Motion-capture input shared by `sandslope track` and `sandslope report --tracks`: the
//! expansion of file arguments (paths or glob patterns) and the warnings around the request
//! layer's one path from capture files to the library (`sandslope_request::track`, which Python
//! takes too). Commands share this code through this module, never through each other.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Result};

use sandslope::gait::{GaitOptions, TrackResult};

/// Expands file arguments: existing paths as they are, anything else as a glob pattern whose
/// matching files are taken in sorted order; a pattern matching no file is an error.
pub fn expand(patterns: &[String]) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for p in patterns {
        if Path::new(p).exists() {
            out.push(PathBuf::from(p));
            continue;
        }
        let matches = glob::glob(p).map_err(|e| anyhow!("`{p}` is not a valid glob pattern: {e}"))?;
        let mut found: Vec<PathBuf> = matches.filter_map(|m| m.ok()).filter(|m| m.is_file()).collect();
        if found.is_empty() {
            bail!("{p}: no such file (and no file matches it as a glob pattern)");
        }
        found.sort();
        out.append(&mut found);
    }
    Ok(out)
}

/// Warns on stderr about each recording (named in `names`) without a complete step.
pub fn warn_without_steps(names: &[String], result: &TrackResult, options: &GaitOptions) {
    for i in result.recordings_without_steps() {
        eprintln!(
            "warning: {}: no complete step (T/2 = {} s without a gap longer than {} frames); not used",
            names[i],
            options.step_duration(),
            options.max_gap()
        );
    }
}
