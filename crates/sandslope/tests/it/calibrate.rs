//! The joint calibration against data simulated with known parameters: it recovers them
//! within its reported intervals, the 68% profile intervals cover the truth about 68% of the
//! time on repeated noisy data, and each warning fires when (and only when) it should.

use rand::{rngs::StdRng, SeedableRng};
use rand_distr::{Distribution, Normal};
use rayon::prelude::*;
use sandslope::calibrate::Interval;
use sandslope::*;

fn slope(d: f64) -> Slope {
    Slope::from_degrees(d).unwrap()
}

fn paper_robot() -> Robot {
    Robot::new(RobotSpec::paper_hexapod()).unwrap()
}

/// A terrain whose k_s falls linearly from `k0` at 0 deg to `rho * k0` at 20 deg (and on), k_n
/// constant 7e5; SDs `cv` of each value.
fn linear_terrain(k0: f64, rho: f64, cv: f64) -> Terrain {
    let pt = |d: f64| {
        let k_s = k0 * (1.0 + (rho - 1.0) * d / 20.0);
        TerrainPoint {
            slope_deg: d,
            k_n: 7e5,
            k_s,
            k_n_sd: Some(7e4),
            k_s_sd: (cv > 0.0).then_some(cv * k_s),
        }
    };
    Terrain::new(TerrainSpec {
        name: None,
        repose_deg: Some(25.0),
        points: vec![pt(0.0), pt(20.0), pt(24.0)],
    })
    .unwrap()
}

/// The model's speed (no repose: an observed speed shows the robot moved).
fn speed(robot: &Robot, terrain: &Terrain, d: f64) -> f64 {
    let mut g = terrain.at(slope(d));
    g.repose = None;
    predict(robot, slope(d), &g).speed.unwrap()
}

fn t1(robot: &Robot, terrain: &Terrain, d: f64) -> f64 {
    predict(robot, slope(d), &terrain.at(slope(d))).anchoring_time.unwrap()
}

const SLOPES: [f64; 6] = [0.0, 5.0, 10.0, 15.0, 20.0, 24.0];

fn param(c: &JointCalibration, quantity: Quantity) -> &Interval {
    &c.fitted(quantity).unwrap_or_else(|| panic!("no {quantity:?}")).estimate
}

const HIP_HEIGHT: Quantity = Quantity::Free(Parameter::Robot(RobotKey::HipHeightM));
const PLATE_SCALE: Quantity = Quantity::Free(Parameter::PlateScale);
const ERROR_FLOOR: Quantity = Quantity::Free(Parameter::ErrorFloor);

fn contains(iv: &Interval, truth: f64) -> bool {
    iv.lower <= truth && truth <= iv.upper
}

/// The robot with the true hip height 0.025 m (the preset assumes 0.03).
fn true_robot() -> Robot {
    Robot::new(RobotSpec { hip_height_m: 0.025, ..RobotSpec::paper_hexapod() }).unwrap()
}

/// Speeds and anchoring times made by the true robot on a terrain whose leg k_s is 20 times
/// the plate's (2e6 level, 0.5 at 20 deg), with relative noise `noise` (0: exact).
fn simulated(seed: u64, noise: f64) -> (Vec<SpeedObservation>, Vec<AnchoringObservation>) {
    let robot = true_robot();
    let leg = linear_terrain(2e6, 0.5, 0.0);
    let mut rng = StdRng::seed_from_u64(seed);
    let z = Normal::new(0.0, 1.0).unwrap();
    let speeds = SLOPES
        .iter()
        .map(|&d| {
            let (v, sd) = (speed(&robot, &leg, d), 0.004);
            SpeedObservation { slope: slope(d), speed: v + noise * sd * z.sample(&mut rng), speed_sd: sd }
        })
        .collect();
    let anchoring = [0.0, 10.0, 20.0]
        .iter()
        .map(|&d| {
            let (t, sd) = (t1(&robot, &leg, d), 0.004);
            AnchoringObservation { slope: slope(d), t1: t + noise * sd * z.sample(&mut rng), t1_sd: sd }
        })
        .collect();
    (speeds, anchoring)
}

fn free(names: &[&str]) -> Vec<FreeParameter> {
    names.iter().map(|n| FreeParameter { parameter: Parameter::parse(n).unwrap(), bounds: None }).collect()
}

