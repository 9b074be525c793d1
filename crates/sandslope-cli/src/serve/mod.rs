//! `sandslope serve`: a local web explorer and a JSON API over the commands (docs/serve.md).
//!
//! The server is a second front end beside `main`: a request `GET /api/<command>?<flag>=<value>`
//! is turned into the command's own argument list, parsed by the command's own clap `Args`
//! (same flags, defaults, checks and messages), and answered with the same library value the
//! command's `--json` prints, serialised the same way, so the two bodies are equal byte for
//! byte. Commands know nothing of the server ([`api`]); the HTTP layer ([`http`]) parses
//! requests, refuses what is too big, and runs every API call on a bounded pool of compute
//! threads, off the threads that accept and read requests. The page ([`page`]) and its scripts
//! are embedded in the binary: nothing is fetched from the network.

pub mod api;
pub mod data;
pub mod http;
pub mod page;

use std::net::IpAddr;
use std::path::PathBuf;

use anyhow::{bail, Context, Result};
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
    /// Threads that compute API answers (default: the machine's cores).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
}

/// Runs `sandslope serve` until the process is stopped.
pub fn run(args: ServeArgs) -> Result<()> {
    // Read everything the server will use now, so a bad file fails at start, not per request.
    sandslope_io::load_robot(&args.robot).context("--robot")?;
    sandslope_io::load_terrain(&args.terrain).context("--terrain")?;
    if let Some(dem) = &args.dem {
        sandslope_io::raster::read_raster(dem)?;
    }
    let threads = match args.threads {
        Some(0) => bail!("--threads = 0 must be at least 1"),
        Some(n) => n,
        None => std::thread::available_parallelism().map_or(2, |n| n.get()),
    };
    let served =
        api::Served { robot: args.robot.clone(), terrain: args.terrain.clone(), dem: args.dem.clone() };
    let server = http::Server::bind(args.host, args.port, served, threads)?;
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
