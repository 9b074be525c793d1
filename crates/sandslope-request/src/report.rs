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

use crate::calibrate;
use crate::error::{RequestError, Result, Words};
use crate::field::{Field, Fields, Table};
use crate::params::Params;
use crate::risk;
use crate::track::{parse_upslope, track_captures, upslope, CaptureRead, Touchdowns, Tracked};

/// `--observed`: `calibrate`'s field, the paper's speeds by default.
pub const OBSERVED: Field =
    calibrate::OBSERVED.help("Observed speeds (slope_deg,speed_m_s,speed_sd_m_s); default: the paper's five");
/// `--forces`: `calibrate`'s field, drawn too.
pub const FORCES: Field = calibrate::FORCES.help(
    "Force tests (a terrain file with k_s_sd, as `sandslope fit` writes): drawn in fig4d/h and \
     used as the k_s shape in the calibration; default: the terrain itself",
);
/// `--t1`: `calibrate`'s field, drawn too.
pub const T1: Field =
    calibrate::T1.help("Observed anchoring times (slope_deg,t1_s,t1_sd_s), drawn in fig5b and calibrated on");
/// `--tracks`: motion-capture recordings at one slope, given once per slope or file (the
/// command line's own repeated argument, so not among [`FIELDS`]' once-given flags; Python's
/// `tracks` is a dict of slope to paths).
pub const TRACKS: Field = Field::text("tracks", "DEG=FILE|GLOB").keyword("tracks").help(
    "Motion-capture recordings at one slope, `DEG=FILE|GLOB` (e.g. `10=runs/10deg-*.csv`); \
     repeat for more files or slopes. Each slope's files are pooled and analysed as `sandslope \
     track` does: their anchoring time t1 joins the observed ones (fig5b and the calibration) \
     and, without --observed, their mean speeds are the observed speeds. Adds fig3b (speed \
     within a stride) and a motion-capture table",
);
/// `--tracks-format`: the recordings' format.
pub const TRACKS_FORMAT: Field = Field::text("tracks-format", "motive|vicon|plain")
    .keyword("tracks_format")
    .help(
    "Format of the --tracks files: motive, vicon or plain; detected from each file's first line when omitted",
);
/// `--tracks-body`: the body tracked in the recordings.
pub const TRACKS_BODY: Field = Field::text("tracks-body", "NAME").keyword("tracks_body").help(
    "Rigid body, marker or model output to track in the --tracks files (required when a file has several)",
);
/// `--tracks-upslope`: the upslope direction in the recordings' frame (a dimensionless
/// vector, unit 1, that may start with a minus).
pub const TRACKS_UPSLOPE: Field = Field::text("tracks-upslope", "AXIS|X,Y,Z")
    .keyword("tracks_upslope")
    .unit("1")
    .range("+x, -x, +y, -y, +z, -z or a non-zero vector")
    .help(
        "Upslope direction in the --tracks files' capture frame: +x, -x, +y, -y, +z, -z or a \
         vector such as `0.91,0,0.41`; estimated per slope from the direction of travel when \
         omitted",
    );
/// `--max-risk`: `risk`'s field (its default the library's), the threshold of the
/// safe-slope limit.
pub const MAX_RISK: Field = risk::MAX_RISK.help("Risk threshold for the safe-slope limit (docs/model.md §9)");
/// `--simulator-fit`: the stride simulator's fit beside the closed form's.
pub const SIMULATOR_FIT: Field = Field::switch("simulator-fit").keyword("simulator_fit").help(
    "Also fit the evidence with the stride simulator in place of the closed form (`calibrate \
     --model simulate`) and show the two fits side by side. Left out by default: its thousands \
     of walks take about 8 minutes of CPU on the paper's evidence with the converged simulator \
     (docs/calibration.md), where the rest of the report takes under a second (docs/simulate.md)",
);

/// `report`'s own once-given fields ([`TRACKS`] besides, given per slope; the robot's, the
/// terrain's and the level step are [`crate::scenario`]'s).
pub const FIELDS: Table = Table {
    command: "report",
    fields: &[OBSERVED, FORCES, T1, TRACKS_FORMAT, TRACKS_BODY, TRACKS_UPSLOPE, MAX_RISK, SIMULATOR_FIT],
};

