//! Online least-squares ellipse calibration of a two-axis compass, in bounded memory: the
//! direct ellipse fit of [`crate::EllipseCalibrator`] (Fitzgibbon, Pilu & Fisher 1999 in
//! the form of Halíř & Flusser 1998) solved from running monomial sums instead of stored
//! readings (see the `conic_sums` module), optionally forgetting old readings.
//!
//! Per reading, [`OnlineEllipseCalibrator::push`] adds the 15 monomials of degree ≤ 4 to
//! the sums (one product each) and may keep the reading as its direction slot's
//! representative for coverage: O(1), no allocation. Every
//! [`OnlineEllipseConfig::refresh_interval_samples`] readings (or a 64th of the readings
//! the sums weigh, if that is more) a refresh of the estimate starts on a copy of the sums and runs one short stage per push (normalise; direct fit;
//! coverage; residual, information matrix and the condition of the headings seen;
//! heading-error bound and refusals; the `refresh` module), so that no push
//! pays for a whole solve. A refresh publishes only what [`Calibrator::solve`] would
//! accept: both run the same stages and refusals, those of the batch fit. None depends on
//! the order of the readings (the sums do not, and coverage is measured on the readings
//! retained per direction, seen through the fitted calibration).
//!
//! What the sums cannot give exactly is approximated to first order in the residuals, which
//! are small whenever a calibration is accepted:
//! * the residual of a reading is taken from the algebraic distance `|u|² − 1 ≈ 2(|u| − 1)`
//!   of its calibrated reading `u` (in field units), so `Σr² ≈ ¼ Σ(|u|² − 1)²`, a quadratic
//!   form in the scatter matrix of the design vector of `u`;
//! * the information matrix of the quality report (see [`crate::quality`]) is built on
//!   `u` itself rather than on `u/|u|`.
//!
//! There is no geometric refinement: on a full turn the direct fit has the same first-order
//! covariance as the maximum-likelihood fit and differs from it by an `O(σ²)` bias only
//! (Kanatani 2008, "Statistical optimization for geometric fitting: theoretical accuracy
//! bound and high order error analysis", IJCV 80), a small fraction of the per-reading
//! noise at any noise a compass calibration is accepted at.

use nalgebra::Vector2;
use truenorth_compass::{CompassCalibration2d, CompassCalibration2dIn};
use truenorth_core::{
    Calibrator, CompassQuality, Mag2Sample, OnlineCalibrator, Persistent, Progress, Pushed, Real,
    Result, Solution,
};

use crate::online::conic::{OnlineConicState, OnlineCore};
use crate::online::conic_sums::MONOMIALS_2D;
use crate::online::ellipse::config::OnlineEllipseConfig;
use crate::online::ellipse::refresh::{ONLINE_SLOTS_2D, Refresh};

/// Online least-squares ellipse calibrator: the direct fit of [`crate::EllipseCalibrator`]
/// from running sums, O(1) memory and O(1) per push (see the module documentation).
///
/// Its running sums and retained readings are in the float type `T` (`f64` by default;
/// [`OnlineEllipseCalibrator::with_precision`] for `f32`, the type of a single-precision
/// FPU), so a push costs a few dozen operations in `T`. A refresh and a solve convert the
/// sums to `f64` (exactly) and fit in `f64` whatever `T` is, returning the calibration in
/// `T`. Why: the fit carries the degree-4 moments, taken about the first reading, to the
/// centroid by a congruence that cancels up to `(offset/radius)⁴` of them, then separates
/// the conic from the next eigenvector of the scatter matrix (a gap 12 to 60 times below
/// its largest eigenvalue on the turns of `tests/online_precision.rs`), and its refusals
/// hold thresholds below `f32`'s resolution (a degenerate spread is one under 10⁻¹⁴);
/// in `f64` the sums' own rounding is all that `f32` costs, measured there at under 10⁻⁵
/// of the field in hard iron and 0.004° in heading. The price is that a refresh stage runs
/// in software on a single-precision FPU (see `examples/embedded`).
///
/// ```
/// use nalgebra::Vector2;
/// use truenorth_calib::{OnlineEllipseCalibrator, OnlineEllipseConfig};
/// use truenorth_core::{Calibrator, Mag2Sample, OnlineCalibrator};
///
/// let mut cal = OnlineEllipseCalibrator::new(OnlineEllipseConfig::default())?;
/// for k in 0..360 {
///     let psi = (k as f64).to_radians();
///     // A level compass in a 30-unit field with a (10, −4) hard iron.
///     let mag = Vector2::new(10.0 + 30.0 * psi.cos(), -4.0 - 30.0 * psi.sin());
///     cal.push(&Mag2Sample { t_s: k as f64, mag })?;
/// }
/// // The running estimate, O(1), and a fresh solve from the current sums agree.
/// let est = cal.estimate().expect("refreshed during the turn");
/// assert!((est.params.hard_iron - Vector2::new(10.0, -4.0)).norm() < 1e-6);
/// let sol = cal.solve()?;
/// assert!((sol.quality.field_magnitude - 30.0).abs() < 1e-6);
/// assert!(cal.progress().ready);
/// # Ok::<(), truenorth_core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct OnlineEllipseCalibrator<T: Real = f64> {
    core: OnlineCore<T, 2, MONOMIALS_2D, ONLINE_SLOTS_2D, Refresh>,
}

