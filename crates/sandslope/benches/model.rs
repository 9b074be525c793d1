//! Benchmarks of the model call and the analyses built on it.
//!
//! `cargo bench -p sandslope --bench model`

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

use sandslope::{
    critical_shear_strength, predict, regime_probabilities, Ground, Robot, RobotSpec, Slope, StepTarget,
    Uncertainty,
};

fn paper_robot() -> Robot {
    Robot::new(RobotSpec::paper_hexapod()).unwrap()
}

fn bench(c: &mut Criterion) {
    let robot = paper_robot();
    let slope = Slope::from_degrees(20.0).unwrap();
    let ground = Ground::new(7e5, 1.4e6).unwrap();
    c.bench_function("predict", |b| {
        b.iter(|| predict(black_box(&robot), black_box(slope), black_box(&ground)))
    });
    c.bench_function("critical_shear_strength", |b| {
        b.iter(|| {
            critical_shear_strength(black_box(&robot), black_box(slope), 7e5, false, StepTarget::Robust)
        })
    });
    let u = Uncertainty::new(0.2, 0.3).unwrap();
    c.bench_function("regime_probabilities", |b| {
        b.iter(|| regime_probabilities(black_box(&robot), black_box(slope), black_box(&ground), u))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
