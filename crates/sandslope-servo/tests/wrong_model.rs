//! Issue 42's "a wrong ID" case that a ping alone does not catch: a servo that answers at its
//! ID but is another model (an XL330-M077, model 1190, whose gearing and torque constant
//! differ from the M288's, ROBOTIS e-Manual) must stop the run before anything moves, naming
//! the servo and the fix, with exit code 2 and every servo's torque left off.

use std::sync::atomic::AtomicBool;

use sandslope::servo::GaitSchedule;
use sandslope::{Robot, RobotSpec, Terrain};
use sandslope_servo::session::default_servos;
use sandslope_servo::{drive, DriveError, DriveSettings, Emulator, EmulatorConfig, Profile};

#[test]
fn a_servo_of_another_model_is_refused_before_anything_moves() {
    let robot = Robot::new(RobotSpec::paper_hexapod()).unwrap();
    let servos = default_servos(6);
    let mut cfg =
        EmulatorConfig::new(robot.clone(), Terrain::constant(7e5, 2e6).unwrap(), 10.0, servos.clone());
    cfg.model_number = 1190;
    cfg.simulated_strides = 3;
    let (emulator, port) = Emulator::start(&cfg).unwrap();
    let mut bus = dynamixel2::Bus::new(port).unwrap();
    let schedule = GaitSchedule::new(&robot, 6).unwrap();
    let settings = DriveSettings {
        servos,
        profile: Profile::Position,
        duration_s: 1.0,
        rate_hz: 50.0,
        current_limit_ma: 1470,
        temperature_limit_c: 65,
        watchdog_s: 2.0,
        bus_watchdog_s: 0.5,
        stop_on_risk: None,
        hold_s: 0.0,
        stand_s: 1.0,
    };
    let stop = AtomicBool::new(false);
    let (report, failure) = drive(&mut bus, &schedule, &settings, None, &stop, &mut |_| Ok(()), &mut |_| {});
    let failure = failure.expect("the run must fail");
    assert!(matches!(failure, DriveError::WrongModel { id: 1, .. }), "{failure}");
    assert_eq!(failure.exit_code(), 2);
    let message = failure.to_string();
    assert!(message.contains("servo ID 1 (leg 0) is model 1190, not an XL330-M288"), "{message}");
    assert!(message.contains("Fix:"), "{message}");
    assert_eq!(report.cycles, 0, "nothing moved");
    drop(bus);
    let tables = emulator.stop(None);
    assert!(tables.torque_enabled.iter().all(|(_, on)| !on), "{:?}", tables.torque_enabled);
}
