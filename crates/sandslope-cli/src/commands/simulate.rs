//! `sandslope simulate`: the dynamic stride simulator (docs/model.md §15-§18) at one slope or
//! over a range of slopes in parallel, beside the closed form's answer for the same inputs;
//! optionally the trajectory as motion capture (`--out`, what `track` reads), a figure and a
//! GIF animation.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;
use sandslope_render::rows::{ConvergenceRow, EnsembleRow, SimSlopeRow};

use crate::args::{warn_extrapolated, FieldArgs, OverrideArgs, RobotArgs, TerrainArgs};
use crate::figures;
use crate::figures::simulate::{Animation, SimulateFigure, SlopesFigure};
use crate::output::{
    check_parent_exists, csv_string, num, print_json, table, write_atomic, Format, FormatArgs,
};
use crate::progress::{spinner, Progress};
use sandslope::simulate::convergence::{RefinedWalk, Refinement, WalkAnswer};
use sandslope::simulate::{BodyPitch, ConvergenceCheck, RftScaling, SimSummary, Simulation};
use sandslope_io::load_speeds;
use sandslope_io::trajectory::plain_mocap_csv;
use sandslope_request::simulate::{
    Answer, SimAnswer, SpreadAnswer, Walks, CHECK_CONVERGENCE, ENSEMBLE, SLOPES,
};
use sandslope_request::SimulateRequest;

/// Arguments of `sandslope simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// The request's own fields, `--slope` to `--rate`
    /// ([`sandslope_request::simulate::FIELDS`]).
    #[command(flatten)]
    pub fields: FieldArgs<SimulateRequest>,
    /// Write the body's centre as plain motion capture (time_s,x_m,y_m,z_m) for `track`; a
    /// name ending .mcap writes ROS 2 messages for Foxglove instead (pose, legs as TF, joint
    /// states, forces as markers; docs/bags.md).
    #[arg(long, value_name = "CSV|MCAP", conflicts_with_all = [SLOPES.flag, ENSEMBLE.flag, CHECK_CONVERGENCE.flag])]
    pub out: Option<PathBuf>,
    /// After the walk, play the channels of --out walk.mcap in real time to Foxglove over its
    /// WebSocket protocol on ADDR (default 127.0.0.1:8765, loopback only), waiting up to 30 s
    /// for a viewer to subscribe first (docs/bags.md, "Watch live").
    #[arg(long, value_name = "ADDR", num_args = 0..=1, conflicts_with_all = [SLOPES.flag, CHECK_CONVERGENCE.flag],
        default_missing_value = sandslope_io::foxglove::DEFAULT_ADDR)]
    pub foxglove: Option<String>,
    /// Draw position, leg depths and leg forces against time (one slope), or simulated,
    /// closed-form and observed speeds against slope (--slopes), to FILE (.png or .svg).
    #[arg(long, value_name = "FILE", conflicts_with_all = [ENSEMBLE.flag, CHECK_CONVERGENCE.flag])]
    pub plot: Option<PathBuf>,
    /// Observed speeds (CSV: slope_deg,speed_m_s,speed_sd_m_s) for the --slopes figure.
    #[arg(long, value_name = "CSV", requires_all = [SLOPES.flag, "plot"])]
    pub observed: Option<PathBuf>,
    /// Side-view animation to FILE.gif: slope, sand with a mark every 5 cm, the body's trace,
    /// legs and force arrows; the whole walk at 20 frames per simulated second, in real time,
    /// up to its first 60 s (1200 frames).
    #[arg(long, value_name = "FILE.gif", conflicts_with_all = [SLOPES.flag, ENSEMBLE.flag, CHECK_CONVERGENCE.flag])]
    pub animate: Option<PathBuf>,
    #[command(flatten)]
    pub robot: RobotArgs,
    #[command(flatten)]
    pub terrain: TerrainArgs,
    #[command(flatten)]
    pub over: OverrideArgs,
    #[command(flatten)]
    pub format: FormatArgs,
}

