//! End-to-end tests of `sandslope design` and `sandslope infer`.

use crate::common;
use common::{json, sandslope, write_arg as write};

use std::path::Path;

use predicates::prelude::*;

/// Every design's safe-slope limit is the number `risk --solve slope` prints for that robot;
/// invalid designs (hip height above 2R) are listed with the reason, not dropped.
#[test]
fn design_json_matches_risk_solve_slope_and_keeps_invalid_designs() {
    // A terrain without SDs, so that the default CVs (and their note) are used: the built-in
    // terrain carries SDs since its joint calibration.
    let tdir = tempfile::tempdir().unwrap();
    let terrain = write(
        tdir.path(),
        "bare.toml",
        "repose_deg = 25.0\n[[points]]\nslope_deg = 0.0\nk_n = 7.0e5\nk_s = 2.0e6\n\
         [[points]]\nslope_deg = 20.0\nk_n = 7.0e5\nk_s = 1.0e6\n",
    );
    let v = json(&[
        "design",
        "--terrain",
        &terrain,
        "--vary",
        "mass_kg=0.35:1.4:2",
        "--vary",
        "hip_height_m=0.03:0.09:2",
        "--slope-target",
        "15",
        "--json",
    ]);
    let designs = v["designs"].as_array().unwrap();
    assert_eq!(designs.len(), 4);
    assert_eq!(v["invalid"], 2);
    let note = v["notes"][0].as_str().unwrap();
    assert!(note.contains("k_n") && note.contains("k_s") && note.contains("default"), "{note}");
    for d in designs {
        let (m, h) =
            (d["params"]["mass_kg"].as_f64().unwrap(), d["params"]["hip_height_m"].as_f64().unwrap());
        if h > 0.08 {
            assert_eq!(d["valid"], false);
            assert!(d["invalid_reason"].as_str().unwrap().contains("hip_height_m"), "{d}");
            assert_eq!(d["pareto"], false);
            continue;
        }
        let dir = tempfile::tempdir().unwrap();
        let robot = write(
            dir.path(),
            "r.toml",
            &format!(
                "mass_kg = {m}\nleg_radius_m = 0.04\nleg_width_m = 0.01\nhip_height_m = {h}\n\
                 leg_speed_rad_s = 6.283185307179586\nstance_legs = 3\nresponse_time_s = 0.2\n"
            ),
        );
        let risk = json(&[
            "risk",
            "--robot",
            &robot,
            "--terrain",
            &terrain,
            "--solve",
            "slope",
            "--cv-n",
            "0.1",
            "--cv-s",
            "0.2",
            "--json",
        ]);
        assert_eq!(d["safe_slope_deg"], risk["safe_slope_deg"], "mass {m}");
        for key in ["speed_m_s", "p_fail", "regime", "k_s_margin", "pareto"] {
            assert!(!d[key].is_null(), "{key} missing in {d}");
        }
    }
    // The lighter robot climbs steeper safely and faster: the heavier one is dominated.
    assert_eq!(designs[0]["pareto"], true);
    assert_eq!(designs[2]["pareto"], false);
}

#[test]
fn design_rejects_bad_vary_with_exit_2_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("d.csv");
    let csv = csv.to_str().unwrap();
    for (vary, says) in [
        ("legs=1:3:3", "valid keys: mass_kg, leg_radius_m"),
        ("mass_kg=1.5:0.3:4", "mass_kg max"),
        ("mass_kg=0:1:3:log", "mass_kg min"),
        ("mass_kg=0.3:1.5:1", "at least 2"),
        ("stance_legs=2:4:4", "whole number"),
        ("mass_kg", "KEY=MIN:MAX:N"),
        ("mass_kg=0.3:1.5:3,mass_kg=0.5", "twice"),
    ] {
        sandslope()
            .args(["design", "--vary", vary, "--slope-target", "15", "--csv", csv])
            .assert()
            .code(2)
            .stderr(predicate::str::contains(says));
        assert!(!Path::new(csv).exists(), "{vary}: partial output");
    }
    sandslope()
        .args(["design", "--vary", "mass_kg=0.3:1:2", "--slope-target", "15", "--max-risk", "1"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("max-risk"));
}

