//! Granular resistive force theory (docs/model.md §16): the generic Fourier form of Li, Zhang
//! and Goldman (Science 339, 1408, 2013), scaled to a terrain's k_n and k_s.
//!
//! An element is a flat strip of the leg with tangent angle beta; it moves in direction gamma
//! (the angle of its velocity below the horizontal, measured on the side it moves towards).
//! Below the free surface it feels the stresses `alpha_z(beta, gamma) * depth` (upward) and
//! `alpha_x(beta, gamma) * depth` (against its horizontal motion). The generic form gives the
//! dimensionless shape of alpha; [`Rft::new`] scales its vertical part so that a horizontal
//! plate pushed straight down feels `k_n * depth` (F = k_n A d) and its horizontal part so that
//! a vertical plate of width W spanning the surface to depth d, pushed sideways, feels
//! `k_s W d^2` (the paper's F_s, §4), i.e. `alpha_x(pi/2, 0) = 2 k_s`.

use wide::{f64x4, CmpGt, CmpLe, CmpLt};

/// Coefficients of the generic form (Li, Zhang and Goldman 2013, Fig. 2 and supplement):
/// `A00, A10, B01, B11, B-11` of alpha_z and `C01, C11, C-11, D10` of alpha_x.
pub(crate) const A00: f64 = 0.206;
pub(crate) const A10: f64 = 0.169;
pub(crate) const B01: f64 = 0.358;
pub(crate) const B11: f64 = 0.212;
pub(crate) const BM11: f64 = 0.055;
pub(crate) const C01: f64 = 0.253;
pub(crate) const C11: f64 = -0.124;
pub(crate) const CM11: f64 = 0.007;
pub(crate) const D10: f64 = 0.088;

/// The generic (unscaled) `(alpha_z, alpha_x)` for an element whose tangent makes `2 beta`
/// with `(cos 2beta, sin 2beta)` and whose motion has `(cos gamma, sin gamma)`, gamma > 0
/// downward, motion towards +x (mirror first for motion towards -x).
#[inline]
pub fn generic(cos2b: f64, sin2b: f64, cosg: f64, sing: f64) -> (f64, f64) {
    let sin_sum = sin2b * cosg + cos2b * sing; // sin(2b + g)
    let sin_diff = sing * cos2b - cosg * sin2b; // sin(g - 2b)
    let cos_sum = cos2b * cosg - sin2b * sing; // cos(2b + g)
    let cos_diff = cosg * cos2b + sing * sin2b; // cos(g - 2b)
    let az = A00 + A10 * cos2b + B01 * sing + B11 * sin_sum + BM11 * sin_diff;
    let ax = C11 * cos_sum + C01 * cosg + CM11 * cos_diff + D10 * sin2b;
    (az, ax)
}

/// How the generic form is scaled to the terrain's k_n and k_s (docs/model.md §16). Both
/// choices make a horizontal plate pushed straight down feel `k_n d` and a vertical plate
/// pushed sideways feel `2 k_s d`; they differ for every other motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RftScaling {
    /// One scale for both stresses that follows the direction of motion,
    /// `zeta_n e_z^2 + zeta_s e_x^2` (the default): motion normal to the surface is governed by
    /// the penetration tests, motion along it by the shear tests.
    #[default]
    Motion,
    /// The normal stress scaled by `zeta_n` and the along-surface stress by `zeta_s`, whatever
    /// the motion: normal stresses by the penetration tests, shear stresses by the shear tests.
    /// Unlike the other two it can push along the motion; the passive projection
    /// ([`Rft::passive_stress`]) removes that part.
    Components,
    /// Li, Zhang and Goldman (2013)'s own scaling: one factor `zeta_n = k_n / alpha_z(0, pi/2)`
    /// for both stresses and every motion (the generic coefficients unchanged). The terrain's
    /// k_s is not used: the slope enters through gravity only.
    Li2013,
}

impl RftScaling {
    /// The setting's name, as `--rft-scaling` and `--json` spell it.
    pub fn name(self) -> &'static str {
        match self {
            RftScaling::Motion => "motion",
            RftScaling::Components => "components",
            RftScaling::Li2013 => "li2013",
        }
    }
}

/// Resistive force theory scaled to one ground (k_n, k_s at one slope).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rft {
    zeta_z: f64,
    zeta_x: f64,
    scaling: RftScaling,
    /// Leg-sand friction coefficient capping the along-surface stress (§20.1), if any.
    friction: Option<f64>,
    /// A one-sided contact (the belly, §20.5): the sand only on the element's right-hand side
    /// (`-n`, `n = (-t_z, t_x)`), so it pushes along `n` and never pulls, and the stress along
    /// the surface is at most this coefficient times that push. `None`: a plate in sand on
    /// both faces, as resistive force theory's plates were.
    unilateral: Option<f64>,
}

