//! The calibration in numbers: the unknowns with their bounds and search coordinates, a
//! candidate point resolved into a robot and a k_s(theta), the pulls and `-2 ln L` there.

use super::evidence::{check_anchoring, check_speeds};
use super::inversion::shear_strength_for_speed;
use super::model::{check_free_for_simulator, SimulatedModel, SpeedModel, Walked, MIN_SIMULATED_K_S};
use super::{
    CalibrationError, JointSetup, ObservationKind, Parameter, Pull, Quantity, RobotKey, ShearLaw, ShearShape,
};
use crate::model::{continued_anchoring_time, continued_speed, level_step_length, normal_equilibrium_depth};
use crate::robot::Robot;
use crate::slope::Slope;
use crate::terrain::interpolate;

/// One quantity the fit varies, with its search bounds and starting value.
///
/// The optimiser works on an unbounded coordinate `u`: a logistic map sends it into the bounds
/// of the *search coordinate*, which is `ln` of the value for a scale quantity (`log`) and the
/// value itself otherwise.
#[derive(Debug, Clone)]
pub(crate) struct Unknown {
    pub quantity: Quantity,
    pub lo: f64,
    pub hi: f64,
    pub log: bool,
    pub start: f64,
}

impl Unknown {
    /// The search coordinate of a value.
    pub fn search_coordinate(&self, value: f64) -> f64 {
        if self.log {
            value.ln()
        } else {
            value
        }
    }

    /// The value at a search coordinate.
    pub fn value_at_search(&self, q: f64) -> f64 {
        if self.log {
            q.exp()
        } else {
            q
        }
    }

    /// The value at an unbounded coordinate.
    pub fn value_at_unbounded(&self, u: f64) -> f64 {
        let t = 1.0 / (1.0 + (-u).exp());
        let (a, b) = (self.search_coordinate(self.lo), self.search_coordinate(self.hi));
        self.value_at_search(a + t * (b - a)).clamp(self.lo, self.hi)
    }

    /// The unbounded coordinate of a value (clamped just inside the bounds).
    pub fn unbounded_coordinate(&self, value: f64) -> f64 {
        let (a, b) = (self.search_coordinate(self.lo), self.search_coordinate(self.hi));
        let t = ((self.search_coordinate(value) - a) / (b - a)).clamp(1e-9, 1.0 - 1e-9);
        (t / (1.0 - t)).ln()
    }

    /// The value sits within 0.1% of the search range of a bound.
    pub fn at_bound(&self, value: f64) -> bool {
        let tol = 1e-3 * (self.search_coordinate(self.hi) - self.search_coordinate(self.lo));
        (self.search_coordinate(value) - self.search_coordinate(self.lo)).abs() < tol
            || (self.search_coordinate(self.hi) - self.search_coordinate(value)).abs() < tol
    }
}

/// One force test: slope, measured plate k_s and its SD (if any).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ForceTest {
    pub slope_deg: f64,
    pub k_s: f64,
    pub sd: Option<f64>,
}

/// The calibration problem: the setup, its unknowns, and the shape of k_s(theta).
pub(crate) struct Problem<'a> {
    pub setup: &'a JointSetup,
    pub unknowns: Vec<Unknown>,
    /// The force tests (empty for a law).
    pub force_tests: Vec<ForceTest>,
    /// For each force test, the index of its unknown (`None`: fixed at the measurement).
    pub force_test_unknown: Vec<Option<usize>>,
    /// The smooth law (`None`: force tests).
    pub law: Option<ShearLaw>,
    /// Observations: speeds, anchoring times and force tests with SDs.
    pub n_obs: usize,
    /// The simulator when it is the model (`None`: the closed form).
    pub simulator: Option<SimulatedModel<'a>>,
    /// The distinct slopes of speeds and anchoring times, degrees (one walk each).
    pub walk_slopes: Vec<f64>,
    /// Whether the optimiser may take its Jacobian by the chain rule through each walk's leg
    /// k_s ([`Problem::walks_depend_only_on_k_s`]); `true` but in the tests that compare.
    pub chain_rule: bool,
    /// The step in `ln k_s` of the chain rule's two walks ([`WALK_LN_K_S_STEP`];
    /// another only in the test that compares the chain rule with the walked columns).
    pub walk_ln_k_s_step: f64,
}

