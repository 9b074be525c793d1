//! The bench's chores of `sandslope drive` (docs/drive.md, "On the bench"): `--zero` reads each
//! servo's Present Position with the legs set at leg angle 0 and writes the offsets into the
//! robot file; `--emulate --pty` serves the emulated servos alone on a pseudo-terminal whose
//! path is printed, for Dynamixel Wizard or the ROBOTIS SDK.

use std::io::Write;
use std::path::Path;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Result};
use sandslope_servo::emulator::{pty_path, Emulator};
use sandslope_servo::session::{emulator_config, BusChoice, DriveConfig};

use crate::error::KeepLog;

/// `drive --zero`: the servos pinged and read, nothing written to them, nothing moved; their
/// Present Positions written into `robot_path`'s `[servos] zero_offsets` (the rest of the file
/// kept as it was).
pub(super) fn zero(config: &DriveConfig, robot_path: &str) -> Result<()> {
    if !Path::new(robot_path).is_file() {
        bail!(
            "--zero writes the offsets into the robot file, but --robot {robot_path} is not a file (a preset?). Fix: write it to a file first (sandslope presets robot {robot_path} > robot.toml) and give --robot robot.toml"
        );
    }
    let text = std::fs::read_to_string(robot_path).map_err(|e| anyhow!("--robot {robot_path}: {e}"))?;
    let read = sandslope_servo::zero::zero_offsets_of(config)?;
    let servos = &config.settings.servos;
    let (offsets, model) = read.map_err(|e| KeepLog { code: e.exit_code(), message: e.to_string() })?;
    let ids: Vec<u8> = servos.iter().map(|s| s.id).collect();
    let directions: Vec<i8> = servos.iter().map(|s| s.direction).collect();
    let updated =
        sandslope_io::servo_zero::with_zero_offsets(&text, robot_path, &ids, &directions, &offsets)?;
    sandslope_files::write_atomic(Path::new(robot_path), updated.as_bytes())?;
    let list = |v: Vec<String>| v.join(", ");
    println!(
        "zero offsets of the {} servos IDs {}: [{}] pulses, written to {robot_path} ([servos] zero_offsets)",
        model.name,
        list(ids.iter().map(|i| i.to_string()).collect()),
        list(offsets.iter().map(|o| o.to_string()).collect())
    );
    Ok(())
}

/// `drive --emulate --pty`: the emulated servos (the run's robot, sand, faults and servo
/// model) served on a pseudo-terminal until `duration_s` (when above 0) or a signal; its path
/// is the first line on stdout.
pub(super) fn serve_pty(config: &DriveConfig, duration_s: f64) -> Result<()> {
    let BusChoice::Emulate(o) = &config.bus else { bail!("--pty needs --emulate") };
    if o.clock == sandslope_servo::clock::ClockKind::Virtual {
        bail!("--emulate-clock virtual: the virtual clock moves with this program's driving loop, and --pty leaves the driving to another program on the wall's clock. Fix: leave --emulate-clock out (real) with --pty");
    }
    let cfg = emulator_config(config, o)?;
    let (emulator, port) = Emulator::start(&cfg)?;
    let path = pty_path(&port).ok_or_else(|| {
        anyhow!("--pty: the system does not say the pseudo-terminal's path (it is read from /proc/self/fd, Linux)")
    })?;
    let model = config.settings.servo.map_or("XL330-M288", |m| m.name);
    let ids: Vec<String> = config.settings.servos.iter().map(|s| s.id.to_string()).collect();
    let mut out = std::io::stdout().lock();
    writeln!(out, "{}", path.display())?;
    out.flush()?;
    drop(out);
    let _ = writeln!(
        std::io::stderr(),
        "emulating {} {model} servos (IDs {}) on {}: open it at any baud rate; {}",
        ids.len(),
        ids.join(", "),
        path.display(),
        if duration_s > 0.0 { format!("for {duration_s} s") } else { "Ctrl-C stops".into() }
    );
    // Ctrl-C or SIGTERM ends the wait; the emulator's thread stops with it.
    crate::error::DRIVING.store(true, Ordering::SeqCst);
    let start = Instant::now();
    while !crate::error::STOP.load(Ordering::SeqCst)
        && (duration_s <= 0.0 || start.elapsed().as_secs_f64() < duration_s)
    {
        std::thread::sleep(Duration::from_millis(20));
    }
    crate::error::DRIVING.store(false, Ordering::SeqCst);
    let report = emulator.stop(None);
    drop(port);
    let _ = writeln!(std::io::stderr(), "{}", sandslope_servo::session::emulator_summary(&report));
    if crate::error::STOP.load(Ordering::SeqCst) {
        let (code, signal) = crate::error::stop_signal();
        return Err(KeepLog { code, message: format!("the emulator stopped ({signal})") }.into());
    }
    Ok(())
}
