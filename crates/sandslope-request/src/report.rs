//! `report`'s request: the paper reproduced and confronted (docs/report.md), on the paper's own
//! evidence or on a user's campaign. The evidence files are read here, once, for `sandslope
//! report` and Python's `sandslope.report`; the answer is the library's one value,
//! [`sandslope::report::report`].

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use sandslope::gait::GaitOptions;
use sandslope::report::{report, Evidence, Report, TrackReading, TrackedSlope};
use sandslope::{Robot, Slope, Terrain};
use sandslope_io::force_tests::report_force_tests;
use sandslope_io::mocap::MocapFormat;
use sandslope_io::presets::{is_default, PresetKind};
use sandslope_io::{load_anchoring_times, load_speeds};

use crate::error::{RequestError, Result, Words};
use crate::track::{track_captures, upslope, CaptureRead, Touchdowns, Tracked};

/// Motion-capture recordings at one slope, pooled.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TracksAt {
    /// Slope of the recordings, degrees, `0 <= slope < 90`.
    pub slope_deg: f64,
    /// The recordings (paths; the command line expands glob patterns first).
    pub files: Vec<PathBuf>,
}

/// The inputs of `report`, besides the robot and terrain themselves (the front end loads
/// those, with its overrides; `robot_source` and `terrain_source` name them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReportRequest {
    /// The robot's file or preset as the inputs table shows it (field `robot`).
    pub robot_source: String,
    /// The terrain's file or preset as the inputs table shows it (field `terrain`).
    pub terrain_source: String,
    /// Observed speeds CSV; default the paper's five (field `observed`).
    pub observed: Option<PathBuf>,
    /// Force tests (a terrain file with k_s_sd, or a preset); default: on the built-in
    /// terrain the paper's as its text reports them, else the terrain itself (field `forces`).
    pub forces: Option<String>,
    /// Observed anchoring times CSV (field `t1`).
    pub t1: Option<PathBuf>,
    /// Motion-capture recordings per slope (field `tracks`).
    pub tracks: Vec<TracksAt>,
    /// Format of the recordings; detected per file when `None` (field `tracks-format`).
    pub tracks_format: Option<MocapFormat>,
    /// Body to track in the recordings (field `tracks-body`).
    pub tracks_body: Option<String>,
    /// Upslope direction in the recordings' capture frame, as given; estimated per slope when
    /// `None` (field `tracks-upslope`).
    pub tracks_upslope: Option<[f64; 3]>,
    /// Risk threshold of the safe-slope limit, strictly between 0 and 1 (field `max-risk`).
    pub max_risk: f64,
    /// Also the stride simulator's joint fit (field `simulator-fit`).
    pub simulator_fit: bool,
}

impl ReportRequest {
    /// Every value checked before any file is read; errors name the field in `words`.
    pub fn check(&self, words: Words) -> Result<()> {
        if !(self.max_risk > 0.0 && self.max_risk < 1.0) {
            let message = match words {
                Words::Flag => format!(
                    "--max-risk: {} is not a failure probability strictly between 0 and 1 (e.g. 0.05)",
                    self.max_risk
                ),
                Words::Keyword => {
                    format!("max_risk = {} must be a probability strictly between 0 and 1", self.max_risk)
                }
            };
            return Err(RequestError::invalid("max-risk", message));
        }
        if let Some(u) = self.tracks_upslope {
            upslope(words, "tracks-upslope", u)?;
        }
        Ok(())
    }

    /// Reads the evidence the request names, for `robot` and `terrain`: on the built-in
    /// terrain without `forces`, the force tests are the paper's as its text reports them (the
    /// built-in terrain was calibrated from them). Tracks are analysed per slope, lowest first,
    /// as `track` does.
    pub fn evidence(&self, robot: Robot, terrain: Terrain, words: Words) -> Result<Evidence> {
        self.check(words)?;
        let forces = report_force_tests(self.forces.as_deref(), &self.terrain_source)
            .map_err(|e| RequestError::from_error(Some("forces"), e))?;
        let observed = match &self.observed {
            Some(p) => Some((
                p.display().to_string(),
                load_speeds(p).map_err(|e| RequestError::from_error(Some("observed"), e))?,
            )),
            None => None,
        };
        let anchoring = match &self.t1 {
            Some(p) => Some((
                p.display().to_string(),
                load_anchoring_times(p).map_err(|e| RequestError::from_error(Some("t1"), e))?,
            )),
            None => None,
        };
        let tracks = self.tracks(robot.stride_period(), words)?;
        let upslope = self.tracks_upslope.map(|u| upslope(words, "tracks-upslope", u)).transpose()?;
        Ok(Evidence {
            robot_source: self.robot_source.clone(),
            terrain_source: self.terrain_source.clone(),
            observed,
            forces,
            anchoring,
            tracks,
            track_reading: TrackReading {
                format: self.tracks_format.map(|f| f.name().to_string()),
                body: self.tracks_body.clone(),
                upslope: upslope.map(|u| u.vector()),
            },
            max_risk: self.max_risk,
            simulator_fit: self.simulator_fit,
            builtin_robot: is_default(&self.robot_source, PresetKind::Robot),
            builtin_terrain: is_default(&self.terrain_source, PresetKind::Terrain),
            robot,
            terrain,
        })
    }

