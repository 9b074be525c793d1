//! The default law's element forces, [`LANES`] elements at a time (docs/model.md §16-§17).
//!
//! Under the default scaling ([`RftScaling::Motion`](super::super::rft::RftScaling)) without
//! leg-sand friction, the force on an element and its Jacobian are
//! [`element_force`](super::super::body::element_force) of
//! [`Rft::passive_stress_and_turn`]: a chain of square roots and divisions with no loop, whose
//! latency, one element after another, was most of a walk's time (the force evaluation was 63%
//! of a 10 degree walk, `perf`, 2026-12-02). Here the same operations, in the same order, run
//! on [`LANES`] elements side by side, their branches (the mirror, the passive projection, rest)
//! taken as selects, so the compiler issues them as vector instructions (two lanes of SSE2 on
//! the baseline x86-64 target, which every `x86_64` build may assume). The answers are the
//! scalar path's to the bit (a test compares them over orientations, directions and speeds
//! down to rest); any other scaling, friction, and the associated stand-in take the scalar
//! path.

use super::super::body::{Contact, BELLY};
use super::super::rft::{Rft, A00, A10, B01, B11, BM11, C01, C11, CM11, D10};
use wide::{f64x4, CmpLe, CmpLt};

/// Elements evaluated side by side.
pub(super) const LANES: usize = 4;
const _: () = assert!(LANES == 4, "the lanes are f64x4");

/// A group's per-step constants, lane by lane: what [`Contact`] and the leg rates give.
#[derive(Debug, Clone, Copy, Default)]
struct Group {
    rel_x: [f64; LANES],
    rel_z: [f64; LANES],
    arm_x: [f64; LANES],
    arm_z: [f64; LANES],
    rate: [f64; LANES],
    weight: [f64; LANES],
    /// `tx^2 - tz^2`: cos 2 beta.
    cos2b: [f64; LANES],
    /// `(2 tx) tz`: sin 2 beta before the mirror's sign.
    sin2b: [f64; LANES],
}

/// A group's forces and Jacobians, lane by lane, with what each adds to the body's sums
/// ([`Lanes::accumulate`]): the moment `rx fz - rz fx`, the Jacobian's third column
/// `-rz d_i0 + rx d_i1` and third row.
#[derive(Debug, Clone, Copy, Default)]
struct Out {
    fx: [f64; LANES],
    fz: [f64; LANES],
    d: [[[f64; LANES]; 2]; 2],
    moment: [f64; LANES],
    third_column: [[f64; LANES]; 2],
    third_row: [[f64; LANES]; 3],
}

/// The step's contacts prepared for [`Lanes::evaluate`], and its last answers.
#[derive(Debug, Default)]
pub(super) struct Lanes {
    groups: Vec<Group>,
    out: Vec<Out>,
    /// The law's `(zeta_z, zeta_x, scale_n)`, when it is the one this path evaluates.
    law: Option<(f64, f64, f64)>,
}

impl Lanes {
    /// Prepares the step's `contacts` (legs turning at `rates`) under the legs' law `leg` and
    /// the belly's `belly`; the path is off (`false`) unless both are the default law without
    /// friction, the same for legs and belly.
    pub(super) fn prepare(&mut self, contacts: &[Contact], rates: &[f64], leg: &Rft, belly: &Rft) -> bool {
        self.law = match (leg.motion_scales(), belly.motion_scales()) {
            (Some(l), Some(b)) if l == b => Some((l.0, l.1, leg.scale_n())),
            _ => None,
        };
        if self.law.is_none() {
            return false;
        }
        let groups = contacts.len().div_ceil(LANES);
        self.groups.clear();
        self.groups.resize(groups, Group::default());
        self.out.resize(groups, Out::default());
        for (k, c) in contacts.iter().enumerate() {
            let (g, l) = (&mut self.groups[k / LANES], k % LANES);
            let (tx, tz) = (c.tangent[0], c.tangent[1]);
            g.rel_x[l] = c.rel[0];
            g.rel_z[l] = c.rel[1];
            g.arm_x[l] = c.arm[0];
            g.arm_z[l] = c.arm[1];
            g.rate[l] = if c.leg == BELLY { 0.0 } else { rates[c.leg] };
            g.weight[l] = c.weight;
            g.cos2b[l] = tx * tx - tz * tz;
            g.sin2b[l] = 2.0 * tx * tz;
        }
        true
    }

