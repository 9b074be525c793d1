//! Cleaning one recording: what cannot be used is dropped and counted, out-of-order rows are put
//! back in order, and a recording that goes down and back up keeps its downstroke only.

use crate::error::ParamError;

use super::MeasureError;

/// A run of at least this many consecutive samples exactly at the maximum force is taken as
/// sensor saturation.
pub const SATURATION_RUN: usize = 3;
/// A recording whose position falls, after its maximum, by at least this fraction of its
/// range over at least [`SATURATION_RUN`] samples has a return stroke (retraction).
pub const RETRACTION_FRACTION: f64 = 0.05;

/// One trial's columns as read, in file order; `None` is a blank cell.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RawRecording {
    /// Time stamps, s, if the recording has them.
    pub time: Option<Vec<Option<f64>>>,
    /// Depth (penetration) or displacement (shear), m.
    pub position: Vec<Option<f64>>,
    /// Force, N.
    pub force: Vec<Option<f64>>,
    /// Rows the reader skipped because a cell was not a number (when asked to skip them).
    pub malformed: usize,
}

/// What [`clean`] removed or changed, by reason.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct Dropped {
    /// Rows with a cell that was not a number, skipped by the reader.
    pub malformed: usize,
    /// Rows with a blank cell.
    pub blank: usize,
    /// Rows with a NaN or infinite value.
    pub non_finite: usize,
    /// Rows after the deepest point of a recording that goes back up (the return stroke).
    pub retraction: usize,
    /// Repeated samples: the same time stamp (or, without time, the same position and force)
    /// as an earlier row.
    pub duplicate: usize,
    /// Samples at the saturated maximum of the sensor.
    pub saturated: usize,
    /// Rows that were out of order (earlier time, or smaller position without time) and were
    /// put back in order, not dropped.
    pub reordered: usize,
}

impl Dropped {
    /// Rows dropped (reordered rows are kept).
    pub fn total(&self) -> usize {
        self.malformed + self.blank + self.non_finite + self.retraction + self.duplicate + self.saturated
    }
}

/// A clean curve: finite samples sorted by position (depth or displacement, m), force in N.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Curve {
    position: Vec<f64>,
    force: Vec<f64>,
}

impl Curve {
    /// A curve from finite samples (sorted by position here); fails on non-finite values.
    pub fn new(position: Vec<f64>, force: Vec<f64>) -> Result<Curve, MeasureError> {
        if position.len() != force.len() {
            return Err(MeasureError::LengthMismatch(position.len(), force.len()));
        }
        for (&x, &f) in position.iter().zip(&force) {
            if !x.is_finite() {
                return Err(ParamError::new("position", x, "finite").into());
            }
            if !f.is_finite() {
                return Err(ParamError::new("force", f, "finite").into());
            }
        }
        let mut idx: Vec<usize> = (0..position.len()).collect();
        idx.sort_by(|&a, &b| position[a].total_cmp(&position[b]));
        Ok(Curve {
            position: idx.iter().map(|&i| position[i]).collect(),
            force: idx.iter().map(|&i| force[i]).collect(),
        })
    }

    /// Positions (depth or displacement), m, ascending.
    pub fn position(&self) -> &[f64] {
        &self.position
    }

    /// Forces, N, matching [`Curve::position`].
    pub fn force(&self) -> &[f64] {
        &self.force
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }

    /// Mean force, N (0 for an empty curve).
    pub fn mean_force(&self) -> f64 {
        if self.force.is_empty() {
            0.0
        } else {
            self.force.iter().sum::<f64>() / self.force.len() as f64
        }
    }

    /// The force at `x` by linear interpolation, held constant beyond the ends.
    pub fn force_at(&self, x: f64) -> f64 {
        let p = &self.position;
        match p.len() {
            0 => 0.0,
            1 => self.force[0],
            n => {
                if x <= p[0] {
                    return self.force[0];
                }
                if x >= p[n - 1] {
                    return self.force[n - 1];
                }
                let i = p.partition_point(|&v| v <= x).clamp(1, n - 1);
                let (x0, x1, f0, f1) = (p[i - 1], p[i], self.force[i - 1], self.force[i]);
                if x1 > x0 {
                    f0 + (f1 - f0) * (x - x0) / (x1 - x0)
                } else {
                    0.5 * (f0 + f1)
                }
            }
        }
    }

    /// The curve with `offset(x)` subtracted from the force at each position.
    pub fn minus(&self, offset: impl Fn(f64) -> f64) -> Curve {
        let force = self.position.iter().zip(&self.force).map(|(&x, &f)| f - offset(x)).collect();
        Curve { position: self.position.clone(), force }
    }
}

