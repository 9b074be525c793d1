//! End-to-end tests of the foundation commands: predict, sweep, calibrate, presets.

use crate::common;
use common::{json_of as json, repo_file, sandslope};

use predicates::prelude::*;
use std::path::Path;

const PREDICT_KEYS: [&str; 18] = [
    "slope_deg",
    "k_n",
    "k_s",
    "regime",
    "cause",
    "d_n_m",
    "level_step_m",
    "d_s_m",
    "t1_s",
    "slip_m",
    "propulsion_m",
    "step_m",
    "speed_m_s",
    "model_speed_m_s",
    "k_s_margin",
    "critical_k_s_progress",
    "critical_k_s_robust",
    "extrapolated",
];

fn keys(v: &serde_json::Value) -> Vec<String> {
    let mut k: Vec<String> = v.as_object().unwrap().keys().cloned().collect();
    k.sort();
    k
}

fn sorted(keys: &[&str]) -> Vec<String> {
    let mut k: Vec<String> = keys.iter().map(|s| s.to_string()).collect();
    k.sort();
    k
}

#[test]
fn predict_json_has_exactly_the_documented_keys_with_defaults() {
    let v = json(sandslope().args(["predict", "--slope", "20", "--json"]));
    assert_eq!(keys(&v), sorted(&PREDICT_KEYS));
    assert_eq!(v["slope_deg"], 20.0);
    assert!(["success", "metastable", "slippage", "sinkage"].contains(&v["regime"].as_str().unwrap()));
}

#[test]
fn predict_with_overrides_matches_hand_worked_values() {
    // 20 deg, k_n = 7e5, k_s = 1e6, paper robot: worked by hand in the library's model tests:
    // d_s = 7.33519 mm, t1 = 29.6045 ms, s = 21.7682 mm, v = 4.35363 cm/s, metastable.
    let v = json(sandslope().args(["predict", "--slope", "20", "--k-n", "7e5", "--k-s", "1e6", "--json"]));
    let close = |key: &str, want: f64| {
        let got = v[key].as_f64().unwrap();
        assert!((got - want).abs() < 1e-5 * want, "{key}: {got} vs {want}");
    };
    close("d_s_m", 7.335_19e-3);
    close("t1_s", 0.029_604_5);
    close("step_m", 0.021_768_2);
    close("speed_m_s", 0.043_536_3);
    assert_eq!(v["regime"], "metastable");
}

#[test]
fn predict_reports_null_where_the_model_is_undefined() {
    // k_s below the anchoring threshold F_a/(W d_max^2) (~5.9e3 on level sand): no anchoring.
    let v = json(sandslope().args(["predict", "--slope", "0", "--k-s", "1000", "--json"]));
    for key in ["t1_s", "slip_m", "propulsion_m", "step_m", "speed_m_s"] {
        assert!(v[key].is_null(), "{key} should be null: {v}");
    }
    assert_eq!(v["regime"], "slippage");
    // Above the angle of repose (25 deg for the default terrain) no k_s is enough: margin is null.
    let v = json(sandslope().args(["predict", "--slope", "26", "--json"]));
    assert!(v["k_s_margin"].is_null());
    assert_eq!(v["regime"], "slippage");
}

#[test]
fn above_repose_the_cause_is_shown_and_the_ruled_out_speed_is_not_presented_as_one() {
    // The default terrain's repose is 25 deg; at 26 deg the stance model still gives its
    // positive speed (2.29 cm/s), which the regime rules out: the surface itself yields.
    let v = json(sandslope().args(["predict", "--slope", "26", "--json"]));
    assert_eq!((v["regime"].as_str(), v["cause"].as_str()), (Some("slippage"), Some("at_or_above_repose")));
    assert!(v["speed_m_s"].is_null());
    let model = v["model_speed_m_s"].as_f64().unwrap();
    // v = s / (T/2) with T/2 = 0.5 s for the paper robot.
    assert!((model - v["step_m"].as_f64().unwrap() / 0.5).abs() < 1e-12 && model > 0.0);
    // The table shows it in parentheses with the reason and the spec section.
    let out = sandslope().args(["predict", "--slope", "26"]).assert().success().get_output().stdout.clone();
    let text = String::from_utf8(out).unwrap();
    let speed_row = text.lines().find(|l| l.contains("speed v")).unwrap();
    assert!(speed_row.contains(&format!("({:.2})", model * 100.0)), "{speed_row}");
    assert!(
        text.contains("at_or_above_repose")
            && text.contains("rules out")
            && text.contains("docs/model.md §6")
    );
    // Below repose nothing is in parentheses and the speed is the model's.
    let v = json(sandslope().args(["predict", "--slope", "20", "--json"]));
    assert_eq!(v["speed_m_s"], v["model_speed_m_s"]);
    assert_eq!(v["cause"], "short_step");
    let text = sandslope().args(["predict", "--slope", "20"]).output().unwrap().stdout;
    assert!(!String::from_utf8(text).unwrap().contains("parentheses"));
}

