//! The one grammar of every front end for the values that are not plain numbers: slope lists
//! (`DEG`, `DEG,DEG,...`, `MIN:MAX:N`), grid axes (`MIN:MAX:N[:log|:lin]`), failure
//! probabilities and the terrain's uncertainty. Errors name the field (the flag without its
//! dashes) and the accepted forms.

use sandslope::risk::UncertainTerrain;
use sandslope::{Axis, AxisScale, Slope, Terrain};

use crate::error::{check_range_in, RequestError, Result, Words};
use crate::field::Field;

/// Which slopes a slope list accepts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SlopeSign {
    /// Climbing only: 0 <= deg < 90.
    Uphill,
    /// Signed inclinations, -90 < deg < 90 (a descent is felt as the climb of its size,
    /// docs/model.md §8).
    Signed,
}

/// Parses a slope list given to `field`: `DEG`, `DEG,DEG,...` or `MIN:MAX:N` (N evenly spaced
/// slopes, both ends included), in degrees, with at most `max` slopes. N and the list's length
/// are checked against `max` before anything is expanded (`0:24:99999999999` is refused at
/// once, not after allocating 800 GB). The one slope-list grammar of every command.
pub fn parse_slope_list(field: &str, text: &str, sign: SlopeSign, max: usize) -> Result<Vec<f64>> {
    let flag = format!("--{field}");
    let bad = |message: String| RequestError::invalid(field, message);
    let number = |s: &str| -> Result<f64> {
        let v: f64 = s
            .trim()
            .parse()
            .map_err(|_| bad(format!("{flag}: `{}` is not a number (in {text})", s.trim())))?;
        match sign {
            SlopeSign::Uphill => Slope::from_degrees(v).map(|_| ()),
            SlopeSign::Signed => Slope::from_signed_degrees(v).map(|_| ()),
        }
        .map_err(|e| bad(e.renamed(&flag).to_string()))?;
        Ok(v)
    };
    if text.contains(':') {
        let parts: Vec<&str> = text.split(':').collect();
        let [lo, hi, n] = parts.as_slice() else {
            return Err(bad(format!(
                "{flag} = {text} must be DEG, a comma list DEG,DEG,... or MIN:MAX:N (e.g. 0:24:13)"
            )));
        };
        let count = n.trim();
        let (lo, hi) = (number(lo)?, number(hi)?);
        let n: usize = count.parse().ok().filter(|n| (2..=max).contains(n)).ok_or_else(|| {
            // The third field is a count, not a step: `0:30:1` most likely meant 1-degree
            // steps, which is the count (MAX - MIN) / step + 1, suggested where whole.
            let step: Option<f64> = count.parse().ok().filter(|s: &f64| *s > 0.0 && hi > lo);
            let hint = step
                .map(|step| (hi - lo) / step + 1.0)
                .filter(|k| (k - k.round()).abs() < 1e-9 && (2.0..=max as f64).contains(&k.round()))
                .map(|k| {
                    format!(
                        "; the third field is the number of slopes, not a step: for steps of {count} deg from {lo} to {hi} write {lo}:{hi}:{}",
                        k.round()
                    )
                })
                .unwrap_or_else(|| "; the third field is the number of slopes, not a step".into());
            bad(format!("{flag}: N `{count}` must be a whole number from 2 to {max} (in {text}){hint}"))
        })?;
        if hi <= lo {
            return Err(bad(format!("{flag} = {text}: MAX must be greater than MIN")));
        }
        return Ok((0..n).map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64).collect());
    }
    let count = text.split(',').count();
    if count > max {
        return Err(bad(format!("{flag} lists {count} slopes; at most {max} are allowed")));
    }
    text.split(',').map(number).collect()
}

/// The numbers of an axis `MIN:MAX:N[:log|:lin]`, before the library checks their ranges.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AxisRange {
    /// First value.
    pub min: f64,
    /// Last value.
    pub max: f64,
    /// Number of values, as written (each use checks it is at least 2).
    pub n: usize,
    /// Spacing.
    pub scale: AxisScale,
}

/// What a grid axis spans, which decides its spacing when none is written: the one default
/// rule of every axis (`--help` and docs/phase-and-risk.md, docs/design.md state it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AxisQuantity {
    /// A strength, k_n or k_s (`phase --k-n`, `risk --map --k-s`): strengths span decades, so
    /// log spacing unless `:lin` is written.
    Strength,
    /// A robot quantity (`design --vary KEY=...`): they vary over less than a decade, so linear
    /// spacing unless `:log` is written.
    Robot,
}

impl AxisQuantity {
    /// The spacing of an axis of this quantity when none is written.
    pub fn default_scale(self) -> AxisScale {
        match self {
            AxisQuantity::Strength => AxisScale::Log,
            AxisQuantity::Robot => AxisScale::Linear,
        }
    }
}

