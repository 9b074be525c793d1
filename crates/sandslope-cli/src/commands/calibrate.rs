//! `sandslope calibrate`: fit the unmeasured quantities (k_s(theta), and any robot key, a
//! plate-to-leg scale or a model-error floor) so that the model agrees with observed speeds,
//! anchoring times and force tests together (docs/calibration.md), and write the result as a
//! terrain file (and robot file) every other command accepts.

use std::fmt::Write as _;
use std::path::Path;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use sandslope::calibrate::{Interval, ObservationKind, SpeedModel, SpeedObservation};
use sandslope::{JointCalibration, Parameter, Quantity, Terrain};
use sandslope_request::calibrate::{
    CalibrateAnswer, CalibrateModel, CalibrateSource, JointAnswer, PerSlopeAnswer, ReposeRecord,
};
use sandslope_request::error::Words;
use sandslope_request::CalibrateRequest;

use crate::args::{FieldArgs, RobotArgs, TerrainArgs};
use crate::figures::calibrate::{speed_pulls, CalibrationFigure};
use crate::output::{check_parent_exists, print_json, table, write_atomic};
use sandslope_io::robot_terrain::{robot_toml, terrain_toml};

/// Arguments of `sandslope calibrate`.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    /// The command line as run (its arguments after the program), for the written files'
    /// `Written by:` header: given by `main`, which owns the process's arguments.
    #[arg(skip)]
    pub command_line: Vec<String>,
    /// `--observed`, `--forces`, `--t1`, `--free`, `--error-floor`, `--law`, `--model`,
    /// `--k-n`, `--name` and `--repose`: the request's own fields
    /// ([`sandslope_request::calibrate::FIELDS`]).
    #[command(flatten)]
    pub fields: FieldArgs<CalibrateRequest>,
    /// Write the calibrated terrain (docs/model.md §7 format) to this TOML file.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Write the robot with its fitted keys to this TOML file (needs a robot key in --free).
    #[arg(long, value_name = "FILE")]
    pub robot_out: Option<PathBuf>,
    /// Draw observed against fitted speeds, with the pulls, to this PNG or SVG file.
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Print the fit as JSON instead of tables.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub robot: RobotArgs,
    /// Source of k_n (when neither --forces nor --k-n is given) and of the angle of repose.
    #[command(flatten)]
    pub terrain: TerrainArgs,
}

/// Runs `sandslope calibrate`: the flags into a [`CalibrateRequest`], its answer into the
/// files, the figure and the tables (or JSON).
pub fn run(args: CalibrateArgs) -> Result<()> {
    let request = CalibrateRequest::from_fields(&args.fields.pairs)?;
    let checked = request.check()?;
    let robot = args.robot.load()?;
    if args.robot_out.is_some() && !checked.fits_robot() {
        anyhow::bail!("--robot-out: no robot key is in --free, so the robot would be written unchanged");
    }
    for out in [Some(&args.out), args.robot_out.as_ref(), args.plot.as_ref()].into_iter().flatten() {
        check_parent_exists(out)?;
    }
    if let Some(p) = &args.plot {
        crate::figures::format_of(p)?;
    }
    let terrain = args.terrain.load()?;
    let source = CalibrateSource { robot: &robot, terrain: &terrain, terrain_name: &args.terrain.terrain };
    // The simulator's fit takes about 8 minutes of CPU on the paper's evidence
    // (docs/calibration.md): a spinner with the time.
    let spin = (request.model == CalibrateModel::Simulate)
        .then(|| crate::progress::spinner(args.json, "fitting with the stride simulator"));
    let answer = request.answer(source, Words::Flag);
    if let Some(spin) = spin {
        spin.finish_and_clear();
    }
    match answer? {
        CalibrateAnswer::Joint(joint) => write_joint(&args, &joint),
        CalibrateAnswer::PerSlope(per_slope) => write_per_slope(&args, &per_slope),
    }
}

/// A joint fit's outputs: the figure first (it is the likeliest to fail), then the files, then
/// the tables or JSON.
fn write_joint(args: &CalibrateArgs, joint: &JointAnswer) -> Result<()> {
    let cal = &joint.calibration;
    if let Some(path) = &args.plot {
        draw_fit(path, &joint.speeds, &joint.terrain, &joint.robot, cal)?;
    }
    write_files(args, cal, &joint.repose)?;
    if args.json {
        return print_json(joint);
    }
    print_joint(cal, &joint.repose);
    if let Some(cf) = &joint.closed_form_fit {
        print_side_by_side(cf, cal);
    }
    Ok(())
}

