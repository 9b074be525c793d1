//! The report's simulator section: the stride simulator (docs/model.md §15-§18) beside the
//! closed form and the observations, slope by slope, and where and why the two part
//! (docs/simulate.md).

use serde::Serialize;

use rayon::prelude::*;

use crate::calibrate::model::{walk_on_ground, MIN_SIMULATED_K_S};
use crate::calibrate::{JointCalibration, SpeedModel, SpeedObservation};
use crate::error::ParamError;
use crate::regime::Regime;
use crate::robot::Robot;
use crate::scenario::Scenario;
use crate::simulate::{
    check_walked, simulate_slopes, BodyPitch, ConvergenceCheck, MotionCause, ScalingSpread, SimSettings,
    SimSummary, SCALINGS,
};
use crate::slope::Slope;
use crate::terrain::Terrain;

/// Simulated seconds per slope in the report (after the simulator's settling).
pub const REPORT_WALK_S: f64 = 10.0;
/// The step of the report's pitch-free walks, as a fraction of the stride period T: twice the
/// free default's (docs/model.md §17). The report shows their speed, regime and pitch, which
/// converge at `T / 8000` at the paper's slopes (on the built-in robot and terrain, within
/// 0.13 cm/s of `T / 32000`'s, no regime apart) though not at every slope (18 degrees: 8.28
/// against 9.08 cm/s at `T / 64000`, and 8.58 at the free default), and does not check them
/// (docs/simulate.md, "The free body's step"); their t1, which on level sand needs
/// `T / 16000`, it does not show. At `T / 16000` the report took
/// 13.4 s of CPU against 8.9 s at `T / 8000` (release build, the built-in robot and terrain),
/// and the CLI's report tests 91 against 67 s (`cargo test -p sandslope-cli --test it report`).
pub const REPORT_FREE_STEPS_PER_STRIDE: f64 = 8000.0;

/// Relative speed difference up to which simulator and closed form are said to agree (the
/// threshold of issue 23's table of reasons).
pub const AGREE_WITHIN: f64 = 0.15;

/// One slope of the simulator section.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SimulatorRecord {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Observed speed at this slope, if any, m/s.
    pub observed_m_s: Option<f64>,
    /// Its SD, m/s.
    pub observed_sd_m_s: Option<f64>,
    /// The simulator's mean step speed with the body's pitch locked (its default, the setting
    /// whose answers converge; the closed form's no-pitch assumption, docs/model.md §15), m/s.
    pub simulated_m_s: f64,
    /// The closed form's speed (`null` where its regime rules a speed out), m/s.
    pub closed_form_m_s: Option<f64>,
    /// The regime read from the simulated motion.
    pub simulated_regime: Regime,
    /// Its cause.
    pub simulated_cause: MotionCause,
    /// The closed form's regime.
    pub closed_form_regime: Regime,
    /// The simulator's mean anchoring time over the measured steps that anchored, s (`null`:
    /// no step anchored).
    pub simulated_t1_s: Option<f64>,
    /// The closed form's anchoring time t1, s (`null`: it does not anchor).
    pub closed_form_t1_s: Option<f64>,
    /// The simulator's mean backward slip before anchoring, m.
    pub simulated_slip_m: Option<f64>,
    /// The closed form's slip `1/2 g sin(theta) t1^2`, m.
    pub closed_form_slip_m: Option<f64>,
    /// The simulator's mean net step, m.
    pub simulated_step_m: f64,
    /// The closed form's net step s, m.
    pub closed_form_step_m: Option<f64>,
    /// Largest |pitch| of the body in the walk with the pitch free, degrees.
    pub max_pitch_deg: f64,
    /// When the body of the walk with the pitch free pitched past 90 degrees, s (`null`: it
    /// did not).
    pub pitch_over_s: Option<f64>,
    /// The simulator's mean step speed with the body free to pitch (one draw from the spread
    /// of a chaotic walk on slopes, docs/simulate.md: shown for what the pitch does), m/s.
    pub pitch_free_m_s: f64,
    /// The regime of that walk.
    pub pitch_free_regime: Regime,
    /// Its cause.
    pub pitch_free_cause: MotionCause,
    /// The smallest speed of the pitch-locked walk under the three contact scalings (motion,
    /// li2013, components; docs/simulate.md, "The scaling as model uncertainty"), m/s: the
    /// model uncertainty of a choice the sand is not measured to make.
    pub scaling_min_m_s: f64,
    /// The largest, m/s.
    pub scaling_max_m_s: f64,
    /// Each scaling's regime, in the order motion, li2013, components.
    pub scaling_regimes: [Regime; 3],
    /// Whether the three scalings' walks end in the same regime (where they do not, the
    /// slope's simulated verdict is the scaling's choice).
    pub scaling_regimes_agree: bool,
    /// Whether the two agree: same regime and, where both have a speed, within 15%.
    pub agree: bool,
    /// Where they part and why, in words: worded by the front end from [`Self::parting`] and
    /// this record's values (empty as [`super::report`] returns it).
    pub why: String,
    /// How the two compare (a value of the words, not of the JSON).
    #[serde(skip)]
    pub parting: Parting,
}

