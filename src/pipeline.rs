//! Pipelines: sensors → calibrators → estimator, wired in a few lines.
//!
//! Each pipeline owns the pieces it wires and exposes one `update` per sample:
//!
//! - [`CompassPipeline`]: raw two-axis magnetometer readings → any online compass
//!   calibrator (it calibrates while it runs) → magnetic and, given a [`Place`], true heading.
//! - [`NavPipeline`]: any vehicle [`HeadingEstimator`] → its estimate plus, given a
//!   [`Place`], true heading and the track rotated onto true north.
//! - [`OrientationPipeline`]: any [`OrientationEstimator`] → its estimate plus, given a
//!   [`Place`], the attitude referred to true instead of magnetic north.
//!
//! Swapping the method inside is the one line that builds it; the pipeline does not change.

use nalgebra::{Rotation2, UnitQuaternion, Vector3};
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{
    AbsoluteHeadingSource, AttitudeEstimate, CompassQuality, Declination, HeadingEstimator,
    ImuSample, Mag2Sample, MagneticHeading, NavEstimate, OnlineCalibrator, OrientationEstimator,
    Result, TrueHeading, VehicleSample, deg_to_rad,
};

/// Where and when the pipeline runs, for the World Magnetic Model's declination.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Place {
    /// Geodetic latitude (WGS84), degrees north.
    pub lat_deg: f64,
    /// Longitude, degrees east.
    pub lon_deg: f64,
    /// Height above the WGS84 ellipsoid, metres.
    pub height_m: f64,
    /// Decimal year, 2025.0–2030.0 (WMM2025's validity).
    pub year: f64,
}

impl Place {
    /// WMM2025 declination here; a place or date the model does not cover is a typed error.
    pub fn declination(&self) -> Result<Declination> {
        truenorth_geomag::declination(
            deg_to_rad(self.lat_deg),
            deg_to_rad(self.lon_deg),
            self.height_m,
            self.year,
        )
    }
}

/// One calibrated compass reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompassReading {
    /// Heading from magnetic north.
    pub magnetic: MagneticHeading,
    /// Heading from true north, when the pipeline was given a [`Place`].
    pub true_heading: Option<TrueHeading>,
    /// Magnitude of the calibrated horizontal field (input unit): compare it with
    /// `quality.field_magnitude` to spot a disturbance.
    pub field_norm: f64,
    /// Quality of the calibration the reading was taken with.
    pub quality: CompassQuality,
}

/// A self-calibrating two-axis compass: every raw reading goes to the calibrator, and once
/// the calibrator has an estimate, each reading comes back as a heading.
///
/// ```
/// use nalgebra::Vector2;
/// use truenorth::calib::{BinnedEllipseCalibrator, BinnedEllipseConfig};
/// use truenorth::core::Mag2Sample;
/// use truenorth::pipeline::{CompassPipeline, Place};
///
/// let calibrator = BinnedEllipseCalibrator::new(BinnedEllipseConfig::default())?;
/// let place = Place { lat_deg: 52.0, lon_deg: 4.4, height_m: 0.0, year: 2026.9 };
/// let mut compass = CompassPipeline::new(calibrator).with_true_north(&place)?;
///
/// // Three turns of a level compass with a hard iron of (8, −3) in a 20-unit field.
/// let mut last = None;
/// for k in 0..1080 {
///     let psi = (k as f64).to_radians();
///     let mag = Vector2::new(8.0 + 20.0 * psi.cos(), -3.0 - 20.0 * psi.sin());
///     last = compass.update(&Mag2Sample { t_s: 0.1 * k as f64, mag })?.or(last);
/// }
/// let reading = last.expect("calibrated after three turns");
/// assert!(reading.true_heading.is_some());
/// # Ok::<(), truenorth::core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct CompassPipeline<C> {
    calibrator: C,
    declination: Option<Declination>,
}

impl<C> CompassPipeline<C>
where
    C: OnlineCalibrator<
            Sample = Mag2Sample,
            Params = CompassCalibration2d,
            Quality = CompassQuality,
        >,
{
    /// A pipeline around `calibrator`, giving magnetic heading.
    pub fn new(calibrator: C) -> Self {
        Self {
            calibrator,
            declination: None,
        }
    }

    /// Also gives true heading, with the WMM2025 declination at `place`.
    pub fn with_true_north(mut self, place: &Place) -> Result<Self> {
        self.declination = Some(place.declination()?);
        Ok(self)
    }

    /// Feeds one raw reading to the calibrator and returns its heading under the current
    /// estimate, or `None` while the calibrator has none yet.
    pub fn update(&mut self, sample: &Mag2Sample) -> Result<Option<CompassReading>> {
        self.calibrator.push(sample)?;
        let Some(solution) = self.calibrator.estimate() else {
            return Ok(None);
        };
        let h = solution.params.heading(sample, None)?;
        Ok(Some(CompassReading {
            magnetic: h.heading,
            true_heading: self.declination.map(|d| h.heading.to_true(d)),
            field_norm: h.field_norm,
            quality: solution.quality,
        }))
    }

    /// The calibrator, to read its progress or save its state.
    pub fn calibrator(&self) -> &C {
        &self.calibrator
    }
}

