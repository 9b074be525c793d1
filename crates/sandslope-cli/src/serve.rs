//! `sandslope serve`: its flags, parsed into the configuration of `sandslope-serve`, which is
//! the server (docs/serve.md).

use std::net::IpAddr;
use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;
use sandslope_serve::drive::SignalFlags;
use sandslope_servo::session::DriveConfig;

use crate::commands::drive::{BusFlag, DriveRunArgs};

use sandslope_request::plan::DEM;
use sandslope_request::scenario::{ROBOT, TERRAIN};
use sandslope_serve::ServeConfig;

/// Arguments of `sandslope serve`.
#[derive(Debug, Args)]
pub struct ServeArgs {
    /// Elevation model the Routes tab and `/api/plan` plan on (GeoTIFF or ESRI ASCII grid);
    /// the only file the server reads after starting. Without it, the Routes tab is off.
    #[arg(long = DEM.flag, value_name = DEM.value_name)]
    pub dem: Option<PathBuf>,
    /// Robot the page starts with and API requests use when they name none: a TOML file or a
    /// built-in preset. Requests may name built-in presets only.
    #[arg(long = ROBOT.flag, value_name = ROBOT.value_name, default_value = ROBOT.default)]
    pub robot: String,
    /// Terrain the page starts with and API requests use when they name none: a TOML file or a
    /// built-in preset. Requests may name built-in presets only.
    #[arg(long = TERRAIN.flag, value_name = TERRAIN.value_name, default_value = TERRAIN.default)]
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
    /// Drive the robot (--robot's [servos]) while serving: the page's Drive tab shows the run
    /// live (time, leg speed, k_s with its 90% interval, the risk, a halt on risk) and can stop
    /// it. Needs --drive-port or --emulate; the run's flags are `sandslope drive`'s.
    #[arg(long, help_heading = "Driving (docs/drive.md)")]
    pub drive: bool,
    /// With --drive: the serial port of the Protocol 2.0 adapter (drive's --port).
    #[arg(long, value_name = "PATH", requires = "drive", help_heading = "Driving (docs/drive.md)")]
    pub drive_port: Option<PathBuf>,
    /// With --drive: drive a bus of emulated XL330s on a pseudo-terminal instead of a port.
    #[arg(long, requires = "drive", conflicts_with = "drive_port", help_heading = "Driving (docs/drive.md)")]
    pub emulate: bool,
    /// With --drive: stream the run to Foxglove over its WebSocket protocol on ADDR
    /// (127.0.0.1:8765 when none is given), as `drive --foxglove` does (docs/bags.md).
    #[arg(long, value_name = "ADDR", num_args = 0..=1, requires = "drive",
        default_missing_value = sandslope_io::foxglove::DEFAULT_ADDR, help_heading = "Driving (docs/drive.md)")]
    pub foxglove: Option<String>,
    #[command(flatten, next_help_heading = "Driving (docs/drive.md)")]
    pub drive_run: DriveRunArgs,
}

/// `--drive`'s typed run, built as `sandslope drive` builds it from the same flags.
fn drive_config(args: &ServeArgs) -> Result<Option<DriveConfig>> {
    if !args.drive {
        if args.drive_run.given() {
            bail!("the driving flags (--slope, --duration, --stop-on-risk, --emulate-*, ...) need --drive");
        }
        return Ok(None);
    }
    let bus = match (&args.drive_port, args.emulate) {
        (Some(p), _) => BusFlag::Port(p.clone()),
        (None, true) => BusFlag::Emulate,
        (None, false) => bail!("--drive needs --drive-port PATH (the adapter's serial port) or --emulate"),
    };
    // The run's flags given, else their defaults: the drive table's.
    let fields = args.drive_run.fields(matches!(bus, BusFlag::Emulate))?;
    let robot = sandslope_io::load_robot(&args.robot)?;
    let terrain = sandslope_io::load_terrain(&args.terrain)?;
    Ok(Some(crate::commands::drive::config(&fields, robot, &args.robot, terrain, bus, true)?))
}

/// Runs `sandslope serve` until the process is stopped: the flags into the server's
/// configuration, checked and served by `sandslope-serve`.
pub fn run(args: ServeArgs) -> Result<()> {
    let flags = SignalFlags {
        stop: &crate::error::STOP,
        driving: &crate::error::DRIVING,
        signal: &crate::error::STOP_SIGNAL,
    };
    let drive_log = args.drive_run.log.clone();
    // The served run writes its log as the CSV flight recorder only; `drive --log run.mcap`
    // keeps the rows in memory and writes them as ROS 2 messages when the run ends.
    if let Some(path) =
        drive_log.as_ref().filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("mcap")))
    {
        bail!(
            "--log {}: a served drive writes its log as CSV (the flight recorder, docs/drive.md); give a .csv path, or record an MCAP with `sandslope drive --log run.mcap`",
            path.display()
        );
    }
    let drive = drive_config(&args)?.map(|c| (c, flags));
    sandslope_serve::run(ServeConfig {
        dem: args.dem,
        robot: args.robot,
        terrain: args.terrain,
        port: args.port,
        host: args.host,
        open: args.open,
        threads: args.threads,
        header_timeout: args.header_timeout,
        send_timeout: args.send_timeout,
        max_connections: args.max_connections,
        allow_host: args.allow_host,
        drive,
        drive_log,
        drive_foxglove: args.foxglove,
    })
}
