//! Robot and terrain files (TOML, keys of docs/model.md §2 and §7) and built-in presets, read
//! into the library's validated [`Robot`] and [`Terrain`].
//!
//! Every error names the file (or preset), the key and the valid range.

use std::path::Path;

use anyhow::{anyhow, bail, Result};

use sandslope::{Robot, RobotSpec, Terrain, TerrainSpec};

use crate::presets::{self, PresetKind};
use sandslope_files::{parse_toml, read_text, Source};

/// Resolves `arg` to a preset of `kind` or a file: an existing path, or anything ending in
/// `.toml`, is a file; otherwise it must be a preset name.
fn resolve(arg: &str, kind: PresetKind) -> Result<(Source, String)> {
    let path = Path::new(arg);
    if path.exists() || arg.ends_with(".toml") {
        return Ok((Source::File(path.to_path_buf()), read_text(path)?));
    }
    match presets::find(arg, kind) {
        Some(p) => Ok((Source::Preset(p.name), p.toml.to_string())),
        None => {
            let what = if kind == PresetKind::Robot { "robot" } else { "terrain" };
            bail!(
                "`{arg}` is neither a {what} file nor a built-in {what} (built-in: {})",
                presets::names(kind)
            )
        }
    }
}

/// Loads a robot from a file or preset name.
pub fn load_robot(arg: &str) -> Result<Robot> {
    let (source, text) = resolve(arg, PresetKind::Robot)?;
    robot_from_toml(&text, &source)
}

/// Parses and validates a robot.
pub fn robot_from_toml(text: &str, source: &Source) -> Result<Robot> {
    // The optional `[servos]` table (servo_log.rs, docs/drive.md) is the driver's, not the model's.
    let (text, _servos) = crate::servo_log::split_servos_table(text);
    let spec: RobotSpec = parse_toml(&text, source)?;
    Robot::new(spec).map_err(|e| anyhow!("{source}: {e}"))
}

/// The `[servos]` table of a robot file or preset, if it has one (docs/drive.md).
pub fn load_servos(arg: &str) -> Result<Option<crate::servo_log::Servos>> {
    let (source, text) = resolve(arg, PresetKind::Robot)?;
    match crate::servo_log::split_servos_table(&text).1 {
        Some(table) => crate::servo_log::parse_servos(&table, &source).map(Some),
        None => Ok(None),
    }
}

/// Loads a terrain from a file or preset name.
pub fn load_terrain(arg: &str) -> Result<Terrain> {
    let (source, text) = resolve(arg, PresetKind::Terrain)?;
    terrain_from_toml(&text, &source)
}

/// Parses and validates a terrain, its k_n and k_s held to their plausible range
/// ([`sandslope::terrain::K_PLAUSIBLE`]).
pub fn terrain_from_toml(text: &str, source: &Source) -> Result<Terrain> {
    let spec: TerrainSpec = parse_toml(text, source)?;
    let terrain = Terrain::new(spec.clone()).map_err(|e| anyhow!("{source}: {e}"))?;
    // Beyond validity, a file's resistances must be plausible (docs/model.md §7): k_n = 1e308
    // was accepted and a live drive then spent 32 s before its first step.
    spec.check_plausible().map_err(|e| anyhow!("{source}: {e}"))?;
    Ok(terrain)
}

/// `header` as `# ` comment lines (each may itself hold several lines), then `body`.
fn with_header(header: &str, body: String) -> String {
    let mut text: String = header.lines().map(|l| format!("# {l}\n")).collect();
    text.push_str(&body);
    text
}

/// A terrain file (docs/model.md §7) as [`load_terrain`] reads it back: `header` as comment
/// lines (where the terrain came from), then the keys.
pub fn terrain_toml(spec: &TerrainSpec, header: &str) -> Result<String> {
    let body = toml::to_string(spec).map_err(|e| anyhow!("cannot write the terrain as TOML: {e}"))?;
    Ok(with_header(header, body))
}