#[test]
fn sweep_has_a_cause_column_in_table_csv_and_json() {
    let args = ["sweep", "--from", "23", "--to", "26", "--step", "1"];
    let v = json(sandslope().args(args).arg("--json"));
    let causes: Vec<&str> = v.as_array().unwrap().iter().map(|r| r["cause"].as_str().unwrap()).collect();
    assert_eq!(causes, ["short_step", "short_step", "at_or_above_repose", "at_or_above_repose"]);
    let speeds: Vec<bool> = v.as_array().unwrap().iter().map(|r| r["speed_m_s"].is_null()).collect();
    assert_eq!(speeds, [false, false, true, true]);
    let csv = sandslope().args(args).arg("--csv").output().unwrap().stdout;
    let csv = String::from_utf8(csv).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "cause").unwrap();
    let speed = header.iter().position(|h| *h == "speed_m_s").unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.iter().map(|r| r[col]).collect::<Vec<_>>(), causes);
    // CSV leaves a ruled-out speed empty.
    assert_eq!(rows[2][speed], "");
    let table = String::from_utf8(sandslope().args(args).output().unwrap().stdout).unwrap();
    assert!(table.lines().next().is_some_and(|l| !l.is_empty()));
    assert!(
        // 25 deg on the built-in terrain, worked independently from docs/model.md §3-§5 with k_s
        // extrapolated from the 20 and 24 deg points: 1.4848 cm/s, shown in parentheses.
        table.contains("cause") && table.contains("at_or_above_repose") && table.contains("(1.48)"),
        "{table}"
    );
    assert!(table.contains("speed in parentheses"));
}

#[test]
fn predict_mass_override_changes_the_load() {
    let light = json(sandslope().args(["predict", "--slope", "10", "--json"]));
    let heavy = json(sandslope().args(["predict", "--slope", "10", "--mass", "1.0", "--json"]));
    // d_n is proportional to the mass: 1.0 / 0.35.
    let ratio = heavy["d_n_m"].as_f64().unwrap() / light["d_n_m"].as_f64().unwrap();
    assert!((ratio - 1.0 / 0.35).abs() < 1e-9);
}

#[test]
fn predict_table_and_csv() {
    sandslope()
        .args(["predict", "--slope", "15"])
        .assert()
        .success()
        .stdout(predicate::str::contains("anchoring time t1").and(predicate::str::contains("regime")));
    sandslope()
        .args(["predict", "--slope", "15", "--csv"])
        .assert()
        .success()
        .stdout(predicate::str::starts_with(PREDICT_KEYS.join(",")));
}

#[test]
fn extrapolation_warns_on_stderr() {
    sandslope()
        .args(["predict", "--slope", "24.5", "--json"])
        .assert()
        .success()
        .stderr(predicate::str::contains("extrapolated"));
}

#[test]
fn sweep_json_rows_and_plots() {
    let v = json(sandslope().args(["sweep", "--from", "0", "--to", "24", "--step", "6", "--json"]));
    let rows = v.as_array().unwrap();
    let slopes: Vec<f64> = rows.iter().map(|r| r["slope_deg"].as_f64().unwrap()).collect();
    assert_eq!(slopes, vec![0.0, 6.0, 12.0, 18.0, 24.0]);
    assert!(rows.iter().all(|r| keys(r) == sorted(&PREDICT_KEYS)));
    // Speed falls with slope on this terrain (k_s decreases and the slip term grows).
    let speeds: Vec<f64> = rows.iter().map(|r| r["speed_m_s"].as_f64().unwrap()).collect();
    assert!(speeds.windows(2).all(|w| w[1] < w[0]), "{speeds:?}");

    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("sweep.png");
    let svg = dir.path().join("sweep.svg");
    let observed = repo_file("data/paper-speeds.csv");
    for out in [&png, &svg] {
        sandslope()
            .args(["sweep", "--to", "25", "--step", "0.5", "--plot"])
            .arg(out)
            .arg("--observed")
            .arg(&observed)
            .assert()
            .success();
    }
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
}

