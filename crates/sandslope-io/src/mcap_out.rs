//! MCAP as an output (docs/bags.md): ROS 2 messages, CDR-encoded, with their `ros2msg`
//! definitions embedded as schemas, so that Foxglove, `ros2 bag play` and any MCAP reader
//! decode them without sandslope's or ROS's message packages. Written by the `mcap` crate
//! (zstd chunks, CRCs, summary and indexes).
//!
//! [`McapOut`] collects a file in memory (the project's outputs are put in place whole, by
//! `files::write_output`); [`simulation_mcap`] is `simulate --out walk.mcap`.

use std::collections::BTreeMap;
use std::io::Cursor;

use anyhow::{anyhow, Result};

use sandslope_bag::messages::{
    self as msg, ColorRgba, Header, JointState, Marker, MarkerArray, Point, Pose, PoseStamped, Quaternion,
    RosMessage, TfMessage, Time, Transform, TransformStamped,
};

/// An MCAP file being written in memory, channel by topic.
pub struct McapOut {
    writer: mcap::Writer<Cursor<Vec<u8>>>,
    schemas: BTreeMap<&'static str, u16>,
    channels: BTreeMap<String, (u16, u32)>,
}

impl std::fmt::Debug for McapOut {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("McapOut").field("channels", &self.channels.keys().collect::<Vec<_>>()).finish()
    }
}

fn mcap_error(e: mcap::McapError) -> anyhow::Error {
    anyhow!("writing MCAP: {e}")
}

impl McapOut {
    /// A new file (profile `ros2`, zstd chunks).
    pub fn new() -> Result<McapOut> {
        let writer = mcap::WriteOptions::new()
            .profile("ros2")
            .compression(Some(mcap::Compression::Zstd))
            .create(Cursor::new(Vec::new()))
            .map_err(mcap_error)?;
        Ok(McapOut { writer, schemas: BTreeMap::new(), channels: BTreeMap::new() })
    }

    /// Writes `message` on `topic` at `time_ns` (log and publish time; the caller keeps them
    /// in order).
    pub fn write<T: RosMessage>(&mut self, topic: &str, time_ns: u64, message: &T) -> Result<()> {
        let schema = match self.schemas.get(T::TYPE) {
            Some(&id) => id,
            None => {
                let id = self
                    .writer
                    .add_schema(T::TYPE, "ros2msg", T::definition().as_bytes())
                    .map_err(mcap_error)?;
                self.schemas.insert(T::TYPE, id);
                id
            }
        };
        let (channel, sequence) = match self.channels.get(topic) {
            Some(&c) => c,
            None => {
                let id =
                    self.writer.add_channel(schema, topic, "cdr", &BTreeMap::new()).map_err(mcap_error)?;
                (id, 0)
            }
        };
        self.channels.insert(topic.to_string(), (channel, sequence.wrapping_add(1)));
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence,
            log_time: time_ns,
            publish_time: time_ns,
        };
        self.writer.write_to_known_channel(&header, &msg::encode(message)).map_err(mcap_error)
    }

    /// Finishes the file (summary, indexes, footer) and returns its bytes.
    pub fn finish(mut self) -> Result<Vec<u8>> {
        self.writer.finish().map_err(mcap_error)?;
        Ok(self.writer.into_inner().into_inner())
    }
}

/// Nanoseconds of a time in seconds from the run's start (negative times, the stand-up before
/// a gait, are kept by starting the clock `offset_s` earlier).
fn ns(t_s: f64, offset_s: f64) -> u64 {
    ((t_s + offset_s) * 1e9).round().max(0.0) as u64
}

/// The header of a message at `t_ns` in `frame`.
fn header(t_ns: u64, frame: &str) -> Header {
    Header { stamp: Time::from_nanos(t_ns.min(i64::MAX as u64) as i64), frame_id: frame.into() }
}

/// Scale of the force arrows, m per N.
pub const FORCE_ARROW_M_PER_N: f64 = 0.02;

