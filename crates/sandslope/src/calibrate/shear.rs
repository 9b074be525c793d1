//! Where the calibrated shear strength k_s(theta) comes from: force tests scaled to the leg, or
//! a smooth law of two parameters (docs/model.md §14).

use crate::terrain::Terrain;
use crate::Slope;

/// A smooth law of k_s(theta) with two parameters, fitted when there are no force tests.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShearLaw {
    /// `k_s0 (1 + (rho - 1) theta / 20 deg)`: linear in degrees, the same form as the terrain
    /// table's interpolation, with `rho = k_s(20 deg) / k_s(0)` itself a parameter.
    Linear,
    /// `k_s0 (cos theta - sin theta / tan phi)`: the Mohr-Coulomb strength left on an infinite
    /// slope with friction angle phi (zero at phi).
    Coulomb,
}

impl ShearLaw {
    /// k_s at `slope` for the law's parameters `[k_s0, rho]` (linear) or `[k_s0, phi_deg]`
    /// (Coulomb), floored at 0, N/m^3.
    pub fn k_s(self, params: [f64; 2], slope: Slope) -> f64 {
        match self {
            ShearLaw::Coulomb => {
                let t = slope.radians();
                (params[0] * (t.cos() - t.sin() / params[1].to_radians().tan())).max(0.0)
            }
            ShearLaw::Linear => (params[0] * (1.0 + (params[1] - 1.0) * slope.degrees() / 20.0)).max(0.0),
        }
    }
}

/// Where k_s(theta) comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum ShearShape {
    /// Force tests: the plate k_s at each measured slope is a fitted value held to the
    /// measurement by its SD (`k_s_sd`; without SDs the measured values are used exactly), and
    /// the leg's k_s is `plate_scale` times it, interpolated as a terrain table (docs/model.md §7).
    ForceTests(Terrain),
    /// A smooth law of two parameters.
    Law(ShearLaw),
}
