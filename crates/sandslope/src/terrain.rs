//! Terrain resistance as a function of slope (docs/model.md §7).
//!
//! A terrain is a table of measured points `(slope_deg, k_n, k_s)` with optional standard
//! deviations, an optional angle of repose and an optional name. Between points values are
//! interpolated linearly in degrees; below the first point the first point holds; above the
//! last point the last segment is extended linearly and floored at zero, and
//! [`Terrain::extrapolates`] says so, so the caller can warn (a docs/model.md §7 choice).
//! [`Terrain::at`] gives the one "ground at a slope" type, [`Ground`], which is all the model
//! needs; [`Terrain::sd_at`] gives the table's uncertainty there.

use serde::{Deserialize, Serialize};

use crate::error::{positive, ParamError};
use crate::slope::Slope;

/// One measured point as written in a terrain file; unknown keys rejected.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TerrainPoint {
    /// Slope at which the point was measured, degrees.
    pub slope_deg: f64,
    /// Normal penetration resistance k_n, N/m^3.
    pub k_n: f64,
    /// Shear strength k_s, N/m^3.
    pub k_s: f64,
    /// Standard deviation of k_n across trials, N/m^3.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k_n_sd: Option<f64>,
    /// Standard deviation of k_s across trials, N/m^3.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k_s_sd: Option<f64>,
}

/// A terrain file: the keys of docs/model.md §7, unknown keys rejected.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TerrainSpec {
    /// A human-readable name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Angle of repose, degrees: at or above it the surface yields (regime slippage).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repose_deg: Option<f64>,
    /// Measured points, at distinct slopes.
    pub points: Vec<TerrainPoint>,
}

/// The ground under the robot at one slope: the inputs of the model besides robot and slope.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ground {
    /// Normal penetration resistance k_n, N/m^3 (0 means no support at any depth).
    pub k_n: f64,
    /// Shear strength k_s, N/m^3 (0 means no anchoring at any depth).
    pub k_s: f64,
    /// Angle of repose of the terrain, if known.
    pub repose: Option<Slope>,
}

impl Ground {
    /// Ground with resistances `k_n`, `k_s` (finite, >= 0) and no known angle of repose.
    pub fn new(k_n: f64, k_s: f64) -> Result<Ground, ParamError> {
        crate::error::non_negative("k_n", k_n)?;
        crate::error::non_negative("k_s", k_s)?;
        Ok(Ground { k_n, k_s, repose: None })
    }

    /// The same ground with an angle of repose.
    pub fn with_repose(self, repose: Option<Slope>) -> Ground {
        Ground { repose, ..self }
    }

    /// Whether `slope` is at or above the angle of repose.
    pub fn beyond_repose(&self, slope: Slope) -> bool {
        self.repose.is_some_and(|r| slope.radians() >= r.radians())
    }
}

/// The range of plausibility of a terrain's resistances k_n and k_s (docs/model.md §7), read
/// from a terrain file or given as `--k-n`/`--k-s`: 10^3 to 10^10 N/m^3, about four decades
/// either side of the paper's glass beads (k_n 7e5, k_s 2e6 to 3e6). Below 10^3 every robot of
/// [`crate::robot::PLAUSIBLE`] sinks (the paper's sinks metres deep); above 10^10 the sand is
/// stiffer than any granular bed, and the simulator's contact solve slows without bound (a
/// k_n of 1e308 kept a live drive 32 s before its first step). A value outside is far more
/// often a unit mistake (0.7 "N/m^3" that was 0.7 N/cm^3) than a terrain, and the message names
/// the unit it fits. The key printed is the one checked (`points[0].k_n`, `--k-s`).
pub const K_PLAUSIBLE: crate::robot::Plausible = crate::robot::Plausible {
    key: "k_n",
    min: 1e3,
    max: 1e10,
    unit: "N/m^3",
    mistakes: &[("kN/m^3", 1e3), ("N/cm^3 (= MN/m^3)", 1e6), ("N/mm^3", 1e9)],
};

/// Checks a resistance given by the user (a terrain file's `k_n` or `k_s`, a `--k-n` or
/// `--k-s` override) against [`K_PLAUSIBLE`]; the error names `key`, the range and the unit it
/// was likely given in.
pub fn check_plausible_resistance(key: &str, value: f64) -> Result<f64, ParamError> {
    K_PLAUSIBLE.check_as(value, "a plausible granular terrain (docs/model.md §7)").map_err(|e| e.renamed(key))
}

