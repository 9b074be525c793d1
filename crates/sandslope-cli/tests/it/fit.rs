//! `sandslope fit` end to end: recordings generated from known k_n and k_s (with noise,
//! offsets, transients, saturation and file defects) are fitted back; malformed inputs get
//! clear errors and no output file; the terrain written loads in `sandslope predict`.

use crate::common;
use common::sandslope;

use crate::synth;

use std::path::{Path, PathBuf};

use serde_json::Value;

use synth::{example_dataset, Dataset, GeneratedTrial};

fn example_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/measurements")
}

/// Runs `fit --json` on a dataset written to a temporary folder; returns the JSON.
fn fit_json(data: &Dataset, extra: &[&str]) -> (Value, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    data.write(dir.path()).unwrap();
    let out = sandslope()
        .arg("fit")
        .arg(dir.path().join("manifest.toml"))
        .args(["--counts-per-newton", "2000", "--json"])
        .args(extra)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    (serde_json::from_slice(&out.stdout).unwrap(), dir)
}

fn trial_json<'a>(json: &'a Value, file: &str) -> &'a Value {
    json["trials"].as_array().unwrap().iter().find(|t| t["file"] == file).unwrap()
}

fn point_json(json: &Value, slope: f64) -> &Value {
    json["points"].as_array().unwrap().iter().find(|p| p["slope_deg"].as_f64() == Some(slope)).unwrap()
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

fn sd(v: &[f64]) -> f64 {
    let m = v.iter().sum::<f64>() / v.len() as f64;
    (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() as f64 - 1.0)).sqrt()
}

#[test]
fn recovers_known_k_n_and_k_s_per_trial_and_reports_drops() {
    let data = example_dataset();
    let (json, _dir) = fit_json(&data, &[]);
    for t in data.trials.iter().filter(|t| !t.air) {
        let j = trial_json(&json, &t.file);
        // Every injected defect and every clipped sample is reported, exactly.
        let d = &j["dropped"];
        let tr = &t.truth;
        assert_eq!(d["blank"], tr.defects.blank, "{}", t.file);
        assert_eq!(d["non_finite"], tr.defects.nan, "{}", t.file);
        assert_eq!(d["duplicate"], tr.defects.duplicate, "{}", t.file);
        assert_eq!(d["reordered"], tr.defects.swapped, "{}", t.file);
        assert_eq!(d["saturated"], tr.saturated, "{}", t.file);
        assert_eq!(j["rows"], tr.rows, "{}", t.file);
        if t.kind == "penetration" {
            assert!(tr.saturated > 0, "the generator clips every penetration trial");
            // Sensor noise 0.02 N over >= 20 samples spanning >= 25 mm: SE <= 0.5% of k_n A;
            // the air drift left by a mean correction is 0.4 N/m, 0.2% of k_n A. 1.5% is 3 SE
            // plus that bias; a window that took the soft layer or the bed bottom is off by
            // more than 3% (see the library tests).
            let k = f(&j["k_n"]);
            assert!((k / tr.k - 1.0).abs() < 0.015, "{}: k_n {k} vs {}", t.file, tr.k);
            assert!(f(&j["r_squared"]) > 0.995, "{}", t.file);
            // The window must exclude the first 2 mm in air and the first half of the 3 mm
            // soft layer (from 3.5 mm the layer is within 0.08 N, 4 noise SDs on one sample, of
            // the line: at the limit of what the tests can see) and stop before the bed bottom
            // at 37 mm.
            let w = j["depth_window_m"].as_array().unwrap();
            assert!(f(&w[0]) >= 0.0035 && f(&w[1]) <= 0.037 + 1e-9, "{}: window {w:?}", t.file);
            assert!(f(&w[1]) - f(&w[0]) >= 0.02, "{}: window {w:?}", t.file);
        } else {
            // Granular fluctuations (2% of F_p, AR(1) with correlation 0.9) leave >= 3.8
            // independent samples on a 40 Hz plateau: SE of the mean <= 1%; the tail of the
            // rise inside the plateau biases by -0.33%. 4.5% = 4 SE + bias.
            let k = f(&j["k_s"]);
            assert!((k / tr.k - 1.0).abs() < 0.045, "{}: k_s {k} vs {}", t.file, tr.k);
            let p = j["plateau_m"].as_array().unwrap();
            // The rise reaches 90% at 2.3 x0 = 6.9 mm; noise and the running median may move
            // the crossing by two 80-Hz samples (1.25 mm), where the rise is still above 84%.
            assert!(f(&p[0]) >= 0.0056, "{}: plateau {p:?}", t.file);
            // The shear in-air runs drift by 0.4 N/m over 100 mm with 0.03 N of noise at 80 Hz:
            // the slope's SE is 0.03 / sqrt(161 * 0.1^2 / 12) = 0.082 N/m, t = 4.9, p < 1e-5:
            // the default subtracts the fitted line, and says so.
            assert_eq!(j["air_correction"], "trend", "{}", t.file);
            let notes = j["notes"].as_array().unwrap();
            assert!(notes.iter().any(|n| n.as_str().unwrap().contains("in-air run drifts by")), "{notes:?}");
            let trend = &j["air_trend"];
            assert!((f(&trend["slope_n_per_m"]) - 0.4).abs() < 4.0 * f(&trend["slope_se"]), "{trend}");
        }
    }
}

