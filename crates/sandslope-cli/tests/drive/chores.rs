//! The bench's chores (docs/drive.md, "On the bench"): the emulator served alone on a
//! pseudo-terminal (`drive --emulate --pty`), and `drive --zero` reading each servo's Present
//! Position over that pty, as it would over a U2D2, into the robot file's zero offsets.

use std::io::{BufRead, BufReader};
use std::process::Stdio;

use super::bin;

/// The emulated shafts sit at these pulses with every leg at angle 0 (the "true" offsets).
const TRUE_OFFSETS: [i32; 6] = [1234, -2048, 4095, 0, 77, 3000];

#[test]
fn zero_reads_the_offsets_over_the_emulators_pty_into_the_robot_file() {
    let dir = tempfile::tempdir().unwrap();
    let preset = bin().args(["presets", "show", "paper-hexapod"]).output().unwrap();
    let preset = String::from_utf8(preset.stdout).unwrap();
    let truth = dir.path().join("truth.toml");
    std::fs::write(
        &truth,
        format!("{preset}\n[servos]\nids = [1, 2, 3, 4, 5, 6]\nzero_offsets = {TRUE_OFFSETS:?}\n"),
    )
    .unwrap();
    let mut emulator = bin()
        .args(["drive", "--emulate", "--pty", "60", "--robot", truth.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(emulator.stdout.take().unwrap()).read_line(&mut line).unwrap();
    let pty = line.trim().to_string();
    assert!(pty.starts_with("/dev/"), "{pty:?}");

    // The robot file being zeroed: its own comments and keys, offsets still at 0.
    let robot = dir.path().join("robot.toml");
    let before = format!(
        "{preset}\n[servos]\n# left side, then right (mirrored)\nids = [1, 2, 3, 4, 5, 6]\ndirections = [1, 1, 1, -1, -1, -1]\nzero_offsets = [0, 0, 0, 0, 0, 0]\nbaud_rate = 1000000\n"
    );
    std::fs::write(&robot, &before).unwrap();
    let out =
        bin().args(["drive", "--zero", "--port", &pty, "--robot", robot.to_str().unwrap()]).output().unwrap();
    let said = super::text(&out);
    assert_eq!(out.status.code(), Some(0), "{said}");
    assert!(said.contains("zero offsets of the XL330-M288 servos IDs 1, 2, 3, 4, 5, 6: [1234, -2048, 4095, 0, 77, 3000] pulses"), "{said}");
    let after = std::fs::read_to_string(&robot).unwrap();
    assert_eq!(
        after,
        before
            .replace("zero_offsets = [0, 0, 0, 0, 0, 0]", "zero_offsets = [1234, -2048, 4095, 0, 77, 3000]")
    );
    // The zeroed file drives: every leg's first goal moves by its offset from the same file
    // with offsets 0 (the dry run's rows at t = 0).
    let first_goals = |text: &str| -> Vec<i64> {
        let file = dir.path().join("dry.toml");
        std::fs::write(&file, text).unwrap();
        let dry = bin()
            .args(["drive", "--dry-run", "--duration", "0", "--robot", file.to_str().unwrap()])
            .output()
            .unwrap();
        String::from_utf8_lossy(&dry.stdout)
            .lines()
            .filter(|l| l.starts_with("0.0000,"))
            .map(|l| l.rsplit(',').next().unwrap().parse().unwrap())
            .collect()
    };
    let (zeroed, unzeroed) = (first_goals(&after), first_goals(&before));
    assert_eq!(zeroed.len(), 6);
    let moved: Vec<i64> = zeroed.iter().zip(&unzeroed).map(|(a, b)| a - b).collect();
    assert_eq!(moved, TRUE_OFFSETS.iter().map(|&o| i64::from(o)).collect::<Vec<_>>());

    // A preset is not a file to write into: refused, nothing read.
    let preset_zero =
        bin().args(["drive", "--zero", "--port", &pty, "--robot", "paper-hexapod"]).output().unwrap();
    assert_eq!(preset_zero.status.code(), Some(2), "{}", super::text(&preset_zero));
    assert!(super::text(&preset_zero).contains("is not a file"));

    // The standalone emulator ends on SIGTERM with 143 and its servos' account.
    Command::new("kill").args(["-TERM", &emulator.id().to_string()]).status().unwrap();
    let end = emulator.wait_with_output().unwrap();
    assert_eq!(end.status.code(), Some(143));
    assert!(String::from_utf8_lossy(&end.stderr).contains("emulator: torque off on every servo"));
}

use std::process::Command;
