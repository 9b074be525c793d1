//! Turning a gappy along-slope coordinate into smooth position and speed: gap interpolation,
//! segmentation at long occlusions, and zero-phase low-pass differentiation.
//!
//! The low-pass filter is a second-order Butterworth run forward and backward (no phase
//! shift, so a speed minimum stays where it is), from the `butterworth` crate, whose
//! `bidirectional` is SciPy's `filtfilt` (odd extension at the ends, steady-state initial
//! conditions). Running a filter twice lowers its -3 dB point; the design cutoff is divided
//! by Winter's correction `C = (2^(1/2) - 1)^(1/4) = 0.802` so that the user's cutoff is
//! the -3 dB point of the combined, zero-phase filter. The speed is the central difference
//! of the filtered position (one-sided at the ends).

use butterworth::{Cutoff, Filter};

use crate::error::ParamError;

/// One stretch of consecutive frames with no gap longer than the allowed one.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// Index of the segment's first frame in the recording.
    pub start: usize,
    /// Along-slope coordinate, m, with short gaps filled by linear interpolation.
    pub along: Vec<f64>,
    /// How many of its frames were interpolated.
    pub interpolated_frames: usize,
}

/// A recording split at its long gaps.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Segmentation {
    /// Segments long enough to analyse, in time order.
    pub segments: Vec<Segment>,
    /// Frames filled by interpolation inside kept segments.
    pub interpolated_frames: usize,
    /// Frames not analysed: inside long gaps, before the first or after the last valid
    /// frame, or in segments shorter than the minimum length.
    pub dropped_frames: usize,
}

/// Splits `along` (NaN where the body was occluded) at gaps longer than `max_gap` frames,
/// fills shorter gaps linearly, and keeps segments of at least `min_frames` frames.
pub fn split_at_gaps(along: &[f64], max_gap: usize, min_frames: usize) -> Segmentation {
    let mut out = Segmentation::default();
    let mut current: Option<Segment> = None;
    let mut last_valid: Option<usize> = None;
    let finish = |seg: Segment, out: &mut Segmentation| {
        if seg.along.len() >= min_frames.max(1) {
            out.interpolated_frames += seg.interpolated_frames;
            out.segments.push(seg);
        } else {
            out.dropped_frames += seg.along.len();
        }
    };
    for (i, &x) in along.iter().enumerate() {
        if !x.is_finite() {
            continue;
        }
        match (last_valid, current.as_mut()) {
            (Some(j), Some(seg)) if i - j - 1 <= max_gap => {
                let x0 = seg.along[seg.along.len() - 1];
                let gap = i - j;
                for k in 1..gap {
                    seg.along.push(x0 + (x - x0) * k as f64 / gap as f64);
                }
                seg.interpolated_frames += gap - 1;
                seg.along.push(x);
            }
            (last, _) => {
                out.dropped_frames += last.map_or(i, |j| i - j - 1);
                if let Some(seg) = current.take() {
                    finish(seg, &mut out);
                }
                current = Some(Segment { start: i, along: vec![x], interpolated_frames: 0 });
            }
        }
        last_valid = Some(i);
    }
    match current {
        Some(seg) => {
            out.dropped_frames += along.len() - seg.start - seg.along.len();
            finish(seg, &mut out);
        }
        None => out.dropped_frames += along.len(),
    }
    out
}

/// Winter's correction for a second-order filter run twice: `(2^(1/2) - 1)^(1/4)`.
pub const TWO_PASS_CORRECTION: f64 = 0.802_411_823_0;

/// A validated zero-phase low-pass differentiator for one frame rate.
#[derive(Debug, Clone)]
pub struct LowPass {
    frame_rate_hz: f64,
    cutoff_hz: f64,
    filter: Filter,
}

impl LowPass {
    /// A low-pass whose combined (forward-backward) -3 dB point is `cutoff_hz`; fails unless
    /// the frame rate is positive and `0 < cutoff_hz < 0.802 * frame_rate_hz / 2` (the
    /// single-pass design cutoff must stay below the Nyquist frequency).
    pub fn new(frame_rate_hz: f64, cutoff_hz: f64) -> Result<LowPass, ParamError> {
        if !(frame_rate_hz.is_finite() && frame_rate_hz > 0.0) {
            return Err(ParamError::new("frame_rate_hz", frame_rate_hz, "a finite number greater than 0"));
        }
        let limit = TWO_PASS_CORRECTION * 0.5 * frame_rate_hz;
        if !(cutoff_hz.is_finite() && cutoff_hz > 0.0 && cutoff_hz < 0.99 * limit) {
            return Err(ParamError::new(
                "cutoff_hz",
                cutoff_hz,
                format!(
                    "greater than 0 and below {:.3} Hz (0.99 x 0.802 x half the frame rate)",
                    0.99 * limit
                ),
            ));
        }
        let design = cutoff_hz / TWO_PASS_CORRECTION;
        let filter = Filter::new(2, frame_rate_hz, Cutoff::LowPass(design)).map_err(|e| {
            ParamError::new("cutoff_hz", cutoff_hz, format!("accepted by the filter design ({e:?})"))
        })?;
        Ok(LowPass { frame_rate_hz, cutoff_hz, filter })
    }

    /// Frame rate, Hz.
    pub fn frame_rate(&self) -> f64 {
        self.frame_rate_hz
    }

    /// Combined -3 dB cutoff, Hz.
    pub fn cutoff(&self) -> f64 {
        self.cutoff_hz
    }

