//! `sandslope`: whether, how fast and by which route a legged robot climbs a sand slope.
//!
//! A thin binary over the `sandslope` library: it parses files and flags into validated
//! library types, runs the model, and writes tables, JSON, CSV and figures.

mod args;
mod commands;
mod error;
mod mocap_input;
mod output;
mod progress;
mod serve;

// The figures and the report page are the render crate's, shared with Python and the server.
use sandslope_render::{figures, report};

use std::io::Write;

use anyhow::Context;
use clap::{Parser, Subcommand};

/// Whether, how fast and why a legged robot climbs a sand slope (the shear-anchoring model of
/// Liao and Qian, arXiv:2603.06928).
#[derive(Debug, Parser)]
#[command(name = "sandslope", version, about, long_about = None, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Every model quantity (d_n, s*, d_s, t1, slip, step, speed, regime) at one slope.
    Predict(commands::predict::PredictArgs),
    /// Dynamic stride simulation on a granular slope (docs/model.md §15-§18), beside the closed form.
    Simulate(commands::simulate::SimulateArgs),
    /// The model over a range of slopes (table, JSON, CSV, or a three-panel figure).
    Sweep(commands::sweep::SweepArgs),
    /// Fit k_s(theta) so the model's speeds match observed ones; write a terrain file.
    Calibrate(commands::calibrate::CalibrateArgs),
    /// Fit k_n and k_s per slope from load-cell recordings into a terrain file (docs/model.md §10).
    Fit(commands::fit::FitArgs),
    /// Speed, anchoring time t1 and slip per step from motion-capture recordings at one slope.
    Track(commands::track::TrackArgs),
    /// Phase diagrams: the regime (sinkage, slippage, metastable, success) over a (k_n, k_s) grid.
    Phase(commands::phase::PhaseArgs),
    /// Failure probability on uncertain terrain, the safe-slope limit and the heaviest safe mass.
    Risk(commands::risk::RiskArgs),
    /// Heading-aware routes (fastest, safest, shortest) and risk maps over an elevation model.
    Plan(commands::plan::PlanArgs),
    /// Robot design exploration: safe-slope limit and speed of every design, and the Pareto front.
    Design(commands::design::DesignArgs),
    /// The paper reproduced and confronted: one self-contained HTML page and report.json.
    Report(commands::report::ReportArgs),
    /// Terrain inference from the gait: posterior of k_s per observed slope, and risk at slopes not walked.
    Infer(commands::infer::InferArgs),
    /// The robot in the loop: drive Dynamixel servos (XL330, XL430, XM430) with the gait, log their state, read the sand from their currents (docs/drive.md).
    Drive(commands::drive::DriveArgs),
    /// List built-in robots and terrains, or print one as TOML.
    Presets(commands::presets::PresetsArgs),
    /// A local web explorer (model, risk, routes on a DEM) and a JSON API equal to `--json`.
    Serve(serve::ServeArgs),
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Predict(a) => commands::predict::run(a),
        Command::Simulate(a) => commands::simulate::run(a),
        Command::Sweep(a) => commands::sweep::run(a),
        Command::Calibrate(a) => {
            let command_line = std::env::args().skip(1).collect();
            commands::calibrate::run(commands::calibrate::CalibrateArgs { command_line, ..a })
        }
        Command::Fit(a) => commands::fit::run(a),
        Command::Track(a) => commands::track::run(a),
        Command::Phase(a) => commands::phase::run(a),
        Command::Risk(a) => commands::risk::run(a),
        Command::Plan(a) => commands::plan::run(a),
        Command::Design(a) => commands::design::run(a),
        Command::Report(a) => commands::report::run(a),
        Command::Infer(a) => commands::infer::run(a),
        Command::Drive(a) => commands::drive::run(a),
        Command::Presets(a) => commands::presets::run(a),
        Command::Serve(a) => serve::run(a),
    }
}

fn main() {
    error::exit_cleanly_on_stream_errors();
    error::clean_up_on_signals();
    error::fail_writes_past_the_file_size_limit();
    let cli = Cli::parse();
    // Every output of a run is put in place together at the end, so a failure leaves none;
    // the server writes nothing of its own and serves for as long as it runs.
    let serving = matches!(cli.command, Command::Serve(_));
    if !serving {
        sandslope_files::stage_outputs();
    }
    let result = match run(cli) {
        // `report --strict` with warnings: the report is kept, the exit code gives the verdict.
        Err(verdict) if error::keeps_outputs(&verdict) => finish().and(Err(verdict)),
        done => done.and_then(|()| finish()),
    };
    if let Err(e) = result {
        sandslope_files::discard_outputs();
        let code = error::exit_code(&e);
        if code == error::EXIT_OK {
            // Stdout was closed by the reader (`sandslope sweep --json | head`): nothing to say.
            std::process::exit(code);
        }
        let mut err = std::io::stderr().lock();
        let _ = writeln!(err, "error: {e}");
        for cause in e.chain().skip(1) {
            let _ = writeln!(err, "  caused by: {cause}");
        }
        std::process::exit(code);
    }
}

/// After a successful run: flush stdout (an error here, such as a full disk, is a failed run:
/// the process's own exit would swallow it), then put every output in place and say so.
fn finish() -> anyhow::Result<()> {
    std::io::stdout().flush().context("cannot write to standard output")?;
    for path in sandslope_files::commit_outputs()? {
        let _ = writeln!(std::io::stderr(), "wrote {}", path.display());
    }
    Ok(())
}
