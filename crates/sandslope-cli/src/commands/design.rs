//! `sandslope design`: which robot climbs the mission's slopes safely and fast. Varies robot
//! keys over ranges (`--vary`), evaluates every design on the uncertain terrain with
//! `sandslope::design::explore`, and prints the Pareto front over (safe-slope limit, speed at
//! `--slope-target`), JSON of every design, a CSV file, and a figure.

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use serde::Serialize;

use sandslope::design::{design_key, explore, Design, DesignGoal, DesignRange, DesignSpace, DesignStudy};
use sandslope::risk::SafeLimit;
use sandslope::robot_key::RobotKey;
use sandslope::{AxisScale, Slope};

use crate::args::{parse_axis_range, parse_max_risk, RobotArgs, TerrainArgs, UncertaintyArgs};
use crate::figures::design::{DesignFigure, SafeSlopeMap};
use crate::figures::{format_of, save};
use crate::output::{check_parent_exists, num, print_json, table, write_atomic};
use crate::progress::progress_bar;

/// Arguments of `sandslope design`.
#[derive(Debug, Args)]
pub struct DesignArgs {
    /// Robot keys to vary: KEY=MIN:MAX:N[:log|:lin] or KEY=VALUE, comma-separated or repeated
    /// (e.g. leg_radius_m=0.03:0.06:7,mass_kg=0.3:1.5:9). Keys: the robot file's (docs/model.md §2).
    #[arg(long, value_name = "KEY=MIN:MAX:N[:log],...", required = true)]
    pub vary: Vec<String>,
    /// The mission's target slope, degrees: speed, regime, p_fail and k_s margin are reported there.
    #[arg(long = "slope-target", value_name = "DEG", allow_negative_numbers = true)]
    pub slope_target: f64,
    #[command(flatten)]
    pub robot: RobotArgs,
    #[command(flatten)]
    pub terrain: TerrainArgs,
    #[command(flatten)]
    pub uncertainty: UncertaintyArgs,
    /// Largest acceptable failure probability, for the safe-slope limit.
    #[arg(long = "max-risk", allow_negative_numbers = true, value_name = "P", default_value = "0.05", value_parser = parse_max_risk)]
    pub max_risk: f64,
    /// Print every design as JSON instead of the front as a table.
    #[arg(long)]
    pub json: bool,
    /// Write one row per design to this CSV file.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Draw the front (and, for two varied keys, a map of the safe-slope limit) to this .png or .svg.
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Rows of the front shown in the table (the JSON and CSV hold every design).
    #[arg(long, value_name = "N", default_value_t = 20)]
    pub show: usize,
}

/// Parses one `KEY=MIN:MAX:N[:log|:lin]` or `KEY=VALUE` item of `--vary`.
pub fn parse_vary_item(item: &str) -> Result<DesignRange> {
    let (key, range) = item
        .split_once('=')
        .ok_or_else(|| anyhow!("--vary: `{item}` must be KEY=MIN:MAX:N[:log|:lin] or KEY=VALUE"))?;
    let key = design_key(key.trim()).map_err(|e| anyhow!("--vary: {e}"))?;
    // Robot quantities vary over less than a decade: linear spacing unless `:log` is written.
    let (min, max, n, scale) = if range.contains(':') {
        let r = parse_axis_range(range, AxisScale::Linear, &format!("--vary: {key}"), item)?
            .ok_or_else(|| anyhow!("--vary: `{item}` must be KEY=MIN:MAX:N[:log|:lin] or KEY=VALUE"))?;
        if r.n < 2 {
            bail!("--vary: {key} N `{}` must be a whole number of at least 2 (in {item})", r.n);
        }
        (r.min, r.max, r.n, r.scale)
    } else {
        let v = range.trim();
        let v =
            v.parse::<f64>().map_err(|_| anyhow!("--vary: {key} value `{v}` is not a number (in {item})"))?;
        (v, v, 1, AxisScale::Linear)
    };
    DesignRange::new(key, min, max, n, scale).map_err(|e| anyhow!("--vary: {e}"))
}

/// One design as printed by `--json`.
#[derive(Debug, Serialize)]
struct DesignRecord {
    params: BTreeMap<&'static str, f64>,
    valid: bool,
    /// Why the robot is not valid (docs/model.md §2), null when it is.
    invalid_reason: Option<String>,
    safe_slope_deg: Option<f64>,
    /// `limit`, `repose` (up to the angle of repose), `none_safe` (not even level ground) or
    /// `beyond_range` (every slope searched).
    safe_limit: Option<&'static str>,
    speed_m_s: Option<f64>,
    p_fail: Option<f64>,
    regime: Option<&'static str>,
    k_s_margin: Option<f64>,
    pareto: bool,
}

