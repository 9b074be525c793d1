//! The ODL label of a PDS3 product (chapter 12 of the PDS3 Standards Reference): statements
//! `KEY = value` inside `OBJECT`/`GROUP` blocks, values as numbers, words, quoted strings,
//! lists and sets with optional `<unit>`s, up to `END`.

use anyhow::{anyhow, bail, Result};

/// Lists nested deeper than this are refused (a label is not a program).
const MAX_NESTING: usize = 16;

/// One value of a label statement: its text (quotes removed) and its `<unit>`, if any.
#[derive(Debug, Clone)]
pub(super) struct Item {
    pub(super) text: String,
    pub(super) unit: Option<String>,
    pub(super) quoted: bool,
}

/// A statement's value: one item, or a list `(a, b)` / set `{a, b}` (nested lists flattened).
#[derive(Debug, Clone)]
pub(super) enum Value {
    One(Item),
    List(Vec<Item>),
}

impl Value {
    /// The value as written, for messages.
    pub(super) fn shown(&self) -> String {
        let item = |i: &Item| {
            let t = if i.quoted { format!("\"{}\"", i.text) } else { i.text.clone() };
            match &i.unit {
                Some(u) => format!("{t} <{u}>"),
                None => t,
            }
        };
        match self {
            Value::One(i) => item(i),
            Value::List(v) => format!("({})", v.iter().map(item).collect::<Vec<_>>().join(", ")),
        }
    }
}

/// A parsed label: `(path, value, line)` with the path the enclosing OBJECT/GROUP names and
/// the keyword joined by dots (`IMAGE.LINES`, `IMAGE_MAP_PROJECTION.MAP_SCALE`).
pub(super) struct Label {
    pub(super) name: String,
    pub(super) entries: Vec<(String, Value, usize)>,
}

impl Label {
    /// The first statement whose path is `key` or ends with `.key`.
    pub(super) fn get(&self, key: &str) -> Option<(&Value, usize)> {
        let dotted = format!(".{key}");
        self.entries.iter().find(|(p, _, _)| p == key || p.ends_with(&dotted)).map(|(_, v, l)| (v, *l))
    }

    /// A numeric value and its unit (upper case), or None when the key is absent.
    pub(super) fn number(&self, key: &str) -> Result<Option<(f64, Option<String>)>> {
        let Some((value, line)) = self.get(key) else { return Ok(None) };
        let Value::One(item) = value else {
            bail!("{}: line {line}: {key} = {} must be one number", self.name, value.shown());
        };
        let x = parse_number(&item.text).ok_or_else(|| {
            anyhow!("{}: line {line}: {key} = {} is not a number", self.name, value.shown())
        })?;
        Ok(Some((x, item.unit.as_ref().map(|u| u.to_ascii_uppercase()))))
    }

    /// A required numeric value and its unit.
    pub(super) fn need_number(&self, key: &str, why: &str) -> Result<(f64, Option<String>)> {
        self.number(key)?.ok_or_else(|| anyhow!("{}: the label has no {key} ({why})", self.name))
    }

    /// A whole number in `min..=max`, or `default` when absent.
    pub(super) fn count(&self, key: &str, min: u64, max: u64, default: Option<u64>) -> Result<u64> {
        match self.number(key)? {
            Some((x, _)) if x.fract() == 0.0 && x >= min as f64 && x <= max as f64 => Ok(x as u64),
            Some((x, _)) => {
                let line = self.get(key).map_or(0, |(_, l)| l);
                bail!("{}: line {line}: {key} = {x} must be a whole number from {min} to {max}", self.name)
            }
            None => default.ok_or_else(|| anyhow!("{}: the label has no {key}", self.name)),
        }
    }

    /// A keyword value (upper case, quotes removed), or None.
    pub(super) fn word(&self, key: &str) -> Option<(String, usize)> {
        match self.get(key)? {
            (Value::One(i), line) => Some((i.text.trim().to_ascii_uppercase(), line)),
            (Value::List(_), _) => None,
        }
    }
}

/// A PDS3 number: decimal, or based integer `radix#digits#` (`16#FF7FFFFB#`).
pub(super) fn parse_number(text: &str) -> Option<f64> {
    parse_based(text).map(|v| v as f64).or_else(|| text.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
}

/// A based integer `radix#digits#` as its bits.
pub(super) fn parse_based(text: &str) -> Option<u64> {
    let t = text.trim();
    let (radix, rest) = t.split_once('#')?;
    let digits = rest.strip_suffix('#')?;
    let radix: u32 = radix.parse().ok().filter(|r| (2..=16).contains(r))?;
    u64::from_str_radix(digits, radix).ok()
}

/// The ODL tokenizer's position in the label text.
struct Cursor<'a> {
    b: &'a [u8],
    pos: usize,
    line: usize,
}

