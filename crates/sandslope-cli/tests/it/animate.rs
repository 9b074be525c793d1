//! `simulate --animate` end to end (issue 41): the GIF holds the whole walk at 20 frames per
//! simulated second played in real time, and a terminal sees progress on stderr while the walk
//! is simulated and drawn, a log (stderr not a terminal) plain lines, and --json nothing.

use crate::common;

use common::sandslope;

/// The frames of a GIF and their delays, hundredths of a second.
fn frame_delays(path: &std::path::Path) -> Vec<u16> {
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::Indexed);
    let mut decoder = options.read_info(std::fs::File::open(path).unwrap()).unwrap();
    let mut delays = Vec::new();
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        delays.push(frame.delay);
    }
    delays
}

/// A 1.5 s walk (the shortest `--duration` takes): frames at t = 0, 0.05, ..., 1.5 s, 31 of
/// them, each shown 5 cs, so that the GIF lasts as long as the walk (the frame at t = 0 adds
/// its 5 cs).
#[test]
fn the_gif_is_the_whole_walk_in_real_time() {
    let dir = tempfile::tempdir().unwrap();
    let gif = dir.path().join("walk.gif");
    sandslope()
        .args(["simulate", "--slope", "10", "--duration", "1.5", "--animate", gif.to_str().unwrap()])
        .assert()
        .success();
    let delays = frame_delays(&gif);
    assert_eq!(delays.len(), 31);
    assert!(delays.iter().all(|&d| d == 5), "{delays:?}");
    let shown_s = delays.iter().map(|&d| f64::from(d) / 100.0).sum::<f64>();
    assert!((shown_s - 1.55).abs() < 1e-9, "{shown_s}");
}

/// `--help` names the cap on the animation's length.
#[test]
fn help_names_the_animation_cap() {
    let out = sandslope().args(["simulate", "--help"]).output().unwrap();
    let help = String::from_utf8(out.stdout).unwrap();
    assert!(help.contains("whole walk") && help.contains("first 60 s"), "{help}");
}

/// `script` (util-linux) runs the command on a pseudo-terminal, as a user's shell does; `None`
/// after saying the test is skipped when it is missing (outside CI).
fn script_or_skip(test: &str) -> Option<()> {
    let ok = std::process::Command::new("script").arg("--version").output().is_ok_and(|o| o.status.success());
    if !ok {
        assert!(std::env::var("CI").as_deref() != Ok("true"), "{test}: no `script` (util-linux) and CI=true");
        eprintln!("{test}: skipped: no `script` (util-linux)");
        return None;
    }
    Some(())
}

/// What a terminal shows for `sandslope ARGS` (stdout and stderr together).
fn on_a_terminal(args: &str) -> String {
    let bin = assert_cmd::cargo::cargo_bin("sandslope");
    let out = std::process::Command::new("script")
        .args(["-qec", &format!("{} {args}", bin.display()), "/dev/null"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
fn a_terminal_sees_progress_a_log_sees_lines_and_json_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let gif = dir.path().join("walk.gif");
    let walk = format!("simulate --slope 10 --duration 1.5 --animate {}", gif.display());
    // Piped (a log, CI): progress as plain lines on stderr, the walk's start and end and the
    // GIF's frames (1.5 s at 20 frames a second from t = 0: 31), with no terminal codes.
    let piped = sandslope().args(walk.split(' ')).output().unwrap();
    let stderr = String::from_utf8_lossy(&piped.stderr);
    // One slope: the walk and its two other contact scalings (the spread, on by default).
    let start = "simulating 1.5 s at 10 deg under each of the three contact scalings";
    assert!(stderr.contains(&format!("{start} ...\n")), "{stderr}");
    assert!(stderr.contains(&format!("{start}: done in ")), "{stderr}");
    assert!(stderr.contains(&format!("drawing {}: 31/31, done in ", gif.display())), "{stderr}");
    assert!(!stderr.contains('\u{1b}'), "{stderr}");
    // --json piped: nothing but the answer.
    let json = sandslope().args(walk.split(' ')).arg("--json").output().unwrap();
    let stderr = String::from_utf8_lossy(&json.stderr);
    assert!(!stderr.contains("simulating") && !stderr.contains("drawing"), "{stderr}");
    if script_or_skip("a_terminal_sees_progress_a_log_sees_lines_and_json_nothing").is_none() {
        return;
    }
    let shown = on_a_terminal(&walk);
    assert!(shown.contains("simulating 1.5 s at 10 deg"), "{shown}");
    assert!(shown.contains(&format!("drawing {}", gif.display())) && shown.contains("/31"), "{shown}");
    let quiet = on_a_terminal(&format!("{walk} --json"));
    assert!(!quiet.contains("simulating") && !quiet.contains("drawing"), "{quiet}");
}
