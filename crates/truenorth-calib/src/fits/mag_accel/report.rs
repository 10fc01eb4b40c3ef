//! The report of the joint magnetometer + accelerometer calibration (see `mag_accel`): the
//! calibration in raw units and body axes, and the heading figures propagated from the
//! parameters' covariance.

use core::ops::Range;
use serde::{Deserialize, Serialize};

use nalgebra::{Rotation3, SMatrix, SVector, UnitQuaternion, Vector3};
use truenorth_accel::AccelTriadCalibration;
use truenorth_compass::CompassCalibration3d;
use truenorth_core::{
    CompassQuality, Error, FitQuality, Result, STANDARD_GRAVITY_MPS2, Solution, Validate,
};

use crate::fits::mag_accel::calibration::MagAccelCalibration;
use crate::fits::mag_accel::config::MagAccelConfig;
use crate::fits::mag_accel::data::{Data, GroupSums, Weights};
use crate::fits::mag_accel::model::{BM, CA, CM, Model, OMEGA, P, level_direction};
use crate::fits::mag_accel::readings::{Sensor, SensorReadings};
use crate::fits::mag_accel::solve::aim_rms;
use crate::fits::normalise::Normaliser;
use crate::numerics::linalg::sym_eigen3;
use crate::quality::{self, CompassUncertainty};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// The heading of the pointing axis (clockwise from magnetic north, radians) of a reading
/// `(a, m)` (normalised coordinates) under `theta`, for an accelerometer reading specific
/// force: the level frame is then (north, west, up).
pub(crate) fn heading_of(
    theta: &SVector<f64, P>,
    r0: &Rotation3<f64>,
    a: &Vector3<f64>,
    m: &Vector3<f64>,
) -> Option<f64> {
    let md = Model::of(theta, r0);
    let u = (md.b_a * (a - md.c_a)).try_normalize(1e-12)?;
    let v = (md.b_m * (m - md.c_m)).try_normalize(1e-12)?;
    let w = level_direction(&u, &(md.rot * v), &md.p)?;
    Some((-w.y).atan2(w.x))
}

/// Finite-difference step of the heading's derivatives, in the normalised units of the
/// parameters and of the readings.
const H: f64 = 1.5e-8;

/// The worst 3σ heading error over the test attitudes (pitch of the pointing axis within
/// ±60°, any roll and heading) from the covariance `cov`, and the RMS per-reading heading
/// noise for direction noise `sigma_a`, `sigma_m` (radians) on the two sensors, degrees.
pub(crate) fn heading_figures(
    theta: &SVector<f64, P>,
    r0: &Rotation3<f64>,
    cov: &SMatrix<f64, P, P>,
    sigma_a: f64,
    sigma_m: f64,
) -> (f64, f64) {
    let md = Model::of(theta, r0);
    let (Some(ba_inv), Some(bm_inv)) = (md.b_a.try_inverse(), md.b_m.try_inverse()) else {
        return (f64::INFINITY, f64::INFINITY);
    };
    // The body frame with x along p: level vectors in it map to the accelerometer's frame
    // by the rotation taking x onto p.
    let to_acc =
        Rotation3::rotation_between(&Vector3::x(), &md.p).unwrap_or_else(Rotation3::identity);
    let dip = (-md.s).clamp(-1.0, 1.0).asin();
    let mut worst: f64 = 0.0;
    let (mut noise_ss, mut count) = (0.0, 0usize);
    for att in test_attitudes() {
        let f_body = att.inverse_transform_vector(&Vector3::new(0.0, 0.0, -1.0));
        let h_body = att.inverse_transform_vector(&Vector3::new(dip.cos(), 0.0, dip.sin()));
        let u = to_acc * f_body;
        let v = md.rot.transpose() * (to_acc * h_body);
        let a = ba_inv * u + md.c_a;
        let m = bm_inv * v + md.c_m;
        let Some(h0) = heading_of(theta, r0, &a, &m) else {
            continue;
        };
        worst = worst.max(heading_variance(theta, r0, cov, &a, &m, h0));
        let ga = reading_sensitivity(
            &|uu: Vector3<f64>| heading_of(theta, r0, &(ba_inv * uu + md.c_a), &m),
            &u,
            h0,
        );
        let gm = reading_sensitivity(
            &|vv: Vector3<f64>| heading_of(theta, r0, &a, &(bm_inv * vv + md.c_m)),
            &v,
            h0,
        );
        noise_ss += sigma_a * sigma_a * ga + sigma_m * sigma_m * gm;
        count += 1;
    }
    let bound = (quality::BOUND_SIGMAS * worst.sqrt()).to_degrees();
    let noise = (noise_ss / count.max(1) as f64).sqrt().to_degrees();
    (
        if bound.is_finite() {
            bound
        } else {
            f64::INFINITY
        },
        noise,
    )
}

