//! Per-slope tables: the trials at each slope averaged, with a standard deviation that combines
//! the spread across trials with each trial's standard error; a kind not measured at a slope
//! filled in from the slopes where it was; and trials that disagree with the others at their
//! slope flagged.

use serde::ser::SerializeMap;

use crate::terrain::TerrainPoint;

use super::line::median;
use super::{Kind, MeasureError};

/// A trial's value of k_n or k_s at its slope.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrialValue {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// The resistance, N/m^3.
    pub k: f64,
    /// Its standard error from the trial's own fit, N/m^3.
    pub se: f64,
}

/// Where a per-slope value came from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Origin {
    /// Measured at this slope.
    Measured,
    /// Not measured here: linear interpolation in degrees between the measured slopes
    /// `below` and `above`.
    Interpolated {
        /// Nearest measured slope below, degrees.
        below: f64,
        /// Nearest measured slope above, degrees.
        above: f64,
    },
    /// Not measured here and outside the measured slopes: the value at the nearest measured
    /// slope, held (a choice: extrapolating a measured table is riskier than holding it).
    Nearest {
        /// The measured slope used, degrees.
        from: f64,
    },
}

/// A resistance at one slope.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlopeStat {
    /// Mean across trials, N/m^3.
    pub mean: f64,
    /// Combined standard deviation, N/m^3: `sqrt(s^2 + (1/n) sum se_i^2)` with `s` the sample
    /// SD across the `n` trials (0 for one trial) and `se_i` each trial's standard error. It is
    /// what the terrain file's `k_n_sd`/`k_s_sd` hold.
    pub sd: f64,
    /// Sample standard deviation across trials (n - 1), N/m^3; `None` with a single trial.
    pub spread_sd: Option<f64>,
    /// Root mean square of the trials' standard errors, N/m^3.
    pub se_rms: f64,
    /// Number of trials at this slope (0 when not measured here).
    pub trials: usize,
    /// Whether measured here or filled from other slopes.
    pub origin: Origin,
}

impl SlopeStat {
    /// The stat of the trials' values at one slope (`values` non-empty).
    fn of(values: &[TrialValue]) -> SlopeStat {
        let k = values.len() as f64;
        let mean = values.iter().map(|v| v.k).sum::<f64>() / k;
        let spread_sd = (values.len() > 1)
            .then(|| (values.iter().map(|v| (v.k - mean).powi(2)).sum::<f64>() / (k - 1.0)).sqrt());
        let se_rms = (values.iter().map(|v| v.se * v.se).sum::<f64>() / k).sqrt();
        let sd = (spread_sd.unwrap_or(0.0).powi(2) + se_rms * se_rms).sqrt();
        SlopeStat { mean, sd, spread_sd, se_rms, trials: values.len(), origin: Origin::Measured }
    }

    /// How a filled-in value was obtained, in words (e.g. `k_s interpolated between 10 and 20
    /// deg`); `None` when measured.
    pub fn note(&self, what: &str) -> Option<String> {
        match self.origin {
            Origin::Measured => None,
            Origin::Interpolated { below, above } => {
                Some(format!("{what} interpolated between {below} and {above} deg"))
            }
            Origin::Nearest { from } => Some(format!("{what} held from {from} deg (nearest measured)")),
        }
    }
}

/// Both resistances at one slope: one row of a terrain file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlopeEstimate {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Normal penetration resistance.
    pub k_n: SlopeStat,
    /// Shear strength.
    pub k_s: SlopeStat,
}

impl SlopeEstimate {
    /// The terrain-file point (docs/model.md §7) with the combined standard deviations.
    pub fn terrain_point(&self) -> TerrainPoint {
        TerrainPoint {
            slope_deg: self.slope_deg,
            k_n: self.k_n.mean,
            k_s: self.k_s.mean,
            k_n_sd: Some(self.k_n.sd),
            k_s_sd: Some(self.k_s.sd),
        }
    }

    /// What was not measured at this slope and how it was filled.
    pub fn notes(&self) -> Vec<String> {
        [self.k_n.note("k_n"), self.k_s.note("k_s")].into_iter().flatten().collect()
    }
}

/// Flat keys: `slope_deg`, `k_n`, `k_n_sd`, `k_n_spread_sd`, `k_n_se_rms`, the same for `k_s`,
/// `trials_penetration`, `trials_shear` and `interpolated` (the notes).
impl serde::Serialize for SlopeEstimate {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(12))?;
        m.serialize_entry("slope_deg", &self.slope_deg)?;
        for (name, st) in [("k_n", &self.k_n), ("k_s", &self.k_s)] {
            m.serialize_entry(name, &st.mean)?;
            m.serialize_entry(&format!("{name}_sd"), &st.sd)?;
            m.serialize_entry(&format!("{name}_spread_sd"), &st.spread_sd)?;
            m.serialize_entry(&format!("{name}_se_rms"), &st.se_rms)?;
        }
        m.serialize_entry("trials_penetration", &self.k_n.trials)?;
        m.serialize_entry("trials_shear", &self.k_s.trials)?;
        m.serialize_entry("interpolated", &self.notes())?;
        m.end()
    }
}

