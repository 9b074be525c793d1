//! `sandslope track` end to end: recordings generated from a known speed profile
//! (`sandslope::gait::synthetic::StepProfile`: touchdown at rest, backward slip to a known
//! t1, propulsion, lift-off) in every supported format, with noise, occlusions and mm units;
//! the recovered speed, t1 and slip are checked against the profile's closed forms.
//!
//! Tolerances (120 frames/s, 0.3 mm noise per axis, 10 Hz zero-phase low pass):
//! - speed: a difference of positions 0.5 s apart, about 0.85 mm/s of noise per step and
//!   less on the mean of ~20 steps: 1 mm/s.
//! - t1: the touchdown estimate can be late by up to a frame (8.3 ms) because the low pass
//!   rounds the speed's kink at touchdown, and the filtered minimum moves by a few ms toward
//!   the flatter side of an asymmetric minimum; the per-step noise scatter (~12 ms, the
//!   minimum is flat) averages to ~3 ms: 15 ms in all.
//! - slip: integrates a speed of at most V_s over t1, so a timing error dt moves it by about
//!   V_s dt (0.15 m/s x 15 ms = 2.3 mm at most here), checked as 20% of the true slip.

use assert_cmd::Command;
use predicates::str::contains;
use sandslope::gait::synthetic::StepProfile;
use serde_json::Value;

use crate::common;

use common::{motive, plain_mm, trajectory, vicon, write};

