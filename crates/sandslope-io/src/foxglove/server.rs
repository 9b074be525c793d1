//! The `foxglove.websocket.v1` server itself (feature `foxglove`): one thread accepting
//! connections, one thread a viewer.

use std::collections::BTreeMap;
use std::io::ErrorKind;
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::Duration;

use anyhow::{anyhow, Result};
use serde_json::{json, Value};
use tungstenite::handshake::server::{ErrorResponse, Request, Response};
use tungstenite::{Message, WebSocket};

use super::{MAX_CLIENTS, QUEUE_MESSAGES, SUBPROTOCOL};
use sandslope_bag::messages::{encode, RosMessage};

/// A channel advertised to the viewers.
struct Channel {
    id: u32,
    topic: String,
    schema_name: &'static str,
    schema: String,
    /// The message a new subscriber gets at once (the run's header).
    latched: Option<(u64, Vec<u8>)>,
}

impl Channel {
    fn advertisement(&self) -> Value {
        json!({
            "id": self.id,
            "topic": self.topic,
            "encoding": "cdr",
            "schemaName": self.schema_name,
            "schema": self.schema,
            "schemaEncoding": "ros2msg",
        })
    }
}

/// A viewer: its queue and its subscriptions (channel id to subscription id).
struct Client {
    id: u64,
    tx: SyncSender<Message>,
    subscriptions: BTreeMap<u32, u32>,
}

#[derive(Default)]
struct State {
    channels: Vec<Channel>,
    clients: Vec<Client>,
    next_client: u64,
}

struct Shared {
    state: Mutex<State>,
    subscribed: Condvar,
    stop: AtomicBool,
    server_info: String,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, State> {
        // A viewer's thread never panics holding the lock; recover the state if one did.
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// `messageData`: opcode 1, the subscription id (u32), the time (u64 ns), the CDR bytes.
fn message_data(subscription: u32, time_ns: u64, data: &[u8]) -> Message {
    let mut frame = Vec::with_capacity(13 + data.len());
    frame.push(1u8);
    frame.extend_from_slice(&subscription.to_le_bytes());
    frame.extend_from_slice(&time_ns.to_le_bytes());
    frame.extend_from_slice(data);
    Message::Binary(frame.into())
}

fn advertise(channels: &[&Channel]) -> Message {
    let list: Vec<Value> = channels.iter().map(|c| c.advertisement()).collect();
    Message::Text(json!({"op": "advertise", "channels": list}).to_string().into())
}

/// A Foxglove WebSocket server (`foxglove.websocket.v1`) publishing ROS 2 messages.
pub struct LiveServer {
    shared: Arc<Shared>,
    addr: SocketAddr,
    accept: Option<JoinHandle<()>>,
    viewers: Arc<Mutex<Vec<JoinHandle<()>>>>,
}

impl std::fmt::Debug for LiveServer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LiveServer").field("addr", &self.addr).finish()
    }
}

impl LiveServer {
    /// Listens on `addr` (`host:port`; port 0 takes a free one, see
    /// [`LiveServer::local_addr`]) and serves viewers from background threads until dropped.
    pub fn start(addr: &str, name: &str) -> Result<LiveServer> {
        let listener =
            TcpListener::bind(addr).map_err(|e| anyhow!("--foxglove {addr}: cannot listen there: {e}"))?;
        let local = listener.local_addr()?;
        listener.set_nonblocking(true)?;
        let session = super::now_ns().to_string();
        let server_info = json!({
            "op": "serverInfo",
            "name": name,
            "capabilities": [],
            "supportedEncodings": [],
            "metadata": {},
            "sessionId": session,
        })
        .to_string();
        let shared = Arc::new(Shared {
            state: Mutex::new(State::default()),
            subscribed: Condvar::new(),
            stop: AtomicBool::new(false),
            server_info,
        });
        let viewers = Arc::new(Mutex::new(Vec::new()));
        let (s, v) = (shared.clone(), viewers.clone());
        let accept = std::thread::Builder::new()
            .name("foxglove-accept".into())
            .spawn(move || accept_loop(listener, s, v))?;
        Ok(LiveServer { shared, addr: local, accept: Some(accept), viewers })
    }

