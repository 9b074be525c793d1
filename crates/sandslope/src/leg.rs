//! The leg's geometry (docs/model.md §3-§4, §15): how deep a leg reaches below the surface as
//! it turns, named once. The closed form reads the anchoring time, the deepest reach and the
//! touchdown angle from a [`Leg`]; the robot's leg is [`RobotLeg`], of the robot file's
//! [`LegShape`] (the paper's [`CLeg`] unless `leg_shape` says otherwise).
//!
//! A leg turns about its hip (the axle, `h` above the undisturbed surface) at the robot's leg
//! speed omega. Its crank angle `psi` is measured as docs/model.md §4 measures the C-leg's
//! `omega t + phi0`: the leg touches the surface at [`Leg::touchdown_angle`] and reaches its
//! deepest point at [`Leg::deepest_angle`], its depth rising monotonically in between (the
//! stance's descent, over which the leg anchors). A new leg shape is one more type
//! implementing [`Leg`]; the closed-form functions of this module then hold for it unchanged.

/// The shape of a robot's legs, the robot file's key `leg_shape` (docs/model.md §2, §15): the
/// paper's C-leg (the default), or the straight spoke and the flat foot the simulator's oracle
/// tests use. The simulator walks any shape; the closed form (docs/model.md §3-§6) is derived
/// for the C-leg only ([`LegShape::closed_form`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LegShape {
    /// A semicircular arc of radius R from the axle to a tip 2R away (the paper's C-leg).
    #[default]
    CLeg,
    /// A straight plate from the axle to 2R along the C's diameter (a spoke).
    Spoke,
    /// A flat foot of area A_c (length A_c / W), R below the axle and centred under it at
    /// angle 0 (the closed form's contact, docs/model.md §3).
    Foot,
}

impl LegShape {
    /// Every shape, in the order the robot file's docs list them.
    pub const ALL: [LegShape; 3] = [LegShape::CLeg, LegShape::Spoke, LegShape::Foot];

    /// The name in robot files and JSON (`c_leg`, `spoke`, `foot`), also [`Leg::name`].
    pub fn name(self) -> &'static str {
        match self {
            LegShape::CLeg => "c_leg",
            LegShape::Spoke => "spoke",
            LegShape::Foot => "foot",
        }
    }

    /// Whether this is the default shape (a robot file that leaves `leg_shape` out).
    pub fn is_c_leg(&self) -> bool {
        *self == LegShape::CLeg
    }

    /// Whether the closed form (docs/model.md §3-§6) holds for this shape: only the C-leg's.
    /// Its geometry is any [`Leg`]'s (the depth, the touchdown and deepest angles, the
    /// anchoring time below), but its composition is Li et al.'s rotary walking of a C-leg:
    /// s* is the step of a leg sliding on the C's circle, whose centre is fixed in solidified
    /// sand; the shear load's `R omega / dt` is the body reaching the C's rolling speed
    /// `R omega`; the shear resistance `k_s W d^2` is an arc cutting the sand edge-on (which a
    /// flat foot does not). Refused for another shape, naming the robot file's key: an error
    /// `leg_shape = "spoke" ...` rather than a number derived for another leg.
    pub fn closed_form(self) -> Result<(), NotClosedForm> {
        if self.is_c_leg() {
            Ok(())
        } else {
            Err(NotClosedForm(self))
        }
    }
}

/// A robot whose legs the closed form does not hold for ([`LegShape::closed_form`]): the
/// message names the robot file's key, the value and the shapes supported.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NotClosedForm(pub LegShape);

impl std::fmt::Display for NotClosedForm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "leg_shape = \"{}\": the closed form (docs/model.md §3-§6) is derived for the C-leg only, \
             so it answers for leg_shape = \"c_leg\" (the default); `simulate` walks every leg_shape \
             (\"c_leg\", \"spoke\", \"foot\")",
            self.0.name()
        )
    }
}

impl std::error::Error for NotClosedForm {}

/// A leg shape's geometry, as the closed form needs it.
pub trait Leg {
    /// Depth of the leg's lowest point below the undisturbed surface at crank angle `psi`,
    /// rad, m (negative: above the surface).
    fn depth_at(&self, psi: f64) -> f64;

    /// Crank angle at touchdown, where the depth is 0, rad.
    fn touchdown_angle(&self) -> f64;

