//! `track`'s request: speed, anchoring time and slip from motion-capture recordings
//! (docs/model.md §11), pooled over the files given for one slope. What `sandslope track`,
//! `sandslope report --tracks` and Python's `sandslope.track` and `sandslope.report(tracks=...)`
//! run: one path from capture files to the library's [`track`] (read every file, build the
//! [`Recording`]s, orient by the capture frame's vertical axis, run the analysis, name the file
//! in any error).

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use sandslope::gait::{track, GaitOptions, Recording, RecordingSummary, TrackResult, Upslope};
use sandslope::{GaitError, Slope, SlopeEvaluation};
use sandslope_io::mocap::{self, Capture, MocapFormat};

use crate::error::{RequestError, Result, Words};
use crate::field::{Field, Fields, Kind, Table};
use crate::params::Params;

/// `--format`: the capture files' format.
pub const FORMAT: Field = Field::text("format", "motive|vicon|plain")
    .keyword("format")
    .help("File format: motive, vicon or plain; detected from the first line when omitted");
/// `--body`: what to track in the files.
pub const BODY: Field = Field::text("body", "NAME")
    .keyword("body")
    .help("Rigid body, marker or model output to track (required when a file has several)");
/// `--topic`: a bag's pose topic.
pub const TOPIC: Field = Field::text("topic", "TOPIC").keyword("topic").help(
    "A ROS 2 bag's topic of geometry_msgs/PoseStamped, nav_msgs/Odometry, \
     geometry_msgs/TransformStamped or tf2_msgs/TFMessage (a bag is a folder with \
     metadata.yaml, or an .mcap or .db3 file; docs/bags.md); the bag's only such topic when \
     omitted, else the error lists the candidates",
);
/// `--frame`: the child frame on a TF topic.
pub const FRAME: Field = Field::text("frame", "FRAME").keyword("frame").help(
    "The child frame to track on a bag's TF topic (e.g. `base_link`), placed in the root of its \
     TF tree (docs/bags.md); the only one when omitted",
);
/// `--upslope`: the upslope direction in the capture frame.
pub const UPSLOPE: Field = Field::text("upslope", "AXIS|X,Y,Z")
    .keyword("upslope")
    .unit("capture-frame axes")
    .range("not zero, finite")
    .help(
        "Upslope direction in the capture frame: +x, -x, +y, -y, +z, -z or a vector such as \
         `0.91,0,0.41`; when omitted, the principal direction of travel, pointed the way it rises \
         along the format's vertical axis (a slide down reads as a negative speed)",
    );
/// `--max-gap`: the longest occlusion filled (the library's
/// [`sandslope::gait::DEFAULT_MAX_GAP`] by default, a test checks).
pub const MAX_GAP: Field =
    Field::new("max-gap", Kind::Whole, "FRAMES").keyword("max_gap").unit("frames").default("10").help(
        "Longest occlusion filled by linear interpolation, frames; longer gaps split the recording \
         into segments analysed separately",
    );
/// `--cutoff`: the speed estimate's low-pass cutoff (the library's
/// [`sandslope::gait::DEFAULT_CUTOFF_HZ`] by default, a test checks).
pub const CUTOFF: Field = Field::number("cutoff", "HZ")
    .keyword("cutoff_hz")
    .key("cutoff_hz")
    .unit("Hz")
    .default("10")
    .range("greater than 0, below half the frame rate")
    .help("Low-pass cutoff for the zero-phase speed estimate, Hz (see docs/tracking.md)");
/// `--touchdowns`: one touchdowns file per recording (Python's `touchdowns`: one list of times
/// per recording).
pub const TOUCHDOWNS: Field = Field::new("touchdowns", Kind::List, "FILE").keyword("touchdowns").help(
    "Touchdown times, s, one per line in the recording's clock (e.g. from the gait controller's \
     log); give it once per recording, in the same order. Estimated from the speed signal when \
     omitted",
);
/// `--slope`: the recordings' slope.
pub const SLOPE: Field = Field::number("slope", "DEG")
    .keyword("slope_deg")
    .key("slope_deg")
    .unit("deg")
    .range("0 to below 90")
    .help("Slope of these recordings, degrees (labels the output and the `--speeds-out` row)");

