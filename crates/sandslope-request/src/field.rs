//! The field tables: every field of a request written once, in the manner of ripgrep's flag
//! definitions. A [`Field`] holds its names (the command-line flag, which is also the HTTP
//! field, and the Python keyword), the library key it sets, its unit, default, kind (its
//! parser), valid range and help line; a request's [`Table`] lists its fields.
//!
//! Every front end reads a request through its table: the command line builds its clap
//! arguments from it and hands the flags given, as `key=value` text pairs, to the request's
//! `from_params` (the one raw-to-typed step, which the server's query and JSON body go
//! through too, [`crate::Params`]); Python's keywords and stubs are checked against it by
//! tests; errors from the library, named by its keys, are mapped back to the field through
//! [`Table::by_key`].

use crate::error::{RequestError, Result};
use crate::params::Params;

/// How a field's text is read: its parser.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A real number (`f64::from_str`, negative values allowed through).
    Number,
    /// A whole number from 0 to 2^32 - 1.
    Whole,
    /// Text: a file, a preset, or a list in a grammar the request itself parses.
    Text,
    /// A switch: given (true) or not; over HTTP `true`, `false`, `1`, `0` or empty.
    Switch,
    /// One of a few words.
    Choice(&'static [&'static str]),
    /// Text that may be given more than once on the command line (`--vary A --vary B`), read
    /// as one comma list (`A,B`), as HTTP and Python give it.
    List,
}

/// One field of a request, written once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Field {
    /// The command-line flag without its dashes, also the HTTP field (`k-s`).
    pub flag: &'static str,
    /// The Python keyword, empty where Python does not take it (`k_s`).
    pub keyword: &'static str,
    /// The library key the field sets (the key of the library's [`sandslope::ParamError`]),
    /// empty where it sets none.
    pub key: &'static str,
    /// The unit of its value, empty for none.
    pub unit: &'static str,
    /// The placeholder of its value in `--help` (`DEG`).
    pub value_name: &'static str,
    /// Its parser.
    pub kind: Kind,
    /// Its default as text, read by the same parser as a given value; `None` when the field
    /// is optional without one (or required).
    pub default: Option<&'static str>,
    /// Its valid range in words (checked by the request or the library), empty for any.
    pub range: &'static str,
    /// Its line in `--help` (and the docs' option lists); `{fallback}` in it stands for
    /// [`Field::fallback`] ([`Field::help_line`] writes it in).
    pub help: &'static str,
    /// The value the request uses when neither the field nor a file gives one, where that is
    /// a library constant rather than a default the field parses (`--cv-n`'s
    /// `sandslope::risk::DEFAULT_CV_N`, used only when the terrain has no k_n_sd either).
    pub fallback: Option<f64>,
    /// Fields of the same table it cannot be given with.
    pub conflicts: &'static [&'static str],
    /// Whether every request must give it.
    pub required: bool,
}

impl Field {
    /// A field named `flag` (keyword and key empty) of `kind`, no default, no help yet.
    pub const fn new(flag: &'static str, kind: Kind, value_name: &'static str) -> Field {
        Field {
            flag,
            keyword: "",
            key: "",
            unit: "",
            value_name,
            kind,
            default: None,
            range: "",
            help: "",
            fallback: None,
            conflicts: &[],
            required: false,
        }
    }

    /// A number field.
    pub const fn number(flag: &'static str, value_name: &'static str) -> Field {
        Field::new(flag, Kind::Number, value_name)
    }

    /// A text field.
    pub const fn text(flag: &'static str, value_name: &'static str) -> Field {
        Field::new(flag, Kind::Text, value_name)
    }

    /// A switch.
    pub const fn switch(flag: &'static str) -> Field {
        Field::new(flag, Kind::Switch, "")
    }

    /// With its Python keyword.
    pub const fn keyword(self, keyword: &'static str) -> Field {
        Field { keyword, ..self }
    }

    /// With the library key it sets.
    pub const fn key(self, key: &'static str) -> Field {
        Field { key, ..self }
    }

    /// With its unit.
    pub const fn unit(self, unit: &'static str) -> Field {
        Field { unit, ..self }
    }

    /// With its default, as text.
    pub const fn default(self, default: &'static str) -> Field {
        Field { default: Some(default), ..self }
    }

    /// With its valid range in words.
    pub const fn range(self, range: &'static str) -> Field {
        Field { range, ..self }
    }

    /// With its help line.
    pub const fn help(self, help: &'static str) -> Field {
        Field { help, ..self }
    }

    /// With the library's value used when neither the field nor a file gives one, written
    /// into the help line at `{fallback}`.
    pub const fn fallback(self, value: f64) -> Field {
        Field { fallback: Some(value), ..self }
    }

    /// The help line as `--help` prints it: [`Field::help`] with `{fallback}` replaced by the
    /// fallback value (`0.1`).
    pub fn help_line(&self) -> String {
        match self.fallback {
            Some(v) => self.help.replace("{fallback}", &v.to_string()),
            None => self.help.to_string(),
        }
    }

