//! The routes' table that `sandslope plan` prints, and the note on the time route.

use sandslope::plan::{NoRoute, Objective, Route};
use sandslope::Regime;
use sandslope_request::format::Explain;

use crate::output::{num, table};

/// Prints the routes' table and the note on the time route.
pub(super) fn print_routes(routes: &[(Objective, Result<Route, NoRoute>)], allow_metastable: bool) {
    let mut t = table(&[
        "route",
        "found",
        "length m",
        "time s",
        "survival",
        "max pitch deg",
        "max roll deg",
        "edges by regime",
    ]);
    for (o, r) in routes {
        match r {
            Ok(r) => {
                let regimes = Regime::ALL
                    .iter()
                    .zip(r.regimes)
                    .filter(|(_, n)| *n > 0)
                    .map(|(g, n)| format!("{g} {n}"))
                    .chain((r.over_roll_limit > 0).then(|| format!("over roll limit {}", r.over_roll_limit)))
                    .collect::<Vec<_>>()
                    .join(", ");
                t.add_row(vec![
                    o.name().to_string(),
                    "yes".into(),
                    num(Some(r.length_m), 1),
                    num(r.time_s, 1),
                    format!("{:.4}", r.survival),
                    num(Some(r.max_pitch_deg), 1),
                    num(Some(r.max_roll_deg), 1),
                    regimes,
                ]);
            }
            Err(e) => {
                t.add_row(vec![
                    o.name().to_string(),
                    "no".into(),
                    "-".into(),
                    "-".into(),
                    "-".into(),
                    "-".into(),
                    "-".into(),
                    e.explain().into(),
                ]);
            }
        }
    }
    println!("{t}");
    if let Some(note) = time_route_note(routes, allow_metastable) {
        println!("note: {note}");
    }
}

/// Why the time route can be slower than another route: it uses success edges only unless
/// `--allow-metastable`, while the risk route may cross metastable edges (issue 28).
fn time_route_note(
    routes: &[(sandslope::plan::Objective, Result<sandslope::plan::Route, sandslope::plan::NoRoute>)],
    allow_metastable: bool,
) -> Option<String> {
    use sandslope::plan::Objective;
    if allow_metastable {
        return None;
    }
    let time_of = |o: Objective| {
        routes.iter().find(|(k, _)| *k == o).and_then(|(_, r)| r.as_ref().ok()).and_then(|r| r.time_s)
    };
    let fastest = time_of(Objective::Time)?;
    let (other, t) = routes
        .iter()
        .filter(|(k, _)| *k != Objective::Time)
        .filter_map(|(k, r)| Some((*k, r.as_ref().ok()?.time_s?)))
        .filter(|(_, t)| *t < fastest)
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    Some(format!(
        "the {} route ({t:.1} s) is faster than the time route ({fastest:.1} s): the time route uses only \
         edges where the robot succeeds (unless --allow-metastable), and the other crosses metastable ones \
         (docs/planning.md)",
        other.name()
    ))
}
