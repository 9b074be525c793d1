//! The servo's model, read at the ping (docs/drive.md, "Servo models"): a servo that answers
//! at its ID with a model number the driver does not know (an XM430-W210, model 1030), or
//! another model than the robot file's `[servos] model` names, stops the run before anything
//! moves, naming the servo, the supported models and the fix, with exit code 2 and every
//! servo's torque left off. A supported model other than the paper's (an XL430-W250, model
//! 1060, which has no Current Limit register) is driven, with its own figures.

use std::sync::atomic::AtomicBool;

use sandslope::servo::{GaitSchedule, ServoModel};
use sandslope::{Robot, RobotSpec, Terrain};
use sandslope_servo::driver::DriveReport;
use sandslope_servo::session::default_servos;
use sandslope_servo::{drive, DriveError, DriveSettings, Emulator, EmulatorConfig, Profile};

/// A 0.5 s run on six emulated servos reporting `model_number`, the robot file naming `named`.
fn run(model_number: u16, named: Option<&'static ServoModel>) -> (DriveReport, Option<DriveError>, bool) {
    let robot = Robot::new(RobotSpec::paper_hexapod()).unwrap();
    let servos = default_servos(6);
    let mut cfg =
        EmulatorConfig::new(robot.clone(), Terrain::constant(7e5, 2e6).unwrap(), 10.0, servos.clone());
    cfg.model_number = model_number;
    cfg.simulated_strides = 3;
    let (emulator, port) = Emulator::start(&cfg).unwrap();
    let mut bus = dynamixel2::Bus::new(port).unwrap();
    let schedule = GaitSchedule::new(&robot, 6).unwrap();
    let settings = DriveSettings {
        servos,
        profile: Profile::Position,
        duration_s: 0.5,
        rate_hz: 50.0,
        current_limit_ma: 1470,
        temperature_limit_c: 65,
        watchdog_s: 2.0,
        bus_watchdog_s: 0.5,
        stop_on_risk: None,
        hold_s: 0.0,
        stand_s: 1.0,
        servo: named,
    };
    let stop = AtomicBool::new(false);
    let (report, failure) = drive(&mut bus, &schedule, &settings, None, &stop, &mut |_| Ok(()), &mut |_| {});
    drop(bus);
    let tables = emulator.stop(None);
    (report, failure, tables.torque_enabled.iter().all(|(_, on)| !on))
}

#[test]
fn a_servo_of_an_unsupported_model_is_refused_before_anything_moves() {
    let (report, failure, all_off) = run(1030, None);
    let failure = failure.expect("the run must fail");
    assert!(matches!(failure, DriveError::WrongModel { id: 1, model: 1030, .. }), "{failure}");
    assert_eq!(failure.exit_code(), 2);
    let message = failure.to_string();
    // The supported models by name and number (the four of docs/drive.md's table; a model
    // added to the list keeps this test as it is).
    assert!(
        message.starts_with(
            "servo ID 1 (leg 0) reports model number 1030: not a supported servo (supported: XL330-M288 (1200), "
        ),
        "{message}"
    );
    for model in ["XL330-M077 (1190)", "XL430-W250 (1060)", "XM430-W350 (1020)"] {
        assert!(message.contains(model), "{model}: {message}");
    }
    assert!(message.contains("Fix:"), "{message}");
    assert_eq!(report.cycles, 0, "nothing moved");
    assert!(all_off);
}

#[test]
fn a_servo_of_another_model_than_the_robot_file_names_is_refused() {
    let (report, failure, all_off) = run(1190, Some(&ServoModel::XL330_M288));
    let message = failure.expect("the run must fail").to_string();
    assert!(
        message.contains("reports model number 1190: an XL330-M077, but the robot file's [servos] model names the XL330-M288"),
        "{message}"
    );
    assert!(message.contains("set [servos] model = \"XL330-M077\""), "{message}");
    assert_eq!(report.cycles, 0, "nothing moved");
    assert!(all_off);
}

/// An XL430-W250 bus: the model is read at the ping, the Current Limit (which it lacks, and
/// which its emulated table refuses with an Access Error) is not written, and its Present Load
/// is read as torque: the run completes.
#[test]
fn a_bus_of_xl430s_is_driven_with_their_own_table() {
    let (report, failure, all_off) = run(1060, None);
    assert!(failure.is_none(), "{failure:?}");
    assert_eq!(report.setup.servo, "XL430-W250");
    assert!(report.cycles > 10, "{}", report.cycles);
    assert!(all_off);
}
