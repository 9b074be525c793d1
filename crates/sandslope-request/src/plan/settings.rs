//! `plan`'s field table ([`FIELDS`]) and the search's settings, descent rule and objectives
//! read from their fields, checked once for the file-based [`PlanRequest`](super::PlanRequest)
//! and the grid requests of `grid.rs`, messages in the front end's words.

use anyhow::anyhow;

use sandslope::plan::{Descent, Objective, PlanSettings};

use crate::error::{check_range, RequestError, Result, Words};
use crate::field::{Field, Kind, Table};
use crate::grammar;
pub use crate::risk::{CV_N, CV_S};

/// `--dem`: the elevation model.
pub const DEM: Field = Field::text("dem", "FILE")
    .required()
    .help("Elevation model: GeoTIFF (.tif), ESRI ASCII grid (.asc) or PDS3 DTM (.img, .lbl)");
/// `--start`: the start in map coordinates.
pub const START: Field =
    Field::text("start", "X,Y").unit("map units").help("Start in map coordinates (or --start-px)");
/// `--goal`: the goal in map coordinates.
pub const GOAL: Field =
    Field::text("goal", "X,Y").unit("map units").help("Goal in map coordinates (or --goal-px)");
/// `--start-px`: the start as a cell.
pub const START_PX: Field = Field::text("start-px", "COL,ROW")
    .unit("cells")
    .conflicts(&["start"])
    .help("Start as a cell of the DEM (column, row from the north-west corner)");
/// `--goal-px`: the goal as a cell.
pub const GOAL_PX: Field = Field::text("goal-px", "COL,ROW")
    .unit("cells")
    .conflicts(&["goal"])
    .help("Goal as a cell of the DEM (column, row from the north-west corner)");
/// `--objective`: what to minimise (Python's `objectives`, a list of the same words).
pub const OBJECTIVE: Field =
    Field::text("objective", "OBJECTIVE[,...]").keyword("objectives").default("time").help(
        "What to minimise (comma-separated for several); the distance route is always added. \
     `time`: the fastest route through cells whose regime is success; `risk`: the maximum \
     survival probability (plus --time-weight times the time); `distance`: the shortest 3-D \
     length, physics ignored (the naive baseline)",
    );
/// `--classes`: the terrain class raster.
pub const CLASSES: Field = Field::text("classes", "FILE")
    .help("Integer raster aligned with the DEM giving each cell's terrain class (with --class-terrain)");
/// `--class-terrain`: each class's terrain.
pub const CLASS_TERRAIN: Field = Field::text("class-terrain", "CLASS=TERRAIN,...")
    .help("Terrain of each class, e.g. `1=dune.toml,2=crust.toml` (files or presets; with --classes)");
/// `--allow-metastable`: metastable edges for the time objective.
pub const ALLOW_METASTABLE: Field = Field::switch("allow-metastable")
    .keyword("allow_metastable")
    .help("Let the time objective use metastable edges (0 < step < s_min)");
/// `--time-weight`: the risk objective's weight on time (the library's
/// [`sandslope::plan::DEFAULT_TIME_WEIGHT`] by default, a test checks).
pub const TIME_WEIGHT: Field = Field::number("time-weight", "PER_S")
    .keyword("time_weight")
    .key("time_weight")
    .unit("1/s")
    .default("0.0001")
    .range("at least 0")
    .help(
        "Risk objective: weight of travel time, per second (1e-4: 100 s weigh like a 1 % risk; 0: \
         survival only, ties broken by length)",
    );
/// `--max-roll`: the cross-slope limit (the library's [`sandslope::plan::DEFAULT_MAX_ROLL_DEG`]
/// by default, a test checks).
pub const MAX_ROLL: Field = Field::number("max-roll", "DEG")
    .keyword("max_roll_deg")
    .key("max_roll_deg")
    .unit("deg")
    .default("20")
    .range("strictly between 0 and 90")
    .help("Cross-slope (roll) limit, degrees: steeper cross slopes are impassable");
/// `--descent`: how descending edges are evaluated.
pub const DESCENT: Field = Field::new("descent", Kind::Choice(&["symmetric", "level"]), "DESCENT")
    .keyword("descent")
    .default("symmetric")
    .help(
        "How descending edges are evaluated: `symmetric`, as climbing |pitch| (docs/model.md §8 \
         default); `level`, as level ground (optimistic)",
    );
/// `--max-memory`: the memory a DEM's planning may take.
pub const MAX_MEMORY: Field = Field::number("max-memory", "GIB").unit("GiB").help(
    "Refuse a DEM whose planning would need more than this many GiB (default: the memory \
     available when plan starts, MemAvailable in /proc/meminfo)",
);
/// `--search`: how the routes are searched for.
pub const SEARCH: Field =
    Field::new("search", Kind::Choice(&["auto", "full", "corridor"]), "SEARCH").default("auto").help(
        "How to search: `full`, the exact optimum over the whole map (48 bytes a cell); `corridor`, \
         coarse-to-fine for maps too large or slow for that: the routes planned on the map averaged \
         over --coarse-factor cells, then the exact optimum at full resolution inside a corridor of \
         --corridor-width coarse cells on each side of the coarse route (an upper bound on the full \
         optimum; docs/planning.md measures the gap; one terrain, no --plot, --risk-map as a GeoTIFF \
         only, computed band by band); `auto`, full for maps of up to 4096 x 4096 cells, corridor above",
    );
