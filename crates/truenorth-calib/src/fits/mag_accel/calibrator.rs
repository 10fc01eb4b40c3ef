//! Joint calibration of a magnetometer and an accelerometer mounted together: the
//! accelerometer's bias, scale and cross-axis sensitivity, the magnetometer's hard and soft
//! iron, the rotation between the two sensors, and — where the readings hold runs of shots
//! aimed at one target while the instrument rolls — the pointing axis, from static or slow
//! readings.
//!
//! What a tilt-compensated heading needs is more than two separate ellipsoid fits: those
//! leave each sensor's frame free to rotate (any rotation of a calibrated sphere is still a
//! sphere), so the field and gravity come out in frames a few degrees apart, and the heading
//! wobbles by about that as the instrument rolls. Steps of [`fit_mag_accel`]:
//! 1. Fit each sensor's ellipsoid ([`crate::fit_ellipsoid`]) as a start, refusing only data
//!    that cannot give one (too few, planar, not an ellipsoid, or a geometry that could not
//!    determine it within [`INITIAL_FIT_BOUND_DEG`]): a few dozen shots often determine one
//!    sensor's ellipsoid poorly on its own, and the joint fit, whose constraints tie the two
//!    together, is judged by its own bound.
//! 2. Align the two frames in closed form: the angle between gravity and the field is the
//!    same in every reading, `ûᵢᵀ M v̂ᵢ = s`, linear and homogeneous in `(M, s)`; the
//!    smallest singular vector gives `M`, and its nearest rotation (polar decomposition) the
//!    alignment — any rotation, so sensors mounted with swapped axes are found too.
//! 3. Refine everything jointly by Levenberg–Marquardt (residuals in `mag_accel_solve`),
//!    each residual group weighted by its own estimated noise.
//! 4. Find runs of shots sharing a pointing direction (`mag_accel_runs`); if there are any,
//!    add the pointing axis and their residuals and refine again. The body frame is then
//!    turned so that x is the pointing axis.
//! 5. Report: each sensor's residual, the dip and its spread, the alignment, the runs, and
//!    the heading error bound propagated from the parameters' covariance to the heading of
//!    the pointing axis over a grid of attitudes (pitch within ±60°, any roll and heading).
//!    The fit is refused when that bound, widened by the Student-t factor of the residuals'
//!    degrees of freedom (a noise estimated from a few dozen shots may come out small by
//!    chance), exceeds the largest accepted one. Unlike the ellipsoid fit's determination
//!    test it takes the noise as estimated, without the floor of
//!    [`quality::MODEL_ERROR_REL`]: that floor describes continuous recordings of a
//!    tumbling sensor, while static averaged shots have far less noise, and the dip and run
//!    residuals expose the model errors the floor stands in for.

// `!(x <= limit)` and `!(x > 0.0)` are deliberate: they are true for NaN, so a NaN fails
// every check instead of slipping through one.
#![expect(clippy::neg_cmp_op_on_partial_ord)]

extern crate alloc;

use alloc::vec::Vec;
use core::ops::Range;

use nalgebra::{Matrix3, Rotation3, SMatrix, SVector, Vector3};
use truenorth_compass::CompassCalibration3d;
use truenorth_core::{
    Calibrator, Error, Progress, Pushed, Result, Solution, Validate, check_finite, check_finite3,
};

use crate::fits::ellipsoid::config::EllipsoidConfig;

