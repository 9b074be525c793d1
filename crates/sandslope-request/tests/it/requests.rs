//! The request layer: field names, defaults and answers, checked against values worked out
//! from the model's own definitions, not from this crate's output.

use sandslope_request::{PredictRequest, RequestError, ScenarioRequest, SweepRequest};

fn pairs(list: &[(&str, &str)]) -> Vec<(String, String)> {
    list.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()
}

fn field(r: Result<impl std::fmt::Debug, RequestError>) -> String {
    r.unwrap_err().field().unwrap_or_default().to_string()
}

#[test]
fn every_refusal_names_its_field() {
    let predict = |list: &[(&str, &str)]| PredictRequest::from_params(&pairs(list)).and_then(|r| r.answer());
    assert_eq!(field(predict(&[])), "slope");
    assert_eq!(field(predict(&[("slope", "abc")])), "slope");
    assert_eq!(field(predict(&[("slope", "95")])), "slope");
    assert_eq!(field(predict(&[("slope", "1"), ("slope", "2")])), "slope");
    assert_eq!(field(predict(&[("slope", "10"), ("mass", "-1")])), "mass");
    assert_eq!(field(predict(&[("slope", "10"), ("k-s", "0")])), "k-s");
    assert_eq!(field(predict(&[("slope", "10"), ("leg-radius", "5")])), "leg-radius");
    assert_eq!(field(predict(&[("slope", "10"), ("stance-legs", "2.5")])), "stance-legs");
    // The paper's robot has h = 0.03 m, so R = 0.01 m breaks h <= 2R: the key at fault is h.
    assert_eq!(field(predict(&[("slope", "10"), ("leg-radius", "0.01")])), "hip-height");
    assert_eq!(field(predict(&[("slope", "10"), ("level-step", "deep")])), "level-step");
    assert_eq!(field(predict(&[("slope", "10"), ("robot", "no-such-robot")])), "robot");
    assert_eq!(field(predict(&[("slope", "10"), ("terrain", "no-such-terrain")])), "terrain");
    assert_eq!(field(predict(&[("slope", "10"), ("wings", "2")])), "wings");
    let sweep = |list: &[(&str, &str)]| SweepRequest::from_params(&pairs(list)).and_then(|r| r.answer());
    assert_eq!(field(sweep(&[("from", "10"), ("to", "0")])), "from");
    assert_eq!(field(sweep(&[("step", "-1")])), "step");
    assert_eq!(field(sweep(&[("step", "1e-9")])), "step");
}

#[test]
fn messages_say_the_valid_range_in_the_flags_words() {
    let e = PredictRequest::from_params(&pairs(&[("slope", "10"), ("mass", "-1")]))
        .unwrap()
        .answer()
        .unwrap_err();
    assert_eq!(e.message(), "--mass = -1 must be a finite number greater than 0");
    let e = SweepRequest::from_params(&pairs(&[("wings", "1")])).unwrap_err();
    // The accepted keys are the fields the request read: the robot table's flags among them.
    let m = e.message();
    for key in [
        "from",
        "to",
        "step",
        "robot",
        "mass",
        "leg-radius",
        "stance-legs",
        "response-time",
        "k-n",
        "level-step",
    ] {
        assert!(m.contains(key), "{key} missing from: {m}");
    }
}

#[test]
fn the_defaults_are_the_command_lines() {
    let sweep = SweepRequest::from_params(&[]).unwrap();
    assert_eq!((sweep.from, sweep.to, sweep.step), (0.0, 30.0, 1.0));
    assert_eq!(sweep.scenario, ScenarioRequest::default());
    // 0, 1, ..., 30: 31 slopes, both ends included.
    let slopes = sweep.slopes().unwrap();
    assert_eq!((slopes.len(), slopes[0], slopes[30]), (31, 0.0, 30.0));
}

#[test]
fn an_answer_is_the_library_value() {
    // docs/model.md §5: v = s / (T/2), with omega = 2 pi rad/s the stance lasts T/2 = 0.5 s;
    // a stance-legs override of 6 on the paper's robot halves the load per leg, and the mass
    // override replaces the file's.
    let e = PredictRequest::from_params(&pairs(&[("slope", "0")])).unwrap().answer().unwrap();
    let speed = e.speed().unwrap();
    assert!((speed - e.prediction.step.unwrap() / 0.5).abs() < 1e-12);
    assert!((speed - 0.157).abs() < 0.157 * 0.05, "{speed}");
    let heavy = PredictRequest::from_params(&pairs(&[("slope", "0"), ("mass", "2")])).unwrap();
    let robot = heavy.scenario.robot.load().unwrap();
    assert_eq!(robot.mass(), 2.0);
    let wide = PredictRequest::from_params(&pairs(&[("slope", "0"), ("stance-legs", "6")])).unwrap();
    assert_eq!(wide.scenario.robot.load().unwrap().spec().stance_legs, 6);
}