    /// Every prepared element's force and Jacobian when the body moves at `v` (creep `eps`).
    pub(super) fn evaluate(&mut self, v: [f64; 3], eps: f64) {
        let Some((zz, zx, scale_n)) = self.law else { return };
        for (g, out) in self.groups.iter().zip(&mut self.out) {
            group(g, out, v, eps, zz, zx, scale_n);
        }
    }

    /// Adds the last [`Lanes::evaluate`]'s forces of the first `n` elements to `forces`, their
    /// force and moment about the centre of mass to `g` and (with `jacobian`) `J^T D J` to `k`,
    /// `J = [[1, 0, -rz], [0, 1, rx]]`: one element after another, the order and the
    /// operations of the scalar path in `Walker::evaluate` (its products formed lane by lane),
    /// so the sums are its to the bit.
    pub(super) fn accumulate(
        &self,
        n: usize,
        forces: &mut Vec<[f64; 2]>,
        g: &mut [f64; 3],
        k: &mut [[f64; 3]; 3],
        jacobian: bool,
    ) {
        for i in 0..n {
            let (o, l) = (&self.out[i / LANES], i % LANES);
            forces.push([o.fx[l], o.fz[l]]);
            g[0] += o.fx[l];
            g[1] += o.fz[l];
            g[2] += o.moment[l];
            if jacobian {
                k[0][0] += o.d[0][0][l];
                k[0][1] += o.d[0][1][l];
                k[0][2] += o.third_column[0][l];
                k[1][0] += o.d[1][0][l];
                k[1][1] += o.d[1][1][l];
                k[1][2] += o.third_column[1][l];
                k[2][0] += o.third_row[0][l];
                k[2][1] += o.third_row[1][l];
                k[2][2] += o.third_row[2][l];
            }
        }
    }

    /// Element `k`'s force and Jacobian from the last [`Lanes::evaluate`] (tests).
    #[cfg(test)]
    fn get(&self, k: usize) -> ([f64; 2], [[f64; 2]; 2]) {
        let (o, l) = (&self.out[k / LANES], k % LANES);
        ([o.fx[l], o.fz[l]], [[o.d[0][0][l], o.d[0][1][l]], [o.d[1][0][l], o.d[1][1][l]]])
    }
}

