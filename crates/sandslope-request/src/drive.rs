//! `drive`'s run, checked once: the numbers that `sandslope drive`'s flags, `serve --drive`'s
//! and Python's `drive` keywords set (docs/drive.md), each against its range and named as each
//! front end names it. The servo crate builds the run from them (`DriveConfig`).

use serde::{Deserialize, Serialize};

use sandslope::servo::ServoModel;
use sandslope::{SignedSlope, Terrain};

use crate::error::{RequestError, Result, Words};
use crate::field::{Field, Fields, Kind, Table};
use crate::params::Params;

/// The numbers of one drive run, as a front end gives them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DriveRun {
    /// Slope of the run, degrees (negative: downhill).
    pub slope_deg: f64,
    /// How long the legs turn, s (0 to 86,400).
    pub duration_s: f64,
    /// Bus read rate, Hz (1 to 1000).
    pub rate_hz: f64,
    /// Seconds the legs hold still at the end (0 to 3600).
    pub hold_s: f64,
    /// The host's watchdog, s (0.01 to 10).
    pub watchdog_s: f64,
    /// The servos' own bus watchdog, s (0.02 to 2.54, its register's range).
    pub bus_watchdog_s: f64,
    /// The servos' current limit, mA (at most the largest a supported model accepts; the
    /// servos' own model is checked at their ping).
    pub current_limit_ma: u16,
    /// The servos' temperature limit, degC (at most the highest a supported model is rated
    /// for; the servos' own model is checked at their ping).
    pub temperature_limit_c: u8,
    /// Stop when the live risk reaches this probability (0 to 1), if given.
    pub stop_on_risk: Option<f64>,
    /// The emulator's current noise, mA (0 to 1000), when the run is emulated.
    pub emulate_noise_ma: Option<f64>,
    /// The emulated sand's k_s, N/m^3, if given.
    pub emulate_k_s: Option<f64>,
}

/// `--slope`: the slope of the run.
pub const SLOPE: Field = Field::number("slope", "DEG")
    .keyword("slope_deg")
    .key("slope_deg")
    .unit("deg")
    .default("0")
    .range("-90 to 90")
    .help("The slope being climbed, degrees (for the live estimate, the log's header and the emulator)");
/// `--duration`: how long the legs turn.
pub const DURATION: Field = Field::number("duration", "S")
    .keyword("duration_s")
    .unit("s")
    .default("10")
    .range("0 to 86400")
    .help("Gait time, s (after standing up)");
/// `--rate`: the bus cycles per second.
pub const RATE: Field = Field::number("rate", "HZ")
    .keyword("rate_hz")
    .unit("Hz")
    .default("50")
    .range("1 to 1000")
    .help("Bus cycles per second aimed at (each: a Sync Write of goals and a Sync Read of state)");
/// `--profile`: how the gait is commanded.
pub const PROFILE: Field =
    Field::new("profile", Kind::Choice(&["position", "velocity"]), "position|velocity")
        .default("position")
        .help(
            "How the gait is commanded: `position` (extended position mode, the schedule's angle every \
         cycle) or `velocity` (velocity mode, the schedule's speed with a phase correction)",
        );
/// `--baud`: the bus's baud rate.
pub const BAUD: Field = Field::new("baud", Kind::Whole, "BAUD")
    .unit("baud")
    .range("one the servos support")
    .help("Baud rate (default: the robot file's [servos] baud_rate, else 57600; the emulator ignores it)");
/// `--stop-on-risk`: halt when the live risk passes it.
pub const STOP_ON_RISK: Field = Field::number("stop-on-risk", "P").keyword("stop_on_risk").range("0 to 1").help(
    "Halt the gait (torque held, legs planted) when the live risk that the walk fails (slippage or sinkage) passes P",
);
/// `--force`: drive beyond the calibrated safe slope.
pub const FORCE: Field = Field::switch("force").keyword("force").help(
    "Drive beyond the calibrated safe slope (`risk --solve slope`); without it such a run is \
     refused before anything moves, naming the limit",
);
/// `--live-window`: the stances the live estimate pools.
pub const LIVE_WINDOW: Field =
    Field::new("live-window", Kind::Whole, "N").keyword("window").unit("stances").range("at least 1").help(
        "Pool the live estimate over the last N stances (a moving window, to follow sand that \
         changes); without it every stance so far is pooled",
    );