impl Rft {
    /// Scales the generic form to `k_n` (N/m^3) and `k_s` (N/m^3) by the default
    /// [`RftScaling::Motion`], docs/model.md §16.
    pub fn new(k_n: f64, k_s: f64) -> Rft {
        Rft::with_scaling(k_n, k_s, RftScaling::Motion)
    }

    /// Scales the generic form to `k_n` and `k_s` by `scaling`, docs/model.md §16.
    pub fn with_scaling(k_n: f64, k_s: f64, scaling: RftScaling) -> Rft {
        // Horizontal plate (beta = 0) pushed straight down (gamma = pi/2).
        let (az_down, _) = generic(1.0, 0.0, 0.0, 1.0);
        // Vertical plate (beta = pi/2, so 2 beta = pi) pushed sideways (gamma = 0).
        let (_, ax_side) = generic(-1.0, 0.0, 1.0, 0.0);
        let zeta_z = k_n / az_down;
        let zeta_x = match scaling {
            RftScaling::Li2013 => zeta_z,
            _ => 2.0 * k_s / ax_side,
        };
        Rft { zeta_z, zeta_x, scaling, friction: None, unilateral: None }
    }

    /// The same law with leg-sand friction `mu` capping the stress along an element's surface
    /// (docs/model.md §20.1); `None` leaves the law as it is.
    pub fn with_friction(self, mu: Option<f64>) -> Rft {
        Rft { friction: mu, ..self }
    }

    /// The same law on a one-sided element (docs/model.md §20.5): the sand, on the element's
    /// right-hand side only, never pulls it (the stress's component along `n = (-t_z, t_x)`
    /// is at least 0), and the stress along the surface is at most the law's own ratio for a
    /// flat plate dragged along the surface, `mu = sigma_x / sigma_z` (0.363 = tan 19.9 deg
    /// under `Motion` and `Li2013`), times that push: a dragged, pressed plate is unchanged,
    /// a lifted one is let go, continuously.
    pub fn one_sided(self) -> Rft {
        let (sx, sz) = self.stress(1.0, 0.0, 1.0, 0.0);
        Rft { unilateral: Some((sx / sz).abs()), ..self }
    }

    /// The one-sided contact's friction coefficient, if the law is one-sided.
    pub fn one_sided_friction(&self) -> Option<f64> {
        self.unilateral
    }

    /// `(zeta_z, zeta_x)` where the law is the default scaling ([`RftScaling::Motion`]) without
    /// friction: the one law the simulator evaluates several elements at a time.
    pub(crate) fn motion_scales(&self) -> Option<(f64, f64)> {
        (self.scaling == RftScaling::Motion && self.friction.is_none() && self.unilateral.is_none())
            .then_some((self.zeta_z, self.zeta_x))
    }

    /// The stress per unit depth of a horizontal plate pushed straight down, N/m^3 (k_n).
    #[inline]
    pub fn scale_n(&self) -> f64 {
        self.zeta_z
    }

    /// [`Rft::stress`] made passive (docs/model.md §16): its component along the motion, where
    /// it has one, removed, `S - max(0, S.e) e`, so the sand never pushes an element along its
    /// own motion. Under `Motion` and `Li2013` the generic form is already passive (a test
    /// checks it over every orientation and direction), so this changes only `Components`.
    #[inline]
    pub fn passive_stress(&self, tx: f64, tz: f64, ex: f64, ez: f64) -> (f64, f64) {
        passive(self.stress(tx, tz, ex, ez), ex, ez)
    }

    /// Stress per unit depth `(sigma_x, sigma_z)`, N/m^3 (force per unit area per unit depth),
    /// on an element with unit tangent `(tx, tz)` moving in unit direction `(ex, ez)` (z up).
    #[inline]
    pub fn stress(&self, tx: f64, tz: f64, ex: f64, ez: f64) -> (f64, f64) {
        // Mirror motion towards -x onto +x: beta -> -beta, the x force flips back after.
        let s = if ex < 0.0 { -1.0 } else { 1.0 };
        let cos2b = tx * tx - tz * tz;
        let sin2b = s * 2.0 * tx * tz;
        let (az, ax) = generic(cos2b, sin2b, ex.abs(), -ez);
        // Motion: the scale follows the direction of motion (normal motion k_n, along-slope
        // motion k_s); Li2013: one scale for everything; Components: normal stress k_n,
        // along-surface stress k_s.
        let (kx, kz) = self.scales(ex, ez);
        let st = (-s * kx * ax, kz * az);
        let st = match self.friction {
            None => st,
            Some(mu) => super::mechanisms::friction_cap(mu, tx, tz, st.0, st.1).0,
        };
        match self.unilateral {
            None => st,
            Some(mu) => super::mechanisms::one_sided_cap(mu, tx, tz, st.0, st.1).0,
        }
    }

