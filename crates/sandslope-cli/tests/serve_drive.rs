//! `sandslope serve --drive`: the server drives the emulated XL330s through the same pty and
//! `dynamixel2` bus code as a real port (issue 42), `/api/drive/status` follows the run with
//! `drive --json`'s per-stance record, the page's Drive tab shows it, and the torque is off on
//! every way out: the run's end, the page's stop button, Ctrl-C, SIGTERM and SIGHUP, a lost servo, and
//! a server that cannot start.

mod common;

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use serde_json::Value;

/// The drive tests time a bus at 50 Hz: one at a time, so that they do not load each other.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// The paper-hexapod's leg speed omega, rad/s: one turn per second (the paper's gait, the
/// robot file's `leg_speed`).
const OMEGA: f64 = 2.0 * std::f64::consts::PI;

/// A running `sandslope serve --drive --emulate ...`, its stderr in a file.
struct Server {
    child: Child,
    addr: String,
    stderr: tempfile::NamedTempFile,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Server {
    fn start(args: &[&str]) -> Server {
        let stderr = tempfile::NamedTempFile::new().unwrap();
        let mut child = Command::new(assert_cmd::cargo::cargo_bin("sandslope"))
            .args(["serve", "--port", "0", "--drive", "--emulate", "--watchdog", "2"])
            .args(args)
            .stdout(Stdio::piped())
            .stderr(stderr.reopen().unwrap())
            .spawn()
            .unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap()).read_line(&mut line).unwrap();
        let addr = line
            .trim()
            .strip_prefix("sandslope serve: http://")
            .and_then(|s| s.strip_suffix('/'))
            .unwrap_or_else(|| panic!("unexpected first line {line:?}: {}", read(&stderr)))
            .to_string();
        Server { child, addr, stderr }
    }

    fn request(&self, method: &str, path: &str) -> (u16, String) {
        let mut s = TcpStream::connect(&self.addr).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
        write!(s, "{method} {path} HTTP/1.0\r\nHost: {}\r\nContent-Length: 0\r\n\r\n", self.addr).unwrap();
        let mut raw = String::new();
        s.read_to_string(&mut raw).unwrap();
        let (head, body) = raw.split_once("\r\n\r\n").expect("no header end");
        (head.split(' ').nth(1).unwrap().parse().unwrap(), body.to_string())
    }

    fn status(&self) -> Value {
        let (code, body) = self.request("GET", "/api/drive/status");
        assert_eq!(code, 200, "{body}");
        serde_json::from_str(&body).unwrap()
    }

    /// Polls the status until `done` holds of it (at most `limit`), returning it and every
    /// state seen on the way.
    fn wait_for(&self, limit: Duration, done: impl Fn(&Value) -> bool) -> (Value, Vec<String>) {
        let began = Instant::now();
        let mut seen: Vec<String> = vec![];
        loop {
            let st = self.status();
            let state = st["state"].as_str().unwrap().to_string();
            if seen.last() != Some(&state) {
                seen.push(state);
            }
            if done(&st) {
                return (st, seen);
            }
            assert!(began.elapsed() < limit, "waited {limit:?}; states {seen:?}; {}", read(&self.stderr));
            std::thread::sleep(Duration::from_millis(100));
        }
    }

    /// Sends `signal` and returns the exit code and stderr.
    fn signal(mut self, signal: &str) -> (Option<i32>, String) {
        let sent = Command::new("kill").args([signal, &self.child.id().to_string()]).status().unwrap();
        assert!(sent.success());
        let began = Instant::now();
        let code = loop {
            if let Some(s) = self.child.try_wait().unwrap() {
                break s.code();
            }
            assert!(began.elapsed() < Duration::from_secs(30), "the server did not exit after {signal}");
            std::thread::sleep(Duration::from_millis(50));
        };
        (code, read(&self.stderr))
    }
}

fn read(f: &tempfile::NamedTempFile) -> String {
    std::fs::read_to_string(f.path()).unwrap_or_default()
}

fn ids(v: &Value) -> Vec<u64> {
    v.as_array().unwrap().iter().map(|i| i.as_u64().unwrap()).collect()
}

fn keys(v: &Value) -> Vec<String> {
    let mut k: Vec<String> = v.as_object().unwrap().keys().cloned().collect();
    k.sort();
    k
}

