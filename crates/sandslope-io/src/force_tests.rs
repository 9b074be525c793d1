//! The force tests a report weighs the model against: a file or preset the user
//! names, or on the built-in terrain the paper's own ([`PAPER_FORCE_TESTS`]), read as a
//! terrain table.

use sandslope::report::ForceTests;

use crate::presets::{is_default, PresetKind, PAPER_FORCE_TESTS};

/// [`PAPER_FORCE_TESTS`] read as a terrain table.
pub fn paper_force_tests() -> anyhow::Result<sandslope::Terrain> {
    let p = PAPER_FORCE_TESTS;
    crate::robot_terrain::terrain_from_toml(p.toml, &sandslope_files::Source::Preset(p.name))
}

/// The force tests of a report: `forces` (a file or preset name) when given; else, on the
/// built-in terrain `terrain_arg == DEFAULT_TERRAIN`, the paper's (the terrain was calibrated
/// from them); else none (the terrain's own table is used).
pub fn report_force_tests(forces: Option<&str>, terrain_arg: &str) -> anyhow::Result<ForceTests> {
    Ok(match forces {
        Some(f) => ForceTests::Given { table: crate::load_terrain(f)?, source: f.to_string() },
        None if is_default(terrain_arg, PresetKind::Terrain) => ForceTests::Paper(paper_force_tests()?),
        None => ForceTests::None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_built_in_force_tests_are_the_data_file() {
        let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/example-force-tests.toml");
        assert_eq!(std::fs::read_to_string(data).unwrap(), PAPER_FORCE_TESTS.toml);
        let t = paper_force_tests().unwrap();
        // The paper's one number: k_s(20)/k_s(0) = 0.40 (Sec. III-C).
        let (p0, p20) = (&t.points()[0], &t.points()[1]);
        assert_eq!((p0.slope_deg, p20.slope_deg), (0.0, 20.0));
        assert!((p20.k_s / p0.k_s - 0.40).abs() < 1e-12);
    }
}
