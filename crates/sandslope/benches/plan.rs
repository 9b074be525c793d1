//! Criterion benchmark of the route search against the `pathfinding` crate's A* on the same
//! graph ([`Planner::edges`]), to justify the hand-written search.
//!
//! `cargo bench -p sandslope --bench plan`
//!
//! The map is the dune field of `bench/plan/run.py` (crests every ~40 m, slopes up to ~30
//! degrees, 0.25 m cells) at 1024 x 1024, planned corner to corner for the time objective.
//! `pathfinding` needs an ordered cost, so its edge costs are rounded to microseconds; the
//! two optima agree to that rounding (checked before timing).

use criterion::{criterion_group, criterion_main, Criterion};
use sandslope::plan::{Cell, ElevationGrid, Objective, PitchTable, PlanSettings, Planner};
use sandslope::{Robot, RobotSpec, Terrain, UncertainTerrain, Uncertainty};

/// The paper's hexapod (the library's `RobotSpec::paper_hexapod`).
fn paper_robot() -> Robot {
    Robot::new(RobotSpec::paper_hexapod()).expect("valid robot")
}

fn dunes(n: usize, cell: f64) -> ElevationGrid {
    use std::f64::consts::TAU;
    let z = (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f64 * cell + 0.5 * cell, (n - i / n) as f64 * cell - 0.5 * cell);
            let crest = 3.0
                * (TAU * x / 40.0 + 0.8 * (TAU * y / 90.0).sin()).sin()
                * (0.6 + 0.4 * (TAU * y / 130.0).cos());
            (crest + 0.25 * (TAU * (x + y) / 11.0).sin()) as f32
        })
        .collect();
    ElevationGrid::new(n, n, cell, cell, z, None).expect("grid")
}

fn bench(c: &mut Criterion) {
    let n = 1024;
    let terrain = UncertainTerrain::with_uncertainty(
        Terrain::constant(7e5, 2e6).expect("terrain"),
        Uncertainty::new(0.1, 0.2).expect("cv"),
    );
    let planner = Planner::new(dunes(n, 0.25), None, &[terrain], &paper_robot(), PlanSettings::default())
        .expect("planner");
    let (start, goal) = (Cell { col: 30, row: n - 31 }, Cell { col: n - 31, row: 30 });
    let ours = || {
        planner
            .route(Objective::Time, start, goal, &|_| std::ops::ControlFlow::Continue(()))
            .expect("endpoints")
            .expect("route")
    };
    // The same cost-to-go bound as the library's: straight-line distance times the smallest
    // time per horizontal metre in the pitch table, sec(pitch) / speed.
    let table = &planner.tables()[0];
    let min_per_m = (0..table.len())
        .filter_map(|i| {
            let tan = PitchTable::tan_of(i);
            table.speed(i).filter(|&v| v > 0.0).map(|v| (1.0 + tan * tan).sqrt() / v)
        })
        .fold(f64::INFINITY, f64::min)
        * (1.0 - 1e-5);
    let h = |c: &Cell| {
        let (dx, dy) = ((c.col as f64 - goal.col as f64) * 0.25, (c.row as f64 - goal.row as f64) * 0.25);
        (min_per_m * dx.hypot(dy) * 1e6) as u64
    };
    let theirs = || {
        pathfinding::directed::astar::astar(
            &start,
            |&c| {
                planner
                    .edges(Objective::Time, c)
                    .map(|(d, s)| (d, (s * 1e6).round() as u64))
                    .collect::<Vec<_>>()
            },
            h,
            |&c| c == goal,
        )
        .expect("route")
    };
    let (a, b) = (ours(), theirs());
    let (ta, tb) = (a.time_s.expect("time"), b.1 as f64 * 1e-6);
    assert!((ta - tb).abs() < 1e-3 * ta, "sandslope {ta} s vs pathfinding {tb} s");
    let mut g = c.benchmark_group("plan 1024 x 1024 dunes, time objective");
    g.sample_size(10);
    g.bench_function("sandslope Planner::route (flat arrays, buckets)", |bch| bch.iter(ours));
    g.bench_function("pathfinding::astar on Planner::edges", |bch| bch.iter(theirs));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
