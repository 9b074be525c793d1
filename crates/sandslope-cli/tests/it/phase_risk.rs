//! End-to-end tests of `sandslope phase` and `sandslope risk`.

use crate::common;
use common::{json, sandslope, write_arg as write};

use std::path::Path;

use assert_cmd::Command;
use predicates::prelude::*;
use serde_json::Value;

/// A terrain with standard deviations: 0 deg k_s 2e6 +- 4e5, 20 deg 1e6 +- 3e5; k_n 7e5 +- 1.4e5.
const UNCERTAIN: &str = r#"
name = "uncertain-sand"
repose_deg = 25.0
[[points]]
slope_deg = 0.0
k_n = 7.0e5
k_s = 2.0e6
k_n_sd = 1.4e5
k_s_sd = 4.0e5
[[points]]
slope_deg = 20.0
k_n = 7.0e5
k_s = 1.0e6
k_n_sd = 1.4e5
k_s_sd = 3.0e5
"#;

/// The CSV has one row per cell and panel with the documented columns, and the sinkage
/// boundary sits at the hand-computed k_n* = m g cos(theta) / (n A_c (2R - h)):
/// 0.35 kg level: 0.35*9.81/3/(4e-4*0.05) = 57225; 1 kg: 163500; times cos(24 deg) on 24 deg.
#[test]
fn phase_csv_has_every_cell_and_the_sinkage_boundary() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("cells.csv");
    sandslope()
        .args(["phase", "--k-n", "1e4:1e7:25", "--k-s", "1e3:1e8:20", "--slope", "0,24", "--mass", "0.35,1"])
        .args(["--csv", csv.to_str().unwrap(), "--json"])
        .assert()
        .success()
        .stderr(format!("wrote {}\n", csv.display()));
    let mut reader = csv::Reader::from_path(&csv).unwrap();
    assert_eq!(
        reader.headers().unwrap().iter().collect::<Vec<_>>(),
        ["k_n", "k_s", "slope_deg", "mass_kg", "regime", "step_m"]
    );
    let mut rows = 0;
    for rec in reader.records() {
        let rec = rec.unwrap();
        rows += 1;
        let num = |k: usize| rec[k].parse::<f64>().unwrap();
        let (k_n, slope, mass) = (num(0), num(2), num(3));
        let k_star = mass * 9.81 * slope.to_radians().cos() / 3.0 / (4e-4 * 0.05);
        let sunk = &rec[4] == "sinkage";
        assert_eq!(sunk, k_n <= k_star, "{rec:?} (k_n* = {k_star})");
        assert!(["sinkage", "slippage", "metastable", "success"].contains(&&rec[4]));
        // Steps are given wherever the leg anchors; success means s >= s_min = R = 0.04 m.
        if &rec[4] == "success" {
            assert!(num(5) >= 0.04);
        }
    }
    assert_eq!(rows, 4 * 25 * 20);
}

#[test]
fn phase_json_summarises_each_panel() {
    let v = json(&["phase", "--k-n", "1e4:1e7:30", "--k-s", "1e3:1e8:30", "--slope", "0,30", "--json"]);
    let panels = v.as_array().unwrap();
    assert_eq!(panels.len(), 2);
    let c = &panels[0]["counts"];
    let total: u64 =
        ["sinkage", "slippage", "metastable", "success"].iter().map(|k| c[k].as_u64().unwrap()).sum();
    assert_eq!(total, 900);
    // The preset terrain (k_n 7e5, k_s 2e6) on level sand: success (docs/model.md §3-§6 by hand,
    // s = 75.7 mm >= 40 mm).
    assert_eq!(panels[0]["terrain"]["regime"], "success");
    // 30 deg is above the preset's angle of repose (25 deg): every non-sunk cell slips.
    assert_eq!(panels[1]["beyond_repose"], true);
    assert_eq!(panels[1]["counts"]["success"], 0);
    assert_eq!(panels[1]["counts"]["metastable"], 0);
    assert!((panels[0]["sinkage_threshold_k_n"].as_f64().unwrap() - 57_225.0).abs() < 1e-6);
}

