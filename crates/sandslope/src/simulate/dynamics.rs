//! The equations of motion and the time stepping (docs/model.md §17).
//!
//! State: centre of mass `(x, z)` in the slope frame, pitch `phi`, their rates and each leg's
//! angle. Gravity has both components, `(-g sin theta, -g cos theta)`. Legs are massless and
//! follow their servo; the sand forces on them act on the body. Resistive force theory is
//! rate-independent (the stress follows the direction of an element's motion, not its speed),
//! so it is stepped like Coulomb friction in Moreau-Jean time stepping: each step holds the
//! geometry of the submerged elements at the start of the step and solves implicitly for the
//! velocity at its end,
//! `M (v1 - v0) = h (M g + sum_i J_i^T F_i(J_i v1 + w_i))`, then `q1 = q0 + h v1`, with
//! every element's force taken at its own new velocity (Newton's method on the 3 body rates).
//! The force never has a component along the element's motion, so with the legs held the step
//! cannot create energy whatever `h` (docs/model.md §17 proves it; a test checks it).

use super::body::{associated_force, element_force, submerged, BodyPitch, Contact, BELLY};
use super::linear::solve_dofs;
use super::mechanisms::{gait_angle, run_up_angle, Trench, CONSTANT_SPEED_DUTY};
use super::rft::{RestSet, Rft};
use super::{Geometry, SimSettings, Trajectory};
use crate::leg::Leg;
use crate::model::G;
use crate::robot::Robot;
use crate::terrain::Ground;
use std::f64::consts::PI;

mod actuator;
mod groups;
mod lanes;
#[cfg(test)]
mod probe;
mod rest;
mod run;
mod strike;

pub(crate) use groups::GroupForces;

/// Elements of the belly plate.
const BELLY_ELEMENTS: usize = 8;
/// A servo that lags its command catches up at this rate, 1/s, up to 1.5 omega.
const CATCH_UP_PER_S: f64 = 20.0;
/// Most Newton iterations of one velocity solve (one stage of the continuation).
const MAX_NEWTON: usize = 12;
/// Most halvings of one Newton step in its line search.
const MAX_HALVINGS: usize = 12;
/// The creep speed the continuation starts from, m/s: far above the creep a walk uses, where
/// the smoothed law is gentle enough for Newton's method from a poor start (docs/model.md §17).
const CONTINUATION_START_M_S: f64 = 1e-2;
/// Newton's method has converged when no body rate changes by more than this fraction of
/// the creep speed (a velocity error far below the creep the smoothing itself allows).
const NEWTON_TOL: f64 = 1e-3;

/// Per-step (per tripod stance) peaks.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct StepPeaks {
    pub max_depth: f64,
    pub peak_force: f64,
    pub peak_torque: f64,
    pub stall_s: f64,
    /// Largest lag of a leg behind its commanded angle, rad.
    pub peak_lag: f64,
}

/// What a run produced.
pub(crate) struct Run {
    pub x: Vec<f64>,
    pub vx: Vec<f64>,
    pub trajectory: Trajectory,
    pub geometry: Geometry,
    pub per_step: Vec<StepPeaks>,
    pub stalled_by_step: Vec<Vec<usize>>,
    /// Largest |pitch| over the walk, rad (full rate).
    pub max_abs_pitch: f64,
    /// First time |pitch| exceeded [`super::PITCH_OVER_RAD`], s.
    pub pitch_over_s: Option<f64>,
    /// Steps whose Newton iteration stopped at its limit before converging.
    pub unconverged_steps: usize,
    /// The sand's force by group at every step, full rate (index i: the step ending at
    /// `(i + 1) dt`).
    pub groups: Vec<GroupForces>,
}

/// Per-leg outputs of one step.
#[derive(Debug, Clone, Copy, Default)]
struct LegOut {
    force: [f64; 2],
    torque: f64,
    depth: f64,
}

