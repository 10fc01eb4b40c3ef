//! Few-shot calibration protocols of hand-held pointing instruments (compass-clinometers,
//! survey pointers) with known truth: an instrument whose magnetometer and accelerometer
//! have their own errors and are mounted a little askew of each other and of the pointing
//! axis, and the shots a user takes to calibrate it.
//!
//! The protocol of [`protocol_shots`] is the common one for such instruments: a few shots in
//! assorted directions, then runs of shots aimed at one target while the instrument is
//! rolled about its pointing axis (e.g. 8 + 2 × 8 = 24 shots). Every shot is a static,
//! averaged reading. Frames: body x is the pointing axis (forward), y right, z down; the
//! attitude rotates body → NED; the accelerometer reads specific force (level: `(0, 0, −g)`
//! in body axes).

use nalgebra::{Matrix3, Rotation3, Unit, Vector3};
use truenorth_core::{EulerZyx, NoiseSource, STANDARD_GRAVITY_MPS2, SplitMix64};

/// The errors of one instrument.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FewShotInstrument {
    /// Total field, µT.
    pub field_ut: f64,
    /// Inclination (dip) of the field, radians, positive down.
    pub dip_rad: f64,
    /// Magnetometer: `raw = mag_matrix · h_body + mag_hard_iron`, µT. The matrix holds the
    /// soft iron, the scale errors and the magnetometer's mounting rotation.
    pub mag_matrix: Matrix3<f64>,
    /// Magnetometer hard iron, µT.
    pub mag_hard_iron: Vector3<f64>,
    /// Accelerometer: `raw = acc_matrix · f_body + acc_bias`, m/s². The matrix holds scale
    /// and cross-axis errors and the accelerometer's mounting rotation.
    pub acc_matrix: Matrix3<f64>,
    /// Accelerometer bias, m/s².
    pub acc_bias: Vector3<f64>,
    /// Magnetometer noise per axis of an averaged shot, relative to the field.
    pub mag_noise_rel: f64,
    /// Accelerometer noise per axis of an averaged shot, relative to g.
    pub acc_noise_rel: f64,
    /// How far a shot of a run strays from its target, radians (1σ per axis: the hand
    /// holding the instrument on a mark).
    pub aim_sigma_rad: f64,
}

/// One shot: raw readings and the truth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shot {
    /// Raw magnetometer, µT.
    pub mag: Vector3<f64>,
    /// Raw accelerometer, m/s².
    pub acc: Vector3<f64>,
    /// True attitude, body → NED (yaw is the heading of the pointing axis).
    pub attitude: EulerZyx,
}

/// A rotation by a random axis and a normally distributed angle of `sigma_rad`.
fn small_rotation(rng: &mut SplitMix64, sigma_rad: f64) -> Rotation3<f64> {
    let v = Vector3::new(
        rng.normal(sigma_rad),
        rng.normal(sigma_rad),
        rng.normal(sigma_rad),
    );
    Rotation3::new(v)
}

/// A symmetric matrix with eigenvalues `1 ± spread` (uniform) along random axes.
fn random_symmetric(rng: &mut SplitMix64, spread: f64) -> Matrix3<f64> {
    let axes = small_rotation(rng, 2.0).into_inner();
    let d = Vector3::from_fn(|_, _| 1.0 + spread * (2.0 * rng.uniform() - 1.0));
    axes * Matrix3::from_diagonal(&d) * axes.transpose()
}