    /// Crank angle of the deepest reach, rad (after [`Leg::touchdown_angle`]).
    fn deepest_angle(&self) -> f64;

    /// Deepest reach below the surface, `depth_at(deepest_angle())`, m.
    fn max_depth(&self) -> f64 {
        self.depth_at(self.deepest_angle())
    }

    /// Crank angle at which the leg, descending, first reaches depth `d` (the inverse of
    /// [`Leg::depth_at`] between touchdown and the deepest angle), rad; `None` when `d` is
    /// deeper than [`Leg::max_depth`] or not a number.
    fn angle_at_depth(&self, d: f64) -> Option<f64>;

    /// The step on level sand when the leg is supported at depth `d` (docs/model.md §3's
    /// s*): the horizontal distance the hip travels while the leg's lowest point is below that
    /// depth, the chord of the circle that point turns on, m; 0 when it never gets there.
    fn level_step(&self, d: f64) -> f64;

    /// The leg's outline as the simulator discretises it (docs/model.md §15): `elements + 1`
    /// nodes in the leg's own frame, x forward and z up from the hip, at crank angle 0; the
    /// simulator turns them clockwise by the crank angle (angle pi/2 takes node `(x, 0)` to
    /// `(0, -x)`), so a node `(x, z)` is `x sin(psi) - z cos(psi) - h` below the surface.
    fn outline(&self, elements: usize) -> Vec<[f64; 2]>;

    /// The shape's name, as `simulate --json` prints it (`c_leg`, `spoke`, `foot`).
    fn name(&self) -> &str;
}

/// The fraction `k / elements` of node `k` along an outline.
fn fractions(elements: usize) -> impl Iterator<Item = f64> {
    (0..=elements).map(move |k| k as f64 / elements as f64)
}

/// The paper's C-leg (docs/model.md §4): a semicircular arc of radius `R` whose lowest point
/// is `d(psi) = R sin(psi) + R - h` below the surface, with the hip `h` above it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CLeg {
    /// Leg radius R, m.
    pub radius: f64,
    /// Hip height h above the undisturbed surface, m.
    pub hip_height: f64,
}

impl Leg for CLeg {
    /// `d(psi) = R sin(psi) + R - h`.
    fn depth_at(&self, psi: f64) -> f64 {
        let r = self.radius;
        r * psi.sin() + r - self.hip_height
    }

    /// `phi0 = asin((h - R) / R)`.
    fn touchdown_angle(&self) -> f64 {
        let r = self.radius;
        ((self.hip_height - r) / r).clamp(-1.0, 1.0).asin()
    }

    /// `pi / 2`: the arc's lowest point straight below the hip.
    fn deepest_angle(&self) -> f64 {
        std::f64::consts::FRAC_PI_2
    }

    /// `d_max = 2R - h`.
    fn max_depth(&self) -> f64 {
        2.0 * self.radius - self.hip_height
    }

    /// `asin((d + h) / R - 1)`.
    fn angle_at_depth(&self, d: f64) -> Option<f64> {
        if d > self.max_depth() || d.is_nan() {
            return None;
        }
        Some(((d + self.hip_height) / self.radius - 1.0).clamp(-1.0, 1.0).asin())
    }

    /// `s* = 2 sqrt(R^2 - (d + h - R)^2)`: the lowest point turns on a circle of radius R whose
    /// centre is `R - h` below the surface, `d + h - R` above depth `d`.
    fn level_step(&self, d: f64) -> f64 {
        let r = self.radius;
        let x = d + self.hip_height - r;
        2.0 * (r * r - x * x).max(0.0).sqrt()
    }

    /// The semicircle from the hip to the tip `2R` ahead, its centre at `(R, 0)`.
    fn outline(&self, elements: usize) -> Vec<[f64; 2]> {
        let r = self.radius;
        fractions(elements)
            .map(|f| {
                let u = std::f64::consts::PI * f;
                [r * (1.0 - u.cos()), -r * u.sin()]
            })
            .collect()
    }

    fn name(&self) -> &str {
        "c_leg"
    }
}

/// A straight plate from the hip to `2R` along the C-leg's diameter (docs/model.md §15's
/// spoke): its tip, the lowest point, is `2R sin(psi) - h` below the surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spoke {
    /// Leg radius R (the spoke is 2R long), m.
    pub radius: f64,
    /// Hip height h above the undisturbed surface, m.
    pub hip_height: f64,
}