fn track(args: &[&str]) -> Value {
    let out =
        Command::cargo_bin("sandslope").unwrap().arg("track").args(args).arg("--json").output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

fn fails(args: &[&str], needle: &str) {
    Command::cargo_bin("sandslope")
        .unwrap()
        .arg("track")
        .args(args)
        .assert()
        .code(2)
        .stderr(contains(needle));
}

fn slope20() -> StepProfile {
    StepProfile::new(0.5, 0.12, 0.40, 0.15, 0.2816).unwrap()
}

fn check(v: &Value, p: &StepProfile) {
    let get = |k: &str| v[k].as_f64().unwrap_or_else(|| panic!("{k} missing in {v}"));
    assert!(
        (get("speed_m_s") - p.mean_speed()).abs() < 1e-3,
        "speed {} vs {}",
        get("speed_m_s"),
        p.mean_speed()
    );
    assert!((get("t1_s") - p.anchoring_time()).abs() < 0.015, "t1 {} vs {}", get("t1_s"), p.anchoring_time());
    assert!((get("slip_m") - p.slip()).abs() < 0.2 * p.slip(), "slip {} vs {}", get("slip_m"), p.slip());
    assert!((get("step_m") - p.step()).abs() < 5e-4);
}

#[test]
fn both_motive_versions_vicon_and_plain_recover_the_profile() {
    let dir = tempfile::tempdir().unwrap();
    let p = slope20();
    let up = [20f64.to_radians().cos(), 0.0, 20f64.to_radians().sin()];
    let rows = trajectory(&p, 10.0, 0.2, up, 3e-4, &[(100, 105), (600, 640)]);
    let m123 = write(dir.path(), "a.csv", &motive(&rows, "1.23", "Meters", 1.0));
    let m125 = write(dir.path(), "b.csv", &motive(&rows, "1.25", "Millimeters", 1000.0));
    let vic = write(dir.path(), "c.csv", &vicon(&rows));
    let pl = write(dir.path(), "d.csv", &plain_mm(&rows));
    for (f, body) in [(&m123, "robot"), (&m125, "robot"), (&vic, "CoM"), (&pl, "x")] {
        let v = track(&[f.to_str().unwrap(), "--body", body]);
        check(&v, &p);
        // The 40-frame occlusion splits the recording, the 5-frame one is interpolated.
        assert_eq!(v["segments"], 2, "{f:?}");
        assert_eq!(v["dropped_frames"], 40);
        assert_eq!(v["interpolated_frames"], 5);
        assert_eq!(v["period_s"], 1.0);
        let u = &v["upslope"];
        assert!(
            (u[0].as_f64().unwrap() - up[0]).abs() < 5e-3 && (u[2].as_f64().unwrap() - up[2]).abs() < 5e-3
        );
        let offset = v["recordings"][0]["touchdown_offset_s"].as_f64().unwrap();
        assert!((offset - 0.2).abs() < 1.0 / 120.0, "offset {offset}");
        assert_eq!(v["per_step"].as_array().unwrap().len(), v["steps"].as_u64().unwrap() as usize);
    }
    // The Motive 1.25 file says its capture rate was 240: the export rate (120) is used.
    let v = track(&[m125.to_str().unwrap(), "--body", "robot"]);
    assert_eq!(v["recordings"][0]["frame_rate_hz"], 120.0);
    // Pooled by glob: twice the steps.
    let one = track(&[m123.to_str().unwrap(), "--body", "robot"])["steps"].as_u64().unwrap();
    let glob = dir.path().join("[ab].csv");
    let both = track(&[glob.to_str().unwrap(), "--body", "robot"]);
    assert_eq!(both["steps"].as_u64().unwrap(), 2 * one);
}

#[test]
fn touchdown_file_and_explicit_upslope() {
    let dir = tempfile::tempdir().unwrap();
    let p = slope20();
    let rows = trajectory(&p, 8.0, 0.35, [0.0, 0.0, -1.0], 3e-4, &[]);
    let f = write(dir.path(), "r.csv", &vicon(&rows));
    let times: String = (0..16).map(|k| format!("{}\n", 0.35 + 0.5 * k as f64)).collect();
    let td = write(dir.path(), "td.txt", &format!("# controller log\n{times}"));
    let v = track(&[f.to_str().unwrap(), "--touchdowns", td.to_str().unwrap(), "--upslope", "-z"]);
    assert_eq!(v["upslope_estimated"], false);
    assert_eq!(v["recordings"][0]["touchdowns"], "given");
    // With the true touchdowns only the noise and the filter's rounding of the minimum
    // remain: t1 within 6 ms, slip within 10%.
    assert!((v["t1_s"].as_f64().unwrap() - 0.12).abs() < 0.006);
    assert!((v["slip_m"].as_f64().unwrap() - p.slip()).abs() < 0.1 * p.slip());
    // Pointing the wrong way makes the robot go downhill.
    let w = track(&[f.to_str().unwrap(), "--upslope", "0,0,1"]);
    assert!((w["speed_m_s"].as_f64().unwrap() + p.mean_speed()).abs() < 1e-3);
}

#[test]
fn level_sand_and_leg_speed() {
    let dir = tempfile::tempdir().unwrap();
    // omega = 4 pi: T = 0.5 s, steps of 0.25 s.
    let p = StepProfile::new(0.25, 0.0, 0.17, 0.0, 0.3).unwrap();
    let rows = trajectory(&p, 6.0, 0.1, [1.0, 0.0, 0.0], 2e-4, &[]);
    let f = write(dir.path(), "l.csv", &plain_mm(&rows));
    let v = track(&[f.to_str().unwrap(), "--leg-speed", &format!("{}", 4.0 * std::f64::consts::PI)]);
    assert!((v["period_s"].as_f64().unwrap() - 0.5).abs() < 1e-12);
    assert!((v["speed_m_s"].as_f64().unwrap() - p.mean_speed()).abs() < 1e-3);
    // No slip: t1 within a couple of frames of touchdown, slip essentially zero.
    assert!(v["t1_s"].as_f64().unwrap() < 0.02);
    assert!(v["slip_m"].as_f64().unwrap() < 2e-4);
}

#[test]
fn speeds_out_appends_calibrate_rows_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    let p = slope20();
    let rows = trajectory(&p, 6.0, 0.0, [1.0, 0.0, 0.0], 3e-4, &[]);
    let f = write(dir.path(), "r.csv", &plain_mm(&rows));
    let speeds = dir.path().join("speeds.csv");
    let png = dir.path().join("fig.png");
    let (fs, ss, ps) = (f.to_str().unwrap(), speeds.to_str().unwrap(), png.to_str().unwrap());
    track(&[fs, "--slope", "20", "--speeds-out", ss]);
    track(&[fs, "--slope", "10", "--speeds-out", ss, "--plot", ps]);
    let text = std::fs::read_to_string(&speeds).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "slope_deg,speed_m_s,speed_sd_m_s");
    assert_eq!(lines.len(), 3);
    let cols: Vec<f64> = lines[1].split(',').map(|c| c.parse().unwrap()).collect();
    assert_eq!(cols[0], 20.0);
    assert!((cols[1] - p.mean_speed()).abs() < 1e-3 && cols[2] > 0.0);
    assert!(std::fs::metadata(&png).unwrap().len() > 10_000);
    fails(&[fs, "--speeds-out", ss], "--speeds-out needs --slope");
    let bad = write(dir.path(), "bad-speeds.csv", "slope,speed\n1,2\n");
    fails(
        &[fs, "--slope", "5", "--speeds-out", bad.to_str().unwrap()],
        "bad-speeds.csv: line 1: the header is `slope,speed`",
    );
    assert_eq!(std::fs::read_to_string(&bad).unwrap(), "slope,speed\n1,2\n");
}

