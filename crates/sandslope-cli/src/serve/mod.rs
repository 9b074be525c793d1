//! `sandslope serve`: a local web explorer and a JSON API over the commands (docs/serve.md).
//!
//! The server is a second front end beside `main`: a request `GET /api/<command>?<flag>=<value>`
//! (or a POST of a JSON object) is read into the command's typed request of
//! `sandslope-request`, the one the command line builds from its flags (same fields, defaults,
//! checks and messages), and answered with the same library value the command's `--json`
//! prints, serialised the same way, so the two bodies are equal byte for byte. Neither clap nor
//! the command modules are used below this file ([`api`], [`data`]); the HTTP layer ([`http`])
//! parses requests, refuses what is too big or not addressed to this server, and runs every
//! API call on one of two bounded pools of compute threads (light and heavy), off the threads
//! that accept and read requests; [`conn`] caps the connections and times them out. The page
//! ([`page`]) and its scripts are embedded in the binary: nothing is fetched from the network.

pub mod api;
pub mod conn;
pub mod data;
pub mod http;
pub mod page;

use std::net::IpAddr;
use std::path::PathBuf;
use std::time::Duration;

use anyhow::{bail, Result};
use clap::Args;

use sandslope_io::presets::{DEFAULT_ROBOT, DEFAULT_TERRAIN};

/// Arguments of `sandslope serve`.
#[derive(Debug, Args)]
pub struct ServeArgs {
    /// Elevation model the Routes tab and `/api/plan` plan on (GeoTIFF or ESRI ASCII grid);
    /// the only file the server reads after starting. Without it, the Routes tab is off.
    #[arg(long, value_name = "FILE")]
    pub dem: Option<PathBuf>,
    /// Robot the page starts with and API requests use when they name none: a TOML file or a
    /// built-in preset. Requests may name built-in presets only.
    #[arg(long, value_name = "FILE|PRESET", default_value = DEFAULT_ROBOT)]
    pub robot: String,
    /// Terrain the page starts with and API requests use when they name none: a TOML file or a
    /// built-in preset. Requests may name built-in presets only.
    #[arg(long, value_name = "FILE|PRESET", default_value = DEFAULT_TERRAIN)]
    pub terrain: String,
    /// Port to listen on; 0 picks any free port (the URL is printed either way).
    #[arg(long, value_name = "N", default_value_t = 8750)]
    pub port: u16,
    /// Address to listen on. Anything but a loopback address exposes the server, which has
    /// no authentication, to the network.
    #[arg(long, value_name = "ADDR", default_value = "127.0.0.1")]
    pub host: IpAddr,
    /// Open the page in the default web browser once the server listens.
    #[arg(long)]
    pub open: bool,
    /// Threads that compute the heavy answers: phase maps, risk, simulations, plans, the DEM and
    /// downloads (default: the machine's cores). `predict`, `sweep` and the page have their own.
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Seconds a connection has to send a request's head, from opening or from the previous
    /// answer's end (so also how long an idle kept-alive connection stays open).
    #[arg(long, value_name = "SECONDS", default_value_t = 10.0)]
    pub header_timeout: f64,
    /// Seconds a client may read nothing of an answer before its connection is closed.
    #[arg(long, value_name = "SECONDS", default_value_t = 30.0)]
    pub send_timeout: f64,
    /// Most connections open at once (at most the open-file limit, `ulimit -n`, less 64); past
    /// it the connection idle longest is closed to make room.
    #[arg(long, value_name = "N", default_value_t = 512)]
    pub max_connections: usize,
    /// Another name the server may be reached by (the Host header), besides localhost and the
    /// address it listens on: a machine name or a reverse proxy's. Repeat for several.
    #[arg(long, value_name = "NAME")]
    pub allow_host: Vec<String>,
}

/// Checks a timeout flag: a finite number of seconds in 0.1..=86400.
fn seconds(flag: &str, value: f64) -> Result<Duration> {
    if !(0.1..=86_400.0).contains(&value) {
        bail!("--{flag} = {value} must be a number of seconds from 0.1 to 86400");
    }
    Ok(Duration::from_secs_f64(value))
}

/// Runs `sandslope serve` until the process is stopped.
pub fn run(args: ServeArgs) -> Result<()> {
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
    let served = api::Served::load(args.robot.clone(), args.terrain.clone(), args.dem.clone())?;
    let server = http::Server::bind(args.host, args.port, served, limits)?;
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
    server.serve()
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
