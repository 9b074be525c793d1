//! Goals a servo accepts (issue 54): the driver against the emulator, whose servos refuse a
//! Goal Position outside the extended position mode's +/-1,048,575 pulses as an XL330 does. A
//! servo left 253 turns along by an earlier run (1,036,288 pulses, 12,287 short of the limit:
//! 3 turns at the paper's 1 turn/s) gets its revolution counter cleared in the setup, and a 4 s
//! run sends goals within a few turns of zero; one whose firmware does not know the Clear
//! instruction makes the run refused before the torque goes on, naming the longest run.

use std::sync::atomic::AtomicBool;

use sandslope::servo::GaitSchedule;
use sandslope::{Robot, RobotSpec, Terrain};
use sandslope_servo::clock::ClockKind;
use sandslope_servo::driver::{drive_on_clock, DriveError};
use sandslope_servo::session::default_servos;
use sandslope_servo::{DriveSettings, Emulator, EmulatorConfig, Profile};

fn run(turns: i32, clear: bool, duration_s: f64) -> (Vec<i32>, Option<DriveError>, Vec<(u8, bool)>) {
    let robot = Robot::new(RobotSpec::paper_hexapod()).unwrap();
    let servos = default_servos(6);
    let mut cfg =
        EmulatorConfig::new(robot.clone(), Terrain::constant(7e5, 2e6).unwrap(), 0.0, servos.clone());
    cfg.initial_turns = turns;
    cfg.clear_supported = clear;
    cfg.simulated_strides = 3;
    // On the virtual clock (docs/drive.md, "The emulator's clock"): 5 s of run in its computing.
    cfg.clock = ClockKind::Virtual;
    let (emulator, port) = Emulator::start(&cfg).unwrap();
    let mut bus = dynamixel2::Bus::new(port).unwrap();
    let schedule = GaitSchedule::new(&robot, 6).unwrap();
    let settings = DriveSettings {
        servos,
        profile: Profile::Position,
        duration_s,
        rate_hz: 50.0,
        current_limit_ma: 1470,
        temperature_limit_c: 65,
        watchdog_s: 2.0,
        bus_watchdog_s: 1.0,
        stop_on_risk: None,
        hold_s: 0.0,
        stand_s: 1.0,
        servo: None,
    };
    let mut goals = vec![];
    let stop = AtomicBool::new(false);
    let (_, failure) = drive_on_clock(
        &mut bus,
        &schedule,
        &settings,
        None,
        &stop,
        &mut |s| {
            goals.push(s.goal_position);
            Ok(())
        },
        &mut |_| {},
        &emulator.clock(),
    );
    drop(bus);
    let report = emulator.stop(None);
    (goals, failure, report.torque_enabled)
}

#[test]
fn a_count_left_near_the_limit_is_cleared_before_the_run() {
    let (goals, failure, torque) = run(253, true, 4.0);
    assert!(failure.is_none(), "{failure:?}");
    // 4 s at 1 turn/s from within the first turn: every goal within +/-(6 turns) of zero.
    assert!(!goals.is_empty());
    assert!(goals.iter().all(|g| g.abs() < 6 * 4096), "{:?}", goals.iter().max());
    assert!(torque.iter().all(|(_, on)| !on));
}

#[test]
fn a_count_that_cannot_be_cleared_refuses_a_run_that_would_pass_the_limit() {
    let (goals, failure, torque) = run(253, false, 4.0);
    match failure {
        Some(e @ DriveError::Range { .. }) => {
            assert_eq!(e.exit_code(), 2);
            let text = e.to_string();
            // From about 1,036,288 pulses (plus the start angle's few hundred), 12,287 pulses of
            // room: about 3 turns, reached at 0.1 + 3 = 3.1 s at the most.
            let longest: f64 = text
                .split("the longest run that fits is ")
                .nth(1)
                .unwrap()
                .split(' ')
                .next()
                .unwrap()
                .parse()
                .unwrap();
            assert!(longest > 2.5 && longest < 3.1, "{text}");
            assert!(text.contains("nothing was moved"), "{text}");
        }
        other => panic!("{other:?}"),
    }
    assert!(goals.is_empty(), "no goal was sent");
    assert!(torque.iter().all(|(_, on)| !on));
}
