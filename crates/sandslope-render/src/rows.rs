//! The CSV rows of results printed one row per item (`--csv` of `risk`, `fit` and `simulate`):
//! each a flat, serialisable view of a library value, columns in the order written. The
//! layouts without a row type of their own (the design study, the risk map) are in
//! [`crate::tables`]; `track`'s step row is the request layer's, shared with its `--json`.

use serde::Serialize;

use sandslope::measure::SlopeEstimate;
use sandslope::risk::{PayloadEnvelope, RiskPoint, SafeMass, SafeSlope};
use sandslope::simulate::convergence::{Refinement, WalkAnswer};
use sandslope::simulate::ensemble::perturbed_mass;
use sandslope::simulate::{ConvergenceCheck, Ensemble, SimSummary};

/// One slope of `risk --csv`: [`RiskPoint`] flattened.
#[derive(Debug, Clone, Serialize)]
pub struct RiskRow {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Coefficient of variation of k_n used.
    pub cv_n: f64,
    /// Coefficient of variation of k_s used.
    pub cv_s: f64,
    /// P(sinkage or slippage).
    pub p_fail: f64,
    /// P(not success).
    pub p_not_success: f64,
    /// P(success).
    pub p_success: f64,
    /// P(metastable).
    pub p_metastable: f64,
    /// P(slippage).
    pub p_slippage: f64,
    /// P(sinkage).
    pub p_sinkage: f64,
}

impl RiskRow {
    /// The row of one slope.
    pub fn of(p: &RiskPoint) -> RiskRow {
        RiskRow {
            slope_deg: p.slope_deg,
            cv_n: p.uncertainty.cv_n,
            cv_s: p.uncertainty.cv_s,
            p_fail: p.p_fail,
            p_not_success: p.p_not_success,
            p_success: p.probabilities.success,
            p_metastable: p.probabilities.metastable,
            p_slippage: p.probabilities.slippage,
            p_sinkage: p.probabilities.sinkage,
        }
    }
}

/// One slope of `risk --solve mass --csv` (and of the payload envelope).
#[derive(Debug, Clone, Serialize)]
pub struct MassRow {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// The risk bound.
    pub max_risk: f64,
    /// The robot's own mass, kg.
    pub robot_mass_kg: f64,
    /// Largest total mass within the bound, kg.
    pub max_mass_kg: Option<f64>,
    /// Largest payload within the bound, kg.
    pub max_payload_kg: Option<f64>,
}

impl MassRow {
    /// The row of one mass limit.
    pub fn of(s: &SafeMass) -> MassRow {
        MassRow {
            slope_deg: s.slope_deg,
            max_risk: s.max_risk,
            robot_mass_kg: s.robot_mass_kg,
            max_mass_kg: s.max_mass_kg,
            max_payload_kg: s.max_payload_kg,
        }
    }

    /// One row per slope of a payload envelope.
    pub fn envelope(env: &PayloadEnvelope) -> Vec<MassRow> {
        env.points
            .iter()
            .map(|p| MassRow {
                slope_deg: p.slope_deg,
                max_risk: env.max_risk,
                robot_mass_kg: env.robot_mass_kg,
                max_mass_kg: p.max_mass_kg,
                max_payload_kg: p.max_payload_kg,
            })
            .collect()
    }
}

/// The one row of `risk --solve slope --csv`.
#[derive(Debug, Clone, Serialize)]
pub struct SafeSlopeRow {
    /// The risk bound.
    pub max_risk: f64,
    /// Steepest slope with P(not success) below the bound, degrees.
    pub success_slope_deg: Option<f64>,
    /// What ended that search.
    pub success_limit_kind: &'static str,
    /// Steepest slope with p_fail below the bound, degrees.
    pub safe_slope_deg: Option<f64>,
    /// What ended that search.
    pub safe_limit_kind: &'static str,
}

impl SafeSlopeRow {
    /// The row of the slope limits.
    pub fn of(sol: &SafeSlope) -> SafeSlopeRow {
        SafeSlopeRow {
            max_risk: sol.max_risk,
            success_slope_deg: sol.success_slope_deg,
            success_limit_kind: sol.success_limit.kind(),
            safe_slope_deg: sol.safe_slope_deg,
            safe_limit_kind: sol.limit.kind(),
        }
    }
}

/// One slope of `fit --csv`: the terrain table's point with its trial counts.
#[derive(Debug, Clone, Serialize)]
pub struct FitRow {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// k_n, N/m^3.
    pub k_n: f64,
    /// Its combined SD.
    pub k_n_sd: f64,
    /// k_s, N/m^3.
    pub k_s: f64,
    /// Its combined SD.
    pub k_s_sd: f64,
    /// Penetration trials behind k_n.
    pub trials_penetration: usize,
    /// Shear trials behind k_s.
    pub trials_shear: usize,
    /// What was interpolated, `; `-separated.
    pub interpolated: String,
}

impl FitRow {
    /// The row of one slope's estimate.
    pub fn of(p: &SlopeEstimate) -> FitRow {
        FitRow {
            slope_deg: p.slope_deg,
            k_n: p.k_n.mean,
            k_n_sd: p.k_n.sd,
            k_s: p.k_s.mean,
            k_s_sd: p.k_s.sd,
            trials_penetration: p.k_n.trials,
            trials_shear: p.k_s.trials,
            interpolated: p.notes().join("; "),
        }
    }
}

