//! Issue 54's reproducers, each spawning the binary against the emulator: goals a servo
//! accepts, a log that survives the process, the exit codes of a broken stderr and a hangup,
//! a servo that stops following, the bus's budget, and bad input refused before anything moves.

use std::io::Read;
use std::process::{Child, Command, Stdio};

use super::{bin, cpu_bound, real_time, text, VIRTUAL};

/// The log's `# status = ...` line (the flight recorder's first line).
fn status(log: &std::path::Path) -> String {
    let text = std::fs::read_to_string(log).unwrap();
    let first = text.lines().next().unwrap();
    first.strip_prefix("# status = ").unwrap_or_else(|| panic!("{first}")).trim_end().to_string()
}

/// Waits until the child says the servos are about to move; returns what stderr said.
fn wait_driving(child: &mut Child) -> (std::process::ChildStderr, String) {
    let mut stderr = child.stderr.take().unwrap();
    let mut seen = Vec::new();
    let started = std::time::Instant::now();
    while !String::from_utf8_lossy(&seen).contains("Ctrl-C stops the gait") {
        let mut buf = [0u8; 256];
        let n = stderr.read(&mut buf).unwrap();
        assert!(
            n > 0 && started.elapsed().as_secs() < 120,
            "never drove: {}",
            String::from_utf8_lossy(&seen)
        );
        seen.extend_from_slice(&buf[..n]);
    }
    (stderr, String::from_utf8_lossy(&seen).into_owned())
}

/// 600 s at 1 turn/s: 600 turns, beyond the extended position mode's 256 (+/-1,048,575
/// pulses). By hand, from the worst start a cleared counter allows (6143 pulses, counting up),
/// the room is 1,048,575 - 6143 - 1 = 1,042,431 pulses = 254.50 turns, reached at 0.1 s (half
/// the 0.2 s run-up) + 254.50 s = 254.6 s. The position profile is refused naming it and the
/// velocity profile; the velocity profile's 600 s sends no Goal Velocity beyond the Velocity
/// Limit it writes, 2 omega = 2 x 60 rev/min / 0.229 = 524 units; and a 250 s position run
/// sends no Goal Position beyond 1,048,575.
#[test]
fn no_goal_outside_the_servos_ranges_over_600_s() {
    let out = bin().args(["drive", "--dry-run", "--duration", "600", "--rate", "1"]).output().unwrap();
    let all = text(&out);
    assert_eq!(out.status.code(), Some(2), "{all}");
    assert!(all.contains("lasts 254.6 s"), "{all}");
    assert!(all.contains("--duration 254 or less, or --profile velocity"), "{all}");
    assert!(out.stdout.is_empty(), "nothing printed before the refusal");
    let goals = |extra: &[&str]| -> (String, Vec<i64>) {
        let out = bin().args(["drive", "--dry-run", "--rate", "1"]).args(extra).output().unwrap();
        assert!(out.status.success(), "{}", text(&out));
        let s = String::from_utf8_lossy(&out.stdout).into_owned();
        let v = s
            .lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with("time_s"))
            .map(|l| l.rsplit(',').next().unwrap().parse::<i64>().unwrap())
            .collect();
        (s, v)
    };
    let (head, v) = goals(&["--duration", "600", "--profile", "velocity"]);
    assert!(head.contains("# write Velocity Limit (44) = 524 "), "{head}");
    assert_eq!(v.len(), 601 * 6);
    assert!(v.iter().all(|g| g.abs() <= 524), "a goal velocity beyond 524");
    // At full speed every leg is commanded 262 units (60 / 0.229 = 262.0), in its direction.
    assert!(v[6..].iter().all(|g| g.abs() == 262), "{:?}", &v[..12]);
    let (_, p) = goals(&["--duration", "250"]);
    let top = p.iter().map(|g| g.abs()).max().unwrap();
    // The last goal: (250 - 0.1) turns from the start, 249.9 x 4096 = 1,023,590 pulses plus the
    // start angle's few hundred: within the range.
    assert!(top <= 1_048_575 && top > 1_023_000, "{top}");
}

