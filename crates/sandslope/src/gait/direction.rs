//! The along-slope coordinate: body positions projected on the upslope direction
//! (docs/model.md §11), and an estimate of that direction from the travel itself.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

use crate::error::ParamError;
use crate::Slope;

/// A unit vector pointing upslope in the motion-capture frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Upslope {
    unit: [f64; 3],
}

impl Upslope {
    /// The direction of `v`, normalised; fails unless `v` is finite and not zero.
    pub fn new(v: [f64; 3]) -> Result<Upslope, ParamError> {
        let norm = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if v.iter().all(|c| c.is_finite()) && norm > 1e-12 {
            Ok(Upslope { unit: [v[0] / norm, v[1] / norm, v[2] / norm] })
        } else {
            Err(ParamError::new("upslope", norm, "a finite, non-zero vector"))
        }
    }

    /// The unit vector `[x, y, z]`.
    pub fn vector(self) -> [f64; 3] {
        self.unit
    }

    /// Along-slope coordinate of `p`: `p . u`.
    pub fn along(self, p: [f64; 3]) -> f64 {
        p[0] * self.unit[0] + p[1] * self.unit[1] + p[2] * self.unit[2]
    }
}

/// The principal direction of travel of one or more recordings (frames with a non-finite
/// coordinate are missing and skipped), oriented so that the summed net displacement (last
/// valid frame minus first) is positive along it.
///
/// It is the eigenvector of the largest eigenvalue of the pooled position covariance (each
/// recording centred on its own mean). It assumes the robot made net progress upslope; when
/// it lost ground, pass the direction explicitly. `None` when fewer than two valid frames
/// exist in total or the body did not move.
pub fn principal_direction(recordings: &[&[[f64; 3]]]) -> Option<Upslope> {
    let mut scatter = Matrix3::<f64>::zeros();
    let mut net = Vector3::<f64>::zeros();
    let mut frames = 0usize;
    for positions in recordings {
        let valid = || positions.iter().filter(|p| p.iter().all(|c| c.is_finite()));
        let n = valid().count();
        if n < 2 {
            continue;
        }
        let mean = valid().fold(Vector3::zeros(), |acc, p| acc + Vector3::from(*p)) / n as f64;
        for p in valid() {
            let d = Vector3::from(*p) - mean;
            scatter += d * d.transpose();
        }
        let first = valid().next()?;
        let last = positions.iter().rev().find(|p| p.iter().all(|c| c.is_finite()))?;
        net += Vector3::from(*last) - Vector3::from(*first);
        frames += n;
    }
    if frames < 2 {
        return None;
    }
    let eigen = SymmetricEigen::new(scatter);
    let (best, largest) = eigen
        .eigenvalues
        .iter()
        .enumerate()
        .fold((0, f64::NEG_INFINITY), |acc, (i, &l)| if l > acc.1 { (i, l) } else { acc });
    if largest.is_nan() || largest <= 0.0 {
        return None;
    }
    let mut u: Vector3<f64> = eigen.eigenvectors.column(best).into();
    if u.dot(&net) < 0.0 {
        u = -u;
    }
    Upslope::new([u.x, u.y, u.z]).ok()
}

/// Smallest slope, degrees, at which [`orient_by_height`] trusts the rise of the direction of
/// travel to tell upslope from downslope.
pub const MIN_ORIENTING_SLOPE_DEG: f64 = 1.0;

/// The direction of travel `travel` oriented upslope by height: on a slope `slope` (of at
/// least [`MIN_ORIENTING_SLOPE_DEG`]) a line of travel in the slope's plane rises by up to
/// sin(theta) per unit length, and upslope is the sense in which it rises along `up` (the
/// capture frame's vertical axis). Whether the robot progressed or slid down does not enter.
/// `None` (orient otherwise) on near-level ground, or when the travel rises by less than a
/// quarter of sin(theta) per unit length (it runs across the slope, or `up` is not the
/// frame's vertical axis).
pub fn orient_by_height(travel: Upslope, up: Upslope, slope: Slope) -> Option<Upslope> {
    if slope.degrees() < MIN_ORIENTING_SLOPE_DEG {
        return None;
    }
    let rise = travel.along(up.vector());
    if rise.abs() < 0.25 * slope.sin() {
        return None;
    }
    let [x, y, z] = travel.vector();
    Some(if rise > 0.0 { travel } else { Upslope { unit: [-x, -y, -z] } })
}

/// The direction of travel `travel` oriented upslope by its own rise along `up` (the capture
/// frame's vertical axis), for recordings whose slope is not given: a line of travel on a slope
/// rises along the vertical in the upslope sense, whichever way the robot went (progress or a
/// slide down). `None` (orient otherwise) when the travel is inclined by less than
/// [`MIN_ORIENTING_SLOPE_DEG`] to the horizontal: level ground has no upslope, and a travel
/// across the slope or a wrong vertical does not rise.
pub fn orient_by_rise(travel: Upslope, up: Upslope) -> Option<Upslope> {
    let rise = travel.along(up.vector());
    if rise.abs() < MIN_ORIENTING_SLOPE_DEG.to_radians().sin() {
        return None;
    }
    let [x, y, z] = travel.vector();
    Some(if rise > 0.0 { travel } else { Upslope { unit: [-x, -y, -z] } })
}

