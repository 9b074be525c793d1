//! What sets t1 on the slopes (docs/simulate.md, "t1 and the contact scaling"): the legs'
//! strength in shear against the body's weight. On the built-in terrain's legs (k_s 3.3e6
//! N/m^3 level, the closed form's leg strength) the new tripod's along-slope resistance grows
//! so fast that it anchors as soon as it lifts the body off its belly, and t1 is that lift's
//! time, about the same at every slope; on legs as weak in shear as the force tests' plate
//! (data/example-force-tests.toml, 1e5 N/m^3 level and 40% of it at 20 degrees, about where
//! `calibrate --model simulate` puts the legs) the body slides back on its new legs until
//! their push passes gravity's pull, which takes longer the steeper the slope: the paper's
//! phase 1.

use super::tests::builtin_terrain;
use super::*;
use crate::model::tests::paper_robot;
use crate::model::G;
use crate::terrain::{Terrain, TerrainPoint, TerrainSpec};

/// The force tests' terrain (data/example-force-tests.toml): k_s 1e5 N/m^3 level and 4e4 at
/// 20 degrees, linear in the slope (extrapolated to 24 degrees, 2.8e4), k_n 7e5.
fn plate_terrain() -> Terrain {
    let pt = |slope_deg, k_s| TerrainPoint { slope_deg, k_n: 7e5, k_s, k_n_sd: None, k_s_sd: None };
    Terrain::new(TerrainSpec {
        name: None,
        repose_deg: Some(25.0),
        points: vec![pt(0.0, 1e5), pt(20.0, 4e4)],
    })
    .unwrap()
}

/// A 3 s walk, pitch locked, the default step.
fn walk(terrain: Terrain, scaling: RftScaling, slope_deg: f64) -> SimSummary {
    let s = Scenario::new(paper_robot(), terrain, None, None).unwrap();
    let settings = SimSettings::new(3.0).unwrap().with_rft_scaling(scaling);
    simulate(&s, SignedSlope::from_degrees(slope_deg).unwrap(), &settings).unwrap().summary
}

/// `(t1, s1, lowest speed in phase 1)` at 10, 15, 20 and 24 degrees.
fn phase1_on_slopes(terrain: &Terrain, scaling: RftScaling) -> Vec<(f64, f64, f64)> {
    [10.0, 15.0, 20.0, 24.0]
        .into_iter()
        .map(|deg| {
            let m = walk(terrain.clone(), scaling, deg);
            (m.t1_s.unwrap(), m.slip_m.unwrap(), m.phase1.unwrap().min_speed_m_s)
        })
        .collect()
}

/// A body that slides from rest down a slope with nothing holding it travels `1/2 g
/// sin(theta) t^2` in `t`: phase 1's slip can be no more, since the new legs push up the slope.
fn free_slide(slope_deg: f64, t: f64) -> f64 {
    0.5 * G * slope_deg.to_radians().sin() * t * t
}

/// On the force tests' legs, under the default law, pitch locked: no backward slip on level
/// sand; on the slopes t1 rises monotonically (by more than half again from 10 to 24 degrees),
/// the slip grows and the lowest speed falls with the slope, and each slip is within the free
/// slide's bound over its own t1: the paper's phase 1 (measured as docs/simulate.md's table
/// "plate-strength legs": t1 35 to 136 ms).
#[test]
fn on_legs_as_weak_in_shear_as_the_force_tests_plate_t1_rises_with_the_slope() {
    let terrain = plate_terrain();
    let level = walk(terrain.clone(), RftScaling::Motion, 0.0);
    assert_eq!(level.slip_m, Some(0.0), "level: {:?}", level.phase1);
    let slopes = [10.0, 15.0, 20.0, 24.0];
    let p = phase1_on_slopes(&terrain, RftScaling::Motion);
    for (k, &(t1, s1, low)) in p.iter().enumerate() {
        assert!(s1 > 0.0 && low < 0.0 && s1 < free_slide(slopes[k], t1), "{} deg: {:?}", slopes[k], p[k]);
        if k > 0 {
            let (t0, s0, l0) = p[k - 1];
            assert!(t1 > t0 && s1 > s0 && low < l0, "{} deg after {}: {p:?}", slopes[k], slopes[k - 1]);
        }
    }
    assert!(p[3].0 > 1.5 * p[0].0, "{p:?}");
}