/// A servo that refuses its goals (the emulator answers them with a Data Range Error, as an
/// XL330 a goal outside its range): exit 3 naming the servo and the register, torque off on
/// every servo, the log kept and marked failed.
#[test]
fn a_refused_goal_stops_the_run_naming_servo_and_register() {
    let (code, all, log, _d) = super::drive_with(&["--duration", "5", "--emulate-fault", "reject:2:2"]);
    assert_eq!(code, Some(3), "{all}");
    assert!(all.contains("servo ID 2 (leg 1) did not take its goal"), "{all}");
    assert!(all.contains("Goal Position (116) = "), "{all}");
    assert!(all.contains("Data Range Error"), "{all}");
    assert!(all.contains("emulator: torque off on every servo"), "{all}");
    assert!(all.contains("torque off confirmed on servos 1, 2, 3, 4, 5, 6"), "{all}");
    assert!(status(&log).starts_with("failed (servo ID 2"), "{}", status(&log));
}

/// The reproducer: the bus stalls 0.7 s at 5 s, longer than the servos' own Bus
/// Watchdog (0.5 s) and shorter than --watchdog (1 s): the servos stop and refuse goals. The
/// run ends as a fault (exit 3), not "completed", naming the watchdog; torque off; log kept.
#[test]
fn a_stall_that_stops_the_servos_is_a_fault_not_completed() {
    let (code, all, log, _d) =
        super::drive_with(&["--duration", "8", "--watchdog", "1", "--emulate-fault", "freeze:5:0.7"]);
    assert_eq!(code, Some(3), "{all}");
    assert!(all.contains("its Bus Watchdog fired"), "{all}");
    assert!(all.contains("emulator: torque off on every servo"), "{all}");
    assert!(status(&log).starts_with("failed"), "{}", status(&log));
    assert!(std::fs::read_to_string(&log).unwrap().ends_with('\n'));
}

/// SIGKILL (the OOM killer): the log is under its own name, marked incomplete, its rows
/// readable up to the last second, and nothing else is left in the folder.
#[test]
fn sigkill_leaves_the_log_readable_to_the_last_second() {
    let _one = real_time();
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("run.csv");
    let mut child = bin()
        .args(["drive", "--emulate", "--duration", "30", "--watchdog", "2", "--log"])
        .arg(&log)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let _stderr = wait_driving(&mut child);
    std::thread::sleep(std::time::Duration::from_secs(3));
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(status(&log).starts_with("incomplete"), "{}", status(&log));
    let read = sandslope_io::servo_log::read_servo_log(&log).unwrap();
    assert!(read.notes.iter().any(|n| n.contains("marked incomplete")), "{:?}", read.notes);
    // Rows up to within a second of the kill: the gait ran about 2 s (3 s less the 1 s stand).
    let last = read.rows.iter().map(|r| r.time_s).fold(f64::MIN, f64::max);
    assert!(last > 1.0, "the last row is at {last} s");
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names, vec![std::ffi::OsString::from("run.csv")], "a temporary file was left");
}

/// stderr piped into a reader that goes away (`2>&1 | head -3`): every later line meets EPIPE.
/// The run goes on to its end, the torque goes off (the JSON report on stdout says so, with
/// the emulator's own tables), the log is kept whole, exit 0 as the run completed.
#[test]
fn a_closed_stderr_skips_neither_torque_off_nor_the_log() {
    let _one = real_time();
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("run.csv");
    let mut child = bin()
        .args(["drive", "--emulate", "--live", "--json", "--duration", "4", "--watchdog", "2", "--log"])
        .arg(&log)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (stderr, _) = wait_driving(&mut child);
    drop(stderr);
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stdout));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["torque_off"]["confirmed"], serde_json::json!([1, 2, 3, 4, 5, 6]));
    assert_eq!(
        v["emulator"].as_str().unwrap().split(" (").next().unwrap(),
        "emulator: torque off on every servo"
    );
    assert_eq!(status(&log), "completed");
    assert!(std::fs::read_to_string(&log).unwrap().ends_with('\n'));
}