#[test]
fn requests_round_trip_through_json() {
    let r = PredictRequest::from_params(&pairs(&[("slope", "12.5"), ("leg-speed", "3"), ("k-n", "1e6")]))
        .unwrap();
    let text = serde_json::to_string(&r).unwrap();
    assert_eq!(serde_json::from_str::<PredictRequest>(&text).unwrap(), r);
}

#[test]
fn risk_refusals_name_their_field_and_the_default_is_seven_slopes() {
    use sandslope_request::risk::{AnswerLimits, RiskRequest};
    let risk = |list: &[(&str, &str)]| RiskRequest::from_params(&pairs(list));
    assert_eq!(field(risk(&[("slope", "0:24:q")])), "slope");
    assert_eq!(field(risk(&[("max-risk", "1.5")])), "max-risk");
    assert_eq!(field(risk(&[("solve", "speed")])), "solve");
    assert_eq!(field(risk(&[("k-n", "1e4:1e7:20")])), "k-n");
    assert_eq!(field(risk(&[("map", "maybe")])), "map");
    assert_eq!(field(risk(&[("map", ""), ("solve", "mass")])), "solve");
    let limits = AnswerLimits { curve_slopes: 3, envelope_slopes: 3, map_cells: 100 };
    let answer = |list: &[(&str, &str)]| risk(list).unwrap().answer(limits);
    assert_eq!(field(answer(&[("cv-s", "-1")])), "cv-s");
    assert_eq!(field(answer(&[("slope", "0:24:4")])), "slope");
    assert_eq!(
        field(answer(&[("map", ""), ("slope", "10"), ("k-n", "1e4:1e7:11"), ("k-s", "1e3:1e6:10")])),
        "k-n"
    );
    // 0:24:7 is 0, 4, ..., 24 degrees: seven points of the curve, in order.
    let default = RiskRequest::from_params(&[]).unwrap();
    let q = &default.question;
    assert_eq!(q.slopes, vec![0.0, 4.0, 8.0, 12.0, 16.0, 20.0, 24.0]);
    assert_eq!((q.max_risk, q.solve, q.map), (0.05, None, None));
}

/// What the command line asks of a risk problem beside the answer comes from the same checked
/// question: `solve slope`'s answer is `slope_limits`, the curve figure's points at the slopes
/// asked are the curve's, a map tells its progress its rows, and `defaults_used` names the
/// default CVs where the library's own curve does.
#[test]
fn a_risk_problem_answers_the_command_lines_other_questions_from_one_check() {
    use sandslope::risk::{risk_curve, RiskAnswer, UncertainTerrain};
    use sandslope::Terrain;
    use sandslope_request::error::Words;
    use sandslope_request::risk::{defaults_used, AnswerLimits, Progress, RiskMapGrid, RiskQuestion, Solve};
    use std::sync::atomic::{AtomicU64, Ordering};

    let robot =
        sandslope_request::RobotRequest { robot: "paper-hexapod".into(), mass: None, overrides: vec![] }
            .load()
            .unwrap();
    // No SDs and no CV given: both defaults are used.
    let bare = || Terrain::constant(7e5, 1.5e6).unwrap();
    let question = |solve: Option<Solve>| RiskQuestion {
        slopes: vec![0.0, 10.0, -20.0],
        cv_n: None,
        cv_s: None,
        max_risk: 0.05,
        solve,
        map: None,
    };
    let lib = AnswerLimits::LIBRARY;
    let curve = question(None).on(&robot, bare(), Words::Flag).unwrap();
    let RiskAnswer::Curve(points) = curve.answer(lib, None, &sandslope_request::risk::NoProgress).unwrap()
    else {
        panic!("three slopes are a curve")
    };
    let slopes: Vec<sandslope::SignedSlope> =
        [0.0, 10.0, -20.0].iter().map(|&d| sandslope::SignedSlope::from_degrees(d).unwrap()).collect();
    let own = risk_curve(&robot, &UncertainTerrain::new(bare(), None, None).unwrap(), &slopes);
    assert_eq!(points, own.points);
    assert_eq!(defaults_used(&RiskAnswer::Curve(points.clone())), own.defaults_used);
    assert!(own.defaults_used.k_n && own.defaults_used.k_s);
    let limits = curve.slope_limits().unwrap();
    let samples = curve.curve_samples(&limits).unwrap();
    assert_eq!(samples.requested, points);
    assert_eq!(samples.fine.first().map(|p| p.slope_deg), Some(0.0));
    assert_eq!(samples.fine.last().map(|p| p.slope_deg), Some(samples.hi));

    let slope = question(Some(Solve::Slope)).on(&robot, bare(), Words::Flag).unwrap();
    assert_eq!(
        slope.answer(lib, None, &sandslope_request::risk::NoProgress).unwrap(),
        RiskAnswer::Slope(Box::new(limits))
    );

    struct Rows(AtomicU64, AtomicU64);
    impl Progress for Rows {
        fn start(&self, steps: u64) {
            self.0.store(steps, Ordering::Relaxed);
        }
        fn step(&self) {
            self.1.fetch_add(1, Ordering::Relaxed);
        }
    }
    let mut map = question(None).on(&robot, bare(), Words::Flag).unwrap();
    let axis = |t: &str| Some(sandslope_request::grammar::parse_strength_axis("k-n", t).unwrap());
    map.map_over(RiskMapGrid { k_n: axis("1e5:1e7:3"), k_s: axis("1e5:1e7:4") });
    let rows = Rows(AtomicU64::new(0), AtomicU64::new(0));
    let RiskAnswer::Map(answer) = map.answer(lib, None, &rows).unwrap() else { panic!("a map") };
    assert_eq!(answer.summary.slope_deg, 0.0);
    assert_eq!((rows.0.into_inner(), rows.1.into_inner()), (4, 4));
    assert_eq!(defaults_used(&RiskAnswer::Map(answer)), own.defaults_used);
}