use crate::fits::ellipsoid::calibrator::raw_coverage;
use crate::fits::ellipsoid::fit::fit_ellipsoid_readings;
use crate::fits::lm;
use crate::fits::mag_accel::calibration::{MagAccelCalibration, MagAccelSample};
use crate::fits::mag_accel::config::{
    INITIAL_FIT_BOUND_DEG, MIN_MAG_ACCEL_READINGS, MagAccelConfig,
};
use crate::fits::mag_accel::data::{Data, GroupSums, Weights};
use crate::fits::mag_accel::model::{
    BA, BM, CA, CM, LIMITS, Limits, Model, P, S, level_direction, unsym,
};
use crate::fits::mag_accel::readings::{
    MagAccelReading, MagAccelStore, SampleSlice, Sensor, SensorReadings,
};
use crate::fits::mag_accel::report::{MagAccelQuality, assemble};
use crate::fits::mag_accel::runs::{RunFinder, RunRule};
use crate::fits::mag_accel::solve::{aim_rms, normal_equations};
use crate::fits::normalise::Normaliser;
use crate::numerics::readings::Readings;
use crate::quality::{self, FitLimits};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Joint magnetometer + accelerometer calibrator (batch): stores every reading pushed and
/// fits them all with [`fit_mag_accel`] on `solve`.
///
/// The readings go to a [`MagAccelStore`]: a `Vec` of the samples by default
/// ([`Self::new`]), or one of the caller's own ([`Self::with_store`]: any
/// [`ReadingStore`](crate::ReadingStore) of six-wide readings, e.g. one that keeps most of
/// a long recording on disk); the fit is the same, bit for bit, whichever store holds them.
///
/// [`Calibrator::progress`] runs the whole fit to decide `ready` (so that it agrees with
/// `solve` exactly): it costs as much as `solve`. Call it now and then, not per sample.
#[derive(Debug, Clone)]
pub struct MagAccelCalibrator<S = Vec<MagAccelSample>> {
    samples: S,
    config: MagAccelConfig,
}

/// The default configuration, samples in memory.
impl Default for MagAccelCalibrator {
    fn default() -> Self {
        Self {
            samples: Vec::new(),
            config: MagAccelConfig::default(),
        }
    }
}

impl MagAccelCalibrator {
    /// A calibrator with the given configuration (validated), keeping the samples in
    /// memory.
    pub fn new(config: MagAccelConfig) -> Result<Self> {
        Self::with_store(config, Vec::new())
    }

    /// The readings stored so far.
    pub fn samples(&self) -> &[MagAccelSample] {
        &self.samples
    }
}

impl<S: MagAccelStore> MagAccelCalibrator<S> {
    /// A calibrator with the given configuration (validated) that keeps its readings in
    /// `store` (emptied first).
    pub fn with_store(config: MagAccelConfig, mut store: S) -> Result<Self> {
        config.validate()?;
        store.clear_samples();
        Ok(Self {
            samples: store,
            config,
        })
    }

    /// The store holding the readings.
    pub fn store(&self) -> &S {
        &self.samples
    }

    /// The configuration in use.
    pub fn config(&self) -> &MagAccelConfig {
        &self.config
    }
}

impl<S: MagAccelStore> Calibrator for MagAccelCalibrator<S> {
    type Sample = MagAccelSample;
    type Params = MagAccelCalibration;
    type Quality = MagAccelQuality;

    fn push(&mut self, sample: &MagAccelSample) -> Result<Pushed> {
        check_finite("timestamp t_s", sample.t_s)?;
        check_finite3("magnetometer reading", &sample.mag)?;
        check_finite3("accelerometer reading", &sample.acc)?;
        self.samples.push_sample(sample)?;
        Ok(Pushed::Accepted)
    }

    /// `ready` runs the fit; `coverage` is the magnetometer's information share before the
    /// fit (see [`crate::EllipsoidCalibrator`]). A store that cannot replay its readings
    /// reports no coverage and not ready.
    fn progress(&self) -> Progress {
        let mags = SensorReadings::new(&self.samples, Sensor::Mag);
        Progress {
            samples: self.samples.len(),
            coverage: raw_coverage(&mags).unwrap_or(0.0),
            ready: self.solve().is_ok(),
        }
    }

    fn solve(&self) -> Result<Solution<MagAccelCalibration, MagAccelQuality>> {
        fit_mag_accel_readings(&self.samples, &self.config)
    }

    fn reset(&mut self) {
        self.samples.clear_samples();
    }
}

/// Smallest standard deviation a residual group is given, relative: keeps the weights
/// finite on noise-free data.
const SIGMA_FLOOR: f64 = 1e-7;

/// Rounds of re-estimating the groups' noise and refitting.
const VARIANCE_ROUNDS: usize = 3;

