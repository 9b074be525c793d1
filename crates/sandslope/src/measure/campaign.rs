//! A whole measurement campaign as one call: every trial cleaned, the in-air runs paired with
//! the trials they calibrate (same kind and slope), each trial fitted and checked, the trials
//! averaged per slope, and every trial that needs a second look flagged.

use std::collections::BTreeMap;
use std::fmt;

use serde::ser::SerializeMap;

use crate::error::{positive, ParamError};
use crate::terrain::TerrainPoint;

use super::air::{AirCorrection, AirMode, AirTrend};
use super::clean::{clean, Cleaned, Curve, Dropped, RawRecording};
use super::penetration::{fit_penetration, PenetrationFit};
use super::shear::{fit_shear, ShearFit, ShearPlate};
use super::slopes::{modified_z_scores, per_slope, SlopeEstimate, TrialValue, OUTLIER_Z};
use super::{Kind, MeasureError};

/// A window (or plateau) covering less than this fraction of the stroke gets a warning.
pub const SHORT_WINDOW_FRACTION: f64 = 1.0 / 3.0;
/// A penetration fit with R^2 below this gets a warning.
pub const LOW_R_SQUARED: f64 = 0.9;
/// Fewest usable rows in a trial from which malformed rows were skipped.
pub const MIN_USABLE_ROWS: usize = 10;

/// The rig: disk area and shear plate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setup {
    /// Penetration disk area A, m^2.
    pub disk_area_m2: f64,
    /// Shear plate.
    pub plate: ShearPlate,
}

/// Choices the user may make instead of the automatic ones.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FitOptions {
    /// Fit k_n over this depth window (m) instead of finding it.
    pub depth_window: Option<(f64, f64)>,
    /// Start the shear plateau at this displacement (m) instead of finding it.
    pub plateau_from: Option<f64>,
    /// How the in-air offset is chosen.
    pub air: AirMode,
}

/// One trial as read.
#[derive(Debug, Clone, PartialEq)]
pub struct TrialInput {
    /// Its label: the file as written in the manifest.
    pub file: String,
    /// Penetration or shear.
    pub kind: Kind,
    /// Slope of the bed, degrees.
    pub slope_deg: f64,
    /// An in-air calibration run (not a measurement).
    pub air: bool,
    /// Data rows in the file.
    pub rows: usize,
    /// The columns.
    pub raw: RawRecording,
}

/// Something about one trial that deserves a second look.
#[derive(Debug, Clone, PartialEq)]
pub enum TrialWarning {
    /// The fitting window (or shear plateau) covers less than a third of the stroke.
    ShortWindow {
        /// Window length, m.
        window_m: f64,
        /// Stroke length, m.
        stroke_m: f64,
    },
    /// The penetration line explains less than 90% of the variance over its window.
    LowRSquared {
        /// R^2.
        r_squared: f64,
    },
    /// The trial's k disagrees with the other trials at its slope.
    Outlier {
        /// `k_n` or `k_s`.
        what: &'static str,
        /// Relative deviation from the median at its slope.
        deviation: f64,
        /// Modified z-score.
        z: f64,
        /// Trials at its slope.
        trials: usize,
    },
    /// No in-air run at this kind and slope: a shear plateau includes the load cell's offset.
    NoAirRun,
}

impl TrialWarning {
    /// A short machine-readable name.
    pub fn code(&self) -> &'static str {
        match self {
            TrialWarning::ShortWindow { .. } => "short_window",
            TrialWarning::LowRSquared { .. } => "low_r_squared",
            TrialWarning::Outlier { .. } => "outlier",
            TrialWarning::NoAirRun => "no_air_run",
        }
    }
}

impl fmt::Display for TrialWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TrialWarning::ShortWindow { window_m, stroke_m } => write!(
                f,
                "window covers {:.1} of the {:.1} mm stroke ({:.0}%, less than a third): check the figure, or set \
                 the window",
                window_m * 1e3,
                stroke_m * 1e3,
                100.0 * window_m / stroke_m
            ),
            TrialWarning::LowRSquared { r_squared } => {
                write!(f, "R^2 = {r_squared:.3} over the window (below {LOW_R_SQUARED}): force is not linear in depth there")
            }
            TrialWarning::Outlier { what, deviation, z, trials } => write!(
                f,
                "{what} is {:+.0}% from the median of the {trials} trials at its slope: an outlier by the modified \
                 z-score ({z:.1}, |M| > {OUTLIER_Z}; MAD pooled over all slopes)",
                100.0 * deviation
            ),
            TrialWarning::NoAirRun => {
                f.write_str("no in-air run at this kind and slope: the plateau force includes any load-cell offset")
            }
        }
    }
}

