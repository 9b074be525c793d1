//! Oracle tests of the simulator (docs/model.md §15-§18).

use super::body::{element_force, leg_nodes, Element};
use super::dynamics::Walker;
use super::rft::Rft;
use super::*;
use crate::model::tests::paper_robot;
use crate::model::{normal_equilibrium_depth, G};
use crate::robot::{Robot, RobotSpec};
use crate::terrain::{Ground, Terrain};

fn scenario(k_n: f64, k_s: f64) -> Scenario {
    Scenario::new(paper_robot(), Terrain::constant(k_n, k_s).unwrap(), None, None).unwrap()
}

/// Static oracle: legs locked with flat feet of area A_c (docs/model.md §3's contact), level
/// sand, loaded quasi-statically (gravity ramped in over 8 s): each foot settles at the closed
/// form's `d_n = m g / (n k_n A_c)` within 1%, at every k_n of a sweep over two decades (d_n from 7.2 mm to 0.07 mm; below 4e5 the belly, 1 cm above the feet, touches).
#[test]
fn locked_feet_settle_at_the_closed_form_depth() {
    let robot = paper_robot();
    // A yield slip of 1 um: the closed form has none (with the default 1 mm, a foot that
    // settles only ~1 mm deep has not mobilised its full stress, docs/model.md §16).
    let settings = SimSettings::new(1.0)
        .unwrap()
        .with_shape(LegShape::Foot)
        .with_locked_legs(0.0)
        .with_yield(1e-6)
        .unwrap();
    for k_n in [4e5, 1e6, 3e6, 1e7, 4e7] {
        let ground = Ground::new(k_n, 2e6).unwrap();
        let mut w = Walker::new(&robot, &ground, 0.0, &settings, 1e-3);
        w.settle(10.0);
        w.hold(500);
        // By hand: d_n = 0.35 * 9.81 / (3 * k_n * 4e-4).
        let d_n = 0.35 * G / (3.0 * k_n * 4e-4);
        assert!((d_n - normal_equilibrium_depth(&robot, Slope::LEVEL, k_n)).abs() < 1e-15);
        let depth = w.leg_depth();
        assert!((depth / d_n - 1.0).abs() < 0.01, "k_n = {k_n}: depth {depth} vs d_n {d_n}");
        let (q, v) = w.state();
        assert!(q[2].abs() < 1e-6 && v.iter().all(|x| x.abs() < 1e-4), "{q:?} {v:?}");
    }
}

/// A leg pushed sideways at fixed depth: a spoke held vertical, reaching d below the surface,
/// dragged along +x with its slip saturated, feels `k_s W d^2` against the motion (the
/// resistive-force scaling of docs/model.md §16), whatever the element count.
#[test]
fn spoke_dragged_sideways_feels_k_s_w_d_squared() {
    let robot = paper_robot();
    let rft = Rft::new(7e5, 2e6);
    for (d, elements) in [(0.02, 16), (0.013, 7), (0.05, 64)] {
        let nodes = leg_nodes(&robot, LegShape::Spoke, elements);
        // Angle pi/2 turns the spoke straight down: node (x, 0) goes to (0, -x).
        let hip_z = 2.0 * robot.leg_radius() - d;
        let world: Vec<[f64; 2]> = nodes.iter().map(|p| [0.0, hip_z - p[0]]).collect();
        let mut fx = 0.0;
        for k in 0..elements {
            let el = Element {
                a: world[k],
                b: world[k + 1],
                va: [0.05, 0.0],
                vb: [0.05, 0.0],
                w: robot.leg_width(),
            };
            if let Some(f) = element_force(&rft, &el, [1e-3, 0.0], 1e-3, 1e-3) {
                fx += f.force[0];
            }
        }
        let expected = 2e6 * 0.01 * d * d;
        assert!((fx + expected).abs() < 1e-9 * expected, "d = {d}: {fx} vs {expected}");
    }
}