/// A simulated walk as MCAP (`simulate --out walk.mcap`; docs/model.md §15-§18), in ROS's
/// frames (x forward, z up, REP 103) with the slope frame turned into the world as
/// `plain_mocap_csv` does (`X = x cos theta - z sin theta`, `Z = x sin theta + z cos theta`):
///
/// - `/sandslope/pose` (`geometry_msgs/PoseStamped`, frame `world`): the body's centre and
///   its attitude, pitched nose-up by the slope plus the body's pitch (a rotation about y by
///   minus that angle);
/// - `/tf` (`tf2_msgs/TFMessage`): `world` to `base_link` (the same pose) and `base_link` to
///   `leg_0` ... `leg_{n-1}` at each hip (x from the simulator's geometry), turned about y by
///   the leg's angle (the crank angle of docs/model.md §15);
/// - `/joint_states` (`sensor_msgs/JointState`): each leg's angle, rad, and servo torque, N m;
/// - `/sandslope/leg_forces` (`visualization_msgs/MarkerArray`, frame `world`): each leg's
///   sand force as an arrow from its hip, [`FORCE_ARROW_M_PER_N`] metres per newton.
///
/// Times are the simulation's, from 0.
pub fn simulation_mcap(
    trajectory: &sandslope::simulate::Trajectory,
    geometry: &sandslope::simulate::Geometry,
    slope_deg: f64,
) -> Result<Vec<u8>> {
    let mut out = McapOut::new()?;
    simulation_messages(trajectory, geometry, slope_deg, &mut out)?;
    out.finish()
}

/// Where ROS 2 messages go: an MCAP file ([`McapOut`]) or a live stream (`foxglove`).
pub trait RosSink {
    /// Sends `message` on `topic` at `time_ns`.
    fn send<T: RosMessage>(&mut self, topic: &str, time_ns: u64, message: &T) -> Result<()>;
}

impl RosSink for McapOut {
    fn send<T: RosMessage>(&mut self, topic: &str, time_ns: u64, message: &T) -> Result<()> {
        self.write(topic, time_ns, message)
    }
}

/// The messages of [`simulation_mcap`], in time order, to any [`RosSink`].
pub fn simulation_messages<S: RosSink>(
    trajectory: &sandslope::simulate::Trajectory,
    geometry: &sandslope::simulate::Geometry,
    slope_deg: f64,
    out: &mut S,
) -> Result<()> {
    let theta = slope_deg.to_radians();
    let (s, c) = theta.sin_cos();
    let world = |x: f64, z: f64| (x * c - z * s, x * s + z * c);
    let legs = geometry.hip_x_m.len();
    let names: Vec<String> = (0..legs).map(|j| format!("leg_{j}")).collect();
    let offset = trajectory.time_s.first().map_or(0.0, |t| (-t).max(0.0));
    let at =
        |v: &Vec<Vec<f64>>, j: usize, i: usize| v.get(j).and_then(|l| l.get(i)).copied().unwrap_or(f64::NAN);
    for (i, &t) in trajectory.time_s.iter().enumerate() {
        let t_ns = ns(t, offset);
        let (wx, wz) = world(trajectory.x_m[i], trajectory.z_m[i]);
        let attitude = Quaternion::about([0.0, 1.0, 0.0], -(theta + trajectory.pitch_rad[i]));
        let pose = Pose { position: Point { x: wx, y: 0.0, z: wz }, orientation: attitude };
        out.send("/sandslope/pose", t_ns, &PoseStamped { header: header(t_ns, "world"), pose })?;
        let mut transforms = vec![TransformStamped {
            header: header(t_ns, "world"),
            child_frame_id: "base_link".into(),
            transform: Transform { translation: pose.position, rotation: attitude },
        }];
        for (j, name) in names.iter().enumerate() {
            transforms.push(TransformStamped {
                header: header(t_ns, "base_link"),
                child_frame_id: name.clone(),
                transform: Transform {
                    translation: Point { x: geometry.hip_x_m[j], y: 0.0, z: 0.0 },
                    rotation: Quaternion::about([0.0, 1.0, 0.0], at(&trajectory.leg_angle_rad, j, i)),
                },
            });
        }
        out.send("/tf", t_ns, &TfMessage { transforms })?;
        let joint = JointState {
            header: header(t_ns, ""),
            name: names.clone(),
            position: (0..legs).map(|j| at(&trajectory.leg_angle_rad, j, i)).collect(),
            velocity: Vec::new(),
            effort: (0..legs).map(|j| at(&trajectory.leg_torque_n_m, j, i)).collect(),
        };
        out.send("/joint_states", t_ns, &joint)?;
        let pitch = trajectory.pitch_rad[i];
        let markers = (0..legs)
            .map(|j| {
                // The hip in the slope frame (the body pitched about its centre), then the world.
                let hx = trajectory.x_m[i] + geometry.hip_x_m[j] * pitch.cos();
                let hz = trajectory.z_m[i] + geometry.hip_x_m[j] * pitch.sin();
                let (fx, fz) = (at(&trajectory.leg_force_x_n, j, i), at(&trajectory.leg_force_z_n, j, i));
                let (ax, az) = world(hx, hz);
                let (bx, bz) = world(hx + FORCE_ARROW_M_PER_N * fx, hz + FORCE_ARROW_M_PER_N * fz);
                Marker {
                    header: header(t_ns, "world"),
                    ns: "leg_forces".into(),
                    id: j as i32,
                    kind: 0,
                    action: 0,
                    pose: Pose::default(),
                    scale: Point { x: 0.004, y: 0.008, z: 0.0 },
                    color: ColorRgba { r: 0.85, g: 0.35, b: 0.1, a: 1.0 },
                    points: vec![Point { x: ax, y: 0.0, z: az }, Point { x: bx, y: 0.0, z: bz }],
                    ..Marker::default()
                }
            })
            .collect();
        out.send("/sandslope/leg_forces", t_ns, &MarkerArray { markers })?;
    }
    Ok(())
}

