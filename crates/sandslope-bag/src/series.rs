//! A bag's topic as a body's trajectory for `track` (poses, odometry or a TF child frame,
//! composed up its tree), on a regular grid of times; sandslope-io's `bag_series` makes it a
//! motion capture, and reads joint states as a servo log. Times are the messages' header
//! stamps (the measurement's time), or the recorder's log time where a stamp is zero (a
//! driver that does not set it).

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{anyhow, bail, Result};

use super::messages::point;
use super::messages::{self, decode, Odometry, PoseStamped, RosMessage, TfMessage, TransformStamped};
use super::{describe_topics, open, scan, stamp_ns, BagMessage, BagTopic};

/// The message types `track --topic` reads a body's position from.
pub const POSE_TYPES: [&str; 4] =
    [PoseStamped::TYPE, Odometry::TYPE, TfMessage::TYPE, TransformStamped::TYPE];

/// Decodes a message as `T`; an error names the bag, the topic and the message's index.
pub fn decode_at<T: RosMessage>(m: &BagMessage<'_>) -> Result<T> {
    decode::<T>(m.data).map_err(|e| anyhow!("{}: topic `{}`, message {}: {e}", m.at, m.topic, m.index))
}

/// Picks the topic: the one named (checked to exist and be of one of `types`), or the only
/// one of those types; otherwise an error listing the candidates. `flag` names the option.
pub fn pick_topic(
    path: &Path,
    topics: &[BagTopic],
    wanted: Option<&str>,
    types: &[&str],
    flag: &str,
) -> Result<BagTopic> {
    let fits = |t: &BagTopic| types.iter().any(|w| messages::same_type(&t.type_name, w));
    match wanted {
        Some(w) => {
            let t = topics.iter().find(|t| t.name == w).ok_or_else(|| {
                anyhow!("{}: no topic `{w}`; the bag has: {}", path.display(), describe_topics(topics, types))
            })?;
            if !fits(t) {
                bail!(
                    "{}: topic `{w}` is {}, not one of {}; the bag has: {}",
                    path.display(),
                    t.type_name,
                    types.join(", "),
                    describe_topics(topics, types)
                );
            }
            Ok(t.clone())
        }
        None => {
            let candidates: Vec<&BagTopic> = topics.iter().filter(|t| fits(t) && t.messages > 0).collect();
            match candidates.as_slice() {
                [one] => Ok((*one).clone()),
                [] => bail!(
                    "{}: no topic of type {}; the bag has: {}",
                    path.display(),
                    types.join(", "),
                    describe_topics(topics, types)
                ),
                many => bail!(
                    "{}: several candidate topics; choose one with {flag}: {}",
                    path.display(),
                    many.iter()
                        .map(|t| format!("{} ({}, {} messages)", t.name, t.type_name, t.messages))
                        .collect::<Vec<_>>()
                        .join("; ")
                ),
            }
        }
    }
}

/// Reads one body's trajectory from a bag: the positions on `topic` (a `PoseStamped`,
/// `Odometry`, `TransformStamped` or `TFMessage` topic; the only such topic when `None`),
/// for `TFMessage` the child frame `frame` (the only one when `None`) composed up its tree to
/// the root (docs/bags.md; for `Odometry` and `TransformStamped`, `frame` must be the child
/// frame when given). Positions are put on the regular grid of the median time step
/// (exactly, when every stamp lies within a quarter step of it; else interpolated linearly,
/// a gap longer than two steps left as occlusion). The capture frame is ROS's: z up (REP
/// 103), the plain format's.
pub fn read_grid(path: &Path, topic: Option<&str>, frame: Option<&str>) -> Result<GridPositions> {
    let Positions { name, body, samples } = read_positions(path, topic, frame)?;
    let (frame_rate_hz, start_time_s, positions) = regular(path, &name, samples)?;
    Ok(GridPositions { body, frame_rate_hz, start_time_s, positions })
}

/// A body's positions on a regular grid of times ([`read_grid`]).
#[derive(Debug, Clone)]
pub struct GridPositions {
    /// The body: the topic, with the child frame and, for a composed TF frame, its root.
    pub body: String,
    /// Frames per second (one over the median time step).
    pub frame_rate_hz: f64,
    /// The first frame's time, s (0: the clock starts at the first position).
    pub start_time_s: f64,
    /// Positions (m), one a frame, NaN where the body was not seen (a gap, an occlusion).
    pub positions: Vec<[f64; 3]>,
}

/// A body's positions as read from a bag's topic, stamped (ns), not yet on a grid.
pub(crate) struct Positions {
    /// The topic read.
    pub name: String,
    /// The body: the topic, with the child frame and, for a composed TF frame, its root.
    pub body: String,
    /// Stamp (ns) and position (m), in the order read.
    pub samples: Vec<(i64, [f64; 3])>,
}

