//! Hostile surroundings (issue 21): outputs through symbolic links, into devices and FIFOs, to
//! a full disk; runs that fail after writing some outputs, and runs that are killed. Each test
//! fails on the tool as it was before the output module (links and FIFOs were replaced by
//! regular files, `> /dev/full` panicked with exit 101, a failed run kept its earlier outputs,
//! a killed run left its temporary file).

use std::io::Read;
use std::os::unix::fs::FileTypeExt;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn sandslope() -> Command {
    Command::new(env!("CARGO_BIN_EXE_sandslope"))
}

fn repo_file(rel: &str) -> String {
    format!("{}/../../{rel}", env!("CARGO_MANIFEST_DIR"))
}

/// Names in `dir`, sorted (hidden temporary files included).
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn an_output_through_a_symlink_replaces_the_target_and_keeps_the_link() {
    let dir = tempfile::tempdir().unwrap();
    let real = dir.path().join("real.svg");
    std::fs::write(&real, "old").unwrap();
    let link = dir.path().join("link.svg");
    std::os::unix::fs::symlink("real.svg", &link).unwrap();
    let out = sandslope()
        .args(["sweep", "--from", "0", "--to", "5", "--step", "1", "--plot"])
        .arg(&link)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink(), "the link was replaced");
    assert!(std::fs::read_to_string(&real).unwrap().contains("<svg"), "the target was not written");
    assert_eq!(names(dir.path()), ["link.svg", "real.svg"]);
}

#[test]
fn an_output_into_a_device_writes_into_it_and_leaves_it_a_device() {
    // A link to /dev/null: before, the link was replaced by a regular file (and `--out
    // /dev/null` as root replaced the machine's /dev/null). This test never touches /dev/null
    // itself, whatever the tool does.
    let dir = tempfile::tempdir().unwrap();
    let link = dir.path().join("null.toml");
    std::os::unix::fs::symlink("/dev/null", &link).unwrap();
    let out = sandslope()
        .args(["calibrate", "--observed", &repo_file("data/paper-speeds.csv"), "--out"])
        .arg(&link)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    assert!(std::fs::metadata("/dev/null").unwrap().file_type().is_char_device());
    assert_eq!(names(dir.path()), ["null.toml"]);
}

#[test]
fn an_output_into_a_fifo_is_read_from_the_fifo() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("pipe.toml");
    let status = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(status.success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || {
            let mut text = String::new();
            std::fs::File::open(&fifo).unwrap().read_to_string(&mut text).unwrap();
            text
        })
    };
    let out = sandslope()
        .args(["calibrate", "--observed", &repo_file("data/paper-speeds.csv"), "--out"])
        .arg(&fifo)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = reader.join().unwrap();
    assert!(text.contains("k_s"), "the FIFO's reader got: {text}");
    assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo(), "the FIFO was replaced");
}

#[test]
fn a_full_disk_on_stdout_exits_3_with_one_line() {
    if !Path::new("/dev/full").exists() {
        eprintln!("skipped: no /dev/full on this system");
        return;
    }
    for format in [None, Some("--json"), Some("--csv")] {
        let mut cmd = sandslope();
        cmd.args(["sweep", "--from", "0", "--to", "30", "--step", "0.5"]);
        if let Some(f) = format {
            cmd.arg(f);
        }
        let out = cmd.stdout(std::fs::File::create("/dev/full").unwrap()).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(3), "{format:?}: {err}");
        assert!(!err.contains("panicked"), "{format:?}: {err}");
        let errors: Vec<&str> = err.lines().filter(|l| !l.starts_with("warning:")).collect();
        assert!(err.contains("standard output") && errors.len() <= 2, "{format:?}: {err}");
    }
}

#[test]
fn a_run_that_fails_after_writing_an_output_leaves_none() {
    // calibrate writes --out, then --robot-out fails (its folder does not exist): before, the
    // terrain file stayed.
    let dir = tempfile::tempdir().unwrap();
    let terrain = dir.path().join("t.toml");
    let out = sandslope()
        .args([
            "calibrate",
            "--observed",
            &repo_file("data/paper-speeds.csv"),
            "--free",
            "hip_height_m",
            "--out",
        ])
        .arg(&terrain)
        .arg("--robot-out")
        .arg(dir.path().join("missing").join("r.toml"))
        .output()
        .unwrap();
    assert_ne!(out.status.code(), Some(0));
    assert_eq!(names(dir.path()), Vec::<String>::new(), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn a_report_that_fails_leaves_no_folder_or_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = sandslope()
        .args(["report", "--out"])
        .arg(dir.path().join("new").join("report"))
        .args(["--observed", "/no/such/speeds.csv"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(names(dir.path()), Vec::<String>::new());
}

#[test]
fn a_killed_run_leaves_no_temporary_file() {
    // 2048 x 2048 cells of phase arrays: long enough (in a debug build) to be killed while
    // writing. Waits for the temporary file to appear, then sends SIGTERM.
    let dir = tempfile::tempdir().unwrap();
    let npy = dir.path().join("npy");
    let mut child = sandslope()
        .args(["phase", "--slope", "0,10,20,24", "--k-n", "1e4:1e7:2048", "--k-s", "1e3:1e8:2048", "--npy"])
        .arg(&npy)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let started = Instant::now();
    let mut saw_temp = false;
    while started.elapsed() < Duration::from_secs(60) {
        if npy.is_dir() && names(&npy).iter().any(|n| n.contains(".partial-")) {
            saw_temp = true;
            break;
        }
        if child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    let _ = Command::new("kill").arg("-TERM").arg(child.id().to_string()).status();
    let status = child.wait().unwrap();
    if !saw_temp {
        eprintln!("note: the run ended before its temporary file was seen ({status:?})");
    }
    if status.success() {
        return; // finished before the signal: its outputs are complete, nothing to check.
    }
    assert_eq!(status.code(), Some(130), "{status:?}");
    assert_eq!(names(dir.path()), Vec::<String>::new(), "a killed run left files behind");
}