    /// Whether `force` (N) can hold an element of unit tangent `tangent` and weight `weight`
    /// (m^3, [`super::body::Contact::weight`]) at rest: the rate-independent law is set-valued
    /// there, and the set is the region bounded by `weight * sigma(e)` over every direction of
    /// motion `e` (docs/model.md §17); [`RestSet`] tests it.
    pub fn holds_at_rest(&self, tangent: [f64; 2], weight: f64, force: [f64; 2]) -> bool {
        weight > 0.0 && self.rest_set(tangent).holds([force[0] / weight, force[1] / weight])
    }

    /// The stresses per unit depth (N/m^3) an element of unit tangent `tangent` can hold at
    /// rest, sampled once at [`SET_DIRECTIONS`] directions of motion, for testing several
    /// stresses against the same set (the elements of a resting group share a tangent).
    ///
    /// Without leg-sand friction the generic form at each sampled direction is linear in the
    /// element's `(cos 2beta, sin 2beta)`, so the set is built from per-direction terms
    /// computed once ([`direction_terms`]): six multiply-adds a direction instead of the whole
    /// law (the set was 40% of a level walk's time, measured with `perf` on 2026-12-01; it
    /// agrees with the law's own stress to round-off, a test checks it). Friction caps the
    /// stress nonlinearly in the tangent, so with friction every direction takes the law.
    pub fn rest_set(&self, tangent: [f64; 2]) -> RestSet {
        let mut set = RestSet::default();
        self.rest_set_into(tangent, &mut set);
        set
    }

    /// [`Rft::rest_set`] written into `set` (a walk keeps one, [`RestSet`] being 5.8 kB).
    pub fn rest_set_into(&self, tangent: [f64; 2], set: &mut RestSet) {
        if self.friction.is_some() || self.unilateral.is_some() {
            for (k, e) in set_directions().iter().enumerate() {
                let st = self.passive_stress(tangent[0], tangent[1], e[0], e[1]);
                set.x[k / 4].as_array_mut()[k % 4] = st.0;
                set.z[k / 4].as_array_mut()[k % 4] = st.1;
            }
            return;
        }
        let (tx, tz) = (tangent[0], tangent[1]);
        let (cos2b, sin2b) = (f64x4::splat(tx * tx - tz * tz), f64x4::splat(2.0 * tx * tz));
        let (zx, zz) = (f64x4::splat(self.zeta_x), f64x4::splat(self.zeta_z));
        let zero = f64x4::splat(0.0);
        let terms = direction_terms();
        // Four directions at a time, the operations of the scalar law in its order (a test
        // compares them with the law); the projection's `max` is `passive`'s test: a component
        // along the motion of zero or less leaves the stress as it is.
        for (k, d) in terms.iter().enumerate() {
            let (ex, ez, mirror) = (d.ex, d.ez, d.mirror);
            let (kx, kz) = match self.scaling {
                RftScaling::Motion => {
                    let zeta = zz * ez * ez + zx * ex * ex;
                    (zeta, zeta)
                }
                RftScaling::Li2013 => (zz, zz),
                RftScaling::Components => (zx, zz),
            };
            let sin2b = mirror * sin2b;
            let az = d.az[0] + cos2b * d.az[1] + sin2b * d.az[2];
            let ax = d.ax[0] + cos2b * d.ax[1] + sin2b * d.ax[2];
            let (sx, sz) = ((mirror ^ f64x4::splat(-0.0)) * kx * ax, kz * az);
            let along = sx * ex + sz * ez;
            let along = along.cmp_gt(zero).blend(along, zero);
            set.x[k] = sx - along * ex;
            set.z[k] = sz - along * ez;
        }
    }

    /// The scale factors `(x, z)` of the generic form's two stresses for motion in the unit
    /// direction `(ex, ez)`, by the scaling (docs/model.md §16).
    #[inline]
    fn scales(&self, ex: f64, ez: f64) -> (f64, f64) {
        match self.scaling {
            RftScaling::Motion => {
                let zeta = self.zeta_z * ez * ez + self.zeta_x * ex * ex;
                (zeta, zeta)
            }
            RftScaling::Li2013 => (self.zeta_z, self.zeta_z),
            RftScaling::Components => (self.zeta_x, self.zeta_z),
        }
    }

