//! Critical shear strength: how strong the sand must be for the robot to make progress.
//!
//! For a fixed robot, slope and k_n, the net step `s` is non-decreasing in k_s (a stronger
//! sand gives a shallower `d_s`, an earlier `t1`, less slip and longer propulsion). So there
//! is a smallest k_s at which `s > 0` (progress) and one at which `s >= s_min` (robust
//! progress). They are found by Brent's bracketed root finder on `ln k_s`. When no k_s is
//! enough the reason is returned instead: that is what a user needs to change.

use std::fmt;

use crate::model::{
    anchoring_threshold_k_s, anchoring_time, level_step_length, net_step, normal_equilibrium_depth,
    shear_equilibrium_depth, shear_load_per_leg,
};
use crate::robot::Robot;
use crate::slope::Slope;

/// Which step length the critical strength must reach.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepTarget {
    /// Any progress: `s > 0` (the slippage / metastable boundary).
    Progress,
    /// Robust progress: `s >= s_min` (the metastable / success boundary, `s = s_min` contour).
    Robust,
}

/// Why no shear strength lets the robot reach its step target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NoShearSuffices {
    /// The legs sink (`d_n >= d_max`): strength in shear cannot help.
    Sinkage {
        /// Normal equilibrium depth, m.
        d_n: f64,
        /// Reach of the leg `2R - h`, m.
        d_max: f64,
    },
    /// The slope is at or above the terrain's angle of repose.
    AtOrAboveRepose,
    /// Even with instant anchoring (`t1 = 0`) the step is the level step `s*`, which is not
    /// above the target.
    LevelStepTooShort {
        /// Level-sand step `s*`, m.
        level_step: f64,
        /// The step that had to be exceeded (0) or reached (s_min), m.
        target: f64,
    },
}

impl fmt::Display for NoShearSuffices {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NoShearSuffices::Sinkage { d_n, d_max } => write!(
                f,
                "no k_s is enough: the legs sink (d_n = {d_n:.4} m >= 2R - h = {d_max:.4} m); raise k_n or lighten the robot"
            ),
            NoShearSuffices::AtOrAboveRepose => {
                write!(f, "no k_s is enough: the slope is at or above the terrain's angle of repose")
            }
            NoShearSuffices::LevelStepTooShort { level_step, target } => write!(
                f,
                "no k_s is enough: even instant anchoring gives the level step s* = {level_step:.4} m, which does not exceed the required {target:.4} m"
            ),
        }
    }
}

impl std::error::Error for NoShearSuffices {}

/// The net step at shear strength `k_s`, continued past the anchoring limit.
///
/// For `k_s` below the anchoring threshold the leg never anchors (the model leaves `s`
/// undefined); the root finder only evaluates `k_s` at or above it.
fn step_at(robot: &Robot, slope: Slope, level_step: f64, k_s: f64) -> f64 {
    let d_s = shear_equilibrium_depth(robot, slope, k_s).min(robot.max_depth());
    let t1 = anchoring_time(robot, d_s).expect("d_s clamped to d_max anchors");
    net_step(robot, slope, level_step, t1)
}