/// A hangup with the terminal gone (an SSH drop): SIGHUP, and every write to stderr fails.
/// Torque off, the log kept and marked interrupted, exit 129 as docs/drive.md says.
#[test]
fn a_hangup_with_the_terminal_gone_exits_129_with_the_log_kept() {
    let _one = real_time();
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("run.csv");
    let mut child = bin()
        .args(["drive", "--emulate", "--json", "--duration", "30", "--watchdog", "2", "--log"])
        .arg(&log)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (stderr, _) = wait_driving(&mut child);
    drop(stderr);
    std::thread::sleep(std::time::Duration::from_secs(2));
    assert!(Command::new("kill").args(["-HUP", &child.id().to_string()]).status().unwrap().success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(129));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["torque_off"]["confirmed"], serde_json::json!([1, 2, 3, 4, 5, 6]));
    assert_eq!(status(&log), "interrupted");
    let read = sandslope_io::servo_log::read_servo_log(&log).unwrap();
    assert!(!read.rows.is_empty());
}

/// `--log r.toml --robot r.toml` would replace the robot file with the log: refused, exit 2,
/// the file untouched.
#[test]
fn the_log_may_not_be_one_of_the_runs_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let robot = dir.path().join("r.toml");
    let preset = bin().args(["presets", "show", "paper-hexapod"]).output().unwrap();
    std::fs::write(&robot, &preset.stdout).unwrap();
    let out = bin()
        .current_dir(dir.path())
        .args(["drive", "--emulate", "--duration", "1", "--robot", "r.toml", "--log"])
        .arg(&robot)
        .output()
        .unwrap();
    let all = text(&out);
    assert_eq!(out.status.code(), Some(2), "{all}");
    assert!(all.contains("that is the run's --robot file"), "{all}");
    assert_eq!(std::fs::read(&robot).unwrap(), preset.stdout);
}

/// `--emulate-fault` with a NaN time or an ID the robot does not have injected nothing before:
/// now exit 2 naming the value and the valid range or IDs.
#[test]
fn emulate_fault_refuses_nan_times_and_ids_off_the_bus() {
    for (fault, says) in [
        ("silent:9:1", "servo ID 9 is not on the bus (the robot's servos are IDs 1, 2, 3, 4, 5, 6)"),
        ("corrupt:2:NaN", "the time `NaN` must be a finite number of seconds, at least 0"),
        ("freeze:1:-2", "the time `-2` must be a finite number"),
    ] {
        let out =
            bin().args(["drive", "--emulate", "--duration", "1", "--emulate-fault", fault]).output().unwrap();
        let all = text(&out);
        assert_eq!(out.status.code(), Some(2), "{fault}: {all}");
        assert!(all.contains(says), "{fault}: {all}");
        assert!(!all.contains("driving"), "{fault}: {all}");
    }
}

/// A servo with a hardware error latched before the run (an overload left from the last one):
/// refused at ping, exit 2, nothing moved (the emulator's torque never went on), no log left.
#[test]
fn a_latched_hardware_error_is_refused_at_ping() {
    let (code, all, log, _d) = super::drive_with(&["--emulate-fault", "latched:3"]);
    assert_eq!(code, Some(2), "{all}");
    assert!(
        all.contains("servo ID 3 (leg 2) has a hardware error latched from before the run: an overload"),
        "{all}"
    );
    assert!(all.contains("nothing was moved"), "{all}");
    assert!(all.contains("emulator: torque off on every servo"), "{all}");
    assert!(!log.exists(), "a log of a run that never moved");
}

/// The bus's budget before anything moves: at the default 57,600 baud, 6 servos' cycle is 256
/// bytes (14 + 5 x 6 for the Sync Write, 14 + 6 for the Sync Read, 6 status packets of 32) =
/// 2560 bits = 44.4 ms, plus the 16 ms latency timer assumed for a USB adapter the system does
/// not describe: 60.4 ms, 16.5 Hz, against the 50 asked. Warned with the fix, before the port
/// (absent here) is opened.
#[test]
fn a_rate_the_bus_cannot_carry_is_warned_with_the_fix() {
    let out =
        bin().args(["drive", "--port", "/dev/ttyUSB-sandslope-none", "--duration", "1"]).output().unwrap();
    let all = text(&out);
    assert_eq!(out.status.code(), Some(2), "{all}");
    assert!(all.contains("warning: --rate 50 Hz asks for 20.0 ms cycles, but at 57600 baud"), "{all}");
    assert!(all.contains("takes 60.4 ms (256 bytes"), "{all}");
    assert!(all.contains("about 16.5 Hz at most"), "{all}");
    assert!(all.contains("--baud 1000000") && all.contains("latency_timer"), "{all}");
    // At 1 Mbaud: 2.56 ms + 16 ms = 18.6 ms, 53.8 Hz: no warning.
    let out = bin()
        .args(["drive", "--port", "/dev/ttyUSB-sandslope-none", "--duration", "1", "--baud", "1000000"])
        .output()
        .unwrap();
    assert!(!text(&out).contains("warning"), "{}", text(&out));
}

