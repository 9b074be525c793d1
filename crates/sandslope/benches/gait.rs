//! One hour of motion capture at 120 frames/s (432,000 frames) through the whole tracking
//! pipeline (`sandslope::gait::analyse`: direction estimate, projection, gap handling,
//! zero-phase low pass and differentiation, touchdown offset, 7,200 steps, stride curve).
//! Target: well under a second in release mode. Run: `cargo bench -p sandslope --bench gait`.

use criterion::{criterion_group, criterion_main, Criterion};
use rand::{RngExt, SeedableRng};
use sandslope::gait::synthetic::StepProfile;
use sandslope::gait::{analyse, GaitOptions, Recording};

fn one_hour() -> Vec<[f64; 3]> {
    let profile = StepProfile::new(0.5, 0.12, 0.40, 0.15, 0.28).unwrap();
    let mut rng = rand::rngs::StdRng::seed_from_u64(1);
    let mut gauss = move || {
        let (u1, u2): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    };
    let (c, s) = (20f64.to_radians().cos(), 20f64.to_radians().sin());
    (0..432_000)
        .map(|i| {
            // An occlusion of 5 frames every 10 s, and of 40 frames every 5 minutes.
            if i % 1200 < 5 || i % 36_000 < 40 {
                return [f64::NAN; 3];
            }
            let t = i as f64 / 120.0;
            let x = profile.position(t + 1.0);
            [
                c * x + 3e-4 * gauss(),
                0.01 * (std::f64::consts::TAU * t).sin() + 3e-4 * gauss(),
                s * x + 3e-4 * gauss(),
            ]
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let positions = one_hour();
    let options = GaitOptions::new(1.0).unwrap();
    let rec =
        Recording { positions: &positions, frame_rate_hz: 120.0, start_time_s: 0.0, touchdowns_s: None };
    let check = analyse(&[rec], &options).unwrap();
    assert!(check.summary.steps > 7000);
    let mut group = c.benchmark_group("gait");
    group.sample_size(20);
    group.bench_function("analyse one hour at 120 fps (432k frames)", |b| {
        b.iter(|| analyse(std::hint::black_box(&[rec]), &options).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
