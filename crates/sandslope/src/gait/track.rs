//! Everything `sandslope track` reports for recordings at one slope, as one serialisable
//! value: the pooled means and SDs across steps, per-recording bookkeeping (frames, segments,
//! gaps, where the touchdowns came from) and every step (docs/model.md §11).

use serde::Serialize;

use super::{analyse, GaitAnalysis, GaitError, GaitOptions, GaitSummary, Recording, StepMeasure};
use crate::slope::Slope;

/// Where a recording's touchdowns came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum TouchdownSource {
    /// Given by the caller (e.g. the gait controller's log).
    Given,
    /// Estimated from the speed signal ([`super::estimate_touchdown_offset`]).
    Estimated,
}

/// One recording's bookkeeping.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RecordingSummary {
    /// Frames per second, as recorded.
    pub frame_rate_hz: f64,
    /// Frames in the recording.
    pub frames: usize,
    /// Segments analysed (the recording is split at gaps longer than the limit).
    pub segments: usize,
    /// Frames filled by interpolation.
    pub interpolated_frames: usize,
    /// Frames not analysed (long gaps, ends, too-short segments).
    pub dropped_frames: usize,
    /// Complete steps found.
    pub steps: usize,
    /// Where its touchdowns came from.
    pub touchdowns: TouchdownSource,
    /// The estimated touchdown offset, s, in `[0, T/2)` (touchdowns at `offset + k T/2` in
    /// the recording's clock); `None` when touchdowns were given or none was found.
    pub touchdown_offset_s: Option<f64>,
}

/// One step, with the index of its recording (input order).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StepRow {
    /// Index of the recording it came from.
    pub recording: usize,
    /// The step.
    #[serde(flatten)]
    pub step: StepMeasure,
}

/// What `track` reports: means and sample SDs across all steps of all recordings (SDs `None`
/// with fewer than two values), the settings used, and the details. The full analysis
/// (smoothed tracks, stride-averaged curve) is kept in [`TrackResult::analysis`] for figures
/// and is not serialised.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrackResult {
    /// The recordings' slope, degrees, if known.
    pub slope_deg: Option<f64>,
    /// Means and SDs across all steps of all recordings.
    #[serde(flatten)]
    pub summary: GaitSummary,
    /// Stride period T used, s.
    pub period_s: f64,
    /// Upslope unit vector in the capture frame.
    pub upslope: [f64; 3],
    /// Whether it was estimated from the travel.
    pub upslope_estimated: bool,
    /// Low-pass cutoff, Hz.
    pub cutoff_hz: f64,
    /// Longest interpolated gap, frames.
    pub max_gap_frames: usize,
    /// Segments analysed, all recordings.
    pub segments: usize,
    /// Frames filled by interpolation, all recordings.
    pub interpolated_frames: usize,
    /// Frames not analysed, all recordings.
    pub dropped_frames: usize,
    /// Per recording, in input order.
    pub recordings: Vec<RecordingSummary>,
    /// Every step, in recording order then time order.
    pub per_step: Vec<StepRow>,
    /// The analysis behind the numbers (tracks, touchdowns, stride-averaged curve).
    #[serde(skip)]
    pub analysis: GaitAnalysis,
}

impl TrackResult {
    /// Indices of the recordings in which no complete step was found (not used).
    pub fn recordings_without_steps(&self) -> impl Iterator<Item = usize> + '_ {
        self.recordings.iter().enumerate().filter(|(_, r)| r.steps == 0).map(|(i, _)| i)
    }
}

