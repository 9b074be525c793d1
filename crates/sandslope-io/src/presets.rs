//! Built-in robots and terrains, embedded in the binary so they work from any directory.
//!
//! Each preset is a TOML file under `crates/sandslope-io/presets/`, in exactly the format a
//! user would write, and is parsed by the same code as a user's file.

/// What a preset describes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PresetKind {
    /// A robot file (docs/model.md §2).
    Robot,
    /// A terrain file (docs/model.md §7).
    Terrain,
}

/// One built-in file.
#[derive(Debug, Clone, Copy)]
pub struct Preset {
    /// Name used on the command line.
    pub name: &'static str,
    /// Robot or terrain.
    pub kind: PresetKind,
    /// One-line description.
    pub summary: &'static str,
    /// The TOML text.
    pub toml: &'static str,
}

/// Default robot when `--robot` is omitted.
pub const DEFAULT_ROBOT: &str = "paper-hexapod";
/// Default terrain when `--terrain` is omitted.
pub const DEFAULT_TERRAIN: &str = "glass-beads-300um";

/// All built-in presets.
pub const PRESETS: &[Preset] = &[
    Preset {
        name: "paper-hexapod",
        kind: PresetKind::Robot,
        summary: "0.35 kg C-leg hexapod of the paper (hip height 0.03 m and contact area W*R assumed)",
        toml: include_str!("../presets/paper-hexapod.toml"),
    },
    Preset {
        name: "glass-beads-300um",
        kind: PresetKind::Terrain,
        summary:
            "300 um glass beads: joint calibration on the paper's speeds and force-test ratio (k_n = 7e5 N/m^3 assumed)",
        toml: include_str!("../presets/glass-beads-300um.toml"),
    },
];

/// The paper's force tests as its text reports them: k_s(20)/k_s(0) = 0.40 and k_n unchanged,
/// with assumed levels and SDs (the file's comments say which). `sandslope report` uses them
/// on the built-in terrain, which was calibrated from them (docs/calibration.md). The same
/// text is `data/example-force-tests.toml` (a test keeps the two equal).
pub const PAPER_FORCE_TESTS: Preset = Preset {
    name: "example-force-tests",
    kind: PresetKind::Terrain,
    summary: "the paper's force tests as its text reports them (levels and SDs assumed)",
    toml: include_str!("../presets/example-force-tests.toml"),
};

/// Whether `--robot`/`--terrain` value `arg` names the default preset of `kind` (and no file
/// of that name, which would win).
pub fn is_default(arg: &str, kind: PresetKind) -> bool {
    let default = if kind == PresetKind::Robot { DEFAULT_ROBOT } else { DEFAULT_TERRAIN };
    arg == default && !std::path::Path::new(arg).exists()
}

/// The preset called `name` of kind `kind`.
pub fn find(name: &str, kind: PresetKind) -> Option<&'static Preset> {
    PRESETS.iter().find(|p| p.name == name && p.kind == kind)
}

/// Names of the presets of one kind, comma-separated, for error messages.
pub fn names(kind: PresetKind) -> String {
    PRESETS.iter().filter(|p| p.kind == kind).map(|p| p.name).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_parses_and_validates() {
        for p in PRESETS {
            let source = sandslope_files::Source::Preset(p.name);
            let ok = match p.kind {
                PresetKind::Robot => crate::robot_terrain::robot_from_toml(p.toml, &source).is_ok(),
                PresetKind::Terrain => crate::robot_terrain::terrain_from_toml(p.toml, &source).is_ok(),
            };
            assert!(ok, "preset {} does not load", p.name);
        }
    }

    #[test]
    fn paper_hexapod_preset_is_the_library_robot() {
        let spec: sandslope::RobotSpec =
            toml::from_str(find("paper-hexapod", PresetKind::Robot).unwrap().toml).unwrap();
        assert_eq!(spec, sandslope::RobotSpec::paper_hexapod());
    }
}