    /// [`Rft::passive_stress`] and its derivative with respect to the angle of the direction
    /// of motion `e` (that is, along `n = (-e_z, e_x)`), worked out from the generic form's
    /// Fourier terms: the Jacobian of an element's force (§17) without the two extra stress
    /// evaluations central differences took. Where `e_x = 0` (the mirror's seam) it is the
    /// derivative on the side `e_x >= 0`.
    #[inline]
    pub fn passive_stress_and_turn(&self, tx: f64, tz: f64, ex: f64, ez: f64) -> ((f64, f64), (f64, f64)) {
        let s = if ex < 0.0 { -1.0 } else { 1.0 };
        let cos2b = tx * tx - tz * tz;
        let sin2b = s * 2.0 * tx * tz;
        let (cosg, sing) = (ex.abs(), -ez);
        // d e / d angle = (-e_z, e_x): d cos(gamma) = s (-e_z), d sin(gamma) = -e_x.
        let (dcosg, dsing) = (-s * ez, -ex);
        let (az, ax) = generic(cos2b, sin2b, cosg, sing);
        let daz =
            B01 * dsing + B11 * (sin2b * dcosg + cos2b * dsing) + BM11 * (dsing * cos2b - dcosg * sin2b);
        let dax =
            C11 * (cos2b * dcosg - sin2b * dsing) + C01 * dcosg + CM11 * (dcosg * cos2b + dsing * sin2b);
        let (st, dst) = match self.scaling {
            RftScaling::Motion => {
                let zeta = self.zeta_z * ez * ez + self.zeta_x * ex * ex;
                let dzeta = 2.0 * ex * ez * (self.zeta_z - self.zeta_x);
                ((-s * zeta * ax, zeta * az), (-s * (dzeta * ax + zeta * dax), dzeta * az + zeta * daz))
            }
            RftScaling::Li2013 => {
                let z = self.zeta_z;
                ((-s * z * ax, z * az), (-s * z * dax, z * daz))
            }
            RftScaling::Components => {
                ((-s * self.zeta_x * ax, self.zeta_z * az), (-s * self.zeta_x * dax, self.zeta_z * daz))
            }
        };
        // Leg-sand friction (§20.1): a capped along-surface stress follows the normal one.
        let (st, dst) = match self.friction {
            None => (st, dst),
            Some(mu) => match super::mechanisms::friction_cap(mu, tx, tz, st.0, st.1) {
                (capped, None) => (capped, dst),
                (capped, Some(slope)) => {
                    let dnormal = -dst.0 * tz + dst.1 * tx;
                    (capped, (slope * dnormal * tx - dnormal * tz, slope * dnormal * tz + dnormal * tx))
                }
            },
        };
        // One-sided contact (§20.5): no pull, and the along-surface stress capped by the push.
        let (st, dst) = match self.unilateral {
            None => (st, dst),
            Some(mu) => match super::mechanisms::one_sided_cap(mu, tx, tz, st.0, st.1) {
                (capped, super::mechanisms::Capped::Free) => (capped, dst),
                (capped, super::mechanisms::Capped::Zero) => (capped, (0.0, 0.0)),
                (capped, super::mechanisms::Capped::Along(slope)) => {
                    let dnormal = -dst.0 * tz + dst.1 * tx;
                    (capped, (slope * dnormal * tx - dnormal * tz, slope * dnormal * tz + dnormal * tx))
                }
            },
        };
        let along = st.0 * ex + st.1 * ez;
        if along <= 0.0 {
            return (st, dst);
        }
        // P = S - (S.e) e: dP = dS - (dS.e + S.n) e - (S.e) n, with n = (-e_z, e_x).
        let dalong = dst.0 * ex + dst.1 * ez + (-st.0 * ez + st.1 * ex);
        (
            (st.0 - along * ex, st.1 - along * ez),
            (dst.0 - dalong * ex + along * ez, dst.1 - dalong * ez - along * ex),
        )
    }
}

/// The set of stresses per unit depth an element can hold at rest (docs/model.md §17): the
/// region bounded by the law's stress `sigma(e)` over every direction of motion `e`, sampled
/// ([`Rft::rest_set`]), its points' x and z components apart (for four at a time).
pub struct RestSet {
    x: [f64x4; CHUNKS],
    z: [f64x4; CHUNKS],
}

/// The sampled directions in fours.
const CHUNKS: usize = SET_DIRECTIONS / 4;

impl Default for RestSet {
    /// The set of an element that holds nothing (every boundary point at zero).
    fn default() -> RestSet {
        RestSet { x: [f64x4::splat(0.0); CHUNKS], z: [f64x4::splat(0.0); CHUNKS] }
    }
}

