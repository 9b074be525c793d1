//! The report's findings worded from its values: the goodness-of-fit sentence, the
//! disagreements (failing comparisons, the per-slope inversion, the calibration's floor and
//! plate scale) and the calibration's warnings.

use sandslope::calibrate::{CalibrationWarning, Parameter};
use sandslope::report::{
    Extrapolation, ForceTests, NoFloorFit, Report, ReportCalibration, SpeedInversion, SpeedRecord,
};

use super::{format_p, sci};

/// Which chi^2 tests the model, in words: the fit without the floor's, when it has degrees
/// of freedom left.
pub(super) fn goodness_of_fit(no_floor: Option<NoFloorFit>) -> String {
    match no_floor.and_then(|n| n.p_value.map(|p| (n, p))) {
        Some((n, p)) => format!(
            "The goodness-of-fit test is the fit without the floor: χ² = {:.1} on {} dof, p = {}. With the floor free, χ²/dof near 1 to 2 is built in (the floor grows until it is), so that χ² tests nothing.",
            n.chi_squared,
            n.dof,
            format_p(p)
        ),
        None => "The fit without the floor has no degrees of freedom left: no goodness-of-fit test is possible on this evidence.".into(),
    }
}

/// The disagreements worded from the report's values, in order: failing comparisons, the
/// inversion, the calibration.
pub(super) fn disagreements(report: &Report, forces: &ForceTests) -> Vec<String> {
    let mut out: Vec<String> = report
        .paper_vs_model
        .iter()
        .filter(|r| !r.agrees)
        .map(|r| {
            let mut item = format!(
                "{}: the paper reports {}, the model gives {} (rule: {}; {}).",
                r.quantity, r.paper, r.model, r.rule, r.source
            );
            if r.id == "heavy_robot_24" {
                if let Some(x) = report.extrapolations.first() {
                    item.push(' ');
                    item.push_str(&extrapolation_sentence(x));
                }
            }
            item
        })
        .collect();
    out.extend(inversion_item(&report.speed_inversion));
    if let Some(c) = &report.calibration {
        out.extend(calibration_items(c, &report.speeds, forces));
    }
    out
}

/// A k_s as the page prints it.
fn k(x: f64) -> String {
    sci(x, 2)
}

/// Why a regime claim beyond the measured slopes fails: the k_s there is extrapolated.
fn extrapolation_sentence(x: &Extrapolation) -> String {
    let range = match (x.k_s_from, x.k_s_to) {
        (Some(a), Some(b)) => format!("k_s({}°) between {} and {} N/m³", x.slope_deg, k(a), k(b)),
        (Some(a), None) => format!("k_s({}°) of at least {} N/m³", x.slope_deg, k(a)),
        (None, Some(b)) => format!("k_s({}°) below {} N/m³", x.slope_deg, k(b)),
        (None, None) => return format!("No k_s at {}° gives {}.", x.slope_deg, x.claim),
    };
    let speed = x.speed_at_k_s_from_m_s.map_or(String::new(), |v| {
        format!(" (there the report's robot would climb at {:.1} cm/s at {}°)", v * 100.0, x.slope_deg)
    });
    format!(
        "This comes from the extrapolation, not from the model's physics: k_s is measured up to {}° only, and the model's k_s({}°) = {} N/m³ is the last segment extended. The claim holds with {range}{speed}.",
        x.last_measured_deg,
        x.slope_deg,
        k(x.k_s_used)
    )
}

/// The per-slope inversion, with the neighbouring slopes where the needed k_s rises.
fn inversion_item(inversion: &[SpeedInversion]) -> Option<String> {
    if inversion.len() < 2 {
        return None;
    }
    let needed: Vec<String> = inversion
        .iter()
        .map(|i| match i.k_s_needed {
            Some(v) => format!("{} at {}°", k(v), i.slope_deg),
            None => format!("none at {}° (above the model's ceiling)", i.slope_deg),
        })
        .collect();
    let rises: Vec<String> = inversion
        .windows(2)
        .filter(|w| matches!((w[0].k_s_needed, w[1].k_s_needed), (Some(a), Some(b)) if b > a))
        .map(|w| format!("{}° to {}°", w[0].slope_deg, w[1].slope_deg))
        .collect();
    if rises.is_empty() {
        return Some(format!(
            "Each observed speed alone needs its own k_s (N/m³): {}; these fall with slope, as a weakening slope should.",
            needed.join(", ")
        ));
    }
    Some(format!(
        "Each observed speed is reachable by its own k_s, but those k_s (N/m³) are {}: k_s would have to rise from {}, where the force tests and any k_s that weakens with slope fall. No k_s falling with slope can follow the observed speeds there.",
        needed.join(", "),
        rises.join(" and from ")
    ))
}

