//! The one uncertainty rule of the whole tool (docs/model.md §9), as one type.
//!
//! At a slope, k_n and k_s are independent log-normal variables whose medians are the
//! terrain table's values. Each coefficient of variation (CV, standard deviation over
//! median) comes from, in this order:
//! 1. a CV given by the user (`--cv-n`, `--cv-s`), the same at every slope;
//! 2. the table's standard deviation (`k_n_sd`, `k_s_sd`, interpolated like the value)
//!    divided by the value, where the table has it at that slope;
//! 3. the default CV, [`DEFAULT_CV_N`] = 0.1 for k_n and [`DEFAULT_CV_S`] = 0.2 for k_s.
//!
//! [`UncertainTerrain`] applies it: `risk`, `plan` and `design` all read their uncertainty
//! from it, so the same terrain and flags give the same uncertainty everywhere. Every result
//! built on it carries [`DefaultsUsed`] so that outputs can say when a default was used.

use serde::{Deserialize, Serialize};

use crate::error::{non_negative, ParamError};
use crate::slope::Slope;
use crate::terrain::{Ground, Terrain};

/// Default coefficient of variation of k_n, used where neither the user nor the table gives
/// one (docs/model.md §9).
pub const DEFAULT_CV_N: f64 = 0.1;
/// Default coefficient of variation of k_s, used where neither the user nor the table gives
/// one (docs/model.md §9).
pub const DEFAULT_CV_S: f64 = 0.2;

/// Coefficients of variation of k_n and k_s (standard deviation over median value).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Uncertainty {
    cv_n: f64,
    cv_s: f64,
}

impl Uncertainty {
    /// No uncertainty: the regime is certain.
    pub const NONE: Uncertainty = Uncertainty { cv_n: 0.0, cv_s: 0.0 };

    /// The defaults of docs/model.md §9: cv 0.1 for k_n, 0.2 for k_s.
    pub const DEFAULT: Uncertainty = Uncertainty { cv_n: DEFAULT_CV_N, cv_s: DEFAULT_CV_S };

    /// Coefficients of variation, each finite and >= 0 (errors name `cv_n` / `cv_s`).
    pub fn new(cv_n: f64, cv_s: f64) -> Result<Uncertainty, ParamError> {
        Ok(Uncertainty { cv_n: non_negative("cv_n", cv_n)?, cv_s: non_negative("cv_s", cv_s)? })
    }

    /// From standard deviations: `cv = sd / value` (0 where the value is 0).
    pub fn from_sd(ground: &Ground, k_n_sd: f64, k_s_sd: f64) -> Result<Uncertainty, ParamError> {
        let cv = |sd: f64, k: f64| if k > 0.0 { sd / k } else { 0.0 };
        Uncertainty::new(cv(k_n_sd, ground.k_n), cv(k_s_sd, ground.k_s))
    }

    /// Coefficient of variation of k_n.
    pub fn cv_n(self) -> f64 {
        self.cv_n
    }
    /// Coefficient of variation of k_s.
    pub fn cv_s(self) -> f64 {
        self.cv_s
    }
    /// Log-space standard deviation of k_n, `sqrt(ln(1 + cv_n^2))`.
    pub fn sigma_n(self) -> f64 {
        (1.0 + self.cv_n * self.cv_n).ln().sqrt()
    }
    /// Log-space standard deviation of k_s, `sqrt(ln(1 + cv_s^2))`.
    pub fn sigma_s(self) -> f64 {
        (1.0 + self.cv_s * self.cv_s).ln().sqrt()
    }
}

/// Where one coefficient of variation came from (docs/model.md §9).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CvSource {
    /// Given by the user (overrides the table).
    Given,
    /// The table's standard deviation divided by its value.
    Table,
    /// The default CV ([`DEFAULT_CV_N`], [`DEFAULT_CV_S`]).
    Default,
}

/// Whether the default CV was used for k_n and for k_s somewhere (at some slope).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct DefaultsUsed {
    /// The default cv of k_n ([`DEFAULT_CV_N`]) was used.
    pub k_n: bool,
    /// The default cv of k_s ([`DEFAULT_CV_S`]) was used.
    pub k_s: bool,
}

