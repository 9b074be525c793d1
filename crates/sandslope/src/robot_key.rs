//! The robot's keys (docs/model.md §2), named once: each key's file name (the TOML key, the
//! JSON key and the Python keyword of `sandslope.Robot(**keys)`, which are one name), its
//! unit, and how to read and set it on a [`RobotSpec`]. Calibration frees the continuous ones
//! ([`RobotKey::FITTABLE`]) and a design study varies any of them; the command-line flags
//! that override some of them are the front ends' (the request layer's field table of robot
//! quantities), mapped from the library's error by its key. Each key's valid range is the robot's
//! own ([`RobotKey::plausible`], [`RobotKey::valid_range`]): the ranges of plausibility of
//! [`crate::robot::PLAUSIBLE`], which [`crate::Robot::new`] checks.

use serde::{Deserialize, Serialize};

use crate::robot::{Plausible, RobotSpec, STANCE_LEGS_RANGE};

/// A key of the robot file (docs/model.md §2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RobotKey {
    /// `mass_kg`.
    MassKg,
    /// `leg_radius_m`.
    LegRadiusM,
    /// `leg_width_m`.
    LegWidthM,
    /// `hip_height_m`.
    HipHeightM,
    /// `leg_speed_rad_s`.
    LegSpeedRadS,
    /// `stance_legs` (whole numbers only).
    StanceLegs,
    /// `response_time_s`.
    ResponseTimeS,
    /// `leg_contact_area_m2`.
    LegContactAreaM2,
    /// `level_step_m`.
    LevelStepM,
    /// `min_step_m`.
    MinStepM,
}

/// One row of the table of robot keys.
#[derive(Debug, Clone, Copy)]
pub struct RobotKeyRow {
    /// The key.
    pub key: RobotKey,
    /// Its name in robot files, JSON and Python keywords.
    pub name: &'static str,
    /// The unit of its value.
    pub unit: &'static str,
    /// What it is, in words.
    pub description: &'static str,
}

impl RobotKey {
    /// The table: every key in the order of docs/model.md §2.
    pub const TABLE: [RobotKeyRow; 10] = [
        row(RobotKey::MassKg, "mass_kg", "kg", "total robot mass m"),
        row(RobotKey::LegRadiusM, "leg_radius_m", "m", "C-leg radius R"),
        row(RobotKey::LegWidthM, "leg_width_m", "m", "leg width W"),
        row(RobotKey::HipHeightM, "hip_height_m", "m", "hip height h (between 0 and 2R)"),
        row(RobotKey::LegSpeedRadS, "leg_speed_rad_s", "rad/s", "leg angular speed omega"),
        row(RobotKey::StanceLegs, "stance_legs", "legs", "legs in stance at once n"),
        row(RobotKey::ResponseTimeS, "response_time_s", "s", "elastic response time dt"),
        row(RobotKey::LegContactAreaM2, "leg_contact_area_m2", "m^2", "leg contact area A_c (default W R)"),
        row(RobotKey::LevelStepM, "level_step_m", "m", "measured level-sand step s* (default: the model's)"),
        row(RobotKey::MinStepM, "min_step_m", "m", "smallest step counted as success s_min"),
    ];

    /// Every key, in the order of docs/model.md §2.
    pub const ALL: [RobotKey; 10] = [
        RobotKey::MassKg,
        RobotKey::LegRadiusM,
        RobotKey::LegWidthM,
        RobotKey::HipHeightM,
        RobotKey::LegSpeedRadS,
        RobotKey::StanceLegs,
        RobotKey::ResponseTimeS,
        RobotKey::LegContactAreaM2,
        RobotKey::LevelStepM,
        RobotKey::MinStepM,
    ];

    /// The continuous keys a calibration may free, in file order (not `stance_legs`, a whole
    /// number, nor `min_step_m`, which no observed speed or time depends on).
    pub const FITTABLE: [RobotKey; 8] = [
        RobotKey::MassKg,
        RobotKey::LegRadiusM,
        RobotKey::LegWidthM,
        RobotKey::HipHeightM,
        RobotKey::LegSpeedRadS,
        RobotKey::ResponseTimeS,
        RobotKey::LegContactAreaM2,
        RobotKey::LevelStepM,
    ];

