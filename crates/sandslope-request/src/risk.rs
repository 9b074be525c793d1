//! [`RiskRequest`]: the probability of failure on an uncertain terrain (docs/model.md §9): a
//! p_fail curve over slopes, the safe-slope limit, the heaviest safe mass or payload envelope,
//! or a map over median (k_n, k_s).

use std::sync::atomic::{AtomicBool, Ordering};

use serde::{Deserialize, Serialize};

use sandslope::limits::{MAX_RISK_MAP_CELLS, MAX_RISK_SLOPES};
use sandslope::risk::{
    payload_envelope, risk_curve, risk_map, safe_mass, safe_slope, DefaultsUsed, RiskAnswer, RiskPoint,
    SafeSlope, UncertainTerrain,
};
use sandslope::{Axis, ParamError, Robot, SignedSlope, Terrain};

use crate::error::{RequestError, Result, Words};
use crate::field::{Field, Fields, Kind, Table};
use crate::grammar::{self, parse_slope_list, AxisRange, SlopeSign};
use crate::params::Params;
use crate::scenario::{load_terrain, RobotRequest, TERRAIN};

/// What a risk request solves for besides the curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Solve {
    /// The safe-slope limit: the steepest slope with p_fail below `max_risk`.
    Slope,
    /// The heaviest total mass with p_fail below `max_risk` at each slope (several slopes:
    /// the payload envelope).
    Mass,
    /// The payload envelope, even at one slope (Python's `payload_envelope`; the field
    /// `solve` takes `slope` or `mass`).
    Envelope,
}

/// The grid of a risk map over median (k_n, k_s): each axis given, or the default around the
/// terrain's medians at the map's slope.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct RiskMapGrid {
    /// Median k_n axis, N/m^3 (field `k-n`).
    pub k_n: Option<AxisRange>,
    /// Median k_s axis, N/m^3 (field `k-s`).
    pub k_s: Option<AxisRange>,
}

/// The inputs of `risk` (and `/api/risk`): the robot and terrain by name, and the question.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RiskRequest {
    /// The robot.
    pub robot: RobotRequest,
    /// A terrain TOML file or a built-in preset (field `terrain`).
    pub terrain: String,
    /// What is asked about them.
    #[serde(flatten)]
    pub question: RiskQuestion,
}

/// What a risk request asks about a robot and a terrain, whichever way they were given: by
/// name in a [`RiskRequest`], or already read (Python's `Robot` and `Terrain`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RiskQuestion {
    /// Slopes, degrees (field `slope`: `DEG`, `DEG,DEG,...` or `MIN:MAX:N`; default 0:24:7;
    /// Python's `slope_deg`).
    pub slopes: Vec<f64>,
    /// Coefficient of variation of k_n at every slope instead of the terrain's (field `cv-n`).
    pub cv_n: Option<f64>,
    /// Coefficient of variation of k_s at every slope instead of the terrain's (field `cv-s`).
    pub cv_s: Option<f64>,
    /// Largest acceptable failure probability (field `max-risk`, default [`MAX_RISK`]'s).
    pub max_risk: f64,
    /// What to solve for (field `solve`: `slope` or `mass`).
    pub solve: Option<Solve>,
    /// A map at the first slope instead (field `map`, its axes `k-n` and `k-s`).
    pub map: Option<RiskMapGrid>,
}

/// How much work one [`RiskRequest::answer`] may do; more is an error naming the limit.
#[derive(Debug, Clone, Copy)]
pub struct AnswerLimits {
    /// Most slopes of a p_fail curve (each a quadrature).
    pub curve_slopes: usize,
    /// Most slopes of a payload envelope (each a search over masses).
    pub envelope_slopes: usize,
    /// Most map cells.
    pub map_cells: u128,
}

impl AnswerLimits {
    /// The library's own limits (the command line's and Python's).
    pub const LIBRARY: AnswerLimits = AnswerLimits {
        curve_slopes: MAX_RISK_SLOPES,
        envelope_slopes: MAX_RISK_SLOPES,
        map_cells: MAX_RISK_MAP_CELLS as u128,
    };
}

