//! The report's figures, drawn from [`Report::plots`] with the figure functions every command
//! uses (inline SVG), in page order; ids and titles are the library's
//! ([`Report::figures`]), the captions are the page's.

use anyhow::Result;
use plotters::chart::SeriesLabelPosition;

use sandslope::report::{Plots, Report, PHASE_PANELS};
use sandslope::{Prediction, TerrainPoint};

use super::PageFigure;
use crate::figures::calibrate::{speed_pulls, CalibrationFigure};
use crate::figures::phase::PhaseFigure;
use crate::figures::risk::CurveFigure;
use crate::figures::simulate::SlopesFigure;
use crate::figures::slope_curves::SlopeCurveFigure;
use crate::figures::step_budget::StepBudgetFigure;
use crate::figures::to_svg;
use crate::figures::track::{StridePanels, TrackFigure};

/// The title the library gave figure `id`.
fn title(report: &Report, id: &str) -> String {
    report.figures.iter().find(|f| f.id == id).map_or_else(|| id.to_string(), |f| f.title.clone())
}

fn add(figures: &mut Vec<PageFigure>, report: &Report, id: &str, caption: String, svg: String) {
    let title = title(report, id);
    figures.push(PageFigure { id: id.into(), title, caption, svg, parts: vec![] });
}

/// Every figure of the page, in order.
pub fn page_figures(report: &Report) -> Result<Vec<PageFigure>> {
    let p = &report.plots;
    let mut figures = Vec::new();
    speed_figures(report, &mut figures)?;
    resistance_figures(report, &mut figures)?;
    step_figures(report, &mut figures)?;

    // fig6a-d: the four phase diagrams, in the paper's order (a, b: 0.35 kg on level sand and
    // at 24 deg; c, d: 1 kg), drawn as one 2 x 2 figure so the panel letters match the paper's.
    let regimes: Vec<String> = PHASE_PANELS
        .iter()
        .zip(&p.phase)
        .map(|((id, ..), panel)| format!("({}) {}", &id[4..], panel.terrain_regime))
        .collect();
    let fig = PhaseFigure::new(&p.phase, 2, report.plain_answer.terrain.clone());
    figures.push(PageFigure {
        id: "fig6".into(),
        title: "Phase diagrams: 0.35 kg and 1 kg, on level sand and at 24°".into(),
        caption: format!(
            "Regime over (k_n, k_s): blue sinkage, red slippage, yellow metastable, green success; the black line is s = R; the star is the terrain at that slope: {}. The paper (Fig. 6d) calls the 1 kg robot at 24° metastable.",
            regimes.join(", ")
        ),
        svg: to_svg(&fig)?,
        parts: PHASE_PANELS.iter().map(|(id, ..)| (id.to_string(), title(report, id))).collect(),
    });

    // p_fail against slope with the safe-slope limit.
    let fig = CurveFigure {
        curve: p.risk.points.iter().map(|q| (q.slope_deg, q.probabilities)).collect(),
        points: vec![],
        hi: 30.0,
        max_risk: p.max_risk,
        limit: p.safe_limit,
        success_limit: p.success_limit,
        title: format!("Failure risk of the {} kg robot", p.mass_kg),
    };
    let note = p.risk.defaults_used.note().map(|n| format!(" {n}.")).unwrap_or_default();
    add(
        &mut figures,
        report,
        "risk",
        format!(
            "p_fail = P(it sinks or slides back) and P(it does not climb steadily) (it sinks, slides back, or climbs slowly and may stall) with log-normal k_n, k_s (docs/model.md §9). Two limits at risk {r}: {}; {}. Between them the robot neither sinks nor slides back but likely climbs slowly and may stall (metastable): it can stall in its own trench.{note}",
            limit_words("the robot climbs steadily (P(not climbing steadily) < risk)", &p.success_limit),
            limit_words("it is safe (P(sinks or slides back) < risk)", &p.safe_limit),
            r = p.max_risk
        ),
        to_svg(&fig)?,
    );

    // The step budget.
    let fig = StepBudgetFigure { budget: &p.step_budget, repose: p.repose_deg };
    add(
        &mut figures,
        report,
        "step_budget",
        "The model's level step s* and what each term of docs/model.md §5 takes from it, up to the angle of repose: the net step is s* minus the three losses. Which term carries the lost step says what the model's speed rests on.".into(),
        to_svg(&fig)?,
    );

    // The stride simulator beside the closed form and the observations.
    if !p.simulated.is_empty() {
        let fig = SlopesFigure {
            sims: &p.simulated,
            pitch_locked: &p.simulated_pitch_locked,
            observed: &p.speeds,
            repose_deg: p.repose_deg,
        };
        add(
            &mut figures,
            report,
            "simulator",
            format!(
                "The dynamic stride simulator (docs/model.md §15-§18, {} s walks on the same robot and terrain) against the closed form and the observed speeds. Slopes where the simulated body pitched over (tumbled) are marked on the zero line and left out of its curve; the dashed curve is the same walks with the body's pitch locked, as the closed form assumes. The table \"The stride simulator against the closed form\" says where the two part and why.",
                sandslope::report::REPORT_WALK_S
            ),
            to_svg(&fig)?,
        );
    }

    // The calibration pulls.
    if let Some(c) = &report.calibration {
        let points = speed_pulls(&c.fit.pulls);
        let subtitle = format!(
            "χ²/dof = {}, floor {:.2} cm/s",
            c.fit.chi_squared_per_dof.map_or("-".into(), |r| format!("{r:.2}")),
            c.fit.error_floor_m_s * 100.0
        );
        add(&mut figures, report, "calibration", "The terrain's k_s shape scaled by a fitted plate_scale, with a fitted model-error floor (docs/calibration.md). Pulls beyond ±2 are red.".into(), to_svg(&CalibrationFigure { points: &points, curve: &p.calibrated_speed, subtitle: &subtitle })?);
    }
    Ok(figures)
}

