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
        .map_err(|e| RequestError::invalid("slope", e))?;
    Ok(scenario.sweep(&slopes))
}

/// How each front end names this request's fields: the command line's flags are the
/// fields; Python's keywords carry their units (`cutoff_hz`, `slope_deg`).
fn name(words: Words, field: &str) -> String {
    match (words, field) {
        (Words::Keyword, "cutoff") => "cutoff_hz".into(),
        (Words::Keyword, "slope") => "slope_deg".into(),
        _ => words.name(field),
    }
}

/// Reads `upslope` as a direction, an error naming its field in `words`.
pub fn upslope(words: Words, field: &str, v: [f64; 3]) -> Result<Upslope> {
    Upslope::new(v).map_err(|e| RequestError::invalid(field, e.renamed(name(words, field))))
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
    /// The analysis's options and slope, checked before any file is read.
    pub fn options(&self, words: Words) -> Result<(GaitOptions, Option<Slope>)> {
        let mut options = GaitOptions::new(self.stride_period_s)
            .map_err(|e| RequestError::invalid("leg-speed", format!("the robot's stride period: {e}")))?
            .with_cutoff(self.cutoff_hz)
            .map_err(|e| RequestError::invalid("cutoff", e.renamed(name(words, "cutoff"))))?
            .with_max_gap(self.max_gap);
        if let Some(u) = self.upslope {
            options = options.with_upslope(upslope(words, "upslope", u)?);
        }
        let slope = self
            .slope_deg
            .map(|d| {
                Slope::from_degrees(d)
                    .map_err(|e| RequestError::invalid("slope", e.renamed(name(words, "slope"))))
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
                    "--touchdowns was given {n} times for {} recordings: give one touchdowns file per recording, in order",
                    self.files.len()
                ),
                Words::Keyword => format!(
                    "touchdowns has {n} lists for {} recordings: give one per recording, in order",
                    self.files.len()
                ),
            };
            return Err(RequestError::invalid("touchdowns", message));
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
            cutoff_name: Some(name(words, "cutoff")),
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
            let c = if sandslope_io::bag::is_bag(f) {
                sandslope_io::bag::series::read_capture(f, read.topic, read.frame)
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
            .map_err(|e| RequestError::from_error(Some("touchdowns"), e))?,
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