impl DefaultsUsed {
    /// Whether any default was used.
    pub fn any(self) -> bool {
        self.k_n || self.k_s
    }

    /// A sentence for outputs, e.g. "no k_s_sd in the terrain: default cv k_s = 0.2 used
    /// (docs/model.md §9)"; `None` when no default was used.
    pub fn note(self) -> Option<String> {
        let mut parts = Vec::new();
        if self.k_n {
            parts.push(format!("k_n_sd: default cv k_n = {DEFAULT_CV_N}"));
        }
        if self.k_s {
            parts.push(format!("k_s_sd: default cv k_s = {DEFAULT_CV_S}"));
        }
        (!parts.is_empty()).then(|| {
            format!(
                "the terrain has no {} used (give --cv-n / --cv-s or the table's SDs to change it; docs/model.md §9)",
                parts.join(", no ")
            )
        })
    }

    /// Either used.
    pub fn or(self, other: DefaultsUsed) -> DefaultsUsed {
        DefaultsUsed { k_n: self.k_n || other.k_n, k_s: self.k_s || other.k_s }
    }
}

/// The uncertainty used at one slope, as every risk result reports it beside the numbers it
/// produced: the coefficients of variation and where each came from (`given`, `table` or
/// `default`, docs/model.md §9).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct UsedUncertainty {
    /// Coefficient of variation of k_n used.
    pub cv_n: f64,
    /// Coefficient of variation of k_s used.
    pub cv_s: f64,
    /// Where cv_n came from.
    pub cv_n_source: CvSource,
    /// Where cv_s came from.
    pub cv_s_source: CvSource,
}

impl UsedUncertainty {
    /// Whether a default CV was used for k_n and for k_s.
    pub fn defaults_used(&self) -> DefaultsUsed {
        DefaultsUsed {
            k_n: self.cv_n_source == CvSource::Default,
            k_s: self.cv_s_source == CvSource::Default,
        }
    }
}

/// The uncertainty at one slope: medians, coefficients of variation and their sources.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UncertainGround {
    /// The median ground (the interpolated table values).
    pub ground: Ground,
    /// The coefficients of variation.
    pub uncertainty: Uncertainty,
    /// Where cv_n came from.
    pub cv_n_source: CvSource,
    /// Where cv_s came from.
    pub cv_s_source: CvSource,
}

impl UncertainGround {
    /// The CVs used here and where they came from.
    pub fn used(&self) -> UsedUncertainty {
        UsedUncertainty {
            cv_n: self.uncertainty.cv_n(),
            cv_s: self.uncertainty.cv_s(),
            cv_n_source: self.cv_n_source,
            cv_s_source: self.cv_s_source,
        }
    }
}

/// A terrain table read as uncertain, by the one rule of docs/model.md §9: at each slope,
/// log-normal k_n and k_s whose medians are the interpolated table values and whose CVs
/// are the user's, else the table's SD over its value, else the defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct UncertainTerrain {
    terrain: Terrain,
    cv_n: Option<f64>,
    cv_s: Option<f64>,
}

/// Largest coefficient of variation a user may give (`--cv-n`, `--cv-s`, Python's `cv_n`):
/// sigma = sqrt(ln(1 + 100^2)) = 3.03 in ln k, a factor of 20 per standard deviation, beyond
/// any measurement. A CV of 1e308 made sigma infinite and the risk map's integration never end
/// (the server fuzz, issue 39).
pub const MAX_GIVEN_CV: f64 = 100.0;

impl UncertainTerrain {
    /// `terrain` with user-given coefficients of variation `cv_n`, `cv_s` (each finite, from 0
    /// to [`MAX_GIVEN_CV`]; errors name `cv_n` / `cv_s`), or `None` to use the table's SDs, or the
    /// defaults where the table has none.
    pub fn new(
        terrain: Terrain,
        cv_n: Option<f64>,
        cv_s: Option<f64>,
    ) -> Result<UncertainTerrain, ParamError> {
        for (key, cv) in [("cv_n", cv_n), ("cv_s", cv_s)] {
            if let Some(cv) = cv {
                if non_negative(key, cv)? > MAX_GIVEN_CV {
                    return Err(ParamError::new(
                        key,
                        cv,
                        format!("at most {MAX_GIVEN_CV} (a standard deviation {MAX_GIVEN_CV} times the value; docs/model.md §9)"),
                    ));
                }
            }
        }
        Ok(UncertainTerrain { terrain, cv_n, cv_s })
    }

