//! The candidate mechanisms for the level stride (docs/model.md §20, issue 38 item 4): switches
//! that each add one piece of physics resistive force theory as the simulator has it leaves
//! out, so that their effect on the walk can be tabled one at a time (docs/simulate.md
//! "The level stride against the paper"). Every switch is off by default, and off it leaves
//! the walk bit for bit as it was, except the one-sided belly, on by default since
//! 2026-12-07 (docs/simulate.md, "Phase 1": the evidence).
//!
//! - [`Mechanisms::leg_friction`]: Coulomb friction between leg and grains caps the stress
//!   along an element's surface (§20.1).
//! - [`Mechanisms::duty_cycle`]: a gait that turns the stance half turn slower than the swing
//!   (§20.2).
//! - [`Mechanisms::one_sided_belly`]: the belly has sand below it only, so it never holds the
//!   body down (§20.5, issue 59).
//! - [`Mechanisms::servo_actuator`]: the legs driven by the servo's motor, not ideal position
//!   sources (§20.6, issue 59).
//! - [`Mechanisms::disturbed_sand`]: sand a leg has already passed through resists less (the
//!   trench, §20.3): [`Trench`].
//!
//! The servo's speed-torque curve applied to the leg rates between velocity solves moved its
//! answer from 34.1 to 22.9 cm/s as the step was refined (docs/model.md §20.4); solved with
//! them, it is [`Mechanisms::servo_actuator`].

use serde::{Deserialize, Serialize};

use crate::error::ParamError;

/// Smallest and largest leg-sand friction coefficient a walk takes.
pub const LEG_FRICTION_RANGE: (f64, f64) = (0.0, 10.0);
/// Smallest and largest duty cycle a walk takes (the stance half turn's share of the period).
pub const DUTY_CYCLE_RANGE: (f64, f64) = (0.1, 0.9);
/// The paper's gait: both half turns at one speed.
pub const CONSTANT_SPEED_DUTY: f64 = 0.5;
/// Disturbed sand as strong as undisturbed: the trench switched off.
pub const UNDISTURBED_SAND: f64 = 1.0;
/// Width of the trench map's cells along the slope, m.
pub const TRENCH_CELL_M: f64 = 1e-3;
/// Most cells the trench map holds (80 MB of depths: 10 km of travel at 1 mm); sand beyond
/// them is taken as undisturbed.
pub const MAX_TRENCH_CELLS: usize = 10_000_000;

/// The switches of docs/model.md §20, all off by default ([`Mechanisms::default`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Mechanisms {
    /// Leg-sand friction coefficient mu (§20.1): the stress along an element's surface is at
    /// most mu times the stress normal to it. `None`: resistive force theory's stresses as
    /// they are (the generic coefficients were measured with plates of their own roughness).
    pub leg_friction: Option<f64>,
    /// Share of the stride period over which a leg turns the half turn from its touchdown
    /// (§20.2); 0.5 (the default): one speed all round, the paper's gait.
    pub duty_cycle: f64,
    /// Resistance of sand that a leg passed through in an earlier stance, as a share of the
    /// undisturbed sand's (§20.3); 1 (the default): the sand is as strong as before.
    pub disturbed_sand: f64,
    /// The belly as the body's underside (§20.5): sand below it only, so it pushes and never
    /// pulls, its along-surface stress capped by its push. `true` (the default since
    /// 2026-12-07, docs/simulate.md "Phase 1": the paper's backward slip after touchdown on
    /// slopes and none on level sand, and a free body that climbs 0 to 20 degrees); `false`
    /// (`--two-faced-belly`): a plate in sand on both faces, as resistive force theory's plates
    /// were, which holds a body being lifted off the sand. Serialised only when off, so a
    /// default walk's output keeps its keys; read as on when absent.
    #[serde(default = "one_sided_by_default", skip_serializing_if = "is_on")]
    pub one_sided_belly: bool,
    /// Each leg driven by the XL330-M288's motor (its torque-speed line and current limit),
    /// its rate solved with the body's in the implicit step (§20.6), instead of an ideal
    /// position source. Serialised only when on.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub servo_actuator: bool,
}