/// `track`'s own fields besides its files (the robot's and the terrain's are
/// [`crate::scenario`]'s).
pub const FIELDS: Table = Table {
    command: "track",
    fields: &[FORMAT, BODY, TOPIC, FRAME, UPSLOPE, MAX_GAP, CUTOFF, TOUCHDOWNS, SLOPE],
};

impl Fields for TrackRequest {
    const TABLE: Table = FIELDS;
}

/// Where the touchdown times of each recording come from.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Touchdowns {
    /// Estimated from each recording's speed signal.
    #[default]
    Estimated,
    /// One touchdowns file per recording, in order (one time in seconds per line).
    Files(Vec<PathBuf>),
    /// One list of times, s, per recording, in order.
    Times(Vec<Vec<f64>>),
}

/// The inputs of a motion-capture analysis at one slope.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrackRequest {
    /// The recordings, pooled (field `files`; the command line expands glob patterns first).
    pub files: Vec<PathBuf>,
    /// File format; detected from each file's first line when `None` (field `format`).
    pub format: Option<MocapFormat>,
    /// Rigid body, marker or model output to track, required when a file has several (field
    /// `body`).
    pub body: Option<String>,
    /// Upslope direction in the capture frame; estimated from the direction of travel when
    /// `None` (field `upslope`).
    pub upslope: Option<[f64; 3]>,
    /// Longest occlusion filled by interpolation, frames (field `max-gap`).
    pub max_gap: usize,
    /// Low-pass cutoff of the speed estimate, Hz (field `cutoff`).
    pub cutoff_hz: f64,
    /// Touchdown times (field `touchdowns`).
    pub touchdowns: Touchdowns,
    /// Slope of the recordings, degrees, when known (field `slope`).
    pub slope_deg: Option<f64>,
    /// The robot's stride period T = 2 pi / omega, s (from the robot's leg speed).
    pub stride_period_s: f64,
    /// A ROS 2 bag's topic of poses, odometry or transforms (field `topic`); the bag's only
    /// such topic when `None` (docs/bags.md).
    #[serde(default)]
    pub topic: Option<String>,
    /// The child frame on a TF topic (field `frame`).
    #[serde(default)]
    pub frame: Option<String>,
}

/// Recordings read and analysed together.
#[derive(Debug)]
pub struct Tracked {
    /// The captures, in the order of the files.
    pub captures: Vec<Capture>,
    /// Each capture's path as displayed.
    pub names: Vec<String>,
    /// The pooled analysis.
    pub result: TrackResult,
}

/// One step as every front end prints it (`track --csv`, the `per_step` of `--json` and of
/// Python's `track`): the library's row with its recording's file instead of its index.
#[derive(Debug, Clone, Serialize)]
pub struct StepRecord<'a> {
    /// The recording's file, as displayed.
    pub file: &'a str,
    /// Touchdown time t0, s (recording clock).
    pub touchdown_s: f64,
    /// Anchoring time t1 - t0, s, if the step anchored.
    pub t1_s: Option<f64>,
    /// Backward slip between t0 and t1, m.
    pub slip_m: Option<f64>,
    /// Net displacement upslope over the step, m.
    pub step_m: f64,
    /// Step-averaged speed, m/s.
    pub speed_m_s: f64,
}

/// One recording as printed: where it came from, then the library's summary.
#[derive(Debug, Clone, Serialize)]
struct RecordingRecord<'a> {
    file: &'a str,
    format: &'static str,
    body: &'a str,
    #[serde(flatten)]
    summary: &'a RecordingSummary,
}

impl Tracked {
    /// Every step with its file instead of its recording's index.
    pub fn step_records(&self) -> Vec<StepRecord<'_>> {
        self.result
            .per_step
            .iter()
            .map(|st| StepRecord {
                file: &self.names[st.recording],
                touchdown_s: st.step.touchdown_s,
                t1_s: st.step.anchoring_time_s,
                slip_m: st.step.slip_m,
                step_m: st.step.step_m,
                speed_m_s: st.step.speed_m_s,
            })
            .collect()
    }

    /// The answer (what `track --json` prints and Python's `track` returns): the library's
    /// value, with each recording's file, format and body, and each step's file.
    pub fn answer(&self) -> serde_json::Result<serde_json::Value> {
        let mut v = serde_json::to_value(&self.result)?;
        let recordings: Vec<RecordingRecord> = self
            .captures
            .iter()
            .zip(&self.names)
            .zip(&self.result.recordings)
            .map(|((c, f), summary)| RecordingRecord {
                file: f,
                format: c.format.name(),
                body: &c.body,
                summary,
            })
            .collect();
        v["recordings"] = serde_json::to_value(recordings)?;
        v["per_step"] = serde_json::to_value(self.step_records())?;
        Ok(v)
    }
}

