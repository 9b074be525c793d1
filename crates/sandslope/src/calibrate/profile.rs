//! 68% profile-likelihood intervals: `{value : min over the others of -2 ln L <= minimum + 1}`,
//! found by walking out from the best value and bracketing the crossing with Brent's method.

use super::optimiser::{minimise, RatioPenalty};
use super::problem::Problem;
use super::{FittedParameter, Interval, Quantity, ShearLaw};

/// What is profiled: one unknown (in its search coordinate), or `ln k_s(20)/k_s(0)` held by a
/// stiff penalty.
#[derive(Clone, Copy)]
pub(crate) enum Profiled {
    Unknown(usize),
    LnShearRatio,
}

/// The profile of `-2 ln L` with the profiled quantity held at `q`, warm-started at `from`.
fn profile_at(problem: &Problem, target: Profiled, q: f64, from: &[f64]) -> (Vec<f64>, f64) {
    match target {
        Profiled::Unknown(j) => {
            let mut x = from.to_vec();
            let u = &problem.unknowns[j];
            x[j] = u.value_at_search(q).clamp(u.lo, u.hi);
            minimise(problem, &x, &[j], None)
        }
        Profiled::LnShearRatio => {
            // The simulator's profile holds the ratio to 1e-3 in its log (its interval is
            // reported to 2-3 digits): a stiffer penalty costs walks in an ill-conditioned search.
            let tolerance = if problem.simulator.is_some() { 1e-3 } else { 1e-5 };
            minimise(problem, from, &[], Some(RatioPenalty { target: q, tolerance }))
        }
    }
}

/// Where a walk starts, where it must stop, its first step and its direction (+1 or -1).
#[derive(Clone, Copy)]
struct Walk {
    q_best: f64,
    limit: f64,
    step0: f64,
    dir: f64,
}

/// One end of the 68% interval: walk from the best value in the walk's direction until the
/// profile rises by 1, then bracket the crossing with Brent's method. Returns `(end, open)`.
///
/// Every profile point is minimised from the nearest point already profiled (a warm start:
/// with the simulator as the model each minimisation walks the robot, and one started near its
/// answer takes a few steps where one started at the last point inside takes many), and Brent
/// stops when the bracket is 1e-3 of the last step with the simulator (1e-4 with the closed
/// form): the end is reported to 2-3 digits.
fn interval_end(problem: &Problem, target: Profiled, best: &[f64], s_min: f64, walk: Walk) -> (f64, bool) {
    let Walk { q_best, limit, step0, dir } = walk;
    let mut q_in = q_best;
    let mut x_in = best.to_vec();
    let mut step = step0;
    // The points profiled so far: (q, minimiser, profile value).
    let mut profiled: Vec<(f64, Vec<f64>, f64)> = vec![(q_best, best.to_vec(), s_min)];
    for _ in 0..40 {
        let mut q = q_in + dir * step;
        let at_limit = (q - limit) * dir >= 0.0;
        if at_limit {
            q = limit;
        }
        let (x, s) = profile_at(problem, target, q, &x_in);
        if s - s_min >= 1.0 {
            profiled.push((q, x, s));
            // With the simulator, a point is warm-started from the nearest point inside the
            // interval (profile below +1), so the bracket follows the profile's branch from the
            // best value: a point outside may sit in another basin (the legs sinking), whose
            // minimum is higher, and a start there put k_s(20)/k_s(0)'s upper end at 0.49 where
            // the profile from inside is 0.54 above the minimum (docs/calibration.md).
            let inside_only = problem.simulator.is_some();
            let f = |q: f64| {
                if let Some(p) = profiled.iter().find(|p| p.0 == q) {
                    return p.2 - s_min - 1.0;
                }
                let nearest = profiled
                    .iter()
                    .filter(|p| !inside_only || p.2 - s_min < 1.0)
                    .min_by(|a, b| (a.0 - q).abs().total_cmp(&(b.0 - q).abs()))
                    .map(|p| p.1.clone());
                let (x, s) = profile_at(problem, target, q, nearest.as_deref().unwrap_or(&x_in));
                profiled.push((q, x, s));
                s - s_min - 1.0
            };
            let rel = if problem.simulator.is_some() { 1e-3 } else { 1e-4 };
            let mut conv = roots::SimpleConvergency { eps: rel * (q - q_in).abs().max(1e-12), max_iter: 40 };
            return match roots::find_root_brent(q_in, q, f, &mut conv) {
                Ok(r) => (r, false),
                Err(_) => (0.5 * (q_in + q), false),
            };
        }
        if at_limit {
            return (limit, true);
        }
        profiled.push((q, x.clone(), s));
        q_in = q;
        x_in = x;
        step *= 2.0;
    }
    (q_in, true)
}

