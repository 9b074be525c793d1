//! A load-cell trial from a bag (`fit`, docs/bags.md): the force on a
//! `geometry_msgs/WrenchStamped` topic and the intruder's position on a pose topic (what
//! `track` reads: `PoseStamped`, `Odometry`, a `TransformStamped` or TF child frame), put
//! together as the columns of a trial CSV (`time_s`, depth or displacement, force).
//!
//! - The force is the wrench's force along `force_axis` (in the load cell's own frame, the
//!   wrench's header frame), sign included: the component that grows as the sand resists.
//! - The position is the intruder's distance from where it was at the first force sample
//!   (its first position if none brackets that stamp) along `position_axis` (in the pose
//!   topic's frame), or, when none is given, along its direction of travel (from its first
//!   position towards the one farthest from it), so a disk pushed down or a plate dragged
//!   downslope gives a depth or displacement that grows.
//! - Each force sample takes the position at its stamp, interpolated linearly between the
//!   two positions around it (the two streams are sampled by different devices); where they
//!   are more than two median position steps apart, or the stamp is outside the positions'
//!   span, the position is blank (the row is counted as blank, docs/measurements.md).
//! - Times are the wrenches' header stamps (the recorder's receive time where a stamp is
//!   zero), from the first wrench.

use std::path::Path;

use anyhow::{bail, Result};

use super::messages::{self, RosMessage, WrenchStamped};
use super::series::{decode_at, pick_topic, read_positions, POSE_TYPES};
use super::stamp_ns;
use super::{open, scan};

/// Parses a signed axis, `x`, `+x`, `-x`, `y`, `+y`, `-y`, `z`, `+z` or `-z`, as a unit
/// vector; `None` for anything else.
pub fn parse_axis(text: &str) -> Option<[f64; 3]> {
    let t = text.trim().to_ascii_lowercase();
    let (sign, name) = match t.strip_prefix('-') {
        Some(rest) => (-1.0, rest),
        None => (1.0, t.strip_prefix('+').unwrap_or(&t)),
    };
    let i = match name {
        "x" => 0,
        "y" => 1,
        "z" => 2,
        _ => return None,
    };
    let mut v = [0.0; 3];
    v[i] = sign;
    Some(v)
}

/// How a trial's bag is read: the topics, the TF frame and the axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadCellOptions<'a> {
    /// The `WrenchStamped` topic; the bag's only one when `None`.
    pub force_topic: Option<&'a str>,
    /// The intruder's pose topic; the bag's only pose topic when `None`.
    pub position_topic: Option<&'a str>,
    /// The child frame on a TF or odometry topic (as `track --frame`).
    pub frame: Option<&'a str>,
    /// The force component read, a unit vector in the load cell's frame.
    pub force_axis: [f64; 3],
    /// The axis the depth or displacement is measured along, a unit vector in the pose
    /// topic's frame; the direction of travel when `None`.
    pub position_axis: Option<[f64; 3]>,
}