/// The calibration's floor against the fit without it, its plate scale, and its warnings.
fn calibration_items(c: &ReportCalibration, speeds: &[SpeedRecord], forces: &ForceTests) -> Vec<String> {
    let fit = &c.fit;
    let mut out = Vec::new();
    if fit.error_floor_m_s > 0.0 {
        let floor = fit.parameter(Parameter::ErrorFloor);
        let test = c.no_floor.and_then(|n| n.p_value.map(|p| (n, p))).map_or(String::new(), |(n, p)| {
            format!(
                " Without the floor the fit gives χ² = {:.1} on {} dof (p = {}).",
                n.chi_squared,
                n.dof,
                format_p(p)
            )
        });
        out.push(format!(
            "A k_s shape that falls with slope fits the speeds only with a model-error floor of {:.2} cm/s (68%: {:.2} to {:.2}) added to the quoted SDs (the smallest {:.2} cm/s).{test}",
            fit.error_floor_m_s * 100.0,
            floor.map_or(0.0, |p| p.estimate.lower * 100.0),
            floor.map_or(0.0, |p| p.estimate.upper * 100.0),
            speeds.iter().map(|o| o.observed_sd_m_s).fold(f64::INFINITY, f64::min) * 100.0
        ));
    }
    let scale = fit.plate_scale();
    if let (Some(level), true) = (fit.shear.first(), scale > 3.0) {
        let what = match forces {
            ForceTests::Paper(_) => "the plate level the force-test file assumes (1 × 10⁵ N/m³: an assumption, not the paper's; only the ratio 0.40 is printed)",
            _ => "what the force tests give",
        };
        out.push(format!(
            "The leg k_s the model needs at {}° ({} N/m³) would give {:.0} N on the paper's 3 cm × 2 cm shear plate (F = k_s W d²), {scale:.0} times {what}: the model's k_s is an effective leg parameter, not the plate's.",
            level.slope_deg,
            k(level.k_s),
            level.plate_force_n
        ));
    }
    // A bound or a poor fit is a top-level warning (calibration_warnings), not a finding.
    for w in &fit.warnings {
        if let CalibrationWarning::SpeedNearCeiling { slope_deg, observed_m_s, sd_m_s, ceiling_m_s } = w {
            let measured = speeds.iter().find(|o| o.slope_deg == *slope_deg).map(|o| o.observed_sd_m_s);
            let sds = match measured {
                Some(sd) if (sd - sd_m_s).abs() > 1e-12 => format!(
                    "± {:.2} cm/s as measured, ± {:.2} with the fitted floor",
                    sd * 100.0,
                    sd_m_s * 100.0
                ),
                _ => format!("± {:.2} cm/s", sd_m_s * 100.0),
            };
            let (where_, consequence) = if observed_m_s > ceiling_m_s {
                ("above", "no k_s reaches it, and the k_s there is pushed to its largest values")
            } else {
                (
                    "within one SD (with the floor) of",
                    "k_s there is barely constrained, and so is any ratio to it",
                )
            };
            out.push(format!(
                "Calibration: the speed at {slope_deg}° ({:.2} {sds}) is {where_} the model's ceiling s*/(T/2) = {:.2} cm/s: {consequence}.",
                observed_m_s * 100.0,
                ceiling_m_s * 100.0
            ));
        }
    }
    out
}

/// The calibration's warnings a reader must see before trusting the page: fitted quantities at
/// a search bound, and a fit far worse than the quoted SDs allow even with the floor.
pub(super) fn calibration_warnings(c: &ReportCalibration) -> Vec<String> {
    let fit = &c.fit;
    let floor_free = fit.parameter(Parameter::ErrorFloor).is_some();
    fit.warnings
        .iter()
        .filter_map(|w| match w {
            CalibrationWarning::ParameterAtBound { name, value, bound } => Some(format!(
                "the calibration's {name} stopped at its search bound ({} at the bound {}): the evidence pushes it further, and every interval and number derived from the fit is unreliable",
                sci(*value, 4),
                sci(*bound, 4)
            )),
            CalibrationWarning::PoorFit { chi_squared_per_dof } => Some(format!(
                "the calibration fits the evidence poorly: χ²/dof = {chi_squared_per_dof:.1}{}, far above 1: the model does not describe these observations within their SDs",
                if floor_free { " even with the model-error floor free" } else { "" }
            )),
            CalibrationWarning::SpeedNearCeiling { .. } => None,
        })
        .collect()
}