#[test]
fn phase_plot_is_written_and_bad_input_fails_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("phase.png");
    sandslope()
        .args(["phase", "--k-n", "1e4:1e7:40", "--k-s", "1e3:1e8:40", "--slope", "0,24", "--mass", "0.35,1"])
        .args(["--plot", png.to_str().unwrap()])
        .assert()
        .success();
    assert!(std::fs::metadata(&png).unwrap().len() > 10_000);

    let bad = dir.path().join("phase.jpg");
    sandslope()
        .args(["phase", "--k-n", "1e4:1e7:10", "--plot", bad.to_str().unwrap()])
        .assert()
        .code(2)
        .stderr(predicate::str::contains(".png or .svg"));
    assert!(!bad.exists());
    sandslope()
        .args(["phase", "--k-n", "1e7:1e4:10"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("--k-n max = 10000 must be"));
    sandslope()
        .args(["phase", "--k-s", "0:1e4:10:log"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("--k-s min"));
    sandslope()
        .args(["phase", "--mass", "0.35,-1"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("--mass = -1"));
    sandslope()
        .args(["phase", "--slope", "95"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("--slope = 95"));
}

/// With no uncertainty the probabilities are the certain regime (0 or 1), in the documented
/// JSON shape.
#[test]
fn risk_without_uncertainty_is_certain() {
    let v = json(&["risk", "--slope", "0", "--cv-n", "0", "--cv-s", "0", "--json"]);
    let keys: Vec<&String> = v.as_object().unwrap().keys().collect();
    assert_eq!(
        keys,
        ["cv_n", "cv_n_source", "cv_s", "cv_s_source", "p_fail", "p_not_success", "p_regime", "slope_deg"]
    );
    assert_eq!(
        (&v["cv_n"], &v["cv_n_source"], &v["cv_s_source"]),
        (&0.0.into(), &"given".into(), &"given".into())
    );
    assert_eq!(v["p_fail"], 0.0);
    assert_eq!(v["p_regime"]["success"], 1.0);
    // At 26 deg, above the preset's repose of 25 deg: certain slippage.
    let v = json(&["risk", "--slope", "10,26", "--cv-n", "0.1", "--cv-s", "0.1", "--json"]);
    assert_eq!(v.as_array().unwrap().len(), 2);
    assert!((v[1]["p_regime"]["slippage"].as_f64().unwrap() - 1.0).abs() < 1e-12);
}

#[test]
fn risk_uses_the_terrain_sds_interpolated_like_the_values() {
    let dir = tempfile::tempdir().unwrap();
    let t = write(dir.path(), "sand.toml", UNCERTAIN);
    let out = sandslope().args(["risk", "--terrain", &t, "--slope", "0,10,20", "--csv"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mut reader = csv::Reader::from_reader(&out.stdout[..]);
    let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    // cv_s: 0 deg 4e5/2e6 = 0.2; 10 deg 3.5e5/1.5e6 = 0.2333; 20 deg 3e5/1e6 = 0.3; cv_n 0.2.
    for (row, cv_s) in rows.iter().zip([0.2, 3.5e5 / 1.5e6, 0.3]) {
        assert!((row[2].parse::<f64>().unwrap() - cv_s).abs() < 1e-12, "{row:?}");
        assert!((row[1].parse::<f64>().unwrap() - 0.2).abs() < 1e-12, "{row:?}");
        let p: Vec<f64> = (3..9).map(|k| row[k].parse().unwrap()).collect();
        // p_fail = slippage + sinkage; the four regimes sum to 1.
        assert!((p[0] - p[4] - p[5]).abs() < 1e-12 && (p[2] + p[3] + p[4] + p[5] - 1.0).abs() < 1e-9);
    }
    // A given CV overrides the table's SD for its variable only (docs/model.md §9).
    let out = sandslope()
        .args(["risk", "--terrain", &t, "--slope", "10", "--cv-s", "0.05", "--csv"])
        .output()
        .unwrap();
    let mut reader = csv::Reader::from_reader(&out.stdout[..]);
    let row = reader.records().next().unwrap().unwrap();
    assert_eq!((&row[1], &row[2]), ("0.2", "0.05"));
    assert!(out.stderr.is_empty(), "{}", String::from_utf8_lossy(&out.stderr));
    // Without sds and without --cv-n/--cv-s: the defaults 0.1 and 0.2, and the output says so.
    // (The built-in terrain carries SDs since its joint calibration: use a table without them.)
    let bare = write(dir.path(), "bare.toml", "[[points]]\nslope_deg = 0.0\nk_n = 7.0e5\nk_s = 2.0e6\n");
    let out = sandslope().args(["risk", "--slope", "10", "--csv", "--terrain", &bare]).output().unwrap();
    assert!(out.status.success());
    let mut reader = csv::Reader::from_reader(&out.stdout[..]);
    let row = reader.records().next().unwrap().unwrap();
    assert_eq!((&row[1], &row[2]), ("0.1", "0.2"));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("default cv k_n = 0.1") && err.contains("default cv k_s = 0.2"), "{err}");
    sandslope()
        .args(["risk", "--slope", "10", "--terrain", &bare])
        .assert()
        .success()
        .stdout(predicate::str::contains("default cv k_s = 0.2"));
    sandslope()
        .args(["risk", "--slope", "10", "--cv-n", "0.1", "--cv-s", "0.1", "--max-risk", "1.5"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("--max-risk = 1.5: 1.5 is not a failure probability"));
}

/// Every `risk --json` result carries the CVs it used and where each came from (docs/model.md
/// §9: given, else the table's SD over its value, else the default), as the CSV and the table
/// do; the stderr note about defaults stays.
#[test]
fn risk_json_reports_the_uncertainty_used_and_its_source() {
    let dir = tempfile::tempdir().unwrap();
    let t = write(dir.path(), "sand.toml", UNCERTAIN);
    let bare = write(dir.path(), "bare.toml", "[[points]]\nslope_deg = 0.0\nk_n = 7.0e5\nk_s = 2.0e6\n");
    let close = |v: &Value, want: f64| (v.as_f64().unwrap() - want).abs() < 1e-12;
    // Per slope, from the table: cv_n 1.4e5/7e5 = 0.2; cv_s at 10 deg 3.5e5/1.5e6, at 20 deg 0.3.
    let v = json(&["risk", "--terrain", &t, "--slope", "10,20", "--json"]);
    for (p, cv_s) in v.as_array().unwrap().iter().zip([3.5e5 / 1.5e6, 0.3]) {
        assert!(close(&p["cv_n"], 0.2) && close(&p["cv_s"], cv_s), "{p}");
        assert_eq!((p["cv_n_source"].as_str(), p["cv_s_source"].as_str()), (Some("table"), Some("table")));
    }
    // A given CV for k_s only; no SDs at all: the defaults, named as such, and the note on stderr.
    let v = json(&["risk", "--terrain", &t, "--slope", "10", "--cv-s", "0.05", "--json"]);
    assert_eq!(
        (v["cv_s"].as_f64(), v["cv_s_source"].as_str(), v["cv_n_source"].as_str()),
        (Some(0.05), Some("given"), Some("table"))
    );
    let out = sandslope().args(["risk", "--terrain", &bare, "--slope", "10", "--json"]).output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!((v["cv_n"].as_f64(), v["cv_s"].as_f64()), (Some(0.1), Some(0.2)));
    assert_eq!((v["cv_n_source"].as_str(), v["cv_s_source"].as_str()), (Some("default"), Some("default")));
    assert!(String::from_utf8_lossy(&out.stderr).contains("default cv k_n = 0.1"));
    // --solve slope: the CVs where the limit's p_fail was evaluated, and the defaults over the table.
    let v = json(&["risk", "--terrain", &bare, "--cv-n", "0.3", "--solve", "slope", "--json"]);
    assert_eq!((v["cv_n"].as_f64(), v["cv_n_source"].as_str()), (Some(0.3), Some("given")));
    assert_eq!((v["cv_s"].as_f64(), v["cv_s_source"].as_str()), (Some(0.2), Some("default")));
    assert_eq!(v["defaults_used"], serde_json::json!({"k_n": false, "k_s": true}));
    let v = json(&["risk", "--terrain", &t, "--solve", "slope", "--json"]);
    let at = v["safe_slope_deg"].as_f64().unwrap();
    assert!(at > 0.0 && at < 25.0, "{v}");
    // From 0 deg (4e5 / 2e6) to 20 deg (3e5 / 1e6) and beyond (docs/model.md §7) both are linear.
    let (sd, k) = (4e5 - 1e5 * at / 20.0, 2e6 - 1e6 * at / 20.0);
    assert!(close(&v["cv_s"], sd / k) && v["cv_s_source"] == "table", "{v}");
    assert_eq!(v["defaults_used"], serde_json::json!({"k_n": false, "k_s": false}));
    // --solve mass at one slope and over several (the envelope), and --map.
    let v = json(&["risk", "--terrain", &t, "--slope", "20", "--solve", "mass", "--json"]);
    assert!(close(&v["cv_s"], 0.3) && v["cv_s_source"] == "table" && v["max_mass_kg"].is_number(), "{v}");
    let v =
        json(&["risk", "--terrain", &t, "--slope", "0,20", "--cv-n", "0.15", "--solve", "mass", "--json"]);
    for (p, cv_s) in v["points"].as_array().unwrap().iter().zip([0.2, 0.3]) {
        assert!(close(&p["cv_s"], cv_s) && p["cv_s_source"] == "table", "{p}");
        assert!(close(&p["cv_n"], 0.15) && p["cv_n_source"] == "given", "{p}");
        assert!(p["max_mass_kg"].is_number() && p["limit"]["kind"] == "limit", "{p}");
    }
    let v = json(&[
        "risk",
        "--terrain",
        &bare,
        "--slope",
        "20",
        "--cv-s",
        "0.4",
        "--map",
        "--k-n",
        "1e5:1e7:3",
        "--k-s",
        "1e5:1e7:3",
        "--json",
    ]);
    assert_eq!(
        (v["cv_n_source"].as_str(), v["cv_s_source"].as_str(), v["cv_s"].as_f64()),
        (Some("default"), Some("given"), Some(0.4))
    );
    assert_eq!(v["defaults_used"], serde_json::json!({"k_n": true, "k_s": false}));
}

/// With no uncertainty the heaviest safe mass is where `predict` turns to failure: check it
/// with `sandslope predict` just either side.
#[test]
fn solve_mass_matches_predict_either_side() {
    let dir = tempfile::tempdir().unwrap();
    let t = write(dir.path(), "weak.toml", "[[points]]\nslope_deg = 0.0\nk_n = 7.0e5\nk_s = 4.0e5\n");
    let v = json(&[
        "risk",
        "--terrain",
        &t,
        "--slope",
        "15",
        "--cv-n",
        "0",
        "--cv-s",
        "0",
        "--solve",
        "mass",
        "--json",
    ]);
    let m = v["max_mass_kg"].as_f64().unwrap();
    assert!(m > 0.35, "{v}");
    assert!((v["max_payload_kg"].as_f64().unwrap() - (m - 0.35)).abs() < 1e-12);
    let regime = |mass: f64| {
        json(&["predict", "--terrain", &t, "--slope", "15", "--mass", &format!("{mass}"), "--json"])["regime"]
            .as_str()
            .unwrap()
            .to_string()
    };
    assert!(["metastable", "success"].contains(&regime(m * 0.999).as_str()), "{m}");
    assert!(["slippage", "sinkage"].contains(&regime(m * 1.001).as_str()), "{m}");

    let v = json(&["risk", "--terrain", &t, "--cv-n", "0", "--cv-s", "0", "--solve", "slope", "--json"]);
    let s = v["safe_slope_deg"].as_f64().unwrap();
    let at =
        |d: f64| json(&["predict", "--terrain", &t, "--slope", &format!("{d}"), "--json"])["regime"].clone();
    assert_ne!(at(s - 0.01), "slippage");
    assert_eq!(at(s + 0.01), "slippage");
}

/// `--solve mass` over several slopes is the payload envelope: each point is the one-slope
/// answer, and the heaviest safe mass does not grow with slope on a terrain that weakens.
#[test]
fn payload_envelope_is_the_one_slope_answer_at_each_slope() {
    let dir = tempfile::tempdir().unwrap();
    let t = write(dir.path(), "sand.toml", UNCERTAIN);
    let plot = dir.path().join("envelope.png");
    let v = json(
        &["risk", "--terrain", &t, "--slope", "0:20:3", "--solve", "mass", "--json", "--plot"]
            .iter()
            .copied()
            .chain([plot.to_str().unwrap()])
            .collect::<Vec<_>>(),
    );
    let points = v["points"].as_array().unwrap();
    assert_eq!(points.len(), 3);
    let mut last = f64::INFINITY;
    for p in points {
        let d = p["slope_deg"].as_f64().unwrap();
        let one = json(&["risk", "--terrain", &t, "--slope", &format!("{d}"), "--solve", "mass", "--json"]);
        assert_eq!(p["max_mass_kg"], one["max_mass_kg"], "{d}");
        let m = p["max_mass_kg"].as_f64().unwrap();
        assert!(m <= last, "{m} after {last}");
        last = m;
    }
    assert!(std::fs::metadata(&plot).unwrap().len() > 10_000);
}

#[test]
fn risk_plots_curve_and_map() {
    let dir = tempfile::tempdir().unwrap();
    let t = write(dir.path(), "sand.toml", UNCERTAIN);
    let curve = dir.path().join("risk.png");
    sandslope()
        .args(["risk", "--terrain", &t, "--slope", "0,10,20", "--plot", curve.to_str().unwrap()])
        .assert()
        .success()
        .stdout(predicate::str::contains("safe-slope limit"));
    assert!(std::fs::metadata(&curve).unwrap().len() > 10_000);
    let map = dir.path().join("map.svg");
    let v = json(&[
        "risk",
        "--terrain",
        &t,
        "--slope",
        "20",
        "--plot",
        map.to_str().unwrap(),
        "--map",
        "--k-n",
        "1e4:1e7:6",
        "--k-s",
        "1e4:1e8:6",
        "--json",
    ]);
    assert_eq!(v["cells"], 36);
    assert!(std::fs::read_to_string(&map).unwrap().contains("<svg"));
}

/// `risk --map` without --plot gives the numbers: one CSV row per cell, k_n-major, each
/// p_fail the one-slope quadrature of `risk` at those medians.
#[test]
fn risk_map_csv_has_every_cell_k_n_major() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("map.csv");
    sandslope()
        // Explicit CVs: the map and the one-cell check below must use the same uncertainty.
        .args(["risk", "--slope", "20", "--cv-n", "0.1", "--cv-s", "0.2", "--map", "--k-n", "1e5:1e7:3"])
        .args(["--k-s", "1e5:1e7:4", "--csv"])
        .arg(&csv)
        .assert()
        .success();
    let mut reader = csv::Reader::from_path(&csv).unwrap();
    assert_eq!(
        reader.headers().unwrap().iter().collect::<Vec<_>>(),
        ["k_n", "k_s", "p_fail", "p_not_success"]
    );
    let rows: Vec<Vec<f64>> =
        reader.records().map(|r| r.unwrap().iter().map(|x| x.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), 12);
    // k_n-major: the first four rows share k_n = 1e5, k_s ascending.
    assert!(rows[..4].iter().all(|r| r[0] == 1e5) && (rows[4][0] / 1e6 - 1.0).abs() < 1e-12);
    assert!(rows[..4].windows(2).all(|w| w[1][1] > w[0][1]));
    // Row 5 is k_n = 1e6, k_s = 1e5 * 100^(1/3): check against a constant terrain there.
    let t = write(
        dir.path(),
        "cell.toml",
        &format!("[[points]]\nslope_deg = 0.0\nk_n = {}\nk_s = {}\n", rows[5][0], rows[5][1]),
    );
    let v = json(&["risk", "--terrain", &t, "--slope", "20", "--cv-n", "0.1", "--cv-s", "0.2", "--json"]);
    assert!((v["p_fail"].as_f64().unwrap() - rows[5][2]).abs() < 1e-6, "{v} vs {:?}", rows[5]);
    assert!(rows.iter().all(|r| r[2] <= r[3] + 1e-12 && (0.0..=1.0).contains(&r[2])));
    // `--json` lists the same cells indexed [k_n][k_s] (Python's risk_map shape), after the
    // axis values.
    let v = json(&[
        "risk",
        "--slope",
        "20",
        "--cv-n",
        "0.1",
        "--cv-s",
        "0.2",
        "--map",
        "--k-n",
        "1e5:1e7:3",
        "--k-s",
        "1e5:1e7:4",
        "--json",
    ]);
    assert_eq!((v["k_n"].as_array().unwrap().len(), v["k_s"].as_array().unwrap().len()), (3, 4));
    for (c, r) in rows.iter().enumerate() {
        let (i, j) = (c / 4, c % 4);
        let near =
            |x: &serde_json::Value, y: f64| (x.as_f64().unwrap() - y).abs() <= 1e-15 * y.abs().max(1e-300);
        assert!(near(&v["k_n"][i], r[0]) && near(&v["k_s"][j], r[1]), "{c}");
        assert!(near(&v["p_fail"][i][j], r[2]) && near(&v["p_not_success"][i][j], r[3]), "{c}");
    }
}

#[test]
fn oversized_grids_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("cells.csv");
    // 100000 x 100000 = 1e10 cells: far beyond the 2^28 limit.
    Command::cargo_bin("sandslope")
        .unwrap()
        .args(["phase", "--k-n", "1e3:1e7:100000", "--k-s", "1e3:1e7:100000", "--csv"])
        .arg(&csv)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("10000000000 cells").and(predicate::str::contains("at most")));
    assert!(!csv.exists());
    // 8000 x 8000 = 6.4e7 cells is a valid map but too many CSV rows (limit 2^25).
    Command::cargo_bin("sandslope")
        .unwrap()
        .args(["phase", "--k-n", "1e3:1e7:8000", "--k-s", "1e3:1e7:8000", "--csv"])
        .arg(&csv)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("--csv would write 64000000 rows"));
    // A risk map of 1e8 cells would not fit in memory: refused up front, nothing written.
    let csv = dir.path().join("m.csv");
    Command::cargo_bin("sandslope")
        .unwrap()
        .args(["risk", "--slope", "20", "--map", "--csv"])
        .arg(&csv)
        .args(["--k-n", "1e4:1e7:10000", "--k-s", "1e4:1e7:10000"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("100000000 map cells"));
    assert!(!csv.exists());
    // Bad grids: N = 0, MIN >= MAX, a log axis through 0.
    for (flag, bad, says) in [
        ("--k-n", "1e4:1e7:0", "--k-n points = 0"),
        ("--k-s", "1e7:1e4:10", "--k-s max"),
        ("--k-n", "0:1e7:10", "greater than 0 on a log axis"),
    ] {
        for cmd in ["phase", "risk"] {
            let mut c = Command::cargo_bin("sandslope").unwrap();
            c.args([cmd, flag, bad]);
            if cmd == "risk" {
                c.args(["--slope", "20", "--map"]);
            }
            c.assert().code(2).stderr(predicate::str::contains(says));
        }
    }
}

#[test]
fn risk_negative_cv_gets_the_valid_range_not_a_parse_error() {
    let out = sandslope().args(["risk", "--slope", "20", "--cv-n", "-1"]).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("cv_n") || err.contains("--cv-n"), "{err}");
    assert!(err.contains("at least 0"), "{err}");
}

/// `risk` reads `--cv-n`/`--cv-s` through the same arguments as `design` and `infer`: the same
/// help and the same message for the same bad value, naming the flag.
#[test]
fn risk_cv_flags_are_the_shared_uncertainty_flags() {
    for (flag, bad) in [("--cv-n", "-0.5"), ("--cv-s", "NaN"), ("--cv-s", "inf")] {
        let want = format!("error: {flag} = {bad} must be a finite number of at least 0\n");
        let risk = sandslope().args(["risk", "--slope", "20", flag, bad]).output().unwrap();
        let design = sandslope()
            .args(["design", "--vary", "leg_width_m=0.005:0.02:4:log", "--slope-target", "20", flag, bad])
            .output()
            .unwrap();
        for out in [risk, design] {
            assert_eq!(out.status.code(), Some(2));
            assert_eq!(String::from_utf8_lossy(&out.stderr), want);
            assert!(out.stdout.is_empty());
        }
    }
    // The same help for the flags everywhere (words compared, whatever clap's line wrapping).
    let help = |cmd: &str| {
        let out = sandslope().args([cmd, "--help"]).output().unwrap();
        String::from_utf8(out.stdout).unwrap().split_whitespace().collect::<Vec<_>>().join(" ")
    };
    for cmd in ["risk", "design", "infer"] {
        let text = help(cmd);
        for says in [
            "--cv-n <CV> Coefficient of variation of k_n (sd / value) at every slope, instead of the terrain's k_n_sd; without either, 0.1 (docs/model.md §9)",
            "--cv-s <CV> Coefficient of variation of k_s (sd / value) at every slope, instead of the terrain's k_s_sd; without either, 0.2 (docs/model.md §9)",
        ] {
            assert!(text.contains(says), "{cmd}: {text}");
        }
    }
}

/// Reads a `.npy` file written by sandslope: (descr, shape, raw data).
fn read_npy(path: &Path) -> (String, Vec<usize>, Vec<u8>) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00", "{}", path.display());
    let len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let dict = std::str::from_utf8(&bytes[10..10 + len]).unwrap();
    let descr = dict.split("'descr': '").nth(1).unwrap().split('\'').next().unwrap().to_string();
    let shape = dict.split("'shape': (").nth(1).unwrap().split(')').next().unwrap();
    let shape =
        shape.split(',').map(str::trim).filter(|s| !s.is_empty()).map(|s| s.parse().unwrap()).collect();
    (descr, shape, bytes[10 + len..].to_vec())
}