/// The walk converges as the step halves (first order): on level sand and on a 10 degree
/// slope with the plate force tests' shear strength (data/example-force-tests.toml), the
/// change in speed from 0.5 to 0.25 ms is smaller than from 1 to 0.5 ms, and the speed and
/// deepest leg depth at 0.5 ms are within 3% of those at 0.25 ms.
#[test]
fn converges_when_the_step_halves() {
    for (slope, k_s) in [(0.0, 1e5), (10.0, 7e4)] {
        let s = scenario(7e5, k_s);
        let run = |dt: f64| {
            simulate(&s, slope, &SimSettings::new(4.0).unwrap().with_dt(dt).unwrap()).unwrap().summary
        };
        let (coarse, mid, fine) = (run(1e-3), run(5e-4), run(2.5e-4));
        let (d1, d2) = ((coarse.speed_m_s - mid.speed_m_s).abs(), (mid.speed_m_s - fine.speed_m_s).abs());
        assert!(d2 < d1, "{slope} deg: {} {} {}", coarse.speed_m_s, mid.speed_m_s, fine.speed_m_s);
        assert!((mid.speed_m_s / fine.speed_m_s - 1.0).abs() < 0.03);
        assert!((mid.max_depth_m / fine.max_depth_m - 1.0).abs() < 0.03);
    }
}

/// Bad input names the value and its range; nothing runs.
#[test]
fn bad_input_names_the_value_and_range() {
    let e = SimSettings::new(-1.0).unwrap_err();
    assert_eq!(e.key, "duration_s");
    assert!(e.to_string().contains("greater than 0"), "{e}");
    let s = scenario(7e5, 2e6);
    let short = simulate(&s, 0.0, &SimSettings::new(1.0).unwrap()).unwrap_err().to_string();
    assert!(short.contains("duration_s = 1") && short.contains("1.5 T = 1.5"), "{short}");
    let coarse = SimSettings::new(5.0).unwrap().with_dt(0.05).unwrap();
    let msg = simulate(&s, 0.0, &coarse).unwrap_err().to_string();
    // omega_n = sqrt(3 * 7e5 * 4e-4 / 0.35) = 48.99 rad/s; 0.5 / omega_n = 0.0102 > T/100.
    assert!(
        msg.starts_with("dt_s = 0.05") && msg.contains("49.0 rad/s") && msg.contains("1.000e-2"),
        "{msg}"
    );
    let msg = simulate(&s, 90.0, &SimSettings::new(5.0).unwrap()).unwrap_err().to_string();
    assert!(msg.starts_with("slope_deg = 90"), "{msg}");
    let stiff = scenario(7e9, 2e6);
    let msg = simulate(&stiff, 0.0, &SimSettings::new(5.0).unwrap().with_dt(1e-3).unwrap()).unwrap_err();
    assert!(msg.to_string().contains("omega_n"), "{msg}");
}

/// The summary's closed form is exactly what `predict` computes for the same inputs.
#[test]
fn closed_form_is_predicts_answer() {
    let s = scenario(7e5, 2e6);
    let sim = simulate(&s, 12.0, &SimSettings::new(2.0).unwrap()).unwrap();
    assert_eq!(sim.summary.closed_form, s.evaluate(12.0).unwrap());
    assert_eq!(sim.summary.steps.len(), 4);
    assert_eq!(sim.summary.steps_measured, 2);
    // 2 s at 120 Hz: 241 samples from t = 0.
    assert_eq!(sim.trajectory.time_s.len(), 241);
    assert!((sim.trajectory.time_s[240] - 2.0).abs() < 1e-12);
}

