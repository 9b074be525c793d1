//! Vicon Nexus CSV: sections such as `Trajectories` or `Model Outputs`, each
//!
//! ```text
//! Trajectories
//! 120
//! ,,robot:CoM,,,robot:LFHD,,,
//! Frame,Sub Frame,X,Y,Z,X,Y,Z
//! ,,mm,mm,mm,mm,mm,mm
//! 1,0,12.3,45.6,78.9,...
//! ```
//!
//! Bodies are the names over an `X,Y,Z` triple with a length unit; `--body` may give the
//! full name (`robot:CoM`) or the part after the colon (`CoM`). Frame `f` is at time
//! `(f - 1) / rate` (frame 1 at t = 0); frames are counted from the rows.

use anyhow::Result;

use super::{pick_body, unit_scale, Rows};

/// Section headers of a Nexus CSV.
pub(crate) const SECTIONS: [&str; 5] = ["Trajectories", "Model Outputs", "Devices", "Joints", "Segments"];

struct Candidate {
    section: usize,
    rate: f64,
    cols: [usize; 3],
    scale: f64,
}

fn is_section(cell: &str) -> bool {
    SECTIONS.iter().any(|s| cell.eq_ignore_ascii_case(s))
}

pub(crate) fn parse(rows: &Rows, body: Option<&str>) -> Result<super::motive::Parsed> {
    let r = &rows.rows;
    let mut candidates: Vec<(String, Candidate)> = Vec::new();
    let mut first_line = r.first().map_or(1, |(l, _)| *l);
    let mut found_section = false;
    let mut i = 0;
    while i < r.len() {
        let head = r[i].1.get(0).unwrap_or("");
        if !(head.eq_ignore_ascii_case("Trajectories") || head.eq_ignore_ascii_case("Model Outputs")) {
            i += 1;
            continue;
        }
        found_section = true;
        first_line = r[i].0;
        if i + 4 >= r.len() {
            return Err(rows.err(
                r[r.len() - 1].0,
                format!(
                    "truncated header: section `{head}` needs a frame-rate row, a name row, `Frame,Sub Frame,X,Y,Z` \
                     and a units row"
                ),
            ));
        }
        let (rate_line, rate_row) = &r[i + 1];
        let rate_cell = rate_row.get(0).unwrap_or("");
        let rate = match rate_cell.parse::<f64>() {
            Ok(v) if v.is_finite() && v > 0.0 => v,
            _ => {
                return Err(
                    rows.err(*rate_line, format!("frame rate `{rate_cell}` must be a number greater than 0"))
                )
            }
        };
        let (names, (cols_line, cols), units) = (&r[i + 2].1, &r[i + 3], &r[i + 4].1);
        if !cols.get(0).is_some_and(|c| c.eq_ignore_ascii_case("Frame")) {
            return Err(rows.err(
                *cols_line,
                "truncated header: expected the column-name row `Frame,Sub Frame,X,Y,Z,...`",
            ));
        }
        let section = i;
        for c in 2..cols.len().saturating_sub(2) {
            let name = names.get(c).unwrap_or("");
            if name.is_empty()
                || (cols.get(c), cols.get(c + 1), cols.get(c + 2)) != (Some("X"), Some("Y"), Some("Z"))
            {
                continue;
            }
            if let Some(scale) = unit_scale(units.get(c).unwrap_or("")) {
                candidates
                    .push((name.to_string(), Candidate { section, rate, cols: [c, c + 1, c + 2], scale }));
            }
        }
        i += 5;
    }
    if !found_section {
        return Err(rows.err(first_line, "no `Trajectories` or `Model Outputs` section"));
    }
    if candidates.is_empty() {
        return Err(
            rows.err(first_line, "no position columns: no name over an `X,Y,Z` triple with units mm or m")
        );
    }
    // Vicon names columns `subject:segment`; either part alone selects it when unique.
    let (name, cand) = pick_body(rows, first_line, candidates, body, |n, w| {
        n == w || n.split_once(':').is_some_and(|(subject, segment)| subject == w || segment == w)
    })?;
    let rate = cand.rate;
    let mut positions = Vec::new();
    let mut first_frame = None;
    for (line, rec) in &r[cand.section + 5..] {
        let frame = rec.get(0).unwrap_or("");
        if is_section(frame) {
            break;
        }
        let f =
            frame.parse::<f64>().ok().filter(|f| f.is_finite()).ok_or_else(|| {
                rows.err(*line, format!("column 1 (Frame): `{frame}` is not a frame number"))
            })?;
        first_frame.get_or_insert(f);
        let mut p = [0.0; 3];
        for (k, &c) in cand.cols.iter().enumerate() {
            let what = format!("`{name}` {}", ["X", "Y", "Z"][k]);
            p[k] = rows.position_cell(*line, rec, c, &what)? * cand.scale;
        }
        positions.push(p);
    }
    if positions.is_empty() {
        return Err(rows.err(r[cand.section + 4].0, "no data rows after the units row"));
    }
    let start = (first_frame.unwrap_or(1.0) - 1.0) / rate;
    Ok((name, rate, start, positions))
}
