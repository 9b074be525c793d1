//! Criterion benchmarks of the stride simulator (`sandslope::simulate`, what `sandslope
//! simulate`, its `--slopes` sweep and the Python `simulate` run), on the built-in robot and
//! terrain at the default 32 elements per leg and the default integration step.
//!
//! Targets of issues 23 and 38: at least 1000 simulated seconds per wall second on one core, and a
//! 31-slope sweep of 10 s walks in under 2 s on 2 cores. `cargo bench -p sandslope --bench
//! simulate` (figures in docs/simulate.md).

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

use sandslope::{
    simulate, simulate_slopes, RobotSpec, Scenario, SignedSlope, SimSettings, Terrain, TerrainPoint,
    TerrainSpec,
};

/// The built-in `glass-beads-300um` preset (crates/sandslope-io/presets), rounded.
fn beads() -> Terrain {
    let points = [(0.0, 3.2607e6), (10.0, 2.3856e6), (15.0, 1.9480e6), (20.0, 1.5104e6), (24.0, 1.1604e6)];
    Terrain::new(TerrainSpec {
        name: None,
        repose_deg: Some(25.0),
        points: points
            .iter()
            .map(|&(slope_deg, k_s)| TerrainPoint { slope_deg, k_n: 7e5, k_s, k_n_sd: None, k_s_sd: None })
            .collect(),
    })
    .expect("valid terrain")
}

fn deg(d: f64) -> SignedSlope {
    SignedSlope::from_degrees(d).expect("a slope in (-90, 90)")
}

fn bench(c: &mut Criterion) {
    let robot = sandslope::Robot::new(RobotSpec::paper_hexapod()).expect("valid robot");
    let scenario = Scenario::new(robot, beads(), None, None).expect("valid scenario");
    let mut group = c.benchmark_group("simulate");
    group.sample_size(10);
    // One core: 10 s walks (the 1000 simulated seconds per wall second target means under
    // 10 ms each), level and at 10 degrees, pitch locked (the default) and free.
    let walk10 = SimSettings::new(10.0).unwrap();
    group.bench_function("one 10 s walk, level, one core", |b| {
        b.iter(|| simulate(black_box(&scenario), deg(0.0), &walk10).unwrap())
    });
    let locked = walk10.with_body_pitch(sandslope::simulate::BodyPitch::Locked);
    group.bench_function("one 10 s walk at 10 deg, pitch locked, one core", |b| {
        b.iter(|| simulate(black_box(&scenario), deg(10.0), &locked).unwrap())
    });
    let free = walk10.with_body_pitch(sandslope::simulate::BodyPitch::Free);
    group.bench_function("one 10 s walk at 10 deg, pitch free, one core", |b| {
        b.iter(|| simulate(black_box(&scenario), deg(10.0), &free).unwrap())
    });
    // Two cores (rayon): 31 slopes of 10 s walks, 0 to 30 degrees, as `simulate --slopes 0:30:31`.
    let slopes: Vec<SignedSlope> = (0..31).map(|d| deg(f64::from(d))).collect();
    group.bench_function("31 slopes x 10 s walks, all cores", |b| {
        b.iter(|| simulate_slopes(black_box(&scenario), &slopes, &walk10).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
