//! The page's sections, each rendered from the library's [`Report`]: heading, warnings,
//! inputs with their provenance, disagreements, the comparison table with its basis, the two
//! calibration fits, and the step budget with the per-slope inversion.

use sandslope::paper::Basis;
use sandslope::report::{ProvenanceKind, Report, ReportCalibration};
use sandslope_format::Outcome;
use sandslope_format::{powers_of_ten as sci, probability as format_p};

use super::{escape, plus_minus};

/// The heading and the paragraph under it: the paper's evidence, or the user's.
pub fn header(report: &Report) -> String {
    let mut h = String::new();
    if report.own_observations {
        h.push_str(
            "<h1>Legged robots on granular slopes: your observations, the model, and where they part</h1>\n",
        );
        h.push_str(
            "<p>The shear-anchoring model of Liao and Qian, <i>Failure Mechanisms and Risk Estimation for Legged \
             Robot Locomotion on Granular Slopes</i> (arXiv:2603.06928), calibrated by <code>sandslope report</code> \
             on your observations (inputs below). One calibration drives every table and figure: the model on this \
             page is the joint calibration's robot and terrain. Figure ids are the paper's figure numbers. The model \
             is specified in the repository's <code>docs/model.md</code>; the calibration in \
             <code>docs/calibration.md</code>.</p>\n",
        );
    } else {
        h.push_str("<h1>Legged robots on granular slopes: the model, the paper, and where they part</h1>\n");
        h.push_str(
            "<p>Liao and Qian, <i>Failure Mechanisms and Risk Estimation for Legged Robot Locomotion on Granular \
             Slopes</i> (arXiv:2603.06928), recomputed by <code>sandslope report</code> from the inputs below. \
             Figure ids are the paper's figure numbers. The model is specified in the repository's \
             <code>docs/model.md</code>; the calibration in <code>docs/calibration.md</code>.</p>\n",
        );
    }
    h
}

/// The plain answer, first: how steep and how fast the robot climbs on this terrain, where it
/// turns metastable and where it fails; the evidence follows.
pub fn plain_answer(report: &Report) -> String {
    format!(
        "<h2 id=\"answer\">The answer</h2>\n<p class=\"answer\"><b>{}</b></p>\n<p>The rest of the page is the evidence: \
         the inputs and where they come from, where the model and the data disagree, every number the paper reports \
         beside the model's, the calibration and the figures.</p>\n",
        escape(&report.plain_answer.text)
    )
}

/// Why the calibration is unreliable and what data would fix it, right after the answer it
/// qualifies (only when the fit flags itself).
pub fn fit_diagnosis(report: &Report) -> String {
    let Some(d) = &report.fit_diagnosis else { return String::new() };
    let mut h = format!(
        "<h2 id=\"unreliable\">Why the calibration is unreliable</h2>\n<p class=\"warn\">{}</p>\n",
        escape(&d.text)
    );
    if !d.remedies.is_empty() {
        h.push_str("<p>What data would fix it:</p>\n<ul>");
        for r in &d.remedies {
            h.push_str(&format!("<li>{}</li>", escape(r)));
        }
        h.push_str("</ul>\n");
    }
    h
}

/// The top-level warnings, before anything else is read.
pub fn warnings(report: &Report) -> String {
    report
        .warnings
        .iter()
        .map(|w| format!("<p class=\"warn\"><b>Warning:</b> {}.</p>\n", escape(w)))
        .collect()
}

fn kind(k: ProvenanceKind) -> &'static str {
    match k {
        ProvenanceKind::Measured => "measured",
        ProvenanceKind::Assumed => "assumed",
        ProvenanceKind::Tuned => "tuned",
        ProvenanceKind::Derived => "derived",
    }
}

/// The inputs table with the provenance of each.
pub fn inputs(report: &Report) -> String {
    let mut h = String::from("<table><tr><th>input</th><th>value</th><th>where it comes from</th></tr>");
    for i in &report.inputs {
        h.push_str(&format!(
            "<tr><td>{}</td><td>{}</td><td><b>{}</b>: {}</td></tr>",
            escape(&i.name),
            escape(&i.value),
            kind(i.provenance.kind),
            escape(&i.provenance.detail)
        ));
    }
    h.push_str("</table>\n<p><small><b>measured</b>: printed in the paper (section given) or your own measurement; \
         <b>assumed</b>: in neither, chosen for the reason given; <b>tuned</b>: chosen to match an observation; \
         <b>derived</b>: follows from other inputs.</small></p>\n");
    h
}