/// The joint calibration of `samples` with its quality report, or a typed refusal saying
/// why the data cannot support one. See the module documentation for the steps.
pub fn fit_mag_accel(
    samples: &[MagAccelSample],
    config: &MagAccelConfig,
) -> Result<Solution<MagAccelCalibration, MagAccelQuality>> {
    fit_mag_accel_readings(&SampleSlice(samples), config)
}

/// [`fit_mag_accel`] of readings replayed from wherever they are kept (see [`Readings`];
/// each reading `[mag; acc]`, a [`MagAccelReading`]): the same result, bit for bit, as of
/// the same samples in one slice. Every pass of the fit goes over them in order and keeps
/// no copy of them: at most a few megabytes of frames and shots for the runs of step 4 (a
/// run, or a stretch of shots aimed one way, longer than that takes more passes), so its
/// memory does not grow with the recording. An error replaying them is returned as it is.
pub fn fit_mag_accel_readings<R: Readings<6> + ?Sized>(
    readings: &R,
    config: &MagAccelConfig,
) -> Result<Solution<MagAccelCalibration, MagAccelQuality>> {
    fit(&Joint(readings), config, LIMITS)
}

/// [`fit_mag_accel_readings`] keeping at most `limits` of the readings at once (the
/// result is the same whatever they are; small ones make more passes).
#[cfg(test)]
pub(crate) fn fit_mag_accel_within<R: Readings<6> + ?Sized>(
    readings: &R,
    config: &MagAccelConfig,
    limits: Limits,
) -> Result<Solution<MagAccelCalibration, MagAccelQuality>> {
    fit(&Joint(readings), config, limits)
}

/// Readings of any kind, sized, so that the fit takes them as one type.
struct Joint<'a, R: ?Sized>(&'a R);

impl<R: Readings<6> + ?Sized> Readings<6> for Joint<'_, R> {
    fn len(&self) -> usize {
        self.0.len()
    }

    fn replay(&self, run: &mut dyn FnMut(&[MagAccelReading])) -> Result<()> {
        self.0.replay(run)
    }

    fn replay_range(
        &self,
        start: usize,
        end: usize,
        run: &mut dyn FnMut(&[MagAccelReading]),
    ) -> Result<()> {
        self.0.replay_range(start, end, run)
    }

    fn in_memory(&self) -> Option<&[MagAccelReading]> {
        self.0.in_memory()
    }

    fn shared(&self) -> Option<&(dyn Readings<6> + Sync)> {
        self.0.shared()
    }
}

fn fit(
    readings: &dyn Readings<6>,
    config: &MagAccelConfig,
    limits: Limits,
) -> Result<Solution<MagAccelCalibration, MagAccelQuality>> {
    config.validate()?;
    check_readings(readings)?;
    // Step 1.
    let Start {
        acc_fit,
        mag_fit,
        data,
        mut theta,
    } = start(readings, config, limits)?;
    // Step 2.
    let (r0, s0) = initial_alignment(&data, &theta)?;
    theta[S] = s0;
    let mut w = initial_weights(&data, &r0, &theta, &acc_fit, &mag_fit)?;
    // Step 3.
    let no_runs: Vec<Range<usize>> = Vec::new();
    theta = refine(&data, &no_runs, &mut w, &r0, theta, config)?;
    // Step 4.
    let (no_runs_theta, no_runs_w) = (theta, w);
    let mut runs = Vec::new();
    if config.find_runs {
        runs = aimed_runs(&data, &r0, &theta, config)?;
        if !runs.is_empty() {
            w.aim = 1.0 / aim_rms(&data, &runs, &r0, &theta)?.max(SIGMA_FLOOR);
            theta = refine(&data, &runs, &mut w, &r0, theta, config)?;
        }
    }
    // Step 5.
    let report = |theta: &SVector<f64, P>, runs: &[Range<usize>], w: &Weights| {
        finish(&data, &r0, theta, runs, w, config)
    };
    let with_runs = report(&theta, &runs, &w)?;
    if runs.is_empty() || with_runs.is_ok() {
        return with_runs;
    }
    // The runs are an option, not a condition: runs found by chance in a long recording
    // (a few consecutive readings rolling about the pointing axis) can leave the pointing
    // axis less certain than the calibration without them. Those readings still count as
    // readings; only the pointing axis falls back to the accelerometer's x.
    report(&no_runs_theta, &[], &no_runs_w)?.or(with_runs)
}

