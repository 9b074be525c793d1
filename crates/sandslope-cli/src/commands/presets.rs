//! `sandslope presets`: list the built-in robots and terrains, or print one as TOML.

use anyhow::{bail, Result};
use clap::{Args, Subcommand};

use crate::output::table;
use sandslope_io::presets::{PresetKind, PRESETS};

/// Arguments of `sandslope presets`.
#[derive(Debug, Args)]
pub struct PresetsArgs {
    #[command(subcommand)]
    command: Option<PresetsCommand>,
}

#[derive(Debug, Subcommand)]
enum PresetsCommand {
    /// Print one preset as TOML (save it to a file to make your own variant).
    Show {
        /// Preset name, as listed by `sandslope presets`.
        name: String,
    },
}

/// Runs `sandslope presets`.
pub fn run(args: PresetsArgs) -> Result<()> {
    match args.command {
        None => {
            let mut t = table(&["name", "kind", "description"]);
            for p in PRESETS {
                let kind = if p.kind == PresetKind::Robot { "robot" } else { "terrain" };
                t.add_row([p.name, kind, p.summary]);
            }
            println!("{t}");
            Ok(())
        }
        Some(PresetsCommand::Show { name }) => match PRESETS.iter().find(|p| p.name == name) {
            Some(p) => {
                print!("{}", p.toml);
                Ok(())
            }
            None => bail!(
                "no preset `{name}` (built-in: {})",
                PRESETS.iter().map(|p| p.name).collect::<Vec<_>>().join(", ")
            ),
        },
    }
}
