//! Criterion benchmarks of the phase map and the risk quadrature.
//!
//! `cargo bench -p sandslope --bench phase`

use criterion::{criterion_group, criterion_main, Criterion};
use sandslope::{
    regime_probabilities, Axis, AxisScale, Ground, PhaseMap, Robot, RobotSpec, Slope, Uncertainty,
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
            b.iter(|| PhaseMap::compute(&robot, slope, None, &kn, &ks, &|| {}).counts())
        });
    }
    let ground = Ground::new(7e5, 1e6).expect("ground");
    let u = Uncertainty::new(0.2, 0.3).expect("cv");
    c.bench_function("regime_probabilities (quadrature)", |b| {
        b.iter(|| regime_probabilities(&robot, slope, &ground, u))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
