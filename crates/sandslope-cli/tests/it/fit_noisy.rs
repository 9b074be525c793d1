//! `fit` on realistic, noisy campaigns (issue 11): a 10 N load cell with 0.5% to 3% full-scale
//! noise, offsets near 0.3 N, an impact bump and a soft layer at the surface, clipping near
//! 10 N (exact or with the noise added after the clip), in-air drift, return strokes, depth in
//! m, cm or mm at 80 to 100 Hz. k_n and k_s must come back within 3% at every slope (the mean
//! of 3 trials), every window forced short must be flagged, and no other.

use crate::common;
use common::sandslope;

use crate::synth;

use std::path::Path;

use serde_json::Value;

use sandslope::measure::{fit_campaign, Campaign, FitOptions, Kind, Setup, TrialInput};
use sandslope_io::measurements::{load_manifest, read_recording_with, ReadOptions};
use synth::{linear_end, noisy_campaign, Dataset, PenetrationShape, Realism, NOISY_STROKE};

const ALL_SLOPES: [f64; 6] = [0.0, 5.0, 10.0, 15.0, 20.0, 24.0];

/// Writes a dataset and fits it in-process (the library call `fit` makes).
fn fit(data: &Dataset, dir: &Path, options: &FitOptions) -> Campaign {
    data.write(dir).unwrap();
    let manifest = load_manifest(&dir.join("manifest.toml")).unwrap();
    let read = ReadOptions { counts_per_newton: Some(synth::COUNTS_PER_NEWTON), skip_malformed: false };
    let trials: Vec<TrialInput> = manifest
        .trials
        .iter()
        .map(|t| {
            let rec = read_recording_with(&t.path, t.kind, read).unwrap();
            TrialInput {
                file: t.file.display().to_string(),
                kind: t.kind,
                slope_deg: t.slope_deg,
                air: t.air,
                rows: rec.rows,
                raw: rec.raw,
            }
        })
        .collect();
    let setup = Setup { disk_area_m2: manifest.disk_area_m2, plate: manifest.plate };
    fit_campaign(&trials, &setup, options).unwrap()
}

/// Largest relative error of the per-slope means against the mean of the true values.
fn worst_errors(data: &Dataset, c: &Campaign) -> (f64, f64) {
    let mut worst = (0.0f64, 0.0f64);
    for p in &c.points {
        for (kind, fitted, slot) in [("penetration", p.k_n.mean, 0), ("shear", p.k_s.mean, 1)] {
            let truth: Vec<f64> = data
                .trials
                .iter()
                .filter(|t| !t.air && t.kind == kind && t.slope_deg == p.slope_deg)
                .map(|t| t.truth.k)
                .collect();
            let mean = truth.iter().sum::<f64>() / truth.len() as f64;
            let err = (fitted / mean - 1.0).abs();
            if slot == 0 {
                worst.0 = worst.0.max(err);
            } else {
                worst.1 = worst.1.max(err);
            }
        }
    }
    worst
}

#[test]
fn k_n_and_k_s_within_3_percent_from_half_to_3_percent_noise() {
    // Why 3% holds at 3% noise: sigma = 0.3 N; the linear part runs from about 4 mm to the
    // clip near 45 mm at 80-100 Hz (0.5-0.625 mm per sample, 65-80 samples), so the SE of one
    // trial's slope is 0.3 / sqrt(70 * 0.041^2 / 12) = 2.8 N/m, 1.3% of k_n A = 220 N/m; the
    // mean of 3 trials 0.75%, and 3% is 4 of those. Two seeds at the highest noise.
    let dir = tempfile::tempdir().unwrap();
    for (noise_fs, seed) in [(0.005, 1), (0.01, 2), (0.02, 3), (0.03, 4), (0.03, 5)] {
        let r = Realism { noise_fs, seed, ..Realism::default() };
        let (data, _) = noisy_campaign(&r, &[]);
        let sub = dir.path().join(format!("n{seed}"));
        let c = fit(&data, &sub, &FitOptions::default());
        let (n, s) = worst_errors(&data, &c);
        eprintln!(
            "noise {:.1}% seed {seed}: worst k_n {:.2}%, k_s {:.2}%",
            noise_fs * 100.0,
            n * 100.0,
            s * 100.0
        );
        assert!(n < 0.03 && s < 0.03, "noise {noise_fs}: k_n {n}, k_s {s}");
        // No window here is forced short: the linear part is over 40 mm of the 50 mm stroke.
        for t in &c.trials {
            assert!(!t.warnings.iter().any(|w| w.code() == "short_window"), "{}: {:?}", t.file, t.warnings);
        }
    }
}

