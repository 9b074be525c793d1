//! The equations of motion and the fixed-step integrator (docs/model.md §17).
//!
//! State: centre of mass `(x, z)` in the slope frame, pitch `phi`, their rates, each leg's
//! angle, and each resistive-force element's elastic slip. Gravity has both components,
//! `(-g sin theta, -g cos theta)`. Legs are massless and follow their servo; the sand forces on
//! them act on the body. One step is linearly implicit Euler:
//! `(M + dt C + dt^2 K)(v1 - v0) = dt (Q(q0, v0) - dt K v0)`, `q1 = q0 + dt v1`, with `C` the
//! velocity and `K` the position Jacobian of the sand forces (depth gain), so the stiff contact
//! neither rings nor blows up at bead-bed stiffness.

use super::body::{assemble, element_force, leg_nodes, Assembly, BodyPitch, Element, Memory, Touch};
use super::rft::Rft;
use super::{Geometry, SimSettings, Trajectory};
use crate::model::G;
use crate::robot::Robot;
use crate::terrain::Ground;
use std::f64::consts::PI;

/// Elements of the belly plate.
const BELLY_ELEMENTS: usize = 8;
/// A servo that lags its command catches up at this rate, 1/s, up to 1.5 omega.
const CATCH_UP_PER_S: f64 = 20.0;

/// Per-step (per tripod stance) peaks.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct StepPeaks {
    pub max_depth: f64,
    pub peak_force: f64,
    pub peak_torque: f64,
    pub stall_s: f64,
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
}

/// Per-leg outputs of one force evaluation.
#[derive(Debug, Clone, Copy, Default)]
struct LegOut {
    force: [f64; 2],
    torque: f64,
    depth: f64,
}

/// The walking robot.
pub(crate) struct Walker {
    rft: Rft,
    mass: f64,
    inertia: f64,
    gx: f64,
    gz: f64,
    omega: f64,
    psi0: f64,
    width: f64,
    belly_width: f64,
    torque_limit: Option<f64>,
    yield_m: f64,
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
    memory: Vec<Memory>,
    touching: Vec<bool>,
    touches: Vec<Touch>,
    /// Scratch: the current leg's node heights.
    heights: Vec<f64>,
    /// The leg nodes turned to `turned_angle` (relative to the hip), kept for the next leg.
    turned: Vec<[f64; 2]>,
    /// The bits of the angle `turned` is for (`None`: none yet).
    turned_angle: Option<u64>,
    /// The elements that touched the sand in the last step.
    prev_slots: Vec<usize>,
    /// Per leg, the angle relative to the body and the lowest node's height relative to the
    /// hip when its nodes were last placed (NaN: never).
    leg_ref: Vec<(f64, f64)>,
    /// Largest distance of a leg node from the hip, rounded up, m.
    reach: f64,
    legs_out: Vec<LegOut>,
    stalled: Vec<bool>,
    time: f64,
    gravity_scale: f64,
}

