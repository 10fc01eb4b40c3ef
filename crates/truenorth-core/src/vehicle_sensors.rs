//! Which sensors a vehicle log carries, and what that set can and cannot tell.
//!
//! Real vehicles come with different sets: a car's CAN bus gives one speed and a yaw rate; a
//! robot gives its two sides' distances and a MEMS gyro; a phone gives a gyro and a
//! magnetometer and no wheels. What an estimator may learn follows from the set alone, before
//! any data are judged: equal left and right speeds on every row carry no yaw, a single speed
//! carries none, and without a compass no heading is referred to north.

use serde::{Deserialize, Serialize};

use crate::VehicleSample;

/// How a log gives the vehicle's travel, ordered by what it gives: wheels give all a speed
/// does, and the yaw too.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Travel {
    /// No distance or speed at all: no position.
    #[default]
    None,
    /// One vehicle speed or distance (a CAN bus's vehicle speed): distance, no yaw.
    Speed,
    /// Left and right wheels (or sides): distance, and the yaw from their difference.
    Wheels,
}

/// The sensors a vehicle log carries, gathered row by row ([`VehicleSensors::add`]).
///
/// ```
/// use truenorth_core::{VehicleSensors, Travel, VehicleSample};
///
/// let mut set = VehicleSensors::default();
/// set.add(&VehicleSample::at(0.0).with_distance(0.0).with_gyro(0.01));
/// set.add(&VehicleSample::at(0.2).with_distance(1.2));
/// assert_eq!(set.travel, Travel::Speed);
/// assert!(set.gyro && !set.compass);
/// assert!(set.heading_source());
/// assert!(set.limits().any(|l| l.contains("north")));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct VehicleSensors {
    /// How the log gives the travel (the richest form seen on any row).
    pub travel: Travel,
    /// A yaw gyro.
    pub gyro: bool,
    /// A horizontal magnetometer.
    pub compass: bool,
    /// Satellite fixes.
    #[serde(default)]
    pub gnss: bool,
    /// Satellite fixes with their course over ground (and speed).
    #[serde(default)]
    pub gnss_course: bool,
}

impl VehicleSensors {
    /// The set of one row.
    pub fn of(sample: &VehicleSample) -> Self {
        let mut s = Self::default();
        s.add(sample);
        s
    }

    /// Adds what `sample` carries.
    pub fn add(&mut self, sample: &VehicleSample) {
        let travel = if sample.wheels.is_some() {
            Travel::Wheels
        } else if sample.dist_m.is_some() {
            Travel::Speed
        } else {
            Travel::None
        };
        self.travel = self.travel.max(travel);
        self.gyro |= sample.gyr_z_rps.is_some();
        self.compass |= sample.mag.is_some();
        self.gnss |= sample.gnss.is_some();
        self.gnss_course |= sample
            .gnss
            .is_some_and(|f| f.course_deg.is_some() && f.speed_mps.is_some());
    }

    /// Whether satellite fixes can correct the estimate: there are fixes, and odometry
    /// carries the position between them or they give their course (the heading's).
    pub fn fixes_used(&self) -> bool {
        self.gnss && (self.travel != Travel::None || self.gnss_course)
    }

    /// Whether anything gives the heading's changes: a gyro, two wheels, or a compass.
    pub fn heading_source(&self) -> bool {
        self.gyro || self.compass || self.travel == Travel::Wheels
    }

    /// Whether the set gives a position: a travel and a heading to draw it along.
    pub fn gives_position(&self) -> bool {
        self.travel != Travel::None && self.heading_source()
    }

