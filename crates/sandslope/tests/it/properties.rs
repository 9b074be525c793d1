//! Property tests over random valid robots and terrains (docs/model.md §3-§7).

use proptest::prelude::*;
use sandslope::model::{level_step_length, normal_equilibrium_depth};
use sandslope::{
    predict, Cause, Ground, Regime, Robot, RobotSpec, Slope, Terrain, TerrainPoint, TerrainSpec,
};

prop_compose! {
    fn robot()(
        mass_kg in 0.05f64..20.0,
        leg_radius_m in 0.01f64..0.3,
        width_frac in 0.05f64..1.0,
        hip_frac in 0.0f64..=1.0,
        leg_speed_rad_s in 0.5f64..20.0,
        stance_legs in 1u32..=6,
        response_time_s in 0.01f64..1.0,
        measured in proptest::option::weighted(0.2, 0.01f64..0.3),
    ) -> Robot {
        Robot::new(RobotSpec {
            mass_kg,
            leg_radius_m,
            leg_width_m: width_frac * leg_radius_m,
            hip_height_m: hip_frac * 2.0 * leg_radius_m,
            leg_speed_rad_s,
            stance_legs,
            response_time_s,
            leg_contact_area_m2: None,
            level_step_m: measured,
            min_step_m: None,
            ..RobotSpec::paper_hexapod()
        }).expect("generated within the valid ranges")
    }
}

fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo.ln()..hi.ln()).prop_map(f64::exp)
}

fn slope() -> impl Strategy<Value = Slope> {
    (0.0f64..60.0).prop_map(|d| Slope::from_degrees(d).expect("in range"))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn anchoring_time_within_half_stride(r in robot(), s in slope(), k_n in log_uniform(1e3, 1e9), k_s in log_uniform(1e3, 1e9)) {
        let p = predict(&r, s, &Ground::new(k_n, k_s).unwrap());
        if let Some(t1) = p.anchoring_time {
            prop_assert!(t1 >= -1e-12 && t1 <= r.stance_duration() + 1e-12, "t1 = {t1}, T/2 = {}", r.stance_duration());
        }
    }

    #[test]
    fn net_step_never_exceeds_level_step(r in robot(), s in slope(), k_n in log_uniform(1e3, 1e9), k_s in log_uniform(1e3, 1e9)) {
        let p = predict(&r, s, &Ground::new(k_n, k_s).unwrap());
        if let Some(step) = p.step {
            prop_assert!(step <= p.level_step * (1.0 + 1e-12) + 1e-15, "s = {step} > s* = {}", p.level_step);
        }
    }

    #[test]
    fn speed_non_decreasing_in_shear_strength(
        r in robot(), s in slope(), k_n in log_uniform(1e3, 1e9), k_s in log_uniform(1e3, 1e9), factor in 1.0f64..100.0,
    ) {
        let g = Ground::new(k_n, k_s).unwrap();
        let weak = predict(&r, s, &g);
        let strong = predict(&r, s, &Ground { k_s: k_s * factor, ..g });
        if let Some(v_weak) = weak.speed {
            // Anchoring at the weaker k_s implies anchoring at the stronger.
            let v_strong = strong.speed.expect("stronger sand anchors too");
            prop_assert!(v_strong >= v_weak - 1e-12 * v_weak.abs().max(1e-9), "{v_weak} -> {v_strong}");
        }
        // And the regime never gets worse with stronger sand (precedence order reversed).
        let rank = |r: Regime| Regime::ALL.iter().position(|&x| x == r).unwrap();
        prop_assert!(rank(strong.regime) >= rank(weak.regime));
    }

    #[test]
    fn regime_follows_precedence(
        r in robot(), s in slope(), k_n in log_uniform(1e3, 1e9), k_s in log_uniform(1e3, 1e9), repose in 1.0f64..89.0,
    ) {
        let g = Ground::new(k_n, k_s).unwrap().with_repose(Some(Slope::from_degrees(repose).unwrap()));
        let p = predict(&r, s, &g);
        let d_n = normal_equilibrium_depth(&r, s, k_n);
        let expected = if d_n >= r.max_depth() {
            Regime::Sinkage
        } else if s.degrees() >= repose || p.step.is_none_or(|x| x <= 0.0) {
            Regime::Slippage
        } else if p.step.unwrap() < r.min_step() {
            Regime::Metastable
        } else {
            Regime::Success
        };
        prop_assert_eq!(p.regime, expected);
        prop_assert_eq!(p.cause.regime(), p.regime);
        if p.regime == Regime::Sinkage {
            prop_assert_eq!(p.cause, Cause::NormalSinkage);
            prop_assert!(r.measured_level_step().is_some() || level_step_length(&r, s, d_n) == 0.0);
        }
    }

    #[test]
    fn interpolation_hits_points_and_holds_the_first_below(
        mut slopes in proptest::collection::btree_set(0u32..800, 1..6),
        values in proptest::collection::vec((log_uniform(1e3, 1e8), log_uniform(1e3, 1e8)), 6),
    ) {
        slopes.insert(100);
        let points: Vec<TerrainPoint> = slopes.iter().zip(values.iter().cycle()).map(|(&d, &(k_n, k_s))| TerrainPoint {
            slope_deg: f64::from(d) / 10.0, k_n, k_s, k_n_sd: None, k_s_sd: None,
        }).collect();
        let t = Terrain::new(TerrainSpec { name: None, repose_deg: None, points: points.clone() }).unwrap();
        for p in &points {
            let g = t.at(Slope::from_degrees(p.slope_deg).unwrap());
            prop_assert!((g.k_n - p.k_n).abs() <= 1e-9 * p.k_n && (g.k_s - p.k_s).abs() <= 1e-9 * p.k_s);
        }
        let first = &t.points()[0];
        if first.slope_deg > 0.0 {
            let g = t.at(Slope::from_degrees(first.slope_deg / 2.0).unwrap());
            prop_assert_eq!((g.k_n, g.k_s), (first.k_n, first.k_s));
        }
        // Between two points the value lies between theirs.
        for w in t.points().windows(2) {
            let mid = t.at(Slope::from_degrees(0.5 * (w[0].slope_deg + w[1].slope_deg)).unwrap());
            prop_assert!((mid.k_s - 0.5 * (w[0].k_s + w[1].k_s)).abs() <= 1e-9 * w[0].k_s.max(w[1].k_s));
        }
    }
}