/// One slope of `simulate --slopes --csv`: the walk beside the closed form.
#[derive(Debug, Clone, Serialize)]
pub struct SimSlopeRow {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Mean speed, m/s.
    pub speed_m_s: f64,
    /// Mean anchoring time, s.
    pub t1_s: Option<f64>,
    /// Mean slip, m.
    pub slip_m: Option<f64>,
    /// Mean step, m.
    pub step_m: f64,
    /// Deepest leg, m.
    pub max_depth_m: f64,
    /// Largest pitch, degrees.
    pub max_pitch_deg: f64,
    /// When the body pitched over, s.
    pub pitch_over_s: Option<f64>,
    /// The walk's regime.
    pub regime: &'static str,
    /// Why.
    pub cause: &'static str,
    /// The closed form's speed, m/s.
    pub closed_form_speed_m_s: Option<f64>,
    /// The closed form's t1, s.
    pub closed_form_t1_s: Option<f64>,
    /// The closed form's slip, m.
    pub closed_form_slip_m: Option<f64>,
    /// The closed form's step, m.
    pub closed_form_step_m: Option<f64>,
    /// The closed form's regime.
    pub closed_form_regime: &'static str,
}

impl SimSlopeRow {
    /// The row of one walk's summary.
    pub fn of(m: &SimSummary) -> SimSlopeRow {
        let p = &m.closed_form.prediction;
        SimSlopeRow {
            slope_deg: m.slope_deg,
            speed_m_s: m.speed_m_s,
            t1_s: m.t1_s,
            slip_m: m.slip_m,
            step_m: m.step_m,
            max_depth_m: m.max_depth_m,
            max_pitch_deg: m.max_pitch_deg,
            pitch_over_s: m.pitch_over_s,
            regime: m.regime.name(),
            cause: m.cause.name(),
            closed_form_speed_m_s: m.closed_form.speed(),
            closed_form_t1_s: p.anchoring_time,
            closed_form_slip_m: p.slip,
            closed_form_step_m: p.step,
            closed_form_regime: p.regime.name(),
        }
    }
}

/// One walk of `simulate --ensemble N --csv`.
#[derive(Debug, Clone, Serialize)]
pub struct EnsembleRow {
    /// The walk's index.
    pub walk: usize,
    /// Its perturbed mass, kg.
    pub mass_kg: f64,
    /// Mean speed, m/s.
    pub speed_m_s: f64,
    /// Mean anchoring time, s.
    pub t1_s: Option<f64>,
    /// Mean step, m.
    pub step_m: f64,
    /// Largest pitch, degrees.
    pub max_pitch_deg: f64,
    /// When the body pitched over, s.
    pub pitch_over_s: Option<f64>,
    /// The walk's regime.
    pub regime: &'static str,
    /// Why.
    pub cause: &'static str,
}

impl EnsembleRow {
    /// One row per walk of an ensemble of a robot of `mass_kg`.
    pub fn rows(e: &Ensemble, mass_kg: f64) -> Vec<EnsembleRow> {
        e.summaries
            .iter()
            .enumerate()
            .map(|(k, m)| EnsembleRow {
                walk: k,
                mass_kg: perturbed_mass(mass_kg, k),
                speed_m_s: m.speed_m_s,
                t1_s: m.t1_s,
                step_m: m.step_m,
                max_pitch_deg: m.max_pitch_deg,
                pitch_over_s: m.pitch_over_s,
                regime: m.regime.name(),
                cause: m.cause.name(),
            })
            .collect()
    }
}

/// One setting of `simulate --check-convergence --csv`: at each slope the walk as asked, then
/// each refined walk against it.
#[derive(Debug, Clone, Serialize)]
pub struct ConvergenceRow {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// `as_asked`, `quarter_step` or `tenth_creep`.
    pub walk: &'static str,
    /// Time step, s.
    pub dt_s: f64,
    /// Creep speed, m/s.
    pub creep_m_s: f64,
    /// Mean speed, m/s (an ensemble's mean).
    pub speed_m_s: f64,
    /// The ensemble mean's standard error, m/s (empty for one walk).
    pub speed_se_m_s: Option<f64>,
    /// The spread of the steps' speeds (standard deviation), m/s (an ensemble's mean).
    pub step_speed_sd_m_s: f64,
    /// Mean anchoring time, s.
    pub t1_s: Option<f64>,
    /// Regime.
    pub regime: &'static str,
    /// Speed minus the walk as asked, m/s (empty on its own row).
    pub speed_change_m_s: Option<f64>,
    /// t1 minus the walk as asked, s.
    pub t1_change_s: Option<f64>,
    /// The steps' spread minus the walk as asked's, m/s.
    pub step_speed_sd_change_m_s: Option<f64>,
    /// Within the tolerances (empty on the walk's own row).
    pub converged: Option<bool>,
}

impl ConvergenceRow {
    /// The walk's row, then one per refinement.
    pub fn rows(c: &ConvergenceCheck) -> Vec<ConvergenceRow> {
        let row = |walk, a: &WalkAnswer| ConvergenceRow {
            slope_deg: c.slope_deg,
            walk,
            dt_s: a.dt_s,
            creep_m_s: a.creep_m_s,
            speed_m_s: a.speed_m_s,
            speed_se_m_s: a.speed_se_m_s,
            step_speed_sd_m_s: a.step_speed_sd_m_s,
            t1_s: a.t1_s,
            regime: a.regime.name(),
            speed_change_m_s: None,
            t1_change_s: None,
            step_speed_sd_change_m_s: None,
            converged: None,
        };
        let mut rows = vec![row("as_asked", &c.walk)];
        for r in &c.refinements {
            let name = match r.refinement {
                Refinement::QuarterStep => "quarter_step",
                Refinement::TenthCreep => "tenth_creep",
            };
            rows.push(ConvergenceRow {
                speed_change_m_s: Some(r.speed_change_m_s),
                t1_change_s: r.t1_change_s,
                step_speed_sd_change_m_s: Some(r.step_speed_sd_change_m_s),
                converged: Some(r.converged),
                ..row(name, &r.answer)
            });
        }
        rows
    }
}
