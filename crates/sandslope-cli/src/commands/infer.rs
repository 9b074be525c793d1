//! `sandslope infer`: what the robot's own gait says about the sand. From observed speeds (and
//! anchoring times), the exact posterior of k_s at each observed slope (`sandslope::infer`);
//! with `--law`, the joint posterior of a shear law and the predicted failure risk, with a
//! credible band, at slopes not walked.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use sandslope::infer::{Bound, InferLaw};
use sandslope_request::error::Words;
use sandslope_request::grammar::uncertain_terrain;
use sandslope_request::infer::{InferAnswer, InferQuestion, ServoLogQuestion, JOINTS, TOPIC};

use crate::args::{FieldArgs, RobotArgs, TerrainArgs};
use crate::figures::infer::InferFigure;
use crate::figures::{format_of, save};
use crate::output::{check_parent_exists, print_json, sci, table};

/// Arguments of `sandslope infer`.
#[derive(Debug, Args)]
pub struct InferArgs {
    /// `--observed`, `--steps`, `--servo-log`, `--topic`, `--joints`, `--effort-unit`,
    /// `--slope`, `--grid-points`, `--cv-n`, `--cv-s`, `--k-s-prior`, `--law` and `--predict`:
    /// the request's own fields ([`sandslope_request::infer::FIELDS`]).
    #[command(flatten)]
    pub fields: FieldArgs<InferQuestion>,
    #[command(flatten)]
    pub robot: RobotArgs,
    /// Terrain giving k_n (and the angle of repose) at each slope; its k_s is not used except
    /// as the comparison in the figure.
    #[command(flatten)]
    pub terrain: TerrainArgs,
    /// Print JSON instead of tables.
    #[arg(long)]
    pub json: bool,
    /// Draw the posterior bands (and with --law the predicted risk) to this .png or .svg file.
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
}

fn bound_note(b: Bound) -> &'static str {
    match b {
        Bound::TwoSided => "",
        Bound::LowerOnly => "only a lower bound: speed at the model's ceiling",
        Bound::UpperOnly => "only an upper bound: speed at the model's floor",
        Bound::Neither => "not bounded: speed insensitive to k_s",
    }
}

/// `infer --servo-log`: k_s from the stance currents of a `drive` log (docs/model.md §19).
fn run_servo_log(args: &InferArgs, question: &ServoLogQuestion) -> Result<()> {
    let robot = args.robot.load()?;
    // The log read and checked, its slope taken, by the request layer (as Python's is).
    let ServoLogQuestion { request, topic, joints, effort } = question;
    let path = request.path.as_path();
    // The servos' model: the robot file's `[servos] model`, else the paper's XL330-M288.
    let servo = sandslope_io::robot_terrain::load_servos(&args.robot.robot)?
        .and_then(|s| s.model)
        .unwrap_or(&sandslope::servo::ServoModel::XL330_M288);
    let mut run = if sandslope_bag::is_bag(path) {
        // A ROS 2 bag's joint states, read as the servo log's leg angles and torques.
        let options = sandslope_io::bag_series::JointOptions {
            topic: topic.as_deref(),
            joints: (!joints.is_empty()).then_some(joints.as_slice()),
            legs: 2 * robot.stance_legs() as usize,
            effort: *effort,
        };
        let log = sandslope_io::bag_series::read_joint_states_of(path, &options, servo)?;
        request.read_log(log, &robot, Words::Flag)?
    } else {
        if topic.is_some() || !joints.is_empty() {
            anyhow::bail!(
                "{} and {} read a ROS 2 bag (a folder with metadata.yaml, an .mcap or .db3 file), but {} is not one",
                TOPIC.long(),
                JOINTS.long(),
                path.display()
            );
        }
        request.read(&robot, Words::Flag)?
    };
    // The grid's reportable torque is the same servo's.
    run.settings.servo = servo;
    let terrain = args.terrain.load()?;
    for note in &run.notes {
        eprintln!("note: {}: {note}", path.display());
    }
    let answer = run.answer(&robot, &terrain)?;
    let slope_deg = run.slope.degrees();
    let k_n = answer.k_n;
    if args.json {
        // The reader's repairs beside the answer (they are the file's, not the sand's), as
        // Python's `infer_servo_log` returns them.
        let mut v = serde_json::to_value(&answer)?;
        if let Some(o) = v.as_object_mut() {
            o.insert("notes".into(), serde_json::json!(run.notes));
        }
        return print_json(&v);
    }
    println!(
        "k_s at {slope_deg} deg from the stance currents of {} strides: {} N/m^3, 90% interval {} - {}{}",
        answer.strides,
        sci(answer.k_s),
        sci(answer.k_s_lo),
        sci(answer.k_s_hi),
        match bound_note_servo(answer.bound) {
            "" => String::new(),
            n => format!(" ({n})"),
        }
    );
    println!(
        "shear load per stance leg: {:.3} N (the stride simulator at that k_s; the closed form's m (g sin theta + R omega / dt) / n is {:.3} N)",
        answer.shear_load_n, answer.closed_form_shear_load_n
    );
    println!(
        "climbing speed those sands give: {:.1} cm/s, 90% interval {:.1} - {:.1} (the stride simulator's walks; the servos do not measure the speed over the ground)",
        100.0 * answer.speed_m_s,
        100.0 * answer.speed_lo_m_s,
        100.0 * answer.speed_hi_m_s
    );
    println!(
        "P(fail) at {slope_deg} deg: {:.3} (slippage {:.3}, sinkage {:.3})",
        answer.p_fail, answer.p_slippage, answer.p_sinkage
    );
    if !answer.swing_offset_n_m.is_empty() {
        let ma: Vec<String> = answer
            .swing_offset_n_m
            .iter()
            .map(|t| format!("{:.0}", servo.current_ma_from_torque(*t)))
            .collect();
        println!(
            "current offsets read in the swings and removed, legs 0 to {}: {} mA (as drive torque, in each leg's sense)",
            ma.len() - 1,
            ma.join(", ")
        );
    }
    println!(
        "k_n {} N/m^3 from the terrain; stance torque K_t I against the stride simulator on {} k_s values (docs/model.md \u{a7}19)",
        sci(k_n),
        request.grid_points
    );
    Ok(())
}