impl RestSet {
    /// Whether the stress `stress` (N/m^3) lies in the set: the winding number of the sampled
    /// boundary about it, counted as signed crossings of a ray (Sunday's rule, exact for the
    /// sampled polygon), which decides as the sum of the edges' angles did without one `atan2`
    /// per edge (that sum and the directions' `sin_cos` were a third of a level walk's time,
    /// measured with `perf` on 2026-11-28). Four edges at a time: the test of each edge is
    /// the same comparisons on the same products as one edge at a time, and the crossings are
    /// counted lane by lane (small whole numbers, exact in `f64`).
    pub fn holds(&self, stress: [f64; 2]) -> bool {
        let (sx, sz) = (f64x4::splat(stress[0]), f64x4::splat(stress[1]));
        let (zero, one) = (f64x4::splat(0.0), f64x4::splat(1.0));
        let mut winding = zero;
        // Point k - 1 of each lane: the last point of the chunk before, then this chunk's first
        // three.
        let last = |a: &f64x4| a.to_array()[3];
        let (mut px, mut pz) = (last(&self.x[CHUNKS - 1]), last(&self.z[CHUNKS - 1]));
        for (x, z) in self.x.iter().zip(&self.z) {
            let (xa, za) = (x.to_array(), z.to_array());
            let p0 = f64x4::from([px, xa[0], xa[1], xa[2]]) - sx;
            let p1 = f64x4::from([pz, za[0], za[1], za[2]]) - sz;
            (px, pz) = (xa[3], za[3]);
            let (n0, n1) = (*x - sx, *z - sz);
            // Which side of the edge prev -> next the stress lies on.
            let left = p0 * n1 - p1 * n0;
            let below = p1.cmp_le(zero);
            let up = below & n1.cmp_gt(zero) & left.cmp_gt(zero);
            let down = !below & n1.cmp_le(zero) & left.cmp_lt(zero);
            winding = winding + up.blend(one, zero) - down.blend(one, zero);
        }
        winding.reduce_add() != 0.0
    }

    /// Boundary point `k`, `(x, z)`.
    #[cfg(test)]
    fn point(&self, k: usize) -> [f64; 2] {
        [self.x[k / 4].to_array()[k % 4], self.z[k / 4].to_array()[k % 4]]
    }
}

/// The unit directions of [`SET_DIRECTIONS`] evenly spaced angles, computed once.
fn set_directions() -> &'static [[f64; 2]] {
    static TABLE: std::sync::OnceLock<Vec<[f64; 2]>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        (0..SET_DIRECTIONS)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / SET_DIRECTIONS as f64;
                [a.cos(), a.sin()]
            })
            .collect()
    })
}

/// The stress `st` made passive for motion in the unit direction `(ex, ez)`: its component
/// along the motion, where it has one, removed (docs/model.md §16).
#[inline]
fn passive(st: (f64, f64), ex: f64, ez: f64) -> (f64, f64) {
    let along = st.0 * ex + st.1 * ez;
    if along > 0.0 {
        (st.0 - along * ex, st.1 - along * ez)
    } else {
        st
    }
}

/// The generic form at four sampled directions of motion, as terms of the element's
/// `(1, cos 2beta, mirror * sin 2beta)`: `alpha_z = az . (1, cos 2beta, mirror sin 2beta)`
/// and likewise `alpha_x` ([`generic`] is linear in the two), each term lane by lane.
struct DirectionTerms {
    /// The unit directions of motion `(ex, ez)`.
    ex: f64x4,
    ez: f64x4,
    /// -1 for motion towards -x (mirrored onto +x, as [`Rft::stress`] does), else 1.
    mirror: f64x4,
    az: [f64x4; 3],
    ax: [f64x4; 3],
}

/// [`DirectionTerms`] of the [`SET_DIRECTIONS`] sampled directions in fours, computed once
/// from [`generic`] at `(cos 2beta, sin 2beta)` = (0, 0), (1, 0) and (0, 1).
fn direction_terms() -> &'static [DirectionTerms] {
    static TABLE: std::sync::OnceLock<Vec<DirectionTerms>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        set_directions()
            .chunks_exact(4)
            .map(|four| {
                let lanes = |f: &dyn Fn([f64; 2]) -> f64| f64x4::from([0, 1, 2, 3].map(|i| f(four[i])));
                let terms = |e: [f64; 2]| {
                    let (cosg, sing) = (e[0].abs(), -e[1]);
                    let (az0, ax0) = generic(0.0, 0.0, cosg, sing);
                    let (azc, axc) = generic(1.0, 0.0, cosg, sing);
                    let (azs, axs) = generic(0.0, 1.0, cosg, sing);
                    ([az0, azc - az0, azs - az0], [ax0, axc - ax0, axs - ax0])
                };
                DirectionTerms {
                    ex: lanes(&|e| e[0]),
                    ez: lanes(&|e| e[1]),
                    mirror: lanes(&|e| if e[0] < 0.0 { -1.0 } else { 1.0 }),
                    az: [0, 1, 2].map(|j| lanes(&|e| terms(e).0[j])),
                    ax: [0, 1, 2].map(|j| lanes(&|e| terms(e).1[j])),
                }
            })
            .collect()
    })
}

/// Directions sampled for the set of stresses the law allows at rest ([`Rft::holds_at_rest`]).
const SET_DIRECTIONS: usize = 360;
const _: () = assert!(SET_DIRECTIONS % 4 == 0, "the set is built four directions at a time");

#[cfg(test)]
mod tests {
    use super::*;

