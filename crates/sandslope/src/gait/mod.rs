//! Gait tracking: speed, anchoring time and slip from motion capture (docs/model.md §11).
//!
//! Works on plain arrays of body positions (frames with a non-finite coordinate are
//! occluded); file formats are the caller's business. The pipeline, per recording:
//! project on the upslope direction ([`direction`]), fill short gaps and split at long ones,
//! low-pass and differentiate without phase shift ([`signal`]), place touchdowns every T/2
//! (given, or estimated from the speed's periodic structure), and measure each step's
//! anchoring time t1, backward slip, net step and speed ([`steps`]). [`analyse`] runs it all
//! on several recordings at one slope and pools their steps; [`track()`] adds everything the
//! `track` command reports ([`TrackResult`]).

pub mod direction;
pub mod signal;
pub mod steps;
#[cfg(any(test, feature = "test-support"))]
pub mod synthetic;
pub mod track;

pub use direction::{principal_direction, project, Upslope};
pub use signal::{split_at_gaps, LowPass, Segment, Segmentation};
pub use steps::{
    estimate_touchdown_offset, measure_step, stride_curve, summarize, touchdowns_in, GaitSummary,
    SmoothTrack, Stats, StepMeasure, StrideCurve, TouchdownOffset, REST_SPEED_FRACTION,
};
pub use track::{track, RecordingSummary, StepRow, TouchdownSource, TrackResult};

use crate::error::{positive, ParamError};

/// Default low-pass cutoff, Hz. Steps come at 2/T = 2 Hz for the paper's robot (T = 1 s);
/// the features to resolve (slip to t1 within 10-150 ms, the propulsion rise) need about
/// the first five harmonics, i.e. up to 10 Hz. At 120 frames/s, white position noise of
/// sigma leaves about `2 pi sigma sqrt(2 fc^3 / (3 fs))` of speed noise: 0.3 mm gives about
/// 4 mm/s at 10 Hz, small beside speeds of 5-16 cm/s.
pub const DEFAULT_CUTOFF_HZ: f64 = 10.0;

/// Default longest occlusion that is interpolated, frames (83 ms at 120 frames/s, a sixth of
/// a step: linear interpolation over it cannot hide a whole slip phase).
pub const DEFAULT_MAX_GAP: usize = 10;

/// Points of the stride-averaged speed curve when the caller has no preference.
pub const DEFAULT_CURVE_POINTS: usize = 121;

/// How to analyse recordings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaitOptions {
    stride_period_s: f64,
    cutoff_hz: f64,
    max_gap_frames: usize,
    upslope: Option<Upslope>,
    vertical: Option<Upslope>,
    curve_points: usize,
}

impl GaitOptions {
    /// Options with stride period `T` (s, > 0; touchdowns every T/2), the default cutoff
    /// and gap, and the upslope direction estimated from the travel.
    pub fn new(stride_period_s: f64) -> Result<GaitOptions, ParamError> {
        Ok(GaitOptions {
            stride_period_s: positive("stride_period_s", stride_period_s)?,
            cutoff_hz: DEFAULT_CUTOFF_HZ,
            max_gap_frames: DEFAULT_MAX_GAP,
            upslope: None,
            vertical: None,
            curve_points: DEFAULT_CURVE_POINTS,
        })
    }

    /// Low-pass cutoff, Hz (checked against each recording's frame rate by [`analyse`]).
    pub fn with_cutoff(self, cutoff_hz: f64) -> Result<GaitOptions, ParamError> {
        Ok(GaitOptions { cutoff_hz: positive("cutoff_hz", cutoff_hz)?, ..self })
    }

    /// Longest occlusion filled by interpolation, frames.
    pub fn with_max_gap(self, frames: usize) -> GaitOptions {
        GaitOptions { max_gap_frames: frames, ..self }
    }

    /// A fixed upslope direction instead of the estimate.
    pub fn with_upslope(self, upslope: Upslope) -> GaitOptions {
        GaitOptions { upslope: Some(upslope), ..self }
    }

    /// The capture frame's vertical (up) axis. With it, [`track()`] orients the estimated
    /// direction of travel so that upslope rises: by the known slope
    /// ([`direction::orient_by_height`]) or, without one, by the travel's own rise
    /// ([`direction::orient_by_rise`]); never by the net motion on a slope.
    pub fn with_vertical(self, up: Upslope) -> GaitOptions {
        GaitOptions { vertical: Some(up), ..self }
    }

    /// The capture frame's vertical axis, if given.
    pub fn vertical(&self) -> Option<Upslope> {
        self.vertical
    }

    /// The fixed upslope direction, if given.
    pub fn upslope(&self) -> Option<Upslope> {
        self.upslope
    }