/// How the simulator's pitch-locked walk and the closed form compare at one slope: the reason
/// they part, short (the page's paragraph above the table and docs/simulate.md explain each
/// mechanism once).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Parting {
    /// The body pitched past 90 degrees at `at_s`, s (the closed form has no pitch).
    Tumbled {
        /// When, s.
        at_s: f64,
    },
    /// The closed form rules a speed out; the regimes say whether they agree.
    NoClosedFormSpeed,
    /// The speeds within [`AGREE_WITHIN`] of each other: `relative` is
    /// `(simulated - closed form) / |closed form|`.
    Within {
        /// The relative difference.
        relative: f64,
    },
    /// Faster: the legs roll and the body vaults over them.
    Vaults {
        /// The relative difference.
        relative: f64,
        /// The rigid rolling step of the robot's legs, m.
        rolling_step_m: f64,
        /// The closed form's level step s*, m.
        level_step_m: f64,
    },
    /// Slower, with a net step below zero: the robot slides back.
    SlidesBack {
        /// The relative difference.
        relative: f64,
    },
    /// Slower with a forward step, not yet explained.
    Slower {
        /// The relative difference.
        relative: f64,
    },
}

/// The slopes of the section: 0 to 24 degrees every 2, and every observed slope, below the
/// terrain's angle of repose.
pub fn section_slopes(speeds: &[SpeedObservation], terrain: &Terrain) -> Vec<f64> {
    let repose = terrain.spec().repose_deg.unwrap_or(90.0);
    let mut slopes: Vec<f64> = (0..=12).map(|i| 2.0 * f64::from(i)).collect();
    slopes.extend(speeds.iter().map(|o| o.slope.degrees()));
    slopes.retain(|&s| s < repose);
    slopes.sort_by(f64::total_cmp);
    slopes.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    slopes
}

/// The section's walks: every slope of [`section_slopes`] with the body's pitch locked (the
/// records' simulated columns) and free to pitch, and the table's records.
#[derive(Debug, Clone)]
pub struct SimulatorWalks {
    /// One record per slope.
    pub records: Vec<SimulatorRecord>,
    /// The walks with the body free to pitch, in slope order.
    pub free: Vec<SimSummary>,
    /// The same walks with the pitch locked.
    pub pitch_locked: Vec<SimSummary>,
    /// Each pitch-locked walk checked: again at a quarter of the step and a tenth of the creep
    /// speed ([`crate::simulate::check_walked`]), in slope order.
    pub convergence: Vec<ConvergenceCheck>,
    /// Each pitch-locked walk beside the same slope under the other two contact scalings, in
    /// slope order.
    pub scaling_spread: Vec<ScalingSpread>,
}