impl Leg for Spoke {
    /// `d(psi) = 2R sin(psi) - h`.
    fn depth_at(&self, psi: f64) -> f64 {
        2.0 * self.radius * psi.sin() - self.hip_height
    }

    /// `asin(h / 2R)`.
    fn touchdown_angle(&self) -> f64 {
        (self.hip_height / (2.0 * self.radius)).clamp(-1.0, 1.0).asin()
    }

    /// `pi / 2`: the spoke straight down.
    fn deepest_angle(&self) -> f64 {
        std::f64::consts::FRAC_PI_2
    }

    /// `asin((d + h) / 2R)`.
    fn angle_at_depth(&self, d: f64) -> Option<f64> {
        if d > self.max_depth() || d.is_nan() {
            return None;
        }
        Some(((d + self.hip_height) / (2.0 * self.radius)).clamp(-1.0, 1.0).asin())
    }

    /// The tip's circle (radius 2R about the hip) cut `d + h` below the hip:
    /// `2 sqrt((2R)^2 - (d + h)^2)`.
    fn level_step(&self, d: f64) -> f64 {
        let (l, x) = (2.0 * self.radius, d + self.hip_height);
        2.0 * (l * l - x * x).max(0.0).sqrt()
    }

    /// Nodes from the hip to `(2R, 0)`.
    fn outline(&self, elements: usize) -> Vec<[f64; 2]> {
        let r = self.radius;
        fractions(elements).map(|f| [2.0 * r * f, 0.0]).collect()
    }

    fn name(&self) -> &str {
        "spoke"
    }
}

/// A flat foot of length `l` (the contact area over the leg width), `R` below the hip and
/// centred under it at crank angle 0 (docs/model.md §3's contact, which the simulator's
/// static oracle holds there). Turned by `psi` its lowest point is an end:
/// `d(psi) = R cos(psi) + (l/2) |sin(psi)| - h`, deepest at `psi = -atan(l / 2R)` with the
/// rear end `rho = sqrt(R^2 + l^2/4)` from the hip straight below it; the descent to it is
/// that end's circle, `rho cos(psi + atan(l / 2R)) - h`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Foot {
    /// Distance R of the foot below the hip, m.
    pub radius: f64,
    /// Foot length l, m.
    pub length: f64,
    /// Hip height h above the undisturbed surface, m.
    pub hip_height: f64,
}

impl Foot {
    /// The ends' distance from the hip, `sqrt(R^2 + l^2/4)`, m, and their angle off the
    /// foot's centre, `atan(l / 2R)`, rad.
    fn end(&self) -> (f64, f64) {
        let half = 0.5 * self.length;
        (self.radius.hypot(half), half.atan2(self.radius))
    }
}

impl Leg for Foot {
    /// `R cos(psi) + (l/2) |sin(psi)| - h`.
    fn depth_at(&self, psi: f64) -> f64 {
        self.radius * psi.cos() + 0.5 * self.length * psi.sin().abs() - self.hip_height
    }

    /// `-atan(l / 2R) - acos(h / rho)`: the rear end reaching the surface.
    fn touchdown_angle(&self) -> f64 {
        let (rho, a) = self.end();
        -a - (self.hip_height / rho).clamp(-1.0, 1.0).acos()
    }

    /// `-atan(l / 2R)`.
    fn deepest_angle(&self) -> f64 {
        -self.end().1
    }

    /// `rho - h`.
    fn max_depth(&self) -> f64 {
        self.end().0 - self.hip_height
    }

    /// `-atan(l / 2R) - acos((d + h) / rho)`.
    fn angle_at_depth(&self, d: f64) -> Option<f64> {
        if d > self.max_depth() || d.is_nan() {
            return None;
        }
        let (rho, a) = self.end();
        Some(-a - ((d + self.hip_height) / rho).clamp(-1.0, 1.0).acos())
    }

    /// The rear end's circle (radius rho about the hip) cut `d + h` below the hip.
    fn level_step(&self, d: f64) -> f64 {
        let (rho, x) = (self.end().0, d + self.hip_height);
        2.0 * (rho * rho - x * x).max(0.0).sqrt()
    }

    /// Nodes from `(-l/2, -R)` to `(l/2, -R)`.
    fn outline(&self, elements: usize) -> Vec<[f64; 2]> {
        let (l, r) = (self.length, self.radius);
        fractions(elements).map(|f| [-0.5 * l + l * f, -r]).collect()
    }