/// Issue 58: a log whose header says `# slope_deg = NaN` is named as the header's fault, not
/// `--slope` (which was not given); `--slope 89` without `--emulate-k-s` says the terrain has
/// no sand there instead of naming the flag not given.
#[test]
fn messages_name_what_was_given() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("nan.csv");
    let header = "# slope_deg = NaN\n";
    let body = "time_s,id,leg,tripod,present_position,present_velocity,present_current_ma,load_percent,input_voltage_v,temperature_c,hardware_error,goal_position,leg_angle_rad,drive_torque_n_m\n0,1,0,0,0,0,100,6.8,5,30,0,0,0.1,0.035\n";
    std::fs::write(&log, format!("{header}{body}")).unwrap();
    let out = bin().args(["infer", "--servo-log"]).arg(&log).output().unwrap();
    let all = text(&out);
    assert_eq!(out.status.code(), Some(2), "{all}");
    assert!(all.contains("header line `# slope_deg` = NaN must be strictly between -90 and 90"), "{all}");
    assert!(all.contains("give the run's slope with --slope"), "{all}");
    // Without --force the safe slope refuses it first (the sand's repose, 25 deg); with it, the
    // emulator says the terrain has no sand there.
    let out = bin().args(["drive", "--emulate", "--slope", "89", "--duration", "1"]).output().unwrap();
    let all = text(&out);
    assert_eq!(out.status.code(), Some(2), "{all}");
    assert!(all.contains("--slope 89 is beyond the calibrated safe slope"), "{all}");
    let out =
        bin().args(["drive", "--emulate", "--slope", "89", "--force", "--duration", "1"]).output().unwrap();
    let all = text(&out);
    assert_eq!(out.status.code(), Some(2), "{all}");
    assert!(all.contains("--slope 89: the terrain's sand has no shear strength"), "{all}");
    assert!(!all.contains("--emulate-k-s = "), "{all}");
}

/// A silent servo loses only its own row: the servos after it on the bus keep theirs in the
/// cycles before the run stops (dynamixel2 would read each next servo's reply in the silent
/// one's place).
#[test]
fn a_silent_servo_loses_only_its_own_row() {
    let (code, all, log, _d) = super::drive_with(&["--emulate-fault", "silent:3:2.5"]);
    assert_eq!(code, Some(3), "{all}");
    let rows = super::log_rows(&log);
    let last3 = rows.iter().filter(|r| r.1 == 2).map(|r| r.0).fold(f64::MIN, f64::max);
    let after: Vec<usize> = rows.iter().filter(|r| r.0 > last3).map(|r| r.1).collect();
    // Three cycles without servo 3 (leg 2) before the run stops, each with legs 0, 1, 3, 4, 5.
    for leg in [0, 1, 3, 4, 5] {
        assert!(after.iter().filter(|&&l| l == leg).count() >= 2, "leg {leg}: {after:?}");
    }
}

/// `drive --slope 28` on the default terrain (glass beads, angle of repose 25 deg) is beyond
/// the calibrated safe slope: refused, exit 2, naming the limit and --force, nothing moved;
/// with --force (and sand the emulator can walk on) it runs.
#[test]
fn a_slope_beyond_the_safe_limit_needs_force() {
    let out = bin().args(["drive", "--emulate", "--slope", "28", "--duration", "1"]).output().unwrap();
    let all = text(&out);
    assert_eq!(out.status.code(), Some(2), "{all}");
    assert!(all.contains("--slope 28 is beyond the calibrated safe slope"), "{all}");
    assert!(all.contains("the sand's angle of repose, 25.0 deg"), "{all}");
    assert!(all.contains("--force"), "{all}");
    assert!(!all.contains("driving"), "{all}");
    let _cpu = cpu_bound();
    let out = bin()
        .args(["drive", "--emulate", "--slope", "28", "--force", "--emulate-k-s", "2e6", "--duration", "1"])
        .args(["--watchdog", "2"])
        .args(VIRTUAL)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
}