/// Projects every position on `upslope`; missing frames (any non-finite coordinate) give NaN.
pub fn project(positions: &[[f64; 3]], upslope: Upslope) -> Vec<f64> {
    positions
        .iter()
        .map(|&p| if p.iter().all(|c| c.is_finite()) { upslope.along(p) } else { f64::NAN })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a 20 deg slope a line of travel in the slope's plane rises by sin 20 = 0.342 per unit
    /// length along the vertical: upslope is the rising sense whichever way the travel was
    /// estimated; level ground, travel across the slope, or a wrong vertical leave it undecided.
    #[test]
    fn orient_by_height_points_upslope_where_the_travel_rises() {
        let (s, c) = 20f64.to_radians().sin_cos();
        let up = Upslope::new([0.0, 0.0, 1.0]).unwrap();
        let rising = Upslope::new([c, 0.0, s]).unwrap();
        let falling = Upslope::new([-c, 0.0, -s]).unwrap();
        let deg = |d: f64| Slope::from_degrees(d).unwrap();
        assert_eq!(orient_by_height(rising, up, deg(20.0)), Some(rising));
        assert_eq!(orient_by_height(falling, up, deg(20.0)).unwrap().vector(), rising.vector());
        assert_eq!(orient_by_height(rising, up, deg(0.5)), None);
        let across = Upslope::new([0.0, 1.0, 0.0]).unwrap();
        assert_eq!(orient_by_height(across, up, deg(20.0)), None);
        // Y-up taken for this Z-up frame: the travel does not rise along y.
        assert_eq!(orient_by_height(rising, Upslope::new([0.0, 1.0, 0.0]).unwrap(), deg(20.0)), None);
    }

    /// Without a slope, the travel's own rise orients it: a line inclined 20 deg (rise
    /// sin 20 = 0.342 per unit length) points upslope whichever way it was estimated; a line
    /// inclined 0.5 deg (below the 1 deg limit) or running level is left to the net motion.
    #[test]
    fn orient_by_rise_points_upslope_without_a_slope() {
        let (s, c) = 20f64.to_radians().sin_cos();
        let up = Upslope::new([0.0, 0.0, 1.0]).unwrap();
        let rising = Upslope::new([c, 0.0, s]).unwrap();
        let falling = Upslope::new([-c, 0.0, -s]).unwrap();
        assert_eq!(orient_by_rise(rising, up), Some(rising));
        assert_eq!(orient_by_rise(falling, up).unwrap().vector(), rising.vector());
        let (s5, c5) = 0.5f64.to_radians().sin_cos();
        assert_eq!(orient_by_rise(Upslope::new([-c5, 0.0, -s5]).unwrap(), up), None);
        let (s2, c2) = 2f64.to_radians().sin_cos();
        assert!(orient_by_rise(Upslope::new([-c2, 0.0, -s2]).unwrap(), up).unwrap().vector()[0] > 0.99);
        assert_eq!(orient_by_rise(Upslope::new([0.0, 1.0, 0.0]).unwrap(), up), None);
    }

    #[test]
    fn normalises_and_rejects_zero() {
        let u = Upslope::new([3.0, 0.0, 4.0]).unwrap();
        assert_eq!(u.vector(), [0.6, 0.0, 0.8]);
        assert!(Upslope::new([0.0; 3]).is_err());
        assert!(Upslope::new([f64::NAN, 1.0, 0.0]).is_err());
    }

    /// A straight climb along (0.8, 0, 0.6) with sideways sway: the principal direction is
    /// the climb's, pointing the way the robot went, even when it travels "backwards" in x.
    #[test]
    fn principal_direction_follows_travel() {
        let dir = [-0.8, 0.0, 0.6];
        let pos: Vec<[f64; 3]> = (0..500)
            .map(|i| {
                let s = i as f64 * 1e-3;
                let sway = 0.01 * (i as f64 * 0.3).sin();
                [dir[0] * s, sway, dir[2] * s]
            })
            .collect();
        let mut with_gap = pos.clone();
        with_gap[100] = [f64::NAN, 0.0, 0.0];
        let u = principal_direction(&[&with_gap]).unwrap().vector();
        // The sway (1 cm) does not average out exactly over 500 frames; its residual
        // correlation with the 0.5 m of travel tilts the axis by a few milliradians at most.
        for k in 0..3 {
            assert!((u[k] - dir[k]).abs() < 5e-3, "{u:?}");
        }
        let along = project(&with_gap, Upslope::new(dir).unwrap());
        assert!(along[100].is_nan());
        assert!((along[499] - 0.499).abs() < 1e-12);
        assert!(principal_direction(&[&pos[..1]]).is_none());
        assert!(principal_direction(&[&vec![[1.0, 2.0, 3.0]; 10]]).is_none());
    }
}
