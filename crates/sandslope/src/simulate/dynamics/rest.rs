//! The active-set steps for elements at rest (docs/model.md §17): where Newton's method on the
//! smoothed law stalls, it is usually circling a solution in which some elements are at rest
//! exactly, their forces inside the set the rate-independent law allows there, as a sticking
//! Coulomb contact. These steps put them there and check the set.

use super::super::body::{Contact, BELLY};
use super::super::rft::RestSet;
use super::{Walker, MAX_HALVINGS, MAX_NEWTON, NEWTON_TOL};

impl Walker {
    /// The active-set step for a sticking element (docs/model.md §17): where Newton's method
    /// stalls, it is usually circling a solution with one element (or one element of each leg
    /// of a tripod, identical, or the whole belly) at rest, its force inside the law's set like
    /// a sticking Coulomb contact. Put the element nearest rest at `near` at rest exactly with
    /// the pitch rate zero (which fixes the body's rates), take the force (and with the pitch
    /// free the moment) the others leave to the resting group from the momentum balance, split
    /// it over the group ([`Walker::rest_split`]), and accept the step if every element's share
    /// lies in the set the rate-independent law allows at rest: the region bounded by
    /// `sigma(e)` over all directions e ([`super::rft::RestSet`]). The elements at rest do no
    /// work, so the step stays passive.
    pub(super) fn sticking(&mut self, near: [f64; 3], v_free: [f64; 3], m: [f64; 3]) -> bool {
        // The first of the slowest (as `Iterator::min_by` picks), each speed computed once.
        let mut slowest: Option<(usize, f64)> = None;
        for k in 0..self.contacts.len() {
            let speed = self.element_speed(k, near);
            if slowest.is_none_or(|(_, s)| speed.total_cmp(&s).is_lt()) {
                slowest = Some((k, speed));
            }
        }
        let Some((pick, _)) = slowest else {
            return false;
        };
        self.rest_group(pick, v_free, m) || (!self.pitch_locked && self.pivot(pick, near, v_free, m))
    }

    /// The speed of contact `k` when the body moves at `v`, its leg turning at its rate.
    fn element_speed(&self, k: usize, v: [f64; 3]) -> f64 {
        let c = &self.contacts[k];
        let rate = if c.leg == BELLY { 0.0 } else { self.rates[c.leg] };
        let u = Walker::element_velocity(c, v, rate);
        (u[0] * u[0] + u[1] * u[1]).sqrt()
    }

    /// The resting group of [`Walker::sticking`]: element `pick` at rest with the pitch rate
    /// zero, and with it every element at rest at those body rates (of one shape, else no).
    fn rest_group(&mut self, pick: usize, v_free: [f64; 3], m: [f64; 3]) -> bool {
        let c = self.contacts[pick];
        let rate = if c.leg == BELLY { 0.0 } else { self.rates[c.leg] };
        // u = v + rate (arm_z, -arm_x) = 0 with the pitch rate zero.
        let v = [-rate * c.arm[1], rate * c.arm[0], 0.0];
        let mut group = std::mem::take(&mut self.rest_group_scratch);
        group.clear();
        group.extend((0..self.contacts.len()).filter(|&k| self.element_speed(k, v) <= 1e-3 * self.eps));
        let held = self.hold_group(&group, c, v, v_free, m);
        self.rest_group_scratch = group;
        held
    }

