//! The model tabulated against pitch, once per terrain class.
//!
//! With one terrain per class, speed, regime and failure probability depend only on the
//! pitch of an edge, so they are computed once on a fine table of `tan(pitch)` rather than
//! per edge. Entry `i` holds the model at `tan(pitch) = i * TAN_STEP`; a lookup rounds the
//! pitch *up* to the next entry (at most 0.06 degrees steeper: conservative where failure
//! grows with slope). Failure probabilities come from [`crate::risk::p_fail`] (within 2e-9 of
//! [`crate::risk::regime_probabilities`] and about a hundred times cheaper),
//! with the uncertainty of [`crate::risk::UncertainTerrain`] (docs/model.md §9), every [`P_FAIL_STEP_DEG`] degrees, interpolated linearly in degrees between samples.
//!
//! Every entry depends only on its index, never on the table's length, so the first entries of
//! a longer table are a shorter table exactly: [`PitchTableCache`] keeps the longest table built
//! for a robot and terrain and hands out its prefixes, so the tiles of a large map (or repeated
//! calls from a notebook) tabulate the model once instead of once each.

use std::sync::{Arc, Mutex};

use rayon::prelude::*;

use crate::model::predict;
use crate::regime::Regime;
use crate::risk::{p_fail, UncertainTerrain};
use crate::robot::Robot;
use crate::slope::Slope;

/// Step of the pitch table in `tan(pitch)` (0.057 degrees on level ground, less when steeper).
pub const TAN_STEP: f64 = 1e-3;
/// Steepest pitch tabulated, degrees; steeper edges (cliffs in the DEM) are impassable.
pub const MAX_PITCH_DEG: f64 = 89.0;
/// Spacing of the failure-probability samples, degrees.
pub const P_FAIL_STEP_DEG: f64 = 0.1;

/// The model of one robot on one terrain class, against pitch.
#[derive(Debug, Clone)]
pub struct PitchTable {
    /// Regime at each entry.
    pub(crate) regime: Vec<Regime>,
    /// Speed along the surface, m/s (NaN where undefined).
    pub(crate) speed: Vec<f32>,
    /// P(sinkage or slippage) at each entry.
    pub(crate) p_fail: Vec<f32>,
    /// Whether any tabulated slope lies beyond the terrain's last measured point.
    pub(crate) extrapolated_from_deg: Option<f64>,
}

impl PitchTable {
    /// Tabulates the model for `robot` on `class` for pitches up to `atan(max_tan)` (capped at
    /// [`MAX_PITCH_DEG`]): one risk evaluation per [`P_FAIL_STEP_DEG`], in parallel. A map
    /// needs no pitch steeper than its steepest gradient.
    pub fn new(robot: &Robot, class: &UncertainTerrain, max_tan: f64) -> PitchTable {
        let n = table_len(max_tan);
        let slope_of = |deg: f64| Slope::from_degrees(deg.clamp(0.0, MAX_PITCH_DEG)).unwrap_or(Slope::LEVEL);
        let rows: Vec<(Regime, f32)> = (0..n)
            .into_par_iter()
            .map(|i| {
                let slope = slope_of((i as f64 * TAN_STEP).atan().to_degrees());
                let p = predict(robot, slope, &class.terrain().at(slope));
                (p.regime, p.speed.map_or(f32::NAN, |v| v as f32))
            })
            .collect();
        let top_deg = ((n - 1) as f64 * TAN_STEP).atan().to_degrees();
        let samples = ((top_deg / P_FAIL_STEP_DEG).ceil() as usize).max(1);
        let p_deg: Vec<f64> = (0..=samples)
            .into_par_iter()
            .map(|k| {
                let slope = slope_of(k as f64 * P_FAIL_STEP_DEG);
                let (ground, uncertainty) = class.at(slope);
                p_fail(robot, slope, &ground, uncertainty)
            })
            .collect();
        let p_fail = (0..n)
            .map(|i| {
                let x = (i as f64 * TAN_STEP).atan().to_degrees() / P_FAIL_STEP_DEG;
                let k = (x.floor() as usize).min(samples - 1);
                let f = (x - k as f64).clamp(0.0, 1.0);
                (p_deg[k] + f * (p_deg[k + 1] - p_deg[k])).clamp(0.0, 1.0) as f32
            })
            .collect();
        let last = class.terrain().points().last().map_or(0.0, |p| p.slope_deg);
        let extrapolated_from_deg =
            (class.terrain().points().len() > 1 && last < MAX_PITCH_DEG).then_some(last);
        let (regime, speed) = rows.into_iter().unzip();
        PitchTable { regime, speed, p_fail, extrapolated_from_deg }
    }

    /// The table entry for `|tan(pitch)|`, rounding up; `None` beyond [`MAX_PITCH_DEG`].
    pub fn index(&self, abs_tan: f64) -> Option<usize> {
        let i = (abs_tan / TAN_STEP).ceil();
        (i < self.regime.len() as f64).then_some(i as usize)
    }

