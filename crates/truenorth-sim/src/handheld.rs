//! Hand-held / head-mounted 3-D motion: smooth random rotation about all axes with small
//! translations, for orientation-filter tests.

use core::f64::consts::TAU;

use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};
use truenorth_core::{
    NoiseSource, Result, STANDARD_GRAVITY_MPS2, SplitMix64, Validate, check_positive, check_range,
};

/// Ground truth of a hand-held motion at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MotionTruth {
    /// Time, seconds.
    pub t_s: f64,
    /// Attitude, body → NED.
    pub attitude: UnitQuaternion<f64>,
    /// Angular rate in body axes at `t_s` (instantaneous, not a mean over a step), rad/s.
    pub gyr_rps: Vector3<f64>,
    /// Linear acceleration in NED, m/s².
    pub accel_ned_mps2: Vector3<f64>,
    /// Specific force in body axes (what an ideal accelerometer reads), m/s².
    pub specific_force_mps2: Vector3<f64>,
}

/// Parameters of the motion (`Default`: one minute at 100 Hz, 1 rad/s and 0.5 m/s² peaks).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HandheldParams {
    /// Length, seconds.
    pub duration_s: f64,
    /// Sample rate, Hz.
    pub rate_hz: f64,
    /// Peak angular rate of each sinusoid, rad/s.
    pub rate_amplitude_rps: f64,
    /// Peak linear acceleration of each sinusoid, m/s².
    pub accel_amplitude_mps2: f64,
    /// Seed for the random frequencies and phases.
    pub seed: u64,
}

impl Default for HandheldParams {
    fn default() -> Self {
        Self {
            duration_s: 60.0,
            rate_hz: 100.0,
            rate_amplitude_rps: 1.0,
            accel_amplitude_mps2: 0.5,
            seed: 1,
        }
    }
}

impl Validate for HandheldParams {
    /// Duration and rate positive and finite, amplitudes finite and ≥ 0.
    fn validate(&self) -> Result<()> {
        check_positive("duration_s", self.duration_s)?;
        check_positive("rate_hz", self.rate_hz)?;
        check_range("rate_amplitude_rps", self.rate_amplitude_rps, 0.0, f64::MAX)?;
        check_range(
            "accel_amplitude_mps2",
            self.accel_amplitude_mps2,
            0.0,
            f64::MAX,
        )?;
        Ok(())
    }
}

/// One sinusoid per axis and term: frequency (Hz), phase (rad).
#[derive(Clone, Copy)]
struct Tone {
    freq_hz: f64,
    phase_rad: f64,
}

const TONES: usize = 3;

/// Generates the motion. Angular rate is a sum of three sinusoids per axis between 0.05 and
/// 1 Hz (head and hand motion is mostly below 1 Hz), integrated exactly per step as a
/// rotation vector at the mid-step rate; the translation is a zero-mean oscillation.
/// [`MotionTruth::gyr_rps`] is the analytic body rate at the sample time (what a gyro
/// following the instantaneous-rate convention reads).
pub fn handheld_motion(p: &HandheldParams) -> Result<Vec<MotionTruth>> {
    p.validate()?;
    let mut rng = SplitMix64::new(p.seed);
    let mut tone = || Tone {
        freq_hz: 0.05 + 0.95 * rng.uniform(),
        phase_rad: TAU * rng.uniform(),
    };
    let rot: [[Tone; TONES]; 3] = core::array::from_fn(|_| core::array::from_fn(|_| tone()));
    let lin: [Tone; 3] = core::array::from_fn(|_| tone());
    let wave = |tones: &[Tone], t: f64| -> f64 {
        tones
            .iter()
            .map(|k| (TAU * k.freq_hz * t + k.phase_rad).sin())
            .sum::<f64>()
            / tones.len() as f64
    };
    let rate = |t: f64| {
        Vector3::new(wave(&rot[0], t), wave(&rot[1], t), wave(&rot[2], t)) * p.rate_amplitude_rps
    };
    let accel = |t: f64| {
        Vector3::new(
            wave(&lin[0..1], t),
            wave(&lin[1..2], t),
            wave(&lin[2..3], t),
        ) * p.accel_amplitude_mps2
    };
    let dt = 1.0 / p.rate_hz;
    let n = check_range(
        "hand-held samples (duration × rate)",
        (p.duration_s * p.rate_hz).round(),
        0.0,
        crate::vehicle::MAX_SAMPLES,
    )? as usize;
    let g = Vector3::new(0.0, 0.0, STANDARD_GRAVITY_MPS2);
    let mut q = UnitQuaternion::identity();
    let mut out = Vec::with_capacity(n + 1);
    for k in 0..=n {
        let t = k as f64 * dt;
        if k > 0 {
            // Body rates: q_{k} = q_{k-1} ⊗ exp(ω_mid dt) (the mid-point rule is 2nd order).
            let w = rate(t - 0.5 * dt);
            q *= UnitQuaternion::from_scaled_axis(w * dt);
        }
        let a = accel(t);
        out.push(MotionTruth {
            t_s: t,
            attitude: q,
            gyr_rps: rate(t),
            accel_ned_mps2: a,
            specific_force_mps2: q.inverse() * (a - g),
        });
    }
    Ok(out)
}