/// The CSV has one row per design with the varied keys first; the table names the front.
#[test]
fn design_csv_and_table() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("d.csv");
    sandslope()
        .args(["design", "--vary", "leg_width_m=0.005:0.02:4:log", "--slope-target", "20", "--cv-n", "0.1"])
        .args(["--cv-s", "0.3", "--csv", csv.to_str().unwrap()])
        .assert()
        .success()
        .stdout(predicate::str::contains("Pareto front").and(predicate::str::contains("leg_width_m")));
    let mut r = csv::Reader::from_path(&csv).unwrap();
    assert_eq!(r.headers().unwrap().get(0), Some("leg_width_m"));
    let rows: Vec<csv::StringRecord> = r.records().map(Result::unwrap).collect();
    assert_eq!(rows.len(), 4);
    // Log spacing: 0.005, 0.01 (x 2^(2/3) steps...), the last 0.02.
    let w: Vec<f64> = rows.iter().map(|r| r[0].parse().unwrap()).collect();
    assert!((w[3] - 0.02).abs() < 1e-12 && (w[1] / w[0] - w[2] / w[1]).abs() < 1e-9);
    // A wider leg anchors shallower: the safe-slope limit never falls as W grows.
    let safe: Vec<f64> = rows.iter().map(|r| r[3].parse().unwrap()).collect();
    assert!(safe.windows(2).all(|p| p[1] >= p[0]), "{safe:?}");
}

/// The worked examples of docs/design.md and docs/inference.md run, and print exactly what
/// the page shows (figures go to a temporary directory instead of docs/figures).
#[test]
fn worked_examples_in_the_docs_run_as_shown() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let dir = tempfile::tempdir().unwrap();
    for page in ["docs/design.md", "docs/inference.md"] {
        let Ok(text) = std::fs::read_to_string(root.join(page)) else {
            assert_eq!(page, "docs/inference.md", "{page} missing");
            continue;
        };
        let mut lines = text.lines().peekable();
        let mut ran = 0;
        while let Some(line) = lines.next() {
            let Some(command) = line.strip_prefix("$ sandslope ") else { continue };
            let mut expected = String::new();
            while let Some(l) = lines.next_if(|l| !l.starts_with("```") && !l.starts_with("$ ")) {
                expected.push_str(l);
                expected.push('\n');
            }
            let mut args: Vec<String> = command.split_whitespace().map(String::from).collect();
            for i in 1..args.len() {
                if matches!(args[i - 1].as_str(), "--plot" | "--csv") {
                    let name = Path::new(&args[i]).file_name().unwrap().to_owned();
                    args[i] = dir.path().join(name).to_string_lossy().into_owned();
                }
            }
            let out = sandslope().current_dir(&root).args(&args).output().unwrap();
            assert!(out.status.success(), "{page}: {command}: {}", String::from_utf8_lossy(&out.stderr));
            assert_eq!(String::from_utf8_lossy(&out.stdout), expected, "{page}: {command}");
            ran += 1;
        }
        assert!(ran > 0, "{page} has no worked example");
    }
}

/// The paper's speeds: level sand is at the ceiling (only a lower bound); the other slopes are
/// bounded, and their medians reproduce the observed speed through `predict` (checked at 20 deg:
/// the model's speed at the median k_s is within one standard error of 4.98 cm/s).
#[test]
fn infer_paper_speeds_json() {
    let v = json(&["infer", "--observed", "../../data/paper-speeds.csv", "--json"]);
    let pts = v["points"].as_array().unwrap();
    assert_eq!(pts.len(), 5);
    assert_eq!((pts[0]["bounded"].as_bool(), pts[0]["bound"].as_str()), (Some(false), Some("lower_only")));
    for p in &pts[1..] {
        assert_eq!(p["bounded"], true, "{p}");
        let (q05, med, q95) = (
            p["k_s_q05"].as_f64().unwrap(),
            p["k_s_median"].as_f64().unwrap(),
            p["k_s_q95"].as_f64().unwrap(),
        );
        assert!(q05 < med && med < q95);
    }
    let k = pts[3]["k_s_median"].as_f64().unwrap().to_string();
    let pred = json(&["predict", "--slope", "20", "--k-s", &k, "--json"]);
    let speed = pred["speed_m_s"].as_f64().unwrap();
    assert!((speed - 0.0498).abs() < 0.0032, "{speed}");
    assert!(v["law"].is_null() && v["prediction"].as_array().unwrap().is_empty());
}

