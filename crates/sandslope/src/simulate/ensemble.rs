//! Ensembles of walks (docs/simulate.md, "Pitch free"): the free body's walk on a slope is
//! chaotic (two walks whose masses differ by 1e-9 part by tens of degrees of pitch within
//! seconds), so a single walk is one draw from a spread, and what converges with the time
//! step is the spread's statistics. [`simulate_ensemble`] walks the robot `n` times with its
//! mass perturbed by `k` [`ENSEMBLE_PERTURBATION`] (relative, `k = 0..n`), far below any
//! scale's precision, and summarises them.

use rayon::prelude::*;
use serde::Serialize;

use super::{simulate, SimSettings, SimSummary, SimulateError};
use crate::error::ParamError;
use crate::gait::Stats;
use crate::regime::Regime;
use crate::scenario::Scenario;
use crate::slope::SignedSlope;

/// The relative mass step between an ensemble's walks.
pub const ENSEMBLE_PERTURBATION: f64 = 1e-9;
/// Smallest and largest ensemble.
pub const ENSEMBLE_RANGE: (usize, usize) = (2, 1000);

/// The mass of an ensemble's walk `k` for a robot of mass `mass`, kg: `mass (1 + k 1e-9)`.
pub fn perturbed_mass(mass: f64, k: usize) -> f64 {
    mass * (1.0 + ENSEMBLE_PERTURBATION * k as f64)
}

/// The walks of an ensemble and their statistics (what `simulate --ensemble N --json` prints).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Ensemble {
    /// Walks in the ensemble.
    pub walks: usize,
    /// The relative mass step between walks.
    pub perturbation: f64,
    /// Mean of the walks' mean step speeds, m/s.
    pub speed_m_s: f64,
    /// Their standard deviation across walks, m/s.
    pub speed_sd_m_s: f64,
    /// The mean's standard error, m/s.
    pub speed_se_m_s: f64,
    /// Mean anchoring time over the walks that anchored, s.
    pub t1_s: Option<f64>,
    /// Its standard error, s: the walks' t1s' SD over the root of their number (`None` with
    /// fewer than two anchored walks).
    pub t1_se_s: Option<f64>,
    /// Walks that pitched over (tumbled).
    pub pitched_over: usize,
    /// How many walks ended in each regime (every regime listed, zero or not).
    pub regimes: std::collections::BTreeMap<Regime, usize>,
    /// The regime most walks ended in (on a tie, the first in [`Regime`]'s order).
    pub regime: Regime,
    /// Every walk's summary, in order of `k`.
    pub summaries: Vec<SimSummary>,
}

/// Walks `scenario`'s robot `n` times at `slope` (2 to 1000; key `ensemble`), the mass of
/// walk `k` multiplied by `1 + k 1e-9`, in parallel, and summarises the spread.
pub fn simulate_ensemble(
    scenario: &Scenario,
    slope: SignedSlope,
    settings: &SimSettings,
    n: usize,
) -> Result<Ensemble, SimulateError> {
    let (lo, hi) = ENSEMBLE_RANGE;
    if !(lo..=hi).contains(&n) {
        return Err(ParamError::new(
            "ensemble",
            n as f64,
            format!("a whole number of walks from {lo} to {hi}"),
        )
        .into());
    }
    let mass = scenario.robot().mass();
    let summaries: Vec<SimSummary> = (0..n)
        .into_par_iter()
        .map(|k| {
            let robot = scenario.robot().with_mass(perturbed_mass(mass, k))?;
            Ok(simulate(&scenario.with_robot(robot), slope, settings)?.summary)
        })
        .collect::<Result<_, SimulateError>>()?;
    // n >= 2 walks, so the mean and its SD exist.
    let (mean, sd) = Stats::of(summaries.iter().map(|s| s.speed_m_s))
        .map_or((0.0, 0.0), |s| (s.mean, s.sd.unwrap_or(0.0)));
    let t1 = Stats::of(summaries.iter().filter_map(|s| s.t1_s));
    let mut regimes: std::collections::BTreeMap<Regime, usize> =
        [Regime::Success, Regime::Metastable, Regime::Slippage, Regime::Sinkage]
            .into_iter()
            .map(|r| (r, 0))
            .collect();
    for s in &summaries {
        *regimes.entry(s.regime).or_default() += 1;
    }
    // The most walks; on a tie the first in the map's order.
    let regime =
        regimes.iter().fold((Regime::Success, 0), |best, (&r, &c)| if c > best.1 { (r, c) } else { best }).0;
    Ok(Ensemble {
        walks: n,
        perturbation: ENSEMBLE_PERTURBATION,
        speed_m_s: mean,
        speed_sd_m_s: sd,
        speed_se_m_s: sd / (n as f64).sqrt(),
        t1_s: t1.map(|t| t.mean),
        t1_se_s: t1.and_then(|t| t.sd.map(|sd| sd / (t.n as f64).sqrt())),
        pitched_over: summaries.iter().filter(|s| s.pitch_over_s.is_some()).count(),
        regimes,
        regime,
        summaries,
    })
}
