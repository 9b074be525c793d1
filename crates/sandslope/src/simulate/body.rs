//! The planar robot (docs/model.md §15): body, legs and their resistive-force elements, and the
//! sand forces on them (docs/model.md §16).
//!
//! Slope frame: x along the slope (upslope positive), z normal to the undisturbed surface
//! (z = 0, sand below), pitch phi positive nose-up. The body's centre of mass lies on the
//! axle line, halfway along; the belly is a flat plate `h` below the axle line.

use super::rft::Rft;

/// Whether the body may pitch (docs/model.md §15). The closed form has no body pitch; locking
/// it in the simulator removes that one difference, so a comparison of the two settings tells
/// what the pitch does to a walk (docs/simulate.md). Locked is the default: its answers
/// converge on the built-in robot and terrain, the free body's on slopes do not (it rears and
/// tumbles from 15 degrees, and whether it does changes with the time step; docs/simulate.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BodyPitch {
    /// The body pitches under the moments of the sand and gravity (chaotic on slopes: a walk
    /// is one draw from a spread whose statistics converge, docs/simulate.md).
    Free,
    /// The body keeps its pitch at zero (parallel to the slope), as the closed form assumes:
    /// the moments are carried by a constraint and the body moves along and normal to the slope
    /// only (the default).
    #[default]
    Locked,
}

impl BodyPitch {
    /// The setting's name, as `--body-pitch` and `--json` spell it.
    pub fn name(self) -> &'static str {
        match self {
            BodyPitch::Free => "free",
            BodyPitch::Locked => "locked",
        }
    }
}

/// What one element feels from the sand this step (docs/model.md §16-§17): its submerged
/// part's geometry at the start of the step, which the implicit velocity step holds fixed.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Contact {
    /// Width times the depth integral over the submerged part, m^3: the force is this times
    /// the stress per unit depth (N/m^3).
    pub weight: f64,
    /// Unit tangent of the element `(tx, tz)` (a to b).
    pub tangent: [f64; 2],
    /// Point of application (depth-weighted centroid) relative to the centre of mass, m.
    pub rel: [f64; 2],
    /// The same point relative to the leg's hip, m (zero for the belly).
    pub arm: [f64; 2],
    /// The leg it belongs to; [`BELLY`] for the belly.
    pub leg: usize,
    /// Deepest point, m.
    pub depth: f64,
}

/// [`Contact::leg`] of a belly element.
pub(crate) const BELLY: usize = usize::MAX;

/// The submerged part of the straight element from world point `a` to `b` of width `w`,
/// clipped at the surface `z = 0` exactly: `(weight, point, tangent, depth)` with `weight`
/// the width times the depth integral (m^3), `point` the depth-weighted centroid. `None` when
/// the element is out of the sand.
#[inline(always)]
pub(crate) fn submerged(a: [f64; 2], b: [f64; 2], w: f64) -> Option<(f64, [f64; 2], [f64; 2], f64)> {
    let (za, zb) = (a[1], b[1]);
    if za >= 0.0 && zb >= 0.0 {
        return None;
    }
    // Submerged part, as parameters [ta, tb] along a -> b.
    let (ta, tb) = if za < 0.0 && zb < 0.0 {
        (0.0, 1.0)
    } else {
        let t0 = za / (za - zb);
        if za < 0.0 {
            (0.0, t0)
        } else {
            (t0, 1.0)
        }
    };
    let d = [b[0] - a[0], b[1] - a[1]];
    let len = (d[0] * d[0] + d[1] * d[1]).sqrt();
    if len <= 0.0 {
        return None;
    }
    let da = -(za + ta * d[1]).min(0.0);
    let db = -(za + tb * d[1]).min(0.0);
    let depth_integral = 0.5 * (tb - ta) * len * (da + db);
    if depth_integral <= 0.0 {
        return None;
    }
    // Depth-weighted centroid of the submerged part.
    let tc = ta + (tb - ta) * (da + 2.0 * db) / (3.0 * (da + db));
    let point = [a[0] + tc * d[0], a[1] + tc * d[1]];
    Some((w * depth_integral, point, [d[0] / len, d[1] / len], da.max(db)))
}

