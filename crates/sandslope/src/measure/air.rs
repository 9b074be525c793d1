//! The in-air offset (docs/model.md §10: "after subtracting the in-air offset"): what the load
//! cell reads with nothing touching it, at the same kind and slope, removed from each trial.
//!
//! The default ([`AirMode::Auto`]) tests whether the in-air run has a trend with position (a
//! t-test on the slope of a least-squares line, two-sided, at [`TREND_ALPHA`]): without a
//! significant trend the mean is subtracted; with one, the fitted line. The line is the in-air
//! curve without its noise: subtracting the raw curve ([`AirMode::Curve`]) would add the in-air
//! run's noise to every sample.

use statrs::distribution::{ContinuousCDF, StudentsT};

use super::clean::Curve;
use super::line::line_fit;

/// Significance level of the in-air trend test. 5% rather than 1%: a drift the test misses is
/// a bias in every trial at that slope, whereas subtracting a line that was not needed only adds
/// the line's (small) uncertainty.
pub const TREND_ALPHA: f64 = 0.05;

/// How the in-air offset is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AirMode {
    /// The mean, or the fitted line when the in-air run has a significant trend.
    #[default]
    Auto,
    /// Always the mean.
    Mean,
    /// Always the in-air force against position, interpolated linearly (held beyond its ends).
    Curve,
}

/// The trend test of the in-air runs at one kind and slope.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct AirTrend {
    /// Slope of the least-squares line of force against position, N/m.
    pub slope_n_per_m: f64,
    /// Its standard error, N/m.
    pub slope_se: f64,
    /// Two-sided p-value of the t-test for a zero slope.
    pub p_value: f64,
    /// Whether `p_value < TREND_ALPHA`.
    pub significant: bool,
}

/// The in-air correction subtracted from a recording.
#[derive(Debug, Clone, PartialEq)]
pub enum AirCorrection {
    /// No in-air run was available.
    None,
    /// The mean in-air force.
    Mean {
        /// Mean force, N.
        offset_n: f64,
        /// Its standard error, N.
        se_n: f64,
    },
    /// The least-squares line of the in-air force against position.
    Trend {
        /// Force at position 0, N.
        intercept_n: f64,
        /// Slope, N/m.
        slope_n_per_m: f64,
        /// Residual standard deviation of the in-air samples, N.
        sigma_n: f64,
        /// Samples.
        n: usize,
        /// Their mean position, m.
        mean_x: f64,
        /// Sum of squared position deviations, m^2.
        sxx: f64,
    },
    /// The in-air force against position, interpolated linearly and held beyond its ends.
    Curve(Curve),
}

