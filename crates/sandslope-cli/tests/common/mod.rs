//! Test helpers shared by the end-to-end tests: running the `sandslope` binary and reading its
//! JSON, repository and temporary files, and (for the motion-capture tests, `track.rs` and
//! `report.rs`) trajectories sampled from a known step profile
//! (`sandslope::gait::synthetic::StepProfile`) with noise and occlusions, written as Motive,
//! Vicon or plain CSV files.
#![allow(dead_code)] // each test binary uses a different subset

use std::path::{Path, PathBuf};

use rand::{RngExt, SeedableRng};
use sandslope::gait::synthetic::StepProfile;

/// The `sandslope` binary under test.
pub fn sandslope() -> assert_cmd::Command {
    assert_cmd::Command::cargo_bin("sandslope").unwrap()
}

/// A file of the repository, by its path from the repository root.
pub fn repo_file(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(rel)
}

/// Runs `cmd`, which must succeed, and parses its stdout as JSON.
pub fn json_of(cmd: &mut assert_cmd::Command) -> serde_json::Value {
    let out = cmd.assert().success().get_output().stdout.clone();
    serde_json::from_slice(&out).unwrap()
}

/// `sandslope ARGS`, which must succeed (its stderr is shown if not), stdout parsed as JSON.
pub fn json(args: &[&str]) -> serde_json::Value {
    let out = sandslope().args(args).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The default report, `sandslope report --out DIR` with no other flag: its folder (read it,
/// write nothing into it) and the command's stdout.
pub struct DefaultReport {
    /// The report's folder: index.html, report.json and the figures.
    pub dir: PathBuf,
    /// What the command printed on stdout.
    pub stdout: String,
}

/// The default report, made once per test binary and shared by the tests that read it (five in
/// tests/it: its page and JSON, its provenance notes, a browser's rendering, the simulator
/// table and docs/phase-and-risk.md's numbers): one debug `report` is about 9 s of CPU, and
/// each test made its own. The folder is `report-default` under Cargo's temporary folder for
/// integration tests (target/tmp), rewritten by each run.
pub fn default_report() -> &'static DefaultReport {
    static REPORT: std::sync::OnceLock<DefaultReport> = std::sync::OnceLock::new();
    REPORT.get_or_init(|| {
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("report-default");
        if dir.exists() {
            std::fs::remove_dir_all(&dir).unwrap();
        }
        let out = sandslope().args(["report", "--out"]).arg(&dir).assert().success();
        let stdout = String::from_utf8(out.get_output().stdout.clone()).unwrap();
        DefaultReport { dir, stdout }
    })
}

/// Debian's `chromium` (or another Chromium on PATH) for the browser tests, or `None` after
/// saying the test is skipped. With `CI=true` a missing browser fails the test instead: CI
/// installs it (.ci/run), so a browser test must never pass there by skipping.
pub fn chromium_or_skip(test: &str) -> Option<String> {
    let found = ["chromium", "chromium-browser", "google-chrome"].iter().find_map(|name| {
        let ok = std::process::Command::new(name).arg("--version").output().is_ok_and(|o| o.status.success());
        ok.then(|| name.to_string())
    });
    if found.is_none() {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "{test}: no chromium installed and CI=true: browser tests must run in CI (apt-get install chromium)"
        );
        eprintln!("{test}: skipped: no chromium installed (apt-get install chromium)");
    }
    found
}

/// The flags every browser test starts headless Chromium with: no first-run, sync, component
/// updates or background traffic, so the only requests are the page's.
pub const CHROMIUM_FLAGS: [&str; 9] = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
];