/// A trial's columns read from a bag, one row per wrench message.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadCellSeries {
    /// Time from the first wrench, s.
    pub time_s: Vec<f64>,
    /// Depth or displacement, m; `None` where no position brackets the stamp.
    pub position_m: Vec<Option<f64>>,
    /// Force, N (NaN where the message's is not finite).
    pub force_n: Vec<f64>,
    /// The wrench topic read.
    pub force_topic: String,
    /// The position's topic (and frame) read.
    pub position_body: String,
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Reads a load-cell trial from the bag at `path` (a folder or one `.mcap` or `.db3`).
/// Errors name the file, the topic and where in the file.
pub fn read_load_cell(path: &Path, options: &LoadCellOptions<'_>) -> Result<LoadCellSeries> {
    let bag = open(path)?;
    let (force_topic, position_topic) = match (options.force_topic, options.position_topic) {
        (Some(f), Some(p)) => (f.to_string(), p.to_string()),
        (f, p) => {
            let all = scan(&bag, None, &mut |_| Ok(()))?;
            let f = pick_topic(path, &all, f, &[WrenchStamped::TYPE], "force_topic")?.name;
            let p = pick_topic(path, &all, p, &POSE_TYPES, "position_topic")?.name;
            (f, p)
        }
    };
    let mut stamps: Vec<i64> = Vec::new();
    let mut force_n: Vec<f64> = Vec::new();
    let all = scan(&bag, Some(&force_topic), &mut |m| {
        if !messages::same_type(m.type_name, WrenchStamped::TYPE) {
            bail!("{}: topic `{}` is {}, not {}", path.display(), m.topic, m.type_name, WrenchStamped::TYPE);
        }
        let w: WrenchStamped = decode_at(m)?;
        let f = w.wrench.force;
        stamps.push(stamp_ns(&w.header, m));
        force_n.push(dot([f.x, f.y, f.z], options.force_axis));
        Ok(())
    })?;
    pick_topic(path, &all, Some(&force_topic), &[WrenchStamped::TYPE], "force_topic")?;
    if stamps.is_empty() {
        bail!("{}: topic `{force_topic}` holds no message", path.display());
    }
    let read = read_positions(path, Some(&position_topic), options.frame)?;
    let mut samples: Vec<(i64, [f64; 3])> =
        read.samples.into_iter().filter(|(_, p)| p.iter().all(|v| v.is_finite())).collect();
    samples.sort_by_key(|s| s.0);
    samples.dedup_by_key(|s| s.0);
    if samples.len() < 2 {
        bail!(
            "{}: topic `{position_topic}`: {} position(s) with distinct stamps; the intruder's path needs two at least",
            path.display(),
            samples.len()
        );
    }
    let p0 = samples[0].1;
    let from_start = |p: [f64; 3]| [p[0] - p0[0], p[1] - p0[1], p[2] - p0[2]];
    let axis = match options.position_axis {
        Some(a) => a,
        None => {
            let far = samples.iter().map(|s| from_start(s.1)).fold([0.0; 3], |best, d| {
                if dot(d, d) > dot(best, best) {
                    d
                } else {
                    best
                }
            });
            let len = dot(far, far).sqrt();
            if len.is_nan() || len <= 0.0 {
                bail!(
                    "{}: topic `{}`: the intruder never moves from ({}, {}, {}) m",
                    path.display(),
                    read.body,
                    p0[0],
                    p0[1],
                    p0[2]
                );
            }
            far.map(|v| v / len)
        }
    };
    let along: Vec<(i64, f64)> = samples.iter().map(|(t, p)| (*t, dot(from_start(*p), axis))).collect();
    let mut steps: Vec<i64> = along.windows(2).map(|w| w[1].0 - w[0].0).collect();
    steps.sort_unstable();
    let longest = 2 * steps[steps.len() / 2];
    let position_at = |t: i64| -> Option<f64> {
        let k = along.partition_point(|s| s.0 < t);
        let (tb, b) = *along.get(k)?;
        if tb == t {
            return Some(b);
        }
        let (ta, a) = *along.get(k.checked_sub(1)?)?;
        (tb - ta <= longest).then(|| a + (b - a) * (t - ta) as f64 / (tb - ta) as f64)
    };
    // Measured from where the intruder was at the first force sample (from its first
    // position when none brackets that stamp).
    let t0 = stamps[0];
    let origin = position_at(t0).unwrap_or(0.0);
    Ok(LoadCellSeries {
        time_s: stamps.iter().map(|t| (t - t0) as f64 * 1e-9).collect(),
        position_m: stamps.iter().map(|t| position_at(*t).map(|d| d - origin)).collect(),
        force_n,
        force_topic,
        position_body: read.body,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axes_parse() {
        assert_eq!(parse_axis("z"), Some([0.0, 0.0, 1.0]));
        assert_eq!(parse_axis(" -X "), Some([-1.0, 0.0, 0.0]));
        assert_eq!(parse_axis("+y"), Some([0.0, 1.0, 0.0]));
        assert_eq!(parse_axis("w"), None);
        assert_eq!(parse_axis("--z"), None);
    }
}