    /// [`Walker::rest_group`]'s test of `group` (resting with `c`, the body at `v`).
    fn hold_group(
        &mut self,
        group: &[usize],
        c: Contact,
        v: [f64; 3],
        v_free: [f64; 3],
        m: [f64; 3],
    ) -> bool {
        let same_shape = group.iter().all(|&k| {
            let t = self.contacts[k].tangent;
            (t[0] - c.tangent[0]).abs() < 1e-9 && (t[1] - c.tangent[1]).abs() < 1e-9
        });
        if !same_shape {
            return false;
        }
        let (_, r) = self.evaluate(v, v_free, m, self.eps, None, false);
        // G = M (v - v_free) - h sum F = 0: the group must carry r/h beyond what it carries now
        // (force, and with the pitch free moment about the centre of mass).
        let mut need = [r[0] / self.dt, r[1] / self.dt];
        let mut moment = r[2] / self.dt;
        let (mut weight, mut centre) = (0.0, [0.0; 2]);
        for &k in group {
            let (f, ck) = (self.forces[k], &self.contacts[k]);
            need[0] += f[0];
            need[1] += f[1];
            moment += ck.rel[0] * f[1] - ck.rel[1] * f[0];
            weight += ck.weight;
            centre[0] += ck.weight * ck.rel[0];
            centre[1] += ck.weight * ck.rel[1];
        }
        if weight <= 0.0 {
            return false;
        }
        let mean = [need[0] / weight, need[1] / weight];
        let Some(shares) =
            self.rest_split(group, weight, [centre[0] / weight, centre[1] / weight], mean, moment)
        else {
            return false;
        };
        let set = self.rest_set(c.leg == BELLY, c.tangent);
        // Equal shares (the pitch locked: every element takes the mean) are tested once.
        let mut tested: Option<[f64; 2]> = None;
        for &s in &shares {
            if tested != Some(s) {
                if !set.holds(s) {
                    return false;
                }
                tested = Some(s);
            }
        }
        for (&k, s) in group.iter().zip(&shares) {
            let w = self.contacts[k].weight;
            self.forces[k] = [w * s[0], w * s[1]];
        }
        self.v = v;
        true
    }

    /// The set at rest of an element of the belly (`belly`) or of a leg with unit tangent
    /// `tangent` ([`super::super::rft::Rft::rest_set`]). The last set built is kept: a body
    /// resting on its belly (with the pitch locked, at one tangent step after step) tests its
    /// load against the same set every step, and building it was a quarter of a level walk's
    /// time (`perf`, 2026-12-02).
    fn rest_set(&mut self, belly: bool, tangent: [f64; 2]) -> &RestSet {
        let key = (belly, tangent.map(f64::to_bits));
        if self.rest_set_for != Some(key) {
            let rft = if belly { &self.belly_rft } else { &self.rft };
            rft.rest_set_into(tangent, &mut self.last_rest_set);
            self.rest_set_for = Some(key);
        }
        &self.last_rest_set
    }

    /// How a resting group (the elements `group`, of summed weight `weight` and weighted
    /// centroid `centre` from the centre of mass) carries the force `weight * mean` (docs/model.md
    /// §17): the stress per unit depth of each element. With the pitch locked the constraint
    /// carries any moment and every element takes `mean`. With the pitch free the group must
    /// carry `moment` about the centre of mass too, which a rigid body resting on several
    /// elements does with statically indeterminate forces; the split taken is the one a rigid
    /// body on a bed of springs gives: the stress normal to the body's axis varies linearly
    /// along it, `s_k = mean + (t_k - t) d n` (t_k the element's position along the axis `a`,
    /// t their weighted mean, n the axis's normal), with `d` what the moment needs:
    /// `sum w_k r_k x s_k = centre x (W mean) + d sum w_k (t_k - t)^2`. `None` when the group
    /// cannot carry a moment (its elements at one place along the axis) and the moment is not
    /// the force's own.
    fn rest_split(
        &self,
        group: &[usize],
        weight: f64,
        centre: [f64; 2],
        mean: [f64; 2],
        moment: f64,
    ) -> Option<Vec<[f64; 2]>> {
        if self.pitch_locked {
            return Some(vec![mean; group.len()]);
        }
        let (sp, cp) = self.q[2].sin_cos();
        let (axis, normal) = ([cp, sp], [-sp, cp]);
        let along = |k: usize| self.contacts[k].rel[0] * axis[0] + self.contacts[k].rel[1] * axis[1];
        let t_mean = centre[0] * axis[0] + centre[1] * axis[1];
        let spread: f64 = group.iter().map(|&k| self.contacts[k].weight * (along(k) - t_mean).powi(2)).sum();
        let excess = moment - weight * (centre[0] * mean[1] - centre[1] * mean[0]);
        // A moment the group cannot carry: below a millionth of its force times the body's length.
        let negligible = 1e-6 * weight * mean[0].hypot(mean[1]) * self.body_length;
        if spread <= f64::EPSILON * weight * self.body_length.powi(2) {
            return (excess.abs() <= negligible).then(|| vec![mean; group.len()]);
        }
        let d = excess / spread;
        Some(
            group
                .iter()
                .map(|&k| {
                    let off = (along(k) - t_mean) * d;
                    [mean[0] + off * normal[0], mean[1] + off * normal[1]]
                })
                .collect(),
        )
    }