#[test]
fn joint_fit_recovers_hip_height_plate_scale_and_ratio_from_exact_data() {
    let (speeds, anchoring) = simulated(1, 0.0);
    // Force tests with the true shape (plate = leg / 20), SD 10%.
    let forces = linear_terrain(1e5, 0.5, 0.1);
    let setup = JointSetup {
        robot: paper_robot(),
        normal: forces.clone(),
        shear: ShearShape::ForceTests(forces),
        speeds,
        anchoring,
        free: free(&["hip_height_m", "plate_scale"]),
        error_floor: 0.0,
    };
    let c = calibrate_jointly(&setup).unwrap();
    let h = param(&c, HIP_HEIGHT);
    let scale = param(&c, PLATE_SCALE);
    assert!((h.value - 0.025).abs() < 1e-5, "h = {h:?}");
    assert!((scale.value - 20.0).abs() < 0.02, "c = {scale:?}");
    assert_eq!(c.plate_scale(), scale.value);
    assert!(contains(h, 0.025) && contains(scale, 20.0));
    assert!((c.shear_ratio_20.value - 0.5).abs() < 1e-3 && contains(&c.shear_ratio_20, 0.5));
    // Exact data: chi^2 ~ 0, every pull ~ 0, no warnings about the fit.
    assert!(c.chi_squared < 1e-4, "chi2 {}", c.chi_squared);
    assert!(c.warnings.iter().all(|w| !matches!(w, CalibrationWarning::PoorFit { .. })));
    // The written robot has the fitted hip height; the terrain carries SDs scaled by c.
    assert!((c.robot.hip_height_m - 0.025).abs() < 1e-5);
    let p0 = &c.terrain.points[0];
    assert!((p0.k_s - 2e6).abs() < 2e3 && (p0.k_s_sd.unwrap() / p0.k_s - 0.1).abs() < 1e-3);
    // The plate force of the level leg k_s: 2e6 * 0.03 * 0.02^2 = 24 N.
    assert!((c.shear[0].plate_force_n - 24.0).abs() < 0.05);
    // Intervals are genuine intervals around the best value, narrow on exact data.
    assert!(h.lower < h.value && h.value < h.upper && h.upper - h.lower < 0.01, "{h:?}");
}

/// Repeated noisy data: the 68% profile intervals of the linear law's two parameters should
/// contain the truth in about 68% of the replicates. With 60 replicates the binomial SD of the
/// coverage is 0.06, so [0.50, 0.85] fails a correct method with probability under 1%.
#[test]
fn profile_intervals_have_68_percent_coverage() {
    let robot = paper_robot();
    let truth = linear_terrain(2e6, 0.5, 0.0);
    let sd = 0.004;
    let reps = 60;
    let hits: Vec<[bool; 2]> = (0..reps)
        .into_par_iter()
        .map(|seed| {
            let mut rng = StdRng::seed_from_u64(1000 + seed);
            let z = Normal::new(0.0, 1.0).unwrap();
            let speeds = SLOPES
                .iter()
                .map(|&d| SpeedObservation {
                    slope: slope(d),
                    speed: speed(&robot, &truth, d) + sd * z.sample(&mut rng),
                    speed_sd: sd,
                })
                .collect();
            let setup = JointSetup {
                robot: robot.clone(),
                normal: truth.clone(),
                shear: ShearShape::Law(ShearLaw::Linear),
                speeds,
                anchoring: vec![],
                free: vec![],
                error_floor: 0.0,
            };
            let c = calibrate_jointly(&setup).unwrap();
            [
                contains(param(&c, Quantity::LevelShearStrength), 2e6),
                contains(param(&c, Quantity::ShearRatio20), 0.5),
            ]
        })
        .collect();
    for (i, name) in ["k_s0", "ratio"].iter().enumerate() {
        let coverage = hits.iter().filter(|h| h[i]).count() as f64 / reps as f64;
        assert!((0.50..=0.85).contains(&coverage), "{name}: coverage {coverage}");
    }
}