/// The positions [`read_grid`] puts on its grid (the same topic and frame rules).
pub(crate) fn read_positions(path: &Path, topic: Option<&str>, frame: Option<&str>) -> Result<Positions> {
    let bag = open(path)?;
    let listed;
    let topics = match topic {
        Some(_) => None,
        None => {
            listed = scan(&bag, None, &mut |_| Ok(()))?;
            Some(listed.as_slice())
        }
    };
    let chosen = topics.map(|t| pick_topic(path, t, None, &POSE_TYPES, "--topic")).transpose()?;
    let name = chosen.as_ref().map_or_else(|| topic.unwrap_or_default().to_string(), |t| t.name.clone());
    let frame = frame.map(|f| f.trim_start_matches('/').to_string());
    // Child frames seen on a TF topic (when no frame is given and several appear, the list).
    let mut frames: BTreeMap<String, u64> = BTreeMap::new();
    let mut samples: Vec<(i64, [f64; 3])> = Vec::new();
    // On a TF topic: every child frame's parent, and the frame's own transforms.
    let mut tf = super::tf::TfFrames::default();
    let mut kind: Option<String> = None;
    let all = scan(&bag, Some(&name), &mut |m| {
        let type_name = m.type_name;
        if kind.is_none() {
            if !POSE_TYPES.iter().any(|t| messages::same_type(type_name, t)) {
                bail!(
                    "{}: topic `{}` is {type_name}, not one of {}",
                    path.display(),
                    m.topic,
                    POSE_TYPES.join(", ")
                );
            }
            kind = Some(type_name.to_string());
        }
        let child_matches = |child: &str| frame.as_deref().is_none_or(|f| f == child.trim_start_matches('/'));
        if messages::same_type(type_name, PoseStamped::TYPE) {
            let p: PoseStamped = decode_at(m)?;
            samples.push((stamp_ns(&p.header, m), point(p.pose.position)));
        } else if messages::same_type(type_name, Odometry::TYPE) {
            let o: Odometry = decode_at(m)?;
            if child_matches(&o.child_frame_id) {
                samples.push((stamp_ns(&o.header, m), point(o.pose.pose.position)));
            }
            *frames.entry(o.child_frame_id).or_default() += 1;
        } else if messages::same_type(type_name, TransformStamped::TYPE) {
            let t: TransformStamped = decode_at(m)?;
            if child_matches(&t.child_frame_id) {
                samples.push((stamp_ns(&t.header, m), point(t.transform.translation)));
            }
            *frames.entry(t.child_frame_id).or_default() += 1;
        } else {
            tf.add(decode_at(m)?, m, frame.as_deref(), &mut samples, &mut frames)?;
        }
        if samples.len() as u64 > super::MAX_MESSAGES {
            bail!(
                "{}: topic `{}`: more than {} positions; split the bag",
                m.at,
                m.topic,
                super::MAX_MESSAGES
            );
        }
        Ok(())
    })?;
    // The topic named must exist and be of a pose type (checked here when it held no message).
    let t = pick_topic(path, &all, Some(&name), &POSE_TYPES, "--topic")?;
    let list_frames = || frames.iter().map(|(f, n)| format!("{f} ({n})")).collect::<Vec<_>>().join(", ");
    let is_tf = messages::same_type(&t.type_name, TfMessage::TYPE);
    let mut body = name.clone();
    if frame.is_none() && (frames.len() > 1 || (is_tf && frames.len() == 1)) {
        // No frame given: on a TF topic the only child frame, read again; else the list.
        match frames.keys().collect::<Vec<_>>().as_slice() {
            [only] => return read_positions(path, Some(&name), Some(only)),
            _ => bail!(
                "{}: topic `{name}` carries several child frames; choose one with --frame: {}",
                path.display(),
                list_frames()
            ),
        }
    }
    if let Some(f) = &frame {
        if messages::same_type(&t.type_name, PoseStamped::TYPE) {
            bail!(
                "{}: --frame selects a child frame, but topic `{name}` is {} (no child frame)",
                path.display(),
                t.type_name
            );
        }
        if samples.is_empty() {
            bail!("{}: topic `{name}` has no child frame `{f}`; it has: {}", path.display(), list_frames());
        }
        body = format!("{name} {f}");
        if is_tf {
            let parent = tf.parents.get(f).cloned().unwrap_or_default();
            let target = super::tf::FrameSamples { frame: f, parent: &parent, samples: tf.samples };
            let (composed, root) = super::tf::in_root(&bag, path, &name, &all, target, &tf.parents)?;
            if root != parent {
                body = format!("{name} {f} in {root}");
                samples = composed
                    .into_iter()
                    .map(|(t, p)| (t, point(messages::Point { x: p[0], y: p[1], z: p[2] })))
                    .collect();
            }
        }
    }
    Ok(Positions { name, body, samples })
}

/// Frames that may be missing per sample beyond [`MIN_MISSING_ALLOWED`] (as the plain
/// motion-capture reader allows): more is a wrong stamp, not an occlusion.
const MISSING_PER_SAMPLE: f64 = 10.0;
/// Missing frames always allowed.
const MIN_MISSING_ALLOWED: f64 = 100_000.0;