impl TerrainSpec {
    /// Checks every point's k_n and k_s against [`K_PLAUSIBLE`] (what a terrain file must
    /// meet beyond [`Terrain::new`]'s validity; fitted and scaled terrains built in the
    /// library are not held to it). Errors name `points[i].k_n` as the file has it.
    pub fn check_plausible(&self) -> Result<(), ParamError> {
        for (i, p) in self.points.iter().enumerate() {
            check_plausible_resistance(&format!("points[{i}].k_n"), p.k_n)?;
            check_plausible_resistance(&format!("points[{i}].k_s"), p.k_s)?;
        }
        Ok(())
    }
}

/// A validated terrain table, points sorted by slope. Build it with [`Terrain::new`].
#[derive(Debug, Clone, PartialEq)]
pub struct Terrain {
    spec: TerrainSpec,
    repose: Option<Slope>,
}

impl Terrain {
    /// Validates a terrain: at least one point; slopes in `[0, 90)` and distinct; k_n, k_s > 0;
    /// SDs >= 0; `repose_deg` in `(0, 90)`. Points are sorted by slope.
    pub fn new(mut spec: TerrainSpec) -> Result<Terrain, ParamError> {
        if spec.points.is_empty() {
            return Err(ParamError::new("points", 0.0, "at least one [[points]] entry"));
        }
        for (i, p) in spec.points.iter().enumerate() {
            let key = |k: &str| format!("points[{i}].{k}");
            Slope::from_degrees(p.slope_deg).map_err(|e| e.renamed(key("slope_deg")))?;
            positive(&key("k_n"), p.k_n)?;
            positive(&key("k_s"), p.k_s)?;
            for (name, sd) in [("k_n_sd", p.k_n_sd), ("k_s_sd", p.k_s_sd)] {
                if let Some(sd) = sd {
                    crate::error::non_negative(&key(name), sd)?;
                }
            }
        }
        spec.points.sort_by(|a, b| a.slope_deg.total_cmp(&b.slope_deg));
        for w in spec.points.windows(2) {
            if w[0].slope_deg == w[1].slope_deg {
                return Err(ParamError::new(
                    "points.slope_deg",
                    w[1].slope_deg,
                    "distinct: two points share this slope",
                ));
            }
        }
        let repose = match spec.repose_deg {
            None => None,
            Some(r) => match Slope::from_degrees(r) {
                Ok(s) if r > 0.0 => Some(s),
                _ => return Err(ParamError::new("repose_deg", r, "strictly between 0 and 90 degrees")),
            },
        };
        Ok(Terrain { spec, repose })
    }

    /// One point everywhere: constant k_n and k_s at every slope.
    pub fn constant(k_n: f64, k_s: f64) -> Result<Terrain, ParamError> {
        Terrain::new(TerrainSpec {
            name: None,
            repose_deg: None,
            points: vec![TerrainPoint { slope_deg: 0.0, k_n, k_s, k_n_sd: None, k_s_sd: None }],
        })
    }

    /// The plain, serialisable form (points sorted by slope).
    pub fn spec(&self) -> &TerrainSpec {
        &self.spec
    }

    /// The terrain's name, if it has one.
    pub fn name(&self) -> Option<&str> {
        self.spec.name.as_deref()
    }

    /// The angle of repose, if known.
    pub fn repose(&self) -> Option<Slope> {
        self.repose
    }

    /// The measured points, sorted by slope.
    pub fn points(&self) -> &[TerrainPoint] {
        &self.spec.points
    }

    /// Whether every point carries both standard deviations.
    pub fn has_uncertainty(&self) -> bool {
        self.spec.points.iter().all(|p| p.k_n_sd.is_some() && p.k_s_sd.is_some())
    }

    /// The segment of the table that covers `slope` (degrees), the fraction along it, and
    /// whether the slope lies beyond the last point (extrapolated).
    fn segment(&self, deg: f64) -> (&TerrainPoint, &TerrainPoint, f64, bool) {
        let pts = &self.spec.points;
        let (a, b, frac, beyond) = segment(pts, |p| p.slope_deg, deg);
        (&pts[a], &pts[b], frac, beyond)
    }

