//! The calibration itself: what it needs ([`JointSetup`]), the fit from several starts, the
//! intervals, and the result with its calibrated terrain and robot (docs/model.md §14,
//! docs/calibration.md).

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use super::model::SpeedModel;
use super::optimiser::minimise;
use super::problem::{build, Candidate, Problem};
use super::profile::{interval_for, ratio_interval, Profiled};
use super::{
    AnchoringObservation, CalibrationError, CalibrationWarning, FittedParameter, FreeParameter, Interval,
    JointCalibration, ObservationKind, Parameter, Pull, Quantity, ShearAtSlope, ShearLaw, ShearShape,
    SpeedObservation,
};
use crate::paper;
use crate::robot::Robot;
use crate::slope::Slope;
use crate::terrain::{interpolate, Terrain, TerrainPoint, TerrainSpec};

/// Everything a joint calibration needs.
#[derive(Debug, Clone)]
pub struct JointSetup {
    /// The robot; its freed keys are starting values.
    pub robot: Robot,
    /// Where k_n(theta) comes from (the force tests themselves, or an assumed terrain).
    pub normal: Terrain,
    /// Where k_s(theta) comes from.
    pub shear: ShearShape,
    /// Observed speeds.
    pub speeds: Vec<SpeedObservation>,
    /// Observed anchoring times.
    pub anchoring: Vec<AnchoringObservation>,
    /// The freed quantities.
    pub free: Vec<FreeParameter>,
    /// The error floor when it is not freed, m/s (>= 0).
    pub error_floor: f64,
}

/// The closed form's speed of `robot` on `terrain` at `points + 1` slopes evenly from `lo_deg`
/// to `hi_deg` (those from 0 to below 90 degrees; `None` where the leg never anchors), through
/// the terrain's angle of repose as the fit takes it (an observed speed shows the robot moved):
/// the fitted model's curve `calibrate --plot` draws beside the observed speeds.
pub fn speed_curve(
    robot: &Robot,
    terrain: &Terrain,
    lo_deg: f64,
    hi_deg: f64,
    points: usize,
) -> Vec<(f64, Option<f64>)> {
    (0..=points)
        .map(|i| lo_deg + (hi_deg - lo_deg) * i as f64 / points as f64)
        .filter_map(|d| Slope::from_degrees(d).ok().map(|s| (d, s)))
        .map(|(d, s)| {
            let mut ground = terrain.at(s);
            ground.repose = None;
            (d, crate::model::predict(robot, s, &ground).speed)
        })
        .collect()
}

/// Fits the free quantities of `setup` to all its evidence at once with the closed form; see
/// the module docs.
pub fn calibrate_jointly(setup: &JointSetup) -> Result<JointCalibration, CalibrationError> {
    calibrate_jointly_with(setup, SpeedModel::ClosedForm)
}

/// Fits the free quantities of `setup` to all its evidence at once with `model` giving the
/// speeds and anchoring times (the closed form, or the stride simulator: `calibrate --model
/// simulate`, docs/calibration.md); the same statistics, intervals and warnings either way.
pub fn calibrate_jointly_with(
    setup: &JointSetup,
    model: SpeedModel,
) -> Result<JointCalibration, CalibrationError> {
    fit(setup, model, None)
}

/// [`calibrate_jointly_with`] that stops when `cancel` is raised (from another thread: a front
/// end's Ctrl-C): the simulator's walks not yet run then fail at once, the search ends within
/// the walks in flight, and the answer is [`CalibrationError::Interrupted`]. The closed form
/// (milliseconds) does not look at the flag.
pub fn calibrate_jointly_cancellable(
    setup: &JointSetup,
    model: SpeedModel,
    cancel: &AtomicBool,
) -> Result<JointCalibration, CalibrationError> {
    fit(setup, model, Some(cancel))
}

