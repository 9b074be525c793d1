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
use crate::field::{Field, Fields, Table};
use crate::params::Params;

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

/// `--depth-window`: k_n's depth window instead of the one found.
pub const DEPTH_WINDOW: Field = Field::text("depth-window", "MIN:MAX")
    .keyword("depth_window")
    .unit("m")
    .range("0 <= MIN < MAX")
    .help("Fit k_n over this depth window, metres, instead of finding it (e.g. 0.005:0.03)");
/// `--plateau-from`: where the shear plateau starts instead of where it is found.
pub const PLATEAU_FROM: Field = Field::number("plateau-from", "M")
    .keyword("plateau_from")
    .unit("m")
    .range("at least 0")
    .help("Shear plateau starts at this displacement, metres, instead of being found (e.g. 0.02)");
/// `--air-curve`: subtract the in-air run's curve (Python's `air="curve"`).
pub const AIR_CURVE: Field = Field::switch("air-curve").conflicts(&["air-mean"]).help(
    "Subtract the in-air run's force curve against position (default: its mean, or its fitted \
     line when it has a significant trend)",
);
/// `--air-mean`: subtract the in-air run's mean (Python's `air="mean"`).
pub const AIR_MEAN: Field = Field::switch("air-mean")
    .help("Subtract the in-air run's mean force even when it has a significant trend");
/// `--skip-malformed`: skip rows with a cell that is not a number.
pub const SKIP_MALFORMED: Field = Field::switch("skip-malformed")
    .keyword("skip_malformed")
    .help("Skip rows with a cell that is not a number (counted per trial) instead of stopping");
/// `--counts-per-newton`: the load cell's counts per newton.
pub const COUNTS_PER_NEWTON: Field = Field::number("counts-per-newton", "COUNTS")
    .keyword("counts_per_newton")
    .range("greater than 0")
    .help("Load-cell counts per newton, for recordings with a force_counts column");

/// `fit`'s own fields (the manifest is its positional argument, Python's first). Python's
/// `air` (`"auto"`, `"curve"` or `"mean"`) is the two switches `--air-curve` and `--air-mean`
/// in one keyword.
pub const FIELDS: Table = Table {
    command: "fit",
    fields: &[DEPTH_WINDOW, PLATEAU_FROM, AIR_CURVE, AIR_MEAN, SKIP_MALFORMED, COUNTS_PER_NEWTON],
};

impl Fields for FitRequest {
    const TABLE: Table = FIELDS;
}

/// Python's `air` keyword: its words, in the order of [`AirMode`]'s variants.
pub const AIR_WORDS: [(&str, AirMode); 3] =
    [("auto", AirMode::Auto), ("curve", AirMode::Curve), ("mean", AirMode::Mean)];