    /// The pivot step (pitch free, docs/model.md §17): element `pick` at rest while the body
    /// turns about it. Its two velocity components fixed at zero leave the pitch rate `w` free,
    /// `v(w) = (-rate a_z + w r_z, rate a_x - w r_x, w)`; the element can carry any force in
    /// its set, so of the three momentum rows only the one along the constraint,
    /// `f(w) = t . G(v(w))` with `t = dv/dw = (r_z, -r_x, 1)`, must vanish (the moment about
    /// the pivot), solved by Newton's method in `w` from the rate at `near` with a halving line
    /// search on `|f|`. The element's own stiffness at rest drops out of `f'`, since its
    /// velocity does not change along `t`. The step is accepted if the force the element must
    /// then carry, `F_pick + (G_x, G_z) / h`, lies in its set at rest. It does no work.
    fn pivot(&mut self, pick: usize, near: [f64; 3], v_free: [f64; 3], m: [f64; 3]) -> bool {
        let c = self.contacts[pick];
        let rate = if c.leg == BELLY { 0.0 } else { self.rates[c.leg] };
        let at = |w: f64| [-rate * c.arm[1] + w * c.rel[1], rate * c.arm[0] - w * c.rel[0], w];
        let t = [c.rel[1], -c.rel[0], 1.0];
        let along = |r: &[f64; 3]| t[0] * r[0] + t[1] * r[1] + t[2] * r[2];
        // Converged when the turn moves no point within the body's length by 1e-3 of the creep.
        let tol = NEWTON_TOL * self.eps / self.body_length;
        let mut jac = [[0.0; 3]; 3];
        let mut w = near[2];
        let (_, r) = self.evaluate(at(w), v_free, m, self.eps, Some(&mut jac), false);
        let mut f = along(&r);
        let mut converged = false;
        for _ in 0..2 * MAX_NEWTON {
            let slope: f64 = (0..3).map(|i| t[i] * (0..3).map(|j| jac[i][j] * t[j]).sum::<f64>()).sum();
            if slope == 0.0 || !slope.is_finite() {
                break;
            }
            let delta = f / slope;
            if delta.abs() < tol {
                converged = true;
                break;
            }
            let mut lambda = 1.0;
            let mut accepted = false;
            let mut trial_jac = [[0.0; 3]; 3];
            for _ in 0..MAX_HALVINGS {
                let trial = w - lambda * delta;
                let (_, rt) = self.evaluate(at(trial), v_free, m, self.eps, Some(&mut trial_jac), false);
                let ft = along(&rt);
                if ft.abs() < f.abs() {
                    (w, f, jac) = (trial, ft, trial_jac);
                    accepted = true;
                    break;
                }
                lambda *= 0.5;
            }
            if !accepted {
                break;
            }
        }
        if !converged {
            return false;
        }
        let v = at(w);
        let (_, r) = self.evaluate(v, v_free, m, self.eps, None, false);
        let carry = [self.forces[pick][0] + r[0] / self.dt, self.forces[pick][1] + r[1] / self.dt];
        if !(c.weight > 0.0
            && self.rest_set(c.leg == BELLY, c.tangent).holds([carry[0] / c.weight, carry[1] / c.weight]))
        {
            return false;
        }
        self.forces[pick] = carry;
        self.v = v;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::super::super::body::{BodyPitch, Contact, BELLY};
    use super::super::super::SimSettings;
    use super::super::Walker;
    use crate::model::tests::paper_robot;
    use crate::terrain::Ground;

    /// A walker with the pitch free, its legs held, and `contacts` as the step's submerged
    /// elements (a hand-made geometry), moving at `v0` under gravity on level sand.
    fn walker_with(contacts: Vec<Contact>, v0: [f64; 3]) -> Walker {
        let robot = paper_robot();
        let settings = SimSettings::new(1.0).unwrap().with_body_pitch(BodyPitch::Free).with_locked_legs(0.0);
        let ground = Ground::new(7e5, 3e6).unwrap();
        let leg = robot.leg();
        let mut w = Walker::with_leg(&robot, &ground, 0.0, &settings, 5e-4, &leg);
        w.contacts = contacts;
        w.rates.iter_mut().for_each(|r| *r = 0.0);
        w.v = v0;
        w
    }

    fn element(rel: [f64; 2], weight: f64, leg: usize) -> Contact {
        Contact { weight, tangent: [1.0, 0.0], rel, arm: [0.0; 2], leg, depth: 0.01 }
    }

    /// The pivot step against the pendulum by hand: a body held at one point `r` from its
    /// centre of mass turns about it, and the step's momentum balance
    /// `m (w r_z - vf_x) = h F_x`, `m (-w r_x - vf_z) = h F_z`,
    /// `I (w - vf_w) = h (r_x F_z - r_z F_x)` gives, eliminating F (the parallel-axis theorem),
    /// `w = (I vf_w + m (r_z vf_x - r_x vf_z)) / (I + m |r|^2)`. A heavy, deep element holds
    /// whatever force that takes.
    #[test]
    fn the_pivot_step_turns_the_body_as_a_pendulum_about_the_resting_element() {
        let r = [0.06, -0.03];
        let v0 = [0.01, -0.02, 0.3];
        let mut w = walker_with(vec![element(r, 1.0, 0)], v0);
        let (m, inertia, h) = (w.mass, w.inertia, w.dt);
        let vf = [v0[0] + h * w.gx, v0[1] + h * w.gz, v0[2]];
        assert!(w.pivot(0, [0.0, 0.0, 0.2], vf, [m, m, inertia]));
        let expect = (inertia * vf[2] + m * (r[1] * vf[0] - r[0] * vf[1]))
            / (inertia + m * (r[0] * r[0] + r[1] * r[1]));
        assert!((w.v[2] - expect).abs() < 1e-9, "{} vs {expect}", w.v[2]);
        // The element is at rest: v + w x r = 0.
        assert!((w.v[0] - w.v[2] * r[1]).abs() < 1e-12 && (w.v[1] + w.v[2] * r[0]).abs() < 1e-12);
        // Its force is the momentum balance's: F = m (v - vf) / h in x and z.
        let f = w.forces[0];
        assert!((f[0] - m * (w.v[0] - vf[0]) / h).abs() < 1e-6 * m / h);
        assert!((f[1] - m * (w.v[1] - vf[1]) / h).abs() < 1e-6 * m / h);
        // A light, shallow element cannot hold it: no pivot.
        let mut w = walker_with(vec![element(r, 1e-12, 0)], v0);
        assert!(!w.pivot(0, [0.0, 0.0, 0.2], vf, [m, m, inertia]));
    }

    /// The split of a resting group under a moment, by hand: two belly elements of weight w at
    /// `t = -a` and `+a` along the level body's axis, a hand's depth below the centre of mass,
    /// carrying a vertical force F and a moment M about the centre of mass. The group's centroid
    /// is below the centre of mass, so the vertical force has no moment of its own
    /// (`c x F = 0`), and `d = M / (2 w a^2)`: the stresses are `F / 2w -/+ a d` vertically.
    #[test]
    fn a_resting_body_carries_a_moment_by_a_linear_split_along_its_axis() {
        let (a, wt, depth) = (0.05, 2e-6, 0.03);
        let contacts = vec![element([-a, -depth], wt, BELLY), element([a, -depth], wt, BELLY)];
        let w = walker_with(contacts, [0.0; 3]);
        let (fz, moment) = (3.0, 0.02);
        let mean = [0.0, fz / (2.0 * wt)];
        let shares = w.rest_split(&[0, 1], 2.0 * wt, [0.0, -depth], mean, moment).unwrap();
        let d = moment / (2.0 * wt * a * a);
        assert!((shares[0][1] - (mean[1] - a * d)).abs() < 1e-6 * mean[1]);
        assert!((shares[1][1] - (mean[1] + a * d)).abs() < 1e-6 * mean[1]);
        assert!(shares[0][0].abs() < 1e-9 && shares[1][0].abs() < 1e-9);
        // The shares carry the force and the moment asked.
        let f: f64 = shares.iter().map(|s| wt * s[1]).sum();
        let m: f64 = shares.iter().zip([-a, a]).map(|(s, x)| wt * x * s[1]).sum();
        assert!((f - fz).abs() < 1e-12 && (m - moment).abs() < 1e-12, "{f} {m}");
        // One element alone carries no moment beyond its force's own.
        let w = walker_with(vec![element([a, -depth], wt, BELLY)], [0.0; 3]);
        assert!(w.rest_split(&[0], wt, [a, -depth], [0.0, fz / wt], moment).is_none());
        assert!(w.rest_split(&[0], wt, [a, -depth], [0.0, fz / wt], a * fz).is_some());
    }
}