/// The step in `ln k_s` of the two walks that give a walk's derivative in its leg k_s (the
/// chain rule of the optimiser's `LeastSquares::chain_rule_jacobian`): 1%, the scale on which a fixed-step
/// walk's speed is smooth in k_s. Below it the speed has kinks (a step of the walk that changes
/// how it is taken, such as the belly's strike in substeps, docs/model.md §17): on the paper's
/// evidence the 24 degree walk's speed at the fitted leg k_s turns from 0.10 to 0.03 m/s per
/// unit `ln k_s` within 0.6%, while over +-4% it follows a cubic within 0.1 mm/s, whose slope
/// there (0.063) the 1% difference gives to 2% (0.062) and a 0.2% one to 26% (0.047). The fit's
/// minimum sits on that kink, and with the one-sided slope of a 0.2% step Levenberg-Marquardt
/// crept along it in steps of a few 0.1%, up to 97 evaluations a minimisation where 10 to 20
/// suffice, and stopped short (docs/calibration.md, "Where the walks go").
pub(crate) const WALK_LN_K_S_STEP: f64 = 1e-2;

/// A candidate point (one value per unknown) resolved into what the model needs.
pub(crate) struct Candidate {
    /// The robot; `None` when the values make an invalid one (say h > 2R with both free).
    pub robot: Option<Robot>,
    pub error_floor: f64,
    /// The plate k_s at each force-test slope, `(slope_deg, k_s)`.
    pub plate: Vec<(f64, f64)>,
    pub plate_scale: f64,
    /// The law's two parameters.
    pub law: [f64; 2],
}

