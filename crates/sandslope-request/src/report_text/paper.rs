//! The comparison with the paper's numbers in words: each row's quantity, the paper's and the
//! model's values as the paper writes them, the rule and why the row has its basis, from the
//! values [`sandslope::paper::compare_with_paper`] decides (docs/model.md §12).

use crate::format::Explain;
use sandslope::paper::{PaperComparison, Reading, SpeedBasis};

/// Writes every row's `quantity`, `paper`, `model`, `rule` and `basis_note` from its reading.
pub(super) fn word_paper_rows(rows: &mut [PaperComparison]) {
    for r in rows {
        let (quantity, paper, model, rule, note) = words(&r.reading);
        r.quantity = quantity;
        r.paper = paper;
        r.model = model;
        r.rule = rule.into();
        r.basis_note = note.into();
    }
}

/// A ratio as the row shows it: two decimals, `-` when there is none.
fn ratio_text(ratio: Option<f64>) -> String {
    ratio.map_or("-".into(), |r| format!("{r:.2}"))
}

/// One row's words: quantity, paper, model, rule, basis note.
fn words(reading: &Reading) -> (String, String, String, &'static str, &'static str) {
    match reading {
        Reading::Speed { slope_deg, mean_m_s, sd_m_s, speed_m_s, regime, cause, why } => (
            format!("speed at {slope_deg} deg (0.35 kg)"),
            format!("{:.2} ± {:.2} cm/s", mean_m_s * 100.0, sd_m_s * 100.0),
            match speed_m_s {
                Some(v) if !regime.is_failure() => format!("{:.2} cm/s ({regime})", v * 100.0),
                _ => format!("- ({regime}: {})", cause.explain()),
            },
            "within 2 SD",
            match why {
                SpeedBasis::HipHeightTuned => {
                    "the hip height h was chosen to put the level-sand ceiling at this speed"
                }
                SpeedBasis::FittedToSpeeds => "the model's k_s was fitted to the paper's five speeds",
                SpeedBasis::NothingFitted => "no input was fitted to the paper's speeds",
            },
        ),
        Reading::ShearRatio { ratio, input } => (
            "k_s(20 deg) / k_s(0)".into(),
            "about 0.40".into(),
            ratio_text(*ratio),
            "within 0.10",
            if *input {
                "the force tests' 0.40 is an input of the calibration (held by its SD)"
            } else {
                "the model's k_s did not take the paper's ratio as input"
            },
        ),
        Reading::NormalRatio { ratio, input } => (
            "k_n(20 deg) / k_n(0)".into(),
            "nearly unchanged (1)".into(),
            ratio_text(*ratio),
            "within 0.15",
            if *input {
                "k_n was assumed constant with slope, as the paper's text says"
            } else {
                "the model's k_n did not take the paper's statement as input"
            },
        ),
        Reading::T1Rises { t1_s } => (
            "anchoring time t1 rises with slope (0 to 24 deg)".into(),
            "monotone increase".into(),
            t1_s.iter()
                .map(|t| t.map_or("-".into(), |t| format!("{:.0}", t * 1000.0)))
                .collect::<Vec<_>>()
                .join(", ")
                + " ms",
            "strictly increasing",
            "any k_s that falls with slope makes d_s and so t1 rise (docs/model.md §4); the paper prints no t1 values to test",
        ),
        Reading::StepPeriod { half_s } => (
            "time between tripod touchdowns, T/2".into(),
            "0.5 s".into(),
            format!("{half_s:.3} s"),
            "within 1%",
            "T/2 = π/ω follows from the paper's leg speed",
        ),
        Reading::HeavyRobot { mass_kg, slope_deg, claim, model } => (
            format!("regime of a {mass_kg} kg robot at {slope_deg} deg"),
            claim.to_string(),
            match model {
                None => "-".into(),
                Some((regime, Some(step), _)) => format!("{regime} (step {:.1} mm)", step * 1000.0),
                Some((regime, None, cause)) => format!("{regime} ({})", cause.explain()),
            },
            "same regime",
            "no input was chosen to match it",
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sandslope::regime::{Cause, Regime};

    /// The paper's rows written by hand: 4.98 ± 0.32 cm/s at 20 deg (Fig. 3a's 0.0498 and
    /// 0.0032 m/s), a model speed of 0.0435 m/s as 4.35 cm/s with its regime, a ratio of 0.4
    /// as 0.40, a t1 of 0.0123 s as 12 ms and a missing one as `-`, T/2 = 0.4996 s as 0.500 s,
    /// and a 1 kg robot's step of 0.0123 m as 12.3 mm.
    #[test]
    fn rows_are_worded_from_their_values() {
        let w = |r: Reading| words(&r);
        let (q, p, m, rule, _) = w(Reading::Speed {
            slope_deg: 20.0,
            mean_m_s: 0.0498,
            sd_m_s: 0.0032,
            speed_m_s: Some(0.0435),
            regime: Regime::Success,
            cause: Cause::RobustStep,
            why: SpeedBasis::NothingFitted,
        });
        assert_eq!(
            (q.as_str(), p.as_str(), rule),
            ("speed at 20 deg (0.35 kg)", "4.98 ± 0.32 cm/s", "within 2 SD")
        );
        assert_eq!(m, format!("4.35 cm/s ({})", Regime::Success));
        assert_eq!(w(Reading::ShearRatio { ratio: Some(0.4), input: false }).2, "0.40");
        assert_eq!(w(Reading::NormalRatio { ratio: None, input: true }).2, "-");
        assert_eq!(w(Reading::T1Rises { t1_s: vec![Some(0.0123), None] }).2, "12, - ms");
        assert_eq!(w(Reading::StepPeriod { half_s: 0.4996 }).2, "0.500 s");
        let heavy = w(Reading::HeavyRobot {
            mass_kg: 1.0,
            slope_deg: 24.0,
            claim: Regime::Metastable,
            model: Some((Regime::Metastable, Some(0.0123), Cause::RobustStep)),
        });
        assert_eq!(heavy.0, "regime of a 1 kg robot at 24 deg");
        assert_eq!(heavy.2, format!("{} (step 12.3 mm)", Regime::Metastable));
    }
}