impl OnlineEllipseCalibrator {
    /// A calibrator with the given configuration, or the first invalid parameter, named.
    pub fn new(config: OnlineEllipseConfig) -> Result<Self> {
        Self::with_precision(config)
    }
}

impl<T: Real> OnlineEllipseCalibrator<T> {
    /// As [`OnlineEllipseCalibrator::new`], its sums and retained readings in `T`:
    /// `OnlineEllipseCalibrator::<f32>::with_precision(config)` for a single-precision FPU.
    /// The configuration is the same `f64` one for every `T`.
    ///
    /// ```
    /// use nalgebra::Vector2;
    /// use truenorth_calib::{OnlineEllipseCalibrator, OnlineEllipseConfig};
    /// use truenorth_core::Calibrator;
    ///
    /// let mut cal = OnlineEllipseCalibrator::<f32>::with_precision(OnlineEllipseConfig::default())?;
    /// for k in 0..360 {
    ///     let psi = (k as f32).to_radians();
    ///     let mag = Vector2::new(10.0 + 30.0 * psi.cos(), -4.0 - 30.0 * psi.sin());
    ///     cal.push_reading(k as f64, &mag)?;
    /// }
    /// // The calibration in f32: hard iron within f32's rounding of the field.
    /// let sol = cal.solve()?;
    /// assert!((sol.params.hard_iron - Vector2::new(10.0f32, -4.0)).norm() < 1e-3);
    /// # Ok::<(), truenorth_core::Error>(())
    /// ```
    pub fn with_precision(config: OnlineEllipseConfig) -> Result<Self> {
        OnlineCore::new(config).map(|core| Self { core })
    }

    /// Adds the reading `mag` (in `T`) taken at `t_s` seconds: as [`Calibrator::push`]
    /// without a conversion from `f64`. O(1), no allocation.
    #[inline]
    pub fn push_reading(&mut self, t_s: f64, mag: &Vector2<T>) -> Result<Pushed> {
        self.core.push(t_s, mag)
    }

    /// The stage a refresh in progress will run at the next push, if one is in progress
    /// (for profiling the per-push cost).
    pub fn refresh_stage(&self) -> Option<u8> {
        self.core.refresh_stage()
    }

    /// The configuration in use.
    pub fn config(&self) -> &OnlineEllipseConfig {
        &self.core.config
    }
}

/// A solution of the `f64` fit with its calibration in `T` (exact for `f64`).
fn narrowed<T: Real>(sol: Solution<CompassCalibration2d>) -> Solution<CompassCalibration2dIn<T>> {
    Solution {
        params: sol.params.to_precision(),
        quality: sol.quality,
    }
}

impl<T: Real> Calibrator for OnlineEllipseCalibrator<T> {
    type Sample = Mag2Sample;
    type Params = CompassCalibration2dIn<T>;
    type Quality = CompassQuality;

    /// Adds a reading to the sums (and, when its direction slot is free, to the retained
    /// readings), and runs one stage of a refresh when one is due. O(1), no allocation; a
    /// non-finite sample is refused and changes nothing. The reading is rounded to `T`.
    fn push(&mut self, sample: &Mag2Sample) -> Result<Pushed> {
        self.core.push(sample.t_s, &sample.mag.map(T::of))
    }

    /// Samples accepted, coverage of the retained readings about the current calibration,
    /// and `ready` exactly when [`Calibrator::solve`] succeeds (it runs the solve: a few
    /// microseconds, independent of the number of readings).
    fn progress(&self) -> Progress {
        self.core.progress()
    }

    /// A fresh solve from the current sums (all stages of a refresh at once), with the
    /// batch fit's refusals. Does not change the calibrator.
    fn solve(&self) -> Result<Solution<CompassCalibration2dIn<T>>> {
        self.core.solve().map(narrowed)
    }

    fn reset(&mut self) {
        self.core.reset();
    }
}

impl<T: Real> OnlineCalibrator for OnlineEllipseCalibrator<T> {
    /// The latest refresh's successful solution. A refresh that is refused (e.g. while
    /// forgetting, after a long straight drive) keeps the previous estimate;
    /// `progress().ready` says whether the current data would support a new one.
    fn estimate(&self) -> Option<Solution<CompassCalibration2dIn<T>>> {
        self.core.estimate().map(narrowed)
    }
}