    /// Regime at entry `i`.
    pub fn regime(&self, i: usize) -> Regime {
        self.regime[i]
    }
    /// Speed at entry `i`, m/s, if defined.
    pub fn speed(&self, i: usize) -> Option<f64> {
        let v = self.speed[i];
        v.is_finite().then_some(f64::from(v))
    }
    /// P(failure) at entry `i`.
    pub fn p_fail(&self, i: usize) -> f64 {
        f64::from(self.p_fail[i])
    }
    /// `tan(pitch)` of entry `i`.
    pub fn tan_of(i: usize) -> f64 {
        i as f64 * TAN_STEP
    }
    /// If the terrain was extrapolated above its last point, that point's slope, degrees.
    pub fn extrapolated_from_deg(&self) -> Option<f64> {
        self.extrapolated_from_deg
    }
    /// Number of entries.
    pub fn len(&self) -> usize {
        self.regime.len()
    }
    /// Whether the table is empty (never for a built table).
    pub fn is_empty(&self) -> bool {
        self.regime.is_empty()
    }
}

impl PitchTable {
    /// The table [`PitchTable::new`] builds for `max_tan`, cut from this longer one (its first
    /// entries, bit for bit); `None` when this table is shorter.
    pub fn prefix(&self, max_tan: f64) -> Option<PitchTable> {
        let n = table_len(max_tan);
        (n <= self.len()).then(|| PitchTable {
            regime: self.regime[..n].to_vec(),
            speed: self.speed[..n].to_vec(),
            p_fail: self.p_fail[..n].to_vec(),
            extrapolated_from_deg: self.extrapolated_from_deg,
        })
    }
}

/// Pitch tables kept between planners, for a process that builds many: the tiles of a map
/// computed one by one, or repeated calls with the same robot and terrain.
///
/// Holds, per robot and terrain class, the longest table built so far (a few, the most recently
/// used first) and answers a request with its prefix, identical to a fresh
/// [`PitchTable::new`]. Building a table is most of the cost of a 1024 x 1024 risk map tile
/// (0.17 of its 0.29 s on the development machine), so tiles after the first run about 2.4x
/// faster. Shared between threads.
#[derive(Debug, Default)]
pub struct PitchTableCache {
    tables: Mutex<Vec<CachedTable>>,
}

/// One robot and terrain class with its longest table.
#[derive(Debug)]
struct CachedTable {
    robot: Robot,
    class: UncertainTerrain,
    table: Arc<PitchTable>,
}

impl PitchTableCache {
    /// Robot and terrain pairs kept; the least recently used goes first.
    pub const CAPACITY: usize = 8;

    /// An empty cache.
    pub fn new() -> PitchTableCache {
        PitchTableCache::default()
    }

    /// The table of `robot` on `class` up to `atan(max_tan)`, from the cache when a long enough
    /// one is there, else built (outside the lock) and kept.
    pub fn table(&self, robot: &Robot, class: &UncertainTerrain, max_tan: f64) -> PitchTable {
        let cached = {
            let mut tables = self.lock();
            let hit = tables.iter().position(|c| c.robot == *robot && c.class == *class);
            hit.map(|i| {
                let entry = tables.remove(i);
                let table = Arc::clone(&entry.table);
                tables.insert(0, entry);
                table
            })
        };
        if let Some(table) = cached.as_deref().and_then(|t| t.prefix(max_tan)) {
            return table;
        }
        let built = PitchTable::new(robot, class, max_tan);
        let mut tables = self.lock();
        match tables.iter().position(|c| c.robot == *robot && c.class == *class) {
            Some(i) if tables[i].table.len() >= built.len() => {}
            Some(i) => tables[i].table = Arc::new(built.clone()),
            None => {
                tables.insert(
                    0,
                    CachedTable {
                        robot: robot.clone(),
                        class: class.clone(),
                        table: Arc::new(built.clone()),
                    },
                );
                tables.truncate(Self::CAPACITY);
            }
        }
        built
    }

    /// Number of robot and terrain pairs held.
    pub fn len(&self) -> usize {
        self.lock().len()
    }