#[test]
fn per_slope_means_sds_and_interpolated_kind() {
    let data = example_dataset();
    let (json, _dir) = fit_json(&data, &[]);
    for slope in [0.0, 5.0, 10.0, 15.0, 20.0, 24.0] {
        let p = point_json(&json, slope);
        for (kind, key, tol) in [("penetration", "k_n", 0.01), ("shear", "k_s", 0.03)] {
            let trials: Vec<&GeneratedTrial> =
                data.trials.iter().filter(|t| !t.air && t.kind == kind && t.slope_deg == slope).collect();
            if trials.is_empty() {
                continue;
            }
            let truth: Vec<f64> = trials.iter().map(|t| t.truth.k).collect();
            let fitted: Vec<f64> = trials.iter().map(|t| f(&trial_json(&json, &t.file)[key])).collect();
            let mean_truth = truth.iter().sum::<f64>() / truth.len() as f64;
            // Mean of 3 trials: per-trial tolerance / sqrt(3), rounded up.
            assert!((f(&p[key]) / mean_truth - 1.0).abs() < tol, "{slope} {key}");
            // |sd(a) - sd(b)| <= sd(a - b) <= max|a - b| sqrt(n / (n - 1)) (triangle inequality).
            let max_err = truth.iter().zip(&fitted).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            let bound = max_err * (1.5f64).sqrt() + 1e-9;
            let spread = f(&p[format!("{key}_spread_sd")]);
            assert!((spread - sd(&truth)).abs() <= bound, "{slope} {key} sd");
            // The terrain's SD combines the spread with the trials' SEs: sqrt(s^2 + mean se^2).
            let ses: Vec<f64> =
                trials.iter().map(|t| f(&trial_json(&json, &t.file)[format!("{key}_se")])).collect();
            let se2 = ses.iter().map(|s| s * s).sum::<f64>() / ses.len() as f64;
            let combined = (spread * spread + se2).sqrt();
            assert!((f(&p[format!("{key}_sd")]) / combined - 1.0).abs() < 1e-12, "{slope} {key} combined sd");
            assert_eq!(p[format!("trials_{kind}")], trials.len());
        }
    }
    // 15 deg has no shear trials: k_s is halfway between the 10 and 20 deg means (linear in
    // degrees), and the point says so.
    let (p10, p15, p20) = (point_json(&json, 10.0), point_json(&json, 15.0), point_json(&json, 20.0));
    let mid = 0.5 * (f(&p10["k_s"]) + f(&p20["k_s"]));
    assert!((f(&p15["k_s"]) / mid - 1.0).abs() < 1e-12);
    assert_eq!(p15["trials_shear"], 0);
    let notes = p15["interpolated"].as_array().unwrap();
    assert_eq!(notes.len(), 1);
    assert!(notes[0].as_str().unwrap().contains("k_s interpolated between 10 and 20 deg"));
    // The paper's shape: k_s at 20 deg about 40% of level, k_n nearly constant.
    let ratio = f(&p20["k_s"]) / f(&point_json(&json, 0.0)["k_s"]);
    assert!((0.3..0.5).contains(&ratio), "{ratio}");
}

#[test]
fn terrain_file_loads_in_predict() {
    let dir = tempfile::tempdir().unwrap();
    let terrain = dir.path().join("fitted.toml");
    let out = sandslope()
        .arg("fit")
        .arg(example_dir().join("manifest.toml"))
        .args(["--counts-per-newton", "2000", "--out"])
        .arg(&terrain)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("pen-00-1.csv") && stdout.contains("k_s interpolated"), "{stdout}");
    let text = std::fs::read_to_string(&terrain).unwrap();
    let table: toml::Table = text.parse().unwrap();
    let points = table["points"].as_array().unwrap();
    assert_eq!(points.len(), 6);
    assert!(points[0].get("k_n_sd").is_some() && points[0].get("k_s_sd").is_some());
    assert_eq!(table["repose_deg"].as_float(), Some(25.0));
    // predict reads it and interpolates it by docs/model.md §7: at 12 deg, 40% of the way
    // from the 10 to the 15 deg point.
    let pred =
        sandslope().args(["predict", "--slope", "12", "--json", "--terrain"]).arg(&terrain).output().unwrap();
    assert!(pred.status.success(), "{}", String::from_utf8_lossy(&pred.stderr));
    let p: Value = serde_json::from_slice(&pred.stdout).unwrap();
    let k_s = |i: usize| points[i]["k_s"].as_float().unwrap();
    let expected = k_s(2) + 0.4 * (k_s(3) - k_s(2));
    assert!((f(&p["k_s"]) / expected - 1.0).abs() < 1e-9);
}

