//! The numbers Liao and Qian report (docs/model.md §12), and the model set beside them.
//!
//! Every constant here is a fact from the paper's text (arXiv:2603.06928), with the place it
//! comes from. [`compare_with_paper`] evaluates a robot and terrain on each of them and says,
//! by a stated rule, whether the model agrees.

use serde::Serialize;

use crate::model::predict;
use crate::regime::Regime;
use crate::robot::Robot;
use crate::slope::Slope;
use crate::terrain::Terrain;

/// Observed step-averaged upslope speeds of the 0.35 kg robot on 300 um glass beads,
/// `(slope_deg, mean_m_s, sd_m_s)` (Sec. III-A, Fig. 3a; `data/paper-speeds.csv`).
pub const SPEEDS: [(f64, f64, f64); 5] = [
    (0.0, 0.157, 0.0097),
    (10.0, 0.110, 0.0014),
    (15.0, 0.105, 0.0023),
    (20.0, 0.0498, 0.0032),
    (24.0, 0.056, 0.016),
];

/// Shear resistance at 20 degrees relative to level sand, "approximately 40%" (Sec. III-C, Fig. 4h).
pub const SHEAR_RATIO_20: f64 = 0.40;

/// Normal resistance "nearly unchanged" with slope (Sec. III-B, Fig. 4d): the ratio
/// k_n(20)/k_n(0) the text implies.
pub const NORMAL_RATIO_20: f64 = 1.0;

/// Slopes of the force tests, degrees (Sec. II-C).
pub const FORCE_TEST_SLOPES: [f64; 6] = [0.0, 5.0, 10.0, 15.0, 20.0, 24.0];

/// Radius of the penetration disk, m (Sec. II-C).
pub const DISK_RADIUS_M: f64 = 0.01;

/// Width of the shear plate, m (Sec. II-C: "height = 2 cm, width = 3 cm").
pub const SHEAR_PLATE_WIDTH_M: f64 = 0.03;

/// Depth of the shear plate, m (Sec. II-C: "maintained at 2 cm").
pub const SHEAR_PLATE_DEPTH_M: f64 = 0.02;

/// Intruder speed in both force tests, m/s (Sec. II-C).
pub const INTRUDER_SPEED_M_S: f64 = 0.05;

/// Angle of repose, "near 25 degrees", degrees (Sec. II-C footnote).
pub const REPOSE_DEG: f64 = 25.0;

/// Touchdown times of the two tripods, s (Sec. III-A).
pub const TOUCHDOWNS_S: [f64; 2] = [0.0, 0.5];

/// Fig. 6d's claim: a robot of this mass (kg) on the measured terrain at this slope (degrees)
/// is metastable.
pub const HEAVY_ROBOT_CLAIM: (f64, f64, Regime) = (1.0, 24.0, Regime::Metastable);

/// The paper's robot as the paper reports it (docs/model.md §2, column "paper"): mass kg, leg
/// radius m, leg width m, leg speed rad/s, legs in stance, response time s. Its hip height is
/// not reported (the built-in robot's is tuned to the level speed).
pub const ROBOT: (f64, f64, f64, f64, u32, f64) = (0.35, 0.04, 0.01, std::f64::consts::TAU, 3, 0.2);

/// Whether `robot` is the paper's robot ([`ROBOT`], each quantity within 0.1%), whatever its
/// hip height and wherever it was read from: only then are the paper's speeds, step period and
/// heavy-robot claim numbers about it. Another robot (a user's 1.2 kg one) is not compared
/// with them (`report` says so and compares only the terrain's ratios).
pub fn is_papers_robot(robot: &Robot) -> bool {
    let (m, r, w, omega, n, dt) = ROBOT;
    let near = |a: f64, b: f64| (a / b - 1.0).abs() <= 1e-3;
    near(robot.mass(), m)
        && near(robot.leg_radius(), r)
        && near(robot.leg_width(), w)
        && near(robot.leg_speed(), omega)
        && robot.stance_legs() == n
        && near(robot.response_time(), dt)
}

/// The ids of [`compare_with_paper`]'s rows that are properties of the terrain alone (its
/// resistances' ratios at 20 and 0 degrees), which stand whatever the robot; every other row
/// is a number about the paper's 0.35 kg robot.
pub const TERRAIN_ROWS: [&str; 2] = ["shear_ratio_20", "normal_ratio_20"];

