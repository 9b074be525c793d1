//! `drive --foxglove` and `simulate --foxglove` (docs/bags.md, "Watch live"): a Foxglove
//! WebSocket client on loopback (tungstenite, speaking `foxglove.websocket.v1` as Foxglove
//! does) subscribes to every channel a run advertises and checks the schemas, the framing of
//! `messageData`, and that a 5 s emulated drive's `/joint_states` comes once a bus cycle.

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use sandslope_bag::messages::{decode, Float64Array, JointState, StringMsg};
use serde_json::{json, Value};
use tungstenite::{ClientRequestBuilder, Message};

/// A channel as advertised: topic, schema name, schema encoding, schema.
type Advertised = (String, String, String, String);

/// What a viewer saw of a run: serverInfo, the channels by id, the messages by subscription
/// (1000 + channel id) as (messageData time, payload), and the run's stdout.
struct Watched {
    info: Value,
    channels: BTreeMap<u64, Advertised>,
    received: BTreeMap<u64, Vec<(u64, Vec<u8>)>>,
    stdout: Vec<u8>,
}

impl Watched {
    /// The id and advertisement of `topic`'s channel (schema encoding ros2msg checked).
    fn channel(&self, topic: &str) -> (u64, &Advertised) {
        let (&id, c) = self
            .channels
            .iter()
            .find(|(_, c)| c.0 == topic)
            .unwrap_or_else(|| panic!("{topic} not advertised"));
        assert_eq!(c.2, "ros2msg", "{topic}");
        (id, c)
    }

    /// The messages received on `topic`.
    fn on(&self, topic: &str) -> &[(u64, Vec<u8>)] {
        self.received.get(&(1000 + self.channel(topic).0)).map_or(&[], |v| v.as_slice())
    }
}

/// Runs `sandslope ARGS --foxglove 127.0.0.1:0`, connects to the address it says as a
/// Foxglove client, subscribes to every channel advertised and reads until the run closes the
/// connection. Bounded: the run is killed after 90 s whatever happens.
fn watch(args: &[&str]) -> Watched {
    watch_until(args, true)
}

