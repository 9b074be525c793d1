//! Contour lines of a scalar field on a grid of two [`Axis`]es, by marching squares: the
//! success boundary of a phase diagram ([`crate::phase::PhaseMap::robust_contour`]) and the
//! `p_fail = max_risk` line of a risk map ([`crate::risk::RiskMap::p_fail_contour`]).

use rayon::prelude::*;

use crate::axis::Axis;

/// A straight piece of a contour line on a map, from `.0` to `.1`, each point `(x, y)` in axis
/// values (on phase diagrams and risk maps `(k_n, k_s)` in N/m^3; distinct from the planner's
/// route segments).
pub type ContourSegment = ((f64, f64), (f64, f64));

/// The contour `field = level` of a scalar field on the grid `x_axis x y_axis` (row-major,
/// one row per y value), by marching squares with linear interpolation in axis coordinates
/// (logarithms on log axes). Squares with a NaN corner are skipped; saddles are resolved by
/// the mean of the four corners. Points are returned in axis values, not coordinates.
pub fn contour_segments(x_axis: &Axis, y_axis: &Axis, field: &[f64], level: f64) -> Vec<ContourSegment> {
    let (nx, ny) = (x_axis.len(), y_axis.len());
    assert_eq!(field.len(), nx * ny, "field must have one value per grid cell");
    let xi: Vec<usize> = (0..nx).collect();
    let yj: Vec<usize> = (0..ny).collect();
    contour_on_cells(x_axis, y_axis, &xi, &yj, |i, j| field[j * nx + i], level)
}

/// [`contour_segments`] over the sub-grid of the cells `xi x yj` (ascending indices into the
/// axes), reading the field through `field(i, j)`: a figure traces its contour over the cells
/// it draws, so tracing costs the same for 400 x 400 and 4096 x 4096 maps.
pub fn contour_on_cells(
    x_axis: &Axis,
    y_axis: &Axis,
    xi: &[usize],
    yj: &[usize],
    field: impl Fn(usize, usize) -> f64 + Sync,
    level: f64,
) -> Vec<ContourSegment> {
    if xi.len() < 2 || yj.len() < 2 {
        return Vec::new();
    }
    let xc: Vec<f64> = xi.iter().map(|&i| x_axis.coordinate(x_axis.value(i))).collect();
    let yc: Vec<f64> = yj.iter().map(|&j| y_axis.coordinate(y_axis.value(j))).collect();
    let at = |a: usize, b: usize| field(xi[a], yj[b]) - level;
    let point = |x: f64, y: f64| (x_axis.from_coordinate(x), y_axis.from_coordinate(y));
    (0..yj.len() - 1)
        .into_par_iter()
        .flat_map_iter(|j| {
            let mut out = Vec::new();
            for i in 0..xi.len() - 1 {
                // Corners counter-clockwise from bottom-left: (i,j), (i+1,j), (i+1,j+1), (i,j+1).
                let v = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
                if v.iter().any(|x| x.is_nan()) {
                    continue;
                }
                let p = [(xc[i], yc[j]), (xc[i + 1], yc[j]), (xc[i + 1], yc[j + 1]), (xc[i], yc[j + 1])];
                // Crossing on edge k, between corners k and k+1.
                let cross = |k: usize| {
                    let (a, b) = (k, (k + 1) % 4);
                    let t = v[a] / (v[a] - v[b]);
                    let (pa, pb) = (p[a], p[b]);
                    point(pa.0 + t * (pb.0 - pa.0), pa.1 + t * (pb.1 - pa.1))
                };
                let above: Vec<bool> = v.iter().map(|&x| x >= 0.0).collect();
                let edges: Vec<usize> = (0..4).filter(|&k| above[k] != above[(k + 1) % 4]).collect();
                match edges.len() {
                    2 => out.push((cross(edges[0]), cross(edges[1]))),
                    4 => {
                        // Saddle: if the centre is on the side of corner 0, corner 0's region
                        // connects through the centre, so the lines cut off corners 1 and 3.
                        let centre_above = v.iter().sum::<f64>() / 4.0 >= 0.0;
                        if centre_above == above[0] {
                            out.push((cross(0), cross(1)));
                            out.push((cross(2), cross(3)));
                        } else {
                            out.push((cross(3), cross(0)));
                            out.push((cross(1), cross(2)));
                        }
                    }
                    _ => {}
                }
            }
            out
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::axis::AxisScale;

    #[test]
    fn contour_of_a_known_field_is_a_circle() {
        // f = x^2 + y^2 on a linear grid; the contour f = 1 is the unit circle.
        let a = Axis::new("x", -2.0 + 2.0, 2.0 + 2.0, 81, AxisScale::Linear).unwrap();
        let field: Vec<f64> = (0..81 * 81)
            .map(|c| {
                let (x, y) = (a.value(c % 81) - 2.0, a.value(c / 81) - 2.0);
                x * x + y * y
            })
            .collect();
        let seg = contour_segments(&a, &a, &field, 1.0);
        assert!(seg.len() > 40);
        for (p, q) in seg {
            for (x, y) in [p, q] {
                let r = ((x - 2.0).powi(2) + (y - 2.0).powi(2)).sqrt();
                assert!((r - 1.0).abs() < 2e-3, "radius {r}");
            }
        }
    }
}