/// The walking robot.
pub(crate) struct Walker {
    /// The sand's law on the legs (with leg-sand friction, §20.1) and on the belly (without).
    rft: Rft,
    belly_rft: Rft,
    mass: f64,
    inertia: f64,
    gx: f64,
    gz: f64,
    omega: f64,
    psi0: f64,
    /// The run-up of the constant-speed gait, s (`SimSettings::ramp_up_s`; 0: full speed at once).
    ramp: f64,
    width: f64,
    belly_width: f64,
    torque_limit: Option<f64>,
    /// The servo as an actuator (§20.6), if on.
    motor: Option<actuator::Motor>,
    /// Creep speed of the smoothed set-valued law, m/s (docs/model.md §17).
    eps: f64,
    dt: f64,
    locked: Option<f64>,
    /// The body's pitch is held at zero (§15, `BodyPitch::Locked`).
    pitch_locked: bool,
    nodes: Vec<[f64; 2]>,
    belly: Vec<[f64; 2]>,
    hips: Vec<f64>,
    tripod: Vec<usize>,
    body_length: f64,
    hip_height: f64,
    q: [f64; 3],
    v: [f64; 3],
    psi: Vec<f64>,
    /// The submerged elements of this step.
    contacts: Vec<Contact>,
    /// Their forces at the solved velocity.
    forces: Vec<[f64; 2]>,
    /// Each leg's rate this step (rad/s).
    rates: Vec<f64>,
    /// Scratch: the current leg's node heights.
    heights: Vec<f64>,
    /// The leg nodes turned to `turned_angle` (relative to the hip), kept for the next leg.
    turned: Vec<[f64; 2]>,
    /// The bits of the angle `turned` is for (`None`: none yet).
    turned_angle: Option<u64>,
    /// Per leg, the angle relative to the body and the lowest node's height relative to the
    /// hip when its nodes were last placed (NaN: never).
    leg_ref: Vec<(f64, f64)>,
    /// Largest distance of a leg node from the hip, rounded up, m.
    reach: f64,
    legs_out: Vec<LegOut>,
    stalled: Vec<bool>,
    time: f64,
    gravity_scale: f64,
    unconverged: usize,
    /// Whether the last step ended in the active-set step for a sticking element
    /// ([`Walker::sticking`]), which the next step then tries first.
    stuck: bool,
    /// Stride period T, s, and duty cycle (docs/model.md §20.2).
    period: f64,
    duty: f64,
    /// Disturbed sand (§20.3), if it resists less than undisturbed sand.
    trench: Option<Trench>,
    /// Per leg, the leg whose contacts stand for it this step: itself, or with the pitch
    /// locked the first leg of its tripod at the same angle (coincident legs, docs/model.md
    /// §17), whose contacts then carry the group's summed weight.
    twin: Vec<usize>,
    /// The body rates (bits) at which `forces` were last evaluated under the walk's own law
    /// (its creep, not the associated stand-in) in this solve, if they were.
    forces_at: Option<[u64; 3]>,
    /// Whether coincident legs are merged (tests compare a walk without).
    merge_coincident: bool,
    /// Steps ended by an active-set step at rest ([`Walker::sticking`]; tests count them).
    rest_steps: usize,
    /// The step's contacts prepared for the default law's evaluation several at a time.
    lanes: lanes::Lanes,
    /// Whether [`Walker::lanes`] evaluates this solve's forces (the default law).
    use_lanes: bool,
    /// The last set at rest built ([`Walker::rest_set`]) and the element it is for: belly or
    /// leg, and the tangent's bits.
    last_rest_set: RestSet,
    rest_set_for: Option<(bool, [u64; 2])>,
    /// Scratch: a resting group's elements ([`Walker::rest_group`]).
    rest_group_scratch: Vec<usize>,
    /// The motors' work so far, J: the sand's torque resisting each leg times its rate,
    /// summed over legs and steps (substeps) times the step.
    motor_work: f64,
    /// Steps taken as substeps because the belly struck the sand ([`Walker::step`]).
    strike_steps: usize,
}

/// Adds an element at `rel` from the centre of mass, with force `f` and (when the Jacobian is
/// wanted) force Jacobian `d`, to the body's force and moment `g` and to `k += J^T d J`,
/// `J = [[1, 0, -rz], [0, 1, rx]]` (the element's velocity's Jacobian in the body's rates).
#[inline(always)]
fn add_element(
    g: &mut [f64; 3],
    k: &mut [[f64; 3]; 3],
    rel: [f64; 2],
    f: [f64; 2],
    d: Option<[[f64; 2]; 2]>,
) {
    let (rx, rz) = (rel[0], rel[1]);
    g[0] += f[0];
    g[1] += f[1];
    g[2] += rx * f[1] - rz * f[0];
    if let Some(d) = d {
        let dj = [
            [d[0][0], d[0][1], -rz * d[0][0] + rx * d[0][1]],
            [d[1][0], d[1][1], -rz * d[1][0] + rx * d[1][1]],
        ];
        for col in 0..3 {
            k[0][col] += dj[0][col];
            k[1][col] += dj[1][col];
            k[2][col] += -rz * dj[0][col] + rx * dj[1][col];
        }
    }
}

