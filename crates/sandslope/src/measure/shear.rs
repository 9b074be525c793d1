//! Shear: `k_s = F_plateau / (W_p d_p^2)` from the quasi-static plateau of force against
//! displacement (docs/model.md §10).

use crate::error::{positive, ParamError};

use super::clean::Curve;
use super::line::median;
use super::{MeasureError, WindowChoice};

/// Width of the running median used to smooth shear curves, as a fraction of the
/// displacement range.
pub const SHEAR_SMOOTHING_WINDOW: f64 = 0.05;
/// The shear plateau is where the smoothed force is at least this fraction of the plateau level.
pub const PLATEAU_FRACTION: f64 = 0.90;

/// The shear plate: width `W_p` and insertion depth `d_p`, m.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ShearPlate {
    width_m: f64,
    depth_m: f64,
}

impl ShearPlate {
    /// A plate of width and insertion depth > 0, m.
    pub fn new(width_m: f64, depth_m: f64) -> Result<ShearPlate, ParamError> {
        Ok(ShearPlate {
            width_m: positive("plate_width_m", width_m)?,
            depth_m: positive("plate_depth_m", depth_m)?,
        })
    }

    /// `W_p d_p^2`, m^3: the factor between plateau force and k_s.
    pub fn factor(&self) -> f64 {
        self.width_m * self.depth_m * self.depth_m
    }
}

/// The fit of one shear trial.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ShearFit {
    /// Shear strength k_s, N/m^3.
    pub k_s: f64,
    /// Standard error of k_s from the plateau's scatter, N/m^3: `sd / sqrt(n_eff)` of the
    /// plateau force over `W_p d_p^2`, with `n_eff = n (1 - r1) / (1 + r1)` for the lag-1
    /// autocorrelation `r1` of the plateau force (neighbouring samples of granular force are
    /// correlated, so `sd / sqrt(n)` would claim too much).
    pub k_s_se: f64,
    /// Mean plateau force, N.
    pub plateau_force_n: f64,
    /// Standard deviation of the force over the plateau, N.
    pub plateau_sd_n: f64,
    /// Displacement range of the plateau, m (first and last sample).
    pub plateau_m: (f64, f64),
    /// Samples on the plateau.
    pub plateau_samples: usize,
    /// Effective number of independent samples on the plateau.
    pub effective_samples: f64,
    /// Whether the plateau start was automatic or set by the user.
    pub window: WindowChoice,
}

/// Fits k_s to a shear curve whose in-air offset has been removed. `from` sets the plateau
/// start (m of displacement) instead of finding it.
///
/// Automatic plateau: the curve is smoothed by a running median over
/// `SHEAR_SMOOTHING_WINDOW` of the displacement range; the plateau level starts as the median
/// force over the second half of the displacement range; the plateau runs from the first to
/// the last sample whose smoothed force is at least `PLATEAU_FRACTION` of the level; the
/// level is then re-taken as the median over that plateau and the plateau found again.
pub fn fit_shear(curve: &Curve, plate: ShearPlate, from: Option<f64>) -> Result<ShearFit, MeasureError> {
    const MIN_SAMPLES: usize = 5;
    let x = curve.position();
    let f = curve.force();
    let n = x.len();
    let (lo, hi, choice) = match from {
        Some(start) => {
            if !start.is_finite() {
                return Err(ParamError::new("plateau start", start, "a finite displacement").into());
            }
            (x.partition_point(|&v| v < start), n, WindowChoice::User)
        }
        None => {
            if n < 2 * MIN_SAMPLES {
                return Err(MeasureError::TooFewSamples {
                    what: "shear curve",
                    got: n,
                    needed: 2 * MIN_SAMPLES,
                });
            }
            let half = 0.5 * SHEAR_SMOOTHING_WINDOW * (x[n - 1] - x[0]);
            // O(n * window) by selection (criterion bench `measure`: 44 ms for 10k samples with
            // a 500-sample window; 236 ms with a full sort). Recordings of a few hundred samples
            // take well under a millisecond.
            let smooth: Vec<f64> = (0..n)
                .map(|i| {
                    let a = x.partition_point(|&v| v < x[i] - half);
                    let b = x.partition_point(|&v| v <= x[i] + half);
                    median(&mut f[a..b].to_vec())
                })
                .collect();
            let mid = x.partition_point(|&v| v < 0.5 * (x[0] + x[n - 1]));
            let mut level = median(&mut f[mid..].to_vec());
            let mut range = (0, n);
            for _ in 0..2 {
                if level.is_nan() || level <= 0.0 {
                    return Err(MeasureError::NoPlateau(level));
                }
                let above = |i: &usize| smooth[*i] >= PLATEAU_FRACTION * level;
                let first = (0..n).find(above).unwrap_or(0);
                let last = (0..n).rev().find(above).unwrap_or(n - 1);
                range = (first, last + 1);
                level = median(&mut f[range.0..range.1].to_vec());
            }
            (range.0, range.1, WindowChoice::Automatic)
        }
    };
    let m = hi.saturating_sub(lo);
    if m < MIN_SAMPLES {
        return Err(MeasureError::TooFewSamples { what: "shear plateau", got: m, needed: MIN_SAMPLES });
    }
    let pf = &f[lo..hi];
    let mean = pf.iter().sum::<f64>() / m as f64;
    let ss: f64 = pf.iter().map(|v| (v - mean).powi(2)).sum();
    let sd = (ss / (m as f64 - 1.0)).sqrt();
    if mean.is_nan() || mean <= 0.0 {
        return Err(MeasureError::NoPlateau(mean));
    }
    let r1 =
        if ss > 0.0 { pf.windows(2).map(|w| (w[0] - mean) * (w[1] - mean)).sum::<f64>() / ss } else { 0.0 };
    let r1 = r1.clamp(0.0, 0.99);
    let n_eff = (m as f64 * (1.0 - r1) / (1.0 + r1)).clamp(1.0, m as f64);
    Ok(ShearFit {
        k_s: mean / plate.factor(),
        k_s_se: sd / n_eff.sqrt() / plate.factor(),
        plateau_force_n: mean,
        plateau_sd_n: sd,
        plateau_m: (x[lo], x[hi - 1]),
        plateau_samples: m,
        effective_samples: n_eff,
        window: choice,
    })
}

