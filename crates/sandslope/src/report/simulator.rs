//! The report's simulator section: the stride simulator (docs/model.md §15-§18) beside the
//! closed form and the observations, slope by slope, and where and why the two part
//! (docs/simulate.md).

use serde::Serialize;

use crate::calibrate::SpeedObservation;
use crate::error::ParamError;
use crate::regime::Regime;
use crate::robot::Robot;
use crate::scenario::Scenario;
use crate::simulate::{simulate_slopes, BodyPitch, MotionCause, SimSettings, SimSummary};
use crate::terrain::Terrain;

/// Simulated seconds per slope in the report (after the simulator's settling).
pub const REPORT_WALK_S: f64 = 10.0;

/// Relative speed difference up to which simulator and closed form are said to agree (the
/// threshold of issue 23's table of reasons).
pub const AGREE_WITHIN: f64 = 0.15;

/// One slope of the simulator section.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SimulatorRecord {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Observed speed at this slope, if any, m/s.
    pub observed_m_s: Option<f64>,
    /// Its SD, m/s.
    pub observed_sd_m_s: Option<f64>,
    /// The simulator's mean step speed, m/s (describes a tumbling body when it pitched over).
    pub simulated_m_s: f64,
    /// The closed form's speed (`null` where its regime rules a speed out), m/s.
    pub closed_form_m_s: Option<f64>,
    /// The regime read from the simulated motion.
    pub simulated_regime: Regime,
    /// Its cause.
    pub simulated_cause: MotionCause,
    /// The closed form's regime.
    pub closed_form_regime: Regime,
    /// The simulator's mean anchoring time over the measured steps that anchored, s (`null`:
    /// no step anchored).
    pub simulated_t1_s: Option<f64>,
    /// The closed form's anchoring time t1, s (`null`: it does not anchor).
    pub closed_form_t1_s: Option<f64>,
    /// The simulator's mean backward slip before anchoring, m.
    pub simulated_slip_m: Option<f64>,
    /// The closed form's slip `1/2 g sin(theta) t1^2`, m.
    pub closed_form_slip_m: Option<f64>,
    /// The simulator's mean net step, m.
    pub simulated_step_m: f64,
    /// The closed form's net step s, m.
    pub closed_form_step_m: Option<f64>,
    /// Largest |pitch| of the simulated body, degrees.
    pub max_pitch_deg: f64,
    /// When the simulated body pitched past 90 degrees, s (`null`: it did not).
    pub pitch_over_s: Option<f64>,
    /// The simulator's mean step speed with the body's pitch locked (the closed form's
    /// no-pitch assumption, docs/model.md §15), m/s.
    pub pitch_locked_m_s: f64,
    /// The regime of that walk.
    pub pitch_locked_regime: Regime,
    /// Its cause.
    pub pitch_locked_cause: MotionCause,
    /// Whether the two agree: same regime and, where both have a speed, within 15%.
    pub agree: bool,
    /// Where they part and why, in words.
    pub why: String,
}

/// The slopes of the section: 0 to 24 degrees every 2, and every observed slope, below the
/// terrain's angle of repose.
pub fn section_slopes(speeds: &[SpeedObservation], terrain: &Terrain) -> Vec<f64> {
    let repose = terrain.spec().repose_deg.unwrap_or(90.0);
    let mut slopes: Vec<f64> = (0..=12).map(|i| 2.0 * f64::from(i)).collect();
    slopes.extend(speeds.iter().map(|o| o.slope.degrees()));
    slopes.retain(|&s| s < repose);
    slopes.sort_by(f64::total_cmp);
    slopes.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    slopes
}

/// The section's walks: every slope of [`section_slopes`] with the body free to pitch and
/// with its pitch locked, and the table's records.
#[derive(Debug, Clone)]
pub struct SimulatorWalks {
    /// One record per slope.
    pub records: Vec<SimulatorRecord>,
    /// The walks with the body free to pitch, in slope order.
    pub free: Vec<SimSummary>,
    /// The same walks with the pitch locked.
    pub pitch_locked: Vec<SimSummary>,
}

/// Simulates `robot` on `terrain` at every slope of [`section_slopes`] (10 s walks, the
/// simulator's defaults), once with the body free to pitch and once with its pitch locked,
/// and sets each beside the closed form and the observed speed.
pub fn simulator_section(
    robot: &Robot,
    terrain: &Terrain,
    speeds: &[SpeedObservation],
) -> Result<SimulatorWalks, ParamError> {
    let slopes = section_slopes(speeds, terrain);
    let scenario = Scenario::new(robot.clone(), terrain.clone(), None, None)?;
    let settings = SimSettings::new(REPORT_WALK_S)?;
    let walk = |settings: &SimSettings| -> Result<Vec<SimSummary>, ParamError> {
        let sims = simulate_slopes(&scenario, &slopes, settings).map_err(|e| match e {
            crate::simulate::SimulateError::Param(p) => p,
        })?;
        Ok(sims.into_iter().map(|s| s.summary).collect())
    };
    let free = walk(&settings)?;
    let pitch_locked = walk(&settings.with_body_pitch(BodyPitch::Locked))?;
    let rolling = crate::simulate::rigid_rolling_step(robot);
    let records = free
        .iter()
        .zip(&pitch_locked)
        .map(|(m, locked)| {
            let observed = speeds.iter().find(|o| (o.slope.degrees() - m.slope_deg).abs() < 1e-9);
            record(m, locked, observed, rolling)
        })
        .collect();
    Ok(SimulatorWalks { records, free, pitch_locked })
}