/// `--slope`: the slopes of the curve (the map's is the first).
pub const SLOPE: Field = Field::text("slope", "DEG|LIST|MIN:MAX:N")
    .keyword("slope_deg")
    .key("slope_deg")
    .unit("deg")
    .default("0:24:7")
    .range("-90 to 90 each, at most 65,536 (docs/model.md §9)")
    .help("Slope(s), degrees: one value, a comma list (0,10,20) or a range MIN:MAX:N (0:24:13)");
/// `--cv-n` and `--cv-s`: the terrain's uncertainty, the fields of its one rule.
pub use crate::grammar::{CV_N, CV_S};
/// `--max-risk`: the largest acceptable failure probability (the library's
/// [`sandslope::risk::DEFAULT_MAX_RISK`] by default, a test checks).
pub const MAX_RISK: Field = Field::number("max-risk", "P")
    .keyword("max_risk")
    .key("max_risk")
    .default("0.05")
    .range("strictly between 0 and 1")
    .help(
        "Largest acceptable failure probability. \"Safe\" has one meaning, for the safe-slope limit \
         and --solve mass alike (docs/model.md §9): p_fail = P(it sinks or slides back) below \
         this. A safe robot may still climb slowly and stall (metastable); the success limit \
         bounds P(it does not climb steadily) instead.",
    );
/// `--solve`: what to solve for besides the curve.
pub const SOLVE: Field =
    Field::new("solve", Kind::Choice(&["slope", "mass"]), "slope|mass").conflicts(&["map"]).help(
        "Solve for the safe-slope limit (`slope`: the steepest slope with p_fail below \
         --max-risk, and the success limit beside it) or the heaviest safe mass at each --slope \
         (`mass`; several slopes give the payload envelope)",
    );
/// `--map`: p_fail over a grid of median (k_n, k_s) instead of the curve.
pub const MAP: Field = Field::switch("map")
    .help("p_fail and p_not_success over a grid of median (k_n, k_s) at the first --slope");
/// `--k-n`: the map's axis of median k_n.
pub const K_N_AXIS: Field = Field::text("k-n", "MIN:MAX:N[:log|:lin]")
    .keyword("k_n_axis")
    .unit("N/m^3")
    .range("0 < MIN < MAX, N at least 2")
    .help(
        "--map grid of median k_n, N/m^3: MIN:MAX:N[:log|:lin], log unless :lin (default: \
         terrain's / 100 to x 100, 200 points)",
    );
/// `--k-s`: the map's axis of median k_s.
pub const K_S_AXIS: Field = Field::text("k-s", "MIN:MAX:N[:log|:lin]")
    .keyword("k_s_axis")
    .unit("N/m^3")
    .range("0 < MIN < MAX, N at least 2")
    .help(
        "--map grid of median k_s, N/m^3: MIN:MAX:N[:log|:lin], log unless :lin (default: \
         terrain's / 1000 to x 100, 200 points)",
    );

/// `risk`'s own fields (the robot's and the terrain's are [`crate::scenario`]'s).
pub const FIELDS: Table =
    Table { command: "risk", fields: &[SLOPE, CV_N, CV_S, MAX_RISK, SOLVE, MAP, K_N_AXIS, K_S_AXIS] };

impl Fields for RiskRequest {
    const TABLE: Table = FIELDS;
}

/// Reads `--max-risk` from `p` (given, else its default): a failure probability strictly
/// between 0 and 1, by [`grammar::parse_max_risk`]. What every request with this field reads.
pub fn max_risk_in(p: &mut Params<'_>) -> Result<f64> {
    let text = MAX_RISK.text_in(p)?.unwrap_or_default();
    grammar::parse_max_risk(text)
        .map_err(|why| RequestError::invalid(MAX_RISK.flag, format!("{} = {text}: {why}", MAX_RISK.long())))
}

/// Parses the field `slope`: the one slope-list grammar, signed (a descent is felt as the
/// climb of its size), at most [`MAX_RISK_SLOPES`].
pub fn parse_slopes(text: &str) -> Result<Vec<f64>> {
    parse_slope_list(SLOPE.flag, text, SlopeSign::Signed, MAX_RISK_SLOPES)
}

