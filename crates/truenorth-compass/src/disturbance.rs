//! Transient magnetic disturbances: a field added for a time window, such as a passing lorry,
//! a bridge or a tram line. They are what a compass calibrator must not mistake for a change
//! of the vehicle's own magnetisation.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use truenorth_core::{Error, Result, check_finite, check_finite3};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Most disturbances one model holds (a fixed array keeps the model allocation-free): enough
/// for a simulated hour on the road.
pub const MAX_DISTURBANCES: usize = 32;

/// How a disturbance rises and falls within its window.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum DisturbanceShape {
    /// Full strength for the whole window (a parked object, a bridge deck).
    Step,
    /// Rises and falls smoothly, `½(1 − cos 2πτ)` over the window, full strength at its middle
    /// (an object that approaches and passes).
    #[default]
    RaisedCosine,
}

/// A field added to the earth's for `duration_s` seconds from `start_s`.
///
/// The field is given in the local-level NED frame (fixed in the world, like the bridge that
/// makes it); the sensor sees it rotated into body axes and distorted by the vehicle's soft
/// iron, exactly as it sees the earth's field.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Disturbance {
    /// Start of the window, seconds of model time.
    pub start_s: f64,
    /// Length of the window, seconds (> 0).
    pub duration_s: f64,
    /// Peak added field, NED, same unit as the earth field.
    pub field_ned: Vector3<f64>,
    /// How it rises and falls.
    pub shape: DisturbanceShape,
}

impl Disturbance {
    /// Checks that the window and field are finite and the duration positive.
    pub fn validate(&self) -> Result<()> {
        check_finite("disturbance start_s", self.start_s)?;
        check_finite("disturbance duration_s", self.duration_s)?;
        check_finite3("disturbance field_ned", &self.field_ned)?;
        if self.duration_s <= 0.0 {
            return Err(Error::OutOfRange {
                what: "disturbance duration_s",
                value: self.duration_s,
                min: f64::MIN_POSITIVE,
                max: f64::INFINITY,
            });
        }
        Ok(())
    }

    /// The added field at model time `t_s` (zero outside the window).
    pub fn field_at(&self, t_s: f64) -> Vector3<f64> {
        let tau = (t_s - self.start_s) / self.duration_s;
        if !(0.0..=1.0).contains(&tau) {
            return Vector3::zeros();
        }
        let gain = match self.shape {
            DisturbanceShape::Step => 1.0,
            DisturbanceShape::RaisedCosine => 0.5 * (1.0 - (core::f64::consts::TAU * tau).cos()),
        };
        self.field_ned * gain
    }
}

/// Up to [`MAX_DISTURBANCES`] disturbances, summed.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Disturbances {
    items: [Option<Disturbance>; MAX_DISTURBANCES],
}

impl Disturbances {
    /// No disturbances.
    pub const fn new() -> Self {
        Self {
            items: [None; MAX_DISTURBANCES],
        }
    }

    /// Adds one; refuses an invalid one or a fifth one with a typed error.
    pub fn add(&mut self, d: Disturbance) -> Result<()> {
        d.validate()?;
        match self.items.iter_mut().find(|s| s.is_none()) {
            Some(slot) => {
                *slot = Some(d);
                Ok(())
            }
            None => Err(Error::OutOfRange {
                what: "number of disturbances",
                value: (MAX_DISTURBANCES + 1) as f64,
                min: 0.0,
                max: MAX_DISTURBANCES as f64,
            }),
        }
    }

    /// Removes all.
    pub fn clear(&mut self) {
        self.items = [None; MAX_DISTURBANCES];
    }

    /// The disturbances held.
    pub fn iter(&self) -> impl Iterator<Item = &Disturbance> {
        self.items.iter().flatten()
    }

    /// Their summed field (NED) at model time `t_s`.
    pub fn field_at(&self, t_s: f64) -> Vector3<f64> {
        self.iter().map(|d| d.field_at(t_s)).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bump(shape: DisturbanceShape) -> Disturbance {
        Disturbance {
            start_s: 10.0,
            duration_s: 4.0,
            field_ned: Vector3::new(1.0, 2.0, 3.0),
            shape,
        }
    }

    #[test]
    fn zero_outside_the_window_full_inside() {
        let d = bump(DisturbanceShape::Step);
        assert_eq!(d.field_at(9.99), Vector3::zeros());
        assert_eq!(d.field_at(14.01), Vector3::zeros());
        assert_eq!(d.field_at(12.0), d.field_ned);
        let r = bump(DisturbanceShape::RaisedCosine);
        assert!((r.field_at(12.0) - r.field_ned).norm() < 1e-12);
        assert!(r.field_at(10.0).norm() < 1e-12);
    }

    #[test]
    fn capacity_and_validation_are_typed_errors() {
        let mut s = Disturbances::new();
        for _ in 0..MAX_DISTURBANCES {
            s.add(bump(DisturbanceShape::Step)).unwrap();
        }
        assert!(matches!(
            s.add(bump(DisturbanceShape::Step)),
            Err(Error::OutOfRange { .. })
        ));
        let mut bad = bump(DisturbanceShape::Step);
        bad.duration_s = 0.0;
        assert!(Disturbances::new().add(bad).is_err());
        bad.duration_s = f64::NAN;
        assert!(Disturbances::new().add(bad).is_err());
        // Every one of the full set counts.
        let want: Vector3<f64> = Vector3::new(1.0, 2.0, 3.0) * MAX_DISTURBANCES as f64;
        assert!((s.field_at(12.0) - want).norm() < 1e-12);
    }
}