/// fig3a (speed against slope) and fig3b (speed within a stride, with tracks).
fn speed_figures(report: &Report, figures: &mut Vec<PageFigure>) -> Result<()> {
    let p = &report.plots;
    let fig = SlopeCurveFigure {
        title: "Step-averaged upslope speed".into(),
        y_label: "speed v (cm/s)".into(),
        // No speed where the regime rules one out (docs/model.md §6).
        model: p
            .model
            .iter()
            .map(|q| (q.slope.degrees(), q.speed.filter(|_| !q.regime.is_failure()).map(|v| v * 100.0)))
            .collect(),
        ruled_out: p
            .model
            .iter()
            .map(|q| (q.slope.degrees(), q.speed.filter(|_| q.regime.is_failure()).map(|v| v * 100.0)))
            .collect(),
        model_label: model_label(report).into(),
        ruled_out_label: RULED_OUT.into(),
        observed: p.speeds.iter().map(|o| (o.slope.degrees(), o.speed * 100.0, o.speed_sd * 100.0)).collect(),
        observed_label: "observed (mean ± SD)".into(),
        reference: None,
        repose: p.repose_deg,
        from_zero: true,
        legend: SeriesLabelPosition::LowerLeft,
    };
    add(figures, report, "fig3a", "The model's step-averaged speed v = s/(T/2) (solid) and the observed speeds (mean ± SD as measured). Where the regime rules a speed out (slippage or sinkage, docs/model.md §6) the line is dashed and faded: the stance model's number, not a speed the robot makes.".into(), to_svg(&fig)?);

    if !p.strides.is_empty() {
        let slopes: Vec<String> = p.strides.iter().map(|(d, _)| format!("{d}°")).collect();
        let fig = StridePanels(p.strides.iter().map(|(_, r)| TrackFigure::new(r, None, &[])).collect());
        add(
            figures,
            report,
            "fig3b",
            format!(
                "The motion-capture tracks' upslope speed against time since touchdown, averaged over strides (mean ± SD band), with the mean anchoring time t1 (docs/model.md §11); one panel per tracked slope, lowest first: {}.",
                slopes.join(", ")
            ),
            to_svg(&fig)?,
        );
    }
    Ok(())
}

/// The legend of a model curve where its regime rules it out (dashed, faded).
const RULED_OUT: &str = "model where the regime rules it out";

/// fig4d, fig4h: k_n and k_s against slope with error bars.
fn resistance_figures(report: &Report, figures: &mut Vec<PageFigure>) -> Result<()> {
    let p = &report.plots;
    let plate_scale = p.plate_scale;
    let label =
        if p.table_is_forces { "force tests (mean ± SD)" } else { "terrain table (± SD where given)" };
    let unit_scale = 1e-5;
    for (id, title, pick) in
        [("fig4d", "Normal penetration resistance k_n", 0usize), ("fig4h", "Shear strength k_s", 1usize)]
    {
        let value = |p: &TerrainPoint| if pick == 0 { (p.k_n, p.k_n_sd) } else { (p.k_s, p.k_s_sd) };
        // Solid up to the terrain's last point, dashed beyond it, where Terrain::at extends
        // the last segment (both include the last point, so the line is unbroken).
        let last = p
            .last_point_deg
            .filter(|&l| p.model.iter().any(|q| q.slope.degrees() > l))
            .unwrap_or(f64::INFINITY);
        let curve = |measured: bool| {
            p.model
                .iter()
                .map(|q| {
                    let d = q.slope.degrees();
                    let keep = if measured { d <= last } else { d >= last };
                    (d, keep.then_some(if pick == 0 { q.k_n } else { q.k_s } * unit_scale))
                })
                .collect()
        };
        let fig = SlopeCurveFigure {
            title: title.into(),
            y_label: format!("{} (10⁵ N/m³)", if pick == 0 { "k_n" } else { "k_s" }),
            model: curve(true),
            ruled_out: curve(false),
            ruled_out_label: format!("extrapolated beyond the terrain's last point ({last}°)"),
            model_label: "terrain used by the model (interpolated)".into(),
            observed: p
                .table
                .iter()
                .map(|t| {
                    let (v, sd) = value(t);
                    let c = if pick == 1 { plate_scale } else { 1.0 };
                    (t.slope_deg, c * v * unit_scale, c * sd.unwrap_or(0.0) * unit_scale)
                })
                .collect(),
            observed_label: if pick == 1 && plate_scale != 1.0 {
                format!("{label} × plate_scale {plate_scale:.1}")
            } else {
                label.into()
            },
            reference: None,
            repose: p.repose_deg,
            from_zero: true,
            // Where the curves are not: k_n is flat, k_s falls with slope.
            legend: if pick == 0 { SeriesLabelPosition::LowerRight } else { SeriesLabelPosition::UpperRight },
        };
        let caption = if pick == 0 {
            "The paper: k_n \"remains nearly constant\" with slope (Fig. 4d).".to_string()
        } else {
            "The paper: k_s at 20° is about 40% of level (Fig. 4h). With force tests given, the model's leg k_s is plate_scale times the plate's (docs/calibration.md).".to_string()
        };
        add(figures, report, id, caption, to_svg(&fig)?);
    }
    Ok(())
}