#[test]
fn user_windows_and_air_curve() {
    let data = example_dataset();
    let (json, _dir) =
        fit_json(&data, &["--depth-window", "0.008:0.030", "--plateau-from", "0.03", "--air-curve"]);
    let t = data.trials.iter().find(|t| t.file == "pen-05-1.csv").unwrap();
    let j = trial_json(&json, &t.file);
    assert_eq!(j["window"], "user");
    let w = j["depth_window_m"].as_array().unwrap();
    assert!(f(&w[0]) >= 0.008 && f(&w[1]) <= 0.030);
    assert!((f(&j["k_n"]) / t.truth.k - 1.0).abs() < 0.015);
    assert_eq!(j["air_correction"], "curve");
    let s = data.trials.iter().find(|t| t.file == "shear-05-1.csv").unwrap();
    let j = trial_json(&json, &s.file);
    assert!(f(&j["plateau_m"][0]) >= 0.03);
    assert!((f(&j["k_s"]) / s.truth.k - 1.0).abs() < 0.045);
}

#[test]
fn csv_output_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    let plots = dir.path().join("figs");
    let out = sandslope()
        .arg("fit")
        .arg(example_dir().join("manifest.toml"))
        .args(["--counts-per-newton", "2000", "--csv", "--plot"])
        .arg(&plots)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let csv = String::from_utf8_lossy(&out.stdout);
    assert!(csv.starts_with("slope_deg,k_n,k_n_sd,k_s,k_s_sd,trials_penetration,trials_shear,interpolated"));
    assert_eq!(csv.lines().count(), 7);
    for name in ["force-measurements", "penetration-force", "shear-force", "k_n-vs-slope", "k_s-vs-slope"] {
        let bytes = std::fs::read(plots.join(format!("{name}.png"))).unwrap();
        assert!(bytes.starts_with(b"\x89PNG") && bytes.len() > 10_000, "{name}");
    }
}

#[test]
fn example_dataset_is_what_the_generator_makes() {
    let dir = example_dir();
    let data = example_dataset();
    assert_eq!(std::fs::read_to_string(dir.join("manifest.toml")).unwrap(), data.manifest());
    for t in &data.trials {
        assert_eq!(std::fs::read_to_string(dir.join(&t.file)).unwrap(), t.csv, "{}", t.file);
    }
}

/// Rewrites `examples/measurements/` from the generator.
#[test]
#[ignore]
fn regenerate_example_dataset() {
    example_dataset().write(&example_dir()).unwrap();
}

// ---------------------------------------------------------------- malformed inputs

/// A small valid dataset (0 and 10 deg, one trial per kind) in a temp folder, modified by
/// `edit`, then fitted with `--out`: returns stderr, asserting exit code 2 and no output file.
fn fails(edit: impl FnOnce(&Path), extra: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let mut data = example_dataset();
    data.trials
        .retain(|t| (t.slope_deg == 0.0 || t.slope_deg == 10.0) && (t.air || t.file.ends_with("-1.csv")));
    data.write(dir.path()).unwrap();
    edit(dir.path());
    let out_file = dir.path().join("out.toml");
    let out = sandslope()
        .arg("fit")
        .arg(dir.path().join("manifest.toml"))
        .args(["--counts-per-newton", "2000", "--out"])
        .arg(&out_file)
        .args(extra)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "stdout: {}", String::from_utf8_lossy(&out.stdout));
    assert!(!out_file.exists(), "no output on error");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn replace_in(path: &Path, from: &str, to: &str) {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.contains(from), "{from} not in {}", path.display());
    std::fs::write(path, text.replacen(from, to, 1)).unwrap();
}

#[test]
fn the_small_dataset_itself_is_valid() {
    let dir = tempfile::tempdir().unwrap();
    let mut data = example_dataset();
    data.trials
        .retain(|t| (t.slope_deg == 0.0 || t.slope_deg == 10.0) && (t.air || t.file.ends_with("-1.csv")));
    data.write(dir.path()).unwrap();
    sandslope()
        .arg("fit")
        .arg(dir.path().join("manifest.toml"))
        .args(["--counts-per-newton", "2000"])
        .assert()
        .success();
}

