//! The report's warnings, worded from its values in the order a reader needs them: a robot
//! other than the paper's without observations, tracks that could not be used, the simulator
//! section left out or not converged, the simulator's fit failed, and last the calibration's
//! own (a quantity at its search bound, a poor fit).

use sandslope::report::{Evidence, Report, SimulatorFitFailure, SimulatorLeftOut, TrackGap, UnusedTrack};
use sandslope::simulate::convergence::Refinement;
use sandslope::simulate::ConvergenceCheck;

use super::answer::another_robot;
use super::findings::calibration_warnings;

/// Every warning of `report`, built from `evidence`, in order.
pub(super) fn warnings(report: &Report, evidence: &Evidence) -> Vec<String> {
    let mut out = Vec::new();
    if report.plain_answer.untested {
        out.push(another_robot(evidence));
    }
    out.extend(report.unused_tracks.iter().map(unused_track));
    out.extend(report.simulator_left_out.as_ref().map(|why| left_out(why, &report.plain_answer.terrain)));
    let unconverged: Vec<String> =
        report.simulator_convergence.iter().filter(|c| !c.converged).map(unconverged_slope).collect();
    if !unconverged.is_empty() {
        out.push(format!(
            "the stride simulator's pitch-locked walk is not converged at {} (the tolerances: a quarter of the \
             time step or a tenth of the creep speed must leave its speed within 3% or 0.3 cm/s, its t1 within \
             1 ms and its regime; docs/simulate.md, \"Checking convergence\"): read those rows with care",
            unconverged.join("; ")
        ));
    }
    out.extend(report.simulator_fit_failures.iter().map(|f| match f {
        SimulatorFitFailure::Fit(e) => format!("the simulator's joint fit failed: {e}"),
        SimulatorFitFailure::Misses(e) => format!("the simulator fit's misses could not be walked: {e}"),
    }));
    if let Some(c) = &report.calibration {
        out.extend(calibration_warnings(c));
    }
    out
}

/// One unconverged slope and what moved: `22° (a quarter of the step: regime slippage to
/// metastable, speed 0.28 to 0.33 cm/s)`; a regime that changes while the speed stays within
/// its tolerance is a speed at the regimes' border (a walk within 0.3 cm/s of zero is a stall,
/// slippage, on either side of zero, docs/model.md §18, so at `s = 0` that border is the band's
/// edge, 0.3 cm/s; at `s_min` it is `s_min`'s).
fn unconverged_slope(c: &ConvergenceCheck) -> String {
    let moved: Vec<String> = c
        .refinements
        .iter()
        .filter(|r| !r.converged)
        .map(|r| {
            let refined = match r.refinement {
                Refinement::QuarterStep => "a quarter of the step",
                Refinement::TenthCreep => "a tenth of the creep speed",
            };
            let mut what = Vec::new();
            if !r.same_regime {
                what.push(format!("regime {} to {}", c.walk.regime, r.answer.regime));
            }
            if !r.speed_within || !r.same_regime {
                what.push(format!(
                    "speed {:.2} to {:.2} cm/s",
                    c.walk.speed_m_s * 100.0,
                    r.answer.speed_m_s * 100.0
                ));
            }
            if !r.t1_within {
                let ms = |t: Option<f64>| t.map_or("-".to_string(), |t| format!("{:.1}", t * 1000.0));
                what.push(format!("t1 {} to {} ms", ms(c.walk.t1_s), ms(r.answer.t1_s)));
            }
            if !r.spread_within {
                what.push(format!("steps' spread {:+.2} cm/s", r.step_speed_sd_change_m_s * 100.0));
            }
            if !r.same_regime && r.speed_within {
                what.push("a speed at the regimes' border".into());
            }
            format!("{refined}: {}", what.join(", "))
        })
        .collect();
    format!("{}° ({})", c.slope_deg, moved.join("; "))
}

/// A tracked slope's anchoring time or speed not used, for the user's terminal.
fn unused_track(u: &UnusedTrack) -> String {
    let (what, why) = match u.gap {
        TrackGap::NoAnchoredStep => ("anchoring time", format!("no anchored step among {} steps", u.steps)),
        TrackGap::NoAnchoringSd => {
            ("anchoring time", "its SD needs at least two anchored steps with different t1".to_string())
        }
        TrackGap::NoSpeedSd => (
            "observed speed",
            format!("its SD needs at least two steps with different speeds; found {} steps", u.steps),
        ),
    };
    format!("--tracks at {}° ({}): no {what} ({why}); not used", u.slope_deg, u.files.join(", "))
}