impl Default for Mechanisms {
    fn default() -> Mechanisms {
        Mechanisms {
            leg_friction: None,
            duty_cycle: CONSTANT_SPEED_DUTY,
            disturbed_sand: UNDISTURBED_SAND,
            one_sided_belly: true,
            servo_actuator: false,
        }
    }
}

/// The belly's default for serde: one-sided ([`Mechanisms::default`]).
fn one_sided_by_default() -> bool {
    true
}

/// Whether a switch is on (serde's `skip_serializing_if` for a default-on switch).
fn is_on(on: &bool) -> bool {
    *on
}

impl Mechanisms {
    /// Checks every switch's range; errors name the key (`leg_friction`, `duty_cycle`,
    /// `disturbed_sand`).
    pub fn checked(self) -> Result<Mechanisms, ParamError> {
        if let Some(mu) = self.leg_friction {
            let (lo, hi) = LEG_FRICTION_RANGE;
            if !(mu.is_finite() && mu >= lo && mu <= hi) {
                return Err(ParamError::new("leg_friction", mu, format!("between {lo} and {hi}")));
            }
        }
        let (lo, hi) = DUTY_CYCLE_RANGE;
        if !(self.duty_cycle.is_finite() && self.duty_cycle >= lo && self.duty_cycle <= hi) {
            return Err(ParamError::new("duty_cycle", self.duty_cycle, format!("between {lo} and {hi}")));
        }
        if !(self.disturbed_sand.is_finite() && self.disturbed_sand > 0.0 && self.disturbed_sand <= 1.0) {
            return Err(ParamError::new(
                "disturbed_sand",
                self.disturbed_sand,
                "greater than 0 and at most 1",
            ));
        }
        Ok(self)
    }
}

/// The gait's clock (docs/model.md §20.2): the angle a leg has turned `t` s after a
/// touchdown, and its rate, for stride period `period` and duty cycle `duty`: the half turn
/// from touchdown in `duty * period`, the other half in the rest. `t` may be negative.
pub fn gait_angle(t: f64, period: f64, duty: f64) -> (f64, f64) {
    use std::f64::consts::PI;
    let k = (t / period).floor();
    let tau = t - k * period;
    let stance = duty * period;
    let (within, rate) = if tau < stance {
        (PI * tau / stance, PI / stance)
    } else {
        (PI + PI * (tau - stance) / (period - stance), PI / (period - stance))
    };
    (2.0 * PI * k + within, rate)
}

/// The constant-speed gait's angle turned `t` s after the gait starts, and its rate, with a
/// run-up of `ramp` s at constant acceleration (docs/model.md §19, the command `sandslope
/// drive` sends): `omega t^2 / (2 r)` and `omega t / r` for `t < r`, then `omega (t - r / 2)`
/// and omega; `ramp = 0` is §15's `omega t`. Before the start (`t < 0`) the legs stand.
pub fn run_up_angle(t: f64, omega: f64, ramp: f64) -> (f64, f64) {
    let t = t.max(0.0);
    if t < ramp {
        (0.5 * omega * t * t / ramp, omega * t / ramp)
    } else {
        (omega * (t - 0.5 * ramp), omega)
    }
}

/// Caps the stress `(sx, sz)` on an element of unit tangent `(tx, tz)` at leg-sand friction
/// `mu` (docs/model.md §20.1): its component along the surface at most `mu` times the
/// magnitude of its component normal to it. Returns the capped stress and, when capped, the
/// factor `mu sign(s_t) sign(s_n)` that maps the normal component's change onto the
/// tangential one (for the Jacobian); `None` when the stress is within the cone.
#[inline]
pub(crate) fn friction_cap(mu: f64, tx: f64, tz: f64, sx: f64, sz: f64) -> ((f64, f64), Option<f64>) {
    let (nx, nz) = (-tz, tx);
    let along = sx * tx + sz * tz;
    let normal = sx * nx + sz * nz;
    let cap = mu * normal.abs();
    if along.abs() <= cap {
        return ((sx, sz), None);
    }
    let capped = cap.copysign(along);
    let slope = mu * along.signum() * normal.signum();
    ((capped * tx + normal * nx, capped * tz + normal * nz), Some(slope))
}