/// Groups per-trial values by slope (exact equality of the degrees given).
fn group(values: &[TrialValue]) -> Vec<(f64, SlopeStat)> {
    let mut sorted = values.to_vec();
    sorted.sort_by(|a, b| a.slope_deg.total_cmp(&b.slope_deg));
    sorted.chunk_by(|a, b| a.slope_deg == b.slope_deg).map(|c| (c[0].slope_deg, SlopeStat::of(c))).collect()
}

/// The stat at `deg` from measured `table` (sorted, non-empty): measured, interpolated or held.
fn lookup(table: &[(f64, SlopeStat)], deg: f64) -> SlopeStat {
    if let Some((_, s)) = table.iter().find(|(d, _)| *d == deg) {
        return *s;
    }
    let i = table.partition_point(|(d, _)| *d < deg);
    if i == 0 || i == table.len() {
        let (from, s) = if i == 0 { table[0] } else { table[table.len() - 1] };
        return SlopeStat { trials: 0, origin: Origin::Nearest { from }, ..s };
    }
    let ((d0, a), (d1, b)) = (table[i - 1], table[i]);
    let w = (deg - d0) / (d1 - d0);
    let lerp = |p: f64, q: f64| p + w * (q - p);
    SlopeStat {
        mean: lerp(a.mean, b.mean),
        sd: lerp(a.sd, b.sd),
        spread_sd: a.spread_sd.zip(b.spread_sd).map(|(p, q)| lerp(p, q)),
        se_rms: lerp(a.se_rms, b.se_rms),
        trials: 0,
        origin: Origin::Interpolated { below: d0, above: d1 },
    }
}

/// Per-slope mean and SDs of k_n and k_s from per-trial values.
///
/// Every slope with a trial of either kind gets a point; where one kind was not measured at a
/// slope it is interpolated linearly in degrees from the slopes where it was (or held from the
/// nearest measured slope outside their range), and its [`Origin`] says so. Fails when either
/// kind has no trial at all.
pub fn per_slope(k_n: &[TrialValue], k_s: &[TrialValue]) -> Result<Vec<SlopeEstimate>, MeasureError> {
    if k_n.is_empty() {
        return Err(MeasureError::NoTrials(Kind::Penetration));
    }
    if k_s.is_empty() {
        return Err(MeasureError::NoTrials(Kind::Shear));
    }
    let (n_table, s_table) = (group(k_n), group(k_s));
    let mut slopes: Vec<f64> = n_table.iter().chain(&s_table).map(|(d, _)| *d).collect();
    slopes.sort_by(f64::total_cmp);
    slopes.dedup();
    Ok(slopes
        .into_iter()
        .map(|d| SlopeEstimate { slope_deg: d, k_n: lookup(&n_table, d), k_s: lookup(&s_table, d) })
        .collect())
}

/// Modified z-score threshold of the outlier test (Iglewicz and Hoaglin 1993).
pub const OUTLIER_Z: f64 = 3.5;
/// Fewest relative deviations pooled across slopes for the outlier test to run.
pub const OUTLIER_MIN_POOL: usize = 5;