#[derive(Debug, Serialize)]
struct StudyRecord {
    slope_target_deg: f64,
    max_risk: f64,
    designs_evaluated: usize,
    invalid: usize,
    notes: Vec<String>,
    template: DesignRecord,
    designs: Vec<DesignRecord>,
}

fn limit_kind(l: &SafeLimit) -> &'static str {
    l.kind()
}

fn record(keys: &[RobotKey], d: &Design) -> DesignRecord {
    let params = keys.iter().zip(&d.params).map(|(k, v)| (k.name(), *v)).collect();
    match &d.outcome {
        Ok(p) => DesignRecord {
            params,
            valid: true,
            invalid_reason: None,
            safe_slope_deg: p.safe_slope_deg,
            safe_limit: Some(limit_kind(&p.safe_limit)),
            speed_m_s: p.speed_m_s,
            p_fail: Some(p.p_fail),
            regime: Some(p.regime.name()),
            k_s_margin: p.k_s_margin,
            pareto: d.pareto,
        },
        Err(reason) => DesignRecord {
            params,
            valid: false,
            invalid_reason: Some(reason.clone()),
            safe_slope_deg: None,
            safe_limit: None,
            speed_m_s: None,
            p_fail: None,
            regime: None,
            k_s_margin: None,
            pareto: false,
        },
    }
}