/// The associated stand-in for [`element_force`] (the start of its solve where Newton's method
/// on the law itself fails, docs/model.md §17): the force on one element moving at `u` (m/s) as
/// the gradient of its dissipation
/// potential (docs/model.md §16-§17): `F = -weight * grad sigma(u)` with
/// `sigma(u) = (sqrt(|u|^2 + eps^2) - eps) d(u / |u|)` and `d(e) = -S(e).e >= 0` the
/// resistive-force stress's own dissipation per unit speed in direction `e` (`S` the passive
/// stress per unit depth). Far above the creep speed `eps` the force opposes the motion with
/// exactly resistive force theory's component along it, `d`, and has `-d'` across it (the
/// associated flow rule); at rest it is smoothed over `eps`. Returns the force, the potential
/// `weight * sigma` and its Hessian `weight * Hess sigma` with negative curvature clamped to
/// zero (for the minimisation's Newton steps).
#[inline(always)]
pub(crate) fn associated_force(
    rft: &Rft,
    c: &Contact,
    u: [f64; 2],
    eps: f64,
) -> ([f64; 2], f64, [[f64; 2]; 2]) {
    let (tx, tz) = (c.tangent[0], c.tangent[1]);
    let s = (u[0] * u[0] + u[1] * u[1]).sqrt();
    // The direction (any at rest: the Hessian at u = 0 is then isotropic, d / eps).
    let e = if s > 1e-300 { [u[0] / s, u[1] / s] } else { [1.0, 0.0] };
    let n = [-e[1], e[0]];
    let dissipation = |ex: f64, ez: f64| {
        let (sx, sz) = rft.passive_stress(tx, tz, ex, ez);
        -(sx * ex + sz * ez)
    };
    const DELTA: f64 = 1e-4;
    let (sd, cd) = (DELTA.sin(), DELTA.cos());
    let d0 = dissipation(e[0], e[1]);
    let dp = dissipation(e[0] * cd - e[1] * sd, e[0] * sd + e[1] * cd);
    let dm = dissipation(e[0] * cd + e[1] * sd, -e[0] * sd + e[1] * cd);
    let d1 = (dp - dm) / (2.0 * DELTA);
    let d2 = (dp - 2.0 * d0 + dm) / (DELTA * DELTA);
    let rho = (s * s + eps * eps).sqrt();
    let g = rho - eps;
    let g1 = s / rho;
    let g2 = eps * eps / (rho * rho * rho);
    // g / s and g / s^2 without 0 / 0 at rest: g = s^2 / (rho + eps).
    let g_s = s / (rho + eps);
    let g_ss = 1.0 / (rho + eps);
    let w = c.weight;
    let force = [-w * (g1 * d0 * e[0] + g_s * d1 * n[0]), -w * (g1 * d0 * e[1] + g_s * d1 * n[1])];
    // Hessian in the (e, n) frame: [[g'' d, g' d'/s - g d'/s^2], [., g' d/s + g d''/s^2]].
    let ee = g2 * d0;
    let g1_s = 1.0 / rho; // g' / s
    let nn = g1_s * d0 + g_ss * d2;
    let en = (g1_s - g_ss) * d1;
    // Clamp to positive semidefinite (eigenvalues of the symmetric 2 x 2 below zero to zero).
    let (mean, diff) = (0.5 * (ee + nn), 0.5 * (ee - nn));
    let rad = (diff * diff + en * en).sqrt();
    let (l1, l2) = (mean + rad, (mean - rad).max(0.0));
    let (ee, nn, en) = if mean - rad >= 0.0 {
        (ee, nn, en)
    } else if rad > 0.0 {
        // Keep only the positive eigenvalue's projector: l1 v v^T.
        let (vx, vy) = if diff >= 0.0 { (diff + rad, en) } else { (en, rad - diff) };
        let norm = vx * vx + vy * vy;
        if norm > 0.0 {
            (l1 * vx * vx / norm + l2, l1 * vy * vy / norm + l2, l1 * vx * vy / norm)
        } else {
            (l1.max(0.0), l1.max(0.0), 0.0)
        }
    } else {
        (0.0, 0.0, 0.0)
    };
    // Back to x-z: H = ee e e^T + nn n n^T + en (e n^T + n e^T), times the weight.
    let mut hess = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            hess[i][j] = w * (ee * e[i] * e[j] + nn * n[i] * n[j] + en * (e[i] * n[j] + n[i] * e[j]));
        }
    }
    (force, w * g * d0, hess)
}

/// The sand's force on one element moving at `u` (m/s), and its Jacobian `dF/du`
/// (docs/model.md §16-§17): `F = weight * phi(|u| / eps) * S(u / |u|)`, where `S` is the
/// passive resistive-force stress per unit depth in the direction of motion and
/// `phi(r) = r / sqrt(1 + r^2)` smooths the set-valued law at rest over the creep speed `eps`.
/// At `u = 0` the force is zero and the Jacobian isotropic. Without `want_jacobian` the
/// Jacobian is left zero (a line search's trial points need only the force).
#[inline(always)]
pub(crate) fn element_force(
    rft: &Rft,
    c: &Contact,
    u: [f64; 2],
    eps: f64,
    want_jacobian: bool,
) -> ([f64; 2], [[f64; 2]; 2]) {
    let s = (u[0] * u[0] + u[1] * u[1]).sqrt();
    let (tx, tz) = (c.tangent[0], c.tangent[1]);
    if s <= 1e-300 {
        let k = c.weight * rft.scale_n() / eps;
        return ([0.0; 2], [[-k, 0.0], [0.0, -k]]);
    }
    let e = [u[0] / s, u[1] / s];
    if !want_jacobian {
        let st = rft.passive_stress(tx, tz, e[0], e[1]);
        let r = s / eps;
        let phi = r / (1.0 + r * r).sqrt();
        return ([c.weight * phi * st.0, c.weight * phi * st.1], [[0.0; 2]; 2]);
    }
    // S and dS/d(angle of e) (de/d(angle) = n = (-e_z, e_x)), the latter in closed form.
    let (st, turn) = rft.passive_stress_and_turn(tx, tz, e[0], e[1]);
    let r = s / eps;
    let root = (1.0 + r * r).sqrt();
    let phi = r / root;
    let force = [c.weight * phi * st.0, c.weight * phi * st.1];
    let ds = [turn.0, turn.1];
    let n = [-e[1], e[0]];
    // d phi / du = phi'(r) / eps e with phi'(r) = 1 / root^3; d e / du = n n^T / s.
    let radial = c.weight / (eps * root * root * root);
    let tangential = c.weight * phi / s;
    let stress = [st.0, st.1];
    let mut jac = [[0.0; 2]; 2];
    for (row, (si, dsi)) in jac.iter_mut().zip(stress.iter().zip(ds)) {
        row[0] = radial * si * e[0] + tangential * dsi * n[0];
        row[1] = radial * si * e[1] + tangential * dsi * n[1];
    }
    (force, jac)
}