/// The smallest k_s (N/m^3) at which the robot reaches `target` on ground with normal
/// resistance `k_n` at `slope`, or why none does.
///
/// `beyond_repose` is whether the slope is at or above the terrain's angle of repose.
/// For [`StepTarget::Progress`] this is the infimum of the k_s giving `s > 0`; where the step
/// is already positive as soon as the leg anchors, it is the anchoring threshold
/// `F_a / (W (2R - h)^2)` (below it there is no anchoring).
pub fn critical_shear_strength(
    robot: &Robot,
    slope: Slope,
    k_n: f64,
    beyond_repose: bool,
    target: StepTarget,
) -> Result<f64, NoShearSuffices> {
    let (s_star, s_target) = reachable_step(robot, slope, k_n, beyond_repose, target)?;
    let k_anchor = anchoring_threshold_k_s(robot, slope);
    let f = |ln_k: f64| step_at(robot, slope, s_star, ln_k.exp()) - s_target;
    let lo = k_anchor.ln();
    if f(lo) >= 0.0 {
        return Ok(k_anchor);
    }
    // Expand upwards until the step exceeds the target; s -> s* > target guarantees an end.
    let mut hi = lo + 1.0;
    while f(hi) <= 0.0 {
        hi += 2.0;
        // Written so that a NaN or infinite end also stops the search (an infinite anchoring
        // threshold once made `hi > lo + 200` never true: a hang).
        if (hi - lo).is_nan() || hi - lo > 200.0 {
            // s is within rounding of s* at k_s ~ e^200 k_anchor: treat as unreachable.
            return Err(NoShearSuffices::LevelStepTooShort { level_step: s_star, target: s_target });
        }
    }
    let mut conv = roots::SimpleConvergency { eps: 1e-13, max_iter: 200 };
    let ln_k = roots::find_root_brent(lo, hi, f, &mut conv).unwrap_or(hi);
    Ok(ln_k.exp())
}

/// Where the net step reaches `target` as a function of the level step: the critical shear
/// strength in closed form (docs/model.md §13), for a robot whose legs do not sink.
///
/// The net step `s(t1) = s* (1 - t1/tau)^2 - g sin(theta) t1 (2 tau - t1) / 2`
/// (`tau = T/2`) is a quadratic in the anchoring time, decreasing on `[0, tau]`; its smaller
/// root `t1 = 2c / (-b + sqrt(b^2 - 4ac))` (the cancellation-free form) with
/// `a = s*/tau^2 + g sin(theta)/2`, `b = -2 s*/tau - g sin(theta) tau`, `c = s* - target` is
/// where `s = target`. A leg reaches the depth `d(t1)` at `t1` only up to its deepest point
/// (`t_max`, `d = d_max`), so `t1` is capped there; the strength is `F_a / (W d(t1)^2)`.
/// Returns `(k_s, capped)`, `k_s = +inf` when `s* <= target` (no strength suffices). The
/// anchoring floor is the caller's (a capped strength is the anchoring threshold itself).
pub(crate) fn critical_closed_form(robot: &Robot, slope: Slope, level_step: f64, target: f64) -> (f64, bool) {
    if level_step <= target {
        return (f64::INFINITY, false);
    }
    let tau = robot.stance_duration();
    let gs = crate::constants::G * slope.sin();
    let a = level_step / (tau * tau) + 0.5 * gs;
    let b = -2.0 * level_step / tau - gs * tau;
    let c = level_step - target;
    let t1 = 2.0 * c / (-b + (b * b - 4.0 * a * c).max(0.0).sqrt());
    let t_max = crate::leg::time_to_deepest(&robot.leg(), robot.leg_speed());
    let capped = t1 >= t_max;
    let d_s = if capped { robot.max_depth() } else { crate::model::leg_depth(robot, t1) };
    (shear_load_per_leg(robot, slope) / (robot.leg_width() * d_s * d_s), capped)
}

/// [`critical_closed_form`] as `(ln k_s, capped)`, the form the risk map integrates over.
pub(crate) fn ln_critical_closed_form(
    robot: &Robot,
    slope: Slope,
    level_step: f64,
    target: f64,
) -> (f64, bool) {
    let (k, capped) = critical_closed_form(robot, slope, level_step, target);
    (k.ln(), capped)
}