#[test]
fn return_strokes_and_drift_are_handled() {
    let r = Realism { noise_fs: 0.02, seed: 6, drift: 8.0, ..Realism::default() };
    let (data, shapes) = noisy_campaign(&r, &[]);
    let dir = tempfile::tempdir().unwrap();
    let c = fit(&data, dir.path(), &FitOptions::default());
    for ((g, shape), t) in data.trials.iter().zip(&shapes).zip(&c.trials) {
        assert_eq!(g.file, t.file);
        let back = if g.kind == "penetration" { shape.retraction && !g.air } else { false };
        if back {
            // Downstroke only: the return (as many rows as the downstroke less one) is dropped
            // and the note says so.
            assert!(t.dropped.retraction > 60, "{}: {:?}", t.file, t.dropped);
            assert!(t.notes.iter().any(|n| n.contains("downstroke only")), "{}: {:?}", t.file, t.notes);
            assert!(t.stroke_m.1 <= NOISY_STROKE + 1e-9);
        }
        if g.kind == "shear" && !g.air && t.dropped.retraction > 0 {
            assert!(t.notes.iter().any(|n| n.contains("forward drag only")), "{:?}", t.notes);
        }
        if !g.air {
            // Drift 8 N/m: over the 50 mm penetration air run (0.2 N noise, 101 samples) its SE
            // is 0.2 / sqrt(101 * 0.05^2 / 12) = 1.4 N/m, t = 5.8; over 100 mm of shear (0.6 N)
            // t = 8: significant in both, so the fitted in-air line is subtracted.
            assert_eq!(t.air_correction, "trend", "{}", t.file);
        }
    }
    // Shear trials of variant 2 include the return.
    assert!(c.trials.iter().any(|t| t.kind == Kind::Shear && t.dropped.retraction > 0));
    let (n, s) = worst_errors(&data, &c);
    assert!(n < 0.03 && s < 0.03, "k_n {n}, k_s {s}");
}

#[test]
fn windows_forced_short_are_flagged_and_only_those() {
    let r = Realism { noise_fs: 0.01, seed: 7, ..Realism::default() };
    let (data, shapes) = noisy_campaign(&r, &ALL_SLOPES);
    let dir = tempfile::tempdir().unwrap();
    let c = fit(&data, dir.path(), &FitOptions::default());
    let mut flagged = 0;
    for ((g, shape), t) in data.trials.iter().zip(&shapes).zip(&c.trials) {
        if g.air || g.kind != "penetration" {
            continue;
        }
        let short = shape.bottom < 0.02;
        let warned = t.warnings.iter().any(|w| w.code() == "short_window");
        assert_eq!(warned, short, "{}: {:?} window {:?}", t.file, t.warnings, t.window_m());
        flagged += usize::from(warned);
        if short {
            // The window stays inside the linear part that there is (before the bottom at 12 mm).
            let end = linear_end(g.truth.k, g.slope_deg, &r, shape);
            let w = t.window_m().unwrap();
            assert!(w.1 <= end + 0.001, "{}: {w:?} end {end}", t.file);
        }
    }
    assert_eq!(flagged, 6);
}

#[test]
fn an_outlier_trial_is_flagged_with_the_test_named() {
    let r = Realism { noise_fs: 0.01, seed: 8, ..Realism::default() };
    let (mut data, _) = noisy_campaign(&r, &[]);
    // Replace pen-10-2 with a trial of 40% higher k_n.
    let i = data.trials.iter().position(|t| t.file == "pen-10-2.csv").unwrap();
    let shape = PenetrationShape { bottom: 0.08, exact_clip: true, retraction: false };
    let k = data.trials[i].truth.k * 1.4;
    let (csv, truth) = synth::noisy_penetration(k, 10.0, &r, &shape, synth::Format::default(), 99);
    data.trials[i].csv = csv;
    data.trials[i].truth = truth;
    let dir = tempfile::tempdir().unwrap();
    let c = fit(&data, dir.path(), &FitOptions::default());
    let outliers: Vec<&str> = c
        .trials
        .iter()
        .filter(|t| t.warnings.iter().any(|w| w.code() == "outlier"))
        .map(|t| t.file.as_str())
        .collect();
    assert_eq!(outliers, vec!["pen-10-2.csv"]);
    let w = c.trials[i].warnings.iter().find(|w| w.code() == "outlier").unwrap().to_string();
    assert!(w.contains("modified z-score") && w.contains("MAD"), "{w}");
}

// ---------------------------------------------------------------- the shipped noisy example

fn noisy_example_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/measurements/noisy")
}

/// The campaign shipped in `examples/measurements/noisy/` (2% noise, the bed bottom at 12 mm in
/// `pen-10-3.csv`).
fn noisy_example() -> Dataset {
    noisy_campaign(&Realism { noise_fs: 0.02, seed: 42, ..Realism::default() }, &[10.0]).0
}