    /// The generic form at its reference motions, by hand from the coefficients:
    /// horizontal plate down: 0.206 + 0.169 + 0.358 + 0.212 + 0.055 = 1.000;
    /// vertical plate sideways: alpha_x = 0.124 + 0.253 - 0.007 = 0.370,
    /// alpha_z = 0.206 - 0.169 = 0.037; horizontal plate dragged sideways:
    /// alpha_x = -0.124 + 0.253 + 0.007 = 0.136.
    #[test]
    fn generic_form_at_reference_motions() {
        let (az, _) = generic(1.0, 0.0, 0.0, 1.0);
        assert!((az - 1.0).abs() < 1e-12);
        let (az, ax) = generic(-1.0, 0.0, 1.0, 0.0);
        assert!((ax - 0.370).abs() < 1e-12 && (az - 0.037).abs() < 1e-12);
        let (_, ax) = generic(1.0, 0.0, 1.0, 0.0);
        assert!((ax - 0.136).abs() < 1e-12);
    }

    /// Scaled: a horizontal plate going down feels k_n upward; a vertical plate going +x
    /// feels 2 k_s against it, and going -x the mirror image; a plate tilted like `/` pushed
    /// straight down is pushed along its underside normal, towards -x.
    #[test]
    fn scaled_stresses_and_mirror_symmetry() {
        let rft = Rft::new(7e5, 2e6);
        let (sx, sz) = rft.stress(1.0, 0.0, 0.0, -1.0);
        assert!(sx.abs() < 1e-6 && (sz - 7e5).abs() < 1e-6);
        let (sx, sz) = rft.stress(0.0, 1.0, 1.0, 0.0);
        assert!((sx + 4e6).abs() < 1e-6 && sz > 0.0);
        let (sx2, sz2) = rft.stress(0.0, 1.0, -1.0, 0.0);
        assert!((sx2 - 4e6).abs() < 1e-6 && (sz2 - sz).abs() < 1e-9);
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let (sx, sz) = rft.stress(h, h, 0.0, -1.0);
        assert!(sx < 0.0 && sz > 0.0);
        // The same plate as `\`: pushed towards +x.
        let (sx, _) = rft.stress(h, -h, 0.0, -1.0);
        assert!(sx > 0.0);
    }

    /// Both scalings hold the two reference motions (k_n d down, 2 k_s d sideways); they part on
    /// a horizontal plate dragged along the surface, whose stress ratio by hand is the generic
    /// 0.136 / 0.375 = tan 19.9 deg under `Motion` whatever k_s, and
    /// (2 k_s / 0.370) 0.136 / (k_n 0.375) = 1.960 k_s / k_n under `Components`.
    #[test]
    fn the_two_scalings_share_the_reference_motions_and_part_on_a_dragged_plate() {
        let (k_n, k_s) = (7e5, 1.5e6);
        for scaling in [RftScaling::Motion, RftScaling::Components] {
            let rft = Rft::with_scaling(k_n, k_s, scaling);
            let (sx, sz) = rft.stress(1.0, 0.0, 0.0, -1.0);
            assert!(sx.abs() < 1e-6 && (sz - k_n).abs() < 1e-6, "{scaling:?}");
            let (sx, _) = rft.stress(0.0, 1.0, 1.0, 0.0);
            assert!((sx + 2.0 * k_s).abs() < 1e-6, "{scaling:?}");
        }
        let ratio = |scaling| {
            let (sx, sz) = Rft::with_scaling(k_n, k_s, scaling).stress(1.0, 0.0, 1.0, 0.0);
            -sx / sz
        };
        assert!((ratio(RftScaling::Motion) - 0.136 / 0.375).abs() < 1e-12);
        assert!((ratio(RftScaling::Motion).atan().to_degrees() - 19.93).abs() < 0.01);
        let by_hand = (2.0 * k_s / 0.370) * 0.136 / (k_n * 0.375);
        assert!((ratio(RftScaling::Components) / by_hand - 1.0).abs() < 1e-12);
    }
}

#[cfg(test)]
mod rest_set_tests {
    use super::*;

