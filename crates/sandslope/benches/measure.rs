//! Speed of the load-cell fits: one penetration and one shear recording of 10 000 samples
//! (a long, fast-logged recording: 125 s at 80 Hz) each.

use criterion::{criterion_group, criterion_main, Criterion};
use sandslope::measure::{clean, fit_penetration, fit_shear, RawRecording, ShearPlate};

fn recording(n: usize, shear: bool) -> RawRecording {
    let mut raw = RawRecording::default();
    for i in 0..n {
        let x = 0.045 * i as f64 / n as f64;
        // Deterministic wiggle in place of noise.
        let wiggle = 0.02 * ((i as f64) * 12.9898).sin();
        let f = if shear { 20.0 * (1.0 - (-x / 0.003).exp()) } else { 220.0 * (x - 0.002).max(0.0) };
        raw.position.push(Some(x));
        raw.force.push(Some(f + wiggle));
    }
    raw
}

fn bench(c: &mut Criterion) {
    let area = std::f64::consts::PI * 1e-4;
    let plate = ShearPlate::new(0.03, 0.02).unwrap();
    let pen = recording(10_000, false);
    let sh = recording(10_000, true);
    c.bench_function("clean + fit_penetration, 10k samples", |b| {
        b.iter(|| fit_penetration(&clean(&pen).unwrap().curve, area, None).unwrap())
    });
    c.bench_function("clean + fit_shear, 10k samples", |b| {
        b.iter(|| fit_shear(&clean(&sh).unwrap().curve, plate, None).unwrap())
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