/// Initial step for the walk along unknown `j`: the conditional standard error from the
/// curvature of `-2 ln L` in it alone (never larger than the profile's), bounded to a sane
/// fraction of the search range.
fn initial_step(problem: &Problem, j: usize, best: &[f64], s_min: f64, q_best: f64, span: f64) -> f64 {
    let h = 1e-3 * span.max(1e-12);
    let s_at = |q: f64| {
        let mut x = best.to_vec();
        let u = &problem.unknowns[j];
        x[j] = u.value_at_search(q).clamp(u.lo, u.hi);
        problem.objective(&x)
    };
    let curv = (s_at(q_best + h) - 2.0 * s_min + s_at(q_best - h)) / (h * h);
    let se = if curv > 0.0 { (2.0 / curv).sqrt() } else { 0.1 * span };
    se.clamp(1e-6 * span.max(1e-9), 0.25 * span.max(1e-9))
}

/// The 68% interval of `target` around the best point `best` (objective `s_min`).
pub(crate) fn interval_for(problem: &Problem, target: Profiled, best: &[f64], s_min: f64) -> Interval {
    let (q_best, lo, hi, step) = match target {
        Profiled::Unknown(j) => {
            let u = &problem.unknowns[j];
            let (q_best, lo, hi) =
                (u.search_coordinate(best[j]), u.search_coordinate(u.lo), u.search_coordinate(u.hi));
            (q_best, lo, hi, initial_step(problem, j, best, s_min, q_best, hi - lo))
        }
        Profiled::LnShearRatio => {
            let r = problem.ratio(best).ln();
            (r, r - 5.0, r + 3.0, 0.05)
        }
    };
    // The two ends are independent searches: in parallel (rayon), the same answer as in turn.
    let ((q_lo, lower_open), (q_hi, upper_open)) = rayon::join(
        || interval_end(problem, target, best, s_min, Walk { q_best, limit: lo, step0: step, dir: -1.0 }),
        || interval_end(problem, target, best, s_min, Walk { q_best, limit: hi, step0: step, dir: 1.0 }),
    );
    let back = |q: f64| match target {
        Profiled::Unknown(j) => problem.unknowns[j].value_at_search(q),
        Profiled::LnShearRatio => q.exp(),
    };
    Interval { value: back(q_best), lower: back(q_lo), upper: back(q_hi), lower_open, upper_open }
}