/// The one grammar of a grid axis, `MIN:MAX:N[:log|:lin]`, for every field that takes one
/// (`k-n`, `k-s`, `design --vary KEY=...`); without `:log` or `:lin` the spacing is the one
/// rule's for `quantity` ([`AxisQuantity::default_scale`]). `None` when `text` is not of that
/// shape (each use names its own forms); errors name `field`, begin with `prefix` and quote
/// `context`.
pub fn parse_axis_range(
    field: &str,
    text: &str,
    quantity: AxisQuantity,
    prefix: &str,
    context: &str,
) -> Result<Option<AxisRange>> {
    let parts: Vec<&str> = text.split(':').map(str::trim).collect();
    if !(3..=4).contains(&parts.len()) {
        return Ok(None);
    }
    let number = |what: &str, s: &str| -> Result<f64> {
        s.parse::<f64>().map_err(|_| {
            RequestError::invalid(field, format!("{prefix} {what} `{s}` is not a number (in {context})"))
        })
    };
    let (min, max) = (number("MIN", parts[0])?, number("MAX", parts[1])?);
    // N < 2 is left to the use: the library's axis names its own key (`--k-n points = 0`).
    let n: usize = parts[2].parse().map_err(|_| {
        RequestError::invalid(
            field,
            format!("{prefix} N `{}` must be a whole number of at least 2 (in {context})", parts[2]),
        )
    })?;
    let scale = match parts.get(3).map(|s| s.to_ascii_lowercase()).as_deref() {
        None => quantity.default_scale(),
        Some("log") => AxisScale::Log,
        Some("lin") | Some("linear") => AxisScale::Linear,
        Some(other) => {
            return Err(RequestError::invalid(
                field,
                format!("{prefix} spacing `{other}` must be `log` or `lin` (in {context})"),
            ))
        }
    };
    Ok(Some(AxisRange { min, max, n, scale }))
}

/// Parses a strength axis `MIN:MAX:N[:log|:lin]` given to `field` (log spacing unless `:lin`,
/// [`AxisQuantity::Strength`]), into its numbers.
pub fn parse_strength_axis(field: &str, text: &str) -> Result<AxisRange> {
    let flag = format!("--{field}");
    parse_axis_range(field, text, AxisQuantity::Strength, &format!("{flag}:"), text)?.ok_or_else(|| {
        RequestError::invalid(
            field,
            format!("{flag} = {text} must be MIN:MAX:N or MIN:MAX:N:log or MIN:MAX:N:lin (e.g. 1e4:1e7:400)"),
        )
    })
}

/// The library's axis of these numbers, its errors naming `field`.
pub fn axis(field: &str, range: AxisRange) -> Result<Axis> {
    Axis::new(&format!("--{field}"), range.min, range.max, range.n, range.scale)
        .map_err(|e| RequestError::invalid(field, e))
}

/// The axis whose values are `v`, given as values (Python's NumPy axes): evenly spaced values
/// (`np.linspace`) or evenly spaced logarithms (`np.geomspace`, `np.logspace`), to a relative
/// 1e-9, so that maps run on exactly the library's grids. `key` names the values in errors and
/// is the error's field.
pub fn axis_of_values(key: &str, v: &[f64]) -> Result<Axis> {
    let refuse = |message: String| RequestError::invalid(key, message);
    if v.len() < 2 {
        return Err(refuse(format!("{key} has {} values; at least 2 are needed", v.len())));
    }
    let (min, max) = (v[0], v[v.len() - 1]);
    let matches = |a: &Axis| {
        v.iter().enumerate().all(|(i, &x)| {
            let y = a.value(i);
            (x - y).abs() <= 1e-9 * x.abs().max(y.abs()).max(f64::MIN_POSITIVE)
        })
    };
    let linear = Axis::new(key, min, max, v.len(), AxisScale::Linear).map_err(|e| refuse(e.to_string()))?;
    if matches(&linear) {
        return Ok(linear);
    }
    if min > 0.0 {
        let log = Axis::new(key, min, max, v.len(), AxisScale::Log).map_err(|e| refuse(e.to_string()))?;
        if matches(&log) {
            return Ok(log);
        }
    }
    Err(refuse(format!(
        "{key} must be ascending and evenly spaced (np.linspace) or evenly spaced in logarithm \
         (np.geomspace), from {min} to {max}"
    )))
}

impl AxisRange {
    /// The range of an axis already built (its values are the axis's own again).
    pub fn of(axis: &Axis) -> AxisRange {
        AxisRange { min: axis.min(), max: axis.max(), n: axis.len(), scale: axis.scale() }
    }
}