impl Walker {
    /// A walker whose legs are `leg`'s outline, `robot.leg_elements()` elements each.
    pub(crate) fn with_leg(
        robot: &Robot,
        ground: &Ground,
        theta: f64,
        settings: &SimSettings,
        dt: f64,
        leg: &dyn Leg,
    ) -> Walker {
        let n = robot.stance_legs() as usize;
        let elements = robot.leg_elements() as usize;
        let r = robot.leg_radius();
        let a = 0.5 * robot.body_length() - r;
        let xs: Vec<f64> = if n == 1 {
            vec![0.0]
        } else {
            (0..n).map(|i| -a + 2.0 * a * i as f64 / (n - 1) as f64).collect()
        };
        let hips: Vec<f64> = (0..2 * n).map(|j| xs[j % n]).collect();
        let tripod: Vec<usize> = (0..2 * n).map(|j| j / n).collect();
        let nodes = leg.outline(elements);
        let h = robot.hip_height();
        let l = robot.body_length();
        let belly: Vec<[f64; 2]> =
            (0..=BELLY_ELEMENTS).map(|k| [-0.5 * l + l * k as f64 / BELLY_ELEMENTS as f64, -h]).collect();
        let legs = 2 * n;
        let slots = legs * elements + BELLY_ELEMENTS;
        let mut w = Walker {
            rft: Rft::with_scaling(ground.k_n, ground.k_s, settings.rft_scaling)
                .with_friction(settings.mechanisms.leg_friction),
            belly_rft: {
                let belly = Rft::with_scaling(ground.k_n, ground.k_s, settings.rft_scaling);
                if settings.mechanisms.one_sided_belly {
                    belly.one_sided()
                } else {
                    belly
                }
            },
            mass: robot.mass(),
            inertia: robot.pitch_inertia(),
            gx: -G * theta.sin(),
            gz: -G * theta.cos(),
            omega: robot.leg_speed(),
            psi0: robot.touchdown_angle(),
            ramp: settings.ramp_up_s,
            width: robot.leg_width(),
            belly_width: robot.body_width(),
            torque_limit: if settings.servo_limit { robot.servo_torque_limit() } else { None },
            motor: settings.mechanisms.servo_actuator.then(actuator::Motor::xl330),
            eps: settings.creep_m_s,
            dt,
            locked: settings.locked_leg_angle,
            pitch_locked: settings.body_pitch == BodyPitch::Locked,
            nodes,
            belly,
            hips,
            tripod,
            body_length: l,
            hip_height: h,
            q: [0.0; 3],
            v: [0.0; 3],
            psi: vec![0.0; legs],
            contacts: Vec::with_capacity(slots),
            forces: Vec::with_capacity(slots),
            rates: vec![0.0; legs],
            heights: Vec::with_capacity(elements + 1),
            turned: Vec::with_capacity(elements + 1),
            turned_angle: None,
            leg_ref: vec![(f64::NAN, f64::NAN); legs],
            reach: 0.0,
            legs_out: vec![LegOut::default(); legs],
            stalled: vec![false; legs],
            time: 0.0,
            gravity_scale: 1.0,
            unconverged: 0,
            stuck: false,
            period: robot.stride_period(),
            duty: settings.mechanisms.duty_cycle,
            trench: (settings.mechanisms.disturbed_sand < 1.0)
                .then(|| Trench::new(settings.mechanisms.disturbed_sand, legs)),
            twin: (0..legs).collect(),
            forces_at: None,
            merge_coincident: true,
            rest_steps: 0,
            lanes: lanes::Lanes::default(),
            use_lanes: false,
            last_rest_set: RestSet::default(),
            rest_set_for: None,
            rest_group_scratch: Vec::new(),
            motor_work: 0.0,
            strike_steps: 0,
        };
        w.reach = w.nodes.iter().map(|p| p[0].hypot(p[1])).fold(0.0, f64::max) * (1.0 + 1e-9);
        for j in 0..legs {
            w.psi[j] = w.command(j, 0.0);
        }
        // Start with the lowest point of legs and belly on the surface.
        let lowest = (0..legs)
            .flat_map(|j| {
                let (s, c) = (-w.psi[j]).sin_cos();
                w.nodes.iter().map(move |p| s * p[0] + c * p[1])
            })
            .fold(-h, f64::min);
        w.q[1] = -lowest;
        w
    }

