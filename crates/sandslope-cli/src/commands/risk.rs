//! `sandslope risk`: the probability of failure when the terrain is uncertain (docs/model.md
//! §9): per slope, p_fail = P(sinkage or slippage) and P(not success); the safe-slope limit
//! (steepest slope below `--max-risk`); the heaviest safe mass at one slope, or at each slope
//! (the payload envelope, `--solve mass`); with `--map`, p_fail over median (k_n, k_s).
//! Translates its flags into the request layer's [`RiskQuestion`], takes the answer from
//! [`RiskProblem`] (every check, and the answer `serve`'s `/api/risk` and Python give), and
//! hands it to printers, writers and figures.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;
use indicatif::ProgressBar;

use sandslope::risk::{
    DefaultsUsed, PayloadEnvelope, RiskAnswer, RiskMapAnswer, RiskPoint, SafeLimit, SafeMass, SafeSlope,
};
use sandslope::Robot;
use sandslope_request::error::Words;
use sandslope_request::risk::{self as request, AnswerLimits, Progress, RiskProblem, RiskQuestion};
use sandslope_request::RiskRequest;

use crate::args::{beyond_last_point, warn_extrapolated, FieldArgs, RobotArgs, TerrainArgs};
use crate::figures::risk::{CurveFigure, EnvelopeFigure, MapFigure};
use crate::figures::save;
use crate::output::{csv_string, num, print_json, sci, table, Format};
use crate::progress::progress_bar;
use sandslope_render::rows::{MassRow, RiskRow, SafeSlopeRow};

/// Arguments of `sandslope risk`.
#[derive(Debug, Args)]
pub struct RiskArgs {
    /// `--slope`, `--cv-n`, `--cv-s`, `--max-risk`, `--solve`, `--map`, `--k-n` and `--k-s`:
    /// the request's own fields ([`sandslope_request::risk::FIELDS`]).
    #[command(flatten)]
    pub fields: FieldArgs<RiskRequest>,
    #[command(flatten)]
    pub robot: RobotArgs,
    #[command(flatten)]
    pub terrain: TerrainArgs,
    /// Draw p_fail against slope (with --map: over (k_n, k_s); with --solve mass over several
    /// slopes: the payload envelope) to this .png or .svg file.
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// With --map: write NumPy arrays into this existing folder: p_fail.npy and
    /// p_not_success.npy (float64, shape k_s x k_n), k_n.npy, k_s.npy.
    #[arg(long, value_name = "DIR", requires = "map")]
    pub npy: Option<PathBuf>,
    /// Print JSON instead of a table.
    #[arg(long, conflicts_with = "csv")]
    pub json: bool,
    /// Print CSV instead of a table; with --map, write every cell to FILE
    /// (k_n,k_s,p_fail,p_not_success, k_n-major) or, without FILE, to stdout.
    #[arg(long, value_name = "FILE", num_args = 0..=1)]
    pub csv: Option<Option<PathBuf>>,
}

impl RiskArgs {
    fn format(&self) -> Format {
        if self.json {
            Format::Json
        } else if self.csv.is_some() {
            Format::Csv
        } else {
            Format::Table
        }
    }

    /// The question these flags ask, read by the request layer's one raw-to-typed step (the
    /// one `/api/risk` takes).
    fn question(&self) -> Result<RiskQuestion> {
        Ok(RiskQuestion::from_fields(&self.fields.pairs)?)
    }

    /// Checks the output flags before anything is computed: the figure's format and folder,
    /// `--csv FILE` only with `--map`, the `--npy` folder.
    fn check_outputs(&self, map: bool) -> Result<()> {
        if let Some(p) = &self.plot {
            crate::figures::format_of(p)?;
            crate::output::check_parent_exists(p)?;
        }
        if let Some(Some(p)) = &self.csv {
            if !map {
                bail!(
                    "--csv FILE writes the cells of --map; without --map, --csv prints to stdout (give no FILE)"
                );
            }
            crate::output::check_parent_exists(p)?;
        }
        if let Some(dir) = &self.npy {
            sandslope_io::npy::prepare_npy_dir(dir)?;
        }
        Ok(())
    }
}

