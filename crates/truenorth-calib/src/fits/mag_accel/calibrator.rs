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

use crate::fits::ellipsoid::fit::fit_ellipsoid;
use crate::fits::lm;
use crate::fits::mag_accel::calibration::{MagAccelCalibration, MagAccelSample};
use crate::fits::mag_accel::config::{
    INITIAL_FIT_BOUND_DEG, MIN_MAG_ACCEL_READINGS, MagAccelConfig,
};
use crate::fits::mag_accel::report::{MagAccelQuality, assemble};
use crate::fits::mag_accel::runs::{RunRule, find_runs};
use crate::fits::mag_accel::solve::{
    BA, BM, CA, CM, Data, GroupSums, Model, P, S, Weights, aim_rms, level_direction,
    normal_equations, unsym,
};
use crate::fits::normalise::Normaliser;
use crate::quality::{self, FitLimits};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Joint magnetometer + accelerometer calibrator (batch): stores every reading pushed and
/// fits them all with [`fit_mag_accel`] on `solve`. [`Calibrator::progress`] runs the fit
/// to decide `ready`.
#[derive(Debug, Clone, Default)]
pub struct MagAccelCalibrator {
    samples: Vec<MagAccelSample>,
    config: MagAccelConfig,
}

impl MagAccelCalibrator {
    /// A calibrator with the given configuration (validated).
    pub fn new(config: MagAccelConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self {
            samples: Vec::new(),
            config,
        })
    }

    /// The readings stored so far.
    pub fn samples(&self) -> &[MagAccelSample] {
        &self.samples
    }
}

impl Calibrator for MagAccelCalibrator {
    type Sample = MagAccelSample;
    type Params = MagAccelCalibration;
    type Quality = MagAccelQuality;

    fn push(&mut self, sample: &MagAccelSample) -> Result<Pushed> {
        check_finite("timestamp t_s", sample.t_s)?;
        check_finite3("magnetometer reading", &sample.mag)?;
        check_finite3("accelerometer reading", &sample.acc)?;
        self.samples.push(*sample);
        Ok(Pushed::Accepted)
    }

    /// `ready` runs the fit; `coverage` is the magnetometer's information share before the
    /// fit (see [`crate::EllipsoidCalibrator`]).
    fn progress(&self) -> Progress {
        let mags: Vec<Vector3<f64>> = self.samples.iter().map(|s| s.mag).collect();
        let mut c = crate::EllipsoidCalibrator::new(self.config.ellipsoid).unwrap_or_default();
        for (k, m) in mags.iter().enumerate() {
            let _ = c.push(&truenorth_core::Mag3Sample {
                t_s: k as f64,
                mag: *m,
            });
        }
        Progress {
            samples: self.samples.len(),
            coverage: c.progress().coverage,
            ready: self.solve().is_ok(),
        }
    }

    fn solve(&self) -> Result<Solution<MagAccelCalibration, MagAccelQuality>> {
        fit_mag_accel(&self.samples, &self.config)
    }

