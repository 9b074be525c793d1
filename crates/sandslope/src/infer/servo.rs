//! The robot as a sensor (docs/model.md §19): what the servos' stance-phase currents say about
//! the sand's shear strength k_s at the slope being climbed, and the live risk of slippage.
//!
//! A leg's drive torque during stance is what the sand resists with. Where the sand holds, the
//! torque carries the body's load (slope and acceleration) and hardly depends on k_s; where it
//! yields, the torque is the sand's capacity at the leg's depth and grows with k_s. The
//! currents are compared, stance bin by stance bin, with the stride simulator's
//! (docs/model.md §15-§18) on a grid of k_s at the same slope and k_n:
//!
//! - statistic: for each stride and tripod, the mean drive torque `tau = K_t I` of the tripod's
//!   legs in each of `bins` equal parts of the stance (legs placed in their stance by their
//!   angle, [`GaitSchedule::stride_position`]); the run-up stride is left out;
//! - likelihood: Gaussian, per bin, around the simulator's mean profile at k_s, with variance
//!   the observed mean's (stride-to-stride scatter over the number of strides) plus the
//!   simulated mean's (its own scatter over its strides) plus the grid's resolution (the
//!   profile's larger change to a neighbouring grid point, squared: the truth lies between
//!   grid points, and the simulated walk is not smooth in k_s) plus a floor;
//! - prior: log-uniform on `[k_s_min, k_s_max]`, as the gait inference's;
//! - answer: the posterior median of k_s, its 90% credible interval (flagged when the data do
//!   not bound a side, [`Bound`]), the leg's shear load (the simulator's along-slope sand force
//!   per stance leg, posterior mean), and the probability that the walk is in the slippage
//!   regime at this slope (posterior weight of the grid's simulated walks that slip).

use rayon::prelude::*;
use serde::Serialize;

use super::{Bound, LogUniformPrior};

mod run_up;
use crate::regime::Regime;
use crate::robot::Robot;
use crate::scenario::Scenario;
use crate::servo::{GaitSchedule, ServoModel};
use crate::simulate::{simulate, SimSettings};
use crate::terrain::Terrain;
pub use run_up::{infer_from_run_up, RUN_UP_OFFSET_SD_MA};
use run_up::{run_up_profile, stance_bin_variance, within_bin_variance};

/// Why currents cannot be turned into k_s.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CurrentInferenceError {
    /// Too few complete strides in the log.
    #[error("the log holds {found} complete stride(s) after the run-up; at least {needed} are needed to estimate k_s from the currents (drive longer: --duration)")]
    TooFewStrides {
        /// Complete strides found.
        found: usize,
        /// Strides needed.
        needed: usize,
    },
    /// The simulator refused the robot, slope or terrain.
    #[error("the stride simulator cannot model this walk: {0}")]
    Simulator(String),
    /// A setting outside its range.
    #[error("{0}")]
    Setting(String),
}

/// The default prior range of k_s for `infer --servo-log` (and Python's `infer_servo_log`),
/// N/m^3: the gait inference's, `infer --k-s-prior`'s default.
pub const SERVO_LOG_K_S_PRIOR: (f64, f64) = (1e4, 1e9);
/// The default number of k_s values the simulator walks for `infer --servo-log`.
pub const SERVO_LOG_GRID_POINTS: usize = 41;

/// One leg's record: its tripod, angle in the gait's frame and drive torque.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LegTrace {
    /// Leg angle, rad, in the gait's frame (unwrapped).
    pub angle_rad: Vec<f64>,
    /// Drive torque the servo exerts in the leg's direction of rotation, N m.
    pub torque_n_m: Vec<f64>,
}

/// Settings of the current inference.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CurrentInferenceSettings {
    /// Prior on k_s.
    pub prior: LogUniformPrior,
    /// k_s values simulated (log-spaced over the prior).
    pub grid_points: usize,
    /// Stance bins of the profile.
    pub bins: usize,
    /// Strides the simulator walks per grid point (the first is left out).
    pub simulated_strides: usize,
    /// Standard deviation added to every bin's, N m (the current's quantisation, 1 mA, and
    /// what the simulator cannot reproduce).
    pub floor_n_m: f64,
    /// Remove each leg's swing-phase torque (the current sensor's zero offset and its drift,
    /// [`remove_swing_offset`]) from the log and from the simulated walks alike. The live
    /// monitor's grid sets it too and takes each leg's last swing median off its stance itself.
    pub swing_offset: bool,
    /// The servos' model (docs/drive.md, "Servo models"): its stall torque bounds the torques
    /// a servo can report ([`ModelGrid::stall_torque_n_m`]). Default: the paper's XL330-M288.
    #[serde(serialize_with = "servo_name")]
    pub servo: &'static ServoModel,
}

fn servo_name<S: serde::Serializer>(servo: &&'static ServoModel, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(servo.name)
}

impl Default for CurrentInferenceSettings {
    fn default() -> Self {
        CurrentInferenceSettings {
            prior: LogUniformPrior::new(3e4, 3e7).expect("valid"),
            grid_points: 31,
            bins: 6,
            simulated_strides: 8,
            floor_n_m: 0.002,
            swing_offset: true,
            servo: &ServoModel::XL330_M288,
        }
    }
}

/// Per-stride stance profiles: `profiles[s][k * bins + b]` is tripod k's mean drive torque in
/// stance bin b of stride `strides[s]`, N m (`None` where no sample fell in the bin).
#[derive(Debug, Clone, PartialEq)]
pub struct StanceProfiles {
    /// Stride numbers.
    pub strides: Vec<i64>,
    /// Bin means, tripod-major.
    pub profiles: Vec<Vec<Option<f64>>>,
    /// Samples behind each bin mean.
    pub counts: Vec<Vec<usize>>,
}

