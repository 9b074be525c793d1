//! Watching a run live in Foxglove (docs/bags.md, "Watch live"): a WebSocket server speaking
//! the `foxglove.websocket.v1` subprotocol (Foxglove's documented WebSocket protocol:
//! `serverInfo`, `advertise`, `subscribe`/`unsubscribe`, binary `messageData`), carrying the
//! same ROS 2 channels, CDR-encoded with their `ros2msg` schemas, as the MCAP files of
//! [`crate::mcap_out`]. The WebSocket itself is the `tungstenite` crate's (cargo feature
//! `foxglove`); without it [`LiveServer::start`] says the build lacks it.
//!
//! The server never holds the robot back: each viewer has its own thread and a bounded queue,
//! and a viewer too slow to keep up loses messages rather than slowing the bus.

use std::net::SocketAddr;

use anyhow::Result;

use crate::mcap_out::{cycle_joint_states, live_message, LiveRecord, RosSink};
use crate::servo_log::ServoLogRow;
use sandslope_bag::messages::RosMessage;

/// The WebSocket subprotocol a Foxglove client asks for.
pub const SUBPROTOCOL: &str = "foxglove.websocket.v1";
/// The address `--foxglove` listens on when given none: loopback only.
pub const DEFAULT_ADDR: &str = "127.0.0.1:8765";
/// Viewers served at once; more are refused at the handshake.
pub const MAX_CLIENTS: usize = 16;
/// Messages queued for one viewer before newer ones are dropped for it.
pub const QUEUE_MESSAGES: usize = 4096;

/// Nanoseconds since the Unix epoch, now.
fn now_ns() -> u64 {
    std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_nanos() as u64)
}

#[cfg(feature = "foxglove")]
mod server;
#[cfg(feature = "foxglove")]
pub use server::LiveServer;

/// Without the `foxglove` feature: a server that cannot start.
#[cfg(not(feature = "foxglove"))]
#[derive(Debug)]
pub struct LiveServer(());

#[cfg(not(feature = "foxglove"))]
impl LiveServer {
    /// Always an error: this build has no WebSocket server.
    pub fn start(_addr: &str, _name: &str) -> Result<LiveServer> {
        anyhow::bail!("--foxglove: this sandslope was built without its `foxglove` feature (cargo build --features foxglove)")
    }
    /// The address listened on.
    pub fn local_addr(&self) -> SocketAddr {
        unreachable!("a LiveServer is never built without the foxglove feature")
    }
    /// Sends `message` on `topic` (never reached).
    pub fn publish<T: RosMessage>(&self, _topic: &str, _time_ns: u64, _message: &T) {}
    /// Keeps `message` for every later subscriber (never reached).
    pub fn latch<T: RosMessage>(&self, _topic: &str, _time_ns: u64, _message: &T) {}
    /// Advertises `topic` (never reached).
    pub fn advertise<T: RosMessage>(&self, _topic: &str) {}
    /// Waits for a subscriber (never reached).
    pub fn wait_for_subscriber(&self, _timeout: std::time::Duration) -> bool {
        false
    }
}

impl RosSink for LiveServer {
    fn send<T: RosMessage>(&mut self, topic: &str, time_ns: u64, message: &T) -> Result<()> {
        self.publish(topic, time_ns, message);
        Ok(())
    }
}

/// A `drive` run streamed live (`drive --foxglove`): the channels of `drive --log run.mcap`
/// (docs/bags.md), each sent as it happens. Times are the wall clock at the first row plus
/// the gait time since it, so Foxglove's live view shows them as now. Its methods take
/// `&self`, so the drive's sample and live-estimate callbacks can both hold it.
#[derive(Debug)]
pub struct DriveStream {
    server: LiveServer,
    inner: std::sync::Mutex<Cycle>,
}

/// The bus cycle being gathered and the clock.
#[derive(Debug, Default)]
struct Cycle {
    rows: Vec<ServoLogRow>,
    clock: Option<(f64, u64)>,
    last_ns: u64,
}

impl Cycle {
    fn time_ns(&mut self, t_s: f64) -> u64 {
        let (t0, w0) = *self.clock.get_or_insert((t_s, now_ns()));
        let t = w0.saturating_add(((t_s - t0).max(0.0) * 1e9) as u64).max(self.last_ns);
        self.last_ns = t;
        t
    }

    fn flush(&mut self, server: &LiveServer) {
        if let Some(first) = self.rows.first() {
            let t_ns = self.time_ns(first.time_s);
            let (state, command) = cycle_joint_states(&self.rows, t_ns);
            server.publish("/joint_states", t_ns, &state);
            server.publish("/sandslope/commands", t_ns, &command);
            self.rows.clear();
        }
    }
}