/// The plate force a shear strength k_s gives on the paper's shear plate,
/// `F = k_s W_p d_p^2`, N (docs/model.md §10).
pub fn plate_force(k_s: f64) -> f64 {
    k_s * SHEAR_PLATE_WIDTH_M * SHEAR_PLATE_DEPTH_M * SHEAR_PLATE_DEPTH_M
}

/// Why a comparison can or cannot test the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Basis {
    /// Nothing of the paper's number went into the model: a test.
    Independent,
    /// The paper's number (or what it follows from) is a model input: agreement by construction.
    Input,
    /// The model was tuned to this number (a calibration or a chosen parameter).
    Tuned,
    /// Follows from the model's structure for any inputs of the usual shape (e.g. t1 rises
    /// whenever k_s falls with slope).
    Consequence,
}

/// What the model being compared was built from, which decides each comparison's [`Basis`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ComparisonContext {
    /// The model's k_s was fitted to the paper's five speeds (the built-in terrain, or a
    /// calibration on them).
    pub fitted_to_paper_speeds: bool,
    /// The robot's hip height was tuned to the paper's level speed (the built-in robot).
    pub tuned_to_level_speed: bool,
    /// The paper's force-test ratio k_s(20)/k_s(0) = 0.40 went into the model's k_s.
    pub shear_ratio_input: bool,
    /// k_n was assumed constant with slope (as the paper's text says) rather than measured.
    pub normal_ratio_input: bool,
}

/// One reported number beside the model's.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PaperComparison {
    /// Stable identifier (`speed_20`, `shear_ratio_20`, ...).
    pub id: String,
    /// What is compared, in words.
    pub quantity: String,
    /// Where in the paper.
    pub source: String,
    /// The paper's value as reported.
    pub paper: String,
    /// The model's value, formatted like the paper's.
    pub model: String,
    /// The paper's number, when it is one.
    pub paper_value: Option<f64>,
    /// The model's number, when it is one.
    pub model_value: Option<f64>,
    /// Whether the model agrees, by `rule`.
    pub agrees: bool,
    /// The rule used to decide.
    pub rule: String,
    /// Whether agreement here tests the model, or holds by construction.
    pub basis: Basis,
    /// Why that basis.
    pub basis_note: String,
}

/// Evaluates `robot` on `terrain` at every number of docs/model.md §12.
///
/// Rules: a speed agrees when within 2 SD of the observed mean; the shear ratio within 0.10 of
/// 0.40 (the paper gives no uncertainty); the normal ratio within 0.15 of 1; the anchoring time
/// must rise with slope at the observed slopes; the step period `T/2` must match the touchdown
/// spacing within 1%; the 1 kg regime must match exactly.
pub fn compare_with_paper(
    robot: &Robot,
    terrain: &Terrain,
    context: ComparisonContext,
) -> Vec<PaperComparison> {
    let mut rows = speed_rows(robot, terrain, context);
    rows.extend(ratio_rows(terrain, context));
    rows.push(t1_row(robot, terrain));
    rows.push(step_period_row(robot));
    rows.push(heavy_robot_row(robot, terrain));
    rows
}

/// A slope of the paper's, in degrees.
fn at(deg: f64) -> Slope {
    Slope::from_degrees(deg).expect("paper slopes are valid")
}

/// The speed at each of the paper's slopes (Fig. 3a), within 2 SD.
fn speed_rows(robot: &Robot, terrain: &Terrain, context: ComparisonContext) -> Vec<PaperComparison> {
    let mut rows = Vec::new();
    for &(deg, mean, sd) in &SPEEDS {
        let p = predict(robot, at(deg), &terrain.at(at(deg)));
        let agrees = p.speed.is_some_and(|v| (v - mean).abs() <= 2.0 * sd) && !p.regime.is_failure();
        let (basis, basis_note) = speed_basis(deg, context);
        rows.push(PaperComparison {
            id: format!("speed_{deg}"),
            quantity: format!("speed at {deg} deg (0.35 kg)"),
            source: "Sec. III-A, Fig. 3a".into(),
            paper: format!("{:.2} ± {:.2} cm/s", mean * 100.0, sd * 100.0),
            model: match p.speed {
                Some(v) if !p.regime.is_failure() => format!("{:.2} cm/s ({})", v * 100.0, p.regime),
                _ => format!("- ({}: {})", p.regime, p.cause.explain()),
            },
            paper_value: Some(mean),
            model_value: p.speed,
            agrees,
            rule: "within 2 SD".into(),
            basis,
            basis_note,
        });
    }
    rows
}