/// A vehicle estimate with its true-north form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavReading {
    /// The estimator's own output (magnetic north).
    pub estimate: NavEstimate,
    /// Heading from true north, when the pipeline was given a [`Place`].
    pub true_heading: Option<TrueHeading>,
    /// (north, east) from the start, metres, on true north: the estimator integrates along
    /// magnetic heading, so its track is turned by the declination. Equal to the
    /// estimator's track without a [`Place`].
    pub true_north_east_m: (f64, f64),
}

/// A vehicle heading / dead-reckoning estimator with true north.
#[derive(Debug, Clone)]
pub struct NavPipeline<E> {
    estimator: E,
    declination: Option<Declination>,
}

impl<E: HeadingEstimator> NavPipeline<E> {
    /// A pipeline around `estimator`, on magnetic north.
    pub fn new(estimator: E) -> Self {
        Self {
            estimator,
            declination: None,
        }
    }

    /// Also gives true heading and the track on true north at `place`.
    pub fn with_true_north(mut self, place: &Place) -> Result<Self> {
        self.declination = Some(place.declination()?);
        Ok(self)
    }

    /// Feeds one sample to the estimator.
    pub fn update(&mut self, sample: &VehicleSample) -> Result<NavReading> {
        let estimate = self.estimator.update(sample)?;
        Ok(self.reading(estimate))
    }

    /// The estimator, to read or save its state.
    pub fn estimator(&self) -> &E {
        &self.estimator
    }

    fn reading(&self, estimate: NavEstimate) -> NavReading {
        let d = self.declination.map_or(0.0, |d| d.0);
        // Magnetic north lies `d` east of true north, so a vector given in the magnetic
        // (north, east) frame turns by +d (clockwise seen from above) into the true frame.
        let v = Rotation2::new(d) * nalgebra::Vector2::new(estimate.north_m, estimate.east_m);
        NavReading {
            estimate,
            true_heading: self.declination.map(|d| estimate.heading.to_true(d)),
            true_north_east_m: (v.x, v.y),
        }
    }
}

/// An orientation estimate with its true-north form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrientationReading {
    /// The estimator's own output (reference frame NED on magnetic north).
    pub estimate: AttitudeEstimate,
    /// Body → NED on true north, when the pipeline was given a [`Place`]; otherwise the
    /// estimator's attitude.
    pub attitude_true: UnitQuaternion<f64>,
}

/// An orientation estimator with true north.
///
/// The estimator may be chosen at run time: a boxed pipeline around a concrete estimator
/// coerces to one around `dyn OrientationEstimator` (the estimator is the struct's last
/// field), so every method runs through the same code.
///
/// ```
/// use nalgebra::Vector3;
/// use truenorth::core::{ImuSample, OrientationEstimator};
/// use truenorth::fusion::{EulerDetector, QuaternionFilter};
/// use truenorth::pipeline::OrientationPipeline;
///
/// type AnyMethod = OrientationPipeline<dyn OrientationEstimator>;
/// let by_name = |name: &str| -> truenorth::core::Result<Box<AnyMethod>> {
///     Ok(match name {
///         "euler-detector" => {
///             Box::new(OrientationPipeline::new(EulerDetector::new(Default::default())?))
///         }
///         _ => Box::new(OrientationPipeline::new(QuaternionFilter::new(Default::default())?)),
///     })
/// };
/// let mut pipeline = by_name("euler-detector")?;
/// let at_rest = ImuSample::new_6d(0.0, Vector3::zeros(), Vector3::new(0.0, 0.0, -9.81));
/// let reading = pipeline.update(&at_rest)?;
/// // Level at rest: the body's z axis points down.
/// assert!((reading.attitude_true * Vector3::z()).z > 0.999);
/// # Ok::<(), truenorth::core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct OrientationPipeline<E: ?Sized> {
    to_true: UnitQuaternion<f64>,
    estimator: E,
}

impl<E: OrientationEstimator> OrientationPipeline<E> {
    /// A pipeline around `estimator`, on magnetic north.
    pub fn new(estimator: E) -> Self {
        Self {
            to_true: UnitQuaternion::identity(),
            estimator,
        }
    }