fn f64s(raw: &[u8]) -> Vec<f64> {
    raw.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap())).collect()
}

/// `--regime-only` writes the same CSV without the step column, byte for byte the full CSV's
/// text up to the regime (each row's first five fields), and no `step_m.npy`; the regime
/// codes in `regime.npy` are the full run's.
#[test]
fn regime_only_leaves_out_the_step() {
    let dir = tempfile::tempdir().unwrap();
    let (full, short) = (dir.path().join("full.csv"), dir.path().join("short.csv"));
    let (full_npy, short_npy) = (dir.path().join("full"), dir.path().join("short"));
    std::fs::create_dir(&full_npy).unwrap();
    std::fs::create_dir(&short_npy).unwrap();
    let grid = [
        "phase",
        "--k-n",
        "1e4:1e7:9",
        "--k-s",
        "1e3:1e8:6",
        "--slope",
        "0,24",
        "--mass",
        "0.35,1",
        "--json",
    ];
    sandslope().args(grid).arg("--csv").arg(&full).arg("--npy").arg(&full_npy).assert().success();
    sandslope()
        .args(grid)
        .arg("--regime-only")
        .arg("--csv")
        .arg(&short)
        .arg("--npy")
        .arg(&short_npy)
        .assert()
        .success();
    let (full, short) = (std::fs::read_to_string(full).unwrap(), std::fs::read_to_string(short).unwrap());
    let (mut f, mut s) = (full.lines(), short.lines());
    assert_eq!(f.next(), Some("k_n,k_s,slope_deg,mass_kg,regime,step_m"));
    assert_eq!(s.next(), Some("k_n,k_s,slope_deg,mass_kg,regime"));
    let mut rows = 0;
    for (a, b) in f.zip(s) {
        let five: Vec<&str> = a.split(',').take(5).collect();
        assert_eq!(five.join(","), b);
        rows += 1;
    }
    assert_eq!((rows, short.lines().count()), (4 * 9 * 6, 4 * 9 * 6 + 1));
    assert_eq!(read_npy(&full_npy.join("regime.npy")), read_npy(&short_npy.join("regime.npy")));
    assert!(full_npy.join("step_m.npy").exists());
    assert!(!short_npy.join("step_m.npy").exists());
}