impl DriveStream {
    /// Starts the server on `addr` and says where to connect (on stderr).
    pub fn start(addr: &str) -> Result<DriveStream> {
        let server = LiveServer::start(addr, "sandslope drive")?;
        use sandslope_bag::messages::{Float64Array, JointState, StringMsg};
        server.advertise::<StringMsg>(sandslope_bag::series::RUN_TOPIC);
        server.advertise::<JointState>("/joint_states");
        server.advertise::<JointState>("/sandslope/commands");
        server.advertise::<Float64Array>("/sandslope/live");
        server.advertise::<StringMsg>("/sandslope/verdict");
        eprintln!("foxglove: streaming on ws://{} (in Foxglove: Open connection)", server.local_addr());
        Ok(DriveStream { server, inner: Default::default() })
    }

    /// The address listened on.
    pub fn local_addr(&self) -> SocketAddr {
        self.server.local_addr()
    }

    fn cycle(&self) -> std::sync::MutexGuard<'_, Cycle> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The run's header (`key = value` pairs) as `/sandslope/run`, kept for every viewer
    /// that subscribes later.
    pub fn header(&self, meta: &[(&str, String)]) {
        let text: String = meta.iter().map(|(k, v)| format!("{k} = {v}\n")).collect();
        self.server.latch(
            sandslope_bag::series::RUN_TOPIC,
            now_ns(),
            &sandslope_bag::messages::StringMsg { data: text },
        );
    }

    /// One servo's row of a bus cycle; a cycle goes out when the next one's first row comes
    /// (or at [`DriveStream::finish`]).
    pub fn row(&self, row: ServoLogRow) {
        let mut cycle = self.cycle();
        if cycle.rows.first().is_some_and(|r| r.time_s != row.time_s) {
            cycle.flush(&self.server);
        }
        cycle.rows.push(row);
    }

    /// A live estimate, as `/sandslope/live` (it may come amid a cycle's rows, which stay
    /// gathered; times never go back, as in `drive --log run.mcap`).
    pub fn live(&self, record: &LiveRecord) {
        let mut cycle = self.cycle();
        let t_ns = cycle.time_ns(record.time_s);
        self.server.publish("/sandslope/live", t_ns, &live_message(record));
    }

    /// The run's end: the last cycle and `/sandslope/verdict`; then what is queued is sent
    /// and the viewers are closed.
    pub fn finish(self, verdict: &str) {
        let mut cycle = self.cycle();
        cycle.flush(&self.server);
        let t_ns = cycle.last_ns;
        drop(cycle);
        self.server.publish(
            "/sandslope/verdict",
            t_ns,
            &sandslope_bag::messages::StringMsg { data: verdict.into() },
        );
    }
}

/// `simulate --foxglove`: the walk of `simulate --out walk.mcap`, played to the viewers in
/// real time (each sample sent at its simulated time after the start), after waiting up to
/// `wait_s` for the first viewer to subscribe.
pub fn play_simulation(
    addr: &str,
    trajectory: &sandslope::simulate::Trajectory,
    geometry: &sandslope::simulate::Geometry,
    slope_deg: f64,
    wait_s: f64,
) -> Result<()> {
    use sandslope_bag::messages::{JointState, MarkerArray, PoseStamped, TfMessage};
    let mut server = LiveServer::start(addr, "sandslope simulate")?;
    server.advertise::<PoseStamped>("/sandslope/pose");
    server.advertise::<TfMessage>("/tf");
    server.advertise::<JointState>("/joint_states");
    server.advertise::<MarkerArray>("/sandslope/leg_forces");
    eprintln!("foxglove: streaming on ws://{} (in Foxglove: Open connection)", server.local_addr());
    server.wait_for_subscriber(std::time::Duration::from_secs_f64(wait_s.max(0.0)));
    let mut paced = Paced { server: &mut server, start: std::time::Instant::now(), wall0: now_ns() };
    crate::mcap_out::simulation_messages(trajectory, geometry, slope_deg, &mut paced)
}

/// A sink that sends each message when its time (from 0) has come.
struct Paced<'a> {
    server: &'a mut LiveServer,
    start: std::time::Instant,
    wall0: u64,
}

impl RosSink for Paced<'_> {
    fn send<T: RosMessage>(&mut self, topic: &str, time_ns: u64, message: &T) -> Result<()> {
        let due = std::time::Duration::from_nanos(time_ns);
        if let Some(wait) = due.checked_sub(self.start.elapsed()) {
            std::thread::sleep(wait);
        }
        self.server.publish(topic, self.wall0.saturating_add(time_ns), message);
        Ok(())
    }
}
