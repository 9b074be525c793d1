//! The values of one grid axis, evenly spaced or log-spaced: the k_n and k_s axes of phase
//! diagrams and risk maps, and the varied keys of a design grid.

use serde::{Deserialize, Serialize};

use crate::error::ParamError;

/// Spacing of grid values along an axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AxisScale {
    /// Evenly spaced values.
    Linear,
    /// Evenly spaced logarithms (the paper's phase diagrams are log-log).
    Log,
}

/// The values of one grid axis: `n >= 2` points from `min` to `max` (both included).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Axis {
    min: f64,
    max: f64,
    #[serde(rename = "points")]
    n: usize,
    scale: AxisScale,
}

impl Axis {
    /// An axis of `n` values from `min` to `max`, named `key` in errors. Requires finite
    /// `0 <= min < max`, `min > 0` on a log axis, and `n >= 2`.
    pub fn new(key: &str, min: f64, max: f64, n: usize, scale: AxisScale) -> Result<Axis, ParamError> {
        let lowest = match scale {
            AxisScale::Linear => 0.0,
            AxisScale::Log => f64::MIN_POSITIVE,
        };
        if !(min.is_finite() && min >= lowest) {
            let expected = match scale {
                AxisScale::Linear => "a finite number of at least 0",
                AxisScale::Log => "a finite number greater than 0 on a log axis",
            };
            return Err(ParamError::new(format!("{key} min"), min, expected));
        }
        if !(max.is_finite() && max > min) {
            return Err(ParamError::new(
                format!("{key} max"),
                max,
                format!("finite and greater than min = {min}"),
            ));
        }
        if n < 2 {
            return Err(ParamError::new(format!("{key} points"), n as f64, "at least 2"));
        }
        Ok(Axis { min, max, n, scale })
    }

    /// `n` log-spaced values from the smallest positive finite value of `values` / `down` to
    /// the largest x `up` (1e3 to 1e9 when none is positive): the default grid around a
    /// terrain's values (the maps' default axes), named `key` in errors.
    pub fn log_around(key: &str, values: &[f64], down: f64, up: f64, n: usize) -> Result<Axis, ParamError> {
        let positive = || values.iter().copied().filter(|v| *v > 0.0 && v.is_finite());
        let (lo, hi) = match positive().next() {
            None => (1e3, 1e9),
            Some(_) => (positive().fold(f64::INFINITY, f64::min) / down, positive().fold(0.0, f64::max) * up),
        };
        Axis::new(key, lo, hi, n, AxisScale::Log)
    }

    /// Number of values.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Always false: an axis has at least two values.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Smallest value.
    pub fn min(&self) -> f64 {
        self.min
    }

    /// Largest value.
    pub fn max(&self) -> f64 {
        self.max
    }

    /// Spacing.
    pub fn scale(&self) -> AxisScale {
        self.scale
    }

    /// The `i`-th value (`i < len`); the ends are exactly `min` and `max`.
    pub fn value(&self, i: usize) -> f64 {
        if i == 0 {
            return self.min;
        }
        if i + 1 >= self.n {
            return self.max;
        }
        let f = i as f64 / (self.n - 1) as f64;
        match self.scale {
            AxisScale::Linear => self.min + f * (self.max - self.min),
            AxisScale::Log => (self.min.ln() + f * (self.max.ln() - self.min.ln())).exp(),
        }
    }

    /// All values, ascending.
    pub fn values(&self) -> Vec<f64> {
        (0..self.n).map(|i| self.value(i)).collect()
    }

    /// The coordinate in which values are evenly spaced: the value itself, or its logarithm.
    pub fn coordinate(&self, value: f64) -> f64 {
        match self.scale {
            AxisScale::Linear => value,
            AxisScale::Log => value.ln(),
        }
    }

    /// The inverse of [`Axis::coordinate`].
    pub fn from_coordinate(&self, c: f64) -> f64 {
        match self.scale {
            AxisScale::Linear => c,
            AxisScale::Log => c.exp(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default grid spans the positive values' range widened by the factors; with no
    /// positive value (a table floored at zero), 1e3 to 1e9.
    #[test]
    fn log_around_widens_the_positive_values() {
        let a = Axis::log_around("k_s", &[0.0, 2e6, f64::NAN, 5e5], 100.0, 10.0, 7).unwrap();
        assert_eq!((a.min(), a.max(), a.len(), a.scale()), (5e3, 2e7, 7, AxisScale::Log));
        let b = Axis::log_around("k_n", &[0.0], 100.0, 100.0, 3).unwrap();
        assert_eq!((b.min(), b.max()), (1e3, 1e9));
        assert_eq!(Axis::log_around("k_n", &[7e5], 100.0, 100.0, 1).unwrap_err().key, "k_n points");
    }

    #[test]
    fn axes_hit_their_ends_and_space_evenly() {
        let a = Axis::new("k", 1e3, 1e7, 5, AxisScale::Log).unwrap();
        let v = a.values();
        assert_eq!((v[0], v[4]), (1e3, 1e7));
        for (x, e) in v.iter().zip([1e3, 1e4, 1e5, 1e6, 1e7]) {
            assert!((x / e - 1.0).abs() < 1e-12, "{x} vs {e}");
        }
        let l = Axis::new("k", 0.0, 10.0, 11, AxisScale::Linear).unwrap();
        assert!((l.value(3) - 3.0).abs() < 1e-12);
        assert!(Axis::new("k", 0.0, 10.0, 11, AxisScale::Log).is_err());
        assert!(Axis::new("k", 5.0, 5.0, 11, AxisScale::Linear).is_err());
        assert_eq!(Axis::new("--k-n", 1.0, 5.0, 1, AxisScale::Linear).unwrap_err().key, "--k-n points");
    }
}