/// fig5b (anchoring time) and fig5c (net step).
fn step_figures(report: &Report, figures: &mut Vec<PageFigure>) -> Result<()> {
    let p: &Plots = &report.plots;
    let fig = SlopeCurveFigure {
        title: "Anchoring time t1".into(),
        y_label: "t1 (ms)".into(),
        model: split(p, |q| q.anchoring_time.map(|t| t * 1e3), false),
        ruled_out: split(p, |q| q.anchoring_time.map(|t| t * 1e3), true),
        model_label: "model".into(),
        ruled_out_label: RULED_OUT.into(),
        observed: p.anchoring.iter().map(|o| (o.slope.degrees(), o.t1 * 1e3, o.t1_sd * 1e3)).collect(),
        observed_label: "observed (mean ± SD)".into(),
        reference: None,
        repose: p.repose_deg,
        from_zero: true,
        legend: SeriesLabelPosition::UpperLeft,
    };
    add(figures, report, "fig5b", "The time after touchdown at which the leg reaches the shear-equilibrium depth d_s (docs/model.md §4). The paper plots measured t1 but prints no values; give --t1 (a CSV of means and SDs) or --tracks (motion-capture recordings) to overlay yours.".into(), to_svg(&fig)?);
    let half = p.stance_duration_s * 1e3;
    let fig = SlopeCurveFigure {
        title: "Net step length".into(),
        y_label: "net step s (mm)".into(),
        model: split(p, |q| q.step.map(|s| s * 1e3), false),
        ruled_out: split(p, |q| q.step.map(|s| s * 1e3), true),
        model_label: "model".into(),
        ruled_out_label: RULED_OUT.into(),
        observed: p.speeds.iter().map(|o| (o.slope.degrees(), o.speed * half, o.speed_sd * half)).collect(),
        observed_label: "observed speed × T/2".into(),
        reference: Some((p.min_step_m * 1e3, "s_min = R: success above, metastable below".into())),
        repose: p.repose_deg,
        from_zero: true,
        legend: SeriesLabelPosition::LowerLeft,
    };
    add(
        figures,
        report,
        "fig5c",
        "s = s2 - s1 (docs/model.md §5); the observed points are the observed speeds times T/2.".into(),
        to_svg(&fig)?,
    );
    Ok(())
}

/// The model's `value` where its regime allows it (`ruled_out = false`) or rules it out.
fn split(p: &Plots, value: impl Fn(&Prediction) -> Option<f64>, ruled_out: bool) -> Vec<(f64, Option<f64>)> {
    p.model
        .iter()
        .map(|q| (q.slope.degrees(), value(q).filter(|_| q.regime.is_failure() == ruled_out)))
        .collect()
}

/// The legend of the model: on the paper's evidence the terrain as given, else the calibration.
fn model_label(report: &Report) -> &'static str {
    if report.own_observations {
        "model calibrated on your observations"
    } else {
        "model on the terrain"
    }
}

/// One slope limit of the risk figure in words: `what` "up to X°" (one decimal), at the angle of
/// repose named so, or why there is none.
fn limit_words(what: &str, limit: &sandslope::risk::SafeLimit) -> String {
    use sandslope::risk::SafeLimit;
    match *limit {
        SafeLimit::Limit { value, .. } => format!("{what} up to {value:.1}°"),
        SafeLimit::Repose { repose_deg, .. } => format!("{what} up to the angle of repose, {repose_deg}°"),
        SafeLimit::NoneSafe { .. } => format!("{what} on no slope, not even level ground"),
        SafeLimit::BeyondRange { up_to, .. } => format!("{what} at every slope searched, up to {up_to}°"),
    }
}
