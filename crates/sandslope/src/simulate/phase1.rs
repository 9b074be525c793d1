//! The paper's phase 1 in a simulated walk (issue 59, item 2): after a tripod touches down at
//! t0 the paper's robot slips back until t1, where the along-slope acceleration turns from
//! negative to positive (docs/model.md §11). Beside each step's t1 and backward slip s1
//! ([`crate::gait::measure_step`]) this gives the most negative speed in phase 1 and what held
//! the body there: the sand's along-slope and normal force on the belly, on the tripod that
//! has just left stance (the old one) and on the tripod that has just touched down (the new
//! one), averaged over phase 1 (docs/simulate.md, "Phase 1: what holds the body at
//! touchdown").

use serde::Serialize;

use super::dynamics::GroupForces;
use crate::gait::{measure_step, SmoothTrack, StepMeasure};

/// Measures the step of a simulated walk that starts at `t0` with tripod `tripod` touching
/// down (steps of `half` s; `track` at full rate, sample i at `i dt`; `groups` as for
/// [`phase_one`]; `level`: the walk is on level sand): the step as `track` measures it
/// (docs/model.md §11) and its phase 1, except that a step that did not slip back has no
/// phase 1 (docs/model.md §18): where the speed's minimum between touchdown and the anchoring
/// time §11 finds is within the measure's resolution of zero or below it (at most three noise
/// SDs, 0.3 mm/s, the rise that makes a minimum count), and the speed never went below minus
/// the track's rest speed before it, or the sand is level, t1 and the slip are 0. A minimum at
/// a clear forward speed (a body that decelerates while its legs swim and speeds up once they
/// anchor, 2.4 mm/s at 63 ms on weak sand) is the paper's t1 and stays.
///
/// Phase 1 is the paper's backward slip ("the instantaneous speed became negative (phase 1, t0
/// to t1)") under the slope's pull, `s1 = 1/2 g sin(theta) t1^2`; a body that coasts forwards
/// on its belly into touchdown (level sand) or rests on it (gentle slopes) has a speed minimum
/// that is no slip's end (docs/simulate.md, "Why t1 did not converge"). On level sand nothing
/// pulls the body back (`s1 = 0` for any t1, and the paper's speed "increased immediately
/// after touchdown"): a backward dip of its centre there is the free body's rocking on its
/// belly (nose-up at 20 deg/s on a belly at rest, the centre moving back at 10 mm/s), no slip.
pub(crate) fn measure(
    track: &SmoothTrack,
    groups: &[GroupForces],
    t0: f64,
    half: f64,
    tripod: usize,
    level: bool,
) -> (StepMeasure, PhaseOne) {
    let dt = 1.0 / track.frame_rate_hz;
    let mut step = measure_step(track, t0, half);
    let mut phase1 = phase_one(&track.speed, groups, dt, t0, step.anchoring_time_s, half, tripod);
    let resolution = 3.0 * track.speed_noise_m_s;
    let no_slip =
        phase1.min_speed_m_s <= resolution && (level || phase1.min_speed_m_s >= -track.rest_speed_m_s);
    if step.anchoring_time_s.is_some_and(|t1| t1 > 0.0) && no_slip {
        step.anchoring_time_s = Some(0.0);
        step.slip_m = Some(0.0);
        phase1 = phase_one(&track.speed, groups, dt, t0, Some(0.0), half, tripod);
    }
    (step, phase1)
}

/// Phase 1 of one step, `[t0, t0 + t1]` (at least one integration step).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct PhaseOne {
    /// Lowest along-slope speed in phase 1, m/s (negative: the body slid back); over the whole
    /// step when it did not anchor.
    pub min_speed_m_s: f64,
    /// The sand's force on the belly, mean over phase 1, `[along slope, normal]`, N.
    pub belly_n: [f64; 2],
    /// On the tripod that has just ended its stance (the other one).
    pub old_tripod_n: [f64; 2],
    /// On the tripod that has just touched down.
    pub new_tripod_n: [f64; 2],
}