    /// With the fields it cannot be given with.
    pub const fn conflicts(self, conflicts: &'static [&'static str]) -> Field {
        Field { conflicts, ..self }
    }

    /// Required: every request must give it.
    pub const fn required(self) -> Field {
        Field { required: true, ..self }
    }

    /// The flag with its dashes (`--k-s`), for messages.
    pub fn long(&self) -> String {
        format!("--{}", self.flag)
    }

    /// Its valid range as numbers, read from its range words ([`bounds_of`]): `(lower,
    /// upper)`, each `None` where the words give no number (what the explorer page writes
    /// into its inputs' `min` and `max`).
    pub fn bounds(&self) -> (Option<Bound>, Option<Bound>) {
        bounds_of(self.range)
    }

    /// The text given for the field in `p`, else its default.
    pub fn text_in<'a>(&self, p: &mut Params<'a>) -> Result<Option<&'a str>> {
        Ok(p.text(self.flag)?.or(self.default))
    }

    /// The field in `p` as a number (given, else its default), checked to be one.
    pub fn number_in(&self, p: &mut Params<'_>) -> Result<Option<f64>> {
        let Some(text) = self.text_in(p)? else { return Ok(None) };
        text.trim().parse::<f64>().map(Some).map_err(|_| {
            RequestError::invalid(self.flag, format!("--{} = `{text}` is not a number", self.flag))
        })
    }

    /// The field in `p` as a number that has a default or must be given.
    pub fn required_number_in(&self, p: &mut Params<'_>) -> Result<f64> {
        self.number_in(p)?.ok_or_else(|| {
            RequestError::invalid(self.flag, format!("--{} is required: {}", self.flag, self.help_line()))
        })
    }

    /// The field in `p` as a whole number from 0 to 2^32 - 1 (given, else its default).
    pub fn whole_in(&self, p: &mut Params<'_>) -> Result<Option<u32>> {
        let Some(text) = self.text_in(p)? else { return Ok(None) };
        text.trim().parse::<u32>().map(Some).map_err(|_| {
            RequestError::invalid(
                self.flag,
                format!("--{} = `{text}` is not a whole number of at least 0", self.flag),
            )
        })
    }

    /// The switch in `p` (absent: false).
    pub fn switch_in(&self, p: &mut Params<'_>) -> Result<bool> {
        p.flag(self.flag)
    }

    /// The field in `p` as one of its choices (given, else its default).
    pub fn choice_in<'a>(&self, p: &mut Params<'a>) -> Result<Option<&'a str>> {
        let Some(text) = self.text_in(p)? else { return Ok(None) };
        let Kind::Choice(choices) = self.kind else { return Ok(Some(text)) };
        let word = text.trim();
        match choices.iter().find(|c| **c == word) {
            Some(_) => Ok(Some(word)),
            None => Err(RequestError::invalid(
                self.flag,
                format!("--{} = `{text}` must be one of: {}", self.flag, choices.join(", ")),
            )),
        }
    }
}

/// One end of a field's valid range as a number, read from its range words.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    /// The end's value, in the field's unit.
    pub value: f64,
    /// Whether the end itself is valid (`0 to 1`, `at least 0`) or not (`strictly between 0
    /// and 1`, `greater than 0`).
    pub inclusive: bool,
}

/// The lower and upper ends of a range written in words, each `None` where the words give no
/// number for it (`at least 1.5 T`, `between 0 and 2R`'s upper end, `within the model's`).
/// The forms: `A to B`, `from A to B`, `a whole number from A to B`, `between A and B`,
/// `strictly between A and B`, `at least A`, `greater than A`, `at most B`, `less than B`,
/// `greater than A, at most B`, each optionally followed by a note in parentheses.
pub fn bounds_of(range: &str) -> (Option<Bound>, Option<Bound>) {
    let words = range.split(" (").next().unwrap_or("").trim();
    let end = |text: &str, inclusive: bool| {
        text.trim().parse::<f64>().ok().filter(|v| v.is_finite()).map(|value| Bound { value, inclusive })
    };
    let pair = |text: &str, sep: &str, inclusive: bool| match text.split_once(sep) {
        Some((lo, hi)) => (end(lo, inclusive), end(hi, inclusive)),
        None => (None, None),
    };
    if let Some(rest) = words.strip_prefix("strictly between ") {
        return pair(rest, " and ", false);
    }
    if let Some(rest) = words.strip_prefix("between ") {
        return pair(rest, " and ", true);
    }
    if let Some(rest) = words.strip_prefix("a whole number from ").or_else(|| words.strip_prefix("from ")) {
        return pair(rest, " to ", true);
    }
    if let Some(rest) = words.strip_prefix("greater than ") {
        return match rest.split_once(", at most ") {
            Some((lo, hi)) => (end(lo, false), end(hi, true)),
            None => (end(rest, false), None),
        };
    }
    if let Some(rest) = words.strip_prefix("at least ") {
        return (end(rest, true), None);
    }
    if let Some(rest) = words.strip_prefix("at most ") {
        return (None, end(rest, true));
    }
    if let Some(rest) = words.strip_prefix("less than ") {
        return (None, end(rest, false));
    }
    pair(words, " to ", true)
}