impl Fields for ReportRequest {
    const TABLE: Table = FIELDS;
}

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
    /// The request of the flags given, `params` ([`FIELDS`]), for the robot and terrain named
    /// by `robot_source` and `terrain_source` and the recordings `tracks` (found by the front
    /// end): the one raw-to-typed step of the command line. Refuses any other key, and a
    /// recordings' field without recordings.
    pub fn from_fields(
        robot_source: String,
        terrain_source: String,
        tracks: Vec<TracksAt>,
        params: &[(String, String)],
    ) -> Result<ReportRequest> {
        let mut p = Params::new(FIELDS.command, params);
        let path = |text: Option<&str>| text.map(PathBuf::from);
        let observed = path(OBSERVED.text_in(&mut p)?);
        let forces = FORCES.text_in(&mut p)?.map(str::to_string);
        let t1 = path(T1.text_in(&mut p)?);
        for f in [&TRACKS_FORMAT, &TRACKS_BODY, &TRACKS_UPSLOPE] {
            if tracks.is_empty() && p.text(f.flag)?.is_some() {
                return Err(RequestError::invalid(
                    f.flag,
                    format!(
                        "{} reads the {} recordings: give {} too",
                        f.long(),
                        TRACKS.long(),
                        TRACKS.long()
                    ),
                ));
            }
        }
        let tracks_format = match TRACKS_FORMAT.text_in(&mut p)? {
            Some(text) => Some(text.parse::<MocapFormat>().map_err(|why| {
                RequestError::invalid(TRACKS_FORMAT.flag, format!("{}: {why}", TRACKS_FORMAT.long()))
            })?),
            None => None,
        };
        let tracks_body = TRACKS_BODY.text_in(&mut p)?.map(str::to_string);
        let tracks_upslope = TRACKS_UPSLOPE
            .text_in(&mut p)?
            .map(|text| {
                parse_upslope(text, &TRACKS_UPSLOPE.long()).map_err(|why| {
                    RequestError::invalid(TRACKS_UPSLOPE.flag, format!("{}: {why}", TRACKS_UPSLOPE.long()))
                })
            })
            .transpose()?;
        let max_risk = risk::max_risk_in(&mut p)?;
        let simulator_fit = SIMULATOR_FIT.switch_in(&mut p)?;
        p.finish()?;
        Ok(ReportRequest {
            robot_source,
            terrain_source,
            observed,
            forces,
            t1,
            tracks,
            tracks_format,
            tracks_body,
            tracks_upslope,
            max_risk,
            simulator_fit,
        })
    }

    /// Every value checked before any file is read; errors name the field in `words`.
    pub fn check(&self, words: Words) -> Result<()> {
        if !(self.max_risk > 0.0 && self.max_risk < 1.0) {
            let message = match words {
                Words::Flag => format!(
                    "{}: {} is not a failure probability strictly between 0 and 1 (e.g. {})",
                    MAX_RISK.long(),
                    self.max_risk,
                    sandslope::risk::DEFAULT_MAX_RISK
                ),
                Words::Keyword => {
                    format!("max_risk = {} must be a probability strictly between 0 and 1", self.max_risk)
                }
            };
            return Err(RequestError::invalid(MAX_RISK.flag, message));
        }
        if let Some(u) = self.tracks_upslope {
            upslope(words, TRACKS_UPSLOPE.flag, u)?;
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
            .map_err(|e| RequestError::from_error(Some(FORCES.flag), e))?;
        let observed = match &self.observed {
            Some(p) => Some((
                p.display().to_string(),
                load_speeds(p).map_err(|e| RequestError::from_error(Some(OBSERVED.flag), e))?,
            )),
            None => None,
        };
        let anchoring = match &self.t1 {
            Some(p) => Some((
                p.display().to_string(),
                load_anchoring_times(p).map_err(|e| RequestError::from_error(Some(T1.flag), e))?,
            )),
            None => None,
        };
        let tracks = self.tracks(robot.stride_period(), words)?;
        let upslope = self.tracks_upslope.map(|u| upslope(words, TRACKS_UPSLOPE.flag, u)).transpose()?;
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
        let field = TRACKS.flag;
        let mut options = GaitOptions::new(period)
            .map_err(|e| RequestError::from_error(None, anyhow::anyhow!("the robot's stride period: {e}")))?;
        if let Some(u) = self.tracks_upslope {
            options = options.with_upslope(upslope(words, TRACKS_UPSLOPE.flag, u)?);
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
                    Words::Flag => TRACKS.long(),
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

/// The report on `evidence` already read ([`ReportRequest::evidence`]), worded
/// ([`crate::report_text::word`]): the command line reads the evidence first, to warn about
/// its recordings before the long part.
pub fn answer_evidence(evidence: &Evidence) -> Result<Report> {
    let mut value = report(evidence).map_err(|e| RequestError::from_error(None, anyhow::anyhow!("{e}")))?;
    crate::report_text::word(&mut value, evidence);
    Ok(value)
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

    /// The flags read by the table: none given is the paper's evidence at the library's
    /// max-risk; a recordings' field without recordings, a bad format or max-risk are refused
    /// naming the flag.
    #[test]
    fn flags_are_read_by_the_table() {
        let from = |tracks: Vec<TracksAt>, list: &[(&str, &str)]| {
            let pairs: Vec<(String, String)> =
                list.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
            ReportRequest::from_fields("paper-hexapod".into(), "glass-beads-300um".into(), tracks, &pairs)
        };
        assert_eq!(from(Vec::new(), &[]).unwrap(), request());
        assert_eq!(request().max_risk, sandslope::risk::DEFAULT_MAX_RISK);
        let e = from(Vec::new(), &[("tracks-body", "hexapod")]).unwrap_err();
        assert_eq!(e.message(), "--tracks-body reads the --tracks recordings: give --tracks too");
        let tracks = vec![TracksAt { slope_deg: 10.0, files: vec![PathBuf::from("a.csv")] }];
        let r = from(
            tracks.clone(),
            &[("tracks-format", "vicon"), ("tracks-upslope", "-x"), ("simulator-fit", "true")],
        )
        .unwrap();
        assert_eq!(
            (r.tracks_format, r.tracks_upslope, r.simulator_fit),
            (Some(MocapFormat::Vicon), Some([-1.0, 0.0, 0.0]), true)
        );
        let e = from(tracks, &[("tracks-format", "qualisys")]).unwrap_err();
        assert!(
            e.message().starts_with("--tracks-format: `qualisys` is not a motion-capture format"),
            "{}",
            e.message()
        );
        let e = from(Vec::new(), &[("max-risk", "1.5")]).unwrap_err();
        assert_eq!(
            (e.field(), e.message().as_str()),
            (
                Some("max-risk"),
                "--max-risk = 1.5: 1.5 is not a failure probability strictly between 0 and 1 (e.g. 0.05)"
            )
        );
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