/// A simulated step serialises the gait's step under its own names and values (SimStep lists
/// them by hand to keep `simulate --json`'s order), then the simulation's quantities.
#[test]
fn a_step_serialises_the_gait_step_in_place() {
    let sim = simulate(&scenario(7e5, 2e6), 12.0, &SimSettings::new(2.0).unwrap()).unwrap();
    let step = sim.summary.steps[3];
    let v = serde_json::to_value(step).unwrap();
    let gait = serde_json::to_value(step.step).unwrap();
    for (k, value) in gait.as_object().unwrap() {
        assert_eq!(&v[k], value, "{k}");
    }
    let text = serde_json::to_string(&step).unwrap();
    let order =
        ["index", "tripod", "touchdown_s", "warmup", "t1_s", "slip_m", "step_m", "speed_m_s", "max_depth_m"];
    let at: Vec<usize> = order.iter().map(|k| text.find(&format!("\"{k}\":")).unwrap()).collect();
    assert!(at.windows(2).all(|w| w[0] < w[1]), "{text}");
    assert_eq!(v.as_object().unwrap().len(), 12);
    // The fourth step touches down at 3 T/2 = 1.5 s (T = 1 s for this robot) on tripod 1.
    assert_eq!(
        (v["index"].as_u64(), v["tripod"].as_u64(), v["warmup"].as_bool()),
        (Some(3), Some(1), Some(false))
    );
    assert_eq!(v["touchdown_s"], 1.5);
}

/// A robot file with 10^9 stance legs is refused before 2 x 10^9 legs are made (it asked for
/// 8 GB and aborted; found by scripts/fuzz.sh); 64 per tripod is the cap, and since issue 39
/// the robot itself refuses more (its range of plausibility, docs/model.md §2).
#[test]
fn a_robot_with_a_billion_legs_is_refused_before_allocating() {
    let spec = RobotSpec { stance_legs: 1_000_000_000, ..paper_robot().spec().clone() };
    let e = Robot::new(spec).unwrap_err().to_string();
    assert!(e.contains("stance_legs = 1000000000 must be a whole number from 1 to 128"), "{e}");
}

/// On stiff level sand (k_n = k_s = 1e8 N/m^3, d_n = 0.03 mm) the simulated C-legs roll on
/// their arcs like a rigid wheel's rim and then pivot on their tips, so the step tends to the
/// rigid-ground rolling step, not to the closed form's geometric s* (docs/simulate.md, "On
/// level sand the legs roll"). By hand, per stance of half a turn on rigid ground with the
/// belly h below the hips (R = 0.04 m, h = 0.03 m, phi0 = asin((h - R)/R)):
/// - the arc rolls from touchdown (the C's circle centre at angle -phi0 above the hip's
///   horizontal) until the tip points straight down: the circle's centre moves
///   R (pi/2 - phi0) = 72.94 mm, and the hip, which starts R cos(phi0) = 38.73 mm behind the
///   centre and ends above it, 38.73 mm more;
/// - the leg then pivots on its tip (2R below the hip) until the body's belly lands, hip h
///   above the tip: the hip moves 2R sqrt(1 - (h / 2R)^2) = 74.16 mm;
///
/// In all 185.83 mm, where s* = 2 sqrt(R^2 - (h - R)^2) = 77.46 mm. The stiff contact needs a
/// small yield slip (1e-4 m: 0.1 mm of elastic creep instead of 1 mm per stance).
#[test]
fn stiff_level_sand_steps_the_rigid_rolling_step_not_s_star() {
    let (r, h) = (0.04_f64, 0.03_f64);
    let phi0 = ((h - r) / r).asin();
    let rolling = r * (std::f64::consts::FRAC_PI_2 - phi0) + r * phi0.cos();
    let pivot = 2.0 * r * (1.0 - (h / (2.0 * r)).powi(2)).sqrt();
    let by_hand = rolling + pivot;
    assert!((by_hand - 0.18583).abs() < 1e-5);
    assert!((rigid_rolling_step(&paper_robot()) - by_hand).abs() < 1e-15);
    let s_star = 2.0 * (r * r - (h - r).powi(2)).sqrt();
    let settings = SimSettings::new(2.5).unwrap().with_yield(1e-4).unwrap();
    let m = simulate(&scenario(1e8, 1e8), 0.0, &settings).unwrap().summary;
    assert_eq!(m.steps_measured, 2);
    assert!((m.step_m / by_hand - 1.0).abs() < 0.03, "step {} m vs rolling {by_hand} m", m.step_m);
    assert!(m.step_m > 2.0 * s_star);
}

