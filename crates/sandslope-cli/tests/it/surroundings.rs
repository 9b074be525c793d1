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
        if npy.is_dir() && names(&npy).iter().any(|n| n.starts_with(".sandslope-")) {
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
    assert_eq!(status.code(), Some(143), "{status:?}");
    assert_eq!(names(dir.path()), Vec::<String>::new(), "a killed run left files behind");
}

// ---- Issue 39: outputs that cannot destroy a user's files ----

/// `calibrate`'s terrain file written to `out` with `dir` as the working folder.
fn calibrate_into(dir: &Path, out: &str) -> std::process::Output {
    sandslope()
        .current_dir(dir)
        .args(["calibrate", "--observed", &repo_file("data/paper-speeds.csv"), "--out", out])
        .output()
        .unwrap()
}

#[test]
fn an_output_never_touches_a_dotfile_named_like_its_old_temporary() {
    // Before: the temporary file of `profile` was `.profile` (and of `t.toml`, `.t.toml.toml`),
    // opened without O_EXCL, so `--out profile` truncated the user's .profile and renamed it.
    let dir = tempfile::tempdir().unwrap();
    for (out, dotfile) in [("profile", ".profile"), ("t.toml", ".t.toml.toml"), ("t.toml", ".t.toml")] {
        std::fs::write(dir.path().join(dotfile), "KEEP\n").unwrap();
        let run = calibrate_into(dir.path(), out);
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        assert_eq!(
            std::fs::read_to_string(dir.path().join(dotfile)).unwrap(),
            "KEEP\n",
            "{dotfile} was changed"
        );
        assert!(std::fs::read_to_string(dir.path().join(out)).unwrap().contains("k_s"));
        std::fs::remove_file(dir.path().join(dotfile)).unwrap();
        std::fs::remove_file(dir.path().join(out)).unwrap();
    }
    assert_eq!(names(dir.path()), Vec::<String>::new(), "a temporary file was left");
}

#[test]
fn a_link_planted_where_a_temporary_file_might_be_is_never_followed() {
    // Before: a link at `.t.toml.toml -> victim` made `--out t.toml` overwrite the victim.
    let dir = tempfile::tempdir().unwrap();
    let victim = dir.path().join("victim");
    std::fs::write(&victim, "precious\n").unwrap();
    for planted in [".t.toml.toml", ".t.toml", ".t.toml.partial", ".sandslope-t.toml"] {
        std::os::unix::fs::symlink(&victim, dir.path().join(planted)).unwrap();
    }
    let run = calibrate_into(dir.path(), "t.toml");
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious\n");
    assert!(std::fs::read_to_string(dir.path().join("t.toml")).unwrap().contains("k_s"));
    assert_eq!(names(dir.path()).len(), 6, "{:?}", names(dir.path()));
}

#[test]
fn a_fifo_output_uses_no_file_in_the_shared_temporary_folder() {
    // Before: a FIFO's output went through `$TMPDIR/.sandslope-<name>.<ext>`, a fixed name any
    // local user could plant a link at.
    let dir = tempfile::tempdir().unwrap();
    let tmpdir = dir.path().join("tmp");
    std::fs::create_dir(&tmpdir).unwrap();
    let victim = dir.path().join("victim");
    std::fs::write(&victim, "precious\n").unwrap();
    for planted in [".sandslope-pipe.toml.toml", ".sandslope-pipe.toml", ".sandslope-pipe"] {
        std::os::unix::fs::symlink(&victim, tmpdir.join(planted)).unwrap();
    }
    let fifo = dir.path().join("pipe.toml");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || {
            let mut text = String::new();
            std::fs::File::open(&fifo).unwrap().read_to_string(&mut text).unwrap();
            text
        })
    };
    let run = sandslope()
        .env("TMPDIR", &tmpdir)
        .args(["calibrate", "--observed", &repo_file("data/paper-speeds.csv"), "--out"])
        .arg(&fifo)
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(reader.join().unwrap().contains("k_s"));
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious\n");
    assert_eq!(names(&tmpdir).len(), 3, "{:?}", names(&tmpdir));
}