    fn name(&self) -> &str {
        "foot"
    }
}

/// A robot's leg ([`crate::Robot::leg`]): its [`LegShape`] built from the robot's radius R,
/// hip height h and, for the foot, its length (the contact area over the leg width). The one
/// leg the closed form and the simulator both take; a value, so the closed form's hot loops
/// (risk maps, plans) build it without allocating.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RobotLeg {
    /// The paper's C-leg.
    CLeg(CLeg),
    /// A straight spoke.
    Spoke(Spoke),
    /// A flat foot.
    Foot(Foot),
}

impl RobotLeg {
    /// The leg of `shape` with radius R, hip height h and foot length `foot_length` (used by
    /// the foot only), m.
    pub fn new(shape: LegShape, radius: f64, hip_height: f64, foot_length: f64) -> RobotLeg {
        match shape {
            LegShape::CLeg => RobotLeg::CLeg(CLeg { radius, hip_height }),
            LegShape::Spoke => RobotLeg::Spoke(Spoke { radius, hip_height }),
            LegShape::Foot => RobotLeg::Foot(Foot { radius, length: foot_length, hip_height }),
        }
    }

    /// The shape.
    pub fn shape(&self) -> LegShape {
        match self {
            RobotLeg::CLeg(_) => LegShape::CLeg,
            RobotLeg::Spoke(_) => LegShape::Spoke,
            RobotLeg::Foot(_) => LegShape::Foot,
        }
    }

    fn geometry(&self) -> &dyn Leg {
        match self {
            RobotLeg::CLeg(l) => l,
            RobotLeg::Spoke(l) => l,
            RobotLeg::Foot(l) => l,
        }
    }
}

impl Leg for RobotLeg {
    fn depth_at(&self, psi: f64) -> f64 {
        self.geometry().depth_at(psi)
    }
    fn touchdown_angle(&self) -> f64 {
        self.geometry().touchdown_angle()
    }
    fn deepest_angle(&self) -> f64 {
        self.geometry().deepest_angle()
    }
    fn max_depth(&self) -> f64 {
        self.geometry().max_depth()
    }
    fn angle_at_depth(&self, d: f64) -> Option<f64> {
        self.geometry().angle_at_depth(d)
    }
    fn level_step(&self, d: f64) -> f64 {
        self.geometry().level_step(d)
    }
    fn outline(&self, elements: usize) -> Vec<[f64; 2]> {
        self.geometry().outline(elements)
    }
    fn name(&self) -> &str {
        self.shape().name()
    }
}

/// Depth of `leg` below the surface `t` seconds after touchdown, turning at `omega` rad/s:
/// `d(omega t + psi0)`, m (docs/model.md §4's `d(t)` for the C-leg).
pub fn depth_after(leg: &(impl Leg + ?Sized), omega: f64, t: f64) -> f64 {
    leg.depth_at(omega * t + leg.touchdown_angle())
}

/// Time from touchdown until `leg`, turning at `omega` rad/s, reaches depth `d_s`:
/// `(psi(d_s) - psi0) / omega`, s (docs/model.md §4's anchoring time t1 for the C-leg); `None`
/// when it never does.
pub fn time_to_depth(leg: &(impl Leg + ?Sized), omega: f64, d_s: f64) -> Option<f64> {
    leg.angle_at_depth(d_s).map(|psi| (psi - leg.touchdown_angle()) / omega)
}

