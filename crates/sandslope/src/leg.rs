//! The leg's geometry (docs/model.md §3-§4, §15): how deep a leg reaches below the surface as
//! it turns, named once. The closed form reads the anchoring time, the deepest reach and the
//! touchdown angle from a [`Leg`]; the robot's C-leg is [`CLeg`].
//!
//! A leg turns about its hip (the axle, `h` above the undisturbed surface) at the robot's leg
//! speed omega. Its crank angle `psi` is measured as docs/model.md §4 measures the C-leg's
//! `omega t + phi0`: the leg touches the surface at [`Leg::touchdown_angle`] and reaches its
//! deepest point at [`Leg::deepest_angle`], its depth rising monotonically in between (the
//! stance's descent, over which the leg anchors). A new leg shape is one more type
//! implementing [`Leg`]; the closed-form functions of this module then hold for it unchanged.

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
}

/// Depth of `leg` below the surface `t` seconds after touchdown, turning at `omega` rad/s:
/// `d(omega t + psi0)`, m (docs/model.md §4's `d(t)` for the C-leg).
pub fn depth_after(leg: &impl Leg, omega: f64, t: f64) -> f64 {
    leg.depth_at(omega * t + leg.touchdown_angle())
}

/// Time from touchdown until `leg`, turning at `omega` rad/s, reaches depth `d_s`:
/// `(psi(d_s) - psi0) / omega`, s (docs/model.md §4's anchoring time t1 for the C-leg); `None`
/// when it never does.
pub fn time_to_depth(leg: &impl Leg, omega: f64, d_s: f64) -> Option<f64> {
    leg.angle_at_depth(d_s).map(|psi| (psi - leg.touchdown_angle()) / omega)
}

/// Time from touchdown to the deepest reach, `(psi_max - psi0) / omega`, s.
pub fn time_to_deepest(leg: &impl Leg, omega: f64) -> f64 {
    (leg.deepest_angle() - leg.touchdown_angle()) / omega
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_6, PI};

    fn close(a: f64, b: f64, tol: f64) {
        assert!((a - b).abs() <= tol, "{a} vs {b}");
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

    /// A toy leg shape, added here alone: a straight spoke of length L turning about a hip at
    /// height h, its tip `L sin(psi) - h` below the surface. The closed form's times hold for
    /// it unchanged; each value below is worked by hand for L = 2h.
    struct Spoke {
        length: f64,
        hip_height: f64,
    }

    impl Leg for Spoke {
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
    }

    #[test]
    fn a_toy_leg_shape_needs_only_its_geometry() {
        let spoke = Spoke { length: 0.06, hip_height: 0.03 };
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
}
