//! The report's words: the sentences a reader sees, worded from the library's values
//! ([`sandslope::report::report`] returns numbers and findings; this module writes the inputs
//! table, the calibration's goodness-of-fit sentence, the disagreements found from the
//! report's values and the calibration's warnings), and the one number format of the page and
//! `report.json` ([`sci`], [`format_p`]). The request's one answer path
//! ([`crate::report::answer_evidence`]) words every report, so the command line, Python and
//! the page read the same text.

use sandslope::calibrate::{CalibrationWarning, Parameter};
use sandslope::paper::{Basis, PaperComparison};
use sandslope::report::{
    Evidence, Extrapolation, ForceTests, Input, NoFloorFit, PlainAnswer, Provenance, ProvenanceKind, Report,
    ReportCalibration, SpeedInversion, SpeedRecord, Summary,
};
use sandslope::risk::SafeLimit;

/// Words `report`, built from `evidence`: its inputs table, its calibration's goodness-of-fit
/// sentence, the disagreements worded from its values (after the library's own) and the
/// calibration's warnings (after the others).
pub fn word(report: &mut Report, evidence: &Evidence) {
    report.inputs = inputs(evidence, report.tracks_give_t1);
    report.summary.text = summary(&report.summary, &report.paper_vs_model);
    report.plain_answer.text = plain_answer(&report.plain_answer);
    if report.plain_answer.untested {
        report.warnings.insert(0, another_robot(evidence));
    }
    if let Some(c) = &mut report.calibration {
        c.goodness_of_fit = goodness_of_fit(c.no_floor);
    }
    let found = disagreements(report, &evidence.forces);
    report.disagreements.extend(found);
    if let Some(c) = &report.calibration {
        let warnings = calibration_warnings(c);
        report.warnings.extend(warnings);
    }
}

/// A probability as text: 2 significant digits, `< 10⁻³⁰⁰` below what a float holds.
pub fn format_p(p: f64) -> String {
    if p <= 0.0 {
        "< 10⁻³⁰⁰".into()
    } else if p >= 0.01 {
        format!("{p:.2}")
    } else {
        sci(p, 1)
    }
}

/// The report's number format, shared by every front end (crate::format).
pub use crate::format::powers_of_ten as sci;

/// The plain answer in one paragraph: how steep the robot climbs steadily and how fast, the
/// first slope where it does not and the first where it fails (the model at the terrain's
/// medians, docs/model.md §5-§6), then the two risk limits (§9).
fn plain_answer(a: &PlainAnswer) -> String {
    let cm = |v: Option<f64>| v.map_or("-".into(), |v| format!("{:.1} cm/s", 100.0 * v));
    let mut text = format!("On {} the {} kg robot ", a.terrain, a.mass_kg);
    match a.climbs_up_to_deg {
        Some(deg) => text.push_str(&format!(
            "climbs steadily up to {deg:.2}° ({} on level ground, {} there)",
            cm(a.level_speed_m_s),
            cm(a.speed_at_limit_m_s)
        )),
        None => text.push_str("does not climb steadily even on level ground"),
    }
    if let Some((deg, regime)) = a.first_not_success.filter(|(_, r)| !r.is_failure()) {
        text.push_str(&format!(
            "; from {deg:.2}° it {} (the paper's \"{}\": it still moves up, {} there, but each step is shorter than \
             the robust step, so the next foothold lands in sand the last one disturbed and it can stall in its own trench)",
            regime.outcome(),
            regime.name(),
            cm(a.speed_at_first_not_success_m_s)
        ));
    }
    if let Some((deg, regime)) = a.first_failure {
        let why = if a.repose_deg.is_some_and(|r| deg >= r) { " (the angle of repose)" } else { "" };
        text.push_str(&format!("; from {deg:.2}°{why} it {} ({})", regime.outcome(), regime.name()));
    }
    text.push_str(" (the model at the terrain's medians, docs/model.md §5-§6).");
    let words = |l: &SafeLimit| match *l {
        SafeLimit::Limit { value, .. } => format!("up to {value:.1}°"),
        SafeLimit::Repose { repose_deg, .. } => format!("up to the angle of repose, {repose_deg}°"),
        SafeLimit::NoneSafe { .. } => "on no slope".into(),
        SafeLimit::BeyondRange { up_to, .. } => format!("at every slope up to {up_to}°"),
    };
    text.push_str(&format!(
        " With the terrain's uncertainty, it climbs steadily (P(not climbing steadily) < {r}) {} and is safe (P(sinks or slides back) < {r}) {} (§9).",
        words(&a.success_limit),
        words(&a.safe_limit),
        r = a.max_risk
    ));
    if a.untested {
        text.push_str(
            " This is the model's prediction for your robot, untested: the paper's speeds are of its 0.35 kg robot, and you gave no observations of yours.",
        );
    }
    if a.unreliable {
        text.push_str(
            " These numbers rest on a calibration that does not fit its observations: read why, and what data would fix it, before using them.",
        );
    }
    text
}

