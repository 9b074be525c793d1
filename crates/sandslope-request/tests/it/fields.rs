//! The field tables hold together: within a request no flag or keyword is taken twice, every
//! default reads with the field's own parser (a choice's among its words), and every flag is
//! in the user docs (docs/*.md or README.md), so an option list cannot leave one out.

use sandslope_request::field::{Kind, Table};
use sandslope_request::{
    calibrate, design, drive, fit, infer, phase, plan, predict, report, risk, scenario, simulate, sweep,
    track,
};

/// Each request's tables: its own, then those it shares.
fn requests() -> Vec<(&'static str, Vec<Table>)> {
    let shared = || vec![scenario::FIELDS, scenario::ROBOT_QUANTITIES];
    // A request on the robot and terrain alone, without the overrides of k_n and k_s.
    let robot_and_terrain = Table { command: "scenario", fields: &[scenario::ROBOT, scenario::TERRAIN] };
    let quantities = scenario::ROBOT_QUANTITIES.fields;
    assert_eq!(quantities[0], scenario::MASS, "the mass is the first robot quantity");
    let without_mass = Table { command: "robot", fields: &quantities[1..] };
    vec![
        ("sweep", [vec![sweep::FIELDS], shared()].concat()),
        ("predict", [vec![predict::FIELDS], shared()].concat()),
        ("simulate", [vec![simulate::FIELDS], shared()].concat()),
        ("risk", vec![risk::FIELDS, robot_and_terrain, scenario::ROBOT_QUANTITIES]),
        // phase's masses are its panels', not the robot's override.
        ("phase", vec![phase::FIELDS, robot_and_terrain, without_mass]),
        ("drive", vec![drive::FIELDS, robot_and_terrain, scenario::ROBOT_QUANTITIES]),
        ("fit", vec![fit::FIELDS]),
        ("calibrate", vec![calibrate::FIELDS, robot_and_terrain, scenario::ROBOT_QUANTITIES]),
        // report's --tracks is given per slope, beside its once-given fields.
        (
            "report",
            vec![
                report::FIELDS,
                Table { command: "report", fields: &[report::TRACKS, scenario::LEVEL_STEP] },
                robot_and_terrain,
                scenario::ROBOT_QUANTITIES,
            ],
        ),
        ("plan", vec![plan::FIELDS, robot_and_terrain, scenario::ROBOT_QUANTITIES]),
        ("design", vec![design::FIELDS, robot_and_terrain, scenario::ROBOT_QUANTITIES]),
        ("infer", vec![infer::FIELDS, robot_and_terrain, scenario::ROBOT_QUANTITIES]),
        ("track", vec![track::FIELDS, robot_and_terrain, scenario::ROBOT_QUANTITIES]),
    ]
}

#[test]
fn no_flag_or_keyword_is_taken_twice_in_a_request() {
    for (command, tables) in requests() {
        let fields: Vec<_> = tables.iter().flat_map(|t| t.fields.iter()).collect();
        for (i, f) in fields.iter().enumerate() {
            for g in &fields[i + 1..] {
                assert_ne!(f.flag, g.flag, "{command}: --{} twice", f.flag);
                if !f.keyword.is_empty() {
                    assert_ne!(f.keyword, g.keyword, "{command}: keyword {} twice", f.keyword);
                }
            }
            for other in f.conflicts {
                assert!(
                    fields.iter().any(|g| g.flag == *other),
                    "{command}: --{} conflicts with no --{other}",
                    f.flag
                );
            }
            assert!(!f.help.is_empty(), "{command}: --{} has no help line", f.flag);
            // A fallback is written into the help where it says `{fallback}`, and only there.
            assert_eq!(f.help.contains("{fallback}"), f.fallback.is_some(), "{command}: --{}", f.flag);
            assert!(!f.help_line().contains("{fallback}"), "{command}: --{}: {}", f.flag, f.help_line());
        }
    }
}

#[test]
fn every_default_reads_with_its_fields_parser() {
    for (command, tables) in requests() {
        for f in tables.iter().flat_map(|t| t.fields.iter()) {
            let Some(default) = f.default else { continue };
            match f.kind {
                Kind::Number => assert!(default.parse::<f64>().is_ok(), "{command} --{}", f.flag),
                Kind::Whole => assert!(default.parse::<u32>().is_ok(), "{command} --{}", f.flag),
                Kind::Choice(words) => assert!(words.contains(&default), "{command} --{}", f.flag),
                Kind::Switch => panic!("{command}: the switch --{} has a default", f.flag),
                Kind::Text | Kind::List => {}
            }
        }
    }
}