/// The disagreements list.
pub fn disagreements(report: &Report) -> String {
    let mut h = if report.own_observations {
        String::from(
            "<h2 id=\"disagree\">Where the model and your observations (and the paper) disagree</h2>\n",
        )
    } else {
        String::from("<h2 id=\"disagree\">Where the model and the paper disagree</h2>\n")
    };
    if report.disagreements.is_empty() {
        h.push_str("<p>Nowhere, by the rules in the table below.</p>");
    } else {
        h.push_str("<ul>");
        for d in &report.disagreements {
            h.push_str(&format!("<li>{}</li>", escape(d)));
        }
        h.push_str("</ul>\n");
    }
    h
}

fn basis(b: Basis) -> &'static str {
    match b {
        Basis::Independent => "independent",
        Basis::Input => "input",
        Basis::Tuned => "tuned",
        Basis::Consequence => "consequence",
    }
}

/// The paper's numbers beside the model's, each with its basis, and the summary.
pub fn comparison(report: &Report) -> String {
    let mut h = String::from("<h2 id=\"numbers\">Every number the paper reports, beside the model's</h2>\n");
    h.push_str(&format!("<p><b>Summary:</b> {}.</p>\n", escape(&report.summary.text)));
    h.push_str(
        "<table><tr><th>quantity</th><th>paper</th><th>model</th><th>agrees?</th><th>rule</th><th>source</th>\
         <th>basis</th></tr>",
    );
    for r in &report.paper_vs_model {
        h.push_str(&format!(
            "<tr class=\"{}\"><td>{}</td><td>{}</td><td>{}</td><td class=\"v\">{}</td><td>{}</td><td>{}</td><td><b>{}</b>: {}</td></tr>",
            if r.agrees { "yes" } else { "no" },
            escape(&r.quantity),
            escape(&r.paper),
            escape(&r.model),
            if r.agrees { "yes" } else { "no" },
            escape(&r.rule),
            escape(&r.source),
            basis(r.basis),
            escape(&r.basis_note)
        ));
    }
    h.push_str("</table>\n<p><small><b>independent</b>: nothing of the paper's number went into the model, so \
         agreement tests it; <b>input</b>: the number is (or follows from) a model input; <b>tuned</b>: the model \
         was fitted to it; <b>consequence</b>: the model's form gives it for any inputs of the usual shape.</small></p>\n");
    h
}

/// The two fits: with the floor (the fitted quantities) and without it (the test).
pub fn calibration(c: &ReportCalibration, model_is_calibration: bool) -> String {
    let fit = &c.fit;
    let mut h = String::from("<h2 id=\"joint-calibration\">Joint calibration</h2>\n");
    h.push_str(&format!(
        "<p>With the model-error floor free: χ² = {:.2} over {} degrees of freedom{}; floor {:.2} cm/s; \
         k<sub>s</sub>(20°)/k<sub>s</sub>(0) = {:.3} (68%: {:.3} to {:.3}; the paper's force tests: about 0.40). {}</p>",
        fit.chi_squared,
        fit.dof,
        fit.chi_squared_per_dof.map_or(String::new(), |r| format!(" (χ²/dof {r:.2})")),
        fit.error_floor_m_s * 100.0,
        fit.shear_ratio_20.value,
        fit.shear_ratio_20.lower,
        fit.shear_ratio_20.upper,
        if model_is_calibration {
            "Every number and figure on this page uses this fit."
        } else {
            "The tables and figures above and below use the terrain as given, not this fit: this is what the evidence makes of its k_s shape."
        }
    ));
    if let Some(n) = &c.no_floor {
        h.push_str(&format!(
            "<p>Without the floor (the quoted SDs only): χ² = {:.2} over {} degrees of freedom{}, p = {}{}.</p>",
            n.chi_squared,
            n.dof,
            n.chi_squared_per_dof.map_or(String::new(), |r| format!(" (χ²/dof {r:.2})")),
            n.p_value.map_or("-".into(), format_p),
            n.plate_scale.map_or(String::new(), |s| format!("; plate_scale {s:.1}"))
        ));
    }
    h.push_str(&format!("<p><b>Which is the test:</b> {}</p>\n", escape(&c.goodness_of_fit)));
    h.push_str("<table><tr><th>fitted quantity</th><th>best</th><th>68% interval</th><th>unit</th></tr>");
    for p in &fit.parameters {
        let (scale, unit) = match p.unit.as_str() {
            "m/s" => (100.0, "cm/s".to_string()),
            "N/m^3" => (1.0, "N/m³".to_string()),
            u => (1.0, u.to_string()),
        };
        h.push_str(&format!(
            "<tr><td>{}</td><td>{}</td><td>{} to {}{}</td><td>{}</td></tr>",
            escape(&p.name),
            sci(p.estimate.value * scale, 3),
            sci(p.estimate.lower * scale, 3),
            sci(p.estimate.upper * scale, 3),
            if p.at_bound { " (at a bound)" } else { "" },
            escape(&unit)
        ));
    }
    h.push_str("</table>\n");
    h
}