    /// The commanded angle of leg `j` at time `t` (the gait starts at t = 0).
    fn command(&self, j: usize, t: f64) -> f64 {
        let offset = PI * self.tripod[j] as f64;
        match self.locked {
            Some(a) => a + offset,
            None if self.duty == CONSTANT_SPEED_DUTY => {
                self.psi0 + run_up_angle(t, self.omega, self.ramp).0 + offset
            }
            None => self.psi0 + self.clock(j, t).0,
        }
    }

    /// The commanded rate of leg `j` at time `t` (the run-up's, then omega, or the clock's).
    fn nominal_rate(&self, j: usize, t: f64) -> f64 {
        if self.duty == CONSTANT_SPEED_DUTY {
            run_up_angle(t, self.omega, self.ramp).1
        } else {
            self.clock(j, t).1
        }
    }

    /// The gait's clock for leg `j` at time `t` (§20.2): the angle turned since tripod 0's
    /// first touchdown and the commanded rate; tripod 1 runs half a period ahead.
    fn clock(&self, j: usize, t: f64) -> (f64, f64) {
        gait_angle(t.max(0.0) + 0.5 * self.period * self.tripod[j] as f64, self.period, self.duty)
    }

    /// Settles the robot for `settle_s` seconds with its legs held at their t = 0 angles while
    /// gravity ramps in over the first 80%.
    pub(crate) fn settle(&mut self, settle_s: f64) {
        let steps = (settle_s / self.dt).round() as usize;
        let ramp = 0.8 * settle_s;
        for i in 0..steps {
            self.gravity_scale = if ramp > 0.0 { ((i + 1) as f64 * self.dt / ramp).min(1.0) } else { 1.0 };
            self.time = -settle_s + i as f64 * self.dt;
            self.step(false);
        }
        self.gravity_scale = 1.0;
        self.time = 0.0;
        self.v = [0.0, 0.0, 0.0];
    }

    /// Records the submerged elements of leg `j` at angle `psi` (body pitch `(sin, cos)`
    /// `pitch_sc`, computed once per step by the caller) in `contacts`; returns the leg's depth.
    fn leg_contacts(&mut self, j: usize, psi: f64, pitch_sc: (f64, f64)) {
        let (sp, cp) = pitch_sc;
        let hip_rel = [cp * self.hips[j], sp * self.hips[j]];
        let hip = [self.q[0] + hip_rel[0], self.q[1] + hip_rel[1]];
        let angle = self.q[2] - psi;
        let elements = self.nodes.len() - 1;
        // A swing leg that was well above the sand when its nodes were last placed is still
        // above it now: a node's height changes by at most `reach` per radian the leg turns
        // relative to the body, plus the hip's own rise or fall. The test leaves a margin of
        // 1e-12 m, far above the nodes' round-off, so it skips a leg only when the full test
        // below would have found every node above the surface (perf: half the legs are in
        // swing at any time).
        let (ref_angle, ref_low) = self.leg_ref[j];
        if hip[1] + ref_low - self.reach * (angle - ref_angle).abs() > 1e-12 {
            return;
        }
        // The nodes turned to the leg's angle. The legs of a tripod turn together (the same psi,
        // bit for bit, unless a servo stalls), so the legs after the first of a tripod find
        // their angle's nodes already turned.
        let mut turned = std::mem::take(&mut self.turned);
        if self.turned_angle != Some(angle.to_bits()) {
            let (sa, ca) = angle.sin_cos();
            turned.clear();
            turned.extend(self.nodes.iter().map(|p| [ca * p[0] - sa * p[1], sa * p[0] + ca * p[1]]));
            self.turned_angle = Some(angle.to_bits());
        }
        let mut heights = std::mem::take(&mut self.heights);
        heights.clear();
        heights.extend(turned.iter().map(|r| hip[1] + r[1]));
        let low = heights.iter().fold(f64::INFINITY, |a, &z| a.min(z)) - hip[1];
        self.leg_ref[j] = (angle, low);
        if heights.iter().any(|&z| z < 0.0) {
            for k in 0..elements {
                if heights[k] >= 0.0 && heights[k + 1] >= 0.0 {
                    continue;
                }
                let a = [hip[0] + turned[k][0], heights[k]];
                let b = [hip[0] + turned[k + 1][0], heights[k + 1]];
                if let Some((mut weight, point, tangent, depth)) = submerged(a, b, self.width) {
                    if let Some(trench) = &mut self.trench {
                        let (da, db) = (-a[1], -b[1]);
                        weight *= trench.factor_over(point[0], da.min(db).max(0.0), da.max(db));
                        trench.sweep(j, a, b);
                    }
                    self.contacts.push(Contact {
                        weight,
                        tangent,
                        rel: [point[0] - self.q[0], point[1] - self.q[1]],
                        arm: [point[0] - hip[0], point[1] - hip[1]],
                        leg: j,
                        depth,
                    });
                }
            }
        }
        self.heights = heights;
        self.turned = turned;
    }