    /// `terrain` with the same uncertainty at every slope (both CVs given).
    pub fn with_uncertainty(terrain: Terrain, u: Uncertainty) -> UncertainTerrain {
        UncertainTerrain { terrain, cv_n: Some(u.cv_n), cv_s: Some(u.cv_s) }
    }

    /// The underlying table.
    pub fn terrain(&self) -> &Terrain {
        &self.terrain
    }

    /// The user-given CVs (k_n, k_s), if any.
    pub fn given(&self) -> (Option<f64>, Option<f64>) {
        (self.cv_n, self.cv_s)
    }

    /// The medians, CVs and their sources at `slope`.
    pub fn sample(&self, slope: Slope) -> UncertainGround {
        let ground = self.terrain.at(slope);
        let (k_n_sd, k_s_sd) = self.terrain.sd_at(slope);
        let pick = |given: Option<f64>, sd: Option<f64>, k: f64, default: f64| match (given, sd) {
            (Some(cv), _) => (cv, CvSource::Given),
            (None, Some(sd)) if k > 0.0 && (sd / k).is_finite() => (sd / k, CvSource::Table),
            // A value extrapolated down to 0: the median is 0 and the spread irrelevant.
            (None, Some(_)) => (0.0, CvSource::Table),
            (None, None) => (default, CvSource::Default),
        };
        let (cv_n, cv_n_source) = pick(self.cv_n, k_n_sd, ground.k_n, DEFAULT_CV_N);
        let (cv_s, cv_s_source) = pick(self.cv_s, k_s_sd, ground.k_s, DEFAULT_CV_S);
        UncertainGround { ground, uncertainty: Uncertainty { cv_n, cv_s }, cv_n_source, cv_s_source }
    }

    /// The median ground and its uncertainty at `slope`.
    pub fn at(&self, slope: Slope) -> (Ground, Uncertainty) {
        let s = self.sample(slope);
        (s.ground, s.uncertainty)
    }

    /// The uncertainty at `slope`.
    pub fn uncertainty_at(&self, slope: Slope) -> Uncertainty {
        self.sample(slope).uncertainty
    }

    /// Whether a default CV is used at some slope: no CV given and some table point lacks
    /// the SD (between such a point and its neighbours the SD is not interpolated).
    pub fn defaults_used(&self) -> DefaultsUsed {
        let pts = self.terrain.points();
        DefaultsUsed {
            k_n: self.cv_n.is_none() && pts.iter().any(|p| p.k_n_sd.is_none()),
            k_s: self.cv_s.is_none() && pts.iter().any(|p| p.k_s_sd.is_none()),
        }
    }