impl SimulateArgs {
    /// The request these flags make: the flags given, read by the request as `/api/simulate`'s
    /// fields are.
    pub fn request(&self) -> Result<SimulateRequest> {
        Ok(SimulateRequest::with_scenario(&self.fields.pairs, self.over.request(&self.robot, &self.terrain))?)
    }
}

/// Runs `sandslope simulate`.
pub fn run(args: SimulateArgs) -> Result<()> {
    let request = args.request()?;
    request.settings()?;
    for path in [&args.out, &args.plot, &args.animate].into_iter().flatten() {
        check_parent_exists(path)?;
    }
    if let Some(path) = &args.plot {
        figures::format_of(path)?;
    }
    if let Some(path) = &args.animate {
        if !path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("gif")) {
            bail!("--animate {} must end in .gif", path.display());
        }
    }
    let observed = args.observed.as_deref().map(load_speeds).transpose()?;
    let walks = request.walks()?;
    if walks.check_convergence {
        return run_check(&args, &walks);
    }
    if let Some(n) = walks.ensemble {
        return run_ensemble(&args, &walks, n);
    }
    if walks.many {
        run_slopes(&args, &walks, observed.as_deref().unwrap_or(&[]))
    } else {
        run_one(&args, &walks)
    }
}

fn run_one(args: &SimulateArgs, walks: &Walks) -> Result<()> {
    let (scenario, slope) = (&walks.scenario, walks.slopes[0].degrees());
    // Progress on stderr (a terminal's, not with --json or --csv): a 10 s walk with its GIF
    // takes tens of seconds.
    let quiet = args.format.format() != Format::Table;
    let under = if walks.scaling_spread { " under each of the three contact scalings" } else { "" };
    let spin =
        Progress::new(0, quiet, &format!("simulating {} s at {slope} deg{under}", walks.settings.duration_s));
    let sims = walks.simulate_with_spreads().map(|(sims, spreads)| (spreads, sims));
    spin.finish();
    let (mut spreads, mut sims) = sims?;
    let (Some(sim), Some(spread)) = (sims.pop(), spreads.pop()) else { bail!("no walk was simulated") };
    if sim.summary.closed_form.extrapolated {
        warn_extrapolated(scenario.terrain(), &[slope]);
    }
    // Every output is rendered before any is written, so a failure leaves nothing behind.
    // `--out walk.mcap`: ROS 2 messages for Foxglove (docs/bags.md); otherwise the plain CSV.
    let csv = match &args.out {
        Some(p) if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("mcap")) => {
            Some(sandslope_io::mcap_out::simulation_mcap(&sim.trajectory, &sim.geometry, slope)?)
        }
        Some(_) => Some(plain_mocap_csv(&sim.trajectory, slope).into_bytes()),
        None => None,
    };
    if let Some(path) = &args.plot {
        figures::save(path, &SimulateFigure { sim: &sim, robot: scenario.robot() })?;
    }
    if let Some(path) = &args.animate {
        let anim = Animation { sim: &sim, slope_deg: slope };
        let mut bar =
            Progress::new(anim.frames().len() as u64, quiet, &format!("drawing {}", path.display()));
        figures::simulate::save_gif(path, &anim, &mut || bar.inc())?;
        bar.finish();
    }
    if let (Some(path), Some(csv)) = (&args.out, &csv) {
        write_atomic(path, csv)?;
    }
    let m = &sim.summary;
    match args.format.format() {
        Format::Json => {
            print_json(&Answer::One(Box::new(SimAnswer { summary: m.clone(), scaling_spread: spread })))?
        }
        Format::Csv => print!("{}", csv_string(&m.steps)?),
        Format::Table => {
            print_one(&sim);
            if let Some(spread) = &spread {
                println!("{}", spread_note(spread));
            }
        }
    }
    if let Some(addr) = &args.foxglove {
        sandslope_io::foxglove::play_simulation(addr, &sim.trajectory, &sim.geometry, slope, 30.0)?;
    }
    Ok(())
}