/// The fields of one request, in the order of its `--help`.
#[derive(Debug, Clone, Copy)]
pub struct Table {
    /// The command (`sweep`), as messages name it.
    pub command: &'static str,
    /// Its own fields (the robot and terrain fields shared by several requests are in
    /// [`crate::scenario::FIELDS`] and the library's table of robot keys).
    pub fields: &'static [Field],
}

impl Table {
    /// The field of `flag`; a name no field has is a mistake in the code (panics).
    pub fn field(&self, flag: &str) -> &'static Field {
        self.fields
            .iter()
            .find(|f| f.flag == flag)
            .unwrap_or_else(|| panic!("{} has no field `{flag}`", self.command))
    }

    /// The field setting the library key `key`, if any.
    pub fn by_key(&self, key: &str) -> Option<&'static Field> {
        self.fields.iter().find(|f| !f.key.is_empty() && f.key == key)
    }

    /// The field of the Python keyword `keyword`, if any.
    pub fn by_keyword(&self, keyword: &str) -> Option<&'static Field> {
        self.fields.iter().find(|f| !f.keyword.is_empty() && f.keyword == keyword)
    }
}

/// A request read through a field table (what the command line builds its arguments from).
pub trait Fields {
    /// The request's own fields.
    const TABLE: Table;
}

#[cfg(test)]
mod tests {
    use super::*;

    const F: Field = Field::number("step", "DEG").default("1").keyword("step_deg").key("step");
    const C: Field = Field::new("mode", Kind::Choice(&["a", "b"]), "a|b").default("a");

    fn pairs(list: &[(&str, &str)]) -> Vec<(String, String)> {
        list.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()
    }

    /// The range words read as numbers, worked by hand from each form.
    #[test]
    fn range_words_read_as_bounds() {
        let b = |value: f64, inclusive: bool| Some(Bound { value, inclusive });
        assert_eq!(bounds_of("-90 to 90"), (b(-90.0, true), b(90.0, true)));
        assert_eq!(bounds_of("-90 to 90 (docs/model.md §8)"), (b(-90.0, true), b(90.0, true)));
        assert_eq!(bounds_of("1e-9 to 1e-3"), (b(1e-9, true), b(0.001, true)));
        assert_eq!(bounds_of("strictly between 0 and 1"), (b(0.0, false), b(1.0, false)));
        assert_eq!(bounds_of("between 0 and 2R"), (b(0.0, true), None));
        assert_eq!(bounds_of("a whole number from 2 to 1000"), (b(2.0, true), b(1000.0, true)));
        assert_eq!(bounds_of("from 0.001 to 250"), (b(0.001, true), b(250.0, true)));
        assert_eq!(bounds_of("at least 0"), (b(0.0, true), None));
        assert_eq!(bounds_of("at least 1.5 T"), (None, None));
        assert_eq!(bounds_of("greater than 0"), (b(0.0, false), None));
        assert_eq!(bounds_of("greater than 0, at most 1"), (b(0.0, false), b(1.0, true)));
        assert_eq!(bounds_of("greater than 0, plausible (docs/model.md §7)"), (None, None));
        assert_eq!(bounds_of("at most T / 100"), (None, None));
        assert_eq!(bounds_of("less than 5"), (None, b(5.0, false)));
        assert_eq!(bounds_of("0 to 90 each, at most 10,000"), (b(0.0, true), None));
        assert_eq!(bounds_of("within the model's"), (None, None));
        assert_eq!(bounds_of(""), (None, None));
        assert_eq!(F.bounds(), (None, None));
    }

    /// A field reads its text, else its default, with its own parser; a bad value is named
    /// by its flag.
    #[test]
    fn a_field_reads_given_else_default() {
        let none = pairs(&[]);
        assert_eq!(F.number_in(&mut Params::new("x", &none)).unwrap(), Some(1.0));
        let given = pairs(&[("step", " 2.5")]);
        assert_eq!(F.number_in(&mut Params::new("x", &given)).unwrap(), Some(2.5));
        let bad = pairs(&[("step", "x")]);
        let e = F.number_in(&mut Params::new("x", &bad)).unwrap_err();
        assert_eq!(e.field(), Some("step"));
        assert_eq!(e.message(), "--step = `x` is not a number");
        assert_eq!(C.choice_in(&mut Params::new("x", &none)).unwrap(), Some("a"));
        let bad = pairs(&[("mode", "c")]);
        let e = C.choice_in(&mut Params::new("x", &bad)).unwrap_err();
        assert_eq!(e.message(), "--mode = `c` must be one of: a, b");
        const T: Table = Table { command: "x", fields: &[F, C] };
        assert_eq!(T.by_key("step").map(|f| f.flag), Some("step"));
        assert_eq!(T.by_keyword("step_deg").map(|f| f.flag), Some("step"));
        assert_eq!(T.by_key("none"), None);
    }
}