fn fit(
    setup: &JointSetup,
    model: SpeedModel,
    cancel: Option<&AtomicBool>,
) -> Result<JointCalibration, CalibrationError> {
    let interrupted = || cancel.is_some_and(|c| c.load(Ordering::Relaxed));
    let problem =
        build(setup, model, cancel).map_err(
            |e| {
                if interrupted() {
                    CalibrationError::Interrupted
                } else {
                    e
                }
            },
        )?;
    let n = problem.unknowns.len();
    let start: Vec<f64> = problem.unknowns.iter().map(|u| u.start).collect();
    // Several starts: the given one, and the scale-like quantities a decade either way.
    let mut starts = vec![start.clone()];
    for factor in [0.1, 10.0, 30.0] {
        let mut s = start.clone();
        for (u, v) in problem.unknowns.iter().zip(s.iter_mut()) {
            let scale_like = matches!(
                u.quantity,
                Quantity::Free(Parameter::PlateScale | Parameter::ErrorFloor) | Quantity::LevelShearStrength
            );
            if scale_like {
                *v = (*v * factor).clamp(u.lo, u.hi);
            }
        }
        if s != start {
            starts.push(s);
        }
    }
    // Every start's search (and the simulator's scan, then a search from its best point) in
    // parallel (rayon); the best is picked in the same order as one after another, so the
    // answer is the same.
    let (mut fits, scanned): (Vec<(Vec<f64>, f64)>, Option<(Vec<f64>, f64)>) = rayon::join(
        || starts.par_iter().map(|s| minimise(&problem, s, &[], None)).collect(),
        || {
            let scanned = problem.simulator.as_ref().and_then(|_| scanned_start(&problem, &start));
            scanned.map(|s| minimise(&problem, &s, &[], None))
        },
    );
    fits.extend(scanned);
    let (mut best, mut s_min) = (start.clone(), f64::INFINITY);
    for (x, v) in fits {
        if v < s_min {
            (best, s_min) = (x, v);
        }
    }
    // Polish once more from the best point.
    let (x, v) = minimise(&problem, &best, &[], None);
    if v < s_min {
        (best, s_min) = (x, v);
    }
    if interrupted() {
        return Err(CalibrationError::Interrupted);
    }

    // Profile intervals, one parameter per task, beside the profile of k_s(20)/k_s(0) where it
    // is one (force tests: it needs no fitted parameter's interval).
    let (intervals, ratio_profile): (Vec<Interval>, Option<Interval>) = rayon::join(
        || {
            (0..n)
                .into_par_iter()
                .map(|j| interval_for(&problem, Profiled::Unknown(j), &best, s_min))
                .collect()
        },
        || problem.law.is_none().then(|| ratio_interval(&problem, &best, s_min, &[])),
    );
    // A profile that found a lower minimum means the global fit was not global: take it.
    let parameters: Vec<FittedParameter> = problem
        .unknowns
        .iter()
        .zip(&intervals)
        .zip(&best)
        .map(|((u, iv), &v)| FittedParameter {
            quantity: u.quantity,
            name: u.quantity.name(),
            unit: u.quantity.unit().into(),
            estimate: Interval { value: v, ..*iv },
            bounds: [u.lo, u.hi],
            at_bound: u.at_bound(v),
        })
        .collect();

    let shear_ratio_20 = ratio_profile.unwrap_or_else(|| ratio_interval(&problem, &best, s_min, &parameters));
    let (pulls, _) = problem.pulls(&best).unwrap_or_default();
    let chi_squared: f64 = pulls.iter().map(|p| p.pull * p.pull).sum();
    let dof = problem.n_obs as i64 - n as i64;
    let chi_squared_per_dof = (dof > 0).then(|| chi_squared / dof as f64);
    let candidate = problem.candidate(&best);
    let robot = candidate.robot.clone().unwrap_or_else(|| setup.robot.clone());

    let shear = shear_table(&problem, &candidate, &robot);
    let terrain = terrain_spec(&problem, &shear);
    let warnings = warnings(&problem, &robot, &pulls, &shear, &parameters, chi_squared_per_dof);
    if interrupted() {
        return Err(CalibrationError::Interrupted);
    }
    Ok(JointCalibration {
        parameters,
        chi_squared,
        dof,
        chi_squared_per_dof,
        error_floor_m_s: candidate.error_floor,
        pulls,
        shear_ratio_20,
        shear,
        robot: robot.spec().clone(),
        terrain,
        warnings,
        model,
        walks: problem.simulator.as_ref().map_or(0, |s| s.walks_run()),
    })
}