/// One group: [`element_force`](super::super::body::element_force) with its Jacobian and
/// [`Rft::passive_stress_and_turn`] under `Motion` without friction, lane by lane as `f64x4`
/// with the same operations in the same order (the expressions are theirs, term for term), the
/// branches as selects and negation as the sign bit flipped (as `-x` does; `wide`'s `Neg` is
/// `0 - x`, which differs on zeros).
#[inline(always)]
fn group(g: &Group, out: &mut Out, v: [f64; 3], eps: f64, zz: f64, zx: f64, scale_n: f64) {
    let neg = |x: f64x4| x ^ f64x4::splat(-0.0);
    let k = f64x4::splat;
    let (zero, one) = (k(0.0), k(1.0));
    let (rate, w) = (f64x4::from(g.rate), f64x4::from(g.weight));
    let (rel_x, rel_z) = (f64x4::from(g.rel_x), f64x4::from(g.rel_z));
    let (arm_x, arm_z) = (f64x4::from(g.arm_x), f64x4::from(g.arm_z));
    // Walker::element_velocity.
    let u0 = k(v[0]) - k(v[2]) * rel_z + rate * arm_z;
    let u1 = k(v[1]) + k(v[2]) * rel_x - rate * arm_x;
    let s = (u0 * u0 + u1 * u1).sqrt();
    let (ex, ez) = (u0 / s, u1 / s);
    // Rft::passive_stress_and_turn: the mirror (sg = -1 for motion towards -x).
    let mirror = ex.cmp_lt(zero);
    let neg_sg = mirror.blend(one, neg(one));
    let cos2b = f64x4::from(g.cos2b);
    let sin2b = f64x4::from(g.sin2b);
    let sin2b = mirror.blend(neg(sin2b), sin2b);
    let (cosg, sing) = (ex.abs(), neg(ez));
    let (dcosg, dsing) = (neg_sg * ez, neg(ex));
    // rft::generic.
    let sin_sum = sin2b * cosg + cos2b * sing;
    let sin_diff = sing * cos2b - cosg * sin2b;
    let cos_sum = cos2b * cosg - sin2b * sing;
    let cos_diff = cosg * cos2b + sing * sin2b;
    let az = k(A00) + k(A10) * cos2b + k(B01) * sing + k(B11) * sin_sum + k(BM11) * sin_diff;
    let ax = k(C11) * cos_sum + k(C01) * cosg + k(CM11) * cos_diff + k(D10) * sin2b;
    let daz =
        k(B01) * dsing + k(B11) * (sin2b * dcosg + cos2b * dsing) + k(BM11) * (dsing * cos2b - dcosg * sin2b);
    let dax =
        k(C11) * (cos2b * dcosg - sin2b * dsing) + k(C01) * dcosg + k(CM11) * (dcosg * cos2b + dsing * sin2b);
    let zeta = k(zz) * ez * ez + k(zx) * ex * ex;
    let dzeta = k(2.0) * ex * ez * k(zz - zx);
    let (st0, st1) = (neg_sg * zeta * ax, zeta * az);
    let (dst0, dst1) = (neg_sg * (dzeta * ax + zeta * dax), dzeta * az + zeta * daz);
    // The passive projection where the stress has a component along the motion.
    let along = st0 * ex + st1 * ez;
    let dalong = dst0 * ex + dst1 * ez + (neg(st0) * ez + st1 * ex);
    let keep = along.cmp_le(zero);
    let st0 = keep.blend(st0, st0 - along * ex);
    let st1 = keep.blend(st1, st1 - along * ez);
    let turn0 = keep.blend(dst0, dst0 - dalong * ex + along * ez);
    let turn1 = keep.blend(dst1, dst1 - dalong * ez - along * ex);
    // element_force.
    let eps_v = k(eps);
    let r = s / eps_v;
    let root = (one + r * r).sqrt();
    let phi = r / root;
    let (n0, n1) = (neg(ez), ex);
    let radial = w / (eps_v * root * root * root);
    let tangential = w * phi / s;
    let j00 = radial * st0 * ex + tangential * turn0 * n0;
    let j01 = radial * st0 * ez + tangential * turn0 * n1;
    let j10 = radial * st1 * ex + tangential * turn1 * n0;
    let j11 = radial * st1 * ez + tangential * turn1 * n1;
    // At rest: no force, an isotropic Jacobian (rare, so its division only where a lane rests).
    let (fx, fz) = (w * phi * st0, w * phi * st1);
    let rest = s.cmp_le(k(1e-300));
    let (fx, fz, j00, j01, j10, j11) = if rest.none() {
        (fx, fz, j00, j01, j10, j11)
    } else {
        let stiff = neg(w * k(scale_n) / eps_v);
        let r = |at: f64x4, moving: f64x4| rest.blend(at, moving);
        (r(zero, fx), r(zero, fz), r(stiff, j00), r(zero, j01), r(zero, j10), r(stiff, j11))
    };
    out.fx = fx.to_array();
    out.fz = fz.to_array();
    out.d = [[j00.to_array(), j01.to_array()], [j10.to_array(), j11.to_array()]];
    // Walker::evaluate's sums: the moment, and J^T D J's third column and row.
    let neg_rz = neg(rel_z);
    out.moment = (rel_x * fz - rel_z * fx).to_array();
    let (c0, c1) = (neg_rz * j00 + rel_x * j01, neg_rz * j10 + rel_x * j11);
    out.third_column = [c0.to_array(), c1.to_array()];
    out.third_row = [
        (neg_rz * j00 + rel_x * j10).to_array(),
        (neg_rz * j01 + rel_x * j11).to_array(),
        (neg_rz * c0 + rel_x * c1).to_array(),
    ];
}

#[cfg(test)]
mod tests {
    use super::super::super::body::element_force;
    use super::super::super::rft::RftScaling;
    use super::*;