/// [`watch`]; a command that does not end by itself (`serve`) is ended (SIGTERM) once the
/// stream closes, and its exit code is not looked at.
fn watch_until(args: &[&str], ends_itself: bool) -> Watched {
    let mut child = Command::new(env!("CARGO_BIN_EXE_sandslope"))
        .args(args)
        .args(["--foxglove", "127.0.0.1:0"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let pid = child.id();
    std::thread::spawn(move || {
        std::thread::sleep(Duration::from_secs(90));
        let _ = Command::new("kill").arg(pid.to_string()).status();
    });
    // The address, from the line the drive prints on stderr (port 0: a free one).
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    let mut url = None;
    let mut said = String::new();
    for _ in 0..50 {
        let mut line = String::new();
        if stderr.read_line(&mut line).unwrap() == 0 {
            break;
        }
        said.push_str(&line);
        if let Some(rest) = line.strip_prefix("foxglove: streaming on ") {
            url = rest.split_whitespace().next().map(str::to_string);
            break;
        }
    }
    let url = url.unwrap_or_else(|| panic!("no address said: {said}"));
    assert!(url.starts_with("ws://127.0.0.1:"), "{url}");
    let drain = std::thread::spawn(move || std::io::read_to_string(stderr).unwrap_or_default());

    let request = ClientRequestBuilder::new(url.parse().unwrap()).with_sub_protocol("foxglove.websocket.v1");
    let (mut ws, response) = tungstenite::connect(request).unwrap();
    assert_eq!(response.headers()["Sec-WebSocket-Protocol"], "foxglove.websocket.v1");

    let mut channels: BTreeMap<u64, Advertised> = BTreeMap::new();
    let mut server_info = None;
    // Per subscription (1000 + channel id): (messageData time, payload).
    let mut received: BTreeMap<u64, Vec<(u64, Vec<u8>)>> = BTreeMap::new();
    let start = Instant::now();
    loop {
        let m = match ws.read() {
            Ok(m) => m,
            Err(_) => break, // the drive ended and closed the connection
        };
        match m {
            Message::Text(t) => {
                let v: Value = serde_json::from_str(t.as_str()).unwrap();
                match v["op"].as_str().unwrap() {
                    "serverInfo" => server_info = Some(v),
                    "advertise" => {
                        let mut subs = Vec::new();
                        for c in v["channels"].as_array().unwrap() {
                            let id = c["id"].as_u64().unwrap();
                            assert_eq!(c["encoding"], "cdr");
                            let s = |k: &str| c[k].as_str().unwrap().to_string();
                            channels
                                .insert(id, (s("topic"), s("schemaName"), s("schemaEncoding"), s("schema")));
                            subs.push(json!({"id": 1000 + id, "channelId": id}));
                        }
                        let sub = json!({"op": "subscribe", "subscriptions": subs}).to_string();
                        ws.send(Message::Text(sub.into())).unwrap();
                    }
                    other => panic!("unexpected op {other}"),
                }
            }
            Message::Binary(b) => {
                // messageData: opcode 1, u32 subscription id, u64 time (ns), the message.
                assert_eq!(b[0], 1, "opcode");
                let sub = u32::from_le_bytes(b[1..5].try_into().unwrap()) as u64;
                let t = u64::from_le_bytes(b[5..13].try_into().unwrap());
                received.entry(sub).or_default().push((t, b[13..].to_vec()));
            }
            Message::Close(_) => break,
            _ => {}
        }
    }
    if !ends_itself {
        let _ = Command::new("kill").arg(pid.to_string()).status();
    }
    let out = child.wait_with_output().unwrap();
    let said = said + &drain.join().unwrap();
    assert!(out.status.success() || !ends_itself, "{said}");
    assert!(start.elapsed() < Duration::from_secs(80), "the drive did not stop by itself");
    let info = server_info.expect("serverInfo first");
    Watched { info, channels, received, stdout: out.stdout }
}

/// The emulated drives of this file run one at a time: two 50 Hz bus loops at once on a
/// loaded 2-core machine make each other's cycles late (the once-a-cycle counts failed once
/// in four runs so).
static ONE_DRIVE: std::sync::Mutex<()> = std::sync::Mutex::new(());

#[test]
fn a_drive_streams_its_channels_once_a_cycle() {
    let _one = ONE_DRIVE.lock().unwrap_or_else(|e| e.into_inner());
    let w = watch(&["drive", "--emulate", "--slope", "10", "--duration", "5", "--live", "--json"]);
    let report: Value = serde_json::from_slice(&w.stdout).unwrap();

    assert_eq!(w.info["name"], "sandslope drive");
    let (_, js_channel) = w.channel("/joint_states");
    assert_eq!(js_channel.1, "sensor_msgs/msg/JointState");
    // The ros2msg definition of sensor_msgs/JointState and its nested std_msgs/Header.
    for field in [
        "float64[] position",
        "float64[] velocity",
        "float64[] effort",
        "string[] name",
        "MSG: std_msgs/Header",
    ] {
        assert!(js_channel.3.contains(field), "schema lacks {field}: {}", js_channel.3);
    }
    assert_eq!(w.channel("/sandslope/commands").1 .1, "sensor_msgs/msg/JointState");
    assert_eq!(w.channel("/sandslope/run").1 .1, "std_msgs/msg/String");

    // The run's header, latched: its slope.
    let header = w.on("/sandslope/run");
    assert_eq!(header.len(), 1);
    assert!(decode::<StringMsg>(&header[0].1).unwrap().data.contains("slope_deg = 10\n"));
    assert_eq!(w.on("/sandslope/verdict").len(), 1);
    // `--live`: one /sandslope/live a stance the report lists, its ten labelled numbers.
    let live = w.on("/sandslope/live");
    assert_eq!(live.len(), report["live"].as_array().unwrap().len());
    assert!(!live.is_empty());
    for (_, bytes) in live {
        let m: Float64Array = decode(bytes).unwrap();
        assert_eq!(m.data.len(), 10);
        assert!(m.layout.dim[0].label.starts_with("tripod,k_s_n_m3,"));
    }

    // Once a cycle: 50 Hz (docs/drive.md's default --rate), six legs named in leg order, the
    // message's time its header's stamp, times increasing.
    let states = w.on("/joint_states");
    assert_eq!(w.on("/sandslope/commands").len(), states.len());
    let mut last = 0;
    for (t, bytes) in states {
        let m: JointState = decode(bytes).unwrap();
        let names: Vec<String> = (0..6).map(|j| format!("leg_{j}")).collect();
        assert_eq!(m.name, names);
        assert_eq!((m.position.len(), m.effort.len()), (6, 6));
        let stamp = m.header.stamp.sec as u64 * 1_000_000_000 + m.header.stamp.nanosec as u64;
        assert_eq!(stamp, *t);
        assert!(*t > last, "times not increasing");
        last = *t;
    }
    let cycles = report["cycles"].as_u64().unwrap();
    let span_s = (states.last().unwrap().0 - states[0].0) as f64 * 1e-9;
    // The gait's 5 s were covered (the client subscribes before the servos move).
    assert!(span_s >= 4.9, "{span_s} s streamed");
    // Every cycle of the stretch received, none twice: as many messages as cycles at the
    // rate the drive achieved (50 Hz, docs/drive.md's default --rate, on an idle machine;
    // cycle times are measured, so a loaded machine's late cycles are fewer, not missing).
    let rate_hz = report["rate_hz"].as_f64().unwrap();
    let expected = span_s * rate_hz + 1.0;
    assert!(
        (states.len() as f64 - expected).abs() <= 0.03 * expected,
        "{} messages over {span_s} s, expected {expected} (one a cycle at {rate_hz} Hz)",
        states.len()
    );
    // At most the first second of the run (the client connecting) missed.
    assert!(states.len() as f64 >= cycles as f64 - rate_hz, "{} messages, {cycles} cycles", states.len());
    assert!(states.len() as u64 <= cycles, "{} messages, {cycles} cycles", states.len());
    eprintln!(
        "{} JointState messages over {span_s:.3} s; the drive reported {cycles} cycles; {} live estimates",
        states.len(),
        live.len()
    );
}

/// `serve --drive --foxglove`: the served run streams the channels of `drive --foxglove`,
/// `/joint_states` once a bus cycle, and its verdict, then closes the stream (the server
/// serves on).
#[test]
fn a_served_drive_streams_its_channels() {
    let _one = ONE_DRIVE.lock().unwrap_or_else(|e| e.into_inner());
    let w = watch_until(
        &["serve", "--port", "0", "--drive", "--emulate", "--slope", "10", "--duration", "3"],
        false,
    );
    assert_eq!(w.info["name"], "sandslope drive");
    let header = w.on("/sandslope/run");
    assert_eq!(header.len(), 1);
    assert!(decode::<StringMsg>(&header[0].1).unwrap().data.contains("slope_deg = 10\n"));
    let verdict = w.on("/sandslope/verdict");
    assert_eq!(verdict.len(), 1);
    let verdict: Value = serde_json::from_str(&decode::<StringMsg>(&verdict[0].1).unwrap().data).unwrap();
    assert_eq!(verdict["outcome"], "completed", "{verdict}");
    // The stand-up (1 s, docs/drive.md) and 3 s of gait, once a cycle at 50 Hz (the default
    // --rate): one message a 20 ms cycle over the span streamed, none twice (a loaded
    // machine's late cycles make fewer, never more).
    let states = w.on("/joint_states");
    assert_eq!(w.on("/sandslope/commands").len(), states.len());
    let span_s = (states.last().unwrap().0 - states[0].0) as f64 * 1e-9;
    assert!(span_s >= 2.9, "{span_s} s streamed");
    let most = span_s * 50.0 + 1.0;
    let n = states.len() as f64;
    assert!(n <= most + 1.0 && n >= 0.8 * most, "{n} messages over {span_s} s, one a cycle is {most}");
    for (_, bytes) in states {
        let m: JointState = decode(bytes).unwrap();
        assert_eq!((m.name.len(), m.position.len()), (6, 6));
    }
    eprintln!("serve --drive: {} JointState messages over {span_s:.3} s", states.len());
}

/// `simulate --foxglove`: the walk of `--out walk.mcap` played once a viewer subscribes, every
/// sample of the 120 Hz trajectory on each of its four channels, in real time.
#[test]
fn a_simulated_walk_plays_to_a_viewer() {
    let started = Instant::now();
    let w = watch(&["simulate", "--slope", "10", "--duration", "1.5", "--json"]);
    assert_eq!(w.info["name"], "sandslope simulate");
    let types = [
        ("/sandslope/pose", "geometry_msgs/msg/PoseStamped"),
        ("/tf", "tf2_msgs/msg/TFMessage"),
        ("/joint_states", "sensor_msgs/msg/JointState"),
        ("/sandslope/leg_forces", "visualization_msgs/msg/MarkerArray"),
    ];
    let poses = w.on("/sandslope/pose");
    for (topic, ty) in types {
        assert_eq!(w.channel(topic).1 .1, ty);
        assert_eq!(w.on(topic).len(), poses.len(), "{topic}");
    }
    // 1.5 s at 120 Hz (--rate's default): samples 1/120 s apart from 0 to 1.5 s.
    assert!((180..=181).contains(&poses.len()), "{} poses", poses.len());
    let span_s = (poses.last().unwrap().0 - poses[0].0) as f64 * 1e-9;
    assert!((span_s - 1.5).abs() < 0.01, "{span_s}");
    // Played in real time: the run lasted at least the walk's 1.5 s.
    assert!(started.elapsed() >= Duration::from_millis(1500));
}

/// A port already taken: exit 2 naming the address, before the servos move, no log left.
#[test]
fn a_taken_port_stops_the_drive_before_it_moves() {
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = taken.local_addr().unwrap().to_string();
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("run.mcap");
    let out = Command::new(env!("CARGO_BIN_EXE_sandslope"))
        .args(["drive", "--emulate", "--duration", "2", "--foxglove", &addr, "--log"])
        .arg(&log)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains(&format!("--foxglove {addr}")) && err.contains("cannot listen"), "{err}");
    assert!(!err.contains("driving"), "the servos were started: {err}");
    assert!(!log.exists());
}
