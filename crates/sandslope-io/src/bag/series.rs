//! A bag's topic as what a command takes: a body's trajectory for `track` (poses, odometry or
//! a TF child frame, composed up its tree), a servo log for `infer --servo-log` (joint
//! states). Times are the
//! messages' header stamps (the measurement's time), or the recorder's log time where a
//! stamp is zero (a driver that does not set it).

use sandslope::servo::ServoModel;
use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{anyhow, bail, Result};

use super::messages::point;
use super::messages::{
    self, decode, JointState, Odometry, PoseStamped, RosMessage, StringMsg, TfMessage, TransformStamped,
};
use super::{describe_topics, open, scan, stamp_ns, BagMessage, BagTopic};
use crate::mocap::{Capture, MocapFormat};
use crate::servo_log::{ServoLog, ServoLogRow};

/// The message types `track --topic` reads a body's position from.
pub const POSE_TYPES: [&str; 4] =
    [PoseStamped::TYPE, Odometry::TYPE, TfMessage::TYPE, TransformStamped::TYPE];

pub(super) fn decode_at<T: RosMessage>(m: &BagMessage<'_>) -> Result<T> {
    decode::<T>(m.data).map_err(|e| anyhow!("{}: topic `{}`, message {}: {e}", m.at, m.topic, m.index))
}

/// Picks the topic: the one named (checked to exist and be of one of `types`), or the only
/// one of those types; otherwise an error listing the candidates. `flag` names the option.
pub(super) fn pick_topic(
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
pub fn read_capture(path: &Path, topic: Option<&str>, frame: Option<&str>) -> Result<Capture> {
    let Positions { name, body, samples } = read_positions(path, topic, frame)?;
    let (frame_rate_hz, start_time_s, positions) = regular(path, &name, samples)?;
    Ok(Capture {
        path: path.to_path_buf(),
        format: MocapFormat::Plain,
        body,
        frame_rate_hz,
        start_time_s,
        positions,
    })
}

/// A body's positions as read from a bag's topic, stamped (ns), not yet on a grid.
pub(super) struct Positions {
    /// The topic read.
    pub name: String,
    /// The body: the topic, with the child frame and, for a composed TF frame, its root.
    pub body: String,
    /// Stamp (ns) and position (m), in the order read.
    pub samples: Vec<(i64, [f64; 3])>,
}

/// The positions [`read_capture`] puts on its grid (the same topic and frame rules).
pub(super) fn read_positions(path: &Path, topic: Option<&str>, frame: Option<&str>) -> Result<Positions> {
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

/// What a `JointState`'s `effort` holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum EffortUnit {
    /// Torque, N m (the message's documented unit).
    #[serde(rename = "n_m")]
    NewtonMetre,
    /// Current, A, turned into torque with the servo model's K_t (docs/model.md §19).
    #[serde(rename = "a")]
    Ampere,
    /// Current, mA (as Dynamixel drivers publish Present Current).
    #[serde(rename = "ma")]
    Milliampere,
}

impl std::str::FromStr for EffortUnit {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "n_m" | "nm" | "n*m" | "torque" => Ok(EffortUnit::NewtonMetre),
            "a" | "amp" | "ampere" => Ok(EffortUnit::Ampere),
            "ma" | "milliampere" => Ok(EffortUnit::Milliampere),
            _ => Err(format!("`{s}` is not an effort unit: n_m (torque), a or ma (current)")),
        }
    }
}

impl EffortUnit {
    /// The drive torque, N m, of an effort in this unit (`K_t I` for currents, by the paper's
    /// XL330-M288; [`EffortUnit::torque_n_m_of`] for another model).
    pub fn torque_n_m(self, effort: f64) -> f64 {
        self.torque_n_m_of(effort, &sandslope::servo::ServoModel::XL330_M288)
    }

    /// The drive torque, N m, of an effort in this unit, a current by `servo`'s K_t.
    pub fn torque_n_m_of(self, effort: f64, servo: &sandslope::servo::ServoModel) -> f64 {
        match self {
            EffortUnit::NewtonMetre => effort,
            EffortUnit::Ampere => servo.torque_from_current_ma(1000.0 * effort),
            EffortUnit::Milliampere => servo.torque_from_current_ma(effort),
        }
    }
}

