//! `sandslope design`: which robot climbs the mission's slopes safely and fast. Varies robot
//! keys over ranges (`--vary`), evaluates every design on the uncertain terrain with
//! `sandslope::design::explore`, and prints the Pareto front over (safe-slope limit, speed at
//! `--slope-target`), JSON of every design, a CSV file, and a figure.

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

use sandslope::design::{Design, DesignSpace, DesignStudy};
use sandslope::risk::SafeLimit;
use sandslope_request::design::DesignAnswer;
use sandslope_request::DesignRequest;

use crate::args::{FieldArgs, RobotArgs, TerrainArgs};
use crate::figures::design::{DesignFigure, SafeSlopeMap};
use crate::figures::{format_of, save};
use crate::output::{check_parent_exists, num, print_json, table, write_atomic};
use crate::progress::progress_bar;

/// Arguments of `sandslope design`.
#[derive(Debug, Args)]
pub struct DesignArgs {
    /// `--vary`, `--slope-target`, `--cv-n`, `--cv-s` and `--max-risk`: the request's own
    /// fields ([`sandslope_request::design::FIELDS`]).
    #[command(flatten)]
    pub fields: FieldArgs<DesignRequest>,
    #[command(flatten)]
    pub robot: RobotArgs,
    #[command(flatten)]
    pub terrain: TerrainArgs,
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

impl DesignArgs {
    /// The request these flags make, read by the request layer's one raw-to-typed step.
    pub fn request(&self) -> Result<DesignRequest> {
        let (robot, terrain) = (self.robot.request(), self.terrain.terrain.clone());
        Ok(DesignRequest::with_sources(&self.fields.pairs, robot, terrain)?)
    }
}

/// Runs `sandslope design`.
pub fn run(args: DesignArgs) -> Result<()> {
    let mut inputs = args.request()?.inputs()?;
    // Check every output before the work.
    if let Some(p) = &args.plot {
        format_of(p)?;
        check_parent_exists(p)?;
    }
    if let Some(p) = &args.csv {
        check_parent_exists(p)?;
    }

    let bar = progress_bar(inputs.space.len() as u64, args.json, "designs");
    let study = inputs.explore(&|| bar.inc(1));
    bar.finish_and_clear();

    if let Some(path) = &args.csv {
        write_atomic(path, sandslope_render::tables::design_csv(&study)?.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(path) = &args.plot {
        let terrain = inputs.terrain.terrain();
        let name = terrain.name().map_or_else(|| args.terrain.terrain.clone(), str::to_string);
        draw(&study, &inputs.space, &name, path)?;
    }
    if args.json {
        return print_json(&DesignAnswer::new(&study, inputs.notes));
    }
    print_table(&study, args.show, &inputs.notes);
    Ok(())
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