/// How [`one_sided_cap`] changed a stress, for its derivative.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Capped {
    /// Not at all.
    Free,
    /// To zero (the law would pull): its derivative is zero.
    Zero,
    /// The along-surface part capped at `mu` times the push: it follows the normal part with
    /// this factor (`mu sign(s_t)`).
    Along(f64),
}

/// The stress `(sx, sz)` on a one-sided element of unit tangent `(tx, tz)`, the sand on its
/// right-hand side (docs/model.md §20.5): its component along `n = (-tz, tx)` (the push) at
/// least 0, and its component along the surface at most `mu` times that push. Continuous in
/// the stress: as the push falls to zero, so does the along-surface part.
#[inline]
pub(crate) fn one_sided_cap(mu: f64, tx: f64, tz: f64, sx: f64, sz: f64) -> ((f64, f64), Capped) {
    let (nx, nz) = (-tz, tx);
    let along = sx * tx + sz * tz;
    let normal = sx * nx + sz * nz;
    if normal <= 0.0 {
        return ((0.0, 0.0), Capped::Zero);
    }
    let cap = mu * normal;
    if along.abs() <= cap {
        return ((sx, sz), Capped::Free);
    }
    let capped = cap.copysign(along);
    ((capped * tx + normal * nx, capped * tz + normal * nz), Capped::Along(mu * along.signum()))
}

/// A depth per cell along the slope, grown to the cells written (at most
/// [`MAX_TRENCH_CELLS`]).
#[derive(Debug, Clone, Default)]
struct DepthMap {
    start: i64,
    depth: Vec<f64>,
}

impl DepthMap {
    fn get(&self, cell: i64) -> f64 {
        let i = cell - self.start;
        if i < 0 {
            return 0.0;
        }
        self.depth.get(i as usize).copied().unwrap_or(0.0)
    }

    fn raise(&mut self, cell: i64, d: f64) {
        if self.depth.is_empty() {
            self.start = cell;
        }
        if cell < self.start {
            // Grown at the front by at least its own length (a robot sliding downslope adds a
            // cell or two a step; one at a time would move the whole map each step).
            let need = (self.start - cell) as usize;
            let room = MAX_TRENCH_CELLS.saturating_sub(self.depth.len());
            if need > room {
                return;
            }
            let more = need.max(self.depth.len()).min(room);
            self.depth.splice(0..0, std::iter::repeat_n(0.0, more));
            self.start -= more as i64;
        }
        let i = (cell - self.start) as usize;
        if i >= self.depth.len() {
            if i >= MAX_TRENCH_CELLS {
                return;
            }
            // `resize` grows the allocation geometrically, so a climb costs amortised O(1).
            self.depth.resize(i + 1, 0.0);
        }
        self.depth[i] = self.depth[i].max(d);
    }

    fn clear(&mut self) {
        self.depth.clear();
    }
}

/// Where the sand has been disturbed (docs/model.md §20.3): the deepest any leg reached at
/// each cell along the slope in its earlier stances. A leg's own stance is added when the leg
/// leaves the sand, so a leg digging in feels undisturbed sand ahead of it, and the next leg
/// (or the same leg a stride later) that reaches the cell above that depth feels the sand at
/// `factor` of its strength.
#[derive(Debug, Clone)]
pub(crate) struct Trench {
    factor: f64,
    done: DepthMap,
    pending: Vec<DepthMap>,
    in_sand: Vec<bool>,
}

impl Trench {
    /// An undisturbed bed for `legs` legs, disturbed sand at `factor` of its strength.
    pub(crate) fn new(factor: f64, legs: usize) -> Trench {
        Trench {
            factor,
            done: DepthMap::default(),
            pending: vec![DepthMap::default(); legs],
            in_sand: vec![false; legs],
        }
    }

    fn cell(x: f64) -> i64 {
        (x / TRENCH_CELL_M).floor() as i64
    }