/// A robot file (docs/model.md §2) as [`load_robot`] reads it back: `header` as comment lines,
/// then the keys.
pub fn robot_toml(spec: &RobotSpec, header: &str) -> Result<String> {
    let body = toml::to_string(spec).map_err(|e| anyhow!("cannot write the robot as TOML: {e}"))?;
    Ok(with_header(header, body))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What the writers write, the readers read back to the same spec; the header is comments.
    #[test]
    fn written_robot_and_terrain_files_read_back() {
        let robot = load_robot("paper-hexapod").unwrap();
        let text = robot_toml(robot.spec(), "Written by: a test\nsecond line").unwrap();
        assert!(text.starts_with("# Written by: a test\n# second line\n"), "{text}");
        let back = robot_from_toml(&text, &Source::Preset("written")).unwrap();
        assert_eq!(back.spec(), robot.spec());
        let terrain = load_terrain("glass-beads-300um").unwrap();
        let text = terrain_toml(terrain.spec(), "k_s per observed slope").unwrap();
        let back = terrain_from_toml(&text, &Source::Preset("written")).unwrap();
        assert_eq!(back.spec(), terrain.spec());
    }

    const PAPER: &str = "mass_kg = 0.35\nleg_radius_m = 0.04\nleg_width_m = 0.01\nhip_height_m = 0.03\n\
                         leg_speed_rad_s = 6.283185307179586\nstance_legs = 3\nresponse_time_s = 0.2\n";

    fn read(extra: &str) -> Result<Robot> {
        robot_from_toml(&format!("{PAPER}{extra}"), &Source::File("r.toml".into()))
    }

    /// The simulator's optional keys (docs/model.md §15): a file without them keeps loading,
    /// with the documented defaults; given ones are range-checked with file and key named.
    #[test]
    fn simulator_keys_are_optional_and_checked() {
        let r = read("").unwrap();
        assert_eq!((r.leg_elements(), r.servo_torque_limit()), (32, None));
        let r = read("body_length_m = 0.3\nservo_torque_limit_n_m = 0.52\nleg_elements = 64\n").unwrap();
        assert_eq!((r.body_length(), r.servo_torque_limit(), r.leg_elements()), (0.3, Some(0.52), 64));
        // I = m L^2 / 12 with the given length: 0.35 * 0.09 / 12.
        assert!((r.pitch_inertia() - 2.625e-3).abs() < 1e-12);
        for (extra, key) in [
            ("leg_elements = 1000\n", "leg_elements = 1000 must be a whole number from 4 to 256"),
            ("servo_torque_limit_n_m = -1.0\n", "servo_torque_limit_n_m = -1"),
            ("pitch_inertia_kg_m2 = 0.0\n", "pitch_inertia_kg_m2 = 0"),
            ("body_width_m = 0.0\n", "body_width_m = 0"),
        ] {
            let msg = format!("{:#}", read(extra).unwrap_err());
            assert!(msg.contains("r.toml") && msg.contains(key), "{extra}: {msg}");
        }
        let msg = format!("{:#}", read("leg_elements = 2.5\n").unwrap_err());
        assert!(msg.contains("leg_elements"), "{msg}");
        let msg = format!("{:#}", read("leg_element = 8\n").unwrap_err());
        assert!(msg.contains("leg_element") && msg.ends_with("did you mean `leg_elements`?"), "{msg}");
    }

    /// `leg_shape` (docs/model.md §2): absent, the C-leg; `spoke` and `foot` read; the file
    /// written back says the shape only when it is not the default; an unknown shape is
    /// refused naming the file, the key, the value and the three shapes.
    #[test]
    fn the_leg_shape_is_read_and_an_unknown_one_refused() {
        use sandslope::LegShape;
        assert_eq!(read("").unwrap().leg_shape(), LegShape::CLeg);
        assert!(!robot_toml(read("").unwrap().spec(), "").unwrap().contains("leg_shape"));
        for (text, shape) in [("c_leg", LegShape::CLeg), ("spoke", LegShape::Spoke), ("foot", LegShape::Foot)]
        {
            let robot = read(&format!("leg_shape = \"{text}\"\n")).unwrap();
            assert_eq!(robot.leg_shape(), shape);
            let back = robot_from_toml(&robot_toml(robot.spec(), "").unwrap(), &Source::Preset("w")).unwrap();
            assert_eq!(back.spec(), robot.spec());
        }
        let msg = format!("{:#}", read("leg_shape = \"wheel\"\n").unwrap_err());
        assert!(msg.contains("r.toml") && msg.contains("leg_shape") && msg.contains("wheel"), "{msg}");
        assert!(msg.contains("`c_leg`, `spoke`, `foot`"), "{msg}");
    }

    /// An unknown key names the key meant: `legs` is a whole word of `stance_legs` only (not of
    /// `leg_radius_m`, whose word is `leg`); `mass` of `mass_kg`; a typo `leg_radus_m` is nearest
    /// `leg_radius_m`; `colour` is near nothing and gets no guess.
    #[test]
    fn an_unknown_key_names_the_key_most_likely_meant() {
        let bad = |line: &str| {
            let text = PAPER.replace("stance_legs = 3\n", "").replace("mass_kg = 0.35\n", "");
            let text = format!("{text}stance_legs = 3\nmass_kg = 0.35\n{line}\n");
            format!("{:#}", robot_from_toml(&text, &Source::File("mine.toml".into())).unwrap_err())
        };
        assert!(bad("legs = 6").ends_with("did you mean `stance_legs`?"), "{}", bad("legs = 6"));
        assert!(bad("mass = 1.2").ends_with("did you mean `mass_kg`?"));
        assert!(bad("leg_radus_m = 0.04").ends_with("did you mean `leg_radius_m`?"));
        assert!(!bad("colour = 1").contains("did you mean"), "{}", bad("colour = 1"));
        let terrain = "[[points]]\nslope_deg = 0.0\nk_n = 7e5\nk_s = 2e6\nks_sd = 1e5\n";
        let msg = format!("{:#}", terrain_from_toml(terrain, &Source::File("t.toml".into())).unwrap_err());
        assert!(msg.ends_with("did you mean `k_s_sd`?"), "{msg}");
    }

    /// A terrain file's k_n of 1e308 (the issue's) is refused with the file, the key as the
    /// file has it and the plausible range; 0.7 given in N/cm^3 is named as 700000 N/m^3.
    #[test]
    fn implausible_terrain_resistances_are_refused_naming_the_file_and_key() {
        let text = |k_n: &str| format!("[[points]]\nslope_deg = 0.0\nk_n = {k_n}\nk_s = 2e6\n");
        let err = |k_n: &str| {
            format!("{:#}", terrain_from_toml(&text(k_n), &Source::File("sand.toml".into())).unwrap_err())
        };
        let msg = err("1e308");
        assert!(
            msg.starts_with("sand.toml: points[0].k_n = 1e308 must be between 1e3 and 1e10 N/m^3"),
            "{msg}"
        );
        assert!(err("0.7").contains("that is 700000 N/m^3"), "{}", err("0.7"));
        assert!(terrain_from_toml(&text("7e5"), &Source::File("sand.toml".into())).is_ok());
    }
}