    /// The closed-form turn derivative against central differences of the stress itself, for
    /// every scaling, tangents round the circle and directions away from the two kinks (the
    /// mirror's seam e_x = 0 and the passive projection's edge S.e = 0).
    #[test]
    fn the_turn_derivative_is_the_stress_differentiated() {
        for (scaling, mu) in [
            (RftScaling::Motion, None),
            (RftScaling::Components, None),
            (RftScaling::Li2013, None),
            (RftScaling::Motion, Some(0.3)),
            (RftScaling::Li2013, Some(0.1)),
        ] {
            let rft = Rft::with_scaling(7e5, 3e6, scaling).with_friction(mu);
            let scale = rft.zeta_z.max(rft.zeta_x);
            for i in 0..24 {
                let b = std::f64::consts::PI * (i as f64 + 0.3) / 24.0;
                let (tx, tz) = (b.cos(), b.sin());
                for k in 0..72 {
                    let a = std::f64::consts::TAU * (k as f64 + 0.37) / 72.0;
                    let (ex, ez) = (a.cos(), a.sin());
                    let h = 1e-6;
                    let p = rft.passive_stress(tx, tz, (a + h).cos(), (a + h).sin());
                    let m = rft.passive_stress(tx, tz, (a - h).cos(), (a - h).sin());
                    let (sp, sm) = (
                        rft.stress(tx, tz, (a + h).cos(), (a + h).sin()),
                        rft.stress(tx, tz, (a - h).cos(), (a - h).sin()),
                    );
                    let along = |st: (f64, f64), t: f64| st.0 * t.cos() + st.1 * t.sin();
                    // The friction cap's edge is a kink too.
                    let capped = |st: (f64, f64)| {
                        mu.is_some_and(|mu| {
                            (st.0 * tx + st.1 * tz).abs() >= mu * (st.1 * tx - st.0 * tz).abs() * 0.999_999
                        })
                    };
                    if ex.abs() < 1e-3
                        || (along(sp, a + h) > 0.0) != (along(sm, a - h) > 0.0)
                        || capped(sp) != capped(sm)
                    {
                        continue;
                    }
                    let (st, turn) = rft.passive_stress_and_turn(tx, tz, ex, ez);
                    let plain = rft.passive_stress(tx, tz, ex, ez);
                    assert!(
                        (st.0 - plain.0).abs() <= 1e-12 * scale && (st.1 - plain.1).abs() <= 1e-12 * scale
                    );
                    let fd = ((p.0 - m.0) / (2.0 * h), (p.1 - m.1) / (2.0 * h));
                    assert!(
                        (turn.0 - fd.0).abs() <= 1e-6 * scale && (turn.1 - fd.1).abs() <= 1e-6 * scale,
                        "{scaling:?} beta {b} angle {a}: {turn:?} against {fd:?}"
                    );
                }
            }
        }
    }

    /// The crossing count decides as the winding angle does: the angle summed with `atan2`
    /// over the same sampled curve (the earlier test), at forces on a grid around the set.
    #[test]
    fn the_crossing_count_agrees_with_the_winding_angle() {
        let rft = Rft::new(7e5, 2e6);
        let w = 1e-5;
        for tangent in [[1.0, 0.0], [0.0, 1.0], [0.6, 0.8], [0.8, -0.6]] {
            for i in -20..=20 {
                for j in -20..=20 {
                    let force = [i as f64 * 0.25e6 * w, j as f64 * 0.1e6 * w + 1e-9];
                    let mut angle = 0.0;
                    let point = |k: usize| {
                        let a = std::f64::consts::TAU * k as f64 / SET_DIRECTIONS as f64;
                        let st = rft.passive_stress(tangent[0], tangent[1], a.cos(), a.sin());
                        [w * st.0 - force[0], w * st.1 - force[1]]
                    };
                    let mut prev = point(0);
                    for k in 1..=SET_DIRECTIONS {
                        let next = point(k % SET_DIRECTIONS);
                        angle += (prev[0] * next[1] - prev[1] * next[0])
                            .atan2(prev[0] * next[0] + prev[1] * next[1]);
                        prev = next;
                    }
                    assert_eq!(
                        rft.holds_at_rest(tangent, w, force),
                        angle.abs() > std::f64::consts::PI,
                        "{tangent:?} {force:?}"
                    );
                }
            }
        }
    }

    /// The set at rest, by its boundary: a horizontal plate's force straight up (what holds it
    /// against being pushed down, k_n W d) is inside at half its size and outside at twice it;
    /// a vertical plate held sideways likewise at 2 k_s; no force at all is inside (rest with no
    /// load).
    #[test]
    fn the_rest_set_is_bounded_by_the_laws_stress_in_every_direction() {
        let rft = Rft::new(7e5, 2e6);
        let w = 1e-5;
        assert!(rft.holds_at_rest([1.0, 0.0], w, [0.0, 0.5 * 7e5 * w]));
        assert!(!rft.holds_at_rest([1.0, 0.0], w, [0.0, 2.0 * 7e5 * w]));
        assert!(rft.holds_at_rest([0.0, 1.0], w, [-0.5 * 4e6 * w, 0.0]));
        assert!(!rft.holds_at_rest([0.0, 1.0], w, [-2.0 * 4e6 * w, 0.0]));
        assert!(rft.holds_at_rest([1.0, 0.0], w, [0.0, 0.0]));
        // Lifted, a horizontal plate feels |alpha_z(0, -pi/2)| = 0.25 of the push's k_n (the
        // generic form: 0.206 + 0.169 - 0.358 - 0.212 - 0.055): a downward force of 0.2 k_n W d
        // holds it, 0.3 does not.
        assert!(rft.holds_at_rest([1.0, 0.0], w, [0.0, -0.2 * 7e5 * w]));
        assert!(!rft.holds_at_rest([1.0, 0.0], w, [0.0, -0.3 * 7e5 * w]));
    }