#[cfg(test)]
mod tests {
    use super::super::TestNoise;
    use super::*;

    fn shear(k_s: f64, sigma: f64, seed: u64) -> Curve {
        // Rise F_p (1 - exp(-x / 4 mm)) over 100 mm, plate 3 cm x 2 cm.
        let mut noise = TestNoise(seed);
        let fp = k_s * 0.03 * 0.02 * 0.02;
        let x: Vec<f64> = (0..=200).map(|i| i as f64 * 0.0005).collect();
        let f = x.iter().map(|&x| fp * (1.0 - (-x / 0.004).exp()) + sigma * noise.normal()).collect();
        Curve::new(x, f).unwrap()
    }

    #[test]
    fn shear_plateau_recovers_k_s() {
        let plate = ShearPlate::new(0.03, 0.02).unwrap();
        for (seed, k_s) in [(5, 2e6), (6, 8e5)] {
            let fit = fit_shear(&shear(k_s, 0.05, seed), plate, None).unwrap();
            // The rise reaches 90% at 2.3 x0 = 9.2 mm; the plateau must start there or later.
            assert!(fit.plateau_m.0 >= 0.0085, "{:?}", fit.plateau_m);
            // Bias from the tail of the rise inside the plateau: x0 * 0.1 / 90 mm = 0.45%;
            // noise 0.05 N / sqrt(180) on >= 9.6 N is < 0.05%; 1% tolerance.
            assert!((fit.k_s / k_s - 1.0).abs() < 0.01, "k_s {} vs {k_s}", fit.k_s);
            // The tail of the rise left in the plateau is a slow trend: it counts as correlation
            // (n_eff well below n), so the SE covers the bias it causes.
            assert!((fit.k_s / k_s - 1.0).abs() < 3.0 * fit.k_s_se / k_s, "{fit:?}");
        }
    }

    #[test]
    fn correlated_noise_lowers_the_effective_samples() {
        // AR(1) with r = 0.9: n_eff = n (0.1 / 1.9) ~ n / 19.
        let mut noise = TestNoise(8);
        let x: Vec<f64> = (0..2000).map(|i| i as f64 * 1e-4).collect();
        let mut ar = 0.0;
        let f = x
            .iter()
            .map(|_| {
                ar = 0.9 * ar + (1.0f64 - 0.81).sqrt() * 0.2 * noise.normal();
                10.0 + ar
            })
            .collect();
        let plate = ShearPlate::new(0.03, 0.02).unwrap();
        let fit = fit_shear(&Curve::new(x, f).unwrap(), plate, Some(0.0)).unwrap();
        let ratio = fit.plateau_samples as f64 / fit.effective_samples;
        assert!((12.0..30.0).contains(&ratio), "{ratio}");
    }

    #[test]
    fn user_plateau_start() {
        let plate = ShearPlate::new(0.03, 0.02).unwrap();
        let fit = fit_shear(&shear(2e6, 0.0, 1), plate, Some(0.04)).unwrap();
        // From 40 mm the rise is complete to exp(-10): k_s exact to 1e-4.
        assert!((fit.k_s / 2e6 - 1.0).abs() < 1e-4);
        assert_eq!(fit.plateau_m.0, 0.04);
        assert_eq!(fit.window, WindowChoice::User);
    }
}