/// k_s(20)/k_s(0) (Fig. 4h) and k_n(20)/k_n(0) (Fig. 4d).
fn ratio_rows(terrain: &Terrain, context: ComparisonContext) -> [PaperComparison; 2] {
    let ratio = |f: &dyn Fn(Slope) -> f64| {
        let level = f(Slope::LEVEL);
        (level > 0.0).then(|| f(at(20.0)) / level)
    };
    let k_s_ratio = ratio(&|s| terrain.at(s).k_s);
    let shear = PaperComparison {
        id: "shear_ratio_20".into(),
        quantity: "k_s(20 deg) / k_s(0)".into(),
        source: "Sec. III-C, Fig. 4h".into(),
        paper: "about 0.40".into(),
        model: k_s_ratio.map_or("-".into(), |r| format!("{r:.2}")),
        paper_value: Some(SHEAR_RATIO_20),
        model_value: k_s_ratio,
        agrees: k_s_ratio.is_some_and(|r| (r - SHEAR_RATIO_20).abs() <= 0.10),
        rule: "within 0.10".into(),
        basis: if context.shear_ratio_input { Basis::Input } else { Basis::Independent },
        basis_note: if context.shear_ratio_input {
            "the force tests' 0.40 is an input of the calibration (held by its SD)".into()
        } else {
            "the model's k_s did not take the paper's ratio as input".into()
        },
    };
    let k_n_ratio = ratio(&|s| terrain.at(s).k_n);
    let normal = PaperComparison {
        id: "normal_ratio_20".into(),
        quantity: "k_n(20 deg) / k_n(0)".into(),
        source: "Sec. III-B, Fig. 4d".into(),
        paper: "nearly unchanged (1)".into(),
        model: k_n_ratio.map_or("-".into(), |r| format!("{r:.2}")),
        paper_value: Some(NORMAL_RATIO_20),
        model_value: k_n_ratio,
        agrees: k_n_ratio.is_some_and(|r| (r - NORMAL_RATIO_20).abs() <= 0.15),
        rule: "within 0.15".into(),
        basis: if context.normal_ratio_input { Basis::Input } else { Basis::Independent },
        basis_note: if context.normal_ratio_input {
            "k_n was assumed constant with slope, as the paper's text says".into()
        } else {
            "the model's k_n did not take the paper's statement as input".into()
        },
    };
    [shear, normal]
}

/// Whether t1 rises with slope (Fig. 5b; the paper prints no values).
fn t1_row(robot: &Robot, terrain: &Terrain) -> PaperComparison {
    let t1: Vec<Option<f64>> =
        SPEEDS.iter().map(|s| predict(robot, at(s.0), &terrain.at(at(s.0))).anchoring_time).collect();
    let rising = t1.windows(2).all(|w| matches!((w[0], w[1]), (Some(a), Some(b)) if b > a));
    PaperComparison {
        id: "t1_rises".into(),
        quantity: "anchoring time t1 rises with slope (0 to 24 deg)".into(),
        source: "Sec. III-A, Fig. 5b".into(),
        paper: "monotone increase".into(),
        model: t1
            .iter()
            .map(|t| t.map_or("-".into(), |t| format!("{:.0}", t * 1000.0)))
            .collect::<Vec<_>>()
            .join(", ")
            + " ms",
        paper_value: None,
        model_value: None,
        agrees: rising,
        rule: "strictly increasing".into(),
        basis: Basis::Consequence,
        basis_note: "any k_s that falls with slope makes d_s and so t1 rise (docs/model.md §4); the paper prints no t1 values to test".into(),
    }
}

/// The time between tripod touchdowns, T/2 (Sec. III-A).
fn step_period_row(robot: &Robot) -> PaperComparison {
    let half = robot.stance_duration();
    PaperComparison {
        id: "step_period".into(),
        quantity: "time between tripod touchdowns, T/2".into(),
        source: "Sec. III-A".into(),
        paper: "0.5 s".into(),
        model: format!("{half:.3} s"),
        paper_value: Some(TOUCHDOWNS_S[1]),
        model_value: Some(half),
        agrees: (half / TOUCHDOWNS_S[1] - 1.0).abs() <= 0.01,
        rule: "within 1%".into(),
        basis: Basis::Input,
        basis_note: "T/2 = π/ω follows from the paper's leg speed".into(),
    }
}

