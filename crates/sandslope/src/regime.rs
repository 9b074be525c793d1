//! Locomotion regimes and the reason behind each (docs/model.md §6).
//!
//! The four regimes of the paper's phase diagrams are checked in a fixed order, the first
//! that holds wins (a choice of docs/model.md): sinkage, slippage, metastable, success. [`Cause`]
//! keeps the finer reason, because "slippage" has three distinct physical origins and a user
//! deciding what to change needs to know which.

use serde::{Deserialize, Serialize};
use std::fmt;

/// The outcome class of a stance on sand.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Regime {
    /// `d_n >= d_max`: the leg never finds normal support within its reach.
    Sinkage,
    /// At or above the angle of repose, no anchoring (`d_s > d_max`), or net step `s <= 0`.
    Slippage,
    /// `0 < s < s_min`: progress, but each foothold lands in disturbed sand.
    Metastable,
    /// `s >= s_min`: robust progress.
    Success,
}

impl Regime {
    /// All regimes in precedence order.
    pub const ALL: [Regime; 4] = [Regime::Sinkage, Regime::Slippage, Regime::Metastable, Regime::Success];

    /// The lowercase name used in files and JSON (`sinkage`, `slippage`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Regime::Sinkage => "sinkage",
            Regime::Slippage => "slippage",
            Regime::Metastable => "metastable",
            Regime::Success => "success",
        }
    }

    /// Whether this regime counts as failure (sinkage or slippage; docs/model.md §9).
    pub fn is_failure(self) -> bool {
        matches!(self, Regime::Sinkage | Regime::Slippage)
    }
}

impl fmt::Display for Regime {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Why a stance ended in its regime.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Cause {
    /// Normal equilibrium depth at or beyond the leg's reach (`d_n >= d_max`).
    NormalSinkage,
    /// The slope is at or above the terrain's angle of repose.
    AtOrAboveRepose,
    /// The shear-equilibrium depth is beyond the leg's reach (`d_s > d_max`).
    NoAnchoring,
    /// The leg anchors, but backward slip cancels propulsion (`s <= 0`).
    NetBackwardStep,
    /// Positive but short step (`0 < s < s_min`).
    ShortStep,
    /// Step at least `s_min`.
    RobustStep,
}

impl Cause {
    /// Every cause, in the order of the regimes they belong to (docs/model.md §6).
    pub const ALL: [Cause; 6] = [
        Cause::NormalSinkage,
        Cause::AtOrAboveRepose,
        Cause::NoAnchoring,
        Cause::NetBackwardStep,
        Cause::ShortStep,
        Cause::RobustStep,
    ];

    /// The regime this cause belongs to.
    pub fn regime(self) -> Regime {
        match self {
            Cause::NormalSinkage => Regime::Sinkage,
            Cause::AtOrAboveRepose | Cause::NoAnchoring | Cause::NetBackwardStep => Regime::Slippage,
            Cause::ShortStep => Regime::Metastable,
            Cause::RobustStep => Regime::Success,
        }
    }

    /// The snake_case name used in files and JSON (`at_or_above_repose`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Cause::NormalSinkage => "normal_sinkage",
            Cause::AtOrAboveRepose => "at_or_above_repose",
            Cause::NoAnchoring => "no_anchoring",
            Cause::NetBackwardStep => "net_backward_step",
            Cause::ShortStep => "short_step",
            Cause::RobustStep => "robust_step",
        }
    }

    /// Whether the stance model's speed `v = s / (T/2)` means nothing in this case: the legs
    /// sink (no normal support to walk on) or the slope is at or above the angle of repose
    /// (the surface itself yields, whatever the legs do). Elsewhere the speed stands, even a
    /// negative one (a net backward step: the robot loses ground).
    pub fn rules_out_speed(self) -> bool {
        matches!(self, Cause::NormalSinkage | Cause::AtOrAboveRepose)
    }
}

/// Classifies a stance by the precedence of docs/model.md §6.
///
/// `sunk`: `d_n >= d_max`; `beyond_repose`: slope at or above repose; `step`: the net step
/// `s`, `None` when the leg does not anchor; `min_step`: s_min.
pub fn classify(sunk: bool, beyond_repose: bool, step: Option<f64>, min_step: f64) -> Cause {
    if sunk {
        return Cause::NormalSinkage;
    }
    if beyond_repose {
        return Cause::AtOrAboveRepose;
    }
    match step {
        None => Cause::NoAnchoring,
        Some(s) if s <= 0.0 => Cause::NetBackwardStep,
        Some(s) if s < min_step => Cause::ShortStep,
        Some(_) => Cause::RobustStep,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn precedence_is_sinkage_slippage_metastable_success() {
        // Sinkage wins over everything, even a long step.
        assert_eq!(classify(true, true, Some(1.0), 0.04).regime(), Regime::Sinkage);
        // Repose wins over a long step.
        assert_eq!(classify(false, true, Some(1.0), 0.04), Cause::AtOrAboveRepose);
        assert_eq!(classify(false, false, None, 0.04), Cause::NoAnchoring);
        assert_eq!(classify(false, false, Some(0.0), 0.04), Cause::NetBackwardStep);
        assert_eq!(classify(false, false, Some(0.039), 0.04).regime(), Regime::Metastable);
        // s = s_min exactly is success (s >= s_min).
        assert_eq!(classify(false, false, Some(0.04), 0.04).regime(), Regime::Success);
    }
}