#[test]
fn plan_refusals_name_their_field() {
    use sandslope_request::PlanRequest;
    let plan = |list: &[(&str, &str)]| PlanRequest::from_params(&pairs(list));
    let dem = ("dem", "dune.asc");
    assert_eq!(field(plan(&[dem, ("goal", "1,1")])), "start");
    assert_eq!(field(plan(&[dem, ("start", "1,1"), ("start-px", "1,1"), ("goal", "2,2")])), "start-px");
    assert_eq!(
        field(plan(&[dem, ("start", "1,1"), ("goal", "2,2"), ("objective", "time,fun")])),
        "objective"
    );
    assert_eq!(field(plan(&[dem, ("start", "1,1"), ("goal", "2,2"), ("search", "dfs")])), "search");
    let r = plan(&[dem, ("start", "1,1"), ("goal", "2,2"), ("max-roll", "95")]).unwrap();
    assert_eq!(field(r.settings()), "max-roll");
    let r = plan(&[dem, ("start-px", "1,1"), ("goal-px", "2,2"), ("coarse-factor", "65")]).unwrap();
    assert_eq!(field(r.check_corridor()), "coarse-factor");
    // The descent rule by its name (the library's, which Python parses too); symmetric unless given.
    let ends = [dem, ("start", "1,1"), ("goal", "2,2")];
    assert_eq!(plan(&ends).unwrap().descent, sandslope::plan::Descent::Symmetric);
    let level = plan(&[ends[0], ends[1], ends[2], ("descent", "level")]).unwrap();
    assert_eq!(level.descent, sandslope::plan::Descent::Level);
    let e = plan(&[ends[0], ends[1], ends[2], ("descent", "down")]).unwrap_err();
    assert_eq!(
        (e.field(), e.message().as_str()),
        (Some("descent"), "--descent = `down` must be symmetric (as climbing |pitch|) or level")
    );
}

#[test]
fn simulate_takes_one_slope_or_a_list_and_the_librarys_defaults() {
    use sandslope::simulate::{BodyPitch, RftScaling};
    use sandslope_request::simulate::SimSlopes;
    use sandslope_request::SimulateRequest;
    let sim = |list: &[(&str, &str)]| SimulateRequest::from_params(&pairs(list));
    assert_eq!(field(sim(&[])), "slope");
    assert_eq!(field(sim(&[("slope", "5"), ("slopes", "0,5")])), "slopes");
    assert_eq!(field(sim(&[("slopes", "0:10:1")])), "slopes");
    assert_eq!(field(sim(&[("slope", "5"), ("body-pitch", "wobbly")])), "body-pitch");
    assert_eq!(field(sim(&[("slope", "90")]).unwrap().walks()), "slope");
    assert_eq!(field(sim(&[("slope", "5"), ("duration", "-1")]).unwrap().walks()), "duration");
    let r = sim(&[("slopes", "0:10:3")]).unwrap();
    assert_eq!(r.slopes, SimSlopes::Many(vec![0.0, 5.0, 10.0]));
    assert_eq!((r.body_pitch, r.rft_scaling), (BodyPitch::default(), RftScaling::default()));
    assert_eq!((r.duration_s, r.rate_hz, r.dt_s), (10.0, 120.0, None));
    // The locked body is the library's default (the converged setting, docs/simulate.md).
    assert_eq!(r.body_pitch, BodyPitch::Locked);
    // The servo limit applies unless `no-servo-limit` is given (bare, as a query string's
    // `&no-servo-limit`, or true/1); the creep speed is checked against its range by name.
    assert!(r.servo_limit && r.creep_m_s.is_none());
    for on in ["", "true", "1"] {
        assert!(!sim(&[("slope", "5"), ("no-servo-limit", on)]).unwrap().servo_limit, "{on:?}");
    }
    assert!(sim(&[("slope", "5"), ("no-servo-limit", "false")]).unwrap().servo_limit);
    assert_eq!(field(sim(&[("slope", "5"), ("no-servo-limit", "maybe")])), "no-servo-limit");
    assert_eq!(field(sim(&[("slope", "5"), ("creep", "1")]).unwrap().walks()), "creep");
    assert_eq!(sim(&[("slope", "5"), ("rft-scaling", "li2013")]).unwrap().rft_scaling, RftScaling::Li2013);
}