/// Bins the stance-phase torques of `legs` by stride and stance bin.
pub fn stance_profiles(schedule: &GaitSchedule, legs: &[LegTrace], bins: usize) -> StanceProfiles {
    let half = 0.5 * schedule.period_s;
    let mut by_stride: std::collections::BTreeMap<i64, (Vec<f64>, Vec<usize>)> = Default::default();
    for (j, leg) in legs.iter().enumerate().take(schedule.legs()) {
        let k = schedule.tripods[j];
        for (&a, &tau) in leg.angle_rad.iter().zip(&leg.torque_n_m) {
            if !(a.is_finite() && tau.is_finite()) {
                continue;
            }
            let (stride, since) = schedule.stride_position(j, a);
            if since >= half {
                continue;
            }
            let b = ((since / half * bins as f64) as usize).min(bins - 1);
            let e = by_stride.entry(stride).or_insert_with(|| (vec![0.0; 2 * bins], vec![0; 2 * bins]));
            e.0[k * bins + b] += tau;
            e.1[k * bins + b] += 1;
        }
    }
    let mut out = StanceProfiles { strides: vec![], profiles: vec![], counts: vec![] };
    for (s, (sum, n)) in by_stride {
        out.strides.push(s);
        out.profiles.push(sum.iter().zip(&n).map(|(&x, &c)| (c > 0).then(|| x / c as f64)).collect());
        out.counts.push(n);
    }
    out
}

/// The simulator's stance profiles over a grid of k_s at one slope (what the currents are
/// compared with); build once per run with [`model_grid`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelGrid {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// k_n used, N/m^3.
    pub k_n: f64,
    /// k_s values, N/m^3 (log-spaced).
    pub k_s: Vec<f64>,
    /// Mean profile per k_s (tripod-major bins), N m.
    pub mean: Vec<Vec<f64>>,
    /// Stride-to-stride SD per bin, N m.
    pub sd: Vec<Vec<f64>>,
    /// Strides behind each mean.
    pub strides: usize,
    /// The simulated walk's regime per k_s.
    pub regime: Vec<Regime>,
    /// Mean along-slope sand force per stance leg over the stance, N.
    pub shear_load_n: Vec<f64>,
    /// The simulated walk's climbing speed per k_s (after its first stride), m/s.
    pub speed_m_s: Vec<f64>,
    /// Bins per tripod.
    pub bins: usize,
    /// Whether the profiles are taken after [`remove_swing_offset`] (and a log's must be).
    pub swing_offset: bool,
    /// Per k_s, tripod 0's run-up stance (stride 0, the legs running up as the driver commands
    /// them), bin by bin, N m: the raw drive torque, no swing having come before it to read a
    /// sensor's offset from ([`infer_from_run_up`]).
    pub run_up_mean: Vec<Vec<f64>>,
    /// The variance of the simulated torque within each bin of a steady stance (strides 1
    /// on, tripod-major), N m^2, averaged over the grid: a stance sampled at the bus's rate
    /// reads a bin's mean from a few samples of a profile that changes within the bin (the
    /// touchdown's peak lasts a few tens of ms), and that sampling error is this over the
    /// samples one leg takes ([`infer_from_stance`]).
    pub within_var: Vec<f64>,
    /// The same for tripod 0's run-up stance ([`infer_from_run_up`]).
    pub run_up_within_var: Vec<f64>,
    /// The servos' stall torque, N m ([`CurrentInferenceSettings::servo`]): grid points whose
    /// profile exceeds it are left out of the resolution term, as no current can read them.
    pub stall_torque_n_m: f64,
}

/// Fewest samples a swing needs for its median to count as the leg's offset there.
pub const MIN_SWING_SAMPLES: usize = 3;

/// Removes each leg's current-sensor offset, estimated from its swings (docs/model.md §19).
///
/// In swing the C-leg turns through the air, and the drive torque it needs is its own inertia
/// and friction, which the model (and the emulator) take as zero; what a servo reports then is
/// its zero-current offset (a Hall sensor's bias, tens of mA on an XL330, and its slow drift
/// as the servo warms). For each leg, the median torque of each swing after the stand (stride
/// 0 on: before its first touchdown a leg of the tripod that stands is loaded) is placed at
/// the swing's mean angle, and every sample's offset is interpolated linearly in the leg's
/// angle between them (a constant beyond the first and last swing); the angle runs with time,
/// so a drift slow against a stride is followed. Returns the corrected legs and each leg's
/// mean offset, N m. A leg with no swing of [`MIN_SWING_SAMPLES`] samples is an error.
pub fn remove_swing_offset(
    schedule: &GaitSchedule,
    legs: &[LegTrace],
) -> Result<(Vec<LegTrace>, Vec<f64>), CurrentInferenceError> {
    let half = 0.5 * schedule.period_s;
    let mut out = Vec::with_capacity(legs.len());
    let mut offsets = Vec::with_capacity(legs.len());
    for (j, leg) in legs.iter().enumerate() {
        let mut swings: std::collections::BTreeMap<i64, (Vec<f64>, Vec<f64>)> = Default::default();
        for (&a, &tau) in leg.angle_rad.iter().zip(&leg.torque_n_m) {
            let (stride, since) = schedule.stride_position(j, a);
            if a.is_finite() && tau.is_finite() && stride >= 0 && since >= half {
                let e = swings.entry(stride).or_default();
                e.0.push(a);
                e.1.push(tau);
            }
        }
        let knots: Vec<(f64, f64)> = swings
            .into_values()
            .filter(|(a, _)| a.len() >= MIN_SWING_SAMPLES)
            .map(|(a, mut tau)| {
                tau.sort_by(f64::total_cmp);
                let n = tau.len();
                let median = if n % 2 == 1 { tau[n / 2] } else { 0.5 * (tau[n / 2 - 1] + tau[n / 2]) };
                (a.iter().sum::<f64>() / n as f64, median)
            })
            .collect();
        if knots.is_empty() {
            return Err(CurrentInferenceError::Setting(format!(
                "leg {j} has no swing with {MIN_SWING_SAMPLES} samples or more: its current sensor's offset cannot be told from its load (a log of whole strides, or a servo that answered in its swings, is needed)"
            )));
        }
        let at = |a: f64| -> f64 {
            let i = knots.partition_point(|k| k.0 <= a);
            if i == 0 {
                knots[0].1
            } else if i == knots.len() {
                knots[i - 1].1
            } else {
                let ((a0, m0), (a1, m1)) = (knots[i - 1], knots[i]);
                m0 + (m1 - m0) * (a - a0) / (a1 - a0)
            }
        };
        offsets.push(knots.iter().map(|k| k.1).sum::<f64>() / knots.len() as f64);
        out.push(LegTrace {
            angle_rad: leg.angle_rad.clone(),
            torque_n_m: leg.angle_rad.iter().zip(&leg.torque_n_m).map(|(&a, &t)| t - at(a)).collect(),
        });
    }
    Ok((out, offsets))
}