impl RiskRequest {
    /// Reads the fields of a risk request ([`FIELDS`], the robot's and the terrain's); refuses
    /// any other key.
    pub fn from_params(params: &[(String, String)]) -> Result<RiskRequest> {
        let mut p = Params::new(FIELDS.command, params);
        let question = RiskQuestion::read(&mut p)?;
        let robot = RobotRequest::from_params(&mut p)?;
        let terrain = TERRAIN.text_in(&mut p)?.unwrap_or_default().to_string();
        p.finish()?;
        Ok(RiskRequest { robot, terrain, question })
    }

    /// The answer (what `risk --json` prints), by the library's calls; more work than
    /// `limits` allows is an error naming the limit.
    pub fn answer(&self, limits: AnswerLimits) -> Result<RiskAnswer> {
        let robot = self.robot.load()?;
        let terrain = load_terrain(&self.terrain)?;
        self.question.answer_on(&robot, terrain, limits, Words::Flag, None)
    }
}

/// Slopes of a p_fail curve computed between two looks at the stop flag (about 0.1 s of work
/// on 2 cores).
const CURVE_SLOPES_PER_CHUNK: usize = 128;

/// Slopes of a payload envelope computed between two looks at the stop flag (each a search
/// over masses).
const ENVELOPE_SLOPES_PER_CHUNK: usize = 8;

impl RiskQuestion {
    /// The question of the command line's flags given, `params` ([`FIELDS`]), the robot and the
    /// terrain read from the flags it shares with other commands; refuses any other key.
    pub fn from_fields(params: &[(String, String)]) -> Result<RiskQuestion> {
        let mut p = Params::new(FIELDS.command, params);
        let question = Self::read(&mut p)?;
        p.finish()?;
        Ok(question)
    }

    /// Reads the question's fields from `p`, each by its row of [`FIELDS`]: the one
    /// raw-to-typed step of every front end.
    fn read(p: &mut Params<'_>) -> Result<RiskQuestion> {
        let slopes = parse_slopes(SLOPE.text_in(p)?.unwrap_or_default())?;
        let cv_n = CV_N.number_in(p)?;
        let cv_s = CV_S.number_in(p)?;
        let max_risk = max_risk_in(p)?;
        let solve = SOLVE.choice_in(p)?.map(|word| if word == "mass" { Solve::Mass } else { Solve::Slope });
        let map = MAP.switch_in(p)?;
        let mut grid = RiskMapGrid::default();
        for (field, axis) in [(&K_N_AXIS, &mut grid.k_n), (&K_S_AXIS, &mut grid.k_s)] {
            if let Some(text) = field.text_in(p)? {
                if !map {
                    return Err(RequestError::invalid(
                        field.flag,
                        format!("{} is the grid of {}: give {} too", field.long(), MAP.long(), MAP.long()),
                    ));
                }
                *axis = Some(grammar::parse_strength_axis(field.flag, text)?);
            }
        }
        if map && solve.is_some() {
            return Err(RequestError::invalid(
                SOLVE.flag,
                format!("{} cannot be used with {}", SOLVE.long(), MAP.long()),
            ));
        }
        Ok(RiskQuestion { slopes, cv_n, cv_s, max_risk, solve, map: map.then_some(grid) })
    }

    /// The question put to `robot` on `terrain`: the CVs checked and the terrain read as
    /// uncertain by the one rule of docs/model.md §9, messages naming the fields in `words`.
    pub fn on(self, robot: &Robot, terrain: Terrain, words: Words) -> Result<RiskProblem<'_>> {
        let (terrain, _) = grammar::uncertain_terrain_in(words, terrain, self.cv_n, self.cv_s)?;
        Ok(RiskProblem { robot, terrain, question: self, words })
    }

    /// The answer for `robot` on `terrain` (what `risk --json` prints), by the library's calls,
    /// messages naming the fields in `words`; more work than `limits` allows is an error
    /// naming the limit. A curve or an envelope is computed in chunks of slopes with `stop`
    /// looked at between them: once it is raised the answer is [`RequestError::interrupted`]
    /// (the cap of 65,536 slopes takes over a minute). No slope is a curve or an envelope of
    /// none; a map or one slope's mass needs one.
    pub fn answer_on(
        &self,
        robot: &Robot,
        terrain: Terrain,
        limits: AnswerLimits,
        words: Words,
        stop: Option<&AtomicBool>,
    ) -> Result<RiskAnswer> {
        self.clone().on(robot, terrain, words)?.answer(limits, stop, &NoProgress)
    }
}