#[test]
fn malformed_files_are_named_with_their_line() {
    let dir = tempfile::tempdir().unwrap();
    let rows = trajectory(&slope20(), 3.0, 0.0, [1.0, 0.0, 0.0], 0.0, &[]);
    let good = motive(&rows, "1.25", "Meters", 1.0);
    let head: String = good.lines().take(5).map(|l| format!("{l}\n")).collect();
    let f = write(dir.path(), "trunc.csv", &head);
    fails(&[f.to_str().unwrap()], "trunc.csv: line 5: truncated header");
    let f = write(dir.path(), "m.csv", &good);
    fails(&[f.to_str().unwrap(), "--body", "nobody"], "no body named `nobody`");
    // Rigid bodies are preferred to markers; with two rigid bodies one must be chosen.
    track(&[f.to_str().unwrap()]);
    let f = write(
        dir.path(),
        "two.csv",
        &good.replace("Marker,Marker,Marker", "Rigid Body,Rigid Body,Rigid Body"),
    );
    fails(&[f.to_str().unwrap()], "choose one with --body");
    let no_pos = good.replace("Position", "Rotation");
    let f = write(dir.path(), "nopos.csv", &no_pos);
    fails(&[f.to_str().unwrap()], "nopos.csv: line 8: no position columns");
    let mut lines: Vec<String> = good.lines().map(String::from).collect();
    lines[20] = lines[20].replacen(",0,0,0,1,", ",0,0,0,1,abc", 1);
    let f = write(dir.path(), "nan.csv", &(lines.join("\n") + "\n"));
    fails(&[f.to_str().unwrap(), "--body", "robot"], "nan.csv: line 21: column 7 (`robot` X): `abc0");
    let zero = good.replace("Export Frame Rate,120.000000", "Export Frame Rate,0");
    let f = write(dir.path(), "zero.csv", &zero);
    fails(&[f.to_str().unwrap(), "--body", "robot"], "zero.csv: line 1: `export frame rate` = `0`");
    let f = write(dir.path(), "vzero.csv", &vicon(&rows).replacen("120", "0", 1));
    fails(&[f.to_str().unwrap()], "vzero.csv: line 2: frame rate `0`");
    let f = write(dir.path(), "plain.csv", "time_s,a,b\n0,1,2\n");
    fails(&[f.to_str().unwrap()], "plain.csv: line 1: no position columns");
    let f = write(dir.path(), "what.csv", "hello,world\n");
    fails(&[f.to_str().unwrap()], "what.csv: line 1: unrecognised format");
    fails(&["does-not-exist-*.csv"], "no such file");
    fails(&[f.to_str().unwrap(), "--upslope", "0,0,0"], "--upslope");
    let f = write(dir.path(), "m2.csv", &good);
    fails(&[f.to_str().unwrap(), "--body", "robot", "--cutoff", "100"], "--cutoff = 100 must be");
}