/// How joint states become a servo log.
#[derive(Debug, Clone, PartialEq)]
pub struct JointOptions<'a> {
    /// The `JointState` topic; when `None`, `/joint_states` if the bag has it, else the only
    /// `JointState` topic.
    pub topic: Option<&'a str>,
    /// Joint names in leg order (leg 0 first); the message's own order when `None` and it
    /// names exactly `legs` joints.
    pub joints: Option<&'a [String]>,
    /// The robot's legs (2 * stance_legs).
    pub legs: usize,
    /// What `effort` holds.
    pub effort: EffortUnit,
}

/// Reads a `sensor_msgs/JointState` topic as a servo log (docs/drive.md's columns): one row
/// per leg per message, the leg angle the joint's position (rad, in the gait's frame, as
/// `drive --log run.mcap` writes it), the drive torque its effort in `effort`'s unit, the
/// time the stamp relative to the first message. Columns a `JointState` does not carry
/// (voltage, temperature, goal) are zero. The mapping of joints to legs is in the notes.
pub fn read_joint_states(path: &Path, options: &JointOptions<'_>) -> Result<ServoLog> {
    read_joint_states_of(path, options, &ServoModel::XL330_M288)
}

/// [`read_joint_states`] for servos of model `servo` (the robot file's `[servos] model`): a
/// current effort is turned into torque, and the log's current and load columns written, by
/// its figures.
pub fn read_joint_states_of(path: &Path, options: &JointOptions<'_>, servo: &ServoModel) -> Result<ServoLog> {
    let bag = open(path)?;
    let types = [JointState::TYPE];
    let name = match options.topic {
        Some(t) => t.to_string(),
        None => {
            // ROS's own name for the robot's joint states wins among several.
            let all = scan(&bag, None, &mut |_| Ok(()))?;
            match all
                .iter()
                .find(|t| t.name == "/joint_states" && messages::same_type(&t.type_name, JointState::TYPE))
            {
                Some(t) => t.name.clone(),
                None => pick_topic(path, &all, None, &types, "--topic")?.name,
            }
        }
    };
    let legs = options.legs;
    let mut map: Option<Vec<String>> = options.joints.map(<[String]>::to_vec);
    if let Some(j) = &map {
        if j.len() != legs {
            bail!("--joints names {} joints, but the robot has {legs} legs (2 * stance_legs); name one per leg, in leg order", j.len());
        }
    }
    let mut rows: Vec<(i64, u64, ServoLogRow)> = Vec::new();
    let mut notes = Vec::new();
    let all = scan(&bag, Some(&name), &mut |m| {
        if !messages::same_type(m.type_name, JointState::TYPE) {
            bail!("{}: topic `{}` is {}, not {}", path.display(), m.topic, m.type_name, JointState::TYPE);
        }
        let js: JointState = decode_at(m)?;
        let at = || format!("{}: topic `{}`, message {}", m.at, m.topic, m.index);
        if js.position.len() != js.name.len() || js.effort.len() != js.name.len() {
            bail!(
                "{}: {} names, {} positions and {} efforts; the leg angle and the effort (current or torque) of \
                 every joint are needed",
                at(),
                js.name.len(),
                js.position.len(),
                js.effort.len()
            );
        }
        let order = map.get_or_insert_with(|| js.name.clone());
        if order.len() != legs {
            bail!(
                "{}: the message names {} joints ({}), the robot has {legs} legs; give their names in leg order with --joints",
                at(),
                order.len(),
                order.join(", ")
            );
        }
        let t = stamp_ns(&js.header, m);
        for (k, joint) in js.name.iter().enumerate() {
            let Some(leg) = order.iter().position(|n| n == joint) else { continue };
            let (angle, effort) = (js.position[k], js.effort[k]);
            if !angle.is_finite() || !effort.is_finite() {
                continue;
            }
            let torque = options.effort.torque_n_m_of(effort, servo);
            let velocity = js.velocity.get(k).copied().unwrap_or(0.0);
            use sandslope::servo::model as x;
            let current_ma = servo.current_ma_from_torque(torque);
            rows.push((
                t,
                m.index,
                ServoLogRow {
                    time_s: 0.0,
                    id: leg.min(252) as u8,
                    leg,
                    tripod: leg % 2,
                    present_position: x::pulses_from_rad(angle).clamp(i32::MIN.into(), i32::MAX.into())
                        as i32,
                    present_velocity: (velocity / x::RAD_S_PER_VELOCITY_UNIT).round().clamp(-1e9, 1e9) as i32,
                    present_current_ma: current_ma.round().clamp(-1e9, 1e9) as i32,
                    load_percent: 100.0 * current_ma / (servo.stall_current_a * 1000.0),
                    input_voltage_v: 0.0,
                    temperature_c: 0,
                    hardware_error: 0,
                    goal_position: 0,
                    leg_angle_rad: angle,
                    drive_torque_n_m: torque,
                },
            ));
        }
        if rows.len() > crate::servo_log::MAX_ROWS {
            bail!("{}: more than {} rows; split the bag", at(), crate::servo_log::MAX_ROWS);
        }
        Ok(())
    })?;
    pick_topic(path, &all, Some(&name), &types, "--topic")?;
    let meta = run_header(&bag, &all)?;
    let order = map.unwrap_or_default();
    for (leg, joint) in order.iter().enumerate() {
        if !rows.iter().any(|r| r.2.leg == leg) {
            bail!("{}: topic `{name}`: no message carries joint `{joint}` (leg {leg})", path.display());
        }
    }
    rows.sort_by_key(|r| (r.0, r.2.leg));
    let t0 = rows.first().map_or(0, |r| r.0);
    notes.push(format!(
        "topic `{name}`: joints {} read as legs 0 to {}; effort in {}",
        order.join(", "),
        legs.saturating_sub(1),
        match options.effort {
            EffortUnit::NewtonMetre => "N m",
            EffortUnit::Ampere => "A (torque = K_t I)",
            EffortUnit::Milliampere => "mA (torque = K_t I)",
        }
    ));
    let lines = rows.iter().map(|r| r.1 as usize + 1).collect();
    let rows = rows
        .into_iter()
        .map(|(t, _, mut r)| {
            r.time_s = (t - t0) as f64 * 1e-9;
            r
        })
        .collect();
    Ok(ServoLog { meta, rows, lines, notes })
}