/// Cells of [`scanned_start`]'s grid over a strength-like quantity's search bounds (their
/// centres are scanned).
const SCAN_POINTS: usize = 13;

/// A start for the simulator's fit from a scan: each strength-like unknown (the plate-to-leg
/// scale, a level shear strength) at [`SCAN_POINTS`] points across its search bounds, the
/// others at `start` and the error floor (if free) at its best for that point, which costs no
/// walks; the grid point with the smallest `-2 ln L`, if it is not `start`. The simulator's
/// speeds are flat in the leg's strength wherever the legs hold (the rolling legs walk 30 cm/s
/// whatever k_s) and again wherever they sink, with the observations between the two, so a
/// local search from the closed form's start can step over that edge into the sinking plateau
/// and stop at the bound: on the paper's evidence it had, at a fit worse by 6.9 in `-2 ln L`
/// (docs/calibration.md).
fn scanned_start(problem: &Problem, start: &[f64]) -> Option<Vec<f64>> {
    let floor = problem.unknowns.iter().position(|u| u.quantity == Quantity::Free(Parameter::ErrorFloor));
    let others: Vec<usize> = (0..problem.unknowns.len()).filter(|&i| Some(i) != floor).collect();
    let mut best: Option<(Vec<f64>, f64)> = None;
    for (i, u) in problem.unknowns.iter().enumerate() {
        let strength =
            matches!(u.quantity, Quantity::Free(Parameter::PlateScale) | Quantity::LevelShearStrength);
        if !strength {
            continue;
        }
        // The grid's points in parallel (rayon), the best picked in their order.
        let scanned: Vec<(Vec<f64>, f64)> = (0..SCAN_POINTS)
            .into_par_iter()
            .map(|k| {
                // Cell centres: a start on a bound has no unbounded coordinate.
                let (a, b) = (u.search_coordinate(u.lo), u.search_coordinate(u.hi));
                let q = a + (b - a) * (k as f64 + 0.5) / SCAN_POINTS as f64;
                let mut x = start.to_vec();
                x[i] = u.value_at_search(q);
                if floor.is_some() {
                    minimise(problem, &x, &others, None)
                } else {
                    let v = problem.objective(&x);
                    (x, v)
                }
            })
            .collect();
        for (x, v) in scanned {
            if best.as_ref().is_none_or(|(_, b)| v < *b) {
                best = Some((x, v));
            }
        }
    }
    best.map(|(x, _)| x).filter(|x| x != start)
}

/// What to be careful about: speeds within one SD of the model's ceiling, values at a search
/// bound, chi^2/dof above 3.
fn warnings(
    problem: &Problem,
    robot: &Robot,
    pulls: &[Pull],
    shear: &[ShearAtSlope],
    parameters: &[FittedParameter],
    chi_squared_per_dof: Option<f64>,
) -> Vec<CalibrationWarning> {
    let mut warnings = Vec::new();
    // The closed form's ceiling s*/(T/2) is not the simulator's: it has no such warning.
    let closed_form = problem.simulator.is_none();
    for p in pulls.iter().filter(|p| closed_form && p.kind == ObservationKind::Speed) {
        let ceiling = shear.iter().find(|s| s.slope_deg == p.slope_deg).map(|s| s.speed_ceiling_m_s);
        let ceiling = ceiling.unwrap_or_else(|| {
            let slope = Slope::from_degrees(p.slope_deg).unwrap_or(Slope::LEVEL);
            problem.level_step(robot, slope) / robot.stance_duration()
        });
        if ceiling - p.observed < p.sd_total {
            warnings.push(CalibrationWarning::SpeedNearCeiling {
                slope_deg: p.slope_deg,
                observed_m_s: p.observed,
                sd_m_s: p.sd_total,
                ceiling_m_s: ceiling,
            });
        }
    }
    for p in parameters.iter().filter(|p| p.at_bound) {
        let v = p.estimate.value;
        let bound =
            if (v - p.bounds[0]).abs() <= (p.bounds[1] - v).abs() { p.bounds[0] } else { p.bounds[1] };
        warnings.push(CalibrationWarning::ParameterAtBound { name: p.name.clone(), value: v, bound });
    }
    if let Some(r) = chi_squared_per_dof.filter(|&r| r > 3.0) {
        warnings.push(CalibrationWarning::PoorFit { chi_squared_per_dof: r });
    }
    warnings
}