/// --law predicts at unobserved slopes with p_fail bands ordered q05 <= median <= q95, and the
/// risk rises with slope for the heavy robot; p_fail at the band's ends is risk's p_fail at those
/// k_s medians.
#[test]
fn infer_law_predicts_risk_with_a_band() {
    let v = json(&[
        "infer",
        "--observed",
        "../../examples/inference/walk-1kg.csv",
        "--mass",
        "1",
        "--law",
        "linear",
        "--predict",
        "18,22",
        "--cv-n",
        "0.1",
        "--cv-s",
        "0.2",
        "--json",
    ]);
    let pred = v["prediction"].as_array().unwrap();
    assert_eq!(pred.len(), 2);
    for p in pred {
        let f = &p["p_fail"];
        let (a, m, b) =
            (f["q05"].as_f64().unwrap(), f["median"].as_f64().unwrap(), f["q95"].as_f64().unwrap());
        assert!(a <= m && m <= b, "{p}");
        assert_eq!(p["observed"], false);
    }
    assert!(pred[1]["p_fail"]["median"].as_f64() > pred[0]["p_fail"]["median"].as_f64());
    let k = pred[1]["k_s"]["median"].as_f64().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let terrain =
        write(dir.path(), "t.toml", &format!("[[points]]\nslope_deg = 0.0\nk_n = 7e5\nk_s = {k}\n"));
    let risk = json(&[
        "risk",
        "--mass",
        "1",
        "--slope",
        "22",
        "--terrain",
        &terrain,
        "--cv-n",
        "0.1",
        "--cv-s",
        "0.2",
        "--json",
    ]);
    let want = risk["p_fail"].as_f64().unwrap();
    let got = pred[1]["p_fail"]["median"].as_f64().unwrap();
    assert!((got - want).abs() < 1e-9, "{got} vs {want}");
}

#[test]
fn infer_rejects_impossible_input_with_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let plot = dir.path().join("p.png");
    for (csv, extra, says) in [
        ("slope_deg,speed_m_s,speed_sd_m_s\n10,0.25,0.005\n", "", "above the model's ceiling"),
        (
            "slope_deg,speed_m_s,speed_sd_m_s\n10,0.1,0\n",
            "",
            "column speed_sd_m_s: 0 is outside the valid range",
        ),
        ("slope_deg,speed_m_s,speed_sd_m_s\n10,0.1,-0.01\n", "", "a standard deviation, greater than 0"),
        ("slope_deg,speed_m_s,speed_sd_m_s\n10,0.1,0.01\n", "--k-s-prior=1e6:1e5", "0 < MIN < MAX"),
        ("slope_deg,speed_m_s,speed_sd_m_s\n10,0.1,0.01\n", "--law=linear", "two or more slopes"),
        (
            "slope_deg,speed_m_s,speed_sd_m_s\n10,0.1,0.01\n10,0.11,0.01\n",
            "",
            "obs.csv: lines 2 and 3 both give slope_deg = 10",
        ),
    ] {
        let f = write(dir.path(), "obs.csv", csv);
        let mut cmd = sandslope();
        cmd.args(["infer", "--observed", &f, "--plot", plot.to_str().unwrap()]);
        if !extra.is_empty() {
            cmd.arg(extra);
        }
        cmd.assert().code(2).stderr(predicate::str::contains(says));
        assert!(!plot.exists(), "{csv}: partial output");
    }
}

/// Faster legs climb faster at the same safe-slope limit on the loose sand, so the front sits
/// at the largest leg speed varied: the table and the JSON say so, naming the key and value;
/// varying the hip height alone, whose best value (about 0.03 m) lies inside 0-0.06 m, gives
/// no such note.
#[test]
fn design_says_when_the_front_is_at_the_bound_of_vary() {
    let terrain = "examples/design/loose-sand.toml";
    let root = env!("CARGO_MANIFEST_DIR").to_string() + "/../../";
    let args = |vary: &str| {
        vec![
            "design".to_string(),
            "--terrain".into(),
            root.clone() + terrain,
            "--vary".into(),
            vary.into(),
            "--slope-target".into(),
            "15".into(),
        ]
    };
    let at_bound = args("hip_height_m=0.0:0.06:31,leg_speed_rad_s=4:12:9");
    sandslope().args(&at_bound).assert().success().stdout(
        predicate::str::contains("at the bound of --vary")
            .and(predicate::str::contains("leg_speed_rad_s = 12, the largest value")),
    );
    let mut with_json = at_bound.clone();
    with_json.push("--json".into());
    let v = json(&with_json.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(
        v["notes"].as_array().unwrap().iter().any(|n| n.as_str().unwrap().contains("leg_speed_rad_s = 12")),
        "{}",
        v["notes"]
    );
    sandslope()
        .args(args("hip_height_m=0.0:0.06:31"))
        .assert()
        .success()
        .stdout(predicate::str::contains("at the bound").not());
}
