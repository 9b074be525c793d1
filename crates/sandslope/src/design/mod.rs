//! Robot design exploration: which robot climbs the mission's slopes safely and fast.
//!
//! The paper ends on the promise that the model can "inform the selection of robot weight, leg
//! size and gait parameters". A [`DesignSpace`] is a template robot with some of its keys
//! (docs/model.md §2) varied over ranges; [`explore`] evaluates every combination on an
//! uncertain terrain (docs/model.md §9) and returns, per design:
//!
//! - the *safe-slope limit*, the steepest slope with `p_fail < max_risk`: the search of
//!   `sandslope risk --solve slope` ([`crate::risk::safe_slope_limit`]), reporting the fast
//!   p_fail it decided with ([`crate::risk::p_fail`]) rather than one more reference quadrature;
//! - at the target slope: the speed, regime and `k_s_margin` on the median terrain
//!   (docs/model.md §5, §6, §13) and `p_fail`;
//! - whether it is on the *Pareto front* over (safe-slope limit, speed at the target slope),
//!   both maximised: no other design is at least as good in both and better in one.
//!
//! Designs the model cannot hold (a hip height above 2R, for instance) are kept, with the
//! reason, so a user sees which corner of the space is impossible rather than a shorter list.

use std::fmt;

use rayon::prelude::*;
use serde::Serialize;

use crate::axis::AxisScale;
use crate::critical::{critical_shear_strength, StepTarget};
use crate::error::ParamError;
use crate::model::predict;
use crate::regime::Regime;
use crate::risk::limits::{safe_slope_search, ReportedPFail};
use crate::risk::{p_fail, SafeLimit, UncertainTerrain};
use crate::robot::{Robot, RobotSpec};
use crate::robot_key::RobotKey;
use crate::slope::Slope;

/// The robot key named `name` (any key of docs/model.md §2 can be varied), or an error
/// listing the valid keys.
pub fn design_key(name: &str) -> Result<RobotKey, DesignError> {
    RobotKey::from_name(name).ok_or_else(|| DesignError::UnknownKey {
        key: name.to_string(),
        valid: RobotKey::ALL.iter().map(|k| k.name()).collect::<Vec<_>>().join(", "),
    })
}

/// Why a design study cannot be set up.
#[derive(Debug, Clone, PartialEq)]
pub enum DesignError {
    /// A key that is not a robot key.
    UnknownKey {
        /// The key given.
        key: String,
        /// The valid keys, comma-separated.
        valid: String,
    },
    /// A key varied twice.
    DuplicateKey(RobotKey),
    /// A range that is empty, reversed, not finite, or not positive on a log scale.
    BadRange(ParamError),
    /// More designs than [`MAX_DESIGNS`].
    TooMany {
        /// Designs the ranges give.
        designs: u128,
    },
    /// `max_risk` outside (0, 1).
    MaxRisk(f64),
}

impl fmt::Display for DesignError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DesignError::UnknownKey { key, valid } => {
                write!(f, "`{key}` is not a robot key that can be varied; valid keys: {valid}")
            }
            DesignError::DuplicateKey(k) => write!(f, "`{k}` is varied twice"),
            DesignError::BadRange(e) => write!(f, "{e}"),
            DesignError::TooMany { designs } => {
                write!(f, "the ranges give {designs} designs; at most {MAX_DESIGNS} are allowed")
            }
            DesignError::MaxRisk(p) => write!(f, "max_risk = {p} must be strictly between 0 and 1"),
        }
    }
}

impl std::error::Error for DesignError {}

/// Most designs one study evaluates (about 10 minutes on two cores).
pub const MAX_DESIGNS: usize = 1 << 21;

/// The values one key takes: `n` points from `min` to `max`, evenly spaced or log-spaced.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DesignRange {
    key: RobotKey,
    values: Vec<f64>,
}

