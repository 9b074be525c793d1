//! The planar robot (docs/model.md §15): body, legs and their resistive-force elements, and the
//! sand forces on them (docs/model.md §16).
//!
//! Slope frame: x along the slope (upslope positive), z normal to the undisturbed surface
//! (z = 0, sand below), pitch phi positive nose-up. The body's centre of mass lies on the
//! axle line, halfway along; the belly is a flat plate `h` below the axle line.

use super::rft::Rft;
use crate::robot::Robot;

/// The shape of every leg (docs/model.md §15): the robot's C-leg, or the plates the oracle
/// tests use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LegShape {
    /// A semicircular arc of radius R from the axle to a tip 2R away (the paper's C-leg).
    CLeg,
    /// A straight plate from the axle to 2R along the C's diameter (a spoke).
    Spoke,
    /// A flat foot of area A_c (length A_c / W), R below the axle and centred under it at
    /// angle 0 (the closed form's contact, docs/model.md §3).
    Foot,
}

/// Whether the body may pitch (docs/model.md §15). The closed form has no body pitch; locking
/// it in the simulator removes that one difference, so a comparison of the two settings tells
/// what the pitch does to a walk (docs/simulate.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BodyPitch {
    /// The body pitches under the moments of the sand and gravity (the default).
    #[default]
    Free,
    /// The body keeps its pitch at zero (parallel to the slope), as the closed form assumes:
    /// the moments are carried by a constraint and the body moves along and normal to the slope
    /// only.
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

/// Node positions of one leg in its own frame (angle 0: the C's circle centre at (R, 0)).
pub(crate) fn leg_nodes(robot: &Robot, shape: LegShape, elements: usize) -> Vec<[f64; 2]> {
    let r = robot.leg_radius();
    (0..=elements)
        .map(|k| {
            let f = k as f64 / elements as f64;
            match shape {
                LegShape::CLeg => {
                    let u = std::f64::consts::PI * f;
                    [r * (1.0 - u.cos()), -r * u.sin()]
                }
                LegShape::Spoke => [2.0 * r * f, 0.0],
                LegShape::Foot => {
                    let l = robot.contact_area() / robot.leg_width();
                    [-0.5 * l + l * f, -r]
                }
            }
        })
        .collect()
}

/// Resistive-force memory of one element (docs/model.md §16: the elastic slip vector).
pub(crate) type Memory = [f64; 2];

/// The generalized force, damping and stiffness a contact adds to the body's equations.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Assembly {
    /// Generalized force (F_x, F_z, torque about the centre of mass).
    pub q: [f64; 3],
    /// `d(-Q)/d(qdot)` times dt-weighted factors (implicit damping), 3x3.
    pub c: [[f64; 3]; 3],
    /// `d(-Q)/dq` (stiffness), 3x3.
    pub k: [[f64; 3]; 3],
}

/// One element's contribution, kept for the memory update after the step.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Touch {
    /// Where its memory lives (leg index or the belly, element index).
    pub slot: usize,
    /// Point of application relative to the centre of mass, m.
    pub rel: [f64; 2],
    /// Its velocity before the step, m/s.
    pub vel: [f64; 2],
}

/// A straight element between world points `a` and `b` with velocities `va`, `vb`, width `w`.
pub(crate) struct Element {
    pub a: [f64; 2],
    pub b: [f64; 2],
    pub va: [f64; 2],
    pub vb: [f64; 2],
    pub w: f64,
}

/// What one element feels: force, its point, the velocity there and the implicit Jacobians.
pub(crate) struct ElementForce {
    pub force: [f64; 2],
    pub point: [f64; 2],
    pub vel: [f64; 2],
    /// Isotropic damping coefficient for the implicit step, N s/m.
    pub damping: f64,
    /// `dF/d(depth)` (vector), N/m: force gained per metre the element moves down.
    pub depth_gain: [f64; 2],
    /// Deepest point, m.
    pub depth: f64,
}