impl Problem<'_> {
    pub fn candidate(&self, x: &[f64]) -> Candidate {
        let mut spec = self.setup.robot.spec().clone();
        let mut c = Candidate {
            robot: None,
            error_floor: self.setup.error_floor,
            plate: self.force_tests.iter().map(|k| (k.slope_deg, k.k_s)).collect(),
            plate_scale: 1.0,
            law: [0.0, 1.0],
        };
        for (unknown, &v) in self.unknowns.iter().zip(x) {
            match unknown.quantity {
                Quantity::Free(Parameter::Robot(k)) => k.set(&mut spec, v),
                Quantity::Free(Parameter::PlateScale) => c.plate_scale = v,
                Quantity::Free(Parameter::ErrorFloor) => c.error_floor = v,
                Quantity::PlateShearStrength { point, .. } => c.plate[point].1 = v,
                Quantity::LevelShearStrength => c.law[0] = v,
                Quantity::ShearRatio20 | Quantity::FrictionAngle => c.law[1] = v,
            }
        }
        // The fitted keys on the setup's robot, keeping its level-step rule (docs/model.md §3).
        c.robot = Robot::new(spec).ok().map(|r| r.with_level_step(self.setup.robot.level_step_rule()));
        c
    }

    /// The leg's k_s at `slope`.
    pub fn k_s(&self, c: &Candidate, slope: Slope) -> f64 {
        match self.law {
            Some(law) => law.k_s(c.law, slope),
            None => c.plate_scale * interpolate(&c.plate, slope.degrees()),
        }
    }

    pub fn k_n(&self, slope: Slope) -> f64 {
        self.setup.normal.at(slope).k_n
    }

    pub fn level_step(&self, robot: &Robot, slope: Slope) -> f64 {
        level_step_length(robot, slope, normal_equilibrium_depth(robot, slope, self.k_n(slope)))
    }

    /// The relative step of the optimiser's finite-difference Jacobian in the unbounded
    /// coordinates: 1e-6 for the smooth closed form; 1e-3 for the simulator, whose walks are
    /// integrated with a fixed step and so are smooth in the parameters only at scales well
    /// above round-off.
    pub fn jacobian_step(&self) -> f64 {
        if self.simulator.is_some() {
            1e-3
        } else {
            1e-6
        }
    }

    /// The ground `(slope_deg, k_n, k_s)` of the walk at every observed slope (in the order of
    /// `walk_slopes`) for candidate `c`.
    pub fn grounds(&self, c: &Candidate) -> Vec<(f64, f64, f64)> {
        self.walk_slopes
            .iter()
            .map(|&deg| {
                let slope = Slope::from_degrees(deg).unwrap_or(Slope::LEVEL);
                let k_n = self.k_n(slope);
                // A law or an extrapolated table can reach k_s <= 0 (no strength); the simulator
                // needs a positive value, and 1 N/m^3 is no strength at all for a 0.35 kg robot.
                (deg, k_n, self.k_s(c, slope).max(MIN_SIMULATED_K_S))
            })
            .collect()
    }

    /// The simulator's walk at every observed slope for candidate `c` (`None` when the model is
    /// the closed form; `Some(Err)` when the simulator refuses a walk).
    fn walked(&self, robot: &Robot, c: &Candidate) -> Option<Result<Vec<Walked>, String>> {
        let sim = self.simulator.as_ref()?;
        Some(sim.walks(robot, &self.grounds(c)))
    }

    /// Whether every walk depends on the free quantities only through its leg k_s (the
    /// simulator is the model and no robot key is free): then a walk's derivative in them is its
    /// derivative in its own k_s times the k_s's, the chain rule the optimiser's Jacobian uses
    /// (docs/calibration.md).
    pub fn walks_depend_only_on_k_s(&self) -> bool {
        self.chain_rule
            && self.simulator.is_some()
            && !self.unknowns.iter().any(|u| matches!(u.quantity, Quantity::Free(Parameter::Robot(_))))
    }

    /// The walk at `deg` among `walks` (in the order of `walk_slopes`).
    fn walk_at(&self, walks: &[Walked], deg: f64) -> Option<Walked> {
        self.walk_slopes.iter().position(|&d| d == deg).and_then(|i| walks.get(i).copied())
    }

    /// Pulls of every observation (speeds, anchoring times, force tests) at `x`, and the
    /// floor's term `sum_speeds ln(1 + f^2 / sd_i^2)` of `-2 ln L`.
    pub fn pulls(&self, x: &[f64]) -> Option<(Vec<Pull>, f64)> {
        self.pulls_with(x, None)
    }

    /// [`Problem::pulls`] with the simulator's walks at `x` given (`walks`, in the order of
    /// `walk_slopes`) rather than walked: the optimiser's chain rule hands in walks continued
    /// linearly from a walked point.
    pub fn pulls_with(&self, x: &[f64], walks: Option<&[Walked]>) -> Option<(Vec<Pull>, f64)> {
        let c = self.candidate(x);
        let robot = c.robot.as_ref()?;
        let walks = match walks {
            Some(w) if self.simulator.is_some() => Some(w.to_vec()),
            _ => match self.walked(robot, &c) {
                None => None,
                Some(Ok(w)) => Some(w),
                Some(Err(_)) => return None,
            },
        };
        let mut out = Vec::with_capacity(self.n_obs);
        let pull = |kind, slope: Slope, observed: f64, sd: f64, sd_total: f64, model: f64| Pull {
            kind,
            slope_deg: slope.degrees(),
            observed,
            sd,
            sd_total,
            model,
            pull: (observed - model) / sd_total,
        };
        for o in &self.setup.speeds {
            let model = match &walks {
                Some(w) => self.walk_at(w, o.slope.degrees())?.speed,
                None => {
                    continued_speed(robot, o.slope, self.level_step(robot, o.slope), self.k_s(&c, o.slope))
                }
            };
            out.push(pull(
                ObservationKind::Speed,
                o.slope,
                o.speed,
                o.speed_sd,
                o.speed_sd.hypot(c.error_floor),
                model,
            ));
        }
        for o in &self.setup.anchoring {
            let model = match &walks {
                Some(w) => self.walk_at(w, o.slope.degrees())?.t1,
                None => continued_anchoring_time(robot, o.slope, self.k_s(&c, o.slope)),
            };
            out.push(pull(ObservationKind::AnchoringTime, o.slope, o.t1, o.t1_sd, o.t1_sd, model));
        }
        for (k, fitted) in self.force_tests.iter().zip(&c.plate) {
            if let Some(sd) = k.sd.filter(|&s| s > 0.0) {
                out.push(Pull {
                    kind: ObservationKind::PlateShearStrength,
                    slope_deg: k.slope_deg,
                    observed: k.k_s,
                    sd,
                    sd_total: sd,
                    model: fitted.1,
                    pull: (k.k_s - fitted.1) / sd,
                });
            }
        }
        let log_det: f64 =
            self.setup.speeds.iter().map(|o| (1.0 + (c.error_floor / o.speed_sd).powi(2)).ln()).sum();
        Some((out, log_det))
    }

    /// Residual vector whose sum of squares is `-2 ln L` (+ const).
    pub fn residuals(&self, x: &[f64]) -> Vec<f64> {
        self.residuals_with(x, None)
    }

    /// [`Problem::residuals`] with the walks given ([`Problem::pulls_with`]).
    pub fn residuals_with(&self, x: &[f64], walks: Option<&[Walked]>) -> Vec<f64> {
        match self.pulls_with(x, walks) {
            Some((pulls, log_det)) => {
                let mut r: Vec<f64> = pulls.iter().map(|p| p.pull).collect();
                r.push(log_det.max(0.0).sqrt());
                r
            }
            // An invalid robot (say h > 2R with both free): a large, flat penalty.
            None => vec![1e3; self.n_obs + 1],
        }
    }

    /// `-2 ln L` (+ const) at `x`.
    pub fn objective(&self, x: &[f64]) -> f64 {
        self.residuals(x).iter().map(|r| r * r).sum()
    }

    /// The value of the force-test unknown `t` that makes k_s(20)/k_s(0) exactly `e^target`
    /// with the other values of `x` (clamped to its bounds), or `None` when `t` is not a force
    /// test's or no positive value does. The table is interpolated linearly, so both k_s(20) and
    /// k_s(0) are linear in the one value `v` and `k_s(20) = e^target k_s(0)` is solved for it
    /// directly (no walks: the plate scale cancels in the ratio).
    pub fn tied_value(&self, x: &[f64], t: usize, target: f64) -> Option<f64> {
        let u = &self.unknowns[t];
        let Quantity::PlateShearStrength { point, .. } = u.quantity else {
            return None;
        };
        let mut c = self.candidate(x);
        let twenty = Slope::from_degrees(20.0).ok()?;
        let mut ends = |v: f64| {
            c.plate[point].1 = v;
            (self.k_s(&c, twenty), self.k_s(&c, Slope::LEVEL))
        };
        let (top0, level0) = ends(0.0);
        let (top1, level1) = ends(1.0);
        let r = target.exp();
        let v = (r * level0 - top0) / ((top1 - top0) - r * (level1 - level0));
        (v.is_finite() && v > 0.0).then(|| v.clamp(u.lo, u.hi))
    }

    /// k_s(20)/k_s(0) at `x`.
    pub fn ratio(&self, x: &[f64]) -> f64 {
        let c = self.candidate(x);
        let level = self.k_s(&c, Slope::LEVEL);
        if level > 0.0 {
            self.k_s(&c, Slope::from_degrees(20.0).unwrap_or(Slope::LEVEL)) / level
        } else {
            f64::NAN
        }
    }
}

