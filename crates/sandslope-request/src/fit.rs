//! `fit`'s request: k_n and k_s per slope from a load-cell campaign (docs/model.md §10,
//! docs/measurements.md), read from its manifest and fitted by one library call,
//! [`sandslope::measure::fit_campaign`]. What `sandslope fit` and Python's `sandslope.fit`
//! both run.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use sandslope::measure::{fit_campaign, AirMode, Campaign, CampaignError, FitOptions, Setup};
use sandslope::{Terrain, TerrainSpec};
use sandslope_io::measurements::{load_manifest, read_trials, MalformedCell, Manifest, ReadOptions};

use crate::error::{RequestError, Result, Words};

/// The inputs of a load-cell fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitRequest {
    /// The campaign's manifest (TOML); trial files are relative to it (field `manifest`).
    pub manifest: PathBuf,
    /// Fit k_n over this depth window, metres, `0 <= MIN < MAX`, instead of finding it
    /// (field `depth-window`).
    pub depth_window: Option<(f64, f64)>,
    /// Start the shear plateau at this displacement, metres, instead of finding it (field
    /// `plateau-from`).
    pub plateau_from: Option<f64>,
    /// How the in-air offset is chosen (fields `air-curve`, `air-mean`; Python's `air`).
    pub air: AirMode,
    /// Load-cell counts per newton, for recordings with a `force_counts` column (field
    /// `counts-per-newton`).
    pub counts_per_newton: Option<f64>,
    /// Skip rows with a cell that is not a number instead of stopping (field `skip-malformed`).
    pub skip_malformed: bool,
}

/// A fitted campaign: the manifest read, the library's campaign and the terrain it gives.
#[derive(Debug, Clone)]
pub struct FitAnswer {
    /// The manifest.
    pub manifest: Manifest,
    /// Every trial's fit and the per-slope table.
    pub campaign: Campaign,
    /// The fitted terrain (docs/model.md §7), with the manifest's name and angle of repose.
    pub terrain: Terrain,
}

/// Parses a depth window `MIN:MAX`, metres, `0 <= MIN < MAX` (the command line's form).
pub fn parse_depth_window(text: &str) -> Result<(f64, f64)> {
    let bad = || {
        RequestError::invalid(
            "depth-window",
            format!("--depth-window `{text}` must be MIN:MAX in metres with 0 <= MIN < MAX, e.g. 0.005:0.03"),
        )
    };
    let (a, b) = text.split_once(':').ok_or_else(bad)?;
    let a: f64 = a.trim().parse().map_err(|_| bad())?;
    let b: f64 = b.trim().parse().map_err(|_| bad())?;
    if !window_is_valid((a, b)) {
        return Err(bad());
    }
    Ok((a, b))
}

fn window_is_valid((a, b): (f64, f64)) -> bool {
    a.is_finite() && b.is_finite() && a >= 0.0 && a < b
}

impl FitRequest {
    /// The analysis's options, checked; errors name the field in `words`.
    pub fn options(&self, words: Words) -> Result<FitOptions> {
        if let Some((a, b)) = self.depth_window.filter(|w| !window_is_valid(*w)) {
            let field = "depth-window";
            return Err(RequestError::invalid(
                field,
                format!(
                    "{} = ({a}, {b}) must be (MIN, MAX) in metres with 0 <= MIN < MAX, e.g. (0.005, 0.03)",
                    words.name(field)
                ),
            ));
        }
        if let Some(x) = self.plateau_from.filter(|x| !(x.is_finite() && *x >= 0.0)) {
            let field = "plateau-from";
            return Err(RequestError::invalid(
                field,
                format!("{} = {x} must be a displacement in metres of at least 0", words.name(field)),
            ));
        }
        Ok(FitOptions { depth_window: self.depth_window, plateau_from: self.plateau_from, air: self.air })
    }

    /// The reading options, checked.
    fn read_options(&self, words: Words) -> Result<ReadOptions> {
        if let Some(c) = self.counts_per_newton.filter(|c| !(c.is_finite() && *c > 0.0)) {
            let field = "counts-per-newton";
            return Err(RequestError::invalid(
                field,
                format!("{} = {c} must be a finite number greater than 0", words.name(field)),
            ));
        }
        Ok(ReadOptions { counts_per_newton: self.counts_per_newton, skip_malformed: self.skip_malformed })
    }