/// The model's speed against slope beside a campaign of tracked speeds (the paper's Fig. 3a,
/// `track --plot` with a `--speeds-out` file of several slopes): the closed form of `robot` on
/// `terrain` at 401 slopes from level to 2 degrees past the steepest observed (at most 89).
pub fn model_curve(
    robot: &sandslope::Robot,
    terrain: sandslope::Terrain,
    steepest_deg: f64,
) -> Result<Vec<SlopeEvaluation>> {
    let scenario = sandslope::Scenario::new(robot.clone(), terrain, None, None)
        .map_err(|e| RequestError::from_error(None, anyhow::anyhow!("{e}")))?;
    let top = (steepest_deg.max(0.0) + 2.0).min(89.0);
    let slopes = (0..=400)
        .map(|k| sandslope::SignedSlope::from_degrees(top * k as f64 / 400.0))
        .collect::<std::result::Result<Vec<_>, _>>()
        .map_err(|e| RequestError::invalid(SLOPE.flag, e))?;
    Ok(scenario.sweep(&slopes))
}

/// How each front end names `field`: the command line by its flag, Python by its keyword
/// (which carries its unit: `cutoff_hz`, `slope_deg`), both from the field's row.
fn name(words: Words, field: &Field) -> String {
    match words {
        Words::Flag => field.long(),
        Words::Keyword => field.keyword.to_string(),
    }
}

/// Reads an upslope as a direction, an error naming its field `field` (`upslope`, or
/// `report`'s `tracks-upslope`) in `words`.
pub fn upslope(words: Words, field: &str, v: [f64; 3]) -> Result<Upslope> {
    Upslope::new(v).map_err(|e| RequestError::invalid(field, e.renamed(words.name(field))))
}

/// Parses an upslope as the command line writes it: `+x`, `-x`, `+y`, `-y`, `+z`, `-z` (or
/// `x`, `y`, `z`) or a vector `x,y,z`, as given (not normalised); `flag` names the flag in the
/// message when the vector is zero or not finite.
pub fn parse_upslope(s: &str, flag: &str) -> std::result::Result<[f64; 3], String> {
    let axis = |i: usize, sign: f64| {
        let mut v = [0.0; 3];
        v[i] = sign;
        v
    };
    let v = match s.trim().to_ascii_lowercase().as_str() {
        "+x" | "x" => axis(0, 1.0),
        "-x" => axis(0, -1.0),
        "+y" | "y" => axis(1, 1.0),
        "-y" => axis(1, -1.0),
        "+z" | "z" => axis(2, 1.0),
        "-z" => axis(2, -1.0),
        other => {
            let parts: Vec<&str> = other.split(',').map(str::trim).collect();
            let nums: Option<Vec<f64>> = parts.iter().map(|p| p.parse::<f64>().ok()).collect();
            match nums.as_deref() {
                Some([x, y, z]) => [*x, *y, *z],
                _ => return Err(format!("`{s}` must be +x, -x, +y, -y, +z, -z or three numbers `x,y,z`")),
            }
        }
    };
    Upslope::new(v).map_err(|e| e.renamed(flag).to_string())?;
    Ok(v)
}