/// The stride simulator's settings for the servo sensor's walks, `duration_s` long, sampled
/// at `rate_hz`, the legs running up over `ramp_up_s` as the driver commands them (the robot
/// file's response time, docs/model.md §19; [`SimSettings::ramp_up_s`]): the emulator's currents and the inference's model profiles both come from
/// these, with the body pitch locked, the setting whose answers converge on the built-in
/// terrain (docs/simulate.md: the free body's walks on slopes change with the time step, so a
/// sensor read against them would read the integrator, not the sand), and otherwise the
/// simulator's default physics (the one-sided belly of docs/model.md §20.5). (Before the legs
/// ran up and a stance's bins carried their sampling error, the one-sided walks' intervals held
/// the truth in 8 of 10 emulated runs; with both, the tests pass on them, docs/drive.md.)
pub fn sensor_walk_settings(
    duration_s: f64,
    rate_hz: f64,
    ramp_up_s: f64,
) -> Result<SimSettings, crate::error::ParamError> {
    Ok(SimSettings::new(duration_s)?
        .with_sample_rate(rate_hz)?
        .with_ramp_up(ramp_up_s)?
        .with_body_pitch(crate::simulate::BodyPitch::Locked))
}

/// The grid's settings within their ranges: at least 3 grid points, 1 bin and 4 simulated
/// strides.
fn check_settings(settings: &CurrentInferenceSettings) -> Result<(), CurrentInferenceError> {
    if settings.grid_points < 3 || settings.bins < 1 || settings.simulated_strides < 4 {
        return Err(CurrentInferenceError::Setting(format!(
            "grid_points (at least 3), bins (at least 1) and simulated_strides (at least 4) are {}, {}, {}",
            settings.grid_points, settings.bins, settings.simulated_strides
        )));
    }
    Ok(())
}

/// Simulates `robot` at `slope` on constant ground `k_n` and each k_s of the settings'
/// grid (in parallel) and bins each walk's stance torques as [`stance_profiles`] bins a log.
pub fn model_grid(
    robot: &Robot,
    k_n: f64,
    slope: crate::slope::SignedSlope,
    settings: &CurrentInferenceSettings,
) -> Result<ModelGrid, CurrentInferenceError> {
    check_settings(settings)?;
    let schedule = GaitSchedule::new(robot, 2 * robot.stance_legs() as usize)
        .map_err(|e| CurrentInferenceError::Simulator(e.to_string()))?;
    let (lo, hi) = (settings.prior.min().ln(), settings.prior.max().ln());
    let n = settings.grid_points;
    let k_s: Vec<f64> = (0..n).map(|i| (lo + (hi - lo) * i as f64 / (n - 1) as f64).exp()).collect();
    // The robot's run-up walked too (the driver's, docs/model.md §19), and the strides after it whole.
    let duration = settings.simulated_strides as f64 * schedule.period_s + schedule.run_up_s;
    let sim_settings = sensor_walk_settings(duration, 200.0, schedule.run_up_s)
        .map_err(|e| CurrentInferenceError::Simulator(e.to_string()))?;
    let bins = settings.bins;
    let walks: Vec<Result<_, CurrentInferenceError>> = k_s
        .par_iter()
        .map(|&ks| {
            let terrain =
                Terrain::constant(k_n, ks).map_err(|e| CurrentInferenceError::Simulator(e.to_string()))?;
            let scenario = Scenario::new(robot.clone(), terrain, None, None)
                .map_err(|e| CurrentInferenceError::Simulator(e.to_string()))?;
            let sim = simulate(&scenario, slope, &sim_settings)
                .map_err(|e| CurrentInferenceError::Simulator(e.to_string()))?;
            let mut legs = simulated_legs(&schedule, &sim);
            let run_up = run_up_profile(&schedule, &legs, bins);
            let run_up_within = within_bin_variance(&schedule, &legs, bins, |s| s == 0);
            if settings.swing_offset {
                legs = remove_swing_offset(&schedule, &legs)?.0;
            }
            let within = within_bin_variance(&schedule, &legs, bins, |s| s >= 1);
            let profiles = stance_profiles(&schedule, &legs, bins);
            let (mean, sd, strides) = profile_statistics(&profiles, 2 * bins);
            let shear = stance_shear_load(&schedule, &sim);
            let speed = sim.summary.speed_m_s;
            Ok((mean, sd, strides, sim.summary.regime, shear, speed, (run_up, within, run_up_within)))
        })
        .collect();
    let mut grid = ModelGrid {
        slope_deg: slope.degrees(),
        k_n,
        k_s,
        mean: vec![],
        sd: vec![],
        strides: usize::MAX,
        regime: vec![],
        shear_load_n: vec![],
        speed_m_s: vec![],
        bins,
        swing_offset: settings.swing_offset,
        run_up_mean: vec![],
        within_var: vec![0.0; 2 * bins],
        run_up_within_var: vec![0.0; bins],
        stall_torque_n_m: settings.servo.stall_torque_n_m,
    };
    let points = walks.len() as f64;
    for w in walks {
        let (mean, sd, strides, regime, shear, speed, (run_up, within, run_up_within)) = w?;
        grid.run_up_mean.push(run_up);
        grid.within_var.iter_mut().zip(&within).for_each(|(g, w)| *g += w / points);
        grid.run_up_within_var.iter_mut().zip(&run_up_within).for_each(|(g, w)| *g += w / points);
        grid.mean.push(mean);
        grid.sd.push(sd);
        grid.strides = grid.strides.min(strides);
        grid.regime.push(regime);
        grid.shear_load_n.push(shear);
        grid.speed_m_s.push(speed);
    }
    Ok(grid)
}