#[test]
fn calibrate_reproduces_the_builtin_terrain() {
    // The preset was written by exactly this command (see docs/calibration.md).
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("gb.toml");
    sandslope()
        .args(["calibrate", "--observed"])
        .arg(repo_file("data/paper-speeds.csv"))
        .arg("--forces")
        .arg(repo_file("data/example-force-tests.toml"))
        .args(["--free", "plate_scale,error_floor", "--name", "glass-beads-300um", "--out"])
        .arg(&out)
        .assert()
        .success()
        .stdout(predicate::str::contains("k_s(20)/k_s(0)"));
    let fresh: toml::Value = toml::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let preset: toml::Value =
        toml::from_str(include_str!("../../../sandslope-io/presets/glass-beads-300um.toml")).unwrap();
    assert_eq!(fresh["name"], preset["name"]);
    assert_eq!(fresh["repose_deg"], preset["repose_deg"]);
    let (a, b) = (fresh["points"].as_array().unwrap(), preset["points"].as_array().unwrap());
    assert_eq!(a.len(), b.len());
    for (p, q) in a.iter().zip(b) {
        for key in ["slope_deg", "k_n", "k_s", "k_n_sd", "k_s_sd"] {
            let (x, y) = (p[key].as_float().unwrap(), q[key].as_float().unwrap());
            assert!((x - y).abs() <= 1e-6 * y.abs(), "{key}: {x} vs {y}");
        }
    }
}

#[test]
fn calibrate_per_slope_reproduces_each_speed_and_json() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ps.toml");
    let v = json(
        sandslope()
            .args(["calibrate", "--law", "per-slope", "--json", "--observed"])
            .arg(repo_file("data/paper-speeds.csv"))
            .arg("--out")
            .arg(&out),
    );
    for r in v["residuals"].as_array().unwrap() {
        assert!(r["residual_m_s"].as_f64().unwrap().abs() < 1e-9, "{r}");
    }
    // The written terrain loads, and predicts the observed speed at an observed slope (10 deg: 0.110 m/s).
    let p = json(sandslope().args(["predict", "--slope", "10", "--json", "--terrain"]).arg(&out));
    assert!((p["speed_m_s"].as_f64().unwrap() - 0.110).abs() < 1e-9);
}

#[test]
fn calibrate_says_when_a_speed_is_beyond_the_model_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let speeds = dir.path().join("fast.csv");
    // 0.20 m/s exceeds the level-sand bound s*/(T/2) = 0.158 m/s of the paper robot.
    std::fs::write(&speeds, "slope_deg,speed_m_s,speed_sd_m_s\n0,0.20,0.01\n10,0.11,0.01\n").unwrap();
    let out = dir.path().join("never.toml");
    sandslope()
        .args(["calibrate", "--law", "per-slope", "--observed"])
        .arg(&speeds)
        .arg("--out")
        .arg(&out)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("outside what the model can reach"));
    assert!(!out.exists());
}