    /// The ground at `slope`: k_n and k_s by the interpolation rule of docs/model.md §7, and
    /// the terrain's angle of repose.
    pub fn at(&self, slope: Slope) -> Ground {
        let (a, b, frac, _) = self.segment(slope.degrees());
        let lerp = |x: f64, y: f64| lerp(x, y, frac);
        Ground { k_n: lerp(a.k_n, b.k_n), k_s: lerp(a.k_s, b.k_s), repose: self.repose }
    }

    /// The standard deviations `(k_n_sd, k_s_sd)` at `slope`, interpolated like the values;
    /// each `None` where the table does not give it at both ends of the segment.
    pub fn sd_at(&self, slope: Slope) -> (Option<f64>, Option<f64>) {
        let (a, b, frac, _) = self.segment(slope.degrees());
        let lerp = |x: Option<f64>, y: Option<f64>| match (x, y) {
            (Some(x), Some(y)) => Some(lerp(x, y, frac)),
            _ => None,
        };
        (lerp(a.k_n_sd, b.k_n_sd), lerp(a.k_s_sd, b.k_s_sd))
    }

    /// Whether `slope` lies above the last measured point, where [`Terrain::at`] extrapolates
    /// the last segment (docs/model.md §7); never for a one-point table.
    pub fn extrapolates(&self, slope: Slope) -> bool {
        self.segment(slope.degrees()).3
    }
}

/// The interpolation rule of docs/model.md §7 over points sorted by slope: the indices of the
/// two points whose segment covers `deg`, the fraction along it, and whether `deg` lies beyond
/// the last point (the last segment extended). Below the first point the first point holds.
fn segment<T>(points: &[T], slope_deg: impl Fn(&T) -> f64, deg: f64) -> (usize, usize, f64, bool) {
    let n = points.len();
    let (a, b, beyond) = if n == 1 || deg <= slope_deg(&points[0]) {
        (0, 0, false)
    } else if deg > slope_deg(&points[n - 1]) {
        (n - 2, n - 1, true)
    } else {
        let i = points.partition_point(|p| slope_deg(p) < deg).max(1);
        (i - 1, i, false)
    };
    let (da, db) = (slope_deg(&points[a]), slope_deg(&points[b]));
    let frac = if db > da { (deg - da) / (db - da) } else { 0.0 };
    (a, b, frac, beyond && n > 1)
}

/// `x + frac (y - x)`, floored at zero (docs/model.md §7).
fn lerp(x: f64, y: f64, frac: f64) -> f64 {
    (x + frac * (y - x)).max(0.0)
}

