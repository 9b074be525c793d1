//! Exit codes (README, "Exit codes"): 2 for bad input, 3 when an output cannot be written, and
//! a quiet 0 when the reader of stdout goes away.

use crate::common;

use std::io::Read;
use std::process::{Command, Stdio};

fn sandslope() -> Command {
    Command::new(env!("CARGO_BIN_EXE_sandslope"))
}

fn repo_file(rel: &str) -> String {
    format!("{}/../../{rel}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn bad_input_exits_2() {
    let out = sandslope().args(["predict", "--slope", "20", "--robot", "no-such-robot"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no-such-robot") && err.contains("paper-hexapod"), "{err}");
}

#[test]
fn an_output_that_cannot_be_written_exits_3() {
    // /proc exists but no regular file can be created in it, even by root.
    let out = sandslope()
        .args([
            "calibrate",
            "--observed",
            &repo_file("data/paper-speeds.csv"),
            "--out",
            "/proc/sandslope-test.toml",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(3), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot write /proc/sandslope-test.toml"));
}

/// An output that outgrows the file-size limit (`ulimit -f`, as on clusters and robot images
/// that set one) is a failed write like a full disk: exit 3 naming the file, nothing left
/// behind. Without the handler SIGXFSZ ended the process (exit 153) and left a `.partial`.
#[test]
fn an_output_past_the_file_size_limit_exits_3_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let walk = dir.path().join("walk.csv");
    // A 2 s walk's CSV is about 13 KB; the limit stops it at 4 KiB.
    let out = common::with_file_size_limit(&mut sandslope(), 4 * 1024)
        .args(["simulate", "--slope", "10", "--duration", "2", "--out"])
        .arg(&walk)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(err.contains("walk.csv") && err.contains("File too large"), "{err}");
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(left.is_empty(), "left behind: {left:?}");
}

/// Runs `args` with stdout a pipe that the reader closes after the first bytes.
fn run_with_closed_stdout(args: &[&str]) -> (Option<i32>, String) {
    let mut child = sandslope().args(args).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let mut first = [0u8; 16];
    child.stdout.as_mut().unwrap().read_exact(&mut first).unwrap();
    drop(child.stdout.take());
    let status = child.wait().unwrap();
    let mut err = String::new();
    child.stderr.take().unwrap().read_to_string(&mut err).unwrap();
    (status.code(), err)
}

#[test]
fn a_closed_stdout_ends_the_run_quietly() {
    // Enough output that the pipe buffer (64 KiB) fills before the run ends.
    for format in ["--json", "--csv", "--table"] {
        let mut args = vec!["sweep", "--from", "0", "--to", "30", "--step", "0.01"];
        if format != "--table" {
            args.push(format);
        }
        let (code, err) = run_with_closed_stdout(&args);
        assert_eq!(code, Some(0), "{format}: {err}");
        assert!(!err.contains("error") && !err.contains("panicked"), "{format}: {err}");
    }
}

#[test]
fn negative_values_in_ranges_reach_the_range_check() {
    // A leading minus used to be taken for an unknown flag ("unexpected argument '-1'").
    let cases: [(&[&str], &str); 7] = [
        (&["phase", "--k-n", "-1:1e7:10"], "--k-n min = -1"),
        (&["phase", "--k-s", "1e4:1e7:-3"], "--k-s"),
        (&["phase", "--mass", "-1"], "--mass = -1"),
        (&["risk", "--slope", "10", "--map", "--k-s", "-1:1e6:3"], "--k-s min = -1"),
        (&["sweep", "--from", "5", "--to", "-5"], "--from = 5"),
        (&["sweep", "--step", "-1"], "--step = -1"),
        (&["predict", "--slope", "10", "--k-n", "-1"], "--k-n = -1"),
    ];
    for (args, want) in cases {
        let out = sandslope().args(args).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(want) && !err.contains("unexpected argument"), "{args:?}: {err}");
    }
    // And a negative slope range is a valid sweep (descending evaluated as climbing).
    let out =
        sandslope().args(["sweep", "--from", "-5", "--to", "5", "--step", "5", "--csv"]).output().unwrap();
    assert!(out.status.success());
    assert_eq!(String::from_utf8_lossy(&out.stdout).lines().count(), 4);
}