fn record(
    m: &SimSummary,
    locked: &SimSummary,
    observed: Option<&SpeedObservation>,
    rolling: f64,
) -> SimulatorRecord {
    let cf = m.closed_form.speed();
    let cf_regime = m.closed_form.prediction.regime;
    let (agree, mut why) = reason(m, cf, cf_regime, rolling);
    if m.pitch_over_s.is_some() {
        why.push_str(&format!(
            "; with the pitch locked: {:.1} cm/s, {} ({})",
            locked.speed_m_s * 100.0,
            locked.regime.name(),
            locked.cause.name()
        ));
    }
    SimulatorRecord {
        slope_deg: m.slope_deg,
        observed_m_s: observed.map(|o| o.speed),
        observed_sd_m_s: observed.map(|o| o.speed_sd),
        simulated_m_s: m.speed_m_s,
        closed_form_m_s: cf,
        simulated_regime: m.regime,
        simulated_cause: m.cause,
        closed_form_regime: cf_regime,
        simulated_t1_s: m.t1_s,
        closed_form_t1_s: m.closed_form.prediction.anchoring_time,
        simulated_slip_m: m.slip_m,
        closed_form_slip_m: m.closed_form.prediction.slip,
        simulated_step_m: m.step_m,
        closed_form_step_m: m.closed_form.prediction.step,
        max_pitch_deg: m.max_pitch_deg,
        pitch_over_s: m.pitch_over_s,
        pitch_locked_m_s: locked.speed_m_s,
        pitch_locked_regime: locked.regime,
        pitch_locked_cause: locked.cause,
        agree,
        why,
    }
}

/// Whether simulator and closed form agree at one slope, and the reason they part, short: the
/// page's paragraph above the table and docs/simulate.md explain each mechanism once.
fn reason(m: &SimSummary, cf: Option<f64>, cf_regime: Regime, rolling: f64) -> (bool, String) {
    if let Some(t) = m.pitch_over_s {
        return (
            false,
            format!("tumbled: the body pitched past 90° at t = {t:.2} s (the closed form has no pitch)"),
        );
    }
    let sim = m.speed_m_s;
    match cf {
        None => (
            m.regime == cf_regime,
            format!(
                "the closed form rules a speed out ({}); the simulated walk is {} ({})",
                cf_regime.name(),
                m.regime.name(),
                m.cause.name()
            ),
        ),
        Some(c) => {
            let rel = (sim - c) / c.abs().max(1e-12);
            let same = m.regime == cf_regime;
            let s_star = m.closed_form.prediction.level_step;
            if rel.abs() <= AGREE_WITHIN {
                (same, format!("within {:.0}% ({:+.0}%)", AGREE_WITHIN * 100.0, rel * 100.0))
            } else if rel > 0.0 {
                (
                    false,
                    format!(
                        "legs roll, body vaults ({:+.0}%): step {:.2} × the rigid rolling {}, {:.1} × s* = {}",
                        rel * 100.0,
                        m.step_m / rolling,
                        mm(Some(rolling)),
                        m.step_m / s_star,
                        mm(Some(s_star))
                    ),
                )
            } else {
                (
                    false,
                    format!(
                        "slower by {:.0}%: slip before anchoring {} against {}; not yet explained",
                        -rel * 100.0,
                        mm(m.slip_m),
                        mm(m.closed_form.prediction.slip)
                    ),
                )
            }
        }
    }
}

/// A length in millimetres for the reasons, `none` where undefined.
fn mm(v: Option<f64>) -> String {
    v.map_or("none".into(), |v| format!("{:.1} mm", v * 1e3))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::slope::Slope;
    use crate::terrain::{TerrainPoint, TerrainSpec};

    fn terrain(repose: f64) -> Terrain {
        Terrain::new(TerrainSpec {
            name: None,
            repose_deg: Some(repose),
            points: vec![TerrainPoint { slope_deg: 0.0, k_n: 7e5, k_s: 3e6, k_n_sd: None, k_s_sd: None }],
        })
        .unwrap()
    }

    /// The grid 0, 2, ..., 24 with the observed 15 added and the duplicate 10 merged; a
    /// repose of 20 cuts everything from 20 up.
    #[test]
    fn slopes_are_the_grid_plus_observed_below_repose() {
        let obs =
            |d: f64| SpeedObservation { slope: Slope::from_degrees(d).unwrap(), speed: 0.1, speed_sd: 0.01 };
        let s = section_slopes(&[obs(10.0), obs(15.0)], &terrain(25.0));
        assert_eq!(s.len(), 14);
        assert!(s.contains(&15.0) && s.contains(&24.0));
        let s = section_slopes(&[obs(15.0), obs(22.0)], &terrain(20.0));
        assert_eq!(s, vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 15.0, 16.0, 18.0]);
    }
}
