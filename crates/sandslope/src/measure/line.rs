//! Line fits and robust statistics: ordinary least squares, a Huber line (iteratively
//! reweighted least squares), medians, and the noise level of a curve estimated from its own
//! samples.

/// A line `y = intercept + slope x` fitted to points, with its statistics.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct LineFit {
    /// Intercept.
    pub intercept: f64,
    /// Slope.
    pub slope: f64,
    /// Standard error of the slope.
    pub slope_se: f64,
    /// Coefficient of determination `1 - SSR / SST` (residuals of this line, unweighted).
    pub r_squared: f64,
    /// Residual standard deviation, `sqrt(SSR / (n - 2))`.
    pub residual_sd: f64,
    /// Number of points.
    pub n: usize,
}

/// Least squares with intercept over `(x, y)`; `None` with fewer than 3 points or no spread
/// in x.
pub fn line_fit(x: &[f64], y: &[f64]) -> Option<LineFit> {
    let n = x.len().min(y.len());
    if n < 3 {
        return None;
    }
    let nf = n as f64;
    let mx = x[..n].iter().sum::<f64>() / nf;
    let my = y[..n].iter().sum::<f64>() / nf;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for i in 0..n {
        let (dx, dy) = (x[i] - mx, y[i] - my);
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    if sxx <= 0.0 {
        return None;
    }
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let ssr = (syy - slope * sxy).max(0.0);
    let r_squared = if syy > 0.0 { 1.0 - ssr / syy } else { 1.0 };
    let residual_sd = (ssr / (nf - 2.0)).sqrt();
    Some(LineFit { intercept, slope, slope_se: residual_sd / sxx.sqrt(), r_squared, residual_sd, n })
}

/// Tuning constant of the Huber line: 95% efficiency at Gaussian noise.
pub const HUBER_K: f64 = 1.345;

/// A Huber M-estimate of a line (iteratively reweighted least squares) with the noise scale
/// `scale` (> 0; e.g. from [`noise_sd`]): residuals up to `HUBER_K * scale` count fully,
/// larger ones with weight `HUBER_K * scale / |r|`, so a few wild samples cannot pull the line.
///
/// The slope's standard error is Huber's asymptotic one,
/// `se^2 = s^2 [sum psi^2 / (n - 2)] / [mean psi']^2 / Sxx` with `psi` the clipped scaled
/// residual; it equals the least-squares SE when no residual is clipped. `None` as for
/// [`line_fit`].
pub fn huber_line(x: &[f64], y: &[f64], scale: f64) -> Option<LineFit> {
    let n = x.len().min(y.len());
    let mut fit = line_fit(x, y)?;
    if !(scale.is_finite() && scale > 0.0) {
        return Some(fit);
    }
    let c = HUBER_K * scale;
    let mut w = vec![1.0; n];
    for _ in 0..50 {
        for i in 0..n {
            let r = (y[i] - fit.intercept - fit.slope * x[i]).abs();
            w[i] = if r <= c { 1.0 } else { c / r };
        }
        let sw: f64 = w.iter().sum();
        let mx = (0..n).map(|i| w[i] * x[i]).sum::<f64>() / sw;
        let my = (0..n).map(|i| w[i] * y[i]).sum::<f64>() / sw;
        let sxx: f64 = (0..n).map(|i| w[i] * (x[i] - mx).powi(2)).sum();
        let sxy: f64 = (0..n).map(|i| w[i] * (x[i] - mx) * (y[i] - my)).sum();
        if sxx <= 0.0 {
            return Some(fit);
        }
        let slope = sxy / sxx;
        let intercept = my - slope * mx;
        let done = (slope - fit.slope).abs() <= 1e-12 * slope.abs().max(1e-300)
            && (intercept - fit.intercept).abs() <= 1e-12 * intercept.abs().max(1e-300);
        fit.slope = slope;
        fit.intercept = intercept;
        if done {
            break;
        }
    }
    let nf = n as f64;
    let mx = x[..n].iter().sum::<f64>() / nf;
    let my = y[..n].iter().sum::<f64>() / nf;
    let sxx: f64 = x[..n].iter().map(|v| (v - mx).powi(2)).sum();
    let syy: f64 = y[..n].iter().map(|v| (v - my).powi(2)).sum();
    let (mut ssr, mut psi2, mut dpsi) = (0.0, 0.0, 0.0);
    for i in 0..n {
        let r = y[i] - fit.intercept - fit.slope * x[i];
        ssr += r * r;
        let u = r / scale;
        psi2 += u.clamp(-HUBER_K, HUBER_K).powi(2);
        if u.abs() <= HUBER_K {
            dpsi += 1.0;
        }
    }
    fit.residual_sd = (ssr / (nf - 2.0)).sqrt();
    fit.r_squared = if syy > 0.0 { 1.0 - ssr / syy } else { 1.0 };
    let dpsi = (dpsi / nf).max(1.0 / nf);
    fit.slope_se = scale * (psi2 / (nf - 2.0)).sqrt() / dpsi / sxx.sqrt();
    Some(fit)
}

/// Median of a slice (reorders it); NaN for an empty one.
pub fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    // Selection, not a full sort: O(len) (the running median calls this once per sample).
    let k = v.len();
    let (below, mid, _) = v.select_nth_unstable_by(k / 2, f64::total_cmp);
    let mid = *mid;
    if k % 2 == 1 {
        mid
    } else {
        let lower = below.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        0.5 * (lower + mid)
    }
}