/// The `--plot` figure: observed speeds, the fitted model's curve, and the pulls.
fn draw_fit(
    path: &Path,
    speeds: &[SpeedObservation],
    terrain: &Terrain,
    fitted_robot: &sandslope::Robot,
    cal: &JointCalibration,
) -> Result<()> {
    let lo = speeds.iter().map(|o| o.slope.degrees()).fold(0.0, f64::min);
    let hi = speeds.iter().map(|o| o.slope.degrees()).fold(lo + 1.0, f64::max);
    let curve = sandslope::calibrate::speed_curve(fitted_robot, terrain, lo, hi, 200);
    let points = speed_pulls(&cal.pulls);
    let title = format!(
        "chi^2/dof = {}, k_s(20)/k_s(0) = {:.2}",
        cal.chi_squared_per_dof.map_or("-".into(), |r| format!("{r:.2}")),
        cal.shear_ratio_20.value
    );
    crate::figures::save(path, &CalibrationFigure { points: &points, curve: &curve, subtitle: &title })?;
    Ok(())
}

/// Writes `--out` (the calibrated terrain) and `--robot-out`, each with a header saying how.
fn write_files(args: &CalibrateArgs, cal: &JointCalibration, repose: &ReposeRecord) -> Result<()> {
    let command = &args.command_line;
    let mut header = String::new();
    writeln!(header, "Written by: sandslope {}", command.join(" "))?;
    writeln!(
        header,
        "Joint calibration (docs/calibration.md): chi^2 = {:.3} over {} dof; error floor {:.4} m/s; k_s(20)/k_s(0) = {:.3} [{:.3}, {:.3}].",
        cal.chi_squared, cal.dof, cal.error_floor_m_s, cal.shear_ratio_20.value, cal.shear_ratio_20.lower, cal.shear_ratio_20.upper
    )?;
    write!(header, "repose_deg: {}", repose.source)?;
    write_atomic(&args.out, terrain_toml(&cal.terrain, &header)?.as_bytes())?;
    if let Some(path) = &args.robot_out {
        let mut header = String::new();
        write!(header, "Written by: sandslope {}", command.join(" "))?;
        for p in cal.parameters.iter().filter(|p| matches!(p.quantity, Quantity::Free(Parameter::Robot(_)))) {
            write!(
                header,
                "\n{} fitted: {:.6e} (68% interval {:.6e} to {:.6e})",
                p.name, p.estimate.value, p.estimate.lower, p.estimate.upper
            )?;
        }
        write_atomic(path, robot_toml(&cal.robot, &header)?.as_bytes())?;
    }
    Ok(())
}

fn interval_text(iv: &Interval, sci: bool) -> String {
    let f = |x: f64| if sci { format!("{x:.4e}") } else { format!("{x:.4}") };
    format!(
        "{}{} to {}{}",
        if iv.lower_open { "≤ " } else { "" },
        f(iv.lower),
        f(iv.upper),
        if iv.upper_open { " (bound)" } else { "" }
    )
}

fn print_joint(cal: &JointCalibration, repose: &ReposeRecord) {
    let mut t = table(&["quantity", "best", "68% interval", "unit"]);
    for p in &cal.parameters {
        let sci = p.estimate.value.abs() >= 1e4 || (p.estimate.value != 0.0 && p.estimate.value.abs() < 1e-2);
        t.add_row([
            p.name.clone(),
            if sci { format!("{:.4e}", p.estimate.value) } else { format!("{:.4}", p.estimate.value) },
            interval_text(&p.estimate, sci),
            p.unit.clone(),
        ]);
    }
    println!("{t}");
    let mut t = table(&["observation", "slope deg", "observed ± SD", "model", "pull"]);
    for p in &cal.pulls {
        use ObservationKind as K;
        let (name, scale, unit) = match p.kind {
            K::Speed => ("speed", 100.0, "cm/s"),
            K::AnchoringTime => ("t1", 1000.0, "ms"),
            K::PlateShearStrength => ("plate k_s", 1.0, "N/m^3"),
        };
        let fmt = |x: f64| {
            if p.kind == K::PlateShearStrength {
                format!("{x:.3e}")
            } else {
                format!("{:.2}", x * scale)
            }
        };
        let sd = if p.sd_total > p.sd * (1.0 + 1e-9) {
            format!("{} (fit {})", fmt(p.sd), fmt(p.sd_total))
        } else {
            fmt(p.sd)
        };
        t.add_row([
            name.to_string(),
            format!("{}", p.slope_deg),
            format!("{} ± {} {unit}", fmt(p.observed), sd),
            format!("{} {unit}", fmt(p.model)),
            format!("{:+.2}", p.pull),
        ]);
    }
    println!("{t}");
    let level = cal.shear.first().map(|s| s.k_s).filter(|k| *k > 0.0);
    let mut t =
        table(&["slope deg", "k_n N/m^3", "k_s N/m^3", "k_s / first", "force on the paper's plate N"]);
    for s in &cal.shear {
        t.add_row([
            format!("{}", s.slope_deg),
            format!("{:.3e}", s.k_n),
            format!("{:.4e}", s.k_s),
            level.map_or("-".into(), |l| format!("{:.3}", s.k_s / l)),
            format!("{:.1}", s.plate_force_n),
        ]);
    }
    println!("{t}");
    println!(
        "chi^2 = {:.2} over {} dof (chi^2/dof {}); error floor {:.2} cm/s",
        cal.chi_squared,
        cal.dof,
        cal.chi_squared_per_dof.map_or("-".into(), |r| format!("{r:.2}")),
        cal.error_floor_m_s * 100.0
    );
    println!(
        "k_s(20)/k_s(0) = {:.3} (68%: {}); the paper's force tests: about 0.40",
        cal.shear_ratio_20.value,
        interval_text(&cal.shear_ratio_20, false)
    );
    println!("repose_deg = {} ({})", repose.deg.map_or("none".into(), |r| format!("{r}")), repose.source);
    for w in &cal.warnings {
        println!("warning: {w}");
    }
}

