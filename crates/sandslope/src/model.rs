//! The shear-anchoring model of a C-legged robot on a sand slope (docs/model.md §3-§6).
//!
//! Each equation is a function named after the paper's quantity, so phase maps and planners
//! can reuse the parts that depend on only one of k_n, k_s; [`predict`] composes them into a
//! [`Prediction`] holding every intermediate value.
//!
//! In order: normal load and equilibrium depth `d_n`, level-sand step `s*`, downslope shear
//! load and shear-equilibrium depth `d_s`, anchoring time `t1`, backward slip `s1`,
//! propulsion `s2`, net step `s = s2 - s1`, step-averaged speed `v = s / (T/2)`, and the regime.

use crate::leg::{depth_after, time_to_depth, Leg};
use crate::regime::{classify, Cause, Regime};
use crate::robot::{LevelStep, Robot};
use crate::slope::Slope;
use crate::terrain::Ground;

pub use crate::constants::G;

/// Normal load per stance leg, `F_N = m g cos(theta) / n`, N.
pub fn normal_load_per_leg(robot: &Robot, slope: Slope) -> f64 {
    robot.mass() * G * slope.cos() / f64::from(robot.stance_legs())
}

/// Normal equilibrium depth, `d_n = m g cos(theta) / (n k_n A_c)`, m (from `F_n = k_n d A_c`).
///
/// Infinite when `k_n = 0`.
pub fn normal_equilibrium_depth(robot: &Robot, slope: Slope, k_n: f64) -> f64 {
    normal_load_per_leg(robot, slope) / (k_n * robot.contact_area())
}

/// The k_n at which `d_n = d_max` exactly: below or at it the robot sinks, N/m^3.
///
/// `k_n* = m g cos(theta) / (n A_c (2R - h))`; infinite when `h = 2R`.
pub fn sinkage_threshold_k_n(robot: &Robot, slope: Slope) -> f64 {
    normal_load_per_leg(robot, slope) / (robot.contact_area() * robot.max_depth())
}

/// Level-sand step length `s*`, m (rotary walking model, docs/model.md §3), for the normal
/// depth `d_n` at `slope`.
///
/// The robot's measured `level_step_m` if given; else `2 sqrt(R^2 - (d + h - R)^2)` when
/// `d_n < d_max`, and 0 when `d_n >= d_max`, where `d = d_n` (the default,
/// [`LevelStep::Slope`]) or `d = d_n / cos(theta)`, the depth on level sand
/// ([`LevelStep::Level`], the paper's definition of s*; docs/model.md §3 marks the choice).
pub fn level_step_length(robot: &Robot, slope: Slope, d_n: f64) -> f64 {
    if let Some(s) = robot.measured_level_step() {
        return s;
    }
    if d_n >= robot.max_depth() {
        return 0.0;
    }
    let d_n = match robot.level_step_rule() {
        LevelStep::Slope => d_n,
        LevelStep::Level => d_n / slope.cos(),
    };
    robot.leg().level_step(d_n)
}

/// Applied downslope shear load per stance leg, `F_a = m (g sin(theta) + R omega / dt) / n`, N.
pub fn shear_load_per_leg(robot: &Robot, slope: Slope) -> f64 {
    let accel = G * slope.sin() + robot.leg_radius() * robot.leg_speed() / robot.response_time();
    robot.mass() * accel / f64::from(robot.stance_legs())
}

/// Shear-equilibrium depth, `d_s = sqrt(F_a / (k_s W))`, m (from `F_s = k_s W d^2`).
///
/// Infinite when `k_s = 0`.
pub fn shear_equilibrium_depth(robot: &Robot, slope: Slope, k_s: f64) -> f64 {
    (shear_load_per_leg(robot, slope) / (k_s * robot.leg_width())).sqrt()
}