    /// Every value checked, before any file is read.
    pub fn check(&self, words: Words) -> Result<()> {
        self.options(words)?;
        self.read_options(words).map(|_| ())
    }

    /// Reads the manifest and its trials and fits them. Errors name the manifest or the
    /// trial's file (and line); a cell that is not a number suggests `skip-malformed`.
    pub fn answer(&self, words: Words) -> Result<FitAnswer> {
        let options = self.options(words)?;
        let manifest =
            load_manifest(&self.manifest).map_err(|e| RequestError::from_error(Some("manifest"), e))?;
        let read = self.read_options(words)?;
        let trials = read_trials(&manifest, read).map_err(|e| {
            if !self.skip_malformed && e.downcast_ref::<MalformedCell>().is_some() {
                let hint = words.name("skip-malformed");
                RequestError::from_error(
                    Some("manifest"),
                    anyhow::anyhow!("{e:#}; {hint} skips such rows and counts them"),
                )
            } else {
                RequestError::from_error(Some("manifest"), e)
            }
        })?;
        let setup = Setup { disk_area_m2: manifest.disk_area_m2, plate: manifest.plate };
        let dir = manifest.path.parent().map(|d| d.join("")).unwrap_or_default();
        let campaign = fit_campaign(&trials, &setup, &options).map_err(|e| {
            let e = match e {
                CampaignError::Trial { .. } | CampaignError::TooFewRows { .. } => {
                    anyhow::anyhow!("{}{e}", dir.display())
                }
                _ => anyhow::anyhow!("{}: {e}", manifest.path.display()),
            };
            RequestError::from_error(Some("manifest"), e)
        })?;
        let spec = TerrainSpec {
            name: manifest.name.clone(),
            repose_deg: manifest.repose_deg,
            points: campaign.terrain_points(),
        };
        let terrain = Terrain::new(spec).map_err(|e| {
            let e = anyhow::anyhow!("{}: fitted terrain is invalid: {e}", manifest.path.display());
            RequestError::from_error(Some("manifest"), e)
        })?;
        Ok(FitAnswer { manifest, campaign, terrain })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request() -> FitRequest {
        FitRequest {
            manifest: PathBuf::from("no-such-manifest.toml"),
            depth_window: None,
            plateau_from: None,
            air: AirMode::Auto,
            counts_per_newton: None,
            skip_malformed: false,
        }
    }

    /// Each check names its field in the front end's words, before any file is read.
    #[test]
    fn checks_name_the_field_as_each_front_end_does() {
        let bad = FitRequest { plateau_from: Some(-1.0), ..request() };
        let e = bad.check(Words::Flag).unwrap_err();
        assert_eq!(e.field(), Some("plateau-from"));
        assert_eq!(e.message(), "--plateau-from = -1 must be a displacement in metres of at least 0");
        let e = bad.check(Words::Keyword).unwrap_err();
        assert_eq!(e.message(), "plateau_from = -1 must be a displacement in metres of at least 0");
        let e =
            FitRequest { depth_window: Some((0.03, 0.005)), ..request() }.check(Words::Keyword).unwrap_err();
        assert!(
            e.message().starts_with("depth_window = (0.03, 0.005) must be (MIN, MAX)"),
            "{}",
            e.message()
        );
        let e = FitRequest { counts_per_newton: Some(0.0), ..request() }.check(Words::Flag).unwrap_err();
        assert_eq!(e.message(), "--counts-per-newton = 0 must be a finite number greater than 0");
        assert!(request().check(Words::Flag).is_ok());
        assert_eq!(request().answer(Words::Flag).unwrap_err().field(), Some("manifest"));
    }

    #[test]
    fn depth_windows_parse_from_min_max() {
        assert_eq!(parse_depth_window("0.005:0.03").unwrap(), (0.005, 0.03));
        for bad in ["0.03:0.01", "0.01", "a:0.03", "-0.01:0.03", "0.01:inf", "0.01:0.01", "a:b"] {
            let e = parse_depth_window(bad).unwrap_err();
            assert_eq!(e.field(), Some("depth-window"), "{bad}");
            assert!(e.message().starts_with(&format!("--depth-window `{bad}` must be MIN:MAX")), "{bad}");
        }
    }
}
