//! Robot and terrain files (TOML, keys of docs/model.md §2 and §7) and built-in presets, read
//! into the library's validated [`Robot`] and [`Terrain`].
//!
//! Every error names the file (or preset), the key and the valid range.

use std::path::Path;

use anyhow::{anyhow, bail, Result};

use sandslope::{Robot, RobotSpec, Terrain, TerrainSpec};

use crate::files::{parse_toml, read_text, Source};
use crate::presets::{self, PresetKind};

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
    let spec: RobotSpec = parse_toml(text, source)?;
    Robot::new(spec).map_err(|e| anyhow!("{source}: {e}"))
}

/// Loads a terrain from a file or preset name.
pub fn load_terrain(arg: &str) -> Result<Terrain> {
    let (source, text) = resolve(arg, PresetKind::Terrain)?;
    terrain_from_toml(&text, &source)
}

/// Parses and validates a terrain.
pub fn terrain_from_toml(text: &str, source: &Source) -> Result<Terrain> {
    let spec: TerrainSpec = parse_toml(text, source)?;
    Terrain::new(spec).map_err(|e| anyhow!("{source}: {e}"))
}