/// `{"code": ..., "message": ...}`.
impl serde::Serialize for TrialWarning {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(2))?;
        m.serialize_entry("code", self.code())?;
        m.serialize_entry("message", &self.to_string())?;
        m.end()
    }
}

/// The result for one trial.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TrialResult {
    /// Its label (the file as written in the manifest).
    pub file: String,
    /// Penetration or shear.
    pub kind: Kind,
    /// Slope, degrees.
    pub slope_deg: f64,
    /// An in-air run.
    pub air: bool,
    /// Data rows read.
    pub rows: usize,
    /// Samples used after cleaning.
    pub used: usize,
    /// What cleaning dropped.
    pub dropped: Dropped,
    /// Position range of the (down)stroke, m.
    pub stroke_m: (f64, f64),
    /// The in-air correction applied: `mean`, `trend`, `curve` or `none` (`none` for in-air runs
    /// themselves).
    pub air_correction: &'static str,
    /// Mean in-air force subtracted, or for an in-air run its own mean force, N.
    pub air_offset_n: Option<f64>,
    /// The trend test of the in-air runs at this kind and slope.
    pub air_trend: Option<AirTrend>,
    /// The penetration fit (penetration trials).
    #[serde(flatten)]
    pub penetration: Option<PenetrationFit>,
    /// The shear fit (shear trials).
    #[serde(flatten)]
    pub shear: Option<ShearFit>,
    /// What deserves a second look.
    pub warnings: Vec<TrialWarning>,
    /// What was done that the user should know about (return stroke dropped, trend subtracted).
    pub notes: Vec<String>,
    /// The clean curve with the in-air offset removed (for figures; not serialised).
    #[serde(skip)]
    pub curve: Curve,
}

impl TrialResult {
    /// The trial's k (k_n or k_s) and its standard error, if it is a measurement.
    pub fn k(&self) -> Option<(f64, f64)> {
        match (&self.penetration, &self.shear) {
            (Some(p), _) => Some((p.k_n, p.k_n_se)),
            (_, Some(s)) => Some((s.k_s, s.k_s_se)),
            _ => None,
        }
    }

    /// The fitting window or plateau, m.
    pub fn window_m(&self) -> Option<(f64, f64)> {
        match (&self.penetration, &self.shear) {
            (Some(p), _) => Some(p.depth_window_m),
            (_, Some(s)) => Some(s.plateau_m),
            _ => None,
        }
    }
}

/// The fit of one kind of trial (for callers that match on the kind).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TrialFit {
    /// Penetration: k_n.
    Penetration(PenetrationFit),
    /// Shear: k_s.
    Shear(ShearFit),
    /// An in-air run.
    Air,
}

impl TrialResult {
    /// The fit as one value.
    pub fn fit(&self) -> TrialFit {
        match (self.penetration, self.shear) {
            (Some(p), _) => TrialFit::Penetration(p),
            (_, Some(s)) => TrialFit::Shear(s),
            _ => TrialFit::Air,
        }
    }
}

/// A whole campaign's result: one row per slope (a terrain table) and one per trial.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Campaign {
    /// Per slope, ascending.
    pub points: Vec<SlopeEstimate>,
    /// Per trial, in input order.
    pub trials: Vec<TrialResult>,
}

impl Campaign {
    /// The terrain table (docs/model.md §7) with the combined standard deviations.
    pub fn terrain_points(&self) -> Vec<TerrainPoint> {
        self.points.iter().map(SlopeEstimate::terrain_point).collect()
    }
}

/// Why a campaign could not be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CampaignError {
    /// The rig's dimensions or the options are out of range.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// One trial could not be cleaned or fitted.
    #[error("{file} ({kind} trial at {slope_deg} deg): {error}")]
    Trial {
        /// The trial's label.
        file: String,
        /// Its kind.
        kind: Kind,
        /// Its slope, degrees.
        slope_deg: f64,
        /// What went wrong.
        error: MeasureError,
    },
    /// Too few rows of a trial survived cleaning.
    #[error("{file}: {usable} of {rows} data rows usable ({dropped}); at least {needed} needed")]
    TooFewRows {
        /// The trial's label.
        file: String,
        /// Data rows read.
        rows: usize,
        /// Rows left.
        usable: usize,
        /// Rows needed.
        needed: usize,
        /// What was dropped, in words.
        dropped: String,
    },
    /// The per-slope table could not be made (a kind without trials).
    #[error(transparent)]
    Table(MeasureError),
}

