//! Criterion benchmarks of the safe-slope limit (`risk::safe_slope_limit`, what
//! `sandslope risk --solve slope`, the report and the Python `safe_slope` run).
//!
//! `cargo bench -p sandslope --bench risk` (figures in docs/phase-and-risk.md).

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

use sandslope::risk::safe_slope_limit;
use sandslope::{Robot, RobotSpec, Terrain, TerrainPoint, TerrainSpec, UncertainTerrain};

/// A terrain table: (slope_deg, k_n, k_s, k_n_sd, k_s_sd) points and a repose angle.
fn terrain(repose_deg: f64, points: &[(f64, f64, f64, f64, f64)]) -> Terrain {
    Terrain::new(TerrainSpec {
        name: None,
        repose_deg: Some(repose_deg),
        points: points
            .iter()
            .map(|&(slope_deg, k_n, k_s, n_sd, s_sd)| TerrainPoint {
                slope_deg,
                k_n,
                k_s,
                k_n_sd: Some(n_sd),
                k_s_sd: Some(s_sd),
            })
            .collect(),
    })
    .expect("valid terrain")
}

fn bench(c: &mut Criterion) {
    let paper = RobotSpec::paper_hexapod();
    // The built-in `glass-beads-300um` preset (crates/sandslope-io/presets), rounded.
    let beads = terrain(
        25.0,
        &[
            (0.0, 7e5, 3.2607e6, 7e4, 5.306e5),
            (10.0, 7e5, 2.3856e6, 7e4, 3.714e5),
            (15.0, 7e5, 1.9480e6, 7e4, 2.918e5),
            (20.0, 7e5, 1.5104e6, 7e4, 2.122e5),
            (24.0, 7e5, 1.1604e6, 7e4, 1.486e5),
        ],
    );
    // examples/design/loose-sand.toml.
    let loose = terrain(32.0, &[(0.0, 3e5, 9e5, 4e4, 2e5), (25.0, 2.8e5, 3e5, 4e4, 1e5)]);
    let cases = [
        ("paper hexapod, glass beads", paper.clone(), UncertainTerrain::new(beads.clone(), None, None)),
        (
            "1 kg, glass beads, cv 0.3/0.5",
            RobotSpec { mass_kg: 1.0, ..paper.clone() },
            UncertainTerrain::new(beads, Some(0.3), Some(0.5)),
        ),
        ("paper hexapod, loose sand", paper, UncertainTerrain::new(loose, None, None)),
    ];
    let mut group = c.benchmark_group("safe_slope_limit");
    group.sample_size(10);
    for (name, spec, t) in cases {
        let robot = Robot::new(spec).expect("valid robot");
        let t = t.expect("valid uncertainty");
        group.bench_function(name, |b| {
            b.iter(|| safe_slope_limit(black_box(&robot), black_box(&t), 0.05).expect("max_risk in (0, 1)"))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
