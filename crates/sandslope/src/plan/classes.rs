//! Terrain classes: the values of a class raster (one number per cell, aligned with the
//! elevation model) mapped to indices into the terrains a plan uses, as [`Planner::new`] takes
//! them. The raster itself is read by the front end (sandslope-io); this is the rule both the
//! command line and Python apply.
//!
//! [`Planner::new`]: super::Planner::new

use super::planner::NO_CLASS;

/// A class value that covers cells but was given no terrain.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("class {value} ({cells} cells) has no terrain (given: {given})")]
pub struct UnmappedClass {
    /// The class value (the smallest one without a terrain).
    pub value: f64,
    /// Cells of that class.
    pub cells: usize,
    /// The classes that have a terrain, comma-separated.
    pub given: String,
}

/// Each cell's index into `class_values` (the classes the terrains are given for, in the order
/// of the terrains): [`NO_CLASS`] where `nodata(i)` (no class: the cell is impassable), an
/// error naming the smallest class value that covers cells but has no terrain. At most 254
/// classes (the index is a byte; [`NO_CLASS`] is 255).
pub fn class_indices(
    values: &[f64],
    nodata: impl Fn(usize) -> bool,
    class_values: &[i64],
) -> Result<Vec<u8>, UnmappedClass> {
    debug_assert!(class_values.len() < usize::from(NO_CLASS));
    let mut unmapped: Option<(f64, usize)> = None;
    let indices = values
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            if nodata(i) {
                return NO_CLASS;
            }
            match class_values.iter().position(|&k| k as f64 == v) {
                Some(p) => p as u8,
                None => {
                    unmapped = match unmapped {
                        Some((u, n)) if u == v => Some((u, n + 1)),
                        Some((u, n)) if u < v => Some((u, n)),
                        _ => Some((v, 1)),
                    };
                    NO_CLASS
                }
            }
        })
        .collect();
    match unmapped {
        None => Ok(indices),
        Some((value, cells)) => Err(UnmappedClass {
            value,
            cells,
            given: class_values.iter().map(|k| k.to_string()).collect::<Vec<_>>().join(", "),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classes_map_to_the_terrains_order_and_nodata_to_no_class() {
        // Cells: class 7, class 2, nodata, class 7; terrains given for 2 then 7.
        let got = class_indices(&[7.0, 2.0, -1.0, 7.0], |i| i == 2, &[2, 7]).unwrap();
        assert_eq!(got, vec![1, 0, NO_CLASS, 1]);
    }

    #[test]
    fn the_smallest_unmapped_class_is_named_with_its_cell_count() {
        // 10 (one cell) and 3 (two cells) have no terrain; 3 is the smaller, numerically
        // (as text "10" < "3").
        let e = class_indices(&[10.0, 3.0, 1.0, 3.0], |_| false, &[1]).unwrap_err();
        assert_eq!(e, UnmappedClass { value: 3.0, cells: 2, given: "1".into() });
        assert_eq!(e.to_string(), "class 3 (2 cells) has no terrain (given: 1)");
    }

    #[test]
    fn a_fractional_value_is_no_class_of_an_integer() {
        let e = class_indices(&[1.5], |_| false, &[1, 2]).unwrap_err();
        assert_eq!((e.value, e.cells), (1.5, 1));
    }
}
