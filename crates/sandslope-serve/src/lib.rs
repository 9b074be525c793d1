//! # sandslope-serve
//!
//! `sandslope serve`: a local web explorer and a JSON API over the commands (docs/serve.md).
//!
//! The server is a front end beside the command line: a request `GET /api/<command>?<flag>=<value>`
//! (or a POST of a JSON object) is read into the command's typed request of
//! `sandslope-request`, the one the command line builds from its flags (same fields, defaults,
//! checks and messages), and answered with the same library value the command's `--json`
//! prints, serialised the same way, so the two bodies are equal byte for byte. This crate
//! depends on neither the command-line crate nor its argument parser: the CLI's `serve` only
//! parses its flags into a [`ServeConfig`] and calls [`run`].
//!
//! Files, from the bottom up: [`reply`] (what every route answers with) and [`served`] (what
//! the server was started with); [`api`] (`/api/<command>`), [`data`] (`/data/...` and
//! `/download/...`, the page's extras) and [`page`] (the embedded page); [`conn`] (the accept
//! loop, the cap on connections and their timeouts, handed the HTTP layer as a function) and
//! [`http`] (requests: Host and Origin checks, the light and heavy compute pools, answers
//! streamed in chunks); [`drive`] is `--drive` (a run driven on a thread of its own, its status
//! and stop). The page and its scripts are embedded in the binary: nothing is
//! fetched from the network.

#![warn(missing_docs)]

pub mod api;
pub mod conn;
pub mod data;
pub mod drive;
pub mod http;
pub mod page;
pub mod reply;
pub mod served;

use std::net::IpAddr;
use std::path::PathBuf;
use std::time::Duration;

use anyhow::{bail, Result};
use sandslope_servo::session::{emulator_summary, DriveConfig, Session};

/// How a server is run: what `sandslope serve`'s flags give (each field is the flag of its
/// name; docs/serve.md).
#[derive(Debug, Clone)]
pub struct ServeConfig {
    /// The elevation model the Routes tab and `/api/plan` plan on (`--dem`).
    pub dem: Option<PathBuf>,
    /// Robot file or preset requests use when they name none (`--robot`).
    pub robot: String,
    /// Terrain file or preset requests use when they name none (`--terrain`).
    pub terrain: String,
    /// Port to listen on; 0 picks any free port (`--port`).
    pub port: u16,
    /// Address to listen on (`--host`).
    pub host: IpAddr,
    /// Open the page in the default web browser once the server listens (`--open`).
    pub open: bool,
    /// Threads that compute the heavy answers (`--threads`; default the machine's cores).
    pub threads: Option<usize>,
    /// Seconds a connection has to send a request's head (`--header-timeout`).
    pub header_timeout: f64,
    /// Seconds a client may read nothing of an answer (`--send-timeout`).
    pub send_timeout: f64,
    /// Most connections open at once (`--max-connections`).
    pub max_connections: usize,
    /// Other names the server may be reached by (`--allow-host`).
    pub allow_host: Vec<String>,
    /// The robot driven while serving (`--drive`): the run `sandslope drive` makes of the same
    /// flags, and the signal handler's flags ([`drive`]).
    pub drive: Option<(DriveConfig, drive::SignalFlags)>,
    /// The driven run's log (`--log`), written as `sandslope drive --log` writes it.
    pub drive_log: Option<PathBuf>,
    /// Stream the driven run to Foxglove on this address (`--foxglove`), as `sandslope drive
    /// --foxglove` does (docs/bags.md, "Watch live").
    pub drive_foxglove: Option<String>,
}

/// Checks a timeout flag: a finite number of seconds in 0.1..=86400.
fn seconds(flag: &str, value: f64) -> Result<Duration> {
    if !(0.1..=86_400.0).contains(&value) {
        bail!("--{flag} = {value} must be a number of seconds from 0.1 to 86400");
    }
    Ok(Duration::from_secs_f64(value))
}