    /// Whether nothing is held yet.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<CachedTable>> {
        // A panic while holding the lock leaves only whole entries behind: keep using them.
        self.tables.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

fn table_len(max_tan: f64) -> usize {
    let cap = MAX_PITCH_DEG.to_radians().tan();
    let top = if max_tan.is_finite() { max_tan.clamp(0.0, cap) } else { cap };
    (top / TAN_STEP).ceil() as usize + 2
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::tests::paper_robot;
    use crate::risk::{regime_probabilities, Uncertainty};
    use crate::terrain::{Ground, Terrain};

    #[test]
    fn table_agrees_with_the_model_at_its_entries() {
        let robot = paper_robot();
        let terrain = Terrain::constant(7e5, 2e6).unwrap();
        let class = UncertainTerrain::new(terrain, None, None).unwrap();
        let t = PitchTable::new(&robot, &class, 0.5);
        assert_eq!(t.len(), 502);
        for deg in [0.0_f64, 10.0, 19.0, 21.5, 26.0] {
            let i = t.index(deg.to_radians().tan()).unwrap();
            let slope = Slope::from_radians(PitchTable::tan_of(i).atan()).unwrap();
            // Rounded up by less than one step.
            assert!(slope.degrees() >= deg - 1e-9 && slope.degrees() < deg + 0.06);
            let p = predict(&robot, slope, &Ground::new(7e5, 2e6).unwrap());
            assert_eq!(t.regime(i), p.regime);
            assert!((t.speed(i).unwrap() - p.speed.unwrap()).abs() < 1e-6);
            let q =
                regime_probabilities(&robot, slope, &Ground::new(7e5, 2e6).unwrap(), Uncertainty::DEFAULT)
                    .p_fail();
            // Linear interpolation over 0.1 degree.
            assert!((t.p_fail(i) - q).abs() < 0.02, "{deg}: {} vs {q}", t.p_fail(i));
        }
        assert!(t.index(0.502).is_none());
    }

    /// Bit-for-bit equality of two tables (speeds hold NaN, so `==` on floats will not do).
    fn same(a: &PitchTable, b: &PitchTable) -> bool {
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        a.regime == b.regime
            && bits(&a.speed) == bits(&b.speed)
            && bits(&a.p_fail) == bits(&b.p_fail)
            && a.extrapolated_from_deg == b.extrapolated_from_deg
    }

    #[test]
    fn cached_tables_are_fresh_tables_bit_for_bit() {
        let robot = paper_robot();
        let terrain = Terrain::new(crate::terrain::TerrainSpec {
            name: None,
            repose_deg: Some(30.0),
            points: [(0.0, 2e6), (20.0, 8e5)]
                .map(|(slope_deg, k_s)| crate::terrain::TerrainPoint {
                    slope_deg,
                    k_n: 7e5,
                    k_s,
                    k_n_sd: None,
                    k_s_sd: None,
                })
                .to_vec(),
        })
        .unwrap();
        let class = UncertainTerrain::new(terrain, Some(0.1), Some(0.2)).unwrap();
        let cache = PitchTableCache::new();
        // Short, longer (rebuilt), shorter again (a prefix), and past the longest kept.
        for max_tan in [0.05, 0.4, 0.17, 0.3999, 0.6, 0.0] {
            let fresh = PitchTable::new(&robot, &class, max_tan);
            assert!(same(&cache.table(&robot, &class, max_tan), &fresh), "max_tan {max_tan}");
        }
        assert_eq!(cache.len(), 1);
        // Another robot gets its own table, not the first robot's.
        let heavy = robot.with_mass(1.0).unwrap();
        assert!(same(&cache.table(&heavy, &class, 0.3), &PitchTable::new(&heavy, &class, 0.3)));
        assert_eq!(cache.len(), 2);
        assert!(PitchTable::new(&robot, &class, 0.1).prefix(0.2).is_none());
    }

    /// `risk` and `plan` read the same uncertainty from the same terrain and CVs (docs/model.md
    /// §9): the table's failure probability is the risk quadrature on the same
    /// [`UncertainTerrain`], within the interpolation between 0.1 degree samples. The terrain
    /// has SDs (cv 0.2 / 0.3) and the user gives cv_s 0.05: the given CV must win in both
    /// (before the rule was unified, plan used the table's 0.3 here, and p_fail moved by
    /// more than 0.1).
    #[test]
    fn plan_and_risk_give_the_same_uncertainty() {
        use crate::risk::failure_risk;
        use crate::terrain::{TerrainPoint, TerrainSpec};
        let robot = paper_robot();
        let point = |slope_deg: f64, k_s: f64| TerrainPoint {
            slope_deg,
            k_n: 7e5,
            k_s,
            k_n_sd: Some(1.4e5),
            k_s_sd: Some(0.3 * k_s),
        };
        let terrain = Terrain::new(TerrainSpec {
            name: None,
            repose_deg: None,
            points: vec![point(0.0, 2e6), point(20.0, 1e6)],
        })
        .unwrap();
        let given = UncertainTerrain::new(terrain.clone(), None, Some(0.05)).unwrap();
        let table_only = UncertainTerrain::new(terrain, None, None).unwrap();
        let t = PitchTable::new(&robot, &given, 0.6);
        let mut separated = 0;
        for deg in [5.0_f64, 12.0, 18.0, 21.0, 23.5, 26.0] {
            let i = t.index(deg.to_radians().tan()).unwrap();
            let slope = Slope::from_radians(PitchTable::tan_of(i).atan()).unwrap();
            let risk = failure_risk(&robot, slope, &given).p_fail();
            assert!((t.p_fail(i) - risk).abs() < 2e-3, "{deg}: plan {} vs risk {risk}", t.p_fail(i));
            assert_eq!(given.uncertainty_at(slope).cv_s(), 0.05);
            let other = failure_risk(&robot, slope, &table_only).p_fail();
            separated += usize::from((other - risk).abs() > 0.1);
        }
        assert!(separated > 0, "the test cannot tell the two rules apart");
    }
}