/// Told how a long answer is getting on (the command line's progress bar over a map's rows).
pub trait Progress: Sync {
    /// The work is `steps` steps long.
    fn start(&self, steps: u64);
    /// One more step is done.
    fn step(&self);
}

/// No one is told: [`Progress`] that shows nothing.
pub struct NoProgress;

impl Progress for NoProgress {
    fn start(&self, _steps: u64) {}
    fn step(&self) {}
}

/// A [`RiskQuestion`] put to a robot and a terrain already read ([`RiskQuestion::on`]): the
/// CVs checked, the terrain read as uncertain. [`RiskProblem::answer`] is the answer every
/// front end gives; the command line also asks for the slope limits beside a curve
/// ([`RiskProblem::slope_limits`]) and for what its figure of the curve draws
/// ([`RiskProblem::curve_samples`]).
#[derive(Debug)]
pub struct RiskProblem<'a> {
    robot: &'a Robot,
    terrain: UncertainTerrain,
    question: RiskQuestion,
    words: Words,
}

/// The error of a library call whose inputs were checked before: its message alone.
fn library(e: &dyn std::fmt::Display) -> RequestError {
    RequestError::from_error(None, anyhow::anyhow!("{e}"))
}

impl<'a> RiskProblem<'a> {
    /// The robot.
    pub fn robot(&self) -> &'a Robot {
        self.robot
    }

    /// The terrain read as uncertain.
    pub fn terrain(&self) -> &UncertainTerrain {
        &self.terrain
    }

    /// The question.
    pub fn question(&self) -> &RiskQuestion {
        &self.question
    }

    /// Asks for the map over `grid` instead (the command line reads `--k-n` and `--k-s` after
    /// checking its outputs); its axes are checked by [`RiskProblem::answer`].
    pub fn map_over(&mut self, grid: RiskMapGrid) {
        self.question.map = Some(grid);
    }

    /// The answer (what `risk --json` prints), by the library's calls; more work than
    /// `limits` allows is an error naming the limit. A curve or an envelope is computed in
    /// chunks of slopes with `stop` looked at between them (then the answer is
    /// [`RequestError::interrupted`]); a map tells `progress` its rows.
    pub fn answer(
        &self,
        limits: AnswerLimits,
        stop: Option<&AtomicBool>,
        progress: &dyn Progress,
    ) -> Result<RiskAnswer> {
        let (robot, terrain, words) = (self.robot, &self.terrain, self.words);
        let (slopes, max_risk) = (&self.question.slopes, self.question.max_risk);
        let first = || {
            slopes.first().copied().ok_or_else(|| {
                RequestError::invalid(
                    SLOPE.flag,
                    format!("{} gives no slope: give at least one", words.name(SLOPE.flag)),
                )
            })
        };
        if let Some(grid) = &self.question.map {
            let slope_deg = first()?;
            let (k_n_axis, k_s_axis) = map_axes_in(words, grid, terrain, slope_deg, limits.map_cells)?;
            let slope = slope_in(words, slope_deg)?;
            progress.start(k_s_axis.len() as u64);
            let map = risk_map(robot, slope, terrain, (&k_n_axis, &k_s_axis), max_risk, &|| progress.step())
                .map_err(|e| library(&e))?;
            return Ok(RiskAnswer::Map(Box::new(map)));
        }
        let chunks = |per_chunk: usize, most: usize, what: &str| {
            too_many(words, slopes.len(), most, what)?;
            Ok(SlopeChunks { slopes, per_chunk, words, stop })
        };
        Ok(match self.question.solve {
            Some(Solve::Mass) if slopes.len() <= 1 => {
                let sol = safe_mass(robot, slope_in(words, first()?)?, terrain, max_risk)
                    .map_err(|e| library(&e))?;
                RiskAnswer::Mass(Box::new(sol))
            }
            // `solve mass` at several slopes is the envelope over them; Python's asks for it at any.
            Some(Solve::Mass | Solve::Envelope) => envelope(
                chunks(ENVELOPE_SLOPES_PER_CHUNK, limits.envelope_slopes, "--solve mass")?,
                robot,
                terrain,
                max_risk,
            )?,
            Some(Solve::Slope) => RiskAnswer::Slope(Box::new(self.slope_limits()?)),
            None => {
                let chunks = chunks(CURVE_SLOPES_PER_CHUNK, limits.curve_slopes, "a p_fail curve")?;
                let parts = chunks.each(
                    |chunk| Ok(risk_curve(robot, terrain, &signed(chunk)?)),
                    |e| match words {
                        Words::Flag => RequestError::invalid(SLOPE.flag, e.renamed(SLOPE.long())),
                        Words::Keyword => RequestError::invalid(SLOPE.flag, e),
                    },
                )?;
                RiskAnswer::of_points(parts.into_iter().flat_map(|c| c.points).collect())
            }
        })
    }

    /// The safe-slope and success limits at the question's `max_risk` (the answer of
    /// `solve slope`, and what the command line's table prints under a curve).
    pub fn slope_limits(&self) -> Result<SafeSlope> {
        safe_slope(self.robot, &self.terrain, self.question.max_risk).map_err(|e| library(&e))
    }

    /// What a figure of p_fail against slope draws beside `limits`: the curve every
    /// [`CURVE_FIGURE_STEP_DEG`] from level up to past the steepest slope asked, the safe-slope
    /// limit and the angle of repose (at least 30 degrees, at most 89.5), and the points at the
    /// slopes asked.
    pub fn curve_samples(&self, limits: &SafeSlope) -> Result<CurveSamples> {
        let slopes = &self.question.slopes;
        let mut hi = slopes.iter().fold(0.0f64, |a, &d| a.max(d.abs())).max(30.0);
        if let Some(v) = limits.limit.value() {
            hi = hi.max(v * 1.25);
        }
        if let Some(r) = self.terrain.terrain().repose() {
            hi = hi.max(r.degrees() + 3.0);
        }
        let hi = hi.min(89.5);
        let n = (hi / CURVE_FIGURE_STEP_DEG).round() as usize;
        let fine: Vec<f64> = (0..=n).map(|i| hi * i as f64 / n as f64).collect();
        let curve = |slopes: &[f64]| {
            Ok::<_, RequestError>(risk_curve(
                self.robot,
                &self.terrain,
                &signed(slopes).map_err(|e| library(&e))?,
            ))
        };
        Ok(CurveSamples { hi, fine: curve(&fine)?.points, requested: curve(slopes)?.points })
    }
}

