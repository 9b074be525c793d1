//! What cannot hold the body on the steep slope (issue 59 item 1; docs/simulate.md, "What
//! cannot hold the body at 24 degrees"): the stance tripod in mid-stance, whose along-slope
//! push is its normal load times a ratio that, under the `motion` and `li2013` scalings, the
//! generic coefficients fix whatever k_s (each element's stress is one scale times the generic
//! stress for its direction of motion, docs/model.md §16), and which stays below gravity's
//! pull at 24 degrees; under `components` the push grows with k_s / k_n and holds.

use super::tests::walker;
use super::*;
use crate::model::tests::paper_robot;
use crate::model::G;
use crate::terrain::Ground;

/// Mean along-slope sand force on the stance tripod over mid-stance (100 to 400 ms after each
/// touchdown, steps 2 to 5), N, and the body's net displacement over that window, m.
fn mid_stance(slope_deg: f64, k_s: f64, scaling: RftScaling) -> (f64, f64) {
    let robot = paper_robot();
    let dt = 1e-3;
    let settings = SimSettings::new(3.0).unwrap().with_rft_scaling(scaling);
    let ground = Ground::new(7e5, k_s).unwrap();
    let mut w = walker(&robot, &ground, slope_deg.to_radians(), &settings, dt);
    w.settle(settings.settle_s);
    let half = robot.stance_duration();
    let run = w.run((3.0 / dt) as usize, half, 120.0);
    let (mut force, mut n, mut moved) = (0.0, 0usize, 0.0);
    for k in 2..6 {
        let (a, b) = (((k as f64 * half + 0.1) / dt) as usize, ((k as f64 * half + 0.4) / dt) as usize);
        for g in &run.groups[a..b] {
            force += g.tripod[k % 2][0];
            n += 1;
        }
        moved += run.x[b] - run.x[a];
    }
    (force / n as f64, moved)
}

/// At 24 degrees gravity pulls the 0.35 kg body down the slope with m g sin 24 = 1.397 N (by
/// hand). Under `motion` the stance tripod's mid-stance push stays below it at every k_s from
/// the plate's 1e5 to 1e7 N/m^3 (two decades: a law whose push grew with k_s would pass it),
/// and the body slides back through mid-stance; under `li2013` k_s is not used at all, so the
/// push is the same to the bit at 1e5 and 1e7. Under `components` at k_s = 1e6 and 1e7 the
/// push exceeds gravity's pull and the body climbs through mid-stance.
#[test]
fn at_24_degrees_the_stance_tripod_cannot_hold_the_body_whatever_k_s_under_motion() {
    let pull = paper_robot().mass() * G * 24f64.to_radians().sin();
    assert!((pull - 1.3966).abs() < 1e-3, "{pull}");
    for k_s in [1e5, 1e6, 1e7] {
        let (push, moved) = mid_stance(24.0, k_s, RftScaling::Motion);
        assert!(push < pull, "motion, k_s {k_s}: push {push} N against {pull}");
        assert!(moved < 0.0, "motion, k_s {k_s}: moved {moved} m in mid-stance");
    }
    let (a, _) = mid_stance(24.0, 1e5, RftScaling::Li2013);
    let (b, _) = mid_stance(24.0, 1e7, RftScaling::Li2013);
    assert_eq!(a, b);
    assert!(a < pull);
    for k_s in [1e6, 1e7] {
        let (push, moved) = mid_stance(24.0, k_s, RftScaling::Components);
        assert!(push > pull, "components, k_s {k_s}: push {push} N against {pull}");
        assert!(moved > 0.0, "components, k_s {k_s}: moved {moved} m");
    }
}

/// The default step (docs/model.md §17): `T / 2000` with the pitch locked, `T / 16000` with it
/// free (the paper's robot: T = 1 s, so 0.5 ms and 62.5 us); a step the user gives is kept
/// either way.
#[test]
fn the_free_body_walks_at_an_eighth_of_the_locked_step_by_default() {
    let s = Scenario::new(paper_robot(), super::tests::builtin_terrain(), None, None).unwrap();
    let slope = Slope::from_degrees(15.0).unwrap();
    // T = 2 pi / omega = 1 s for the paper's robot (omega = 2 pi rad/s).
    let t = paper_robot().stride_period();
    assert!((t - 1.0).abs() < 1e-12);
    let locked = SimSettings::new(1.5).unwrap();
    let free = locked.with_body_pitch(BodyPitch::Free);
    assert_eq!(integration_step_for(&s, slope, &locked).unwrap(), t / 2000.0);
    assert_eq!(integration_step_for(&s, slope, &free).unwrap(), t / 16000.0);
    assert_eq!(integration_step(&s, slope, None).unwrap(), t / 2000.0);
    let given = free.with_dt(4e-4).unwrap();
    assert_eq!(integration_step_for(&s, slope, &given).unwrap(), 4e-4);
    let walked = simulate(&s, SignedSlope::from_degrees(15.0).unwrap(), &free).unwrap();
    assert_eq!(walked.summary.dt_s, t / 16000.0);
}

/// The scaling spread at 24 degrees (docs/simulate.md, "The scaling as model uncertainty"):
/// each walk under its own scaling, the range spanning them, and the regimes apart, since under
/// `motion` the stance tripod cannot hold the body there and under `components` it can (the
/// test above, against gravity's pull by hand). `li2013` reads no k_s, so its walk is the same
/// to the bit on sand of ten times the k_s.
#[test]
fn the_scaling_spread_walks_each_scaling_and_spans_them() {
    let at = |k_s: f64| {
        let s =
            Scenario::new(paper_robot(), crate::terrain::Terrain::constant(7e5, k_s).unwrap(), None, None)
                .unwrap();
        spread::scaling_spread(&s, SignedSlope::from_degrees(24.0).unwrap(), &SimSettings::new(3.0).unwrap())
            .unwrap()
    };
    let (a, b) = (at(1e6), at(1e7));
    for (w, s) in a.walks.iter().zip(spread::SCALINGS) {
        assert_eq!(w.rft_scaling, s);
        assert!(a.min_speed_m_s <= w.speed_m_s && w.speed_m_s <= a.max_speed_m_s);
    }
    assert!(a.walks.iter().any(|w| w.speed_m_s == a.min_speed_m_s));
    assert!(a.walks.iter().any(|w| w.speed_m_s == a.max_speed_m_s));
    assert!(a.min_speed_m_s < 0.0 && a.max_speed_m_s > 0.0);
    assert!(!a.regimes_agree);
    assert_eq!(a.regimes[0], Regime::Slippage);
    assert_eq!(a.walks[1].speed_m_s, b.walks[1].speed_m_s);
}