/// One live estimate of a `drive` run (docs/model.md §19), as `/sandslope/live` carries it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LiveRecord {
    /// Gait time at the end of the stance, s.
    pub time_s: f64,
    /// The numbers, in the order of [`LIVE_FIELDS`].
    pub values: [f64; 10],
}

/// The live estimate's numbers as `/sandslope/live`'s `Float64MultiArray` orders them (its
/// one dimension's label lists them).
pub const LIVE_FIELDS: [&str; 10] = [
    "tripod",
    "k_s_n_m3",
    "k_s_lo_n_m3",
    "k_s_hi_n_m3",
    "speed_m_s",
    "speed_lo_m_s",
    "speed_hi_m_s",
    "p_fail",
    "p_slippage",
    "p_sinkage",
];

/// A `drive` run as MCAP (`drive --log run.mcap`; docs/drive.md's log as ROS 2 messages),
/// from the rows of its servo log (one per servo per bus cycle), its live estimates, its
/// header's `key = value` pairs and its outcome:
///
/// - `/sandslope/run` (`std_msgs/String`, at the start): the header, one `key = value` a line;
/// - `/joint_states` (`sensor_msgs/JointState`, one per cycle): joints `leg_0` ... in leg
///   order, position the leg angle in the gait's frame (rad), velocity from Present Velocity
///   (rad/s, the shaft's sense), effort the drive torque `K_t I` (N m) — what
///   `infer --servo-log run.mcap` reads back;
/// - `/sandslope/commands` (`sensor_msgs/JointState`, one per cycle): the goal position sent,
///   as the shaft's angle (rad, Goal Position x 2 pi / 4096);
/// - `/sandslope/live` (`std_msgs/Float64MultiArray`, one per stance with `--live`):
///   [`LIVE_FIELDS`];
/// - `/sandslope/verdict` (`std_msgs/String`, at the end): how the run ended.
///
/// Times are gait times, the clock started at the first row (the stand-up's negative times
/// kept in order).
pub fn drive_mcap(
    rows: &[crate::servo_log::ServoLogRow],
    live: &[LiveRecord],
    meta: &[(&str, String)],
    verdict: &str,
) -> Result<Vec<u8>> {
    use sandslope_bag::messages::StringMsg;
    let offset = rows.iter().map(|r| r.time_s).fold(0.0f64, f64::min).abs();
    let mut out = McapOut::new()?;
    let text: String = meta.iter().map(|(k, v)| format!("{k} = {v}\n")).collect();
    out.write(
        sandslope_bag::series::RUN_TOPIC,
        ns(rows.first().map_or(0.0, |r| r.time_s), offset),
        &StringMsg { data: text },
    )?;
    let mut live = live.iter().peekable();
    let mut end = 0;
    let mut last_ns = 0;
    while end < rows.len() {
        // One bus cycle: the rows at one time.
        let start = end;
        while end < rows.len() && rows[end].time_s == rows[start].time_s {
            end += 1;
        }
        let cycle = &rows[start..end];
        let t_ns = ns(cycle[0].time_s, offset).max(last_ns);
        while let Some(l) = live.next_if(|l| l.time_s <= cycle[0].time_s) {
            let at = ns(l.time_s, offset).max(last_ns);
            out.write("/sandslope/live", at, &live_message(l))?;
            last_ns = at;
        }
        let t_ns = t_ns.max(last_ns);
        let (state, command) = cycle_joint_states(cycle, t_ns);
        out.write("/joint_states", t_ns, &state)?;
        out.write("/sandslope/commands", t_ns, &command)?;
        last_ns = t_ns;
    }
    for l in live {
        let at = ns(l.time_s, offset).max(last_ns);
        out.write("/sandslope/live", at, &live_message(l))?;
        last_ns = at;
    }
    out.write("/sandslope/verdict", last_ns, &StringMsg { data: verdict.to_string() })?;
    out.finish()
}

