//! How motion-capture tracks enter the report: each slope's pooled analysis (docs/model.md §11)
//! becomes an anchoring-time observation and, without other observed speeds, a speed
//! observation; slopes that give neither are listed ([`UnusedTrack`]) for the front ends to
//! word.

use serde::Serialize;

use crate::calibrate::AnchoringObservation;
use crate::calibrate::SpeedObservation;
use crate::gait::track::TrackResult;
use crate::gait::GaitSummary;
use crate::slope::Slope;

/// One slope's recordings, analysed pooled (what `sandslope track` reports for them).
#[derive(Debug, Clone, PartialEq)]
pub struct TrackedSlope {
    /// Slope of the recordings, degrees.
    pub slope_deg: f64,
    /// The recordings pooled at this slope, as given or matched.
    pub files: Vec<String>,
    /// The pooled analysis.
    pub result: TrackResult,
}

/// One slope's row of the motion-capture table and of report.json's `tracks`: its files and
/// the summary `track` reports for them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrackRecord {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// The recordings pooled at this slope, as given or matched.
    pub files: Vec<String>,
    /// Means and SDs across their steps.
    #[serde(flatten)]
    pub summary: GaitSummary,
}

impl From<&TrackedSlope> for TrackRecord {
    fn from(t: &TrackedSlope) -> TrackRecord {
        TrackRecord { slope_deg: t.slope_deg, files: t.files.clone(), summary: t.result.summary }
    }
}

/// What a tracked slope fails to give.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrackGap {
    /// No anchoring time: no step anchored.
    NoAnchoredStep,
    /// No anchoring time with an SD: fewer than two anchored steps with different t1.
    NoAnchoringSd,
    /// No observed speed with an SD: fewer than two steps with different speeds.
    NoSpeedSd,
}

/// A tracked slope whose anchoring time or speed cannot be used: without an SD > 0 an
/// observation has no weight in the calibration. The front ends word it, as a note on the page
/// and a warning on the user's terminal.
#[derive(Debug, Clone, PartialEq)]
pub struct UnusedTrack {
    /// Slope of the recordings, degrees.
    pub slope_deg: f64,
    /// The recordings pooled at this slope.
    pub files: Vec<String>,
    /// The complete steps found in them.
    pub steps: usize,
    /// What they fail to give.
    pub gap: TrackGap,
}

/// The tracks split into observations, and every slope whose t1 or speed cannot be used, in
/// slope order (the anchoring time before the speed).
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct TrackUse {
    pub anchoring: Vec<AnchoringObservation>,
    pub speeds: Vec<SpeedObservation>,
    pub unused: Vec<UnusedTrack>,
}

impl TrackUse {
    /// `observed_given`: the observed speeds come from elsewhere, so the tracks' speeds are
    /// shown only.
    pub fn new(tracks: &[TrackedSlope], observed_given: bool) -> Result<TrackUse, crate::ParamError> {
        let mut out = TrackUse::default();
        for t in tracks {
            let r = &t.result.summary;
            let slope = Slope::from_degrees(t.slope_deg).map_err(|e| e.renamed("tracks slope_deg"))?;
            let unused =
                |gap| UnusedTrack { slope_deg: t.slope_deg, files: t.files.clone(), steps: r.steps, gap };
            match (r.t1_s, r.t1_sd_s) {
                (Some(t1), Some(sd)) if sd > 0.0 => {
                    out.anchoring.push(AnchoringObservation { slope, t1, t1_sd: sd })
                }
                (None, _) => out.unused.push(unused(TrackGap::NoAnchoredStep)),
                _ => out.unused.push(unused(TrackGap::NoAnchoringSd)),
            }
            if observed_given {
                continue;
            }
            match r.speed_sd_m_s {
                Some(sd) if sd > 0.0 => {
                    out.speeds.push(SpeedObservation { slope, speed: r.speed_m_s, speed_sd: sd })
                }
                _ => out.unused.push(unused(TrackGap::NoSpeedSd)),
            }
        }
        Ok(out)
    }
}
