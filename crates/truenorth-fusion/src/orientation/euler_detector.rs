//! The orientation angle detector of WO 00/36376, every piece of it:
//!
//! 1. **Motion angles** from the (conditioned) gyro rates by the Z-Y-X Euler kinematics,
//!    `A_x = (J_x + tan β sin γ J_y + tan β cos γ J_z) dt`, `A_y = (cos γ J_y − sin γ J_z) dt`,
//!    `A_z = (sin γ J_y + cos γ J_z)/cos β dt`, with the previous pitch β and roll γ (the OCR
//!    lost a column and a sign; this is the standard form).
//! 2. **Integrated angles** `SA = previous angle + A`.
//! 3. **Static angles** from the accelerometers: pitch and roll from three with the roll
//!    quadrant ([`truenorth_accel::static_tilt`]), or from two by `asin` without it.
//! 4. **Tentative yaw** from the magnetometer levelled with the static pitch and roll
//!    ([`truenorth_compass::tilt_compensated_heading`]); with two magnetometers, `M_z` is
//!    reconstructed from the start-up field ([`truenorth_compass::MzReconstruction`]).
//! 5. **Correction definer** ([`CorrectionDefinerConfig`](super::CorrectionDefinerConfig)): modes (1)–(7).
//! 6. **Correction** `angle = SA − k·E`, `E = SA − static`, `k = dt/τ`, per axis and only
//!    where the static angle was judged accurate.
//! 7. **Coefficient table** ([`coefficient_table`]).
//! 8. **Gyro conditioning** ([`GyroConditioning`](super::GyroConditioning)) and 9. the **oscillation remover**, from
//!    `truenorth-gyro`.
//! 10. The **yaw + pitch variant** ([`EulerVariant::YawPitch`]).
//!
//! A step longer than `max_gap_s` restarts the detector from the sample's static angles
//! (status `gap`), as the quaternion filter does.
//!
//! The detector reports no σ (`sigma_rad` is `None`): its corrections switch on and off
//! with the definer's tests and pull towards an unfiltered static angle, which errs by the
//! body's acceleration over g at every corrected sample (32° of inclination on BROAD's
//! fast-translation trial 16), and it has no estimate of the gyro's bias; an error model
//! for that switching would have to be built and tested of its own, and a σ that has not
//! been tested is no promise.
//!
//! Frames: body x forward, y right, z down; yaw clockwise from magnetic north, pitch nose
//! up, roll right side down (the seed's pitch is positive nose down: see
//! `truenorth_accel::static_tilt`). The output quaternion is `Rz(yaw)·Ry(pitch)·Rx(roll)`,
//! body → NED. Unlike the seed, which reports yaw relative to its value at start-up, yaw here
//! is the magnetic heading, as every estimator's in this workspace.

use nalgebra::{UnitQuaternion, Vector3};
use truenorth_accel::static_tilt;
use truenorth_compass::{MzReconstruction, tilt_compensated_heading};
use truenorth_core::{
    AttitudeEstimate, AttitudeStatus, Error, EulerZyx, ImuSample, OrientationEstimator, Persistent,
    Result, STANDARD_GRAVITY_MPS2, Tilt, Validate, wrap_pi,
};

use super::euler_config::{EulerDetectorConfig, EulerVariant, coefficient_table};
use super::euler_state::EulerDetectorState;
use super::time_gap::Step;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Smallest |cos β| the Euler kinematics divide by: at pitch ±90° yaw and roll are not
/// separable and their rates are unbounded; the detector keeps integrating with this floor
/// (a limit of every Euler-angle detector, which the quaternion filter does not share).
const MIN_COS_PITCH: f64 = 1e-3;

/// The orientation angle detector of WO 00/36376 (see the module documentation).
///
/// ```
/// use nalgebra::Vector3;
/// use truenorth_core::{ImuSample, OrientationEstimator};
/// use truenorth_fusion::{EulerDetector, EulerDetectorConfig};
///
/// let mut d = EulerDetector::new(EulerDetectorConfig::default())?;
/// // Still and level, facing magnetic north.
/// for k in 0..500 {
///     let s = ImuSample::new_9d(
///         0.01 * k as f64,
///         Vector3::zeros(),
///         Vector3::new(0.0, 0.0, -9.81),
///         Vector3::new(20.0, 0.0, 45.0),
///     );
///     d.update(&s)?;
/// }
/// assert!(d.estimate().attitude.angle() < 1e-6);
/// # Ok::<(), truenorth_core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct EulerDetector {
    state: EulerDetectorState,
    /// The state before any sample (derived from the parameters): where a gap and
    /// [`OrientationEstimator::reset`] start again.
    fresh: EulerDetectorState,
    /// The M_z reconstruction for a two-axis magnetometer (derived from the parameters).
    mz: Option<MzReconstruction>,
}