/// The regime of the heavy robot at 24 deg (Fig. 6d).
fn heavy_robot_row(robot: &Robot, terrain: &Terrain) -> PaperComparison {
    let (mass, deg, claim) = HEAVY_ROBOT_CLAIM;
    let heavy = robot.with_mass(mass).ok().map(|r| predict(&r, at(deg), &terrain.at(at(deg))));
    PaperComparison {
        id: "heavy_robot_24".into(),
        quantity: format!("regime of a {mass} kg robot at {deg} deg"),
        source: "Sec. IV, Fig. 6d".into(),
        paper: claim.to_string(),
        model: heavy.map_or("-".into(), |p| match p.step {
            Some(s) => format!("{} (step {:.1} mm)", p.regime, s * 1000.0),
            None => format!("{} ({})", p.regime, p.cause.explain()),
        }),
        paper_value: None,
        model_value: heavy.and_then(|p| p.step),
        agrees: heavy.is_some_and(|p| p.regime == claim),
        rule: "same regime".into(),
        basis: Basis::Independent,
        basis_note: "no input was chosen to match it".into(),
    }
}

/// The basis of the comparison of the speed at `deg`, and why.
fn speed_basis(deg: f64, context: ComparisonContext) -> (Basis, String) {
    if deg == 0.0 && context.tuned_to_level_speed {
        (Basis::Tuned, "the hip height h was chosen to put the level-sand ceiling at this speed".into())
    } else if context.fitted_to_paper_speeds {
        (Basis::Tuned, "the model's k_s was fitted to the paper's five speeds".into())
    } else {
        (Basis::Independent, "no input was fitted to the paper's speeds".into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::tests::paper_robot;

    #[test]
    fn plate_force_by_hand() {
        // 1e6 N/m^3 * 0.03 m * (0.02 m)^2 = 12 N.
        assert!((plate_force(1e6) - 12.0).abs() < 1e-9);
    }

    #[test]
    fn comparison_on_a_terrain_that_matches_the_ratio() {
        // k_s falls to 40% at 20 deg; k_n constant: both ratio rows agree, T/2 = 0.5 s agrees.
        let t = Terrain::new(crate::TerrainSpec {
            name: None,
            repose_deg: Some(25.0),
            points: vec![
                crate::TerrainPoint { slope_deg: 0.0, k_n: 7e5, k_s: 2e6, k_n_sd: None, k_s_sd: None },
                crate::TerrainPoint { slope_deg: 20.0, k_n: 7e5, k_s: 8e5, k_n_sd: None, k_s_sd: None },
            ],
        })
        .unwrap();
        let rows = compare_with_paper(&paper_robot(), &t, ComparisonContext::default());
        let row = |id: &str| rows.iter().find(|r| r.id == id).unwrap();
        assert!((row("shear_ratio_20").model_value.unwrap() - 0.4).abs() < 1e-12);
        assert!(row("shear_ratio_20").agrees && row("normal_ratio_20").agrees && row("step_period").agrees);
        // 5 speeds + 5 other rows; with nothing fitted, only T/2 (an input) and the t1 trend
        // (a consequence) do not test the model.
        assert_eq!(rows.len(), 10);
        let independent = rows.iter().filter(|r| r.basis == Basis::Independent).count();
        assert_eq!(independent, 8);
        let tuned = ComparisonContext {
            fitted_to_paper_speeds: true,
            tuned_to_level_speed: true,
            ..Default::default()
        };
        let rows = compare_with_paper(&paper_robot(), &t, tuned);
        assert!(rows.iter().filter(|r| r.id.starts_with("speed_")).all(|r| r.basis == Basis::Tuned));
        // A 1e6 k_s at 20 deg gave 4.35 cm/s in the model tests; here k_s(20) = 8e5 gives less,
        // and the observed 4.98 ± 0.32 agrees only if within 0.64 cm/s: checked, not assumed.
        let v20 = row("speed_20").model_value.unwrap();
        assert_eq!(row("speed_20").agrees, (v20 - 0.0498).abs() <= 0.0064);
    }
}