/// `--hold`: the legs held after a halt.
pub const HOLD: Field = Field::number("hold", "S")
    .keyword("hold_s")
    .unit("s")
    .default("2")
    .range("0 to 3600")
    .help("After a halt, seconds the legs are held before the torque goes off");
/// `--current-limit`: the servos' Current Limit.
pub const CURRENT_LIMIT: Field = Field::new("current-limit", Kind::Whole, "MA")
    .keyword("current_limit_ma")
    .unit("mA")
    .default("1470")
    .range("within the model's")
    .help(
        "Current Limit written to every servo, mA (within the model's: 0 to 1750 on the XL330s, 0 \
         to 3209 on the XM430-W350; 1470 is the XL330-M288's stall current at 5 V; the XL430-W250 \
         has none)",
    );
/// `--temperature-limit`: the servos' Temperature Limit.
pub const TEMPERATURE_LIMIT: Field = Field::new("temperature-limit", Kind::Whole, "DEGC")
    .keyword("temperature_limit_c")
    .unit("degC")
    .default("65")
    .range("within the model's rated maximum")
    .help(
        "Temperature Limit written to every servo, degC (within the model's rated maximum: 70 on \
         the XL330s, 72 on the XL430-W250, 80 on the XM430-W350)",
    );
/// `--watchdog`: the host's watchdog.
pub const WATCHDOG: Field = Field::number("watchdog", "S")
    .keyword("watchdog_s")
    .unit("s")
    .default("1")
    .range("0.01 to 10")
    .help("Longest bus cycle accepted before everything stops, s");
/// `--bus-watchdog`: the servos' own Bus Watchdog.
pub const BUS_WATCHDOG: Field = Field::number("bus-watchdog", "S")
    .keyword("bus_watchdog_s")
    .unit("s")
    .default("0.5")
    .range("0.02 to 2.54")
    .help("The servos' own Bus Watchdog, s (0.02 to 2.54): they stop by themselves if the driver goes quiet");
/// `--emulate-noise`: the emulator's current noise.
pub const EMULATE_NOISE: Field = Field::number("emulate-noise", "MA")
    .keyword("noise_ma")
    .unit("mA")
    .default("10")
    .range("0 to 1000")
    .help("Emulator: Present Current noise, mA (standard deviation)");
/// `--emulate-seed`: the seed of the emulator's noise (read as a whole number up to 2^64 - 1).
pub const EMULATE_SEED: Field =
    Field::text("emulate-seed", "N").keyword("seed").default("1").help("Emulator: seed of the noise");
/// `--emulate-k-s`: the emulated sand's k_s.
pub const EMULATE_K_S: Field = Field::number("emulate-k-s", "N/M^3")
    .keyword("k_s")
    .unit("N/m^3")
    .range("greater than 0")
    .help("Emulator: the sand's k_s (N/m^3) instead of the terrain's at the slope");
/// `--emulate-weaken`: the emulated sand weakening during the run.
pub const EMULATE_WEAKEN: Field = Field::text("emulate-weaken", "S:K_S")
    .keyword("weaken")
    .help("Emulator: the sand weakens to K_S N/m^3 at S seconds after the start, S:K_S");