impl EulerDetector {
    /// A detector with the given parameters.
    pub fn new(config: EulerDetectorConfig) -> Result<Self> {
        config.validate()?;
        Self::with_state(EulerDetectorState::initial(config)?)
    }

    /// The detector continuing from a valid `state`.
    fn with_state(state: EulerDetectorState) -> Result<Self> {
        let config = state.config;
        let mz = match config.startup_field {
            Some(f) => Some(MzReconstruction::new(f.total, f.inclination_rad)?),
            None => None,
        };
        Ok(Self {
            state,
            fresh: EulerDetectorState::initial(config)?,
            mz,
        })
    }

    /// The parameters in use.
    pub fn config(&self) -> &EulerDetectorConfig {
        &self.state.config
    }

    /// The gyro rates the variant needs, conditioned (rad/s; x is 0 for the yaw + pitch
    /// variant).
    fn rates(&mut self, sample: &ImuSample, dt_s: Option<f64>) -> Result<Vector3<f64>> {
        let g = &sample.gyr_rps;
        let raw = match self.state.config.variant {
            EulerVariant::Full => g.as_xyz().ok_or(Error::Unsupported {
                reason: "the full Euler detector needs gyros on x, y and z; use variant yaw_pitch for two",
            })?,
            EulerVariant::YawPitch => match (g.y, g.z) {
                (Some(y), Some(z)) => Vector3::new(0.0, y, z),
                _ => {
                    return Err(Error::Unsupported {
                        reason: "the yaw + pitch Euler detector needs gyros on y and z",
                    });
                }
            },
        };
        let Some(dt_s) = dt_s else {
            return Ok(raw);
        };
        let mut out = Vector3::zeros();
        for i in 0..3 {
            let mut j = self.state.conditioners[i].push(raw[i], dt_s)?;
            if let Some(r) = self.state.oscillation_removers.as_mut() {
                j = r[i].push(j)?;
            }
            out[i] = j;
        }
        Ok(out)
    }

    /// Static pitch and roll, and whether `| |a| − g |` is within mode (7)'s tolerance.
    fn static_tilt(&self, sample: &ImuSample) -> Option<(Tilt, bool)> {
        let a = &sample.acc_mps2;
        let g = STANDARD_GRAVITY_MPS2;
        let gravity_ok = |n: f64| {
            self.state
                .config
                .definer
                .gravity_tol_mps2
                .is_none_or(|tol| (n - g).abs() <= tol)
        };
        match self.state.config.variant {
            EulerVariant::YawPitch => {
                let fx = a.x?;
                (fx.abs() <= g).then(|| {
                    (
                        Tilt {
                            pitch_rad: (fx / g).asin(),
                            roll_rad: 0.0,
                        },
                        true,
                    )
                })
            }
            EulerVariant::Full => {
                if let Some(f) = a.as_xyz() {
                    // Three accelerometers: atan2 with the roll quadrant, and mode (7).
                    let t = static_tilt(&f).ok()?;
                    Some((t, gravity_ok(f.norm())))
                } else {
                    // Two (x, y): |a| = g is assumed, so no quadrant and no mode (7).
                    let (fx, fy) = (a.x?, a.y?);
                    let sp = (fx / g).clamp(-1.0, 1.0);
                    let pitch = sp.asin();
                    let cp = pitch.cos().max(MIN_COS_PITCH);
                    let roll = (-fy / (g * cp)).clamp(-1.0, 1.0).asin();
                    Some((
                        Tilt {
                            pitch_rad: pitch,
                            roll_rad: roll,
                        },
                        true,
                    ))
                }
            }
        }
    }

    /// The tentative yaw from the magnetometer levelled with the static tilt.
    fn tentative_yaw(&self, sample: &ImuSample, tilt: &Tilt) -> Result<Option<f64>> {
        if !self.state.config.use_mag {
            return Ok(None);
        }
        let m = &sample.mag;
        if let Some(m3) = m.as_xyz() {
            return Ok(Some(tilt_compensated_heading(&m3, tilt)));
        }
        let Some(mxy) = m.as_xy() else {
            return Ok(None);
        };
        let rec = self.mz.ok_or(Error::Unsupported {
            reason: "a two-axis magnetometer needs startup_field (total field and inclination) for the M_z reconstruction",
        })?;
        // A radicand far below zero (the field changed since start-up) leaves yaw to the gyro.
        Ok(rec.heading_rad(&mxy, tilt, self.state.angles.yaw_rad).ok())
    }