/// Printed under every table that puts simulated and closed-form numbers side by side.
const DISAGREE_NOTE: &str =
    "note: the simulator and the closed form are known to disagree; docs/simulate.md \
(\"The simulator against the closed form\") lists where and why. Read the two columns as a test of the closed form's \
assumptions, not as two estimates of one speed.";

fn print_one(sim: &Simulation) {
    let m = &sim.summary;
    let p = &m.closed_form.prediction;
    println!(
        "slope {} deg, k_n {:.3e}, k_s {:.3e} N/m^3: {} s simulated at dt = {:.2e} s, {} steps measured (after one \
         stride of warm-up)",
        m.slope_deg, m.k_n, m.k_s, m.duration_s, m.dt_s, m.steps_measured
    );
    let mut t = table(&["", "simulated", "closed form"]);
    t.add_row([
        "speed cm/s".into(),
        format!("{:.2} ± {:.2}", m.speed_m_s * 100.0, m.speed_sd_m_s * 100.0),
        num(p.speed.map(|v| v * 100.0), 2),
    ]);
    t.add_row(["t1 ms".into(), num(m.t1_s.map(|v| v * 1e3), 1), num(p.anchoring_time.map(|v| v * 1e3), 1)]);
    t.add_row(["slip mm".into(), num(m.slip_m.map(|v| v * 1e3), 2), num(p.slip.map(|v| v * 1e3), 2)]);
    // Phase 1's lowest speed; the closed form's body slides from rest at g sin(theta) until t1
    // (its s1 = 1/2 g sin(theta) t1^2), so its lowest speed is -g sin(theta) t1 (docs/model.md §18).
    let cf_low = p.anchoring_time.map(|t1| -sandslope::G * m.slope_deg.to_radians().sin() * t1);
    t.add_row([
        "lowest speed in phase 1 cm/s".into(),
        num(m.phase1.map(|q| q.min_speed_m_s * 100.0), 2),
        num(cf_low.map(|v| v * 100.0), 2),
    ]);
    t.add_row(["step mm".into(), format!("{:.2}", m.step_m * 1e3), num(p.step.map(|v| v * 1e3), 2)]);
    t.add_row([
        "deepest leg mm".into(),
        format!("{:.2} (reach 2R - h = {:.1})", m.max_depth_m * 1e3, m.d_max_m * 1e3),
        format!("d_n = {}", num(p.normal_depth.map(|v| v * 1e3), 2)),
    ]);
    let largest = match m.body_pitch {
        BodyPitch::Free => format!("{:.1}", m.max_pitch_deg),
        BodyPitch::Locked => "0 (locked)".to_string(),
    };
    t.add_row(["largest pitch deg".into(), largest, "0 (no pitch)".to_string()]);
    t.add_row(["regime", m.regime.name(), p.regime.name()]);
    t.add_row(["cause", m.cause.name(), p.cause.name()]);
    println!("{t}");
    println!("{DISAGREE_NOTE}");
    if m.rft_scaling != RftScaling::Motion {
        println!(
            "resistive force theory scaled by {} (--rft-scaling {}, docs/model.md §16)",
            m.rft_scaling.name(),
            m.rft_scaling.name()
        );
    }
    if let Some(limit) = m.servo_torque_limit_n_m {
        println!("servo torque limit {limit} N m (the robot file's; --no-servo-limit drives ideal servos)");
    }
    if m.body_pitch == BodyPitch::Free {
        println!("{FREE_NOTE}");
    }
    if m.unconverged_steps > 0 {
        println!(
            "{} time step(s) ended their implicit solve unconverged (docs/simulate.md, \"Convergence\")",
            m.unconverged_steps
        );
    }
    if let Some(at) = m.pitch_over_s {
        println!(
            "the body pitched past 90 deg at t = {at:.2} s: the robot tumbled, and the step means above describe \
             a tumbling body, not a walk (docs/simulate.md)"
        );
    }
    if !m.stalled_legs.is_empty() {
        let legs: Vec<String> = m.stalled_legs.iter().map(|l| l.to_string()).collect();
        println!("servo stalled (torque limit bound) on legs {}", legs.join(", "));
    }
    if m.unanchored_steps > 0 {
        println!(
            "{} measured step(s) never anchored (the speed did not turn from falling to rising)",
            m.unanchored_steps
        );
    }
}

