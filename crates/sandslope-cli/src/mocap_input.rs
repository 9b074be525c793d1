//! Motion-capture input shared by `sandslope track` and `sandslope report --tracks`: the
//! parsers of the format and upslope flags, the expansion of file arguments (paths or glob
//! patterns), touchdown files, and the one path from capture files to the library's
//! [`track()`] (read every file, build the [`Recording`]s, run the analysis of docs/model.md
//! §11, name the file in any error). Commands share this code through this module, never
//! through each other.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Result};

use sandslope::gait::{track, GaitOptions, Recording, TrackResult, Upslope};
use sandslope::Slope;
use sandslope_io::mocap::{self, Capture, MocapFormat};

use crate::progress::progress_bar;

/// Parses a motion-capture format flag (`motive`, `vicon` or `plain`).
pub fn parse_mocap_format(s: &str) -> Result<MocapFormat, String> {
    s.parse()
}

/// Parses an upslope flag: `+x`, `-x`, `+y`, `-y`, `+z`, `-z` (or `x`, `y`, `z`) or a vector
/// `x,y,z`; `flag` names the flag in the message when the vector is zero or not finite.
pub fn parse_upslope(s: &str, flag: &str) -> Result<Upslope, String> {
    let axis = |i: usize, sign: f64| {
        let mut v = [0.0; 3];
        v[i] = sign;
        v
    };
    let v = match s.trim().to_ascii_lowercase().as_str() {
        "+x" | "x" => axis(0, 1.0),
        "-x" => axis(0, -1.0),
        "+y" | "y" => axis(1, 1.0),
        "-y" => axis(1, -1.0),
        "+z" | "z" => axis(2, 1.0),
        "-z" => axis(2, -1.0),
        other => {
            let parts: Vec<&str> = other.split(',').map(str::trim).collect();
            let nums: Option<Vec<f64>> = parts.iter().map(|p| p.parse::<f64>().ok()).collect();
            match nums.as_deref() {
                Some([x, y, z]) => [*x, *y, *z],
                _ => return Err(format!("`{s}` must be +x, -x, +y, -y, +z, -z or three numbers `x,y,z`")),
            }
        }
    };
    Upslope::new(v).map_err(|e| e.renamed(flag).to_string())
}

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

/// How to read a set of capture files (the `--format` and `--body` flags).
#[derive(Debug, Clone, Copy)]
pub struct CaptureOptions<'a> {
    /// File format; detected from each file's first line when `None`.
    pub format: Option<MocapFormat>,
    /// Rigid body, marker or model output to track (required when a file has several).
    pub body: Option<&'a str>,
    /// The flag that sets the low-pass cutoff, to name in a cutoff error (`None`: the
    /// default cutoff, named as the library names it).
    pub cutoff_flag: Option<&'a str>,
}

/// Recordings read and analysed together: the captures in input order, their display
/// names, and the library's result.
#[derive(Debug)]
pub struct Tracked {
    /// The captures, in the order of the files.
    pub captures: Vec<Capture>,
    /// Each capture's path as displayed.
    pub names: Vec<String>,
    /// The pooled analysis.
    pub result: TrackResult,
}

/// Reads `files` (a progress bar on a terminal when there are several), analyses them pooled
/// with `options` at `slope` (if known), and warns on stderr about recordings without a
/// complete step. `touchdowns` holds one touchdowns file per capture file (one time in
/// seconds per line), or is empty to estimate them. Errors name the file (and line, for a
/// malformed file).
pub fn track_files(
    files: &[PathBuf],
    read: CaptureOptions<'_>,
    touchdowns: &[PathBuf],
    options: &GaitOptions,
    slope: Option<Slope>,
) -> Result<Tracked> {
    // Large exports take a while to parse: a bar on a terminal, nothing when piped.
    let bar = progress_bar(files.len() as u64, files.len() < 2, "reading recordings");
    let captures: Vec<Capture> = files
        .iter()
        .map(|f| {
            let c = mocap::read(f, read.format, read.body);
            bar.inc(1);
            c
        })
        .collect::<Result<_>>()?;
    bar.finish_and_clear();
    let touchdowns: Vec<Vec<f64>> =
        touchdowns.iter().map(|p| sandslope_io::mocap::load_touchdowns(p)).collect::<Result<_>>()?;
    let recordings: Vec<Recording> =
        captures.iter().enumerate().map(|(i, c)| c.recording(touchdowns.get(i).map(Vec::as_slice))).collect();
    // Upslope rises along the capture frame's vertical axis, when the files agree on one.
    let mut options = *options;
    if let [first, rest @ ..] = captures.as_slice() {
        if options.vertical().is_none() && rest.iter().all(|c| c.format == first.format) {
            if let Ok(up) = sandslope::gait::Upslope::new(first.format.vertical_axis()) {
                options = options.with_vertical(up);
            }
        }
    }
    let result = track(&recordings, &options, slope).map_err(|e| match e {
        sandslope::GaitError::Param { index, source } => {
            let source = match read.cutoff_flag {
                Some(flag) if source.key == "cutoff_hz" => source.renamed(flag),
                _ => source,
            };
            anyhow!(
                "{}: {source} (at its frame rate {} Hz)",
                captures[index].path.display(),
                captures[index].frame_rate_hz
            )
        }
        // Errors of the pooled analysis name the recordings they are about.
        other => match captures.as_slice() {
            [one] => anyhow!("{}: {other}", one.path.display()),
            many => anyhow!(
                "{} recordings ({}{}): {other}",
                many.len(),
                many.iter().take(3).map(|c| c.path.display().to_string()).collect::<Vec<_>>().join(", "),
                if many.len() > 3 { ", ..." } else { "" }
            ),
        },
    })?;
    let names: Vec<String> = captures.iter().map(|c| c.path.display().to_string()).collect();
    for i in result.recordings_without_steps() {
        eprintln!(
            "warning: {}: no complete step (T/2 = {} s without a gap longer than {} frames); not used",
            names[i],
            options.step_duration(),
            options.max_gap()
        );
    }
    Ok(Tracked { captures, names, result })
}