/// A torque limit far below what the legs need stalls the servos, and the summary says so.
#[test]
fn a_weak_servo_stalls_and_is_named() {
    let weak =
        Robot::new(RobotSpec { servo_torque_limit_n_m: Some(0.01), ..RobotSpec::paper_hexapod() }).unwrap();
    let s = Scenario::new(weak, Terrain::constant(7e5, 2e6).unwrap(), None, None).unwrap();
    let m = simulate(&s, 10.0, &SimSettings::new(3.0).unwrap()).unwrap().summary;
    assert!(!m.stalled_legs.is_empty());
    assert!(m.steps.iter().any(|st| st.stall_s > 0.0));
    let strong = simulate(&scenario(7e5, 2e6), 10.0, &SimSettings::new(3.0).unwrap()).unwrap().summary;
    assert!(strong.stalled_legs.is_empty());
    assert!(m.speed_m_s < strong.speed_m_s);
}

/// Numbers for docs/simulate.md (run with `cargo test -p sandslope --release --lib
/// simulate::tests::table -- --ignored --nocapture`).
#[test]
#[ignore]
fn dt_series() {
    for (slope, k_s) in [(0.0, 1e5), (10.0, 7e4), (10.0, 2e6)] {
        let s = scenario(7e5, k_s);
        for dt in [2e-3, 1e-3, 5e-4, 2.5e-4, 1.25e-4] {
            let m =
                simulate(&s, slope, &SimSettings::new(4.0).unwrap().with_dt(dt).unwrap()).unwrap().summary;
            let sp: Vec<String> = m.steps.iter().map(|s| format!("{:.3}", s.step.speed_m_s)).collect();
            println!(
                "{slope} {k_s} {dt}: v={:.4} t1={:?} d={:.4} {}",
                m.speed_m_s,
                m.t1_s,
                m.max_depth_m,
                sp.join(" ")
            );
        }
    }
}

#[test]
#[ignore]
fn table() {
    let s = Scenario::new(paper_robot(), builtin_terrain(), None, None).unwrap();
    for slope in [0.0, 4.0, 8.0, 10.0, 12.0, 15.0, 16.0, 20.0, 24.0] {
        let m = simulate(&s, slope, &SimSettings::new(10.0).unwrap()).unwrap().summary;
        let p = &m.closed_form.prediction;
        println!(
            "| {slope} | {:.1} / {:.1} | {:.2} / {:.2} | {:.1} / {:.1} | {:.2} / {:.2} | {} / {} | {:.1} |",
            m.t1_s.unwrap_or(f64::NAN) * 1e3,
            p.anchoring_time.unwrap_or(f64::NAN) * 1e3,
            m.slip_m.unwrap_or(f64::NAN) * 1e3,
            p.slip.unwrap_or(f64::NAN) * 1e3,
            m.step_m * 1e3,
            p.step.unwrap_or(f64::NAN) * 1e3,
            m.speed_m_s * 1e2,
            p.speed.unwrap_or(f64::NAN) * 1e2,
            m.regime,
            p.regime,
            m.max_depth_m * 1e3,
        );
    }
}

/// The built-in glass-beads terrain (crates/sandslope-io/presets/glass-beads-300um.toml).
fn builtin_terrain() -> Terrain {
    use crate::terrain::{TerrainPoint, TerrainSpec};
    let pt = |slope_deg, k_s| TerrainPoint { slope_deg, k_n: 7e5, k_s, k_n_sd: None, k_s_sd: None };
    Terrain::new(TerrainSpec {
        name: None,
        repose_deg: Some(25.0),
        points: vec![
            pt(0.0, 3_260_672.8),
            pt(10.0, 2_385_555.1),
            pt(15.0, 1_947_996.3),
            pt(20.0, 1_510_437.4),
            pt(24.0, 1_160_390.4),
        ],
    })
    .unwrap()
}

