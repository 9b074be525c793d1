//! OptiTrack Motive CSV export, format versions 1.23 and 1.25.
//!
//! ```text
//! Format Version,1.25,Take Name,...,Capture Frame Rate,120.0,Export Frame Rate,120.0,...,Length Units,Millimeters,...
//!
//! ,Type,Rigid Body,Rigid Body,...
//! ,Name,robot,robot,...
//! ,ID,1,1,...
//! ,Parent,,,...                      (1.25 only)
//! ,,Rotation,Rotation,Rotation,Rotation,Position,Position,Position,...
//! Frame,Time (Seconds),X,Y,Z,W,X,Y,Z,...
//! 0,0.000000,...
//! ```
//!
//! Frames are counted from the data rows (not from the header's frame count); the export
//! frame rate is used when it differs from the capture rate; empty cells are occlusions.

use std::collections::BTreeMap;

use anyhow::Result;

use super::{pick_body, unit_scale, Rows};

/// Body name, frame rate, first time and positions (m).
pub(crate) type Parsed = (String, f64, f64, Vec<[f64; 3]>);

pub(crate) fn parse(rows: &Rows, body: Option<&str>) -> Result<Parsed> {
    let (frame_rate, scale) = metadata(rows)?;
    let (header, names_at) = header_rows(rows)?;
    let names_line = rows.rows[names_at].0;
    let candidates = position_columns(rows, &header, names_at)?;
    let (name, cols) = pick_body(rows, names_line, candidates, body, |n, w| n == w)?;

    let mut positions = Vec::with_capacity(rows.rows.len() - names_at);
    let mut start_time = None;
    for (line, r) in &rows.rows[names_at + 1..] {
        if start_time.is_none() {
            let t = r.get(1).unwrap_or("");
            start_time = Some(t.parse::<f64>().ok().filter(|t| t.is_finite()).ok_or_else(|| {
                rows.err(*line, format!("column 2 (Time (Seconds)): `{t}` is not a number"))
            })?);
        }
        let mut p = [0.0; 3];
        for (k, &c) in cols.iter().enumerate() {
            let what = format!("`{name}` {}", ["X", "Y", "Z"][k]);
            p[k] = rows.position_cell(*line, r, c, &what)? * scale;
        }
        positions.push(p);
    }
    if positions.is_empty() {
        return Err(rows.err(names_line, "no data rows after the column names"));
    }
    Ok((name, frame_rate, start_time.unwrap_or(0.0), positions))
}

/// The metadata row's frame rate (export, else capture) and length unit in metres.
fn metadata(rows: &Rows) -> Result<(f64, f64)> {
    let Some((meta_line, meta)) = rows.rows.first() else {
        return Err(anyhow::anyhow!("{}: the file is empty", rows.path.display()));
    };
    let meta_line = *meta_line;
    let cells: Vec<&str> = meta.iter().collect();
    let mut keys = BTreeMap::new();
    for pair in cells.chunks(2) {
        if let [k, v] = pair {
            keys.insert(k.to_ascii_lowercase(), *v);
        }
    }
    if !cells.first().is_some_and(|c| c.eq_ignore_ascii_case("Format Version")) {
        return Err(rows.err(meta_line, "not a Motive CSV export: the first cell must be `Format Version`"));
    }
    let rate_of = |key: &str| -> Result<Option<f64>> {
        match keys.get(key) {
            None => Ok(None),
            Some(v) => match v.parse::<f64>() {
                Ok(r) if r.is_finite() && r > 0.0 => Ok(Some(r)),
                _ => Err(rows.err(meta_line, format!("`{key}` = `{v}` must be a frame rate greater than 0"))),
            },
        }
    };
    let capture = rate_of("capture frame rate")?;
    let export = rate_of("export frame rate")?;
    let frame_rate = export.or(capture).ok_or_else(|| {
        rows.err(meta_line, "no `Export Frame Rate` or `Capture Frame Rate` in the metadata row")
    })?;
    let scale = match keys.get("length units") {
        None => 1.0,
        Some(u) => unit_scale(u).ok_or_else(|| {
            rows.err(meta_line, format!("`Length Units` = `{u}` must be Meters, Centimeters or Millimeters"))
        })?,
    };
    Ok((frame_rate, scale))
}