/// Runs `sandslope design`.
pub fn run(args: DesignArgs) -> Result<()> {
    let robot = args.robot.load()?;
    let mut ranges = Vec::new();
    for text in &args.vary {
        for item in text.split(',').filter(|s| !s.trim().is_empty()) {
            ranges.push(parse_vary_item(item.trim())?);
        }
    }
    let space = DesignSpace::new(robot.spec().clone(), ranges).map_err(|e| anyhow!("--vary: {e}"))?;
    let max_risk = args.max_risk;
    let target = Slope::from_signed_degrees(args.slope_target)
        .map_err(|e| anyhow!("{}", e.renamed("--slope-target")))?;
    let goal = DesignGoal::new(max_risk, target).map_err(|e| anyhow!("--max-risk: {e}"))?;
    let (terrain, note) = args.uncertainty.apply(args.terrain.load()?)?;
    let notes: Vec<String> = note.into_iter().collect();
    // Check every output before the work.
    if let Some(p) = &args.plot {
        format_of(p)?;
        check_parent_exists(p)?;
    }
    if let Some(p) = &args.csv {
        check_parent_exists(p)?;
    }

    let bar = progress_bar(space.len() as u64, args.json, "designs");
    let study = explore(&space, &terrain, &goal, &|| bar.inc(1));
    bar.finish_and_clear();
    let mut notes = notes;
    notes.extend(front_at_bounds(&study, &space));

    if let Some(path) = &args.csv {
        write_atomic(path, sandslope_render::tables::design_csv(&study)?.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(path) = &args.plot {
        let name = terrain.terrain().name().map_or_else(|| args.terrain.terrain.clone(), str::to_string);
        draw(&study, &space, &name, path)?;
    }
    if args.json {
        let keys = &study.keys;
        return print_json(&StudyRecord {
            slope_target_deg: study.slope_target_deg,
            max_risk,
            designs_evaluated: study.designs.len(),
            invalid: study.invalid_count(),
            notes,
            template: record(keys, &study.template),
            designs: study.designs.iter().map(|d| record(keys, d)).collect(),
        });
    }
    print_table(&study, args.show, &notes);
    Ok(())
}

/// A note for each varied key whose smallest or largest value holds designs of the Pareto
/// front: the front is then cut by the range searched, and a better design may lie beyond it.
fn front_at_bounds(study: &DesignStudy, space: &DesignSpace) -> Vec<String> {
    let front = study.front();
    let mut notes = Vec::new();
    for (i, range) in space.ranges().iter().enumerate() {
        let values = range.values();
        let (Some(&lo), Some(&hi)) = (values.first(), values.last()) else { continue };
        if values.len() < 2 {
            continue;
        }
        for (value, end) in [(lo, "smallest"), (hi, "largest")] {
            let at = front.iter().filter(|d| d.params[i] == value).count();
            if at > 0 {
                notes.push(format!(
                    "the Pareto front is at the bound of --vary: {at} of its {} designs have {} = {value}, the {end} value \
                     searched; a better design may lie beyond it (widen the range to see)",
                    front.len(),
                    range.key().name()
                ));
            }
        }
    }
    notes
}

fn print_table(study: &DesignStudy, show: usize, notes: &[String]) {
    let front = study.front();
    println!(
        "{} designs, {} invalid; Pareto front over (safe-slope limit at p_fail < {}, speed at {} deg): {} designs",
        study.designs.len(),
        study.invalid_count(),
        study.max_risk,
        study.slope_target_deg,
        front.len()
    );
    let mut header: Vec<String> = study.keys.iter().map(|k| k.name().to_string()).collect();
    const OUTCOME: [&str; 5] = ["safe slope (deg)", "speed (cm/s)", "p_fail", "regime", "k_s margin"];
    header.extend(OUTCOME.map(String::from));
    let refs: Vec<&str> = header.iter().map(String::as_str).collect();
    let mut t = table(&refs);
    let row = |d: &Design| -> Vec<String> {
        let mut r: Vec<String> = d.params.iter().map(|v| format!("{v:.4}")).collect();
        match &d.outcome {
            Ok(p) => r.extend([
                match p.safe_limit {
                    SafeLimit::NoneSafe { .. } => "none".into(),
                    SafeLimit::BeyondRange { up_to, .. } => format!(">= {up_to}"),
                    SafeLimit::Limit { value, .. } => format!("{value:.3}"),
                    SafeLimit::Repose { repose_deg, .. } => format!("{repose_deg} (repose)"),
                },
                num(p.speed_m_s.map(|v| 100.0 * v), 2),
                format!("{:.4}", p.p_fail),
                p.regime.name().to_string(),
                num(p.k_s_margin, 3),
            ]),
            Err(reason) => r.extend([
                format!("invalid: {reason}"),
                String::new(),
                String::new(),
                String::new(),
                String::new(),
            ]),
        }
        r
    };
    for d in front.iter().take(show) {
        t.add_row(row(d));
    }
    println!("{t}");
    if front.len() > show {
        println!("({} more on the front: --show N, --json or --csv FILE for all)", front.len() - show);
    }
    let template = row(&study.template);
    // Each of the template's outcomes named, as the table's columns are.
    let labelled: Vec<String> =
        OUTCOME.iter().zip(&template[study.keys.len()..]).map(|(name, v)| format!("{name} {v}")).collect();
    println!(
        "template robot (the --robot file): {}{}",
        labelled.join(", "),
        if study.template.pareto { " (on the front)" } else { " (dominated by a design in the space)" }
    );
    let mut reasons: BTreeMap<&str, usize> = BTreeMap::new();
    for d in &study.designs {
        if let Err(r) = &d.outcome {
            *reasons.entry(r.as_str()).or_default() += 1;
        }
    }
    for (reason, count) in reasons.iter().take(5) {
        println!("invalid ({count} designs): {reason}");
    }
    for n in notes {
        println!("note: {n}");
    }
    println!(
        "safe-slope limit: steepest slope with p_fail < {} from level up, as `sandslope risk --solve slope` (docs/model.md \u{a7}9)",
        study.max_risk
    );
}

fn draw(study: &DesignStudy, space: &DesignSpace, terrain: &str, path: &std::path::Path) -> Result<()> {
    let point = |d: &Design| -> Option<(f64, f64)> {
        let p = d.outcome.as_ref().ok()?;
        Some((p.safe_slope_rank(), p.speed_m_s?))
    };
    let all: Vec<(f64, f64)> = study.designs.iter().filter(|d| !d.pareto).filter_map(point).collect();
    let mut front: Vec<(f64, f64)> = study.designs.iter().filter(|d| d.pareto).filter_map(point).collect();
    front.sort_by(|a, b| a.0.total_cmp(&b.0));
    // A map when exactly two keys vary over at least two values each.
    let varied: Vec<usize> =
        (0..space.ranges().len()).filter(|&i| space.ranges()[i].values().len() > 1).collect();
    let map = (varied.len() == 2).then(|| {
        let (a, b) = (&space.ranges()[varied[0]], &space.ranges()[varied[1]]);
        SafeSlopeMap {
            x_key: a.key().name().to_string(),
            y_key: b.key().name().to_string(),
            x: a.values().to_vec(),
            y: b.values().to_vec(),
            // Designs are numbered first range slowest; with only these two varying, the
            // design index is i_a * n_b + i_b.
            safe: study
                .designs
                .iter()
                .map(|d| d.outcome.as_ref().ok().map(|p| p.safe_slope_rank()))
                .collect(),
        }
    });
    let figure = DesignFigure {
        others: all,
        front,
        template: point(&study.template),
        map,
        title: format!(
            "Designs on {terrain}: safe-slope limit (p_fail < {}) vs speed at {} deg",
            study.max_risk, study.slope_target_deg
        ),
    };
    save(path, &figure)
}
