//! The simulator section's reasons in words: where the stride simulator and the closed form
//! part at each slope ([`Parting`]), and why the simulator's joint fit misses an observed speed
//! ([`SimulatorMiss`]), each short (the page's paragraph and docs/simulate.md explain each
//! mechanism once).

use sandslope::report::{Parting, SimulatorMiss, SimulatorRecord, AGREE_WITHIN};

/// Fills the reason of every record and every miss of the simulator's fit.
pub(super) fn word_simulator(records: &mut [SimulatorRecord], misses: &mut [SimulatorMiss]) {
    for r in records {
        r.why = parting(r);
    }
    for m in misses {
        m.why = miss_reason(m);
    }
}

/// Where the simulator's pitch-locked walk and the closed form part at one slope.
fn parting(r: &SimulatorRecord) -> String {
    match r.parting {
        Parting::Tumbled { at_s } => {
            format!("tumbled: the body pitched past 90° at t = {at_s:.2} s (the closed form has no pitch)")
        }
        Parting::NoClosedFormSpeed => format!(
            "the closed form rules a speed out ({}); the simulated walk is {} ({})",
            r.closed_form_regime.name(),
            r.simulated_regime.name(),
            r.simulated_cause.name()
        ),
        Parting::Within { relative } => {
            format!("within {:.0}% ({:+.0}%)", AGREE_WITHIN * 100.0, relative * 100.0)
        }
        Parting::Vaults { relative, rolling_step_m, level_step_m } => format!(
            "legs roll, body vaults ({:+.0}%): step {:.2} × the rigid rolling {}, {:.1} × s* = {}",
            relative * 100.0,
            r.simulated_step_m / rolling_step_m,
            mm(Some(rolling_step_m)),
            r.simulated_step_m / level_step_m,
            mm(Some(level_step_m))
        ),
        Parting::SlidesBack { relative } => format!(
            "slides back ({:+.0}%): net step {}, slip before anchoring {} against {} \
             (docs/simulate.md, \"The mechanisms across the slopes\")",
            relative * 100.0,
            mm(Some(r.simulated_step_m)),
            mm(r.simulated_slip_m),
            mm(r.closed_form_slip_m)
        ),
        Parting::Slower { relative } => format!(
            "slower by {:.0}%: slip before anchoring {} against {}; not yet explained",
            -relative * 100.0,
            mm(r.simulated_slip_m),
            mm(r.closed_form_slip_m)
        ),
    }
}

/// Why the fit's walk misses the observation, and what the k_s scan reaches there.
fn miss_reason(m: &SimulatorMiss) -> String {
    let cm = |v: f64| format!("{:.1} cm/s", v * 100.0);
    let what = if let Some(t) = m.pitch_over_s {
        format!("the body pitches over (past 90° at t = {t:.2} s)")
    } else if m.fitted_m_s <= 0.0 {
        format!("the robot makes no upslope progress ({}, {})", m.regime.name(), m.cause.name())
    } else if m.fitted_m_s > m.observed_m_s {
        format!(
            "the legs roll and the body vaults over them: step {} = {:.2} × the rigid rolling step, {:.1} × the \
             closed form's s*",
            mm(Some(m.step_m)),
            m.step_m / m.rolling_step_m,
            m.step_m / m.level_step_m
        )
    } else {
        format!(
            "it walks slower ({}; slip before anchoring {}, t1 {})",
            m.regime.name(),
            mm(m.slip_m),
            m.t1_s.map_or("none".into(), |t| format!("{:.0} ms", t * 1e3))
        )
    };
    let reach = &m.reach_m_s;
    let (lo, hi) = reach.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let (first, last) =
        (m.reach_k_s.first().copied().unwrap_or(f64::NAN), m.reach_k_s.last().copied().unwrap_or(f64::NAN));
    let scan =
        format!("across leg k_s from {first:.0e} to {last:.0e} N/m³ it walks {} to {} here", cm(lo), cm(hi));
    let reach = match m.reached_between {
        None => format!("{scan}: none of these {} walks reaches {}", reach.len(), cm(m.observed_m_s)),
        Some([a, b]) => format!(
            "{scan}: the walks bracket {} first between k_s = {a:.0e} and {b:.0e}, where the joint fit, which \
             ties the slopes together through the k_s law, does not go",
            cm(m.observed_m_s)
        ),
    };
    format!("{what}; {reach}")
}

