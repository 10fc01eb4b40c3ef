//! # truenorth-calib
//!
//! Calibrators: they learn sensor parameters from data and say how far to trust them.
//! Every calibrator implements [`truenorth_core::Calibrator`]: `push` samples, watch
//! `progress` (whose `ready` says exactly whether `solve` would succeed), `solve` for
//! parameters plus a [`truenorth_core::CompassQuality`] report, or get a typed refusal that
//! says why the data cannot support a calibration. `solve` never changes what a calibrator
//! has learned. Every calibrator is built from a validated, serde `*Config` with
//! `new(config)`.
//!
//! The least-squares calibrators fit everything they were given in one go:
//! [`EllipseCalibrator`] (two-axis compass: hard iron and symmetric soft iron from a direct
//! ellipse fit refined on the Sampson distance) and [`EllipsoidCalibrator`] (three-axis
//! magnetometer: hard iron and full symmetric soft iron from a direct ellipsoid fit refined
//! by Levenberg–Marquardt), and [`MagAccelCalibrator`] (a magnetometer and an
//! accelerometer together: both ellipsoids, the rotation between the sensors from the
//! constant dip, and the pointing axis from runs of shots aimed at one target). The
//! [`quality`] module holds the report every calibrator shares: what the readings determine
//! (not how much of the sphere they fill), the predicted uncertainty and a verdict.
//! Their passes over the readings cut them into segments of 65,536, folded on every core
//! (with `std`) and merged in order: the result is the same, to the bit, on any number of
//! threads, and for readings kept anywhere ([`Readings`]: in memory, or a store that
//! replays ranges of them, as the CLI's spill to disk does).
//!
//! The seed calibrators learn online, sample by sample, without allocating:
//! [`MeritCircleCalibrator`] (US 5,297,063: circumcentres of reading triples, merged by a
//! figure of merit; hard iron only), [`BinnedEllipseCalibrator`] (EP 0634001: heading bins,
//! origin iteration and the counter-rotating phasor ellipse; hard and soft iron, with
//! restart) and [`TurnCompassCalibrator`] (EP 0640207: centre and radii from the extrema of a
//! full turn, found by the [`extrema`] tracker that the gyro half reuses). The merit circle
//! and the binned ellipse keep a running estimate
//! ([`truenorth_core::OnlineCalibrator::estimate`]); all three save and restore their state
//! ([`truenorth_core::Persistent`]).
//!
//! Two calibrators learn a vehicle's other sensors against the compass:
//! [`TurnCalibrator`] (EP 0640207, both halves: the gyro's zero from a standstill and its
//! conversion constant from compass extrema half a turn apart, with the compass's centre and
//! radii from the same turn) and [`SpeedCoefficientCalibrator`] (US 4,788,645 eqs. 9-13: the
//! coefficient `a` of the wheels' speed correction, refined turn by turn against the
//! compass with the patent's gating, clamp and filter constant).
//!
//! ```
//! use nalgebra::{Matrix2, Vector2};
//! use truenorth_calib::{EllipseCalibrator, EllipseConfig};
//! use truenorth_core::{Calibrator, Error, Mag2Sample};
//!
//! // A level compass in a 20 µT horizontal field, turned once round. Its readings are
//! // shifted by a (12, −7) µT hard iron and squashed 25 % along a diagonal (soft iron).
//! let (s, c) = 45f64.to_radians().sin_cos();
//! let axis = Matrix2::new(c, -s, s, c);
//! let soft = axis * Matrix2::new(1.25, 0.0, 0.0, 1.0) * axis.transpose();
//! let raw = |psi: f64| Vector2::new(12.0, -7.0) + soft * Vector2::new(20.0 * psi.cos(), -20.0 * psi.sin());
//!
//! let mut cal = EllipseCalibrator::new(EllipseConfig::default())?;
//! for k in 0..90 {
//!     let psi = (4.0 * k as f64).to_radians();
//!     cal.push(&Mag2Sample { t_s: 0.1 * k as f64, mag: raw(psi) })?;
//! }
//! let solution = cal.solve()?;
//! assert!((solution.params.hard_iron - Vector2::new(12.0, -7.0)).norm() < 1e-6);
//! // Heading 120° (clockwise from magnetic north) comes out as 120°.
//! let heading = solution.params.heading_rad(&raw(120f64.to_radians()));
//! assert!((heading.to_degrees() - 120.0).abs() < 1e-6);
//! // The report says how far to trust it.
//! assert_eq!(solution.quality.fit.coverage, 1.0);
//! assert!(solution.quality.heading_error_bound_deg() < 0.1);
//!
//! // Half a turn is not enough, and the refusal says so; `progress` agrees.
//! let mut half = EllipseCalibrator::new(EllipseConfig::default())?;
//! for k in 0..45 {
//!     half.push(&Mag2Sample { t_s: k as f64, mag: raw((4.0 * k as f64).to_radians()) })?;
//! }
//! assert!(matches!(half.solve(), Err(Error::InsufficientCoverage { .. })));
//! assert!(!half.progress().ready);
//! # Ok::<(), truenorth_core::Error>(())
//! ```
#![cfg_attr(not(feature = "std"), no_std)]