/// The k_s each observed speed alone implies (where the model can reach it).
fn inverted_k_s(setup: &JointSetup) -> Vec<(f64, f64)> {
    setup
        .speeds
        .iter()
        .filter_map(|o| {
            let k_n = setup.normal.at(o.slope).k_n;
            shear_strength_for_speed(&setup.robot, o.slope, k_n, o.speed).ok().map(|k| (o.slope.degrees(), k))
        })
        .collect()
}

/// The unknown of one freed parameter, with its bounds checked.
fn free_unknown(
    setup: &JointSetup,
    parameter: Parameter,
    bounds: Option<(f64, f64)>,
) -> Result<Unknown, CalibrationError> {
    let (default, log, start) = match parameter {
        Parameter::Robot(k) if !RobotKey::FITTABLE.contains(&k) => {
            return Err(CalibrationError::NotFittable {
                name: k.name().to_string(),
                fittable: Parameter::names(),
            });
        }
        Parameter::Robot(k) => {
            let k_n_level = setup.normal.at(Slope::LEVEL).k_n;
            (k.default_bounds(setup.robot.spec()), k.is_scale(), k.value_for(&setup.robot, k_n_level))
        }
        Parameter::PlateScale => {
            if !matches!(setup.shear, ShearShape::ForceTests(_)) {
                return Err(CalibrationError::PlateScaleWithoutForces);
            }
            ((1e-3, 1e4), true, 1.0)
        }
        Parameter::ErrorFloor => {
            // Start inside: at the median observed SD (a logistic map has no slope at its bound).
            let mut sds: Vec<f64> = setup.speeds.iter().map(|o| o.speed_sd).collect();
            sds.sort_by(f64::total_cmp);
            let median = sds.get(sds.len() / 2).copied().unwrap_or(0.0);
            ((0.0, 0.1), false, setup.error_floor.max(median))
        }
    };
    let (lo, hi) = bounds.unwrap_or(default);
    let bad = |reason: String| CalibrationError::BadBounds { name: parameter.name().into(), reason };
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(bad(format!("{lo}:{hi} must be finite with min < max")));
    }
    if log && lo <= 0.0 {
        return Err(bad(format!("min = {lo} must be greater than 0 for a scale parameter")));
    }
    Ok(Unknown { quantity: Quantity::Free(parameter), lo, hi, log, start: start.clamp(lo, hi) })
}