/// `--npy` writes the same cells as `--csv`: regime codes (0 sinkage .. 3 success), steps
/// with NaN where the CSV is empty, and the axes; for risk, p_fail as in the map CSV.
#[test]
fn npy_arrays_hold_the_same_cells_as_the_csv() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("cells.csv");
    sandslope()
        .args([
            "phase",
            "--k-n",
            "1e4:1e7:7",
            "--k-s",
            "1e3:1e8:5",
            "--slope",
            "0,24",
            "--mass",
            "0.35,1",
            "--json",
        ])
        .arg("--csv")
        .arg(&csv)
        .arg("--npy")
        .arg(dir.path())
        .assert()
        .success();
    let (descr, shape, regime) = read_npy(&dir.path().join("regime.npy"));
    assert_eq!((descr.as_str(), shape), ("|i1", vec![2, 2, 5, 7]));
    let (descr, _, step) = read_npy(&dir.path().join("step_m.npy"));
    assert_eq!(descr, "<f8");
    let step = f64s(&step);
    assert_eq!(f64s(&read_npy(&dir.path().join("slope_deg.npy")).2), [0.0, 24.0]);
    assert_eq!(read_npy(&dir.path().join("k_n.npy")).1, [7]);
    let names = ["sinkage", "slippage", "metastable", "success"];
    let mut reader = csv::Reader::from_path(&csv).unwrap();
    let mut n = 0;
    for (c, row) in reader.records().enumerate() {
        let row = row.unwrap();
        assert_eq!(names[regime[c] as usize], &row[4], "cell {c}");
        match row[5].parse::<f64>() {
            Ok(s) => assert_eq!(s, step[c]),
            Err(_) => assert!(step[c].is_nan()),
        }
        n += 1;
    }
    assert_eq!(n, 140);
    // Risk: a missing folder is made (as `fit --plot` makes its folder, issue 28); the arrays
    // then match the CSV.
    let risk_dir = dir.path().join("risk").join("npy");
    let out = sandslope()
        .args([
            "risk",
            "--slope",
            "20",
            "--map",
            "--k-n",
            "1e5:1e7:3",
            "--k-s",
            "1e5:1e7:4",
            "--csv",
            "--npy",
        ])
        .arg(&risk_dir)
        .output()
        .unwrap();
    assert!(out.status.success());
    let (_, shape, p) = read_npy(&risk_dir.join("p_fail.npy"));
    assert_eq!(shape, [4, 3]);
    let p = f64s(&p);
    let mut reader = csv::Reader::from_reader(&out.stdout[..]);
    for (c, row) in reader.records().enumerate() {
        // CSV is k_n-major (c = i * 4 + j); the array is [k_s][k_n].
        let (i, j) = (c / 4, c % 4);
        assert_eq!(row.unwrap()[2].parse::<f64>().unwrap(), p[j * 3 + i]);
    }
}