/// Refuses too few readings and non-finite ones (the first, magnetometer before
/// accelerometer).
fn check_readings(readings: &dyn Readings<6>) -> Result<()> {
    if readings.len() < MIN_MAG_ACCEL_READINGS {
        return Err(Error::TooFewPoints {
            got: readings.len(),
            need: MIN_MAG_ACCEL_READINGS,
        });
    }
    let mut first_bad = Ok(());
    readings.replay(&mut |run| {
        for r in run {
            if first_bad.is_ok() {
                first_bad = check_finite3("magnetometer reading", &Sensor::Mag.of(r))
                    .and_then(|_| check_finite3("accelerometer reading", &Sensor::Acc.of(r)));
            }
        }
    })?;
    first_bad
}

/// Step 1's outcome: each sensor's own ellipsoid, the readings normalised, and the joint
/// parameters the ellipsoids give.
struct Start<'a> {
    acc_fit: Solution<CompassCalibration3d>,
    mag_fit: Solution<CompassCalibration3d>,
    data: Data<'a>,
    theta: SVector<f64, P>,
}

/// Step 1: each sensor's ellipsoid, accepted up to [`INITIAL_FIT_BOUND_DEG`], as the start
/// of the joint fit, in the normalised readings' units.
fn start<'a>(
    readings: &'a dyn Readings<6>,
    config: &MagAccelConfig,
    limits: Limits,
) -> Result<Start<'a>> {
    let start = EllipsoidConfig {
        limits: FitLimits {
            max_heading_error_bound_deg: INITIAL_FIT_BOUND_DEG,
            ..config.ellipsoid.limits
        },
        ..config.ellipsoid
    };
    let acc = SensorReadings::new(readings, Sensor::Acc);
    let mag = SensorReadings::new(readings, Sensor::Mag);
    let acc_fit = fit_ellipsoid_readings(&acc, &start)?;
    let mag_fit = fit_ellipsoid_readings(&mag, &start)?;
    let na = Normaliser::of_finite(&acc, "point")?;
    let nm = Normaliser::of_finite(&mag, "point")?;
    let mut theta = SVector::<f64, P>::zeros();
    let put = |theta: &mut SVector<f64, P>,
               c0: usize,
               b0: usize,
               sol: &Solution<CompassCalibration3d>,
               n: &Normaliser<3>| {
        let c = (sol.params.hard_iron - n.centre) / n.scale;
        let b = sol.params.soft_iron * (n.scale / sol.quality.field_magnitude);
        theta.fixed_rows_mut::<3>(c0).copy_from(&c);
        for (k, v) in unsym(&b).iter().enumerate() {
            theta[b0 + k] = *v;
        }
    };
    put(&mut theta, CA, BA, &acc_fit, &na);
    put(&mut theta, CM, BM, &mag_fit, &nm);
    Ok(Start {
        acc_fit,
        mag_fit,
        data: Data::new(readings, na, nm, limits),
        theta,
    })
}

/// Step 2's weights: each sensor's from the residual of its own ellipsoid, the dip's from
/// its residual at the closed-form alignment.
fn initial_weights(
    data: &Data,
    r0: &Rotation3<f64>,
    theta: &SVector<f64, P>,
    acc_fit: &Solution<CompassCalibration3d>,
    mag_fit: &Solution<CompassCalibration3d>,
) -> Result<Weights> {
    let mut w = Weights {
        acc: 1.0 / acc_fit.quality.fit.residual_rms_rel.max(SIGMA_FLOOR),
        mag: 1.0 / mag_fit.quality.fit.residual_rms_rel.max(SIGMA_FLOOR),
        dip: 1.0,
        aim: 1.0,
    };
    w.dip = 1.0 / dip_rms(data, r0, theta)?.max(SIGMA_FLOOR);
    Ok(w)
}