/// Spacing of the curve in [`CurveSamples`], degrees.
pub const CURVE_FIGURE_STEP_DEG: f64 = 0.25;

/// What a figure of p_fail against slope draws ([`RiskProblem::curve_samples`]).
#[derive(Debug, Clone, PartialEq)]
pub struct CurveSamples {
    /// The steepest slope drawn, degrees.
    pub hi: f64,
    /// The curve from level to `hi`.
    pub fine: Vec<RiskPoint>,
    /// The points at the slopes asked, in their order.
    pub requested: Vec<RiskPoint>,
}

/// Whether a default CV was used where `answer` was evaluated (docs/model.md §9): at its
/// slopes, over the whole table for the slope limits (their search covers it).
pub fn defaults_used(answer: &RiskAnswer) -> DefaultsUsed {
    let over = |points: &[RiskPoint]| {
        points.iter().fold(DefaultsUsed::default(), |a, p| a.or(p.uncertainty.defaults_used()))
    };
    match answer {
        RiskAnswer::Point(p) => p.uncertainty.defaults_used(),
        RiskAnswer::Curve(points) => over(points),
        RiskAnswer::Slope(sol) => sol.defaults_used,
        RiskAnswer::Mass(sol) => sol.uncertainty.defaults_used(),
        RiskAnswer::Envelope(env) => env.defaults_used,
        RiskAnswer::Map(map) => map.summary.defaults_used,
    }
}