    /// The resistance factor for an element whose centroid is at `x` and whose submerged part
    /// spans depths `lo` to `hi` (m below the surface): the share of its depth integral above
    /// the disturbed depth `D` there resists at `factor`, the rest at 1 (docs/model.md §20.3).
    /// Along a straight element the depth integral up to depth z grows as z^2, so that share is
    /// `(D^2 - lo^2) / (hi^2 - lo^2)`, clamped to 0 and 1: the factor changes continuously as
    /// an element digs past the trench's bottom (a step in it, at the centroid, made the walks
    /// at 24 degrees move with the time step).
    pub(crate) fn factor_over(&self, x: f64, lo: f64, hi: f64) -> f64 {
        let d = self.done.get(Trench::cell(x));
        if d <= lo {
            1.0
        } else if d >= hi {
            self.factor
        } else {
            let share = (d * d - lo * lo) / (hi * hi - lo * lo);
            1.0 - (1.0 - self.factor) * share
        }
    }

    /// Records that leg `leg` swept the segment from `a` to `b` (x, height; height below 0 in
    /// the sand) in this step.
    pub(crate) fn sweep(&mut self, leg: usize, a: [f64; 2], b: [f64; 2]) {
        self.in_sand[leg] = true;
        let (ca, cb) = (Trench::cell(a[0]), Trench::cell(b[0]));
        let (lo, hi) = (ca.min(cb), ca.max(cb));
        for cell in lo..=hi {
            let x = (cell as f64 + 0.5) * TRENCH_CELL_M;
            let f = if b[0] != a[0] { ((x - a[0]) / (b[0] - a[0])).clamp(0.0, 1.0) } else { 0.5 };
            let depth = -(a[1] + f * (b[1] - a[1]));
            if depth > 0.0 {
                self.pending[leg].raise(cell, depth);
            }
        }
    }