    /// Gives each leg's contacts the weight of the legs it stands for ([`Walker::twin`]) and
    /// moves their point of application along the body to the group's mean hip (the pitch is
    /// zero, so the body's axis is the slope's x): the group's summed force and moment.
    fn carry_twins(&mut self) {
        let legs = self.twin.len();
        for first in 0..legs {
            let (mut count, mut offset) = (0usize, 0.0);
            for j in (first..legs).filter(|&j| self.twin[j] == first) {
                count += 1;
                offset += self.hips[j] - self.hips[first];
            }
            if count < 2 {
                continue;
            }
            let (n, shift) = (count as f64, offset / count as f64);
            for c in self.contacts.iter_mut().filter(|c| c.leg == first) {
                c.weight *= n;
                c.rel[0] += shift;
            }
        }
    }

    /// Records the belly's submerged elements.
    fn belly_contacts(&mut self, pitch_sc: (f64, f64)) {
        let (sp, cp) = pitch_sc;
        let q = self.q;
        let point = |p: [f64; 2]| [q[0] + cp * p[0] - sp * p[1], q[1] + sp * p[0] + cp * p[1]];
        // The belly is a straight plate: its lowest point is one of its ends.
        let end_height = |p: [f64; 2]| q[1] + (sp * p[0] + cp * p[1]);
        if end_height(self.belly[0]).min(end_height(self.belly[BELLY_ELEMENTS])) > 1e-12 {
            return;
        }
        for k in 0..BELLY_ELEMENTS {
            let (a, b) = (point(self.belly[k]), point(self.belly[k + 1]));
            if let Some((weight, p, tangent, depth)) = submerged(a, b, self.belly_width) {
                self.contacts.push(Contact {
                    weight,
                    tangent,
                    rel: [p[0] - q[0], p[1] - q[1]],
                    arm: [0.0; 2],
                    leg: BELLY,
                    depth,
                });
            }
        }
    }

    /// Element `c`'s velocity when the body moves at `v`: `J v + w`, with the leg's own
    /// rotation at `rate` (clockwise positive) about the hip.
    #[inline(always)]
    fn element_velocity(c: &Contact, v: [f64; 3], rate: f64) -> [f64; 2] {
        [v[0] - v[2] * c.rel[1] + rate * c.arm[1], v[1] + v[2] * c.rel[0] - rate * c.arm[0]]
    }