/// The step budget (docs/model.md §5) and the per-slope inversion, one row per observed slope.
pub fn step_budget(report: &Report) -> String {
    if report.step_budget.is_empty() {
        return String::new();
    }
    let mut h = String::from("<h2 id=\"step-budget\">Where the step is lost</h2>\n");
    h.push_str(
        "<p>The model's net step is the level step s* minus three losses (docs/model.md §5): the shorter \
         propulsion time s* (1 - ((T/2 - t1)/(T/2))²), the inherited-speed term g sin θ t1 (T/2 - t1) of the \
         propulsion, and the backward slip ½ g sin θ t1². t1 is also given in frames of the paper's 120 fps \
         motion capture. The last two columns invert each observed speed alone: the k<sub>s</sub> it needs, \
         beside the model's.</p>\n",
    );
    h.push_str(
        "<table><tr><th>slope (°)</th><th>s* (mm)</th><th>t1 (ms)</th><th>t1 (frames)</th><th>shorter propulsion (mm)</th>\
         <th>inherited speed (mm)</th><th>slip (mm)</th><th>net step (mm)</th><th>k<sub>s</sub> needed (N/m³)</th>\
         <th>model k<sub>s</sub> (N/m³)</th></tr>",
    );
    let mm = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{:.1}", v * 1e3));
    for b in &report.step_budget {
        let inv = report.speed_inversion.iter().find(|i| i.slope_deg == b.slope_deg);
        h.push_str(&format!(
            "<tr><td>{}</td><td>{:.1}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            b.slope_deg,
            b.level_step_m * 1e3,
            b.t1_s.map_or("-".into(), |t| format!("{:.1}", t * 1e3)),
            b.t1_frames.map_or("-".into(), |f| format!("{f:.1}")),
            mm(b.shorter_propulsion_m),
            mm(b.inherited_speed_m),
            plus_minus(b.slip_m.map(|s| s * 1e3), None, 1.0, 1),
            mm(b.step_m),
            inv.and_then(|i| i.k_s_needed).map_or("none (above the ceiling)".into(), |k| sci(k, 2)),
            inv.map_or("-".into(), |i| sci(i.k_s_model, 2)),
        ));
    }
    h.push_str("</table>\n");
    h
}

/// `simulated / closed form` of one quantity times `scale`, `-` where one is undefined.
fn pair(sim: Option<f64>, cf: Option<f64>, scale: f64, decimals: usize) -> String {
    let f = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{:.*}", decimals, v * scale));
    format!("{} / {}", f(sim), f(cf))
}