/// A `(slope_deg, value)` table (sorted by slope, not empty) at `deg`, by the terrain table's
/// interpolation rule (docs/model.md §7): what a table of fitted values between force-test
/// slopes follows.
pub(crate) fn interpolate(points: &[(f64, f64)], deg: f64) -> f64 {
    let (a, b, frac, _) = segment(points, |p| p.0, deg);
    lerp(points[a].1, points[b].1, frac)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pt(slope_deg: f64, k_n: f64, k_s: f64) -> TerrainPoint {
        TerrainPoint { slope_deg, k_n, k_s, k_n_sd: None, k_s_sd: None }
    }

    fn two_point() -> Terrain {
        Terrain::new(TerrainSpec {
            name: None,
            repose_deg: Some(25.0),
            points: vec![pt(20.0, 6e5, 1e6), pt(0.0, 7e5, 2e6)],
        })
        .unwrap()
    }

    fn at(t: &Terrain, deg: f64) -> (Ground, bool) {
        let s = Slope::from_degrees(deg).unwrap();
        (t.at(s), t.extrapolates(s))
    }

    /// The range is 1e3 to 1e10 N/m^3, edges included; k_n = 1e308 (the file) is
    /// refused under the file's key, and 0.7 given in N/cm^3 is named as 0.7 * 1e6 = 700000
    /// N/m^3 (700 given in kN/m^3 likewise), while 1e308 fits no unit.
    #[test]
    fn implausible_resistances_are_refused_with_the_range_and_the_likely_unit() {
        let spec = |k_n: f64, k_s: f64| TerrainSpec {
            name: None,
            repose_deg: None,
            points: vec![pt(0.0, k_n, k_s)],
        };
        assert!(spec(1e3, 1e10).check_plausible().is_ok());
        assert!(spec(7e5, 2e6).check_plausible().is_ok());
        let e = spec(1e308, 2e6).check_plausible().unwrap_err();
        assert_eq!(e.key, "points[0].k_n");
        let text = e.to_string();
        assert!(text.contains("between 1e3 and 1e10 N/m^3") && !text.contains("if it was given"), "{text}");
        let e = spec(7e5, 0.7).check_plausible().unwrap_err();
        assert_eq!(e.key, "points[0].k_s");
        assert!(e.to_string().contains("if it was given in N/cm^3 (= MN/m^3), that is 700000 N/m^3"), "{e}");
        let e = check_plausible_resistance("--k-n", 700.0).unwrap_err().to_string();
        assert!(e.starts_with("--k-n = 700 must be") && e.contains("in kN/m^3, that is 700000 N/m^3"), "{e}");
        assert!(check_plausible_resistance("k", 9.99e2).is_err());
        assert!(check_plausible_resistance("k", 1.01e10).is_err());
    }

    #[test]
    fn interpolates_linearly_in_degrees() {
        let t = two_point();
        // Halfway: (2e6 + 1e6)/2 and (7e5 + 6e5)/2.
        let (g, extrapolated) = at(&t, 10.0);
        assert!((g.k_s - 1.5e6).abs() < 1e-6);
        assert!((g.k_n - 6.5e5).abs() < 1e-6);
        assert!(!extrapolated);
    }

    #[test]
    fn holds_first_point_below_and_extrapolates_above_with_floor() {
        let t = Terrain::new(TerrainSpec {
            name: None,
            repose_deg: None,
            points: vec![pt(5.0, 7e5, 2e6), pt(15.0, 7e5, 1e6)],
        })
        .unwrap();
        assert_eq!(at(&t, 0.0).0.k_s, 2e6);
        // Slope of -1e5 per degree beyond 15: at 20 deg 5e5, flagged.
        let (g, extrapolated) = at(&t, 20.0);
        assert!((g.k_s - 5e5).abs() < 1e-6);
        assert!(extrapolated);
        // At 40 deg the line is negative: floored at zero.
        assert_eq!(at(&t, 40.0).0.k_s, 0.0);
    }

    #[test]
    fn standard_deviations_interpolate_like_values_and_need_both_ends() {
        let sd = |slope_deg, k_n_sd, k_s_sd| TerrainPoint { k_n_sd, k_s_sd, ..pt(slope_deg, 7e5, 2e6) };
        let t = Terrain::new(TerrainSpec {
            name: None,
            repose_deg: None,
            points: vec![sd(0.0, Some(1e4), Some(2e5)), sd(10.0, Some(3e4), None)],
        })
        .unwrap();
        // A quarter of the way: 1e4 + 0.25 * 2e4; k_s_sd missing at one end.
        let (n, s) = t.sd_at(Slope::from_degrees(2.5).unwrap());
        assert!((n.unwrap() - 1.5e4).abs() < 1e-9);
        assert_eq!(s, None);
    }

    #[test]
    fn single_point_is_constant() {
        let t = Terrain::constant(7e5, 2e6).unwrap();
        for d in [0.0, 10.0, 60.0] {
            let (g, extrapolated) = at(&t, d);
            assert_eq!((g.k_n, g.k_s, extrapolated), (7e5, 2e6, false));
        }
    }

    #[test]
    fn rejects_bad_tables() {
        let none = TerrainSpec { name: None, repose_deg: None, points: vec![] };
        assert!(Terrain::new(none).is_err());
        let dup =
            TerrainSpec { name: None, repose_deg: None, points: vec![pt(5.0, 1.0, 1.0), pt(5.0, 2.0, 2.0)] };
        assert!(Terrain::new(dup).is_err());
        let neg = TerrainSpec { name: None, repose_deg: None, points: vec![pt(5.0, -1.0, 1.0)] };
        assert_eq!(Terrain::new(neg).unwrap_err().key, "points[0].k_n");
        let rep = TerrainSpec { name: None, repose_deg: Some(0.0), points: vec![pt(5.0, 1.0, 1.0)] };
        assert_eq!(Terrain::new(rep).unwrap_err().key, "repose_deg");
    }
}