/// The interval of `k_s(20)/k_s(0)`: a parameter of the linear law, a monotone function of the
/// friction angle for Coulomb, a penalty-held profile for force tests (exact when the force
/// values are not free).
pub(crate) fn ratio_interval(
    problem: &Problem,
    best: &[f64],
    s_min: f64,
    params: &[FittedParameter],
) -> Interval {
    let value = problem.ratio(best);
    let find = |q: Quantity| params.iter().find(|p| p.quantity == q);
    match problem.law {
        Some(ShearLaw::Linear) => find(Quantity::ShearRatio20).map(|p| p.estimate),
        Some(ShearLaw::Coulomb) => find(Quantity::FrictionAngle).map(|p| {
            let twenty = crate::Slope::from_degrees(20.0).unwrap_or(crate::Slope::LEVEL);
            let r = |phi: f64| ShearLaw::Coulomb.k_s([1.0, phi], twenty);
            Interval { value, lower: r(p.estimate.lower), upper: r(p.estimate.upper), ..p.estimate }
        }),
        None => {
            let free_force_tests = problem.force_test_unknown.iter().any(Option::is_some);
            Some(if free_force_tests {
                interval_for(problem, Profiled::LnShearRatio, best, s_min)
            } else {
                Interval { value, lower: value, upper: value, lower_open: false, upper_open: false }
            })
        }
    }
    .unwrap_or(Interval { value, lower: value, upper: value, lower_open: false, upper_open: false })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::problem::build;
    use crate::calibrate::{FreeParameter, JointSetup, Parameter, ShearShape, SpeedModel, SpeedObservation};
    use crate::model::tests::paper_robot;
    use crate::slope::Slope;
    use crate::terrain::{Terrain, TerrainPoint, TerrainSpec};

    /// The paper's evidence as `calibrate --observed data/paper-speeds.csv --forces
    /// data/example-force-tests.toml --free plate_scale,error_floor` reads it.
    fn paper_setup() -> JointSetup {
        let p = |slope_deg, k_s, k_s_sd| TerrainPoint {
            slope_deg,
            k_n: 7e5,
            k_s,
            k_n_sd: Some(7e4),
            k_s_sd: Some(k_s_sd),
        };
        let forces = Terrain::new(TerrainSpec {
            name: None,
            repose_deg: Some(25.0),
            points: vec![p(0.0, 1e5, 1.5e4), p(20.0, 4e4, 6e3)],
        })
        .unwrap();
        let speed = |deg: f64, speed, speed_sd| SpeedObservation {
            slope: Slope::from_degrees(deg).unwrap(),
            speed,
            speed_sd,
        };
        let free = |parameter| FreeParameter { parameter, bounds: None };
        JointSetup {
            robot: paper_robot(),
            normal: forces.clone(),
            shear: ShearShape::ForceTests(forces),
            speeds: vec![
                speed(0.0, 0.157, 0.0097),
                speed(10.0, 0.110, 0.0014),
                speed(15.0, 0.105, 0.0023),
                speed(20.0, 0.0498, 0.0032),
                speed(24.0, 0.056, 0.016),
            ],
            anchoring: vec![],
            free: vec![free(Parameter::PlateScale), free(Parameter::ErrorFloor)],
            error_floor: 0.0,
        }
    }

    /// Diagnostic (run by hand, release build, a few minutes): the profile of k_s(20)/k_s(0)
    /// near its upper end on the paper's evidence, minimised with the chain rule's Jacobian and
    /// with the columns walked, from the best point of each.
    #[test]
    #[ignore]
    fn ratio_profile_near_its_upper_end_with_and_without_the_chain_rule() {
        let setup = paper_setup();
        for chain_rule in [true, false] {
            let mut problem = build(&setup, SpeedModel::simulator_for_fit(), None).unwrap();
            problem.chain_rule = chain_rule;
            let start = [1.04, 0.1, 97_500.0, 40_900.0];
            let (best, s_min) = crate::calibrate::optimiser::minimise(&problem, &start, &[], None);
            println!("chain rule {chain_rule}: best {best:?} -2lnL {s_min:.5}");
            for r in [0.46, 0.48, 0.49, 0.50, 0.51, 0.52, 0.53, 0.55] {
                let (x, s) = profile_at(&problem, Profiled::LnShearRatio, f64::ln(r), &best);
                let (x2, s2) = profile_at(&problem, Profiled::LnShearRatio, f64::ln(r), &x);
                println!(
                    "  ratio {r}: profile {:.4} (again from there {:.4}) at {x:?} / {x2:?}",
                    s - s_min,
                    s2 - s_min
                );
            }
            println!("walks {}", problem.simulator.as_ref().unwrap().walks_run());
        }
    }
}