/// The `key = value` lines of a bag's [`RUN_TOPIC`] (what `drive --log run.mcap` writes
/// there: the CSV log's header, the slope among them); empty when the bag has none.
fn run_header(bag: &super::Bag, topics: &[BagTopic]) -> Result<BTreeMap<String, String>> {
    let mut meta = BTreeMap::new();
    if topics.iter().any(|t| t.name == RUN_TOPIC && messages::same_type(&t.type_name, StringMsg::TYPE)) {
        scan(bag, Some(RUN_TOPIC), &mut |m| {
            let text: StringMsg = decode_at(m)?;
            for line in text.data.lines() {
                if let Some((k, v)) = line.split_once('=') {
                    meta.insert(k.trim().to_string(), v.trim().to_string());
                }
            }
            Ok(())
        })?;
    }
    Ok(meta)
}

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

    #[test]
    fn efforts_become_torques() {
        assert_eq!("MA".parse::<EffortUnit>().unwrap(), EffortUnit::Milliampere);
        // K_t = 0.52 N m / 1.47 A: 1.47 A is the stall torque.
        assert!((EffortUnit::Ampere.torque_n_m(1.47) - 0.52).abs() < 1e-12);
        assert!((EffortUnit::Milliampere.torque_n_m(1470.0) - 0.52).abs() < 1e-12);
        assert_eq!(EffortUnit::NewtonMetre.torque_n_m(0.3), 0.3);
        assert!("volts".parse::<EffortUnit>().is_err());
        // Another model's K_t (the robot file's [servos] model): the XM430-W350's 4.1 N m at
        // 2.3 A, so 1.15 A is 2.05 N m; a torque stays a torque.
        let xm = &sandslope::servo::ServoModel::XM430_W350;
        assert!((EffortUnit::Ampere.torque_n_m_of(1.15, xm) - 2.05).abs() < 1e-12);
        assert!((EffortUnit::Milliampere.torque_n_m_of(2300.0, xm) - 4.1).abs() < 1e-12);
        assert_eq!(EffortUnit::NewtonMetre.torque_n_m_of(0.3, xm), 0.3);
    }
}