/// The simulated legs as the servos would report them: leg j of the schedule is the
/// simulator's leg of the same tripod and rank, its drive torque the sand's resisting torque
/// about the hip (`-leg_torque_n_m`, the simulator's sign being the servo's torque on the leg
/// in the plane's positive sense).
pub fn simulated_legs(schedule: &GaitSchedule, sim: &crate::simulate::Simulation) -> Vec<LegTrace> {
    let tr = &sim.trajectory;
    let mapping = leg_mapping(schedule, &sim.geometry.tripod);
    mapping
        .iter()
        .map(|&m| LegTrace {
            angle_rad: tr.leg_angle_rad[m].clone(),
            torque_n_m: tr.leg_torque_n_m[m].iter().map(|t| -t).collect(),
        })
        .collect()
}

/// For each schedule leg, the simulator leg of the same tripod and rank within the tripod.
pub fn leg_mapping(schedule: &GaitSchedule, sim_tripods: &[usize]) -> Vec<usize> {
    let mut seen = [0usize; 2];
    (0..schedule.legs())
        .map(|j| {
            let k = schedule.tripods[j];
            let rank = seen[k];
            seen[k] += 1;
            sim_tripods.iter().enumerate().filter(|(_, &t)| t == k).map(|(i, _)| i).nth(rank).unwrap_or(k)
        })
        .collect()
}

fn stance_shear_load(schedule: &GaitSchedule, sim: &crate::simulate::Simulation) -> f64 {
    let tr = &sim.trajectory;
    let (mut sum, mut n) = (0.0, 0usize);
    for (j, tripod) in sim.geometry.tripod.iter().enumerate() {
        let leg = (0..schedule.legs()).find(|&l| schedule.tripods[l] == *tripod).unwrap_or(0);
        for (i, &a) in tr.leg_angle_rad[j].iter().enumerate() {
            let (stride, _) = schedule.stride_position(leg, a);
            if stride >= 1 && schedule.in_stance(leg, a) {
                sum += tr.leg_force_x_n[j][i];
                n += 1;
            }
        }
    }
    if n == 0 {
        0.0
    } else {
        sum / n as f64
    }
}

/// Mean and SD over complete strides (stride >= 1) of each bin; the number of strides.
fn profile_statistics(p: &StanceProfiles, width: usize) -> (Vec<f64>, Vec<f64>, usize) {
    let rows: Vec<Vec<f64>> = p
        .strides
        .iter()
        .zip(&p.profiles)
        .filter(|(&s, row)| s >= 1 && row.len() == width && row.iter().all(Option::is_some))
        .map(|(_, row)| row.iter().map(|v| v.unwrap_or(0.0)).collect())
        .collect();
    let n = rows.len();
    let mut mean = vec![0.0; width];
    let mut sd = vec![0.0; width];
    if n == 0 {
        return (mean, sd, 0);
    }
    for r in &rows {
        for (m, v) in mean.iter_mut().zip(r) {
            *m += v / n as f64;
        }
    }
    if n > 1 {
        for r in &rows {
            for ((s, v), m) in sd.iter_mut().zip(r).zip(&mean) {
                *s += (v - m).powi(2) / (n - 1) as f64;
            }
        }
        sd.iter_mut().for_each(|s| *s = s.sqrt());
    }
    (mean, sd, n)
}

/// Grid points on either side whose profiles bound the grid's resolution term (docs/model.md
/// §19): the simulated walk switches between stride patterns from one k_s to the next, so one
/// neighbour is not enough (calibrated against the emulator, docs/drive.md).
pub const RESOLUTION_REACH: usize = 1;

/// What the currents say about the sand: k_s with its 90% interval, the leg's shear load and
/// the risk of slippage at the slope.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CurrentInference {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// k_n assumed (the terrain's at the slope), N/m^3.
    pub k_n: f64,
    /// Posterior median of k_s, N/m^3.
    pub k_s: f64,
    /// 5% posterior quantile, N/m^3.
    pub k_s_lo: f64,
    /// 95% posterior quantile, N/m^3.
    pub k_s_hi: f64,
    /// Which sides of the interval the data bound.
    pub bound: Bound,
    /// The leg's along-slope shear load during stance, N (posterior mean of the simulator's).
    pub shear_load_n: f64,
    /// The closed form's shear load per leg, `m (g sin theta + R omega / dt) / n`, N (§4).
    pub closed_form_shear_load_n: f64,
    /// The climbing speed these sands give (the posterior median of the simulated walks'
    /// speeds), m/s: what the servos alone say of the speed over the ground, which they do not
    /// measure.
    pub speed_m_s: f64,
    /// 5% posterior quantile of the climbing speed, m/s.
    pub speed_lo_m_s: f64,
    /// 95% posterior quantile of the climbing speed, m/s.
    pub speed_hi_m_s: f64,
    /// Probability of the slippage regime at this slope.
    pub p_slippage: f64,
    /// Probability of the sinkage regime at this slope.
    pub p_sinkage: f64,
    /// Probability that the walk fails at this slope (slippage or sinkage, §18; the metastable
    /// regime, which still climbs, left out as `risk`'s p_fail leaves it out): the risk
    /// `drive --stop-on-risk` watches.
    pub p_fail: f64,
    /// Strides (or, live, stances) used.
    pub strides: usize,
    /// Mean measured stance profile, N m (tripod-major bins).
    pub measured_profile_n_m: Vec<f64>,
    /// The grid's k_s, N/m^3, and the posterior probability of each.
    pub posterior: Vec<(f64, f64)>,
    /// Each leg's current-sensor offset removed, as drive torque (N m; the mean over its
    /// swings, [`remove_swing_offset`]); empty when none was removed, and live (the monitor
    /// removes each leg's last swing median before the stance reaches the inference).
    pub swing_offset_n_m: Vec<f64>,
}