impl DesignRange {
    /// `n >= 1` values of `key` from `min` to `max` (`n = 1`: `min` only, and `max` must equal
    /// it). Finite, `min <= max`, `min > 0` on a log scale; `stance_legs` values must be whole
    /// numbers of at least 1.
    pub fn new(
        key: RobotKey,
        min: f64,
        max: f64,
        n: usize,
        scale: AxisScale,
    ) -> Result<DesignRange, DesignError> {
        let bad = |what: &str, v: f64, expected: String| {
            DesignError::BadRange(ParamError::new(format!("{key} {what}"), v, expected))
        };
        if !min.is_finite() || (scale == AxisScale::Log && min <= 0.0) {
            return Err(bad("min", min, "finite (and greater than 0 on a log scale)".into()));
        }
        if !max.is_finite() || max < min || (n > 1 && max == min) {
            return Err(bad("max", max, format!("finite and greater than min = {min}")));
        }
        if n == 0 || (n == 1 && max != min) {
            return Err(bad("points", n as f64, "at least 2 for a range (MIN:MAX:N), or one value".into()));
        }
        // Decided before the values are made: one range cannot exceed the study's cap.
        if n > MAX_DESIGNS {
            return Err(bad(
                "points",
                n as f64,
                format!("at most {MAX_DESIGNS} (the most designs one study evaluates)"),
            ));
        }
        // Rounded to 12 significant digits, so that 0.0:0.06:13 gives 0.06, not
        // 0.060000000000000005 (which a hip-height check against 2R = 0.06 would reject).
        let snap = |v: f64| format!("{v:.11e}").parse::<f64>().unwrap_or(v);
        let values: Vec<f64> = (0..n)
            .map(|i| {
                if n == 1 {
                    return min;
                }
                let f = i as f64 / (n - 1) as f64;
                snap(match scale {
                    AxisScale::Linear => min + f * (max - min),
                    AxisScale::Log => (min.ln() + f * (max.ln() - min.ln())).exp(),
                })
            })
            .collect();
        if key == RobotKey::StanceLegs {
            if let Some(&v) =
                values.iter().find(|v| v.fract() != 0.0 || **v < 1.0 || **v > f64::from(u32::MAX))
            {
                return Err(bad(
                    "value",
                    v,
                    "a whole number of at least 1 (choose MIN, MAX, N so every step is whole)".into(),
                ));
            }
        }
        Ok(DesignRange { key, values })
    }

    /// The key varied.
    pub fn key(&self) -> RobotKey {
        self.key
    }

    /// Its values.
    pub fn values(&self) -> &[f64] {
        &self.values
    }
}

/// A template robot and the ranges of the keys to vary: every combination is one design.
#[derive(Debug, Clone)]
pub struct DesignSpace {
    template: RobotSpec,
    ranges: Vec<DesignRange>,
    count: usize,
}

impl DesignSpace {
    /// The space of `template` with `ranges` varied (each key once, at most [`MAX_DESIGNS`]
    /// combinations). Designs are numbered with the first range varying slowest.
    pub fn new(template: RobotSpec, ranges: Vec<DesignRange>) -> Result<DesignSpace, DesignError> {
        for (i, r) in ranges.iter().enumerate() {
            if ranges[..i].iter().any(|q| q.key == r.key) {
                return Err(DesignError::DuplicateKey(r.key));
            }
        }
        let count: u128 = ranges.iter().map(|r| r.values.len() as u128).product();
        if count > MAX_DESIGNS as u128 {
            return Err(DesignError::TooMany { designs: count });
        }
        Ok(DesignSpace { template, ranges, count: count as usize })
    }

    /// The template robot.
    pub fn template(&self) -> &RobotSpec {
        &self.template
    }

    /// The ranges, in the order given.
    pub fn ranges(&self) -> &[DesignRange] {
        &self.ranges
    }

    /// Number of designs.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether the space is empty (never: no ranges is the template alone).
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The varied values of design `index`, one per range.
    pub fn params(&self, index: usize) -> Vec<f64> {
        let mut rest = index;
        let mut out = vec![0.0; self.ranges.len()];
        for (slot, r) in out.iter_mut().zip(&self.ranges).rev() {
            let n = r.values.len();
            *slot = r.values[rest % n];
            rest /= n;
        }
        out
    }

    /// The robot file of design `index` (not yet validated).
    pub fn spec(&self, index: usize) -> RobotSpec {
        let mut spec = self.template.clone();
        for (r, v) in self.ranges.iter().zip(self.params(index)) {
            r.key.set(&mut spec, v);
        }
        spec
    }
}

/// What a study asks of every design.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DesignGoal {
    max_risk: f64,
    slope_target: Slope,
}

impl DesignGoal {
    /// `max_risk` strictly between 0 and 1, and the mission's target slope.
    pub fn new(max_risk: f64, slope_target: Slope) -> Result<DesignGoal, DesignError> {
        if !(max_risk.is_finite() && max_risk > 0.0 && max_risk < 1.0) {
            return Err(DesignError::MaxRisk(max_risk));
        }
        Ok(DesignGoal { max_risk, slope_target })
    }