    /// The address listened on.
    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    fn publish_bytes(
        &self,
        topic: &str,
        time_ns: u64,
        schema: (&'static str, String),
        data: Vec<u8>,
        latch: bool,
    ) {
        let mut state = self.shared.lock();
        let index = self.channel(&mut state, topic, schema);
        let id = state.channels[index].id;
        for c in &state.clients {
            if let Some(&sub) = c.subscriptions.get(&id) {
                // A full queue (a viewer not keeping up) loses this message, not the robot's time.
                let _ = c.tx.try_send(message_data(sub, time_ns, &data));
            }
        }
        if latch {
            state.channels[index].latched = Some((time_ns, data));
        }
    }

    /// Advertises `topic` before its first message, so a viewer can subscribe to it at once.
    pub fn advertise<T: RosMessage>(&self, topic: &str) {
        self.channel(&mut self.shared.lock(), topic, (T::TYPE, T::definition()));
    }

    /// The index of `topic`'s channel, advertised to every viewer when new.
    fn channel(&self, state: &mut State, topic: &str, schema: (&'static str, String)) -> usize {
        if let Some(i) = state.channels.iter().position(|c| c.topic == topic) {
            return i;
        }
        let channel = Channel {
            id: state.channels.len() as u32 + 1,
            topic: topic.to_string(),
            schema_name: schema.0,
            schema: schema.1,
            latched: None,
        };
        let ad = advertise(&[&channel]);
        for c in &state.clients {
            let _ = c.tx.try_send(ad.clone());
        }
        state.channels.push(channel);
        state.channels.len() - 1
    }

    /// Sends `message` on `topic` to every viewer subscribed to it (the channel advertised on
    /// first use).
    pub fn publish<T: RosMessage>(&self, topic: &str, time_ns: u64, message: &T) {
        self.publish_bytes(topic, time_ns, (T::TYPE, T::definition()), encode(message), false);
    }

    /// As [`LiveServer::publish`], and keeps the message for every later subscriber.
    pub fn latch<T: RosMessage>(&self, topic: &str, time_ns: u64, message: &T) {
        self.publish_bytes(topic, time_ns, (T::TYPE, T::definition()), encode(message), true);
    }

    /// Waits up to `timeout` for a viewer to subscribe to a channel; whether one did.
    pub fn wait_for_subscriber(&self, timeout: Duration) -> bool {
        let state = self.shared.lock();
        let (state, _) = self
            .shared
            .subscribed
            .wait_timeout_while(state, timeout, |s| s.clients.iter().all(|c| c.subscriptions.is_empty()))
            .unwrap_or_else(|e| e.into_inner());
        state.clients.iter().any(|c| !c.subscriptions.is_empty())
    }
}

impl Drop for LiveServer {
    /// Sends what is queued, closes every viewer and stops listening.
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::SeqCst);
        if let Some(a) = self.accept.take() {
            let _ = a.join();
        }
        let viewers = std::mem::take(&mut *self.viewers.lock().unwrap_or_else(|e| e.into_inner()));
        for v in viewers {
            let _ = v.join();
        }
    }
}

fn accept_loop(listener: TcpListener, shared: Arc<Shared>, viewers: Arc<Mutex<Vec<JoinHandle<()>>>>) {
    while !shared.stop.load(Ordering::SeqCst) {
        match listener.accept() {
            Ok((stream, _)) => {
                let s = shared.clone();
                let handle = std::thread::Builder::new().name("foxglove-viewer".into()).spawn(move || {
                    if let Some(ws) = handshake(stream) {
                        serve(ws, &s);
                    }
                });
                if let Ok(h) = handle {
                    viewers.lock().unwrap_or_else(|e| e.into_inner()).push(h);
                }
            }
            Err(e) if e.kind() == ErrorKind::WouldBlock => std::thread::sleep(Duration::from_millis(20)),
            Err(_) => std::thread::sleep(Duration::from_millis(20)),
        }
    }
}