/// The first warning of a report on a robot other than the paper's without observations of its
/// own ([`PlainAnswer::untested`]): nothing about the paper's 0.35 kg robot is fitted or
/// compared.
fn another_robot(evidence: &Evidence) -> String {
    let r = &evidence.robot;
    let (mass, ..) = sandslope::paper::ROBOT;
    format!(
        "your robot ({}, {} kg, R = {} cm) is not the paper's ({mass} kg, R = 4 cm) and you gave no observations \
         of it (--observed, --t1, --tracks): the paper's speeds, anchoring trend, step period and heavy-robot claim \
         are of the paper's robot, so this report neither fits nor compares them; it is the model's prediction \
         for your robot on {}, untested. Give its measured speeds with --observed to test and calibrate it",
        evidence.robot_source,
        r.mass(),
        r.leg_radius() * 100.0,
        evidence.terrain_source
    )
}

/// The comparison table summed up in a sentence: the independent agreements counted, or the
/// one independent number named.
fn summary(counts: &Summary, rows: &[PaperComparison]) -> String {
    let construction = format!(
        "{} more agree by construction (inputs, tuned values, consequences of the model's form), out of {} compared",
        counts.by_construction_agree, counts.total
    );
    let mut independent = rows.iter().filter(|r| r.basis == Basis::Independent);
    match (counts.independent, independent.next()) {
        (0, _) | (_, None) => {
            format!("none of the paper's numbers tests the model independently here; {construction}")
        }
        // One number: name it, rather than "0 of the paper's 1 independent numbers".
        (1, Some(row)) => format!(
            "one of the paper's numbers tests the model independently, the {}: paper {}, model {}, so the model {} it; {construction}",
            row.quantity,
            row.paper,
            row.model,
            if row.agrees { "agrees with" } else { "disagrees with" }
        ),
        (n, Some(_)) => format!(
            "the model agrees with {} of the paper's {n} independent numbers; {construction}",
            counts.independent_agree
        ),
    }
}

