//! `sandslope track`: speed, anchoring time and slip from motion-capture recordings
//! (docs/model.md §11), pooled over the files given for one slope; optionally appends the
//! mean speed to a speeds file for `sandslope calibrate` and draws the paper's Fig. 3b (and
//! Fig. 3a once the speeds file holds several slopes).

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;

use sandslope::gait::{TouchdownSource, TrackResult};
use sandslope_request::error::Words;
use sandslope_request::track::{TrackRequest, SLOPE};

use crate::args::{FieldArgs, RobotArgs, TerrainArgs};
use crate::mocap_input::{expand, warn_without_steps};
use crate::output::{csv_string, num, print_json, table, write_atomic, Format, FormatArgs};
use sandslope_io::mocap::Capture;
use sandslope_io::{parse_speeds, SpeedRow};

/// Arguments of `sandslope track`.
#[derive(Debug, Args)]
pub struct TrackArgs {
    /// Recordings at one slope (files or glob patterns such as `runs/10deg-*.csv`), pooled.
    #[arg(required = true, value_name = "FILE|GLOB")]
    pub files: Vec<String>,
    /// `--format`, `--body`, `--topic`, `--frame`, `--upslope`, `--max-gap`, `--cutoff`,
    /// `--touchdowns` and `--slope`: the request's own fields
    /// ([`sandslope_request::track::FIELDS`]).
    #[command(flatten)]
    pub fields: FieldArgs<TrackRequest>,
    #[command(flatten)]
    pub robot: RobotArgs,
    #[command(flatten)]
    pub terrain: TerrainArgs,
    /// Append `slope_deg,speed_m_s,speed_sd_m_s` to this file (created with a header), the
    /// format `sandslope calibrate` reads; needs --slope.
    #[arg(long, value_name = "FILE")]
    pub speeds_out: Option<PathBuf>,
    /// Draw the speed within a stride (mean, SD band, t1) to this PNG or SVG; with a
    /// --speeds-out file holding several slopes, also speed against slope with the model.
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    #[command(flatten)]
    pub format_args: FormatArgs,
}

/// Appends one row to a speeds file (creating it with its header), atomically, after checking
/// that the existing file is one `sandslope calibrate` can read; returns all rows now in it.
fn append_speed(path: &Path, row: SpeedRow) -> Result<Vec<SpeedRow>> {
    const HEADER: &str = "slope_deg,speed_m_s,speed_sd_m_s";
    let existing = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
        Err(e) => return Err(anyhow!("cannot read {}: {e}", path.display())),
    };
    let mut text = existing.clone();
    if existing.trim().is_empty() {
        text = format!("{HEADER}\n");
    } else {
        parse_speeds(&existing, path)?;
        if !text.ends_with('\n') {
            text.push('\n');
        }
    }
    text.push_str(&format!("{},{},{}\n", row.slope_deg, row.speed_m_s, row.speed_sd_m_s));
    // The rows as the file will hold them, read from the text (the file itself is put in
    // place only when the whole run has succeeded).
    let rows = parse_speeds(&text, path)?;
    write_atomic(path, text.as_bytes())?;
    Ok(rows
        .into_iter()
        .map(|o| SpeedRow { slope_deg: o.slope.degrees(), speed_m_s: o.speed, speed_sd_m_s: o.speed_sd })
        .collect())
}

