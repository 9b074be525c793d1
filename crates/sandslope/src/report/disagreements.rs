//! The report's "where the model and the evidence disagree" items, each with the rule or the
//! computation that found it: the comparison rows that fail their rule (regime claims beyond
//! the measured slopes attributed to the extrapolation), the per-slope inversion and the rises
//! of k_s it needs, the calibration's model-error floor against the fit without it, the plate
//! scale, and the calibration's warnings.

use crate::calibrate::SpeedObservation;
use crate::calibrate::{AnchoringObservation, CalibrationWarning, Parameter};
use crate::model::predict;
use crate::paper::PaperComparison;
use crate::robot::Robot;
use crate::terrain::Terrain;

use super::audit::{Extrapolation, SpeedInversion};
use super::{format_p, sci, ForceTests, ReportCalibration};

/// Everything the disagreements are generated from.
pub(crate) struct Findings<'a> {
    pub rows: &'a [PaperComparison],
    pub calibration: Option<&'a ReportCalibration>,
    pub speeds: &'a [SpeedObservation],
    pub inversion: &'a [SpeedInversion],
    pub extrapolations: &'a [Extrapolation],
    pub forces: &'a ForceTests,
}

/// The disagreements, in order: failing comparisons, the inversion, the calibration.
pub(crate) fn disagreements(f: &Findings<'_>) -> Vec<String> {
    let mut out: Vec<String> = f
        .rows
        .iter()
        .filter(|r| !r.agrees)
        .map(|r| {
            let mut item = format!(
                "{}: the paper reports {}, the model gives {} (rule: {}; {}).",
                r.quantity, r.paper, r.model, r.rule, r.source
            );
            if r.id == "heavy_robot_24" {
                if let Some(x) = f.extrapolations.first() {
                    item.push(' ');
                    item.push_str(&extrapolation_sentence(x));
                }
            }
            item
        })
        .collect();
    out.extend(inversion_item(f.inversion));
    if let Some(c) = f.calibration {
        out.extend(calibration_items(c, f.speeds, f.forces));
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
fn calibration_items(c: &ReportCalibration, speeds: &[SpeedObservation], forces: &ForceTests) -> Vec<String> {
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
            speeds.iter().map(|o| o.speed_sd).fold(f64::INFINITY, f64::min) * 100.0
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
            let measured = speeds.iter().find(|o| o.slope.degrees() == *slope_deg).map(|o| o.speed_sd);
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
pub(crate) fn calibration_warnings(c: &ReportCalibration) -> Vec<String> {
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

/// The user's observations against the model (the calibration on them): every speed or
/// anchoring time more than 2 quoted SDs from the model's value.
pub(crate) fn observation_items(
    robot: &Robot,
    terrain: &Terrain,
    speeds: &[SpeedObservation],
    anchoring: &[AnchoringObservation],
) -> Vec<String> {
    let mut out = Vec::new();
    for o in speeds {
        let p = predict(robot, o.slope, &terrain.at(o.slope));
        let pull = p.speed.map(|v| (o.speed - v) / o.speed_sd);
        if pull.is_none_or(|z| z.abs() > 2.0) {
            out.push(format!(
                "Your speed at {}°: observed {:.2} ± {:.2} cm/s (SD as measured), the calibrated model gives {} (rule: within 2 SD).",
                o.slope.degrees(),
                o.speed * 100.0,
                o.speed_sd * 100.0,
                match (p.speed, pull) {
                    (Some(v), Some(z)) => format!("{:.2} cm/s, {:.1} SD away", v * 100.0, z.abs()),
                    _ => format!("no speed ({})", p.cause.explain()),
                }
            ));
        }
    }
    for o in anchoring {
        let p = predict(robot, o.slope, &terrain.at(o.slope));
        let pull = p.anchoring_time.map(|t| (o.t1 - t) / o.t1_sd);
        if pull.is_none_or(|z| z.abs() > 2.0) {
            out.push(format!(
                "Your anchoring time at {}°: observed t1 = {:.0} ± {:.0} ms, the calibrated model gives {} (rule: within 2 SD).",
                o.slope.degrees(),
                o.t1 * 1e3,
                o.t1_sd * 1e3,
                match (p.anchoring_time, pull) {
                    (Some(t), Some(z)) => format!(
                        "{:.0} ms (the observed is {:.1} times the model's, {:.1} SD away)",
                        t * 1e3,
                        o.t1 / t,
                        z.abs()
                    ),
                    _ => "no anchoring".to_string(),
                }
            ));
        }
    }
    out
}
