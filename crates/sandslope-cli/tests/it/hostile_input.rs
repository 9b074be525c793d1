//! Hostile input (issue 21): sizes that come from input are decided before anything is
//! allocated, and values no robot on sand has are refused at the edge. Each case failed before
//! its fix: a range of 1e11 slopes or designs aborted the process after minutes and gigabytes,
//! and a speeds table holding -1e308 hung `calibrate --plot` in the plotting library's tick loop.

use crate::common;

use std::time::{Duration, Instant};

use common::{repo_file, sandslope};
use predicates::prelude::*;
use predicates::str::contains;

/// Runs `args`, which must exit 2 within `limit` with `needle` on stderr.
fn refused_fast(args: &[&str], needle: &str, limit: Duration) {
    let start = Instant::now();
    sandslope().args(args).timeout(limit * 10).assert().code(2).stderr(contains(needle));
    assert!(start.elapsed() < limit, "{args:?} took {:?}", start.elapsed());
}

#[test]
fn huge_ranges_are_refused_before_they_are_expanded() {
    let fast = Duration::from_secs(3);
    refused_fast(
        &["risk", "--slope", "0:24:99999999999"],
        "--slope: N `99999999999` must be a whole number from 2 to 65536",
        fast,
    );
    refused_fast(
        &["design", "--vary", "mass_kg=0.3:1:99999999999", "--slope-target", "15"],
        "mass_kg points",
        fast,
    );
    refused_fast(&["simulate", "--slopes", "0:24:99999999999"], "--slopes: N", fast);
    refused_fast(
        &[
            "infer",
            "--observed",
            repo_file("data/paper-speeds.csv").to_str().unwrap(),
            "--law",
            "linear",
            "--predict",
            "0:30:99999999999",
        ],
        "--predict: N",
        fast,
    );
    refused_fast(&["sweep", "--from", "0", "--to", "24", "--step", "1e-9"], "at most 100000 slopes", fast);
    refused_fast(&["phase", "--k-n", "1e4:1e7:99999999", "--k-s", "1e4:1e7:99999999"], "cells", fast);
}

#[test]
fn max_risk_says_the_same_everywhere() {
    // `report` needs its folder (`--out`, which clap requires first) and design its --vary and
    // --slope-target (clap asks for them before any value is read); the bad threshold is refused
    // before the folder is made.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    let out = out.to_str().unwrap();
    let design = ["design", "--vary", "mass_kg=1", "--slope-target", "10"];
    for args in [&["risk"][..], &design, &["report", "--out", out]] {
        sandslope().args(args).args(["--max-risk", "1.5"]).assert().code(2).stderr(
            contains("--max-risk").and(contains("1.5 is not a failure probability strictly between 0 and 1")),
        );
    }
    assert!(!dir.path().join("report").exists());
}

#[test]
fn an_impossible_speed_is_refused_at_once_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    for (row, column) in
        [("0,-1e308,0.01", "speed_m_s"), ("0,0.1,1e-320", "speed_sd_m_s"), ("0,0.1,1e308", "speed_sd_m_s")]
    {
        let speeds = dir.path().join("speeds.csv");
        std::fs::write(&speeds, format!("slope_deg,speed_m_s,speed_sd_m_s\n10,0.1,0.01\n{row}\n")).unwrap();
        let plot = dir.path().join("fit.svg");
        let out = dir.path().join("terrain.toml");
        let needle = format!("speeds.csv: line 3: column {column}");
        refused_fast(
            &[
                "calibrate",
                "--observed",
                speeds.to_str().unwrap(),
                "--plot",
                plot.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ],
            &needle,
            Duration::from_secs(5),
        );
        assert!(!plot.exists() && !out.exists(), "{row} left a file");
    }
}

/// Errors found after reading still name the file they are about.
#[test]
fn errors_after_reading_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let still = dir.path().join("still.csv");
    std::fs::write(&still, "time_s,x_m,y_m,z_m\n0,0,0,0\n0.01,0,0,0\n0.02,0,0,0\n").unwrap();
    sandslope()
        .arg("track")
        .arg(&still)
        .assert()
        .code(2)
        .stderr(contains("still.csv: cannot estimate the upslope direction: the body did not move"));
    let dup = dir.path().join("dup.csv");
    std::fs::write(&dup, "slope_deg,speed_m_s,speed_sd_m_s\n10,0.1,0.01\n10,0.1,0.01\n").unwrap();
    for cmd in [&["infer", "--observed"][..], &["calibrate", "--out", "t.toml", "--observed"][..]] {
        sandslope()
            .current_dir(dir.path())
            .args(cmd)
            .arg(&dup)
            .assert()
            .code(2)
            .stderr(contains("dup.csv: lines 2 and 3 both give slope_deg = 10"));
    }
    assert!(!dir.path().join("t.toml").exists());
}

/// One wrong time in a plain capture (0.2 s, then 655360.2 s) asked for 78 million NaN frames
/// (1.9 GB) before any check; now the row is named at once (found by scripts/fuzz.sh).
#[test]
fn a_capture_whose_time_jumps_by_days_is_refused_before_filling_the_gap() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::from("time_s,x_m,y_m,z_m\n");
    for i in 0..25 {
        text.push_str(&format!("{},{},0.2,0.05\n", f64::from(i) / 120.0, 0.2 + f64::from(i) * 0.001));
    }
    text.push_str("655360.2,0.25,0.2,0.05\n");
    let file = dir.path().join("jump.csv");
    std::fs::write(&file, text).unwrap();
    refused_fast(
        &["track", file.to_str().unwrap()],
        "jump.csv: line 27: time_s = 655360.2 is frame 78643224",
        Duration::from_secs(3),
    );
}

/// The fuzz at 100,000 inputs per command found `predict --json` hanging on a robot file whose
/// `response_time_s` had become `1e-320` (positive and finite, so accepted): the shear load
/// m (g + R omega / dt) overflowed to infinity and the critical-strength search never ended.
/// Now exit 2 at once, naming the file, the key and the valid range.
#[test]
fn a_response_time_that_overflows_the_loads_is_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let robot = dir.path().join("robot.toml");
    let preset = sandslope().args(["presets", "show", "paper-hexapod"]).output().unwrap();
    let text = String::from_utf8(preset.stdout)
        .unwrap()
        .replace("response_time_s = 0.2", "response_time_s = 1e-320");
    assert!(text.contains("response_time_s = 1e-320"));
    std::fs::write(&robot, text).unwrap();
    refused_fast(
        &["predict", "--robot", robot.to_str().unwrap(), "--slope", "15", "--json"],
        "robot.toml: response_time_s = 1e-320 must be large enough that the shear load",
        Duration::from_secs(3),
    );
}
