//! Online least-squares ellipsoid calibration of a three-axis magnetometer, in bounded
//! memory: the direct ellipsoid fit of [`crate::EllipsoidCalibrator`] (Li & Griffiths 2004)
//! solved from the 35 running monomial sums of degree ≤ 4 (see the `conic_sums` module),
//! optionally forgetting old readings.
//!
//! It works as the two-axis [`crate::OnlineEllipseCalibrator`] does (see that module for
//! the approximations the sums imply): O(1) per push, and a refresh every
//! [`OnlineEllipsoidConfig::refresh_interval_samples`] readings (or a 64th of the readings
//! the sums weigh, if that is more) split into short stages, one
//! per push — here more of them, since the 3-D algebra is larger (the heading-error bound
//! alone visits 256 directions, 32 per stage). Coverage is the share of the equal-area
//! direction cells of [`crate::quality`] holding a retained reading, at most one per cell.

use nalgebra::Vector3;
use truenorth_compass::{CompassCalibration3d, CompassCalibration3dIn};
use truenorth_core::{
    Calibrator, CompassQuality, Mag3Sample, OnlineCalibrator, Persistent, Progress, Pushed, Real,
    Result, Solution,
};

use crate::online::conic::{OnlineConicState, OnlineCore};
use crate::online::conic_sums::MONOMIALS_3D;
use crate::online::ellipsoid::config::OnlineEllipsoidConfig;
use crate::online::ellipsoid::refresh::Refresh;
use crate::quality::SPHERE_CELLS;

/// Online least-squares ellipsoid calibrator: the direct fit of
/// [`crate::EllipsoidCalibrator`] from running sums, O(1) memory and O(1) per push.
///
/// As the two-axis [`crate::OnlineEllipseCalibrator`], its sums and retained readings are
/// in the float type `T` (`f64` by default, [`OnlineEllipsoidCalibrator::with_precision`]
/// for `f32`), and its fit runs in `f64` (the same reasons, sharper: 35 moments of degree
/// 4 in 3-D), returning the calibration in `T`.
///
/// ```
/// use nalgebra::Vector3;
/// use truenorth_calib::{OnlineEllipsoidCalibrator, OnlineEllipsoidConfig};
/// use truenorth_core::{Calibrator, Mag3Sample};
///
/// let mut cal = OnlineEllipsoidCalibrator::new(OnlineEllipsoidConfig::default())?;
/// let golden = std::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
/// for k in 0..500 {
///     // Directions spread over the sphere, a 50-unit field, a (5, −2, 8) hard iron.
///     let z = 1.0 - (2.0 * k as f64 + 1.0) / 500.0;
///     let r = (1.0 - z * z).sqrt();
///     let (s, c) = (golden * k as f64).sin_cos();
///     let mag = Vector3::new(5.0, -2.0, 8.0) + 50.0 * Vector3::new(r * c, r * s, z);
///     cal.push(&Mag3Sample { t_s: k as f64, mag })?;
/// }
/// let sol = cal.solve()?;
/// assert!((sol.params.hard_iron - Vector3::new(5.0, -2.0, 8.0)).norm() < 1e-6);
/// assert!((sol.quality.field_magnitude - 50.0).abs() < 1e-6);
/// # Ok::<(), truenorth_core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct OnlineEllipsoidCalibrator<T: Real = f64> {
    core: OnlineCore<T, 3, MONOMIALS_3D, SPHERE_CELLS, Refresh>,
}

impl OnlineEllipsoidCalibrator {
    /// A calibrator with the given configuration, or the first invalid parameter, named.
    pub fn new(config: OnlineEllipsoidConfig) -> Result<Self> {
        Self::with_precision(config)
    }
}

impl<T: Real> OnlineEllipsoidCalibrator<T> {
    /// As [`OnlineEllipsoidCalibrator::new`], its sums and retained readings in `T`:
    /// `OnlineEllipsoidCalibrator::<f32>::with_precision(config)` for a single-precision
    /// FPU. The configuration is the same `f64` one for every `T`.
    pub fn with_precision(config: OnlineEllipsoidConfig) -> Result<Self> {
        OnlineCore::new(config).map(|core| Self { core })
    }

    /// Adds the reading `mag` (in `T`) taken at `t_s` seconds: as [`Calibrator::push`]
    /// without a conversion from `f64`. O(1), no allocation.
    #[inline]
    pub fn push_reading(&mut self, t_s: f64, mag: &Vector3<T>) -> Result<Pushed> {
        self.core.push(t_s, mag)
    }

    /// The stage a refresh in progress will run at the next push, if one is in progress
    /// (for profiling the per-push cost).
    pub fn refresh_stage(&self) -> Option<u8> {
        self.core.refresh_stage()
    }

    /// The configuration in use.
    pub fn config(&self) -> &OnlineEllipsoidConfig {
        &self.core.config
    }
}

/// A solution of the `f64` fit with its calibration in `T` (exact for `f64`).
fn narrowed<T: Real>(sol: Solution<CompassCalibration3d>) -> Solution<CompassCalibration3dIn<T>> {
    Solution {
        params: sol.params.to_precision(),
        quality: sol.quality,
    }
}

impl<T: Real> Calibrator for OnlineEllipsoidCalibrator<T> {
    type Sample = Mag3Sample;
    type Params = CompassCalibration3dIn<T>;
    type Quality = CompassQuality;

    /// Adds a reading to the sums (and, when its direction cell is free, to the retained
    /// readings), and runs one stage of a refresh when one is due. O(1), no allocation; a
    /// non-finite sample is refused and changes nothing. The reading is rounded to `T`.
    fn push(&mut self, sample: &Mag3Sample) -> Result<Pushed> {
        self.core.push(sample.t_s, &sample.mag.map(T::of))
    }

    /// Samples accepted, direction-cell coverage of the retained readings about the current
    /// calibration, and `ready` exactly when [`Calibrator::solve`] succeeds (it runs the
    /// solve: tens of microseconds, independent of the number of readings).
    fn progress(&self) -> Progress {
        self.core.progress()
    }

    fn solve(&self) -> Result<Solution<CompassCalibration3dIn<T>>> {
        self.core.solve().map(narrowed)
    }

    fn reset(&mut self) {
        self.core.reset();
    }
}

impl<T: Real> OnlineCalibrator for OnlineEllipsoidCalibrator<T> {
    /// The latest refresh's successful solution (a refused refresh keeps the previous one).
    fn estimate(&self) -> Option<Solution<CompassCalibration3dIn<T>>> {
        self.core.estimate().map(narrowed)
    }
}

/// The saved state of an [`OnlineEllipsoidCalibrator`].
pub type OnlineEllipsoidState = OnlineConicState<OnlineEllipsoidConfig, CompassCalibration3d>;

// For `f64` only, as the other per-sample types' persistence (a `T` to infer would make
// `OnlineEllipsoidCalibrator::restore(state)` ambiguous).
impl Persistent for OnlineEllipsoidCalibrator {
    type State = OnlineEllipsoidState;
    const SNAPSHOT_VERSION: u32 = 1;

    fn state(&self) -> OnlineEllipsoidState {
        self.core.state()
    }

    fn from_state(state: OnlineEllipsoidState) -> Result<Self> {
        OnlineCore::restore(state).map(|core| Self { core })
    }
}