/// The header rows (`type`, `name`, `id`, `parent`, `kind` -> row index) up to the column-name
/// row `Frame,Time (Seconds),...`, and that row's index.
fn header_rows(rows: &Rows) -> Result<(BTreeMap<&'static str, usize>, usize)> {
    let meta_line = rows.rows.first().map_or(0, |(l, _)| *l);
    // Header rows up to the column-name row `Frame,Time (Seconds),...`.
    let mut header: BTreeMap<&'static str, usize> = BTreeMap::new();
    let mut names_at = None;
    for (i, (_, r)) in rows.rows.iter().enumerate().skip(1) {
        let label = r.get(1).unwrap_or("");
        if r.get(0).is_some_and(|c| c.eq_ignore_ascii_case("Frame")) {
            names_at = Some(i);
            break;
        }
        let kind = match label.to_ascii_lowercase().as_str() {
            "type" => "type",
            "name" => "name",
            "id" => "id",
            "parent" => "parent",
            "" if r.iter().any(|c| c == "Position" || c == "Rotation") => "kind",
            _ => continue,
        };
        header.insert(kind, i);
    }
    let last_line = rows.rows.last().map_or(meta_line, |(l, _)| *l);
    let Some(names_at) = names_at else {
        return Err(rows.err(
            last_line,
            "truncated header: the file ends before the column-name row `Frame,Time (Seconds),X,Y,Z,...` (a Motive \
             export has rows Type, Name, ID, [Parent,] Rotation/Position, then the column names)",
        ));
    };
    let names_line = rows.rows[names_at].0;
    for needed in ["type", "name", "kind"] {
        if !header.contains_key(needed) {
            let what = if needed == "kind" { "`Rotation`/`Position`" } else { needed };
            return Err(
                rows.err(names_line, format!("truncated header: no {what} row before the column names"))
            );
        }
    }
    Ok((header, names_at))
}

/// The position X/Y/Z columns of each rigid body (of each marker if there is no rigid body).
fn position_columns(
    rows: &Rows,
    header: &BTreeMap<&'static str, usize>,
    names_at: usize,
) -> Result<Vec<(String, [usize; 3])>> {
    let names_line = rows.rows[names_at].0;
    let row = |k: &str| &rows.rows[header[k]].1;
    let (types, names, kinds, axes) = (row("type"), row("name"), row("kind"), &rows.rows[names_at].1);

    // Position X/Y/Z columns per body, rigid bodies first, markers if there are none.
    let mut bodies: Vec<(String, &str, [Option<usize>; 3])> = Vec::new();
    for c in 2..axes.len() {
        if kinds.get(c) != Some("Position") {
            continue;
        }
        let axis = match axes.get(c) {
            Some("X") => 0,
            Some("Y") => 1,
            Some("Z") => 2,
            _ => continue,
        };
        let (ty, name) = (types.get(c).unwrap_or(""), names.get(c).unwrap_or(""));
        match bodies.iter_mut().find(|(n, t, _)| n == name && *t == ty) {
            Some(b) => b.2[axis] = Some(c),
            None => {
                let mut cols = [None; 3];
                cols[axis] = Some(c);
                bodies.push((name.to_string(), ty, cols));
            }
        }
    }
    let complete = |ty: &str| -> Vec<(String, [usize; 3])> {
        bodies
            .iter()
            .filter(|(_, t, _)| t.eq_ignore_ascii_case(ty))
            .filter_map(|(n, _, c)| Some((n.clone(), [c[0]?, c[1]?, c[2]?])))
            .collect()
    };
    let mut candidates = complete("Rigid Body");
    if candidates.is_empty() {
        candidates = complete("Marker");
    }
    if candidates.is_empty() {
        return Err(rows.err(
            names_line,
            "no position columns: no rigid body or marker has X, Y and Z columns under `Position`",
        ));
    }
    Ok(candidates)
}
