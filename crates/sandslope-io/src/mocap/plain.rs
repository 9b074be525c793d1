//! Plain CSV: a header with `time_s` and `x_m,y_m,z_m` (or `x_mm,y_mm,z_mm`), one row per
//! frame; other columns are ignored, empty position cells are occlusions, and missing rows
//! (a time step skipped) are occlusions too. The frame rate is 1 / the median time step.

use anyhow::Result;

use super::Rows;

pub(crate) fn parse(rows: &Rows) -> Result<super::motive::Parsed> {
    let Some((head_line, head)) = rows.rows.first() else {
        return Err(anyhow::anyhow!("{}: the file is empty", rows.path.display()));
    };
    let find = |name: &str| head.iter().position(|c| c == name);
    let time = find("time_s").ok_or_else(|| rows.err(*head_line, "no `time_s` column in the header"))?;
    let (cols, scale) =
        match (find("x_m"), find("y_m"), find("z_m"), find("x_mm"), find("y_mm"), find("z_mm")) {
            (Some(x), Some(y), Some(z), _, _, _) => ([x, y, z], 1.0),
            (_, _, _, Some(x), Some(y), Some(z)) => ([x, y, z], 1e-3),
            _ => return Err(rows.err(
                *head_line,
                "no position columns: the header needs x_m,y_m,z_m (metres) or x_mm,y_mm,z_mm (millimetres)",
            )),
        };
    let mut samples: Vec<(u64, f64, [f64; 3])> = Vec::with_capacity(rows.rows.len());
    for (line, r) in &rows.rows[1..] {
        let t = r.get(time).unwrap_or("");
        let t =
            t.parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| {
                rows.err(*line, format!("column {} (time_s): `{t}` is not a number", time + 1))
            })?;
        if let Some((_, prev, _)) = samples.last() {
            if t <= *prev {
                return Err(
                    rows.err(*line, format!("time_s = {t} must be greater than the previous row's {prev}"))
                );
            }
        }
        let mut p = [0.0; 3];
        for (k, &c) in cols.iter().enumerate() {
            p[k] = rows.position_cell(*line, r, c, ["x", "y", "z"][k])? * scale;
        }
        samples.push((*line, t, p));
    }
    if samples.len() < 2 {
        return Err(rows.err(*head_line, "need at least two data rows to know the frame rate"));
    }
    let mut steps: Vec<f64> = samples.windows(2).map(|w| w[1].1 - w[0].1).collect();
    steps.sort_by(f64::total_cmp);
    let t0 = samples[0].1;
    // The median step, refined over the whole span (times are often printed rounded).
    let median = steps[steps.len() / 2];
    let span = samples[samples.len() - 1].1 - t0;
    let dt = span / (span / median).round().max(1.0);
    // Missing frames are filled with NaN: decided before filling, so that one wrong time
    // (0.2 s, then 655360.2 s) cannot ask for 78 million frames (found by scripts/fuzz.sh).
    let rows_read = samples.len() as f64;
    let max_frames = (MISSING_PER_ROW * rows_read).max(MIN_MISSING_ALLOWED) + rows_read;
    let mut positions = Vec::with_capacity(samples.len());
    for (line, t, p) in samples {
        let x = (t - t0) / dt;
        let index = x.round();
        if (x - index).abs() > 0.25 {
            return Err(rows.err(
                line,
                format!("time_s = {t} is off the regular grid of {dt} s steps from {t0}; resample the file"),
            ));
        }
        if index >= max_frames {
            return Err(rows.err(
                line,
                format!(
                    "time_s = {t} is frame {index} of {dt} s steps from {t0}, but the file has only {} rows: \
                     at most {} frames may be missing (a wrong time, or a recording to split)",
                    rows_read,
                    max_frames - rows_read
                ),
            ));
        }
        positions.resize(index as usize, [f64::NAN; 3]);
        positions.push(p);
    }
    Ok(("body".into(), 1.0 / dt, t0, positions))
}

/// Frames that may be missing per row read (beyond [`MIN_MISSING_ALLOWED`]): a recording that is
/// mostly gaps is a wrong time column, not an occluded marker.
const MISSING_PER_ROW: f64 = 10.0;
/// Missing frames always allowed (about 14 minutes at 120 Hz).
const MIN_MISSING_ALLOWED: f64 = 100_000.0;