    fn reset(&mut self) {
        self.samples.clear();
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
    config.validate()?;
    check_readings(samples)?;
    let acc: Vec<Vector3<f64>> = samples.iter().map(|s| s.acc).collect();
    let mag: Vec<Vector3<f64>> = samples.iter().map(|s| s.mag).collect();
    // Step 1.
    let Start {
        acc_fit,
        mag_fit,
        na,
        nm,
        data,
        mut theta,
    } = start(&acc, &mag, config)?;
    // Step 2.
    let (r0, s0) = initial_alignment(&data, &theta)?;
    theta[S] = s0;
    let mut w = initial_weights(&data, &r0, &theta, &acc_fit, &mag_fit);
    // Step 3.
    let no_runs: Vec<Range<usize>> = Vec::new();
    theta = refine(&data, &no_runs, &mut w, &r0, theta, config)?;
    // Step 4.
    let (no_runs_theta, no_runs_w) = (theta, w);
    let mut runs = Vec::new();
    if config.find_runs {
        runs = aimed_runs(&data, samples.len(), &r0, &theta, config);
        if !runs.is_empty() {
            w.aim = 1.0 / aim_rms(&data, &runs, &r0, &theta).max(SIGMA_FLOOR);
            theta = refine(&data, &runs, &mut w, &r0, theta, config)?;
        }
    }
    // Step 5.
    let report = |theta: &SVector<f64, P>, runs: &[Range<usize>], w: &Weights| {
        finish(
            samples,
            &data,
            (&na, &nm),
            &r0,
            theta,
            runs,
            w,
            &mag,
            config,
        )
    };
    let with_runs = report(&theta, &runs, &w);
    if runs.is_empty() || with_runs.is_ok() {
        return with_runs;
    }
    // The runs are an option, not a condition: runs found by chance in a long recording
    // (a few consecutive readings rolling about the pointing axis) can leave the pointing
    // axis less certain than the calibration without them. Those readings still count as
    // readings; only the pointing axis falls back to the accelerometer's x.
    report(&no_runs_theta, &[], &no_runs_w).or(with_runs)
}

/// Refuses too few readings and non-finite ones.
fn check_readings(samples: &[MagAccelSample]) -> Result<()> {
    if samples.len() < MIN_MAG_ACCEL_READINGS {
        return Err(Error::TooFewPoints {
            got: samples.len(),
            need: MIN_MAG_ACCEL_READINGS,
        });
    }
    for s in samples {
        check_finite3("magnetometer reading", &s.mag)?;
        check_finite3("accelerometer reading", &s.acc)?;
    }
    Ok(())
}

/// Step 1's outcome: each sensor's own ellipsoid, the normalisers of the two sensors'
/// readings, the normalised readings, and the joint parameters the ellipsoids give.
struct Start {
    acc_fit: Solution<CompassCalibration3d>,
    mag_fit: Solution<CompassCalibration3d>,
    na: Normaliser<3>,
    nm: Normaliser<3>,
    data: Data,
    theta: SVector<f64, P>,
}

/// Step 1: each sensor's ellipsoid, accepted up to [`INITIAL_FIT_BOUND_DEG`], as the start
/// of the joint fit, in the normalised readings' units.
fn start(acc: &[Vector3<f64>], mag: &[Vector3<f64>], config: &MagAccelConfig) -> Result<Start> {
    let start = EllipsoidConfig {
        limits: FitLimits {
            max_heading_error_bound_deg: INITIAL_FIT_BOUND_DEG,
            ..config.ellipsoid.limits
        },
        ..config.ellipsoid
    };
    let acc_fit = fit_ellipsoid(acc, &start)?;
    let mag_fit = fit_ellipsoid(mag, &start)?;
    let na = Normaliser::of(acc)?;
    let nm = Normaliser::of(mag)?;
    let data = Data {
        acc: acc.iter().map(|a| (a - na.centre) / na.scale).collect(),
        mag: mag.iter().map(|m| (m - nm.centre) / nm.scale).collect(),
    };
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
        na,
        nm,
        data,
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
) -> Weights {
    let mut w = Weights {
        acc: 1.0 / acc_fit.quality.fit.residual_rms_rel.max(SIGMA_FLOOR),
        mag: 1.0 / mag_fit.quality.fit.residual_rms_rel.max(SIGMA_FLOOR),
        dip: 1.0,
        aim: 1.0,
    };
    w.dip = 1.0 / dip_rms(data, r0, theta).max(SIGMA_FLOOR);
    w
}

/// Step 4: the runs of shots sharing a pointing direction among the `n` readings, from
/// their level frames at the refined calibration.
fn aimed_runs(
    data: &Data,
    n: usize,
    r0: &Rotation3<f64>,
    theta: &SVector<f64, P>,
    config: &MagAccelConfig,
) -> Vec<Range<usize>> {
    let frames: Vec<Option<Matrix3<f64>>> =
        (0..n).map(|i| level_frame(data, i, r0, theta)).collect();
    find_runs(
        &frames,
        &Vector3::x(),
        &RunRule {
            tolerance_rad: config.run_tolerance_deg.to_radians(),
            min_roll_rad: config.run_min_roll_deg.to_radians(),
            min_shots: config.run_min_shots,
        },
    )
}

/// Step 5: the covariance, the calibration and its report, and the refusal on the heading
/// bound (widened to the Student-t quantile of σ's degrees of freedom).
#[allow(clippy::too_many_arguments)]
fn finish(
    samples: &[MagAccelSample],
    data: &Data,
    (na, nm): (&Normaliser<3>, &Normaliser<3>),
    r0: &Rotation3<f64>,
    theta: &SVector<f64, P>,
    runs: &[Range<usize>],
    w: &Weights,
    mag: &[Vector3<f64>],
    config: &MagAccelConfig,
) -> Result<Solution<MagAccelCalibration, MagAccelQuality>> {
    let (ne, sums) = normal_equations(data, runs, w, r0, theta).ok_or(Error::Degenerate {
        reason: "the joint fit left a reading at a sensor's centre; check the input",
    })?;
    let cov = ne.jtj.try_inverse().ok_or(Error::Degenerate {
        reason: "the readings do not determine the joint calibration (singular information); add readings in other orientations",
    })?;
    let out = assemble(
        samples, data, na, nm, r0, theta, runs, &sums, &cov, w, mag, config,
    )?;
    let dof = (3 * samples.len()) as f64 - (P - 2 * usize::from(runs.is_empty())) as f64;
    quality::require_certain(
        &out.quality.mag,
        dof.max(1.0),
        config.max_heading_error_bound_deg,
    )?;
    Ok(out)
}

/// The rotation taking the magnetometer's calibrated frame into the accelerometer's, and
/// the cosine of the angle between gravity and the field, in closed form (step 2).
fn initial_alignment(data: &Data, theta: &SVector<f64, P>) -> Result<(Rotation3<f64>, f64)> {
    let m = Model::of(theta, &Rotation3::identity());
    // Σ zzᵀ for z = (vec(û v̂ᵀ), −1): the homogeneous least squares of ûᵀMv̂ − s = 0.
    let mut a = SMatrix::<f64, 10, 10>::zeros();
    for (acc, mag) in data.acc.iter().zip(&data.mag) {
        let (Some(u), Some(v)) = (
            (m.b_a * (acc - m.c_a)).try_normalize(1e-12),
            (m.b_m * (mag - m.c_m)).try_normalize(1e-12),
        ) else {
            continue;
        };
        let mut z = SVector::<f64, 10>::zeros();
        for i in 0..3 {
            for j in 0..3 {
                z[3 * i + j] = u[i] * v[j];
            }
        }
        z[9] = -1.0;
        a += z * z.transpose();
    }
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
fn dip_rms(data: &Data, r0: &Rotation3<f64>, theta: &SVector<f64, P>) -> f64 {
    let w = Weights {
        acc: 0.0,
        mag: 0.0,
        dip: 1.0,
        aim: 0.0,
    };
    normal_equations(data, &[], &w, r0, theta)
        .map(|(_, s)| (s.dip.0 / s.dip.1.max(1) as f64).sqrt())
        .unwrap_or(1.0)
}

/// The level frame (rows: the level axes in the accelerometer's frame) of reading `i`.
fn level_frame(
    data: &Data,
    i: usize,
    r0: &Rotation3<f64>,
    theta: &SVector<f64, P>,
) -> Option<Matrix3<f64>> {
    let m = Model::of(theta, r0);
    let u = (m.b_a * (data.acc[i] - m.c_a)).try_normalize(1e-12)?;
    let v = (m.b_m * (data.mag[i] - m.c_m)).try_normalize(1e-12)?;
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
        let out = lm::minimise(
            "joint magnetometer + accelerometer refinement",
            theta,
            config.max_iterations,
            // Three residuals per reading (accelerometer, magnetometer, dip), and one per
            // shot in a run.
            3 * data.acc.len() + runs.iter().map(|r| r.len()).sum::<usize>(),
            |t| normal_equations(data, runs, w, r0, t).map(|(ne, _)| ne),
        )?;
        theta = out.params;
        let Some((_, s)) = normal_equations(data, runs, w, r0, &theta) else {
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