/// Parses a depth window `MIN:MAX`, metres, `0 <= MIN < MAX` (the command line's form).
pub fn parse_depth_window(text: &str) -> Result<(f64, f64)> {
    let bad = || {
        RequestError::invalid(
            DEPTH_WINDOW.flag,
            format!(
                "{} `{text}` must be MIN:MAX in metres with 0 <= MIN < MAX, e.g. 0.005:0.03",
                DEPTH_WINDOW.long()
            ),
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
    /// The request of the flags given, `params` ([`FIELDS`]), on the campaign of `manifest`:
    /// the one raw-to-typed step of the command line. Refuses any other key.
    pub fn from_fields(manifest: PathBuf, params: &[(String, String)]) -> Result<FitRequest> {
        let mut p = Params::new(FIELDS.command, params);
        let depth_window = DEPTH_WINDOW.text_in(&mut p)?.map(parse_depth_window).transpose()?;
        let plateau_from = PLATEAU_FROM.number_in(&mut p)?;
        let air = match (AIR_CURVE.switch_in(&mut p)?, AIR_MEAN.switch_in(&mut p)?) {
            (true, true) => {
                return Err(RequestError::invalid(
                    AIR_CURVE.flag,
                    format!("{} cannot be used with {}", AIR_CURVE.long(), AIR_MEAN.long()),
                ))
            }
            (true, false) => AirMode::Curve,
            (false, true) => AirMode::Mean,
            (false, false) => AirMode::Auto,
        };
        let counts_per_newton = COUNTS_PER_NEWTON.number_in(&mut p)?;
        let skip_malformed = SKIP_MALFORMED.switch_in(&mut p)?;
        p.finish()?;
        Ok(FitRequest { manifest, depth_window, plateau_from, air, counts_per_newton, skip_malformed })
    }

    /// Python's `air` keyword as the mode it names, or an error listing its words.
    pub fn air_mode(word: &str) -> Result<AirMode> {
        AIR_WORDS.iter().find(|(w, _)| *w == word).map(|&(_, mode)| mode).ok_or_else(|| {
            let words: Vec<String> = AIR_WORDS.iter().map(|(w, _)| format!("{w:?}")).collect();
            let (last, rest) = words.split_last().expect("three words");
            RequestError::invalid(
                AIR_CURVE.flag,
                format!("air = {word:?} must be {} or {last}", rest.join(", ")),
            )
        })
    }

    /// The analysis's options, checked; errors name the field in `words`.
    pub fn options(&self, words: Words) -> Result<FitOptions> {
        if let Some((a, b)) = self.depth_window.filter(|w| !window_is_valid(*w)) {
            return Err(RequestError::invalid(
                DEPTH_WINDOW.flag,
                format!(
                    "{} = ({a}, {b}) must be (MIN, MAX) in metres with 0 <= MIN < MAX, e.g. (0.005, 0.03)",
                    words.name(DEPTH_WINDOW.flag)
                ),
            ));
        }
        if let Some(x) = self.plateau_from.filter(|x| !(x.is_finite() && *x >= 0.0)) {
            return Err(RequestError::invalid(
                PLATEAU_FROM.flag,
                format!(
                    "{} = {x} must be a displacement in metres of at least 0",
                    words.name(PLATEAU_FROM.flag)
                ),
            ));
        }
        Ok(FitOptions { depth_window: self.depth_window, plateau_from: self.plateau_from, air: self.air })
    }

    /// The reading options, checked.
    fn read_options(&self, words: Words) -> Result<ReadOptions> {
        if let Some(c) = self.counts_per_newton.filter(|c| !(c.is_finite() && *c > 0.0)) {
            return Err(RequestError::invalid(
                COUNTS_PER_NEWTON.flag,
                format!(
                    "{} = {c} must be a finite number greater than 0",
                    words.name(COUNTS_PER_NEWTON.flag)
                ),
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
                let hint = words.name(SKIP_MALFORMED.flag);
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

    fn pairs(list: &[(&str, &str)]) -> Vec<(String, String)> {
        list.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()
    }

    /// The flags read by the table: none given is the automatic analysis; each given flag
    /// sets its value; the two air switches together, or a key of no field, are refused.
    #[test]
    fn flags_are_read_by_the_table() {
        let manifest = PathBuf::from("m.toml");
        assert_eq!(
            FitRequest::from_fields(manifest.clone(), &[]).unwrap(),
            FitRequest { manifest: manifest.clone(), ..request() }
        );
        let given = pairs(&[
            ("depth-window", "0.005:0.03"),
            ("plateau-from", "0.02"),
            ("air-mean", "true"),
            ("counts-per-newton", "2000"),
            ("skip-malformed", "true"),
        ]);
        let r = FitRequest::from_fields(manifest.clone(), &given).unwrap();
        assert_eq!(
            (r.depth_window, r.plateau_from, r.air, r.counts_per_newton, r.skip_malformed),
            (Some((0.005, 0.03)), Some(0.02), AirMode::Mean, Some(2000.0), true)
        );
        let both = pairs(&[("air-curve", "true"), ("air-mean", "true")]);
        let e = FitRequest::from_fields(manifest.clone(), &both).unwrap_err();
        assert_eq!(e.message(), "--air-curve cannot be used with --air-mean");
        let e = FitRequest::from_fields(manifest.clone(), &pairs(&[("plateau-from", "x")])).unwrap_err();
        assert_eq!(e.message(), "--plateau-from = `x` is not a number");
        let e = FitRequest::from_fields(manifest, &pairs(&[("slope", "1")])).unwrap_err();
        assert!(e.message().starts_with("unknown parameter `slope`: fit takes"), "{}", e.message());
        assert_eq!(FitRequest::air_mode("curve").unwrap(), AirMode::Curve);
        assert_eq!(
            FitRequest::air_mode("x").unwrap_err().message(),
            "air = \"x\" must be \"auto\", \"curve\" or \"mean\""
        );
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