impl FewShotInstrument {
    /// An instrument with the errors typical of a hand-held device built from consumer
    /// sensors (a random draw, the same for a given seed): hard iron up to half the field,
    /// soft iron and scale ±10 %, magnetometer mounted 3° askew (1σ per axis), accelerometer
    /// bias 0.1 m/s², scale ±2 %, cross-axis ±1 % and mounting 1°; field 50 µT dipping
    /// 65°; shot noise 0.1 % of the field and of g; aim 0.2°.
    pub fn typical(seed: u64) -> Self {
        let mut rng = SplitMix64::new(seed);
        let deg = |d: f64| d.to_radians();
        let field_ut = 50.0;
        let mag_matrix =
            small_rotation(&mut rng, deg(3.0)).into_inner() * random_symmetric(&mut rng, 0.1);
        let mag_hard_iron =
            Vector3::from_fn(|_, _| field_ut * 0.5 * (2.0 * rng.uniform() - 1.0) / 3f64.sqrt());
        let cross = Matrix3::from_fn(|i, j| {
            if i == j {
                0.0
            } else {
                0.01 * (2.0 * rng.uniform() - 1.0)
            }
        });
        let scale = Matrix3::from_diagonal(&Vector3::from_fn(|_, _| {
            1.0 + 0.02 * (2.0 * rng.uniform() - 1.0)
        }));
        let acc_matrix = small_rotation(&mut rng, deg(1.0)).into_inner() * (scale + cross);
        let acc_bias = Vector3::from_fn(|_, _| rng.normal(0.1));
        Self {
            field_ut,
            dip_rad: deg(65.0),
            mag_matrix,
            mag_hard_iron,
            acc_matrix,
            acc_bias,
            mag_noise_rel: 0.001,
            acc_noise_rel: 0.001,
            aim_sigma_rad: deg(0.2),
        }
    }

    /// The field in NED, µT (magnetic north).
    pub fn field_ned(&self) -> Vector3<f64> {
        let (s, c) = self.dip_rad.sin_cos();
        Vector3::new(self.field_ut * c, 0.0, self.field_ut * s)
    }

    /// The raw readings of a shot at `attitude`, with shot noise.
    pub fn shot(&self, attitude: EulerZyx, rng: &mut SplitMix64) -> Shot {
        let r = attitude.to_quaternion();
        let h = r.inverse_transform_vector(&self.field_ned());
        let f = r.inverse_transform_vector(&Vector3::new(0.0, 0.0, -STANDARD_GRAVITY_MPS2));
        let mn = self.mag_noise_rel * self.field_ut;
        let an = self.acc_noise_rel * STANDARD_GRAVITY_MPS2;
        Shot {
            mag: self.mag_matrix * h + self.mag_hard_iron + Vector3::from_fn(|_, _| rng.normal(mn)),
            acc: self.acc_matrix * f + self.acc_bias + Vector3::from_fn(|_, _| rng.normal(an)),
            attitude,
        }
    }
}

/// A random attitude with the pointing axis at any heading, inclined up to `max_pitch_rad`
/// (uniform in the sine of the inclination, so the directions are spread evenly over that
/// band of the sphere), at any roll.
pub fn random_attitude(rng: &mut SplitMix64, max_pitch_rad: f64) -> EulerZyx {
    let tau = core::f64::consts::TAU;
    let s = max_pitch_rad.sin();
    EulerZyx {
        yaw_rad: tau * rng.uniform() - core::f64::consts::PI,
        pitch_rad: (s * (2.0 * rng.uniform() - 1.0)).asin(),
        roll_rad: tau * rng.uniform() - core::f64::consts::PI,
    }
}

/// A run of `n` shots aimed at one target (heading `yaw_rad`, inclination `pitch_rad`) with
/// the instrument rolled through a full turn about its pointing axis in equal steps from a
/// random start, each shot off its target by the instrument's aim error.
pub fn rolled_run(
    instrument: &FewShotInstrument,
    yaw_rad: f64,
    pitch_rad: f64,
    n: usize,
    rng: &mut SplitMix64,
) -> Vec<Shot> {
    let start = core::f64::consts::TAU * rng.uniform();
    (0..n)
        .map(|k| {
            let roll = start + core::f64::consts::TAU * k as f64 / n as f64;
            let aimed = EulerZyx {
                yaw_rad,
                pitch_rad,
                roll_rad: roll,
            }
            .to_quaternion();
            // The aim error turns the whole instrument a little (in the reference frame).
            let err = nalgebra::UnitQuaternion::from_rotation_matrix(&small_rotation(
                rng,
                instrument.aim_sigma_rad,
            ));
            instrument.shot(EulerZyx::from_quaternion(&(err * aimed)), rng)
        })
        .collect()
}