/// The scaling spread under a one-slope table: the three speeds, the range and whether the
/// regimes agree, with what it means and which measurement would decide (docs/simulate.md).
fn spread_note(spread: &SpreadAnswer) -> String {
    let walks: Vec<String> = spread
        .walks
        .iter()
        .map(|w| format!("{} {:.2} cm/s ({})", w.rft_scaling.name(), w.speed_m_s * 100.0, w.regime.name()))
        .collect();
    let verdict = if spread.regimes_agree {
        "the regimes agree".to_string()
    } else {
        "the regimes DISAGREE: this slope's verdict is the scaling's choice, not the sand's".to_string()
    };
    format!(
        "model uncertainty, the contact scaling (not measured; --scaling-spread): {}; speed {:.2} to {:.2} cm/s \
         (range {:.2}); {verdict}. The measurement that would decide: a leg-wide plate dragged along the \
         surface at the stance depth, its horizontal and vertical forces together (docs/simulate.md, \
         \"The scaling as model uncertainty\")",
        walks.join(", "),
        spread.min_speed_m_s * 100.0,
        spread.max_speed_m_s * 100.0,
        spread.range_m_s * 100.0
    )
}

/// Under a table of slopes with their scaling spread.
const SPREAD_NOTE: &str = "3 scalings: the slope walked under each contact scaling (motion, li2013, components; none measured), the smallest and largest speed and whether the regimes agree; where they DISAGREE the verdict is the scaling's choice, not the sand's, until a leg-wide plate dragged along the surface at the stance depth is measured, its horizontal and vertical forces together (docs/simulate.md, \"The scaling as model uncertainty\")";

/// What a walk with the body free to pitch is (docs/simulate.md, "Pitch free").
const FREE_NOTE: &str = "body pitch free (--body-pitch free): its default step is an eighth of the locked walk's (T/16000), which its speeds on slopes and its t1 on level sand need to converge, and with --two-faced-belly its pitch is unstable on slopes (one walk is one draw of a spread; --ensemble N gives it); check with --check-convergence (docs/simulate.md)";

fn run_ensemble(args: &SimulateArgs, walks: &Walks, n: usize) -> Result<()> {
    let quiet = args.format.format() != Format::Table;
    let spin = spinner(quiet, &format!("simulating {n} walks at {} deg", walks.slopes[0].degrees()));
    let e = walks.simulate_ensemble(n);
    spin.finish_and_clear();
    let e = e?;
    match args.format.format() {
        Format::Json => print_json(&Answer::Ensemble(Box::new(e)))?,
        Format::Csv => {
            let rows = EnsembleRow::rows(&e, walks.scenario.robot().mass());
            print!("{}", csv_string(&rows)?);
        }
        Format::Table => {
            println!(
                "{n} walks at {} deg (mass perturbed by {:e} relative between walks):",
                walks.slopes[0].degrees(),
                e.perturbation
            );
            println!(
                "speed {:.2} +/- {:.2} cm/s (SD; standard error {:.2}), mean t1 {} ms",
                e.speed_m_s * 100.0,
                e.speed_sd_m_s * 100.0,
                e.speed_se_m_s * 100.0,
                num(e.t1_s.map(|t| t * 1e3), 1)
            );
            let counts: Vec<String> = e.regimes.iter().map(|(r, c)| format!("{} {c}", r.name())).collect();
            println!(
                "regimes: {} (most: {}); pitched over: {} of {n}",
                counts.join(", "),
                e.regime.name(),
                e.pitched_over
            );
            if walks.settings.body_pitch == BodyPitch::Locked {
                println!("body pitch locked: the walk is stable, so the walks differ by rounding (docs/simulate.md)");
            }
        }
    }
    Ok(())
}