/// Infers k_s from a whole log's stance currents (`infer --servo-log`). Needs at least three
/// complete strides after the run-up.
pub fn infer_from_currents(
    robot: &Robot,
    grid: &ModelGrid,
    legs: &[LegTrace],
) -> Result<CurrentInference, CurrentInferenceError> {
    let observed = ObservedProfile::read(robot, legs, grid.bins, grid.swing_offset)?;
    Ok(observed.answer(robot, grid))
}

/// A log's stance profile, read before any walk is simulated: its legs' offsets removed, the
/// mean and variance of each bin over its strides. Everything that can refuse a log (too
/// few strides, a leg with no swing) refuses here, so a bad log costs no grid of walks.
struct ObservedProfile {
    mean: Vec<f64>,
    var: Vec<f64>,
    strides: usize,
    offsets: Vec<f64>,
    bins: usize,
    swing_offset: bool,
}

impl ObservedProfile {
    fn read(
        robot: &Robot,
        legs: &[LegTrace],
        bins: usize,
        swing_offset: bool,
    ) -> Result<ObservedProfile, CurrentInferenceError> {
        let schedule = GaitSchedule::new(robot, legs.len())
            .map_err(|e| CurrentInferenceError::Setting(e.to_string()))?;
        let (corrected, offsets) =
            if swing_offset { remove_swing_offset(&schedule, legs)? } else { (legs.to_vec(), vec![]) };
        let profiles = stance_profiles(&schedule, &corrected, bins);
        let (mean, sd, n) = profile_statistics(&profiles, 2 * bins);
        if n < 3 {
            return Err(CurrentInferenceError::TooFewStrides { found: n, needed: 3 });
        }
        let var = sd.iter().map(|s| s * s / n as f64).collect();
        Ok(ObservedProfile { mean, var, strides: n, offsets, bins, swing_offset })
    }

    /// The posterior of k_s on `grid` (built with this profile's bins and offset rule).
    fn answer(&self, robot: &Robot, grid: &ModelGrid) -> CurrentInference {
        debug_assert_eq!((grid.bins, grid.swing_offset), (self.bins, self.swing_offset));
        let bins: Vec<usize> = (0..2 * grid.bins).collect();
        let mut answer = posterior_answer(robot, grid, &self.mean, &self.var, &bins, self.strides);
        answer.swing_offset_n_m = self.offsets.clone();
        answer
    }
}

/// `infer --servo-log` whole: k_n of `terrain` at `slope`, the simulator's grid there, and
/// the posterior of k_s from the legs' stance torques (`legs[j]`: leg j of the alternating
/// tripod, 2 * stance_legs of them). The CLI reads a log into `legs`; Python passes arrays.
pub fn infer_servo_log(
    robot: &Robot,
    terrain: &Terrain,
    slope: crate::slope::SignedSlope,
    legs: &[LegTrace],
    settings: &CurrentInferenceSettings,
) -> Result<CurrentInference, CurrentInferenceError> {
    let expected = 2 * robot.stance_legs() as usize;
    if legs.len() != expected {
        return Err(CurrentInferenceError::Setting(format!(
            "{} legs given; the alternating tripod of this robot (stance_legs = {}) has {expected}",
            legs.len(),
            robot.stance_legs()
        )));
    }
    let (ground, _) = Scenario::new(robot.clone(), terrain.clone(), None, None)
        .map_err(|e| CurrentInferenceError::Setting(e.to_string()))?
        .ground_at(slope.felt());
    // The log is read (and refused) before the grid's walks are simulated.
    check_settings(settings)?;
    let observed = ObservedProfile::read(robot, legs, settings.bins, settings.swing_offset)?;
    let grid = model_grid(robot, ground.k_n, slope, settings)?;
    Ok(observed.answer(robot, &grid))
}

/// Live update after one stance: the posterior from tripod `tripod`'s bins of one stance
/// (`profile`, its `counts`), with `noise_sd_n_m` the torque noise of one sample.
pub fn infer_from_stance(
    robot: &Robot,
    grid: &ModelGrid,
    tripod: usize,
    profile: &[Option<f64>],
    counts: &[usize],
    noise_sd_n_m: f64,
) -> Option<CurrentInference> {
    let b = grid.bins;
    let mut mean = vec![0.0; 2 * b];
    let mut var = vec![0.0; 2 * b];
    let mut used = vec![];
    for i in 0..b {
        let idx = tripod * b + i;
        let (Some(v), c) = (profile.get(idx).copied().flatten(), counts.get(idx).copied().unwrap_or(0))
        else {
            continue;
        };
        if c == 0 {
            continue;
        }
        mean[idx] = v;
        var[idx] = stance_bin_variance(robot, noise_sd_n_m, grid.within_var.get(idx).copied(), c);
        used.push(idx);
    }
    if used.len() < b {
        return None;
    }
    // One stance is one draw of the simulator's stride-to-stride scatter, not a mean over many.
    let mut answer = posterior_answer_single(robot, grid, &mean, &var, &used);
    answer.strides = 1;
    Some(answer)
}

