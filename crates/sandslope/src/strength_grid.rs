//! [`StrengthGrid`]: a robot at a slope, on a terrain with its angle of repose, over a grid of
//! the sand's strengths k_n x k_s. What a phase map (docs/model.md §6) and a risk map (§9) are
//! computed over, one value rather than five arguments that travel together.

use crate::axis::Axis;
use crate::robot::Robot;
use crate::slope::Slope;

/// A robot at a slope on a terrain whose angle of repose is `repose`, over the grid
/// `k_n x k_s` (k_n along a row, one row per k_s).
#[derive(Debug, Clone, Copy)]
pub struct StrengthGrid<'a> {
    /// The robot.
    pub robot: &'a Robot,
    /// The slope it climbs (a descent is evaluated as the climb of its size, §8).
    pub slope: Slope,
    /// The terrain's angle of repose, if it has one: at or beyond it every cell slips.
    pub repose: Option<Slope>,
    /// The normal resistances k_n, N/m^3: the grid's columns.
    pub k_n: &'a Axis,
    /// The shear strengths k_s, N/m^3: the grid's rows.
    pub k_s: &'a Axis,
}

impl<'a> StrengthGrid<'a> {
    /// The grid of `k_n x k_s` for `robot` at `slope`, with the terrain's angle of repose.
    pub fn new(robot: &'a Robot, slope: Slope, repose: Option<Slope>, k_n: &'a Axis, k_s: &'a Axis) -> Self {
        StrengthGrid { robot, slope, repose, k_n, k_s }
    }

    /// Whether the slope is at or beyond the angle of repose (every cell slips, §6).
    pub fn beyond_repose(&self) -> bool {
        self.repose.is_some_and(|r| self.slope.radians() >= r.radians())
    }

    /// The number of cells.
    pub fn cells(&self) -> usize {
        self.k_n.len() * self.k_s.len()
    }
}