/// Runs the server until the process is stopped: checks the configuration (errors name its
/// flag), reads the robot, terrain and DEM, listens and prints the URL.
pub fn run(args: ServeConfig) -> Result<()> {
    let cores = std::thread::available_parallelism().map_or(2, |n| n.get());
    let threads = match args.threads {
        Some(0) => bail!("--threads = 0 must be at least 1"),
        Some(n) => n,
        None => cores,
    };
    if args.max_connections == 0 {
        bail!("--max-connections = 0 must be at least 1");
    }
    let mut max_connections = args.max_connections;
    if let Some(files) = conn::open_file_limit() {
        let room = files.saturating_sub(conn::RESERVED_FDS).max(1);
        if room < max_connections {
            eprintln!(
                "note: at most {room} connections (--max-connections {max_connections}): this process may open \
                 {files} files (ulimit -n), {} of them kept for other uses",
                conn::RESERVED_FDS
            );
            max_connections = room;
        }
    }
    let limits = http::Limits {
        conn: conn::ConnLimits {
            header_timeout: seconds("header-timeout", args.header_timeout)?,
            send_timeout: seconds("send-timeout", args.send_timeout)?,
            max_connections,
        },
        threads,
        light_threads: cores,
        allowed_hosts: args.allow_host.clone(),
    };
    // Read everything the server will use now, so a bad file fails at start, not per request.
    let served = served::Served::load(args.robot.clone(), args.terrain.clone(), args.dem.clone())?;
    // The run: its monitor's grid and its bus, before listening (a missing port fails here,
    // nothing having moved).
    if let Some(p) = &args.drive_log {
        sandslope_files::check_parent_exists(p)?;
    }
    // The Foxglove server first: a port already taken stops the command before anything moves.
    let foxglove = match (&args.drive, &args.drive_foxglove) {
        (Some(_), Some(addr)) => Some(sandslope_io::foxglove::DriveStream::start(addr)?),
        _ => None,
    };
    let session = match args.drive {
        Some((config, flags)) => Some((Session::open(config)?, flags)),
        None => None,
    };
    let mut server = match http::Server::bind(args.host, args.port, served, limits) {
        Ok(s) => s,
        Err(e) => {
            if let Some(r) = session.and_then(|(s, _)| s.close()) {
                eprintln!("{}", emulator_summary(&r));
            }
            return Err(e);
        }
    };
    let driving = match session {
        Some((session, flags)) => {
            let servos = session.config().settings.servos.len();
            let log = args.drive_log.clone().map(|path| drive::LogFile {
                path,
                robot: args.robot.clone(),
                terrain: args.terrain.clone(),
            });
            if let Some(f) = &foxglove {
                f.header(&sandslope_servo::log::log_meta(&session, &args.robot, &args.terrain));
            }
            let thread = drive::DriveThread::start(session, flags, log, foxglove)?;
            server.show_drive(std::sync::Arc::clone(&thread.live));
            eprintln!(
                "driving {servos} servos: the page's Drive tab shows the run; its stop button or Ctrl-C stops the gait and turns the torque off"
            );
            Some(thread)
        }
        None => None,
    };
    let url = format!("http://{}/", server.address());
    if !args.host.is_loopback() {
        eprintln!(
            "warning: listening on {}: the server has no authentication; anyone who can reach this address can \
             use it (the default, 127.0.0.1, serves this computer only)",
            args.host
        );
    }
    println!("sandslope serve: {url}");
    use std::io::Write;
    std::io::stdout().flush()?;
    if args.open {
        open_browser(&url);
    }
    let result = server.serve();
    // The server failed: stop the gait and turn the torque off before the process ends.
    if let Some(thread) = driving {
        thread.stop_and_join();
    }
    result
}

/// Asks the desktop to open `url`; a failure is a note, not an error (the URL is printed).
fn open_browser(url: &str) {
    let opener = if cfg!(target_os = "macos") {
        "open"
    } else if cfg!(windows) {
        "explorer"
    } else {
        "xdg-open"
    };
    if let Err(e) = std::process::Command::new(opener).arg(url).spawn() {
        eprintln!("note: could not open a browser ({opener}: {e}); open {url} by hand");
    }
}