/// On the built-in glass beads p_fail stays below 0.05 up to the angle of repose, 25 degrees
/// (the terrain file's `repose_deg`), where the sand flows and p_fail jumps to 1: the limit is
/// named as the repose, not as a risk threshold at "24.999"; a stricter risk crosses below it
/// and is given as a slope.
#[test]
fn a_safe_slope_limit_at_the_angle_of_repose_is_named_as_such() {
    let out = |max_risk: &str| {
        let o = sandslope().args(["risk", "--solve", "slope", "--max-risk", max_risk]).assert().success();
        String::from_utf8(o.get_output().stdout.clone()).unwrap()
    };
    let at_repose = out("0.05");
    assert!(at_repose.contains("up to the angle of repose, 25 deg"), "{at_repose}");
    let below = out("0.001");
    assert!(below.contains("safe-slope limit") && !below.contains("repose"), "{below}");
    let v = json(&["risk", "--solve", "slope", "--max-risk", "0.001", "--json"]);
    assert!(v["safe_slope_deg"].as_f64().unwrap() < 24.0, "{v}");
    assert_eq!(v["limit"]["kind"], "limit", "{v}");
    // A program tells the repose from a risk limit by `limit.kind`, and reads the repose itself.
    let v = json(&["risk", "--solve", "slope", "--json"]);
    assert_eq!(v["limit"]["kind"], "repose", "{v}");
    assert_eq!(v["limit"]["repose_deg"], 25.0, "{v}");
    assert_eq!(v["safe_slope_deg"], 25.0, "{v}");
}