#[test]
fn noisy_example_is_what_the_generator_makes() {
    let dir = noisy_example_dir();
    let data = noisy_example();
    assert_eq!(std::fs::read_to_string(dir.join("manifest.toml")).unwrap(), data.manifest());
    for t in &data.trials {
        assert_eq!(std::fs::read_to_string(dir.join(&t.file)).unwrap(), t.csv, "{}", t.file);
    }
}

/// What docs/measurements.md says of the noisy example: per-slope means within 3% of the true
/// means, except k_n at 10 deg, pulled down by the trial whose window was forced short (and
/// flagged).
#[test]
fn noisy_example_as_documented() {
    let data = noisy_example();
    let dir = tempfile::tempdir().unwrap();
    let c = fit(&data, dir.path(), &FitOptions::default());
    for p in &c.points {
        for (kind, fitted) in [("penetration", p.k_n.mean), ("shear", p.k_s.mean)] {
            let truth: Vec<f64> = data
                .trials
                .iter()
                .filter(|t| !t.air && t.kind == kind && t.slope_deg == p.slope_deg)
                .map(|t| t.truth.k)
                .collect();
            let err = fitted / (truth.iter().sum::<f64>() / truth.len() as f64) - 1.0;
            eprintln!("{kind} {} deg: {:+.2}%", p.slope_deg, 100.0 * err);
            if kind == "penetration" && p.slope_deg == 10.0 {
                assert!(err < -0.03, "{err}");
            } else {
                assert!(err.abs() < 0.03, "{kind} {} deg: {err}", p.slope_deg);
            }
        }
    }
    let flagged: Vec<&str> =
        c.trials.iter().filter(|t| !t.warnings.is_empty()).map(|t| t.file.as_str()).collect();
    assert_eq!(flagged, vec!["pen-10-3.csv"]);
}

/// Rewrites `examples/measurements/noisy/` from the generator.
#[test]
#[ignore]
fn regenerate_noisy_example() {
    noisy_example().write(&noisy_example_dir()).unwrap();
}

// ---------------------------------------------------------------- the CLI on a noisy campaign