/// What the check of the section's walks found (each walked again at a quarter of the time step
/// and a tenth of the creep speed): measured for this robot and terrain, not assumed.
fn convergence_sentence(checks: &[sandslope::simulate::ConvergenceCheck]) -> String {
    if checks.is_empty() {
        return String::new();
    }
    let changes = || checks.iter().flat_map(|c| c.refinements.iter().map(move |r| (c, r)));
    // A share of the walk's speed only where the walk is faster than the check's absolute floor:
    // nearer zero it is no measure (0.07 cm/s on the 22 degree walk's 0.02 cm/s read 404%).
    let speed = changes()
        .filter(|(c, _)| c.walk.speed_m_s.abs() >= c.speed_tolerance_m_s)
        .map(|(c, r)| (r.speed_change_m_s / c.walk.speed_m_s).abs())
        .fold(0.0, f64::max);
    let speed_abs = changes().map(|(_, r)| r.speed_change_m_s.abs()).fold(0.0, f64::max);
    let t1 = changes().filter_map(|(_, r)| r.t1_change_s).map(f64::abs).fold(0.0, f64::max);
    let spread = changes().map(|(_, r)| r.step_speed_sd_change_m_s.abs()).fold(0.0, f64::max);
    let regimes = changes().filter(|(_, r)| !r.same_regime).count();
    let converged = checks.iter().filter(|c| c.converged).count();
    let verdict = if converged == checks.len() {
        format!("Each of these {} walks is converged, checked here", checks.len())
    } else {
        let not: Vec<String> =
            checks.iter().filter(|c| !c.converged).map(|c| format!("{}°", c.slope_deg)).collect();
        format!(
            "Of these {} walks {converged} are converged, checked here; <b>not at {}</b>, whose rows are to be read \
             with care",
            checks.len(),
            not.join(", ")
        )
    };
    format!(
        "{verdict}: walked again at a quarter of the time step and at a tenth of the creep speed, no speed moved by \
         more than {:.2} cm/s (nor by more than {:.1}% of a walk faster than {} cm/s), no spread of a walk's step speeds by more than {:.2} cm/s, no t1 by more than {:.2} ms, \
         and {} (tolerances 3% or 0.3 cm/s for the speed and the spread, 1 ms, the same regime; \
         <code>simulate --check-convergence</code>, docs/simulate.md).",
        speed_abs * 100.0,
        speed * 100.0,
        sandslope::simulate::convergence::SPEED_TOLERANCE_M_S * 100.0,
        spread * 100.0,
        t1 * 1e3,
        if regimes == 0 { "no regime changed".to_string() } else { format!("{regimes} regime(s) changed") }
    )
}