/// Simulates `robot` on `terrain` at every slope of [`section_slopes`] (10 s walks, the
/// simulator's defaults), once with the body's pitch locked (the default) and once free to
/// pitch, sets each beside the closed form and the observed speed, and checks each locked walk
/// for convergence (again at a quarter of the step and a tenth of the creep speed).
pub fn simulator_section(
    robot: &Robot,
    terrain: &Terrain,
    speeds: &[SpeedObservation],
) -> Result<SimulatorWalks, ParamError> {
    let slopes = section_slopes(speeds, terrain)
        .into_iter()
        .map(crate::slope::SignedSlope::from_degrees)
        .collect::<Result<Vec<_>, _>>()?;
    let scenario = Scenario::new(robot.clone(), terrain.clone(), None, None)?;
    let settings = SimSettings::new(REPORT_WALK_S)?;
    let walk = |settings: &SimSettings| -> Result<Vec<SimSummary>, ParamError> {
        let sims = simulate_slopes(&scenario, &slopes, settings).map_err(|e| match e {
            crate::simulate::SimulateError::Param(p) => p,
        })?;
        Ok(sims.into_iter().map(|s| s.summary).collect())
    };
    let free_dt = robot.stride_period() / REPORT_FREE_STEPS_PER_STRIDE;
    let free = walk(&settings.with_body_pitch(BodyPitch::Free).with_dt(free_dt)?)?;
    let locked = settings.with_body_pitch(BodyPitch::Locked);
    let pitch_locked = walk(&locked)?;
    // The contact scaling is not measured: each locked walk again under the other two (two
    // walks a slope more, against the convergence check's five).
    let by_scaling = SCALINGS
        .iter()
        .map(|&s| {
            if s == locked.rft_scaling {
                Ok(pitch_locked.clone())
            } else {
                walk(&locked.with_rft_scaling(s))
            }
        })
        .collect::<Result<Vec<_>, _>>()?;
    let scaling_spread: Vec<ScalingSpread> = (0..slopes.len())
        .map(|i| {
            let walks = by_scaling.iter().map(|w| w[i].clone()).collect();
            ScalingSpread::of_walks(pitch_locked[i].slope_deg, walks)
        })
        .collect();
    // The locked answers are the section's: each is checked, not assumed, to be converged.
    let convergence = slopes
        .par_iter()
        .zip(&pitch_locked)
        .map(|(&slope, m)| check_walked(&scenario, slope, &locked, m))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| match e {
            crate::simulate::SimulateError::Param(p) => p,
        })?;
    let rolling = crate::simulate::rigid_rolling_step(robot);
    let records = pitch_locked
        .iter()
        .zip(&free)
        .zip(&scaling_spread)
        .map(|((m, free), spread)| {
            let observed = speeds.iter().find(|o| (o.slope.degrees() - m.slope_deg).abs() < 1e-9);
            record(m, free, spread, observed, rolling)
        })
        .collect();
    Ok(SimulatorWalks { records, free, pitch_locked, convergence, scaling_spread })
}

fn record(
    m: &SimSummary,
    free: &SimSummary,
    spread: &ScalingSpread,
    observed: Option<&SpeedObservation>,
    rolling: f64,
) -> SimulatorRecord {
    let cf = m.closed_form.speed();
    let cf_regime = m.closed_form.prediction.regime;
    let (agree, parting) = reason(m, cf, cf_regime, rolling);
    SimulatorRecord {
        slope_deg: m.slope_deg,
        observed_m_s: observed.map(|o| o.speed),
        observed_sd_m_s: observed.map(|o| o.speed_sd),
        simulated_m_s: m.speed_m_s,
        closed_form_m_s: cf,
        simulated_regime: m.regime,
        simulated_cause: m.cause,
        closed_form_regime: cf_regime,
        simulated_t1_s: m.t1_s,
        closed_form_t1_s: m.closed_form.prediction.anchoring_time,
        simulated_slip_m: m.slip_m,
        closed_form_slip_m: m.closed_form.prediction.slip,
        simulated_step_m: m.step_m,
        closed_form_step_m: m.closed_form.prediction.step,
        max_pitch_deg: free.max_pitch_deg,
        pitch_over_s: free.pitch_over_s,
        pitch_free_m_s: free.speed_m_s,
        pitch_free_regime: free.regime,
        pitch_free_cause: free.cause,
        scaling_min_m_s: spread.min_speed_m_s,
        scaling_max_m_s: spread.max_speed_m_s,
        scaling_regimes: spread.regimes,
        scaling_regimes_agree: spread.regimes_agree,
        agree,
        why: String::new(),
        parting,
    }
}

