//! Every `sandslope` command the README, docs/*.md and examples/*/README.md show, run as written
//! (issue 28): each fenced block's commands go to `sh` unchanged, with this build's `sandslope`
//! first on PATH. Each document runs in a fresh scratch folder holding copies of `data/`,
//! `examples/` and the GDAL fixtures, its blocks in order (a later block may use what an earlier
//! one wrote), plus the files a reader of the README has made by then and other docs use:
//! `my-robot.toml` and `my-sand.toml`, made by the README's own commands.
//!
//! A doc command that fails, or that names a file no step makes, fails this test with the
//! command (`sh -x`) and its stderr. What is not run is listed in `SKIPPED` with the reason, and
//! each entry must still match a command in the docs (no stale exceptions).
//!
//! The output a `console` block shows under a command is checked too: every line shown must
//! be a line the command prints now (issue 27: every number the docs quote regenerated).
//!
//! The README's placeholders for a reader's own recordings (`runs/10deg-*.csv`,
//! `runs/15deg-a.csv`, ...) are made from the example recordings and from `sandslope simulate
//! --out`, the only inputs this test provides that the docs do not.

use crate::common;

use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Duration;

/// Wall time one documented block may take before it counts as hung: the debug build's
/// `simulate --animate` took over 120 s on this 2-core machine under a load average of 10.
const BLOCK_TIMEOUT_S: u64 = 600;

use common::repo_file;

/// Commands that are not run, by their first words, and why.
const SKIPPED: &[(&str, &str)] = &[
    ("sandslope serve", "runs until stopped (and --open starts a browser); tests/serve.rs covers it"),
    ("cargo run", "the same `report --out report/` the README shows as `sandslope report` below it"),
    ("bash scripts/test.sh", "the whole test suite, this test included"),
    ("pip install", "installs the Python package; scripts/test.sh does"),
    ("python -c", "Python: crates/sandslope-py/tests/test_docs_examples.py runs it"),
    ("python3 bench/", "a benchmark against NumPy, minutes long; run by hand"),
    ("curl ", "needs a running `sandslope serve`; tests/serve.rs calls every endpoint"),
    (
        "sandslope drive --port",
        "needs a robot on a serial port; tests/drive.rs drives the emulator through the same code",
    ),
];

/// One fenced code block: where it is, its language tag and its text.
struct Block {
    file: String,
    line: usize,
    lang: String,
    body: String,
}

fn blocks(rel: &str) -> Vec<Block> {
    let text = std::fs::read_to_string(repo_file(rel)).unwrap();
    let mut out = Vec::new();
    let mut open: Option<Block> = None;
    for (i, line) in text.lines().enumerate() {
        if let Some(rest) = line.strip_prefix("```") {
            match open.take() {
                Some(b) => out.push(b),
                None => {
                    open = Some(Block {
                        file: rel.into(),
                        line: i + 1,
                        lang: rest.trim().into(),
                        body: String::new(),
                    })
                }
            }
        } else if let Some(b) = open.as_mut() {
            b.body.push_str(line);
            b.body.push('\n');
        }
    }
    assert!(open.is_none(), "{rel}: a code block is not closed");
    out
}

/// The logical command lines of a block (continuation lines joined), without comments, in the
/// order shown. `sh` blocks are scripts; in `console` blocks only lines starting with `$ ` are
/// commands (the rest is their output); other blocks (`text`, `toml`, ...) have none. An
/// untagged block is refused: it would be ambiguous.
fn commands(b: &Block) -> Vec<String> {
    assert!(!b.lang.is_empty(), "{}:{}: tag the code block (sh, console, text, ...)", b.file, b.line);
    let script = matches!(b.lang.as_str(), "sh" | "bash");
    if !script && b.lang != "console" {
        return Vec::new();
    }
    let mut out = Vec::new();
    let mut lines = b.body.lines();
    while let Some(line) = lines.next() {
        let line = line.trim_end();
        let cmd = if script {
            line.trim_start()
        } else if let Some(c) = line.strip_prefix("$ ") {
            c
        } else {
            continue;
        };
        if cmd.is_empty() || cmd.starts_with('#') {
            continue;
        }
        let mut full = cmd.to_string();
        while full.ends_with('\\') {
            full.pop();
            match lines.next() {
                Some(next) => full.push_str(next.trim_end()),
                None => break,
            }
        }
        out.push(full);
    }
    out
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let dest = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_dir(&entry.path(), &dest);
        } else {
            std::fs::copy(entry.path(), dest).unwrap();
        }
    }
}