    /// The key's row of [`RobotKey::TABLE`].
    pub fn row(self) -> &'static RobotKeyRow {
        &Self::TABLE[self as usize]
    }

    /// The file key (also the JSON key and the Python keyword).
    pub fn name(self) -> &'static str {
        self.row().name
    }

    /// The unit of the key's value.
    pub fn unit(self) -> &'static str {
        self.row().unit
    }

    /// The key named in a library error on the robot ([`crate::Robot::new`]'s `ParamError`
    /// names the robot file's key), where it is one.
    pub fn of_error(error: &crate::error::ParamError) -> Option<RobotKey> {
        Self::from_name(&error.key)
    }

    /// The key's range of plausibility ([`crate::robot::PLAUSIBLE`]); `None` for
    /// `stance_legs` (a whole number in [`STANCE_LEGS_RANGE`]) and `hip_height_m` (between 0
    /// and 2 `leg_radius_m`, docs/model.md §2).
    pub fn plausible(self) -> Option<&'static Plausible> {
        Plausible::of(self.name())
    }

    /// The key's valid range in words, as [`crate::Robot::new`] checks it.
    pub fn valid_range(self) -> String {
        match (self, self.plausible()) {
            (_, Some(p)) => format!("from {} to {} {}", p.min, p.max, p.unit),
            (RobotKey::StanceLegs, None) => {
                let (lo, hi) = STANCE_LEGS_RANGE;
                format!("a whole number from {lo} to {hi}")
            }
            (_, None) => "from 0 to 2 leg_radius_m".to_string(),
        }
    }

    /// The key named `name` in robot files.
    pub fn from_name(name: &str) -> Option<RobotKey> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// The spec's value of this key (`None` for an optional key it leaves to its default).
    pub fn get(self, spec: &RobotSpec) -> Option<f64> {
        match self {
            RobotKey::MassKg => Some(spec.mass_kg),
            RobotKey::LegRadiusM => Some(spec.leg_radius_m),
            RobotKey::LegWidthM => Some(spec.leg_width_m),
            RobotKey::HipHeightM => Some(spec.hip_height_m),
            RobotKey::LegSpeedRadS => Some(spec.leg_speed_rad_s),
            RobotKey::StanceLegs => Some(f64::from(spec.stance_legs)),
            RobotKey::ResponseTimeS => Some(spec.response_time_s),
            RobotKey::LegContactAreaM2 => spec.leg_contact_area_m2,
            RobotKey::LevelStepM => spec.level_step_m,
            RobotKey::MinStepM => spec.min_step_m,
        }
    }

    /// Sets the key in `spec` (unvalidated: [`crate::Robot::new`] checks the whole spec).
    /// `stance_legs` takes `value` truncated to a whole number; callers check it is one.
    pub fn set(self, spec: &mut RobotSpec, value: f64) {
        match self {
            RobotKey::MassKg => spec.mass_kg = value,
            RobotKey::LegRadiusM => spec.leg_radius_m = value,
            RobotKey::LegWidthM => spec.leg_width_m = value,
            RobotKey::HipHeightM => spec.hip_height_m = value,
            RobotKey::LegSpeedRadS => spec.leg_speed_rad_s = value,
            RobotKey::StanceLegs => spec.stance_legs = value as u32,
            RobotKey::ResponseTimeS => spec.response_time_s = value,
            RobotKey::LegContactAreaM2 => spec.leg_contact_area_m2 = Some(value),
            RobotKey::LevelStepM => spec.level_step_m = Some(value),
            RobotKey::MinStepM => spec.min_step_m = Some(value),
        }
    }
}

impl std::fmt::Display for RobotKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

const fn row(
    key: RobotKey,
    name: &'static str,
    unit: &'static str,
    description: &'static str,
) -> RobotKeyRow {
    RobotKeyRow { key, name, unit, description }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table's rows are in the enum's order (what `row` relies on), and every name is the
    /// robot file's: a spec written with each key set reads back with that key.
    #[test]
    fn rows_follow_the_enum_and_names_are_the_file_keys() {
        for (i, k) in RobotKey::ALL.into_iter().enumerate() {
            assert_eq!(RobotKey::TABLE[i].key, k);
            assert_eq!(serde_json::to_value(k).unwrap(), k.name());
            assert_eq!(RobotKey::from_name(k.name()), Some(k));
            let mut spec = RobotSpec::paper_hexapod();
            k.set(&mut spec, 2.0);
            let json = serde_json::to_value(&spec).unwrap();
            assert_eq!(json[k.name()], 2.0, "{k}: {json}");
        }
        assert_eq!(RobotKey::from_name("legs"), None);
    }

    /// The table's units are the ranges' units, and every key but the two with a rule of their
    /// own has a range of plausibility (so a new key cannot go unchecked).
    #[test]
    fn every_key_has_its_range_in_the_units_of_the_table() {
        for k in RobotKey::ALL {
            match k.plausible() {
                Some(p) => assert_eq!(p.unit, k.unit(), "{k}"),
                None => assert!(matches!(k, RobotKey::StanceLegs | RobotKey::HipHeightM), "{k} has no range"),
            }
        }
        assert_eq!(RobotKey::MassKg.valid_range(), "from 0.001 to 250 kg");
        assert_eq!(RobotKey::StanceLegs.valid_range(), "a whole number from 1 to 128");
    }
}
