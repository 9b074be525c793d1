//! The inclination of the sand surface along the direction of travel (docs/model.md §1).
//!
//! Angles are degrees only at the edges of the program; a [`Slope`] is built
//! from degrees and gives radians, sine and cosine to the physics.
//! The model covers climbing, so a `Slope` is in `[0, 90)` degrees; descending travel is
//! mapped onto it by the caller (docs/model.md §8 evaluates descent with `|theta|`).

use crate::error::ParamError;

/// An inclination in `[0, 90)` degrees.
///
/// Stored in degrees, the unit users give, so that a slope prints back exactly as entered.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Default)]
pub struct Slope {
    degrees: f64,
}

impl Slope {
    /// Level ground.
    pub const LEVEL: Slope = Slope { degrees: 0.0 };

    /// A slope from degrees; fails unless `0 <= degrees < 90`.
    pub fn from_degrees(degrees: f64) -> Result<Slope, ParamError> {
        if degrees.is_finite() && (0.0..90.0).contains(&degrees) {
            Ok(Slope { degrees })
        } else {
            Err(ParamError::new("slope_deg", degrees, "between 0 and 90 degrees (90 excluded)"))
        }
    }

    /// A slope from radians; fails unless `0 <= radians < pi/2`.
    pub fn from_radians(radians: f64) -> Result<Slope, ParamError> {
        Slope::from_degrees(radians.to_degrees()).map_err(|e| ParamError {
            value: radians,
            expected: "between 0 and pi/2 radians (pi/2 excluded)".into(),
            ..e
        })
    }

    /// The slope felt when travelling with signed inclination `degrees`: descending
    /// (`degrees < 0`) is evaluated as climbing `|degrees|` (docs/model.md §8, a choice).
    pub fn from_signed_degrees(degrees: f64) -> Result<Slope, ParamError> {
        Slope::from_degrees(degrees.abs()).map_err(|e| ParamError {
            value: degrees,
            expected: "strictly between -90 and 90 degrees".into(),
            ..e
        })
    }

    /// The inclination in radians.
    pub fn radians(self) -> f64 {
        self.degrees.to_radians()
    }

    /// The inclination in degrees.
    pub fn degrees(self) -> f64 {
        self.degrees
    }

    /// `sin(theta)`.
    pub fn sin(self) -> f64 {
        self.radians().sin()
    }

    /// `cos(theta)`.
    pub fn cos(self) -> f64 {
        self.radians().cos()
    }
}

/// A slope along the direction of travel as a user gives it, in `(-90, 90)` degrees
/// (negative: descending), validated once. Answers print it back as given; the physics takes
/// the [`Slope`] it is [`felt`](SignedSlope::felt) as (docs/model.md §8: descent evaluated as
/// the climb of its size).
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Default)]
pub struct SignedSlope {
    degrees: f64,
}

impl SignedSlope {
    /// A signed slope from degrees; fails unless `-90 < degrees < 90` (the error of
    /// [`Slope::from_signed_degrees`], key `slope_deg`).
    pub fn from_degrees(degrees: f64) -> Result<SignedSlope, ParamError> {
        Slope::from_signed_degrees(degrees).map(|_| SignedSlope { degrees })
    }

    /// The slope in degrees, as given.
    pub fn degrees(self) -> f64 {
        self.degrees
    }

    /// The slope the robot climbs: `|degrees|` (docs/model.md §8).
    pub fn felt(self) -> Slope {
        Slope { degrees: self.degrees.abs() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degrees_round_trip_and_range() {
        let s = Slope::from_degrees(30.0).unwrap();
        assert!((s.sin() - 0.5).abs() < 1e-12);
        assert!((s.degrees() - 30.0).abs() < 1e-12);
        assert!(Slope::from_degrees(-1.0).is_err());
        assert!(Slope::from_degrees(90.0).is_err());
        assert!(Slope::from_degrees(f64::NAN).is_err());
        assert_eq!(Slope::from_signed_degrees(-12.0).unwrap(), Slope::from_degrees(12.0).unwrap());
    }

    /// A signed slope keeps its sign and is felt as its size; the same range as
    /// `from_signed_degrees`, ends excluded.
    #[test]
    fn signed_slopes_keep_their_sign_and_are_felt_as_their_size() {
        let s = SignedSlope::from_degrees(-12.5).unwrap();
        assert_eq!(s.degrees(), -12.5);
        assert_eq!(s.felt(), Slope::from_degrees(12.5).unwrap());
        assert_eq!(SignedSlope::from_degrees(30.0).unwrap().felt().degrees(), 30.0);
        for bad in [90.0, -90.0, f64::NAN, f64::INFINITY] {
            let e = SignedSlope::from_degrees(bad).unwrap_err();
            assert_eq!(e.key, "slope_deg");
            assert_eq!(e.expected, "strictly between -90 and 90 degrees");
        }
    }
}