/// One bus cycle's rows (one per servo) as `/joint_states` (leg angle in the gait's frame,
/// the shaft's velocity in rad/s, the drive torque in N m) and `/sandslope/commands` (the goal
/// position as the shaft's angle, rad), both stamped `t_ns`: what [`drive_mcap`] writes a
/// cycle and `foxglove::DriveStream` sends live.
pub fn cycle_joint_states(cycle: &[crate::servo_log::ServoLogRow], t_ns: u64) -> (JointState, JointState) {
    use sandslope::servo::model as x;
    let mut state = JointState { header: header(t_ns, ""), ..JointState::default() };
    let mut command = JointState { header: header(t_ns, ""), ..JointState::default() };
    for r in cycle {
        let name = format!("leg_{}", r.leg);
        state.name.push(name.clone());
        state.position.push(r.leg_angle_rad);
        state.velocity.push(f64::from(r.present_velocity) * x::RAD_S_PER_VELOCITY_UNIT);
        state.effort.push(r.drive_torque_n_m);
        command.name.push(name);
        command.position.push(f64::from(r.goal_position) * x::RAD_PER_PULSE);
    }
    (state, command)
}

/// A live estimate as `/sandslope/live` carries it (one dimension labelled [`LIVE_FIELDS`]).
pub fn live_message(l: &LiveRecord) -> sandslope_bag::messages::Float64Array {
    use sandslope_bag::messages::{ArrayDimension, ArrayLayout, Float64Array};
    let layout = ArrayLayout {
        dim: vec![ArrayDimension { label: LIVE_FIELDS.join(","), size: 10, stride: 10 }],
        data_offset: 0,
    };
    Float64Array { layout, data: l.values.to_vec() }
}

/// How a run ended, as `/sandslope/verdict` says it: the failure when there is one, else the
/// outcome as `drive --json` gives it (`{"outcome": "completed", ...}`, never Rust's
/// `Result`), else why it did not start.
pub fn verdict_text<T: serde::Serialize>(
    outcome: &std::result::Result<T, String>,
    failure: Option<&dyn std::fmt::Display>,
) -> String {
    match (failure, outcome) {
        (Some(e), _) => e.to_string(),
        (None, Ok(outcome)) => serde_json::to_string(outcome).unwrap_or_default(),
        (None, Err(why)) => why.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sandslope_bag::messages::decode;

    /// A two-sample walk written and read back with the `mcap` crate's own reader: schemas,
    /// channels, message counts and one pose worked by hand.
    #[test]
    fn a_walk_reads_back() {
        let tr = sandslope::simulate::Trajectory {
            time_s: vec![0.0, 0.5],
            x_m: vec![0.0, 1.0],
            z_m: vec![0.0, 0.0],
            pitch_rad: vec![0.0; 2],
            vx_m_s: vec![0.0; 2],
            vz_m_s: vec![0.0; 2],
            leg_angle_rad: vec![vec![0.0, 1.0]; 2],
            leg_depth_m: vec![vec![0.0; 2]; 2],
            leg_force_x_n: vec![vec![1.0; 2]; 2],
            leg_force_z_n: vec![vec![2.0; 2]; 2],
            leg_torque_n_m: vec![vec![0.1; 2]; 2],
        };
        let g = sandslope::simulate::Geometry {
            hip_x_m: vec![0.1, -0.1],
            tripod: vec![0, 1],
            leg_nodes_m: vec![],
            body_length_m: 0.3,
            hip_height_m: 0.02,
        };
        let bytes = simulation_mcap(&tr, &g, 30.0).unwrap();
        let mut poses = Vec::new();
        let mut topics = BTreeMap::new();
        for m in mcap::MessageStream::new(&bytes).unwrap() {
            let m = m.unwrap();
            let schema = m.channel.schema.as_ref().unwrap();
            assert_eq!(schema.encoding, "ros2msg");
            *topics.entry(m.channel.topic.clone()).or_insert(0) += 1;
            if m.channel.topic == "/sandslope/pose" {
                poses.push((m.log_time, decode::<PoseStamped>(&m.data).unwrap()));
            }
        }
        assert_eq!(topics.len(), 4);
        assert!(topics.values().all(|&n| n == 2));
        // 1 m along a 30-degree slope: (cos 30, 0, sin 30) in the world, at 0.5 s.
        let (t, p) = &poses[1];
        assert_eq!(*t, 500_000_000);
        assert!((p.pose.position.x - 0.866_025_403_784_438_6).abs() < 1e-12);
        assert!((p.pose.position.z - 0.5).abs() < 1e-12);
        // Pitched nose-up by 30 degrees: a rotation about y by -30 degrees.
        assert!((p.pose.orientation.y - (-15f64.to_radians()).sin()).abs() < 1e-12);
    }
}