/// "3 blank, 2 NaN/inf, ..." or "none".
pub fn dropped_text(d: &Dropped) -> String {
    let parts: Vec<String> = [
        (d.malformed, "malformed (skipped)"),
        (d.blank, "blank"),
        (d.non_finite, "NaN/inf"),
        (d.retraction, "return stroke"),
        (d.duplicate, "repeated"),
        (d.saturated, "saturated"),
        (d.reordered, "reordered (kept)"),
    ]
    .iter()
    .filter(|(n, _)| *n > 0)
    .map(|(n, what)| format!("{n} {what}"))
    .collect();
    if parts.is_empty() {
        "none".into()
    } else {
        parts.join(", ")
    }
}

/// Fits a whole campaign: cleans every trial, pairs each measuring trial with the in-air runs
/// of its kind and slope (their offset chosen by `options.air`), fits k_n or k_s, adds the
/// in-air correction's uncertainty to each trial's standard error, warns where a window is
/// short, a line poor or a trial an outlier, and averages per slope ([`per_slope`]).
pub fn fit_campaign(
    trials: &[TrialInput],
    setup: &Setup,
    options: &FitOptions,
) -> Result<Campaign, CampaignError> {
    let area = positive("disk_area_m2", setup.disk_area_m2)?;
    let cleaned = clean_all(trials)?;
    // In-air runs by (kind, slope).
    let key = |t: &TrialInput| (t.kind, t.slope_deg.to_bits());
    let mut runs: BTreeMap<(Kind, u64), Vec<&Curve>> = BTreeMap::new();
    for (t, c) in trials.iter().zip(&cleaned) {
        if t.air {
            runs.entry(key(t)).or_default().push(&c.curve);
        }
    }
    let corrections: BTreeMap<(Kind, u64), (AirCorrection, Option<AirTrend>)> =
        runs.iter().map(|(k, r)| (*k, AirCorrection::choose(r, options.air))).collect();
    let none = (AirCorrection::None, None);
    let mut results = Vec::with_capacity(trials.len());
    for (t, c) in trials.iter().zip(cleaned) {
        let (air, trend) = corrections.get(&key(t)).unwrap_or(&none);
        results.push(fit_trial(t, c, air, trend.as_ref(), setup, area, options)?);
    }
    let values = flag_outliers(&mut results);
    let k_n: Vec<TrialValue> = values[0].iter().map(|v| v.1).collect();
    let k_s: Vec<TrialValue> = values[1].iter().map(|v| v.1).collect();
    let points = per_slope(&k_n, &k_s).map_err(CampaignError::Table)?;
    Ok(Campaign { points, trials: results })
}

/// Each trial's curve cleaned (docs/model.md's cleaning), refused when too few rows are left.
fn clean_all(trials: &[TrialInput]) -> Result<Vec<Cleaned>, CampaignError> {
    let mut cleaned = Vec::with_capacity(trials.len());
    for t in trials {
        let c = clean(&t.raw).map_err(|error| CampaignError::Trial {
            file: t.file.clone(),
            kind: t.kind,
            slope_deg: t.slope_deg,
            error,
        })?;
        let needed = if c.dropped.malformed > 0 { MIN_USABLE_ROWS } else { 1 };
        if c.curve.len() < needed {
            return Err(CampaignError::TooFewRows {
                file: t.file.clone(),
                rows: t.rows,
                usable: c.curve.len(),
                needed,
                dropped: dropped_text(&c.dropped),
            });
        }
        cleaned.push(c);
    }
    Ok(cleaned)
}

