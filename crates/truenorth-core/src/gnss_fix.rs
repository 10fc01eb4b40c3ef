//! A satellite fix as a receiver reports it: where, how well, and (if it says) how fast and
//! which way over the ground.

use serde::{Deserialize, Serialize};

use crate::{Result, Validate, check_finite, check_range};

/// One GNSS fix: WGS84 latitude and longitude, and what the receiver says with it.
///
/// ```
/// use truenorth_core::{GnssFix, Validate};
///
/// let fix = GnssFix::at(52.5163, 13.3777).with_sigma(2.5).with_velocity(13.9, 92.0);
/// assert!(fix.validate().is_ok());
/// assert!(GnssFix::at(91.0, 0.0).validate().is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GnssFix {
    /// Latitude, degrees north (WGS84).
    pub lat_deg: f64,
    /// Longitude, degrees east (WGS84).
    pub lon_deg: f64,
    /// The receiver's 1σ horizontal accuracy, m, if it reports one.
    #[serde(default)]
    pub sigma_m: Option<f64>,
    /// Speed over ground, m/s, if it reports one.
    #[serde(default)]
    pub speed_mps: Option<f64>,
    /// Course over ground, degrees clockwise from true north, if it reports one.
    #[serde(default)]
    pub course_deg: Option<f64>,
}

/// Largest horizontal accuracy a fix may claim, m: a receiver that is 100 km unsure has no
/// fix.
pub const MAX_GNSS_SIGMA_M: f64 = 1e5;

/// Largest speed over ground a vehicle fix may carry, m/s (Mach 1 at sea level).
pub const MAX_GNSS_SPEED_MPS: f64 = 343.0;

impl GnssFix {
    /// A fix at `lat_deg`, `lon_deg` with nothing else reported.
    pub const fn at(lat_deg: f64, lon_deg: f64) -> Self {
        Self {
            lat_deg,
            lon_deg,
            sigma_m: None,
            speed_mps: None,
            course_deg: None,
        }
    }

    /// The fix with the receiver's 1σ horizontal accuracy, m.
    pub const fn with_sigma(mut self, sigma_m: f64) -> Self {
        self.sigma_m = Some(sigma_m);
        self
    }

    /// The fix with speed over ground (m/s) and course over ground (degrees clockwise from
    /// true north).
    pub const fn with_velocity(mut self, speed_mps: f64, course_deg: f64) -> Self {
        self.speed_mps = Some(speed_mps);
        self.course_deg = Some(course_deg);
        self
    }
}

impl Validate for GnssFix {
    /// Checks latitude within ±90°, longitude within ±360°, an accuracy that is positive and
    /// at most [`MAX_GNSS_SIGMA_M`], a speed within 0..[`MAX_GNSS_SPEED_MPS`] and a finite
    /// course.
    fn validate(&self) -> Result<()> {
        check_range("lat_deg", self.lat_deg, -90.0, 90.0)?;
        check_range("lon_deg", self.lon_deg, -360.0, 360.0)?;
        if let Some(s) = self.sigma_m {
            check_range("gnss_sigma_m", s, f64::MIN_POSITIVE, MAX_GNSS_SIGMA_M)?;
        }
        if let Some(v) = self.speed_mps {
            check_range("gnss_speed_mps", v, 0.0, MAX_GNSS_SPEED_MPS)?;
        }
        if let Some(c) = self.course_deg {
            check_finite("gnss_course_deg", c)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn validation_never_panics_and_refuses_non_finite(
            lat in any::<f64>(), lon in any::<f64>(), sigma in any::<f64>(),
            speed in any::<f64>(), course in any::<f64>(),
        ) {
            let fix = GnssFix::at(lat, lon).with_sigma(sigma).with_velocity(speed, course);
            let ok = fix.validate().is_ok();
            if ok {
                prop_assert!(lat.abs() <= 90.0 && lon.abs() <= 360.0);
                prop_assert!(sigma > 0.0 && sigma <= MAX_GNSS_SIGMA_M);
                prop_assert!((0.0..=MAX_GNSS_SPEED_MPS).contains(&speed) && course.is_finite());
            }
            if ![lat, lon, sigma, speed, course].iter().all(|v| v.is_finite()) {
                prop_assert!(!ok);
            }
        }
    }
}