/// Why the simulator section is left out; `terrain` is the model's terrain as the page names it.
fn left_out(why: &SimulatorLeftOut, terrain: &str) -> String {
    let why = match why {
        SimulatorLeftOut::AtBound { name, value } => format!(
            "the model is the calibration on your observations, and its {name} ran to its search bound ({value:.3e}): \
             no terrain of yours, and so stiff that the simulator's walks would take minutes (see the calibration's \
             warnings and why it is unreliable)"
        ),
        SimulatorLeftOut::Implausible { key, value, slope_deg } => {
            let k = sandslope::terrain::K_PLAUSIBLE;
            format!(
                "the model's terrain ({terrain}) has {key} = {value:.3e} N/m^3 at {slope_deg}°, outside the plausible \
                 {:e} to {:e} N/m^3 (docs/model.md §7), where the simulator's walks take minutes; a calibration run \
                 to a search bound puts it there (see its warnings)",
                k.min, k.max
            )
        }
        SimulatorLeftOut::Refused(e) => e.clone(),
    };
    format!("the stride simulator section is left out: {why}")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A slope whose one step gives neither an anchoring-time SD nor a speed SD: two warnings
    /// naming the slope, the files and why.
    #[test]
    fn unused_tracks_are_named_with_why() {
        let u =
            |gap| UnusedTrack { slope_deg: 20.0, files: vec!["a.csv".into(), "b.csv".into()], steps: 1, gap };
        assert_eq!(
            unused_track(&u(TrackGap::NoAnchoringSd)),
            "--tracks at 20° (a.csv, b.csv): no anchoring time (its SD needs at least two anchored steps with \
             different t1); not used"
        );
        assert_eq!(
            unused_track(&u(TrackGap::NoAnchoredStep)),
            "--tracks at 20° (a.csv, b.csv): no anchoring time (no anchored step among 1 steps); not used"
        );
        assert_eq!(
            unused_track(&u(TrackGap::NoSpeedSd)),
            "--tracks at 20° (a.csv, b.csv): no observed speed (its SD needs at least two steps with different \
             speeds; found 1 steps); not used"
        );
    }

    /// A k_s of 3 x 10^10 N/m^3 lies beyond the plausible 10^10: the warning names the value,
    /// the slope and the range; a fit at its bound names the quantity and where it stopped.
    #[test]
    fn a_left_out_simulator_section_says_why() {
        let w = left_out(&SimulatorLeftOut::Implausible { key: "k_s", value: 3e10, slope_deg: 0.0 }, "stiff");
        assert!(w.contains("(stiff) has k_s = 3.000e10 N/m^3 at 0°") && w.contains("1e3 to 1e10"), "{w}");
        let w = left_out(&SimulatorLeftOut::AtBound { name: "plate_scale".into(), value: 1e4 }, "sand");
        assert!(
            w.starts_with("the stride simulator section is left out: ")
                && w.contains("plate_scale ran to its search bound (1.000e4)"),
            "{w}"
        );
    }

    /// A walk on the edge of the stall band (docs/model.md §18: 0.28 cm/s, a stall, slippage;
    /// 0.33 cm/s at a quarter of the step, metastable): within the speed's 0.3 cm/s, a regime
    /// changed: named with both speeds and as a speed at the regimes' border; a t1 that moves
    /// 1.5 ms names both t1s. (The 22 degree walk, 0.02 against -0.05 cm/s, is a stall at both
    /// and no longer warns.)
    #[test]
    fn an_unconverged_slope_names_what_moved() {
        use sandslope::regime::Regime;
        use sandslope::simulate::convergence::{RefinedWalk, WalkAnswer};
        let answer = |v: f64, t1: f64, regime| WalkAnswer {
            dt_s: 5e-4,
            creep_m_s: 1e-7,
            speed_m_s: v,
            speed_se_m_s: None,
            step_speed_sd_m_s: 0.0,
            t1_s: Some(t1),
            regime,
        };
        let refined = |a: WalkAnswer, speed_within, t1_within, same_regime| RefinedWalk {
            refinement: Refinement::QuarterStep,
            answer: a,
            speed_change_m_s: 0.0,
            t1_change_s: None,
            step_speed_sd_change_m_s: 0.0,
            speed_within,
            t1_within,
            same_regime,
            spread_within: true,
            converged: false,
        };
        let check = |walk: WalkAnswer, r: RefinedWalk| ConvergenceCheck {
            slope_deg: 22.0,
            walks: 1,
            walk,
            refinements: vec![r],
            converged: false,
            speed_tolerance: 0.03,
            speed_tolerance_m_s: 0.003,
            t1_tolerance_s: 0.001,
        };
        let walk = answer(0.0028, 0.0080, Regime::Slippage);
        let c = check(walk, refined(answer(0.0033, 0.0081, Regime::Metastable), true, true, false));
        assert_eq!(
            unconverged_slope(&c),
            format!(
                "22° (a quarter of the step: regime {} to {}, speed 0.28 to 0.33 cm/s, a speed at the regimes' border)",
                Regime::Slippage,
                Regime::Metastable
            )
        );
        let c = check(walk, refined(answer(0.0028, 0.0095, Regime::Slippage), true, false, true));
        assert_eq!(unconverged_slope(&c), "22° (a quarter of the step: t1 8.0 to 9.5 ms)");
    }
}