impl AirCorrection {
    /// The correction for the in-air runs `runs` (all of one kind and slope) in `mode`, with the
    /// trend test (absent with fewer than 3 samples in all).
    pub fn choose(runs: &[&Curve], mode: AirMode) -> (AirCorrection, Option<AirTrend>) {
        let runs: Vec<&Curve> = runs.iter().copied().filter(|c| !c.is_empty()).collect();
        if runs.is_empty() {
            return (AirCorrection::None, None);
        }
        let xs: Vec<f64> = runs.iter().flat_map(|c| c.position().iter().copied()).collect();
        let fs: Vec<f64> = runs.iter().flat_map(|c| c.force().iter().copied()).collect();
        let n = xs.len();
        let mean_f = fs.iter().sum::<f64>() / n as f64;
        let sd_f = if n > 1 {
            (fs.iter().map(|f| (f - mean_f).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
        } else {
            0.0
        };
        let mean = AirCorrection::Mean { offset_n: mean_f, se_n: sd_f / (n as f64).sqrt() };
        let line = line_fit(&xs, &fs);
        let trend = line.map(|l| {
            let t = if l.slope_se > 0.0 { l.slope / l.slope_se } else { f64::INFINITY * l.slope.signum() };
            let p_value = match StudentsT::new(0.0, 1.0, (n - 2) as f64) {
                Ok(d) if t.is_finite() => 2.0 * (1.0 - d.cdf(t.abs())),
                _ => {
                    if l.slope == 0.0 {
                        1.0
                    } else {
                        0.0
                    }
                }
            };
            AirTrend {
                slope_n_per_m: l.slope,
                slope_se: l.slope_se,
                p_value,
                significant: p_value < TREND_ALPHA,
            }
        });
        let correction = match mode {
            AirMode::Mean => mean,
            AirMode::Curve => curve_of(&runs),
            AirMode::Auto => match (line, trend) {
                (Some(l), Some(t)) if t.significant => {
                    let mean_x = xs.iter().sum::<f64>() / n as f64;
                    let sxx = xs.iter().map(|x| (x - mean_x).powi(2)).sum::<f64>();
                    let ssr: f64 =
                        xs.iter().zip(&fs).map(|(x, f)| (f - l.intercept - l.slope * x).powi(2)).sum();
                    AirCorrection::Trend {
                        intercept_n: l.intercept,
                        slope_n_per_m: l.slope,
                        sigma_n: (ssr / (n - 2) as f64).sqrt(),
                        n,
                        mean_x,
                        sxx,
                    }
                }
                _ => mean,
            },
        };
        (correction, trend)
    }

    /// The offset at position `x`, N (0 when there is no correction).
    pub fn at(&self, x: f64) -> f64 {
        match self {
            AirCorrection::None => 0.0,
            AirCorrection::Mean { offset_n, .. } => *offset_n,
            AirCorrection::Trend { intercept_n, slope_n_per_m, .. } => intercept_n + slope_n_per_m * x,
            AirCorrection::Curve(c) => c.force_at(x),
        }
    }

    /// `mean`, `trend`, `curve` or `none`.
    pub fn name(&self) -> &'static str {
        match self {
            AirCorrection::None => "none",
            AirCorrection::Mean { .. } => "mean",
            AirCorrection::Trend { .. } => "trend",
            AirCorrection::Curve(_) => "curve",
        }
    }

    /// The mean offset, N: the mean, the line at the in-air run's mean position, or the mean
    /// of the curve's samples; `None` without correction.
    pub fn mean_offset(&self) -> Option<f64> {
        match self {
            AirCorrection::None => None,
            AirCorrection::Mean { offset_n, .. } => Some(*offset_n),
            AirCorrection::Trend { .. } => Some(self.at(self.trend_mean_x())),
            AirCorrection::Curve(c) => Some(c.mean_force()),
        }
    }

    fn trend_mean_x(&self) -> f64 {
        match self {
            AirCorrection::Trend { mean_x, .. } => *mean_x,
            _ => 0.0,
        }
    }

    /// Standard error of the mean offset subtracted over samples centred on position `x`, N.
    pub fn offset_se_at(&self, x: f64) -> f64 {
        match self {
            AirCorrection::Mean { se_n, .. } => *se_n,
            AirCorrection::Trend { sigma_n, n, mean_x, sxx, .. } => {
                let lever = if *sxx > 0.0 { (x - mean_x).powi(2) / sxx } else { 0.0 };
                sigma_n * (1.0 / *n as f64 + lever).sqrt()
            }
            _ => 0.0,
        }
    }
}

/// The average curve of several in-air runs, on the union of their positions.
fn curve_of(runs: &[&Curve]) -> AirCorrection {
    match runs.len() {
        0 => AirCorrection::None,
        1 => AirCorrection::Curve(runs[0].clone()),
        k => {
            let mut xs: Vec<f64> = runs.iter().flat_map(|c| c.position().iter().copied()).collect();
            xs.sort_by(f64::total_cmp);
            xs.dedup();
            let fs = xs.iter().map(|&x| runs.iter().map(|c| c.force_at(x)).sum::<f64>() / k as f64).collect();
            match Curve::new(xs, fs) {
                Ok(c) => AirCorrection::Curve(c),
                Err(_) => AirCorrection::None,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::TestNoise;
    use super::*;

    #[test]
    fn forced_mean_and_curve() {
        let air1 = Curve::new(vec![0.0, 1.0], vec![1.0, 3.0]).unwrap();
        let air2 = Curve::new(vec![0.0, 1.0], vec![3.0, 5.0]).unwrap();
        let (m, _) = AirCorrection::choose(&[&air1, &air2], AirMode::Mean);
        assert_eq!(m.at(7.0), 3.0);
        let (c, _) = AirCorrection::choose(&[&air1, &air2], AirMode::Curve);
        assert_eq!((c.at(-1.0), c.at(0.5), c.at(2.0)), (2.0, 3.0, 4.0));
        let data = Curve::new(vec![0.5], vec![10.0]).unwrap();
        assert_eq!(data.minus(|x| c.at(x)).force(), &[7.0]);
        assert_eq!(AirCorrection::choose(&[], AirMode::Auto).0, AirCorrection::None);
    }

    #[test]
    fn auto_takes_the_trend_only_when_significant() {
        // 60 samples over 45 mm, noise 0.1 N: the slope's SE is 0.1 / sqrt(60 * 0.045^2 / 12)
        // = 0.57 N/m. A drift of 20 N/m is 35 SE: trend.
        let make = |drift: f64, seed: u64| {
            let mut noise = TestNoise(seed);
            let xs: Vec<f64> = (0..60).map(|i| i as f64 * 0.045 / 59.0).collect();
            let fs = xs.iter().map(|x| 0.3 + drift * x + 0.1 * noise.normal()).collect();
            Curve::new(xs, fs).unwrap()
        };
        let drifting = make(20.0, 3);
        // (The line's residual SD is the noise, 0.1 N, within 25%.)
        let (c, t) = AirCorrection::choose(&[&drifting], AirMode::Auto);
        let t = t.unwrap();
        assert!(t.significant && t.p_value < 1e-10 && (t.slope_n_per_m - 20.0).abs() < 4.0 * t.slope_se);
        assert_eq!(c.name(), "trend");
        // Without drift the test picks the trend in about 5% of runs (its level): at most 20 of
        // 200 (expected 10; P(> 20) < 3e-3).
        let wrong = (0..200u64)
            .filter(|&seed| {
                let (c, t) = AirCorrection::choose(&[&make(0.0, seed)], AirMode::Auto);
                assert_eq!(c.name() == "trend", t.unwrap().significant);
                t.unwrap().significant
            })
            .count();
        assert!(wrong <= 20, "{wrong}");
    }
}