/// The level step `s*` at `k_n` and the step `target` asks for, or why no k_s reaches it:
/// the legs sink, the slope is at or beyond repose, or `s*` (the step's supremum as
/// k_s -> infinity, where d_s -> 0 and t1 -> 0) is not above the target. Shared by the root
/// finder and the closed form, so both refuse the same cases.
fn reachable_step(
    robot: &Robot,
    slope: Slope,
    k_n: f64,
    beyond_repose: bool,
    target: StepTarget,
) -> Result<(f64, f64), NoShearSuffices> {
    let d_n = normal_equilibrium_depth(robot, slope, k_n);
    let d_max = robot.max_depth();
    if d_n >= d_max {
        return Err(NoShearSuffices::Sinkage { d_n, d_max });
    }
    if beyond_repose {
        return Err(NoShearSuffices::AtOrAboveRepose);
    }
    let s_star = level_step_length(robot, slope, d_n);
    let s_target = match target {
        StepTarget::Progress => 0.0,
        StepTarget::Robust => robot.min_step(),
    };
    if s_star <= s_target {
        return Err(NoShearSuffices::LevelStepTooShort { level_step: s_star, target: s_target });
    }
    Ok((s_star, s_target))
}

/// The same as [`critical_shear_strength`], in closed form instead of by root finding
/// (docs/model.md §13): about a hundred times faster, and equal to it within the root
/// finder's tolerance (relative 1e-9 in the tests). Risk maps evaluate it on fine grids.
pub fn critical_shear_strength_closed_form(
    robot: &Robot,
    slope: Slope,
    k_n: f64,
    beyond_repose: bool,
    target: StepTarget,
) -> Result<f64, NoShearSuffices> {
    let (s_star, s_target) = reachable_step(robot, slope, k_n, beyond_repose, target)?;
    let (ln_k, _) = ln_critical_closed_form(robot, slope, s_star, s_target);
    Ok(ln_k.exp().max(anchoring_threshold_k_s(robot, slope)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constants::G;
    use crate::model::{leg_depth, predict, tests::paper_robot};
    use crate::regime::Regime;
    use crate::terrain::Ground;

    /// Independent closed form: s(t1) = s* (1 - 2 t1/T)^2 - g sin(theta) t1 (T - t1)/2 is a
    /// quadratic in t1; solve s = target for the root in [0, T/2], then
    /// d_s = d(t1) and k_s = F_a / (W d_s^2).
    fn closed_form(robot: &Robot, slope: Slope, s_star: f64, target: f64) -> f64 {
        let t = robot.stride_period();
        let gs = G * slope.sin();
        let a = 4.0 * s_star / (t * t) + 0.5 * gs;
        let b = -4.0 * s_star / t - 0.5 * gs * t;
        let c = s_star - target;
        let t1 = (-b - (b * b - 4.0 * a * c).sqrt()) / (2.0 * a);
        let d_s = leg_depth(robot, t1);
        shear_load_per_leg(robot, slope) / (robot.leg_width() * d_s * d_s)
    }

    #[test]
    fn matches_closed_form_on_slopes() {
        let r = paper_robot();
        for deg in [10.0, 15.0, 20.0, 24.0, 35.0] {
            let slope = Slope::from_degrees(deg).unwrap();
            let s_star = level_step_length(&r, slope, normal_equilibrium_depth(&r, slope, 7e5));
            for (target, s_t) in [(StepTarget::Progress, 0.0), (StepTarget::Robust, r.min_step())] {
                let k = critical_shear_strength(&r, slope, 7e5, false, target).unwrap();
                let expect = closed_form(&r, slope, s_star, s_t).max(anchoring_threshold_k_s(&r, slope));
                assert!((k - expect).abs() < 1e-9 * expect, "{deg} {target:?}: {k} vs {expect}");
            }
        }
    }

    #[test]
    fn boundary_regimes_on_either_side() {
        let r = paper_robot();
        let slope = Slope::from_degrees(20.0).unwrap();
        let k0 = critical_shear_strength(&r, slope, 7e5, false, StepTarget::Progress).unwrap();
        let k1 = critical_shear_strength(&r, slope, 7e5, false, StepTarget::Robust).unwrap();
        assert!(k0 < k1);
        let at = |k: f64| predict(&r, slope, &Ground::new(7e5, k).unwrap()).regime;
        assert_eq!(at(k0 * 0.999), Regime::Slippage);
        assert_eq!(at(k0 * 1.001), Regime::Metastable);
        assert_eq!(at(k1 * 0.999), Regime::Metastable);
        assert_eq!(at(k1 * 1.001), Regime::Success);
    }

    #[test]
    fn level_sand_progress_starts_at_anchoring() {
        // On level sand there is no slip, so any anchoring gives s > 0 (h > 0 keeps t1 < T/2).
        let r = paper_robot();
        let k = critical_shear_strength(&r, Slope::LEVEL, 7e5, false, StepTarget::Progress).unwrap();
        assert!((k - anchoring_threshold_k_s(&r, Slope::LEVEL)).abs() < 1e-9 * k);
    }

    #[test]
    fn reports_why_no_strength_suffices() {
        let r = paper_robot();
        let slope = Slope::from_degrees(20.0).unwrap();
        assert!(matches!(
            critical_shear_strength(&r, slope, 1e4, false, StepTarget::Progress),
            Err(NoShearSuffices::Sinkage { .. })
        ));
        assert_eq!(
            critical_shear_strength(&r, slope, 7e5, true, StepTarget::Progress),
            Err(NoShearSuffices::AtOrAboveRepose)
        );
        // A measured level step shorter than s_min: robust progress impossible.
        let short = r.with_mass(0.35).unwrap();
        let short =
            crate::Robot::new(crate::RobotSpec { level_step_m: Some(0.03), ..short.spec().clone() }).unwrap();
        assert!(matches!(
            critical_shear_strength(&short, slope, 7e5, false, StepTarget::Robust),
            Err(NoShearSuffices::LevelStepTooShort { .. })
        ));
    }
    /// The closed form agrees with the root finder on many robots, slopes and k_n (including
    /// level ground where the anchoring threshold binds, a measured level step, heavy robots
    /// and k_n near the sinkage threshold), and fails for the same reasons.
    #[test]
    fn closed_form_agrees_with_the_root_finder() {
        let base = paper_robot();
        let measured =
            Robot::new(crate::RobotSpec { level_step_m: Some(0.06), ..base.spec().clone() }).unwrap();
        let low_hip = Robot::new(crate::RobotSpec { hip_height_m: 0.005, ..base.spec().clone() }).unwrap();
        let mut checked = 0;
        for robot in [base.clone(), base.with_mass(1.0).unwrap(), measured, low_hip] {
            for deg in [0.0, 5.0, 12.0, 20.0, 24.0, 33.0] {
                let slope = Slope::from_degrees(deg).unwrap();
                let k_star = crate::model::sinkage_threshold_k_n(&robot, slope);
                for f in [1.0001, 1.01, 1.3, 2.0, 5.0, 30.0, 300.0, 1e4] {
                    for target in [StepTarget::Progress, StepTarget::Robust] {
                        let k_n = k_star * f;
                        let brent = critical_shear_strength(&robot, slope, k_n, false, target);
                        let closed = critical_shear_strength_closed_form(&robot, slope, k_n, false, target);
                        match (brent, closed) {
                            (Ok(a), Ok(b)) => {
                                assert!((a / b - 1.0).abs() < 1e-9, "{deg} {f} {target:?}: {a} vs {b}");
                                checked += 1;
                            }
                            (Err(a), Err(b)) => assert_eq!(
                                std::mem::discriminant(&a),
                                std::mem::discriminant(&b),
                                "{deg} {f} {target:?}"
                            ),
                            (a, b) => panic!("{deg} {f} {target:?}: {a:?} vs {b:?}"),
                        }
                    }
                }
                assert!(critical_shear_strength_closed_form(
                    &robot,
                    slope,
                    k_star * 0.99,
                    false,
                    StepTarget::Progress
                )
                .is_err());
            }
        }
        assert!(checked > 250, "{checked}");
    }
}