#[test]
fn dev_stdout_and_links_to_it_write_into_a_pipe_and_append_to_a_file() {
    // Before: `--out /dev/stdout` failed when stdout was a pipe and replaced the file when it
    // was one (the shell's `>>` lost what was there).
    let dir = tempfile::tempdir().unwrap();
    let link = dir.path().join("out.toml");
    std::os::unix::fs::symlink("/proc/self/fd/1", &link).unwrap();
    for target in [Path::new("/dev/stdout"), Path::new("/dev/fd/1"), link.as_path()] {
        // A pipe.
        let run = sandslope()
            .args(["calibrate", "--observed", &repo_file("data/paper-speeds.csv"), "--out"])
            .arg(target)
            .output()
            .unwrap();
        assert!(run.status.success(), "{target:?}: {}", String::from_utf8_lossy(&run.stderr));
        assert!(String::from_utf8_lossy(&run.stdout).contains("[[points]]"), "{target:?}");
        // A file opened for appending, as `>> file` opens it.
        let file = dir.path().join("appended.txt");
        std::fs::write(&file, "BEFORE\n").unwrap();
        let ino = std::os::unix::fs::MetadataExt::ino(&std::fs::metadata(&file).unwrap());
        let append = std::fs::OpenOptions::new().append(true).open(&file).unwrap();
        let run = sandslope()
            .args(["calibrate", "--observed", &repo_file("data/paper-speeds.csv"), "--out"])
            .arg(target)
            .stdout(append)
            .output()
            .unwrap();
        assert!(run.status.success(), "{target:?}: {}", String::from_utf8_lossy(&run.stderr));
        let text = std::fs::read_to_string(&file).unwrap();
        assert!(text.starts_with("BEFORE\n") && text.contains("[[points]]"), "{target:?}: {text}");
        let now = std::os::unix::fs::MetadataExt::ino(&std::fs::metadata(&file).unwrap());
        assert_eq!(ino, now, "{target:?}: the file was replaced, not written");
    }
    assert_eq!(names(dir.path()), ["appended.txt", "out.toml"]);
}

#[test]
fn a_full_disk_while_drawing_exits_3_naming_the_file() {
    // Before: a full disk while drawing exited 2 ("bad input") with the image encoder's debug
    // text (`ImageError(IoError(Custom { .. }))`).
    if !Path::new("/dev/full").exists() {
        eprintln!("skipped: no /dev/full on this system");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for name in ["sweep.png", "sweep.svg"] {
        let link = dir.path().join(name);
        std::os::unix::fs::symlink("/dev/full", &link).unwrap();
        let run = sandslope()
            .args(["sweep", "--from", "0", "--to", "5", "--step", "1", "--plot"])
            .arg(&link)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(3), "{name}: {err}");
        assert!(err.contains(name) && err.contains("No space left on device"), "{name}: {err}");
        assert!(!err.contains("Error(") && !err.contains("Custom"), "{name}: debug text: {err}");
    }
    let gif = dir.path().join("walk.gif");
    std::os::unix::fs::symlink("/dev/full", &gif).unwrap();
    let run = sandslope()
        .args(["simulate", "--slope", "10", "--duration", "1.5", "--animate"])
        .arg(&gif)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(3), "{err}");
    assert!(err.contains("walk.gif") && !err.contains("Error("), "{err}");
}

/// Runs `sandslope` with `args` in the background, waits until it has run for `after`, sends
/// `signal`, and returns its exit code.
fn code_after_signal(signal: &str, args: &[&str], after: Duration) -> Option<i32> {
    let mut child = sandslope().args(args).stdout(Stdio::null()).stderr(Stdio::null()).spawn().unwrap();
    std::thread::sleep(after);
    let _ = Command::new("kill").arg(format!("-{signal}")).arg(child.id().to_string()).status();
    child.wait().unwrap().code()
}

#[test]
fn sigterm_exits_143_and_sigint_130() {
    // A server runs until it is stopped: the signal is the only way it ends.
    let args = ["serve", "--port", "0"];
    assert_eq!(code_after_signal("TERM", &args, Duration::from_millis(700)), Some(143));
    assert_eq!(code_after_signal("INT", &args, Duration::from_millis(700)), Some(130));
    assert_eq!(code_after_signal("HUP", &args, Duration::from_millis(700)), Some(129));
}

/// Whether this test runs as root (CI does): the tests below then also run the tool as the
/// unprivileged user `nobody` (uid 65534) through util-linux's `setpriv`.
fn is_root() -> bool {
    std::os::unix::fs::MetadataExt::uid(&std::fs::metadata("/proc/self").unwrap()) == 0
}