impl Walker {
    pub(crate) fn new(robot: &Robot, ground: &Ground, theta: f64, settings: &SimSettings, dt: f64) -> Walker {
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
        let nodes = leg_nodes(robot, settings.shape, elements);
        let h = robot.hip_height();
        let l = robot.body_length();
        let belly: Vec<[f64; 2]> =
            (0..=BELLY_ELEMENTS).map(|k| [-0.5 * l + l * k as f64 / BELLY_ELEMENTS as f64, -h]).collect();
        let legs = 2 * n;
        let slots = legs * elements + BELLY_ELEMENTS;
        let mut w = Walker {
            rft: Rft::with_scaling(ground.k_n, ground.k_s, settings.rft_scaling),
            mass: robot.mass(),
            inertia: robot.pitch_inertia(),
            gx: -G * theta.sin(),
            gz: -G * theta.cos(),
            omega: robot.leg_speed(),
            psi0: robot.touchdown_angle(),
            width: robot.leg_width(),
            belly_width: robot.body_width(),
            torque_limit: robot.servo_torque_limit(),
            yield_m: settings.yield_m,
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
            memory: vec![[0.0; 2]; slots],
            touching: vec![false; slots],
            touches: Vec::with_capacity(slots),
            heights: Vec::with_capacity(elements + 1),
            turned: Vec::with_capacity(elements + 1),
            turned_angle: None,
            prev_slots: Vec::with_capacity(slots),
            leg_ref: vec![(f64::NAN, f64::NAN); legs],
            reach: 0.0,
            legs_out: vec![LegOut::default(); legs],
            stalled: vec![false; legs],
            time: 0.0,
            gravity_scale: 1.0,
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
            None => self.psi0 + self.omega * t.max(0.0) + offset,
        }
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

    /// World position of body point `p` (body frame) and of the centre of mass offset.
    #[inline]
    fn rot(&self, c: f64, s: f64, p: [f64; 2]) -> [f64; 2] {
        [c * p[0] - s * p[1], s * p[0] + c * p[1]]
    }

    /// Sand forces on leg `j` at angle `psi` turning at `rate`, assembled into `asm`; records
    /// touching elements when `record`.
    /// `pitch_sc`: the body pitch's `(sin, cos)`, computed once per step by the caller.
    fn leg_forces(
        &mut self,
        j: usize,
        psi: f64,
        rate: f64,
        pitch_sc: (f64, f64),
        asm: &mut Assembly,
        record: bool,
    ) -> LegOut {
        let (sp, cp) = pitch_sc;
        let hip_rel = self.rot(cp, sp, [self.hips[j], 0.0]);
        let hip = [self.q[0] + hip_rel[0], self.q[1] + hip_rel[1]];
        let angle = self.q[2] - psi;
        let elements = self.nodes.len() - 1;
        // A swing leg that was well above the sand when its nodes were last placed is still
        // above it now: a node's height changes by at most `reach` per radian the leg turns
        // relative to the body, plus the hip's own rise or fall. The test leaves a margin of
        // 1e-12 m, far above the nodes' round-off, so it skips a leg only when the full test
        // below would have found every node above the surface: the same forces, bit for bit,
        // without the leg's sine and cosine and node placement (perf: `sincos` was 9% and the
        // nodes a quarter of the step).
        let (ref_angle, ref_low) = self.leg_ref[j];
        if hip[1] + ref_low - self.reach * (angle - ref_angle).abs() > 1e-12 {
            if record {
                self.touching[j * elements..(j + 1) * elements].fill(false);
            }
            return LegOut::default();
        }
        // The nodes turned to the leg's angle. The legs of a tripod turn together (the same psi,
        // bit for bit, unless a servo stalls), so the legs after the first of a tripod find
        // their angle's nodes already turned: the same numbers without their sine, cosine and
        // rotations (perf: `sincos` was 5% of the walk).
        let mut turned = std::mem::take(&mut self.turned);
        if self.turned_angle != Some(angle.to_bits()) {
            let (sa, ca) = angle.sin_cos();
            turned.clear();
            turned.extend(self.nodes.iter().map(|p| [ca * p[0] - sa * p[1], sa * p[0] + ca * p[1]]));
            self.turned_angle = Some(angle.to_bits());
        }
        let (q, v) = (self.q, self.v);
        let point = |r: [f64; 2]| {
            let rel = [hip_rel[0] + r[0], hip_rel[1] + r[1]];
            // v = V + w J rel - rate J (r - hip), J(a, b) = (-b, a).
            let vel = [v[0] - v[2] * rel[1] + rate * r[1], v[1] + v[2] * rel[0] - rate * r[0]];
            ([hip[0] + r[0], hip[1] + r[1]], rel, vel)
        };
        let _ = q;
        let mut out = LegOut::default();
        // Each node's height, computed exactly as `point` computes it. A leg wholly above the
        // surface feels nothing (every element would return `None`); half the legs are in swing
        // at any time. Within a leg in the sand, an element with both nodes above the surface
        // is skipped the same way, before its nodes' velocities are formed (perf: the node
        // transforms were a quarter of the step).
        let mut heights = std::mem::take(&mut self.heights);
        heights.clear();
        heights.extend(turned.iter().map(|r| hip[1] + r[1]));
        // The reference for the swing test above: the lowest node relative to the hip now.
        // (From the heights: within round-off of the exact value, far inside the 1e-12 margin.)
        let low = heights.iter().fold(f64::INFINITY, |a, &z| a.min(z)) - hip[1];
        self.leg_ref[j] = (angle, low);
        if heights.iter().all(|&z| z >= 0.0) {
            if record {
                self.touching[j * elements..(j + 1) * elements].fill(false);
            }
            self.heights = heights;
            self.turned = turned;
            return out;
        }
        // The last node transformed, shared by consecutive submerged elements.
        let mut last: Option<(usize, [f64; 2], [f64; 2])> = None;
        for k in 0..elements {
            let slot = j * elements + k;
            if heights[k] >= 0.0 && heights[k + 1] >= 0.0 {
                if record {
                    self.touching[slot] = false;
                }
                continue;
            }
            let (pa, va) = match last {
                Some((i, p, v)) if i == k => (p, v),
                _ => {
                    let (p, _, v) = point(turned[k]);
                    (p, v)
                }
            };
            let (pb, _, vb) = point(turned[k + 1]);
            last = Some((k + 1, pb, vb));
            let el = Element { a: pa, b: pb, va, vb, w: self.width };
            match element_force(&self.rft, &el, self.memory[slot], self.yield_m, self.dt) {
                Some(f) => {
                    let rel = [f.point[0] - self.q[0], f.point[1] - self.q[1]];
                    assemble(asm, &f, rel);
                    out.force[0] += f.force[0];
                    out.force[1] += f.force[1];
                    out.torque += (f.point[0] - hip[0]) * f.force[1] - (f.point[1] - hip[1]) * f.force[0];
                    out.depth = out.depth.max(f.depth);
                    if record {
                        self.touches.push(Touch { slot, rel, vel: f.vel });
                        self.touching[slot] = true;
                    }
                }
                None if record => self.touching[slot] = false,
                None => {}
            }
        }
        self.heights = heights;
        self.turned = turned;
        out
    }

    /// The belly's sand forces.
    /// `pitch_sc`: the body pitch's `(sin, cos)`, computed once per step by the caller.
    fn belly_forces(&mut self, asm: &mut Assembly, pitch_sc: (f64, f64)) {
        let (sp, cp) = pitch_sc;
        let (q, v) = (self.q, self.v);
        let base = self.memory.len() - BELLY_ELEMENTS;
        let point = |p: [f64; 2]| {
            let rel = [cp * p[0] - sp * p[1], sp * p[0] + cp * p[1]];
            ([q[0] + rel[0], q[1] + rel[1]], [v[0] - v[2] * rel[1], v[1] + v[2] * rel[0]])
        };
        // The belly is a straight plate: its lowest point is one of its ends. With both ends
        // more than 1e-12 m above the surface (far above the nodes' round-off) every node is
        // above it, and every element would feel nothing: skipped, the same forces bit for bit
        // (perf: the belly is out of the sand most of a walk, and its eight elements were
        // placed every step).
        let end_height = |p: [f64; 2]| q[1] + (sp * p[0] + cp * p[1]);
        if end_height(self.belly[0]).min(end_height(self.belly[BELLY_ELEMENTS])) > 1e-12 {
            self.touching[base..].fill(false);
            return;
        }
        for k in 0..BELLY_ELEMENTS {
            let (a, va) = point(self.belly[k]);
            let (b, vb) = point(self.belly[k + 1]);
            let slot = base + k;
            let el = Element { a, b, va, vb, w: self.belly_width };
            match element_force(&self.rft, &el, self.memory[slot], self.yield_m, self.dt) {
                Some(f) => {
                    let rel = [f.point[0] - self.q[0], f.point[1] - self.q[1]];
                    assemble(asm, &f, rel);
                    self.touches.push(Touch { slot, rel, vel: f.vel });
                    self.touching[slot] = true;
                }
                None => self.touching[slot] = false,
            }
        }
    }

    /// One integration step; `gait`: legs follow the gait (else held).
    fn step(&mut self, gait: bool) {
        let dt = self.dt;
        self.touches.clear();
        let mut asm = Assembly::default();
        let legs = self.psi.len();
        let pitch_sc = self.q[2].sin_cos();
        for j in 0..legs {
            let (psi, rate) = if gait {
                let cmd = self.command(j, self.time);
                let desired = if self.locked.is_some() {
                    0.0
                } else if self.torque_limit.is_some() {
                    (self.omega + (cmd - self.psi[j]) * CATCH_UP_PER_S).clamp(0.0, 1.5 * self.omega)
                } else {
                    self.omega
                };
                (self.psi[j], desired)
            } else {
                (self.psi[j], 0.0)
            };
            self.stalled[j] = false;
            let out = match self.torque_limit {
                // An ideal servo: the leg's forces go straight into the assembly.
                None => self.leg_forces(j, psi, rate, pitch_sc, &mut asm, true),
                Some(limit) => {
                    let mut trial = asm;
                    let start = self.touches.len();
                    let mut out = self.leg_forces(j, psi, rate, pitch_sc, &mut trial, true);
                    // The sand's torque about the hip resists the rotation when positive (the
                    // leg turns clockwise); beyond the limit the servo stalls and holds its angle.
                    if rate > 0.0 && out.torque > limit {
                        self.touches.truncate(start);
                        trial = asm;
                        out = self.leg_forces(j, psi, 0.0, pitch_sc, &mut trial, true);
                        self.stalled[j] = true;
                    }
                    asm = trial;
                    out
                }
            };
            self.legs_out[j] = out;
            let used = if self.stalled[j] { 0.0 } else { rate };
            if gait {
                self.psi[j] = psi + used * dt;
            }
        }
        self.belly_forces(&mut asm, pitch_sc);
        // Gravity.
        asm.q[0] += self.mass * self.gx * self.gravity_scale;
        asm.q[1] += self.mass * self.gz * self.gravity_scale;
        // (M + dt C + dt^2 K) dv = dt (Q - dt K v)
        let m = [self.mass, self.mass, self.inertia];
        let mut a = [[0.0; 3]; 3];
        let mut rhs = [0.0; 3];
        for i in 0..3 {
            let kv: f64 = asm.k[i].iter().zip(&self.v).map(|(k, v)| k * v).sum();
            for (aik, (c, k)) in a[i].iter_mut().zip(asm.c[i].iter().zip(&asm.k[i])) {
                *aik = dt * c + dt * dt * k;
            }
            a[i][i] += m[i];
            rhs[i] = dt * (asm.q[i] - dt * kv);
        }
        if self.pitch_locked {
            // The constraint phi = 0 carries the pitch moment: the third equation becomes
            // dv_phi = 0 (the pitch rate stays at its initial zero).
            a[2] = [0.0, 0.0, 1.0];
            rhs[2] = 0.0;
        }
        let dv = solve3(a, rhs);
        for ((v, q), d) in self.v.iter_mut().zip(self.q.iter_mut()).zip(dv) {
            *v += d;
            *q += dt * *v;
        }
        // Memory: each touching element's slip grows by its new velocity, capped at yield.
        let y = self.yield_m;
        for t in &self.touches {
            let vel = [t.vel[0] + dv[0] - dv[2] * t.rel[1], t.vel[1] + dv[1] + dv[2] * t.rel[0]];
            let e = &mut self.memory[t.slot];
            e[0] += dt * vel[0];
            e[1] += dt * vel[1];
            let n = (e[0] * e[0] + e[1] * e[1]).sqrt();
            if n > y {
                e[0] *= y / n;
                e[1] *= y / n;
            }
        }
        // An element that left the sand forgets its slip. Only an element that touched in the
        // last step can hold one (every other was zeroed when it left), so only those are
        // looked at (perf: the loop over every element was a tenth of the step).
        for &slot in &self.prev_slots {
            if !self.touching[slot] {
                self.memory[slot] = [0.0; 2];
            }
        }
        self.prev_slots.clear();
        self.prev_slots.extend(self.touches.iter().map(|t| t.slot));
        self.time += dt;
    }

    /// Walks `n_steps` integration steps from t = 0, recording the full-rate along-slope
    /// position and speed, per-step peaks (steps of `half` = T/2) and samples at `rate_hz`.
    pub(crate) fn run(mut self, n_steps: usize, half: f64, rate_hz: f64) -> Run {
        let legs = self.psi.len();
        let n_gait_steps = ((n_steps as f64 * self.dt) / half).ceil() as usize + 1;
        let mut per_step = vec![StepPeaks::default(); n_gait_steps];
        let mut stalled_by_step: Vec<Vec<usize>> = vec![Vec::new(); n_gait_steps];
        let mut x = Vec::with_capacity(n_steps + 1);
        let mut vx = Vec::with_capacity(n_steps + 1);
        let samples = ((n_steps as f64 * self.dt) * rate_hz).floor() as usize + 1;
        let mut tr = Trajectory {
            time_s: Vec::with_capacity(samples),
            x_m: Vec::with_capacity(samples),
            z_m: Vec::with_capacity(samples),
            pitch_rad: Vec::with_capacity(samples),
            vx_m_s: Vec::with_capacity(samples),
            vz_m_s: Vec::with_capacity(samples),
            leg_angle_rad: vec![Vec::with_capacity(samples); legs],
            leg_depth_m: vec![Vec::with_capacity(samples); legs],
            leg_force_x_n: vec![Vec::with_capacity(samples); legs],
            leg_force_z_n: vec![Vec::with_capacity(samples); legs],
            leg_torque_n_m: vec![Vec::with_capacity(samples); legs],
        };
        let mut next_sample = 0usize;
        let mut prev = (self.q, self.v, 0.0);
        let mut max_abs_pitch = self.q[2].abs();
        let mut pitch_over_s = None;
        x.push(self.q[0]);
        vx.push(self.v[0]);
        // Sample t = 0 from the settled state (legs as the first step will see them).
        for i in 0..n_steps {
            self.step(true);
            x.push(self.q[0]);
            vx.push(self.v[0]);
            let t = (i + 1) as f64 * self.dt;
            max_abs_pitch = max_abs_pitch.max(self.q[2].abs());
            if pitch_over_s.is_none() && self.q[2].abs() > super::PITCH_OVER_RAD {
                pitch_over_s = Some(t);
            }
            let k = ((t - 0.5 * self.dt) / half).floor().max(0.0) as usize;
            if let Some(p) = per_step.get_mut(k) {
                for j in 0..legs {
                    let o = self.legs_out[j];
                    p.max_depth = p.max_depth.max(o.depth);
                    // The squared force here, its root once at the end (sqrt is monotonic and
                    // correctly rounded, so the root of the largest is the largest root).
                    p.peak_force = p.peak_force.max(o.force[0].powi(2) + o.force[1].powi(2));
                    p.peak_torque = p.peak_torque.max(o.torque.abs());
                    if self.stalled[j] {
                        p.stall_s += self.dt;
                        if !stalled_by_step[k].contains(&j) {
                            stalled_by_step[k].push(j);
                        }
                    }
                }
            }
            while next_sample < samples {
                let ts = next_sample as f64 / rate_hz;
                if ts > t + 1e-12 {
                    break;
                }
                let (q0, v0, t0) = prev;
                let f = if t > t0 { ((ts - t0) / (t - t0)).clamp(0.0, 1.0) } else { 1.0 };
                let lerp = |a: f64, b: f64| a + f * (b - a);
                tr.time_s.push(ts);
                tr.x_m.push(lerp(q0[0], self.q[0]));
                tr.z_m.push(lerp(q0[1], self.q[1]));
                tr.pitch_rad.push(lerp(q0[2], self.q[2]));
                tr.vx_m_s.push(lerp(v0[0], self.v[0]));
                tr.vz_m_s.push(lerp(v0[1], self.v[1]));
                for j in 0..legs {
                    let o = self.legs_out[j];
                    tr.leg_angle_rad[j].push(self.psi[j]);
                    tr.leg_depth_m[j].push(o.depth);
                    tr.leg_force_x_n[j].push(o.force[0]);
                    tr.leg_force_z_n[j].push(o.force[1]);
                    tr.leg_torque_n_m[j].push(-o.torque);
                }
                next_sample += 1;
            }
            prev = (self.q, self.v, t);
        }
        for p in &mut per_step {
            p.peak_force = p.peak_force.sqrt();
        }
        let geometry = Geometry {
            hip_x_m: self.hips.clone(),
            tripod: self.tripod.clone(),
            leg_nodes_m: self.nodes.clone(),
            body_length_m: self.body_length,
            hip_height_m: self.hip_height,
        };
        Run { x, vx, trajectory: tr, geometry, per_step, stalled_by_step, max_abs_pitch, pitch_over_s }
    }

    /// Current state `(x, z, pitch)` and rates (tests).
    #[cfg(test)]
    pub(crate) fn state(&self) -> ([f64; 3], [f64; 3]) {
        (self.q, self.v)
    }

    /// Runs `steps` integration steps with the legs held (tests).
    #[cfg(test)]
    pub(crate) fn hold(&mut self, steps: usize) {
        for _ in 0..steps {
            self.step(false);
        }
    }

    /// Deepest leg point below the surface now, m (tests).
    #[cfg(test)]
    pub(crate) fn leg_depth(&self) -> f64 {
        self.legs_out.iter().map(|o| o.depth).fold(0.0, f64::max)
    }
}

/// Solves the 3x3 system `a x = b` by Cramer's rule (the matrix is the mass matrix plus
/// small positive terms, so it is well conditioned).
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> [f64; 3] {
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&a);
    let mut x = [0.0; 3];
    for (c, xc) in x.iter_mut().enumerate() {
        let mut m = a;
        for r in 0..3 {
            m[r][c] = b[r];
        }
        *xc = det(&m) / d;
    }
    x
}