#[test]
fn skip_malformed_counts_rows_and_the_strict_default_names_the_column() {
    let r = Realism { noise_fs: 0.01, seed: 9, ..Realism::default() };
    let (data, _) = noisy_campaign(&r, &[]);
    let dir = tempfile::tempdir().unwrap();
    data.write(dir.path()).unwrap();
    // One malformed cell (`12x4`) in one of 48 files.
    let path = dir.path().join("pen-05-1.csv");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let header: Vec<String> = lines[0].split(',').map(String::from).collect();
    let force_col = header.iter().position(|h| h.starts_with("force")).unwrap();
    let mut cells: Vec<String> = lines[20].split(',').map(String::from).collect();
    cells[force_col] = "12x4".into();
    lines[20] = cells.join(",");
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    let manifest = dir.path().join("manifest.toml");
    let out = sandslope().arg("fit").arg(&manifest).args(["--counts-per-newton", "2000"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    let name = &header[force_col];
    assert!(
        e.contains(&format!(
            "pen-05-1.csv: line 21, column {} ({name}): `12x4` is not a number",
            force_col + 1
        )),
        "{e}"
    );
    assert!(e.contains("--skip-malformed"), "{e}");
    let out = sandslope()
        .arg("fit")
        .arg(&manifest)
        .args(["--counts-per-newton", "2000", "--skip-malformed", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json: Value = serde_json::from_slice(&out.stdout).unwrap();
    let trials = json["trials"].as_array().unwrap();
    for t in trials {
        let expected = if t["file"] == "pen-05-1.csv" { 1 } else { 0 };
        assert_eq!(t["dropped"]["malformed"], expected, "{}", t["file"]);
    }
    // A file where most rows are malformed: too few rows left, an error naming the file.
    let path = dir.path().join("shear-05-1.csv");
    let text = std::fs::read_to_string(&path).unwrap();
    let bad: String = text
        .lines()
        .enumerate()
        .map(|(i, l)| if i > 5 { format!("{l}x\n") } else { format!("{l}\n") })
        .collect();
    std::fs::write(&path, bad).unwrap();
    let out = sandslope()
        .arg("fit")
        .arg(&manifest)
        .args(["--counts-per-newton", "2000", "--skip-malformed"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("shear-05-1.csv") && e.contains("malformed (skipped)") && e.contains("at least 10 needed"),
        "{e}"
    );
}

#[test]
fn json_has_warnings_windows_and_combined_sds_and_air_mean_forces_the_mean() {
    let r = Realism { noise_fs: 0.02, seed: 10, ..Realism::default() };
    let (data, _) = noisy_campaign(&r, &ALL_SLOPES);
    let dir = tempfile::tempdir().unwrap();
    data.write(dir.path()).unwrap();
    let run = |extra: &[&str]| -> Value {
        let out = sandslope()
            .arg("fit")
            .arg(dir.path().join("manifest.toml"))
            .args(["--counts-per-newton", "2000", "--json"])
            .args(extra)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let json = run(&[]);
    let t = json["trials"].as_array().unwrap().iter().find(|t| t["file"] == "pen-10-3.csv").unwrap();
    let w = t["warnings"].as_array().unwrap();
    assert!(
        w.iter()
            .any(|w| w["code"] == "short_window"
                && w["message"].as_str().unwrap().contains("less than a third")),
        "{w:?}"
    );
    for key in ["k_n", "k_n_se", "r_squared", "residual_sd_n", "noise_sd_n", "depth_window_m", "stroke_m"] {
        assert!(!t[key].is_null(), "{key}");
    }
    let p = &json["points"][0];
    let (spread, se) = (p["k_n_spread_sd"].as_f64().unwrap(), p["k_n_se_rms"].as_f64().unwrap());
    assert!((p["k_n_sd"].as_f64().unwrap() - spread.hypot(se)).abs() < 1e-6 * spread.hypot(se));
    let json = run(&["--air-mean"]);
    assert!(json["trials"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|t| t["air"] == false)
        .all(|t| t["air_correction"] == "mean"));
}

#[test]
fn plot_folder_that_cannot_be_created_is_an_io_error_with_nothing_written() {
    let r = Realism { noise_fs: 0.01, seed: 11, ..Realism::default() };
    let (data, _) = noisy_campaign(&r, &[]);
    let dir = tempfile::tempdir().unwrap();
    data.write(dir.path()).unwrap();
    // A plot folder inside a regular file cannot be created.
    let blocker = dir.path().join("not-a-folder");
    std::fs::write(&blocker, "x").unwrap();
    let terrain = dir.path().join("t.toml");
    let out = sandslope()
        .arg("fit")
        .arg(dir.path().join("manifest.toml"))
        .args(["--counts-per-newton", "2000", "--out"])
        .arg(&terrain)
        .arg("--plot")
        .arg(blocker.join("figs"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(3), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot create plot folder"));
    assert!(!terrain.exists());
}

/// How often 3% noise misses the 3% target (run by hand: `--ignored --nocapture`).
#[test]
#[ignore]
fn failure_rate_at_3_percent_noise() {
    let dir = tempfile::tempdir().unwrap();
    let (mut worst_n, mut worst_s, mut fails) = (Vec::new(), Vec::new(), 0);
    for seed in 100..140 {
        let r = Realism { noise_fs: 0.03, seed, ..Realism::default() };
        let (data, _) = noisy_campaign(&r, &[]);
        let c = fit(&data, &dir.path().join(format!("s{seed}")), &FitOptions::default());
        let (n, s) = worst_errors(&data, &c);
        worst_n.push(n);
        worst_s.push(s);
        fails += usize::from(n >= 0.03 || s >= 0.03);
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    eprintln!(
        "40 campaigns at 3% noise: worst-slope error k_n mean {:.2}% max {:.2}%, k_s mean {:.2}% max {:.2}%; {fails} over 3%",
        100.0 * mean(&worst_n),
        100.0 * max(&worst_n),
        100.0 * mean(&worst_s),
        100.0 * max(&worst_s)
    );
}

#[test]
#[ignore]
fn trial_error_stats() {
    let dir = tempfile::tempdir().unwrap();
    for drift in [0.0, 2.0] {
        let mut errs = Vec::new();
        let mut ses = Vec::new();
        let mut starts = Vec::new();
        let mut ends = Vec::new();
        for seed in 200..212 {
            let r = Realism { noise_fs: 0.03, seed, drift, ..Realism::default() };
            let (data, shapes) = noisy_campaign(&r, &[]);
            let c = fit(&data, &dir.path().join(format!("d{drift}s{seed}")), &FitOptions::default());
            for ((g, t), sh) in data.trials.iter().zip(&c.trials).zip(&shapes) {
                if let Some(p) = t.penetration {
                    errs.push(p.k_n / g.truth.k - 1.0);
                    ses.push(p.k_n_se / g.truth.k);
                    starts.push(p.depth_window_m.0);
                    ends.push(p.depth_window_m.1 - linear_end(g.truth.k, g.slope_deg, &r, sh));
                }
            }
        }
        let m = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let sd = |v: &[f64]| {
            let mm = m(v);
            (v.iter().map(|x| (x - mm).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt()
        };
        eprintln!("drift {drift}: k_n err mean {:.3}% sd {:.3}% mean se {:.3}%, start {:.2} mm, end - linear end {:.2} mm (sd {:.2})",
            100.0 * m(&errs), 100.0 * sd(&errs), 100.0 * m(&ses), 1e3 * m(&starts), 1e3 * m(&ends), 1e3 * sd(&ends));
    }
}