    /// Frames of odd extension at each end: about three filter time constants, at most
    /// `n - 1`.
    fn padding(&self, n: usize) -> usize {
        let pad = (3.0 * self.frame_rate_hz / self.cutoff_hz).ceil() as usize;
        pad.min(n.saturating_sub(1))
    }

    /// Zero-phase low-pass of `x`; returned unchanged when shorter than 3 samples.
    pub fn smooth(&self, x: &[f64]) -> Vec<f64> {
        if x.len() < 3 {
            return x.to_vec();
        }
        let data = x.to_vec();
        // The padding is at most n - 1, which is all the crate requires.
        self.filter.bidirectional_with_padding(&data, self.padding(x.len())).unwrap_or(data)
    }

    /// Estimated standard deviation of the speed noise left after smoothing `raw` into
    /// `smoothed`, m/s: the residual `raw - smoothed` is taken as white position noise of
    /// SD sigma, which after the low-pass and differentiation leaves
    /// `2 pi sigma sqrt(2 fc^3 / (3 fs))` (the integral of `(2 pi f)^2 sigma^2 / (fs/2)`
    /// from 0 to fc).
    pub fn speed_noise(&self, raw: &[f64], smoothed: &[f64]) -> f64 {
        let n = raw.len().min(smoothed.len());
        if n == 0 {
            return 0.0;
        }
        let var = raw.iter().zip(smoothed).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / n as f64;
        let (fc, fs) = (self.cutoff_hz, self.frame_rate_hz);
        std::f64::consts::TAU * var.sqrt() * (2.0 * fc.powi(3) / (3.0 * fs)).sqrt()
    }

    /// Smoothed position and its time derivative (central differences), both per frame.
    pub fn position_and_speed(&self, x: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let pos = self.smooth(x);
        let speed = central_difference(&pos, self.frame_rate_hz);
        (pos, speed)
    }
}

/// `dx/dt` by central differences (one-sided at the ends); zeros for fewer than 2 samples.
pub fn central_difference(x: &[f64], frame_rate_hz: f64) -> Vec<f64> {
    let n = x.len();
    if n < 2 {
        return vec![0.0; n];
    }
    let mut v = Vec::with_capacity(n);
    v.push((x[1] - x[0]) * frame_rate_hz);
    for i in 1..n - 1 {
        v.push((x[i + 1] - x[i - 1]) * 0.5 * frame_rate_hz);
    }
    v.push((x[n - 1] - x[n - 2]) * frame_rate_hz);
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaps_are_filled_or_split() {
        let nan = f64::NAN;
        // frames: nan | 0 1 _ 3 | 9 long gap of 4 | 8 9 10 | nan
        let x = [nan, 0.0, 1.0, nan, 3.0, nan, nan, nan, nan, 8.0, 9.0, 10.0, nan];
        let s = split_at_gaps(&x, 3, 2);
        assert_eq!(s.segments.len(), 2);
        assert_eq!(s.segments[0].start, 1);
        assert_eq!(s.segments[0].along, vec![0.0, 1.0, 2.0, 3.0]);
        assert_eq!(s.segments[1].start, 9);
        assert_eq!(s.interpolated_frames, 1);
        // 1 leading + 4 in the long gap + 1 trailing
        assert_eq!(s.dropped_frames, 6);
        // With max_gap 4 the long gap is filled; with min length 5 the short piece is dropped.
        assert_eq!(split_at_gaps(&x, 4, 2).segments.len(), 1);
        let short = split_at_gaps(&x, 3, 4);
        assert_eq!(short.segments.len(), 1);
        assert_eq!(short.dropped_frames, 9);
        assert_eq!(split_at_gaps(&[nan; 4], 3, 1).dropped_frames, 4);
    }

    #[test]
    fn rejects_cutoffs_at_or_above_nyquist() {
        assert!(LowPass::new(120.0, 10.0).is_ok());
        assert!(LowPass::new(120.0, 48.0).is_err());
        assert!(LowPass::new(120.0, 0.0).is_err());
        assert!(LowPass::new(0.0, 10.0).is_err());
    }

    /// A 2 Hz sinusoid (the step rate) passes a 10 Hz low-pass with its derivative intact;
    /// a 40 Hz ripple on it is removed, and nothing is shifted in time (zero phase).
    #[test]
    fn differentiates_slow_motion_and_removes_fast_ripple() {
        let fs = 120.0;
        let w = 2.0 * std::f64::consts::PI * 2.0;
        let x: Vec<f64> = (0..600)
            .map(|i| {
                let t = i as f64 / fs;
                0.01 * (w * t).sin() + 0.001 * (2.0 * std::f64::consts::PI * 40.0 * t).sin() + 0.1 * t
            })
            .collect();
        let (_, v) = LowPass::new(fs, 10.0).unwrap().position_and_speed(&x);
        for (i, vi) in v.iter().enumerate().take(540).skip(60) {
            let t = i as f64 / fs;
            let exact = 0.01 * w * (w * t).cos() + 0.1;
            // Central difference of a 2 Hz wave loses (1 - sinc) ~ 0.4%; the 10 Hz filter
            // attenuates 2 Hz by < 0.1%; the 40 Hz ripple (0.25 m/s peak in speed) by > 99%.
            assert!((vi - exact).abs() < 0.004, "t = {t}: {vi} vs {exact}");
        }
    }
}