/// `--emulate-fault`: a fault of the emulated bus.
pub const EMULATE_FAULT: Field = Field::text("emulate-fault", "KIND:..").help(
    "Emulator: a fault, silent:ID:S (servo ID stops answering at S s), corrupt:ID:S (its \
     packets fail their CRC from S s) or freeze:S:LEN (the bus hangs for LEN s from S s)",
);
/// `--emulate-offset`: the emulated current sensors' zero bias.
pub const EMULATE_OFFSET: Field =
    Field::text("emulate-offset", "MA[,MA..]").unit("mA").range("-500 to 500 each").help(
        "Emulator: a current sensor's zero bias, mA added to every Present Current: one value for \
     every servo, or one per servo in leg order, comma-separated (within -500 to 500)",
    );
/// `--emulate-clock`: the emulated run's clock, the wall's or a virtual one.
pub const EMULATE_CLOCK: Field =
    Field::new("emulate-clock", Kind::Choice(&["real", "virtual"]), "real|virtual")
        .default("real")
        .keyword("clock")
        .help(
            "Emulator: `real` (a run of S seconds takes S seconds: the loop's real timing) or `virtual` \
         (simulated time: the run takes its computing time, docs/drive.md)",
        );

/// `drive`'s run fields, which `serve --drive` shares (the robot's and the terrain's are
/// [`crate::scenario`]'s; the bus flags and `--log` are each command's own).
pub const FIELDS: Table = Table {
    command: "drive",
    fields: &[
        SLOPE,
        DURATION,
        RATE,
        PROFILE,
        BAUD,
        STOP_ON_RISK,
        FORCE,
        LIVE_WINDOW,
        HOLD,
        CURRENT_LIMIT,
        TEMPERATURE_LIMIT,
        WATCHDOG,
        BUS_WATCHDOG,
        EMULATE_NOISE,
        EMULATE_SEED,
        EMULATE_K_S,
        EMULATE_WEAKEN,
        EMULATE_FAULT,
        EMULATE_OFFSET,
        EMULATE_CLOCK,
    ],
};

/// The fields that only an emulated bus takes.
const EMULATOR: [&Field; 7] = [
    &EMULATE_NOISE,
    &EMULATE_SEED,
    &EMULATE_K_S,
    &EMULATE_WEAKEN,
    &EMULATE_FAULT,
    &EMULATE_OFFSET,
    &EMULATE_CLOCK,
];

/// Every field of a drive run, read from text by [`DriveFields::from_params`] and checked: the
/// numbers in [`DriveRun`], the rest as the servo crate's run takes them.
#[derive(Debug, Clone, PartialEq)]
pub struct DriveFields {
    /// The numbers, checked against their ranges.
    pub run: DriveRun,
    /// `--profile`: `position` or `velocity`.
    pub profile: String,
    /// `--baud`, if given.
    pub baud: Option<u32>,
    /// `--force`.
    pub force: bool,
    /// `--live-window`, if given (at least 1).
    pub live_window: Option<usize>,
    /// `--emulate-seed`.
    pub emulate_seed: u64,
    /// `--emulate-weaken`, unparsed (`S:K_S`).
    pub emulate_weaken: Option<String>,
    /// `--emulate-fault`, unparsed (`KIND:..`).
    pub emulate_fault: Option<String>,
    /// `--emulate-offset`, unparsed (one value or one per servo).
    pub emulate_offset: Option<String>,
    /// `--emulate-clock`: `real` or `virtual`.
    pub emulate_clock: String,
}

impl Fields for DriveFields {
    const TABLE: Table = FIELDS;
}