extern crate alloc;

pub mod quality;

mod fits;
mod numerics;
mod online;
mod seed;

pub use seed::extrema;

pub use fits::ellipse::{
    Ellipse, EllipseCalibrator, EllipseConfig, MIN_POINTS_2D, fit_ellipse, fit_ellipse_direct,
    fit_ellipse_readings,
};
pub use fits::ellipsoid::{
    Ellipsoid, EllipsoidCalibrator, EllipsoidConfig, MIN_POINTS_3D, fit_ellipsoid,
    fit_ellipsoid_direct, fit_ellipsoid_readings,
};
pub use fits::mag_accel::{
    INITIAL_FIT_BOUND_DEG, MIN_MAG_ACCEL_READINGS, MagAccelCalibration, MagAccelCalibrator,
    MagAccelConfig, MagAccelQuality, MagAccelReading, MagAccelSample, MagAccelStore, fit_mag_accel,
    fit_mag_accel_readings, mag_accel_reading,
};
pub use numerics::circumcentre::{Circumcircle, circumcircle};
pub use numerics::readings::{READINGS_RUN_MULTIPLE, ReadingStore, Readings};
pub use online::conic_sums::{RetainedSnapshot, SumsSnapshot};
pub use online::ellipse::{
    ONLINE_SLOTS_2D, OnlineConicState, OnlineEllipseCalibrator, OnlineEllipseConfig,
    OnlineEllipseState, PendingRefresh,
};
pub use online::ellipsoid::{
    OnlineEllipsoidCalibrator, OnlineEllipsoidConfig, OnlineEllipsoidState,
};
pub use seed::binned::{BinState, MAX_BINS, ellipse_parameters};
pub use seed::binned::{
    BinnedEllipseCalibrator, BinnedEllipseConfig, MAX_INIT_SAMPLES, MAX_UPDATE_PUSHES, UpdatePhase,
};
pub use seed::binned::{BinnedEllipseCalibratorState, BinnedUpdateState};
pub use seed::merit_circle::{
    MERIT_CIRCLE_MIN_ARC_DEG, MeritCircleCalibrator, MeritCircleCalibratorState, MeritCircleConfig,
    MeritCircleState, RING,
};
pub use seed::speed_coefficient::{
    SpeedCoefficientCalibrator, SpeedCoefficientConfig, SpeedCoefficientState, SpeedStep,
};
pub use seed::turn::{
    DEFAULT_MAX_GAP_S, MIN_TURN_SAMPLES, TurnCompassCalibrator, TurnCompassCalibratorState,
    TurnConfig, TurnEllipse, TurnExtrema, TurnExtremaState, TurnTag,
};
pub use seed::turn_gyro::{
    MIN_REST_S, RawHeading, TurnCalibration, TurnCalibrator, TurnCalibratorState, TurnQuality,
    TurnSample,
};

/// The code blocks of the crate's README, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
