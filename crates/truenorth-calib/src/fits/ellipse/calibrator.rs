//! The batch least-squares ellipse calibrator: every reading kept, fitted with [`fit_ellipse`] on
//! `solve`.

extern crate alloc;

use alloc::vec::Vec;

use nalgebra::Vector2;
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{
    Calibrator, CompassQuality, Mag2Sample, Progress, Pushed, Result, Solution, Validate,
    check_finite, check_finite2,
};

use crate::quality::{self};

use crate::fits::ellipse::config::EllipseConfig;
#[cfg(doc)]
use crate::fits::ellipse::fit::fit_ellipse;
use crate::fits::ellipse::fit::fit_ellipse_readings;
use crate::numerics::reading::read_by_coordinate;
use crate::numerics::readings::{ReadingStore, bbox_centre};
/// Least-squares ellipse calibrator (batch): stores every reading pushed and fits them all
/// with [`fit_ellipse`] on `solve`.
///
/// Its memory grows with every push; for calibrating while driving use the online
/// least-squares calibrator, which keeps only the fit's sums. The readings go to a
/// [`ReadingStore`]: a `Vec` by default ([`Self::new`]), or one of the caller's own
/// ([`Self::with_store`]), e.g. one that keeps most of a long recording on disk; the fit
/// is the same, bit for bit, whichever store holds them.
///
/// [`Calibrator::progress`] runs the whole fit to decide `ready` (so that it agrees with
/// `solve` exactly): it costs as much as `solve`, O(n). Call it now and then, not per sample.
///
/// ```
/// use truenorth_calib::{EllipseCalibrator, EllipseConfig};
/// use truenorth_core::{Calibrator, Mag2Sample};
/// use nalgebra::Vector2;
///
/// let mut cal = EllipseCalibrator::new(EllipseConfig::default())?;
/// for k in 0..72 {
///     let psi = (k as f64 * 5.0).to_radians();
///     // A level compass in a 30-unit field with a (10, −4) hard iron.
///     let mag = Vector2::new(10.0 + 30.0 * psi.cos(), -4.0 - 30.0 * psi.sin());
///     cal.push(&Mag2Sample { t_s: k as f64, mag })?;
/// }
/// assert!(cal.progress().ready);
/// let sol = cal.solve()?;
/// assert!((sol.params.hard_iron - Vector2::new(10.0, -4.0)).norm() < 1e-6);
/// assert!((sol.quality.field_magnitude - 30.0).abs() < 1e-6);
/// # Ok::<(), truenorth_core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct EllipseCalibrator<S = Vec<Vector2<f64>>> {
    points: S,
    config: EllipseConfig,
}

/// The default configuration, readings in memory.
impl Default for EllipseCalibrator {
    fn default() -> Self {
        Self {
            points: Vec::new(),
            config: EllipseConfig::default(),
        }
    }
}

impl EllipseCalibrator {
    /// A calibrator with the given configuration (validated), keeping the readings in
    /// memory.
    pub fn new(config: EllipseConfig) -> Result<Self> {
        Self::with_store(config, Vec::new())
    }

    /// The readings stored so far.
    pub fn points(&self) -> &[Vector2<f64>] {
        &self.points
    }
}

impl<S: ReadingStore<2>> EllipseCalibrator<S> {
    /// A calibrator with the given configuration (validated) that keeps its readings in
    /// `store` (emptied first).
    pub fn with_store(config: EllipseConfig, mut store: S) -> Result<Self> {
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
    pub fn config(&self) -> &EllipseConfig {
        &self.config
    }
}

impl<S: ReadingStore<2>> Calibrator for EllipseCalibrator<S> {
    type Sample = Mag2Sample;
    type Params = CompassCalibration2d;
    type Quality = CompassQuality;

    fn push(&mut self, sample: &Mag2Sample) -> Result<Pushed> {
        check_finite("timestamp t_s", sample.t_s)?;
        let mag = read_by_coordinate(&sample.mag);
        check_finite2("magnetometer reading", &mag)?;
        self.points.push(mag)?;
        Ok(Pushed::Accepted)
    }

    /// `ready` runs the fit (see the type's documentation); `coverage` is seen from the
    /// centre of the readings' bounding box (the centre of any full ellipse; an estimate
    /// before the fit). A store that cannot replay its readings reports no coverage and not
    /// ready.
    fn progress(&self) -> Progress {
        let coverage = bbox_centre(&self.points)
            .and_then(|c| quality::coverage_of(&self.points, &c))
            .map_or(0.0, |cov| cov.fraction);
        Progress {
            samples: self.points.len(),
            coverage,
            ready: self.solve().is_ok(),
        }
    }

    fn solve(&self) -> Result<Solution<CompassCalibration2d>> {
        fit_ellipse_readings(&self.points, &self.config)
    }

    fn reset(&mut self) {
        self.points.clear();
    }
}
