//! A TF child frame's position in the root of its tree: the frame's transforms composed with
//! those of its parent, its parent's parent, ... up to a frame that is nobody's child (the
//! motion-capture system's `world`, `map` or `odom`), as `tf2` does. A parent that moves (on
//! the same TF topic) is interpolated at each of the child's stamps, linearly in translation
//! and by slerp in rotation, `tf2`'s own rule; a parent published on `/tf_static` (when the
//! topic read is `/tf`) is fixed. The rotations and their composition are `nalgebra`'s.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use anyhow::{anyhow, bail, Result};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};

use super::messages::{self, decode, RosMessage, TfMessage, Transform};
use super::{scan, Bag, BagMessage, BagTopic, MAX_MESSAGES};

/// The topic static transforms are published on, read with `/tf`.
pub const TF_STATIC: &str = "/tf_static";

/// Longest chain of parents followed (a deeper tree is a loop or a damaged bag).
const MAX_DEPTH: usize = 64;

/// A transform as an isometry (the rotation normalised; a zero quaternion is the identity's
/// stand-in only if every component is zero, which `tf2` refuses too: an error here).
pub(super) fn isometry(t: &Transform) -> Option<Isometry3<f64>> {
    let r = t.rotation;
    let q = Quaternion::new(r.w, r.x, r.y, r.z);
    let norm = q.norm();
    if !(norm.is_finite() && norm > 1e-9) {
        return None;
    }
    let p = t.translation;
    Some(Isometry3::from_parts(Translation3::new(p.x, p.y, p.z), UnitQuaternion::from_quaternion(q)))
}

/// Where a frame's transform to its parent comes from.
enum Link {
    /// Published on the topic read: interpolated at each stamp.
    Moving,
    /// Published on `/tf_static`.
    Fixed(Isometry3<f64>),
}

/// The parents of the frames of `/tf_static` (child to parent and transform), read once.
fn read_static(bag: &Bag, path: &Path) -> Result<BTreeMap<String, (String, Isometry3<f64>)>> {
    let mut out = BTreeMap::new();
    scan(bag, Some(TF_STATIC), &mut |m| {
        if !messages::same_type(m.type_name, TfMessage::TYPE) {
            bail!("{}: topic `{TF_STATIC}` is {}, not {}", path.display(), m.type_name, TfMessage::TYPE);
        }
        let tf: TfMessage =
            decode(m.data).map_err(|e| anyhow!("{}: topic `{}`, message {}: {e}", m.at, m.topic, m.index))?;
        for t in tf.transforms {
            let iso = isometry(&t.transform).ok_or_else(|| {
                anyhow!(
                    "{}: topic `{}`, message {}: frame `{}` has a zero rotation",
                    m.at,
                    m.topic,
                    m.index,
                    t.child_frame_id
                )
            })?;
            let child = t.child_frame_id.trim_start_matches('/').to_string();
            out.insert(child, (t.header.frame_id.trim_start_matches('/').to_string(), iso));
        }
        Ok(())
    })?;
    Ok(out)
}

/// What a TF topic's messages leave for [`in_root`]: every child frame's parent (the first
/// seen), and the tracked frame's own transforms.
#[derive(Default)]
pub(super) struct TfFrames {
    /// Child frame to parent.
    pub parents: BTreeMap<String, String>,
    /// The tracked frame's transforms to its parent, with their stamps (ns).
    pub samples: Vec<(i64, Isometry3<f64>)>,
}