    /// The implicit velocity step (docs/model.md §17): the body rates `v1` with
    /// `G(v1) = M (v1 - v_free) - h sum_i J_i^T F_i(J_i v1 + w_i) = 0`, by Newton's method
    /// from the last step's rates with a backtracking line search on `|G|^2_{M^-1}`; where the
    /// last step ended in the active-set step for a sticking element, that step is tried first
    /// (an active set carried from step to step: a resting element stays at rest while the
    /// force it needs stays in the law's set). Where Newton's method fails, the same equation is solved along a continuation in the creep speed (from
    /// [`CONTINUATION_START_M_S`] down by tenfold stages to the walk's own, each stage started
    /// from the last); where that fails, the associated law's solution (a convex minimisation,
    /// always solvable) starts a last attempt; where that fails too, the iterate with the
    /// smallest residual is kept and the step counted. The forces are left in `self.forces`.
    fn solve(&mut self, v_free: [f64; 3], m: [f64; 3]) -> bool {
        let mut v = self.v;
        if self.pitch_locked {
            v[2] = 0.0;
        }
        let eps = self.eps;
        self.forces_at = None;
        self.use_lanes = self.lanes.prepare(&self.contacts, &self.rates, &self.rft, &self.belly_rft);
        if self.stuck && self.sticking(v, v_free, m) {
            self.rest_steps += 1;
            return true;
        }
        self.stuck = false;
        let (first, ok, r1) = self.newton(v, v_free, m, eps, false);
        if ok {
            return self.finish(first, v_free, m, true);
        }
        if self.sticking(first, v_free, m) {
            self.stuck = true;
            self.rest_steps += 1;
            return true;
        }
        let (mut best, mut best_merit) = (first, r1);
        let mut stage = v;
        let mut e = CONTINUATION_START_M_S.max(eps);
        loop {
            let (next, ok, r) = self.newton(stage, v_free, m, e, false);
            if e <= eps {
                if ok {
                    return self.finish(next, v_free, m, true);
                }
                if r < best_merit {
                    (best, best_merit) = (next, r);
                }
                break;
            }
            stage = next;
            e = (0.1 * e).max(eps);
        }
        let (start, _, _) = self.newton(v, v_free, m, eps, true);
        let (second, ok, r2) = self.newton(start, v_free, m, eps, false);
        if ok || r2 <= best_merit {
            best = second;
        }
        self.finish(best, v_free, m, ok)
    }

    /// Takes `v` as the step's rates (leaving its forces in `self.forces`).
    fn finish(&mut self, v: [f64; 3], v_free: [f64; 3], m: [f64; 3], ok: bool) -> bool {
        // A converged Newton iterate was the last point evaluated: its forces are in place.
        if self.forces_at != Some(v.map(f64::to_bits)) {
            let _ = self.evaluate(v, v_free, m, self.eps, None, false);
        }
        self.v = v;
        ok
    }

    /// Newton's method from `v` on the law itself (`associated`: false; line search on
    /// `|G|^2_{M^-1}`) or on the associated law (line search on its potential `Phi`): the last
    /// iterate, whether it converged (a Newton step below [`NEWTON_TOL`] times the creep
    /// speed) and the smallest merit seen.
    fn newton(
        &mut self,
        mut v: [f64; 3],
        v_free: [f64; 3],
        m: [f64; 3],
        eps: f64,
        associated: bool,
    ) -> ([f64; 3], bool, f64) {
        let dofs = if self.pitch_locked { 2 } else { 3 };
        let merit = |r: &[f64; 3]| (0..dofs).map(|i| r[i] * r[i] / m[i]).sum::<f64>();
        let value = |phi: f64, r: &[f64; 3]| if associated { phi } else { merit(r) };
        let tol = NEWTON_TOL * eps;
        let mut jac = [[0.0; 3]; 3];
        let (phi, mut grad) = self.evaluate(v, v_free, m, eps, Some(&mut jac), associated);
        let mut f0 = value(phi, &grad);
        let (mut best, mut best_merit) = (v, merit(&grad));
        for _ in 0..MAX_NEWTON {
            let delta = solve_dofs(&jac, &grad, dofs);
            let size = (0..dofs).map(|i| delta[i].abs()).fold(0.0, f64::max);
            if size < tol {
                return (v, true, merit(&grad));
            }
            // The decrease a full step promises (Phi: G.delta; |G|^2: 2 |G|^2).
            let slope =
                if associated { (0..dofs).map(|i| grad[i] * delta[i]).sum::<f64>() } else { 2.0 * f0 };
            let mut lambda = 1.0;
            let mut accepted = false;
            // Each trial is evaluated with its Jacobian: an accepted trial is the next iterate,
            // whose evaluation is then not repeated (the walk is the same to the bit).
            let mut trial_jac = [[0.0; 3]; 3];
            for _ in 0..MAX_HALVINGS {
                let mut trial = v;
                for i in 0..dofs {
                    trial[i] -= lambda * delta[i];
                }
                let (pt, rt) = self.evaluate(trial, v_free, m, eps, Some(&mut trial_jac), associated);
                let ft = value(pt, &rt);
                if ft <= f0 - 1e-4 * lambda * slope.max(0.0) {
                    v = trial;
                    grad = rt;
                    f0 = ft;
                    jac = trial_jac;
                    accepted = true;
                    break;
                }
                lambda *= 0.5;
            }
            if !accepted {
                return (best, false, best_merit);
            }
            let mr = merit(&grad);
            if mr < best_merit {
                (best, best_merit) = (v, mr);
            }
        }
        (best, false, best_merit)
    }