/// `--coarse-factor`: fine cells per coarse cell of the corridor search.
pub const COARSE_FACTOR: Field = Field::new("coarse-factor", Kind::Whole, "N")
    .unit("cells")
    .default("8")
    .range("2 to 64")
    .help("Corridor search: fine cells per coarse cell along each axis (2 to 64)");
/// `--corridor-width`: the corridor's half-width.
pub const CORRIDOR_WIDTH: Field = Field::new("corridor-width", Kind::Whole, "CELLS")
    .unit("coarse cells")
    .default("8")
    .range("1 to 256")
    .help("Corridor search: the corridor's half-width around the coarse route, in coarse cells (1 to 256)");

/// `plan`'s own fields (the robot's and the terrain's are [`crate::scenario`]'s).
pub const FIELDS: Table = Table {
    command: "plan",
    fields: &[
        DEM,
        START,
        GOAL,
        START_PX,
        GOAL_PX,
        OBJECTIVE,
        CLASSES,
        CLASS_TERRAIN,
        ALLOW_METASTABLE,
        TIME_WEIGHT,
        MAX_ROLL,
        DESCENT,
        CV_N,
        CV_S,
        MAX_MEMORY,
        SEARCH,
        COARSE_FACTOR,
        CORRIDOR_WIDTH,
    ],
};

/// The planner's settings from their fields, checked, messages in `words`: the command line's
/// checks its flags first (`--max-roll`, `--time-weight`, `--cv-n`, `--cv-s`); the library
/// names its keys as Python's keywords (`max_roll_deg`, `time_weight`), each mapped back to
/// its field by [`FIELDS`].
#[allow(clippy::too_many_arguments)]
pub fn settings_in(
    words: Words,
    max_roll: f64,
    descent: Descent,
    allow_metastable: bool,
    time_weight: f64,
    cv_n: Option<f64>,
    cv_s: Option<f64>,
) -> Result<PlanSettings> {
    if words == Words::Flag {
        let max_roll = check_range(MAX_ROLL.flag, max_roll, 0.0, 90.0)?;
        if max_roll <= 0.0 || max_roll >= 90.0 {
            return Err(RequestError::invalid(
                MAX_ROLL.flag,
                format!("{} = {max_roll} must be strictly between 0 and 90 degrees", MAX_ROLL.long()),
            ));
        }
        check_range(TIME_WEIGHT.flag, time_weight, 0.0, f64::INFINITY)?;
    }
    grammar::check_cvs_in(words, cv_n, cv_s)?;
    PlanSettings::new(max_roll, descent, allow_metastable, time_weight).map_err(|e| match words {
        Words::Flag => RequestError::from_error(None, anyhow!("{e}")),
        Words::Keyword => RequestError::invalid(FIELDS.by_key(&e.key).unwrap_or(&MAX_ROLL).flag, e),
    })
}

/// The descent rule named `text` (`symmetric` or `level`), or an error in `words`.
pub fn parse_descent(words: Words, text: &str) -> Result<Descent> {
    Descent::parse(text).ok_or_else(|| {
        let message = match words {
            Words::Flag => {
                format!("{} = `{text}` must be symmetric (as climbing |pitch|) or level", DESCENT.long())
            }
            Words::Keyword => format!("{} = {text:?} must be \"symmetric\" or \"level\"", DESCENT.keyword),
        };
        RequestError::invalid(DESCENT.flag, message)
    })
}

/// The objectives of a request in the order given: each item one word or a comma list of
/// them (`time,risk`), so the command line's and HTTP's one text and Python's list of words
/// (or its one text) read alike, each word by [`parse_objective`].
pub fn parse_objectives<S: AsRef<str>>(words: Words, items: &[S]) -> Result<Vec<Objective>> {
    items.iter().flat_map(|item| item.as_ref().split(',')).map(|name| parse_objective(words, name)).collect()
}