/// The test attitudes of [`heading_figures`]: pitch of the pointing axis −60° to 60° in
/// steps of 30°, roll in twelve and heading in eight equal steps.
fn test_attitudes() -> impl Iterator<Item = UnitQuaternion<f64>> {
    [-60.0f64, -30.0, 0.0, 30.0, 60.0]
        .into_iter()
        .flat_map(|pitch_deg| {
            (0..12).flat_map(move |k| {
                (0..8).map(move |j| {
                    truenorth_core::EulerZyx {
                        yaw_rad: core::f64::consts::TAU * j as f64 / 8.0,
                        pitch_rad: pitch_deg.to_radians(),
                        roll_rad: core::f64::consts::TAU * k as f64 / 12.0,
                    }
                    .to_quaternion()
                })
            })
        })
}

/// The variance `gᵀ cov g` of the heading `h0` of the reading `(a, m)`, `g` its gradient in
/// the parameters by forward differences.
fn heading_variance(
    theta: &SVector<f64, P>,
    r0: &Rotation3<f64>,
    cov: &SMatrix<f64, P, P>,
    a: &Vector3<f64>,
    m: &Vector3<f64>,
    h0: f64,
) -> f64 {
    let mut g = SVector::<f64, P>::zeros();
    for p in 0..P {
        let mut t = *theta;
        t[p] += H;
        if let Some(hp) = heading_of(&t, r0, a, m) {
            g[p] = truenorth_core::angle_diff(hp, h0) / H;
        }
    }
    g.dot(&(cov * g))
}

/// Per-reading noise: the sum of the squared sensitivities of the heading `h0` to the unit
/// vector `x` of one sensor, across it (`perturb` gives the heading with `x` replaced).
fn reading_sensitivity(
    perturb: &dyn Fn(Vector3<f64>) -> Option<f64>,
    x: &Vector3<f64>,
    h0: f64,
) -> f64 {
    let e1 = x.cross(&Vector3::new(0.3, -0.5, 0.8)).normalize();
    let e2 = x.cross(&e1);
    [e1, e2]
        .iter()
        .map(|e| {
            perturb(x + e * H).map_or(0.0, |hp| (truenorth_core::angle_diff(hp, h0) / H).powi(2))
        })
        .sum()
}

