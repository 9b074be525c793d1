//! Terrain measurements with a load cell (docs/model.md §10): k_n from penetration curves,
//! k_s from shear curves, and the per-slope table that is a terrain file.
//!
//! Everything here works on plain arrays (no file formats), one concept per module:
//!
//! - [`clean`](mod@clean): a [`RawRecording`] holds one trial's columns as read (a blank cell is `None`);
//!   [`clean()`] drops what cannot be used (blank, non-finite, repeated and saturated samples,
//!   the return stroke of a recording that goes down and back up) and says what it dropped
//!   ([`Dropped`]), giving a [`Curve`] sorted by position;
//! - [`air`]: the in-air offset subtracted from a recording ([`AirCorrection`]), chosen by a
//!   significance test of the in-air run's trend unless the user forces it ([`AirMode`]);
//! - [`line`](mod@line): line fits (ordinary least squares, Huber), medians and the noise level of a
//!   curve estimated from its own samples;
//! - [`penetration`]: the linear window of force against depth and `k_n = b / A`;
//! - [`shear`]: the quasi-static plateau of a shear curve and `k_s = F_plateau / (W_p d_p^2)`;
//! - [`slopes`]: trials averaged per slope with combined standard deviations, kinds not measured
//!   at a slope interpolated, outlier trials flagged;
//! - [`campaign`]: the whole analysis as one call, [`fit_campaign`]: trials in (in-air runs
//!   paired with the trials they calibrate), per-trial fits, warnings and per-slope results out.
//!
//! The automatic methods and their tolerances are documented in `docs/measurements.md`.

use std::fmt;

use crate::error::ParamError;

pub mod air;
pub mod campaign;
pub mod clean;
pub mod line;
pub mod penetration;
pub mod shear;
pub mod slopes;

pub use air::{AirCorrection, AirMode, AirTrend};
pub use campaign::{
    fit_campaign, Campaign, CampaignError, FitOptions, Setup, TrialFit, TrialInput, TrialResult, TrialWarning,
};
pub use clean::{clean, Cleaned, Curve, Dropped, RawRecording, SATURATION_RUN};
pub use line::{huber_line, line_fit, noise_sd, LineFit};
pub use penetration::{disk_area, fit_penetration, PenetrationFit};
pub use shear::{fit_shear, ShearFit, ShearPlate};
pub use slopes::{per_slope, Origin, SlopeEstimate, SlopeStat, TrialValue};

/// Which load-cell test a recording comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// A disk pushed normal to the surface: force against depth, gives k_n.
    Penetration,
    /// A plate dragged downslope: force against displacement, gives k_s.
    Shear,
}

impl Kind {
    /// `penetration` or `shear`.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Penetration => "penetration",
            Kind::Shear => "shear",
        }
    }
}

impl fmt::Display for Kind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// How the fitting window of one trial was chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum WindowChoice {
    /// Found automatically.
    Automatic,
    /// Set by the user.
    User,
}

/// Why a recording could not be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeasureError {
    /// A parameter (area, plate size, window) is out of range.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// Too few usable samples for the step named.
    #[error("{what}: {got} usable samples, at least {needed} needed")]
    TooFewSamples {
        /// What needed them.
        what: &'static str,
        /// How many there were.
        got: usize,
        /// How many are needed.
        needed: usize,
    },
    /// The columns of a recording have different lengths (a caller bug, not user input).
    #[error("columns have different lengths ({0} and {1})")]
    LengthMismatch(usize, usize),
    /// No stretch of at least `MIN_WINDOW_SAMPLES` samples is straight within the curve's noise
    /// with a slope clearly above zero.
    #[error(
        "no linear window: no stretch of the curve is straight within its noise (SD {noise_sd_n:.3} N) with force \
         rising clearly with depth (steepest stretch {steepest_n_per_m:.1} N/m); set the depth window by hand"
    )]
    NoLinearWindow {
        /// Noise SD estimated from the curve, N.
        noise_sd_n: f64,
        /// Slope of the steepest candidate stretch, N/m.
        steepest_n_per_m: f64,
    },
    /// The shear force never rises above zero after the offset is removed.
    #[error("shear force has no positive plateau (median force over the second half {0:.4} N)")]
    NoPlateau(f64),
    /// No trials of a kind at all.
    #[error("no {0} trials: at least one is needed to make a terrain")]
    NoTrials(Kind),
}

/// Deterministic standard normal noise for the tests (SplitMix64 + Box-Muller).
#[cfg(test)]
pub(crate) struct TestNoise(pub u64);

#[cfg(test)]
impl TestNoise {
    pub(crate) fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    pub(crate) fn normal(&mut self) -> f64 {
        let u = self.uniform().max(1e-300);
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * self.uniform()).cos()
    }
}