impl DriveFields {
    /// Reads a run's fields, each by its row of [`FIELDS`] (given, else its default), and
    /// checks the numbers ([`DriveRun::check`]); the `--emulate-*` fields only when `emulate`
    /// (the bus is emulated). Refuses any other key; errors name the flag.
    pub fn from_params(params: &[(String, String)], emulate: bool) -> Result<DriveFields> {
        let mut p = Params::new(FIELDS.command, params);
        if !emulate {
            if let Some((given, _)) = params.iter().find(|(k, _)| EMULATOR.iter().any(|f| f.flag == k)) {
                return Err(RequestError::invalid(
                    FIELDS.field(given).flag,
                    format!("--{given} is the emulator's: give --emulate too"),
                ));
            }
        }
        let number = |p: &mut Params<'_>, f: &Field| f.required_number_in(p);
        let whole = |p: &mut Params<'_>, f: &Field, most: u32| -> Result<Option<u32>> {
            match f.whole_in(p)? {
                Some(v) if v > most => Err(RequestError::invalid(
                    f.flag,
                    format!("{} = {v} must be within 0 to {most}", f.long()),
                )),
                v => Ok(v),
            }
        };
        let current = whole(&mut p, &CURRENT_LIMIT, u32::from(u16::MAX))?.unwrap_or_default();
        let temperature = whole(&mut p, &TEMPERATURE_LIMIT, u32::from(u8::MAX))?.unwrap_or_default();
        let run = DriveRun {
            slope_deg: number(&mut p, &SLOPE)?,
            duration_s: number(&mut p, &DURATION)?,
            rate_hz: number(&mut p, &RATE)?,
            hold_s: number(&mut p, &HOLD)?,
            watchdog_s: number(&mut p, &WATCHDOG)?,
            bus_watchdog_s: number(&mut p, &BUS_WATCHDOG)?,
            current_limit_ma: current as u16,
            temperature_limit_c: temperature as u8,
            stop_on_risk: STOP_ON_RISK.number_in(&mut p)?,
            emulate_noise_ma: Some(number(&mut p, &EMULATE_NOISE)?).filter(|_| emulate),
            emulate_k_s: EMULATE_K_S.number_in(&mut p)?,
        };
        let profile = PROFILE.choice_in(&mut p)?.unwrap_or_default().to_string();
        let baud = BAUD.whole_in(&mut p)?;
        let force = FORCE.switch_in(&mut p)?;
        let live_window = match LIVE_WINDOW.whole_in(&mut p)? {
            Some(0) => {
                return Err(RequestError::invalid(
                    LIVE_WINDOW.flag,
                    format!(
                        "{} = 0 must be at least 1 stance (leave it out to pool every stance)",
                        LIVE_WINDOW.long()
                    ),
                ))
            }
            w => w.map(|w| w as usize),
        };
        let seed = EMULATE_SEED.text_in(&mut p)?.unwrap_or_default();
        let emulate_seed = seed.trim().parse::<u64>().map_err(|_| {
            RequestError::invalid(
                EMULATE_SEED.flag,
                format!("{} = `{seed}` is not a whole number from 0 to 2^64 - 1", EMULATE_SEED.long()),
            )
        })?;
        let text = |p: &mut Params<'_>, f: &Field| Ok::<_, RequestError>(f.text_in(p)?.map(str::to_string));
        let emulate_weaken = text(&mut p, &EMULATE_WEAKEN)?;
        let emulate_fault = text(&mut p, &EMULATE_FAULT)?;
        let emulate_offset = text(&mut p, &EMULATE_OFFSET)?;
        let emulate_clock = EMULATE_CLOCK.choice_in(&mut p)?.unwrap_or_default().to_string();
        p.finish()?;
        run.check(Words::Flag)?;
        Ok(DriveFields {
            run,
            profile,
            baud,
            force,
            live_window,
            emulate_seed,
            emulate_weaken,
            emulate_fault,
            emulate_offset,
            emulate_clock,
        })
    }
}