/// The stride simulator beside the closed form and the observations, with where they part.
pub fn simulator(report: &Report) -> String {
    if report.simulator.is_empty() {
        return String::new();
    }
    let agree = report.simulator.iter().filter(|r| r.agree).count();
    let tumbles = report.simulator.iter().filter(|r| r.pitch_over_s.is_some()).count();
    let disagree = report.simulator.iter().filter(|r| !r.scaling_regimes_agree).count();
    let mut h =
        String::from("<h2 id=\"simulator-table\">The stride simulator against the closed form</h2>\n");
    h.push_str(&format!(
        "<p>The same robot and terrain walked by the dynamic stride simulator (<code>sandslope simulate</code>: \
         a planar body on C-legs in resistive-force sand, stepped implicitly as the rate-independent law it is, \
         docs/model.md §15-§18; {} s walks) with the body's pitch locked, its default. {} It tests the \
         closed form's assumptions (quasi-static stance, the leg's circle fixed in solidified sand). They agree \
         (same regime, speeds within {:.0}%) at {agree} of {} slopes.</p>\n\
         <p>What survives convergence. <i>Legs roll</i>: a simulated C-leg rolls on its arc like a wheel's rim, so \
         its step tends to the rigid-ground rolling step and its speed is two to three times the closed form's and \
         the paper's below 20°, where the closed form's leg slides along its own circle held by solidified sand and \
         steps s*; resistive force theory has no term that holds the circle. <i>Anchoring</i>: on slopes the simulated body slips \
         back after touchdown, as the paper's did, and on level sand it does not; its slip grows with the slope but \
         is a fraction of the closed form's ½ g sin θ t1², because the new legs push up the slope from their first \
         contact (the belly is the body's underside, which the sand pushes and never pulls down, docs/model.md \
         §20.5; docs/simulate.md, \"Phase 1\"). No switch of the simulator with a \
         measured input brings the level speed to the paper's 15.7 cm/s (docs/simulate.md, \"The level stride\"), \
         nor do leg-sand friction, a slower stance or sand weakened where earlier steps dug it (docs/model.md §20); \
         the last slows the walk on slopes and leaves level sand as it was, as the trench the paper names for \
         metastability would (docs/simulate.md, \"The mechanisms across the slopes\"). \
         The paper's own rise from 20° to 24° (+0.62 ± 1.63 cm/s, 0.4 SD) and its plateau from 10° to 15° (1.9 SD) \
         are within its scatter: neither model is asked to follow them. <i>24°</i>: the simulated robot slides \
         back where the paper's climbed, because in mid-stance its stance legs push up the slope with less than \
         gravity's pull whatever k_s under the default contact scaling; scaled by component (<code>--rft-scaling \
         components</code>) the same legs hold and it climbs, and the scaling is not measured, so the simulator's \
         verdicts on steep slopes carry that spread (docs/simulate.md, \"What the simulator does not match\"): the \
         column <i>3 contact scalings</i> walks each slope under <code>motion</code>, <code>li2013</code> and \
         <code>components</code> and gives the range of their speeds and whether their regimes agree; where they \
         disagree the verdict is the scaling's, not the sand's, until a leg-wide plate dragged along the surface \
         at the stance depth is measured, its horizontal and vertical forces together (docs/simulate.md, \"The \
         scaling as model uncertainty\"). Here they disagree at {disagree} of the slopes. \
         <i>Pitch free</i>: the pitch-free columns, with the body free to pitch, climb from 0° to 20° without \
         tumbling; they walk at a quarter of the locked walk's step, where on the built-in robot and terrain \
         their speeds and regimes converge at most slopes but not at all of them, and they are not checked \
         here slope by slope (docs/simulate.md, \"Convergence\" and \"The free body's step\"): they are not \
         the section's answers, which hold the body parallel to the slope as the closed \
         form does. Here {tumbles} of these slopes tumbled.</p>\n",
        sandslope::report::REPORT_WALK_S,
        convergence_sentence(&report.simulator_convergence),
        sandslope::report::AGREE_WITHIN * 100.0,
        report.simulator.len()
    ));
    h.push_str(
        "<p>Speeds in cm/s. Each row's last cell says whether the two agree or, in a word, where they part; \
         open it for the why and the step's parts (t1, slip and step, simulated / closed form).</p>\n\
         <table class=\"sim\"><tr><th>slope (°)</th><th>observed</th><th>closed form</th><th>simulated</th>\
         <th>pitch free</th><th>regime: closed form / simulated (hover: the outcome)</th><th>pitch free: largest pitch (°)</th>\
         <th>3 contact scalings: speed, regimes (hover: each)</th><th>verdict</th></tr>",
    );
    for r in &report.simulator {
        let free = if r.pitch_over_s.is_some() { "- (tumbled)".to_string() } else { cm_s(r.pitch_free_m_s) };
        h.push_str(&format!(
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td><abbr title=\"{} / {}\">{} / {}</abbr></td><td>{}</td><td>{}</td>{}</tr>",
            r.slope_deg,
            plus_minus(r.observed_m_s.map(|v| v * 100.0), r.observed_sd_m_s.map(|v| v * 100.0), 1.0, 1),
            r.closed_form_m_s.map_or("- (ruled out)".into(), cm_s),
            cm_s(r.simulated_m_s),
            free,
            r.closed_form_regime.outcome(),
            r.simulated_regime.outcome(),
            r.closed_form_regime.name(),
            r.simulated_regime.name(),
            largest_pitch(r),
            scaling_cell(r),
            verdict_cell(r),
        ));
    }
    h.push_str("</table>\n");
    h
}

/// The pitch-locked walk's speed range under the three contact scalings and whether their
/// regimes agree; each scaling's regime on hover.
fn scaling_cell(r: &sandslope::report::SimulatorRecord) -> String {
    let names: Vec<String> = sandslope::simulate::SCALINGS
        .iter()
        .zip(&r.scaling_regimes)
        .map(|(s, g)| format!("{} {}", s.name(), g.name()))
        .collect();
    format!(
        "<abbr title=\"{}\">{:.1} to {:.1}, {}</abbr>",
        names.join(", "),
        r.scaling_min_m_s * 100.0,
        r.scaling_max_m_s * 100.0,
        if r.scaling_regimes_agree { "agree" } else { "<b>disagree</b>" }
    )
}