fn run_check(args: &SimulateArgs, walks: &Walks) -> Result<()> {
    let quiet = args.format.format() != Format::Table;
    let what = match walks.slopes.as_slice() {
        [one] => format!("the walk at {} deg", one.degrees()),
        many => format!("the walks at {} slopes", many.len()),
    };
    let spin = spinner(quiet, &format!("checking {what} at a quarter of the step and a tenth of the creep"));
    let answer = walks.respond();
    spin.finish_and_clear();
    let answer = answer?;
    let checks: Vec<&ConvergenceCheck> = match &answer {
        Answer::Convergence(c) => vec![c],
        Answer::Convergences(all) => all.iter().collect(),
        _ => bail!("the convergence check gave no answer"),
    };
    match args.format.format() {
        Format::Json => print_json(&answer)?,
        Format::Csv => {
            let rows: Vec<ConvergenceRow> = checks.iter().flat_map(|c| ConvergenceRow::rows(c)).collect();
            print!("{}", csv_string(&rows)?);
        }
        Format::Table if walks.many => print_checks(&checks, walks),
        Format::Table => print_check(checks[0], walks),
    }
    Ok(())
}

/// A change with its sign and `digits` decimals; one that rounds to zero is "+0.00", not
/// "-0.00".
fn signed(v: f64, digits: usize) -> String {
    let s = format!("{v:+.digits$}");
    if s.trim_start_matches(['-', '+', '0', '.']).is_empty() {
        s.replacen('-', "+", 1)
    } else {
        s
    }
}

/// A refinement's change as the tables print it: speed (and its share of the walk's, where the
/// walk is faster than the check's absolute floor: nearer zero the share is no measure, -404%
/// for a change of 0.07 cm/s on a walk of 0.02 cm/s), the steps' spread, t1.
fn change_cell(c: &ConvergenceCheck, r: &RefinedWalk) -> String {
    let pct = if c.walk.speed_m_s.abs() >= c.speed_tolerance_m_s {
        format!(" ({}%)", signed(100.0 * r.speed_change_m_s / c.walk.speed_m_s.abs(), 1))
    } else {
        String::new()
    };
    let t1 = r.t1_change_s.map_or("-".to_string(), |d| signed(d * 1e3, 2));
    format!(
        "speed {} cm/s{pct}, spread {} cm/s, t1 {t1} ms",
        signed(r.speed_change_m_s * 100.0, 2),
        signed(r.step_speed_sd_change_m_s * 100.0, 2)
    )
}

/// "yes", or what fell outside the tolerances.
fn within_cell(r: &RefinedWalk) -> String {
    let failed: Vec<&str> = [
        ("speed", r.speed_within),
        ("spread", r.spread_within),
        ("t1", r.t1_within),
        ("regime", r.same_regime),
    ]
    .into_iter()
    .filter(|(_, ok)| !ok)
    .map(|(what, _)| what)
    .collect();
    if failed.is_empty() {
        "yes".to_string()
    } else {
        format!("no: {}", failed.join(", "))
    }
}

/// The tolerances line under the convergence tables.
fn tolerances_note(c: &ConvergenceCheck) -> String {
    format!(
        "tolerances: speed and the steps' spread within {:.0}% or {:.1} cm/s, t1 within {:.0} ms, the same regime (docs/simulate.md, \"Checking convergence\")",
        c.speed_tolerance * 100.0,
        c.speed_tolerance_m_s * 100.0,
        c.t1_tolerance_s * 1e3
    )
}