/// The outlier test of trials against the other trials at their slope: the **modified z-score**
/// `M = 0.6745 (r - median r) / MAD`, flagged when `|M| > OUTLIER_Z` (Iglewicz and Hoaglin),
/// applied to each trial's relative deviation `r = k / median - 1` from the median of its slope,
/// with the MAD **pooled over all slopes** (three trials cannot estimate a spread on their own;
/// the relative spread of a sand is taken to be alike at every slope) and kept above the
/// trials' median relative standard error (trials cannot be told apart more finely than they
/// were measured). Slopes with fewer than 3 trials are not tested, nor is anything when fewer
/// than [`OUTLIER_MIN_POOL`] deviations can be pooled (the median trial of an odd count is left
/// out of the pool: its deviation is 0 by construction).
///
/// Returns, for each value in order, its modified z-score, or `None` when not tested.
pub fn modified_z_scores(values: &[TrialValue]) -> Vec<Option<f64>> {
    let mut medians: Vec<(f64, f64, usize)> = Vec::new();
    for v in values {
        if !medians.iter().any(|m| m.0 == v.slope_deg) {
            let mut ks: Vec<f64> =
                values.iter().filter(|w| w.slope_deg == v.slope_deg).map(|w| w.k).collect();
            let n = ks.len();
            medians.push((v.slope_deg, median(&mut ks), n));
        }
    }
    let slope_median =
        |d: f64| medians.iter().find(|m| m.0 == d).map(|m| (m.1, m.2)).unwrap_or((f64::NAN, 0));
    let rel: Vec<Option<f64>> = values
        .iter()
        .map(|v| {
            let (med, n) = slope_median(v.slope_deg);
            (n >= 3 && med > 0.0).then(|| v.k / med - 1.0)
        })
        .collect();
    let mut pool: Vec<f64> = rel.iter().flatten().filter(|r| **r != 0.0).map(|r| r.abs()).collect();
    if pool.len() < OUTLIER_MIN_POOL {
        return vec![None; values.len()];
    }
    let mad = median(&mut pool);
    let mut rel_se: Vec<f64> = values.iter().filter(|v| v.k > 0.0).map(|v| v.se / v.k).collect();
    let floor = 0.6745 * median(&mut rel_se);
    let scale = mad.max(if floor.is_finite() { floor } else { 0.0 });
    if scale <= 0.0 {
        return vec![None; values.len()];
    }
    rel.iter().map(|r| r.map(|r| 0.6745 * r / scale)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tv(slope_deg: f64, k: f64, se: f64) -> TrialValue {
        TrialValue { slope_deg, k, se }
    }

    #[test]
    fn per_slope_means_sds_and_interpolation() {
        let k_n = [tv(0.0, 6.0, 0.0), tv(0.0, 8.0, 0.0), tv(20.0, 10.0, 0.5), tv(10.0, 9.0, 0.3)];
        let k_s = [tv(0.0, 4.0, 1.0), tv(0.0, 2.0, 1.0), tv(20.0, 1.0, 0.0), tv(20.0, 3.0, 0.0)];
        let pts = per_slope(&k_n, &k_s).unwrap();
        assert_eq!(pts.iter().map(|p| p.slope_deg).collect::<Vec<_>>(), vec![0.0, 10.0, 20.0]);
        // 0 deg: k_n mean 7, spread sqrt(2), no SE: sd sqrt(2). k_s mean 3, spread sqrt(2),
        // SE 1 each: sd = sqrt(2 + 1) = sqrt(3).
        assert_eq!(pts[0].k_n.mean, 7.0);
        assert!((pts[0].k_n.sd - 2f64.sqrt()).abs() < 1e-12);
        assert!((pts[0].k_s.sd - 3f64.sqrt()).abs() < 1e-12);
        assert!((pts[0].k_s.spread_sd.unwrap() - 2f64.sqrt()).abs() < 1e-12);
        // 10 deg: k_s not measured: halfway between 3 and 2, sd halfway between sqrt 3 and sqrt 2.
        assert_eq!(pts[1].k_s.origin, Origin::Interpolated { below: 0.0, above: 20.0 });
        assert!((pts[1].k_s.mean - 2.5).abs() < 1e-12 && pts[1].k_s.trials == 0);
        assert!((pts[1].k_s.sd - 0.5 * (3f64.sqrt() + 2f64.sqrt())).abs() < 1e-12);
        // 10 deg k_n: one trial: its SE is the SD.
        assert_eq!((pts[1].k_n.spread_sd, pts[1].k_n.sd), (None, 0.3));
        assert_eq!(pts[1].notes(), vec!["k_s interpolated between 0 and 20 deg".to_string()]);
        // Outside the measured range: held from the nearest.
        let pts = per_slope(&[tv(0.0, 1.0, 0.1), tv(24.0, 2.0, 0.1)], &[tv(0.0, 5.0, 0.1)]).unwrap();
        assert_eq!(pts[1].k_s.origin, Origin::Nearest { from: 0.0 });
        assert_eq!(pts[1].k_s.mean, 5.0);
        assert_eq!(per_slope(&[], &[tv(0.0, 1.0, 0.0)]), Err(MeasureError::NoTrials(Kind::Penetration)));
        assert_eq!(per_slope(&[tv(0.0, 1.0, 0.0)], &[]), Err(MeasureError::NoTrials(Kind::Shear)));
        // Serialised with flat keys.
        let j = serde_json::to_value(pts[0]).unwrap();
        assert_eq!(j["k_n"], 1.0);
        assert_eq!(j["trials_penetration"], 1);
        assert_eq!(j["k_n_spread_sd"], serde_json::Value::Null);
    }

    #[test]
    fn outlier_by_pooled_modified_z_score() {
        // Four slopes, three trials each, about 3% apart; at 10 deg one trial is 30% high.
        // Pooled |r| (median trial left out): 0.03 (7 times) and 0.3: MAD = 0.03.
        // The 30% trial: M = 0.6745 * 0.3 / 0.03 = 6.7 > 3.5; the others 0.67.
        let mut v = Vec::new();
        for d in [0.0, 5.0, 10.0, 15.0] {
            v.push(tv(d, 1.0, 0.001));
            v.push(tv(d, 0.97, 0.001));
            v.push(tv(d, if d == 10.0 { 1.3 } else { 1.03 }, 0.001));
        }
        let z = modified_z_scores(&v);
        assert!((z[8].unwrap() - 0.6745 * 0.3 / 0.03).abs() < 1e-9, "{z:?}");
        let flagged: Vec<usize> = (0..v.len()).filter(|&i| z[i].unwrap().abs() > OUTLIER_Z).collect();
        assert_eq!(flagged, vec![8]);
        // Trials measured no better than 20%: the floor 0.6745 * 0.2 makes M = 1.5: not flagged.
        for t in &mut v {
            t.se = 0.2 * t.k;
        }
        assert!(modified_z_scores(&v)[8].unwrap().abs() < OUTLIER_Z);
        // Too few to pool: not tested.
        assert_eq!(modified_z_scores(&v[..3]), vec![None; 3]);
    }
}