fn posterior_answer_single(
    robot: &Robot,
    grid: &ModelGrid,
    mean: &[f64],
    var_obs: &[f64],
    bins: &[usize],
) -> CurrentInference {
    // The simulated stance scatters from stride to stride as a single stance does: its full
    // SD, not the SD of its mean.
    let g = ModelGrid { strides: 1, ..grid.clone() };
    posterior_answer(robot, &g, mean, var_obs, bins, 1)
}

fn posterior_answer(
    robot: &Robot,
    grid: &ModelGrid,
    mean: &[f64],
    var_obs: &[f64],
    bins: &[usize],
    strides: usize,
) -> CurrentInference {
    posterior_answer_common(robot, grid, mean, var_obs, bins, strides, 0.0)
}

/// [`posterior_answer`] with a shift common to every bin of variance `common_var` integrated
/// out (an unknown sensor offset): the covariance `diag(v) + c 1 1^T`, whose quadratic form
/// and log-determinant are the independent bins' less `c (sum r/v)^2 / (1 + c sum 1/v)` and
/// plus `ln(1 + c sum 1/v)` (the matrix determinant lemma and Sherman-Morrison).
fn posterior_answer_common(
    robot: &Robot,
    grid: &ModelGrid,
    mean: &[f64],
    var_obs: &[f64],
    bins: &[usize],
    strides: usize,
    common_var: f64,
) -> CurrentInference {
    let floor = CurrentInferenceSettings::default().floor_n_m;
    let sim_n = grid.strides.max(1) as f64;
    let n = grid.k_s.len();
    // The grid's resolution: a k_s between two grid points gives a profile anywhere between
    // theirs, and the simulator's walk is not smooth in k_s (a stride's slip can switch between
    // neighbouring k_s): SD the larger step to a neighbour.
    // One variance for every grid point (a variance that differs between points would favour
    // the smooth stretches of the grid): the mean square of the profile's change between
    // neighbouring grid points, bin by bin, over the points whose walk a servo could report.
    // At the stiff end of the grid (k_s >= 1.5e7 N/m^3 at 15 deg on the paper's robot) a few
    // simulated walks spike to tens of N m in one tripod's bins (stride-to-stride SD up to
    // 13 N m, 2026-11-28), beyond the servo's stall torque, which no current can read; their
    // jumps made the mean square 1e6 times the rest's for that tripod and flattened every
    // stance of it (tripod 1's live estimates spanned the prior). They keep their own scatter
    // in `grid.sd`.
    let reportable =
        |i: usize| grid.mean[i].iter().zip(&grid.sd[i]).all(|(m, sd)| m.abs() + sd <= grid.stall_torque_n_m);
    let model_var: Vec<f64> = (0..mean.len())
        .map(|b| {
            let d: Vec<f64> = (1..n)
                .filter(|&i| reportable(i) && reportable(i - 1))
                .map(|i| (grid.mean[i][b] - grid.mean[i - 1][b]).powi(2))
                .collect();
            d.iter().sum::<f64>() / d.len().max(1) as f64
        })
        .collect();
    let step = |_i: usize, b: usize| -> f64 { model_var[b].sqrt() };
    let loglik: Vec<f64> = (0..n)
        .map(|i| {
            let v =
                |b: usize| var_obs[b] + grid.sd[i][b].powi(2) / sim_n + step(i, b).powi(2) + floor * floor;
            let r = |b: usize| mean[b] - grid.mean[i][b];
            let independent: f64 = bins.iter().map(|&b| -0.5 * (r(b) * r(b) / v(b) + v(b).ln())).sum();
            if common_var > 0.0 {
                let (sr, si) =
                    bins.iter().fold((0.0, 0.0), |(sr, si), &b| (sr + r(b) / v(b), si + 1.0 / v(b)));
                let d = 1.0 + common_var * si;
                independent + 0.5 * (common_var * sr * sr / d - d.ln())
            } else {
                independent
            }
        })
        .collect();
    let top = loglik.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let w: Vec<f64> = loglik.iter().map(|l| (l - top).exp()).collect();
    let total: f64 = w.iter().sum();
    let p: Vec<f64> = w.iter().map(|x| x / total).collect();
    let ln: Vec<f64> = grid.k_s.iter().map(|k| k.ln()).collect();
    let q = |level: f64| quantile(&ln, &p, level).exp();
    let (lo, med, hi) = (q(0.05), q(0.5), q(0.95));
    let last = p.len() - 1;
    let upper_open = w[last] > super::UNBOUNDED_LIKELIHOOD;
    let lower_open = w[0] > super::UNBOUNDED_LIKELIHOOD;
    let bound = match (lower_open, upper_open) {
        (false, false) => Bound::TwoSided,
        (false, true) => Bound::LowerOnly,
        (true, false) => Bound::UpperOnly,
        (true, true) => Bound::Neither,
    };
    // (`0.0 +`: an empty sum of floats is -0.0.)
    let weight_of = |regime: Regime| {
        0.0 + p.iter().zip(&grid.regime).filter(|(_, r)| **r == regime).map(|(x, _)| x).sum::<f64>()
    };
    let (p_slip, p_sink) = (weight_of(Regime::Slippage), weight_of(Regime::Sinkage));
    let shear = p.iter().zip(&grid.shear_load_n).map(|(x, f)| x * f).sum();
    let speed = |level: f64| weighted_quantile(&grid.speed_m_s, &p, level);
    let slope = grid.slope_deg.abs().to_radians();
    let closed = robot.mass()
        * (crate::model::G * slope.sin() + robot.leg_radius() * robot.leg_speed() / robot.response_time())
        / f64::from(robot.stance_legs());
    CurrentInference {
        slope_deg: grid.slope_deg,
        k_n: grid.k_n,
        k_s: med,
        k_s_lo: lo,
        k_s_hi: hi,
        bound,
        shear_load_n: shear,
        closed_form_shear_load_n: closed,
        speed_m_s: speed(0.5),
        speed_lo_m_s: speed(0.05),
        speed_hi_m_s: speed(0.95),
        p_slippage: p_slip,
        p_sinkage: p_sink,
        p_fail: p_slip + p_sink,
        strides,
        measured_profile_n_m: mean.to_vec(),
        posterior: grid.k_s.iter().copied().zip(p).collect(),
        swing_offset_n_m: vec![],
    }
}