/// Runs `script` with `sh -ex` in `dir`, this build's `sandslope` first on PATH; panics with
/// `what`, the trace and stderr if it fails or takes more than two minutes.
fn run(dir: &Path, script: &str, what: &str) {
    let bin = Path::new(env!("CARGO_BIN_EXE_sandslope"));
    let path = format!("{}:{}", bin.parent().unwrap().display(), std::env::var("PATH").unwrap_or_default());
    let out = assert_cmd::Command::new("sh")
        .args(["-exc", script])
        .current_dir(dir)
        .env("PATH", path)
        .timeout(Duration::from_secs(BLOCK_TIMEOUT_S))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{what} failed ({}):\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A scratch folder as a reader of the docs has it: copies of `data/`, `examples/` and the
/// GDAL and PDS3 fixtures, and the files the README's commands make.
fn scratch_seed() -> tempfile::TempDir {
    let template = tempfile::tempdir().unwrap();
    let seed = template.path();
    copy_dir(&repo_file("data"), &seed.join("data"));
    copy_dir(&repo_file("examples"), &seed.join("examples"));
    for fixtures in ["gdal", "pds3"] {
        copy_dir(
            &repo_file(&format!("crates/sandslope-io/tests/fixtures/{fixtures}")),
            &seed.join(format!("crates/sandslope-io/tests/fixtures/{fixtures}")),
        );
    }
    std::fs::create_dir_all(seed.join("docs/figures")).unwrap();
    run(
        seed,
        // The README's commands that make the reader's robot and terrain files.
        "sandslope presets show paper-hexapod > my-robot.toml
         sandslope fit examples/measurements/manifest.toml --counts-per-newton 2000 --out my-sand.toml
         # the README's stand-ins for a reader's own recordings
         mkdir -p runs
         cp examples/tracking/slope10-motive123.csv runs/10deg-a.csv
         cp examples/tracking/slope20-motive125.csv runs/20deg-a.csv
         cp examples/tracking/slope20-vicon.csv runs/20deg-b.csv
         sandslope simulate --slope 15 --out runs/15deg-a.csv
         sandslope simulate --slope 15 --duration 8 --out runs/15deg-b.csv",
        "making the reader's files",
    );

    template
}

/// The README, docs/*.md and examples/*/README.md, in that order.
fn doc_files() -> Vec<String> {
    let mut files = vec!["README.md".to_string()];
    for folder in ["docs", "examples"] {
        let mut more: Vec<String> = std::fs::read_dir(repo_file(folder))
            .unwrap()
            .map(|e| e.unwrap().path())
            .flat_map(|p| if p.is_dir() { vec![p.join("README.md")] } else { vec![p] })
            .filter(|p| p.is_file() && p.extension().is_some_and(|e| e == "md"))
            .map(|p| format!("{folder}/{}", p.strip_prefix(repo_file(folder)).unwrap().display()))
            .collect();
        more.sort();
        files.extend(more);
    }
    files
}

/// The emulated drives the docs show run here on the emulator's virtual clock (docs/drive.md,
/// "The emulator's clock"): `sandslope drive --emulate ...` gets `--emulate-clock virtual`
/// after `--emulate`, unless the command names a clock or serves a pty (which refuses it). On
/// the wall's clock the README's, docs/commands.md's, docs/drive.md's and docs/bags.md's five
/// drives waited out 29 s of gait, and on a loaded machine the README's missed its cycles (its
/// servos' Bus Watchdog fired at t = 1.0 s, load 12, 2026-12-07). The docs keep showing what a
/// user types; tests/drive.rs and tests/foxglove_live.rs test the real loop.
fn on_the_virtual_clock(cmd: String) -> String {
    const DRIVE: &str = "sandslope drive --emulate ";
    if cmd.starts_with(DRIVE) && !cmd.contains("--emulate-clock") && !cmd.contains("--pty") {
        format!("{}--emulate-clock virtual {}", DRIVE, &cmd[DRIVE.len()..])
    } else {
        cmd
    }
}

/// Runs every block of `file` that holds a `sandslope` command, in a fresh copy of `seed`;
/// counts the commands run and marks the `SKIPPED` entries used.
fn run_document(seed: &Path, file: &str, ran: &AtomicUsize, skips_used: &[AtomicBool]) {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    copy_dir(seed, root);
    for b in blocks(file) {
        let mut script = Vec::new();
        for cmd in commands(&b) {
            if let Some(i) = SKIPPED.iter().position(|(start, _)| cmd.starts_with(start)) {
                skips_used[i].store(true, Ordering::Relaxed);
                continue;
            }
            if cmd.starts_with("sandslope ") {
                ran.fetch_add(1, Ordering::Relaxed);
            }
            script.push(on_the_virtual_clock(cmd));
        }
        if script.iter().any(|c| c.starts_with("sandslope ")) {
            run(root, &script.join("\n"), &format!("the block at {}:{}", b.file, b.line));
        }
    }
    if file == "docs/tracking.md" {
        the_example_reports_diagnosis_is_what_the_docs_say(root);
    }
}

/// docs/tracking.md's report on the example recordings: the slopes the calibration's
/// diagnosis names and the numbers the doc (and docs/commands.md, and docs/calibration.md) quote from
/// it, read from the report.json its command wrote.
fn the_example_reports_diagnosis_is_what_the_docs_say(root: &Path) {
    let json =
        std::fs::read_to_string(root.join("report/report.json")).expect("docs/tracking.md writes report/");
    let r: serde_json::Value = serde_json::from_str(&json).unwrap();
    let d = &r["fit_diagnosis"];
    let c = d["contradictions"].as_array().expect("the example's fit is diagnosed");
    let slopes: Vec<f64> = c.iter().map(|c| c["slope_deg"].as_f64().unwrap()).collect();
    assert_eq!(slopes, [10.0, 20.0], "{d}");
    let flat = |rel: &str| {
        std::fs::read_to_string(repo_file(rel)).unwrap().split_whitespace().collect::<Vec<_>>().join(" ")
    };
    let (tracking, calibration, commands) =
        (flat("docs/tracking.md"), flat("docs/calibration.md"), flat("docs/commands.md"));
    let cm = |v: &serde_json::Value| 100.0 * v.as_f64().unwrap();
    let at10 = format!("{:.1} ± {:.1} cm", cm(&c[0]["model_step_m"]), cm(&c[0]["model_step_sd_m"]));
    let at20 = format!("{:.1} ± {:.1} cm", cm(&c[1]["model_step_m"]), cm(&c[1]["model_step_sd_m"]));
    let no_floor = &r["calibration"]["no_floor"];
    let chi = format!("χ² = {:.0} on {}", no_floor["chi_squared"].as_f64().unwrap(), no_floor["dof"]);
    let t1 = format!("t1 = {:.0} ms", 1e3 * c[1]["t1_s"].as_f64().unwrap());
    for (text, name, wanted) in [
        (&tracking, "docs/tracking.md", vec![&at10, &at20, &chi]),
        (&calibration, "docs/calibration.md", vec![&at20, &t1]),
    ] {
        for w in wanted {
            assert!(text.contains(w.as_str()), "{name} should quote `{w}` from the example report");
        }
    }
    let step20 = format!("step at 20° is {:.1} cm", cm(&c[1]["model_step_m"]));
    assert!(
        commands.contains(&step20) && commands.contains(&t1),
        "docs/commands.md should quote `{step20}` and `{t1}`"
    );
}

/// The documents run on one worker per core, each taking the next document when it is done:
/// the test ran them one after another in 166 s of CI's 10 minutes (418 s under load), one
/// core idle. Each document has its own scratch folder, so they cannot meet.
#[test]
fn every_command_in_the_readme_and_docs_runs_as_written() {
    let files = doc_files();

    let template = scratch_seed();
    let seed = template.path();

    let ran = AtomicUsize::new(0);
    let skips_used: Vec<AtomicBool> = SKIPPED.iter().map(|_| AtomicBool::new(false)).collect();
    let next = AtomicUsize::new(0);
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get()).clamp(1, files.len().max(1));
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| {
                while let Some(file) = files.get(next.fetch_add(1, Ordering::Relaxed)) {
                    let start = std::time::Instant::now();
                    run_document(seed, file, &ran, &skips_used);
                    eprintln!("{file}: {:.1} s", start.elapsed().as_secs_f64());
                }
            });
        }
    });
    let ran = ran.into_inner();
    eprintln!("{ran} sandslope commands from {} documents ran as written", files.len());
    // Guards against a parser that finds nothing: the docs show more than 50 commands.
    assert!(ran >= 50, "only {ran} sandslope commands found in {files:?}");
    for ((start, why), used) in SKIPPED.iter().zip(skips_used) {
        assert!(
            used.into_inner(),
            "SKIPPED lists `{start}` ({why}) but no doc shows such a command any more"
        );
    }
}

