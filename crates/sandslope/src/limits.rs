//! Sizes the library accepts, decided before anything is allocated (issue 21). Every front end
//! (the CLI, Python, the server) checks its input against the same caps, so that a size that
//! comes from input (an axis length, a range, a slope count) is refused at once with the cap
//! in the message, never after minutes and gigabytes, never with an abort.

use crate::error::ParamError;

/// Most cells of phase maps in one call, over all panels (2^28: 256 MiB of regime codes and
/// 2 GiB of steps; about a minute on two cores).
pub const MAX_PHASE_CELLS: usize = 1 << 28;

/// Most cells of one risk map (2^24: two 128 MiB arrays of probabilities, each cell a
/// quadrature).
pub const MAX_RISK_MAP_CELLS: usize = 1 << 24;

/// Most slopes one risk curve evaluates (2^16, each a quadrature of a few ms).
pub const MAX_RISK_SLOPES: usize = 1 << 16;

/// The number of cells of an `nx` x `ny` grid (times `panels`), or an error naming `what` and
/// the cap when it exceeds `max` (or overflows).
pub fn grid_cells(what: &str, nx: usize, ny: usize, panels: usize, max: usize) -> Result<usize, ParamError> {
    let cells = nx.checked_mul(ny).and_then(|c| c.checked_mul(panels));
    match cells {
        Some(c) if c <= max => Ok(c),
        _ => Err(ParamError::new(
            what,
            nx as f64 * ny as f64 * panels as f64,
            format!(
                "at most {max} cells (here {nx} x {ny}{})",
                if panels > 1 { format!(" x {panels} panels") } else { String::new() }
            ),
        )),
    }
}

/// `n` when it is at most `max`, else an error naming `what` and the cap.
pub fn count(what: &str, n: usize, max: usize) -> Result<usize, ParamError> {
    if n <= max {
        Ok(n)
    } else {
        Err(ParamError::new(what, n as f64, format!("at most {max}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids_within_the_cap_pass_and_larger_or_overflowing_ones_name_it() {
        assert_eq!(grid_cells("map", 4, 5, 1, 20), Ok(20));
        let e = grid_cells("map", 100_000, 100_000, 1, MAX_RISK_MAP_CELLS).unwrap_err().to_string();
        assert!(e.contains("at most 16777216 cells (here 100000 x 100000)"), "{e}");
        assert!(grid_cells("map", usize::MAX, 2, 1, usize::MAX).is_err());
        assert!(grid_cells("map", 3, 3, 3, 26).unwrap_err().to_string().contains("x 3 panels"));
        assert_eq!(count("slopes", 3, 3), Ok(3));
        assert!(count("slopes", 4, 3).unwrap_err().to_string().contains("at most 3"));
    }
}