    /// The step's gradient `G(v) = M (v - v_free) - h sum_i J_i^T F_i` under the law
    /// (`associated`: its associated stand-in, with the potential `Phi(v)` as well) and, when
    /// asked, its Jacobian `M - h sum_i J_i^T dF_i/du J_i`; the forces are left in `forces`.
    fn evaluate(
        &mut self,
        v: [f64; 3],
        v_free: [f64; 3],
        m: [f64; 3],
        eps: f64,
        jac: Option<&mut [[f64; 3]; 3]>,
        associated: bool,
    ) -> (f64, [f64; 3]) {
        let h = self.dt;
        let (contacts, forces, rates) = (&self.contacts, &mut self.forces, &self.rates);
        let (leg_rft, belly_rft) = (&self.rft, &self.belly_rft);
        let mut g = [0.0; 3];
        let mut k = [[0.0; 3]; 3];
        let mut potential = 0.0;
        let want = jac.is_some();
        forces.clear();
        // The default law's forces several elements at a time, and their sums (the same to
        // the bit as the loop below).
        let lanes = !associated && self.use_lanes;
        if lanes {
            self.lanes.evaluate(v, eps);
            self.lanes.accumulate(contacts.len(), forces, &mut g, &mut k, want);
        }
        for c in contacts.iter().filter(|_| !lanes) {
            let rate = if c.leg == BELLY { 0.0 } else { rates[c.leg] };
            let u = Walker::element_velocity(c, v, rate);
            let rft = if c.leg == BELLY { belly_rft } else { leg_rft };
            let (f, d) = if associated {
                let (f, p, hess) = associated_force(rft, c, u, eps);
                potential += p;
                (f, [[-hess[0][0], -hess[0][1]], [-hess[1][0], -hess[1][1]]])
            } else {
                element_force(rft, c, u, eps, want)
            };
            forces.push(f);
            add_element(&mut g, &mut k, c.rel, f, want.then_some(d));
        }
        let mut r = [0.0; 3];
        self.forces_at = (eps == self.eps && !associated).then(|| v.map(f64::to_bits));
        let mut phi = h * potential;
        for i in 0..3 {
            r[i] = m[i] * (v[i] - v_free[i]) - h * g[i];
            phi += 0.5 * m[i] * (v[i] - v_free[i]).powi(2);
        }
        if let Some(jac) = jac {
            for i in 0..3 {
                for col in 0..3 {
                    jac[i][col] = -h * k[i][col];
                }
                jac[i][i] += m[i];
            }
        }
        (phi, r)
    }