/// Quantile of the discrete distribution that puts probability `p[i]` on `values[i]`: the
/// smallest value whose cumulative probability reaches `level`. For a quantity that is not
/// monotone in the grid's k_s (a walk's speed can switch between neighbouring k_s), so the
/// values are sorted rather than interpolated. NaN when there are none.
fn weighted_quantile(values: &[f64], p: &[f64], level: f64) -> f64 {
    let mut pairs: Vec<(f64, f64)> = values.iter().copied().zip(p.iter().copied()).collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = pairs.iter().map(|x| x.1).sum();
    let mut cum = 0.0;
    for &(v, w) in &pairs {
        cum += w;
        if cum >= level * total * (1.0 - 1e-12) {
            return v;
        }
    }
    pairs.last().map_or(f64::NAN, |x| x.0)
}

/// Quantile of a distribution given as probabilities at grid points `x` (each point's mass
/// spread evenly over its cell, cells meeting half-way between points).
pub(crate) fn quantile(x: &[f64], p: &[f64], level: f64) -> f64 {
    let n = x.len();
    let edge = |i: usize| -> f64 {
        if i == 0 {
            x[0] - 0.5 * (x[1] - x[0])
        } else if i == n {
            x[n - 1] + 0.5 * (x[n - 1] - x[n - 2])
        } else {
            0.5 * (x[i - 1] + x[i])
        }
    };
    let mut acc = 0.0;
    for (i, &pi) in p.iter().enumerate().take(n) {
        if acc + pi >= level && pi > 0.0 {
            let f = (level - acc) / pi;
            return edge(i) + f * (edge(i + 1) - edge(i));
        }
        acc += pi;
    }
    edge(n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::robot::RobotSpec;

    /// A hand-made grid at 20 degrees (k_n 7e5): the profiles `mean` (one row a point of
    /// `k_s`, two values a row) with no simulated scatter, one stride, every walk a success at
    /// 0.1 m/s, `bins` bins a tripod, no run-up and a servo of stall torque `stall_n_m`.
    fn grid_at_20_deg(k_s: Vec<f64>, mean: Vec<Vec<f64>>, bins: usize, stall_n_m: f64) -> ModelGrid {
        let n = k_s.len();
        ModelGrid {
            slope_deg: 20.0,
            k_n: 7e5,
            k_s,
            mean,
            sd: vec![vec![0.0; 2]; n],
            strides: 1,
            regime: vec![Regime::Success; n],
            shear_load_n: vec![0.0; n],
            speed_m_s: vec![0.1; n],
            bins,
            swing_offset: false,
            run_up_mean: vec![],
            within_var: vec![0.0; 2],
            run_up_within_var: vec![0.0; bins],
            stall_torque_n_m: stall_n_m,
        }
    }

    /// The resolution term leaves out grid points a servo could not report, by the run's
    /// servo model. Three points, one bin, profiles 0.1, 0.2 and 1.0 N m, a stance reading 0.2
    /// with no noise: on the XL330-M288 (stall 0.52 N m) only the step 0.1 -> 0.2 counts, the
    /// resolution variance is 0.01 and with the floor's 0.002^2 v = 0.010004; the weights
    /// exp(-r^2 / 2v) are 0.6067, 1 and 1.3e-14, so the middle point has 1 / 1.6067 = 0.6224.
    /// On the XM430-W350 (stall 4.1 N m) both steps count: v = (0.01 + 0.64) / 2 + 4e-6 =
    /// 0.325004, weights 0.98473, 1 and 0.37360, the middle point 1 / 2.35833 = 0.42403.
    #[test]
    fn the_reportable_torque_is_the_servo_models_by_hand() {
        let robot = Robot::new(RobotSpec::paper_hexapod()).unwrap();
        let grid = |servo: &'static ServoModel| {
            let mean = vec![vec![0.1, 0.0], vec![0.2, 0.0], vec![1.0, 0.0]];
            grid_at_20_deg(vec![1e5, 2e5, 4e5], mean, 1, servo.stall_torque_n_m)
        };
        let p =
            |servo| posterior_answer(&robot, &grid(servo), &[0.2, 0.0], &[0.0, 0.0], &[0], 1).posterior[1].1;
        assert!((p(&ServoModel::XL330_M288) - 0.6224).abs() < 1e-4, "{}", p(&ServoModel::XL330_M288));
        assert!((p(&ServoModel::XM430_W350) - 0.42403).abs() < 1e-4, "{}", p(&ServoModel::XM430_W350));
    }

    /// A stance's shift common to every bin (an unknown sensor offset) integrated out, by
    /// hand: two grid points 0.01 N m apart in both of two bins, a reading on the first; each
    /// bin's v is the resolution term 0.01^2 plus the floor 0.002^2, 1.04e-4. Independent bins
    /// put the second point at ln(w1 / w0) = -0.5 x 2 x 0.01^2 / v; a common variance c adds
    /// 0.5 c (sum r/v)^2 / (1 + c sum 1/v) there (the log-determinant term is the same at both
    /// points): a shift that explains the residuals costs little.
    #[test]
    fn a_common_offset_is_integrated_out_by_hand() {
        let robot = Robot::new(RobotSpec::paper_hexapod()).unwrap();
        let grid = grid_at_20_deg(vec![1e5, 2e5], vec![vec![0.11, 0.21], vec![0.1, 0.2]], 2, 100.0);
        let v: f64 = 1.04e-4;
        let l = |c: f64| {
            let a = posterior_answer_common(&robot, &grid, &[0.11, 0.21], &[0.0, 0.0], &[0, 1], 1, c);
            (a.posterior[1].1 / a.posterior[0].1).ln()
        };
        let independent = -0.5 * (0.01f64.powi(2) / v) * 2.0;
        assert!((l(0.0) - independent).abs() < 1e-9, "{} {independent}", l(0.0));
        let (sr, si) = (2.0 * 0.01 / v, 2.0 / v);
        let c = 1e-4;
        let shift = 0.5 * c * sr * sr / (1.0 + c * si);
        // ln(1 + c sum 1/v) is the same at both points: only the quadratic form differs.
        assert!((l(c) - (independent + shift)).abs() < 1e-9, "{} {}", l(c), independent + shift);
        assert!(l(c) > l(0.0));
    }

    #[test]
    fn quantiles_of_a_flat_distribution_by_hand() {
        // Four equal cells over [-0.5, 3.5]: the median is 1.5, the 5% quantile 0.2 - 0.5.
        let x = [0.0, 1.0, 2.0, 3.0];
        let p = [0.25; 4];
        assert!((quantile(&x, &p, 0.5) - 1.5).abs() < 1e-12);
        assert!((quantile(&x, &p, 0.05) - (-0.5 + 0.2)).abs() < 1e-12);
    }

    /// Speeds out of grid order (a walk's speed is not monotone in k_s), worked by hand:
    /// sorted 0.10 (p 0.2), 0.20 (0.5), 0.30 (0.3); cumulative 0.2, 0.7, 1.0.
    #[test]
    fn weighted_quantiles_of_unsorted_speeds_by_hand() {
        let v = [0.30, 0.10, 0.20];
        let p = [0.3, 0.2, 0.5];
        assert_eq!(weighted_quantile(&v, &p, 0.05), 0.10);
        assert_eq!(weighted_quantile(&v, &p, 0.2), 0.10);
        assert_eq!(weighted_quantile(&v, &p, 0.5), 0.20);
        assert_eq!(weighted_quantile(&v, &p, 0.7), 0.20);
        assert_eq!(weighted_quantile(&v, &p, 0.95), 0.30);
        assert!(weighted_quantile(&[], &[], 0.5).is_nan());
    }

    #[test]
    fn binning_places_samples_by_angle() {
        let robot = Robot::new(RobotSpec::paper_hexapod()).unwrap();
        let s = GaitSchedule::new(&robot, 6).unwrap();
        // Leg 0 (tripod 0) at 1/8 of the way through stance of stride 2 with torque 0.1, and
        // in its swing (ignored); leg 1 (tripod 1) at 7/8 of its stance with 0.3.
        let a0 = s.start_angle(0) + 2.0 * 2.0 * std::f64::consts::PI + std::f64::consts::PI / 8.0;
        let a0_swing = a0 + std::f64::consts::PI;
        let a1 = s.touchdown_angle_rad + 2.0 * 2.0 * std::f64::consts::PI + 7.0 * std::f64::consts::PI / 8.0;
        let legs = vec![
            LegTrace { angle_rad: vec![a0, a0_swing], torque_n_m: vec![0.1, 9.0] },
            LegTrace { angle_rad: vec![a1], torque_n_m: vec![0.3] },
        ];
        let p = stance_profiles(&s, &legs, 4);
        assert_eq!(p.strides, vec![2]);
        // 1/8 of stance is bin 0 of 4; 7/8 is bin 3, tripod 1's bins start at 4.
        assert_eq!(p.profiles[0][0], Some(0.1));
        assert_eq!(p.profiles[0][7], Some(0.3));
        assert_eq!(p.counts[0].iter().sum::<usize>(), 2);
    }

    #[test]
    fn swing_offset_is_interpolated_between_swings_by_hand() {
        let robot = Robot::new(RobotSpec::paper_hexapod()).unwrap();
        let s = GaitSchedule::new(&robot, 6).unwrap();
        let td = s.touchdown_angle_rad;
        // Swings of strides 0 and 1 (angle td + pi to td + 2 pi past each touchdown), three
        // samples each at offsets 0.01 and 0.03 N m (medians of {0.01, 0.01, 0.5} and
        // {0.03, -0.2, 0.03}), centred at td + 1.5 pi and td + 3.5 pi; a stance sample of 0.1
        // N m at td + 2.5 pi, half-way, gets 0.02 removed; one before the first swing
        // (stride -1's swing, not used) gets the first swing's 0.01; a leg with no swing fails.
        let pi = std::f64::consts::PI;
        let a = |x: f64| td + x * pi;
        let leg = LegTrace {
            angle_rad: vec![a(-0.5), a(1.25), a(1.5), a(1.75), a(2.5), a(3.25), a(3.5), a(3.75)],
            torque_n_m: vec![0.7, 0.01, 0.01, 0.5, 0.1, 0.03, -0.2, 0.03],
        };
        let (out, offsets) = remove_swing_offset(&s, std::slice::from_ref(&leg)).unwrap();
        let t = &out[0].torque_n_m;
        assert!((t[4] - 0.08).abs() < 1e-12, "{t:?}");
        assert!((t[0] - 0.69).abs() < 1e-12, "{t:?}");
        assert!((offsets[0] - 0.02).abs() < 1e-12);
        let stance_only = LegTrace { angle_rad: vec![a(0.5), a(2.5)], torque_n_m: vec![0.1, 0.1] };
        assert!(remove_swing_offset(&s, &[stance_only]).is_err());
    }
}