    /// The largest acceptable failure probability.
    pub fn max_risk(&self) -> f64 {
        self.max_risk
    }

    /// The target slope.
    pub fn slope_target(&self) -> Slope {
        self.slope_target
    }
}

/// How one valid design performs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Performance {
    /// The safe-slope limit (null when no slope is safe, or every slope searched is; see
    /// `safe_limit`), degrees.
    pub safe_slope_deg: Option<f64>,
    /// The search's outcome, as `risk --solve slope` reports it.
    pub safe_limit: SafeLimit,
    /// Speed at the target slope on the median terrain, m/s (null: the leg never anchors).
    pub speed_m_s: Option<f64>,
    /// Regime at the target slope on the median terrain.
    pub regime: Regime,
    /// Failure probability at the target slope.
    pub p_fail: f64,
    /// Median k_s over the smallest k_s giving progress at the target slope (null: none does).
    pub k_s_margin: Option<f64>,
}

impl Performance {
    /// The safe-slope limit as a number to rank by: the limit, the end of the search when
    /// every slope is safe, and -1 when none is.
    pub fn safe_slope_rank(&self) -> f64 {
        match self.safe_limit {
            SafeLimit::Limit { value, .. } => value,
            SafeLimit::Repose { repose_deg, .. } => repose_deg,
            SafeLimit::BeyondRange { up_to, .. } => up_to,
            SafeLimit::NoneSafe { .. } => -1.0,
        }
    }
}

/// One design and how it did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Design {
    /// The varied keys' values, in the order of the space's ranges.
    pub params: Vec<f64>,
    /// The evaluation, or why the robot is not a valid robot (docs/model.md §2).
    pub outcome: Result<Performance, String>,
    /// Whether the design is on the Pareto front over (safe-slope limit, speed at the target).
    pub pareto: bool,
}

/// The result of [`explore`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DesignStudy {
    /// The keys varied, in the order of every design's `params`.
    pub keys: Vec<RobotKey>,
    /// Largest acceptable failure probability.
    pub max_risk: f64,
    /// Target slope, degrees.
    pub slope_target_deg: f64,
    /// Every design, in the space's order.
    pub designs: Vec<Design>,
    /// The template robot's own evaluation (`pareto`: whether it would be on the front).
    pub template: Design,
}

impl DesignStudy {
    /// The designs on the Pareto front, best safe-slope limit first.
    pub fn front(&self) -> Vec<&Design> {
        let mut f: Vec<&Design> = self.designs.iter().filter(|d| d.pareto).collect();
        let rank = |d: &Design| d.outcome.as_ref().map_or(f64::NEG_INFINITY, |p| p.safe_slope_rank());
        f.sort_by(|a, b| rank(b).total_cmp(&rank(a)));
        f
    }

    /// Number of designs that are not valid robots.
    pub fn invalid_count(&self) -> usize {
        self.designs.iter().filter(|d| d.outcome.is_err()).count()
    }
}

/// Evaluates one robot against `goal` on `terrain`.
pub fn evaluate(robot: &Robot, terrain: &UncertainTerrain, goal: &DesignGoal) -> Performance {
    let target = goal.slope_target;
    let (ground, u) = terrain.at(target);
    let prediction = predict(robot, target, &ground);
    let k_s_margin = critical_shear_strength(
        robot,
        target,
        ground.k_n,
        ground.beyond_repose(target),
        StepTarget::Progress,
    )
    .ok()
    .map(|k| ground.k_s / k);
    let safe_limit = safe_slope_search(robot, terrain, goal.max_risk, ReportedPFail::Fast);
    Performance {
        safe_slope_deg: safe_limit.value(),
        safe_limit,
        speed_m_s: prediction.speed,
        regime: prediction.regime,
        p_fail: p_fail(robot, target, &ground, u),
        k_s_margin,
    }
}

fn evaluate_spec(
    spec: RobotSpec,
    terrain: &UncertainTerrain,
    goal: &DesignGoal,
) -> Result<Performance, String> {
    Robot::new(spec).map(|r| evaluate(&r, terrain, goal)).map_err(|e| e.to_string())
}

