//! The outcomes in words: what the robot does at a slope, in a field engineer's words, with
//! the paper's regime name beside it, and why a stance ended in its regime (docs/model.md §6,
//! "Outcomes"). The library decides the [`Regime`] and [`Cause`]; every page, table and
//! sentence of every front end writes them through [`Outcome`] and [`Explain`], so there is one
//! vocabulary.
//! Files and JSON keep the library's names ([`Regime::name`], [`Cause::name`]).

use sandslope::plan::NoRoute;
use sandslope::{Cause, Regime};

/// A regime in words. Import it to write `regime.outcome()` and `regime.in_words()`.
pub trait Outcome {
    /// What the robot does: `climbs steadily` (success), `climbs slowly and may stall`
    /// (metastable: it progresses, but by less than a robust step, each foothold in sand the
    /// last one disturbed), `slides back` (slippage), `sinks` (sinkage).
    fn outcome(self) -> &'static str;

    /// The outcome with the paper's regime name beside it: `climbs slowly and may stall
    /// (metastable)`.
    fn in_words(self) -> String;
}

impl Outcome for Regime {
    fn outcome(self) -> &'static str {
        match self {
            Regime::Sinkage => "sinks",
            Regime::Slippage => "slides back",
            Regime::Metastable => "climbs slowly and may stall",
            Regime::Success => "climbs steadily",
        }
    }

    fn in_words(self) -> String {
        format!("{} ({})", self.outcome(), self.name())
    }
}

/// A cause in words. Import it to write `cause.explain()` (and `no_route.explain()`).
pub trait Explain {
    /// A one-line explanation: why the stance ended in its regime, or why a plan's objective
    /// found no route.
    fn explain(self) -> &'static str;
}

/// Why an objective of `plan` found no route: `plan`'s table, `plan --json`'s and `/api/plan`'s
/// `message`, and Python's.
impl Explain for NoRoute {
    fn explain(self) -> &'static str {
        match self {
            NoRoute::StartImpassable => {
                "start impassable: every heading out of the start cell is too steep or too cross-sloped"
            }
            NoRoute::GoalImpassable => {
                "goal impassable: every heading into the goal cell is too steep or too cross-sloped"
            }
            NoRoute::GoalUnreachable => "goal unreachable: no chain of passable edges joins start and goal",
        }
    }
}

impl Explain for Cause {
    fn explain(self) -> &'static str {
        match self {
            Cause::NormalSinkage => "legs sink: normal equilibrium depth d_n reaches the leg's reach 2R - h",
            Cause::AtOrAboveRepose => {
                "slope at or above the terrain's angle of repose: the surface itself yields"
            }
            Cause::NoAnchoring => {
                "no anchoring: shear-equilibrium depth d_s is beyond the leg's reach 2R - h"
            }
            Cause::NetBackwardStep => "backward slip before anchoring cancels propulsion: net step <= 0",
            Cause::ShortStep => {
                "progress, but the step is shorter than s_min: footholds land in disturbed sand"
            }
            Cause::RobustStep => "robust progress: step at least s_min",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// docs/model.md §6's outcomes, each beside its regime's name, and each cause's outcome its
    /// regime's (a short step is metastable: climbs slowly and may stall).
    #[test]
    fn outcomes_are_the_field_engineers_words() {
        assert_eq!(Regime::Metastable.in_words(), "climbs slowly and may stall (metastable)");
        assert_eq!(Regime::Success.in_words(), "climbs steadily (success)");
        assert_eq!(Regime::Slippage.outcome(), "slides back");
        assert_eq!(Regime::Sinkage.outcome(), "sinks");
        assert_eq!(Cause::ShortStep.regime().outcome(), "climbs slowly and may stall");
        assert!(Cause::NoAnchoring.explain().contains("d_s"));
    }

    /// Each reason a plan finds no route is worded with its file name first (`goal
    /// unreachable` for `goal_unreachable`, the name `plan --json` writes as `reason`), and
    /// says what blocked it.
    #[test]
    fn no_route_reasons_are_worded_after_their_names() {
        for (reason, name, why) in [
            (NoRoute::StartImpassable, "start_impassable", "out of the start cell"),
            (NoRoute::GoalImpassable, "goal_impassable", "into the goal cell"),
            (NoRoute::GoalUnreachable, "goal_unreachable", "no chain of passable edges"),
        ] {
            let words = reason.explain();
            assert!(words.starts_with(&format!("{}:", name.replace('_', " "))), "{words}");
            assert!(words.contains(why), "{words}");
        }
    }
}