    /// The set built from the per-direction terms is the law's own passive stress at every
    /// sampled direction (to round-off), for every scaling and tangents round the circle,
    /// including the reference plates; with friction it is the law itself.
    #[test]
    fn the_rest_set_from_direction_terms_is_the_law() {
        for (scaling, mu) in [
            (RftScaling::Motion, None),
            (RftScaling::Components, None),
            (RftScaling::Li2013, None),
            (RftScaling::Motion, Some(0.3)),
        ] {
            let rft = Rft::with_scaling(7e5, 3e6, scaling).with_friction(mu);
            let scale = rft.zeta_z.max(rft.zeta_x);
            for i in 0..=36 {
                let b = std::f64::consts::PI * i as f64 / 36.0 + if i % 5 == 1 { 0.013 } else { 0.0 };
                let (tx, tz) = (b.cos(), b.sin());
                let set = rft.rest_set([tx, tz]);
                for (k, e) in set_directions().iter().enumerate() {
                    let point = set.point(k);
                    let law = rft.passive_stress(tx, tz, e[0], e[1]);
                    assert!(
                        (point[0] - law.0).abs() <= 1e-12 * scale
                            && (point[1] - law.1).abs() <= 1e-12 * scale,
                        "{scaling:?} {mu:?} beta {b}: {point:?} against {law:?}"
                    );
                }
            }
        }
    }
}

#[cfg(test)]
mod passivity_tests {
    use super::*;

    /// The share of a (beta, gamma) grid (1 degree, every orientation and direction) where the
    /// raw stress has a component along the motion, and the largest such component relative
    /// to the stress.
    fn active_share(rft: &Rft, passive: bool) -> (f64, f64) {
        let (mut along, mut worst, mut n) = (0usize, 0.0f64, 0usize);
        for b in 0..180 {
            let beta = (b as f64).to_radians();
            let (tx, tz) = (beta.cos(), beta.sin());
            for g in 0..360 {
                let gamma = (g as f64 + 0.5).to_radians();
                let (ex, ez) = (gamma.cos(), gamma.sin());
                let (sx, sz) =
                    if passive { rft.passive_stress(tx, tz, ex, ez) } else { rft.stress(tx, tz, ex, ez) };
                let dot = sx * ex + sz * ez;
                if dot > 1e-9 * sx.hypot(sz) {
                    along += 1;
                    worst = worst.max(dot / sx.hypot(sz));
                }
                n += 1;
            }
        }
        (along as f64 / n as f64, worst)
    }

    /// docs/model.md §16's passivity: the generic form itself never pushes along the motion, so
    /// `Motion` (a positive scalar times it) and `Li2013` (one factor) are passive as they stand
    /// at every k_s / k_n; `Components` is not (the audit of issue 38: 4.6% of directions at the
    /// built-in k_s/k_n = 4.66, more at k_s/k_n = 0.01), and its passive projection is.
    #[test]
    fn every_scaling_is_passive_and_components_only_after_projection() {
        for ratio in [0.01, 0.1, 1.0, 4.66, 100.0] {
            let k_n = 7e5;
            for scaling in [RftScaling::Motion, RftScaling::Li2013] {
                let (share, _) = active_share(&Rft::with_scaling(k_n, ratio * k_n, scaling), false);
                assert_eq!(share, 0.0, "{scaling:?} at k_s/k_n = {ratio}");
            }
            let comp = Rft::with_scaling(k_n, ratio * k_n, RftScaling::Components);
            assert_eq!(active_share(&comp, true).0, 0.0, "projected components at {ratio}");
        }
        let (share, worst) = active_share(&Rft::with_scaling(7e5, 3.26e6, RftScaling::Components), false);
        assert!(share > 0.01 && worst > 0.01, "components raw: {share} {worst}");
        let (low, _) = active_share(&Rft::with_scaling(7e5, 7e3, RftScaling::Components), false);
        assert!(low > share, "{low} vs {share}");
    }

    /// Li et al. 2013's single factor: k_n straight down, and a vertical plate dragged sideways
    /// feels the generic 0.370 k_n per unit depth, whatever k_s (by hand from the coefficients:
    /// 0.124 + 0.253 - 0.007 = 0.370).
    #[test]
    fn li2013_uses_one_factor_from_k_n() {
        for k_s in [1e4, 3e6] {
            let rft = Rft::with_scaling(7e5, k_s, RftScaling::Li2013);
            let (sx, sz) = rft.stress(1.0, 0.0, 0.0, -1.0);
            assert!(sx.abs() < 1e-6 && (sz - 7e5).abs() < 1e-6);
            let (sx, _) = rft.stress(0.0, 1.0, 1.0, 0.0);
            assert!((sx + 0.370 * 7e5).abs() < 1e-6, "{sx}");
        }
    }
}
