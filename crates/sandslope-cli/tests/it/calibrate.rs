//! End-to-end tests of `sandslope calibrate`: the joint fit's outputs (terrain, robot, figure,
//! JSON), the angle of repose carried over from the source terrain, and the refusals.

use crate::common;
use common::{json_of as json, repo_file, sandslope};

use predicates::prelude::*;

#[test]
fn calibrate_without_repose_carries_the_source_terrains_and_says_so() {
    // Issue 16: the written terrain must keep repose_deg = 25 of the default terrain, so that
    // `predict --slope 28` on it says slippage (beyond repose) as the source terrain does.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.toml");
    sandslope()
        .args(["calibrate", "--observed"])
        .arg(repo_file("data/paper-speeds.csv"))
        .arg("--out")
        .arg(&out)
        .assert()
        .success()
        .stdout(predicate::str::contains("repose_deg = 25 (carried over from --terrain glass-beads-300um)"));
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.contains("repose_deg = 25.0"), "{text}");
    let p = json(sandslope().args(["predict", "--slope", "28", "--json", "--terrain"]).arg(&out));
    assert_eq!(p["regime"], "slippage");
    // --repose still overrides, and per-slope carries it too.
    let v = json(
        sandslope()
            .args(["calibrate", "--law", "per-slope", "--json", "--observed"])
            .arg(repo_file("data/paper-speeds.csv"))
            .arg("--out")
            .arg(&out),
    );
    assert_eq!(v["repose"]["deg"], 25.0);
    assert_eq!(v["terrain"]["repose_deg"], 25.0);
}

#[test]
fn joint_calibration_writes_terrain_robot_plot_and_full_json() {
    let dir = tempfile::tempdir().unwrap();
    let (out, robot, plot) = (dir.path().join("t.toml"), dir.path().join("r.toml"), dir.path().join("c.png"));
    let v = json(
        sandslope()
            .args(["calibrate", "--json", "--observed"])
            .arg(repo_file("data/paper-speeds.csv"))
            .arg("--forces")
            .arg(repo_file("data/example-force-tests.toml"))
            .args(["--free", "plate_scale,error_floor,hip_height_m=0.02:0.06", "--out"])
            .arg(&out)
            .arg("--robot-out")
            .arg(&robot)
            .arg("--plot")
            .arg(&plot),
    );
    for key in [
        "parameters",
        "chi_squared",
        "dof",
        "chi_squared_per_dof",
        "pulls",
        "shear_ratio_20",
        "shear",
        "robot",
        "terrain",
        "warnings",
        "repose",
    ] {
        assert!(!v[key].is_null(), "missing {key}");
    }
    // 5 speeds + 2 force tests, 5 fitted quantities (3 freed, 2 plate values).
    assert_eq!(v["pulls"].as_array().unwrap().len(), 7);
    assert_eq!(v["dof"], 2);
    let names: Vec<&str> =
        v["parameters"].as_array().unwrap().iter().map(|p| p["name"].as_str().unwrap()).collect();
    assert!(names.contains(&"hip_height_m") && names.contains(&"k_s_plate(20 deg)"), "{names:?}");
    let h = v["parameters"].as_array().unwrap().iter().find(|p| p["name"] == "hip_height_m").unwrap();
    let (lo, val, hi) =
        (h["lower"].as_f64().unwrap(), h["value"].as_f64().unwrap(), h["upper"].as_f64().unwrap());
    assert!((0.02..=0.06).contains(&val) && lo <= val && val <= hi);
    // The plate force is k_s * 0.03 * 0.02^2 for every slope.
    for s in v["shear"].as_array().unwrap() {
        let (k, f) = (s["k_s"].as_f64().unwrap(), s["plate_force_n"].as_f64().unwrap());
        assert!((f - k * 1.2e-5).abs() < 1e-9 * f.max(1.0));
    }
    // The robot file loads and holds the fitted hip height; the terrain loads.
    let r: toml::Value = toml::from_str(&std::fs::read_to_string(&robot).unwrap()).unwrap();
    assert!((r["hip_height_m"].as_float().unwrap() - val).abs() < 1e-12);
    sandslope()
        .args(["predict", "--slope", "10", "--robot"])
        .arg(&robot)
        .arg("--terrain")
        .arg(&out)
        .assert()
        .success();
    assert_eq!(&std::fs::read(&plot).unwrap()[..8], b"\x89PNG\r\n\x1a\n");
}

#[test]
fn calibrate_refuses_bad_free_lists_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.toml");
    let run = |extra: &[&str], needle: &str| {
        sandslope()
            .args(["calibrate", "--observed"])
            .arg(repo_file("data/paper-speeds.csv"))
            .arg("--out")
            .arg(&out)
            .args(extra)
            .assert()
            .code(2)
            .stderr(predicate::str::contains(needle));
        assert!(!out.exists(), "{extra:?} wrote output");
    };
    run(&["--free", "stance_legs"], "unknown quantity `stance_legs`");
    run(&["--free", "hip_height_m=0.01"], "MIN:MAX");
    run(&["--free", "hip_height_m=0.05:0.01"], "min < max");
    run(&["--free", "plate_scale"], "plate_scale needs force tests");
    run(&["--free", "error_floor", "--error-floor", "0.01"], "give one of them");
    run(&["--robot-out", "r.toml"], "no robot key is in --free");
    run(&["--plot", "x.gif"], ".png or .svg");
    // An unwritable plot folder: checked before any file is written.
    let missing = dir.path().join("nope").join("c.png");
    sandslope()
        .args(["calibrate", "--observed"])
        .arg(repo_file("data/paper-speeds.csv"))
        .arg("--out")
        .arg(&out)
        .arg("--plot")
        .arg(&missing)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("does not exist"));
    assert!(!out.exists());
}