/// Parses a failure probability: a number strictly between 0 and 1.
pub fn parse_max_risk(text: &str) -> std::result::Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(p) if p > 0.0 && p < 1.0 => Ok(p),
        Ok(p) => Err(format!(
            "{p} is not a failure probability strictly between 0 and 1 (e.g. {})",
            sandslope::risk::DEFAULT_MAX_RISK
        )),
        Err(_) => Err(format!(
            "`{text}` is not a number: expected a failure probability strictly between 0 and 1 (e.g. {})",
            sandslope::risk::DEFAULT_MAX_RISK
        )),
    }
}

/// `--cv-n` (risk, plan, design, infer): the coefficient of variation of k_n instead of the terrain's.
pub const CV_N: Field = Field::number("cv-n", "CV")
    .keyword("cv_n")
    .key("cv_n")
    .range("at least 0")
    .fallback(sandslope::risk::DEFAULT_CV_N)
    .help(
        "Coefficient of variation of k_n (sd / value) at every slope, instead of the terrain's \
         k_n_sd; without either, {fallback} (docs/model.md §9)",
    );
/// `--cv-s` (risk, plan, design, infer): the coefficient of variation of k_s instead of the terrain's.
pub const CV_S: Field = Field::number("cv-s", "CV")
    .keyword("cv_s")
    .key("cv_s")
    .range("at least 0")
    .fallback(sandslope::risk::DEFAULT_CV_S)
    .help(
        "Coefficient of variation of k_s (sd / value) at every slope, instead of the terrain's \
         k_s_sd; without either, {fallback} (docs/model.md §9)",
    );
/// The terrain's uncertainty by the one rule of docs/model.md §9 (a given CV, else the table's
/// SD over its value, else the library's `DEFAULT_CV_N` / `DEFAULT_CV_S`), with the note to
/// print when a default is used anywhere on the table. Errors name the field: `--cv-n = -1 must be a finite number of at least 0`.
pub fn uncertain_terrain(
    terrain: Terrain,
    cv_n: Option<f64>,
    cv_s: Option<f64>,
) -> Result<(UncertainTerrain, Option<String>)> {
    uncertain_terrain_in(Words::Flag, terrain, cv_n, cv_s)
}

/// [`uncertain_terrain`], naming the CVs in the front end's `words` (`--cv-s`, `cv_s`).
pub fn uncertain_terrain_in(
    words: Words,
    terrain: Terrain,
    cv_n: Option<f64>,
    cv_s: Option<f64>,
) -> Result<(UncertainTerrain, Option<String>)> {
    check_cvs_in(words, cv_n, cv_s)?;
    let u = UncertainTerrain::new(terrain, cv_n, cv_s).map_err(|e| {
        let field = if e.key == CV_S.key { &CV_S } else { &CV_N };
        RequestError::invalid(field.flag, e.renamed(words.name(field.flag)))
    })?;
    let note = u.defaults_used().note();
    Ok((u, note))
}

/// Checks the CVs alone, before any file is read: each a finite number of at least 0 (the
/// library's [`UncertainTerrain::new`] has the upper bound).
pub fn check_cvs(cv_n: Option<f64>, cv_s: Option<f64>) -> Result<()> {
    check_cvs_in(Words::Flag, cv_n, cv_s)
}

/// [`check_cvs`], naming the CVs in the front end's `words`.
pub fn check_cvs_in(words: Words, cv_n: Option<f64>, cv_s: Option<f64>) -> Result<()> {
    for (field, cv) in [(&CV_N, cv_n), (&CV_S, cv_s)] {
        if let Some(cv) = cv {
            check_range_in(words, field.flag, cv, 0.0, f64::INFINITY)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_axis(field: &str, text: &str) -> Result<Axis> {
        axis(field, parse_strength_axis(field, text)?)
    }

    #[test]
    fn axes_parse_and_reject_bad_input_naming_the_field() {
        let a = parse_axis("k-n", "1e4:1e7:31").unwrap();
        assert_eq!((a.min(), a.max(), a.len(), a.scale()), (1e4, 1e7, 31, AxisScale::Log));
        assert_eq!(parse_axis("k-n", "0:10:11:lin").unwrap().scale(), AxisScale::Linear);
        for bad in ["1e4:1e7", "a:1e7:3", "1e4:1e7:x", "1e4:1e7:3:cubic", "0:1e7:3", "1e7:1e4:3", "1e4:1e7:1"]
        {
            let e = parse_axis("k-n", bad).unwrap_err();
            assert_eq!(e.field(), Some("k-n"), "{bad}");
            assert!(e.message().contains("--k-n"), "{bad}: {}", e.message());
        }
    }
}