#[test]
fn missing_force_column() {
    let e = fails(|d| replace_in(&d.join("pen-00-air.csv"), "force_n", "load"), &[]);
    assert!(e.contains("pen-00-air.csv") && e.contains("line 1") && e.contains("no force column"), "{e}");
    assert!(e.contains("found: depth_mm, load"), "{e}");
}

#[test]
fn unknown_unit() {
    let e = fails(|d| replace_in(&d.join("pen-00-air.csv"), "depth_mm", "depth_in"), &[]);
    assert!(e.contains("pen-00-air.csv: line 1, column 1: unknown unit `in`"), "{e}");
    assert!(e.contains("depth_m, depth_mm, depth_cm"), "{e}");
}

#[test]
fn empty_file() {
    let e = fails(|d| std::fs::write(d.join("shear-10-1.csv"), "").unwrap(), &[]);
    assert!(e.contains("shear-10-1.csv: empty file") && e.contains("displacement_mm"), "{e}");
}

#[test]
fn trial_file_does_not_exist() {
    let e = fails(|d| std::fs::remove_file(d.join("shear-00-1.csv")).unwrap(), &[]);
    assert!(e.contains("manifest.toml: [[trial]] #") && e.contains("(shear-00-1.csv)"), "{e}");
    assert!(e.contains("does not exist"), "{e}");
}

#[test]
fn manifest_without_penetration_trials() {
    let dir = tempfile::tempdir().unwrap();
    let mut data = example_dataset();
    data.trials.retain(|t| t.slope_deg == 0.0 && (t.kind == "shear" || t.air));
    data.write(dir.path()).unwrap();
    let out = sandslope().arg("fit").arg(dir.path().join("manifest.toml")).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("manifest.toml: no penetration trial (with air = false)") && e.contains("3 shear"),
        "{e}"
    );
}

#[test]
fn cell_that_is_not_a_number() {
    // Line 11 of a time_s,depth_mm,force_counts file: its third cell becomes `oops`.
    let e = fails(
        |d| {
            let path = d.join("pen-10-1.csv");
            let text = std::fs::read_to_string(&path).unwrap();
            let mut lines: Vec<String> = text.lines().map(String::from).collect();
            assert_eq!(lines[0], "time_s,depth_mm,force_counts");
            let cells: Vec<&str> = lines[10].split(',').collect();
            lines[10] = format!("{},{},oops", cells[0], cells[1]);
            std::fs::write(&path, lines.join("\n")).unwrap();
        },
        &[],
    );
    assert!(e.contains("pen-10-1.csv: line 11, column 3 (force_counts): `oops` is not a number"), "{e}");
}

#[test]
fn counts_without_factor() {
    // Remove --counts-per-newton by running without it on a counts file.
    let dir = tempfile::tempdir().unwrap();
    let mut data = example_dataset();
    data.trials.retain(|t| t.slope_deg == 0.0);
    data.write(dir.path()).unwrap();
    let out = sandslope().arg("fit").arg(dir.path().join("manifest.toml")).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("force_counts needs the load cell's counts per newton, from your calibration (--counts-per-newton; counts_per_newton= in Python)"), "{e}");
}

#[test]
fn unknown_manifest_key_and_bad_slope() {
    let e = fails(|d| replace_in(&d.join("manifest.toml"), "air = false", "air = false\nrepeat = 2"), &[]);
    assert!(e.contains("manifest.toml") && e.contains("line") && e.contains("repeat"), "{e}");
    let e = fails(|d| replace_in(&d.join("manifest.toml"), "slope_deg = 10.0", "slope_deg = 95.0"), &[]);
    assert!(e.contains("[[trial]] #") && e.contains("slope_deg = 95 must be between 0 and 90"), "{e}");
}

#[test]
fn bad_flags() {
    let e = fails(|_| {}, &["--depth-window", "0.03:0.01"]);
    assert!(e.contains("--depth-window `0.03:0.01` must be MIN:MAX"), "{e}");
    let e = fails(|_| {}, &["--plateau-from=-0.01"]);
    assert!(e.contains("--plateau-from = -0.01 must be a displacement in metres of at least 0"), "{e}");
    let dir = tempfile::tempdir().unwrap();
    let out = sandslope()
        .arg("fit")
        .arg(example_dir().join("manifest.toml"))
        .arg("--counts-per-newton=-3")
        .arg("--out")
        .arg(dir.path().join("t.toml"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr)
        .contains("--counts-per-newton = -3 must be a finite number greater than 0"));
    assert!(!dir.path().join("t.toml").exists());
}

#[test]
fn window_with_too_few_samples() {
    let e = fails(|_| {}, &["--depth-window", "0.0100:0.0101"]);
    assert!(e.contains("penetration trial at 0 deg") && e.contains("at least 3 needed"), "{e}");
}