/// Analyses recordings made at `slope` (if known) and gathers everything `track` reports
/// (docs/model.md §11). Errors as [`analyse`].
pub fn track(
    recordings: &[Recording<'_>],
    options: &GaitOptions,
    slope: Option<Slope>,
) -> Result<TrackResult, GaitError> {
    // Upslope from the frame's vertical axis (with the slope when known, otherwise from the
    // travel's own rise along it): a walk that slides down then reports a negative speed, where
    // orienting the direction of travel by the net motion (analyse's fallback, kept only for
    // level ground and travel across the slope, which have no upslope) would call the slide
    // progress.
    let by_height = match (options.upslope(), options.vertical()) {
        (None, Some(up)) => {
            let all: Vec<&[[f64; 3]]> = recordings.iter().map(|r| r.positions).collect();
            super::direction::principal_direction(&all).and_then(|travel| match slope {
                Some(s) => super::direction::orient_by_height(travel, up, s),
                None => super::direction::orient_by_rise(travel, up),
            })
        }
        _ => None,
    };
    let mut a = match by_height {
        Some(u) => analyse(recordings, &options.with_upslope(u))?,
        None => analyse(recordings, options)?,
    };
    if by_height.is_some() {
        a.upslope_estimated = true;
    }
    let summaries = recordings
        .iter()
        .zip(&a.recordings)
        .map(|(rec, r)| RecordingSummary {
            frame_rate_hz: rec.frame_rate_hz,
            frames: rec.positions.len(),
            segments: r.tracks.len(),
            interpolated_frames: r.interpolated_frames,
            dropped_frames: r.dropped_frames,
            steps: r.steps.len(),
            touchdowns: if rec.touchdowns_s.is_some() {
                TouchdownSource::Given
            } else {
                TouchdownSource::Estimated
            },
            touchdown_offset_s: r.touchdown_offset.map(|o| o.offset_s),
        })
        .collect();
    let per_step = a
        .recordings
        .iter()
        .enumerate()
        .flat_map(|(recording, r)| r.steps.iter().map(move |&step| StepRow { recording, step }))
        .collect();
    Ok(TrackResult {
        slope_deg: slope.map(Slope::degrees),
        summary: a.summary,
        period_s: options.stride_period(),
        upslope: a.upslope.vector(),
        upslope_estimated: a.upslope_estimated,
        cutoff_hz: options.cutoff(),
        max_gap_frames: options.max_gap(),
        segments: a.recordings.iter().map(|r| r.tracks.len()).sum(),
        interpolated_frames: a.recordings.iter().map(|r| r.interpolated_frames).sum(),
        dropped_frames: a.recordings.iter().map(|r| r.dropped_frames).sum(),
        recordings: summaries,
        per_step,
        analysis: a,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gait::synthetic::StepProfile;
    use crate::gait::tests::recording;

    /// Two recordings of a known profile, one with a 40-frame occlusion and one with its
    /// true touchdowns given: the pooled numbers are the profile's, the bookkeeping adds up.
    #[test]
    fn pools_recordings_and_keeps_their_bookkeeping() {
        let profile = StepProfile::new(0.5, 0.12, 0.40, 0.12, 0.30).unwrap();
        let dir = [0.9, 0.0, 0.435_889_894_354_067_4];
        let mut a = recording(&profile, dir, 1200, 0.2, 3e-4);
        for p in &mut a[600..640] {
            *p = [f64::NAN; 3];
        }
        let b = recording(&profile, dir, 1200, 0.2, 3e-4);
        let truth: Vec<f64> = (0..20).map(|k| 0.2 + 0.5 * k as f64).collect();
        let recs = [
            Recording { positions: &a, frame_rate_hz: 120.0, start_time_s: 0.0, touchdowns_s: None },
            Recording { positions: &b, frame_rate_hz: 120.0, start_time_s: 0.0, touchdowns_s: Some(&truth) },
        ];
        let r =
            track(&recs, &GaitOptions::new(1.0).unwrap(), Some(Slope::from_degrees(10.0).unwrap())).unwrap();
        assert_eq!(r.slope_deg, Some(10.0));
        assert_eq!((r.recordings[0].segments, r.recordings[0].dropped_frames), (2, 40));
        assert_eq!(r.recordings[1].touchdowns, TouchdownSource::Given);
        assert_eq!(r.recordings[1].touchdown_offset_s, None);
        let offset = r.recordings[0].touchdown_offset_s.unwrap();
        assert!((offset - 0.2).abs() < 1.0 / 120.0, "{offset}");
        assert_eq!(r.summary.steps, r.per_step.len());
        assert_eq!(r.summary.steps, r.recordings.iter().map(|x| x.steps).sum::<usize>());
        assert_eq!(r.segments, 3);
        assert!(r.per_step.iter().any(|s| s.recording == 1));
        // The profile's mean speed (a difference of positions over 0.5 s: 1 mm/s for noise).
        assert!((r.summary.speed_m_s - profile.mean_speed()).abs() < 1e-3);
        assert!(r.summary.speed_sd_m_s.unwrap() < 0.01);
        assert_eq!(r.recordings_without_steps().count(), 0);
    }
}