impl Cursor<'_> {
    fn peek(&self) -> Option<u8> {
        self.b.get(self.pos).copied()
    }
    fn bump(&mut self) -> Option<u8> {
        let c = self.peek()?;
        self.pos += 1;
        if c == b'\n' {
            self.line += 1;
        }
        Some(c)
    }
    /// Skips white space and `/* comments */`.
    fn skip_space(&mut self) {
        loop {
            match self.peek() {
                Some(c) if c.is_ascii_whitespace() || c == 0 => {
                    self.bump();
                }
                Some(b'/') if self.b.get(self.pos + 1) == Some(&b'*') => {
                    self.pos += 2;
                    while self.pos < self.b.len() && !self.b[self.pos..].starts_with(b"*/") {
                        self.bump();
                    }
                    self.pos = (self.pos + 2).min(self.b.len());
                }
                _ => return,
            }
        }
    }
    /// A bare word: up to white space or punctuation.
    fn word(&mut self) -> String {
        let start = self.pos;
        while let Some(c) = self.peek() {
            if c.is_ascii_whitespace() || b"=,(){}<>\"'".contains(&c) || c == 0 {
                break;
            }
            self.pos += 1;
        }
        String::from_utf8_lossy(&self.b[start..self.pos]).into_owned()
    }
}

/// Parses an ODL label up to its `END` statement.
pub(super) fn parse_label(name: &str, text: &[u8]) -> Result<Label> {
    let mut c = Cursor { b: text, pos: 0, line: 1 };
    let mut stack: Vec<String> = Vec::new();
    let mut entries = Vec::new();
    loop {
        c.skip_space();
        let line = c.line;
        if c.peek().is_none() {
            bail!(
                "{name}: the PDS3 label has no END statement in its first {} bytes (not a PDS3 label, or truncated)",
                text.len()
            );
        }
        let key = c.word().to_ascii_uppercase();
        if key.is_empty() {
            bail!(
                "{name}: line {line}: expected a keyword, found `{}`",
                char::from(c.peek().unwrap_or(b' '))
            );
        }
        if key == "END" {
            return Ok(Label { name: name.to_owned(), entries });
        }
        c.skip_space();
        if key == "END_OBJECT" || key == "END_GROUP" {
            if c.peek() == Some(b'=') {
                c.bump();
                c.skip_space();
                c.word();
            }
            if stack.pop().is_none() {
                bail!("{name}: line {line}: {key} without an OBJECT or GROUP to end");
            }
            continue;
        }
        if c.bump() != Some(b'=') {
            bail!("{name}: line {line}: keyword `{key}` is not followed by `=`");
        }
        c.skip_space();
        let value = parse_value(name, &mut c, 0)?;
        if key == "OBJECT" || key == "GROUP" {
            let Value::One(item) = &value else {
                bail!("{name}: line {line}: {key} = {} must be a name", value.shown());
            };
            stack.push(item.text.to_ascii_uppercase());
            continue;
        }
        let path = if stack.is_empty() { key } else { format!("{}.{key}", stack.join(".")) };
        entries.push((path, value, line));
    }
}

/// One value: a quoted string, a list or set, or a bare word; then an optional `<unit>`.
fn parse_value(name: &str, c: &mut Cursor, depth: usize) -> Result<Value> {
    if depth > MAX_NESTING {
        bail!("{name}: line {}: lists nested more than {MAX_NESTING} deep", c.line);
    }
    let line = c.line;
    match c.peek() {
        Some(open @ (b'(' | b'{')) => {
            c.bump();
            let close = if open == b'(' { b')' } else { b'}' };
            let mut items: Vec<Item> = Vec::new();
            loop {
                c.skip_space();
                match c.peek() {
                    Some(b',') => {
                        c.bump();
                    }
                    Some(x) if x == close => {
                        c.bump();
                        // A unit after the list (`(450, 550) <NM>`) applies to every item.
                        if let Some(u) = unit(c) {
                            for i in items.iter_mut().filter(|i| i.unit.is_none()) {
                                i.unit = Some(u.clone());
                            }
                        }
                        return Ok(Value::List(items));
                    }
                    None => bail!("{name}: line {line}: a list opened here is never closed"),
                    Some(_) => match parse_value(name, c, depth + 1)? {
                        Value::One(i) => items.push(i),
                        Value::List(v) => items.extend(v),
                    },
                }
            }
        }
        Some(q @ (b'"' | b'\'')) => {
            c.bump();
            let start = c.pos;
            while c.peek().is_some_and(|x| x != q) {
                c.bump();
            }
            if c.peek().is_none() {
                bail!("{name}: line {line}: a quoted value opened here is never closed");
            }
            let text =
                String::from_utf8_lossy(&c.b[start..c.pos]).split_whitespace().collect::<Vec<_>>().join(" ");
            c.bump();
            Ok(Value::One(Item { text, unit: unit(c), quoted: true }))
        }
        _ => {
            let text = c.word();
            if text.is_empty() {
                bail!("{name}: line {line}: a keyword has no value");
            }
            Ok(Value::One(Item { text, unit: unit(c), quoted: false }))
        }
    }
}

/// An optional `<unit>` after a value, on the same line.
fn unit(c: &mut Cursor) -> Option<String> {
    while c.peek().is_some_and(|x| x == b' ' || x == b'\t') {
        c.bump();
    }
    if c.peek() != Some(b'<') {
        return None;
    }
    c.bump();
    let start = c.pos;
    while c.peek().is_some_and(|x| x != b'>' && x != b'\n') {
        c.bump();
    }
    let u = String::from_utf8_lossy(&c.b[start..c.pos]).trim().to_owned();
    if c.peek() == Some(b'>') {
        c.bump();
    }
    Some(u)
}