/// The payload envelope over `chunks`' slopes, in chunks.
fn envelope(
    chunks: SlopeChunks<'_>,
    robot: &Robot,
    terrain: &UncertainTerrain,
    max_risk: f64,
) -> Result<RiskAnswer> {
    let words = chunks.words;
    let parts = chunks.each(
        |chunk| payload_envelope(robot, terrain, &signed(chunk)?, max_risk),
        |e| match words {
            // The command line's message as it always was: the library's, unnamed.
            Words::Flag => RequestError::from_error(None, anyhow::anyhow!("{e}")),
            Words::Keyword if e.key.starts_with("slope_deg") => RequestError::invalid(SLOPE.flag, e),
            Words::Keyword => RequestError::from_error(None, anyhow::anyhow!("{e}")),
        },
    )?;
    let mut parts = parts.into_iter();
    let mut env = parts.next().expect("SlopeChunks::each computes at least once");
    for part in parts {
        env.points.extend(part.points);
        env.defaults_used = env.defaults_used.or(part.defaults_used);
    }
    Ok(RiskAnswer::Envelope(Box::new(env)))
}

/// More than `most` slopes refused, in `words`.
fn too_many(words: Words, n: usize, most: usize, what: &str) -> Result<()> {
    match words {
        _ if n <= most => Ok(()),
        Words::Flag => Err(RequestError::invalid(
            SLOPE.flag,
            format!("{} gives {n} slopes; at most {most} are allowed for {what} here", SLOPE.long()),
        )),
        Words::Keyword => sandslope::limits::count("len(slope_deg)", n, most)
            .map(|_| ())
            .map_err(|e| RequestError::invalid(SLOPE.flag, e)),
    }
}

/// A request's slopes in chunks, with the stop flag looked at between them.
struct SlopeChunks<'a> {
    slopes: &'a [f64],
    per_chunk: usize,
    words: Words,
    stop: Option<&'a AtomicBool>,
}

impl SlopeChunks<'_> {
    /// `compute` over each chunk (at least once, on no slopes when there are none); a library
    /// error about a slope names it in Python's words when there are several (`slope_deg[i]`)
    /// before `refuse` makes it the request's error.
    fn each<T>(
        &self,
        compute: impl Fn(&[f64]) -> std::result::Result<T, ParamError>,
        refuse: impl Fn(ParamError) -> RequestError,
    ) -> Result<Vec<T>> {
        let slopes = self.slopes;
        let chunks: Vec<&[f64]> =
            if slopes.is_empty() { vec![slopes] } else { slopes.chunks(self.per_chunk).collect() };
        let mut out = Vec::with_capacity(chunks.len());
        for (c, chunk) in chunks.into_iter().enumerate() {
            if self.stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
                return Err(RequestError::interrupted());
            }
            let part = compute(chunk).map_err(|e| {
                refuse(match self.words {
                    Words::Keyword if slopes.len() > 1 && e.key == "slope_deg" => {
                        let bad = chunk.iter().position(|&d| SignedSlope::from_degrees(d).is_err());
                        e.renamed(format!("slope_deg[{}]", c * self.per_chunk + bad.unwrap_or(0)))
                    }
                    _ => e,
                })
            })?;
            out.push(part);
        }
        Ok(out)
    }
}

/// A slope as the library's type (signed: answers print it as given), an error naming the
/// field `slope` in `words`.
fn slope_in(words: Words, deg: f64) -> Result<SignedSlope> {
    SignedSlope::from_degrees(deg).map_err(|e| match words {
        Words::Flag => RequestError::invalid(SLOPE.flag, e.renamed(SLOPE.long())),
        Words::Keyword => RequestError::invalid(SLOPE.flag, e),
    })
}