#[test]
fn a_free_error_floor_is_the_maximum_likelihood_one_when_the_stated_sds_are_too_small() {
    // Speeds made with noise of SD 1 cm/s but stated SD 0.1 cm/s. With equal stated SDs s the
    // likelihood is maximised at s^2 + f^2 = RSS / n (RSS of the fitted model), so the fitted
    // floor must satisfy f = sqrt(RSS/n - s^2) at its own best fit: a closed form to check against.
    let robot = paper_robot();
    let truth = linear_terrain(2e6, 0.5, 0.0);
    let mut rng = StdRng::seed_from_u64(42);
    let z = Normal::new(0.0, 1.0).unwrap();
    let speeds: Vec<SpeedObservation> = [0.0, 4.0, 8.0, 12.0, 16.0, 20.0, 24.0]
        .iter()
        .map(|&d| SpeedObservation {
            slope: slope(d),
            speed: speed(&robot, &truth, d) + 0.01 * z.sample(&mut rng),
            speed_sd: 0.001,
        })
        .collect();
    let setup = JointSetup {
        robot,
        normal: truth.clone(),
        shear: ShearShape::Law(ShearLaw::Linear),
        speeds,
        anchoring: vec![],
        free: free(&["error_floor"]),
        error_floor: 0.0,
    };
    let c = calibrate_jointly(&setup).unwrap();
    let f = param(&c, ERROR_FLOOR);
    let n = c.pulls.len() as f64;
    let rss: f64 = c.pulls.iter().map(|p| (p.observed - p.model).powi(2)).sum();
    let expected = (rss / n - 0.001f64.powi(2)).sqrt();
    assert!((f.value / expected - 1.0).abs() < 1e-3, "floor {f:?} vs {expected}");
    assert!(f.value > 0.001 && f.lower < f.value && f.value < f.upper, "floor {f:?}");
    assert!((c.error_floor_m_s - f.value).abs() < 1e-12);
    // At the ML floor chi^2 = n exactly (each pull^2 sums to RSS / (RSS/n)).
    assert!((c.chi_squared - n).abs() < 1e-2, "chi2 {}", c.chi_squared);
    // Without the floor, the same data fit badly: the poor-fit warning fires.
    let fixed = calibrate_jointly(&JointSetup { free: vec![], ..setup.clone() }).unwrap();
    assert!(fixed.chi_squared_per_dof.unwrap() > 3.0);
    assert!(fixed.warnings.iter().any(|w| matches!(w, CalibrationWarning::PoorFit { .. })));
    assert!(c.warnings.iter().all(|w| !matches!(w, CalibrationWarning::PoorFit { .. })));
}

#[test]
fn warnings_fire_for_the_ceiling_and_for_a_bound() {
    let robot = paper_robot();
    // The ceiling s*/(T/2) with k_n 7e5 and h 0.03 is 15.82 cm/s (docs/calibration.md); a level
    // speed of 15.7 ± 0.97 is within one SD of it, 12.0 ± 0.5 is not.
    let terrain = linear_terrain(2e6, 0.5, 0.0);
    let obs = |level: f64, sd: f64| {
        vec![
            SpeedObservation { slope: slope(0.0), speed: level, speed_sd: sd },
            SpeedObservation { slope: slope(10.0), speed: 0.11, speed_sd: 0.01 },
            SpeedObservation { slope: slope(20.0), speed: 0.05, speed_sd: 0.01 },
        ]
    };
    let run = |speeds, free: Vec<FreeParameter>| {
        calibrate_jointly(&JointSetup {
            robot: robot.clone(),
            normal: terrain.clone(),
            shear: ShearShape::Law(ShearLaw::Linear),
            speeds,
            anchoring: vec![],
            free,
            error_floor: 0.0,
        })
        .unwrap()
    };
    let near = |c: &JointCalibration| {
        c.warnings.iter().any(|w| matches!(w, CalibrationWarning::SpeedNearCeiling { .. }))
    };
    let c = run(obs(0.157, 0.0097), vec![]);
    assert!(near(&c));
    let ceiling = c.shear[0].speed_ceiling_m_s;
    assert!((ceiling - 0.1582).abs() < 2e-4, "ceiling {ceiling}");
    assert!(!near(&run(obs(0.12, 0.005), vec![])));
    // Bounds that exclude the true hip height: the fit sits at the bound and says so.
    let bounded = vec![FreeParameter {
        parameter: Parameter::Robot(RobotKey::HipHeightM),
        bounds: Some((0.035, 0.04)),
    }];
    let c = run(obs(0.12, 0.005), bounded);
    let at = c
        .warnings
        .iter()
        .any(|w| matches!(w, CalibrationWarning::ParameterAtBound { name, .. } if name == "hip_height_m"));
    let p = c.parameter(Parameter::Robot(RobotKey::HipHeightM)).unwrap();
    assert_eq!(at, p.at_bound);
    assert!(p.at_bound, "{p:?}");
}