/// `sandslope` run as `nobody` when this test is root and `setpriv` exists; `None` otherwise
/// (the test then runs as the user it is, which is already unprivileged).
fn as_nobody() -> Option<Command> {
    if !is_root() {
        return None;
    }
    let mut cmd = Command::new("setpriv");
    cmd.args(["--reuid=65534", "--regid=65534", "--clear-groups", env!("CARGO_BIN_EXE_sandslope")]);
    cmd.output().ok().filter(|o| o.status.code().is_some())?;
    Some(cmd)
}

/// A temporary folder the unprivileged user may write (owned by `nobody` when run as root).
fn folder_for_nobody() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    if is_root() {
        std::os::unix::fs::chown(dir.path(), Some(65534), Some(65534)).unwrap();
    }
    dir
}

#[test]
fn as_an_unprivileged_user_dotfiles_and_planted_links_are_safe_too() {
    let Some(mut nobody) = as_nobody() else {
        eprintln!("not root: the other tests already ran unprivileged");
        return;
    };
    let dir = folder_for_nobody();
    let victim = dir.path().join("victim");
    std::fs::write(&victim, "precious\n").unwrap();
    std::fs::write(dir.path().join(".profile"), "KEEP\n").unwrap();
    std::os::unix::fs::symlink(&victim, dir.path().join(".t.toml.toml")).unwrap();
    for out in ["profile", "t.toml"] {
        let run = nobody
            .current_dir(dir.path())
            .args(["calibrate", "--observed", &repo_file("data/paper-speeds.csv"), "--out", out])
            .output()
            .unwrap();
        assert!(run.status.success(), "{out}: {}", String::from_utf8_lossy(&run.stderr));
        let meta = std::fs::metadata(dir.path().join(out)).unwrap();
        assert_eq!(std::os::unix::fs::MetadataExt::uid(&meta), 65534, "{out} not written by nobody");
        nobody = as_nobody().unwrap();
    }
    assert_eq!(std::fs::read_to_string(dir.path().join(".profile")).unwrap(), "KEEP\n");
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious\n");
}

#[test]
fn another_users_link_in_a_shared_sticky_folder_is_not_followed() {
    // The kernel's fs.protected_symlinks refuses to open such a link for anyone but its
    // owner; the writer follows links by hand (to replace the target atomically), so it
    // applies the same rule. Here root (CI) is the victim of a link `nobody` planted in /tmp.
    let Some(mut nobody) = as_nobody() else {
        eprintln!("skipped: needs root to play two users");
        return;
    };
    let shared = tempfile::tempdir().unwrap();
    std::fs::set_permissions(shared.path(), std::os::unix::fs::PermissionsExt::from_mode(0o1777)).unwrap();
    let victim_dir = tempfile::tempdir().unwrap();
    let victim = victim_dir.path().join("victim.toml");
    std::fs::write(&victim, "precious\n").unwrap();
    let link = shared.path().join("out.toml");
    // Planted by nobody: `ln -s` run as nobody.
    let mut ln = Command::new("setpriv");
    ln.args(["--reuid=65534", "--regid=65534", "--clear-groups", "ln", "-s"]).arg(&victim).arg(&link);
    assert!(ln.status().unwrap().success());
    let run = sandslope()
        .args(["calibrate", "--observed", &repo_file("data/paper-speeds.csv"), "--out"])
        .arg(&link)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{err}");
    assert!(err.contains("owned by another user"), "{err}");
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious\n");
    // The owner of a link in a shared folder may still use it.
    let own = folder_for_nobody();
    let own_target = own.path().join("mine.toml");
    std::fs::write(&own_target, "old\n").unwrap();
    std::os::unix::fs::chown(&own_target, Some(65534), Some(65534)).unwrap();
    let own_link = shared.path().join("mine.toml");
    let mut ln = Command::new("setpriv");
    ln.args(["--reuid=65534", "--regid=65534", "--clear-groups", "ln", "-s"]).arg(&own_target).arg(&own_link);
    assert!(ln.status().unwrap().success());
    let run = nobody
        .args(["calibrate", "--observed", &repo_file("data/paper-speeds.csv"), "--out"])
        .arg(&own_link)
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(std::fs::read_to_string(&own_target).unwrap().contains("k_s"));
}