/// A progress bar told a map's rows by the request layer.
struct Bar(ProgressBar);

impl Progress for Bar {
    fn start(&self, steps: u64) {
        self.0.set_length(steps);
    }

    fn step(&self) {
        self.0.inc(1);
    }
}

/// One slope limit in words: `p` names the probability it bounds (`p_fail` or
/// `P(not success)`). A limit at the angle of repose ([`SafeLimit::Repose`]: there p_fail
/// jumps to 1, the sand flows) is named as the repose, not as a risk threshold.
fn describe_limit(limit: &SafeLimit, p: &str, max_risk: f64) -> String {
    match *limit {
        SafeLimit::NoneSafe { p_fail } => {
            format!("no slope: {p} = {p_fail:.4} >= {max_risk} already on level ground")
        }
        SafeLimit::Limit { value, p_fail } => {
            format!("up to {value:.1} deg ({p} < {max_risk} from level up to {value:.3} deg, {p_fail:.4} there)")
        }
        SafeLimit::Repose { repose_deg, p_fail } => format!(
            "up to the angle of repose, {repose_deg} deg ({p} < {max_risk} below it, {p_fail:.4} just below; at and \
             beyond repose the sand flows and every regime is slippage)"
        ),
        SafeLimit::BeyondRange { up_to, p_fail } => {
            format!("beyond {up_to} deg, the end of the search ({p} there {p_fail:.4} < {max_risk})")
        }
    }
}

/// The two slope limits of `sol` in words, the success limit first (it answers "how steep
/// can we go?"), each named by what it bounds, and what lies between them.
fn describe_slope_limits(sol: &SafeSlope) -> String {
    let r = sol.max_risk;
    let mut out = format!(
        "climbs (success limit, P(not success) < {r}): {}\ndoes not fail (safe-slope limit, p_fail = P(sinkage or slippage) < {r}): {}",
        describe_limit(&sol.success_limit, "P(not success)", r),
        describe_limit(&sol.limit, "p_fail", r)
    );
    if let (Some(a), Some(b)) = (sol.success_slope_deg, sol.safe_slope_deg) {
        if b - a >= 0.05 {
            out.push_str(&format!(
                "\nbetween {a:.1} and {b:.1} deg the robot likely climbs slowly and may stall (metastable): it neither sinks \
                 nor slides back, but each step is shorter than the minimum and it can stall in its own trench (docs/model.md §5)"
            ));
        }
    }
    out
}

/// Runs `sandslope risk`.
pub fn run(args: RiskArgs) -> Result<()> {
    let robot = args.robot.load()?;
    let question = args.question()?;
    let map = question.map.is_some();
    let problem = question.on(&robot, args.terrain.load()?, Words::Flag)?;
    args.check_outputs(map)?;
    let extrapolated = beyond_last_point(problem.terrain().terrain(), &problem.question().slopes);
    if !extrapolated.is_empty() {
        warn_extrapolated(problem.terrain().terrain(), &extrapolated);
    }
    let format = args.format();
    let json = format == Format::Json;
    let bar = Bar(if map { progress_bar(0, json, "p_fail map") } else { ProgressBar::hidden() });
    let answer = problem.answer(AnswerLimits::LIBRARY, None, &bar)?;
    bar.0.finish_and_clear();
    let defaults = request::defaults_used(&answer);
    note_defaults(defaults);
    match answer {
        RiskAnswer::Map(map) => print_map(&args, &robot, *map),
        RiskAnswer::Envelope(env) => {
            if let Some(path) = &args.plot {
                save(path, &EnvelopeFigure::new(&env, &robot_title(&problem)))?;
            }
            print_envelope(*env, format)
        }
        RiskAnswer::Mass(sol) => {
            if args.plot.is_some() {
                draw_curve(&args, &problem, &problem.slope_limits()?, json)?;
            }
            match format {
                Format::Json => print_json(&RiskAnswer::Mass(sol)),
                Format::Csv => {
                    print!("{}", csv_string(&[MassRow::of(&sol)])?);
                    Ok(())
                }
                Format::Table => {
                    println!("{}", describe_mass_limit(&sol));
                    Ok(())
                }
            }
        }
        RiskAnswer::Slope(sol) => {
            if args.plot.is_some() {
                draw_curve(&args, &problem, &sol, json)?;
            }
            print_slope_limits(*sol, format)
        }
        RiskAnswer::Point(p) => curve(&args, &problem, vec![*p], defaults),
        RiskAnswer::Curve(points) => curve(&args, &problem, points, defaults),
    }
}