/// Under `li2013` the legs' along-slope resistance scales with k_n, not the built-in k_s
/// (k_s is not read): t1 rises monotonically with the slope on the built-in terrain too, the
/// slip grows and stays within the free slide's bound.
#[test]
fn under_li2013_t1_rises_with_the_slope_on_the_built_in_terrain() {
    let slopes = [10.0, 15.0, 20.0, 24.0];
    let p = phase1_on_slopes(&builtin_terrain(), RftScaling::Li2013);
    for (k, &(t1, s1, low)) in p.iter().enumerate() {
        assert!(s1 > 0.0 && low < 0.0 && s1 < free_slide(slopes[k], t1), "{} deg: {:?}", slopes[k], p[k]);
        if k > 0 {
            assert!(t1 > p[k - 1].0 && s1 > p[k - 1].1, "{} deg: {p:?}", slopes[k]);
        }
    }
}

/// On the built-in terrain's legs, 33 times the plate's strength in shear, the new tripod
/// anchors as soon as it lifts the body: every slope's t1 lies within 3 ms of the others'
/// (measured 7.4 to 9.7 ms) and is shorter than the weak legs' t1 at the same slope by more
/// than half. The slope barely moves t1 and the paper's rise does not appear: the mechanism,
/// not the scheme (converged: `phase1_tests`).
#[test]
fn on_the_built_in_legs_t1_is_the_lift_and_does_not_rise_with_the_slope() {
    let slopes = [10.0, 15.0, 20.0, 24.0];
    let strong = phase1_on_slopes(&builtin_terrain(), RftScaling::Motion);
    let weak = phase1_on_slopes(&plate_terrain(), RftScaling::Motion);
    let t1s: Vec<f64> = strong.iter().map(|p| p.0).collect();
    let (lo, hi) = t1s.iter().fold((f64::INFINITY, 0.0f64), |(a, b), &t| (a.min(t), b.max(t)));
    assert!(lo > 0.0 && hi - lo < 3e-3, "t1 {t1s:?}");
    for k in 0..4 {
        let t1 = strong[k].0;
        assert!(t1 < 0.5 * weak[k].0, "{} deg: t1 {t1} against the weak legs' {}", slopes[k], weak[k].0);
    }
}

/// The free body on the force tests' legs, the free default step: t1 rises from 10 to 15 to
/// 20 degrees (measured 63, 106, 144 ms, docs/simulate.md's free "plate-strength legs" table),
/// where on the built-in legs it does not exceed 14 ms at any of them (8.6, 12.4, 13.4): the
/// same mechanism as the locked body's. (At 24 degrees the free body on these legs sinks.)
#[test]
fn the_free_body_on_weak_legs_t1_rises_with_the_slope_too() {
    let free = |terrain: Terrain, deg: f64| {
        let s = Scenario::new(paper_robot(), terrain, None, None).unwrap();
        let settings = SimSettings::new(3.0).unwrap().with_body_pitch(BodyPitch::Free);
        simulate(&s, SignedSlope::from_degrees(deg).unwrap(), &settings).unwrap().summary.t1_s.unwrap()
    };
    let weak: Vec<f64> = [10.0, 15.0, 20.0].map(|d| free(plate_terrain(), d)).to_vec();
    let strong: Vec<f64> = [10.0, 15.0, 20.0].map(|d| free(builtin_terrain(), d)).to_vec();
    assert!(weak[0] < weak[1] && weak[1] < weak[2], "weak legs' t1 {weak:?}");
    assert!(strong.iter().all(|&t| t < 0.02) && weak[0] > 0.04, "strong {strong:?}, weak {weak:?}");
}