/// The k_s at which `d_s = d_max` exactly: below it the leg never anchors, N/m^3.
///
/// `k_s^a = F_a / (W (2R - h)^2)`; infinite when `h = 2R`.
pub fn anchoring_threshold_k_s(robot: &Robot, slope: Slope) -> f64 {
    let d_max = robot.max_depth();
    shear_load_per_leg(robot, slope) / (robot.leg_width() * d_max * d_max)
}

/// Leg depth below the surface during stance, `d(t) = R sin(omega t + phi0) + R - h`, m.
///
/// `d(0) = 0`; the maximum `2R - h` is reached at `omega t + phi0 = pi/2`.
pub fn leg_depth(robot: &Robot, t: f64) -> f64 {
    depth_after(&robot.leg(), robot.leg_speed(), t)
}

/// Anchoring time, `t1 = (asin((d_s + h)/R - 1) - phi0) / omega`, s, in `[0, T/2]`.
///
/// `None` when `d_s > d_max`: the leg never reaches shear equilibrium in this stance.
pub fn anchoring_time(robot: &Robot, d_s: f64) -> Option<f64> {
    time_to_depth(&robot.leg(), robot.leg_speed(), d_s)
}

/// Anchoring time at `k_s`, continued at the anchoring limit: where the leg would not anchor
/// (`d_s > d_max`, or `k_s <= 0`) it is taken to anchor at its deepest point, `d_s = d_max`, s.
///
/// Not the model's prediction there (which has no t1, docs/model.md §4) but the continuous
/// extension that calibration and inference fit through, so their objectives have no jump at
/// the anchoring threshold (docs/model.md §14).
pub fn continued_anchoring_time(robot: &Robot, slope: Slope, k_s: f64) -> f64 {
    let d_s = if k_s > 0.0 { shear_equilibrium_depth(robot, slope, k_s) } else { f64::INFINITY };
    anchoring_time(robot, d_s.min(robot.max_depth())).unwrap_or(robot.stance_duration())
}

/// Step-averaged speed at `k_s` with level step `level_step`, continued at the anchoring limit
/// as [`continued_anchoring_time`] is, m/s.
pub fn continued_speed(robot: &Robot, slope: Slope, level_step: f64, k_s: f64) -> f64 {
    step_speed(robot, net_step(robot, slope, level_step, continued_anchoring_time(robot, slope, k_s)))
}

/// Backward slip before anchoring, `s1 = 1/2 g sin(theta) t1^2`, m.
pub fn backward_slip(slope: Slope, t1: f64) -> f64 {
    0.5 * G * slope.sin() * t1 * t1
}

/// Propulsion after anchoring, `s2 = s* ((T/2 - t1)/(T/2))^2 - g sin(theta) t1 (T/2 - t1)`, m.
pub fn propulsion(robot: &Robot, slope: Slope, level_step: f64, t1: f64) -> f64 {
    let half = robot.stance_duration();
    let left = half - t1;
    level_step * (left / half).powi(2) - G * slope.sin() * t1 * left
}

/// Net step `s = s2 - s1 = s* ((T/2 - t1)/(T/2))^2 - 1/2 g sin(theta) t1 (T - t1)`, m.
pub fn net_step(robot: &Robot, slope: Slope, level_step: f64, t1: f64) -> f64 {
    propulsion(robot, slope, level_step, t1) - backward_slip(slope, t1)
}

/// Step-averaged speed along the surface, `v = s / (T/2)`, m/s.
pub fn step_speed(robot: &Robot, step: f64) -> f64 {
    step / robot.stance_duration()
}

