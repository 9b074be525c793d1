//! The requests Python answers over arrays (`phase` over NumPy axes, `risk` over NumPy slopes,
//! `plan` over a NumPy DEM):
//! the same cells and points as the library's own calls, refusals named as Python names its
//! keywords, and a raised stop flag ending the work between chunks.

use std::sync::atomic::AtomicBool;

use sandslope::risk::{risk_curve, RiskAnswer, UncertainTerrain};
use sandslope::{Axis, AxisScale, Robot, RobotSpec, Terrain};
use sandslope_request::error::Words;
use sandslope_request::phase::PhaseMapRequest;
use sandslope_request::plan::{ClassRaster, GridPlanRequest, GridRequest, GridSource};
use sandslope_request::risk::{AnswerLimits, RiskQuestion, Solve};

fn robot() -> Robot {
    Robot::new(RobotSpec::paper_hexapod()).unwrap()
}

fn terrain() -> Terrain {
    Terrain::constant(3e6, 1e6).unwrap()
}

fn phase_map(n: usize) -> PhaseMapRequest {
    let k_n = Axis::new("k_n", 1e4, 1e7, n, AxisScale::Log).unwrap().values();
    let k_s = Axis::new("k_s", 1e3, 1e7, n + 1, AxisScale::Linear).unwrap().values();
    PhaseMapRequest { slope_deg: 10.0, k_n_axis: k_n, k_s_axis: k_s, repose_deg: None, regime_only: false }
}

/// The map over values is the map over the axes they match: each cell's regime is the
/// library's prediction there, and the counts add up to the cells.
#[test]
fn a_phase_map_over_values_is_the_library_grid() {
    let request = phase_map(7);
    let answer = request.answer(&robot(), None, None).unwrap();
    assert_eq!(answer.k_n_axis.scale(), AxisScale::Log);
    assert_eq!(answer.k_s_axis.scale(), AxisScale::Linear);
    assert_eq!(answer.counts.total(), 7 * 8);
    assert_eq!(answer.step_m.as_ref().map(Vec::len), Some(56));
    let slope = sandslope::SignedSlope::from_degrees(10.0).unwrap();
    for (j, &k_s) in request.k_s_axis.iter().enumerate() {
        for (i, &k_n) in request.k_n_axis.iter().enumerate() {
            let scenario = sandslope::Scenario::new(robot(), terrain(), Some(k_n), Some(k_s)).unwrap();
            let regime = scenario.evaluate(slope).prediction.regime;
            let code = sandslope::Regime::ALL.iter().position(|&g| g == regime).unwrap() as i8;
            assert_eq!(answer.regime[j * 7 + i], code, "cell ({i}, {j})");
        }
    }
    let only = PhaseMapRequest { regime_only: true, ..request.clone() }.answer(&robot(), None, None).unwrap();
    assert_eq!((&only.regime, only.step_m), (&answer.regime, None));
    // A terrain lends its angle of repose, unless one is given: at 10 degrees, a repose of 10
    // makes cells slip that climbed without one.
    let table = sandslope::TerrainSpec { repose_deg: Some(10.0), ..terrain().spec().clone() };
    let steep = Terrain::new(table).unwrap();
    let map = |r: &PhaseMapRequest, t| r.answer(&robot(), t, None).unwrap().regime;
    let at_ten = map(&PhaseMapRequest { repose_deg: Some(10.0), ..request.clone() }, None);
    assert_ne!(at_ten, answer.regime);
    assert_eq!(map(&request, Some(&steep)), at_ten);
    assert_eq!(
        map(&PhaseMapRequest { repose_deg: Some(40.0), ..request.clone() }, Some(&steep)),
        answer.regime
    );
}