/// A cleaned recording.
#[derive(Debug, Clone, PartialEq)]
pub struct Cleaned {
    /// The usable samples, sorted by position.
    pub curve: Curve,
    /// What was dropped, by reason.
    pub dropped: Dropped,
    /// Position range of the stroke recorded (downstroke, saturated samples included), m.
    pub stroke: (f64, f64),
}

/// Cleans one recording: drops rows with blank cells, NaNs or infinities, the return stroke,
/// repeated samples and saturated samples; puts out-of-order rows back in order; returns the
/// curve sorted by position and what was dropped.
///
/// Acquisition order is by time when the recording has a time column, otherwise the file
/// order. A recording whose position, after its maximum, falls back by at least
/// [`RETRACTION_FRACTION`] of its range over at least [`SATURATION_RUN`] rows goes down and
/// back up: only the downstroke (up to the first sample at the maximum) is kept, and the rows
/// after it are counted as `retraction`. Without time, rows whose position goes backwards on
/// the downstroke are counted as reordered. A repeated sample is a row with the same time
/// stamp as an earlier row (without time: the same position and force). Saturation: when the
/// maximum force occurs in a run of at least [`SATURATION_RUN`] consecutive samples (in
/// acquisition order), every sample at that maximum is dropped (a load cell that saturates
/// reads its full-scale value).
pub fn clean(raw: &RawRecording) -> Result<Cleaned, MeasureError> {
    let n = raw.position.len();
    if raw.force.len() != n {
        return Err(MeasureError::LengthMismatch(n, raw.force.len()));
    }
    if let Some(t) = &raw.time {
        if t.len() != n {
            return Err(MeasureError::LengthMismatch(n, t.len()));
        }
    }
    let mut dropped = Dropped { malformed: raw.malformed, ..Dropped::default() };
    let has_time = raw.time.is_some();
    // (time or file index, position, force) in file order.
    let mut rows: Vec<(f64, f64, f64)> = Vec::with_capacity(n);
    for i in 0..n {
        let t = raw.time.as_ref().map(|t| t[i]);
        let (Some(x), Some(f), Some(t)) = (raw.position[i], raw.force[i], t.unwrap_or(Some(i as f64))) else {
            dropped.blank += 1;
            continue;
        };
        if !(x.is_finite() && f.is_finite() && t.is_finite()) {
            dropped.non_finite += 1;
            continue;
        }
        rows.push((t, x, f));
    }
    if has_time {
        // Out of order in time: a row earlier than the latest row before it.
        let mut latest = f64::NEG_INFINITY;
        for r in &rows {
            if r.0 < latest {
                dropped.reordered += 1;
            }
            latest = latest.max(r.0);
        }
        rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    // The return stroke: rows after the first sample at the deepest position.
    if let Some(deepest) = rows.iter().map(|r| r.1).reduce(f64::max) {
        let shallowest = rows.iter().map(|r| r.1).fold(f64::INFINITY, f64::min);
        let m = rows.iter().position(|r| r.1 == deepest).unwrap_or(0);
        let after = rows.len() - 1 - m;
        let back = rows[m + 1..].iter().map(|r| r.1).fold(deepest, f64::min);
        if after >= SATURATION_RUN && deepest - back >= RETRACTION_FRACTION * (deepest - shallowest) {
            dropped.retraction = after;
            rows.truncate(m + 1);
        }
    }
    if !has_time {
        // Without time the file order is the acquisition order; on a downstroke the position
        // does not go backwards, so a row below the deepest row before it is out of order.
        let mut deepest = f64::NEG_INFINITY;
        for r in &rows {
            if r.1 < deepest {
                dropped.reordered += 1;
            }
            deepest = deepest.max(r.1);
        }
        // Stable: rows at one position keep their file order.
        rows.sort_by(|a, b| a.1.total_cmp(&b.1));
    }
    let stroke = rows.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |s, r| (s.0.min(r.1), s.1.max(r.1)));
    // Repeated samples.
    let mut kept: Vec<(f64, f64, f64)> = Vec::with_capacity(rows.len());
    for r in rows {
        let repeat = if has_time {
            kept.last().is_some_and(|k| k.0 == r.0)
        } else {
            // Sorted by position: equal positions are adjacent; look back over them.
            kept.iter().rev().take_while(|k| k.1 == r.1).any(|k| k.2 == r.2)
        };
        if repeat {
            dropped.duplicate += 1;
        } else {
            kept.push(r);
        }
    }
    // Saturation at the maximum.
    if let Some(max) = kept.iter().map(|r| r.2).reduce(f64::max) {
        let mut longest = 0;
        let mut run = 0;
        for r in &kept {
            run = if r.2 == max { run + 1 } else { 0 };
            longest = longest.max(run);
        }
        if longest >= SATURATION_RUN {
            let before = kept.len();
            kept.retain(|r| r.2 < max);
            dropped.saturated = before - kept.len();
        }
    }
    let curve = Curve::new(kept.iter().map(|r| r.1).collect(), kept.iter().map(|r| r.2).collect())?;
    let stroke = if stroke.0 <= stroke.1 { stroke } else { (0.0, 0.0) };
    Ok(Cleaned { curve, dropped, stroke })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clean_counts_each_defect() {
        let raw = RawRecording {
            time: Some(vec![
                Some(0.0),
                Some(0.1),
                Some(0.1),
                Some(0.3),
                Some(0.2),
                None,
                Some(0.5),
                Some(0.6),
                Some(0.7),
                Some(0.8),
            ]),
            position: vec![
                Some(0.0),
                Some(0.1),
                Some(0.1),
                Some(0.3),
                Some(0.2),
                Some(0.4),
                Some(f64::NAN),
                Some(0.6),
                Some(0.7),
                Some(0.8),
            ],
            force: vec![
                Some(1.0),
                Some(2.0),
                Some(2.0),
                Some(4.0),
                Some(3.0),
                Some(5.0),
                Some(5.0),
                Some(9.0),
                Some(9.0),
                Some(9.0),
            ],
            malformed: 2,
        };
        let c = clean(&raw).unwrap();
        // Row 5: blank time; row 6: NaN; row 2: repeat of row 1's time; row 4 earlier than
        // row 3 (reordered, kept); rows 7-9: three consecutive 9.0 N, the maximum: saturated;
        // the reader skipped 2 malformed rows.
        assert_eq!(
            c.dropped,
            Dropped {
                malformed: 2,
                blank: 1,
                non_finite: 1,
                retraction: 0,
                duplicate: 1,
                saturated: 3,
                reordered: 1
            }
        );
        assert_eq!(c.dropped.total(), 8);
        assert_eq!(c.curve.position(), &[0.0, 0.1, 0.2, 0.3]);
        assert_eq!(c.curve.force(), &[1.0, 2.0, 3.0, 4.0]);
        // The stroke includes the saturated samples.
        assert_eq!(c.stroke, (0.0, 0.8));
    }

    #[test]
    fn two_equal_maxima_are_not_saturation() {
        let raw = RawRecording {
            time: None,
            position: (0..5).map(|i| Some(i as f64)).collect(),
            force: vec![Some(1.0), Some(3.0), Some(3.0), Some(2.0), Some(1.0)],
            malformed: 0,
        };
        assert_eq!(clean(&raw).unwrap().dropped.saturated, 0);
    }

    #[test]
    fn retraction_keeps_the_downstroke_only() {
        // Down 0..=10 mm, back up to 4 mm (6 rows): the return is dropped, with or without time.
        let down: Vec<f64> = (0..=10).map(|i| i as f64 * 1e-3).collect();
        let up: Vec<f64> = (4..10).rev().map(|i| i as f64 * 1e-3).collect();
        let xs: Vec<f64> = down.iter().chain(&up).copied().collect();
        // Force on the way up is lower (unloading): it must not be mixed into the downstroke.
        let fs: Vec<f64> =
            xs.iter().enumerate().map(|(i, x)| if i <= 10 { 100.0 * x } else { 20.0 * x }).collect();
        for time in [false, true] {
            let raw = RawRecording {
                time: time.then(|| (0..xs.len()).map(|i| Some(i as f64 * 0.01)).collect()),
                position: xs.iter().map(|&x| Some(x)).collect(),
                force: fs.iter().map(|&f| Some(f)).collect(),
                malformed: 0,
            };
            let c = clean(&raw).unwrap();
            assert_eq!(c.dropped.retraction, 6);
            assert_eq!(c.dropped.reordered, 0);
            assert_eq!(c.curve.position(), &down[..]);
            assert!(c.curve.force().iter().zip(&down).all(|(f, x)| (f - 100.0 * x).abs() < 1e-12));
        }
        // A swapped pair at the end is not a retraction.
        let raw = RawRecording {
            time: None,
            position: [0.0, 1.0, 2.0, 4.0, 3.0].iter().map(|&x| Some(x)).collect(),
            force: [0.0, 1.0, 2.0, 4.0, 3.0].iter().map(|&x| Some(x)).collect(),
            malformed: 0,
        };
        let c = clean(&raw).unwrap();
        assert_eq!((c.dropped.retraction, c.dropped.reordered, c.curve.len()), (0, 1, 5));
    }
}