    /// Ends a step: a leg that swept no sand in it has left the sand, and its stance's trench
    /// joins the disturbed sand.
    pub(crate) fn end_step(&mut self) {
        for leg in 0..self.pending.len() {
            if !self.in_sand[leg] && !self.pending[leg].depth.is_empty() {
                let p = std::mem::take(&mut self.pending[leg]);
                for (i, &d) in p.depth.iter().enumerate() {
                    if d > 0.0 {
                        self.done.raise(p.start + i as i64, d);
                    }
                }
                self.pending[leg] = p;
                self.pending[leg].clear();
            }
            self.in_sand[leg] = false;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn the_clock_at_half_duty_is_the_constant_speed_gait() {
        let (period, omega) = (1.0, 2.0 * PI);
        for i in -20..60 {
            let t = 0.037 * i as f64;
            let (a, rate) = gait_angle(t, period, 0.5);
            assert!((a - omega * t).abs() < 1e-12, "{t}: {a}");
            assert!((rate - omega).abs() < 1e-12);
        }
    }

    #[test]
    fn the_clock_turns_the_stance_half_in_its_share_of_the_period() {
        // D = 0.7, T = 2 s: half a turn in 1.4 s (pi / 1.4 rad/s), the other in 0.6 s.
        let (a, rate) = gait_angle(0.7, 2.0, 0.7);
        assert!((a - PI / 2.0).abs() < 1e-12 && (rate - PI / 1.4).abs() < 1e-12);
        let (a, rate) = gait_angle(1.4, 2.0, 0.7);
        assert!((a - PI).abs() < 1e-12 && (rate - PI / 0.6).abs() < 1e-12);
        let (a, _) = gait_angle(1.7, 2.0, 0.7);
        assert!((a - 1.5 * PI).abs() < 1e-12);
        let (a, _) = gait_angle(2.0 + 0.7, 2.0, 0.7);
        assert!((a - 2.5 * PI).abs() < 1e-12);
    }

    #[test]
    fn friction_caps_the_stress_along_the_surface_and_keeps_the_normal() {
        // A horizontal element (tangent +x, normal +z) pushed with stress (3, 2): along 3,
        // normal 2; mu = 0.5 caps the along component at 1.
        let ((sx, sz), slope) = friction_cap(0.5, 1.0, 0.0, 3.0, 2.0);
        assert!((sx - 1.0).abs() < 1e-12 && (sz - 2.0).abs() < 1e-12);
        assert_eq!(slope, Some(0.5));
        let ((sx, sz), slope) = friction_cap(0.5, 1.0, 0.0, -3.0, 2.0);
        assert!((sx + 1.0).abs() < 1e-12 && (sz - 2.0).abs() < 1e-12 && slope == Some(-0.5));
        // Within the cone: unchanged.
        assert_eq!(friction_cap(2.0, 1.0, 0.0, 3.0, 2.0), ((3.0, 2.0), None));
        // A tilted element: the tangential component is capped, the normal one kept.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let ((sx, sz), _) = friction_cap(0.2, h, h, 1.0, 0.0);
        let (along, normal) = (sx * h + sz * h, -sx * h + sz * h);
        assert!((normal + h).abs() < 1e-12 && (along - 0.2 * h).abs() < 1e-12);
    }

    #[test]
    fn the_trench_is_felt_by_the_next_stance_not_the_one_digging_it() {
        let mut t = Trench::new(0.5, 2);
        // Leg 0 sweeps 10 mm deep from x = 0 to 4 mm.
        t.sweep(0, [0.0, -0.01], [0.004, -0.01]);
        t.end_step();
        // Still in the sand this step: nothing disturbed yet.
        t.sweep(0, [0.0, -0.01], [0.004, -0.01]);
        assert_eq!(t.factor_over(0.002, 0.004, 0.005), 1.0);
        t.end_step();
        // Leg 0 lifts out: its trench is done.
        t.end_step();
        assert_eq!(t.factor_over(0.002, 0.004, 0.005), 0.5);
        assert_eq!(t.factor_over(0.002, 0.0, 0.01), 0.5);
        // Deeper than the trench, or beside it: undisturbed.
        assert_eq!(t.factor_over(0.002, 0.011, 0.012), 1.0);
        assert_eq!(t.factor_over(0.006, 0.004, 0.005), 1.0);
        assert_eq!(t.factor_over(-0.002, 0.004, 0.005), 1.0);
        // Across the bottom (10 mm), by hand: an element from the surface to 20 mm has a
        // quarter of its depth integral (10^2 / 20^2) in the trench, so 1 - 0.5 / 4 = 0.875;
        // from 5 to 15 mm, (100 - 25) / (225 - 25) = 0.375 of it, so 1 - 0.5 * 0.375 = 0.8125.
        assert!((t.factor_over(0.002, 0.0, 0.02) - 0.875).abs() < 1e-12);
        assert!((t.factor_over(0.002, 0.005, 0.015) - 0.8125).abs() < 1e-12);
    }

    /// A bed written from far downslope upwards and back (a robot sliding down, then
    /// climbing) keeps every depth where it was written, and one beyond the cap is dropped.
    #[test]
    fn the_bed_grows_both_ways_and_keeps_its_depths() {
        let mut m = DepthMap::default();
        for c in (-5000..100).rev() {
            m.raise(c, c as f64 + 1e4);
        }
        for c in 100..200 {
            m.raise(c, 1.0);
        }
        assert_eq!(m.get(-5000), -5000.0 + 1e4);
        assert_eq!(m.get(0), 1e4);
        assert_eq!(m.get(150), 1.0);
        assert_eq!(m.get(-6000), 0.0);
        assert_eq!(m.get(500), 0.0);
        assert!(m.depth.len() <= 2 * 5200 + 200, "{}", m.depth.len());
        m.raise(-(MAX_TRENCH_CELLS as i64) - 10, 1.0);
        assert_eq!(m.get(-(MAX_TRENCH_CELLS as i64) - 10), 0.0);
    }

    #[test]
    fn the_switches_check_their_ranges() {
        let ok = Mechanisms::default();
        assert!(ok.checked().is_ok());
        let bad = |m: Mechanisms| m.checked().unwrap_err().key;
        assert_eq!(bad(Mechanisms { leg_friction: Some(-0.1), ..ok }), "leg_friction");
        assert_eq!(bad(Mechanisms { duty_cycle: 0.95, ..ok }), "duty_cycle");
        assert_eq!(bad(Mechanisms { disturbed_sand: 0.0, ..ok }), "disturbed_sand");
        assert_eq!(bad(Mechanisms { disturbed_sand: 1.5, ..ok }), "disturbed_sand");
        assert_eq!(bad(Mechanisms { leg_friction: Some(f64::NAN), ..ok }), "leg_friction");
    }
}