/// Everything the model says about one stance of `robot` on `ground` at `slope`.
///
/// Lengths in m, times in s, forces in N. `None` marks a quantity docs/model.md leaves undefined:
/// without anchoring (`d_s > d_max`) there is no t1, slip, propulsion, step or speed; with
/// `k_n = 0` (or `k_s = 0`) the depth `d_n` (or `d_s`) is infinite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prediction {
    /// The slope evaluated.
    pub slope: Slope,
    /// Normal penetration resistance used, N/m^3.
    pub k_n: f64,
    /// Shear strength used, N/m^3.
    pub k_s: f64,
    /// Normal load per stance leg `F_N`, N.
    pub normal_load: f64,
    /// Normal equilibrium depth `d_n`, m.
    pub normal_depth: Option<f64>,
    /// Level-sand step length `s*`, m.
    pub level_step: f64,
    /// Downslope shear load per stance leg `F_a`, N.
    pub shear_load: f64,
    /// Shear-equilibrium depth `d_s`, m.
    pub shear_depth: Option<f64>,
    /// Anchoring time `t1`, s.
    pub anchoring_time: Option<f64>,
    /// Backward slip before anchoring `s1`, m.
    pub slip: Option<f64>,
    /// Propulsion after anchoring `s2`, m.
    pub propulsion: Option<f64>,
    /// Net step `s`, m (negative: the robot loses ground).
    pub step: Option<f64>,
    /// Step-averaged speed along the surface `v`, m/s.
    pub speed: Option<f64>,
    /// The regime (docs/model.md §6).
    pub regime: Regime,
    /// The finer reason for the regime.
    pub cause: Cause,
}