#[test]
fn a_phase_map_refuses_in_python_words_and_stops_on_its_flag() {
    let message = |r: PhaseMapRequest| r.check(None).unwrap_err().message();
    assert!(message(PhaseMapRequest { repose_deg: Some(0.0), ..phase_map(3) })
        .starts_with("repose_deg = 0 must be"));
    assert!(
        message(PhaseMapRequest { slope_deg: 95.0, ..phase_map(3) }).starts_with("slope_deg = 95 must be")
    );
    assert!(
        message(PhaseMapRequest { k_n_axis: vec![1.0], ..phase_map(3) }).starts_with("k_n_axis has 1 values")
    );
    let uneven = PhaseMapRequest { k_s_axis: vec![1.0, 2.0, 4.5], ..phase_map(3) };
    assert!(message(uneven).starts_with("k_s_axis must be ascending and evenly spaced"));
    let huge = (0..20_000).map(f64::from).collect::<Vec<_>>();
    let huge = PhaseMapRequest { k_n_axis: huge.clone(), k_s_axis: huge, ..phase_map(3) };
    assert!(message(huge).contains("at most 268435456 cells (here 20000 x 20000)"));
    let raised = AtomicBool::new(true);
    let e = phase_map(3).answer(&robot(), None, Some(&raised)).unwrap_err();
    assert_eq!((e.field(), e.message().as_str()), (None, "interrupted"));
}

fn question(slopes: Vec<f64>, solve: Option<Solve>) -> RiskQuestion {
    RiskQuestion { slopes, cv_n: None, cv_s: None, max_risk: 0.05, solve, map: None }
}

/// A curve over more slopes than one chunk holds is the library's curve over them all, point
/// for point; its refusals name Python's element, or the command line's flag.
#[test]
fn a_risk_curve_in_chunks_is_the_whole_curve() {
    let slopes: Vec<f64> = (0..300).map(|i| f64::from(i) * 0.08).collect();
    let limits = AnswerLimits::LIBRARY;
    let answer = question(slopes.clone(), None).answer_on(&robot(), terrain(), limits, Words::Keyword, None);
    let RiskAnswer::Curve(points) = answer.unwrap() else { panic!("a curve") };
    let uncertain = UncertainTerrain::new(terrain(), None, None).unwrap();
    let signed: Vec<sandslope::SignedSlope> =
        slopes.iter().map(|&d| sandslope::SignedSlope::from_degrees(d).unwrap()).collect();
    assert_eq!(points, risk_curve(&robot(), &uncertain, &signed).points);
    let mut bad = slopes;
    bad[200] = 95.0;
    let e =
        question(bad.clone(), None).answer_on(&robot(), terrain(), limits, Words::Keyword, None).unwrap_err();
    assert!(e.message().starts_with("slope_deg[200] = 95 must be"), "{}", e.message());
    let e = question(bad, None).answer_on(&robot(), terrain(), limits, Words::Flag, None).unwrap_err();
    assert!(e.message().starts_with("--slope = 95 must be"), "{}", e.message());
    let few = AnswerLimits { curve_slopes: 2, ..limits };
    let e = question(vec![1.0, 2.0, 3.0], None).answer_on(&robot(), terrain(), few, Words::Keyword, None);
    assert_eq!(e.unwrap_err().message(), "len(slope_deg) = 3 must be at most 2");
    let raised = AtomicBool::new(true);
    let e = question(vec![1.0], None).answer_on(&robot(), terrain(), limits, Words::Keyword, Some(&raised));
    assert_eq!(e.unwrap_err().message(), "interrupted");
}

/// The envelope at one slope is an envelope (Python's `payload_envelope`), where `solve mass`
/// at one slope is that slope's heaviest safe mass; the two agree.
#[test]
fn an_envelope_at_one_slope_is_the_safe_mass_there() {
    let limits = AnswerLimits::LIBRARY;
    let ask =
        |solve| question(vec![8.0], Some(solve)).answer_on(&robot(), terrain(), limits, Words::Keyword, None);
    let (Ok(RiskAnswer::Envelope(env)), Ok(RiskAnswer::Mass(mass))) =
        (ask(Solve::Envelope), ask(Solve::Mass))
    else {
        panic!("an envelope and a mass")
    };
    assert_eq!(env.points.len(), 1);
    assert_eq!(env.points[0].max_mass_kg, mass.max_mass_kg);
}