/// The protocol: `assorted` shots in assorted directions as a user is told to take them —
/// headings spread round the circle (equal steps from a random start, ±10°), pointing
/// alternately up and down by 30–50°, at random rolls — then `runs` runs of `per_run`
/// rolled shots, each aimed at a random target within ±45° of level.
pub fn protocol_shots(
    instrument: &FewShotInstrument,
    assorted: usize,
    runs: usize,
    per_run: usize,
    seed: u64,
) -> Vec<Shot> {
    let mut rng = SplitMix64::new(seed ^ 0x5EED_F0CA_11B8_A7E5);
    let tau = core::f64::consts::TAU;
    let start = tau * rng.uniform();
    let mut shots: Vec<Shot> = (0..assorted)
        .map(|k| {
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            let a = EulerZyx {
                yaw_rad: start + tau * k as f64 / assorted as f64 + rng.normal(10f64.to_radians()),
                pitch_rad: sign * (30.0 + 20.0 * rng.uniform()).to_radians(),
                roll_rad: tau * rng.uniform(),
            };
            instrument.shot(a, &mut rng)
        })
        .collect();
    for _ in 0..runs {
        let target = random_attitude(&mut rng, 45f64.to_radians());
        shots.extend(rolled_run(
            instrument,
            target.yaw_rad,
            target.pitch_rad,
            per_run,
            &mut rng,
        ));
    }
    shots
}

/// The pointing axis of the body in the sensors' frames is body x; this is its direction
/// in NED for `attitude` (for tests that compare headings of the pointing axis).
pub fn pointing_ned(attitude: &EulerZyx) -> Unit<Vector3<f64>> {
    Unit::new_normalize(attitude.to_quaternion() * Vector3::x())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shots_follow_the_instrument_model() {
        let ins = FewShotInstrument::typical(4);
        let mut rng = SplitMix64::new(1);
        let a = random_attitude(&mut rng, 1.0);
        let quiet = FewShotInstrument {
            mag_noise_rel: 0.0,
            acc_noise_rel: 0.0,
            ..ins
        };
        let s = quiet.shot(a, &mut rng);
        // Undo the errors: back to the field and gravity of the true attitude.
        let h = ins.mag_matrix.try_inverse().unwrap() * (s.mag - ins.mag_hard_iron);
        assert!((h.norm() - 50.0).abs() < 1e-9);
        let f = ins.acc_matrix.try_inverse().unwrap() * (s.acc - ins.acc_bias);
        assert!((f.norm() - STANDARD_GRAVITY_MPS2).abs() < 1e-9);
        // The angle between gravity and the field is the dip, in every shot.
        let cos = -f.normalize().dot(&h.normalize());
        assert!((cos.asin() - ins.dip_rad).abs() < 1e-9);
    }

    #[test]
    fn a_run_keeps_its_pointing_and_rolls_through_a_turn() {
        let ins = FewShotInstrument::typical(5);
        let mut rng = SplitMix64::new(2);
        let run = rolled_run(&ins, 0.7, 0.3, 8, &mut rng);
        let p0 = pointing_ned(&run[0].attitude);
        for s in &run {
            let angle = p0.angle(&pointing_ned(&s.attitude));
            assert!(angle < 5.0 * ins.aim_sigma_rad, "{}", angle.to_degrees());
        }
        let protocol = protocol_shots(&ins, 8, 2, 8, 9);
        assert_eq!(protocol.len(), 24);
        assert_eq!(
            protocol,
            protocol_shots(&ins, 8, 2, 8, 9),
            "deterministic by seed"
        );
    }
}