    /// One step of `self.dt` (see [`Walker::step`]).
    fn substep(&mut self, gait: bool) {
        let dt = self.dt;
        let legs = self.psi.len();
        let pitch_sc = self.q[2].sin_cos();
        self.contacts.clear();
        // Coincident legs (docs/model.md §17): with the pitch locked (exactly zero, so every
        // hip at the same height) a tripod's legs at the same angle have the same submerged
        // elements, tangents and arms, differing only by their hips' along-body offsets, and
        // (the pitch rate being zero) the same element velocities, so the same stresses. Their
        // forces are then one leg's times their number, and their moment about the centre of
        // mass that force at their mean offset: the first leg's contacts carry the group, and
        // the others are not placed at all (a third of the force evaluations; disturbed sand,
        // which tells the legs' tracks apart, keeps every leg).
        // The pitch and its rate are checked, not assumed, to be exactly zero.
        let merge = self.merge_coincident
            && self.pitch_locked
            && self.q[2] == 0.0
            && self.v[2] == 0.0
            && self.trench.is_none();
        for j in 0..legs {
            let psi = self.psi[j];
            let first = (0..j).find(|&i| {
                merge
                    && self.twin[i] == i
                    && self.tripod[i] == self.tripod[j]
                    && self.psi[i].to_bits() == psi.to_bits()
            });
            self.twin[j] = first.unwrap_or(j);
            if first.is_none() {
                self.leg_contacts(j, psi, pitch_sc);
            }
        }
        if merge {
            self.carry_twins();
        }
        self.belly_contacts(pitch_sc);
        for j in 0..legs {
            self.stalled[j] = false;
            self.rates[j] = if gait {
                let cmd = self.command(j, self.time);
                let nominal = self.nominal_rate(j, self.time);
                if self.locked.is_some() {
                    0.0
                } else if let Some(motor) = self.motor {
                    self.demanded_rate(j, &motor)
                } else if self.torque_limit.is_some() {
                    (nominal + (cmd - self.psi[j]) * CATCH_UP_PER_S).clamp(0.0, 1.5 * nominal)
                } else if self.duty == CONSTANT_SPEED_DUTY && self.ramp == 0.0 {
                    self.omega
                } else {
                    // Exactly onto the command at the step's end (the clock's rate changes
                    // within a step at the half turns).
                    (self.command(j, self.time + dt) - self.psi[j]) / dt
                }
            } else {
                0.0
            };
        }
        let m = [self.mass, self.mass, self.inertia];
        let gs = self.gravity_scale;
        let v_free = [self.v[0] + dt * self.gx * gs, self.v[1] + dt * self.gz * gs, self.v[2]];
        let v0 = self.v;
        let mut converged = self.solve(v_free, m);
        if let (Some(motor), true) = (self.motor, gait && self.locked.is_none()) {
            let demand = self.rates.clone();
            converged = self.actuate(motor, &demand, v_free, m, v0);
        }
        // A torque-limited servo whose leg the sand resists by more than its limit at the solved
        // motion stalls for the step (holds its angle); the step is solved again without it.
        if let Some(limit) = self.torque_limit {
            for _ in 0..legs {
                self.leg_outputs();
                let mut more = false;
                for j in 0..legs {
                    if self.rates[j] > 0.0 && self.legs_out[j].torque > limit {
                        self.rates[j] = 0.0;
                        self.stalled[j] = true;
                        more = true;
                    }
                }
                if !more {
                    break;
                }
                self.v = v0;
                converged = self.solve(v_free, m);
            }
        }
        if !converged {
            self.unconverged += 1;
        }
        self.leg_outputs();
        self.motor_work += self.legs_out.iter().zip(&self.rates).map(|(o, r)| o.torque * r).sum::<f64>() * dt;
        for (q, v) in self.q.iter_mut().zip(self.v) {
            *q += dt * v;
        }
        if gait {
            for (psi, rate) in self.psi.iter_mut().zip(&self.rates) {
                *psi += rate * dt;
            }
        }
        if let Some(trench) = &mut self.trench {
            trench.end_step();
        }
        self.time += dt;
    }

    /// Each leg's sand force, torque about its hip (positive: resisting the leg's clockwise
    /// turn) and depth, from the solved forces.
    fn leg_outputs(&mut self) {
        self.legs_out.iter_mut().for_each(|o| *o = LegOut::default());
        for (c, f) in self.contacts.iter().zip(&self.forces) {
            if c.leg == BELLY {
                continue;
            }
            let o = &mut self.legs_out[c.leg];
            o.force[0] += f[0];
            o.force[1] += f[1];
            o.torque += c.arm[0] * f[1] - c.arm[1] * f[0];
            o.depth = o.depth.max(c.depth);
        }
        // Coincident legs share their first leg's contacts: each carries an equal part.
        let legs = self.twin.len();
        for first in 0..legs {
            let count = self.twin.iter().filter(|&&t| t == first).count();
            if count < 2 {
                continue;
            }
            let n = count as f64;
            let o = &mut self.legs_out[first];
            o.force = [o.force[0] / n, o.force[1] / n];
            o.torque /= n;
            let share = *o;
            for j in first + 1..legs {
                if self.twin[j] == first {
                    self.legs_out[j] = share;
                }
            }
        }
    }
}