/// A run's defaults, as Python's `sandslope.drive_defaults()` shows them and its `drive` takes
/// them for a keyword left out: each the default of its row of [`FIELDS`], read by the same
/// step as a given value ([`DriveFields::from_params`] with nothing given, on an emulated
/// bus), so that it is written once, in the table.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RunDefaults {
    /// The slope climbed, degrees (`--slope`).
    pub slope_deg: f64,
    /// Gait time after standing up, s (`--duration`).
    pub duration_s: f64,
    /// Bus cycles per second aimed at (`--rate`).
    pub rate_hz: f64,
    /// Seconds the legs are held after a halt on risk (`--hold`).
    pub hold_s: f64,
    /// Current Limit written to every servo, mA (`--current-limit`): the paper's XL330-M288's
    /// stall current at 5 V, 1.47 A (below the XM430-W350's 2.3 A, so safe on every supported
    /// model with current control; a test holds the row to the library's figure).
    pub current_limit_ma: u16,
    /// Temperature Limit written to every servo, degC (`--temperature-limit`).
    pub temperature_limit_c: u8,
    /// Longest bus cycle accepted, s (`--watchdog`).
    pub watchdog_s: f64,
    /// The servos' own Bus Watchdog, s (`--bus-watchdog`).
    pub bus_watchdog_s: f64,
    /// Seconds the legs take to stand to their start angles before the gait (no field sets
    /// it: the servo crate's `STAND_S`, given by the front end).
    pub stand_s: f64,
    /// The emulator's Present Current noise, mA (`--emulate-noise`).
    pub emulate_noise_ma: f64,
    /// The emulator's noise seed (`--emulate-seed`).
    pub emulate_seed: u64,
    /// Estimate k_s and the risk after every stance (`drive --live`, a switch: off unless
    /// given; `--stop-on-risk` implies it and `serve --drive` always does it). Off: the
    /// monitor's grid costs seconds of CPU before the robot moves.
    pub live: bool,
}

impl RunDefaults {
    /// The table's defaults, with the legs standing up for `stand_s` seconds.
    pub fn read(stand_s: f64) -> Result<RunDefaults> {
        let DriveFields { run, emulate_seed, .. } = DriveFields::from_params(&[], true)?;
        Ok(RunDefaults {
            slope_deg: run.slope_deg,
            duration_s: run.duration_s,
            rate_hz: run.rate_hz,
            hold_s: run.hold_s,
            current_limit_ma: run.current_limit_ma,
            temperature_limit_c: run.temperature_limit_c,
            watchdog_s: run.watchdog_s,
            bus_watchdog_s: run.bus_watchdog_s,
            stand_s,
            emulate_noise_ma: run.emulate_noise_ma.unwrap_or_default(),
            emulate_seed,
            live: false,
        })
    }
}

/// Python's `clock` keyword ([`EMULATE_CLOCK`]'s row): the word given, else the row's default,
/// checked against the row's choices; the error names the keyword and the choices.
pub fn emulate_clock_keyword(given: Option<&str>) -> Result<&'static str> {
    let choices: &[&'static str] = match EMULATE_CLOCK.kind {
        Kind::Choice(choices) => choices,
        _ => &[],
    };
    let word = given.map(str::trim).or(EMULATE_CLOCK.default).unwrap_or_default();
    choices.iter().copied().find(|c| *c == word).ok_or_else(|| {
        RequestError::invalid(
            EMULATE_CLOCK.flag,
            format!("{} = \"{word}\" must be one of: {}", EMULATE_CLOCK.keyword, choices.join(", ")),
        )
    })
}

/// A field as each front end names it: the command line's flag, or Python's keyword (which
/// carries its unit), from its row of [`FIELDS`].
fn name(words: Words, field: &Field) -> String {
    match words {
        Words::Flag => field.long(),
        Words::Keyword if field.keyword.is_empty() => words.name(field.flag),
        Words::Keyword => field.keyword.to_string(),
    }
}

/// `value` within `lo..=hi`, else an error naming the field and the range.
fn within(words: Words, field: &Field, value: f64, lo: f64, hi: f64) -> Result<()> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(RequestError::invalid(
            field.flag,
            format!("{} = {value} must be between {lo} and {hi}", name(words, field)),
        ))
    }
}