/// On sand of k_s 2.5e5 N/m^3 at 20 deg the calibrated closed form says slippage (k_s margin
/// 0.49), the stride simulator success: `--stop-on-risk 0.5` halts on the closed form's
/// verdict at the first stance estimated, tripod 0's run-up stance (read against the grid
/// walks' own run-ups, docs/drive.md), exit 5; the JSON carries both verdicts. That stance
/// ends at 0.6 s (docs/model.md §19: 0.2 pi turned in the 0.2 s run-up, the remaining 0.8 pi
/// at 2 pi rad/s, 0.4 s): read at the leg's measured angle, which lags its goal by the
/// position loop's 25 ms, and at the next 50 Hz cycle, about 0.64 s; the bound leaves five
/// cycles (0.1 s) for a loaded machine. Within the first stride (tripod 1's first stance ends
/// at 1.1 s).
#[test]
fn stop_on_risk_halts_on_the_more_pessimistic_verdict() {
    let _cpu = cpu_bound();
    let out = bin()
        .args(["drive", "--emulate", "--slope", "20", "--emulate-k-s", "2.5e5", "--duration", "6"])
        .args(VIRTUAL)
        .args(["--stop-on-risk", "0.5", "--hold", "0.2", "--watchdog", "2", "--json"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(5), "{}", text(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["outcome"], "halted");
    let t = v["time_s"].as_f64().unwrap();
    assert!((0.6..0.75).contains(&t), "halted at {t} s");
    assert_eq!(v["live"][0]["tripod"], 0, "{}", v["live"]);
    let p = &v["live"][0]["pooled"];
    let (sim, closed) = (p["p_fail_simulator"].as_f64().unwrap(), p["p_fail_closed_form"].as_f64().unwrap());
    assert!(closed > 0.5 && closed > sim, "{p}");
    assert_eq!(p["p_fail"].as_f64().unwrap(), closed.max(sim));
    // The EEPROM written only where it differs: against the emulator's factory tables (Return
    // Delay Time 250, Operating Mode 3, Temperature Limit 70, Current Limit 1750, Velocity
    // Limit 445, Drive Mode 0) five registers a servo differ and one holds: 30 written, 6 kept.
    assert_eq!(v["setup"]["eeprom_written"], 30, "{}", v["setup"]);
    assert_eq!(v["setup"]["eeprom_kept"], 6, "{}", v["setup"]);
    assert_eq!(v["setup"]["counter_cleared"], true);
    // The prior (the terrain's own k_s at 20 deg, inside its safe slope) did not halt it.
    assert!(v["prior_p_fail"].as_f64().unwrap() < 0.5, "{v}");
}

/// Twenty emulated runs on constant sand (k_s 1.95e6 N/m^3, 20 deg, 6 s, seeds 1-20): the
/// pooled 90% interval at the end covers the truth in at least 16 (nominal 90% less 10 points).
/// On the virtual clock, two runs at a time (on the wall's clock four at once missed stances on
/// two cores; on the virtual one two keep the cores busy).
#[test]
fn the_pooled_interval_covers_the_truth_at_its_rate() {
    let _cpu = cpu_bound();
    let mut covered = 0;
    let mut seen = vec![];
    for batch in (1..=20).collect::<Vec<u32>>().chunks(2) {
        let children: Vec<_> = batch
            .iter()
            .map(|seed| {
                bin()
                    .args([
                        "drive",
                        "--emulate",
                        "--slope",
                        "20",
                        "--emulate-k-s",
                        "1.95e6",
                        "--duration",
                        "6",
                    ])
                    .args(["--live", "--json", "--watchdog", "2", "--emulate-seed", &seed.to_string()])
                    .args(VIRTUAL)
                    .stdout(Stdio::piped())
                    .stderr(Stdio::null())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for c in children {
            let out = c.wait_with_output().unwrap();
            assert!(out.status.success());
            let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
            let p = &v["live"].as_array().unwrap().last().unwrap()["pooled"];
            let (lo, hi) = (p["k_s_lo"].as_f64().unwrap(), p["k_s_hi"].as_f64().unwrap());
            covered += usize::from(lo <= 1.95e6 && 1.95e6 <= hi);
            seen.push((lo, hi));
        }
    }
    assert!(covered >= 16, "{covered} of 20: {seen:?}");
}