fn print_check(c: &ConvergenceCheck, walks: &Walks) {
    let walks_word =
        if c.walks == 1 { "one walk".to_string() } else { format!("means of {} walks", c.walks) };
    println!(
        "convergence at {} deg ({walks_word} a setting, {} s each): {}",
        c.slope_deg,
        walks.settings.duration_s,
        if c.converged { "converged" } else { "NOT converged" }
    );
    let mut t = table(&["walk", "dt ms", "creep m/s", "speed cm/s", "t1 ms", "regime", "change", "within"]);
    let cells = |a: &WalkAnswer| {
        let speed = match a.speed_se_m_s {
            Some(se) => format!("{:.2} ± {:.2}", a.speed_m_s * 100.0, se * 100.0),
            None => format!("{:.2}", a.speed_m_s * 100.0),
        };
        [
            format!("{:.4}", a.dt_s * 1e3),
            format!("{:.0e}", a.creep_m_s),
            speed,
            num(a.t1_s.map(|t| t * 1e3), 2),
            a.regime.name().to_string(),
        ]
    };
    let [dt, creep, speed, t1, regime] = cells(&c.walk);
    t.add_row(["as asked".to_string(), dt, creep, speed, t1, regime, String::new(), String::new()]);
    for r in &c.refinements {
        let [dt, creep, speed, t1, regime] = cells(&r.answer);
        t.add_row([
            r.refinement.label().to_string(),
            dt,
            creep,
            speed,
            t1,
            regime,
            change_cell(c, r),
            within_cell(r),
        ]);
    }
    println!("{t}");
    println!("{}", tolerances_note(c));
    if c.walks > 1 {
        println!("speeds are the ensembles' means +/- their standard errors");
    }
    if c.refinements.len() == 1 {
        println!("the creep speed is at its smallest (1e-9 m/s): no tenth of it to walk");
    }
    if walks.settings.body_pitch == BodyPitch::Free && c.walks == 1 {
        println!("{FREE_NOTE}");
    }
}

fn print_checks(checks: &[&ConvergenceCheck], walks: &Walks) {
    let passed = checks.iter().filter(|c| c.converged).count();
    println!(
        "convergence at {} slopes (one walk a setting, {} s each): {passed} converged, {} not",
        checks.len(),
        walks.settings.duration_s,
        checks.len() - passed
    );
    let mut t = table(&["slope deg", "speed cm/s", "t1 ms", "regime", "dt / 4", "creep / 10", "converged"]);
    for c in checks {
        let at = |k: Refinement| c.refinements.iter().find(|r| r.refinement == k);
        let cell = |k: Refinement| {
            at(k).map_or("-".to_string(), |r| format!("{} ({})", change_cell(c, r), within_cell(r)))
        };
        t.add_row([
            format!("{}", c.slope_deg),
            format!("{:.2}", c.walk.speed_m_s * 100.0),
            num(c.walk.t1_s.map(|t| t * 1e3), 2),
            c.walk.regime.name().to_string(),
            cell(Refinement::QuarterStep),
            cell(Refinement::TenthCreep),
            if c.converged { "yes" } else { "NO" }.to_string(),
        ]);
    }
    println!("{t}");
    if let Some(c) = checks.first() {
        println!("{}", tolerances_note(c));
    }
    if walks.settings.body_pitch == BodyPitch::Free {
        println!("{FREE_NOTE}");
    }
}