/// The p_fail curve at the slopes asked (`points`): drawn with the slope limits, and printed,
/// in a table with the limits under it.
fn curve(
    args: &RiskArgs,
    problem: &RiskProblem<'_>,
    points: Vec<RiskPoint>,
    defaults: DefaultsUsed,
) -> Result<()> {
    let format = args.format();
    let limits =
        if format == Format::Table || args.plot.is_some() { Some(problem.slope_limits()?) } else { None };
    if let Some(limits) = &limits {
        draw_curve(args, problem, limits, format == Format::Json)?;
    }
    print_curve(points, defaults, limits.as_ref(), format)
}

/// Prints the slope limits of `--solve slope`.
fn print_slope_limits(sol: SafeSlope, format: Format) -> Result<()> {
    match format {
        Format::Json => print_json(&RiskAnswer::Slope(Box::new(sol))),
        Format::Csv => {
            let row = SafeSlopeRow::of(&sol);
            print!("{}", csv_string(&[row])?);
            Ok(())
        }
        Format::Table => {
            println!("{}", describe_slope_limits(&sol));
            Ok(())
        }
    }
}

/// Tells the user on stderr when a default CV was used (docs/model.md §9).
fn note_defaults(defaults: DefaultsUsed) {
    if let Some(note) = defaults.note() {
        eprintln!("note: {note}");
    }
}

/// The robot's mass and the terrain's name, for a figure's title.
fn robot_title(problem: &RiskProblem<'_>) -> String {
    let name = problem.terrain().terrain().name().unwrap_or("terrain");
    format!("m = {} kg on {name}", problem.robot().mass())
}

/// Prints the risk curve, and in a table the success and safe-slope limits if they were
/// searched and the note on the default CVs used.
fn print_curve(
    points: Vec<RiskPoint>,
    defaults: DefaultsUsed,
    limits: Option<&SafeSlope>,
    format: Format,
) -> Result<()> {
    match format {
        Format::Json => print_json(&RiskAnswer::of_points(points)),
        Format::Csv => {
            let rows: Vec<RiskRow> = points.iter().map(RiskRow::of).collect();
            print!("{}", csv_string(&rows)?);
            Ok(())
        }
        Format::Table => {
            let mut t = table(&[
                "slope (deg)",
                "cv k_n",
                "cv k_s",
                "p_fail",
                "p_not_success",
                "P(sinkage)",
                "P(slippage)",
                "P(metastable)",
                "P(success)",
            ]);
            let f = |x: f64| format!("{x:.4}");
            for p in &points {
                let q = &p.probabilities;
                t.add_row([
                    format!("{}", p.slope_deg),
                    format!("{:.3}", p.uncertainty.cv_n),
                    format!("{:.3}", p.uncertainty.cv_s),
                    f(p.p_fail),
                    f(p.p_not_success),
                    f(q.sinkage),
                    f(q.slippage),
                    f(q.metastable),
                    f(q.success),
                ]);
            }
            println!("{t}");
            if let Some(limits) = limits {
                println!("{}", describe_slope_limits(limits));
            }
            if let Some(note) = defaults.note() {
                println!("note: {note}");
            }
            println!("p_fail = P(sinkage or slippage); log-normal k_n, k_s (docs/model.md §9), deterministic quadrature");
            Ok(())
        }
    }
}