/// The calibrated k_s at the slopes of the written terrain: the observed and force-test slopes
/// (and every whole degree between them for the curved Coulomb law).
fn shear_table(problem: &Problem, candidate: &Candidate, robot: &Robot) -> Vec<ShearAtSlope> {
    // The observed slopes, and the force-test slopes (so nothing observed is extrapolated).
    let mut slopes: Vec<f64> = problem.setup.speeds.iter().map(|o| o.slope.degrees()).collect();
    slopes.extend(problem.setup.anchoring.iter().map(|o| o.slope.degrees()));
    slopes.extend(problem.force_tests.iter().map(|k| k.slope_deg));
    slopes.sort_by(f64::total_cmp);
    slopes.dedup();
    if let (Some(ShearLaw::Coulomb), Some(&first), Some(&last)) = (problem.law, slopes.first(), slopes.last())
    {
        let whole: Vec<f64> = (first.ceil() as i64..=last.floor() as i64).map(|d| d as f64).collect();
        slopes.extend(whole);
        slopes.sort_by(f64::total_cmp);
        slopes.dedup();
    }
    slopes
        .into_iter()
        .filter_map(|deg| Slope::from_degrees(deg).ok().map(|s| (deg, s)))
        .map(|(deg, slope)| {
            let k_s = problem.k_s(candidate, slope);
            ShearAtSlope {
                slope_deg: deg,
                k_n: problem.k_n(slope),
                k_s,
                k_s_plate: problem.law.is_none().then(|| interpolate(&candidate.plate, deg)),
                plate_force_n: k_s * paper::SHEAR_PLATE_WIDTH_M * paper::SHEAR_PLATE_DEPTH_M.powi(2),
                speed_ceiling_m_s: problem.level_step(robot, slope) / robot.stance_duration(),
            }
        })
        .collect()
}