/// The pitch-free walk's largest pitch as the table shows it: in degrees while the body stays
/// upright, else "tumbled" with when (the summed rotation of a body rolling over, thousands of
/// degrees, is no angle a reader can picture).
fn largest_pitch(r: &sandslope::report::SimulatorRecord) -> String {
    match r.pitch_over_s {
        Some(t) => format!("tumbled (past 90° at {t:.1} s)"),
        None => format!("{:.0}", r.max_pitch_deg),
    }
}

/// The simulator table's last cell: "agree", or where the two part in a few words (the text
/// of `why` before its first colon), with the whole of `why` and the step's parts in a
/// collapsible note, so that no cell holds a paragraph.
fn verdict_cell(r: &sandslope::report::SimulatorRecord) -> String {
    let label = if r.agree { "agree" } else { r.why.split_once(": ").map_or(r.why.as_str(), |(l, _)| l) };
    let mut note = String::new();
    if !r.why.is_empty() {
        note.push_str(&format!("{}. ", escape(&r.why)));
    }
    note.push_str(&format!(
        "Simulated cause: {}; pitch free: {}. t1 (ms) {}; slip (mm) {}; step (mm) {} (simulated / closed form).",
        r.simulated_cause.name().replace('_', " "),
        r.pitch_free_regime.name(),
        pair(r.simulated_t1_s, r.closed_form_t1_s, 1e3, 1),
        pair(r.simulated_slip_m, r.closed_form_slip_m, 1e3, 1),
        pair(Some(r.simulated_step_m), r.closed_form_step_m, 1e3, 0),
    ));
    format!(
        "<td class=\"{}\"><details><summary>{}</summary>{note}</details></td>",
        if r.agree { "agree" } else { "part" },
        escape(label)
    )
}

/// The stride simulator's joint fit beside the closed form's (`report --simulator-fit`), or
/// why it is left out and the flag that adds it.
pub fn simulator_fit(report: &Report) -> String {
    let Some(closed) = report.calibration.as_ref().map(|c| &c.fit) else {
        return String::new();
    };
    let mut h =
        String::from("<h2 id=\"simulator-fit\">The simulator's joint fit beside the closed form's</h2>\n");
    let Some(sim) = &report.simulator_fit else {
        h.push_str(
            "<p>Not run for this page. The same joint calibration with the stride simulator in place of the \
             closed form walks the robot thousands of times (5,722 four-second walks on the paper's evidence, about \
             8 minutes of CPU), where the rest of this report takes under a second: \
             <code>sandslope report --simulator-fit</code> adds it here, and <code>sandslope calibrate --model \
             simulate</code> prints it alone (docs/calibration.md gives its result on the paper's evidence).</p>\n",
        );
        return h;
    };
    h.push_str(&format!(
        "<p>The same evidence, the same free quantities, fitted by the closed form and by the stride simulator \
         ({} walks; <code>calibrate --model simulate</code>). A smaller error floor would mean the simulator \
         explains the observations better; an observation the simulator misses by far more than its SD is one no \
         parameter set of the simulator reaches.</p>\n",
        sim.walks
    ));
    h.push_str(
        "<table><tr><th>observation</th><th>slope (°)</th><th>observed ± SD</th><th>closed form</th><th>pull</th>\
         <th>simulator</th><th>pull</th></tr>",
    );
    for (c, s) in closed.pulls.iter().zip(&sim.pulls) {
        use sandslope::calibrate::ObservationKind as K;
        let (name, scale, unit) = match c.kind {
            K::Speed => ("speed", 100.0, "cm/s"),
            K::AnchoringTime => ("t1", 1e3, "ms"),
            K::PlateShearStrength => ("plate k_s", 1.0, "N/m³"),
        };
        h.push_str(&format!(
            "<tr><td>{name}</td><td>{}</td><td>{} ± {} {unit}</td><td>{} {unit}</td><td>{:+.2}</td><td>{} {unit}</td><td>{:+.2}</td></tr>",
            c.slope_deg,
            sci(c.observed * scale, 2),
            sci(c.sd * scale, 2),
            sci(c.model * scale, 2),
            c.pull,
            sci(s.model * scale, 2),
            s.pull
        ));
    }
    h.push_str("</table>\n<table><tr><th>fitted quantity</th><th>closed form (68%)</th><th>simulator (68%)</th></tr>");
    let cell = |p: Option<&sandslope::FittedParameter>| {
        p.map_or("-".to_string(), |p| {
            let scale = if p.unit == "m/s" { 100.0 } else { 1.0 };
            format!(
                "{} ({} to {}{})",
                sci(p.estimate.value * scale, 3),
                sci(p.estimate.lower * scale, 3),
                sci(p.estimate.upper * scale, 3),
                if p.at_bound { ", at a bound" } else { "" }
            )
        })
    };
    for p in &closed.parameters {
        let unit = match p.unit.as_str() {
            "m/s" => " (cm/s)".to_string(),
            "" => String::new(),
            u => format!(" ({u})"),
        };
        h.push_str(&format!(
            "<tr><td>{}{}</td><td>{}</td><td>{}</td></tr>",
            escape(&p.name),
            escape(&unit),
            cell(Some(p)),
            cell(sim.fitted(p.quantity))
        ));
    }
    let dof = |c: &sandslope::JointCalibration| format!("{:.2} / {}", c.chi_squared, c.dof);
    h.push_str(&format!("<tr><td>χ² / dof</td><td>{}</td><td>{}</td></tr></table>\n", dof(closed), dof(sim)));
    h.push_str(&simulator_misses(&report.simulator_fit_misses));
    h
}