/// The saved state of an [`OnlineEllipseCalibrator`]: everything it learned and the
/// refresh in progress, so a restored calibrator continues bit for bit.
pub type OnlineEllipseState = OnlineConicState<OnlineEllipseConfig, CompassCalibration2d>;

// For `f64` only, as the other per-sample types' persistence (a `T` to infer would make
// `OnlineEllipseCalibrator::restore(state)` ambiguous).
impl Persistent for OnlineEllipseCalibrator {
    type State = OnlineEllipseState;
    const SNAPSHOT_VERSION: u32 = 1;

    fn state(&self) -> OnlineEllipseState {
        self.core.state()
    }

    fn from_state(state: OnlineEllipseState) -> Result<Self> {
        OnlineCore::restore(state).map(|core| Self { core })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::online::ellipse::refresh::STAGES;
    use nalgebra::Vector2;
    use truenorth_core::Error;

    fn turn(n: usize, span_deg: f64) -> impl Iterator<Item = Mag2Sample> {
        (0..n).map(move |k| {
            let psi = (span_deg * k as f64 / n as f64).to_radians();
            Mag2Sample {
                t_s: k as f64,
                mag: Vector2::new(3.0 + 2.0 * psi.cos(), -1.0 - 1.5 * psi.sin()),
            }
        })
    }

    #[test]
    fn coverage_of_a_full_and_a_half_turn() {
        let mut cal = OnlineEllipseCalibrator::new(OnlineEllipseConfig::default()).unwrap();
        for s in turn(180, 180.0) {
            cal.push(&s).unwrap();
        }
        assert!(matches!(
            cal.solve(),
            Err(Error::InsufficientCoverage { .. })
        ));
        for s in turn(360, 360.0) {
            cal.push(&s).unwrap();
        }
        let sol = cal.solve().unwrap();
        assert_eq!(sol.quality.fit.coverage, 1.0);
        assert!((sol.params.hard_iron - Vector2::new(3.0, -1.0)).norm() < 1e-9);
    }

    /// A refresh spread over pushes gives exactly the solve of the sums it started from.
    #[test]
    fn refresh_stages_give_the_solve() {
        let config = OnlineEllipseConfig {
            refresh_interval_samples: 1_000_000,
            ..Default::default()
        };
        let mut cal = OnlineEllipseCalibrator::new(config).unwrap();
        let mut at_start = None;
        // 12° per reading: the first refresh, at `min_samples`, sees a full turn.
        for (k, s) in turn(400, 4800.0).enumerate() {
            let pushed = cal.push(&s).unwrap();
            if k + 1 == config.min_samples as usize {
                at_start = Some(cal.solve());
            }
            if k + 1 < config.min_samples as usize + STAGES as usize - 1 {
                assert_eq!(pushed, Pushed::Accepted);
            } else if k + 1 == config.min_samples as usize + STAGES as usize - 1 {
                assert_eq!(pushed, Pushed::NewEstimate);
            }
        }
        assert_eq!(at_start.map(|r| r.ok()), Some(cal.estimate()));
        assert!(cal.estimate().is_some());
    }

    /// Refresh starts over `n` readings of a steady turn, with the given half-life.
    fn refreshes(n: usize, half_life: Option<f64>) -> usize {
        let config = OnlineEllipseConfig {
            forgetting_half_life_samples: half_life,
            ..Default::default()
        };
        let mut cal = OnlineEllipseCalibrator::new(config).unwrap();
        let mut started = 0;
        for s in turn(n, 360.0 * n as f64 / 720.0) {
            cal.push(&s).unwrap();
            // The push that starts a refresh runs its first stage.
            started += usize::from(cal.refresh_stage() == Some(1));
        }
        started
    }

    /// Refreshes thin out as the readings in the sums grow: one per 32 readings up to
    /// 2,048, then one per 64th of the readings, about 64·ln(n/2048) more. Forgetting caps
    /// the memory, and so the spacing, at a half-life: with a half-life under 64 × 32
    /// readings they stay one per 32 readings.
    #[test]
    fn refreshes_thin_out_with_the_readings_the_sums_weigh() {
        let n = 200_000;
        let logarithmic = 64.0 + 64.0 * (n as f64 / 2048.0).ln();
        let got = refreshes(n, None) as f64;
        assert!(
            (got - logarithmic).abs() <= 0.05 * logarithmic,
            "{got} refreshes, expected about {logarithmic}"
        );
        let forgetting = refreshes(n, Some(1_000.0));
        assert!(
            forgetting.abs_diff(n / 32) <= 2,
            "{forgetting} refreshes with forgetting, expected one per 32 readings"
        );
    }
}