/// Which chi^2 tests the model, in words: the fit without the floor's, when it has degrees
/// of freedom left.
fn goodness_of_fit(no_floor: Option<NoFloorFit>) -> String {
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
fn disagreements(report: &Report, forces: &ForceTests) -> Vec<String> {
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
fn calibration_warnings(c: &ReportCalibration) -> Vec<String> {
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

fn row(name: &str, value: impl Into<String>, kind: ProvenanceKind, detail: impl Into<String>) -> Input {
    Input { name: name.into(), value: value.into(), provenance: Provenance { kind, detail: detail.into() } }
}

use ProvenanceKind::{Assumed, Derived, Measured, Tuned};

/// The robot's rows: on the built-in robot one per group of keys, else the user's file.
fn robot_rows(e: &Evidence) -> Vec<Input> {
    let r = &e.robot;
    if !e.builtin_robot {
        return vec![row(
            "robot",
            e.robot_source.clone(),
            Assumed,
            "your robot file: sandslope cannot tell which of its values were measured",
        )];
    }
    vec![
        row(
            "robot: m, R, W, ω, n",
            format!(
                "{} ({} kg, R = {} cm, W = {} cm, ω = {} rad/s, n = {} legs in stance)",
                e.robot_source,
                r.mass(),
                r.leg_radius() * 100.0,
                r.leg_width() * 100.0,
                if (r.leg_speed() - std::f64::consts::TAU).abs() < 1e-12 { "2π".to_string() } else { format!("{:.4}", r.leg_speed()) },
                r.stance_legs()
            ),
            Measured,
            "the paper, Sec. II-A (robot) and Sec. III-D (alternating tripod, n = 3)",
        ),
        row(
            "robot: response time Δt",
            format!("{} s", r.response_time()),
            Measured,
            "the paper, Sec. III-D (\"characteristic elastic response time\", after Li et al. 2009)",
        ),
        row(
            "robot: hip height h",
            format!("{} m", r.hip_height()),
            Tuned,
            "not reported by the paper; chosen so that the level-sand speed ceiling s*/(T/2) sits just above the observed 15.7 cm/s at 0°",
        ),
        row(
            "robot: leg contact area A_c",
            format!("{} m² (W R)", sci(r.contact_area(), 1)),
            Assumed,
            "not reported by the paper; docs/model.md §2 takes W R",
        ),
        row(
            "robot: stride period T",
            format!("{} s (T/2 = {} s)", r.stride_period(), r.stance_duration()),
            Derived,
            "T = 2π/ω from the paper's leg speed",
        ),
    ]
}

/// The terrain's rows.
fn terrain_rows(e: &Evidence) -> Vec<Input> {
    if !e.builtin_terrain {
        return vec![row(
            "terrain",
            e.terrain_source.clone(),
            Assumed,
            "your terrain file: sandslope cannot tell which of its values were measured",
        )];
    }
    // With the user's observations the page's model is calibrated on them, not on the paper's
    // speeds (one calibration drives the page, issue 28).
    let k_s = if e.has_own_observations() {
        let forces = match e.forces {
            ForceTests::Given { .. } => "your force tests",
            ForceTests::Paper(_) => "the paper's force-test ratio",
            ForceTests::None => "the terrain's own k_s shape",
        };
        row(
            "terrain: leg k_s(θ)",
            format!("{}, recalibrated", e.terrain_source),
            Tuned,
            format!("the joint calibration on your observations (below) and {forces} (docs/calibration.md): plate_scale and a model-error floor fitted"),
        )
    } else {
        row(
            "terrain: leg k_s(θ)",
            e.terrain_source.clone(),
            Tuned,
            "the joint calibration on the paper's five speeds and its force-test ratio (docs/calibration.md): plate_scale and a model-error floor fitted",
        )
    };
    vec![
        k_s,
        row(
            "terrain: k_n",
            "7 × 10⁵ N/m³ at every slope",
            Assumed,
            "the paper prints no k_n; its constancy with slope is the paper's (Sec. III-B), its level an order-of-magnitude value",
        ),
        row("terrain: angle of repose", "25°", Measured, "the paper, Sec. II-C footnote (\"25° approaches the angle of repose\")"),
    ]
}

/// The evidence's rows: speeds, force tests, anchoring times, tracks.
fn evidence_rows(e: &Evidence, tracks_give_t1: bool) -> Vec<Input> {
    let tracks = &e.tracks;
    let mut out = vec![match (&e.observed, tracks.is_empty()) {
        (Some((p, _)), _) => row("observed speeds", p.clone(), Measured, "your measurements"),
        (None, false) => row(
            "observed speeds",
            "the motion-capture tracks' (mean ± SD per slope, --tracks)",
            Measured,
            "your recordings, analysed as sandslope track does (docs/model.md §11)",
        ),
        (None, true) if !sandslope::paper::is_papers_robot(&e.robot) => row(
            "observed speeds",
            "none (the paper's five are of its 0.35 kg robot, not yours)",
            Assumed,
            "give your robot's measured speeds with --observed to test the model on it",
        ),
        (None, true) => row(
            "observed speeds",
            "the paper's five (docs/model.md §12)",
            Measured,
            "the paper, Sec. III-A and Fig. 3a (means and SDs as printed)",
        ),
    }];
    out.extend(match &e.forces {
        ForceTests::Given { source, .. } => vec![row("force tests", source.clone(), Measured, "your measurements")],
        ForceTests::Paper(_) => vec![
            row(
                "force tests: k_s(20°)/k_s(0)",
                "0.40 (data/example-force-tests.toml)",
                Measured,
                "the paper, Sec. III-C (\"approximately 40%\"); its Fig. 4d/h values are not printed",
            ),
            row(
                "force tests: levels and SDs",
                "plate k_s(0) = 1 × 10⁵ N/m³, k_n = 7 × 10⁵ N/m³; SDs 15% (k_s), 10% (k_n)",
                Assumed,
                "not in the paper: order-of-magnitude values for loose glass beads; with plate_scale free only the ratio and its SD matter",
            ),
        ],
        ForceTests::None => vec![row(
            "force tests",
            "the terrain's own table",
            Derived,
            "none given: the terrain's k_s shape is the one calibrated",
        )],
    });
    let mut t1_sources: Vec<String> = e.anchoring.iter().map(|(p, _)| p.clone()).collect();
    if tracks_give_t1 {
        t1_sources.push("the motion-capture tracks (--tracks)".into());
    }
    if !t1_sources.is_empty() {
        out.push(row("anchoring times", t1_sources.join(" and "), Measured, "your measurements"));
    }
    for t in tracks {
        out.push(row(
            &format!("motion capture at {}°", t.slope_deg),
            t.files.join(", "),
            Measured,
            "your recordings",
        ));
    }
    if !tracks.is_empty() {
        let r = &e.track_reading;
        out.push(row(
            "motion-capture reading",
            format!(
                "format {}; body {}; upslope {}; stride period T = {} s (the robot's)",
                r.format.as_deref().unwrap_or("detected per file"),
                r.body.as_deref().unwrap_or("chosen per file (no --tracks-body)"),
                r.upslope.map_or("estimated per slope from the travel".to_string(), |v| {
                    format!("[{:.3}, {:.3}, {:.3}]", v[0], v[1], v[2])
                }),
                e.robot.stride_period()
            ),
            Derived,
            "the flags given and the robot's leg speed",
        ));
    }
    out
}

/// The inputs table: what the report was made from, each with its provenance.
fn inputs(e: &Evidence, tracks_give_t1: bool) -> Vec<Input> {
    let mut out = robot_rows(e);
    out.extend(terrain_rows(e));
    out.extend(evidence_rows(e, tracks_give_t1));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The one number format: plain from 0.01 to 10⁴ with `decimals + 1` significant digits,
    /// else a mantissa with `decimals` digits and a superscript power of ten.
    #[test]
    fn sci_writes_plain_or_powers_of_ten() {
        assert_eq!(sci(1.234e6, 2), "1.23 × 10⁶");
        assert_eq!(sci(4e-4, 1), "4.0 × 10⁻⁴");
        assert_eq!(sci(0.5, 1), "0.50");
        assert_eq!(sci(123.456, 2), "123");
        assert_eq!(sci(0.0, 2), "0");
        assert_eq!(format_p(0.2), "0.20");
        assert_eq!(format_p(0.003), "3.0 × 10⁻³");
        assert_eq!(format_p(0.0), "< 10⁻³⁰⁰");
    }

    /// The paper's evidence worded: the inputs table (the contact area W R = 1 cm x 4 cm =
    /// 4.0 x 10⁻⁴ m², the paper's five speeds measured), the goodness-of-fit sentence, and the
    /// inversion's disagreement (the k_s the observed speeds need rises from 20° to 24°, where
    /// the paper's 4.98 cm/s becomes 5.6 cm/s).
    #[test]
    fn the_papers_report_is_worded() {
        let robot = sandslope_io::load_robot("paper-hexapod").unwrap();
        let terrain = sandslope_io::load_terrain("glass-beads-300um").unwrap();
        let request = crate::report::ReportRequest::from_fields(
            "paper-hexapod".into(),
            "glass-beads-300um".into(),
            Vec::new(),
            &[],
        )
        .unwrap();
        let r = request.answer(robot, terrain, crate::error::Words::Flag).unwrap();
        let row = |name: &str| r.inputs.iter().find(|i| i.name == name).unwrap();
        assert_eq!(row("robot: leg contact area A_c").value, "4.0 × 10⁻⁴ m² (W R)");
        assert_eq!(row("observed speeds").provenance.kind, ProvenanceKind::Measured);
        let c = r.calibration.as_ref().unwrap();
        assert!(c
            .goodness_of_fit
            .starts_with("The goodness-of-fit test is the fit without the floor: χ² = "));
        assert!(
            r.disagreements.iter().any(|d| d.contains("would have to rise from") && d.contains("20° to 24°")),
            "{:?}",
            r.disagreements
        );
    }

    /// The plain answer worded from its values alone: a robot that climbs steadily to 18.5°
    /// at 15.7 cm/s on level ground and 6.2 there, turns metastable at 18.75° (the paper's
    /// name beside the field engineer's words) and slides back from the repose, 25°; both risk
    /// limits; untested and unreliable each add their sentence.
    #[test]
    fn the_plain_answer_is_worded_from_its_values() {
        use sandslope::regime::Regime;
        let mut a = PlainAnswer {
            mass_kg: 0.35,
            terrain: "sand".into(),
            climbs_up_to_deg: Some(18.5),
            level_speed_m_s: Some(0.157),
            speed_at_limit_m_s: Some(0.062),
            first_not_success: Some((18.75, Regime::Metastable)),
            first_failure: Some((25.0, Regime::Slippage)),
            success_limit: SafeLimit::Limit { value: 17.04, p_fail: 0.04 },
            safe_limit: SafeLimit::Repose { repose_deg: 25.0, p_fail: 0.01 },
            max_risk: 0.05,
            speed_at_first_not_success_m_s: Some(0.05),
            repose_deg: Some(25.0),
            untested: false,
            unreliable: false,
            text: String::new(),
        };
        let text = plain_answer(&a);
        assert!(
            text.starts_with(
                "On sand the 0.35 kg robot climbs steadily up to 18.50° (15.7 cm/s on level ground, 6.2 cm/s there); \
                 from 18.75° it climbs slowly and may stall (the paper's \"metastable\": it still moves up, 5.0 cm/s there"
            ),
            "{text}"
        );
        assert!(
            text.contains("; from 25.00° (the angle of repose) it slides back (slippage) (the model"),
            "{text}"
        );
        assert!(
            text.ends_with(
                "(P(not climbing steadily) < 0.05) up to 17.0° and is safe (P(sinks or slides back) < 0.05) up to \
                 the angle of repose, 25° (§9)."
            ),
            "{text}"
        );
        (a.untested, a.unreliable, a.climbs_up_to_deg) = (true, true, None);
        let text = plain_answer(&a);
        assert!(text.starts_with("On sand the 0.35 kg robot does not climb steadily even on level ground;"));
        assert!(
            text.contains("prediction for your robot, untested")
                && text.contains("does not fit its observations")
        );
    }

    /// The summary: no independent row, one (named), or several (counted).
    #[test]
    fn the_summary_names_one_independent_number_and_counts_more() {
        let row = |id: &str, basis: Basis, agrees: bool| PaperComparison {
            id: id.into(),
            quantity: format!("{id} quantity"),
            source: String::new(),
            paper: "1".into(),
            model: "2".into(),
            paper_value: None,
            model_value: None,
            agrees,
            rule: String::new(),
            basis,
            basis_note: String::new(),
        };
        let count = |rows: &[PaperComparison]| {
            let independent: Vec<&PaperComparison> =
                rows.iter().filter(|r| r.basis == Basis::Independent).collect();
            Summary {
                independent: independent.len(),
                independent_agree: independent.iter().filter(|r| r.agrees).count(),
                by_construction_agree: rows
                    .iter()
                    .filter(|r| r.basis != Basis::Independent && r.agrees)
                    .count(),
                total: rows.len(),
                text: String::new(),
            }
        };
        let mut rows = vec![row("a", Basis::Input, true)];
        assert_eq!(
            summary(&count(&rows), &rows),
            "none of the paper's numbers tests the model independently here; 1 more agree by construction \
             (inputs, tuned values, consequences of the model's form), out of 1 compared"
        );
        rows.push(row("b", Basis::Independent, false));
        assert!(summary(&count(&rows), &rows)
            .starts_with("one of the paper's numbers tests the model independently, the b quantity: paper 1, model 2, so the model disagrees with it; 1 more"));
        rows.push(row("c", Basis::Independent, true));
        assert!(summary(&count(&rows), &rows).starts_with(
            "the model agrees with 1 of the paper's 2 independent numbers; 1 more agree by construction"
        ));
    }

    /// A 1.2 kg robot without observations: the first warning says it is not the paper's
    /// 0.35 kg robot, with its mass, and the plain answer that it is untested.
    #[test]
    fn another_robot_is_warned_first() {
        let robot = sandslope_io::load_robot("paper-hexapod").unwrap().with_mass(1.2).unwrap();
        let terrain = sandslope_io::load_terrain("glass-beads-300um").unwrap();
        let request = crate::report::ReportRequest::from_fields(
            "paper-hexapod".into(),
            "glass-beads-300um".into(),
            Vec::new(),
            &[],
        )
        .unwrap();
        let r = request.answer(robot, terrain, crate::error::Words::Flag).unwrap();
        assert!(
            r.warnings[0].contains("kg, R = 4 cm) is not the paper's (0.35 kg, R = 4 cm)")
                && r.warnings[0].contains("1.2 kg"),
            "{:?}",
            r.warnings
        );
        assert!(
            r.plain_answer.text.contains("prediction for your robot, untested"),
            "{}",
            r.plain_answer.text
        );
    }
}