/// The standard deviation of white noise on a curve, estimated from its own samples by
/// pseudo-residuals (Gasser, Sroka and Jennen-Steinmetz 1986): each sample against the straight
/// line through its two neighbours, `e_i = w f_{i-1} + (1 - w) f_{i+1} - f_i` with
/// `w = (x_{i+1} - x_i) / (x_{i+1} - x_{i-1})`, whose variance is `sigma^2 (1 + w^2 + (1-w)^2)`
/// wherever the curve is locally straight. The scale is taken robustly, `1.4826 * median
/// |e_i| / sqrt(1 + w^2 + (1-w)^2)`, so kinks (contact, bed bottom) and spikes do not count.
/// `None` with fewer than 3 samples with distinct neighbours.
pub fn noise_sd(x: &[f64], f: &[f64]) -> Option<f64> {
    let n = x.len().min(f.len());
    let mut e: Vec<f64> = (1..n.saturating_sub(1))
        .filter_map(|i| {
            let span = x[i + 1] - x[i - 1];
            if span <= 0.0 {
                return None;
            }
            let w = (x[i + 1] - x[i]) / span;
            let r = w * f[i - 1] + (1.0 - w) * f[i + 1] - f[i];
            Some(r.abs() / (1.0 + w * w + (1.0 - w) * (1.0 - w)).sqrt())
        })
        .collect();
    (e.len() >= 3).then(|| 1.482_602_218_505_602 * median(&mut e))
}

#[cfg(test)]
mod tests {
    use super::super::TestNoise;
    use super::*;

    #[test]
    fn line_fit_recovers_exact_line_and_se_zero() {
        let x = [0.0, 1.0, 2.0, 3.0];
        let y = [1.0, 3.0, 5.0, 7.0];
        let l = line_fit(&x, &y).unwrap();
        assert!((l.slope - 2.0).abs() < 1e-12 && (l.intercept - 1.0).abs() < 1e-12);
        assert!(l.slope_se.abs() < 1e-12 && (l.r_squared - 1.0).abs() < 1e-12);
        // Hand-worked: y = 0, 1, 1, 2 over x = 0..3: slope 0.6, intercept 0.1, SSR = 0.2,
        // Sxx = 5, se = sqrt(0.2 / 2 / 5) = sqrt(0.02), SST = 2, R^2 = 0.9.
        let l = line_fit(&x, &[0.0, 1.0, 1.0, 2.0]).unwrap();
        assert!((l.slope - 0.6).abs() < 1e-12 && (l.intercept - 0.1).abs() < 1e-12);
        assert!((l.slope_se - 0.02f64.sqrt()).abs() < 1e-12 && (l.r_squared - 0.9).abs() < 1e-12);
        assert!((l.residual_sd - 0.1f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn huber_equals_least_squares_without_outliers_and_ignores_a_spike() {
        // Residuals all within 1.345 * scale: the Huber line is the least-squares line.
        let x = [0.0, 1.0, 2.0, 3.0];
        let y = [0.0, 1.0, 1.0, 2.0];
        let (h, l) = (huber_line(&x, &y, 1.0).unwrap(), line_fit(&x, &y).unwrap());
        assert!((h.slope - l.slope).abs() < 1e-12 && (h.slope_se - l.slope_se).abs() < 1e-9);
        // y = 2x with noise 0.01 and one spike of +5 at x = 10 (of 0..=20): least squares
        // tilts by 5 * (10 - 10) / Sxx = 0 there, so put it at the end (x = 20): OLS slope
        // moves by 5 * 10 / 770 = 0.065; Huber keeps it within a few noise SEs.
        let mut noise = TestNoise(9);
        let x: Vec<f64> = (0..=20).map(f64::from).collect();
        let mut y: Vec<f64> = x.iter().map(|v| 2.0 * v + 0.01 * noise.normal()).collect();
        y[20] += 5.0;
        let l = line_fit(&x, &y).unwrap();
        let h = huber_line(&x, &y, 0.01).unwrap();
        assert!((l.slope - 2.0).abs() > 0.05, "{l:?}");
        assert!((h.slope - 2.0).abs() < 0.003, "{h:?}");
    }

    #[test]
    fn noise_sd_from_pseudo_residuals() {
        // A line with a kink and uneven spacing plus noise 0.2: the estimate is within 15%
        // (SE of a MAD-based scale over ~400 values is about 5%).
        let mut noise = TestNoise(4);
        let mut x = Vec::new();
        let mut t = 0.0;
        for i in 0..400 {
            t += if i % 3 == 0 { 0.7e-3 } else { 0.4e-3 };
            x.push(t);
        }
        let f: Vec<f64> = x
            .iter()
            .map(|&v| 200.0 * v + if v > 0.1 { 4000.0 * (v - 0.1) } else { 0.0 } + 0.2 * noise.normal())
            .collect();
        let s = noise_sd(&x, &f).unwrap();
        assert!((s / 0.2 - 1.0).abs() < 0.15, "{s}");
        assert_eq!(noise_sd(&[0.0, 1.0], &[0.0, 1.0]), None);
    }
}