#[test]
fn anchoring_times_alone_calibrate_k_s() {
    // t1 observations made by the model itself on a terrain with k_s 2e6 at 0 and 1e6 at 20 deg
    // (linear law, rho = 0.5): 0 deg t1 = 11.0361 ms (docs/model.md worked example, k_n 7e5);
    // the others computed with `predict` below, then fitted back.
    let dir = tempfile::tempdir().unwrap();
    let terrain = dir.path().join("truth.toml");
    std::fs::write(
        &terrain,
        "repose_deg = 25.0\n[[points]]\nslope_deg = 0.0\nk_n = 7e5\nk_s = 2e6\n[[points]]\nslope_deg = 20.0\nk_n = 7e5\nk_s = 1e6\n",
    )
    .unwrap();
    let mut rows = String::from("slope_deg,t1_s,t1_sd_s\n");
    for d in ["0", "10", "20"] {
        let p = json(sandslope().args(["predict", "--slope", d, "--json", "--terrain"]).arg(&terrain));
        rows.push_str(&format!("{d},{},0.002\n", p["t1_s"].as_f64().unwrap()));
    }
    assert!(rows.contains("\n0,0.01103"), "{rows}");
    let t1 = dir.path().join("t1.csv");
    std::fs::write(&t1, rows).unwrap();
    let out = dir.path().join("fit.toml");
    let v = json(
        sandslope().args(["calibrate", "--json", "--k-n", "7e5", "--t1"]).arg(&t1).arg("--out").arg(&out),
    );
    let ratio = v["shear_ratio_20"]["value"].as_f64().unwrap();
    assert!((ratio - 0.5).abs() < 1e-3, "{ratio}");
    let k0 = v["parameters"].as_array().unwrap().iter().find(|p| p["name"] == "k_s0").unwrap()["value"]
        .as_f64()
        .unwrap();
    assert!((k0 / 2e6 - 1.0).abs() < 1e-3, "{k0}");
}

/// `--model simulate` (issue 23): one observed speed, force tests used exactly, only the error
/// floor free. The simulator's model speed is what `simulate` gives for the same robot, ground
/// and the fit's walk setting (4 s at T / 500, 2 ms for the paper's robot of T = 1 s); with one speed the best floor solves
/// `sd^2 + f^2 = (observed - model)^2` (docs/calibration.md), so f is worked out from that
/// speed alone; the closed form's fit is printed beside it. Refusals exit 2 naming the flag.
#[test]
fn model_simulate_fits_the_walks_and_shows_the_closed_form_beside() {
    let dir = tempfile::tempdir().unwrap();
    let forces = common::write_arg(
        dir.path(),
        "forces.toml",
        "repose_deg = 25.0\n[[points]]\nslope_deg = 0.0\nk_n = 7.0e5\nk_s = 1.0e5\n",
    );
    let observed =
        common::write_arg(dir.path(), "v.csv", "slope_deg,speed_m_s,speed_sd_m_s\n0,0.157,0.0097\n");
    let out = dir.path().join("t.toml");
    let args = |extra: &[&str]| {
        let mut c = sandslope();
        c.args(["calibrate", "--model", "simulate", "--forces", &forces, "--observed", &observed, "--out"])
            .arg(&out)
            .args(extra);
        c
    };
    let v = json(&mut args(&["--free", "error_floor=0:0.5", "--json"]));
    assert_eq!(v["model"]["kind"], "simulator");
    assert_eq!(v["model"]["settings"]["duration_s"], 4.0);
    assert_eq!(v["walks"], 1);
    let walk = json(
        sandslope()
            .args(["simulate", "--slope", "0", "--duration", "4", "--dt", "0.002", "--json", "--terrain"])
            .arg(&forces),
    );
    let model = v["pulls"][0]["model"].as_f64().unwrap();
    assert_eq!(model, walk["speed_m_s"].as_f64().unwrap());
    let r: f64 = 0.157 - model;
    let f = (r * r - 0.0097f64 * 0.0097).max(0.0).sqrt();
    // Within 0.2%: with the simulator the optimiser stops at a relative change of 1e-6 in -2 ln L,
    // which leaves about sqrt(1e-6) = 1e-3 in a parameter at a smooth minimum.
    let fitted = v["error_floor_m_s"].as_f64().unwrap();
    assert!((fitted - f).abs() < 2e-3 * f, "{fitted} vs {f}");
    let cf = &v["closed_form_fit"];
    assert_eq!(cf["model"]["kind"], "closed_form");
    assert!(cf["pulls"][0]["model"].as_f64().unwrap() != model);
    // The tables print both fits side by side.
    args(&["--free", "error_floor"])
        .assert()
        .success()
        .stdout(predicate::str::contains("closed form").and(predicate::str::contains("simulator")));
    // (The floor is bounded to 0.5 m/s: the default bound 0.1 m/s is below what this walk needs.)
    // Refusals: exit 2, naming the flag, nothing written.
    std::fs::remove_file(&out).unwrap();
    args(&["--free", "response_time_s"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("response_time_s").and(predicate::str::contains("simulator")));
    args(&["--law", "per-slope"]).assert().code(2).stderr(predicate::str::contains("--law per-slope"));
    assert!(!out.exists());
}