/// A whole emulated run at 20 deg on k_s = 2.5e5 N/m^3, watched through the endpoint and then
/// on the page.
#[test]
fn the_status_endpoint_and_the_drive_tab_follow_an_emulated_run() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let server = Server::start(&["--slope", "20", "--emulate-k-s", "2.5e5", "--duration", "4"]);
    // Two estimates, and the leg speed measured: the meter needs the run-up and a whole stride
    // period of positions after it, while the first estimates come from the run-up stance
    // (which one arrives first depends on the machine's timing).
    let (mid, _) = server.wait_for(Duration::from_secs(120), |s| {
        s["estimates"].as_u64().unwrap() >= 2 && s["leg_speed_rad_s"].as_f64().unwrap() > 0.0
    });
    assert_eq!(mid["state"], "driving", "{mid}");
    // The leg speed measured from the servos' positions is the robot file's omega: the
    // emulated shafts follow the commanded gait (within 5%: a stride period of positions after the run-up).
    let speed = mid["leg_speed_rad_s"].as_f64().unwrap();
    assert!((speed - OMEGA).abs() < 0.05 * OMEGA, "leg speed {speed} rad/s against {OMEGA}");
    assert!((mid["commanded_leg_speed_rad_s"].as_f64().unwrap() - OMEGA).abs() < 1e-9);
    let (end, seen) = server.wait_for(Duration::from_secs(60), |s| s["state"] != "driving");
    assert_eq!(end["state"], "completed", "{end}; {seen:?}");
    assert_eq!(ids(&end["torque_off"]["confirmed"]), vec![1, 2, 3, 4, 5, 6], "{end}");
    assert_eq!(
        end["emulator"].as_str().unwrap().split(" (").next(),
        Some("emulator: torque off on every servo")
    );
    assert_eq!(end["halted"], false);
    // 4 s of gait at 50 Hz after a 1 s stand: about 250 cycles (the bus may run a little slow).
    let cycles = end["cycles"].as_u64().unwrap();
    assert!((150..=260).contains(&cycles), "{cycles} cycles");
    // One stance per tripod per period (1 s) after the run-up: about 6 in 4 s.
    let estimates = end["estimates"].as_u64().unwrap();
    assert!((4..=8).contains(&estimates), "{estimates} estimates");
    // The last stance's estimate of the emulated sand: the truth 2.5e5 within a factor of 2 of
    // its interval (one stance's interval is a factor of about 3 wide, docs/drive.md).
    let inf = &end["live"]["inference"];
    let (lo, hi) = (inf["k_s_lo"].as_f64().unwrap(), inf["k_s_hi"].as_f64().unwrap());
    assert!(lo < 5e5 && hi > 1.25e5, "[{lo}, {hi}]");
    assert!(inf["p_fail"].as_f64().unwrap() < 0.05, "{inf}");
    // The record is `drive --json`'s per-stance one: the same keys.
    let out = common::sandslope()
        .args([
            "drive",
            "--emulate",
            "--slope",
            "20",
            "--duration",
            "2",
            "--live",
            "--json",
            "--watchdog",
            "2",
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let cli: Value = serde_json::from_slice(&out.stdout).unwrap();
    let record = &cli["live"][0];
    assert_eq!(keys(&end["live"]), keys(record));
    assert_eq!(keys(&end["live"]["inference"]), keys(&record["inference"]));

    // The page: the Drive tab shows the endpoint's numbers.
    let Some(browser) =
        common::chromium_or_skip("the_status_endpoint_and_the_drive_tab_follow_an_emulated_run")
    else {
        return;
    };
    let dom = dump_dom(&browser, &server, "/?tab=drive");
    assert!(
        dom.contains(r#"<button data-tab="drive" class="active">Drive</button>"#),
        "the tab is not shown"
    );
    assert_eq!(text_of(&dom, "drive-state"), "completed (emulated bus)");
    same_number(attribute(&dom, "id=\"drive-k-s\"", "data-value"), &inf["k_s"]);
    same_number(attribute(&dom, "id=\"drive-k-s\"", "data-lo"), &inf["k_s_lo"]);
    same_number(attribute(&dom, "id=\"drive-p-fail\"", "data-value"), &inf["p_fail"]);
    same_number(attribute(&dom, "id=\"drive-climb\"", "data-value"), &inf["speed_m_s"]);
    // Both pooled verdicts, and a note where they disagree: at 20 deg on k_s 2.5e5 N/m^3 the
    // closed form says slippage (k_s margin 0.49) and the simulator success (docs/drive.md).
    let pooled = &end["live"]["pooled"];
    same_number(attribute(&dom, "id=\"drive-verdicts\"", "data-simulator"), &pooled["p_fail_simulator"]);
    same_number(attribute(&dom, "id=\"drive-verdicts\"", "data-closed-form"), &pooled["p_fail_closed_form"]);
    let (sim, cf) =
        (pooled["p_fail_simulator"].as_f64().unwrap(), pooled["p_fail_closed_form"].as_f64().unwrap());
    assert!(sim < 0.5 && cf >= 0.5, "the verdicts agree here: simulator {sim}, closed form {cf}");
    assert_eq!(attribute(&dom, "id=\"drive-verdicts\"", "data-disagree").as_deref(), Some("true"));
    assert!(attribute(&dom, "id=\"drive-disagree\"", "hidden").is_none(), "the note is hidden");
    let note = text_of(&dom, "drive-disagree");
    assert!(
        note.contains("the simulator says the walk succeeds")
            && note.contains("the closed form that it fails"),
        "{note}"
    );
    let t = end["time_s"].as_f64().unwrap();
    assert_eq!(text_of(&dom, "drive-time"), format!("{t:.2} / 4"));
    assert!(text_of(&dom, "drive-end").contains("Torque off confirmed on servos 1, 2, 3, 4, 5, 6"));
    assert!(attribute(&dom, "id=\"drive-stop\"", "disabled").is_some(), "the stop button after the end");
    assert_eq!(text_of(&dom, "log-errors"), "", "page errors");
}

/// A number as JavaScript's `String(n)` writes it (the shortest round trip, as serde_json).
/// The page's number (JavaScript's shortest round-trip text of the endpoint's value) is the
/// endpoint's, to the last bits: serde_json's default parser (without `float_roundtrip`) may
/// land one ulp from the nearest double, which JavaScript's does not (seen: the page's
/// 1.4444550812821376e-34 against 1.4444550812821374e-34 re-printed by the test).
fn same_number(shown: Option<String>, json: &Value) {
    let shown = shown.expect("the attribute is on the page");
    let page: f64 = shown.parse().unwrap_or_else(|_| panic!("not a number on the page: {shown}"));
    let value = json.as_f64().unwrap();
    assert!(
        (page - value).abs() <= 4.0 * f64::EPSILON * value.abs(),
        "the page shows {shown}, the endpoint {}",
        number(json)
    );
}

fn number(v: &Value) -> String {
    let x = v.as_f64().unwrap();
    let s = format!("{x}");
    if x.abs() >= 1e21 || (x != 0.0 && x.abs() < 1e-6) {
        format!("{x:e}").replace('e', "e+").replace("e+-", "e-")
    } else {
        s
    }
}

fn dump_dom(browser: &str, server: &Server, path: &str) -> String {
    let profile = tempfile::tempdir().unwrap();
    let out = Command::new("timeout")
        .arg("90")
        .arg(browser)
        .args(common::CHROMIUM_FLAGS)
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .args(["--window-size=1400,1000", "--virtual-time-budget=10000", "--dump-dom"])
        .arg(format!("http://{}{path}", server.addr))
        .output()
        .unwrap();
    String::from_utf8_lossy(&out.stdout).to_string()
}

fn text_of(dom: &str, id: &str) -> String {
    let anchor = format!("id=\"{id}\"");
    let at = dom.find(&anchor).unwrap_or_else(|| panic!("no #{id} in the page"));
    let open = at + dom[at..].find('>').unwrap() + 1;
    dom[open..open + dom[open..].find('<').unwrap()].to_string()
}

fn attribute(dom: &str, anchor: &str, name: &str) -> Option<String> {
    let at = dom.find(anchor)?;
    let start = dom[..at].rfind('<')?;
    let end = at + dom[at..].find('>')?;
    let tag = &dom[start..end];
    if let Some(from) = tag.find(&format!(" {name}=\"")) {
        let from = from + name.len() + 3;
        return Some(tag[from..from + tag[from..].find('"')?].to_string());
    }
    // A bare attribute (`disabled`).
    tag.split_whitespace().any(|w| w == name).then(String::new)
}

/// The page's stop button takes the CLI's Ctrl-C path: the gait stops, the torque goes off,
/// and the server goes on serving.
#[test]
fn the_stop_endpoint_stops_the_gait_and_turns_the_torque_off() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("stopped.csv");
    let server = Server::start(&["--duration", "60", "--log", log.to_str().unwrap()]);
    server.wait_for(Duration::from_secs(120), |s| s["state"] == "driving");
    // A GET does not stop a robot.
    assert_eq!(server.request("GET", "/api/drive/stop").0, 405);
    let (code, body) = server.request("POST", "/api/drive/stop");
    assert_eq!(code, 200, "{body}");
    let (end, _) = server.wait_for(Duration::from_secs(30), |s| s["state"] != "driving");
    assert_eq!(end["state"], "interrupted", "{end}");
    assert!(end["time_s"].as_f64().unwrap() < 30.0);
    assert_eq!(ids(&end["torque_off"]["confirmed"]), vec![1, 2, 3, 4, 5, 6], "{end}");
    assert!(end["emulator"].as_str().unwrap().starts_with("emulator: torque off on every servo"), "{end}");
    let (code, _) = server.request("GET", "/api/predict?slope=10");
    assert_eq!(code, 200, "the server serves on after the stop");
    // The log is in place while the server serves on (a later Ctrl-C would not take it back).
    check_log(dir.path(), &log, 0.0);
}

/// `--log`'s file after a run: in place, whole (its last row ends with a line end, the reader
/// repaired nothing), every servo's rows up to at least `until` s, and nothing else left in
/// its folder (no temporary file).
fn check_log(dir: &std::path::Path, log: &std::path::Path, until: f64) {
    let text = std::fs::read_to_string(log).unwrap();
    assert!(text.ends_with('\n'), "the log ends mid-row");
    let read = sandslope_io::servo_log::read_servo_log(log).unwrap();
    assert!(read.notes.is_empty(), "{:?}", read.notes);
    assert!(read.rows.last().unwrap().time_s >= until, "{} < {until}", read.rows.last().unwrap().time_s);
    let mut ids: Vec<u8> = read.rows.iter().map(|r| r.id).collect();
    ids.sort_unstable();
    ids.dedup();
    assert_eq!(ids, vec![1, 2, 3, 4, 5, 6]);
    let left: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(left.len(), 1, "{left:?}");
}

/// A signal mid-run: the gait stops, the torque is turned off and read back, the log is put in
/// place whole, and the server exits with 128 + the signal (130 for SIGINT, 143 for SIGTERM,
/// 129 for SIGHUP, as every interrupted run of the tool; docs/drive.md says why).
fn signal_mid_run(signal: &str, expect: i32) {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("served.csv");
    let server = Server::start(&["--duration", "60", "--log", log.to_str().unwrap()]);
    let (st, _) = server.wait_for(Duration::from_secs(120), |s| {
        s["state"] == "driving" && s["time_s"].as_f64().unwrap() > 0.5
    });
    let (code, stderr) = server.signal(signal);
    assert_eq!(code, Some(expect), "{stderr}");
    assert!(stderr.contains("torque off confirmed on servos 1, 2, 3, 4, 5, 6"), "{stderr}");
    assert!(stderr.contains("emulator: torque off on every servo"), "{stderr}");
    check_log(dir.path(), &log, st["time_s"].as_f64().unwrap());
}

#[test]
fn ctrl_c_turns_the_torque_off_before_the_server_exits() {
    signal_mid_run("-INT", 130);
}

#[test]
fn sigterm_turns_the_torque_off_before_the_server_exits() {
    signal_mid_run("-TERM", 143);
}

/// The terminal that started the server closes (an ssh session to the robot drops).
#[test]
fn sighup_turns_the_torque_off_before_the_server_exits() {
    signal_mid_run("-HUP", 129);
}

/// A servo that stops answering mid-run: the run fails naming it, the torque goes off on the
/// others, and the server goes on serving the run's end. On the emulator's virtual clock
/// (`--emulate-clock virtual`, docs/drive.md): nothing here watches the run as it goes.
#[test]
fn a_lost_servo_is_named_and_the_others_are_turned_off() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let server = Server::start(&[
        "--duration",
        "30",
        "--emulate-fault",
        "silent:3:1.5",
        "--bus-watchdog",
        "0.1",
        "--emulate-clock",
        "virtual",
    ]);
    let (end, _) = server.wait_for(Duration::from_secs(120), |s| s["state"] == "failed");
    let error = end["error"].as_str().unwrap();
    assert!(error.contains("servo ID 3 (leg 2) stopped answering"), "{error}");
    assert!(error.contains("check its cable"), "{error}");
    assert_eq!(ids(&end["torque_off"]["confirmed"]), vec![1, 2, 4, 5, 6], "{end}");
    assert_eq!(ids(&end["torque_off"]["unconfirmed"]), vec![3], "{end}");
    // Servo 3's own Bus Watchdog stopped it (the emulator's table says so).
    assert!(end["emulator"].as_str().unwrap().contains("Bus Watchdog fired on servos 3"), "{end}");
}

/// A server that cannot listen (the port is taken) exits with the bus closed and nothing
/// moved: the emulator's servos never had the torque on.
#[test]
fn a_server_that_cannot_listen_leaves_the_torque_off() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = taken.local_addr().unwrap().port().to_string();
    let out = common::sandslope()
        .args(["serve", "--port", &port, "--drive", "--emulate", "--duration", "5"])
        .timeout(Duration::from_secs(120))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(stderr.contains(&format!("cannot listen on 127.0.0.1:{port}")), "{stderr}");
    assert!(stderr.contains("emulator: torque off on every servo (0 packets"), "{stderr}");
    drop(taken);
}

#[test]
fn driving_flags_without_a_bus_or_without_drive_are_refused() {
    let out = common::sandslope().args(["serve", "--port", "0", "--drive"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--drive needs --drive-port PATH"));
    let out = common::sandslope().args(["serve", "--port", "0", "--slope", "10"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("need --drive"));
    let out = common::sandslope().args(["serve", "--port", "0", "--emulate"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let out = common::sandslope()
        .args(["serve", "--port", "0", "--drive", "--emulate", "--stop-on-risk", "1.5"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--stop-on-risk"));
}