/// The calibrated terrain: k_n (and its SD) from the normal source, k_s from the fit, k_s SD
/// the force tests' SD times the plate scale; the source's angle of repose and name carried over.
fn terrain_spec(problem: &Problem, shear: &[ShearAtSlope]) -> TerrainSpec {
    let normal = &problem.setup.normal;
    let force_test_sds: Option<Vec<(f64, f64)>> =
        problem.force_tests.iter().map(|k| k.sd.map(|sd| (k.slope_deg, sd))).collect();
    let points = shear
        .iter()
        .map(|s| {
            let (k_n_sd, _) = normal.sd_at(Slope::from_degrees(s.slope_deg).unwrap_or(Slope::LEVEL));
            // The force tests' SD (interpolated like the value) times the plate scale.
            let k_s_sd = force_test_sds.as_ref().and_then(|sds| {
                s.k_s_plate.filter(|&p| p > 0.0).map(|p| interpolate(sds, s.slope_deg) * s.k_s / p)
            });
            TerrainPoint { slope_deg: s.slope_deg, k_n: s.k_n, k_s: s.k_s, k_n_sd, k_s_sd }
        })
        .collect();
    let repose_deg = match &problem.setup.shear {
        ShearShape::ForceTests(t) => t.spec().repose_deg.or(normal.spec().repose_deg),
        ShearShape::Law(_) => normal.spec().repose_deg,
    };
    TerrainSpec { name: None, repose_deg, points }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::model::walk_on_ground;
    use crate::model::tests::paper_robot;
    use crate::simulate::SimSettings;

    /// The plotted curve is the closed form's speed through the angle of repose, as the fit
    /// takes it: on sand that flows from 15 degrees the closed form calls 30 degrees slippage
    /// (docs/model.md §6) but still gives the speed its k_n and k_s make, and the curve draws
    /// that; its slopes are the ends and the evenly spaced ones between.
    #[test]
    fn the_speed_curve_runs_through_the_angle_of_repose() {
        let robot = paper_robot();
        let spec = TerrainSpec {
            name: None,
            repose_deg: Some(15.0),
            points: vec![TerrainPoint { slope_deg: 0.0, k_n: 7e5, k_s: 3e6, k_n_sd: None, k_s_sd: None }],
        };
        let terrain = Terrain::new(spec).unwrap();
        let curve = speed_curve(&robot, &terrain, 0.0, 30.0, 2);
        assert_eq!(curve.iter().map(|p| p.0).collect::<Vec<_>>(), vec![0.0, 15.0, 30.0]);
        let thirty = Slope::from_degrees(30.0).unwrap();
        let closed = crate::model::predict(&robot, thirty, &terrain.at(thirty));
        assert_eq!(closed.regime, crate::regime::Regime::Slippage);
        assert_eq!(curve[2].1, closed.speed);
        assert!(curve[2].1.is_some_and(|v| v > 0.0), "{curve:?}");
    }

    /// The scan puts the simulator's fit in the basin of the leg strength that made the speeds:
    /// speeds walked at `plate_scale` 0.4 (leg k_s 0.4 x the force tests' 1e5 at 0 deg and, by
    /// hand, 0.4 x 7e4 at 10 deg, halfway to 4e4 at 20), observed with small SDs and fitted with
    /// the scale and the error floor free from the closed form's start: the scan's start is
    /// within one of its cells (a factor e^(ln(1e7)/13) = 3.5 on the bounds 1e-3 to 1e4) of 0.4,
    /// where the given start (10, from the closed form) is not.
    #[test]
    fn the_scan_starts_the_simulators_fit_in_the_basin_of_the_strength_that_made_the_speeds() {
        // The two-faced belly's walks, whose speeds put the closed form's start (10) outside the
        // scan's cell of 0.4; the one-sided belly's (the default) put it at 1, inside it.
        let settings = SimSettings::new(1.5)
            .unwrap()
            .with_dt(2e-3)
            .unwrap()
            .with_mechanisms(crate::simulate::Mechanisms { one_sided_belly: false, ..Default::default() })
            .unwrap();
        let walked =
            |deg: f64, k_s: f64| walk_on_ground(&paper_robot(), deg, 7e5, k_s, &settings).unwrap().speed_m_s;
        let point = |slope_deg, k_s| TerrainPoint { slope_deg, k_n: 7e5, k_s, k_n_sd: None, k_s_sd: None };
        let forces = Terrain::new(TerrainSpec {
            name: None,
            repose_deg: None,
            points: vec![point(0.0, 1e5), point(20.0, 4e4)],
        })
        .unwrap();
        let observed = |deg: f64, speed: f64| SpeedObservation {
            slope: Slope::from_degrees(deg).unwrap(),
            speed,
            speed_sd: 0.002,
        };
        let free = |parameter| FreeParameter { parameter, bounds: None };
        let setup = JointSetup {
            robot: paper_robot(),
            normal: forces.clone(),
            shear: ShearShape::ForceTests(forces),
            speeds: vec![observed(0.0, walked(0.0, 0.4 * 1e5)), observed(10.0, walked(10.0, 0.4 * 7e4))],
            anchoring: vec![],
            free: vec![free(Parameter::PlateScale), free(Parameter::ErrorFloor)],
            error_floor: 0.0,
        };
        let problem = build(&setup, SpeedModel::Simulator { settings }, None).unwrap();
        let scale = problem
            .unknowns
            .iter()
            .position(|u| u.quantity == Quantity::Free(Parameter::PlateScale))
            .unwrap();
        let start: Vec<f64> = problem.unknowns.iter().map(|u| u.start).collect();
        let scanned = scanned_start(&problem, &start).expect("a start other than the given one");
        let u = &problem.unknowns[scale];
        assert_eq!((u.lo, u.hi), (1e-3, 1e4));
        let cell = (u.hi / u.lo).ln() / SCAN_POINTS as f64;
        assert!((start[scale] / 0.4).ln().abs() > cell, "the given start {}", start[scale]);
        assert!(
            (scanned[scale] / 0.4).ln().abs() < cell,
            "scanned start {} (given start {})",
            scanned[scale],
            start[scale]
        );
    }
}
