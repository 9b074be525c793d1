//! The live monitor's first stance and the sampling of a stance's bins (docs/model.md §19,
//! docs/drive.md): tripod 0's run-up stance read against the grid walks' own run-ups, and the
//! profile's variance within a bin that a stance read at the bus's rate samples.

use super::{posterior_answer_common, stance_profiles, CurrentInference, GaitSchedule, LegTrace, ModelGrid};
use crate::robot::Robot;

/// The pooled variance of `legs`' stance torques within each bin (tripod-major) of the
/// strides `keep` takes, about each stride's bin mean, N m^2 (0 where a bin has too few).
pub(super) fn within_bin_variance(
    schedule: &GaitSchedule,
    legs: &[LegTrace],
    bins: usize,
    keep: impl Fn(i64) -> bool,
) -> Vec<f64> {
    let half = 0.5 * schedule.period_s;
    // (stride, bin) -> (n, sum, sum of squares)
    let mut groups: std::collections::BTreeMap<(i64, usize), (f64, f64, f64)> = Default::default();
    for (j, leg) in legs.iter().enumerate().take(schedule.legs()) {
        let k = schedule.tripods[j];
        for (&a, &tau) in leg.angle_rad.iter().zip(&leg.torque_n_m) {
            let (stride, since) = schedule.stride_position(j, a);
            if a.is_finite() && tau.is_finite() && since < half && keep(stride) {
                let b = ((since / half * bins as f64) as usize).min(bins - 1);
                let g = groups.entry((stride, k * bins + b)).or_default();
                *g = (g.0 + 1.0, g.1 + tau, g.2 + tau * tau);
            }
        }
    }
    let mut ss = vec![0.0; 2 * bins];
    let mut dof = vec![0.0; 2 * bins];
    for ((_, b), (n, sum, sq)) in groups {
        if n >= 2.0 {
            ss[b] += (sq - sum * sum / n).max(0.0);
            dof[b] += n - 1.0;
        }
    }
    ss.iter().zip(&dof).map(|(s, d)| if *d > 0.0 { s / d } else { 0.0 }).collect()
}

/// Tripod 0's run-up stance (stride 0) of `legs`, bin by bin (0 where a bin is empty).
pub(super) fn run_up_profile(schedule: &GaitSchedule, legs: &[LegTrace], bins: usize) -> Vec<f64> {
    let p = stance_profiles(schedule, legs, bins);
    let row = p.strides.iter().position(|&s| s == 0).map(|i| &p.profiles[i]);
    (0..bins).map(|b| row.and_then(|r| r[b]).unwrap_or(0.0)).collect()
}

/// The current sensor's zero offset of one servo before any swing has shown it, as a
/// standard deviation, mA: the offsets the log tests inject span -40 to 40 mA (docs/drive.md,
/// "Messy logs"), a uniform spread's SD 40 / sqrt 3 = 23 mA, rounded up.
pub const RUN_UP_OFFSET_SD_MA: f64 = 25.0;

/// Live estimate from tripod 0's run-up stance (stride 0: the legs running up over the
/// response time, docs/model.md §19), read against the grid walks' own run-up stances
/// ([`ModelGrid::run_up_mean`]). No swing has come before it, so the torques are raw: each
/// leg's unknown sensor offset (SD `offset_sd_n_m`) is integrated out, the tripod's mean
/// offset shifting every bin alike (a covariance `offset_sd^2 / n` common to the bins). The
/// simulated scatter is the steady stances' (one run-up per walk shows none of its own).
/// `None` when the grid has no run-up or a bin is empty.
pub fn infer_from_run_up(
    robot: &Robot,
    grid: &ModelGrid,
    profile: &[Option<f64>],
    counts: &[usize],
    noise_sd_n_m: f64,
    offset_sd_n_m: f64,
) -> Option<CurrentInference> {
    let b = grid.bins;
    if grid.run_up_mean.len() != grid.k_s.len() {
        return None;
    }
    let mut mean = vec![0.0; 2 * b];
    let mut var = vec![0.0; 2 * b];
    for i in 0..b {
        let (v, c) = (profile.get(i).copied().flatten()?, counts.get(i).copied().unwrap_or(0));
        if c == 0 {
            return None;
        }
        mean[i] = v;
        var[i] = stance_bin_variance(robot, noise_sd_n_m, grid.run_up_within_var.get(i).copied(), c);
    }
    let pad = |m: &Vec<f64>| m.iter().copied().chain(std::iter::repeat(0.0)).take(2 * b).collect();
    let g = ModelGrid { strides: 1, mean: grid.run_up_mean.iter().map(pad).collect(), ..grid.clone() };
    let common = offset_sd_n_m * offset_sd_n_m / f64::from(robot.stance_legs());
    let used: Vec<usize> = (0..b).collect();
    let mut answer = posterior_answer_common(robot, &g, &mean, &var, &used, 1, common);
    answer.strides = 1;
    Some(answer)
}

/// The variance of one stance's bin mean of `count` samples, N m^2: the sensor's noise over
/// the samples, plus the profile's variance within the bin (`within_var`, the grid's) over the
/// samples one leg took (a tripod's legs are read in the same bus cycles, at the same points
/// of their common profile, so they do not sample it independently).
pub(super) fn stance_bin_variance(
    robot: &Robot,
    noise_sd_n_m: f64,
    within_var: Option<f64>,
    count: usize,
) -> f64 {
    let c = count as f64;
    let per_leg = (c / f64::from(robot.stance_legs())).max(1.0);
    noise_sd_n_m * noise_sd_n_m / c + within_var.unwrap_or(0.0) / per_leg
}