    /// The recordings analysed per slope, lowest slope first; `period` is the robot's stride
    /// period.
    fn tracks(&self, period: f64, words: Words) -> Result<Vec<TrackedSlope>> {
        let field = "tracks";
        let mut options = GaitOptions::new(period)
            .map_err(|e| RequestError::from_error(None, anyhow::anyhow!("the robot's stride period: {e}")))?;
        if let Some(u) = self.tracks_upslope {
            options = options.with_upslope(upslope(words, "tracks-upslope", u)?);
        }
        let mut tracks: Vec<&TracksAt> = self.tracks.iter().collect();
        tracks.sort_by(|a, b| a.slope_deg.total_cmp(&b.slope_deg));
        let read = CaptureRead {
            format: self.tracks_format,
            body: self.tracks_body.as_deref(),
            cutoff_name: None,
            topic: None,
            frame: None,
        };
        let mut out = Vec::new();
        for t in tracks {
            let slope = Slope::from_degrees(t.slope_deg).map_err(|e| {
                let name = match words {
                    Words::Flag => "--tracks".to_string(),
                    Words::Keyword => "tracks slope".to_string(),
                };
                RequestError::invalid(field, e.renamed(name))
            })?;
            if t.files.is_empty() {
                return Err(RequestError::invalid(
                    field,
                    format!("tracks at {} deg: no recording given", t.slope_deg),
                ));
            }
            let Tracked { names, result, .. } = track_captures(
                &t.files,
                read.clone(),
                &Touchdowns::Estimated,
                &options,
                Some(slope),
                &mut || (),
            )?;
            out.push(TrackedSlope { slope_deg: t.slope_deg, files: names, result });
        }
        Ok(out)
    }

    /// The report (what `report --out DIR` writes as `report.json`) for `robot` and `terrain`.
    pub fn answer(&self, robot: Robot, terrain: Terrain, words: Words) -> Result<Report> {
        answer_evidence(&self.evidence(robot, terrain, words)?)
    }
}

/// The report on `evidence` already read ([`ReportRequest::evidence`]): the command line reads
/// the evidence first, to warn about its recordings before the long part.
pub fn answer_evidence(evidence: &Evidence) -> Result<Report> {
    report(evidence).map_err(|e| RequestError::from_error(None, anyhow::anyhow!("{e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request() -> ReportRequest {
        ReportRequest {
            robot_source: "paper-hexapod".into(),
            terrain_source: "glass-beads-300um".into(),
            observed: None,
            forces: None,
            t1: None,
            tracks: Vec::new(),
            tracks_format: None,
            tracks_body: None,
            tracks_upslope: None,
            max_risk: 0.05,
            simulator_fit: false,
        }
    }

    fn model() -> (Robot, Terrain) {
        (
            sandslope_io::load_robot("paper-hexapod").unwrap(),
            sandslope_io::load_terrain("glass-beads-300um").unwrap(),
        )
    }

    #[test]
    fn checks_name_the_field() {
        for p in [0.0, 1.0, f64::NAN] {
            let e = ReportRequest { max_risk: p, ..request() }.check(Words::Keyword).unwrap_err();
            assert_eq!(e.field(), Some("max-risk"));
            assert!(
                e.message().starts_with(&format!("max_risk = {p} must be a probability")),
                "{}",
                e.message()
            );
        }
        let e =
            ReportRequest { tracks_upslope: Some([0.0; 3]), ..request() }.check(Words::Keyword).unwrap_err();
        assert_eq!(e.field(), Some("tracks-upslope"));
        assert!(e.message().starts_with("tracks_upslope"), "{}", e.message());
        assert!(request().check(Words::Flag).is_ok());
    }

    /// The evidence on the defaults: the paper's (no observations of the user's own, the
    /// built-in robot and terrain recognised); a track slope of 90 degrees or one without a
    /// recording is refused under the field `tracks`, and a missing file under its own field.
    #[test]
    fn evidence_is_read_once_and_errors_name_the_field() {
        let (robot, terrain) = model();
        let ev = request().evidence(robot.clone(), terrain.clone(), Words::Flag).unwrap();
        assert!(ev.builtin_robot && ev.builtin_terrain && !ev.has_own_observations());
        let at = |slope_deg: f64, files: Vec<PathBuf>| ReportRequest {
            tracks: vec![TracksAt { slope_deg, files }],
            ..request()
        };
        let e = at(90.0, vec![PathBuf::from("x.csv")])
            .evidence(robot.clone(), terrain.clone(), Words::Keyword)
            .unwrap_err();
        assert_eq!(e.field(), Some("tracks"));
        assert!(e.message().starts_with("tracks slope = 90"), "{}", e.message());
        let e = at(10.0, Vec::new()).evidence(robot.clone(), terrain.clone(), Words::Flag).unwrap_err();
        assert_eq!(e.message(), "tracks at 10 deg: no recording given");
        let e = ReportRequest { observed: Some(PathBuf::from("no-such-speeds.csv")), ..request() }
            .evidence(robot, terrain, Words::Flag)
            .unwrap_err();
        assert_eq!(e.field(), Some("observed"));
        assert!(e.message().contains("no-such-speeds.csv"), "{}", e.message());
    }
}