/// Phase 1 of the step that starts at `t0` with tripod `tripod` touching down, anchoring
/// `t1` s later (`None`: not anchored, the whole step of `half` s), from the full-rate speed
/// `vx` (sample i at `i dt`) and group forces `groups` (entry i: the step ending at
/// `(i + 1) dt`).
pub(crate) fn phase_one(
    vx: &[f64],
    groups: &[GroupForces],
    dt: f64,
    t0: f64,
    t1: Option<f64>,
    half: f64,
    tripod: usize,
) -> PhaseOne {
    let end = t0 + t1.unwrap_or(half).max(dt);
    let first = ((t0 / dt).round() as usize).min(vx.len().saturating_sub(1));
    let last = ((end / dt).round() as usize).clamp(first + 1, vx.len().saturating_sub(1).max(first + 1));
    let min_speed_m_s = vx[first..=last.min(vx.len() - 1)].iter().copied().fold(f64::INFINITY, f64::min);
    // Steps first..last (ending at (first + 1) dt .. last dt) lie in the window.
    let window = &groups[first.min(groups.len())..last.min(groups.len())];
    let n = window.len().max(1) as f64;
    let mean = |f: &dyn Fn(&GroupForces) -> [f64; 2]| {
        let s = window.iter().map(f).fold([0.0; 2], |a, b| [a[0] + b[0], a[1] + b[1]]);
        [s[0] / n, s[1] / n]
    };
    let new = tripod.min(1);
    PhaseOne {
        min_speed_m_s,
        belly_n: mean(&|g| g.belly),
        old_tripod_n: mean(&|g| g.tripod[1 - new]),
        new_tripod_n: mean(&|g| g.tripod[new]),
    }
}

/// The mean of `phases` field by field; `None` when there are none.
pub(crate) fn mean<'a>(phases: impl Iterator<Item = &'a PhaseOne>) -> Option<PhaseOne> {
    let (mut sum, mut n) = (PhaseOne::default(), 0usize);
    for p in phases {
        sum.min_speed_m_s += p.min_speed_m_s;
        for k in 0..2 {
            sum.belly_n[k] += p.belly_n[k];
            sum.old_tripod_n[k] += p.old_tripod_n[k];
            sum.new_tripod_n[k] += p.new_tripod_n[k];
        }
        n += 1;
    }
    (n > 0).then(|| {
        let d = n as f64;
        let avg = |a: [f64; 2]| [a[0] / d, a[1] / d];
        PhaseOne {
            min_speed_m_s: sum.min_speed_m_s / d,
            belly_n: avg(sum.belly_n),
            old_tripod_n: avg(sum.old_tripod_n),
            new_tripod_n: avg(sum.new_tripod_n),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A made-up record: speed falling linearly to -2 m/s at sample 4 and rising after; the
    /// belly pushing 1 N, tripod 0 pushing 2 N from step 3 on, tripod 1 pushing 4 N.
    #[test]
    fn phase_one_takes_the_window_from_touchdown_to_anchoring() {
        let dt = 0.01;
        let vx: Vec<f64> = (0..20).map(|i| -2.0 + 0.5 * (i as f64 - 4.0).abs()).collect();
        let groups: Vec<GroupForces> = (0..20)
            .map(|i| GroupForces {
                belly: [1.0, 3.0],
                tripod: [[if i >= 3 { 2.0 } else { 0.0 }, 0.0], [4.0, 1.0]],
            })
            .collect();
        // Touchdown at sample 2 (t0 = 0.02 s) by tripod 0, t1 = 0.02 s: samples 2..=4, steps 2, 3.
        let p = phase_one(&vx, &groups, dt, 0.02, Some(0.02), 0.1, 0);
        assert_eq!(p.min_speed_m_s, -2.0);
        assert_eq!(p.belly_n, [1.0, 3.0]);
        assert_eq!(p.new_tripod_n, [1.0, 0.0]);
        assert_eq!(p.old_tripod_n, [4.0, 1.0]);
        // Anchored at once: one integration step; the speed at touchdown is the lowest.
        let p = phase_one(&vx, &groups, dt, 0.08, Some(0.0), 0.1, 1);
        assert_eq!(p.min_speed_m_s, vx[8]);
        assert_eq!(p.new_tripod_n, [4.0, 1.0]);
        assert_eq!(p.old_tripod_n, [2.0, 0.0]);
    }
}