/// Runs the whole model for one stance (docs/model.md §3-§6).
pub fn predict(robot: &Robot, slope: Slope, ground: &Ground) -> Prediction {
    let finite = |x: f64| x.is_finite().then_some(x);
    let d_n = normal_equilibrium_depth(robot, slope, ground.k_n);
    let s_star = level_step_length(robot, slope, d_n);
    let d_s = shear_equilibrium_depth(robot, slope, ground.k_s);
    let t1 = anchoring_time(robot, d_s);
    let slip = t1.map(|t1| backward_slip(slope, t1));
    let s2 = t1.map(|t1| propulsion(robot, slope, s_star, t1));
    let step = match (s2, slip) {
        (Some(s2), Some(s1)) => Some(s2 - s1),
        _ => None,
    };
    let cause = classify(d_n >= robot.max_depth(), ground.beyond_repose(slope), step, robot.min_step());
    Prediction {
        slope,
        k_n: ground.k_n,
        k_s: ground.k_s,
        normal_load: normal_load_per_leg(robot, slope),
        normal_depth: finite(d_n),
        level_step: s_star,
        shear_load: shear_load_per_leg(robot, slope),
        shear_depth: finite(d_s),
        anchoring_time: t1,
        slip,
        propulsion: s2,
        step,
        speed: step.map(|s| step_speed(robot, s)),
        regime: cause.regime(),
        cause,
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::robot::RobotSpec;
    use std::f64::consts::PI;

    pub(crate) fn paper_robot() -> Robot {
        Robot::new(RobotSpec::paper_hexapod()).unwrap()
    }

    fn deg(d: f64) -> Slope {
        Slope::from_degrees(d).unwrap()
    }

    fn close(a: f64, b: f64, rel: f64) {
        assert!((a - b).abs() <= rel * b.abs().max(1e-300), "{a} vs {b}");
    }

    /// Level sand, k_n = 7e5, k_s = 2e6, worked by hand (digits checked with an independent
    /// transcription of docs/model.md in Python):
    /// F_N = 0.35*9.81/3 = 1.14450 N; d_n = 1.14450/(7e5*4e-4) = 4.08750e-3 m;
    /// s* = 2 sqrt(0.04^2 - (0.0040875 + 0.03 - 0.04)^2) = 2 sqrt(0.0016 - 3.49577e-5) = 0.0791209 m;
    /// F_a = 0.35*(0.04*2pi/0.2)/3 = 0.146608 N; d_s = sqrt(0.146608/(2e6*0.01)) = 2.70747e-3 m;
    /// t1 = (asin(0.0327075/0.04 - 1) - asin(-0.25))/(2 pi) = (-0.183340 + 0.252680)/(2 pi) = 0.0110361 s;
    /// s1 = 0; s = s* (1 - 2 t1)^2 = 0.0791212 * 0.956338 = 0.0756670 m; v = s/0.5 = 0.151334 m/s.
    #[test]
    fn level_sand_by_hand() {
        let p = predict(&paper_robot(), Slope::LEVEL, &Ground::new(7e5, 2e6).unwrap());
        close(p.normal_load, 1.144_50, 1e-5);
        close(p.normal_depth.unwrap(), 4.087_50e-3, 1e-5);
        close(p.level_step, 0.079_121_2, 1e-6);
        close(p.shear_load, 0.146_608, 1e-5);
        close(p.shear_depth.unwrap(), 2.707_47e-3, 1e-5);
        close(p.anchoring_time.unwrap(), 0.011_036_1, 1e-5);
        assert_eq!(p.slip.unwrap(), 0.0);
        close(p.step.unwrap(), 0.075_667_0, 1e-5);
        close(p.speed.unwrap(), 0.151_334, 1e-5);
        assert_eq!(p.regime, Regime::Success);
    }

    /// 20 degrees, k_n = 7e5, k_s = 1e6, worked by hand (digits checked as above):
    /// sin = 0.342020, cos = 0.939693; d_n = 4.08750e-3*0.939693 = 3.84099e-3 m;
    /// s* = 2 sqrt(0.0016 - (0.00384099 - 0.01)^2) = 2 sqrt(0.0016 - 3.79334e-5) = 0.0790460 m;
    /// F_a = 0.35*(9.81*0.342020 + 1.256637)/3 = 0.35*4.611855/3 = 0.538050 N;
    /// d_s = sqrt(0.538050/1e4) = 7.33519e-3 m;
    /// t1 = (asin(0.0373352/0.04 - 1) - (-0.252680))/(2 pi) = (-0.0666698 + 0.252680)/(2 pi) = 0.0296045 s;
    /// s1 = 0.5*3.355216*0.0296045^2 = 1.47030e-3 m;
    /// s2 = 0.0790460*(0.4703955/0.5)^2 - 3.355216*0.0296045*0.4703955 = 0.0699636 - 0.0467239 = 0.0232385 m;
    /// s = 0.0217682 m; v = 0.0435363 m/s; 0 < s < s_min = 0.04, so metastable.
    #[test]
    fn twenty_degrees_by_hand() {
        let p = predict(&paper_robot(), deg(20.0), &Ground::new(7e5, 1e6).unwrap());
        close(p.normal_depth.unwrap(), 3.840_99e-3, 1e-5);
        close(p.level_step, 0.079_046_0, 1e-6);
        close(p.shear_load, 0.538_050, 1e-5);
        close(p.shear_depth.unwrap(), 7.335_19e-3, 1e-5);
        close(p.anchoring_time.unwrap(), 0.029_604_5, 1e-5);
        close(p.slip.unwrap(), 1.470_30e-3, 1e-5);
        close(p.propulsion.unwrap(), 0.023_238_5, 1e-5);
        close(p.step.unwrap(), 0.021_768_2, 1e-5);
        close(p.speed.unwrap(), 0.043_536_3, 1e-5);
        assert_eq!(p.regime, Regime::Metastable);
    }

    #[test]
    fn leg_depth_is_zero_at_touchdown_and_max_at_quarter_turn() {
        let r = paper_robot();
        assert!(leg_depth(&r, 0.0).abs() < 1e-15);
        let t_max = (PI / 2.0 - r.touchdown_angle()) / r.leg_speed();
        close(leg_depth(&r, t_max), r.max_depth(), 1e-12);
        // anchoring_time inverts leg_depth.
        let t1 = anchoring_time(&r, 0.02).unwrap();
        close(leg_depth(&r, t1), 0.02, 1e-12);
    }

    #[test]
    fn sinkage_when_normal_depth_reaches_reach() {
        let r = paper_robot();
        // d_n = d_max = 0.05 at k_n = 1.1445/(4e-4*0.05) = 57225 N/m^3 on level sand.
        close(sinkage_threshold_k_n(&r, Slope::LEVEL), 57_225.0, 1e-9);
        let p = predict(&r, Slope::LEVEL, &Ground::new(57_225.0, 2e6).unwrap());
        assert_eq!(p.regime, Regime::Sinkage);
        assert_eq!(p.level_step, 0.0);
        let p = predict(&r, Slope::LEVEL, &Ground::new(57_300.0, 2e6).unwrap());
        assert_ne!(p.regime, Regime::Sinkage);
    }

    #[test]
    fn no_anchoring_leaves_motion_undefined() {
        let r = paper_robot();
        // d_s > d_max = 0.05 when k_s < F_a/(W d_max^2) = 0.146608/(0.01*0.0025) = 5864.3 on level sand.
        close(anchoring_threshold_k_s(&r, Slope::LEVEL), 5_864.31, 1e-5);
        let p = predict(&r, Slope::LEVEL, &Ground::new(7e5, 5_000.0).unwrap());
        assert_eq!(p.cause, Cause::NoAnchoring);
        assert!(p.anchoring_time.is_none() && p.step.is_none() && p.speed.is_none());
        // k_s = 0: infinite d_s, reported as None rather than inf.
        let p = predict(&r, Slope::LEVEL, &Ground::new(7e5, 0.0).unwrap());
        assert!(p.shear_depth.is_none());
        assert_eq!(p.regime, Regime::Slippage);
    }

    #[test]
    fn repose_forces_slippage() {
        let r = paper_robot();
        let g = Ground::new(7e5, 1e8).unwrap().with_repose(Some(deg(25.0)));
        assert_eq!(predict(&r, deg(24.9), &g).regime, Regime::Success);
        assert_eq!(predict(&r, deg(25.0), &g).cause, Cause::AtOrAboveRepose);
    }

    #[test]
    fn level_speed_bound_is_4r_over_t() {
        // s* <= 2R so v <= 4R/T = 0.16 m/s; attained when d_n + h = R and t1 -> 0.
        let r = paper_robot();
        // d_n = 0.01 at k_n = 1.1445/(4e-4*0.01) = 286125.
        let p = predict(&r, Slope::LEVEL, &Ground::new(286_125.0, 1e15).unwrap());
        close(p.level_step, 0.08, 1e-9);
        close(p.speed.unwrap(), 0.16, 1e-5);
        assert!(p.speed.unwrap() <= 0.16);
    }

    /// The s* choice of docs/model.md §3 at 24 degrees, k_n = 7e5, by hand: level-ground depth
    /// d = 0.35*9.81/(3*7e5*4e-4) = 4.08750e-3 m; at the slope d_n = d cos 24 = 3.73412e-3 m.
    /// s* = 2 sqrt(R^2 - (d + h - R)^2) with R = 0.04, h = 0.03: 2 sqrt(1.6e-3 - (-5.91250e-3)^2)
    /// = 7.91212e-2 m (level) and 2 sqrt(1.6e-3 - (-6.26588e-3)^2) = 7.90124e-2 m (slope).
    #[test]
    fn level_step_rules_by_hand() {
        let slope = deg(24.0);
        let d_n = normal_equilibrium_depth(&paper_robot(), slope, 7e5);
        close(d_n, 4.08750e-3 * 24f64.to_radians().cos(), 1e-5);
        let by_hand = |d: f64| 2.0 * (0.04f64.powi(2) - (d + 0.03 - 0.04).powi(2)).sqrt();
        let slope_rule = level_step_length(&paper_robot(), slope, d_n);
        let level_rule = level_step_length(&paper_robot().with_level_step(LevelStep::Level), slope, d_n);
        close(slope_rule, by_hand(3.73412e-3), 1e-5);
        close(level_rule, by_hand(4.08750e-3), 1e-5);
        close(level_rule, 7.91212e-2, 1e-5);
        close(slope_rule, 7.90124e-2, 1e-5);
        // Level ground: the two rules are one.
        assert_eq!(
            level_step_length(&paper_robot(), Slope::LEVEL, 4.0875e-3),
            level_step_length(&paper_robot().with_level_step(LevelStep::Level), Slope::LEVEL, 4.0875e-3)
        );
    }
}