/// Step 4: the runs of shots sharing a pointing direction among the readings, from their
/// level frames at the refined calibration.
fn aimed_runs(
    data: &Data,
    r0: &Rotation3<f64>,
    theta: &SVector<f64, P>,
    config: &MagAccelConfig,
) -> Result<Vec<Range<usize>>> {
    let mut finder = RunFinder::new(
        Vector3::x(),
        RunRule {
            tolerance_rad: config.run_tolerance_deg.to_radians(),
            min_roll_rad: config.run_min_roll_deg.to_radians(),
            min_shots: config.run_min_shots,
        },
        data.limits.stretch_frames,
    );
    let model = Model::of(theta, r0);
    loop {
        let mut k = 0usize;
        data.replay(|a, m| {
            if finder.wants(k) {
                finder.push(level_frame(a, m, &model));
            }
            k += 1;
        })?;
        if !finder.end_pass() {
            return Ok(finder.runs());
        }
    }
}

/// Step 5: the covariance, the calibration and its report, and the refusal on the heading
/// bound (widened to the Student-t quantile of σ's degrees of freedom). The outer error is
/// one replaying the readings, the inner one the refusal.
fn finish(
    data: &Data,
    r0: &Rotation3<f64>,
    theta: &SVector<f64, P>,
    runs: &[Range<usize>],
    w: &Weights,
    config: &MagAccelConfig,
) -> Result<Result<Solution<MagAccelCalibration, MagAccelQuality>>> {
    let Some((ne, sums)) = normal_equations(data, runs, w, r0, theta)? else {
        return Ok(Err(Error::Degenerate {
            reason: "the joint fit left a reading at a sensor's centre; check the input",
        }));
    };
    let Some(cov) = ne.jtj.try_inverse() else {
        return Ok(Err(Error::Degenerate {
            reason: "the readings do not determine the joint calibration (singular information); add readings in other orientations",
        }));
    };
    let out = match assemble(data, r0, theta, runs, &sums, &cov, w, config)? {
        Ok(out) => out,
        Err(e) => return Ok(Err(e)),
    };
    let dof = (3 * data.len()) as f64 - (P - 2 * usize::from(runs.is_empty())) as f64;
    Ok(quality::require_certain(
        &out.quality.mag,
        dof.max(1.0),
        config.max_heading_error_bound_deg,
    )
    .map(|()| out))
}

/// The rotation taking the magnetometer's calibrated frame into the accelerometer's, and
/// the cosine of the angle between gravity and the field, in closed form (step 2).
fn initial_alignment(data: &Data, theta: &SVector<f64, P>) -> Result<(Rotation3<f64>, f64)> {
    let m = Model::of(theta, &Rotation3::identity());
    // Σ zzᵀ for z = (vec(û v̂ᵀ), −1): the homogeneous least squares of ûᵀMv̂ − s = 0.
    let mut a = SMatrix::<f64, 10, 10>::zeros();
    data.replay(|acc, mag| {
        let (Some(u), Some(v)) = (
            (m.b_a * (acc - m.c_a)).try_normalize(1e-12),
            (m.b_m * (mag - m.c_m)).try_normalize(1e-12),
        ) else {
            return;
        };
        let mut z = SVector::<f64, 10>::zeros();
        for i in 0..3 {
            for j in 0..3 {
                z[3 * i + j] = u[i] * v[j];
            }
        }
        z[9] = -1.0;
        a += z * z.transpose();
    })?;
    let singular = Error::Degenerate {
        reason: "the readings do not determine the rotation between the magnetometer and the accelerometer; take readings in more orientations",
    };
    let e = nalgebra::SymmetricEigen::try_new(a, f64::EPSILON, 10_000).ok_or(singular.clone())?;
    let k = e.eigenvalues.imin();
    let x = e.eigenvectors.column(k);
    let mut mm = Matrix3::from_fn(|i, j| x[3 * i + j]);
    let mut s = x[9];
    if mm.determinant() < 0.0 {
        mm = -mm;
        s = -s;
    }
    let svd = mm.svd(true, true);
    let (Some(uu), Some(vt)) = (svd.u, svd.v_t) else {
        return Err(singular);
    };
    let mut rot = uu * vt;
    if rot.determinant() < 0.0 {
        return Err(singular);
    }
    rot = Rotation3::from_matrix_eps(&rot, 1e-12, 100, Rotation3::identity()).into_inner();
    let scale = svd.singular_values.mean();
    if !(scale > 0.0) {
        return Err(singular);
    }
    Ok((
        Rotation3::from_matrix_unchecked(rot),
        (s / scale).clamp(-1.0, 1.0),
    ))
}

