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

/// Coefficients of the generic form (Li, Zhang and Goldman 2013, Fig. 2 and supplement):
/// `A00, A10, B01, B11, B-11` of alpha_z and `C01, C11, C-11, D10` of alpha_x.
const A00: f64 = 0.206;
const A10: f64 = 0.169;
const B01: f64 = 0.358;
const B11: f64 = 0.212;
const BM11: f64 = 0.055;
const C01: f64 = 0.253;
const C11: f64 = -0.124;
const CM11: f64 = 0.007;
const D10: f64 = 0.088;

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

/// Resistive force theory scaled to one ground (k_n, k_s at one slope).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rft {
    zeta_z: f64,
    zeta_x: f64,
}

impl Rft {
    /// Scales the generic form to `k_n` (N/m^3) and `k_s` (N/m^3), docs/model.md §16.
    pub fn new(k_n: f64, k_s: f64) -> Rft {
        // Horizontal plate (beta = 0) pushed straight down (gamma = pi/2).
        let (az_down, _) = generic(1.0, 0.0, 0.0, 1.0);
        // Vertical plate (beta = pi/2, so 2 beta = pi) pushed sideways (gamma = 0).
        let (_, ax_side) = generic(-1.0, 0.0, 1.0, 0.0);
        Rft { zeta_z: k_n / az_down, zeta_x: 2.0 * k_s / ax_side }
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
        // The scale follows the direction of motion: normal motion k_n, along-slope motion k_s.
        let zeta = self.zeta_z * ez * ez + self.zeta_x * ex * ex;
        (-s * zeta * ax, zeta * az)
    }
}

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
}