/// `s` with its first letter capitalised.
fn sentence(s: &str) -> String {
    let mut c = s.chars();
    c.next().map_or(String::new(), |f| f.to_uppercase().chain(c).collect())
}

/// The observed speeds the simulator's fit misses (by more than `MISS_SD` of their own SD),
/// each with why and what a scan of the leg's k_s reaches at that slope.
fn simulator_misses(misses: &[sandslope::report::SimulatorMiss]) -> String {
    if misses.is_empty() {
        return format!(
            "<p>The simulator's fit comes within {} SD (each observation's own) of every observed speed.</p>\n",
            sandslope::report::MISS_SD
        );
    }
    let mut h = format!(
        "<p>The observations the simulator's fit misses by more than {} SD of their own, the reason the error \
         floor must grow, and why (each walked again on the fitted ground, and at each leg k_s of a scan at \
         that slope):</p>\n<ul>\n",
        sandslope::report::MISS_SD
    );
    for m in misses {
        h.push_str(&format!(
            "<li><b>{}°: observed {:.1} ± {:.2} cm/s, the simulator's fit {:.1} cm/s ({:+.1} SD).</b> {}.</li>\n",
            m.slope_deg,
            m.observed_m_s * 100.0,
            m.observed_sd_m_s * 100.0,
            m.fitted_m_s * 100.0,
            m.miss_sd,
            escape(&sentence(&m.why))
        ));
    }
    h.push_str("</ul>\n");
    h
}

/// A speed in m/s as cm/s with one decimal, without the sign of a speed that rounds to zero
/// (a walk at -0.04 cm/s reads "0.0", not "-0.0").
fn cm_s(v_m_s: f64) -> String {
    let rounded = (v_m_s * 1000.0).round() / 10.0;
    format!("{:.1}", if rounded == 0.0 { 0.0 } else { rounded })
}

#[cfg(test)]
mod cm_s_tests {
    use super::cm_s;

    /// By hand: 0.3476 m/s is 34.76 cm/s, 34.8 to one decimal; -0.0004 m/s is -0.04 cm/s, which
    /// rounds to zero and reads without a sign; -0.081 m/s keeps its sign.
    #[test]
    fn speeds_round_to_one_decimal_without_a_signed_zero() {
        assert_eq!(cm_s(0.3476), "34.8");
        assert_eq!(cm_s(-0.0004), "0.0");
        assert_eq!(cm_s(-0.081), "-8.1");
    }
}