/// A plan over heights in memory (Python's `plan`): a tilted plane, 12 x 12 cells of 1 m.
fn grid_plan() -> (GridPlanRequest, Vec<f64>) {
    let heights: Vec<f64> = (0..144).map(|i| f64::from(i / 12) * 0.05 + f64::from(i % 12) * 0.02).collect();
    let grid = GridRequest {
        cell_x: 1.0,
        cell_y: 1.0,
        row_widths_m: None,
        nodata: None,
        cv_n: None,
        cv_s: None,
        max_roll_deg: 20.0,
        descent: "symmetric".into(),
        allow_metastable: false,
        time_weight: 0.0,
    };
    let objectives = vec!["time".to_string(), "distance".to_string()];
    (
        GridPlanRequest { grid, start: (1, 1), goal: (10, 10), objectives, origin: Some((100.0, 50.0)) },
        heights,
    )
}

#[test]
fn a_plan_over_heights_finds_its_routes_and_refuses_in_python_words() {
    let (request, heights) = grid_plan();
    let (robot, terrain) = (robot(), terrain());
    let source = GridSource {
        heights: &heights,
        rows: 12,
        cols: 12,
        robot: &robot,
        terrain: &terrain,
        classes: None,
        class_terrains: None,
    };
    let result = request.answer(&source, None).unwrap();
    let (_, route) = result.routes.iter().find(|(o, _)| o.name() == "distance").unwrap();
    let cells = request.route_cells(route.as_ref().unwrap(), &result.planner);
    assert_eq!((cells.rows[0], cells.cols[0]), (1, 1));
    assert_eq!((cells.x_m[0], cells.y_m[0]), (101.5, 48.5));
    assert_eq!(cells.heading_deg.len() + 1, cells.rows.len());
    // Without an origin the south-west corner is at (0, 0): the first cell's centre 10.5 m north.
    let south_west = GridPlanRequest { origin: None, ..request.clone() };
    let cells = south_west.route_cells(route.as_ref().unwrap(), &result.planner);
    assert_eq!((cells.x_m[0], cells.y_m[0]), (1.5, 10.5));
    let classes = Some(ClassRaster { values: &heights, shape: (12, 12) });
    let half = GridSource { classes, class_terrains: None, ..source };
    let e = request.answer(&half, None).unwrap_err();
    assert_eq!(e.message(), "classes and class_terrains go together: give both or neither");
    let source = GridSource { classes: None, ..half };
    let refused = |r: GridPlanRequest| r.answer(&source, None).unwrap_err().message();
    let fast = GridPlanRequest { objectives: vec!["fast".into()], ..request.clone() };
    assert_eq!(refused(fast), r#"objective = "fast" must be "time", "risk" or "distance""#);
    let steep = GridPlanRequest {
        grid: GridRequest { max_roll_deg: 95.0, ..request.grid.clone() },
        ..request.clone()
    };
    assert!(refused(steep).starts_with("max_roll_deg = 95 must be strictly between 0 and 90"));
    let down = GridPlanRequest {
        grid: GridRequest { descent: "down".into(), ..request.grid.clone() },
        ..request.clone()
    };
    assert_eq!(refused(down), r#"descent = "down" must be "symmetric" or "level""#);
    let outside = GridPlanRequest { start: (500, 3), ..request.clone() };
    assert_eq!(refused(outside), "start = (500, 3) is outside the map: rows 0 to 11, columns 0 to 11");
    let raised = AtomicBool::new(true);
    assert_eq!(request.answer(&source, Some(&raised)).unwrap_err().message(), "interrupted");
    let bands = request.grid.risk_raster(&source).unwrap();
    assert_eq!(bands.len(), 2 * 144);
}