    /// The lanes are the scalar path to the bit, each element's force and Jacobian and their
    /// sums: elements round the circle (and the reference plates), legs turning and the belly,
    /// body rates in every direction and at speeds from 1e3 times the creep down to exact
    /// rest, so every branch (mirror, projection, rest) is taken in some lane next to lanes
    /// that do not take it.
    #[test]
    fn the_lanes_are_the_scalar_path_to_the_bit() {
        let rft = Rft::with_scaling(7e5, 3.26e6, RftScaling::Motion);
        let eps = 1e-7;
        let mut contacts = Vec::new();
        for i in 0..=37 {
            let b = std::f64::consts::PI * i as f64 / 36.0 + if i % 3 == 1 { 0.011 } else { 0.0 };
            contacts.push(Contact {
                weight: 1e-6 * (1.0 + i as f64),
                tangent: [b.cos(), b.sin()],
                rel: [0.01 * (i as f64 - 18.0), -0.03 - 0.001 * i as f64],
                arm: if i % 5 == 0 { [0.0; 2] } else { [0.02 * b.sin(), -0.02 * b.cos()] },
                leg: if i % 5 == 0 { BELLY } else { i % 6 },
                depth: 0.01,
            });
        }
        let rates = [0.0, 6.2, 3.1, 0.0, 12.5, 1e-9];
        let mut lanes = Lanes::default();
        assert!(lanes.prepare(&contacts, &rates, &rft, &rft));
        let mut count = 0;
        for speed in [0.0, 1e-10, 1e-7, 1e-4, 0.3] {
            for k in 0..16 {
                let a = std::f64::consts::TAU * k as f64 / 16.0;
                for spin in [0.0, -2.0, 0.7] {
                    let v = [speed * a.cos(), speed * a.sin(), spin * speed];
                    lanes.evaluate(v, eps);
                    // The sums as Walker::evaluate's scalar path forms them.
                    let (mut g, mut k) = ([0.0; 3], [[0.0; 3]; 3]);
                    for (i, c) in contacts.iter().enumerate() {
                        let rate = if c.leg == BELLY { 0.0 } else { rates[c.leg] };
                        let u = super::super::Walker::element_velocity(c, v, rate);
                        let (f, d) = element_force(&rft, c, u, eps, true);
                        let (lf, ld) = lanes.get(i);
                        assert_eq!(lf.map(f64::to_bits), f.map(f64::to_bits), "{i} {v:?}");
                        assert_eq!(
                            ld.map(|r| r.map(f64::to_bits)),
                            d.map(|r| r.map(f64::to_bits)),
                            "{i} {v:?}"
                        );
                        super::super::add_element(&mut g, &mut k, c.rel, f, Some(d));
                        count += 1;
                    }
                    let (mut forces, mut lg, mut lk) = (Vec::new(), [0.0; 3], [[0.0; 3]; 3]);
                    lanes.accumulate(contacts.len(), &mut forces, &mut lg, &mut lk, true);
                    assert_eq!(forces.len(), contacts.len());
                    assert_eq!(lg.map(f64::to_bits), g.map(f64::to_bits), "{v:?}");
                    assert_eq!(lk.map(|r| r.map(f64::to_bits)), k.map(|r| r.map(f64::to_bits)), "{v:?}");
                }
            }
        }
        assert!(count > 5000);
        // Elements at rest exactly: the group's body rates cancel a leg's turn at its point.
        let c = contacts[1];
        let v = [-rates[c.leg] * c.arm[1], rates[c.leg] * c.arm[0], 0.0];
        lanes.evaluate(v, eps);
        let (f, d) = lanes.get(1);
        let k = c.weight * rft.scale_n() / eps;
        assert_eq!((f, d), ([0.0; 2], [[-k, 0.0], [0.0, -k]]));
    }

    /// The path is the default law's only: another scaling, friction on the legs, or a belly
    /// law unlike the legs' turn it off.
    #[test]
    fn other_laws_take_the_scalar_path() {
        let motion = Rft::new(7e5, 3e6);
        let mut lanes = Lanes::default();
        for (leg, belly) in [
            (Rft::with_scaling(7e5, 3e6, RftScaling::Li2013), motion),
            (Rft::with_scaling(7e5, 3e6, RftScaling::Components), motion),
            (motion.with_friction(Some(0.3)), motion),
            (motion, Rft::new(7e5, 2e6)),
        ] {
            assert!(!lanes.prepare(&[], &[], &leg, &belly));
        }
        assert!(lanes.prepare(&[], &[], &motion, &motion));
    }
}