#[test]
fn vicon_subject_or_segment_selects_the_body() {
    // Vicon names columns `subject:segment`: `robot`, `CoM` and `robot:CoM` all select it.
    let dir = tempfile::tempdir().unwrap();
    let two =
        "Trajectories\n120\n,,robot:CoM,,,box:Top,,\nFrame,Sub Frame,X,Y,Z,X,Y,Z\n,,mm,mm,mm,mm,mm,mm\n";
    let mut text = String::from(two);
    for i in 0..600 {
        // The robot moves upslope at 0.1 m/s; the box stays put.
        text.push_str(&format!("{},0,{:.3},0,0,5,5,5\n", i + 1, 100.0 * f64::from(i) / 120.0));
    }
    let f = write(dir.path(), "two.csv", &text);
    let f = f.to_str().unwrap();
    for body in ["robot", "CoM", "robot:CoM"] {
        let v = track(&[f, "--body", body, "--upslope", "+x"]);
        assert!((v["speed_m_s"].as_f64().unwrap() - 0.1).abs() < 1e-3, "{body}: {v}");
    }
    fails(&[f, "--body", "wheel"], "no body named `wheel`");
}

#[test]
fn the_table_rounds_frame_rates_and_json_keeps_them() {
    // Motive writes the export rate of a 120 Hz take as 119.99999666435033.
    let dir = tempfile::tempdir().unwrap();
    let p = slope20();
    let rows = trajectory(&p, 6.0, 0.2, [1.0, 0.0, 0.0], 3e-4, &[]);
    let text = motive(&rows, "1.23", "Meters", 1.0)
        .replace("Export Frame Rate,120.000000", "Export Frame Rate,119.99999666435033");
    let f = write(dir.path(), "m.csv", &text);
    let v = track(&[f.to_str().unwrap(), "--body", "robot"]);
    let hz = v["recordings"][0]["frame_rate_hz"].as_f64().unwrap();
    assert!((hz - 119.999_996_664_350_33).abs() < 1e-9 && hz != 120.0, "{hz}");
    let out = Command::cargo_bin("sandslope")
        .unwrap()
        .args(["track", f.to_str().unwrap(), "--body", "robot"])
        .output()
        .unwrap();
    let table = String::from_utf8(out.stdout).unwrap();
    // Piped: no progress bar or anything else on stderr.
    assert!(out.stderr.is_empty(), "{}", String::from_utf8_lossy(&out.stderr));
    let row = table.lines().find(|l| l.contains("m.csv")).unwrap();
    let cells: Vec<&str> = row.split_whitespace().collect();
    assert!(cells.contains(&"120"), "{row}");
    assert!(!table.contains("119.99"), "{table}");
    // The stride "phase" is called what it is: the touchdown offset.
    assert!(table.contains("touchdown offset") && !table.contains("phase"), "{table}");
}

#[test]
fn a_closed_stdout_ends_track_quietly() {
    // Ten copies of a 40 s recording: about 800 steps, far more JSON and CSV than a pipe holds.
    use std::io::Read;
    use std::process::Stdio;
    let dir = tempfile::tempdir().unwrap();
    let rows = trajectory(&slope20(), 40.0, 0.2, [1.0, 0.0, 0.0], 3e-4, &[]);
    let text = plain_mm(&rows);
    let files: Vec<String> = (0..10)
        .map(|i| write(dir.path(), &format!("r{i}.csv"), &text).to_str().unwrap().to_string())
        .collect();
    for format in ["--json", "--csv"] {
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_sandslope"))
            .arg("track")
            .args(&files)
            .arg(format)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut first = [0u8; 16];
        child.stdout.as_mut().unwrap().read_exact(&mut first).unwrap();
        drop(child.stdout.take());
        let status = child.wait().unwrap();
        let mut err = String::new();
        child.stderr.take().unwrap().read_to_string(&mut err).unwrap();
        assert_eq!(status.code(), Some(0), "{format}: {err}");
        assert!(!err.contains("error") && !err.contains("panicked"), "{format}: {err}");
    }
}
