//! What the report compares and walks, given the evidence: on a robot other than the paper's
//! no number about the paper's 0.35 kg robot ([`another_robot_without_observations`],
//! [`terrain_rows_only`]); the counts of the comparisons ([`summary`]); and the simulator's
//! walks only on a plausible terrain ([`simulator_walks`]).

use serde::Serialize;

use super::simulator::{self, SimulatorWalks};
use super::Evidence;
use crate::calibrate::{CalibrationWarning, JointCalibration, SpeedObservation};
use crate::paper::{self, Basis, PaperComparison};
use crate::robot::Robot;
use crate::terrain::Terrain;

/// The comparison table summed up.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Comparisons whose basis is independent.
    pub independent: usize,
    /// Of those, how many agree.
    pub independent_agree: usize,
    /// Comparisons that agree by construction (input, tuned, consequence).
    pub by_construction_agree: usize,
    /// All comparisons.
    pub total: usize,
    /// The summary sentence: worded by the front end from the counts and the comparison rows
    /// (empty as [`super::report`] returns it).
    pub text: String,
}

/// The summary of `rows`: independent agreements counted (its sentence is the front end's,
/// worded from these counts and the rows; empty here).
pub(crate) fn summary(rows: &[PaperComparison]) -> Summary {
    let independent = rows.iter().filter(|r| r.basis == Basis::Independent).count();
    let independent_agree = rows.iter().filter(|r| r.basis == Basis::Independent && r.agrees).count();
    let by_construction_agree = rows.iter().filter(|r| r.basis != Basis::Independent && r.agrees).count();
    Summary { independent, independent_agree, by_construction_agree, total: rows.len(), text: String::new() }
}

/// Whether the report is on a robot other than the paper's ([`paper::is_papers_robot`])
/// without observations of its own (`--observed`, `--t1`, `--tracks`). Then the paper's speeds,
/// anchoring trend, step period and heavy-robot claim, all numbers about its 0.35 kg robot, are
/// neither fitted nor compared: the report is the model for this robot on this terrain,
/// untested, and only the terrain's ratios are set beside the paper's (the front end words the
/// warning first).
pub(crate) fn another_robot_without_observations(evidence: &Evidence) -> bool {
    !evidence.has_own_observations() && !paper::is_papers_robot(&evidence.robot)
}

/// The comparison rows that stand whatever the robot ([`paper::TERRAIN_ROWS`]); the front end
/// labels them as the terrain's against the paper's glass beads.
pub(crate) fn terrain_rows_only(rows: Vec<PaperComparison>) -> Vec<PaperComparison> {
    rows.into_iter().filter(|r| paper::TERRAIN_ROWS.contains(&r.id.as_str())).collect()
}

/// The quantity of `fit` that scales the terrain (any but the error floor) stopped at its search
/// bound, when the report's model is that fit (the evidence has observations of the user's):
/// `(name, value)`.
pub(crate) fn terrain_at_bound(fit: &JointCalibration, evidence: &Evidence) -> Option<(String, f64)> {
    if !evidence.has_own_observations() {
        return None;
    }
    fit.warnings.iter().find_map(|w| match w {
        CalibrationWarning::ParameterAtBound { name, value, .. } if name != "error_floor" => {
            Some((name.clone(), *value))
        }
        _ => None,
    })
}

/// Why the report's simulator section is left out (the front ends word it as a warning).
#[derive(Debug, Clone, PartialEq)]
pub enum SimulatorLeftOut {
    /// The model is the calibration on the user's observations, and the quantity `name` that
    /// scales its terrain ran to its search bound, at `value`: no terrain of the user's, and so
    /// stiff that the walks would take minutes.
    AtBound {
        /// The quantity.
        name: String,
        /// Where it stopped.
        value: f64,
    },
    /// The model's terrain has a stiffness outside [`crate::terrain::K_PLAUSIBLE`]
    /// (docs/model.md §7), where the walks take minutes.
    Implausible {
        /// `k_n` or `k_s`.
        key: &'static str,
        /// The value, N/m^3.
        value: f64,
        /// The slope of the terrain's point that has it, degrees.
        slope_deg: f64,
    },
    /// The simulator refuses the robot or the terrain: its error.
    Refused(String),
}

/// The simulator section's walks ([`simulator::simulator_section`]), or why they are left out:
/// the simulator refuses the robot; the model is a calibration whose terrain scale ran to its
/// search bound (`at_bound`, [`terrain_at_bound`]); or the model's terrain lies outside the
/// plausible range. The last two are no terrain of the user's, and stiff: one outlier speed
/// (5 m/s at 10 degrees among the paper's) took plate_scale to its bound 10^4 and k_s to 10^9
/// N/m^3, where the section's 70 walks took 115 s of CPU against 5 s for the whole clean report.
pub(crate) fn simulator_walks(
    robot: &Robot,
    terrain: &Terrain,
    speeds: &[SpeedObservation],
    at_bound: Option<(String, f64)>,
) -> Result<SimulatorWalks, SimulatorLeftOut> {
    if let Some((name, value)) = at_bound {
        return Err(SimulatorLeftOut::AtBound { name, value });
    }
    // No walk on a terrain outside the plausible range (docs/model.md §7), which only a fit run
    // to its search bound makes (one outlier speed took plate_scale to 10^4 and k_s to 3 x
    // 10^10 N/m^3): there its walks took minutes of CPU where the rest takes seconds.
    let k = crate::terrain::K_PLAUSIBLE;
    let implausible = terrain.points().iter().find_map(|p| {
        [("k_n", p.k_n), ("k_s", p.k_s)]
            .into_iter()
            .find(|(_, v)| !(k.min..=k.max).contains(v))
            .map(|(key, value)| SimulatorLeftOut::Implausible { key, value, slope_deg: p.slope_deg })
    });
    match implausible {
        Some(why) => Err(why),
        None => simulator::simulator_section(robot, terrain, speeds)
            .map_err(|e| SimulatorLeftOut::Refused(e.to_string())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::tests::paper_robot;

    /// A model terrain whose k_s is 3e10 N/m^3 (what a plate_scale of 10^4 makes of a 3e6
    /// table) lies beyond the plausible 1e10: no walk is made, and the reason names the value
    /// and the slope; a fit at its bound is named before any walk too.
    #[test]
    fn no_walk_on_an_implausible_terrain_or_a_fit_at_its_bound() {
        let stiff = Terrain::constant(7e5, 3e10).unwrap();
        let why = simulator_walks(&paper_robot(), &stiff, &[], None).unwrap_err();
        assert_eq!(why, SimulatorLeftOut::Implausible { key: "k_s", value: 3e10, slope_deg: 0.0 });
        let sand = Terrain::constant(7e5, 2e6).unwrap();
        let why = simulator_walks(&paper_robot(), &sand, &[], Some(("plate_scale".into(), 1e4))).unwrap_err();
        assert_eq!(why, SimulatorLeftOut::AtBound { name: "plate_scale".into(), value: 1e4 });
    }
}