/// docs/model.md §18's precedence, by hand: repose first, then a pitch-over (whatever the
/// steps measured), then a stalled servo only when the walk failed.
#[test]
fn pitch_over_outranks_every_cause_but_repose() {
    assert_eq!(motion_cause(Cause::AtOrAboveRepose, true, true), MotionCause::AtOrAboveRepose);
    assert_eq!(motion_cause(Cause::RobustStep, true, false), MotionCause::PitchOver);
    assert_eq!(motion_cause(Cause::NormalSinkage, true, true), MotionCause::PitchOver);
    assert_eq!(motion_cause(Cause::NetBackwardStep, false, true), MotionCause::ServoStall);
    assert_eq!(motion_cause(Cause::RobustStep, false, true), MotionCause::RobustStep);
    assert_eq!(motion_cause(Cause::ShortStep, false, false), MotionCause::ShortStep);
}

/// The tumble docs/simulate.md reports: on the built-in robot at 20 degrees with k_s(20) of the
/// built-in terrain (1.51e6 N/m^3), the body rears up about its rear stance leg and passes 90
/// degrees within the first two seconds, where on level sand it stays within 15 degrees. The
/// walk is then a failure with cause pitch_over, not the slippage at -50 cm/s its steps alone
/// would say.
#[test]
fn a_body_that_pitches_past_ninety_degrees_is_reported_as_pitched_over() {
    let settings = SimSettings::new(3.0).unwrap();
    let level = simulate(&scenario(7e5, 3.26e6), 0.0, &settings).unwrap().summary;
    assert!(level.pitch_over_s.is_none() && level.max_pitch_deg < 15.0, "{}", level.max_pitch_deg);
    assert_ne!(level.cause, MotionCause::PitchOver);
    let steep = simulate(&scenario(7e5, 1.51e6), 20.0, &settings).unwrap().summary;
    let t = steep.pitch_over_s.expect("pitched over");
    assert!(t < 2.0 && steep.max_pitch_deg > 90.0, "{t} {}", steep.max_pitch_deg);
    assert_eq!((steep.cause, steep.regime), (MotionCause::PitchOver, Regime::Slippage));
}

/// `BodyPitch::Locked` holds the body parallel to the slope: in the walk that tumbles above
/// (20 degrees, built-in sand) the pitch stays exactly zero at every sample and nothing pitches
/// over, while the free body of the same walk passes 90 degrees.
#[test]
fn a_locked_body_keeps_its_pitch_at_zero_where_the_free_one_tumbles() {
    let free = SimSettings::new(3.0).unwrap();
    let locked = free.with_body_pitch(BodyPitch::Locked);
    let s = scenario(7e5, 1.51e6);
    assert!(simulate(&s, 20.0, &free).unwrap().summary.pitch_over_s.is_some());
    let sim = simulate(&s, 20.0, &locked).unwrap();
    assert!(sim.trajectory.pitch_rad.iter().all(|&p| p == 0.0));
    let m = sim.summary;
    assert_eq!((m.max_pitch_deg, m.pitch_over_s, m.body_pitch), (0.0, None, BodyPitch::Locked));
    assert_ne!(m.cause, MotionCause::PitchOver);
}

/// The rigid rolling step worked out by hand (the test above) assumes a level body; with the
/// pitch locked the simulator walks it on stiff level sand without the pitch's wobble.
#[test]
fn a_locked_body_on_stiff_level_sand_steps_the_rigid_rolling_step() {
    let by_hand = rigid_rolling_step(&paper_robot());
    let settings =
        SimSettings::new(2.5).unwrap().with_yield(1e-4).unwrap().with_body_pitch(BodyPitch::Locked);
    let m = simulate(&scenario(1e8, 1e8), 0.0, &settings).unwrap().summary;
    assert_eq!(m.steps_measured, 2);
    assert!((m.step_m / by_hand - 1.0).abs() < 0.01, "step {} m vs rolling {by_hand} m", m.step_m);
}