impl TfFrames {
    /// Takes one `TFMessage` read at `m`: each child frame's parent, counted in `frames`; for
    /// `frame`, its transform kept and its translation pushed to `positions` (an error if its
    /// parent changes).
    pub(super) fn add(
        &mut self,
        tf: TfMessage,
        m: &BagMessage<'_>,
        frame: Option<&str>,
        positions: &mut Vec<(i64, [f64; 3])>,
        frames: &mut BTreeMap<String, u64>,
    ) -> Result<()> {
        for t in tf.transforms {
            let child = t.child_frame_id.trim_start_matches('/').to_string();
            let parent = t.header.frame_id.trim_start_matches('/');
            let first = self.parents.entry(child.clone()).or_insert_with(|| parent.to_string());
            if frame == Some(child.as_str()) {
                if first != parent {
                    bail!(
                        "{}: topic `{}`, message {}: frame `{child}` changes parent from `{first}` to `{parent}`",
                        m.at,
                        m.topic,
                        m.index
                    );
                }
                // A zero rotation: the translation is still the frame's position.
                let v = t.transform.translation;
                let iso = isometry(&t.transform).unwrap_or_else(|| Isometry3::translation(v.x, v.y, v.z));
                let ns = super::stamp_ns(&t.header, m);
                positions.push((ns, super::messages::point(v)));
                self.samples.push((ns, iso));
            }
            *frames.entry(child).or_default() += 1;
        }
        Ok(())
    }
}

/// One TF frame as read from its topic: the frame, its parent, its stamped transforms.
pub(super) struct FrameSamples<'a> {
    /// The frame tracked.
    pub frame: &'a str,
    /// Its parent (the header's frame).
    pub parent: &'a str,
    /// Its transforms to the parent, with their stamps (ns).
    pub samples: Vec<(i64, Isometry3<f64>)>,
}

/// The positions of `target` in the root of its tree, and the root's name. `parents` maps
/// every child frame seen on `topic` to its parent. A position is NaN (an occlusion to the
/// analysis) where a moving parent has no transform around the stamp (no extrapolation, as
/// in `tf2`).
/// Positions of a frame in the tree's root frame: (log time, ns; position, m).
type Positions = Vec<(i64, [f64; 3])>;

pub(super) fn in_root(
    bag: &Bag,
    path: &Path,
    topic: &str,
    topics: &[BagTopic],
    target: FrameSamples<'_>,
    parents: &BTreeMap<String, String>,
) -> Result<(Positions, String)> {
    // The chain of parents: each link from a frame to its own parent.
    let has_static = topic == "/tf" && topics.iter().any(|t| t.name == TF_STATIC);
    let mut fixed: Option<BTreeMap<String, (String, Isometry3<f64>)>> = None;
    let mut chain: Vec<(String, Link)> = Vec::new();
    let mut frame = target.parent.to_string();
    let mut seen = vec![target.frame.to_string()];
    loop {
        if seen.contains(&frame) {
            seen.push(frame);
            bail!("{}: topic `{topic}`: the TF tree loops: {}", path.display(), seen.join(" -> "));
        }
        if seen.len() > MAX_DEPTH {
            bail!(
                "{}: topic `{topic}`: frame `{}` has more than {MAX_DEPTH} ancestors",
                path.display(),
                target.frame
            );
        }
        seen.push(frame.clone());
        if let Some(p) = parents.get(&frame) {
            chain.push((frame, Link::Moving));
            frame = p.clone();
            continue;
        }
        if has_static && fixed.is_none() {
            fixed = Some(read_static(bag, path)?);
        }
        match fixed.as_ref().and_then(|f| f.get(&frame)) {
            Some((p, iso)) => {
                chain.push((frame, Link::Fixed(*iso)));
                frame = p.clone();
            }
            None => break,
        }
    }
    let root = frame;
    let position = |iso: &Isometry3<f64>| {
        let v = iso.translation.vector;
        [v.x, v.y, v.z]
    };
    if chain.is_empty() {
        return Ok((target.samples.iter().map(|(t, iso)| (*t, position(iso))).collect(), root));
    }
    // The moving ancestors' transforms, read again from the topic.
    let mut moving: HashMap<String, Vec<(i64, Isometry3<f64>)>> = chain
        .iter()
        .filter(|(_, l)| matches!(l, Link::Moving))
        .map(|(f, _)| (f.clone(), Vec::new()))
        .collect();
    if !moving.is_empty() {
        let mut kept = 0u64;
        scan(bag, Some(topic), &mut |m| {
            let tf: TfMessage = decode(m.data)
                .map_err(|e| anyhow!("{}: topic `{}`, message {}: {e}", m.at, m.topic, m.index))?;
            for t in tf.transforms {
                let child = t.child_frame_id.trim_start_matches('/');
                if let Some(series) = moving.get_mut(child) {
                    let iso = isometry(&t.transform).ok_or_else(|| {
                        anyhow!(
                            "{}: topic `{}`, message {}: frame `{child}` has a zero rotation",
                            m.at,
                            m.topic,
                            m.index
                        )
                    })?;
                    series.push((super::stamp_ns(&t.header, m), iso));
                    kept += 1;
                }
            }
            if kept > MAX_MESSAGES {
                bail!(
                    "{}: topic `{}`: more than {MAX_MESSAGES} transforms of the frames above `{}`",
                    m.at,
                    m.topic,
                    target.frame
                );
            }
            Ok(())
        })?;
        for series in moving.values_mut() {
            series.sort_by_key(|s| s.0);
            series.dedup_by_key(|s| s.0);
        }
    }
    let out = target
        .samples
        .iter()
        .map(|(t, iso)| {
            let mut pose = *iso;
            for (f, link) in &chain {
                let up = match link {
                    Link::Fixed(iso) => Some(*iso),
                    Link::Moving => moving.get(f).and_then(|s| at(s, *t)),
                };
                match up {
                    Some(up) => pose = up * pose,
                    None => return (*t, [f64::NAN; 3]),
                }
            }
            (*t, position(&pose))
        })
        .collect();
    Ok((out, root))
}

