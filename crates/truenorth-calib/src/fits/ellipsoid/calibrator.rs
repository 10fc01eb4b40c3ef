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
use crate::fits::ellipsoid::fit::bbox_centre;
use crate::fits::ellipsoid::fit::fit_ellipsoid;
/// Least-squares ellipsoid calibrator (batch): stores every reading pushed and fits them
/// all with [`fit_ellipsoid`] on `solve`.
///
/// [`Calibrator::progress`] runs the whole fit to decide `ready` (so that it agrees with
/// `solve` exactly): it costs as much as `solve`, O(n). Call it now and then, not per sample.
#[derive(Debug, Clone, Default)]
pub struct EllipsoidCalibrator {
    points: Vec<Vector3<f64>>,
    config: EllipsoidConfig,
}

impl EllipsoidCalibrator {
    /// A calibrator with the given configuration (validated).
    pub fn new(config: EllipsoidConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self {
            points: Vec::new(),
            config,
        })
    }

    /// The readings stored so far.
    pub fn points(&self) -> &[Vector3<f64>] {
        &self.points
    }

    /// The configuration in use.
    pub fn config(&self) -> &EllipsoidConfig {
        &self.config
    }
}

impl Calibrator for EllipsoidCalibrator {
    type Sample = Mag3Sample;
    type Params = CompassCalibration3d;
    type Quality = CompassQuality;

    fn push(&mut self, sample: &Mag3Sample) -> Result<Pushed> {
        check_finite("timestamp t_s", sample.t_s)?;
        check_finite3("magnetometer reading", &sample.mag)?;
        self.points.push(sample.mag);
        Ok(Pushed::Accepted)
    }

    /// `ready` runs the fit (see the type's documentation); `coverage` is the information
    /// share of an evenly covered sphere ([`quality::CompassUncertainty::efficiency`]) of the
    /// directions seen from the centre of the readings' bounding box (an estimate before
    /// the fit).
    fn progress(&self) -> Progress {
        let centre = bbox_centre(&self.points);
        let raw = CompassCalibration3d {
            hard_iron: centre,
            soft_iron: Matrix3::identity(),
        };
        let field = quality::mean_corrected_norm_3d(&self.points, &raw);
        let coverage = quality::assess_3d(&self.points, &raw, field)
            .uncertainty
            .efficiency(3);
        Progress {
            samples: self.points.len(),
            coverage,
            ready: self.solve().is_ok(),
        }
    }

    fn solve(&self) -> Result<Solution<CompassCalibration3d>> {
        fit_ellipsoid(&self.points, &self.config)
    }

    fn reset(&mut self) {
        self.points.clear();
    }
}