    /// Points of the stride-averaged speed curve (at least 2).
    pub fn with_curve_points(self, points: usize) -> GaitOptions {
        GaitOptions { curve_points: points.max(2), ..self }
    }

    /// Stride period T, s.
    pub fn stride_period(&self) -> f64 {
        self.stride_period_s
    }

    /// Step duration T/2, s.
    pub fn step_duration(&self) -> f64 {
        0.5 * self.stride_period_s
    }

    /// Low-pass cutoff, Hz.
    pub fn cutoff(&self) -> f64 {
        self.cutoff_hz
    }

    /// Longest interpolated gap, frames.
    pub fn max_gap(&self) -> usize {
        self.max_gap_frames
    }
}

/// One recording: body positions at a constant frame rate, m.
#[derive(Debug, Clone, Copy)]
pub struct Recording<'a> {
    /// Positions `[x, y, z]` per frame, m; any non-finite coordinate marks an occluded frame.
    pub positions: &'a [[f64; 3]],
    /// Frames per second.
    pub frame_rate_hz: f64,
    /// Time of the first frame in the recording's clock, s.
    pub start_time_s: f64,
    /// Touchdown times in the same clock, s, if known (e.g. from the gait controller's log);
    /// estimated from the speed signal otherwise.
    pub touchdowns_s: Option<&'a [f64]>,
}

/// What was found in one recording.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordingAnalysis {
    /// Analysed segments, smoothed.
    pub tracks: Vec<SmoothTrack>,
    /// Touchdowns used in each track.
    pub touchdowns: Vec<Vec<f64>>,
    /// The estimated touchdown offset (`None` when touchdowns were given or no segment was
    /// long enough).
    pub touchdown_offset: Option<TouchdownOffset>,
    /// Frames filled by interpolation.
    pub interpolated_frames: usize,
    /// Frames not analysed (long gaps, ends, too-short segments).
    pub dropped_frames: usize,
    /// Its steps, in time order.
    pub steps: Vec<StepMeasure>,
}

/// Pooled result for recordings at one slope.
#[derive(Debug, Clone, PartialEq)]
pub struct GaitAnalysis {
    /// Upslope direction used.
    pub upslope: Upslope,
    /// Whether it was estimated (principal direction of travel).
    pub upslope_estimated: bool,
    /// Per-recording details, in input order.
    pub recordings: Vec<RecordingAnalysis>,
    /// Summary over all steps of all recordings.
    pub summary: GaitSummary,
    /// Speed averaged over strides against time since touchdown (`None` if no whole stride was recorded).
    pub curve: Option<StrideCurve>,
}

impl GaitAnalysis {
    /// All steps of all recordings.
    pub fn steps(&self) -> impl Iterator<Item = &StepMeasure> {
        self.recordings.iter().flat_map(|r| r.steps.iter())
    }
}

/// Why recordings could not be analysed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GaitError {
    /// No upslope direction was given and the body did not move.
    #[error("cannot estimate the upslope direction: the body did not move (give it explicitly)")]
    NoDirection,
    /// A recording's frame rate or the cutoff is invalid.
    #[error("recording {index}: {source}")]
    Param {
        /// Index of the recording.
        index: usize,
        /// The invalid parameter.
        source: ParamError,
    },
    /// Not a single whole step was found.
    #[error(
        "no complete step found: every recording needs at least one stretch of T/2 = {step_s} s without a gap \
         longer than {max_gap} frames"
    )]
    NoSteps {
        /// Step duration, s.
        step_s: f64,
        /// Longest interpolated gap, frames.
        max_gap: usize,
    },
}