fn print_envelope(env: PayloadEnvelope, format: Format) -> Result<()> {
    match format {
        Format::Json => print_json(&RiskAnswer::Envelope(Box::new(env))),
        Format::Csv => {
            let rows = MassRow::envelope(&env);
            print!("{}", csv_string(&rows)?);
            Ok(())
        }
        Format::Table => {
            // A row's note only where its search did not end at a threshold crossing (at a
            // crossing p_fail is the threshold itself: saying so on every row said nothing).
            let notes: Vec<Option<String>> = env
                .points
                .iter()
                .map(|p| match p.limit {
                    SafeLimit::NoneSafe { p_fail } => {
                        Some(format!("none safe: p_fail {p_fail:.4} already at the robot's own mass"))
                    }
                    // (A mass search never ends at a repose: that is a slope's.)
                    SafeLimit::Limit { .. } | SafeLimit::Repose { .. } => None,
                    SafeLimit::BeyondRange { up_to, .. } => {
                        Some(format!("safe up to {up_to:.3} kg, the end of the search"))
                    }
                })
                .collect();
            let with_notes = notes.iter().any(Option::is_some);
            let mut header = vec!["slope (deg)", "heaviest safe mass (kg)", "payload (kg)"];
            if with_notes {
                header.push("note");
            }
            let mut t = table(&header);
            for (p, note) in env.points.iter().zip(notes) {
                let mut row =
                    vec![format!("{}", p.slope_deg), num(p.max_mass_kg, 4), num(p.max_payload_kg, 4)];
                if with_notes {
                    row.push(note.unwrap_or_default());
                }
                t.add_row(row);
            }
            println!("{t}");
            println!(
                "payload envelope: heaviest total mass with p_fail = P(sinks or slides back) < {} (robot's own mass {} kg; \
                 at each limit p_fail reaches the threshold; a safe mass may still climb slowly and stall, docs/model.md §9)",
                env.max_risk, env.robot_mass_kg
            );
            if let Some(note) = env.defaults_used.note() {
                println!("note: {note}");
            }
            Ok(())
        }
    }
}

fn describe_mass_limit(sol: &SafeMass) -> String {
    match sol.limit {
        SafeLimit::NoneSafe { p_fail } => format!(
            "no payload is safe at {} deg: p_fail = {p_fail:.4} >= {} already at the robot's own {} kg",
            sol.slope_deg, sol.max_risk, sol.robot_mass_kg
        ),
        // (A mass search never ends at a repose: that is a slope's.)
        SafeLimit::Limit { value, p_fail } | SafeLimit::Repose { repose_deg: value, p_fail } => format!(
            "heaviest safe total mass at {} deg: {value:.4} kg (payload {:.4} kg over the robot's {} kg), p_fail {p_fail:.4} < {} \
             (safe: it does not sink or slide back; at this mass it may still climb slowly and stall, docs/model.md §9)",
            sol.slope_deg,
            value - sol.robot_mass_kg,
            sol.robot_mass_kg,
            sol.max_risk
        ),
        SafeLimit::BeyondRange { up_to, p_fail } => format!(
            "p_fail < {} at {} deg for every total mass up to {up_to:.4} kg searched (p_fail there {p_fail:.4})",
            sol.max_risk, sol.slope_deg
        ),
    }
}