/// Whether simulator and closed form agree at one slope, and how they part.
fn reason(m: &SimSummary, cf: Option<f64>, cf_regime: Regime, rolling: f64) -> (bool, Parting) {
    if let Some(at_s) = m.pitch_over_s {
        return (false, Parting::Tumbled { at_s });
    }
    let sim = m.speed_m_s;
    match cf {
        None => (m.regime == cf_regime, Parting::NoClosedFormSpeed),
        Some(c) => {
            let relative = (sim - c) / c.abs().max(1e-12);
            if relative.abs() <= AGREE_WITHIN {
                (m.regime == cf_regime, Parting::Within { relative })
            } else if relative > 0.0 {
                let level_step_m = m.closed_form.prediction.level_step;
                (false, Parting::Vaults { relative, rolling_step_m: rolling, level_step_m })
            } else if m.step_m < 0.0 {
                (false, Parting::SlidesBack { relative })
            } else {
                (false, Parting::Slower { relative })
            }
        }
    }
}

/// How far, in the observation's own SD, the simulator's fit must miss an observed speed for
/// [`simulator_fit_misses`] to name it.
pub const MISS_SD: f64 = 2.0;

/// Leg shear strengths, N/m^3, at which [`simulator_fit_misses`] walks each missed slope to see
/// whether any ground strength reaches the observation there: half-decades from 1e4 to 1e7, the
/// range of docs/calibration.md's table (at 1e4 the paper's robot already sinks).
pub const REACH_K_S: [f64; 7] = [1e4, 3e4, 1e5, 3e5, 1e6, 3e6, 1e7];

/// An observed speed that the stride simulator's joint fit (`calibrate --model simulate`)
/// misses by more than [`MISS_SD`] of the observation's own SD, and why: issue 23 asks the
/// report to name the observation no parameter set of the simulator reaches.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SimulatorMiss {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Observed speed, m/s.
    pub observed_m_s: f64,
    /// Its SD, m/s.
    pub observed_sd_m_s: f64,
    /// The simulator's speed on the fitted ground at this slope (the fit's walk), m/s.
    pub fitted_m_s: f64,
    /// `(fitted - observed) / SD`, without the fit's error floor.
    pub miss_sd: f64,
    /// The regime of that walk, read from its motion.
    pub regime: Regime,
    /// Its cause.
    pub cause: MotionCause,
    /// Whether the body pitched past 90 degrees.
    pub pitched_over: bool,
    /// The walk's mean net step, m.
    pub step_m: f64,
    /// The rigid rolling step of the robot's legs (docs/simulate.md), m.
    pub rolling_step_m: f64,
    /// The closed form's level step s* on the fitted ground, m.
    pub level_step_m: f64,
    /// The leg k_s of each walk of the scan ([`REACH_K_S`]), N/m^3, on the fitted ground's k_n.
    pub reach_k_s: Vec<f64>,
    /// The speed of each walk of the scan, m/s.
    pub reach_m_s: Vec<f64>,
    /// The first pair of neighbouring scanned k_s whose speeds bracket the observation
    /// (`null`: no walk of the scan reaches it).
    pub reached_between: Option<[f64; 2]>,
    /// Why, in words: worded by the front end from this miss's values (empty as
    /// [`super::report`] returns it).
    pub why: String,
    /// When the body pitched past 90 degrees, s (a value of the words, not of the JSON).
    #[serde(skip)]
    pub pitch_over_s: Option<f64>,
    /// The walk's mean backward slip before anchoring, m (likewise).
    #[serde(skip)]
    pub slip_m: Option<f64>,
    /// The walk's mean anchoring time, s (likewise).
    #[serde(skip)]
    pub t1_s: Option<f64>,
}