    /// Whether a default CV is used at `slope`.
    pub fn defaults_used_at(&self, slope: Slope) -> DefaultsUsed {
        let s = self.sample(slope);
        DefaultsUsed { k_n: s.cv_n_source == CvSource::Default, k_s: s.cv_s_source == CvSource::Default }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    /// The server fuzz's hang (a risk map with --cv-n 1e308 ran for ever) is refused at the
    /// edge with the range; 100 itself is accepted.
    #[test]
    fn a_given_cv_beyond_100_is_refused() {
        let t = Terrain::constant(7e5, 2e6).unwrap();
        let e = UncertainTerrain::new(t.clone(), Some(1e308), None).unwrap_err();
        assert_eq!(e.key, "cv_n");
        assert!(e.to_string().contains("at most 100"), "{e}");
        assert_eq!(UncertainTerrain::new(t.clone(), None, Some(100.5)).unwrap_err().key, "cv_s");
        assert!(UncertainTerrain::new(t, Some(100.0), Some(0.0)).is_ok());
    }

    use super::*;
    use crate::terrain::{TerrainPoint, TerrainSpec};

    fn slope(d: f64) -> Slope {
        Slope::from_degrees(d).unwrap()
    }

    /// (slope_deg, k_n, k_s, k_n_sd, k_s_sd).
    type Point = (f64, f64, f64, Option<f64>, Option<f64>);

    pub(crate) fn table(points: &[Point], repose: Option<f64>) -> Terrain {
        Terrain::new(TerrainSpec {
            name: None,
            repose_deg: repose,
            points: points
                .iter()
                .map(|&(slope_deg, k_n, k_s, k_n_sd, k_s_sd)| TerrainPoint {
                    slope_deg,
                    k_n,
                    k_s,
                    k_n_sd,
                    k_s_sd,
                })
                .collect(),
        })
        .unwrap()
    }

    /// The rule, worked by hand: at 10 deg between 0 deg (k_s 2e6 +- 2e5) and 20 deg
    /// (1e6 +- 3e5) the table gives k_s 1.5e6 +- 2.5e5, cv 1/6; k_n 7e5 +- 7e4, cv 0.1.
    #[test]
    fn given_overrides_table_which_overrides_default() {
        let t = table(&[(0.0, 7e5, 2e6, Some(7e4), Some(2e5)), (20.0, 7e5, 1e6, Some(7e4), Some(3e5))], None);
        let s = UncertainTerrain::new(t.clone(), None, None).unwrap().sample(slope(10.0));
        assert!((s.ground.k_s - 1.5e6).abs() < 1e-6);
        assert!(
            (s.uncertainty.cv_s() - 1.0 / 6.0).abs() < 1e-12 && (s.uncertainty.cv_n() - 0.1).abs() < 1e-12
        );
        assert_eq!((s.cv_n_source, s.cv_s_source), (CvSource::Table, CvSource::Table));
        // A given CV replaces the table's spread for its variable only.
        let u = UncertainTerrain::new(t.clone(), Some(0.25), None).unwrap();
        let s = u.sample(slope(10.0));
        assert!(
            (s.uncertainty.cv_n() - 0.25).abs() < 1e-15 && (s.uncertainty.cv_s() - 1.0 / 6.0).abs() < 1e-12
        );
        assert_eq!((s.cv_n_source, s.cv_s_source), (CvSource::Given, CvSource::Table));
        assert!(!u.defaults_used().any());
        // No SDs and nothing given: the defaults, and the terrain says so.
        let bare = UncertainTerrain::new(Terrain::constant(7e5, 2e6).unwrap(), None, Some(0.3)).unwrap();
        let s = bare.sample(slope(12.0));
        assert_eq!((s.uncertainty.cv_n(), s.uncertainty.cv_s()), (0.1, 0.3));
        assert_eq!(bare.defaults_used(), DefaultsUsed { k_n: true, k_s: false });
        assert!(bare.defaults_used().note().unwrap().contains("default cv k_n = 0.1"));
        assert_eq!(
            UncertainTerrain::new(Terrain::constant(1.0, 1.0).unwrap(), Some(-0.1), None).unwrap_err().key,
            "cv_n"
        );
    }

    /// A table with an SD at one point only: between that point and one without, the SD is
    /// not interpolated and the default applies there.
    #[test]
    fn partial_sds_fall_back_to_the_default_where_missing() {
        let t = table(&[(0.0, 7e5, 2e6, Some(1.4e5), None), (20.0, 7e5, 1e6, None, None)], None);
        let u = UncertainTerrain::new(t, None, None).unwrap();
        let s = u.sample(slope(0.0));
        assert_eq!((s.cv_n_source, s.uncertainty.cv_n()), (CvSource::Table, 0.2));
        let s = u.sample(slope(10.0));
        assert_eq!((s.cv_n_source, s.uncertainty.cv_n()), (CvSource::Default, DEFAULT_CV_N));
        assert_eq!(u.defaults_used(), DefaultsUsed { k_n: true, k_s: true });
        assert_eq!(u.defaults_used_at(slope(0.0)), DefaultsUsed { k_n: false, k_s: true });
    }
}