/// Time from touchdown to the deepest reach, `(psi_max - psi0) / omega`, s.
pub fn time_to_deepest(leg: &(impl Leg + ?Sized), omega: f64) -> f64 {
    (leg.deepest_angle() - leg.touchdown_angle()) / omega
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_6, PI};

    fn close(a: f64, b: f64, tol: f64) {
        assert!((a - b).abs() <= tol, "{a} vs {b}");
    }

    /// The closed form answers for the C-leg only: another shape is refused naming the robot
    /// file's key, the value, the shape it answers for and the three shapes `simulate` walks.
    #[test]
    fn the_closed_form_refuses_another_shape_by_name() {
        assert_eq!(LegShape::default(), LegShape::CLeg);
        assert_eq!(LegShape::CLeg.closed_form(), Ok(()));
        for shape in [LegShape::Spoke, LegShape::Foot] {
            let e = shape.closed_form().unwrap_err().to_string();
            assert!(e.starts_with(&format!("leg_shape = \"{}\": the closed form", shape.name())), "{e}");
            assert!(
                e.contains("leg_shape = \"c_leg\"") && e.contains("(\"c_leg\", \"spoke\", \"foot\")"),
                "{e}"
            );
        }
        // The names are serde's, which the robot file reads.
        for shape in LegShape::ALL {
            assert_eq!(serde_json::to_value(shape).unwrap(), shape.name());
        }
    }

    /// The robot's leg is its shape's: the paper's robot (R = 4 cm, h = 3 cm, A_c = W R) with
    /// spokes reaches 2R - h = 5 cm, touching down at asin(3/8); with feet (length A_c / W =
    /// R = 4 cm) its ends are sqrt(4^2 + 2^2) = sqrt(20) cm from the hip, sqrt(20) - 3 cm deep.
    #[test]
    fn the_robots_leg_is_its_shape() {
        let robot = |shape| {
            crate::Robot::new(crate::RobotSpec { leg_shape: shape, ..crate::RobotSpec::paper_hexapod() })
                .unwrap()
        };
        let c = robot(LegShape::CLeg);
        assert_eq!(c.leg(), RobotLeg::CLeg(CLeg { radius: 0.04, hip_height: 0.03 }));
        assert_eq!((c.leg().name(), c.leg_shape()), ("c_leg", LegShape::CLeg));
        let spoke = robot(LegShape::Spoke).leg();
        assert_eq!(spoke.name(), "spoke");
        close(spoke.max_depth(), 0.05, 1e-15);
        close(spoke.touchdown_angle(), (3.0f64 / 8.0).asin(), 1e-15);
        let foot = robot(LegShape::Foot).leg();
        assert_eq!(foot.shape(), LegShape::Foot);
        close(foot.max_depth(), 0.2f64.sqrt() / 10.0 - 0.03, 1e-15);
    }

    /// The paper's C-leg, R = 4 cm with the hip at h = 3 cm: touchdown at asin(-1/4), the
    /// deepest reach 2R - h = 5 cm straight below the hip, and at psi = 0 the arc's centre
    /// height R - h = 1 cm (worked by hand).
    #[test]
    fn c_leg_by_hand() {
        let leg = CLeg { radius: 0.04, hip_height: 0.03 };
        close(leg.touchdown_angle(), (-0.25f64).asin(), 1e-15);
        close(leg.depth_at(leg.touchdown_angle()), 0.0, 1e-15);
        close(leg.max_depth(), 0.05, 1e-15);
        close(leg.depth_at(FRAC_PI_2), 0.05, 1e-15);
        close(leg.depth_at(0.0), 0.01, 1e-15);
        // Supported at 1 cm: the circle's centre 1 + 3 - 4 = 0 cm from it, a full diameter.
        close(leg.level_step(0.01), 0.08, 1e-15);
        close(leg.level_step(0.05), 0.0, 1e-15);
        // sin(psi) = (0.02 + 0.03) / 0.04 - 1 = 0.25.
        close(leg.angle_at_depth(0.02).unwrap(), 0.25f64.asin(), 1e-15);
        assert_eq!(leg.angle_at_depth(0.051), None);
        assert_eq!(leg.angle_at_depth(f64::NAN), None);
        // At omega = 2 pi rad/s the deepest point comes (pi/2 + asin(1/4)) / (2 pi) s in.
        close(time_to_deepest(&leg, 2.0 * PI), (FRAC_PI_2 + 0.25f64.asin()) / (2.0 * PI), 1e-15);
    }

    /// The deepest node of `leg`'s outline turned by `psi` as the simulator turns it
    /// (`x sin(psi) - z cos(psi) - h` below the surface), m.
    fn outline_depth(leg: &impl Leg, h: f64, psi: f64) -> f64 {
        let nodes = leg.outline(4000);
        nodes.iter().map(|p| p[0] * psi.sin() - p[1] * psi.cos() - h).fold(f64::MIN, f64::max)
    }

    /// The simulator's outlines agree with the closed form's depth at every crank angle (to
    /// the discretisation: nodes pi/4000 rad apart on a 4 cm arc
    /// miss its lowest point by at most R (1 - cos(pi/8000)) = 3.1e-9 m),
    /// over the half turn each closed form describes.
    #[test]
    fn outlines_reach_the_closed_form_depth() {
        let c = CLeg { radius: 0.04, hip_height: 0.03 };
        let spoke = Spoke { radius: 0.04, hip_height: 0.03 };
        let foot = Foot { radius: 0.04, length: 0.04, hip_height: 0.03 };
        for k in 0..=40 {
            let psi = -1.5 + 3.0 * k as f64 / 40.0;
            close(outline_depth(&c, 0.03, psi), c.depth_at(psi), 3.1e-9);
            // The spoke's tip is its lowest point once it points below the hip (psi >= 0).
            if psi >= 0.0 {
                close(outline_depth(&spoke, 0.03, psi), spoke.depth_at(psi), 1e-15);
            }
            close(outline_depth(&foot, 0.03, psi), foot.depth_at(psi), 1e-15);
        }
    }

    /// The spoke (2R = 8 cm, h = 3 cm) and the foot (R = 4 cm, l = 6 cm, h = 3 cm) by hand.
    #[test]
    fn spoke_and_foot_by_hand() {
        let spoke = Spoke { radius: 0.04, hip_height: 0.03 };
        close(spoke.touchdown_angle(), (3.0f64 / 8.0).asin(), 1e-15);
        close(spoke.max_depth(), 0.05, 1e-15);
        close(spoke.angle_at_depth(0.01).unwrap(), 0.5f64.asin(), 1e-15);
        // Supported at 1 cm: the tip's 8 cm circle cut 4 cm below the hip, 2 sqrt(48) cm.
        close(spoke.level_step(0.01), 0.02 * 48f64.sqrt(), 1e-15);
        assert_eq!(spoke.angle_at_depth(0.0501), None);
        // The foot's ends are 5 cm from the hip (3-4-5), atan(3/4) off its centre.
        let foot = Foot { radius: 0.04, length: 0.06, hip_height: 0.03 };
        let a = 0.75f64.atan();
        close(foot.depth_at(0.0), 0.01, 1e-15);
        close(foot.deepest_angle(), -a, 1e-15);
        close(foot.max_depth(), 0.02, 1e-15);
        close(foot.depth_at(-a), 0.02, 1e-15);
        // The rear end touches down where 5 cos(psi + a) = 3: psi = -a - acos(3/5).
        close(foot.touchdown_angle(), -a - 0.6f64.acos(), 1e-15);
        close(foot.depth_at(foot.touchdown_angle()), 0.0, 1e-15);
        close(foot.angle_at_depth(0.01).unwrap(), -a - 0.8f64.acos(), 1e-15);
        // Supported at 1 cm: the 5 cm circle cut 4 cm below the hip, 6 cm.
        close(foot.level_step(0.01), 0.06, 1e-15);
    }

    /// A toy leg shape, added here alone: a straight spoke of length L turning about a hip at
    /// height h, its tip `L sin(psi) - h` below the surface. The closed form's times hold for
    /// it unchanged; each value below is worked by hand for L = 2h.
    struct Stick {
        length: f64,
        hip_height: f64,
    }

    impl Leg for Stick {
        fn depth_at(&self, psi: f64) -> f64 {
            self.length * psi.sin() - self.hip_height
        }
        fn touchdown_angle(&self) -> f64 {
            (self.hip_height / self.length).asin()
        }
        fn deepest_angle(&self) -> f64 {
            FRAC_PI_2
        }
        fn angle_at_depth(&self, d: f64) -> Option<f64> {
            let s = (d + self.hip_height) / self.length;
            (s <= 1.0).then(|| s.asin())
        }
        /// The tip's circle (radius L about the hip) cut at h + d below the hip.
        fn level_step(&self, d: f64) -> f64 {
            let x = d + self.hip_height;
            2.0 * (self.length * self.length - x * x).max(0.0).sqrt()
        }
        fn outline(&self, elements: usize) -> Vec<[f64; 2]> {
            fractions(elements).map(|f| [self.length * f, 0.0]).collect()
        }
        fn name(&self) -> &str {
            "stick"
        }
    }

    #[test]
    fn a_toy_leg_shape_needs_only_its_geometry() {
        let spoke = Stick { length: 0.06, hip_height: 0.03 };
        // Touchdown where sin(psi) = h / L = 1/2: psi0 = pi/6; deepest L - h = 3 cm.
        close(spoke.touchdown_angle(), FRAC_PI_6, 1e-15);
        close(spoke.max_depth(), 0.03, 1e-15);
        // Depth 3 cm is reached at psi = pi/2, so after (pi/2 - pi/6) / omega = (pi/3) / pi s
        // at omega = pi rad/s; depth 0 at once.
        close(time_to_depth(&spoke, PI, 0.03).unwrap(), 1.0 / 3.0, 1e-15);
        close(time_to_depth(&spoke, PI, 0.0).unwrap(), 0.0, 1e-15);
        assert_eq!(time_to_depth(&spoke, PI, 0.031), None);
        close(time_to_deepest(&spoke, PI), 1.0 / 3.0, 1e-15);
        // Half a second in, psi = pi/6 + pi/2 = 2 pi/3: 6 sin(2 pi/3) - 3 cm = 3 sqrt(3) - 3 cm.
        close(depth_after(&spoke, PI, 0.5), 0.03 * 3f64.sqrt() - 0.03, 1e-15);
        // Supported at the surface: 2 sqrt(6^2 - 3^2) cm = 6 sqrt(3) cm; at its deepest, none.
        close(spoke.level_step(0.0), 0.06 * 3f64.sqrt(), 1e-15);
        close(spoke.level_step(0.03), 0.0, 1e-15);
    }

    /// The simulator walks the toy shape from its [`Leg`] alone (docs/model.md §15): a stick
    /// as long as the spoke (2R) walks the spoke's walk sample for sample, and one of 1.5R, whose
    /// tip reaches 1.5R - h = 3 cm below the surface against the spoke's 5 cm on the paper's
    /// robot (R = 4 cm, h = 3 cm), makes progress on the built-in terrain's level sand, but less
    /// than the spoke and than rigid ground allows: the chord its tip cuts at the surface,
    /// 2 sqrt(6^2 - 3^2) = 10.4 cm, is shorter than the spoke's 2 sqrt(8^2 - 3^2) = 14.8 cm.
    #[test]
    fn the_simulator_walks_a_toy_leg_shape() {
        use crate::scenario::Scenario;
        use crate::simulate::{simulate, simulate_with_leg, SimSettings};
        use crate::slope::SignedSlope;
        let spec = crate::RobotSpec { leg_shape: LegShape::Spoke, ..crate::RobotSpec::paper_hexapod() };
        let robot = crate::Robot::new(spec).unwrap();
        let (r, h) = (robot.leg_radius(), robot.hip_height());
        let terrain = crate::terrain::Terrain::constant(7e5, 3_260_672.8).unwrap();
        let scenario = Scenario::new(robot, terrain, None, None).unwrap();
        let settings = SimSettings::new(2.0).unwrap();
        let level = SignedSlope::from_degrees(0.0).unwrap();
        let spoke = simulate(&scenario, level, &settings).unwrap();
        let long = Stick { length: 2.0 * r, hip_height: h };
        let same = simulate_with_leg(&scenario, level, &settings, &long).unwrap();
        assert_eq!((spoke.summary.shape.as_str(), same.summary.shape.as_str()), ("spoke", "stick"));
        assert_eq!(same.trajectory, spoke.trajectory);
        assert_eq!(same.geometry, spoke.geometry);
        let short = Stick { length: 1.5 * r, hip_height: h };
        close(short.level_step(0.0), 0.06 * 3f64.sqrt(), 1e-15);
        let walk = simulate_with_leg(&scenario, level, &settings, &short).unwrap().summary;
        assert!(walk.max_depth_m <= short.max_depth() + 1e-3, "{} m deep", walk.max_depth_m);
        // Nor faster than on rigid ground, where the hip (held at h by the belly) moves the
        // chord, 10.4 cm, per half stride (T = 2 pi / omega = 1 s): 20.8 cm/s.
        let half = 0.5 * 2.0 * PI / scenario.robot().leg_speed();
        assert!(walk.speed_m_s < 1.02 * short.level_step(0.0) / half, "{} m/s", walk.speed_m_s);
        assert!(
            walk.speed_m_s > 0.0 && walk.speed_m_s < spoke.summary.speed_m_s,
            "stick {} m/s, spoke {} m/s",
            walk.speed_m_s,
            spoke.summary.speed_m_s
        );
    }
}
