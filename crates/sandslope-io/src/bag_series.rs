//! A ROS 2 bag's topics as what the commands take, where that is one of the library's types
//! (the bag itself is read by sandslope-bag): a body's trajectory as a motion capture for
//! `track` ([`read_capture`]), joint states as a servo log for `infer --servo-log`
//! ([`read_joint_states`]).

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{bail, Result};
use sandslope::servo::ServoModel;
use sandslope_bag::messages::{self, JointState, RosMessage, StringMsg};
use sandslope_bag::series::{decode_at, pick_topic, read_grid, GridPositions, RUN_TOPIC};
use sandslope_bag::{open, scan, stamp_ns, Bag, BagTopic};

use crate::mocap::{Capture, MocapFormat};
use crate::servo_log::{ServoLog, ServoLogRow};

/// Reads one body's trajectory from a bag as a motion capture in the plain format's frame
/// (ROS's: z up, REP 103): the topic and frame rules and the grid are
/// [`sandslope_bag::series::read_grid`]'s.
pub fn read_capture(path: &Path, topic: Option<&str>, frame: Option<&str>) -> Result<Capture> {
    let GridPositions { body, frame_rate_hz, start_time_s, positions } = read_grid(path, topic, frame)?;
    Ok(Capture {
        path: path.to_path_buf(),
        format: MocapFormat::Plain,
        body,
        frame_rate_hz,
        start_time_s,
        positions,
    })
}

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
fn run_header(bag: &Bag, topics: &[BagTopic]) -> Result<BTreeMap<String, String>> {
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