/// p_fail and p_not_success against slope, sampled every 0.25 degrees (the request layer's
/// samples), to `--plot`.
fn draw_curve(args: &RiskArgs, problem: &RiskProblem<'_>, limits: &SafeSlope, quiet: bool) -> Result<()> {
    let Some(path) = &args.plot else { return Ok(()) };
    let bar = progress_bar(1, quiet, "p_fail curve");
    let samples = problem.curve_samples(limits)?;
    bar.finish_and_clear();
    let figure = CurveFigure {
        curve: samples.fine.iter().map(|p| (p.slope_deg, p.probabilities)).collect(),
        points: samples.requested.iter().map(|p| (p.slope_deg.abs(), p.p_fail)).collect(),
        hi: samples.hi,
        max_risk: limits.max_risk,
        limit: limits.limit,
        success_limit: limits.success_limit,
        title: format!("Failure risk: {}", robot_title(problem)),
    };
    save(path, &figure)
}

/// `--map`: writes the cells (`--csv FILE`, `--npy`) and the figure, and prints p_fail and
/// p_not_success over median (k_n, k_s) at one slope.
fn print_map(args: &RiskArgs, robot: &Robot, answer: RiskMapAnswer) -> Result<()> {
    let (map, summary) = (&answer.map, &answer.summary);
    let (slope_deg, max_risk, u) = (summary.slope_deg, summary.max_risk, summary.uncertainty);
    let (k_n_axis, k_s_axis) = (map.k_n_axis, map.k_s_axis);
    if let Some(Some(path)) = &args.csv {
        sandslope_render::tables::write_risk_map_csv(path, map)?;
    }
    if let Some(dir) = &args.npy {
        sandslope_render::tables::write_risk_map_npy(dir, map)?;
    }
    if let Some(path) = &args.plot {
        let figure = MapFigure {
            k_n_axis,
            k_s_axis,
            p_fail: map.p_fail.clone(),
            contour: map.p_fail_contour(max_risk),
            star: (summary.terrain_k_n, summary.terrain_k_s),
            max_risk,
            title: format!(
                "p_fail at {slope_deg}\u{b0}, m = {} kg, cv k_n = {:.2}, cv k_s = {:.2}",
                robot.mass(),
                u.cv_n,
                u.cv_s
            ),
        };
        save(path, &figure)?;
    }
    match args.format() {
        Format::Json => print_json(&RiskAnswer::Map(Box::new(answer))),
        Format::Csv => match &args.csv {
            Some(None) => {
                let mut out = std::io::BufWriter::new(std::io::stdout().lock());
                sandslope_render::tables::risk_map_csv(map, &mut out)
                    .and_then(|_| out.flush())
                    .context("cannot write to stdout")
            }
            _ => Ok(()),
        },
        Format::Table => {
            println!(
                "p_fail map at {slope_deg} deg: {} x {} cells (k_n {} to {}, k_s {} to {} N/m^3), cv k_n {:.3}, cv k_s {:.3}",
                k_n_axis.len(),
                k_s_axis.len(),
                sci(k_n_axis.min()),
                sci(k_n_axis.max()),
                sci(k_s_axis.min()),
                sci(k_s_axis.max()),
                u.cv_n,
                u.cv_s
            );
            println!(
                "{} of {} cells have p_fail < {max_risk}; the terrain's own medians (k_n {}, k_s {}) have p_fail {:.4}",
                summary.cells_below_max_risk,
                summary.cells,
                sci(summary.terrain_k_n),
                sci(summary.terrain_k_s),
                summary.terrain_p_fail
            );
            if let Some(note) = summary.defaults_used.note() {
                println!("note: {note}");
            }
            Ok(())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slope_lists_and_ranges() {
        let parse_slopes = request::parse_slopes;
        assert_eq!(parse_slopes("20").unwrap(), vec![20.0]);
        assert_eq!(parse_slopes("0, 10,20").unwrap(), vec![0.0, 10.0, 20.0]);
        assert_eq!(parse_slopes("0:24:4").unwrap(), vec![0.0, 8.0, 16.0, 24.0]);
        for bad in ["x", "0:24", "0:24:1", "24:0:5", "95", "0:24:q"] {
            assert!(parse_slopes(bad).unwrap_err().to_string().contains("--slope"), "{bad}");
        }
    }
}