/// Evaluates every design of `space` on `terrain` (in parallel), marks the Pareto front, and
/// evaluates the template. `design_done` is called once per finished design, from any thread.
pub fn explore(
    space: &DesignSpace,
    terrain: &UncertainTerrain,
    goal: &DesignGoal,
    design_done: &(dyn Fn() + Sync),
) -> DesignStudy {
    let mut designs: Vec<Design> = (0..space.len())
        .into_par_iter()
        .map(|i| {
            let outcome = evaluate_spec(space.spec(i), terrain, goal);
            design_done();
            Design { params: space.params(i), outcome, pareto: false }
        })
        .collect();
    let points: Vec<Option<(f64, f64)>> = designs.iter().map(front_point).collect();
    for (d, on) in designs.iter_mut().zip(pareto_front(&points)) {
        d.pareto = on;
    }
    // The template is on the front if nothing in the space dominates it.
    let outcome = evaluate_spec(space.template.clone(), terrain, goal);
    let mut template = Design {
        params: space.ranges.iter().map(|r| r.key.get(&space.template).unwrap_or(f64::NAN)).collect(),
        outcome,
        pareto: false,
    };
    if let Some((s, v)) = front_point(&template) {
        template.pareto = !points.iter().flatten().any(|&(s2, v2)| s2 >= s && v2 >= v && (s2 > s || v2 > v));
    }
    DesignStudy {
        keys: space.ranges.iter().map(|r| r.key).collect(),
        max_risk: goal.max_risk,
        slope_target_deg: goal.slope_target.degrees(),
        designs,
        template,
    }
}

/// The design's point in the (safe-slope limit, speed at target) plane; `None` when invalid or
/// when the leg never anchors at the target (no speed).
fn front_point(d: &Design) -> Option<(f64, f64)> {
    let p = d.outcome.as_ref().ok()?;
    Some((p.safe_slope_rank(), p.speed_m_s?))
}