#[test]
fn every_flag_is_in_the_user_docs() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    let mut docs = std::fs::read_to_string(format!("{root}/README.md")).unwrap();
    for entry in std::fs::read_dir(format!("{root}/docs")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "md") {
            docs.push_str(&std::fs::read_to_string(path).unwrap());
        }
    }
    for (command, tables) in requests() {
        for f in tables.iter().flat_map(|t| t.fields.iter()) {
            let flag = format!("--{}", f.flag);
            let documented = docs.match_indices(&flag).any(|(i, _)| {
                !docs[i + flag.len()..].starts_with(|c: char| c.is_ascii_alphanumeric() || c == '-')
            });
            assert!(documented, "{command}: {flag} is in no page of docs/ nor the README");
        }
    }
}

/// The parameters of the Python function `name` as written in `text` between `start` and the
/// matching `)`: each `(keyword, default as written)`.
fn python_parameters(text: &str, start: &str) -> Vec<(String, Option<String>)> {
    let at = text.find(start).unwrap_or_else(|| panic!("no `{start}`")) + start.len();
    let (mut depth, mut params, mut current) = (0i32, Vec::new(), String::new());
    for c in text[at..].chars() {
        match c {
            '(' | '[' | '{' => depth += 1,
            ')' | ']' | '}' if depth == 0 => break,
            ')' | ']' | '}' => depth -= 1,
            ',' if depth == 0 => {
                params.push(std::mem::take(&mut current));
                continue;
            }
            _ => {}
        }
        current.push(c);
    }
    params.push(current);
    params
        .iter()
        .map(|p| p.trim())
        .filter(|p| !p.is_empty() && !p.starts_with('*'))
        .map(|p| {
            let (head, default) = match p.split_once('=') {
                Some((h, d)) => (h, Some(d.trim().trim_matches('"').to_string())),
                None => (p, None),
            };
            (head.split(':').next().unwrap_or(head).trim().to_string(), default)
        })
        .collect()
}

/// Python's functions read through a field table: (function, its source in crates/sandslope-py/src,
/// the table, the keywords of the table it takes).
fn python_functions() -> Vec<(&'static str, &'static str, Table, Vec<&'static str>)> {
    let settings = ["cv_n", "cv_s", "max_roll_deg", "descent", "allow_metastable"];
    vec![
        ("risk_raster", "plan.rs", plan::FIELDS, settings.to_vec()),
        ("plan", "plan.rs", plan::FIELDS, [&settings[..], &["time_weight", "objectives"]].concat()),
        ("infer_servo_log_file", "servo.rs", infer::FIELDS, vec!["slope_deg", "k_s_prior", "grid_points"]),
        ("infer_servo_log", "servo.rs", infer::FIELDS, vec!["slope_deg", "k_s_prior", "grid_points"]),
        ("track", "measure.rs", track::FIELDS, track::FIELDS.fields.iter().map(|f| f.keyword).collect()),
    ]
}

/// Python's keywords are the table's: each function the table is read for takes them (in its
/// `#[pyo3(signature)]` and in the stub `_sandslope.pyi`), and where the stub writes a
/// default it is the table's (a switch's is `False`).
#[test]
fn python_keywords_and_stub_defaults_are_the_tables() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let stub =
        std::fs::read_to_string(format!("{root}/sandslope-py/python/sandslope/_sandslope.pyi")).unwrap();
    for (function, file, table, keywords) in python_functions() {
        let source = std::fs::read_to_string(format!("{root}/sandslope-py/src/{file}")).unwrap();
        let signature = source
            .split("#[pyo3(signature = (")
            .skip(1)
            .find(|s| {
                s.contains(&format!("pub fn {function}<")) || s.contains(&format!("pub fn {function}("))
            })
            .unwrap_or_else(|| panic!("no signature of {function} in {file}"));
        let rust: Vec<String> = python_parameters(signature, "").into_iter().map(|(k, _)| k).collect();
        let python = python_parameters(&stub, &format!("def {function}("));
        for keyword in keywords {
            let field =
                table.by_keyword(keyword).unwrap_or_else(|| panic!("{function}: no field of {keyword}"));
            assert!(rust.iter().any(|k| k == keyword), "{function}'s signature lacks {keyword}");
            let (_, default) = python
                .iter()
                .find(|(k, _)| k == keyword)
                .unwrap_or_else(|| panic!("the stub's {function} lacks {keyword}"));
            // `None` is the table's default (or none), as the request reads a field not given.
            let Some(default) = default.as_deref().filter(|d| *d != "None") else { continue };
            match (field.kind, field.default) {
                (Kind::Switch, _) => assert_eq!(default, "False", "{function}({keyword})"),
                (_, None) => panic!("{function}({keyword}) = {default}: the table has no default"),
                (Kind::Number, Some(d)) => {
                    assert_eq!(default.parse::<f64>().ok(), d.parse::<f64>().ok(), "{function}({keyword})")
                }
                (_, Some(d)) => assert_eq!(default, d, "{function}({keyword})"),
            }
        }
    }
}