impl DriveRun {
    /// Checks every number against its range; errors name the field in `words`.
    pub fn check(&self, words: Words) -> Result<()> {
        SignedSlope::from_degrees(self.slope_deg)
            .map_err(|e| RequestError::invalid(SLOPE.flag, e.renamed(name(words, &SLOPE))))?;
        within(words, &DURATION, self.duration_s, 0.0, 86_400.0)?;
        within(words, &RATE, self.rate_hz, 1.0, 1000.0)?;
        within(words, &HOLD, self.hold_s, 0.0, 3600.0)?;
        within(words, &WATCHDOG, self.watchdog_s, 0.01, 10.0)?;
        within(words, &BUS_WATCHDOG, self.bus_watchdog_s, 0.02, 2.54)?;
        let max_ma =
            ServoModel::ALL.iter().filter_map(|m| m.max_current_limit_ma()).fold(0.0, f64::max).floor();
        let max_c = ServoModel::ALL.iter().map(|m| m.max_temperature_c).max().unwrap_or(0);
        if f64::from(self.current_limit_ma) > max_ma {
            return Err(RequestError::invalid(
                CURRENT_LIMIT.flag,
                format!(
                    "{} = {} must be within 0 to {max_ma} mA (the largest Current Limit of a supported servo)",
                    name(words, &CURRENT_LIMIT),
                    self.current_limit_ma,
                ),
            ));
        }
        if self.temperature_limit_c > max_c {
            return Err(RequestError::invalid(
                TEMPERATURE_LIMIT.flag,
                format!(
                    "{} = {} must be within 0 to {max_c} degC (the highest rating of a supported servo)",
                    name(words, &TEMPERATURE_LIMIT),
                    self.temperature_limit_c,
                ),
            ));
        }
        if let Some(p) = self.stop_on_risk {
            within(words, &STOP_ON_RISK, p, 0.0, 1.0)?;
        }
        if let Some(noise) = self.emulate_noise_ma {
            within(words, &EMULATE_NOISE, noise, 0.0, 1000.0)?;
        }
        if let Some(k) = self.emulate_k_s {
            Terrain::constant(1.0, k)
                .map_err(|e| RequestError::invalid(EMULATE_K_S.flag, e.renamed(name(words, &EMULATE_K_S))))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Python's `clock`: left out, the wall's (`--emulate-clock`'s default, `real`); a word of
    /// the row's taken as given; another refused naming the keyword and both choices.
    #[test]
    fn the_clock_keyword_reads_the_emulate_clock_row() {
        assert_eq!(emulate_clock_keyword(None).unwrap(), "real");
        assert_eq!(emulate_clock_keyword(Some(" virtual")).unwrap(), "virtual");
        let e = emulate_clock_keyword(Some("wall")).unwrap_err();
        assert_eq!(e.message(), "clock = \"wall\" must be one of: real, virtual");
    }

    /// The run's defaults are the table's, read as given values are: 0 deg, 10 s at 50 Hz,
    /// held 2 s, watchdogs 1 s and 0.5 s, 65 degC, the emulator's 10 mA noise and seed 1; the
    /// Current Limit is the XL330-M288's stall current at 5 V (1.47 A, the library's figure).
    #[test]
    fn run_defaults_are_the_tables() {
        let d = RunDefaults::read(1.0).unwrap();
        assert_eq!((d.slope_deg, d.duration_s, d.rate_hz, d.hold_s), (0.0, 10.0, 50.0, 2.0));
        assert_eq!((d.watchdog_s, d.bus_watchdog_s, d.temperature_limit_c), (1.0, 0.5, 65));
        assert_eq!((d.emulate_noise_ma, d.emulate_seed, d.stand_s, d.live), (10.0, 1, 1.0, false));
        assert_eq!(f64::from(d.current_limit_ma), (ServoModel::XL330_M288.stall_current_a * 1000.0).round());
    }

    fn run() -> DriveRun {
        DriveRun {
            slope_deg: 10.0,
            duration_s: 5.0,
            rate_hz: 100.0,
            hold_s: 1.0,
            watchdog_s: 1.0,
            bus_watchdog_s: 0.5,
            current_limit_ma: 1470,
            temperature_limit_c: 65,
            stop_on_risk: None,
            emulate_noise_ma: Some(2.0),
            emulate_k_s: None,
        }
    }

    /// One check, in each front end's words: the command line's flags, Python's keywords.
    #[test]
    fn a_drive_run_is_checked_once_in_each_front_ends_words() {
        assert!(run().check(Words::Flag).is_ok());
        let long = DriveRun { duration_s: 90_000.0, ..run() };
        assert_eq!(
            long.check(Words::Flag).unwrap_err().message(),
            "--duration = 90000 must be between 0 and 86400"
        );
        assert_eq!(
            long.check(Words::Keyword).unwrap_err().message(),
            "duration_s = 90000 must be between 0 and 86400"
        );
        let risky = DriveRun { stop_on_risk: Some(1.5), ..run() };
        assert_eq!(
            risky.check(Words::Keyword).unwrap_err().message(),
            "stop_on_risk = 1.5 must be between 0 and 1"
        );
        let steep = DriveRun { slope_deg: 95.0, ..run() };
        let e = steep.check(Words::Keyword).unwrap_err();
        assert_eq!(e.field(), Some("slope"));
        assert!(e.message().starts_with("slope_deg = 95"), "{}", e.message());
        // The XM430-W350 is rated to 80 degC, the hottest supported servo.
        let hot = DriveRun { temperature_limit_c: 81, ..run() };
        assert!(hot
            .check(Words::Flag)
            .unwrap_err()
            .message()
            .starts_with("--temperature-limit = 81 must be within 0 to 80"));
        let soft = DriveRun { emulate_k_s: Some(-1.0), ..run() };
        assert!(soft.check(Words::Keyword).unwrap_err().message().starts_with("k_s = -1"));
    }

    fn pairs(list: &[(&str, &str)]) -> Vec<(String, String)> {
        list.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()
    }

    /// No field given: the table's defaults (level, 10 s at 50 Hz, 2 s hold, the XL330-M288's
    /// 1470 mA stall current, 65 degC, watchdogs 1 s and 0.5 s, the position profile); the
    /// emulator's fields only with an emulated bus; each error names its flag.
    #[test]
    fn fields_read_given_else_their_defaults() {
        let f = DriveFields::from_params(&[], true).unwrap();
        let expected = DriveRun {
            slope_deg: 0.0,
            duration_s: 10.0,
            rate_hz: 50.0,
            hold_s: 2.0,
            watchdog_s: 1.0,
            bus_watchdog_s: 0.5,
            current_limit_ma: 1470,
            temperature_limit_c: 65,
            stop_on_risk: None,
            emulate_noise_ma: Some(10.0),
            emulate_k_s: None,
        };
        assert_eq!(f.run, expected);
        assert_eq!(
            (f.profile.as_str(), f.baud, f.force, f.live_window, f.emulate_seed),
            ("position", None, false, None, 1)
        );
        let f = DriveFields::from_params(
            &pairs(&[("slope", "-5"), ("profile", "velocity"), ("force", "true")]),
            false,
        )
        .unwrap();
        assert_eq!(
            (f.run.slope_deg, f.run.emulate_noise_ma, f.profile.as_str(), f.force),
            (-5.0, None, "velocity", true)
        );
        let e = DriveFields::from_params(&pairs(&[("emulate-noise", "3")]), false).unwrap_err();
        assert_eq!(e.message(), "--emulate-noise is the emulator's: give --emulate too");
        let e = DriveFields::from_params(&pairs(&[("live-window", "0")]), false).unwrap_err();
        assert_eq!(e.field(), Some("live-window"));
        let e = DriveFields::from_params(&pairs(&[("current-limit", "70000")]), false).unwrap_err();
        assert_eq!(e.message(), "--current-limit = 70000 must be within 0 to 65535");
        let e = DriveFields::from_params(&pairs(&[("duration", "90000")]), false).unwrap_err();
        assert_eq!(e.message(), "--duration = 90000 must be between 0 and 86400");
    }
}