/// One trial's result: an in-air run's mean force, or a trial's fit after subtracting its
/// in-air correction, with its notes and warnings.
fn fit_trial(
    t: &TrialInput,
    c: Cleaned,
    air: &AirCorrection,
    trend: Option<&AirTrend>,
    setup: &Setup,
    area: f64,
    options: &FitOptions,
) -> Result<TrialResult, CampaignError> {
    let mut r = TrialResult {
        file: t.file.clone(),
        kind: t.kind,
        slope_deg: t.slope_deg,
        air: t.air,
        rows: t.rows,
        used: c.curve.len(),
        dropped: c.dropped,
        stroke_m: c.stroke,
        air_correction: "none",
        air_offset_n: None,
        air_trend: trend.copied(),
        penetration: None,
        shear: None,
        warnings: Vec::new(),
        notes: Vec::new(),
        curve: Curve::default(),
    };
    if c.dropped.retraction > 0 {
        let what = if t.kind == Kind::Penetration { "deepest point" } else { "farthest displacement" };
        r.notes.push(format!(
            "goes back after its {what}: {} rows of the return stroke dropped, the {} only is used",
            c.dropped.retraction,
            if t.kind == Kind::Penetration { "downstroke" } else { "forward drag" }
        ));
    }
    if c.dropped.malformed > 0 {
        r.notes.push(format!("{} rows with a malformed cell skipped", c.dropped.malformed));
    }
    if t.air {
        r.air_offset_n = Some(c.curve.mean_force());
        r.curve = c.curve;
        return Ok(r);
    }
    r.air_correction = air.name();
    r.air_offset_n = air.mean_offset();
    match (air, trend) {
        (AirCorrection::None, _) => {
            if t.kind == Kind::Shear {
                r.warnings.push(TrialWarning::NoAirRun);
            } else {
                r.notes.push(
                    "no in-air run at this kind and slope: force not offset-corrected (the fitted intercept \
                     absorbs a constant offset; k_n is unaffected)"
                        .into(),
                );
            }
        }
        (AirCorrection::Trend { slope_n_per_m, .. }, Some(tr)) => r.notes.push(format!(
            "the in-air run drifts by {slope_n_per_m:.3} N/m (t-test p = {:.1e} < 0.05): its fitted line is \
             subtracted",
            tr.p_value
        )),
        _ => {}
    }
    let corrected = c.curve.minus(|x| air.at(x));
    let fail =
        |error| CampaignError::Trial { file: t.file.clone(), kind: t.kind, slope_deg: t.slope_deg, error };
    let stroke = c.stroke.1 - c.stroke.0;
    let window = match t.kind {
        Kind::Penetration => {
            let mut p = fit_penetration(&corrected, area, options.depth_window).map_err(fail)?;
            // The in-air run bounds a drift (a slope in force against depth, which k_n would
            // absorb) only to its slope's SE, whether or not the trend was subtracted.
            p.k_n_se = p.k_n_se.hypot(trend.map_or(0.0, |t| t.slope_se) / area);
            if p.r_squared < LOW_R_SQUARED {
                r.warnings.push(TrialWarning::LowRSquared { r_squared: p.r_squared });
            }
            r.penetration = Some(p);
            p.depth_window_m
        }
        Kind::Shear => {
            let mut s = fit_shear(&corrected, setup.plate, options.plateau_from).map_err(fail)?;
            let mid = 0.5 * (s.plateau_m.0 + s.plateau_m.1);
            s.k_s_se = s.k_s_se.hypot(air.offset_se_at(mid) / setup.plate.factor());
            r.shear = Some(s);
            s.plateau_m
        }
    };
    let length = window.1 - window.0;
    if stroke > 0.0 && length < SHORT_WINDOW_FRACTION * stroke {
        r.warnings.push(TrialWarning::ShortWindow { window_m: length, stroke_m: stroke });
    }
    r.curve = corrected;
    Ok(r)
}

/// Flags each trial whose k is an outlier against the other trials at the same slope
/// (modified z-score over OUTLIER_Z); returns the trials' (index, k) for k_n and k_s.
fn flag_outliers(results: &mut [TrialResult]) -> [Vec<(usize, TrialValue)>; 2] {
    // Per slope, and outliers against the other trials at the same slope.
    let mut values: [Vec<(usize, TrialValue)>; 2] = [Vec::new(), Vec::new()];
    for (i, r) in results.iter().enumerate() {
        if let Some((k, se)) = r.k() {
            let slot = if r.kind == Kind::Penetration { 0 } else { 1 };
            values[slot].push((i, TrialValue { slope_deg: r.slope_deg, k, se }));
        }
    }
    for (slot, what) in [(0, "k_n"), (1, "k_s")] {
        let vals: Vec<TrialValue> = values[slot].iter().map(|v| v.1).collect();
        let z = modified_z_scores(&vals);
        for ((i, v), z) in values[slot].iter().zip(z) {
            let Some(z) = z else { continue };
            if z.abs() > OUTLIER_Z {
                let at: Vec<f64> = vals.iter().filter(|w| w.slope_deg == v.slope_deg).map(|w| w.k).collect();
                let mut sorted = at.clone();
                sorted.sort_by(f64::total_cmp);
                let median = if sorted.len() % 2 == 1 {
                    sorted[sorted.len() / 2]
                } else {
                    0.5 * (sorted[sorted.len() / 2 - 1] + sorted[sorted.len() / 2])
                };
                results[*i].warnings.push(TrialWarning::Outlier {
                    what,
                    deviation: v.k / median - 1.0,
                    z,
                    trials: at.len(),
                });
            }
        }
    }
    values
}