#[test]
fn presets_list_and_show() {
    sandslope()
        .arg("presets")
        .assert()
        .success()
        .stdout(predicate::str::contains("paper-hexapod").and(predicate::str::contains("glass-beads-300um")));
    let out =
        sandslope().args(["presets", "show", "paper-hexapod"]).assert().success().get_output().stdout.clone();
    let v: toml::Value = toml::from_str(std::str::from_utf8(&out).unwrap()).unwrap();
    assert_eq!(v["mass_kg"].as_float(), Some(0.35));
    sandslope()
        .args(["presets", "show", "nope"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("paper-hexapod"));
}

/// Runs a failing command and checks exit code 2, one clear message, no panic.
fn fails_with(args: &[&str], dir: &Path, message: &str) {
    sandslope()
        .current_dir(dir)
        .args(args)
        .assert()
        .code(2)
        .stderr(predicate::str::contains(message).and(predicate::str::contains("panicked").not()));
}

#[test]
fn bad_inputs_get_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let robot = std::fs::read_to_string(repo_file("crates/sandslope-io/presets/paper-hexapod.toml")).unwrap();
    std::fs::write(d.join("tall.toml"), robot.replace("hip_height_m = 0.03", "hip_height_m = 0.09")).unwrap();
    std::fs::write(d.join("extra.toml"), format!("{robot}\nwheels = 4\n")).unwrap();
    std::fs::write(d.join("terrain.toml"), "[[points]]\nslope_deg = 0\nk_n = 7e5\nk_s = -1\n").unwrap();
    std::fs::write(d.join("speeds.csv"), "slope_deg,speed_m_s,speed_sd_m_s\n0,fast,0.01\n").unwrap();

    // 1. A robot value out of range names the key and the range.
    fails_with(
        &["predict", "--slope", "10", "--robot", "tall.toml"],
        d,
        "hip_height_m = 0.09 must be between 0 and 2 * leg_radius_m = 0.08",
    );
    // 2. Unknown keys are rejected and named.
    fails_with(&["predict", "--slope", "10", "--robot", "extra.toml"], d, "unknown field `wheels`");
    // 3. A terrain value out of range names the point and key.
    fails_with(&["predict", "--slope", "10", "--terrain", "terrain.toml"], d, "points[0].k_s = -1");
    // 4. A slope outside the model's range.
    fails_with(&["predict", "--slope", "95"], d, "--slope = 95");
    // 5. A non-positive mass.
    fails_with(&["predict", "--slope", "10", "--mass", "-1"], d, "--mass = -1");
    // 6. An unknown preset lists the built-in ones.
    fails_with(&["predict", "--slope", "10", "--robot", "spider"], d, "built-in: paper-hexapod");
    // 7. A missing file names it.
    fails_with(&["predict", "--slope", "10", "--terrain", "missing.toml"], d, "missing.toml");
    // 8. A non-numeric cell in a speeds file names the file and line.
    fails_with(&["calibrate", "--observed", "speeds.csv", "--out", "x.toml"], d, "speeds.csv: line 2");
    assert!(!d.join("x.toml").exists());
    // 9. A plot with an unknown extension, and no partial output.
    fails_with(&["sweep", "--plot", "fig.jpg"], d, "must end in .png or .svg");
    assert!(!d.join("fig.jpg").exists());
    // 9b. A plot into a folder that does not exist.
    fails_with(&["sweep", "--plot", "no/such/dir/fig.png"], d, "the folder no/such/dir does not exist");
    // 10. A zero step.
    fails_with(&["sweep", "--step", "0"], d, "--step = 0");
    // 11. Zero overrides.
    fails_with(&["predict", "--slope", "10", "--k-s", "0"], d, "--k-s = 0");
}

#[test]
fn robot_quantity_flags_equal_a_robot_file_with_those_values() {
    // The same robot written as a file and given as flags must predict the same, byte for byte.
    let dir = tempfile::tempdir().unwrap();
    let preset =
        std::fs::read_to_string(repo_file("crates/sandslope-io/presets/paper-hexapod.toml")).unwrap();
    let edited = preset
        .replace("leg_radius_m = 0.04", "leg_radius_m = 0.05")
        .replace("leg_speed_rad_s = 6.283185307179586", "leg_speed_rad_s = 4")
        .replace("stance_legs = 3", "stance_legs = 2");
    assert_ne!(edited, preset);
    let file = common::write_arg(dir.path(), "robot.toml", &edited);
    for slope in ["0", "12.5", "22"] {
        let by_file =
            sandslope().args(["sweep", "--json", "--robot", &file, "--to", slope]).output().unwrap();
        let by_flags = sandslope()
            .args([
                "sweep",
                "--json",
                "--leg-radius",
                "0.05",
                "--leg-speed",
                "4",
                "--stance-legs",
                "2",
                "--to",
                slope,
            ])
            .output()
            .unwrap();
        assert!(by_file.status.success() && by_flags.status.success());
        assert_eq!(by_file.stdout, by_flags.stdout);
    }
    // A hip height above 2R is refused naming the flag (docs/model.md §2: 0 <= h <= 2R).
    sandslope().args(["predict", "--slope", "10", "--leg-radius", "0.01"]).assert().code(2).stderr(
        predicates::str::contains("--hip-height = 0.03 must be between 0 and 2 * leg_radius_m = 0.02"),
    );
}

/// `MIN:MAX:N` takes a count: `0:30:1`, meant as steps of 1 degree, is refused (exit 2) with
/// the count that gives those steps, (30 - 0) / 1 + 1 = 31; a step that does not divide the
/// range gets the explanation without a suggestion.
#[test]
fn a_slope_range_with_a_step_for_a_count_suggests_the_count() {
    for (cmd, flag) in [("simulate", "--slopes"), ("risk", "--slope")] {
        sandslope()
            .args([cmd, flag, "0:30:1"])
            .assert()
            .code(2)
            .stderr(predicate::str::contains("the third field is the number of slopes, not a step"))
            .stderr(predicate::str::contains("write 0:30:31"));
    }
    // Steps of 0.5 deg from 10 to 20: (20 - 10) / 0.5 + 1 = 21 slopes (0.5 is not a count).
    sandslope()
        .args(["risk", "--slope", "10:20:0.5"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("write 10:20:21"));
    sandslope()
        .args(["risk", "--slope", "0:10:0"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("number of slopes").and(predicate::str::contains("write").not()));
}
