//! Writing the servos' zero offsets into a robot file (`sandslope drive --zero`,
//! docs/drive.md, "Zero offsets"): the `[servos]` table's `zero_offsets` set, everything else
//! of the file (its keys, comments and layout) kept as it was. A file without a `[servos]`
//! table gets one, with the IDs and directions the offsets were read with, so that they keep
//! their meaning.

use anyhow::{anyhow, Result};
use toml_edit::{Array, DocumentMut, Item, Table};

/// `text` (a robot file) with `[servos] zero_offsets = offsets`; `ids` and `directions` are
/// written too where the file has no `[servos]` table. `source` names the file in errors.
pub fn with_zero_offsets(
    text: &str,
    source: &str,
    ids: &[u8],
    directions: &[i8],
    offsets: &[i32],
) -> Result<String> {
    let mut doc: DocumentMut = text.parse().map_err(|e| anyhow!("{source}: {e}"))?;
    let array = |v: Vec<i64>| Item::Value(Array::from_iter(v).into());
    if !doc.contains_key("servos") {
        let mut t = Table::new();
        t.insert("ids", array(ids.iter().map(|&i| i64::from(i)).collect()));
        t.insert("directions", array(directions.iter().map(|&d| i64::from(d)).collect()));
        doc.insert("servos", Item::Table(t));
    }
    let servos = doc
        .get_mut("servos")
        .and_then(Item::as_table_like_mut)
        .ok_or_else(|| anyhow!("{source}: `servos` must be a table ([servos])"))?;
    servos.insert("zero_offsets", array(offsets.iter().map(|&o| i64::from(o)).collect()));
    Ok(doc.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_offsets_replace_the_old_ones_and_the_rest_stays() {
        let text = "# my robot\nmass_kg = 0.35 # weighed\n\n[servos]\nids = [1, 2]\nzero_offsets = [0, 0]\nbaud_rate = 1000000\n";
        let out = with_zero_offsets(text, "r.toml", &[1, 2], &[1, -1], &[100, -2048]).unwrap();
        assert_eq!(
            out,
            "# my robot\nmass_kg = 0.35 # weighed\n\n[servos]\nids = [1, 2]\nzero_offsets = [100, -2048]\nbaud_rate = 1000000\n"
        );
    }

    #[test]
    fn a_file_without_servos_gets_the_table_it_was_read_with() {
        let out = with_zero_offsets("mass_kg = 0.35\n", "r.toml", &[1, 2], &[1, -1], &[7, 9]).unwrap();
        assert_eq!(
            out,
            "mass_kg = 0.35\n\n[servos]\nids = [1, 2]\ndirections = [1, -1]\nzero_offsets = [7, 9]\n"
        );
        assert!(with_zero_offsets("servos = 3\n", "r.toml", &[1], &[1], &[0]).is_err());
    }
}