/// Puts time-stamped positions on a regular grid: frame rate, start time, positions.
fn regular(path: &Path, topic: &str, mut samples: Vec<(i64, [f64; 3])>) -> Result<(f64, f64, Vec<[f64; 3]>)> {
    samples.sort_by_key(|s| s.0);
    samples.dedup_by_key(|s| s.0);
    if samples.len() < 2 {
        bail!(
            "{}: topic `{topic}`: {} position(s) with distinct stamps; at least two are needed to know the frame rate",
            path.display(),
            samples.len()
        );
    }
    let t0 = samples[0].0;
    let secs = |ns: i64| (ns - t0) as f64 * 1e-9;
    let mut steps: Vec<i64> = samples.windows(2).map(|w| w[1].0 - w[0].0).collect();
    steps.sort_unstable();
    let median = steps[steps.len() / 2] as f64 * 1e-9;
    let span = secs(samples[samples.len() - 1].0);
    let dt = span / (span / median).round().max(1.0);
    let n = samples.len() as f64;
    let frames = (span / dt).round() + 1.0;
    let max_frames = (MISSING_PER_SAMPLE * n).max(MIN_MISSING_ALLOWED) + n;
    if frames > max_frames {
        bail!(
            "{}: topic `{topic}`: {n} positions over {span} s at {dt} s steps would be {frames} frames, most of \
             them missing (at most {} may be); a wrong stamp, or a recording to split",
            path.display(),
            max_frames - n
        );
    }
    let on_grid = samples.iter().all(|(t, _)| {
        let x = secs(*t) / dt;
        (x - x.round()).abs() <= 0.25
    });
    let mut positions = vec![[f64::NAN; 3]; frames as usize];
    if on_grid {
        let last = positions.len() - 1;
        for (t, p) in &samples {
            let k = (secs(*t) / dt).round() as usize;
            positions[k.min(last)] = *p;
        }
    } else {
        // Linear interpolation between the two samples around each frame, when they are at
        // most two steps apart (a longer gap is an occlusion).
        let mut j = 0;
        for (k, out) in positions.iter_mut().enumerate() {
            let t = k as f64 * dt;
            while j + 2 < samples.len() && secs(samples[j + 1].0) < t {
                j += 1;
            }
            let (ta, pa) = (secs(samples[j].0), samples[j].1);
            let (tb, pb) = (secs(samples[j + 1].0), samples[j + 1].1);
            if tb - ta <= 2.0 * dt + 1e-12 && (ta..=tb).contains(&t) {
                let w = (t - ta) / (tb - ta);
                *out = std::array::from_fn(|i| pa[i] + w * (pb[i] - pa[i]));
            }
        }
    }
    // The recording's clock starts at its first position (a bag's stamps are wall-clock
    // nanoseconds, 1.7e9 s, where a double's step is 0.24 us).
    Ok((1.0 / dt, 0.0, positions))
}

/// The topic `drive --log run.mcap` writes its log's header on.
pub const RUN_TOPIC: &str = "/sandslope/run";

#[cfg(test)]
mod tests {
    use super::*;

    /// Stamps within a quarter step of the grid are snapped (the values kept exactly); one
    /// off it makes every frame an interpolation, which on a straight line at 1 m/s gives
    /// x = t at every frame (worked by hand: steps 10, 13, 7, 10 ms, median 10 ms, span 40 ms).
    #[test]
    fn positions_are_put_on_the_median_grid() {
        let path = Path::new("b.mcap");
        let at = |ms: i64, x: f64| (ms * 1_000_000, [x, 0.0, 0.0]);
        let (hz, t0, p) =
            regular(path, "/p", vec![at(0, 5.0), at(11, 6.0), at(19, 7.0), at(30, 8.0)]).unwrap();
        assert_eq!((hz, t0), (100.0, 0.0));
        assert_eq!(p.iter().map(|p| p[0]).collect::<Vec<_>>(), vec![5.0, 6.0, 7.0, 8.0]);
        let line = [0, 10, 23, 30, 40].map(|ms| at(ms, ms as f64 * 1e-3));
        let (hz, _, p) = regular(path, "/p", line.to_vec()).unwrap();
        assert!((hz - 100.0).abs() < 1e-9);
        for (k, v) in p.iter().enumerate() {
            assert!((v[0] - k as f64 * 0.01).abs() < 1e-15, "frame {k}: {}", v[0]);
        }
        // A gap of more than two steps is left as an occlusion, snapped or interpolated (53 ms
        // is off the 10 ms grid by 0.3 of a step).
        let (_, _, p) = regular(path, "/p", [0, 10, 20, 50, 60, 70].map(|ms| at(ms, 1.0)).to_vec()).unwrap();
        assert!(p[3][0].is_nan() && p[4][0].is_nan() && p[2][0] == 1.0 && p[5][0] == 1.0);
        let (_, _, p) = regular(path, "/p", [0, 10, 20, 53, 60, 70].map(|ms| at(ms, 1.0)).to_vec()).unwrap();
        assert!(p[3..=5].iter().all(|v| v[0].is_nan()) && p[2][0] == 1.0 && p[6][0] == 1.0);
        let e = regular(path, "/p", vec![at(0, 1.0)]).unwrap_err().to_string();
        assert!(e.contains("b.mcap: topic `/p`: 1 position(s)"), "{e}");
    }
}