/// The calibration in raw units and body axes, and its report. The outer error is one
/// replaying the readings, the inner one a refusal.
#[allow(clippy::too_many_arguments)]
pub(crate) fn assemble(
    data: &Data,
    r0: &Rotation3<f64>,
    theta: &SVector<f64, P>,
    runs: &[Range<usize>],
    sums: &GroupSums,
    cov: &SMatrix<f64, P, P>,
    w: &Weights,
    config: &MagAccelConfig,
) -> Result<Result<Solution<MagAccelCalibration, MagAccelQuality>>> {
    let (na, nm) = (&data.na, &data.nm);
    let md = Model::of(theta, r0);
    let cal = match raw_calibration(&md, na, nm) {
        Ok(cal) => cal,
        Err(e) => return Ok(Err(e)),
    };
    let rms = |(ss, n): (f64, usize)| (ss / n.max(1) as f64).sqrt();
    let (sigma_a, sigma_m) = (rms(sums.acc), rms(sums.mag));
    let (bound, noise) = heading_figures(theta, r0, cov, 1.0 / w.acc, 1.0 / w.mag);
    // The magnetometer's own geometry, for its coverage, condition and dilution.
    let mag_raw = SensorReadings::new(data.readings, Sensor::Mag);
    let own = quality::assess_3d_of(&mag_raw, &cal.mag, cal.field)?;
    let sigmas = ParameterSigmas::of(cov, &md, na, nm);
    let dip_spread =
        (rms(sums.dip) / md.s.clamp(-1.0, 1.0).acos().sin().abs().max(1e-9)).to_degrees();
    let run_shots: usize = runs.iter().map(|r| r.len()).sum();
    let aim_rms_deg = if runs.is_empty() {
        0.0
    } else {
        aim_rms(data, runs, r0, theta)?.to_degrees() * 3f64.sqrt()
    };
    let quality = MagAccelQuality {
        mag: quality::with_expected_field(
            joint_compass_quality(
                data.len(),
                &own,
                sigma_m,
                (bound, noise),
                cal.field,
                &sigmas,
            ),
            config.expected_field,
        ),
        accel_residual_rms_rel: sigma_a,
        accel_bias_sigma: sigmas.accel_bias,
        dip_deg: cal.dip_rad.to_degrees(),
        dip_spread_deg: dip_spread,
        alignment_deg: Rotation3::from_matrix_unchecked(md.rot)
            .angle()
            .to_degrees(),
        alignment_sigma_deg: sigmas.alignment_rad.to_degrees(),
        runs: runs.len(),
        run_shots,
        pointing_offset_deg: md.p.angle(&Vector3::x()).to_degrees(),
        aim_rms_deg,
    };
    Ok(Ok(Solution {
        params: cal,
        quality,
    }))
}

/// The magnetometer's report of the joint fit: the points, coverage, condition and
/// dilution of its own geometry (`own`), its field-norm residual `sigma_m`, the joint
/// fit's heading figures `(bound, noise)` and the parameters' σ.
fn joint_compass_quality(
    points: usize,
    own: &CompassQuality,
    sigma_m: f64,
    (bound, noise): (f64, f64),
    field: f64,
    sigmas: &ParameterSigmas,
) -> CompassQuality {
    CompassQuality {
        fit: FitQuality {
            points,
            coverage: own.fit.coverage,
            residual_rms_rel: sigma_m,
            condition: own.fit.condition,
        },
        heading_error_3sigma_deg: bound,
        heading_error_systematic_deg: 0.0,
        heading_noise_rms_deg: noise,
        field_magnitude: field,
        field_ratio_to_expected: None,
        uncertainty: CompassUncertainty {
            dilution: own.uncertainty.dilution,
            hard_iron_sigma: sigmas.hard_iron,
            soft_iron_sigma_rel: sigmas.soft_iron_rel,
        },
    }
}

/// The calibration of the model `md` in raw units (undoing the normalisers `na`, `nm`) and
/// body axes (x along the pointing axis); refused when not finite.
fn raw_calibration(
    md: &Model,
    na: &Normaliser<3>,
    nm: &Normaliser<3>,
) -> Result<MagAccelCalibration> {
    let not_finite = Error::Degenerate {
        reason: "the joint fit is not finite; check the input scale",
    };
    // u = B_n((x − μ)/s − c_n) = (B_n/s)(x − (μ + s·c_n)).
    let acc_bias = na.centre + md.c_a * na.scale;
    let acc_unit = md.b_a / na.scale;
    let hard_iron = nm.centre + md.c_m * nm.scale;
    let mag_unit = md.b_m / nm.scale;
    let gravity = acc_unit.determinant().powf(-1.0 / 3.0);
    let field = mag_unit.determinant().powf(-1.0 / 3.0);
    if !(gravity.is_finite() && gravity > 0.0 && field.is_finite() && field > 0.0) {
        return Err(not_finite);
    }
    // Body frame: x along the pointing axis (the accelerometer's x without runs).
    let to_body =
        Rotation3::rotation_between(&md.p, &Vector3::x()).unwrap_or_else(Rotation3::identity);
    let accel = AccelTriadCalibration {
        bias: acc_bias,
        matrix: (to_body.into_inner() * acc_unit) * STANDARD_GRAVITY_MPS2,
    };
    let mag = CompassCalibration3d {
        hard_iron,
        soft_iron: mag_unit * field,
    };
    let cal = MagAccelCalibration {
        mag,
        mag_to_body: to_body.into_inner() * md.rot,
        accel,
        field,
        gravity,
        dip_rad: (-md.s).clamp(-1.0, 1.0).asin(),
    };
    cal.validate().map_err(|_| not_finite.clone())?;
    Ok(cal)
}

