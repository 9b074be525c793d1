//! Criterion benchmarks of the phase map, the risk map and the risk quadrature.
//!
//! `cargo bench -p sandslope --bench phase` (figures in docs/phase-and-risk.md).

use criterion::{criterion_group, criterion_main, Criterion};
use sandslope::{
    regime_probabilities, Axis, AxisScale, Ground, PhaseMap, RiskMap, Robot, RobotSpec, Slope, StrengthGrid,
    Uncertainty,
};

/// The paper's hexapod (the library's `RobotSpec::paper_hexapod`).
fn paper_robot() -> Robot {
    Robot::new(RobotSpec::paper_hexapod()).expect("valid robot")
}

fn bench(c: &mut Criterion) {
    let robot = paper_robot();
    let slope = Slope::from_degrees(20.0).expect("valid slope");
    for n in [400usize, 4096] {
        let kn = Axis::new("k_n", 7e3, 7e7, n, AxisScale::Log).expect("axis");
        let ks = Axis::new("k_s", 2e3, 2e8, n, AxisScale::Log).expect("axis");
        c.bench_function(&format!("phase map {n} x {n}"), |b| {
            b.iter(|| PhaseMap::compute(&StrengthGrid::new(&robot, slope, None, &kn, &ks), &|| {}).counts())
        });
    }
    // The target: a 1024 x 1024 risk map (p_fail and p_not_success) in under 1 s, at
    // the default spreads and at wide ones. The grid spans the built-in terrain's medians
    // at 20 degrees / 100 to x 100 (k_n) and / 1000 to x 100 (k_s), like `risk --map`.
    let mut group = c.benchmark_group("risk map");
    group.sample_size(10);
    let kn = Axis::new("k_n", 7e3, 7e7, 1024, AxisScale::Log).expect("axis");
    let ks = Axis::new("k_s", 1.4e3, 1.4e8, 1024, AxisScale::Log).expect("axis");
    for (cv_n, cv_s) in [(0.1, 0.2), (0.3, 0.5), (0.1, 0.01)] {
        let u = Uncertainty::new(cv_n, cv_s).expect("cv");
        group.bench_function(format!("1024 x 1024, cv {cv_n}/{cv_s}"), |b| {
            b.iter(|| {
                RiskMap::compute(&StrengthGrid::new(&robot, slope, None, &kn, &ks), u, &|| {}).p_fail.len()
            })
        });
    }
    group.finish();
    let ground = Ground::new(7e5, 1e6).expect("ground");
    let u = Uncertainty::new(0.2, 0.3).expect("cv");
    c.bench_function("regime_probabilities (quadrature)", |b| {
        b.iter(|| regime_probabilities(&robot, slope, &ground, u))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