/// The WebSocket handshake, accepting only clients that ask for `foxglove.websocket.v1`.
fn handshake(stream: TcpStream) -> Option<WebSocket<TcpStream>> {
    stream.set_nonblocking(false).ok()?;
    stream.set_read_timeout(Some(Duration::from_secs(5))).ok()?;
    stream.set_write_timeout(Some(Duration::from_secs(2))).ok()?;
    // The closure's type is tungstenite's handshake callback; its error is an HTTP response.
    #[allow(clippy::result_large_err)]
    let check = |request: &Request, mut response: Response| -> Result<Response, ErrorResponse> {
        let asks = request
            .headers()
            .get_all("Sec-WebSocket-Protocol")
            .iter()
            .filter_map(|v| v.to_str().ok())
            .any(|v| v.split(',').any(|p| p.trim() == SUBPROTOCOL));
        if !asks {
            let mut refusal = ErrorResponse::new(Some(format!("this server speaks only {SUBPROTOCOL}")));
            *refusal.status_mut() = tungstenite::http::StatusCode::BAD_REQUEST;
            return Err(refusal);
        }
        response
            .headers_mut()
            .insert("Sec-WebSocket-Protocol", tungstenite::http::HeaderValue::from_static(SUBPROTOCOL));
        Ok(response)
    };
    tungstenite::accept_hdr(stream, check).ok()
}

/// Serves one viewer: `serverInfo` and the channels so far, then its queue and its requests,
/// until it leaves or the server stops.
fn serve(mut ws: WebSocket<TcpStream>, shared: &Shared) {
    let (tx, rx): (SyncSender<Message>, Receiver<Message>) = sync_channel(QUEUE_MESSAGES);
    let id = {
        let mut state = shared.lock();
        if state.clients.len() >= MAX_CLIENTS {
            let _ = ws.close(None);
            let _ = ws.flush();
            return;
        }
        let id = state.next_client;
        state.next_client += 1;
        let _ = tx.try_send(Message::Text(shared.server_info.clone().into()));
        if !state.channels.is_empty() {
            let _ = tx.try_send(advertise(&state.channels.iter().collect::<Vec<_>>()));
        }
        state.clients.push(Client { id, tx, subscriptions: BTreeMap::new() });
        id
    };
    let _ = ws.get_ref().set_read_timeout(Some(Duration::from_millis(10)));
    // A write that fails (the viewer gone, or not reading for the 2 s write timeout) ends it.
    'serve: loop {
        let mut wrote = false;
        while let Ok(m) = rx.try_recv() {
            if ws.write(m).is_err() {
                break 'serve;
            }
            wrote = true;
        }
        if wrote && ws.flush().is_err() {
            break;
        }
        if shared.stop.load(Ordering::SeqCst) {
            // Whatever was published before the stop is in the queue: send it, then close.
            while let Ok(m) = rx.try_recv() {
                if ws.write(m).is_err() {
                    break 'serve;
                }
            }
            let _ = ws.close(None);
            let _ = ws.flush();
            break;
        }
        match ws.read() {
            Ok(Message::Text(text)) => request(text.as_str(), id, shared),
            Ok(Message::Close(_)) => break,
            Ok(_) => {}
            Err(tungstenite::Error::Io(e))
                if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
            Err(_) => break,
        }
    }
    shared.lock().clients.retain(|c| c.id != id);
}

/// A viewer's `subscribe` or `unsubscribe` (other operations are not offered in serverInfo's
/// capabilities and are ignored).
fn request(text: &str, id: u64, shared: &Shared) {
    let Ok(v) = serde_json::from_str::<Value>(text) else { return };
    let mut state = shared.lock();
    let State { channels, clients, .. } = &mut *state;
    let Some(client) = clients.iter_mut().find(|c| c.id == id) else { return };
    match v["op"].as_str() {
        Some("subscribe") => {
            for s in v["subscriptions"].as_array().into_iter().flatten() {
                let (Some(sub), Some(channel)) = (s["id"].as_u64(), s["channelId"].as_u64()) else {
                    continue;
                };
                let (Ok(sub), Ok(channel)) = (u32::try_from(sub), u32::try_from(channel)) else { continue };
                let Some(c) = channels.iter().find(|c| c.id == channel) else { continue };
                client.subscriptions.insert(channel, sub);
                if let Some((t, data)) = &c.latched {
                    let _ = client.tx.try_send(message_data(sub, *t, data));
                }
            }
            shared.subscribed.notify_all();
        }
        Some("unsubscribe") => {
            let ids: Vec<u64> =
                v["subscriptionIds"].as_array().into_iter().flatten().filter_map(Value::as_u64).collect();
            client.subscriptions.retain(|_, sub| !ids.contains(&u64::from(*sub)));
        }
        _ => {}
    }
}