impl TrackRequest {
    /// The command line's request: the fields given, `params` (by [`FIELDS`], the one
    /// raw-to-typed step), on the recordings `files` (the command line expands its patterns
    /// first) of a robot whose stride period is `stride_period_s`; refuses any other key.
    pub fn from_fields(
        params: &[(String, String)],
        files: Vec<PathBuf>,
        stride_period_s: f64,
    ) -> Result<TrackRequest> {
        let mut p = Params::new(FIELDS.command, params);
        let format = FORMAT
            .text_in(&mut p)?
            .map(|f| {
                f.parse::<MocapFormat>().map_err(|why| {
                    RequestError::invalid(FORMAT.flag, format!("{} = {f}: {why}", FORMAT.long()))
                })
            })
            .transpose()?;
        let text = |f: &Field, p: &mut Params<'_>| f.text_in(p).map(|t| t.map(str::to_string));
        let (body, topic, frame) = (text(&BODY, &mut p)?, text(&TOPIC, &mut p)?, text(&FRAME, &mut p)?);
        let upslope = UPSLOPE
            .text_in(&mut p)?
            .map(|u| {
                parse_upslope(u, &UPSLOPE.long()).map_err(|why| {
                    RequestError::invalid(UPSLOPE.flag, format!("{} = {u}: {why}", UPSLOPE.long()))
                })
            })
            .transpose()?;
        let max_gap = MAX_GAP.whole_in(&mut p)?.unwrap_or_default() as usize;
        let cutoff_hz = CUTOFF.required_number_in(&mut p)?;
        let touchdowns = match TOUCHDOWNS.text_in(&mut p)? {
            None => Touchdowns::Estimated,
            Some(list) => Touchdowns::Files(list.split(',').map(PathBuf::from).collect()),
        };
        let slope_deg = SLOPE.number_in(&mut p)?;
        p.finish()?;
        Ok(TrackRequest {
            files,
            format,
            body,
            upslope,
            max_gap,
            cutoff_hz,
            touchdowns,
            slope_deg,
            stride_period_s,
            topic,
            frame,
        })
    }

    /// The analysis's options and slope, checked before any file is read.
    pub fn options(&self, words: Words) -> Result<(GaitOptions, Option<Slope>)> {
        let mut options = GaitOptions::new(self.stride_period_s)
            .map_err(|e| {
                RequestError::invalid(
                    crate::scenario::LEG_SPEED.flag,
                    format!("the robot's stride period: {e}"),
                )
            })?
            .with_cutoff(self.cutoff_hz)
            .map_err(|e| RequestError::invalid(CUTOFF.flag, e.renamed(name(words, &CUTOFF))))?
            .with_max_gap(self.max_gap);
        if let Some(u) = self.upslope {
            options = options.with_upslope(upslope(words, UPSLOPE.flag, u)?);
        }
        let slope = self
            .slope_deg
            .map(|d| {
                Slope::from_degrees(d)
                    .map_err(|e| RequestError::invalid(SLOPE.flag, e.renamed(name(words, &SLOPE))))
            })
            .transpose()?;
        let given = match &self.touchdowns {
            Touchdowns::Estimated => None,
            Touchdowns::Files(f) => Some(f.len()),
            Touchdowns::Times(t) => Some(t.len()),
        };
        if let Some(n) = given.filter(|n| *n != self.files.len()) {
            let message = match words {
                Words::Flag => format!(
                    "{} was given {n} times for {} recordings: give one touchdowns file per recording, in order",
                    TOUCHDOWNS.long(),
                    self.files.len()
                ),
                Words::Keyword => format!(
                    "touchdowns has {n} lists for {} recordings: give one per recording, in order",
                    self.files.len()
                ),
            };
            return Err(RequestError::invalid(TOUCHDOWNS.flag, message));
        }
        Ok((options, slope))
    }

    /// Reads the recordings and analyses them pooled; `on_read` runs after each file is read
    /// (a progress bar's tick). Errors name the file (and line, for a malformed file).
    pub fn answer(&self, words: Words, on_read: &mut dyn FnMut()) -> Result<Tracked> {
        let (options, slope) = self.options(words)?;
        let read = CaptureRead {
            format: self.format,
            body: self.body.as_deref(),
            cutoff_name: Some(name(words, &CUTOFF)),
            topic: self.topic.as_deref(),
            frame: self.frame.as_deref(),
        };
        track_captures(&self.files, read, &self.touchdowns, &options, slope, on_read)
    }
}

/// How capture files are read, and how an error about the cutoff names it.
#[derive(Debug, Clone)]
pub struct CaptureRead<'a> {
    /// File format; detected from each file's first line when `None`.
    pub format: Option<MocapFormat>,
    /// Rigid body, marker or model output to track (required when a file has several).
    pub body: Option<&'a str>,
    /// The cutoff's name in an error about it (`None`: as the library names it).
    pub cutoff_name: Option<String>,
    /// A ROS 2 bag's topic (docs/bags.md); the bag's only pose topic when `None`.
    pub topic: Option<&'a str>,
    /// The child frame on a bag's TF topic.
    pub frame: Option<&'a str>,
}