/// The observed speeds the simulator's joint fit `fit` misses by more than [`MISS_SD`] SDs,
/// each with the walk on the fitted ground (the fit's own setting, so its speed is the fit's
/// model value), a scan of the leg's k_s at that slope ([`REACH_K_S`]) and the reason. Empty
/// when `fit` is the closed form's.
pub fn simulator_fit_misses(
    fit: &JointCalibration,
    speeds: &[SpeedObservation],
) -> Result<Vec<SimulatorMiss>, ParamError> {
    let SpeedModel::Simulator { settings } = fit.model else {
        return Ok(Vec::new());
    };
    let robot = Robot::new(fit.robot.clone())?;
    let terrain = Terrain::new(fit.terrain.clone())?;
    fit_misses(&robot, &|s| (terrain.at(s).k_n, terrain.at(s).k_s), speeds, &settings)
}

/// [`simulator_fit_misses`] on the ground `ground(slope) = (k_n, k_s)` with the walks'
/// `settings`.
fn fit_misses(
    robot: &Robot,
    ground: &(dyn Fn(Slope) -> (f64, f64) + Sync),
    speeds: &[SpeedObservation],
    settings: &SimSettings,
) -> Result<Vec<SimulatorMiss>, ParamError> {
    let rolling = crate::simulate::rigid_rolling_step(robot);
    let mut misses = Vec::new();
    for o in speeds {
        let deg = o.slope.degrees();
        let (k_n, k_s) = ground(o.slope);
        // As the fit walks: a k_s at or below zero (an extrapolated law) is no strength at all.
        let m = walk_on_ground(robot, deg, k_n, k_s.max(MIN_SIMULATED_K_S), settings)?;
        let miss_sd = (m.speed_m_s - o.speed) / o.speed_sd;
        if miss_sd.is_nan() || miss_sd.abs() <= MISS_SD {
            continue;
        }
        let reach_m_s = REACH_K_S
            .par_iter()
            .map(|&k| walk_on_ground(robot, deg, k_n, k, settings).map(|w| w.speed_m_s))
            .collect::<Result<Vec<f64>, ParamError>>()?;
        let reached_between = bracket(&REACH_K_S, &reach_m_s, o.speed);
        misses.push(SimulatorMiss {
            slope_deg: deg,
            observed_m_s: o.speed,
            observed_sd_m_s: o.speed_sd,
            fitted_m_s: m.speed_m_s,
            miss_sd,
            regime: m.regime,
            cause: m.cause,
            pitched_over: m.pitch_over_s.is_some(),
            step_m: m.step_m,
            rolling_step_m: rolling,
            level_step_m: m.closed_form.prediction.level_step,
            reach_k_s: REACH_K_S.to_vec(),
            reach_m_s,
            reached_between,
            why: String::new(),
            pitch_over_s: m.pitch_over_s,
            slip_m: m.slip_m,
            t1_s: m.t1_s,
        });
    }
    Ok(misses)
}