/// The problem for `setup`, with every check of the evidence, the freed parameters and their
/// bounds, and the starting values (from the speeds inverted alone where they exist).
pub(crate) fn build<'a>(
    setup: &'a JointSetup,
    model: SpeedModel,
    cancel: Option<&'a std::sync::atomic::AtomicBool>,
) -> Result<Problem<'a>, CalibrationError> {
    check_speeds(&setup.speeds)?;
    check_anchoring(&setup.anchoring)?;
    if setup.speeds.is_empty() && setup.anchoring.is_empty() {
        return Err(CalibrationError::NoObservations);
    }
    if !(setup.error_floor.is_finite() && setup.error_floor >= 0.0) {
        return Err(CalibrationError::BadErrorFloor(setup.error_floor));
    }
    let mut unknowns: Vec<Unknown> = Vec::new();
    for f in &setup.free {
        if matches!(model, SpeedModel::Simulator { .. }) {
            check_free_for_simulator(f.parameter)?;
        }
        if unknowns.iter().any(|u| u.quantity == Quantity::Free(f.parameter)) {
            return Err(CalibrationError::DuplicateParameter { name: f.parameter.name().into() });
        }
        unknowns.push(free_unknown(setup, f.parameter, f.bounds)?);
    }
    let inverted = inverted_k_s(setup);
    let (mut force_tests, mut force_test_unknown, mut law) = (Vec::new(), Vec::new(), None);
    match &setup.shear {
        ShearShape::ForceTests(terrain) => {
            for p in terrain.points() {
                force_tests.push(ForceTest {
                    slope_deg: p.slope_deg,
                    k_s: p.k_s,
                    sd: p.k_s_sd.filter(|&s| s > 0.0),
                });
            }
            for (point, k) in force_tests.iter().enumerate() {
                let Some(sd) = k.sd else {
                    force_test_unknown.push(None);
                    continue;
                };
                force_test_unknown.push(Some(unknowns.len()));
                unknowns.push(Unknown {
                    quantity: Quantity::PlateShearStrength { point, slope_deg: k.slope_deg },
                    lo: (k.k_s - 10.0 * sd).max(k.k_s * 1e-3),
                    hi: k.k_s + 10.0 * sd,
                    log: true,
                    start: k.k_s,
                });
            }
            // Start the plate scale where the speeds' own k_s lie (geometric mean of the ratios).
            let plate: Vec<(f64, f64)> = force_tests.iter().map(|k| (k.slope_deg, k.k_s)).collect();
            let ln: Vec<f64> = inverted.iter().map(|&(d, k)| (k / interpolate(&plate, d)).ln()).collect();
            let scale = unknowns.iter_mut().find(|u| u.quantity == Quantity::Free(Parameter::PlateScale));
            if let (Some(u), false) = (scale, ln.is_empty()) {
                let c = (ln.iter().sum::<f64>() / ln.len() as f64).exp();
                u.start = c.clamp(u.lo, u.hi);
            }
        }
        ShearShape::Law(l) => {
            law = Some(*l);
            let level = inverted.first().map_or(1e6, |&(_, k)| k).clamp(1e3, 1e11);
            let theta_max = setup.speeds.iter().map(|o| o.slope.degrees()).fold(0.0, f64::max);
            let [first, second] = Quantity::of_law(*l);
            unknowns.push(Unknown { quantity: first, lo: 1.0, hi: 1e12, log: true, start: level });
            unknowns.push(match l {
                ShearLaw::Coulomb => Unknown {
                    quantity: second,
                    lo: theta_max + 1e-3,
                    hi: 89.999,
                    log: false,
                    start: (theta_max + 20.0).min(89.0),
                },
                ShearLaw::Linear => Unknown { quantity: second, lo: 0.0, hi: 5.0, log: false, start: 0.8 },
            });
        }
    }
    let n_force = force_tests.iter().filter(|k| k.sd.is_some()).count();
    let n_obs = setup.speeds.len() + setup.anchoring.len() + n_force;
    if unknowns.len() > n_obs {
        return Err(CalibrationError::TooFewObservations { observations: n_obs, parameters: unknowns.len() });
    }
    let mut walk_slopes: Vec<f64> = setup.speeds.iter().map(|o| o.slope.degrees()).collect();
    walk_slopes.extend(setup.anchoring.iter().map(|o| o.slope.degrees()));
    walk_slopes.sort_by(f64::total_cmp);
    walk_slopes.dedup();
    let simulator = match model {
        SpeedModel::ClosedForm => None,
        SpeedModel::Simulator { settings } => Some(SimulatedModel::new(settings, cancel)),
    };
    let problem = Problem {
        setup,
        unknowns,
        force_tests,
        force_test_unknown,
        law,
        n_obs,
        simulator,
        walk_slopes,
        chain_rule: true,
        walk_ln_k_s_step: WALK_LN_K_S_STEP,
    };
    // The simulator refuses some robots and grounds (more than 64 stance legs, a step too
    // coarse for the stiffness): say so now rather than fit a flat penalty.
    let start: Vec<f64> = problem.unknowns.iter().map(|u| u.start).collect();
    let c = problem.candidate(&start);
    if let (Some(robot), true) = (c.robot.as_ref(), problem.simulator.is_some()) {
        if let Some(Err(reason)) = problem.walked(robot, &c) {
            return Err(CalibrationError::Simulator { reason });
        }
    }
    Ok(problem)
}