/// Runs `sandslope track`.
pub fn run(args: TrackArgs) -> Result<()> {
    for p in [&args.speeds_out, &args.plot].into_iter().flatten() {
        crate::output::check_parent_exists(p)?;
    }
    // --leg-speed (the robot's, shared by every command) sets the stride period T = 2 pi / omega,
    // and the model curve of --plot is that robot's too.
    let robot = args.robot.load()?;
    // The flags read by the request layer's one raw-to-typed step, on the files expanded.
    let request = TrackRequest::from_fields(&args.fields.pairs, Vec::new(), robot.stride_period())?;
    // --slope is checked once, by the request (a slope from 0 to below 90 degrees).
    let slope = request.slope_deg;
    if args.speeds_out.is_some() && slope.is_none() {
        bail!("--speeds-out needs {} (the slope of these recordings, degrees)", SLOPE.long());
    }
    if let Some(p) = &args.plot {
        crate::figures::format_of(p)?;
    }
    let request = TrackRequest { files: expand(&args.files)?, ..request };
    let (options, _) = request.options(Words::Flag)?;
    // Large exports take a while to parse: a bar on a terminal, nothing when piped.
    let n = request.files.len() as u64;
    let bar = crate::progress::progress_bar(n, n < 2, "reading recordings");
    let tracked = request.answer(Words::Flag, &mut || bar.inc(1));
    bar.finish_and_clear();
    let tracked = tracked?;
    warn_without_steps(&tracked.names, &tracked.result, &options);
    let result = &tracked.result;

    let mut campaign = None;
    if let (Some(path), Some(slope_deg)) = (&args.speeds_out, slope) {
        let sd = match result.summary.speed_sd_m_s {
            Some(sd) if sd > 0.0 => sd,
            _ => bail!(
                "cannot append to {}: the speed SD needs at least two steps with different speeds (found {} steps)",
                path.display(),
                result.summary.steps
            ),
        };
        let rows =
            append_speed(path, SpeedRow { slope_deg, speed_m_s: result.summary.speed_m_s, speed_sd_m_s: sd })
                .with_context(|| format!("appending to {}", path.display()))?;
        campaign = Some(rows);
    }
    if let Some(path) = &args.plot {
        let overlay = campaign.filter(|rows| {
            let mut s: Vec<f64> = rows.iter().map(|r| r.slope_deg).collect();
            s.sort_by(f64::total_cmp);
            s.dedup();
            s.len() >= 2
        });
        // The model's speed against slope beside a campaign (Fig. 3a), from the library.
        let model = match &overlay {
            Some(rows) => {
                let top = rows.iter().map(|r| r.slope_deg).fold(0.0, f64::max);
                sandslope_request::track::model_curve(&robot, args.terrain.load()?, top)?
            }
            None => Vec::new(),
        };
        let fig = crate::figures::track::TrackFigure::new(result, overlay, &model);
        crate::figures::save(path, &fig)?;
    }

    match args.format_args.format() {
        Format::Json => print_json(&tracked.answer()?),
        Format::Csv => {
            print!("{}", csv_string(&tracked.step_records())?);
            Ok(())
        }
        Format::Table => {
            print_table(result, &tracked.captures, &tracked.names);
            Ok(())
        }
    }
}

fn print_table(r: &TrackResult, captures: &[Capture], names: &[String]) {
    let pm = |m: Option<f64>, sd: Option<f64>, scale: f64, d: usize| match (m, sd) {
        (Some(m), Some(sd)) => format!("{:.d$} ± {:.d$}", m * scale, sd * scale),
        (Some(m), None) => format!("{:.d$}", m * scale),
        _ => "-".into(),
    };
    let s = &r.summary;
    let mut t = table(&["quantity", "mean ± SD across steps", "unit"]);
    let rows: Vec<[String; 3]> = vec![
        ["slope".into(), num(r.slope_deg, 1), "deg".into()],
        ["step-averaged speed v".into(), pm(Some(s.speed_m_s), s.speed_sd_m_s, 100.0, 2), "cm/s".into()],
        ["anchoring time t1".into(), pm(s.t1_s, s.t1_sd_s, 1e3, 1), "ms".into()],
        ["backward slip s1".into(), pm(s.slip_m, s.slip_sd_m, 1e3, 2), "mm".into()],
        ["net step s".into(), pm(Some(s.step_m), s.step_sd_m, 1e3, 2), "mm".into()],
        ["steps (unanchored)".into(), format!("{} ({})", s.steps, s.unanchored_steps), "".into()],
        ["stride period T".into(), format!("{:.3}", r.period_s), "s".into()],
        [
            format!("upslope direction{}", if r.upslope_estimated { " (estimated)" } else { "" }),
            format!("[{:.3}, {:.3}, {:.3}]", r.upslope[0], r.upslope[1], r.upslope[2]),
            "".into(),
        ],
    ];
    for row in rows {
        t.add_row(row);
    }
    println!("{t}");
    let mut f = table(&[
        "file",
        "body",
        "fps",
        "frames",
        "segments",
        "interp.",
        "dropped",
        "steps",
        "touchdown offset",
    ]);
    for ((rec, c), name) in r.recordings.iter().zip(captures).zip(names) {
        f.add_row([
            name.clone(),
            c.body.clone(),
            fps(rec.frame_rate_hz),
            rec.frames.to_string(),
            rec.segments.to_string(),
            rec.interpolated_frames.to_string(),
            rec.dropped_frames.to_string(),
            rec.steps.to_string(),
            match (rec.touchdown_offset_s, rec.touchdowns) {
                (Some(p), _) => format!("{:.1} ms (estimated)", p * 1e3),
                (None, TouchdownSource::Given) => "given (--touchdowns)".into(),
                (None, TouchdownSource::Estimated) => "none found".into(),
            },
        ]);
    }
    println!("{f}");
}

/// A frame rate for people: whole numbers as such, otherwise three decimals (Motive writes
/// 119.99999666435033 for a 120 Hz capture).
fn fps(hz: f64) -> String {
    let s = format!("{hz:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

#[cfg(test)]
mod tests {
    use super::fps;

    #[test]
    fn frame_rates_are_rounded_for_people() {
        assert_eq!(fps(119.999_996_664_350_33), "120");
        assert_eq!(fps(100.0), "100");
        assert_eq!(fps(59.94), "59.94");
        assert_eq!(fps(29.970_03), "29.97");
    }
}