/// Reads `files` and analyses them pooled with `options` at `slope` (if known): the one path
/// every front end takes from capture files to the library's [`track`]. Touchdown files are
/// read after the captures.
pub fn track_captures(
    files: &[PathBuf],
    read: CaptureRead<'_>,
    touchdowns: &Touchdowns,
    options: &GaitOptions,
    slope: Option<Slope>,
    on_read: &mut dyn FnMut(),
) -> Result<Tracked> {
    let file_error = |e: anyhow::Error| RequestError::from_error(Some("files"), e);
    let captures: Vec<Capture> = files
        .iter()
        .map(|f| {
            // A ROS 2 bag (a folder with metadata.yaml, an .mcap or .db3 file) by its topic.
            let c = if sandslope_bag::is_bag(f) {
                sandslope_io::bag_series::read_capture(f, read.topic, read.frame)
            } else {
                mocap::read(f, read.format, read.body)
            };
            on_read();
            c
        })
        .collect::<anyhow::Result<_>>()
        .map_err(file_error)?;
    let touchdowns: Vec<Vec<f64>> = match touchdowns {
        Touchdowns::Estimated => Vec::new(),
        Touchdowns::Times(t) => t.clone(),
        Touchdowns::Files(paths) => paths
            .iter()
            .map(|p| mocap::load_touchdowns(p))
            .collect::<anyhow::Result<_>>()
            .map_err(|e| RequestError::from_error(Some(TOUCHDOWNS.flag), e))?,
    };
    let recordings: Vec<Recording> =
        captures.iter().enumerate().map(|(i, c)| c.recording(touchdowns.get(i).map(Vec::as_slice))).collect();
    // Upslope rises along the capture frame's vertical axis, when the files agree on one.
    let mut options = *options;
    if let [first, rest @ ..] = captures.as_slice() {
        if options.vertical().is_none() && rest.iter().all(|c| c.format == first.format) {
            if let Ok(up) = Upslope::new(first.format.vertical_axis()) {
                options = options.with_vertical(up);
            }
        }
    }
    let result = track(&recordings, &options, slope).map_err(|e| {
        file_error(match e {
            GaitError::Param { index, source } => {
                let source = match &read.cutoff_name {
                    Some(name) if source.key == "cutoff_hz" => source.renamed(name),
                    _ => source,
                };
                anyhow::anyhow!(
                    "{}: {source} (at its frame rate {} Hz)",
                    captures[index].path.display(),
                    captures[index].frame_rate_hz
                )
            }
            // Errors of the pooled analysis name the recordings they are about.
            other => match captures.as_slice() {
                [one] => anyhow::anyhow!("{}: {other}", one.path.display()),
                many => anyhow::anyhow!(
                    "{} recordings ({}{}): {other}",
                    many.len(),
                    many.iter().take(3).map(|c| c.path.display().to_string()).collect::<Vec<_>>().join(", "),
                    if many.len() > 3 { ", ..." } else { "" }
                ),
            },
        })
    })?;
    let names: Vec<String> = captures.iter().map(|c| c.path.display().to_string()).collect();
    Ok(Tracked { captures, names, result })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request() -> TrackRequest {
        TrackRequest {
            files: vec![PathBuf::from("a.csv"), PathBuf::from("b.csv")],
            format: None,
            body: None,
            upslope: None,
            max_gap: 10,
            cutoff_hz: 8.0,
            touchdowns: Touchdowns::Estimated,
            slope_deg: None,
            stride_period_s: 1.0,
            topic: None,
            frame: None,
        }
    }

    fn pairs(list: &[(&str, &str)]) -> Vec<(String, String)> {
        list.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()
    }

    /// The table's defaults are the library's (Python's signature takes those), and the
    /// fields read into the request: nothing given is the library's 10 frames and 10 Hz, the
    /// touchdowns estimated; each bad value is named by its flag.
    #[test]
    fn fields_read_by_the_table_with_the_librarys_defaults() {
        let number = |f: &Field| f.default.map(|d| d.parse::<f64>().unwrap());
        assert_eq!(number(&MAX_GAP), Some(sandslope::gait::DEFAULT_MAX_GAP as f64));
        assert_eq!(number(&CUTOFF), Some(sandslope::gait::DEFAULT_CUTOFF_HZ));
        let files = vec![PathBuf::from("a.csv"), PathBuf::from("b.csv")];
        let r = TrackRequest::from_fields(&[], files.clone(), 1.0).unwrap();
        assert_eq!(r, TrackRequest { cutoff_hz: 10.0, ..request() });
        let given = pairs(&[
            ("format", "vicon"),
            ("upslope", "-y"),
            ("touchdowns", "a.txt,b.txt"),
            ("slope", "10"),
            ("max-gap", "3"),
        ]);
        let r = TrackRequest::from_fields(&given, files.clone(), 1.0).unwrap();
        assert_eq!(
            (r.format, r.upslope, r.max_gap, r.slope_deg),
            (Some(MocapFormat::Vicon), Some([0.0, -1.0, 0.0]), 3, Some(10.0))
        );
        assert_eq!(r.touchdowns, Touchdowns::Files(vec!["a.txt".into(), "b.txt".into()]));
        let err =
            |list: &[(&str, &str)]| TrackRequest::from_fields(&pairs(list), files.clone(), 1.0).unwrap_err();
        assert_eq!(err(&[("format", "bvh")]).field(), Some("format"));
        assert!(err(&[("upslope", "up")]).message().starts_with("--upslope = up: `up` must be +x"));
        assert_eq!(
            err(&[("max-gap", "-1")]).message(),
            "--max-gap = `-1` is not a whole number of at least 0"
        );
    }

    /// Each check names its field as each front end spells it, before any file is read.
    #[test]
    fn checks_name_the_field_as_each_front_end_does() {
        let bad = TrackRequest { cutoff_hz: -1.0, ..request() };
        let e = bad.options(Words::Flag).unwrap_err();
        assert_eq!(e.field(), Some("cutoff"));
        assert!(e.message().starts_with("--cutoff = -1 must be"), "{}", e.message());
        assert!(bad.options(Words::Keyword).unwrap_err().message().starts_with("cutoff_hz = -1 must be"));
        let e = TrackRequest { slope_deg: Some(90.0), ..request() }.options(Words::Keyword).unwrap_err();
        assert_eq!(e.field(), Some("slope"));
        assert!(e.message().starts_with("slope_deg = 90 must be"), "{}", e.message());
        let e = TrackRequest { upslope: Some([0.0; 3]), ..request() }.options(Words::Flag).unwrap_err();
        assert_eq!(e.field(), Some("upslope"));
        // Three touchdown lists for two recordings.
        let td = Touchdowns::Times(vec![vec![0.5]; 3]);
        let e = TrackRequest { touchdowns: td, ..request() }.options(Words::Keyword).unwrap_err();
        assert_eq!(e.field(), Some("touchdowns"));
        assert_eq!(e.message(), "touchdowns has 3 lists for 2 recordings: give one per recording, in order");
        let (_, slope) = TrackRequest { slope_deg: Some(10.0), ..request() }.options(Words::Flag).unwrap();
        assert_eq!(slope.map(|s| s.degrees()), Some(10.0));
    }

    /// A file that does not exist is named, under the field `files`.
    #[test]
    fn a_missing_recording_is_named() {
        let r = TrackRequest { files: vec![PathBuf::from("no-such-recording.csv")], ..request() };
        let e = r.answer(Words::Flag, &mut || ()).unwrap_err();
        assert_eq!(e.field(), Some("files"));
        assert!(e.message().contains("no-such-recording.csv"), "{}", e.message());
    }

    /// The upslope grammar: an axis is the unit vector along it; a vector is kept as given
    /// (normalised once, by the analysis); a zero vector is refused, naming the flag.
    #[test]
    fn upslopes_parse_as_given() {
        assert_eq!(parse_upslope("+y", "--upslope").unwrap(), [0.0, 1.0, 0.0]);
        assert_eq!(parse_upslope("-Z", "--upslope").unwrap(), [0.0, 0.0, -1.0]);
        assert_eq!(parse_upslope(" 3, 0, 4 ", "--upslope").unwrap(), [3.0, 0.0, 4.0]);
        assert!(parse_upslope("0,0,0", "--upslope").unwrap_err().starts_with("--upslope"));
        assert!(parse_upslope("up", "--upslope").unwrap_err().contains("must be +x"));
        // (3, 0, 4) / 5, by hand.
        assert_eq!(upslope(Words::Flag, "upslope", [3.0, 0.0, 4.0]).unwrap().vector(), [0.6, 0.0, 0.8]);
    }
}