#[test]
fn bad_setups_are_refused_with_the_reason() {
    let terrain = linear_terrain(2e6, 0.5, 0.0);
    let base = JointSetup {
        robot: paper_robot(),
        normal: terrain.clone(),
        shear: ShearShape::Law(ShearLaw::Linear),
        speeds: vec![SpeedObservation { slope: slope(0.0), speed: 0.15, speed_sd: 0.01 }],
        anchoring: vec![],
        free: vec![],
        error_floor: 0.0,
    };
    // Two law parameters from one speed.
    assert!(matches!(calibrate_jointly(&base), Err(CalibrationError::TooFewObservations { .. })));
    let plate = JointSetup { free: free(&["plate_scale"]), ..base.clone() };
    assert_eq!(calibrate_jointly(&plate).unwrap_err(), CalibrationError::PlateScaleWithoutForces);
    let bounds = JointSetup {
        free: vec![FreeParameter { parameter: Parameter::PlateScale, bounds: Some((2.0, 1.0)) }],
        shear: ShearShape::ForceTests(linear_terrain(1e5, 0.5, 0.1)),
        ..base.clone()
    };
    assert!(matches!(calibrate_jointly(&bounds), Err(CalibrationError::BadBounds { .. })));
    let bad_sd = vec![SpeedObservation { slope: slope(0.0), speed: 0.15, speed_sd: 0.0 }];
    let e = calibrate_jointly(&JointSetup { speeds: bad_sd, ..base.clone() }).unwrap_err();
    assert!(matches!(e, CalibrationError::BadObservation { what: "speed", .. }), "{e:?}");
    let twice = vec![base.speeds[0], base.speeds[0]];
    let e = calibrate_jointly(&JointSetup { speeds: twice, ..base.clone() }).unwrap_err();
    assert!(matches!(e, CalibrationError::DuplicateSlope { what: "speed", .. }), "{e:?}");
    let none = JointSetup { speeds: vec![], ..base };
    assert_eq!(calibrate_jointly(&none).unwrap_err(), CalibrationError::NoObservations);
    assert_eq!(Parameter::parse("level_step_m"), Some(Parameter::Robot(RobotKey::LevelStepM)));
    assert_eq!(Parameter::parse("stance_legs"), None);
}

/// The two smooth laws recover the parameters that made exact speeds: linear with k_s0 = 2e6
/// and -5e4 per degree (rho = 1 + 20 (-5e4) / 2e6 = 0.5), Coulomb with k_s0 = 2e6 and phi = 35
/// deg (rho = cos 20 - sin 20 / tan 35 = 0.939693 - 0.342020 / 0.700208 = 0.451241).
#[test]
fn smooth_laws_recover_the_parameters_that_made_exact_speeds() {
    let robot = paper_robot();
    let normal = Terrain::constant(7e5, 1.0).unwrap();
    let cases = [
        (ShearLaw::Linear, [2.0e6, 0.5], Quantity::ShearRatio20, 0.5, 0.5),
        (ShearLaw::Coulomb, [2.0e6, 35.0], Quantity::FrictionAngle, 35.0, 0.451_241),
    ];
    for (law, truth, second, second_truth, ratio) in cases {
        let k_s = |d: f64| match law {
            ShearLaw::Linear => 2.0e6 - 5.0e4 * d,
            ShearLaw::Coulomb => {
                let t = d.to_radians();
                2.0e6 * (t.cos() - t.sin() / 35f64.to_radians().tan())
            }
        };
        let speeds: Vec<SpeedObservation> = SLOPES
            .iter()
            .map(|&d| {
                let v = predict(&robot, slope(d), &Ground::new(7e5, k_s(d)).unwrap()).speed.unwrap();
                SpeedObservation { slope: slope(d), speed: v, speed_sd: 0.005 }
            })
            .collect();
        let setup = JointSetup {
            robot: robot.clone(),
            normal: normal.clone(),
            shear: ShearShape::Law(law),
            speeds,
            anchoring: vec![],
            free: vec![],
            error_floor: 0.0,
        };
        let c = calibrate_jointly(&setup).unwrap();
        assert!(c.chi_squared < 1e-6, "{law:?}: chi2 {}", c.chi_squared);
        let level = param(&c, Quantity::LevelShearStrength).value;
        assert!((level / truth[0] - 1.0).abs() < 1e-4, "{law:?}: k_s0 {level}");
        let got = param(&c, second).value;
        assert!((got / second_truth - 1.0).abs() < 1e-4, "{law:?}: {got} vs {second_truth}");
        assert!((c.shear_ratio_20.value - ratio).abs() < 1e-4, "{law:?}: ratio {:?}", c.shear_ratio_20);
        for s in &c.shear {
            assert!((s.k_s / k_s(s.slope_deg) - 1.0).abs() < 1e-4, "{law:?} at {}: {}", s.slope_deg, s.k_s);
        }
    }
}