/// RMS of the dip residuals `ûᵀRv̂ − s`.
fn dip_rms(data: &Data, r0: &Rotation3<f64>, theta: &SVector<f64, P>) -> Result<f64> {
    let w = Weights {
        acc: 0.0,
        mag: 0.0,
        dip: 1.0,
        aim: 0.0,
    };
    Ok(normal_equations(data, &[], &w, r0, theta)?
        .map(|(_, s)| (s.dip.0 / s.dip.1.max(1) as f64).sqrt())
        .unwrap_or(1.0))
}

/// The level frame (rows: the level axes in the accelerometer's frame) of the reading
/// `(a, mg)` (normalised) under the model `m`.
fn level_frame(a: &Vector3<f64>, mg: &Vector3<f64>, m: &Model) -> Option<Matrix3<f64>> {
    let u = (m.b_a * (a - m.c_a)).try_normalize(1e-12)?;
    let v = (m.b_m * (mg - m.c_m)).try_normalize(1e-12)?;
    let rows: [Vector3<f64>; 3] = [Vector3::x(), Vector3::y(), Vector3::z()]
        .map(|e| level_direction(&u, &(m.rot * v), &e).unwrap_or_else(Vector3::zeros));
    let f = Matrix3::from_columns(&rows);
    (f.determinant().abs() > 0.5).then_some(f)
}

/// Levenberg–Marquardt with the groups' noise re-estimated between rounds (variance
/// components): each group's σ² is its residual sum of squares over its share of the
/// redundancy.
fn refine(
    data: &Data,
    runs: &[Range<usize>],
    w: &mut Weights,
    r0: &Rotation3<f64>,
    mut theta: SVector<f64, P>,
    config: &MagAccelConfig,
) -> Result<SVector<f64, P>> {
    for _ in 0..VARIANCE_ROUNDS {
        let weights = *w;
        let out = lm::minimise_replayed(
            "joint magnetometer + accelerometer refinement",
            theta,
            config.max_iterations,
            // Three residuals per reading (accelerometer, magnetometer, dip), and one per
            // shot in a run.
            3 * data.len() + runs.iter().map(|r| r.len()).sum::<usize>(),
            |t| Ok(normal_equations(data, runs, &weights, r0, t)?.map(|(ne, _)| ne)),
        )??;
        theta = out.params;
        let Some((_, s)) = normal_equations(data, runs, w, r0, &theta)? else {
            break;
        };
        *w = reweighted(&s, runs.is_empty());
    }
    Ok(theta)
}

/// Weights from the groups' residuals: σ_g² = SS_g / (n_g · (1 − P_free/M)).
fn reweighted(s: &GroupSums, no_runs: bool) -> Weights {
    let free = (P - if no_runs { 2 } else { 0 }) as f64;
    let m = (s.acc.1 + s.mag.1 + s.dip.1 + s.aim.1) as f64;
    let redundancy = (1.0 - free / m).max(0.05);
    let sigma = |(ss, n): (f64, usize)| {
        if n == 0 {
            1.0
        } else {
            (ss / (n as f64 * redundancy)).sqrt().max(SIGMA_FLOOR)
        }
    };
    Weights {
        acc: 1.0 / sigma(s.acc),
        mag: 1.0 / sigma(s.mag),
        dip: 1.0 / sigma(s.dip),
        aim: 1.0 / sigma(s.aim),
    }
}
