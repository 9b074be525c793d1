//! The field tables hold together: within a request no flag or keyword is taken twice, every
//! default reads with the field's own parser (a choice's among its words), and every flag is
//! in the user docs (docs/*.md or README.md), so an option list cannot leave one out.

use sandslope_request::field::{Kind, Table};
use sandslope_request::{drive, phase, predict, risk, scenario, simulate, sweep};

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
                Kind::Text => {}
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
