//! Global maps whose longitudes wrap at the seam (0/360 on a MOLA MEGDR, -180/180 on a global
//! GeoTIFF in degrees): the columns on either side of the seam are neighbours on the body. The
//! planner's grid has a western and an eastern border, so a route across the seam is planned
//! on the map with its columns rolled ([`seam_roll`]): the map's edges are moved to the
//! meridian opposite the endpoints (halfway round from the midpoint of the shorter arc between
//! their longitudes), where a route between them would have to go round the far side of the
//! body. The rolled map is the same heights and georeference, `west` moved by whole columns, so
//! every output (routes, risk map) is in longitudes that run on continuously across the seam
//! (a cell 4.75 degrees east of the seam of a 0..360 map is written 364.75).

use super::grid::Raster;

/// Whether `raster` is a geographic map (longitude, latitude in degrees) whose columns span
/// all 360 degrees of longitude, its eastern edge the western one (to a millionth of a cell).
pub fn wraps_in_longitude(raster: &Raster) -> bool {
    raster.crs.is_geographic()
        && raster.cols >= 3
        && (raster.cols as f64 * raster.geo.cell_x - 360.0).abs() <= 1e-6 * raster.geo.cell_x
}

/// The column shift that rolls a map of `cols` columns wrapping in longitude so that its new
/// western edge is the meridian opposite the midpoint of the shorter arc between columns `a`
/// and `b` (the start's and the goal's): the rolled map's column `j` is the map's column
/// `(j + shift) % cols`. Both endpoints then lie at least a quarter of the map from its edges.
pub fn seam_roll(cols: usize, a: usize, b: usize) -> usize {
    let n = cols as i64;
    let (a, b) = (a as i64 % n, b as i64 % n);
    // Eastward distance from a to b; the shorter arc goes east when it is at most half round.
    let east = (b - a).rem_euclid(n);
    let twice_mid = if 2 * east <= n { 2 * a + east } else { 2 * a - (n - east) };
    let mid = twice_mid.div_euclid(2);
    (mid + n / 2).rem_euclid(n) as usize
}

/// A map column in the frame of a map rolled by `shift` columns ([`seam_roll`]).
pub fn rolled_column(col: usize, cols: usize, shift: usize) -> usize {
    (col % cols + cols - shift % cols) % cols
}

impl Raster {
    /// The raster with its columns rolled by `shift` ([`seam_roll`]): its values (if held)
    /// rotated row by row and its western edge moved `shift` cells east, then by 360 degrees
    /// so that the rolled map's middle longitude lies within the original map's longitudes.
    /// Adds a note saying so. Only for a map that [`wraps_in_longitude`].
    pub fn rolled_columns(mut self, shift: usize) -> Raster {
        let n = self.cols;
        let shift = shift % n;
        if shift == 0 {
            return self;
        }
        if self.values.len() == n * self.rows {
            for row in self.values.chunks_mut(n) {
                row.rotate_left(shift);
            }
        }
        let west0 = self.geo.west;
        let mut west = west0 + shift as f64 * self.geo.cell_x;
        if west + 180.0 >= west0 + 360.0 {
            west -= 360.0;
        }
        self.geo.west = west;
        self.notes.push(format!(
            "the map spans all 360 degrees of longitude: routes wrap across its edges at longitude {} (= {}), \
             planned on the map with its columns rolled so that its edges lie at longitude {}, the meridian \
             opposite the start and the goal (a route round the far side of the body, across that meridian, is \
             not searched); the outputs' longitudes run on across the seam, from {} to {}",
            round(west0),
            round(west0 + 360.0),
            round(west.rem_euclid(360.0)),
            round(west),
            round(west + 360.0)
        ));
        self
    }
}

/// A longitude for a note: to 9 decimals, without float noise.
fn round(x: f64) -> f64 {
    (x * 1e9).round() / 1e9
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_seam_goes_opposite_the_endpoints() {
        // 720 columns of half a degree: columns 710 (355.25 E) and 9 (4.75 E) are 19 columns
        // apart across the seam; their midpoint is column 719.5, so the new edge is 359.5 columns
        // on: the rolled map starts at column 359 and the endpoints sit at 351 and 370.
        let s = seam_roll(720, 710, 9);
        assert_eq!(s, 359);
        assert_eq!((rolled_column(710, 720, s), rolled_column(9, 720, s)), (351, 370));
        // The same endpoints the other way round, and a pair whose shorter arc does not cross
        // the seam (100 and 300: midpoint 200, new edge at 560).
        assert_eq!(seam_roll(720, 9, 710), 359);
        assert_eq!(seam_roll(720, 100, 300), 560);
        assert_eq!((rolled_column(100, 720, 560), rolled_column(300, 720, 560)), (260, 460));
        // Every pair ends at least a quarter of the map from the rolled map's edges.
        for (a, b) in [(0, 0), (0, 359), (0, 361), (5, 715), (719, 0), (123, 480)] {
            let s = seam_roll(720, a, b);
            for c in [a, b] {
                let j = rolled_column(c, 720, s);
                assert!((179..=541).contains(&j), "{a} {b}: {c} -> {j}");
            }
        }
    }
}