/// "How steep can we go?" has two answers and both are given, named apart: on the built-in
/// terrain the median robot is metastable from about 18 degrees (`predict`), so the slope up
/// to which it climbs (P(not success) < 0.05) lies below that, far below the repose that caps
/// p_fail. With no uncertainty the success limit is where `predict` stops saying success.
#[test]
fn risk_solve_slope_gives_the_success_limit_beside_the_safe_slope_limit() {
    let regime = |t: Option<&str>, d: f64| {
        let mut a = vec!["predict".to_string(), "--slope".into(), format!("{d}"), "--json".into()];
        if let Some(t) = t {
            a.extend(["--terrain".into(), t.into()]);
        }
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        json(&a)["regime"].as_str().unwrap().to_string()
    };
    // The built-in terrain: where the median robot stops succeeding, found by predict alone.
    let metastable_from = (0..=120).map(|i| i as f64 * 0.25).find(|&d| regime(None, d) != "success").unwrap();
    assert!((15.0..=20.0).contains(&metastable_from), "{metastable_from}");
    let v = json(&["risk", "--solve", "slope", "--json"]);
    let success = v["success_slope_deg"].as_f64().unwrap();
    assert!(success < metastable_from && success > 5.0, "{v}");
    assert!(
        v["success_limit"]["kind"] == "limit" && v["success_limit"]["p_fail"].as_f64().unwrap() < 0.05,
        "{v}"
    );
    let table = sandslope().args(["risk", "--solve", "slope"]).assert().success();
    let text = String::from_utf8(table.get_output().stdout.clone()).unwrap();
    assert!(
        text.contains(&format!("climbs (success limit, P(not success) < 0.05): up to {success:.1} deg")),
        "{text}"
    );
    assert!(text.contains("does not fail (safe-slope limit") && text.contains("metastable"), "{text}");
    // No uncertainty: P(not success) is 0 or 1, so the limit is predict's own transition.
    let dir = tempfile::tempdir().unwrap();
    let t = write(dir.path(), "sand.toml", UNCERTAIN);
    let v = json(&["risk", "--terrain", &t, "--cv-n", "0", "--cv-s", "0", "--solve", "slope", "--json"]);
    let s = v["success_slope_deg"].as_f64().unwrap();
    assert_eq!(regime(Some(&t), s - 0.01), "success");
    assert_ne!(regime(Some(&t), s + 0.01), "success");
    let csv = sandslope().args(["risk", "--solve", "slope", "--csv"]).assert().success();
    let csv = String::from_utf8(csv.get_output().stdout.clone()).unwrap();
    assert!(
        csv.starts_with("max_risk,success_slope_deg,success_limit_kind,safe_slope_deg,safe_limit_kind\n"),
        "{csv}"
    );
    assert!(csv.contains(",limit,25.0,repose"), "{csv}");
}