    fn step(&mut self, sample: &ImuSample, dt_s: f64) -> Result<AttitudeEstimate> {
        let j = self.rates(sample, Some(dt_s))?;
        let cfg = self.state.config;
        let prev = self.state.angles;
        // 1. Motion angles with the previous pitch and roll.
        let (sg, cg) = prev.roll_rad.sin_cos();
        let cb = {
            let c = prev.pitch_rad.cos();
            if c.abs() < MIN_COS_PITCH {
                MIN_COS_PITCH.copysign(c)
            } else {
                c
            }
        };
        let tb = prev.pitch_rad.sin() / cb;
        let motion = Vector3::new(
            (j.x + tb * (sg * j.y + cg * j.z)) * dt_s,
            (cg * j.y - sg * j.z) * dt_s,
            (sg * j.y + cg * j.z) / cb * dt_s,
        );
        // 2. Integrated angles (roll, pitch, yaw).
        let mut sa = [
            wrap_pi(prev.roll_rad + motion.x),
            prev.pitch_rad + motion.y,
            wrap_pi(prev.yaw_rad + motion.z),
        ];
        if cfg.variant == EulerVariant::YawPitch {
            sa[0] = 0.0;
        }
        let mut status = AttitudeStatus::default();
        // 3.–4. Static angles and tentative yaw.
        if let Some((tilt, gravity_ok)) = self.static_tilt(sample) {
            let yaw = self.tentative_yaw(sample, &tilt)?;
            let raw_static = [tilt.roll_rad, tilt.pitch_rad, yaw.unwrap_or(sa[2])];
            // 5. Correction definer: compare this sample's static angles (or their moving
            // averages) with the previous ones.
            let stat = match cfg.definer.moving_average {
                Some(_) => {
                    let mut s = [0.0; 3];
                    for i in 0..3 {
                        // Average the change-free part: the angles unwrapped near the last.
                        let base = self.state.previous_static.map_or(raw_static[i], |p| p[i]);
                        let near = base + wrap_pi(raw_static[i] - base);
                        s[i] = self.state.averages[i].push(near);
                    }
                    s
                }
                None => raw_static,
            };
            let accurate = self.judge(&stat, &motion, gravity_ok, yaw.is_some());
            self.state.previous_static = Some(stat);
            // 6.–7. Correction with the coefficient table.
            let m = if cfg.coefficient_table {
                coefficient_table(sa[1], sa[0])
            } else {
                [1.0; 3]
            };
            for i in 0..3 {
                if accurate[i] && !(i == 0 && cfg.variant == EulerVariant::YawPitch) {
                    let k = (dt_s / cfg.tau_s[i]).min(1.0) * m[i];
                    let e = wrap_pi(sa[i] - raw_static[i]);
                    sa[i] = wrap_pi(sa[i] - k * e);
                }
            }
            status.accel_used = accurate[0] || accurate[1];
            status.mag_used = accurate[2];
            status.mag_disturbed = yaw.is_some() && !accurate[2];
        }
        self.state.angles = through_vertical(sa);
        let q = self.state.angles.to_quaternion();
        Ok(AttitudeEstimate {
            t_s: sample.t_s,
            attitude: q,
            attitude_6d: None,
            gyro_bias_rps: Vector3::zeros(),
            sigma_rad: None,
            status,
        })
    }

    /// Modes (1)–(7): which of (roll, pitch, yaw) may be corrected.
    fn judge(
        &self,
        stat: &[f64; 3],
        motion: &Vector3<f64>,
        gravity_ok: bool,
        has_yaw: bool,
    ) -> [bool; 3] {
        let d = &self.state.config.definer;
        let Some(prev) = self.state.previous_static else {
            return [false; 3];
        };
        let change = |i: usize| wrap_pi(stat[i] - prev[i]);
        let tilt_ok = |i: usize, a: f64| match d.tilt_change_rad {
            None => true,
            Some(b) if d.tilt_change_against_motion => (change(i) - a).abs() <= b,
            Some(b) => change(i).abs() <= b,
        };
        let roll = gravity_ok && tilt_ok(0, motion.x);
        let pitch = gravity_ok && tilt_ok(1, motion.y);
        let yaw = has_yaw
            && gravity_ok
            && d.yaw_change_rad
                .is_none_or(|b| (change(2) - motion.z).abs() <= b);
        [roll, pitch, yaw]
    }
}