/// A length in millimetres for the reasons, `none` where undefined.
fn mm(v: Option<f64>) -> String {
    v.map_or("none".into(), |v| format!("{:.1} mm", v * 1e3))
}

#[cfg(test)]
mod tests {
    use super::*;
    use sandslope::simulate::MotionCause;
    use sandslope::{Cause, Regime};

    /// A level walk at 21.0 cm/s against the closed form's 15.0 (+40%) with a step of 10.5 cm,
    /// 1.05 times a 10.0 cm rolling step and 1.5 times an s* of 7.0 cm: the legs roll; at
    /// 14.0 against 15.0 (-7%) they agree within 15%; a net step of -2 mm slides back.
    #[test]
    fn the_reasons_the_simulator_and_the_closed_form_part_are_worded() {
        let mut r = SimulatorRecord {
            slope_deg: 0.0,
            observed_m_s: None,
            observed_sd_m_s: None,
            simulated_m_s: 0.21,
            closed_form_m_s: Some(0.15),
            simulated_regime: Regime::Success,
            simulated_cause: MotionCause::Model(Cause::RobustStep),
            closed_form_regime: Regime::Success,
            simulated_t1_s: None,
            closed_form_t1_s: None,
            simulated_slip_m: Some(0.001),
            closed_form_slip_m: Some(0.004),
            simulated_step_m: 0.105,
            closed_form_step_m: Some(0.075),
            max_pitch_deg: 0.0,
            pitch_over_s: None,
            pitch_free_m_s: 0.21,
            pitch_free_regime: Regime::Success,
            pitch_free_cause: MotionCause::Model(Cause::RobustStep),
            scaling_min_m_s: 0.2,
            scaling_max_m_s: 0.22,
            scaling_regimes: [Regime::Success; 3],
            scaling_regimes_agree: true,
            agree: false,
            why: String::new(),
            parting: Parting::Vaults { relative: 0.4, rolling_step_m: 0.1, level_step_m: 0.07 },
        };
        assert_eq!(
            parting(&r),
            "legs roll, body vaults (+40%): step 1.05 × the rigid rolling 100.0 mm, 1.5 × s* = 70.0 mm"
        );
        r.parting = Parting::Within { relative: -1.0 / 15.0 };
        assert_eq!(parting(&r), "within 15% (-7%)");
        (r.simulated_step_m, r.parting) = (-0.002, Parting::SlidesBack { relative: -1.2 });
        assert!(
            parting(&r).starts_with(
                "slides back (-120%): net step -2.0 mm, slip before anchoring 1.0 mm against 4.0 mm"
            ),
            "{}",
            parting(&r)
        );
    }

    /// The paper's 15.7 cm/s on level sand against a fitted walk at 30.0 cm/s whose legs roll
    /// (step 15.0 cm, 1.25 times a 12.0 cm rolling step, 2.5 times s* = 6.0 cm), and a scan
    /// from 10⁴ to 10⁷ N/m³ that walks 20.0 cm/s to 31.0 cm/s: none of its 7 walks reaches it.
    #[test]
    fn a_miss_names_the_mechanism_and_what_the_scan_reaches() {
        let m = SimulatorMiss {
            slope_deg: 0.0,
            observed_m_s: 0.157,
            observed_sd_m_s: 0.005,
            fitted_m_s: 0.3,
            miss_sd: 28.6,
            regime: Regime::Success,
            cause: MotionCause::Model(Cause::RobustStep),
            pitched_over: false,
            step_m: 0.15,
            rolling_step_m: 0.12,
            level_step_m: 0.06,
            reach_k_s: sandslope::report::REACH_K_S.to_vec(),
            reach_m_s: vec![0.2, 0.25, 0.28, 0.3, 0.31, 0.31, 0.31],
            reached_between: None,
            why: String::new(),
            pitch_over_s: None,
            slip_m: None,
            t1_s: None,
        };
        assert_eq!(
            miss_reason(&m),
            "the legs roll and the body vaults over them: step 150.0 mm = 1.25 × the rigid rolling step, 2.5 × the \
             closed form's s*; across leg k_s from 1e4 to 1e7 N/m³ it walks 20.0 cm/s to 31.0 cm/s here: none of these 7 \
             walks reaches 15.7 cm/s"
        );
    }
}