/// A moving frame's transform at `t`: exact at a stamp, interpolated between the two around
/// it (translation linearly, rotation by slerp), `None` outside its stamps.
fn at(series: &[(i64, Isometry3<f64>)], t: i64) -> Option<Isometry3<f64>> {
    let k = series.partition_point(|s| s.0 < t);
    let (tb, b) = series.get(k)?;
    if *tb == t {
        return Some(*b);
    }
    let (ta, a) = series.get(k.checked_sub(1)?)?;
    let w = (t - ta) as f64 / (tb - ta) as f64;
    let translation = a.translation.vector.lerp(&b.translation.vector, w);
    let rotation = a.rotation.try_slerp(&b.rotation, w, 1e-12).unwrap_or(a.rotation);
    Some(Isometry3::from_parts(translation.into(), rotation))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    /// Worked by hand: a parent 1 m along x, turned 90 degrees about z, carries a child 1 m
    /// along its own x to (1, 1, 0); halfway between a parent at x = 0 and x = 2 (same
    /// rotation) the child is at (1, 1, 0) again.
    #[test]
    fn transforms_compose_and_interpolate() {
        let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_2);
        let parent = Isometry3::from_parts(Translation3::new(1.0, 0.0, 0.0), turn);
        let child = Isometry3::translation(1.0, 0.0, 0.0);
        let p = (parent * child).translation.vector;
        assert!((p - Vector3::new(1.0, 1.0, 0.0)).norm() < 1e-12, "{p}");
        let series = [
            (0, Isometry3::from_parts(Translation3::new(0.0, 0.0, 0.0), turn)),
            (10, Isometry3::from_parts(Translation3::new(2.0, 0.0, 0.0), turn)),
        ];
        let mid = at(&series, 5).unwrap();
        let p = (mid * child).translation.vector;
        assert!((p - Vector3::new(1.0, 1.0, 0.0)).norm() < 1e-12, "{p}");
        assert!(at(&series, 11).is_none() && at(&series, -1).is_none());
        assert_eq!(at(&series, 10).unwrap(), series[1].1);
    }
}