/// The map's axes (the grid's, else the defaults around the terrain's medians at
/// `slope_deg`, an error naming `slope` if it is out of range), at most `max_cells` cells,
/// naming the fields in `words` (Python's keywords: `slope_deg`, `len(k_n_axis) *
/// len(k_s_axis)`).
pub fn map_axes_in(
    words: Words,
    grid: &RiskMapGrid,
    terrain: &UncertainTerrain,
    slope_deg: f64,
    max_cells: u128,
) -> Result<(Axis, Axis)> {
    let slope = slope_in(words, slope_deg)?;
    let given = |field: &str, range: Option<AxisRange>| range.map(|r| grammar::axis(field, r)).transpose();
    let (k_n_axis, k_s_axis) = sandslope::risk::map_axes(
        terrain,
        slope,
        given(K_N_AXIS.flag, grid.k_n)?,
        given(K_S_AXIS.flag, grid.k_s)?,
    )
    .map_err(|e| RequestError::from_error(None, anyhow::anyhow!("{e}")))?;
    let cells = k_n_axis.len() as u128 * k_s_axis.len() as u128;
    if cells > max_cells {
        if words == Words::Keyword {
            let (nx, ny, most) =
                (k_n_axis.len(), k_s_axis.len(), usize::try_from(max_cells).unwrap_or(usize::MAX));
            let e = sandslope::limits::grid_cells("len(k_n_axis) * len(k_s_axis)", nx, ny, 1, most);
            return Err(RequestError::invalid(K_N_AXIS.flag, e.expect_err("over the cap")));
        }
        let side = (max_cells as f64).sqrt().floor();
        return Err(RequestError::invalid(
            K_N_AXIS.flag,
            format!(
                "{} and {} give {cells} map cells; at most {max_cells} are allowed (e.g. {side} x {side}), to keep the map in memory",
                K_N_AXIS.long(),
                K_S_AXIS.long()
            ),
        ));
    }
    Ok((k_n_axis, k_s_axis))
}

/// The slopes as the library takes them, each checked (an error keyed `slope_deg`, which the
/// callers name as their front end does).
fn signed(slopes: &[f64]) -> std::result::Result<Vec<SignedSlope>, ParamError> {
    slopes.iter().map(|&d| SignedSlope::from_degrees(d).map_err(|e| e.renamed("slope_deg"))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table's default of `--max-risk` is the library's, which Python's signatures take.
    #[test]
    fn max_risk_default_is_the_librarys() {
        assert_eq!(MAX_RISK.default.map(str::parse::<f64>), Some(Ok(sandslope::risk::DEFAULT_MAX_RISK)));
    }

    /// Without a field given, the question is the default curve: 0 to 24 degrees in 7 slopes
    /// (every 4 degrees), at p_fail 0.05, no CV override, no solve, no map.
    #[test]
    fn defaults_are_the_curve_over_0_to_24_degrees() {
        let q = RiskQuestion::from_fields(&[]).unwrap();
        assert_eq!(q.slopes, vec![0.0, 4.0, 8.0, 12.0, 16.0, 20.0, 24.0]);
        assert_eq!((q.max_risk, q.cv_n, q.cv_s, q.solve, q.map), (0.05, None, None, None, None));
    }

    /// The map's axes need the map; solve and map do not go together; each error names its
    /// flag.
    #[test]
    fn map_fields_are_checked_together() {
        let pairs = |list: &[(&str, &str)]| -> Vec<(String, String)> {
            list.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()
        };
        let e = RiskQuestion::from_fields(&pairs(&[("k-n", "1e5:1e7:3")])).unwrap_err();
        assert_eq!(e.message(), "--k-n is the grid of --map: give --map too");
        let e = RiskQuestion::from_fields(&pairs(&[("map", "true"), ("solve", "mass")])).unwrap_err();
        assert_eq!(e.message(), "--solve cannot be used with --map");
        let e = RiskQuestion::from_fields(&pairs(&[("solve", "speed")])).unwrap_err();
        assert_eq!(e.message(), "--solve = `speed` must be one of: slope, mass");
        let e = RiskQuestion::from_fields(&pairs(&[("max-risk", "1")])).unwrap_err();
        assert!(e.message().starts_with("--max-risk = 1: "), "{}", e.message());
        let q = RiskQuestion::from_fields(&pairs(&[("map", ""), ("k-s", "1:10:2:lin")])).unwrap();
        let grid = q.map.unwrap();
        assert!(grid.k_n.is_none() && grid.k_s.is_some());
    }
}