fn run_slopes(args: &SimulateArgs, walks: &Walks, observed: &[sandslope::SpeedObservation]) -> Result<()> {
    let (scenario, settings) = (&walks.scenario, &walks.settings);
    let quiet = args.format.format() != Format::Table;
    let under = if walks.scaling_spread { " under each of the three contact scalings" } else { "" };
    let spin = spinner(quiet, &format!("simulating {} slopes{under}", walks.slopes.len()));
    let sims = walks.simulate_with_spreads().map(|(sims, spreads)| (spreads, sims));
    spin.finish_and_clear();
    let (spreads, sims) = sims?;
    let beyond: Vec<f64> =
        sims.iter().filter(|s| s.summary.closed_form.extrapolated).map(|s| s.summary.slope_deg).collect();
    if !beyond.is_empty() {
        warn_extrapolated(scenario.terrain(), &beyond);
    }
    let summaries: Vec<SimSummary> = sims.into_iter().map(|s| s.summary).collect();
    if let Some(path) = &args.plot {
        let repose_deg = scenario.terrain().repose().map(|r| r.degrees());
        figures::save(path, &SlopesFigure { sims: &summaries, pitch_locked: &[], observed, repose_deg })?;
    }
    match args.format.format() {
        Format::Json => print_json(&Answer::Many(
            summaries
                .into_iter()
                .zip(spreads)
                .map(|(summary, scaling_spread)| SimAnswer { summary, scaling_spread })
                .collect(),
        ))?,
        Format::Csv => {
            let rows: Vec<SimSlopeRow> = summaries.iter().map(SimSlopeRow::of).collect();
            print!("{}", csv_string(&rows)?);
        }
        Format::Table => {
            let mut header = vec![
                "slope deg",
                "speed cm/s sim | cf",
                "t1 ms sim | cf",
                "slip mm sim | cf",
                "step mm sim | cf",
                "regime sim | cf",
                "cause (sim)",
            ];
            if walks.scaling_spread {
                header.push("3 scalings: speed cm/s, regimes");
            }
            let mut t = table(&header);
            for (m, spread) in summaries.iter().zip(&spreads) {
                let p = &m.closed_form.prediction;
                let mut row = vec![
                    format!("{}", m.slope_deg),
                    format!(
                        "{:.2} | {}",
                        m.speed_m_s * 100.0,
                        num(m.closed_form.speed().map(|v| v * 100.0), 2)
                    ),
                    format!(
                        "{} | {}",
                        num(m.t1_s.map(|v| v * 1e3), 1),
                        num(p.anchoring_time.map(|v| v * 1e3), 1)
                    ),
                    format!("{} | {}", num(m.slip_m.map(|v| v * 1e3), 2), num(p.slip.map(|v| v * 1e3), 2)),
                    format!("{:.1} | {}", m.step_m * 1e3, num(p.step.map(|v| v * 1e3), 1)),
                    format!("{} | {}", m.regime.name(), p.regime.name()),
                    m.cause.name().to_string(),
                ];
                if let Some(sp) = spread {
                    row.push(format!(
                        "{:.2} to {:.2}, {}",
                        sp.min_speed_m_s * 100.0,
                        sp.max_speed_m_s * 100.0,
                        if sp.regimes_agree { "agree" } else { "DISAGREE" }
                    ));
                }
                t.add_row(row);
            }
            println!("{t}");
            println!("{DISAGREE_NOTE}");
            if walks.scaling_spread {
                println!("{SPREAD_NOTE}");
            }
            if settings.body_pitch == BodyPitch::Free {
                println!("{FREE_NOTE}");
            }
            if settings.rft_scaling != RftScaling::Motion {
                println!(
                    "resistive force theory scaled by {} (--rft-scaling {}, docs/model.md §16)",
                    settings.rft_scaling.name(),
                    settings.rft_scaling.name()
                );
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use sandslope_request::simulate::parse_slopes;

    #[test]
    fn slope_ranges_name_the_flag() {
        assert_eq!(parse_slopes("0:24:3").unwrap(), vec![0.0, 12.0, 24.0]);
        assert_eq!(parse_slopes("-10,5").unwrap(), vec![-10.0, 5.0]);
        for bad in ["0:24", "a:1:1", "0:95:5", "10:0:2", "0:10:0", "0:10:1001"] {
            let msg = parse_slopes(bad).unwrap_err().to_string();
            assert!(msg.starts_with("--slopes"), "{bad}: {msg}");
        }
    }

    /// A change that rounds to zero prints "+0.00" whatever its sign; others keep theirs.
    #[test]
    fn a_change_that_rounds_to_zero_has_no_minus() {
        assert_eq!(signed(-0.001, 2), "+0.00");
        assert_eq!(signed(-0.0, 2), "+0.00");
        assert_eq!(signed(0.004, 2), "+0.00");
        assert_eq!(signed(-0.04, 1), "+0.0");
        assert_eq!(signed(-0.5, 2), "-0.50");
        assert_eq!(signed(0.14, 1), "+0.1");
        assert_eq!(signed(-12.346, 2), "-12.35");
    }
}
