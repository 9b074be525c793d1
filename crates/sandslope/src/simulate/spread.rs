//! The contact scaling as model uncertainty (issue 59 items 1 and 4; docs/simulate.md, "The
//! scaling as model uncertainty"). How resistive force theory is scaled to the terrain's k_n
//! and k_s (docs/model.md §16) is not measured, and on steep slopes it decides the answer: at 24
//! degrees the built-in robot slides back under `motion` and `li2013` and climbs at 31 cm/s
//! under `components`. [`scaling_spread`] walks one slope under all three scalings, the other
//! settings as given, and gives the range of their speeds and whether their regimes agree.

use rayon::prelude::*;
use serde::Serialize;

use super::{simulate, RftScaling, SimSettings, SimSummary, SimulateError};
use crate::regime::Regime;
use crate::scenario::Scenario;
use crate::slope::SignedSlope;

/// The three scalings, in the order [`ScalingSpread::walks`] lists them.
pub const SCALINGS: [RftScaling; 3] = [RftScaling::Motion, RftScaling::Li2013, RftScaling::Components];

/// One slope walked under every scaling.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScalingSpread {
    /// The slope, degrees.
    pub slope_deg: f64,
    /// The smallest of the walks' speeds, m/s.
    pub min_speed_m_s: f64,
    /// The largest, m/s.
    pub max_speed_m_s: f64,
    /// Whether every scaling's walk ended in the same regime.
    pub regimes_agree: bool,
    /// Each scaling's regime, in [`SCALINGS`]' order.
    pub regimes: [Regime; 3],
    /// Each scaling's walk, in [`SCALINGS`]' order.
    pub walks: Vec<SimSummary>,
}

/// Walks `scenario`'s robot at `slope` under each of [`SCALINGS`] (in parallel), every other
/// setting as in `settings` (whose own scaling is ignored).
pub fn scaling_spread(
    scenario: &Scenario,
    slope: SignedSlope,
    settings: &SimSettings,
) -> Result<ScalingSpread, SimulateError> {
    let walks = SCALINGS
        .par_iter()
        .map(|&s| simulate(scenario, slope, &settings.with_rft_scaling(s)).map(|w| w.summary))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(ScalingSpread::of_walks(slope.degrees(), walks))
}

impl ScalingSpread {
    /// The spread of three walks of one slope already walked, one under each of [`SCALINGS`]
    /// in that order (what a front end that walked the asked scaling itself, and the other two
    /// beside it, sets side by side; [`scaling_spread`] walks all three).
    ///
    /// # Panics
    /// If `walks` is not three long.
    pub fn of_walks(slope_deg: f64, walks: Vec<SimSummary>) -> ScalingSpread {
        assert_eq!(walks.len(), SCALINGS.len(), "one walk per scaling");
        let speeds = walks.iter().map(|w| w.speed_m_s);
        let regimes = [walks[0].regime, walks[1].regime, walks[2].regime];
        ScalingSpread {
            slope_deg,
            min_speed_m_s: speeds.clone().fold(f64::INFINITY, f64::min),
            max_speed_m_s: speeds.fold(f64::NEG_INFINITY, f64::max),
            regimes_agree: regimes.iter().all(|&r| r == regimes[0]),
            regimes,
            walks,
        }
    }
}