    /// Also gives the attitude on true north at `place`.
    pub fn with_true_north(mut self, place: &Place) -> Result<Self> {
        let d = place.declination()?.0;
        // Magnetic NED is true NED turned by the declination about down (z).
        self.to_true = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), d);
        Ok(self)
    }
}

impl<E: OrientationEstimator + ?Sized> OrientationPipeline<E> {
    /// Feeds one sample to the estimator.
    pub fn update(&mut self, sample: &ImuSample) -> Result<OrientationReading> {
        let estimate = self.estimator.update(sample)?;
        Ok(OrientationReading {
            estimate,
            attitude_true: self.to_true * estimate.attitude,
        })
    }

    /// The estimator, to read or save its state.
    pub fn estimator(&self) -> &E {
        &self.estimator
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use truenorth_core::{EulerZyx, angle_diff};

    /// A stand-in vehicle estimator: drives straight along a fixed magnetic heading.
    struct Straight {
        heading: f64,
        est: NavEstimate,
    }

    impl HeadingEstimator for Straight {
        fn update(&mut self, s: &VehicleSample) -> Result<NavEstimate> {
            let d = s.wheels.map_or(0.0, |w| 0.5 * (w.dist_l_m + w.dist_r_m));
            self.est = NavEstimate {
                t_s: s.t_s,
                north_m: d * self.heading.cos(),
                east_m: d * self.heading.sin(),
                distance_m: d,
                ..NavEstimate::at_start(s.t_s, MagneticHeading::new(self.heading), 0.0)
            };
            Ok(self.est)
        }
        fn estimate(&self) -> NavEstimate {
            self.est
        }
        fn reset(&mut self) {}
    }

    /// A stand-in orientation estimator: holds one attitude.
    struct Fixed(UnitQuaternion<f64>);

    impl OrientationEstimator for Fixed {
        fn update(&mut self, _: &ImuSample) -> Result<AttitudeEstimate> {
            Ok(AttitudeEstimate::initial(self.0))
        }
        fn estimate(&self) -> AttitudeEstimate {
            AttitudeEstimate::initial(self.0)
        }
        fn reset(&mut self) {}
    }

    fn place(lat_deg: f64, lon_deg: f64) -> Place {
        Place {
            lat_deg,
            lon_deg,
            height_m: 0.0,
            year: 2027.0,
        }
    }

    proptest! {
        #[test]
        fn true_track_follows_true_heading(
            heading in -3.1f64..3.1, dist in 1.0f64..1e4,
            lat in -60.0f64..60.0, lon in -180.0f64..180.0,
        ) {
            let p = place(lat, lon);
            let decl = p.declination().unwrap().0;
            let mut nav = NavPipeline::new(Straight { heading, est: NavEstimate::at_start(0.0, MagneticHeading::new(0.0), 0.0) })
                .with_true_north(&p).unwrap();
            let r = nav.update(&VehicleSample::at(1.0).with_wheels(dist, dist)).unwrap();
            let th = r.true_heading.unwrap().rad();
            prop_assert!(angle_diff(th, heading + decl).abs() < 1e-9);
            // The true-north track points along the true heading and keeps its length.
            let (n, e) = r.true_north_east_m;
            prop_assert!(angle_diff(e.atan2(n), th).abs() < 1e-9);
            prop_assert!(((n * n + e * e).sqrt() - dist).abs() < 1e-9 * dist);
        }

        #[test]
        fn true_attitude_adds_declination_to_yaw_only(
            yaw in -3.1f64..3.1, pitch in -1.4f64..1.4, roll in -3.1f64..3.1,
            lat in -60.0f64..60.0, lon in -180.0f64..180.0,
        ) {
            let p = place(lat, lon);
            let decl = p.declination().unwrap().0;
            let e = EulerZyx { yaw_rad: yaw, pitch_rad: pitch, roll_rad: roll };
            let mut o = OrientationPipeline::new(Fixed(e.to_quaternion())).with_true_north(&p).unwrap();
            let r = o.update(&ImuSample::new_6d(0.0, Vector3::zeros(), Vector3::zeros())).unwrap();
            let t = EulerZyx::from_quaternion(&r.attitude_true);
            prop_assert!(angle_diff(t.yaw_rad, yaw + decl).abs() < 1e-9);
            prop_assert!((t.pitch_rad - pitch).abs() < 1e-9);
            prop_assert!(angle_diff(t.roll_rad, roll).abs() < 1e-9);
        }
    }

    #[test]
    fn a_place_outside_the_model_is_refused() {
        let p = Place {
            year: 2040.0,
            ..place(10.0, 10.0)
        };
        assert!(
            OrientationPipeline::new(Fixed(UnitQuaternion::identity()))
                .with_true_north(&p)
                .is_err()
        );
        let nan = place(f64::NAN, 0.0);
        assert!(nan.declination().is_err());
    }
}