    /// A short name for the set, as a report names it (without the satellite fixes, which
    /// [`VehicleSensors::gnss`] says).
    pub fn name(&self) -> &'static str {
        match (self.travel, self.gyro, self.compass) {
            (Travel::None, false, false) => "nothing a vehicle estimator can use",
            (Travel::None, true, false) => "gyro only",
            (Travel::None, false, true) => "compass only",
            (Travel::None, true, true) => "gyro + compass, no wheels",
            (Travel::Speed, false, false) => "speed only",
            (Travel::Speed, true, false) => "speed + yaw rate",
            (Travel::Speed, false, true) => "speed + compass",
            (Travel::Speed, true, true) => "speed + yaw rate + compass",
            (Travel::Wheels, false, false) => "wheels only",
            (Travel::Wheels, true, false) => "wheels + gyro",
            (Travel::Wheels, false, true) => "wheels + compass",
            (Travel::Wheels, true, true) => "wheels + gyro + compass",
        }
    }

    /// What this set cannot tell, one sentence each: what a run on it must say it does not
    /// know. Empty for a full set (wheels, gyro and compass).
    pub fn limits(&self) -> impl Iterator<Item = &'static str> {
        let s = *self;
        let fixes = s.fixes_used();
        let all: [(bool, &'static str); 6] = [
            (
                !s.heading_source(),
                "no heading: nothing measures the heading or its changes (a gyro, two wheels or a compass)",
            ),
            (
                s.travel == Travel::None,
                "no position: no wheel or speed gives the distance travelled",
            ),
            (
                !s.compass && !fixes && s.heading_source(),
                "no north: without a compass the heading is relative to the start",
            ),
            (
                s.gyro && s.travel != Travel::Wheels && !s.compass && !fixes,
                "no gyro gain: nothing else measures the turns, so a yaw-rate scale error is not learned and widens the heading's uncertainty with every turn",
            ),
            (
                s.gyro && s.travel != Travel::Wheels && !fixes,
                "gyro bias only at rest or against the compass: no wheels say when the vehicle drives straight",
            ),
            (
                s.travel == Travel::Speed && !s.gyro && s.compass,
                "heading changes only from the compass: no gyro or wheels bridge a disturbed field",
            ),
        ];
        all.into_iter().filter(|(on, _)| *on).map(|(_, text)| text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;
    use proptest::prelude::*;

    fn row(k: u8) -> VehicleSample {
        let mut s = VehicleSample::at(0.0);
        if k & 1 != 0 {
            s = s.with_wheels(0.0, 0.0);
        }
        if k & 2 != 0 {
            s = s.with_distance(0.0);
        }
        if k & 4 != 0 {
            s = s.with_gyro(0.0);
        }
        if k & 8 != 0 {
            s = s.with_mag(Vector2::new(1.0, 0.0));
        }
        s
    }

    proptest! {
        /// What a log carries does not depend on the order of its rows, and a row more
        /// never takes a sensor away.
        #[test]
        fn the_set_is_order_free_and_only_grows(kinds in proptest::collection::vec(0u8..16, 0..12)) {
            let mut forward = VehicleSensors::default();
            let mut before = forward;
            for &k in &kinds {
                forward.add(&row(k));
                prop_assert!(forward.travel >= before.travel);
                prop_assert!(forward.gyro >= before.gyro && forward.compass >= before.compass);
                before = forward;
            }
            let mut backward = VehicleSensors::default();
            for &k in kinds.iter().rev() {
                backward.add(&row(k));
            }
            prop_assert_eq!(forward, backward);
        }
    }

    #[test]
    fn fixes_give_north_and_the_gyro_s_errors_where_odometry_carries_them() {
        let fix = crate::GnssFix::at(52.5, 13.4);
        let s = VehicleSensors::of(
            &VehicleSample::at(0.0)
                .with_distance(0.0)
                .with_gyro(0.0)
                .with_gnss(fix),
        );
        assert!(s.fixes_used());
        assert_eq!(s.limits().count(), 0);
        let no_odometry = VehicleSensors::of(&VehicleSample::at(0.0).with_gyro(0.0).with_gnss(fix));
        assert!(!no_odometry.fixes_used());
        assert!(no_odometry.limits().any(|l| l.starts_with("no north")));
        // Without odometry a fix's course still refers the heading and the gyro's errors:
        // only the position is missing.
        let courses = VehicleSensors::of(
            &VehicleSample::at(0.0)
                .with_gyro(0.0)
                .with_gnss(fix.with_velocity(10.0, 90.0)),
        );
        assert!(courses.fixes_used());
        let limits: Vec<_> = courses.limits().collect();
        assert_eq!(limits.len(), 1, "{limits:?}");
        assert!(limits[0].starts_with("no position"));
    }

    #[test]
    fn a_full_set_has_no_limits() {
        let s = VehicleSensors::of(
            &VehicleSample::at(0.0)
                .with_wheels(0.0, 0.0)
                .with_gyro(0.0)
                .with_mag(Vector2::new(1.0, 0.0)),
        );
        assert_eq!(s.limits().count(), 0);
        assert_eq!(s.name(), "wheels + gyro + compass");
    }

    #[test]
    fn speed_alone_gives_no_heading() {
        let s = VehicleSensors::of(&VehicleSample::at(0.0).with_distance(0.0));
        assert!(!s.heading_source() && !s.gives_position());
        assert!(s.limits().any(|l| l.starts_with("no heading")));
    }

    #[test]
    fn wheels_outrank_a_speed_on_another_row() {
        let mut s = VehicleSensors::of(&VehicleSample::at(0.0).with_wheels(0.0, 0.0));
        s.add(&VehicleSample::at(0.1).with_distance(0.0));
        assert_eq!(s.travel, Travel::Wheels);
    }
}
