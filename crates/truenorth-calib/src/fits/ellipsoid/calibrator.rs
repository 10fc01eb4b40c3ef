//! The batch least-squares ellipsoid calibrator: every reading kept, fitted with
//! [`fit_ellipsoid`] on `solve`.

extern crate alloc;

use alloc::vec::Vec;

use nalgebra::{Matrix3, Vector3};
use truenorth_compass::CompassCalibration3d;
use truenorth_core::{
    Calibrator, CompassQuality, Mag3Sample, Progress, Pushed, Result, Solution, Validate,
    check_finite, check_finite3,
};

use crate::quality::{self};

use crate::fits::ellipsoid::config::EllipsoidConfig;
#[cfg(doc)]
use crate::fits::ellipsoid::fit::fit_ellipsoid;
use crate::fits::ellipsoid::fit::fit_ellipsoid_readings;
use crate::numerics::reading::read_by_coordinate3;
use crate::numerics::readings::{ReadingStore, Readings, bbox_centre, replay_points};
/// Least-squares ellipsoid calibrator (batch): stores every reading pushed and fits them
/// all with [`fit_ellipsoid`] on `solve`.
///
/// The readings go to a [`ReadingStore`]: a `Vec` by default ([`Self::new`]), or one of the
/// caller's own ([`Self::with_store`]), e.g. one that keeps most of a long recording on
/// disk; the fit is the same, bit for bit, whichever store holds them.
///
/// [`Calibrator::progress`] runs the whole fit to decide `ready` (so that it agrees with
/// `solve` exactly): it costs as much as `solve`, O(n). Call it now and then, not per sample.
#[derive(Debug, Clone)]
pub struct EllipsoidCalibrator<S = Vec<Vector3<f64>>> {
    points: S,
    config: EllipsoidConfig,
}

/// The default configuration, readings in memory.
impl Default for EllipsoidCalibrator {
    fn default() -> Self {
        Self {
            points: Vec::new(),
            config: EllipsoidConfig::default(),
        }
    }
}

impl EllipsoidCalibrator {
    /// A calibrator with the given configuration (validated), keeping the readings in
    /// memory.
    pub fn new(config: EllipsoidConfig) -> Result<Self> {
        Self::with_store(config, Vec::new())
    }

    /// The readings stored so far.
    pub fn points(&self) -> &[Vector3<f64>] {
        &self.points
    }
}

impl<S: ReadingStore<3>> EllipsoidCalibrator<S> {
    /// A calibrator with the given configuration (validated) that keeps its readings in
    /// `store` (emptied first).
    pub fn with_store(config: EllipsoidConfig, mut store: S) -> Result<Self> {
        config.validate()?;
        store.clear();
        Ok(Self {
            points: store,
            config,
        })
    }

    /// The store holding the readings.
    pub fn store(&self) -> &S {
        &self.points
    }

    /// The configuration in use.
    pub fn config(&self) -> &EllipsoidConfig {
        &self.config
    }
}

impl<S: ReadingStore<3>> Calibrator for EllipsoidCalibrator<S> {
    type Sample = Mag3Sample;
    type Params = CompassCalibration3d;
    type Quality = CompassQuality;

    fn push(&mut self, sample: &Mag3Sample) -> Result<Pushed> {
        check_finite("timestamp t_s", sample.t_s)?;
        let mag = read_by_coordinate3(&sample.mag);
        check_finite3("magnetometer reading", &mag)?;
        self.points.push(mag)?;
        Ok(Pushed::Accepted)
    }

    /// `ready` runs the fit (see the type's documentation); `coverage` is the information
    /// share of an evenly covered sphere ([`quality::CompassUncertainty::efficiency`]) of the
    /// directions seen from the centre of the readings' bounding box (an estimate before
    /// the fit). A store that cannot replay its readings reports no coverage and not ready.
    fn progress(&self) -> Progress {
        let coverage = raw_coverage(&self.points).unwrap_or(0.0);
        Progress {
            samples: self.points.len(),
            coverage,
            ready: self.solve().is_ok(),
        }
    }

    fn solve(&self) -> Result<Solution<CompassCalibration3d>> {
        fit_ellipsoid_readings(&self.points, &self.config)
    }

    fn reset(&mut self) {
        self.points.clear();
    }
}

/// The coverage of [`EllipsoidCalibrator::progress`]: the information share of the directions
/// seen from the bounding-box centre, without a soft iron, judged at the mean distance from
/// it (as `quality::mean_corrected_norm_3d` gives it for readings in one slice).
pub(crate) fn raw_coverage<R: Readings<3> + ?Sized>(points: &R) -> Result<f64> {
    let centre = bbox_centre(points)?;
    let raw = CompassCalibration3d {
        hard_iron: centre,
        soft_iron: Matrix3::identity(),
    };
    let (mut sum, mut n) = (0.0, 0usize);
    replay_points(points, |p| {
        let r = raw.correct(p).norm();
        if r.is_finite() {
            sum += r;
            n += 1;
        }
    })?;
    let field = if n > 0 { sum / n as f64 } else { 0.0 };
    Ok(quality::assess_3d_of(points, &raw, field)?
        .uncertainty
        .efficiency(3))
}