/// The predicted 1σ of the parameters the report gives, from the covariance.
struct ParameterSigmas {
    /// Each hard-iron component, the magnetometer's raw unit.
    hard_iron: [f64; 3],
    /// Each accelerometer bias component, its raw unit.
    accel_bias: [f64; 3],
    /// The soft iron's largest entry σ over the size of `B`.
    soft_iron_rel: f64,
    /// The alignment rotation (the norm of its three components), radians.
    alignment_rad: f64,
}

impl ParameterSigmas {
    fn of(cov: &SMatrix<f64, P, P>, md: &Model, na: &Normaliser<3>, nm: &Normaliser<3>) -> Self {
        let sd = |k: usize| cov[(k, k)].max(0.0).sqrt();
        let mut hard_iron = [0.0; 3];
        let mut accel_bias = [0.0; 3];
        for k in 0..3 {
            hard_iron[k] = sd(CM + k) * nm.scale;
            accel_bias[k] = sd(CA + k) * na.scale;
        }
        // The soft iron relative: σ of B's entries over B's size.
        let b_size = sym_eigen3(&md.b_m).map_or(1.0, |(l, _)| l.mean());
        let soft_iron_rel = (BM..BM + 6).map(sd).fold(0.0, f64::max) / b_size;
        let alignment_rad = (0..3)
            .map(|k| cov[(OMEGA + k, OMEGA + k)].max(0.0))
            .sum::<f64>()
            .sqrt();
        Self {
            hard_iron,
            accel_bias,
            soft_iron_rel,
            alignment_rad,
        }
    }
}

/// How far to trust a joint calibration.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct MagAccelQuality {
    /// The magnetometer's report: its points, coverage and condition (its own geometry),
    /// its field-norm residual, and the heading figures of the joint calibration (the 3σ
    /// bound is that of the heading of the pointing axis, propagated from every
    /// parameter's uncertainty, the accelerometer's and the alignment's included); its
    /// uncertainty has the σ of the joint fit and the dilution of its own geometry.
    pub mag: CompassQuality,
    /// RMS of `|f|/g − 1` of the calibrated accelerometer.
    pub accel_residual_rms_rel: f64,
    /// Predicted 1σ of each accelerometer bias component, its raw unit.
    pub accel_bias_sigma: [f64; 3],
    /// Mean dip, degrees.
    pub dip_deg: f64,
    /// RMS spread of the dip over the readings, degrees: how well gravity and the field
    /// keep their angle after calibration.
    pub dip_spread_deg: f64,
    /// Angle of the rotation between the magnetometer's and the accelerometer's calibrated
    /// frames, degrees.
    pub alignment_deg: f64,
    /// Predicted 1σ of that rotation (the norm of its three components), degrees.
    pub alignment_sigma_deg: f64,
    /// Runs of shots aimed at one target that were found.
    pub runs: usize,
    /// Shots in those runs.
    pub run_shots: usize,
    /// Angle between the pointing axis the runs found and the accelerometer's x axis,
    /// degrees (0 without runs).
    pub pointing_offset_deg: f64,
    /// RMS of the runs' pointing directions about their means, degrees (how steadily the
    /// target was held, plus what the model leaves).
    pub aim_rms_deg: f64,
}