fn bound_note_servo(b: Bound) -> &'static str {
    match b {
        Bound::TwoSided => "",
        Bound::LowerOnly => "only a lower bound: the currents look alike for any stronger sand",
        Bound::UpperOnly => "only an upper bound: the currents look alike for any weaker sand",
        Bound::Neither => "not bounded: the currents hardly depend on k_s at this slope",
    }
}

/// Runs `sandslope infer`.
pub fn run(args: InferArgs) -> Result<()> {
    let (request, cv_n, cv_s) = match InferQuestion::from_fields(&args.fields.pairs)? {
        InferQuestion::ServoLog(question) => return run_servo_log(&args, &question),
        InferQuestion::Gait { request, cv_n, cv_s } => (request, cv_n, cv_s),
    };
    let robot = args.robot.load()?;
    let obs = request.observations()?;
    let (terrain, note) = uncertain_terrain(args.terrain.load()?, cv_n, cv_s)?;
    if let Some(p) = &args.plot {
        format_of(p)?;
        check_parent_exists(p)?;
    }
    let answer = request.answer(&robot, &terrain, note, &obs)?;
    let InferAnswer { prior, points, law, notes, .. } = &answer;
    let prior = *prior;
    if let Some(path) = &args.plot {
        let figure = InferFigure {
            points: points.clone(),
            law: law.clone(),
            table: terrain.terrain().points().iter().map(|p| (p.slope_deg, p.k_s)).collect(),
            prior,
            title: format!(
                "k_s from the gait of {} kg on {}",
                robot.mass(),
                terrain.terrain().name().unwrap_or("the terrain")
            ),
        };
        save(path, &figure)?;
    }
    if args.json {
        return print_json(&answer);
    }
    let mut t = table(&["slope (deg)", "speed (m/s)", "k_n", "k_s median", "k_s 90% interval", "note"]);
    for p in points {
        t.add_row([
            format!("{}", p.slope_deg),
            format!("{:.4} ± {:.4}", p.speed_m_s, p.speed_se_m_s),
            sci(p.k_n),
            sci(p.k_s_median),
            format!("{} – {}", sci(p.k_s_q05), sci(p.k_s_q95)),
            bound_note(p.bound).to_string(),
        ]);
    }
    println!("{t}");
    println!(
        "posterior of k_s per slope on a ln k_s grid, log-uniform prior {}:{} N/m^3 (docs/inference.md)",
        sci(prior.min()),
        sci(prior.max())
    );
    if let Some(l) = &law {
        let (name, unit) = match l.law {
            InferLaw::Linear => ("per degree", "N/m^3/deg"),
            InferLaw::Coulomb => ("friction angle", "deg"),
        };
        println!(
            "{:?} law: k_s0 {} [{} – {}] N/m^3, {name} {:.4e} [{:.4e} – {:.4e}] {unit} (median [90% interval])",
            l.law,
            sci(l.k_s0.median),
            sci(l.k_s0.q05),
            sci(l.k_s0.q95),
            l.second.median,
            l.second.q05,
            l.second.q95
        );
        let mut t =
            table(&["slope (deg)", "k_s median", "k_s 90% band", "p_fail median", "p_fail 90% band", ""]);
        for p in &l.prediction {
            t.add_row([
                format!("{}", p.slope_deg),
                sci(p.k_s.median),
                format!("{} – {}", sci(p.k_s.q05), sci(p.k_s.q95)),
                format!("{:.4}", p.p_fail.median),
                format!("{:.4} – {:.4}", p.p_fail.q05, p.p_fail.q95),
                if p.observed { "observed".into() } else { String::new() },
            ]);
        }
        println!("{t}");
        println!("p_fail = P(sinkage or slippage) with the law's k_s as the median and the terrain's spread (docs/model.md \u{a7}9)");
    }
    for n in notes {
        println!("note: {n}");
    }
    Ok(())
}