/// The objective named `name` (`time`, `risk` or `distance`), or an error in `words`.
pub fn parse_objective(words: Words, name: &str) -> Result<Objective> {
    let name = name.trim();
    Objective::ALL.into_iter().find(|o| o.name() == name).ok_or_else(|| {
        let message = match words {
            Words::Flag => {
                format!("{}: `{name}` is not an objective: time, risk or distance", OBJECTIVE.long())
            }
            Words::Keyword => {
                format!("objective = {name:?} must be \"time\", \"risk\" or \"distance\"")
            }
        };
        RequestError::invalid(OBJECTIVE.flag, message)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::{PlanRequest, PlanSearch};

    fn pairs(list: &[(&str, &str)]) -> Vec<(String, String)> {
        list.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()
    }

    /// The table's defaults of `--max-roll` and `--time-weight` are the library's, which
    /// Python's signatures take.
    #[test]
    fn defaults_are_the_librarys() {
        let number = |f: &Field| f.default.map(|d| d.parse::<f64>().unwrap());
        assert_eq!(number(&MAX_ROLL), Some(sandslope::plan::DEFAULT_MAX_ROLL_DEG));
        assert_eq!(number(&TIME_WEIGHT), Some(sandslope::plan::DEFAULT_TIME_WEIGHT));
        assert_eq!(DESCENT.default.and_then(Descent::parse), Some(Descent::default()));
    }

    /// With a DEM and the endpoints alone, every other field is the table's default: the time
    /// objective, a 20 degree roll limit, 1e-4 per second, the symmetric descent, the search
    /// chosen by size, 8 x 8 coarse cells and a corridor 8 coarse cells wide.
    #[test]
    fn defaults_fill_what_is_not_given() {
        let given = pairs(&[("dem", "d.tif"), ("start", "0,0"), ("goal-px", "1,1")]);
        let r = PlanRequest::from_params(&given).unwrap();
        assert_eq!(r.objectives, vec![Objective::Time]);
        assert_eq!((r.max_roll, r.time_weight, r.descent), (20.0, 1e-4, Descent::Symmetric));
        assert_eq!((r.search, r.coarse_factor, r.corridor_width), (PlanSearch::Auto, 8, 8));
        assert_eq!(
            (r.cv_n, r.cv_s, r.max_memory, r.allow_metastable, r.classes),
            (None, None, None, false, None)
        );
    }

    /// A comma text and a list of words are the same objectives, in the order given; a word
    /// that is none is named in the front end's words.
    #[test]
    fn objectives_read_from_a_comma_text_or_a_list() {
        let both = vec![Objective::Time, Objective::Risk];
        assert_eq!(parse_objectives(Words::Flag, &["time,risk"]).unwrap(), both);
        assert_eq!(parse_objectives(Words::Keyword, &["time", "risk"]).unwrap(), both);
        assert_eq!(
            parse_objectives(Words::Keyword, &[" risk , distance"]).unwrap(),
            vec![Objective::Risk, Objective::Distance]
        );
        let e = parse_objectives(Words::Keyword, &["time,fast"]).unwrap_err();
        assert_eq!(
            (e.field(), e.message().as_str()),
            (Some("objective"), "objective = \"fast\" must be \"time\", \"risk\" or \"distance\"")
        );
        let e = parse_objectives(Words::Flag, &["time,fast"]).unwrap_err();
        assert_eq!(e.message(), "--objective: `fast` is not an objective: time, risk or distance");
    }

    /// The checks across fields name the field at fault: an endpoint missing or given twice,
    /// a class raster without its terrains, a search or objective that is not one.
    #[test]
    fn fields_are_checked_together_naming_their_flag() {
        let err = |list: &[(&str, &str)]| {
            let mut given = pairs(&[("dem", "d.tif")]);
            given.extend(pairs(list));
            PlanRequest::from_params(&given).unwrap_err()
        };
        let e = err(&[("goal", "1,1")]);
        assert_eq!(
            (e.field(), e.message().as_str()),
            (Some("start"), "give --start X,Y or --start-px COL,ROW")
        );
        let e = err(&[("start", "0,0"), ("goal", "1,1"), ("goal-px", "1,1")]);
        assert_eq!(
            (e.field(), e.message().as_str()),
            (Some("goal-px"), "--goal-px cannot be used with --goal: give one")
        );
        let e = err(&[("start", "0,0"), ("goal", "1,1"), ("classes", "c.tif")]);
        assert_eq!(e.message(), "--classes needs --class-terrain too: give both or neither");
        let e = err(&[("start", "0,0"), ("goal", "1,1"), ("search", "fast")]);
        assert_eq!(e.message(), "--search = `fast` must be one of: auto, full, corridor");
        let e = err(&[("start", "0,0"), ("goal", "1,1"), ("objective", "time,speed")]);
        assert_eq!(e.message(), "--objective: `speed` is not an objective: time, risk or distance");
        let e = PlanRequest::from_params(&pairs(&[("start", "0,0"), ("goal", "1,1")])).unwrap_err();
        assert_eq!(e.field(), Some("dem"));
    }

    /// Python's settings errors come back from the library by its keys and are named by the
    /// table's fields.
    #[test]
    fn library_keys_map_to_their_fields() {
        let e = settings_in(Words::Keyword, 20.0, Descent::Symmetric, false, -1.0, None, None).unwrap_err();
        assert_eq!(e.field(), Some("time-weight"));
        let e = settings_in(Words::Keyword, 95.0, Descent::Symmetric, false, 0.0, None, None).unwrap_err();
        assert_eq!(e.field(), Some("max-roll"));
    }
}