/// A `console` block's commands with the output the doc shows under each.
fn transcripts(b: &Block) -> Vec<(String, Vec<String>)> {
    let mut out: Vec<(String, Vec<String>)> = Vec::new();
    let mut lines = b.body.lines();
    while let Some(line) = lines.next() {
        if let Some(cmd) = line.strip_prefix("$ ") {
            let mut full = cmd.trim_end().to_string();
            while full.ends_with('\\') {
                full.pop();
                match lines.next() {
                    Some(next) => full.push_str(next.trim_end()),
                    None => break,
                }
            }
            out.push((full, Vec::new()));
        } else if let Some((_, shown)) = out.last_mut() {
            if !line.trim().is_empty() {
                shown.push(line.trim_end().to_string());
            }
        }
    }
    out
}

/// Issue 27: every number the docs quote is regenerated. The output a `console` block shows
/// under a `$ sandslope ...` line (docs/design.md's Pareto front, docs/inference.md's posteriors
/// and predictions) is what the command prints now: every line shown is a line of its stdout or
/// stderr, in the same scratch folder as the docs-examples test.
#[test]
fn console_transcripts_in_the_docs_are_what_the_commands_print() {
    let seed = scratch_seed();
    let bin = Path::new(env!("CARGO_BIN_EXE_sandslope"));
    let path = format!("{}:{}", bin.parent().unwrap().display(), std::env::var("PATH").unwrap_or_default());
    let mut checked = 0;
    for file in doc_files() {
        if !blocks(&file).iter().any(|b| b.lang == "console") {
            continue;
        }
        let dir = tempfile::tempdir().unwrap();
        copy_dir(seed.path(), dir.path());
        for b in blocks(&file).iter().filter(|b| b.lang == "console") {
            for (cmd, shown) in transcripts(b) {
                if !cmd.starts_with("sandslope ") {
                    continue;
                }
                let out = assert_cmd::Command::new("sh")
                    .args(["-c", &cmd])
                    .current_dir(dir.path())
                    .env("PATH", &path)
                    .timeout(Duration::from_secs(BLOCK_TIMEOUT_S))
                    .output()
                    .unwrap();
                assert!(out.status.success(), "{}:{}: `{cmd}` failed", b.file, b.line);
                let printed: Vec<String> = String::from_utf8_lossy(&out.stdout)
                    .lines()
                    .chain(String::from_utf8_lossy(&out.stderr).lines())
                    .map(|l| l.trim_end().to_string())
                    .collect();
                for line in &shown {
                    assert!(
                        printed.contains(line),
                        "{}:{}: `{cmd}` no longer prints the line the doc shows:\n{line}\nit prints:\n{}",
                        b.file,
                        b.line,
                        printed.join("\n")
                    );
                    checked += 1;
                }
            }
        }
    }
    // Guards against a parser that finds nothing: design.md and inference.md show 40+ lines.
    assert!(checked >= 40, "only {checked} transcript lines found");
}