/// Which points are not dominated (another at least as large in both coordinates and larger
/// in one); `None` points never are on the front. O(n log n).
pub fn pareto_front(points: &[Option<(f64, f64)>]) -> Vec<bool> {
    let mut order: Vec<usize> = (0..points.len()).filter(|&i| points[i].is_some()).collect();
    let xy = |i: usize| points[i].expect("filtered");
    // Largest x first; among equal x, largest y first.
    order.sort_by(|&a, &b| {
        let ((xa, ya), (xb, yb)) = (xy(a), xy(b));
        xb.total_cmp(&xa).then(yb.total_cmp(&ya))
    });
    let mut on = vec![false; points.len()];
    let mut best_y = f64::NEG_INFINITY; // best y among strictly larger x
    let mut k = 0;
    while k < order.len() {
        let x = xy(order[k]).0;
        let group_end = order[k..].iter().position(|&i| xy(i).0 != x).map_or(order.len(), |p| k + p);
        let group_best = xy(order[k]).1;
        for &i in &order[k..group_end] {
            // Not dominated: y is the group's best and beats every larger x.
            on[i] = xy(i).1 == group_best && group_best > best_y;
        }
        best_y = best_y.max(group_best);
        k = group_end;
    }
    on
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::terrain::Terrain;

    #[test]
    fn pareto_front_by_hand() {
        // (1,5) (2,4) (3,1) are the front; (1,3) and (2,2) are dominated; (3,1) twice: both on;
        // (0,5) is dominated by (1,5) (equal y, larger x); None never on.
        let pts = [
            Some((1.0, 5.0)),
            Some((2.0, 4.0)),
            Some((3.0, 1.0)),
            Some((1.0, 3.0)),
            Some((2.0, 2.0)),
            Some((3.0, 1.0)),
            Some((0.0, 5.0)),
            None,
        ];
        assert_eq!(pareto_front(&pts), vec![true, true, true, false, false, true, false, false]);
    }

    /// A brute-force O(n^2) check on a random cloud with ties.
    #[test]
    fn pareto_front_matches_brute_force() {
        use rand::{rngs::StdRng, RngExt, SeedableRng};
        let mut rng = StdRng::seed_from_u64(7);
        let pts: Vec<Option<(f64, f64)>> = (0..400)
            .map(|_| {
                (rng.random::<f64>() > 0.05)
                    .then(|| ((rng.random::<f64>() * 20.0).round(), (rng.random::<f64>() * 20.0).round()))
            })
            .collect();
        let fast = pareto_front(&pts);
        for (i, p) in pts.iter().enumerate() {
            let brute = p.is_some_and(|(x, y)| {
                !pts.iter().flatten().any(|&(x2, y2)| x2 >= x && y2 >= y && (x2 > x || y2 > y))
            });
            assert_eq!(fast[i], brute, "{i}: {p:?}");
        }
    }

    #[test]
    fn keys_ranges_and_space() {
        let e = design_key("legs").unwrap_err().to_string();
        assert!(e.contains("legs") && e.contains("mass_kg") && e.contains("min_step_m"), "{e}");
        let r = DesignRange::new(RobotKey::MassKg, 0.1, 10.0, 3, AxisScale::Log).unwrap();
        assert_eq!(r.values(), [0.1, 1.0, 10.0]);
        let h = DesignRange::new(RobotKey::HipHeightM, 0.0, 0.06, 13, AxisScale::Linear).unwrap();
        assert_eq!((h.values()[12], h.values()[7]), (0.06, 0.035));
        assert!(DesignRange::new(RobotKey::MassKg, 1.0, 0.5, 3, AxisScale::Linear).is_err());
        assert!(DesignRange::new(RobotKey::MassKg, 0.0, 1.0, 3, AxisScale::Log).is_err());
        assert!(DesignRange::new(RobotKey::StanceLegs, 2.0, 4.0, 4, AxisScale::Linear).is_err());
        let legs = DesignRange::new(RobotKey::StanceLegs, 2.0, 4.0, 3, AxisScale::Linear).unwrap();
        let mass = DesignRange::new(RobotKey::MassKg, 0.3, 0.5, 2, AxisScale::Linear).unwrap();
        let space = DesignSpace::new(RobotSpec::paper_hexapod(), vec![legs.clone(), mass.clone()]).unwrap();
        assert_eq!(space.len(), 6);
        // First range slowest: design 3 is (legs 3, mass 0.5).
        assert_eq!(space.params(3), vec![3.0, 0.5]);
        let spec = space.spec(3);
        assert_eq!((spec.stance_legs, spec.mass_kg), (3, 0.5));
        assert!(matches!(
            DesignSpace::new(RobotSpec::paper_hexapod(), vec![mass.clone(), mass]),
            Err(DesignError::DuplicateKey(_))
        ));
    }

    /// A small study on a certain terrain: invalid designs (hip above 2R) are reported with
    /// the reason; the heaviest robot is never on the front when a lighter one with the same
    /// legs is both faster and safer; speed and regime are `predict`'s at the median terrain.
    #[test]
    fn small_study() {
        let t = UncertainTerrain::new(
            Terrain::new(crate::terrain::TerrainSpec {
                name: None,
                repose_deg: Some(25.0),
                points: vec![
                    crate::TerrainPoint { slope_deg: 0.0, k_n: 7e5, k_s: 1.7e6, k_n_sd: None, k_s_sd: None },
                    crate::TerrainPoint {
                        slope_deg: 24.0,
                        k_n: 7e5,
                        k_s: 1.36e6,
                        k_n_sd: None,
                        k_s_sd: None,
                    },
                ],
            })
            .unwrap(),
            Some(0.1),
            Some(0.2),
        )
        .unwrap();
        let space = DesignSpace::new(
            RobotSpec::paper_hexapod(),
            vec![
                DesignRange::new(RobotKey::HipHeightM, 0.02, 0.09, 3, AxisScale::Linear).unwrap(),
                DesignRange::new(RobotKey::MassKg, 0.3, 1.5, 3, AxisScale::Linear).unwrap(),
            ],
        )
        .unwrap();
        let goal = DesignGoal::new(0.05, Slope::from_degrees(15.0).unwrap()).unwrap();
        let count = std::sync::atomic::AtomicUsize::new(0);
        let study = explore(&space, &t, &goal, &|| {
            count.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        });
        assert_eq!(count.into_inner(), 9);
        assert_eq!(study.invalid_count(), 3);
        let bad = &study.designs[6];
        assert_eq!(bad.params, vec![0.09, 0.3]);
        assert!(bad.outcome.as_ref().unwrap_err().contains("hip_height_m = 0.09"), "{bad:?}");
        assert!(!bad.pareto);
        for d in &study.designs[..6] {
            let p = d.outcome.as_ref().unwrap();
            let r = Robot::new(space.spec(study.designs.iter().position(|x| x == d).unwrap())).unwrap();
            let (g, _) = t.at(goal.slope_target());
            let want = predict(&r, goal.slope_target(), &g);
            assert_eq!((p.speed_m_s, p.regime), (want.speed, want.regime));
        }
        assert!(study.designs.iter().any(|d| d.pareto));
        assert!(study.template.outcome.is_ok());
    }
}
