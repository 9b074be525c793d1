//! How motion-capture tracks enter the report: each slope's pooled analysis (docs/model.md §11)
//! becomes an anchoring-time observation and, without other observed speeds, a speed
//! observation; slopes that give neither are named in notes.

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

/// The tracks split into observations, with a note (for the page) and a warning (for the
/// user's terminal) on every slope whose t1 or speed cannot be used: without an SD > 0 an
/// observation has no weight in the calibration.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct TrackUse {
    pub anchoring: Vec<AnchoringObservation>,
    pub speeds: Vec<SpeedObservation>,
    pub notes: Vec<String>,
    pub warnings: Vec<String>,
}

impl TrackUse {
    /// `observed_given`: the observed speeds come from elsewhere, so the tracks' speeds are
    /// shown only.
    pub fn new(tracks: &[TrackedSlope], observed_given: bool) -> Result<TrackUse, crate::ParamError> {
        let mut out = TrackUse::default();
        for t in tracks {
            let r = &t.result.summary;
            let files = t.files.join(", ");
            let slope = Slope::from_degrees(t.slope_deg).map_err(|e| e.renamed("tracks slope_deg"))?;
            match (r.t1_s, r.t1_sd_s) {
                (Some(t1), Some(sd)) if sd > 0.0 => {
                    out.anchoring.push(AnchoringObservation { slope, t1, t1_sd: sd })
                }
                _ => {
                    let why = if r.t1_s.is_none() {
                        format!("no anchored step among {} steps", r.steps)
                    } else {
                        "its SD needs at least two anchored steps with different t1".to_string()
                    };
                    out.notes.push(format!(
                        "The tracks at {}° ({files}) give no anchoring time ({why}): not drawn in fig5b nor used in the calibration.",
                        t.slope_deg
                    ));
                    out.warnings.push(format!(
                        "--tracks at {}° ({files}): no anchoring time ({why}); not used",
                        t.slope_deg
                    ));
                }
            }
            if observed_given {
                continue;
            }
            match r.speed_sd_m_s {
                Some(sd) if sd > 0.0 => {
                    out.speeds.push(SpeedObservation { slope, speed: r.speed_m_s, speed_sd: sd })
                }
                _ => {
                    let why = format!(
                        "its SD needs at least two steps with different speeds; found {} steps",
                        r.steps
                    );
                    out.warnings.push(format!(
                        "--tracks at {}° ({files}): no observed speed ({why}); not used",
                        t.slope_deg
                    ));
                    out.notes.push(format!(
                        "The tracks at {}° ({files}) give no observed speed ({why}): not drawn in fig3a nor used in the calibration.",
                        t.slope_deg
                    ));
                }
            }
        }
        if observed_given && !tracks.is_empty() {
            out.notes.push(
                "The observed speeds are --observed's: the tracks' speeds are shown in this table only."
                    .into(),
            );
        }
        Ok(out)
    }
}