/// The closed form's and the simulator's fits of the same evidence, side by side.
fn print_side_by_side(closed: &JointCalibration, sim: &JointCalibration) {
    let settings = match sim.model {
        SpeedModel::Simulator { settings } => settings,
        SpeedModel::ClosedForm => return,
    };
    println!();
    println!(
        "The same evidence fitted by the closed form and by the simulator ({} s walks at dt = {} ms, \
         creep speed {:e} m/s; {} walks):",
        settings.duration_s,
        settings.dt_s.map_or("default".into(), |d| format!("{}", d * 1e3)),
        settings.creep_m_s,
        sim.walks
    );
    let mut t =
        table(&["observation", "slope deg", "observed ± SD", "closed form", "pull", "simulator", "pull"]);
    for (c, s) in closed.pulls.iter().zip(&sim.pulls) {
        use ObservationKind as K;
        let (name, scale, unit, sci) = match c.kind {
            K::Speed => ("speed", 100.0, "cm/s", false),
            K::AnchoringTime => ("t1", 1000.0, "ms", false),
            K::PlateShearStrength => ("plate k_s", 1.0, "N/m^3", true),
        };
        let f = |x: f64| if sci { format!("{x:.3e}") } else { format!("{:.2}", x * scale) };
        t.add_row([
            name.to_string(),
            format!("{}", c.slope_deg),
            format!("{} ± {} {unit}", f(c.observed), f(c.sd)),
            format!("{} {unit}", f(c.model)),
            format!("{:+.2}", c.pull),
            format!("{} {unit}", f(s.model)),
            format!("{:+.2}", s.pull),
        ]);
    }
    println!("{t}");
    let mut t = table(&["quantity", "closed form (68%)", "simulator (68%)"]);
    let cell = |p: Option<&sandslope::FittedParameter>| {
        p.map_or("-".into(), |p| {
            let sci =
                p.estimate.value.abs() >= 1e4 || (p.estimate.value != 0.0 && p.estimate.value.abs() < 1e-2);
            let v =
                if sci { format!("{:.3e}", p.estimate.value) } else { format!("{:.4}", p.estimate.value) };
            format!("{v} ({})", interval_text(&p.estimate, sci))
        })
    };
    for p in &closed.parameters {
        t.add_row([p.name.clone(), cell(Some(p)), cell(sim.fitted(p.quantity))]);
    }
    let dof = |c: &JointCalibration| {
        format!(
            "{:.2} / {} ({})",
            c.chi_squared,
            c.dof,
            c.chi_squared_per_dof.map_or("-".into(), |r| format!("{r:.2}"))
        )
    };
    t.add_row(["chi^2 / dof".to_string(), dof(closed), dof(sim)]);
    t.add_row([
        "error floor cm/s".to_string(),
        format!("{:.2}", closed.error_floor_m_s * 100.0),
        format!("{:.2}", sim.error_floor_m_s * 100.0),
    ]);
    t.add_row([
        "k_s(20)/k_s(0)".to_string(),
        format!("{:.3}", closed.shear_ratio_20.value),
        format!("{:.3}", sim.shear_ratio_20.value),
    ]);
    println!("{t}");
}

/// `--law per-slope`'s outputs: the terrain file, then the table or JSON.
fn write_per_slope(args: &CalibrateArgs, answer: &PerSlopeAnswer) -> Result<()> {
    let command = &args.command_line;
    let header = format!(
        "Written by: sandslope {}\nk_s per observed slope, inverted from each speed\nrepose_deg: {}",
        command.join(" "),
        answer.repose.source
    );
    write_atomic(&args.out, terrain_toml(&answer.terrain, &header)?.as_bytes())?;
    if args.json {
        return print_json(answer);
    }
    println!("law: per-slope (each speed inverted by root finding)");
    let level = answer.residuals.first().map(|r| r.k_s).filter(|k| *k > 0.0);
    let mut t = table(&["slope deg", "k_s N/m^3", "k_s / first", "observed cm/s", "model cm/s"]);
    for r in &answer.residuals {
        t.add_row([
            format!("{}", r.slope_deg),
            format!("{:.4e}", r.k_s),
            level.map_or("-".into(), |l| format!("{:.3}", r.k_s / l)),
            format!("{:.2} ± {:.2}", r.observed_m_s * 100.0, r.observed_sd_m_s * 100.0),
            format!("{:.2}", r.model_m_s * 100.0),
        ]);
    }
    println!("{t}");
    let repose = &answer.repose;
    println!("repose_deg = {} ({})", repose.deg.map_or("none".into(), |r| format!("{r}")), repose.source);
    Ok(())
}