/// Analyses recordings made at one slope and pools their steps (docs/model.md §11).
pub fn analyse(recordings: &[Recording<'_>], options: &GaitOptions) -> Result<GaitAnalysis, GaitError> {
    let (upslope, estimated) = match options.upslope {
        Some(u) => (u, false),
        None => {
            let all: Vec<&[[f64; 3]]> = recordings.iter().map(|r| r.positions).collect();
            (principal_direction(&all).ok_or(GaitError::NoDirection)?, true)
        }
    };
    let step_s = options.step_duration();
    let mut results = Vec::with_capacity(recordings.len());
    for (index, rec) in recordings.iter().enumerate() {
        let filter = LowPass::new(rec.frame_rate_hz, options.cutoff_hz)
            .map_err(|source| GaitError::Param { index, source })?;
        let min_frames = (step_s * rec.frame_rate_hz).ceil() as usize + 2;
        let along = project(rec.positions, upslope);
        let seg = split_at_gaps(&along, options.max_gap_frames, min_frames);
        let tracks: Vec<SmoothTrack> = seg
            .segments
            .iter()
            .map(|s| {
                let (position, speed) = filter.position_and_speed(&s.along);
                let speed_noise_m_s = filter.speed_noise(&s.along, &position);
                SmoothTrack {
                    speed_noise_m_s,
                    rest_speed_m_s: REST_SPEED_FRACTION * speed_noise_m_s,
                    start_time_s: rec.start_time_s + s.start as f64 / rec.frame_rate_hz,
                    frame_rate_hz: rec.frame_rate_hz,
                    position,
                    speed,
                }
            })
            .collect();
        let (touchdown_offset, touchdowns): (Option<TouchdownOffset>, Vec<Vec<f64>>) = match rec.touchdowns_s
        {
            Some(given) => {
                let per_track = tracks
                    .iter()
                    .map(|t| given.iter().copied().filter(|&t0| t.covers(t0, step_s)).collect())
                    .collect();
                (None, per_track)
            }
            None => {
                let offset = estimate_touchdown_offset(&tracks, step_s);
                let per_track = match offset {
                    Some(p) => tracks.iter().map(|t| touchdowns_in(t, p.offset_s, step_s)).collect(),
                    None => vec![Vec::new(); tracks.len()],
                };
                (offset, per_track)
            }
        };
        let steps = tracks
            .iter()
            .zip(&touchdowns)
            .flat_map(|(t, tds)| tds.iter().map(move |&t0| measure_step(t, t0, step_s)))
            .collect();
        results.push(RecordingAnalysis {
            tracks,
            touchdowns,
            touchdown_offset,
            interpolated_frames: seg.interpolated_frames,
            dropped_frames: seg.dropped_frames,
            steps,
        });
    }
    let all_steps: Vec<StepMeasure> = results.iter().flat_map(|r| r.steps.iter().copied()).collect();
    let summary =
        summarize(&all_steps).ok_or(GaitError::NoSteps { step_s, max_gap: options.max_gap_frames })?;
    let pairs: Vec<(&SmoothTrack, &[f64])> =
        results.iter().flat_map(|r| r.tracks.iter().zip(r.touchdowns.iter().map(|v| v.as_slice()))).collect();
    let curve = stride_curve(&pairs, options.stride_period_s, options.curve_points);
    Ok(GaitAnalysis { upslope, upslope_estimated: estimated, recordings: results, summary, curve })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::synthetic::StepProfile;
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// Positions of a body following `profile` upslope along `dir`, with touchdowns at
    /// `offset + k T/2` in the recording clock, 1 cm of lateral sway at the stride rate and
    /// Gaussian noise of `noise` m per axis (Box-Muller on a seeded generator).
    pub(crate) fn recording(
        profile: &StepProfile,
        dir: [f64; 3],
        frames: usize,
        offset: f64,
        noise: f64,
    ) -> Vec<[f64; 3]> {
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let mut gauss = move || {
            let (u1, u2): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
            (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        };
        let side = [-dir[1], dir[0], 0.0];
        (0..frames)
            .map(|i| {
                let t = i as f64 / 120.0;
                // Shift so that a touchdown falls at `offset`.
                let s = profile.position(t - offset + 2.0 * profile.step_duration());
                let sway = 0.01 * (std::f64::consts::TAU * t).sin();
                let mut p = [0.0; 3];
                for k in 0..3 {
                    p[k] = dir[k] * s + side[k] * sway + noise * gauss();
                }
                p
            })
            .collect()
    }

    /// 20 s at 120 frames/s of a profile with t1 = 120 ms, slip 9.17 mm, speed 7.03 cm/s,
    /// 0.3 mm noise per axis, touchdowns at 0.2 + k/2 s.
    ///
    /// Tolerances: the step speed is a difference of positions over 0.5 s, so noise gives
    /// about 0.3 mm * sqrt(2) / 0.5 s = 0.85 mm/s per step and far less on the mean: 1 mm/s.
    /// The estimated touchdown can be late by up to one frame (8.3 ms) because the 10 Hz
    /// low pass rounds the speed's kink at touchdown (noise-free it is 5.6 ms late here), and
    /// t1, counted from it, is early by as much; the per-step t1 scatter from noise (about
    /// 15 ms, the minimum is flat) averages to about 2.5 ms over 39 steps: 12 ms in all. With
    /// the true touchdowns given, only the noise and the filter's rounding of the asymmetric
    /// minimum remain: 5 ms. The slip integrates a speed of about 0.1 m/s over t1, so the
    /// timing errors above move it by about 10%.
    #[test]
    fn recovers_known_profile() {
        let profile = StepProfile::new(0.5, 0.12, 0.40, 0.12, 0.30).unwrap();
        let dir = [0.9, 0.0, 0.435_889_894_354_067_4];
        let pos = recording(&profile, dir, 2400, 0.2, 3e-4);
        let rec = Recording { positions: &pos, frame_rate_hz: 120.0, start_time_s: 0.0, touchdowns_s: None };
        let a = analyse(&[rec], &GaitOptions::new(1.0).unwrap()).unwrap();
        let r = &a.recordings[0];
        let s = a.summary;
        assert!((a.upslope.vector()[0] - 0.9).abs() < 5e-3);
        assert!(a.upslope_estimated);
        assert!((r.touchdown_offset.unwrap().offset_s - 0.2).abs() < 1.0 / 120.0);
        assert_eq!(r.steps.len(), 39);
        assert!((s.speed_m_s - profile.mean_speed()).abs() < 1e-3);
        assert!((s.step_m - profile.step()).abs() < 5e-4);
        assert!((s.t1_s.unwrap() - profile.anchoring_time()).abs() < 0.012);
        assert!((s.slip_m.unwrap() - profile.slip()).abs() < 0.1 * profile.slip());
        assert_eq!(s.unanchored_steps, 0);
        let curve = a.curve.unwrap();
        assert_eq!(curve.strides, 19);
        // The curve starts at a touchdown and dips to -V_s at t1 in its first half.
        let half = curve.time_s.iter().filter(|&&t| t < 0.5).count();
        let (jmin, vmin) =
            curve.mean[..half]
                .iter()
                .enumerate()
                .fold((0, f64::MAX), |acc, (j, &v)| if v < acc.1 { (j, v) } else { acc });
        assert!((vmin + 0.12).abs() < 0.01, "{vmin}");
        assert!((curve.time_s[jmin] - 0.12).abs() < 0.02);

        let truth: Vec<f64> = (0..40).map(|k| 0.2 + 0.5 * k as f64).collect();
        let given = Recording { touchdowns_s: Some(&truth), ..rec };
        let b = analyse(&[given], &GaitOptions::new(1.0).unwrap()).unwrap();
        assert!(b.recordings[0].touchdown_offset.is_none());
        assert!((b.summary.t1_s.unwrap() - profile.anchoring_time()).abs() < 0.005);
        assert!((b.summary.slip_m.unwrap() - profile.slip()).abs() < 0.05 * profile.slip());
    }

    /// Level sand: no slip, the speed rises right after touchdown, so t1 = 0 and slip = 0.
    #[test]
    fn level_sand_has_no_slip() {
        let profile = StepProfile::new(0.5, 0.0, 0.35, 0.0, 0.4).unwrap();
        let pos = recording(&profile, [0.0, 1.0, 0.0], 1200, 0.1, 2e-4);
        let rec = Recording { positions: &pos, frame_rate_hz: 120.0, start_time_s: 0.0, touchdowns_s: None };
        let a = analyse(&[rec], &GaitOptions::new(1.0).unwrap()).unwrap();
        let s = a.summary;
        assert!((s.speed_m_s - profile.mean_speed()).abs() < 1e-3);
        // The noise can make the minimum wander by a frame or two around touchdown.
        assert!(s.t1_s.unwrap() < 0.02);
        assert!(s.slip_m.unwrap() < 2e-4);
    }

    #[test]
    fn long_gap_splits_and_nothing_moving_is_an_error() {
        let profile = StepProfile::new(0.5, 0.1, 0.4, 0.1, 0.3).unwrap();
        let mut pos = recording(&profile, [1.0, 0.0, 0.0], 1200, 0.0, 0.0);
        for p in &mut pos[500..530] {
            *p = [f64::NAN; 3];
        }
        for p in &mut pos[800..805] {
            p[1] = f64::NAN;
        }
        let rec = Recording { positions: &pos, frame_rate_hz: 120.0, start_time_s: 3.0, touchdowns_s: None };
        let a = analyse(&[rec], &GaitOptions::new(1.0).unwrap()).unwrap();
        let r = &a.recordings[0];
        assert_eq!(r.tracks.len(), 2);
        assert_eq!(r.dropped_frames, 30);
        assert_eq!(r.interpolated_frames, 5);
        assert!((r.tracks[1].start_time_s - (3.0 + 530.0 / 120.0)).abs() < 1e-12);
        assert!((a.summary.speed_m_s - profile.mean_speed()).abs() < 1e-3);
        let still = vec![[1.0, 2.0, 3.0]; 300];
        let rec = Recording { positions: &still, ..rec };
        assert_eq!(analyse(&[rec], &GaitOptions::new(1.0).unwrap()).unwrap_err(), GaitError::NoDirection);
        let short = &pos[..50];
        let rec = Recording { positions: short, ..rec };
        assert!(matches!(analyse(&[rec], &GaitOptions::new(1.0).unwrap()), Err(GaitError::NoSteps { .. })));
    }
}