/// The Z-Y-X angles (roll, pitch, yaw) with a pitch integrated past ±90° expressed again
/// in range: `(γ, β, α)` and `(γ + π, ±π − β, α + π)` are the same attitude, so the
/// integration continues through the vertical instead of sticking at it.
fn through_vertical([roll, pitch, yaw]: [f64; 3]) -> EulerZyx {
    use core::f64::consts::{FRAC_PI_2, PI};
    let pitch = wrap_pi(pitch);
    if pitch.abs() <= FRAC_PI_2 {
        EulerZyx {
            yaw_rad: yaw,
            pitch_rad: pitch,
            roll_rad: roll,
        }
    } else {
        EulerZyx {
            yaw_rad: wrap_pi(yaw + PI),
            pitch_rad: PI.copysign(pitch) - pitch,
            roll_rad: wrap_pi(roll + PI),
        }
    }
}

impl OrientationEstimator for EulerDetector {
    /// A non-finite value, a timestamp that does not increase, or missing sensors for the
    /// chosen variant is an error and changes nothing. A step longer than `max_gap_s`
    /// restarts the detector from the sample (status `gap`); a step that would make such
    /// gaps the majority of the steps is an [`Error::Implausible`] time base.
    fn update(&mut self, sample: &ImuSample) -> Result<AttitudeEstimate> {
        sample.check_finite()?;
        let saved = self.state;
        let result = (|| {
            let dt = self.state.clock.dt_s(sample.t_s)?;
            let step = dt.map(|d| self.state.gaps.classify(d)).transpose()?;
            if let Some(step) = step {
                self.state.gaps.count(step);
            }
            let gap = step == Some(Step::Gap);
            if gap {
                // The conditioners' and the definer's memories span the gap: start afresh.
                self.state = EulerDetectorState {
                    clock: self.state.clock,
                    gaps: self.state.gaps,
                    ..self.fresh
                };
            }
            let Some(dt_s) = dt.filter(|_| !gap) else {
                // The first sample: the static angles (and tentative yaw) are the attitude.
                self.rates(sample, None)?;
                if let Some((tilt, _)) = self.static_tilt(sample) {
                    let yaw = self.tentative_yaw(sample, &tilt)?.unwrap_or(0.0);
                    self.state.angles = EulerZyx {
                        yaw_rad: yaw,
                        pitch_rad: tilt.pitch_rad,
                        roll_rad: tilt.roll_rad,
                    };
                    self.state.initialised = true;
                }
                let q = self.state.angles.to_quaternion();
                let estimate = AttitudeEstimate {
                    t_s: sample.t_s,
                    status: AttitudeStatus {
                        gap,
                        ..AttitudeStatus::default()
                    },
                    attitude_6d: None,
                    ..AttitudeEstimate::initial(q)
                };
                self.state.estimate = Some(estimate);
                return Ok(estimate);
            };
            let e = self.step(sample, dt_s)?;
            if !e.attitude.coords.iter().all(|v| v.is_finite()) {
                return Err(Error::OutOfRange {
                    what: "IMU reading (the update overflowed)",
                    value: f64::INFINITY,
                    min: 0.0,
                    max: 1e6,
                });
            }
            self.state.estimate = Some(e);
            Ok(e)
        })();
        if result.is_err() {
            self.state = saved;
        }
        result
    }

    /// The estimate after the last sample; before the first, level and facing north.
    fn estimate(&self) -> AttitudeEstimate {
        self.state.estimate.unwrap_or_else(|| AttitudeEstimate {
            attitude_6d: None,
            ..AttitudeEstimate::initial(UnitQuaternion::identity())
        })
    }

    /// Back to the state before any sample, with the same parameters.
    fn reset(&mut self) {
        self.state = self.fresh;
    }
}

impl Persistent for EulerDetector {
    type State = EulerDetectorState;
    const SNAPSHOT_VERSION: u32 = 1;

    fn state(&self) -> EulerDetectorState {
        self.state
    }

    /// Refuses a state that is not valid (see [`EulerDetectorState`]'s `validate`).
    fn from_state(state: EulerDetectorState) -> Result<Self> {
        state.validate()?;
        Self::with_state(state)
    }
}