/// Checks a browser screenshot (PNG) shows content: more than 3 % non-white pixels and more
/// than 20 colours (a blank or broken page has neither).
pub fn assert_shows_content(shot: &Path) {
    let decoder = png::Decoder::new(std::fs::File::open(shot).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    let pixels: Vec<&[u8]> = buf[..info.buffer_size()].chunks(channels).collect();
    let non_white = pixels.iter().filter(|p| p[..3].iter().any(|&c| c < 235)).count();
    let mut colours: Vec<[u8; 3]> = pixels.iter().map(|p| [p[0] & 0xf0, p[1] & 0xf0, p[2] & 0xf0]).collect();
    colours.sort_unstable();
    colours.dedup();
    let fraction = non_white as f64 / pixels.len() as f64;
    assert!(fraction > 0.03, "{}: nearly blank: {fraction:.4} of pixels non-white", shot.display());
    assert!(colours.len() > 20, "{}: only {} colours", shot.display(), colours.len());
}

/// Writes `text` to `dir/name` and returns the path as a string, for an argument list.
pub fn write_arg(dir: &Path, name: &str, text: &str) -> String {
    write(dir, name, text).to_string_lossy().into_owned()
}

/// Frame rate of the generated recordings, frames/s.
pub const FPS: f64 = 120.0;

/// (time, position or None when occluded), metres.
pub type Rows = Vec<(f64, Option<[f64; 3]>)>;

/// `seconds` of a robot stepping with profile `p` along `dir` (unit vector), first touchdown
/// at `offset` s, with Gaussian noise of SD `noise` m per axis and frames `gaps` (half-open
/// index ranges) occluded; the noise is seeded, so the recording is reproducible.
pub fn trajectory(
    p: &StepProfile,
    seconds: f64,
    offset: f64,
    dir: [f64; 3],
    noise: f64,
    gaps: &[(usize, usize)],
) -> Rows {
    trajectory_seeded(p, seconds, offset, dir, noise, gaps, 11)
}

/// [`trajectory`] with its own noise: recordings pooled together need independent noise.
pub fn trajectory_seeded(
    p: &StepProfile,
    seconds: f64,
    offset: f64,
    dir: [f64; 3],
    noise: f64,
    gaps: &[(usize, usize)],
    seed: u64,
) -> Rows {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let mut gauss = move || {
        let (u1, u2): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    };
    let n = (seconds * FPS) as usize;
    (0..n)
        .map(|i| {
            let t = i as f64 / FPS;
            let s = p.position(t - offset + 2.0 * p.step_duration());
            let pos = [
                dir[0] * s + noise * gauss(),
                dir[1] * s + 0.3 + noise * gauss(),
                dir[2] * s + noise * gauss(),
            ];
            (t, (!gaps.iter().any(|&(a, b)| (a..b).contains(&i))).then_some(pos))
        })
        .collect()
}

/// One position as three CSV cells scaled by `scale` (1000 for mm); empty when occluded.
pub fn cells(p: Option<[f64; 3]>, scale: f64) -> String {
    match p {
        Some(p) => format!("{},{},{}", p[0] * scale, p[1] * scale, p[2] * scale),
        None => ",,".into(),
    }
}

/// A Motive CSV export (`version` 1.23 or 1.25) with rigid body `robot` and marker `m1`.
pub fn motive(rows: &Rows, version: &str, units: &str, scale: f64) -> String {
    let mut s = format!(
        "Format Version,{version},Take Name,t,Capture Frame Rate,240.000000,Export Frame Rate,120.000000,\
         Total Exported Frames,99999,Rotation Type,Quaternion,Length Units,{units},Coordinate Space,Global\n\n"
    );
    s += ",Type,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Marker,Marker,Marker\n";
    s += ",Name,robot,robot,robot,robot,robot,robot,robot,m1,m1,m1\n,ID,1,1,1,1,1,1,1,2,2,2\n";
    if version == "1.25" {
        s += ",Parent,,,,,,,,,,\n";
    }
    s += ",,Rotation,Rotation,Rotation,Rotation,Position,Position,Position,Position,Position,Position\n";
    s += "Frame,Time (Seconds),X,Y,Z,W,X,Y,Z,X,Y,Z\n";
    for (i, (t, p)) in rows.iter().enumerate() {
        let rot = if p.is_some() { "0,0,0,1" } else { ",,," };
        s += &format!("{i},{t:.6},{rot},{},1,2,3\n", cells(*p, scale));
    }
    s
}

/// A Vicon Nexus trajectories export, subject `robot`, segment `CoM`, in mm.
pub fn vicon(rows: &Rows) -> String {
    let mut s = "Trajectories\n120\n,,robot:CoM,,\nFrame,Sub Frame,X,Y,Z\n,,mm,mm,mm\n".to_string();
    for (i, (_, p)) in rows.iter().enumerate() {
        s += &format!("{},0,{}\n", i + 1, cells(*p, 1000.0));
    }
    s
}

/// A plain CSV (`time_s,x_mm,y_mm,z_mm,quality`).
pub fn plain_mm(rows: &Rows) -> String {
    let mut s = "time_s,x_mm,y_mm,z_mm,quality\n".to_string();
    for (t, p) in rows {
        s += &format!("{t:.6},{},1\n", cells(*p, 1000.0));
    }
    s
}

/// Writes `text` to `dir/name`, returning the path.
pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// `cmd` with the file-size limit (`ulimit -f`) set to `bytes` in the child only.
pub fn with_file_size_limit(cmd: &mut std::process::Command, bytes: u64) -> &mut std::process::Command {
    use std::os::unix::process::CommandExt;
    // SAFETY: setrlimit is async-signal-safe; nothing else runs between fork and exec.
    unsafe {
        cmd.pre_exec(move || {
            let lim = libc::rlimit { rlim_cur: bytes as libc::rlim_t, rlim_max: bytes as libc::rlim_t };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &lim) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        })
    }
}