/// The first pair of neighbouring `xs` whose `ys` lie on either side of `target` (or on it).
fn bracket(xs: &[f64], ys: &[f64], target: f64) -> Option<[f64; 2]> {
    (1..xs.len().min(ys.len()))
        .find(|&i| (ys[i - 1] - target) * (ys[i] - target) <= 0.0)
        .map(|i| [xs[i - 1], xs[i]])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::slope::Slope;
    use crate::terrain::{TerrainPoint, TerrainSpec};

    fn terrain(repose: f64) -> Terrain {
        Terrain::new(TerrainSpec {
            name: None,
            repose_deg: Some(repose),
            points: vec![TerrainPoint { slope_deg: 0.0, k_n: 7e5, k_s: 3e6, k_n_sd: None, k_s_sd: None }],
        })
        .unwrap()
    }

    /// The grid 0, 2, ..., 24 with the observed 15 added and the duplicate 10 merged; a
    /// repose of 20 cuts everything from 20 up.
    #[test]
    fn slopes_are_the_grid_plus_observed_below_repose() {
        let obs =
            |d: f64| SpeedObservation { slope: Slope::from_degrees(d).unwrap(), speed: 0.1, speed_sd: 0.01 };
        let s = section_slopes(&[obs(10.0), obs(15.0)], &terrain(25.0));
        assert_eq!(s.len(), 14);
        assert!(s.contains(&15.0) && s.contains(&24.0));
        let s = section_slopes(&[obs(15.0), obs(22.0)], &terrain(20.0));
        assert_eq!(s, vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 15.0, 16.0, 18.0]);
    }

    #[test]
    fn a_bracket_is_the_first_neighbouring_pair_on_either_side_of_the_target() {
        let (xs, ys) = ([1.0, 2.0, 3.0, 4.0], [5.0, 3.0, 1.0, 4.0]);
        assert_eq!(bracket(&xs, &ys, 2.0), Some([2.0, 3.0]));
        // On a value: the first pair that holds it.
        assert_eq!(bracket(&xs, &ys, 3.0), Some([1.0, 2.0]));
        // Non-monotonic: the rise from 1 to 4 brackets 3.5.
        assert_eq!(bracket(&xs, &ys, 4.5), Some([1.0, 2.0]));
        assert_eq!(bracket(&xs, &ys, 0.5), None);
        assert_eq!(bracket(&xs, &ys, 6.0), None);
    }

    /// On stiff level sand the paper's robot rolls on its legs (docs/simulate.md): a level
    /// speed of 15.7 cm/s, the paper's, is missed, named with the rolling legs, and no leg k_s
    /// of the scan reaches it; an observation whose SD covers any walking speed is not named.
    #[test]
    fn a_level_speed_below_the_rolling_legs_is_named_as_unreached() {
        let robot = crate::model::tests::paper_robot();
        // Pitch locked: the free body somersaults on sand this stiff (docs/simulate.md).
        let settings = SimSettings::new(2.5).unwrap().with_body_pitch(crate::simulate::BodyPitch::Locked);
        let level = Slope::from_degrees(0.0).unwrap();
        let obs = |speed_sd| SpeedObservation { slope: level, speed: 0.157, speed_sd };
        let misses = fit_misses(&robot, &|_| (1e8, 1e8), &[obs(0.005)], &settings).unwrap();
        assert_eq!(misses.len(), 1);
        let m = &misses[0];
        // The rigid rolling step over half a period is the most a leg that does not slide can
        // carry the body.
        let rolling_speed = crate::simulate::rigid_rolling_step(&robot) / robot.stance_duration();
        assert!(m.fitted_m_s > 0.6 * rolling_speed && m.fitted_m_s < 1.02 * rolling_speed, "{m:?}");
        assert!((m.miss_sd - (m.fitted_m_s - 0.157) / 0.005).abs() < 1e-9 && m.miss_sd > MISS_SD);
        assert!(m.step_m > 0.0 && m.pitch_over_s.is_none());
        assert_eq!(m.reach_m_s.len(), REACH_K_S.len());
        assert!(m.reach_m_s.iter().all(|&v| v > 0.157), "{:?}", m.reach_m_s);
        assert_eq!(m.reached_between, None);
        // An SD of 10 m/s covers every walk: nothing to name.
        assert!(fit_misses(&robot, &|_| (1e8, 1e8), &[obs(10.0)], &settings).unwrap().is_empty());
    }
}