/// Sand force on an element (docs/model.md §16), updating nothing: `memory` is the element's
/// elastic slip, `yield_m` the slip at which the stress reaches its resistive-force value,
/// `dt` the step. `None` when the element is out of the sand.
#[inline(always)]
pub(crate) fn element_force(
    rft: &Rft,
    el: &Element,
    memory: Memory,
    yield_m: f64,
    dt: f64,
) -> Option<ElementForce> {
    let (za, zb) = (el.a[1], el.b[1]);
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
    let d = [el.b[0] - el.a[0], el.b[1] - el.a[1]];
    let len = (d[0] * d[0] + d[1] * d[1]).sqrt();
    if len <= 0.0 {
        return None;
    }
    let da = -(za + ta * d[1]).min(0.0);
    let db = -(za + tb * d[1]).min(0.0);
    let sub = (tb - ta) * len;
    let depth_integral = 0.5 * sub * (da + db);
    if depth_integral <= 0.0 {
        return None;
    }
    // Depth-weighted centroid of the submerged part.
    let tc = ta + (tb - ta) * (da + 2.0 * db) / (3.0 * (da + db));
    let point = [el.a[0] + tc * d[0], el.a[1] + tc * d[1]];
    let vel = [el.va[0] + tc * (el.vb[0] - el.va[0]), el.va[1] + tc * (el.vb[1] - el.va[1])];
    let trial = [memory[0] + dt * vel[0], memory[1] + dt * vel[1]];
    let m = (trial[0] * trial[0] + trial[1] * trial[1]).sqrt();
    if m <= 0.0 {
        return None;
    }
    let (ex, ez) = (trial[0] / m, trial[1] / m);
    let (sx, sz) = rft.stress(d[0] / len, d[1] / len, ex, ez);
    let full = el.w * depth_integral;
    let sat = (m / yield_m).min(1.0);
    let force = [sx * full * sat, sz * full * sat];
    let magnitude = (sx * sx + sz * sz).sqrt() * full;
    let gain = sub / depth_integral;
    Some(ElementForce {
        force,
        point,
        vel,
        damping: dt * magnitude / yield_m.max(m),
        depth_gain: [force[0] * gain, force[1] * gain],
        depth: da.max(db),
    })
}

/// Adds an element force acting at `rel` (from the centre of mass) to the body's assembly.
///
/// With the velocity Jacobian rows `jx = (1, 0, -rel_z)`, `jz = (0, 1, rel_x)` the damping adds
/// `c (jx jx^T + jz jz^T)` and the depth gain `(J^T dF/d(depth)) jz^T`; the entries are written
/// out with the Jacobians' zeros and ones already applied (the products with exact 0 and 1 the
/// general 3 x 3 loop formed change nothing, so the sums are the same numbers; perf: the loop
/// was a fifth of the step).
#[inline]
pub(crate) fn assemble(asm: &mut Assembly, f: &ElementForce, rel: [f64; 2]) {
    let (rx, rz) = (rel[0], rel[1]);
    asm.q[0] += f.force[0];
    asm.q[1] += f.force[1];
    asm.q[2] += rx * f.force[1] - rz * f.force[0];
    let c = f.damping;
    // c (jx jx^T + jz jz^T): [[1, 0, -rz], [0, 1, rx], [-rz, rx, rz^2 + rx^2]] times c.
    let (c02, c12, c22) = (c * -rz, c * rx, c * (rz * rz + rx * rx));
    asm.c[0][0] += c;
    asm.c[0][2] += c02;
    asm.c[1][1] += c;
    asm.c[1][2] += c12;
    asm.c[2][0] += c02;
    asm.c[2][1] += c12;
    asm.c[2][2] += c22;
    // Generalized depth gain g = J^T dF/d(depth) = (g_x, g_z, -rz g_x + rx g_z); K += g jz^T,
    // whose first column is zero.
    let g = [f.depth_gain[0], f.depth_gain[1], -rz * f.depth_gain[0] + rx * f.depth_gain[1]];
    for (row, gi) in asm.k.iter_mut().zip(g) {
        row[1] += gi;
        row[2] += gi * rx;
    }
}
